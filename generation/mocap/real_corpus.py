"""The real-capture corpus: labelled captured clips on our gait and gesture skeletons in one ``.npz``, with filters.

File layout (default ``var/mocap/bandai-namco.npz``, :data:`DEFAULT_PATH`; command lines take another from
``--corpus`` or the env var ``REAL_CORPUS``, :func:`real_corpus_path`). Per skeleton kind K in {gait, gesture}
that has clips:

- ``K_rotations`` (sum of frames, J, 4) float32 local unit quaternions (w, x, y, z);
- ``K_root_positions`` (sum of frames, 3) float32 metres, y-up;
- ``K_starts`` (clips + 1,) int64: clip i of kind K is rows ``starts[i]:starts[i+1]``, in the order of K's clips;
- ``K_offsets`` (J, 3) float64 metres, ``K_joints`` (J,) str, ``K_parents`` (J,) int64: the skeleton itself;

plus ``clips_json`` (JSON list, one object per clip, in file order: name, dataset, content, style, label, take,
split, skeleton, fps, frames, import_error_cm, height_m, source, metadata) and ``meta_json`` (JSON object:
dataset, licence, citation, skeletons {K: {height, build}}, split_rule, tool_version, and whatever else the writer
adds). Clips of one kind keep their relative order in ``clips_json``.
"""
from __future__ import annotations

import json
import math
import os
from collections.abc import Iterable, Mapping
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from generation.core.motion import Motion, MotionFormatError
from generation.core.skeleton import Skeleton
from generation.core.splits import SPLITS
from protocol.vocabulary import MODALITIES

REPO_ROOT = Path(__file__).resolve().parents[2]
DEFAULT_PATH = REPO_ROOT / "var" / "mocap" / "bandai-namco.npz"
ENV_VAR = "REAL_CORPUS"
DEFAULT_BML_PATH = REPO_ROOT / "var" / "mocap" / "emotion-gait-bml.npz"
"""The BML walks of Emotion-Gait in this file format (:mod:`generation.mocap.emotion_gait_bml`)."""
BML_ENV_VAR = "BML_CORPUS"

DATASETS = ("bandai-namco-1", "bandai-namco-2")
SKELETON_KINDS = MODALITIES
LICENCE = "CC BY-NC 4.0"
CITATION = ("M. Kobayashi, C.-C. Liao, K. Inoue, S. Yojima, M. Takahashi. Motion Capture Dataset for Practical Use "
            "of AI-based Motion Editing and Stylization. arXiv:2306.08861, 2023.")
SOURCE_URL = "https://github.com/BandaiNamcoResearchInc/Bandai-Namco-Research-Motiondataset"
TOOL_VERSION = "generation.mocap.real_corpus 1"

CLIP_FIELDS = ("name", "dataset", "content", "style", "label", "take", "split", "skeleton", "fps", "frames",
               "import_error_cm", "height_m", "source", "metadata")
"""Keys of each object in ``clips_json``."""


@dataclass
class CorpusClip:
    """One captured take on our skeleton, with its labels.

    Attributes:
        name: file stem, e.g. "dataset-1_walk_happy_001".
        dataset: "bandai-namco-1" or "bandai-namco-2".
        content: the dataset's content name (walk, walk-turn-left, bow, wave-left-hand, ...).
        style: the dataset's own style name (happy, normal, exhausted, masculinity, ...).
        label: study vocabulary where ``protocol.vocabulary.capture_label`` maps the style, else the style.
        take: take number from the file name (1, 2, ...).
        split: "train", "val" or "test", held out by take (a pure function of the file name).
        skeleton: "gait" (21 joints, whole body) or "gesture" (23 joints).
        motion: the Motion on that skeleton (30 fps, metres, y-up); its metadata carries captured=True, dataset,
            take, licence and citation.
        import_error_cm: the importer's error against the source's joint positions, centimetres (NaN unknown).
        height_m: the source's standing height, metres (NaN unknown).
        source: the source file's path as it was imported.
    """

    name: str
    dataset: str
    content: str
    style: str
    label: str
    take: int
    split: str
    skeleton: str
    motion: Motion
    import_error_cm: float = math.nan
    height_m: float = math.nan
    source: str = ""


def real_corpus_path(environ: Mapping[str, str] | None = None) -> Path:
    """The corpus file: ``environ["REAL_CORPUS"]`` when ``environ`` is given and sets it, else :data:`DEFAULT_PATH`
    (``<repo>/var/mocap/bandai-namco.npz``). Only the edges pass an environment (a command line's ``main``, the
    Django settings); library functions take the path as an argument and default to :data:`DEFAULT_PATH`."""
    return RealCorpora.from_environ(environ or {}).bandai


@dataclass(frozen=True)
class RealCorpora:
    """Where the two real-capture corpus files are: ``bandai`` (Bandai Namco, this module's) and ``bml`` (the BML
    walks of Emotion-Gait). The default is the built ones under ``var/mocap/``; an edge (a command line, the Django
    settings) builds another with :meth:`of` or :meth:`from_environ` and passes it down (a render worker gets it
    inside its job)."""

    bandai: Path = DEFAULT_PATH
    bml: Path = DEFAULT_BML_PATH

    @classmethod
    def of(cls, bandai: str | Path | None = None, bml: str | Path | None = None) -> RealCorpora:
        """The corpora at ``bandai`` and ``bml``, each the default where None or empty."""
        return cls(Path(bandai) if bandai else DEFAULT_PATH, Path(bml) if bml else DEFAULT_BML_PATH)

    @classmethod
    def from_environ(cls, environ: Mapping[str, str]) -> RealCorpora:
        """The corpora that ``$REAL_CORPUS`` and ``$BML_CORPUS`` name in ``environ`` (defaults where unset)."""
        return cls.of(environ.get(ENV_VAR), environ.get(BML_ENV_VAR))


DEFAULT_CORPORA = RealCorpora()
"""The built corpora under ``var/mocap/`` (the default of every function that takes ``corpora``)."""


def _float_or_none(x: float) -> float | None:
    return None if x is None or not math.isfinite(float(x)) else float(x)


def _check_clip(clip: CorpusClip) -> None:
    if clip.skeleton not in SKELETON_KINDS:
        raise ValueError(f"clip {clip.name}: skeleton must be one of {SKELETON_KINDS}, got {clip.skeleton!r}")
    if clip.split not in SPLITS:
        raise ValueError(f"clip {clip.name}: split must be one of {SPLITS}, got {clip.split!r}")
    if clip.motion.skeleton.name != clip.skeleton:
        raise ValueError(f"clip {clip.name}: motion is on the {clip.motion.skeleton.name!r} skeleton, "
                         f"not {clip.skeleton!r}")


def save_real_corpus(path: str | Path, clips: list[CorpusClip], meta: dict) -> Path:
    """Write ``clips`` and ``meta`` (merged over the default dataset, licence, citation and tool version) to one
    compressed ``.npz`` (parent folders created, written atomically). Every clip of a kind must share one skeleton
    (same joints and offsets). Returns the path."""
    path = Path(path)
    by_kind: dict[str, list[CorpusClip]] = {k: [] for k in SKELETON_KINDS}
    for clip in clips:
        _check_clip(clip)
        by_kind[clip.skeleton].append(clip)
    arrays: dict[str, np.ndarray] = {}
    skeletons = {}
    for kind, group in by_kind.items():
        if not group:
            continue
        sk = group[0].motion.skeleton
        for clip in group[1:]:
            other = clip.motion.skeleton
            if other.joints != sk.joints or not np.allclose(other.offsets, sk.offsets, atol=1e-9):
                raise ValueError(f"clip {clip.name}: its {kind} skeleton differs from that of {group[0].name}; "
                                 "a corpus holds one skeleton per kind")
        lengths = [c.motion.num_frames for c in group]
        arrays[f"{kind}_rotations"] = np.concatenate([c.motion.rotations for c in group]).astype(np.float32)
        arrays[f"{kind}_root_positions"] = np.concatenate([c.motion.root_positions for c in group]).astype(np.float32)
        arrays[f"{kind}_starts"] = np.concatenate([[0], np.cumsum(lengths)]).astype(np.int64)
        arrays[f"{kind}_offsets"] = np.asarray(sk.offsets, dtype=np.float64)
        arrays[f"{kind}_joints"] = np.asarray(sk.joints)
        arrays[f"{kind}_parents"] = np.asarray(sk.parents, dtype=np.int64)
        skeletons[kind] = {"height": float(sk.height), "build": sk.build}
    rows = [{"name": c.name, "dataset": c.dataset, "content": c.content, "style": c.style, "label": c.label,
             "take": int(c.take), "split": c.split, "skeleton": c.skeleton, "fps": float(c.motion.fps),
             "frames": int(c.motion.num_frames), "import_error_cm": _float_or_none(c.import_error_cm),
             "height_m": _float_or_none(c.height_m), "source": c.source, "metadata": c.motion.metadata}
            for c in clips]
    full_meta = {"dataset": "Bandai Namco Research Motion Dataset", "licence": LICENCE, "citation": CITATION,
                 "source_url": SOURCE_URL, "tool_version": TOOL_VERSION, **meta, "skeletons": skeletons}
    arrays["clips_json"] = np.asarray(json.dumps(rows))
    arrays["meta_json"] = np.asarray(json.dumps(full_meta))
    path.parent.mkdir(parents=True, exist_ok=True)
    tmp = path.with_name(path.name + ".tmp.npz")
    np.savez_compressed(tmp, **arrays)
    os.replace(tmp, path)
    return path


def _as_set(name: str, value, allowed: Iterable[str] | None = None) -> set[str] | None:
    if value is None:
        return None
    values = {value} if isinstance(value, str) else set(value)
    if allowed is not None:
        bad = sorted(values - set(allowed))
        if bad:
            raise ValueError(f"{name} must be among {tuple(allowed)}, got {bad}")
    return values


def read_meta(path: str | Path | None = None) -> dict:
    """The corpus's ``meta_json`` object (dataset, licence, citation, skeletons, split_rule, tool_version, ...)."""
    data = _open(path)
    return json.loads(str(data["meta_json"]))


def _open(path: str | Path | None):
    path = Path(path) if path is not None else DEFAULT_PATH
    if not path.is_file():
        raise FileNotFoundError(f"{path}: no real-capture corpus there (build it with `python -m generation.mocap "
                                f"dataset bandai-namco DIR --out {path}`, or name another: --corpus, {ENV_VAR})")
    try:
        data = np.load(path, allow_pickle=False)
    except (OSError, ValueError) as exc:
        raise MotionFormatError(f"{path}: not a readable .npz file ({exc})") from None
    for key in ("clips_json", "meta_json"):
        if key not in data:
            raise MotionFormatError(f"{path}: missing field {key!r}; not a real-capture corpus")
    return data


def load_real_corpus(path: str | Path | None = None, skeleton: str | None = None, split=None, contents=None,
                     styles=None) -> list[CorpusClip]:
    """Clips of the corpus at ``path`` (default :data:`DEFAULT_PATH`), in file order, keeping those whose
    skeleton is ``skeleton`` ("gait"/"gesture"), split is in ``split``, content in ``contents`` and style in
    ``styles`` (each a name or a collection of names; None keeps all). Only the kept clips are decoded.

    Raises FileNotFoundError for a missing file, MotionFormatError for a malformed one, ValueError for an unknown
    skeleton or split name."""
    kinds = _as_set("skeleton", skeleton, SKELETON_KINDS)
    splits = _as_set("split", split, SPLITS)
    contents, styles = _as_set("contents", contents), _as_set("styles", styles)
    data = _open(path)
    rows = json.loads(str(data["clips_json"]))
    meta = json.loads(str(data["meta_json"]))
    skeletons: dict[str, Skeleton] = {}
    arrays: dict[str, tuple[np.ndarray, np.ndarray, np.ndarray]] = {}   # NpzFile decodes on every access
    position = {k: 0 for k in SKELETON_KINDS}
    out = []
    for row in rows:
        kind = row["skeleton"]
        if kind not in position:
            raise MotionFormatError(f"clip {row.get('name')}: unknown skeleton {kind!r}")
        i = position[kind]
        position[kind] += 1
        if ((kinds is not None and kind not in kinds) or (splits is not None and row["split"] not in splits)
                or (contents is not None and row["content"] not in contents)
                or (styles is not None and row["style"] not in styles)):
            continue
        if kind not in arrays:
            info = meta.get("skeletons", {}).get(kind, {})
            try:
                skeletons[kind] = Skeleton(kind, tuple(str(j) for j in data[f"{kind}_joints"]),
                                           tuple(int(p) for p in data[f"{kind}_parents"]), data[f"{kind}_offsets"],
                                           float(info.get("height", 0.0)), info.get("build", "male"))
                arrays[kind] = (data[f"{kind}_starts"], data[f"{kind}_rotations"], data[f"{kind}_root_positions"])
            except KeyError as exc:
                raise MotionFormatError(f"corpus lacks the {kind} arrays ({exc})") from None
        starts, rotations, roots = arrays[kind]
        a, b = int(starts[i]), int(starts[i + 1])
        if b - a != row["frames"]:
            raise MotionFormatError(f"clip {row['name']}: {b - a} rows in {kind}_starts but {row['frames']} frames")
        metadata = {**row.get("metadata", {}), "captured": True, "dataset": row["dataset"], "content": row["content"],
                    "style": row["style"], "label": row["label"], "take": row["take"], "split": row["split"],
                    "licence": meta.get("licence", LICENCE), "citation": meta.get("citation", CITATION)}
        motion = Motion(skeletons[kind], rotations[a:b], roots[a:b],
                        float(row["fps"]), metadata)
        out.append(CorpusClip(row["name"], row["dataset"], row["content"], row["style"], row["label"],
                              int(row["take"]), row["split"], kind, motion,
                              math.nan if row.get("import_error_cm") is None else float(row["import_error_cm"]),
                              math.nan if row.get("height_m") is None else float(row["height_m"]),
                              row.get("source", "")))
    return out
