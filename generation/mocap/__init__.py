"""Bring your own motion capture: BVH and joint-position files -> Motions on the gait or gesture skeleton.

Django-free. ``python -m generation.mocap import PATH... --skeleton gait|gesture --out DIR [--labels CSV]
[--label-pattern REGEX] [--joint-map JSON] [--scale S] [--fps F] [--layout NAME]`` writes one Motion ``.npz``
per input and ``DIR/import_report.csv`` (``source, status, message, frames, fps, duration_s, mapped_joints,
unmapped_joints, retarget_max_error_m, height_m``). Modules:
- :mod:`.rigs`: joint-name normalisation (namespaces, separators, sides) and automatic maps for Mixamo, CMU,
  Biovision/MotionBuilder, 3ds Max Biped, Bandai-Namco and Kinect v2 names;
- :mod:`.positions`: CSV/NPY joint positions and named layouts (Emotion-Gait 16 joints, Kinect v2);
- :mod:`.labels`: emotion labels from a CSV or a file-name pattern, in the study vocabulary;
- :mod:`.importer`: one file -> Motion + report row (units, up axis, scaling, IK);
- :mod:`.bandai_namco`: the Bandai Namco Research Motion Dataset's layout, labels and held-out split by take;
- :mod:`.dataset_import`: a labelled dataset -> the real-capture corpus (process pool, report per file);
- :mod:`.emotion_gait_bml`: the Emotion-Gait BML walks (positions only) -> the corpus: checks, IK, split by
  performer; :mod:`.root_travel`: root travel of a walk captured in place, from the stance foot;
- :mod:`.real_corpus`: the real-capture corpus file (:class:`~.real_corpus.CorpusClip`, save/load, filters);
- :mod:`.cli`: the command (``import``, ``corpus``, ``dataset bandai-namco|emotion-gait-bml DIR --out CORPUS``).
See docs/mocap.md.
"""
from .importer import REPORT_COLUMNS, ImportOptions, ImportResult, import_file
from .rigs import RigMapError, auto_joint_map, normalise

__all__ = ["REPORT_COLUMNS", "ImportOptions", "ImportResult", "import_file", "RigMapError", "auto_joint_map",
           "normalise"]
