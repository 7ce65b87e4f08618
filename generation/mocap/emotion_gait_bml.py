"""The BML walks of Emotion-Gait (positions only) -> the real-capture corpus: IK fit, root travel, performer split.

Data (``../shared/mocap/emotion-gait-bml/bml_walks.npz``, its README): 120 walks of the Biological Motion Library,
30 actors x 4 acted emotions (happy, sad, angry, neutral), 75 frames of 16 joint positions each (y up, height
normalised to about 1.03 head-to-foot, about 30 fps), with the acted label and the Emotion-Gait annotators'
majority perceived label. Every clip is one gait cycle repeated (:func:`generation.mocap.root_travel.loop_period`)
with the root fixed at one point ("on a treadmill"). Licence: research use with citation of Ma, Paterson & Pollick
(2006) and of STEP (Bhattacharya et al., AAAI 2020); see :data:`CITATION`.

Per clip (:func:`fit_clip`):

1. **Checks** (a failed one is an ``error`` row naming the cause; nothing is patched): finite values and at least
   :data:`MIN_FRAMES` frames; *units*: the body's vertical extent (median over frames of the highest minus the
   lowest joint) lies in :data:`NORMALISED_EXTENT` (height-normalised data; metres or centimetres would not);
   *mirrored*: the knees must bend forwards of the facing that the hip line gives with left = up x forward
   (:func:`mirror_score`; a left/right swap or a mirrored coordinate system turns it negative).
2. **Scale**: positions times ``height`` / the source's standing height (hip height / 0.530,
   :func:`generation.mocap.importer.standing_height_m`), so the bone lengths are the data's at a standing height
   of ``height``.
3. **Root travel** (:func:`generation.mocap.root_travel.reconstruct_root_travel`): minus the stance foot's
   velocity integrated on the ground plane, the stance foot's height put back on one level; the walk then goes
   along its own direction in the world.
4. **IK**: :func:`generation.mocap.importer.solve_onto` with the map :data:`JOINT_MAP`: the import check solves
   onto our joints with the actor's own bone lengths (its largest miss over mapped joints is ``import_error_cm``;
   over :data:`MAX_IK_ERROR_M` the clip is an ``error``), the Motion is on our gait skeleton of ``height`` (feet
   put where the source's are). Our joints the data lacks (lower back: between root and chest; toes and index
   fingers: their rest offsets) get rest values. The head marker sits well in front of the neck (the README: 50-60
   degrees forward of vertical): the neck -> head direction is turned back by :data:`HEAD_MARKER_PITCH_DEG` about
   the body's left-right axis (one constant for the set, so the differences between clips stay).
5. **Floor**: the Motion is raised so that the median over frames of its lowest foot joint is at
   :data:`FLOOR_CLEARANCE_M`.

Split (:func:`split_for`, :data:`SPLIT_RULE`): whole performers are held out, never single clips.
"""
from __future__ import annotations

import sys
import zlib
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from generation.core.motion import Motion
from generation.core.skeleton import REFERENCE_HEIGHT_M, gait_skeleton
from protocol.vocabulary import GAIT_EMOTIONS

from .dataset_import import TAKE_COLUMNS, write_report
from .importer import REPORT_COLUMNS, solve_onto, standing_height_m
from .real_corpus import CorpusClip, save_real_corpus
from .root_travel import loop_period, reconstruct_root_travel, seam_frames

DATASET = "emotion-gait-bml"
FILE_NAME = "bml_walks.npz"
FPS = 30.0
LICENCE = "research use only, with citation (Biological Motion Library; Emotion-Gait labels)"
CITATION = ("Y. Ma, H. M. Paterson, F. E. Pollick. A motion capture library for the study of identity, gender, and "
            "emotion perception from biological motion. Behavior Research Methods 38(1):134-141, 2006. "
            "U. Bhattacharya, T. Mittal, R. Chandra, T. Randhavane, A. Bera, D. Manocha. STEP: Spatial Temporal "
            "Graph Convolutional Networks for Emotion Perception from Gaits. AAAI 2020.")
SOURCE_URL = ("https://github.com/UttaranB127/lstm_emotions (joint data, utils/data_sin); "
              "https://github.com/vijay4313/proxemo (labels, emotion_classification/sample_data/labels.h5)")

SOURCE_JOINTS = ("root", "spine", "neck", "head", "l_shoulder", "l_elbow", "l_hand", "r_shoulder", "r_elbow",
                 "r_hand", "l_hip", "l_knee", "l_foot", "r_hip", "r_knee", "r_foot")
"""The file's 16 joints, in its order (``joint_names``)."""
JOINT_MAP = {"root": "root", "spine": "spine", "neck": "neck", "head": "head",
             "left_shoulder": "l_shoulder", "left_elbow": "l_elbow", "left_hand": "l_hand",
             "right_shoulder": "r_shoulder", "right_elbow": "r_elbow", "right_hand": "r_hand",
             "left_hip": "l_hip", "left_knee": "l_knee", "left_heel": "l_foot",
             "right_hip": "r_hip", "right_knee": "r_knee", "right_heel": "r_foot"}
"""Our gait joint -> the file's joint. ``spine`` is the chest the arms branch from; ``foot`` is the ankle."""
EMOTION_CODES = {"Happy": "happy", "Sad": "sad", "Angry": "angry", "Neutral": "neutral"}

MIN_FRAMES = 20
NORMALISED_EXTENT = (0.8, 1.3)
"""Accepted vertical extent of a clip in file units (the set is normalised to about 1.03)."""
MAX_IK_ERROR_M = 0.06
"""Largest accepted miss (metres at the standing height) of the actor-proportioned solve. Marker-based bone
lengths vary within a clip (README: coefficient of variation up to 0.10), so the bound is wider than the 3 cm of
BVH imports; measured on the 120 clips: see docs/benchmarks/mocap.md, "BML walks"."""
HEAD_MARKER_PITCH_DEG = 45.0
"""The head marker's forward tilt from the neck that is turned back (median neck -> head angle of the set minus
our rest head's few degrees)."""
FLOOR_CLEARANCE_M = 0.0
BLEND_M = 0.02
SPEED_BLEND_M_S = 0.05
SMOOTH_FRAMES = 1
"""Stance-weight scales for a 1.75 m body (:func:`generation.mocap.root_travel.stance_weights`), scaled with the
height; chosen on the Bandai walks whose travel is known (docs/benchmarks/mocap.md, "Root travel")."""
ANKLE_SPEED_GAIN = 1.112
"""Ground travel from ankles alone (the BML walks have no toes) falls short: a stance ankle moves forward while
the heel rolls onto the foot and while it rises onto the toes. The gain is calibrated on the Bandai dataset-1
walks' first takes (true / reconstructed speed, ankles only) and checked on their second takes
(benchmarks/bench_root_travel.py)."""
TEST_PERFORMERS = 6
VAL_PERFORMERS = 3
SPLIT_RULE = (f"Held out by performer (never by clip): the 30 BML actors are ranked by crc32 of their name "
              f"(BML_<actor>); the first {TEST_PERFORMERS} are test, the next {VAL_PERFORMERS} val, the rest "
              "train. A pure function of the performer's name, so adding clips never moves an actor.")


class BmlFormatError(ValueError):
    """The data file is missing or not laid out as the README says; the message names the file and field."""


@dataclass(frozen=True)
class BmlClip:
    """One BML walk as stored: ``positions`` (T, 16, 3) in file units; labels in the study vocabulary."""

    key: str
    performer: str
    acted: str
    perceived: str
    positions: np.ndarray

    @property
    def name(self) -> str:
        return self.key.removesuffix(".csv").removesuffix("_positions")


def split_for(performer: str, performers) -> str:
    """The split of ``performer`` among all ``performers`` (:data:`SPLIT_RULE`)."""
    ranked = sorted(set(performers), key=lambda p: (zlib.crc32(p.encode()), p))
    k = ranked.index(performer)
    return "test" if k < TEST_PERFORMERS else "val" if k < TEST_PERFORMERS + VAL_PERFORMERS else "train"


def data_file(root: Path) -> Path:
    """``root`` itself when it is the .npz, else ``root/bml_walks.npz`` (or the one found below it)."""
    root = Path(root)
    if root.is_file():
        return root
    direct = root / FILE_NAME
    if direct.is_file():
        return direct
    found = sorted(root.rglob(FILE_NAME)) if root.is_dir() else []
    if not found:
        raise BmlFormatError(f"{root}: no {FILE_NAME} there (the Emotion-Gait BML walks, "
                             "../shared/mocap/emotion-gait-bml/)")
    return found[0]


def load_clips(root: Path) -> list[BmlClip]:
    """The clips of the data file under ``root`` (:func:`data_file`), in file order."""
    path = data_file(root)
    try:
        data = np.load(path, allow_pickle=False)
        fields = {k: data[k] for k in data.files}
    except (OSError, ValueError) as exc:
        raise BmlFormatError(f"{path}: not a readable .npz ({exc})") from None
    need = ("positions", "key", "performer", "acted_label", "perceived_label", "joint_names")
    missing = [k for k in need if k not in fields]
    if missing:
        raise BmlFormatError(f"{path}: missing field(s) {', '.join(missing)}")
    names = tuple(str(n) for n in fields["joint_names"])
    if names != SOURCE_JOINTS:
        raise BmlFormatError(f"{path}: field 'joint_names' is {names}, expected {SOURCE_JOINTS}")
    P = np.asarray(fields["positions"], dtype=np.float64)
    n = len(fields["key"])
    if P.ndim != 4 or P.shape[0] != n or P.shape[2:] != (len(SOURCE_JOINTS), 3):
        raise BmlFormatError(f"{path}: field 'positions' has shape {P.shape}, expected ({n}, T, 16, 3)")
    out = []
    for i in range(n):
        labels = []
        for f in ("acted_label", "perceived_label"):
            v = str(fields[f][i])
            if v not in EMOTION_CODES:
                raise BmlFormatError(f"{path}: field {f!r} row {i}: {v!r} is not one of {', '.join(EMOTION_CODES)}")
            labels.append(EMOTION_CODES[v])
        out.append(BmlClip(str(fields["key"][i]), str(fields["performer"][i]), labels[0], labels[1], P[i]))
    return out


def vertical_extent(P: np.ndarray) -> float:
    """Median over frames of the highest minus the lowest joint height (file units)."""
    return float(np.median(P[..., 1].max(1) - P[..., 1].min(1)))


def mirror_score(P: np.ndarray) -> float:
    """Mean over frames and legs of the knee's forward offset from the hip-ankle midpoint along the facing the
    hip line gives (forward = (left hip - right hip) x up), divided by the leg length: positive for a body whose
    left and right are labelled right, negative when they are swapped or the coordinates are mirrored."""
    ix = {n: k for k, n in enumerate(SOURCE_JOINTS)}
    up = np.array([0.0, 1.0, 0.0])
    fwd = np.cross(P[:, ix["l_hip"]] - P[:, ix["r_hip"]], up)
    fwd /= np.maximum(np.linalg.norm(fwd, axis=-1, keepdims=True), 1e-12)
    out = []
    for s in ("l", "r"):
        hip, knee, foot = P[:, ix[f"{s}_hip"]], P[:, ix[f"{s}_knee"]], P[:, ix[f"{s}_foot"]]
        leg = np.linalg.norm(hip - knee, axis=-1) + np.linalg.norm(knee - foot, axis=-1)
        out.append(((knee - 0.5 * (hip + foot)) * fwd).sum(-1) / np.maximum(leg, 1e-12))
    return float(np.mean(out))


def ik_error_p95(fitted: Motion, Q: np.ndarray) -> float:
    """95th percentile over frames and mapped joints of the distance (metres) between the actor-proportioned
    solve ``fitted`` and the source positions ``Q`` (T, 16, 3) it was solved from."""
    ours = fitted.positions()[:, [fitted.skeleton.index(j) for j in JOINT_MAP]]
    theirs = Q[:, [SOURCE_JOINTS.index(t) for t in JOINT_MAP.values()]]
    return float(np.percentile(np.linalg.norm(ours - theirs, axis=-1), 95))


VERTICAL_ORDER = (("l_hip", "l_knee", "l_foot"), ("r_hip", "r_knee", "r_foot"), ("neck", "spine", "root"),
                  ("head", "root"), ("l_shoulder", "l_hip"), ("r_shoulder", "r_hip"))
"""Chains whose joints are each above the next in an upright walk (in at least :data:`ORDER_SHARE` of frames)."""
ORDER_SHARE = 0.9


def misordered(P: np.ndarray) -> list[str]:
    """Chains of :data:`VERTICAL_ORDER` that are not top-to-bottom in most frames: a file whose columns are not
    in the documented joint order (or upside down)."""
    ix = {n: k for k, n in enumerate(SOURCE_JOINTS)}
    out = []
    for chain in VERTICAL_ORDER:
        y = P[:, [ix[j] for j in chain], 1]
        share = float((np.diff(y, axis=1) < 0).all(1).mean())
        if share < ORDER_SHARE:
            out.append(f"{' > '.join(chain)} in {100 * share:.0f}% of frames")
    return out


def check_clip(P: np.ndarray) -> list[str]:
    """Causes that make a clip unusable (empty when it can be fitted), before any fitting."""
    if not np.isfinite(P).all():
        return ["positions are not all finite"]
    if len(P) < MIN_FRAMES:
        return [f"{len(P)} frames; at least {MIN_FRAMES} are needed"]
    problems = []
    extent = vertical_extent(P)
    low, high = NORMALISED_EXTENT
    if not low <= extent <= high:
        problems.append(f"wrong units: vertical extent {extent:.3g} file units, expected {low}-{high} "
                        "(the set is height-normalised to about 1.03)")
    odd = misordered(P)
    if odd:
        problems.append("joints out of order (columns not in the documented order?): " + "; ".join(odd))
    score = mirror_score(P)
    if score <= 0:
        problems.append(f"mirrored left/right: the knees bend backwards of the facing the hip line gives "
                        f"(score {score:.3f}; left/right labels swapped or mirrored coordinates)")
    return problems


def _turn_head_marker(P: np.ndarray, degrees: float) -> np.ndarray:
    """P with the neck -> head vector turned back (up, away from the facing) by ``degrees`` about the body's
    left-right axis (hip line)."""
    ix = {n: k for k, n in enumerate(SOURCE_JOINTS)}
    P = P.copy()
    axis = P[:, ix["l_hip"]] - P[:, ix["r_hip"]]
    axis[:, 1] = 0.0
    axis /= np.maximum(np.linalg.norm(axis, axis=-1, keepdims=True), 1e-12)
    v = P[:, ix["head"]] - P[:, ix["neck"]]
    a = np.radians(degrees)
    # Rodrigues about the left axis k by -a: with left = up x forward, that turns forward towards up
    k = axis
    rot = (v * np.cos(-a) + np.cross(k, v) * np.sin(-a) + k * (k * v).sum(-1, keepdims=True) * (1 - np.cos(-a)))
    P[:, ix["head"]] = P[:, ix["neck"]] + rot
    return P


def neck_head_angle_deg(P: np.ndarray) -> float:
    """Median over frames of the angle between the neck -> head vector and the vertical, degrees, signed positive
    forward of the hip-line facing."""
    ix = {n: k for k, n in enumerate(SOURCE_JOINTS)}
    fwd = np.cross(P[:, ix["l_hip"]] - P[:, ix["r_hip"]], [0.0, 1.0, 0.0])
    fwd /= np.maximum(np.linalg.norm(fwd, axis=-1, keepdims=True), 1e-12)
    v = P[:, ix["head"]] - P[:, ix["neck"]]
    return float(np.median(np.degrees(np.arctan2((v * fwd).sum(-1), v[:, 1]))))


def fit_clip(clip: BmlClip, performers, height: float = REFERENCE_HEIGHT_M, build: str = "male",
             max_ik_error_m: float = MAX_IK_ERROR_M) -> tuple[CorpusClip | None, dict]:
    """One clip -> (its CorpusClip, or None when it cannot be fitted; the report row)."""
    split = split_for(clip.performer, performers)
    row = {c: "" for c in report_columns()}
    row.update(source=clip.key, status="error", dataset=DATASET, content="walk", style=clip.acted, label=clip.acted,
               take=1, split=split, skeleton="gait", performer=clip.performer, perceived_label=clip.perceived)
    P = clip.positions
    problems = check_clip(P)
    if problems:
        row["message"] = f"{clip.key}: " + "; ".join(problems)
        return None, row
    period = loop_period(P)
    seams = np.flatnonzero(seam_frames(P)).tolist()
    jm_index = {ours: theirs for ours, theirs in JOINT_MAP.items()}
    source_height = standing_height_m(P, SOURCE_JOINTS, jm_index)
    scale = height / source_height
    Q = _turn_head_marker(P * scale, HEAD_MARKER_PITCH_DEG)
    ix = {n: k for k, n in enumerate(SOURCE_JOINTS)}
    travel, _ = reconstruct_root_travel(Q, FPS, ([ix["l_foot"]], [ix["r_foot"]]), blend=BLEND_M * height / 1.75,
                                        smooth_frames=SMOOTH_FRAMES, hips=(ix["l_hip"], ix["r_hip"]),
                                        speed_blend=SPEED_BLEND_M_S * height / 1.75)
    travel[:, [0, 2]] *= ANKLE_SPEED_GAIN
    Q = Q + travel[:, None, :]
    target = gait_skeleton(height, build)
    fitted, _, import_err, _ = solve_onto(Q, SOURCE_JOINTS, target, JOINT_MAP, "source")
    ik_err = ik_error_p95(fitted, Q)
    motion, _, _, err = solve_onto(Q, SOURCE_JOINTS, target, JOINT_MAP, "ours")
    row.update(frames=len(P), fps=f"{FPS:g}", duration_s=f"{len(P) / FPS:.4f}", mapped_joints=len(JOINT_MAP),
               unmapped_joints=";".join(j for j in target.joints if j not in JOINT_MAP),
               retarget_max_error_m=f"{err:.6f}", height_m=f"{height:.4f}", import_error_cm=f"{100 * import_err:.2f}",
               ik_error_p95_cm=f"{100 * ik_err:.2f}")
    if ik_err > max_ik_error_m:
        row["message"] = (f"{clip.key}: IK error {100 * ik_err:.1f} cm (95th percentile over frames and joints) "
                          f"exceeds {100 * max_ik_error_m:.1f} cm (the actor-proportioned solve does not reproduce "
                          "the positions: wrong joint order or units?)")
        return None, row
    root = motion.root_positions.copy()
    feet = [target.index(j) for j in ("left_heel", "left_toe", "right_heel", "right_toe")]
    lowest = np.median(motion.positions()[:, feet, 1].min(1))
    root[:, 1] += FLOOR_CLEARANCE_M - lowest
    speed = np.linalg.norm(np.diff(travel[:, [0, 2]], axis=0), axis=-1).mean() * FPS
    meta = {"origin": "captured", "synthetic": False, "captured": True, "source": clip.key, "format": "positions",
            "dataset": DATASET, "content": "walk", "style": clip.acted, "label": clip.acted, "take": 1,
            "split": split, "performer": clip.performer, "acted_label": clip.acted, "perceived_label": clip.perceived,
            "emotion": {e: float(e == clip.acted) for e in GAIT_EMOTIONS},
            "perceived_emotion": {e: float(e == clip.perceived) for e in GAIT_EMOTIONS},
            "licence": LICENCE, "citation": CITATION, "source_url": SOURCE_URL,
            "source_height_normalised": round(source_height, 4), "scale_to_height": round(scale, 5),
            "loop_period_frames": period, "loop_seams": seams,
            "root_travel": {"method": "stance foot (generation.mocap.root_travel)", "gain": ANKLE_SPEED_GAIN,
                            "speed_m_s": round(float(speed), 4)},
            "head_marker_pitch_deg": HEAD_MARKER_PITCH_DEG, "import_error_cm": round(100 * import_err, 3),
            "ik_error_p95_cm": round(100 * ik_err, 3)}
    out = Motion(target, motion.rotations, root, FPS, meta)
    row.update(status="ok", message="")
    clip_out = CorpusClip(clip.name, DATASET, "walk", clip.acted, clip.acted, 1, split, "gait", out,
                          100 * import_err, height, clip.key)
    return clip_out, row


EXTRA_COLUMNS = ("ik_error_p95_cm", "performer", "perceived_label")


def report_columns() -> tuple[str, ...]:
    """The Bandai report's columns (importer's, then dataset ... skeleton), then :data:`EXTRA_COLUMNS`."""
    return (*REPORT_COLUMNS, *TAKE_COLUMNS, *EXTRA_COLUMNS)


def report_path(out: Path) -> Path:
    """The report beside the corpus: ``<corpus stem>.import_report.csv`` (so that it does not overwrite the
    Bandai corpus's ``import_report.csv`` in the same folder)."""
    out = Path(out)
    return out.with_name(out.stem + ".import_report.csv")


def import_clips(clips: list[BmlClip], height: float = REFERENCE_HEIGHT_M, build: str = "male",
                 max_ik_error_m: float = MAX_IK_ERROR_M) -> tuple[list[CorpusClip], list[dict]]:
    """Fit every clip: (the ones that fitted, one report row per clip), in file order."""
    performers = sorted({c.performer for c in clips})
    results = [fit_clip(c, performers, height, build, max_ik_error_m) for c in clips]
    return [c for c, _ in results if c is not None], [r for _, r in results]


def performer_split(clips) -> dict[str, list[str]]:
    """{split: sorted performers}."""
    performers = sorted({c.performer for c in clips})
    out: dict[str, list[str]] = {"train": [], "val": [], "test": []}
    for p in performers:
        out[split_for(p, performers)].append(p)
    return out


def build_emotion_gait_bml(root: Path, out: Path, height: float = REFERENCE_HEIGHT_M, build: str = "male",
                           quiet: bool = False, max_ik_error_m: float = MAX_IK_ERROR_M) -> int:
    """Read, fit and save: the corpus at ``out``, the report beside it (:func:`report_path`). Exit status 0 when
    every clip fitted, 1 when any failed (the others are still saved; no corpus when none fitted), 2 for an
    unreadable data file."""
    try:
        source = load_clips(root)
    except BmlFormatError as exc:
        print(f"error: {exc}", file=sys.stderr)
        return 2
    clips, rows = import_clips(source, height, build, max_ik_error_m)
    report = write_report(report_path(out), rows, report_columns())
    failed = [r for r in rows if r["status"] != "ok"]
    if clips:
        meta = {"dataset": "Emotion-Gait BML walks (Biological Motion Library, Emotion-Gait perceived labels)",
                "datasets": [DATASET], "licence": LICENCE, "citation": CITATION, "source_url": SOURCE_URL,
                "split_rule": SPLIT_RULE, "performer_split": performer_split(source),
                "source_root": str(root), "takes_found": len(source), "takes_failed": len(failed),
                "max_ik_error_m": max_ik_error_m, "labels": "style/label = acted; metadata perceived_label"}
        save_real_corpus(out, clips, meta)
    if not quiet:
        print(f"imported {len(clips)} of {len(source)} BML walks -> {out if clips else 'no corpus written'}; "
              f"report {report}", file=sys.stderr)
        for r in failed:
            print(f"  error: {r['message']}", file=sys.stderr)
    return 1 if failed or not clips else 0
