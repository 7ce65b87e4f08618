"""The gesture network's SYNTHETIC training corpus: project-written sentences paired with procedural gestures.

Seed 003 trains on the MPI Emotional Body Expressions database (captured motion, 1,447 sequences), which is not
available offline. In its place, each sentence of ``generation/data/sentences_synthetic.csv`` (330 sentences
written for this project: 11 MPI emotions x 15 narration + 15 conversation lines) is paired with procedural
seated gestures from :func:`generation.procedural.gesture.seated_gesture`, whose affective traits follow the
intended emotion's arousal (speed) and dominance (expansion) as in seed 003 section 4.3. The gesture lasts as long
as the sentence takes to say (:func:`generation.gesture.config.gesture_seconds`), starts and ends at the seated
rest pose, is performed by a female or male body (``gesture_skeleton(build=gender)``) and leads with the dominant
hand. Everything here is synthetic and labelled so in metadata; none of it is captured motion.

Each sentence also gets a counterfactual variant, performed with another emotion than the one it was written for,
so that the emotion attributes, not only the wording, decide the style (:func:`build_dataset`).

Splits are by sentence (80/10/10, stratified by emotion), so every variant of a sentence lands in one split.

``build_dataset(augment=N)`` adds N more SYNTHETIC training sentences made by recombining the phrases of
training-split sentences (:func:`augment_rows`; sentence ids ``aug00000``...), so that the network sees the same
words in more contexts and learns each phrase's gesture kind from its words rather than memorising whole sentences.
They are always in the training split; the split of the corpus sentences is computed before and does not change.
"""
from __future__ import annotations

import csv
import dataclasses
import hashlib
import json
import re
from dataclasses import dataclass
from pathlib import Path

import numpy as np
import torch

from generation.core.motion import Motion
from generation.core.quaternion import np_qfix, np_qnormalize
from generation.core.skeleton import gesture_skeleton
from generation.core.splits import SPLITS
from generation.procedural.emotion import gesture_params_for_vad
from generation.procedural.gesture import seated_gesture, seated_rest_pose
from protocol.vocabulary import GESTURE_VAD

from . import config
from .text import EMBED_DIM, cached_encodings, count_words, pad_tokens

SYNTHETIC_LABEL = "synthetic procedural gestures"


class CorpusFormatError(ValueError):
    """The sentence CSV is malformed; the message names the file, line and field."""


@dataclass(frozen=True)
class SentenceRow:
    sentence_id: str
    emotion: str
    task: str
    sentence: str


def nrc_vad(emotion: str) -> tuple[float, float, float]:
    """(valence, arousal, dominance) in [0, 1] of an emotion word from the NRC-VAD table (Mohammad, ACL 2018)."""
    key = emotion.strip().lower()
    if key not in GESTURE_VAD:
        raise ValueError(f"emotion {emotion!r} is not in the NRC-VAD table; known: {', '.join(GESTURE_VAD)}")
    v, a, d = GESTURE_VAD[key]
    return float(v), float(a), float(d)


def load_sentences(path: str | Path = config.SENTENCES_CSV) -> list[SentenceRow]:
    """Rows of the sentence corpus CSV (columns sentence_id, emotion, task, sentence)."""
    path = Path(path)
    if not path.is_file():
        raise CorpusFormatError(f"{path}: sentence corpus not found")
    rows: list[SentenceRow] = []
    seen: set[str] = set()
    with path.open(newline="", encoding="utf-8") as fh:
        reader = csv.DictReader(fh)
        expected = ["sentence_id", "emotion", "task", "sentence"]
        if reader.fieldnames != expected:
            raise CorpusFormatError(f"{path}: line 1: header must be {','.join(expected)}, got {reader.fieldnames}")
        for line, rec in enumerate(reader, start=2):
            sid, emo, task, text = (rec.get(k) or "" for k in expected)
            if not sid or sid in seen:
                raise CorpusFormatError(f"{path}: line {line}: field sentence_id is empty or repeated ({sid!r})")
            if emo not in GESTURE_VAD:
                raise CorpusFormatError(f"{path}: line {line}: field emotion {emo!r} is not an NRC-VAD word")
            if task not in config.TASKS:
                raise CorpusFormatError(f"{path}: line {line}: field task must be one of {config.TASKS}, got {task!r}")
            if count_words(text) == 0:
                raise CorpusFormatError(f"{path}: line {line}: field sentence has no words")
            seen.add(sid)
            rows.append(SentenceRow(sid, emo, task, text.strip()))
    if not rows:
        raise CorpusFormatError(f"{path}: no sentences")
    return rows


def one_hot(value: str, vocabulary: tuple[str, ...], field: str) -> np.ndarray:
    if value not in vocabulary:
        raise ValueError(f"{field} must be one of {vocabulary}, got {value!r}")
    out = np.zeros(len(vocabulary), dtype=np.float32)
    out[vocabulary.index(value)] = 1.0
    return out


def attribute_vector(task: str, vad: tuple[float, float, float], gender: str, handedness: str) -> np.ndarray:
    """The agent attributes of seed 003 section 3.3: [A (2), E = VAD (3), G (2), H (2)] -> (9,) float32."""
    vad = np.asarray(vad, dtype=np.float32)
    if vad.shape != (3,) or not np.all((vad >= 0) & (vad <= 1)):
        raise ValueError(f"VAD must be three values in [0, 1], got {vad}")
    return np.concatenate([one_hot(task, config.TASKS, "task"), vad, one_hot(gender, config.GENDERS, "gender"),
                           one_hot(handedness, config.HANDEDNESS, "handedness")])


def split_sentences(rows: list[SentenceRow], seed: int = 0) -> dict[str, str]:
    """sentence_id -> "train" | "val" | "test": 80/10/10 within each emotion (rounded), fixed seed."""
    rng = np.random.default_rng(seed)
    out: dict[str, str] = {}
    by_emotion: dict[str, list[str]] = {}
    for r in rows:
        by_emotion.setdefault(r.emotion, []).append(r.sentence_id)
    for emo in sorted(by_emotion):
        ids = list(by_emotion[emo])
        rng.shuffle(ids)
        n_val = n_test = max(1, int(round(0.1 * len(ids)))) if len(ids) >= 3 else 0
        for i, sid in enumerate(ids):
            out[sid] = "test" if i < n_test else "val" if i < n_test + n_val else "train"
    return out


def rest_rotations(gender: str) -> tuple[np.ndarray, np.ndarray]:
    """Seated rest (start- and end-of-sequence) pose of the gender's body: (23, 4) rotations, (3,) root metres."""

    rot, root = seated_rest_pose(gesture_skeleton(build=gender))
    return np.asarray(rot, dtype=np.float64), np.asarray(root, dtype=np.float64)


DEICTIC_WORDS = frozenset("you your yours yourself this that these those there here look".split())


def gesture_kind_for(sentence: str, arousal: float) -> str:
    """The procedural gesture kind a sentence gets, so the words matter to the gesture, not only its length.

    Deictic words (you, this, there, look, ...) -> "pointing"; otherwise high arousal (>= 0.6) or an exclamation
    -> "beat" (seed 003: beats go with aroused speech); otherwise "descriptive".
    """
    words = {w.lower() for w in re.findall(r"[A-Za-z']+", sentence)}
    if words & DEICTIC_WORDS:
        return "pointing"
    if arousal >= 0.6 or sentence.rstrip().endswith("!"):
        return "beat"
    return "descriptive"


MAX_PHRASES = 3
PROCEDURAL_DETAIL_SEED = 0


def phrases(sentence: str) -> list[str]:
    """The sentence cut at , ; : ? ! . (up to MAX_PHRASES; extra phrases are merged into the last one)."""
    parts = [p.strip() for p in re.split(r"[,;:?!.]+", sentence) if count_words(p) > 0]
    parts = parts or [sentence]
    if len(parts) > MAX_PHRASES:
        parts = parts[: MAX_PHRASES - 1] + [" ".join(parts[MAX_PHRASES - 1:])]
    return parts


def procedural_gesture(row: SentenceRow, gender: str, handedness: str, seed: int,
                       fps: float = config.TRAIN_FPS, emotion: str | None = None) -> Motion:
    """One SYNTHETIC training gesture for a sentence: procedural, seated, emotion-driven, at ``fps``.

    One gesture per phrase of the sentence (:func:`phrases`), its kind from the phrase's words
    (:func:`gesture_kind_for`), its style from the emotion's VAD (``gesture_params_for_vad``, with individual
    variation from ``seed``) and the acting task (:func:`_task_style`); the length follows the word count.
    The procedural generator's own random details (beat phase, pointing aim) use one fixed seed: nothing in the
    text or the attributes could predict them, so a random draw per example would only add unlearnable noise.
    ``emotion`` performs the sentence with another emotion than the one it was written for (default: its own).
    """

    emotion = row.emotion if emotion is None else emotion
    v, a, d = nrc_vad(emotion)
    rng = np.random.default_rng(seed)
    ending = row.sentence.rstrip()[-1:]
    params = [_task_style(gesture_params_for_vad(v, a, d, rng, kind=gesture_kind_for(p + ending, a),
                                                 handedness=handedness), row.task)
              for p in phrases(row.sentence)]
    n_frames = config.gesture_frames(count_words(row.sentence), fps)
    motion = seated_gesture(params, n_frames, fps, gesture_skeleton(build=gender), seed=PROCEDURAL_DETAIL_SEED)
    motion.metadata.update({"synthetic": True, "origin": "procedural", "sentence_id": row.sentence_id,
                            "task": row.task, "emotion_label": emotion, "kinds": [p.kind for p in params]})
    return motion


def _task_style(params, task: str):
    """Narration is more exaggerated and theatrical, conversation subtler (seed 003 section 3.3.1)."""

    scale = {"narration": 1.2, "conversation": 0.8}[task]
    return dataclasses.replace(params, amplitude=float(np.clip(params.amplitude * scale, 0.2, 1.6)),
                               head_motion=float(np.clip(params.head_motion * scale, 0.0, 0.4))).validate()


AUGMENT_PREFIX = "aug"
_JOINERS = (", ", ", ", "; ")


def is_augmented(row: SentenceRow) -> bool:
    """True for the phrase-recombination sentences of :func:`augment_rows` (never in the corpus CSV)."""
    return row.sentence_id.startswith(AUGMENT_PREFIX)


def _proper_words(rows: list[SentenceRow]) -> set[str]:
    """Words written capitalised inside a sentence (not after . ? !) in ``rows``: names, days, "I", "I'm"...;
    they keep their capital when a phrase that starts with them is moved inside a new sentence."""
    out = {"I"}
    for r in rows:
        for m in re.finditer(r"[A-Za-z']+", r.sentence):
            before = r.sentence[: m.start()].rstrip()
            if before and before[-1] not in ".?!" and m.group()[0].isupper():
                out.add(m.group())
    return out


def augment_rows(rows: list[SentenceRow], split: dict[str, str], n: int, seed: int = 0) -> list[SentenceRow]:
    """``n`` SYNTHETIC training sentences made by recombining phrases of the training-split sentences of ``rows``.

    Each new sentence joins a run of consecutive phrases (:func:`phrases`) of one training sentence with a run of
    another's, at most :data:`MAX_PHRASES` phrases and no more words than the longest source sentence (nor fewer
    than the shortest), e.g. "The report is on your desk, we actually did it!". Phrases are joined by ", " or "; ";
    the first word is capitalised, later phrases lose their capital unless it starts a name or "I"; the sentence
    ends with the last phrase's source's end mark, and a "?" or "!" that ended the first source stays after its
    phrase (so end marks travel with their phrases). The task comes from
    the first source; the emotion is drawn uniformly from the 11 emotions, balanced (each emotion n/11 times,
    shuffled), so wording and emotion are decorrelated and each emotion gets each gesture kind: the kind then
    follows the words (and arousal), which is what the network has to learn from them. Sentences that repeat a
    corpus sentence (any split) or an earlier new one are redrawn. Ids are ``aug00000``, ``aug00001``, ...
    Only sentences that ``split`` puts in "train" are sources; deterministic given ``rows``, ``split``, ``seed``.
    """
    if isinstance(n, bool) or not isinstance(n, (int, np.integer)) or n < 0:
        raise ValueError(f"augment must be a whole number >= 0 of extra training sentences, got {n!r}")
    n = int(n)
    if n == 0:
        return []
    sources = [r for r in rows if split.get(r.sentence_id) == "train" and not is_augmented(r)]
    if len(sources) < 2:
        raise ValueError(f"augment needs at least 2 training sentences to recombine, got {len(sources)}")
    rng = np.random.default_rng(np.random.SeedSequence([int(seed), 0xA06]))
    proper = _proper_words(sources)
    parts = [phrases(r.sentence) for r in sources]
    ends = [r.sentence.rstrip()[-1] if r.sentence.rstrip()[-1] in ".?!" else "." for r in sources]
    n_words = [count_words(r.sentence) for r in sources]
    lo, hi = min(n_words), max(n_words)
    seen = {re.sub(r"\W+", " ", r.sentence).strip().lower() for r in rows}
    emotions = tuple(GESTURE_VAD)
    schedule: list[str] = []
    out: list[SentenceRow] = []
    attempts = 0
    while len(out) < n:
        attempts += 1
        if attempts > 200 * n + 1000:
            raise ValueError(f"could not make {n} distinct recombined sentences from {len(sources)} training "
                             f"sentences (made {len(out)})")
        a, b = (int(x) for x in rng.choice(len(sources), size=2, replace=False))
        runs = []
        for src in (a, b):
            k = len(parts[src])
            length = int(rng.integers(1, k + 1))
            start = int(rng.integers(0, k - length + 1))
            runs.append((parts[src][start:start + length], start + length == k))
        chosen = runs[0][0] + runs[1][0]
        words = sum(count_words(p) for p in chosen)
        if len(chosen) > MAX_PHRASES or not lo <= words <= hi:
            continue
        # after each phrase: a joiner, or the first source's "?"/"!" when its run ends that sentence
        marks = [_JOINERS[int(rng.integers(len(_JOINERS)))] for _ in chosen[:-1]]
        if runs[0][1] and ends[a] in "?!":
            marks[len(runs[0][0]) - 1] = ends[a] + " "
        text = ""
        for j, p in enumerate(chosen):
            first, rest = (p.split(" ", 1) + [""])[:2]
            if j == 0 or marks[j - 1].startswith(("?", "!")):
                first = first[:1].upper() + first[1:]
            elif first not in proper:
                first = first[:1].lower() + first[1:]
            text += (first + " " + rest).strip() + (marks[j] if j < len(marks) else ends[b])
        norm = re.sub(r"\W+", " ", text).strip().lower()
        if norm in seen:
            continue
        seen.add(norm)
        if not schedule:
            schedule = [emotions[int(i)] for i in rng.permutation(len(emotions))]
        out.append(SentenceRow(f"{AUGMENT_PREFIX}{len(out):05d}", schedule.pop(), sources[a].task, text))
    return out


@dataclass
class GestureDataset:
    """Padded arrays of paired examples (N examples, S tokens, T frames at ``fps``, J = 23 joints).

    Attributes:
        tokens: (N, S, 384) float32 token vectors; token_lengths (N,) int64.
        rotations: (N, T, J, 4) float32 unit quaternions, padded past each length with the rest pose.
        lengths: (N,) int64 frames. attributes: (N, 9) float32. offsets: (N, J, 3) float32 metres.
        rest: (N, J, 4) float32 seated rest pose. root: (N, 3) float32 seated root position, metres.
        vad: (N, 3) float32. sentence_index: (N,) index into ``rows``. split: (N,) "train"/"val"/"test".
        gender, handedness: (N,) str. rows: the sentence rows. fps: frame rate.
        emotion: (N,) str, the emotion each gesture performs (its sentence's own, or another one for the
        counterfactual variants; None = the sentences' own).
    """

    tokens: np.ndarray
    token_lengths: np.ndarray
    rotations: np.ndarray
    lengths: np.ndarray
    attributes: np.ndarray
    offsets: np.ndarray
    rest: np.ndarray
    root: np.ndarray
    vad: np.ndarray
    sentence_index: np.ndarray
    split: np.ndarray
    gender: np.ndarray
    handedness: np.ndarray
    rows: list[SentenceRow]
    fps: float
    emotion: np.ndarray | None = None

    def __post_init__(self):
        if self.emotion is None:
            self.emotion = np.array([self.rows[int(i)].emotion for i in self.sentence_index])

    def __len__(self) -> int:
        return len(self.lengths)

    def indices(self, split: str) -> np.ndarray:
        if split not in SPLITS:
            raise ValueError(f"split must be one of {SPLITS}, got {split!r}")
        return np.flatnonzero(self.split == split)

    def row(self, i: int) -> SentenceRow:
        return self.rows[int(self.sentence_index[i])]

    def batch(self, idx, noise: float = 0.0, generator: torch.Generator | None = None) -> dict[str, torch.Tensor]:
        """Teacher-forcing batch for examples ``idx``, cropped to their longest sequence (CPU tensors).

        Returns tensors: tokens (B, S, 384), token_mask (B, S) bool, attributes (B, 9), inputs (B, T, J, 4) (the rest
        pose then frames 0..T-2, plus Gaussian ``noise`` before normalising), targets (B, T, J, 4), positions (B, T),
        progress (B, T, 2), mask (B, T) bool, offsets (B, J, 3), rest (B, J, 4).
        """
        return self.on_device(torch.device("cpu")).batch(idx, noise, generator)

    def on_device(self, device: torch.device | str) -> DeviceCorpus:
        """The arrays the training batches are cut from, as tensors placed once on ``device``."""
        return DeviceCorpus(self, torch.device(device))


def with_emotions(data: GestureDataset, idx, emotions) -> GestureDataset:
    """Each example of ``idx`` (its sentence, task, body and handedness) said with each of ``emotions``, example
    by example (len(idx) x len(emotions) entries, the emotions varying fastest), as a :class:`GestureDataset` to
    decode from: attributes carry the emotion's VAD (:func:`nrc_vad`), ``emotion`` names it; the rotations are the
    example's own, not a gesture of the new emotion, and every entry is in the "test" split."""
    idx = np.asarray(idx)
    emotions = tuple(emotions)
    src = np.repeat(idx, len(emotions))
    emo = np.array(emotions * len(idx))
    vad = np.array([nrc_vad(e) for e in emo], dtype=np.float32).reshape(len(src), 3)
    attrs = np.stack([attribute_vector(data.row(i).task, v, str(data.gender[i]), str(data.handedness[i]))
                      for i, v in zip(src, vad)]).astype(np.float32).reshape(len(src), -1)
    return GestureDataset(tokens=data.tokens[src], token_lengths=data.token_lengths[src],
                          rotations=data.rotations[src], lengths=data.lengths[src], attributes=attrs,
                          offsets=data.offsets[src], rest=data.rest[src], root=data.root[src], vad=vad,
                          sentence_index=data.sentence_index[src], split=np.array(["test"] * len(src)),
                          gender=data.gender[src], handedness=data.handedness[src], rows=data.rows, fps=data.fps,
                          emotion=emo)


class DeviceCorpus:
    """A :class:`GestureDataset`'s training arrays as tensors on one device, so batches are cut there.

    Moving the whole synthetic corpus (660 x 75 x 23 x 4 rotations, about 18 MB) to the GPU once keeps it busy:
    a batch is a few index operations on the device, with no host-to-device copy. Random numbers (input noise) are
    drawn from a CPU ``torch.Generator`` and then moved, so the same seed gives the same batches on every device.
    """

    def __init__(self, data: GestureDataset, device: torch.device):
        self.device, self.fps = device, data.fps
        self.lengths_np, self.token_lengths_np = data.lengths, data.token_lengths

        def put(a):
            return torch.from_numpy(np.ascontiguousarray(a)).to(device)

        self.tokens, self.token_lengths = put(data.tokens), put(data.token_lengths)
        self.rotations, self.lengths = put(data.rotations), put(data.lengths)
        self.attributes, self.offsets, self.rest = put(data.attributes), put(data.offsets), put(data.rest)

    def batch(self, idx, noise: float = 0.0, generator: torch.Generator | None = None) -> dict[str, torch.Tensor]:
        """As :meth:`GestureDataset.batch`, with every tensor on :attr:`device`."""
        idx_np = np.asarray(idx)
        T = int(self.lengths_np[idx_np].max())
        S = int(self.token_lengths_np[idx_np].max())
        idx_t = torch.as_tensor(idx_np, dtype=torch.long).to(self.device)
        targets = self.rotations[idx_t, :T]
        rest = self.rest[idx_t]
        inputs = torch.cat((rest[:, None], targets[:, :-1]), dim=1)
        if noise > 0:
            inputs = inputs + (noise * torch.randn(inputs.shape, generator=generator)).to(self.device)
            inputs = inputs / inputs.norm(dim=-1, keepdim=True)
        lengths = self.lengths[idx_t]
        positions = torch.arange(T, device=self.device)[None].expand(len(idx_np), T)
        return {
            "tokens": self.tokens[idx_t, :S],
            "token_mask": torch.arange(S, device=self.device)[None] < self.token_lengths[idx_t][:, None],
            "attributes": self.attributes[idx_t],
            "inputs": inputs,
            "targets": targets,
            "positions": positions,
            "progress": progress_features(positions, lengths, self.fps),
            "mask": positions < lengths[:, None],
            "offsets": self.offsets[idx_t],
            "rest": rest,
        }


def progress_features(frames: torch.Tensor, lengths: torch.Tensor, fps: float) -> torch.Tensor:
    """Where frames (B, T) sit in gestures of ``lengths`` (B,) frames -> (B, T, 2): fraction done, seconds left / 10."""
    last = (lengths[:, None] - 1).clamp_min(1).to(torch.float32)
    t = frames.to(torch.float32)
    return torch.stack(((t / last).clamp(0, 1), ((last - t).clamp_min(0) / fps) / 10.0), dim=-1)


def _make_pairs(rows: list[SentenceRow], variants: int, counterfactual: int, seed: int, fps: float) -> dict:
    """The procedural gestures of every sentence: ``variants`` with the sentence's own emotion, then
    ``counterfactual`` with another emotion drawn uniformly from the rest. Returns arrays sentence_index (N,),
    emotion, gender, handedness (N,) str, lengths (N,) and rotations (N, T_max, 23, 4) float32 (padded with the
    last frame)."""
    rng = np.random.default_rng(seed)
    motions, sentence_index, emotion, gender, hand = [], [], [], [], []
    emotions = tuple(GESTURE_VAD)
    for i, row in enumerate(rows):
        others = [e for e in emotions if e != row.emotion]
        for k in range(variants + counterfactual):
            emo = row.emotion if k < variants else others[int(rng.integers(len(others)))]
            g = config.GENDERS[int(rng.integers(2))]
            h = config.HANDEDNESS[int(rng.integers(2))] if k % 2 == 0 else ("left" if hand[-1] == "right"
                                                                             else "right")
            m = procedural_gesture(row, g, h, seed=seed * 100_003 + i * (variants + counterfactual) + k, fps=fps,
                                   emotion=emo)
            motions.append(np_qfix(np_qnormalize(m.rotations)).astype(np.float32))
            sentence_index.append(i)
            emotion.append(emo)
            gender.append(g)
            hand.append(h)
    lengths = np.array([len(m) for m in motions], dtype=np.int64)
    rotations = np.zeros((len(motions), int(lengths.max()), 23, 4), dtype=np.float32)
    for n, m in enumerate(motions):
        rotations[n, : len(m)] = m
        rotations[n, len(m):] = m[-1]
    return {"sentence_index": np.array(sentence_index), "emotion": np.array(emotion), "gender": np.array(gender),
            "handedness": np.array(hand), "lengths": lengths, "rotations": rotations}


def build_dataset(variants: int = 2, seed: int = 0, fps: float = config.TRAIN_FPS,
                  sentences_csv: str | Path = config.SENTENCES_CSV, cache_dir: str | Path | None = None,
                  rows: list[SentenceRow] | None = None, counterfactual: int = 1, augment: int = 0) -> GestureDataset:
    """Pair every sentence with ``variants`` procedural gestures of its own emotion and ``counterfactual`` of
    another emotion (random gender and handedness per gesture).

    The corpus sentences are written for one emotion each, so with own-emotion gestures only the wording and the
    emotion attributes always agree and the network can read the style off the words; the counterfactual gestures
    (the same sentence performed with another emotion) make the attributes carry it, which is what generation
    with a chosen emotion needs. Token vectors are cached in ``cache_dir/sentence_tokens.npz``, the
    paired gestures in a second npz keyed by the corpus content and the arguments, so a second call is fast.

    ``augment`` = N > 0 adds N phrase-recombination sentences (:func:`augment_rows`, seeded by ``seed``) to the
    training split, each paired with one procedural gesture of its drawn emotion (the emotions are already
    spread over the 11, so no counterfactual is needed); the split of ``rows`` is computed first and is the same
    as with ``augment=0``, so the validation and test examples do not change. Their token vectors and gestures
    are cached in files of their own (``sentence_tokens_aug.npz``, ``gesture_pairs_aug_<key>.npz``, the key from
    the new sentences, so from N, the seed and the corpus); ``augment=0`` reads and writes exactly the files it
    did before.
    """
    if isinstance(augment, bool) or not isinstance(augment, (int, np.integer)) or augment < 0:
        raise ValueError(f"augment must be a whole number >= 0 of extra training sentences, got {augment!r}")
    cache_dir = Path(cache_dir) if cache_dir is not None else config.DEFAULT_VAR_DIR
    rows = rows if rows is not None else load_sentences(sentences_csv)
    split = split_sentences(rows, seed)
    encodings = cached_encodings([r.sentence for r in rows], cache_dir / "sentence_tokens.npz")

    pairs = _cached_pairs(cache_dir, "gesture_pairs", rows, f"|{variants}|{counterfactual}|{seed}|{fps}",
                          lambda: _make_pairs(rows, variants, counterfactual, seed, fps))
    if augment:
        extra = augment_rows(rows, split, int(augment), seed)
        encodings = encodings + cached_encodings([r.sentence for r in extra], cache_dir / "sentence_tokens_aug.npz")
        aug_pairs = _cached_pairs(cache_dir, "gesture_pairs_aug", extra, f"|{seed}|{fps}",
                                  lambda: _make_pairs(extra, 1, 0, seed + 7919, fps))
        pairs = _concat_pairs(pairs, aug_pairs, offset=len(rows))
        split = {**split, **{r.sentence_id: "train" for r in extra}}
        rows = list(rows) + extra
    return assemble_dataset(pairs, rows, encodings, split, fps)


def _cached_pairs(cache_dir: Path, prefix: str, rows: list[SentenceRow], options: str, make) -> dict:
    """The :func:`_make_pairs` arrays for ``rows``: read from ``cache_dir/<prefix>_<key>.npz`` (the key hashes the
    rows, ``options`` and the generator's source) or made by ``make()`` and written there."""
    src = json.dumps([[r.sentence_id, r.emotion, r.task, r.sentence] for r in rows]) + options
    key = hashlib.sha1((src + config.generator_fingerprint()).encode()).hexdigest()[:12]
    path = cache_dir / f"{prefix}_{key}.npz"
    if path.is_file():
        with np.load(path, allow_pickle=False) as data:
            return {k: data[k] for k in data.files}
    pairs = make()
    path.parent.mkdir(parents=True, exist_ok=True)
    np.savez_compressed(path, **pairs)
    return pairs


def _concat_pairs(a: dict, b: dict, offset: int) -> dict:
    """The arrays of two :func:`_make_pairs` results as one; ``b``'s sentence indices are shifted by ``offset``
    and the shorter rotations are padded with their last frame, as :func:`_make_pairs` pads."""
    T = max(a["rotations"].shape[1], b["rotations"].shape[1])

    def pad(r):
        return np.concatenate([r, np.repeat(r[:, -1:], T - r.shape[1], axis=1)], axis=1) if r.shape[1] < T else r

    out = {k: np.concatenate([a[k], b[k]]) for k in ("emotion", "gender", "handedness", "lengths")}
    out["sentence_index"] = np.concatenate([a["sentence_index"], b["sentence_index"] + offset])
    out["rotations"] = np.concatenate([pad(a["rotations"]), pad(b["rotations"])])
    return out


def assemble_dataset(pairs: dict, rows: list[SentenceRow], encodings: list[np.ndarray], split: dict[str, str],
              fps: float) -> GestureDataset:
    """A :class:`GestureDataset` from the arrays of :func:`_make_pairs` and the sentences' token vectors."""

    sentence_index, gender, hand = pairs["sentence_index"], pairs["gender"], pairs["handedness"]
    tokens_list = [encodings[i] for i in sentence_index]
    for e in tokens_list:
        assert e.shape[1] == EMBED_DIM
    tokens, token_lengths = pad_tokens(tokens_list)
    emotion = pairs["emotion"].astype(str)
    vad = np.array([nrc_vad(e) for e in emotion], dtype=np.float32)
    attributes = np.stack([attribute_vector(rows[i].task, vad[n], gender[n], hand[n])
                           for n, i in enumerate(sentence_index)])
    rest_cache = {g: rest_rotations(g) for g in config.GENDERS}
    offsets = np.stack([gesture_skeleton(build=str(g)).offsets for g in gender]).astype(np.float32)
    rest = np.stack([rest_cache[str(g)][0] for g in gender]).astype(np.float32)
    root = np.stack([rest_cache[str(g)][1] for g in gender]).astype(np.float32)
    return GestureDataset(tokens=tokens, token_lengths=token_lengths, rotations=pairs["rotations"],
                          lengths=pairs["lengths"], attributes=attributes, offsets=offsets, rest=rest, root=root,
                          vad=vad, sentence_index=np.asarray(sentence_index),
                          split=np.array([split[rows[i].sentence_id] for i in sentence_index]),
                          gender=np.asarray(gender).astype(str), handedness=np.asarray(hand).astype(str),
                          rows=rows, fps=fps, emotion=emotion)
