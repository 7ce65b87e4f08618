"""Researchers' own stimuli: videos and motion files made elsewhere, imported into the clip catalogue beside the
generated clips (``python manage.py import_clips MANIFEST.csv``). Plain Python, no Django: the command and the
admin pass a catalogue step that writes the Clip row.

    manifest.py   the manifest CSV: columns, one checked row per line, paths kept inside the manifest's folder
    probe.py      what ffmpeg says about a video: container, codecs, duration, frame size, audio
    video.py      a video -> the delivery formats (H.264 MP4 with +faststart, optional VP9 WebM) and a poster
    motion.py     a BVH -> the importer's checks, the platform's renderer and the quality record
    run.py        one row staged, then committed all-or-nothing; the import report
"""
from .manifest import MANIFEST_COLUMNS, ManifestError, ManifestRow, read_manifest
from .run import REPORT_COLUMNS, ImportSettings, RowOutcome, import_manifest, write_report

__all__ = ["MANIFEST_COLUMNS", "REPORT_COLUMNS", "ImportSettings", "ManifestError", "ManifestRow", "RowOutcome",
           "import_manifest", "read_manifest", "write_report"]
