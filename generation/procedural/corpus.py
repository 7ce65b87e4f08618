"""The SYNTHETIC emotion-labelled training corpora (procedural gaits and seated gestures).

No emotion-labelled body-motion data set can be had offline (REFERENCE.md section 7), so the
networks are trained on procedural motion whose style follows the literature mapping in
:mod:`generation.procedural.emotion`. Everything here is synthetic and says so: file names contain
"synthetic", each corpus carries ``metadata = {"synthetic": True, "origin": "procedural", ...}``,
and the gait labels are *simulated* annotator counts (seed 000 section 3.2.2), not human ratings.

Gait corpus (:func:`build_gait_corpus`): pure emotions and continuous mixtures, varied body heights
and builds, straight / curved / sharp-turn paths, 240 frames at 30 fps by default (the gait network
subsamples every 4th frame, T = 60). Gesture corpus (:func:`build_gesture_corpus`): one seated
gesture sequence per spec (emotion word, task, gender, handedness, frames).

Command line: ``python -m generation.procedural.corpus [--out DIR] [--seed N] [--num N]`` or
``python manage.py build_corpus``.
"""
from __future__ import annotations

import argparse
import json
import time
from collections import Counter
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from generation.core.motion import Motion
from generation.core.paths import PATH_KINDS, random_path
from generation.core.skeleton import gait_skeleton, gesture_skeleton
from generation.core.splits import SPLITS
from protocol.vocabulary import GAIT_EMOTIONS, GENDERS, GESTURE_EMOTIONS, GESTURE_TASKS, HANDEDNESS

from .emotion import gait_params_for_emotion, gesture_params_for_vad, simulate_annotators, vad_for
from .gesture import GESTURE_KINDS, seated_gesture
from .walk import walk

DEFAULT_DIR = Path("var/corpus")
GAIT_CORPUS_FILE = "gait_corpus_synthetic.npz"
GESTURE_CORPUS_FILE = "gesture_corpus_synthetic.npz"
FORMAT_VERSION = 1


class CorpusFormatError(ValueError):
    """A corpus file is malformed; the message names the file and the field."""


def _stratified_split(groups: np.ndarray, rng: np.random.Generator) -> np.ndarray:
    """80/10/10 train/val/test within each group label (rounded; val and test get at least one when n >= 3)."""
    split = np.empty(len(groups), dtype="<U5")
    for g in sorted(set(groups.tolist())):
        idx = np.flatnonzero(groups == g)
        rng.shuffle(idx)
        n = len(idx)
        n_val = n_test = max(1, int(round(0.1 * n))) if n >= 3 else 0
        split[idx[:n_test]] = "test"
        split[idx[n_test:n_test + n_val]] = "val"
        split[idx[n_test + n_val:]] = "train"
    return split


def _body(rng: np.random.Generator, build: str | None = None) -> tuple[float, str]:
    """A random body: build, and height from a normal per build (male 1.76 +- 0.07 m, female 1.63 +- 0.065 m)."""
    build = build or ("male" if rng.random() < 0.5 else "female")
    mean, sd = (1.76, 0.07) if build == "male" else (1.63, 0.065)
    return float(np.clip(rng.normal(mean, sd), 1.45, 2.0)), build


def _load_npz(path: Path, required: tuple[str, ...]):
    path = Path(path)
    try:
        data = np.load(path, allow_pickle=False)
    except (OSError, ValueError) as exc:
        raise CorpusFormatError(f"{path}: not a readable .npz corpus ({exc})") from None
    for key in required:
        if key not in data:
            raise CorpusFormatError(f"{path}: missing field {key!r}")
    return data


# ---- gait ----------------------------------------------------------------------------------------
@dataclass
class GaitCorpus:
    """N synthetic procedural walks on the 21-joint gait skeleton.

    Attributes:
        rotations: (N, T, 21, 4) float32 local unit quaternions.
        root_positions: (N, T, 3) float32 metres (y-up).
        emotion: (N, 4) float32 soft labels (happy, sad, angry, neutral): l1-normalised counts of
            *simulated* annotators (seed 000 section 3.2.2).
        true_emotion: (N, 4) float32 the emotion vector the walk parameters were made from.
        split: (N,) "train" / "val" / "test" (80/10/10, stratified by dominant true emotion).
        path_kind: (N,) "straight" / "curved" / "sharp_turn".
        height: (N,) body height in metres; build: (N,) "male" / "female" (rebuild the skeleton with
            ``gait_skeleton(height[i], build[i])``).
        params: N dicts (WalkParams fields, phase, seed) as used to make each walk.
        fps: frame rate. seed: the corpus seed. metadata: {"synthetic": True, ...}.
    """

    rotations: np.ndarray
    root_positions: np.ndarray
    emotion: np.ndarray
    true_emotion: np.ndarray
    split: np.ndarray
    path_kind: np.ndarray
    height: np.ndarray
    build: np.ndarray
    params: list
    fps: float = 30.0
    seed: int = 0
    metadata: dict = field(default_factory=dict)

    def __len__(self) -> int:
        return len(self.rotations)

    @property
    def num_frames(self) -> int:
        return self.rotations.shape[1]

    def skeleton(self, i: int):
        return gait_skeleton(float(self.height[i]), str(self.build[i]))

    def motion(self, i: int) -> Motion:
        """Sequence ``i`` as a Motion (float64), with its labels in the metadata."""
        meta = {"origin": "procedural", "synthetic": True, "corpus_index": int(i),
                "emotion": dict(zip(GAIT_EMOTIONS, map(float, self.emotion[i]), strict=True)),
                "true_emotion": dict(zip(GAIT_EMOTIONS, map(float, self.true_emotion[i]), strict=True)),
                "split": str(self.split[i]), "path_kind": str(self.path_kind[i]), "params": self.params[i]}
        return Motion(self.skeleton(i), self.rotations[i], self.root_positions[i], self.fps, meta)

    def indices(self, split: str) -> np.ndarray:
        if split not in SPLITS:
            raise ValueError(f"split must be one of {SPLITS}, got {split!r}")
        return np.flatnonzero(self.split == split)

    def summary(self) -> dict:
        dominant = np.asarray(GAIT_EMOTIONS)[self.true_emotion.argmax(1)]
        pure = self.true_emotion.max(1) > 0.999
        return {
            "sequences": len(self),
            "frames": self.num_frames,
            "fps": self.fps,
            "pure_per_emotion": {e: int(((dominant == e) & pure).sum()) for e in GAIT_EMOTIONS},
            "mixtures": int((~pure).sum()),
            "dominant_per_emotion": {e: int((dominant == e).sum()) for e in GAIT_EMOTIONS},
            "split": {s: int((self.split == s).sum()) for s in SPLITS},
            "path_kind": dict(Counter(self.path_kind.tolist())),
            "build": dict(Counter(self.build.tolist())),
            "height_range_m": [float(self.height.min()), float(self.height.max())],
        }

    def save(self, path: str | Path) -> Path:
        """Write a compressed .npz (creates the folder)."""
        path = Path(path)
        path.parent.mkdir(parents=True, exist_ok=True)
        np.savez_compressed(
            path, rotations=self.rotations.astype(np.float32), root_positions=self.root_positions.astype(np.float32),
            emotion=self.emotion.astype(np.float32), true_emotion=self.true_emotion.astype(np.float32),
            split=self.split.astype(str), path_kind=self.path_kind.astype(str), height=self.height.astype(np.float64),
            build=self.build.astype(str), params=json.dumps(self.params), fps=np.float64(self.fps),
            seed=np.int64(self.seed), metadata=json.dumps(self.metadata), format_version=np.int64(FORMAT_VERSION),
            emotion_names=np.asarray(GAIT_EMOTIONS))
        return path

    @classmethod
    def load(cls, path: str | Path) -> GaitCorpus:
        """Read a file written by :meth:`save`; CorpusFormatError names a missing or inconsistent field."""
        required = ("rotations", "root_positions", "emotion", "true_emotion", "split", "path_kind", "height", "build",
                    "params", "fps", "seed", "metadata")
        data = _load_npz(path, required)
        try:
            corpus = cls(rotations=data["rotations"], root_positions=data["root_positions"], emotion=data["emotion"],
                         true_emotion=data["true_emotion"], split=data["split"].astype(str),
                         path_kind=data["path_kind"].astype(str), height=data["height"],
                         build=data["build"].astype(str), params=json.loads(str(data["params"])),
                         fps=float(data["fps"]), seed=int(data["seed"]), metadata=json.loads(str(data["metadata"])))
        except ValueError as exc:
            raise CorpusFormatError(f"{path}: bad params or metadata field ({exc})") from None
        corpus.validate(str(path))
        return corpus

    def validate(self, where: str = "GaitCorpus") -> GaitCorpus:
        N = len(self.rotations)
        checks = {
            "rotations": (self.rotations.ndim == 4 and self.rotations.shape[2:] == (21, 4), "(N, T, 21, 4)"),
            "root_positions": (self.root_positions.shape == self.rotations.shape[:2] + (3,), "(N, T, 3)"),
            "emotion": (self.emotion.shape == (N, 4), "(N, 4)"),
            "true_emotion": (self.true_emotion.shape == (N, 4), "(N, 4)"),
            "split": (self.split.shape == (N,) and set(self.split.tolist()) <= set(SPLITS), "(N,) train/val/test"),
            "path_kind": (self.path_kind.shape == (N,), "(N,)"),
            "height": (self.height.shape == (N,), "(N,)"),
            "build": (self.build.shape == (N,), "(N,)"),
            "params": (len(self.params) == N, "N entries"),
        }
        for name, (ok, want) in checks.items():
            if not ok:
                raise CorpusFormatError(f"{where}: field {name!r} should be {want} with N={N}")
        if not np.allclose(self.emotion.sum(1), 1.0, atol=1e-4):
            raise CorpusFormatError(f"{where}: field 'emotion' rows must be l1-normalised")
        return self


def sample_true_emotions(n: int, rng: np.random.Generator, pure_fraction: float = 0.4) -> np.ndarray:
    """(n, 4) emotion vectors: ``pure_fraction`` one-hot (balanced over the 4 emotions), the rest mixtures.

    Mixtures are Dirichlet(0.7) draws over all four emotions, so two- and three-way blends of
    every kind occur.
    """
    n_pure = int(round(pure_fraction * n))
    pure = np.eye(4)[np.arange(n_pure) % 4]
    mix = rng.dirichlet(np.full(4, 0.7), size=n - n_pure)
    out = np.concatenate([pure, mix])
    return out[rng.permutation(n)]


def build_gait_corpus(num_sequences: int = 1000, seed: int = 0, frames: int = 240, fps: float = 30.0,
                      n_annotators: int = 10, pure_fraction: float = 0.4, progress: bool = False) -> GaitCorpus:
    """Build the synthetic gait corpus (deterministic from ``seed``).

    Each sequence: a true emotion vector (pure or mixture), walk parameters from
    :func:`~generation.procedural.emotion.gait_params_for_emotion` with individual variation, a random body
    (height, build), a random straight / curved / sharp-turn path long enough for the walk, a random
    starting gait phase; the soft label is the relative count of ``n_annotators`` simulated
    annotators (:func:`~generation.procedural.emotion.simulate_annotators`).

    Returns a :class:`GaitCorpus`; about 5 ms per 240-frame sequence on one core.
    """
    if int(num_sequences) < 1:
        raise ValueError(f"num_sequences must be at least 1, got {num_sequences}")
    if int(frames) < 2:
        raise ValueError(f"frames must be at least 2, got {frames}")
    N, T = int(num_sequences), int(frames)
    root_rng = np.random.default_rng(seed)
    true = sample_true_emotions(N, root_rng, pure_fraction)
    child_seeds = np.random.SeedSequence(seed).spawn(N)
    rotations = np.zeros((N, T, 21, 4), dtype=np.float32)
    roots = np.zeros((N, T, 3), dtype=np.float32)
    emotion = np.zeros((N, 4))
    heights = np.zeros(N)
    builds = np.empty(N, dtype="<U6")
    kinds = np.empty(N, dtype="<U10")
    params_out = []
    for i in range(N):
        rng = np.random.default_rng(child_seeds[i])
        params = gait_params_for_emotion(true[i], rng)
        height, build = _body(rng)
        skeleton = gait_skeleton(height, build)
        distance = params.speed_mps * height / 1.75 * T / fps + 1.0
        path = random_path(rng, distance)
        phase = float(rng.random())
        walk_seed = int(rng.integers(2 ** 31))
        motion = walk(params, path, T, fps, skeleton, phase=phase, seed=walk_seed)
        rotations[i] = motion.rotations
        roots[i] = motion.root_positions
        emotion[i] = simulate_annotators(true[i], n_annotators, rng)
        heights[i], builds[i], kinds[i] = height, build, path.kind
        params_out.append({**params.to_dict(), "phase": phase, "walk_seed": walk_seed})
        if progress and (i + 1) % 200 == 0:
            print(f"  {i + 1}/{N} walks")
    split = _stratified_split(np.asarray(GAIT_EMOTIONS)[true.argmax(1)], root_rng)
    metadata = {"synthetic": True, "origin": "procedural",
                "generator": "generation.procedural.corpus.build_gait_corpus",
                "labels": f"simulated annotators (n={n_annotators}), not human ratings",
                "emotions": list(GAIT_EMOTIONS), "path_kinds": list(PATH_KINDS), "frames": T, "fps": fps}
    return GaitCorpus(rotations, roots, emotion.astype(np.float32), true.astype(np.float32), split, kinds, heights,
                      builds, params_out, float(fps), int(seed), metadata).validate()


# ---- gestures ------------------------------------------------------------------------------------
@dataclass
class GestureCorpus:
    """N synthetic procedural seated gesture sequences on the 23-joint gesture skeleton.

    Attributes:
        rotations: (N, T_max, 23, 4) float32 local unit quaternions; frames past ``lengths[i]``
            repeat the last frame (the seated rest pose).
        root_positions: (N, T_max, 3) float32 metres (the seated root, constant).
        lengths: (N,) int64 valid frames.
        vad: (N, 3) float32 NRC-VAD (valence, arousal, dominance) of the emotion word.
        emotion, task, gender, handedness, split: (N,) str.
        height: (N,) metres; gender doubles as the skeleton build.
        params: N lists of GestureParams dicts. fps, seed, metadata as for the gait corpus.
    """

    rotations: np.ndarray
    root_positions: np.ndarray
    lengths: np.ndarray
    vad: np.ndarray
    emotion: np.ndarray
    task: np.ndarray
    gender: np.ndarray
    handedness: np.ndarray
    split: np.ndarray
    height: np.ndarray
    params: list
    fps: float = 30.0
    seed: int = 0
    metadata: dict = field(default_factory=dict)

    def __len__(self) -> int:
        return len(self.lengths)

    def skeleton(self, i: int):
        return gesture_skeleton(float(self.height[i]), str(self.gender[i]))

    def motion(self, i: int) -> Motion:
        n = int(self.lengths[i])
        meta = {"origin": "procedural", "synthetic": True, "corpus_index": int(i),
                "emotion_label": str(self.emotion[i]),
                "vad": [float(x) for x in self.vad[i]], "task": str(self.task[i]), "split": str(self.split[i]),
                "handedness": str(self.handedness[i]), "params": self.params[i]}
        return Motion(self.skeleton(i), self.rotations[i, :n], self.root_positions[i, :n], self.fps, meta)

    def save(self, path: str | Path) -> Path:
        path = Path(path)
        path.parent.mkdir(parents=True, exist_ok=True)
        np.savez_compressed(
            path, rotations=self.rotations.astype(np.float32), root_positions=self.root_positions.astype(np.float32),
            lengths=self.lengths.astype(np.int64), vad=self.vad.astype(np.float32), emotion=self.emotion.astype(str),
            task=self.task.astype(str), gender=self.gender.astype(str), handedness=self.handedness.astype(str),
            split=self.split.astype(str), height=self.height.astype(np.float64), params=json.dumps(self.params),
            fps=np.float64(self.fps), seed=np.int64(self.seed), metadata=json.dumps(self.metadata),
            format_version=np.int64(FORMAT_VERSION))
        return path

    @classmethod
    def load(cls, path: str | Path) -> GestureCorpus:
        required = ("rotations", "root_positions", "lengths", "vad", "emotion", "task", "gender", "handedness",
                    "split", "height", "params", "fps", "seed", "metadata")
        data = _load_npz(path, required)
        try:
            corpus = cls(rotations=data["rotations"], root_positions=data["root_positions"], lengths=data["lengths"],
                         vad=data["vad"], emotion=data["emotion"].astype(str), task=data["task"].astype(str),
                         gender=data["gender"].astype(str), handedness=data["handedness"].astype(str),
                         split=data["split"].astype(str), height=data["height"],
                         params=json.loads(str(data["params"])), fps=float(data["fps"]), seed=int(data["seed"]),
                         metadata=json.loads(str(data["metadata"])))
        except ValueError as exc:
            raise CorpusFormatError(f"{path}: bad params or metadata field ({exc})") from None
        N = len(corpus.lengths)
        if corpus.rotations.shape[0] != N or corpus.rotations.shape[2:] != (23, 4) or corpus.vad.shape != (N, 3):
            raise CorpusFormatError(f"{path}: rotations must be (N, T, 23, 4) and vad (N, 3) with N={N}")
        return corpus


def _parse_spec(spec, i: int) -> tuple[str, str, str, str, int]:
    if isinstance(spec, dict):
        try:
            spec = (spec["emotion"], spec["task"], spec["gender"], spec["handedness"], spec["n_frames"])
        except KeyError as exc:
            raise ValueError(f"gesture spec {i}: missing key {exc}") from None
    if len(spec) != 5:
        raise ValueError(f"gesture spec {i}: expected (emotion, task, gender, handedness, n_frames), got {spec!r}")
    word, task, gender, hand, n = spec
    vad_for(word)  # KeyError naming the known words
    if task not in GESTURE_TASKS:
        raise ValueError(f"gesture spec {i}: task must be one of {GESTURE_TASKS}, got {task!r}")
    if gender not in GENDERS:
        raise ValueError(f"gesture spec {i}: gender must be one of {GENDERS}, got {gender!r}")
    if hand not in HANDEDNESS:
        raise ValueError(f"gesture spec {i}: handedness must be one of {HANDEDNESS}, got {hand!r}")
    if int(n) < 8:
        raise ValueError(f"gesture spec {i}: n_frames must be at least 8, got {n}")
    return str(word).lower(), task, gender, hand, int(n)


def build_gesture_corpus(specs, seed: int = 0, fps: float = 30.0) -> GestureCorpus:
    """One synthetic seated gesture sequence per spec (deterministic from ``seed``).

    Args:
        specs: sequence of (emotion word, task "narration"/"conversation", gender "male"/"female",
            handedness "left"/"right", n_frames) tuples, or dicts with those keys.
        seed: random seed (body height, gesture kinds, individual variation).

    Each sequence has one gesture per ~1.5 s (at least one), kinds drawn by
    :func:`~generation.procedural.emotion.gesture_params_for_vad` from the word's NRC-VAD values; narration is
    performed larger (amplitude x1.2) than conversation (x0.8), as seed 003 section 3.3.1 describes.
    """
    parsed = [_parse_spec(s, i) for i, s in enumerate(specs)]
    if not parsed:
        raise ValueError("build_gesture_corpus needs at least one spec")
    N = len(parsed)
    T_max = max(p[4] for p in parsed)
    child_seeds = np.random.SeedSequence(seed).spawn(N)
    rotations = np.zeros((N, T_max, 23, 4), dtype=np.float32)
    roots = np.zeros((N, T_max, 3), dtype=np.float32)
    lengths = np.zeros(N, dtype=np.int64)
    vad = np.zeros((N, 3))
    heights = np.zeros(N)
    params_out = []
    for i, (word, task, gender, hand, n) in enumerate(parsed):
        rng = np.random.default_rng(child_seeds[i])
        v, a, d = vad_for(word)
        height, _ = _body(rng, gender)
        n_gestures = max(1, int(round(n / fps / 1.5)))
        gain = 1.2 if task == "narration" else 0.8
        plist = []
        for _ in range(n_gestures):
            p = gesture_params_for_vad(v, a, d, rng, handedness=hand)
            p.amplitude = float(np.clip(p.amplitude * gain, 0.2, 1.6))
            p.head_motion = float(np.clip(p.head_motion * gain, 0.0, 0.4))
            plist.append(p.validate())
        motion = seated_gesture(plist, n, fps, gesture_skeleton(height, gender), seed=int(rng.integers(2 ** 31)))
        rotations[i, :n] = motion.rotations
        rotations[i, n:] = motion.rotations[-1]
        roots[i, :n] = motion.root_positions
        roots[i, n:] = motion.root_positions[-1]
        lengths[i], vad[i], heights[i] = n, (v, a, d), height
        params_out.append([p.to_dict() for p in plist])
    emotion = np.asarray([p[0] for p in parsed])
    split = _stratified_split(emotion, np.random.default_rng(seed))
    metadata = {"synthetic": True, "origin": "procedural",
                "generator": "generation.procedural.corpus.build_gesture_corpus",
                "vad_source": "NRC-VAD lexicon (Mohammad, ACL 2018)", "kinds": list(GESTURE_KINDS), "fps": fps}
    return GestureCorpus(rotations, roots, lengths, vad.astype(np.float32), emotion,
                         np.asarray([p[1] for p in parsed]), np.asarray([p[2] for p in parsed]),
                         np.asarray([p[3] for p in parsed]), split, heights, params_out, float(fps), int(seed),
                         metadata)


def default_gesture_specs(n_frames: int = 150) -> list[tuple[str, str, str, str, int]]:
    """Every MPI emotion x task x gender x handedness once (88 specs), for a demo gesture corpus."""
    male_first = GENDERS[::-1]  # the order the demo corpus has always been built in (its seeds follow the order)
    return [(e, t, g, h, n_frames)
            for e in GESTURE_EMOTIONS for t in GESTURE_TASKS for g in male_first for h in HANDEDNESS]


# ---- command line ----------------------------------------------------------------------------------
def build_and_save(out_dir: str | Path = DEFAULT_DIR, seed: int = 0, num_sequences: int = 1000, frames: int = 240,
                   gestures: bool = False, echo=print) -> dict:
    """Build the gait corpus (and optionally the demo gesture corpus), save them, report what was built."""
    out_dir = Path(out_dir)
    t0 = time.perf_counter()
    gait = build_gait_corpus(num_sequences, seed, frames)
    t_build = time.perf_counter() - t0
    gait_path = gait.save(out_dir / GAIT_CORPUS_FILE)
    t_total = time.perf_counter() - t0
    info = {"gait": {**gait.summary(), "path": str(gait_path), "build_s": round(t_build, 2),
                     "build_and_save_s": round(t_total, 2)}}
    echo(f"SYNTHETIC gait corpus -> {gait_path} ({gait_path.stat().st_size / 2 ** 20:.1f} MiB)")
    s = info["gait"]
    echo(f"  {s['sequences']} sequences x {s['frames']} frames at {s['fps']:g} fps; "
         f"built in {t_build:.1f} s, saved in {t_total - t_build:.1f} s")
    echo(f"  pure per emotion: {s['pure_per_emotion']}; mixtures: {s['mixtures']}")
    echo(f"  dominant emotion: {s['dominant_per_emotion']}")
    echo(f"  split: {s['split']}; paths: {s['path_kind']}; builds: {s['build']}; "
         f"heights {s['height_range_m'][0]:.2f}-{s['height_range_m'][1]:.2f} m")
    if gestures:
        t1 = time.perf_counter()
        ges = build_gesture_corpus(default_gesture_specs(), seed)
        ges_path = ges.save(out_dir / GESTURE_CORPUS_FILE)
        info["gesture"] = {"sequences": len(ges), "path": str(ges_path), "build_s": round(time.perf_counter() - t1, 2),
                           "per_emotion": dict(Counter(ges.emotion.tolist())),
                           "split": {k: int((ges.split == k).sum()) for k in SPLITS}}
        echo(f"SYNTHETIC gesture corpus -> {ges_path}: {len(ges)} sequences in {info['gesture']['build_s']} s; "
             f"split {info['gesture']['split']}")
    return info


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description="Build the SYNTHETIC procedural training corpora.")
    parser.add_argument("--out", default=str(DEFAULT_DIR), help="output folder (default var/corpus)")
    parser.add_argument("--seed", type=int, default=0)
    parser.add_argument("--num", type=int, default=1000, help="gait sequences (default 1000)")
    parser.add_argument("--frames", type=int, default=240, help="frames per gait sequence at 30 fps (default 240)")
    parser.add_argument("--gestures", action="store_true", help="also build the 88-sequence demo gesture corpus")
    args = parser.parse_args(argv)
    build_and_save(args.out, args.seed, args.num, args.frames, args.gestures)
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
