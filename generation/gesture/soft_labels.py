"""Soft emotion targets from people's ratings: each rated gesture's perceived shares as its emotion attribute.

The gesture network is conditioned on the intended emotion as a point of the NRC-VAD space, E in [0, 1]^3 (seed 003
section 3.3: a categorical term mapped through the NRC-VAD lexicon), not on a category vector. Seed 003's own study
compares intended and perceived emotion the same way: each perceived category mapped to its VAD values
(section 6.3). So the soft target of a rated gesture is its perceived shares over the 11 gesture_emotion categories
(``share_afraid .. share_surprised`` of ``clip_norms.csv``, section ``gesture_emotion``, question ``perceived``)
times their NRC-VAD values (``protocol.vocabulary.GESTURE_VAD``): the share-weighted VAD, which goes into the attribute
vector where a category's VAD would (:func:`soft_vad`).

What a training example needs besides the target:

- the motion people rated, ``MEDIA_ROOT/motions/<clip_id>.bvh`` (23-joint gesture skeleton), resampled to the
  network's rate (:data:`generation.gesture.config.TRAIN_FPS`);
- the sentence, task, body build and handedness the gesture goes with (:func:`clip_speech`). clips.csv's public
  columns do not carry them, so they come from, in this order: extra columns ``sentence, task, gender,
  handedness`` of the clip's row in clips.csv (a catalogue may carry extra columns), the clip's record
  ``MEDIA_ROOT/clip_records/<clip_id>.json`` (the inputs of its generator), and for a source gesture the sentence
  and task of the generated clip paired with it (its record's ``source_clip_id``). A rated gesture with no sentence
  (a captured take such as the Bandai Namco "bye" gestures) cannot be a text-to-gesture example: it is left out,
  named in the log and in the weights file (``skipped``).

Reading clip_norms.csv, the catalogue and the motion files is shared with the gait network's soft labels
(:mod:`generation.formats.rated_clips`); problems raise :class:`SoftLabelError` naming file, line and column.
``python -m generation.gesture.train --soft-labels clip_norms.csv`` trains on these examples (rated clips only;
``--init-from`` the shipped weights to fine-tune), and the weights file records the norms under
``corpus.soft_labels``: path, sha256, study, clips and their numbers of ratings, and the clips left out.
"""
from __future__ import annotations

import json
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from generation.core.quaternion import np_qfix, np_qnormalize
from generation.core.skeleton import gesture_skeleton
from generation.formats.rated_clips import (
    NormRow,
    SoftLabelError,
    clip_motion_path,
    default_catalogue,
    norms_record,
    read_catalogue,
    read_clip_motion,
    read_norm_rows,
    where,
)
from protocol.vocabulary import GESTURE_EMOTIONS, GESTURE_VAD

from . import config
from .data import GestureDataset, SentenceRow, attribute_vector, rest_rotations
from .text import cached_encodings, count_words, pad_tokens

__all__ = ["SPEECH_FIELDS", "SoftLabelError", "Speech", "clip_speech", "load_soft_label_dataset",
           "read_soft_labels", "soft_vad"]

SPEECH_FIELDS = ("sentence", "task", "gender", "handedness")
VAD_TABLE = np.array([GESTURE_VAD[e] for e in GESTURE_EMOTIONS], dtype=np.float64)   # (11, 3)
TARGET = "share-weighted NRC-VAD of the gesture_emotion categories"


@dataclass(frozen=True)
class Speech:
    """What a gesture goes with: the sentence said, the task (narration or conversation), build and handedness."""
    sentence: str
    task: str
    gender: str
    handedness: str


def read_soft_labels(path: str | Path, min_ratings: int = 1) -> list[NormRow]:
    """The gesture emotion rows of a clip_norms.csv with at least ``min_ratings`` ratings (shares in
    GESTURE_EMOTIONS order). Raises SoftLabelError."""
    return read_norm_rows(path, "gesture", "gesture_emotion", GESTURE_EMOTIONS, min_ratings=min_ratings)


def soft_vad(shares) -> np.ndarray:
    """Perceived shares (..., 11) in GESTURE_EMOTIONS order -> the share-weighted NRC-VAD (..., 3), each in 0..1."""
    return np.asarray(shares, dtype=np.float64) @ VAD_TABLE


def _record(records_dir: Path | None, clip_id: str) -> dict:
    path = None if records_dir is None else records_dir / f"{clip_id}.json"
    if path is None or not path.is_file():
        return {}
    try:
        return json.loads(path.read_text(encoding="utf-8"))
    except (OSError, ValueError) as exc:
        raise SoftLabelError(f"{path}: cannot read the clip record ({exc})") from None


def _inputs(record: dict) -> dict:
    meta = record.get("metadata") or {}
    return {**(meta.get("motion") or {}), **(meta.get("inputs") or {})}


def paired_generated(records_dir: Path | None) -> dict[str, dict]:
    """source clip id -> the record of the generated clip paired with it (``source_clip_id``), from every record."""
    out: dict[str, dict] = {}
    for path in sorted(records_dir.glob("*.json")) if records_dir is not None and records_dir.is_dir() else ():
        try:
            rec = json.loads(path.read_text(encoding="utf-8"))
        except (OSError, ValueError):
            continue
        if rec.get("source_clip_id"):
            out.setdefault(str(rec["source_clip_id"]), rec)
    return out


def clip_speech(clip_id: str, catalogue_row: dict | None, records_dir: Path | None,
                paired: dict[str, dict]) -> tuple[Speech | None, str]:
    """The :class:`Speech` of a rated gesture and where it came from, or (None, why not). The clip's catalogue row's
    extra columns win over its record's generator inputs; a source clip's missing sentence and task come from the
    generated clip paired with it."""
    fields = {k: str(v).strip() for k, v in _inputs(_record(records_dir, clip_id)).items()
              if k in SPEECH_FIELDS and v not in (None, "")}
    found = "clip record" if fields else ""
    partner = paired.get(clip_id)
    if partner is not None and "sentence" not in fields:
        inputs = _inputs(partner)
        fields.update({k: str(inputs[k]).strip() for k in ("sentence", "task") if inputs.get(k)})
        found = f"clip record of the generated clip {partner.get('clip_id', '?')} paired with it"
    extra = {k: (catalogue_row or {}).get(k) or "" for k in SPEECH_FIELDS}
    if any(v.strip() for v in extra.values()):
        fields.update({k: v.strip() for k, v in extra.items() if v.strip()})
        found = "clips.csv columns"
    missing = [k for k in SPEECH_FIELDS if not fields.get(k)]
    if missing:
        return None, (f"no {', '.join(missing)} (neither clips.csv columns {', '.join(SPEECH_FIELDS)} nor its clip "
                      f"record name them)")
    return Speech(fields["sentence"], fields["task"], fields["gender"], fields["handedness"]), found


def _check_speech(speech: Speech, row: NormRow, source: str) -> None:
    for name, value, allowed in (("task", speech.task, config.TASKS), ("gender", speech.gender, config.GENDERS),
                                 ("handedness", speech.handedness, config.HANDEDNESS)):
        if value not in allowed:
            raise SoftLabelError(f"{where(source, row)}: its {name} {value!r} is not one of {', '.join(allowed)}")
    if count_words(speech.sentence) == 0:
        raise SoftLabelError(f"{where(source, row)}: its sentence {speech.sentence!r} has no words")


def load_soft_label_dataset(norms_path: str | Path, motions_dir: str | Path, study: str | None = None,
                            min_ratings: int = 1, catalogue: str | Path | None = None,
                            records_dir: str | Path | None = None, cache_dir: str | Path | None = None,
                            max_frames: int = 512, log=print) -> tuple[GestureDataset, dict]:
    """A :class:`GestureDataset` of every rated gesture that has a sentence (all in the "train" split; attribute
    E = :func:`soft_vad` of its shares; ``emotion`` its most chosen category) and the record of the norms for the
    weights file: ``{path, sha256, study, n_clips, n_ratings, clips, target, skipped: {clip_id: why}}``.

    ``catalogue`` defaults to ``clips.csv`` beside the motions folder and ``records_dir`` to ``clip_records``
    beside it (``MEDIA_ROOT``'s own layout); token vectors are cached in ``cache_dir`` (default
    :data:`generation.gesture.config.DEFAULT_VAR_DIR`). Raises SoftLabelError naming file, line and column for an
    unknown clip, a missing or foreign motion, a gesture longer than ``max_frames`` at the network's rate, or no
    usable gesture at all."""
    norms_path, motions_dir = Path(norms_path), Path(motions_dir)
    source = norms_path.name
    rows = read_soft_labels(norms_path, min_ratings)
    catalogue_path = Path(catalogue) if catalogue is not None else default_catalogue(motions_dir)
    clips = read_catalogue(catalogue_path)
    records = Path(records_dir) if records_dir is not None else motions_dir.parent / "clip_records"
    paired = paired_generated(records)
    used, speeches, motions, skipped = [], [], [], {}
    for row in rows:
        if clips is not None and row.clip_id not in clips:   # unknown: said so before anything else
            clip_motion_path(row, motions_dir, clips, source, str(catalogue_path))
        speech, found = clip_speech(row.clip_id, (clips or {}).get(row.clip_id), records, paired)
        if speech is None:
            skipped[row.clip_id] = found
            log(f"{where(source, row)}: left out, {found}")
            continue
        _check_speech(speech, row, source)
        motion = read_clip_motion(row, motions_dir, gesture_skeleton(build=speech.gender), clips, source,
                                  str(catalogue_path)).resample(config.TRAIN_FPS)
        if motion.num_frames > max_frames:
            raise SoftLabelError(f"{where(source, row)}: its motion is {motion.num_frames} frames at "
                                 f"{config.TRAIN_FPS:g} fps, the network takes at most {max_frames}")
        used.append(row)
        speeches.append(speech)
        motions.append(motion)
    if not used:
        raise SoftLabelError(f"{source}: none of its {len(rows)} rated gesture(s) has a sentence to train on "
                             f"({'; '.join(f'{k}: {v}' for k, v in skipped.items())})")
    data = _dataset(used, speeches, motions, Path(cache_dir) if cache_dir is not None else config.DEFAULT_VAR_DIR)
    norms = norms_record(norms_path, used, study, target=TARGET, skipped=skipped)
    return data, norms


def _dataset(rows: list[NormRow], speeches: list[Speech], motions: list, cache_dir: Path) -> GestureDataset:
    """The training arrays of rated gestures (shapes as :class:`GestureDataset` documents)."""
    lengths = np.array([m.num_frames for m in motions], dtype=np.int64)
    rotations = np.zeros((len(motions), int(lengths.max()), len(motions[0].skeleton.joints), 4), dtype=np.float32)
    for n, m in enumerate(motions):
        rot = np_qfix(np_qnormalize(m.rotations)).astype(np.float32)
        rotations[n, :len(rot)] = rot
        rotations[n, len(rot):] = rot[-1]
    vad = soft_vad(np.stack([r.shares for r in rows])).astype(np.float32)
    emotion = np.array([GESTURE_EMOTIONS[int(np.argmax(r.shares))] for r in rows])
    rest = {g: rest_rotations(g) for g in {s.gender for s in speeches}}
    tokens, token_lengths = pad_tokens(cached_encodings([s.sentence for s in speeches],
                                                        cache_dir / "sentence_tokens.npz"))
    return GestureDataset(
        tokens=tokens, token_lengths=token_lengths, rotations=rotations, lengths=lengths,
        attributes=np.stack([attribute_vector(s.task, v, s.gender, s.handedness) for s, v in zip(speeches, vad)]),
        offsets=np.stack([m.skeleton.offsets for m in motions]).astype(np.float32),
        rest=np.stack([rest[s.gender][0] for s in speeches]).astype(np.float32),
        root=np.stack([rest[s.gender][1] for s in speeches]).astype(np.float32), vad=vad,
        sentence_index=np.arange(len(rows)), split=np.array(["train"] * len(rows)),
        gender=np.array([s.gender for s in speeches]), handedness=np.array([s.handedness for s in speeches]),
        rows=[SentenceRow(r.clip_id, e, s.task, s.sentence) for r, e, s in zip(rows, emotion, speeches)],
        fps=config.TRAIN_FPS, emotion=emotion)
