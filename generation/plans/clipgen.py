"""Turn a validated plan entry into a Motion by calling the right generator.

The network generators (gait_net, gesture_net, rbf: they load torch) are imported inside the function that
needs them, so planning, hashing and procedural clips never load torch, and a missing or broken network fails only
the entries that use it, with a message naming the entry (:class:`ClipGenerationError`).

A network generator whose weights are not there yet may be replaced by the entry's ``fallback``
(procedural_walk for gait_net, procedural_gesture for gesture_net). The clip is then recorded with the
generator that really made it, ``metadata["fallback_for"]`` and ``synthetic: True``; it is never passed off
as the network's output. Its content hash differs, so once the weights exist the clip is rendered anew.
"""
from __future__ import annotations

import ast
import dataclasses
import functools
import hashlib
import importlib
import math
import os
from pathlib import Path

import numpy as np

from generation.core import paths
from generation.core.foot_contact import plant_feet
from generation.core.motion import Motion
from generation.core.paths import GroundPath
from generation.core.quaternion import np_qfix, np_qslerp
from generation.core.skeleton import gait_skeleton, gesture_skeleton
from generation.formats.bvh import write_bvh
from generation.gesture.config import gesture_seconds
from generation.mocap.captured import WALK_FILES, captured_walks, chain_clip_repeats
from generation.procedural.emotion import gait_params_for_emotion, gesture_params_for_vad
from generation.procedural.gesture import seated_gesture
from generation.procedural.walk import walk
from generation.rbf.neutral_base import neutral_cycle
from generation.rbf.real_neutral import load_cycle
from study_protocol import GESTURE_VAD

from .captured_file import CapturedFileError, captured_file_motion
from .schema import ClipEntry

#: Declared generator versions. Clip hashes also carry a digest of each generator's source code and data
#: (:func:`source_digest`) and of network weights, so code changes re-render by themselves; bump these to
#: force it (e.g. after a change in a library outside the project).
GENERATOR_VERSIONS = {
    "gait_net": "1",
    "procedural_walk": "1",
    "captured": "1",
    "captured_file": "1",
    "neutral_walk": "1",
    "rbf": "1",
    "gesture_net": "1",
    "procedural_gesture": "1",
}
#: Modules each generator needs (checked before rendering starts).
GENERATOR_MODULES = {
    "gait_net": ("generation.gait.generate", "generation.core.paths", "generation.core.foot_contact"),
    "procedural_walk": ("generation.procedural.walk", "generation.procedural.emotion", "generation.core.paths"),
    "captured": ("generation.mocap.captured", "generation.core.foot_contact"),
    "captured_file": ("generation.plans.captured_file", "generation.mocap.importer"),
    "neutral_walk": ("generation.rbf.neutral_base", "generation.rbf.real_neutral", "generation.rbf.stylise",
                     "generation.core.foot_contact"),
    "rbf": ("generation.rbf.neutral_base", "generation.rbf.real_neutral", "generation.rbf.data_features",
            "generation.rbf.stylise", "generation.core.foot_contact"),
    "gesture_net": ("generation.gesture.generate",),
    "procedural_gesture": ("generation.procedural.gesture", "generation.procedural.emotion"),
}
WEIGHTS_DIR = Path(__file__).resolve().parent.parent / "data" / "weights"
#: Weights files of the network generators (shipped defaults).
GENERATOR_WEIGHTS = {
    "gait_net": WEIGHTS_DIR / "gait_net_real.pt",   # the default of generation.gait.weights (real capture)
    "gesture_net": WEIGHTS_DIR / "gesture_net_default.pt",
}


class ClipGenerationError(RuntimeError):
    """A plan entry could not be turned into motion; the message names the entry and the cause."""


def availability(generator: str) -> str | None:
    """None when ``generator`` can run here, else the reason it cannot (missing module or weights)."""
    for mod in GENERATOR_MODULES[generator]:
        try:
            importlib.import_module(mod)
        except Exception as exc:  # noqa: BLE001 - any import failure makes the generator unavailable
            return f"module {mod} cannot be imported ({type(exc).__name__}: {exc})"
    weights = GENERATOR_WEIGHTS.get(generator)
    if weights is not None and not weights.is_file():
        return f"weights file {weights} is missing"
    return None


@functools.cache
def _file_digest(path: str, size: int, mtime_ns: int) -> str:
    h = hashlib.sha256()
    with open(path, "rb") as f:
        for block in iter(lambda: f.read(1 << 20), b""):
            h.update(block)
    return h.hexdigest()[:12]


PACKAGE_DIR = Path(__file__).resolve().parent.parent
#: The shared study protocol (vocabularies); generators that import it depend on it too.
PROTOCOL_MODULE = PACKAGE_DIR.parent / "study_protocol.py"


def _imported_files(path: Path) -> set[Path]:
    """Project source files a module imports (relative ``from .x`` and absolute ``generation.x`` imports,
    including imports inside functions)."""
    out: set[Path] = set()
    for node in ast.walk(ast.parse(path.read_text(encoding="utf-8"))):
        if not isinstance(node, ast.ImportFrom):
            continue
        if node.level:
            base = path.parent
            for _ in range(node.level - 1):
                base = base.parent
            parts = node.module.split(".") if node.module else []
        elif node.module and node.module.split(".")[0] == "generation":
            base, parts = PACKAGE_DIR, node.module.split(".")[1:]
        elif node.module == PROTOCOL_MODULE.stem:
            out.add(PROTOCOL_MODULE)
            continue
        else:
            continue
        target = base.joinpath(*parts)
        candidates = [target.with_suffix(".py"), target / "__init__.py"]
        candidates += [target / f"{a.name}.py" for a in node.names]
        out.update(c.resolve() for c in candidates if c.is_file())
    return out


def source_files(generator: str) -> list[Path]:
    """The files whose content a generator's output depends on: its modules and everything they import
    from the project (followed transitively), this file, and the small data files under ``generation/data``
    (weights apart; they have their own digest)."""
    todo = [PACKAGE_DIR.joinpath(*m.split(".")[1:]).with_suffix(".py") for m in GENERATOR_MODULES[generator]]
    seen: set[Path] = set()
    while todo:
        path = todo.pop().resolve()
        if path in seen or not path.is_file():
            continue
        seen.add(path)
        todo.extend(_imported_files(path) - seen)
    seen.add(Path(__file__).resolve())
    data = PACKAGE_DIR / "data"
    return sorted(seen) + sorted(p.resolve() for p in data.rglob("*") if p.is_file() and "weights" not in p.parts
                                 and p.stat().st_size < 5_000_000)


@functools.cache
def source_digest(generator: str) -> str:
    """Digest of :func:`source_files`. It goes into the clip hash, so a change to a generator's code or data
    renders its clips anew instead of reusing stale files."""
    files = source_files(generator)
    h = hashlib.sha256()
    for f in files:
        h.update(str(f.relative_to(PACKAGE_DIR.parent)).encode())
        h.update(f.read_bytes())
    return h.hexdigest()[:12]


def generator_version(generator: str) -> str:
    """Version string that goes into the clip hash: the declared version, the digest of the generator's
    source code and data (:func:`source_digest`) and, for networks, of the weights file."""
    version = f"{GENERATOR_VERSIONS[generator]}+src{source_digest(generator)}"
    weights = GENERATOR_WEIGHTS.get(generator)
    if weights is not None and weights.is_file():
        st = weights.stat()
        version += "+w" + _file_digest(str(weights), st.st_size, st.st_mtime_ns)
    return version


def resolve(entry: ClipEntry) -> tuple[ClipEntry, str | None]:
    """The entry as it will be made: itself, or its fallback when the generator is unavailable.

    Returns (entry, reason the requested generator was replaced or None). Raises ClipGenerationError when
    neither the generator nor a fallback can run.
    """
    reason = availability(entry.generator)
    if reason is None:
        return entry, None
    if entry.fallback is None:
        raise ClipGenerationError(f"{entry.where}: generator {entry.generator!r} is not available: {reason}")
    fb_reason = availability(entry.fallback)
    if fb_reason is not None:
        raise ClipGenerationError(f"{entry.where}: generator {entry.generator!r} is not available ({reason}) "
                                  f"and its fallback {entry.fallback!r} neither ({fb_reason})")
    return fallback_entry(entry), f"{entry.generator} unavailable: {reason}"


def fallback_entry(entry: ClipEntry) -> ClipEntry:
    """The entry re-expressed for its fallback generator (inputs mapped; the intent is unchanged)."""
    fb = entry.with_generator(entry.fallback)
    if entry.generator == "gesture_net":
        inp = entry.inputs
        n_words = len(inp["sentence"].split())
        seconds = float(gesture_seconds(n_words))
        inputs = {"emotion_label": inp["emotion_label"], "kind": None, "gender": inp["gender"],
                  "handedness": inp["handedness"], "duration_s": round(min(max(seconds, 2.0), 60.0), 3)}
        fb = dataclasses.replace(fb, inputs=inputs)
    return fb


# ---- paths -------------------------------------------------------------------------------------
def make_path(trajectory: dict):
    """A GroundPath from a normalised plan trajectory (metres; angles in degrees in the plan)."""
    kind, length = trajectory["kind"], trajectory["length_m"]
    if kind == "straight":
        return paths.straight(length)
    if kind == "curved":
        return paths.curved(trajectory["radius_m"], math.radians(trajectory["angle_deg"]), length)
    return paths.sharp_turn(math.radians(trajectory["angle_deg"]), length, trajectory["at_fraction"])


# ---- generators --------------------------------------------------------------------------------
DEVICE_ENV = "GENERATION_DEVICE"
"""Environment variable naming the torch device of the network generators ("cpu" when unset; ``manage.py
generate_clips --device`` sets it, so that the render worker processes it spawns inherit it)."""


def generation_device(device: str | None = None) -> str:
    """The device the network generators run on: ``device`` when given, else ``$GENERATION_DEVICE``, else "cpu"
    (stimuli identical to those made on a machine without a GPU)."""
    return device or os.environ.get(DEVICE_ENV) or "cpu"


def _gait_net(entry: ClipEntry, fps: float) -> Motion:
    from generation.gait.generate import emotion_transition, generate_gaits, load_default_model  # heavy: torch

    inp = entry.inputs
    net = load_default_model(generation_device(), weights=inp.get("weights"))
    steps = int(math.ceil(inp["duration_s"] * net.fps)) + 1
    if "transition" in inp:
        emotions = emotion_transition(inp["transition"]["initial"], inp["transition"]["final"], steps)[None]
    else:
        emotions = np.asarray([inp["emotion"]])
    return generate_gaits(None, [make_path(inp["trajectory"])], emotions, steps=steps, fps_out=fps, model=net,
                          rng_seed=entry.seed)[0]


def _procedural_walk(entry: ClipEntry, fps: float) -> Motion:
    inp = entry.inputs
    rng = np.random.default_rng(entry.seed)
    n_frames = int(round(inp["duration_s"] * fps)) + 1
    path = make_path(inp["trajectory"])
    if "transition" in inp:
        a = gait_params_for_emotion(inp["transition"]["initial"], rng)
        b = gait_params_for_emotion(inp["transition"]["final"], rng)
        motion = transition_walk(a, b, path, n_frames, fps, seed=entry.seed)
        motion.metadata["final_emotion"] = inp["transition"]["final"]
        motion.metadata["emotion"] = inp["transition"]["initial"]
    else:
        params = gait_params_for_emotion(inp["emotion"], rng)
        motion = walk(params, path, n_frames, fps, seed=entry.seed)
        motion.metadata["emotion"] = inp["emotion"]
    return motion


def transition_walk(a, b, path, n_frames: int, fps: float, seed: int | None = None, hold: float = 0.3,
                    n_blend: int = 3, overlap_s: float = 0.4) -> Motion:
    """A procedural walk whose parameters change from ``a`` to ``b`` (WalkParams) along ``path``.

    ``procedural_walk.walk`` keeps its parameters constant, so the walk is made of segments: pure ``a`` for
    the first ``hold`` of the time, ``n_blend`` segments with parameters blended linearly in between, pure
    ``b`` for the last ``hold``. Each segment starts where the previous one stood at that moment (arc
    length along the path and gait phase carried over), and consecutive segments are cross-faded over
    ``overlap_s`` seconds (slerp of rotations, lerp of root positions), so there is no jump. Feet may slide
    slightly during a cross-fade. Synthetic, like every procedural walk (used as the clearly marked
    fallback for gait_net transitions).

    Returns a Motion of ``n_frames`` frames at ``fps`` on the gait skeleton.
    """
    T = int(n_frames)
    weights = [0.0] + [(k + 1) / (n_blend + 1) for k in range(n_blend)] + [1.0]
    mid = (1.0 - 2 * hold) / n_blend
    fractions = [hold] + [mid] * n_blend + [hold]
    bounds = np.round(np.cumsum([0.0] + fractions) * (T - 1)).astype(int)
    overlap = max(1, int(round(overlap_s * fps)))
    arc, phase = 0.0, 0.0
    rot = np.zeros((T, 21, 4))
    root = np.zeros((T, 3))
    done = 0
    segments_meta = []
    for k, w in enumerate(weights):
        params = a.blend(b, w).validate()
        start, stop = int(bounds[k]), (T if k == len(weights) - 1 else int(bounds[k + 1]) + overlap)
        stop = min(stop, T)
        n = stop - start
        if n < 2:
            continue
        # The rest of the path from where this segment starts (the walker continues straight past its end).
        sub = GroundPath(path.point_at(np.arange(arc, arc + params.speed_mps * n / fps + 3.0, 0.02)), path.kind)
        m = walk(params, sub, n, fps, phase=phase, seed=None if seed is None else seed + k)
        seg_rot, seg_root = np_qfix(m.rotations), m.root_positions
        if k == 0:
            rot[start:stop], root[start:stop] = seg_rot, seg_root
        else:
            n_fade = min(overlap, done - start, n)
            if n_fade > 0:
                ramp = (np.arange(1, n_fade + 1) / (n_fade + 1))
                prev = rot[start:start + n_fade]
                cur = seg_rot[:n_fade]
                cur = np.where((prev * cur).sum(-1, keepdims=True) < 0, -cur, cur)
                rot[start:start + n_fade] = np_qslerp(prev, cur, np.broadcast_to(ramp[:, None], prev.shape[:-1]))
                root[start:start + n_fade] = (1 - ramp[:, None]) * root[start:start + n_fade] + \
                    ramp[:, None] * seg_root[:n_fade]
            rot[start + n_fade:stop], root[start + n_fade:stop] = seg_rot[n_fade:], seg_root[n_fade:]
        done = stop
        seg_len = (int(bounds[k + 1]) - start) if k < len(weights) - 1 else n
        arc += params.speed_mps * (m.skeleton.height / 1.75) * seg_len / fps
        phase += seg_len / fps * params.cadence_spm / 120.0
        segments_meta.append({"blend": round(w, 4), "start_frame": start, "params": params.to_dict()})
    meta = {"origin": "procedural", "synthetic": True, "path_kind": path.kind, "transition_segments": segments_meta,
            "transition_method": "segmented procedural walk with cross-fades (clipgen.transition_walk)"}
    return Motion(gait_skeleton(), np_qfix(rot), root, fps, meta)


def _captured_file(entry: ClipEntry, fps: float) -> Motion:
    """An imported motion file (generation/plans/captured_file.py); errors name the entry and the field."""
    try:
        return captured_file_motion(entry.inputs, entry.modality, fps)
    except CapturedFileError as exc:
        raise ClipGenerationError(f"{entry.where}: {exc}") from None


def _captured(entry: ClipEntry, fps: float) -> Motion:
    names = [name for name, _ in WALK_FILES]
    clip = entry.inputs["clip"]
    if clip not in names:
        raise ClipGenerationError(f"{entry.where}: captured clip {clip!r} not shipped (have {names})")
    motion = captured_walks()[names.index(clip)]
    if entry.inputs["cycles"] > 1:
        motion = chain_clip_repeats(motion, entry.inputs["cycles"])
        # The walker clips do not loop exactly (last pose 17-38 deg from the first): at every seam the standing
        # foot jumped 6-9 cm (skate 9-11 cm/s over 8 repeats vs 3-8 for one clip). Plant the feet, and say so.
        # lower_pelvis: locking the sliding source feet put the stance knee fully straight in 17-27 % of the
        # frames; lowering the pelvis where out of reach (<= 2.5 cm, smoothed) avoids that.
        motion = plant_feet(motion, lower_pelvis=True)
        motion.metadata.update({"foot_planting": True,
                                "foot_planting_reason": "seams of the chained repeats (chain_clip_repeats)"})
    return motion


@functools.lru_cache(maxsize=2)
def _neutral_cycle(base: str = "real") -> Motion:
    """The RBF styliser's neutral base: averaged real normal walks (shipped file) or averaged procedural walks."""
    return load_cycle() if base == "real" else neutral_cycle()


def _neutral_walk(entry: ClipEntry, fps: float) -> Motion:
    from generation.rbf.stylise import cycle_stride, plant_walk_feet, warp_and_repeat_cycle  # heavy: torch

    inp = entry.inputs
    base = _neutral_cycle(inp.get("base", "real"))
    rot, root = warp_and_repeat_cycle(base.rotations, base.root_positions, cycle_stride(base), base.duration,
                                      inp["speed"], inp["n_cycles"], fps)
    meta = dict(base.metadata)
    meta.update({"generator": "neutral_walk", "n_cycles": inp["n_cycles"], "speed": inp["speed"],
                 "base": inp.get("base", "real")})
    # planted like the RBF-styled walks it is compared with (_rbf), so they differ by the features only
    return plant_walk_feet(Motion(base.skeleton, rot, root, fps, meta))


def _rbf(entry: ClipEntry, fps: float) -> Motion:
    from generation.rbf.stylise import stylise  # heavy: torch

    inp = entry.inputs
    motion = stylise(_neutral_cycle(inp.get("base", "real")), inp["theme"], inp["weight"], inp["n_features"],
                     speed=inp["speed"], n_cycles=inp["n_cycles"], fps=fps, features=inp.get("features", "expert"))
    motion.metadata["base"] = inp.get("base", "real")
    return motion


def _gesture_net(entry: ClipEntry, fps: float) -> Motion:
    from generation.gesture.generate import generate_gesture  # heavy: torch

    inp = entry.inputs
    return generate_gesture(inp["sentence"], inp["task"], inp["emotion_label"], inp["gender"], inp["handedness"],
                            fps=fps, seed=entry.seed, noise=inp["noise"])


def _procedural_gesture(entry: ClipEntry, fps: float) -> Motion:
    inp = entry.inputs
    v, a, d = GESTURE_VAD[inp["emotion_label"]] if "emotion_label" in inp else inp["vad"]
    rng = np.random.default_rng(entry.seed)
    params = gesture_params_for_vad(v, a, d, rng, kind=inp["kind"], handedness=inp["handedness"])
    n_frames = int(round(inp["duration_s"] * fps))
    motion = seated_gesture(params, n_frames, fps, gesture_skeleton(build=inp["gender"]), seed=entry.seed)
    motion.metadata.update({"emotion_label": inp.get("emotion_label"), "valence": v, "arousal": a, "dominance": d,
                            "gender": inp["gender"], "handedness": inp["handedness"]})
    return motion


MAKERS = {
    "gait_net": _gait_net,
    "procedural_walk": _procedural_walk,
    "captured": _captured,
    "captured_file": _captured_file,
    "neutral_walk": _neutral_walk,
    "rbf": _rbf,
    "gesture_net": _gesture_net,
    "procedural_gesture": _procedural_gesture,
}


def make_motion(entry: ClipEntry, fps: float | None = None, requested: str | None = None,
                fallback_reason: str | None = None) -> Motion:
    """Generate the motion of a (resolved) entry at ``fps`` (default: the entry's render fps).

    Args:
        entry: a validated entry, after :func:`resolve` (its ``generator`` is the one that runs).
        requested: the generator the plan asked for, when a fallback replaced it.
        fallback_reason: why, for the metadata.
    Returns the Motion with metadata naming the entry, the generator that made it, origin and whether it
    is synthetic. ClipGenerationError names the entry when the generator fails.
    """
    fps = fps or entry.render.fps
    try:
        motion = MAKERS[entry.generator](entry, fps)
    except ClipGenerationError:
        raise
    except Exception as exc:  # noqa: BLE001 - reported with the entry's name, original traceback chained
        raise ClipGenerationError(f"{entry.where}: generator {entry.generator!r} failed: "
                                  f"{type(exc).__name__}: {exc}") from exc
    meta = motion.metadata
    meta.setdefault("synthetic", meta.get("origin") in ("procedural", "generated") and entry.generator != "captured")
    meta["generator_module_origin"] = meta.get("origin")
    meta["origin"] = entry.origin
    meta["generator"] = entry.generator
    meta["entry_id"] = entry.id
    if requested and requested != entry.generator:
        meta["fallback_for"] = requested
        meta["fallback_reason"] = fallback_reason or ""
        meta["synthetic"] = True
    return motion


# ---- motion files ------------------------------------------------------------------------------
def write_motion_bvh(motion: Motion, motions_dir: str | Path, clip_id: str) -> Path:
    """Keep a clip's motion as ``motions_dir/<clip_id>.bvh`` (DESIGN.md: ``MEDIA_ROOT/motions/<clip_id>.bvh``).

    The file appears under its final name only when complete (temporary name, then rename). Like the clip records,
    ``motions_dir`` is never served: a motion file names no condition, but its id is the clip's.
    Returns the path written.
    """
    if not clip_id or any(c in clip_id for c in "/\\.") or clip_id.strip() != clip_id:
        raise ValueError(f"clip id {clip_id!r} cannot name a file")
    motions_dir = Path(motions_dir)
    motions_dir.mkdir(parents=True, exist_ok=True)
    path = motions_dir / f"{clip_id}.bvh"
    tmp = motions_dir / f".{clip_id}.bvh.tmp"
    write_bvh(motion, tmp)
    tmp.replace(path)
    return path
