"""SIMULATED norming studies: answers drawn from a known per-clip perception, to check that the norms recover it.

Nothing here is data from people. Participant ids start with ``sim-``, every ``external_id`` is ``synthetic``.

Each candidate clip gets a simulated true perception: a label distribution ``p`` over its question's domain drawn
from a Dirichlet around the intended label (concentration ``concentration`` times
``(1 - noise) * intended + noise / L``), so clips differ as real stimuli do. Participants follow the cyclic norming
design of :mod:`protocol.norming` (M clips each, section by section). An answer:

- gait (emotion_choice, multi-select): a first label drawn from ``p``; with probability ``multi_select_prob`` a
  second, different label drawn from ``p`` without the first; the answer is the label(s) joined by ';';
- gesture (gesture_emotion): the intended emotion and ``n_options - 1`` others drawn uniformly are offered; the
  answer is drawn from ``p`` restricted to the offered options;
- theme clips (theme_rating): a rating 1..7 drawn from ``p`` over the seven points;
- intensity and naturalness: 1..5, uniform.

:func:`expected_shares` gives the share vector the norms should converge to (the simulated truth): for gait
``(1 - m) p + m (p + q) / 2`` with ``q_j = sum_i p_i p_j / (1 - p_i)`` (the second label's distribution); for
gesture the exact mean over every offered set (all C(L-1, n_options-1) sets enumerated); ``p`` for a scale.
"""

from __future__ import annotations

import itertools
from dataclasses import dataclass

import numpy as np
import pandas as pd

from protocol.norming import clip_order, cyclic_block
from protocol.vocabulary import (
    CLIP_COLUMNS,
    GAIT_EMOTIONS,
    PARTICIPANT_COLUMNS,
    RESPONSE_COLUMNS,
    norms_domain,
)

NORMING_QUESTION = {"gait": ("emotion_choice", "perceived"), "gesture": ("gesture_emotion", "perceived"),
                    "theme": ("theme_rating", "rating")}
"""Candidate kind -> (section_type, question) of its emotion question in a norming study."""


@dataclass(frozen=True)
class SimulatedNorming:
    """A simulated norming study's exports (DataFrames in the public formats) and its truth: ``truth`` has one row
    per clip (clip_id, section_type, question) and ``share_<label>`` columns of the expected shares."""

    responses: pd.DataFrame
    clips: pd.DataFrame
    participants: pd.DataFrame
    truth: pd.DataFrame


def candidate_kind(clip: pd.Series) -> str:
    """'theme' for an RBF clip with a theme, else the clip's modality."""
    theme = clip.get("theme")
    return "theme" if isinstance(theme, str) and theme not in ("", "neutral") else str(clip["modality"])


def _intended_index(clip: pd.Series, kind: str, domain: tuple[str, ...]) -> int | None:
    if kind == "gait":
        v = clip[list(GAIT_EMOTIONS)].to_numpy(float)
        return None if not np.isfinite(v).all() else int(np.argmax(v))
    if kind == "gesture":
        return domain.index(clip["emotion_label"]) if clip["emotion_label"] in domain else None
    return None


def true_perception(rng, clips: pd.DataFrame, concentration: float = 12.0, noise: float = 0.35) -> list[np.ndarray]:
    """One simulated label distribution per clip (in clips' order) over its question's domain."""
    out = []
    for _, clip in clips.iterrows():
        kind = candidate_kind(clip)
        domain = norms_domain(*NORMING_QUESTION[kind])
        L = len(domain)
        if kind == "theme":
            centre = np.exp(-0.5 * ((np.arange(L) - (2 + 3 * min(1.0, abs(clip["weight"] or 0.5)))) / 1.2) ** 2)
            base = centre / centre.sum()
        else:
            j = _intended_index(clip, kind, domain)
            base = np.full(L, 1.0 / L) if j is None else (1 - noise) * np.eye(L)[j] + noise / L
        out.append(rng.dirichlet(concentration * base + 1e-3))
    return out


def expected_shares(p: np.ndarray, kind: str, multi_select_prob: float, n_options: int = 4,
                    intended: int | None = None) -> np.ndarray:
    """The share vector the norms converge to for true distribution ``p`` (L,) (module docstring)."""
    if kind == "gait":
        q = np.array([sum(p[i] * p[j] / (1 - p[i]) for i in range(len(p)) if i != j and p[i] < 1)
                      for j in range(len(p))])
        return (1 - multi_select_prob) * p + multi_select_prob * (p + q) / 2
    if kind == "gesture":
        others = [j for j in range(len(p)) if j != intended]
        total = np.zeros(len(p))
        sets = list(itertools.combinations(others, n_options - 1))
        for s in sets:
            shown = [intended, *s]
            total[shown] += p[shown] / p[shown].sum()
        return total / len(sets)
    return p


def simulate_norming(clips: pd.DataFrame, n_participants: int, m: int, seed: int = 0,
                     multi_select_prob: float = 0.3, concentration: float = 12.0, noise: float = 0.35,
                     n_options: int = 4) -> SimulatedNorming:
    """A SIMULATED norming study of ``clips`` (clips.csv rows: CLIP_COLUMNS): one section per candidate kind
    present (gait, gesture, theme), each with the cyclic design of ``m`` clips per participant, and the expected
    shares. Vectorised over answers; 10,000 participants x 40 ratings take a few seconds."""
    rng = np.random.default_rng(seed)
    clips = clips.reset_index(drop=True)
    kinds = np.array([candidate_kind(c) for _, c in clips.iterrows()])
    perception = true_perception(rng, clips, concentration, noise)
    pids = np.array([f"sim-{i:06d}" for i in range(n_participants)], dtype=object)
    frames, truth_rows = [], []
    for kind, (section_type, question) in NORMING_QUESTION.items():
        rows = np.flatnonzero(kinds == kind)
        if not len(rows):
            continue
        domain = norms_domain(section_type, question)
        ids = clips.loc[rows, "clip_id"].astype(str).tolist()
        order = clip_order(ids, section_type)
        pos = {cid: rows[ids.index(cid)] for cid in order}
        blocks = np.array([[pos[order[b]] for b in cyclic_block(len(order), m, i)] for i in range(n_participants)])
        who = np.repeat(np.arange(n_participants), blocks.shape[1])
        which = blocks.ravel()
        table = np.zeros((len(clips), len(domain)))
        table[rows] = np.stack([perception[r] for r in rows])
        intended_of = np.full(len(clips), -1)
        for r in rows:
            j = _intended_index(clips.loc[r], kind, domain)
            intended_of[r] = -1 if j is None else j
        answers = _draw(rng, kind, table[which], intended_of[which], domain, multi_select_prob, n_options)
        n = len(which)
        base = {"participant_id": pids[who], "section_type": section_type,
                "clip_id": clips.loc[which, "clip_id"].to_numpy(), "response_ms": rng.integers(2500, 9000, n)}
        frames.append(pd.DataFrame({**base, "question": question, "answer": answers}))
        for extra in ("intensity", "naturalness"):
            frames.append(pd.DataFrame({**base, "question": extra, "answer": rng.integers(1, 6, n).astype(str)}))
        for r in rows:
            j = _intended_index(clips.loc[r], kind, domain)
            e = expected_shares(perception[r], kind, multi_select_prob, n_options, j)
            truth_rows.append({"clip_id": clips.loc[r, "clip_id"], "section_type": section_type, "question": question,
                               **{f"share_{lab}": v for lab, v in zip(domain, e)}})
    responses = pd.concat(frames, ignore_index=True)[list(RESPONSE_COLUMNS)]
    participants = pd.DataFrame({c: "" for c in PARTICIPANT_COLUMNS}, index=range(n_participants))
    participants["participant_id"] = pids
    participants["status"] = "completed"
    participants["external_id"] = "synthetic"
    return SimulatedNorming(responses, clips[list(CLIP_COLUMNS)], participants[list(PARTICIPANT_COLUMNS)],
                            pd.DataFrame(truth_rows))


def _draw(rng, kind: str, P: np.ndarray, intended: np.ndarray, domain, multi_select_prob: float,
          n_options: int) -> np.ndarray:
    """One answer string per row of P (A, L)."""
    A, L = P.shape
    names = np.asarray(domain, dtype=object)
    if kind == "gesture":
        keep = np.zeros((A, L), bool)
        keep[np.arange(A), intended] = True
        noise = rng.random((A, L))
        noise[np.arange(A), intended] = np.inf
        others = np.argsort(noise, axis=1)[:, :n_options - 1]
        keep[np.arange(A)[:, None], others] = True
        P = np.where(keep, P, 0)
    first = _categorical(rng, P)
    if kind != "gait":
        return names[first]
    P2 = P + 1e-12
    P2[np.arange(A), first] = 0
    second = _categorical(rng, P2)
    two = rng.random(A) < multi_select_prob
    lo, hi = np.minimum(first, second), np.maximum(first, second)
    table = np.array([[names[i] if i == j else f"{names[i]};{names[j]}" for j in range(L)] for i in range(L)],
                     dtype=object)
    return np.where(two, table[lo, hi], names[first])


def _categorical(rng, probs: np.ndarray) -> np.ndarray:
    c = np.cumsum(probs, axis=1)
    u = rng.random((probs.shape[0], 1)) * c[:, -1:]
    return np.minimum((u >= c).sum(axis=1), probs.shape[1] - 1)


__all__ = ["NORMING_QUESTION", "SimulatedNorming", "expected_shares", "simulate_norming", "true_perception"]
