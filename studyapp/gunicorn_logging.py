"""A gunicorn logger that keeps participant credentials out of the access log.

    gunicorn studyapp.wsgi --logger-class studyapp.gunicorn_logging.RedactingLogger --access-logfile -

Every URL-bearing atom (request line %(r)s, path %(U)s, query %(q)s, referer %(f)s and the {referer}i header) goes
through studyapp.security.redact: /p/<token>/ becomes /p/***/ and PROLIFIC_PID=..., STUDY_ID=..., SESSION_ID=...
become NAME=***. The error log is filtered the same way.
"""
from __future__ import annotations

from gunicorn.glogging import Logger

from .security import RedactTokensFilter, redact

URL_ATOMS = ("r", "U", "q", "f", "{referer}i", "{origin}i")


class RedactingLogger(Logger):
    """gunicorn's logger with the participant credentials redacted from the access and error logs."""

    def setup(self, cfg):
        """Set up gunicorn's logs and add one RedactTokensFilter to each (not a second on a reload)."""
        super().setup(cfg)
        for log in (self.error_log, self.access_log):
            if not any(isinstance(f, RedactTokensFilter) for f in log.filters):
                log.addFilter(RedactTokensFilter())

    def atoms(self, resp, req, environ, request_time):
        """The access log's atoms with every URL-bearing one (URL_ATOMS) passed through studyapp.security.redact."""
        atoms = super().atoms(resp, req, environ, request_time)
        for key in URL_ATOMS:
            if isinstance(atoms.get(key), str):
                atoms[key] = redact(atoms[key])
        return atoms
