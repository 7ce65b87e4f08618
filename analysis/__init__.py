"""Statistics, figures and reports for perceptual studies of emotive motion.

Plain pandas/scipy/pingouin/matplotlib; never imports Django nor ``generation``.

Entry points:
- :func:`analysis.report.write_report` (responses.csv, clips.csv, participants.csv -> report folder)
- ``python -m analysis RESPONSES CLIPS PARTICIPANTS --out DIR``
- :func:`analysis.simulate.simulate_study` and ``python -m analysis.simulate`` (synthetic participants)
"""
