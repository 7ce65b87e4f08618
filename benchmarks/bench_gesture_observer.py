"""How well the synthetic gesture observer (generation/quality/gesture_observer.py) reads gesture emotion.

    python -m benchmarks.bench_gesture_observer [--json var/gobs/bench.json] [--skip-generated] [--skip-plan]

1. Held-out procedural gestures: the observer is fitted on the training split of the SYNTHETIC gesture corpus and
   tested on its validation and test sentences (11-class accuracy, per-class recall, confusion, accuracy of the
   arousal half (NRC-VAD arousal > 0.5) of the top label).
2. Generated gestures: one example of every test sentence said with each of the 11 emotions by the shipped gesture
   network (``decode_examples``, as in benchmarks/bench_gesture.py), read by the same observer.
3. The seed003 plan's gesture entries: every motion made as ``generate_clips`` makes it (no video, no figure-height
   projection) and checked by the quality gate (:func:`generation.pipeline.plan_qa.run`).

Everything here is synthetic: procedural gestures, a network trained on them, an observer trained on them.
"""
from __future__ import annotations

import argparse
import hashlib
import json
import os
import platform
import sys
import time
from collections import Counter
from pathlib import Path

import numpy as np

from benchmarks.bench_record import one_thread
from generation.gesture.data import GestureDataset, attribute_vector, build_dataset, nrc_vad
from generation.quality.gesture_observer import (
    GestureObserver,
    arousal_half,
    corpus_descriptors,
    motion_descriptors,
    positions_of,
)
from protocol.vocabulary import GESTURE_EMOTIONS, GESTURE_VAD

ROOT = Path(__file__).resolve().parents[1]


def scores(observer: GestureObserver, X: np.ndarray, truth) -> dict:
    """Accuracy, arousal-half accuracy, per-class recall, confusion counts (truth -> read) and top-p statistics of
    the observer on descriptors ``X`` (N, 32) with intended emotions ``truth`` (N,)."""
    truth = np.asarray(truth).astype(str)
    p = observer.proba_features(X)
    read = np.array([GESTURE_EMOTIONS[k] for k in p.argmax(1)])
    top_p = p.max(1)
    right = read == truth
    half = np.array([arousal_half(a) == arousal_half(b) for a, b in zip(read, truth)])
    recall = {e: (float(right[truth == e].mean()) if (truth == e).any() else None) for e in GESTURE_EMOTIONS}
    confusion = {e: dict(Counter(read[truth == e])) for e in GESTURE_EMOTIONS if (truth == e).any()}
    wrong = ~right
    return {"n": int(len(truth)), "accuracy": float(right.mean()), "arousal_half_accuracy": float(half.mean()),
            "recall": recall, "confusion": confusion, "top_p_median_right": _median(top_p[right]),
            "top_p_median_wrong": _median(top_p[wrong]), "wrong_other_half": int((wrong & ~half).sum()),
            "wrong_same_half": int((wrong & half).sum()), "rules": flag_rules(p, truth)}


def flag_rules(p: np.ndarray, truth: np.ndarray) -> dict:
    """Candidate gesture flag rules on readings ``p`` (N, 11) of clips with intended emotions ``truth`` (N,):
    the share of these honest clips each flags, and the share of wrongly labelled clips it catches (every clip
    paired with each of the 10 other emotions as if that were intended; "far" = NRC arousal differs by >= 0.3,
    "near" = less).

    - ``top label p>=t``: the top label differs from the intended one and has p >= t;
    - ``other half p>=t``: the probability summed over the other arousal half (> 0.5 / <= 0.5) is >= t;
    - ``arousal gap>=g``: |observed arousal (probability-weighted NRC arousal) - intended arousal| >= g (chosen).
    """
    A = np.array([GESTURE_VAD[e][1] for e in GESTURE_EMOTIONS])
    high = A > 0.5
    top = p.argmax(1)
    top_p = p.max(1)
    p_high = p[:, high].sum(1)
    observed_arousal = p @ A
    k_true = np.array([GESTURE_EMOTIONS.index(e) for e in truth])
    claims = [(n, j) for n in range(len(truth)) for j in range(len(A)) if j != k_true[n]]
    n_idx = np.array([n for n, _ in claims])
    j_idx = np.array([j for _, j in claims])
    far = np.abs(A[j_idx] - A[k_true[n_idx]]) >= 0.3

    def rule(k, n, t):  # flag when clip n is said to show emotion k
        name, value = t
        if name == "top":
            return (top[n] != k) & (top_p[n] >= value)
        if name == "half":
            return np.where(high[k], 1 - p_high[n], p_high[n]) >= value
        return np.abs(observed_arousal[n] - A[k]) >= value

    out = {}
    for label, t in ([(f"top label p>={v}", ("top", v)) for v in (0.8, 0.9)]
                     + [(f"other half p>={v}", ("half", v)) for v in (0.8, 0.9)]
                     + [(f"arousal gap>={v}", ("gap", v)) for v in (0.2, 0.25, 0.3, 0.35)]):
        honest = rule(k_true, np.arange(len(truth)), t)
        swapped = rule(j_idx, n_idx, t)
        out[label] = {"honest_flagged": float(honest.mean()), "far_caught": float(swapped[far].mean()),
                      "near_caught": float(swapped[~far].mean())}
    return out


def _median(x) -> float | None:
    return float(np.median(x)) if len(x) else None


def generated_descriptors(data: GestureDataset, weights: Path) -> tuple[np.ndarray, np.ndarray]:
    """Descriptors (N, 32) and intended emotions (N,) of one example per test sentence said with each of the 11
    emotions by the network ``weights`` (its own gender, handedness and task)."""
    from generation.gesture.generate import decode_examples, load_model

    net = load_model(weights)
    test = data.indices("test")
    seen, firsts = set(), []
    for i in test:
        if int(data.sentence_index[i]) not in seen:
            seen.add(int(data.sentence_index[i]))
            firsts.append(i)
    rows = [(i, emo, nrc_vad(emo)) for i in firsts for emo in GESTURE_EMOTIONS]
    src = np.array([i for i, _, _ in rows])
    attrs = np.stack([attribute_vector(data.row(i).task, vad, str(data.gender[i]), str(data.handedness[i]))
                      for i, _, vad in rows]).astype(np.float32)
    fake = GestureDataset(tokens=data.tokens[src], token_lengths=data.token_lengths[src], rotations=data.rotations[src],
                          lengths=data.lengths[src], attributes=attrs, offsets=data.offsets[src], rest=data.rest[src],
                          root=data.root[src], vad=np.array([v for _, _, v in rows], dtype=np.float32),
                          sentence_index=data.sentence_index[src], split=np.array(["test"] * len(rows)),
                          gender=data.gender[src], handedness=data.handedness[src], rows=data.rows, fps=data.fps,
                          emotion=np.array([e for _, e, _ in rows]))
    gen = decode_examples(net, fake, np.arange(len(rows)))
    X = np.stack([motion_descriptors(positions_of(g, fake, n), data.fps)["features"] for n, g in enumerate(gen)])
    return X, fake.emotion


def plan_summary(plan: str, weights: Path) -> dict:
    """Quality gate over the plan's gesture entries without video or figure-height projection."""
    from generation.pipeline.plan_qa import run, summary_line

    rows = run(plan, modality="gesture", figure_height=False, log=lambda s: None)
    out = {"rows": rows, "summary": summary_line(r["flag"] for r in rows)}
    for gen in sorted({r["generator"] for r in rows}):
        sel = [r for r in rows if r["generator"] == gen and r.get("intended") and r.get("observed")]
        if sel:
            gaps = [abs(r["observed_arousal"] - GESTURE_VAD[r["intended"]][1]) for r in sel]
            out[gen] = {"n": len(sel), "accuracy": float(np.mean([r["observed"] == r["intended"] for r in sel])),
                        "arousal_half_accuracy": float(np.mean([arousal_half(r["observed"]) == arousal_half(
                            r["intended"]) for r in sel])),
                        "arousal_gap_median": float(np.median(gaps)), "arousal_gap_max": float(np.max(gaps)),
                        "flagged": sum(bool(r["flag"]) for r in sel),
                        "top_label_p090_would_flag": sum(r["observed"] != r["intended"] and r["observed_p"] >= 0.9
                                                         for r in sel),
                        **relabelled_caught(sel)}
    return out


def relabelled_caught(rows: list[dict]) -> dict:
    """Share of the plan's clips the gate would flag if each were labelled with each of the 10 other emotions
    (far: NRC arousal differs by >= 0.3 from the clip's real intended emotion; near: less), with the default
    ``gesture_arousal_gap``."""
    from generation.quality.checks import failed_checks

    far, near = [], []
    for r in rows:
        for e in GESTURE_EMOTIONS:
            if e != r["intended"]:
                flagged = "observer" in failed_checks(r, None, e)
                (far if abs(GESTURE_VAD[e][1] - GESTURE_VAD[r["intended"]][1]) >= 0.3 else near).append(flagged)
    return {"relabelled_far_caught": float(np.mean(far)), "relabelled_near_caught": float(np.mean(near))}


def main(argv=None) -> int:
    one_thread()
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--json", default=str(ROOT / "var" / "quality" / "gesture_observer_bench.json"))
    ap.add_argument("--weights", default=str(ROOT / "generation" / "data" / "weights" / "gesture_net_default.pt"))
    ap.add_argument("--skip-generated", action="store_true")
    ap.add_argument("--skip-plan", action="store_true")
    args = ap.parse_args(argv)
    weights = Path(args.weights)
    t0 = time.perf_counter()
    data = build_dataset()
    tr = data.indices("train")
    X_all = corpus_descriptors(data, np.arange(len(data)))
    observer = GestureObserver(X_all[tr], data.emotion[tr], data.fps)
    out = {"machine": f"{platform.node()} ({os.cpu_count()} cores), load {os.getloadavg()}",
           "date": time.strftime("%Y-%m-%d %H:%M UTC", time.gmtime()), "n_train": int(len(tr)),
           "weights_sha256": hashlib.sha256(weights.read_bytes()).hexdigest() if weights.is_file() else None}
    for split in ("train", "val", "test"):
        idx = data.indices(split)
        out[f"procedural_{split}"] = scores(observer, X_all[idx], data.emotion[idx])
    print(json.dumps({k: out[f"procedural_{k}"]["accuracy"] for k in ("train", "val", "test")}), flush=True)
    if not args.skip_generated:
        X_gen, y_gen = generated_descriptors(data, weights)
        out["generated"] = scores(observer, X_gen, y_gen)
        print("generated", out["generated"]["accuracy"], out["generated"]["arousal_half_accuracy"], flush=True)
    if not args.skip_plan:
        out["seed003"] = plan_summary("seed003", weights)
        print(out["seed003"]["summary"], flush=True)
    out["seconds"] = time.perf_counter() - t0
    Path(args.json).parent.mkdir(parents=True, exist_ok=True)
    Path(args.json).write_text(json.dumps(out, indent=1, default=float))
    print(f"wrote {args.json}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
