"""PostgreSQL connections stay bounded (Django's pool, sized from DB_CONNECTIONS and WEB_CONCURRENCY), and a
request that cannot get a connection is a 503 with Retry-After, never a traceback."""
from __future__ import annotations

import pytest
from django.db import OperationalError
from django.test import Client
from django.urls import reverse

from studyapp import settings as app_settings
from studyapp.views_health import RETRY_AFTER_S, database_unavailable

pytestmark = pytest.mark.django_db
PG = "postgres://postgres@127.0.0.1:5432/studies"


def test_postgres_gets_a_pool_sized_from_the_worker_count(monkeypatch):
    monkeypatch.setenv("DATABASE_URL", PG)
    monkeypatch.setenv("DB_CONNECTIONS", "40")
    monkeypatch.setenv("WEB_CONCURRENCY", "4")
    config = app_settings.database_from_env()
    assert config["ENGINE"] == "django.db.backends.postgresql"
    assert config["CONN_MAX_AGE"] == 0                      # the pool and persistent connections exclude each other
    assert config["OPTIONS"]["pool"] == {"min_size": 1, "max_size": 10, "timeout": 5.0, "max_idle": 300.0}
    monkeypatch.setenv("WEB_CONCURRENCY", "64")
    assert app_settings.database_from_env()["OPTIONS"]["pool"]["max_size"] == 2      # never fewer than 2
    monkeypatch.setenv("DB_POOL", "0")
    config = app_settings.database_from_env()
    assert "pool" not in config.get("OPTIONS", {}) and config["CONN_MAX_AGE"] == 0


def test_sqlite_has_no_pool(monkeypatch):
    monkeypatch.delenv("DATABASE_URL", raising=False)
    assert "pool" not in app_settings.database_from_env()["OPTIONS"]


def test_bad_pool_settings_are_clear_errors(monkeypatch):
    from django.core.exceptions import ImproperlyConfigured

    monkeypatch.setenv("DATABASE_URL", PG)
    monkeypatch.setenv("WEB_CONCURRENCY", "0")
    with pytest.raises(ImproperlyConfigured, match="WEB_CONCURRENCY"):
        app_settings.database_from_env()


def test_the_pool_is_installed():
    import psycopg_pool

    assert psycopg_pool.ConnectionPool


def _pool_timeout() -> Exception:
    from psycopg_pool import PoolTimeout

    try:
        try:
            raise PoolTimeout("couldn't get a connection after 5.00 sec")
        except PoolTimeout as exc:
            raise OperationalError(str(exc)) from exc       # as Django's wrap_database_errors raises it
    except OperationalError as wrapped:
        return wrapped


NO_CONNECTION = [_pool_timeout, lambda: OperationalError("FATAL: sorry, too many clients already"),
                 lambda: OperationalError("database is locked"),
                 lambda: OperationalError('connection failed: connection to server at "127.0.0.1", port 5432 '
                                          "failed: Connection refused"),
                 lambda: OperationalError('connection is bad: connection to server on socket "/run/postgresql/'
                                          '.s.PGSQL.5432" failed: No such file or directory\n\tIs the server '
                                          "running locally and accepting connections on that socket?"),
                 lambda: OperationalError("connection failed: FATAL:  the database system is starting up"),
                 lambda: OperationalError("could not connect to server: No such file or directory"),
                 lambda: OperationalError("FATAL: remaining connection slots are reserved for roles with the "
                                          "SUPERUSER attribute")]
"""Errors that mean no database connection could be had: the pool's wait ran out, PostgreSQL refused or was not
there, SQLite stayed locked."""
OTHER_DATABASE_FAULTS = [lambda: OperationalError("no such table: studyapp_participant"),
                         lambda: OperationalError("no such column: studyapp_participant.seed"),
                         lambda: OperationalError('connection failed: connection to server at "127.0.0.1", port '
                                                  '5432 failed: FATAL:  password authentication failed for user '
                                                  '"studies"'),
                         lambda: OperationalError('connection failed: connection to server at "127.0.0.1", port '
                                                  '5432 failed: FATAL:  database "studies" does not exist'),
                         lambda: OperationalError("disk I/O error")]
"""OperationalErrors that are faults of the deployment or a bug, not a busy server: a plain 500."""


@pytest.mark.parametrize("error", NO_CONNECTION)
def test_no_connection_is_a_503_with_retry_after(monkeypatch, settings, error):
    from studyapp.participant import views

    settings.DEBUG = False

    def refuse(*args, **kwargs):
        raise error()

    monkeypatch.setattr(views, "participant_by_token", refuse)
    client = Client(raise_request_exception=False)
    r = client.get(reverse("studyapp:resume", args=["x" * 20]))
    assert r.status_code == 503
    assert r["Retry-After"] == str(RETRY_AFTER_S)
    text = r.content.decode()
    assert "reload" in text and "Traceback" not in text and "OperationalError" not in text


def test_a_failure_in_middleware_is_a_503_too(monkeypatch, settings):
    from django.contrib.sessions.backends.db import SessionStore

    settings.DEBUG = False

    def refuse(self, *args, **kwargs):
        raise _pool_timeout()

    monkeypatch.setattr(SessionStore, "load", refuse)
    client = Client(raise_request_exception=False)
    client.cookies["sessionid"] = "abcdefghijklmnop"
    r = client.get("/admin/login/")               # the login page reads the session (request.user)
    assert r.status_code == 503 and r["Retry-After"] == str(RETRY_AFTER_S)


@pytest.mark.parametrize("error", [lambda: ZeroDivisionError("division by zero"), *OTHER_DATABASE_FAULTS])
def test_other_errors_stay_a_plain_500(monkeypatch, settings, error):
    from studyapp.participant import views

    settings.DEBUG = False

    def fail(*args, **kwargs):
        raise error()

    monkeypatch.setattr(views, "participant_by_token", fail)
    r = Client(raise_request_exception=False).get(reverse("studyapp:resume", args=["x" * 20]))
    assert r.status_code == 500 and "Retry-After" not in r and b"Traceback" not in r.content


def test_the_cause_chain_is_read():
    assert database_unavailable(_pool_timeout())
    from psycopg_pool import PoolTimeout

    try:
        try:
            raise PoolTimeout("pool exhausted")                # the pool's own type, whatever its words
        except PoolTimeout as exc:
            raise OperationalError("wrapped") from exc
    except OperationalError as wrapped:
        assert database_unavailable(wrapped)
    assert not database_unavailable(ValueError("x"))
    assert not database_unavailable(None)
