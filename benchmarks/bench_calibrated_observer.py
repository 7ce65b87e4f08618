"""Judges calibrated on real walks: the gait observers trained on both real corpora, their recall on held-out
real actors, and their reading of the seed000 plan's generated walks judged against that real reference.

    python -m benchmarks.bench_calibrated_observer [--weights W.pt ...] [--json OUT.json]

1. Observers (generation/quality/calibrated_observer.py): acted-label and perceived-label variants, fitted on
   Bandai dataset-1 training takes + the BML training and validation actors; the Bandai-only real-capture observer
   of the gate until now (generation/quality/real_observer.py) as the baseline.
2. Held-out real actors: the 6 BML test actors (24 walks; never in training), per class recall (acted labels for
   the acted variant and the baseline, perceived labels for the perceived variant), and the Bandai test takes.
   Also a steadier estimate: 5-fold cross-validation by actor over all 30 BML actors (every actor read once by an
   observer that never saw it; Bandai training takes in every fold).
3. Generated walks: the seed000 plan's gait_net clips (as plan_qa makes them, not rendered) for each weights file:
   per emotion, the share of its pure clips and mixtures with a dominant share >= 0.8 read as intended, beside the
   held-out recall ("read as intended at least as often as held-out real actors' walks of that emotion"), the
   share read as neutral, transitions read at their ends (first and last 4 s), and the mixture response
   (perceived share vs intended share, emotion mixed with neutral) with whether it is monotone.
Real capture: Bandai Namco Research Motion Dataset (Kobayashi et al. 2023, CC BY-NC 4.0); BML walks (Ma, Paterson &
Pollick 2006) with Emotion-Gait labels (STEP, Bhattacharya et al. AAAI 2020), research use.
"""
from __future__ import annotations

import argparse
import datetime
import json
import os
import time
from pathlib import Path

import numpy as np

from benchmarks.bench_record import one_thread
from generation.mocap.real_corpus import RealCorpora, load_real_corpus
from generation.quality import calibrated_observer as co
from generation.quality import real_observer as ro
from protocol.vocabulary import CAPTURE_GAIT_EMOTIONS, GAIT_EMOTIONS

ROOT = Path(__file__).resolve().parents[1]


def confusion(obs, clips, labels: str) -> dict:
    cm = np.zeros((4, 4), int)
    for c in clips:
        e = co.clip_label(c, labels)
        if e is not None:
            cm[GAIT_EMOTIONS.index(e), int(obs.proba(c.motion).argmax())] += 1
    return {"confusion": cm.tolist(), "n": {e: int(cm[i].sum()) for i, e in enumerate(GAIT_EMOTIONS)},
            "recall": {e: (round(float(cm[i, i] / cm[i].sum()), 3) if cm[i].sum() else None)
                       for i, e in enumerate(GAIT_EMOTIONS)},
            "accuracy": round(float(np.trace(cm) / max(cm.sum(), 1)), 3)}


def cross_validated(bandai_train, bml_all, labels: str, folds: int = 5) -> dict:
    """Every BML actor read by an observer fitted on the other folds' actors + the Bandai training takes."""
    actors = sorted({c.motion.metadata["performer"] for c in bml_all})
    rng = np.random.default_rng(0)
    order = list(rng.permutation(actors))
    cm = np.zeros((4, 4), int)
    for k in range(folds):
        out = set(order[k::folds])
        train = bandai_train + [c for c in bml_all if c.motion.metadata["performer"] not in out]
        held = [c for c in bml_all if c.motion.metadata["performer"] in out]
        obs = co.CalibratedGaitObserver(train, held, labels)
        cm += obs.heldout_confusion
    return {"folds": folds, "confusion": cm.tolist(),
            "recall": {e: round(float(cm[i, i] / max(cm[i].sum(), 1)), 3) for i, e in enumerate(GAIT_EMOTIONS)},
            "n": {e: int(cm[i].sum()) for i, e in enumerate(GAIT_EMOTIONS)},
            "accuracy": round(float(np.trace(cm) / cm.sum()), 3)}


def plan_judgement(observers: dict, rows: list[dict], reference: dict) -> dict:
    """Per observer: pure + dominant >= 0.8 clips per emotion read as intended / as neutral, against the held-out
    recall; transitions' ends."""
    from benchmarks.bench_gait_real import plan_readings

    out = {}
    parts = plan_readings(rows)
    for name, obs in observers.items():
        per = {}
        for e in GAIT_EMOTIONS:
            sel = [r for r in rows if len(r["vectors"]) == 1 and max(r["vectors"][0]) >= 0.8
                   and GAIT_EMOTIONS[int(np.argmax(r["vectors"][0]))] == e]
            reads = [GAIT_EMOTIONS[int(obs.proba(r["motion"]).argmax())] for r in sel]
            per[e] = {"n": len(sel), "read_as_intended": (round(float(np.mean([x == e for x in reads])), 3)
                                                         if reads else None),
                      "read_as_neutral": round(float(np.mean([x == "neutral" for x in reads])), 3) if reads else None,
                      "reads": reads, "clips": [r["seed"] for r in sel]}
        rec = reference.get(name, {})
        judged = co.judge_against_reference({e: v["read_as_intended"] for e, v in per.items()}, rec)
        ends = [p for p in parts if p["kind"] == "transition" and p["asked"]]
        end_hits = [GAIT_EMOTIONS[int(obs.proba(p["motion"]).argmax())] == p["asked"] for p in ends]
        out[name] = {"per_emotion": per, "heldout_recall": rec, "at_least_real": judged,
                     "transition_ends": {"n": len(ends), "read_as_asked": round(float(np.mean(end_hits)), 3)
                                         if end_hits else None}}
    return out


def mixture(net, observers: dict) -> dict:
    from benchmarks.bench_gait_real import MIX_SHARES, mixture_response

    out = {}
    for name, obs in observers.items():
        resp = mixture_response(net, obs)
        mono = {}
        for e, per in resp.items():
            p = [per[f"{w:g}"]["p_emotion"] for w in MIX_SHARES]
            mono[e] = bool(all(b >= a - 1e-9 for a, b in zip(p, p[1:])))
        out[name] = {"response": resp, "monotone_p": mono}
    return out


def main(argv=None) -> int:
    one_thread()
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--weights", nargs="*", default=[], help="gait weights files (default: the shipped real ones)")
    ap.add_argument("--json", type=Path, default=ROOT / "docs" / "benchmarks" / "calibrated_observer.json")
    ap.add_argument("--skip-plan", action="store_true")
    ap.add_argument("--skip-mixture", action="store_true")
    a = ap.parse_args(argv)
    t0 = time.time()
    corpora = RealCorpora.from_environ(os.environ)   # $REAL_CORPUS and $BML_CORPUS, else var/mocap/
    bandai, bml = corpora.bandai, corpora.bml
    bandai_train = [c for c in load_real_corpus(bandai, skeleton="gait", split="train", contents="walk")
                    if c.dataset == ro.EMOTION_DATASET and c.style in CAPTURE_GAIT_EMOTIONS]
    bandai_test = [c for c in load_real_corpus(bandai, skeleton="gait", split="test", contents="walk")
                   if c.dataset == ro.EMOTION_DATASET and c.style in CAPTURE_GAIT_EMOTIONS]
    bml_all = load_real_corpus(bml, skeleton="gait")
    train = bandai_train + [c for c in bml_all if c.split in ("train", "val")]
    held = [c for c in bml_all if c.split == "test"]
    observers = {"acted": co.CalibratedGaitObserver(train, held, "acted", "bench"),
                 "perceived": co.CalibratedGaitObserver(train, held, "perceived", "bench"),
                 "bandai-only (before)": ro.train_real_observer(bandai)}
    label_of = {"acted": "acted", "perceived": "perceived", "bandai-only (before)": "acted"}
    res = {"date": datetime.date.today().isoformat(), "corpora": [str(bandai), str(bml)],
           "train": {k: {"bandai_takes": len(bandai_train), "bml_walks": len(train) - len(bandai_train)}
                     for k in ("acted", "perceived")},
           "heldout_actors": sorted({c.motion.metadata["performer"] for c in held}), "heldout": {}, "bandai_test": {},
           "cross_validated": {}}
    for name, obs in observers.items():
        res["heldout"][name] = confusion(obs, held, label_of[name])
        res["bandai_test"][name] = confusion(obs, bandai_test, "acted")
        if name != "perceived":
            res["heldout"][f"{name}, against perceived labels"] = confusion(obs, held, "perceived")
    for labels in ("acted", "perceived"):
        res["cross_validated"][labels] = cross_validated(bandai_train, bml_all, labels)
    print(json.dumps({k: v["recall"] for k, v in res["heldout"].items()}), flush=True)
    print(json.dumps({k: v["recall"] for k, v in res["cross_validated"].items()}), flush=True)
    reference = {name: res["heldout"][name]["recall"] for name in observers}
    if not a.skip_plan:
        from benchmarks.bench_gait_real import plan_walks
        from generation.gait.generate import load_model
        from generation.gait.weights import weights_path

        weights = a.weights or [str(weights_path("real"))]
        res["plan"] = {}
        res["mixture"] = {}
        for w in weights:
            net = load_model(w)
            same = Path(w).resolve() == weights_path("real").resolve()
            rows = plan_walks("real", None if same else net)
            res["plan"][w] = plan_judgement(observers, rows, reference)
            print(w, json.dumps({n: {e: v["read_as_intended"] for e, v in j["per_emotion"].items()}
                                 for n, j in res["plan"][w].items()}), flush=True)
            if not a.skip_mixture:
                res["mixture"][w] = mixture(net, observers)
            print(f"{w}: {time.time() - t0:.0f} s", flush=True)
    res["seconds"] = round(time.time() - t0, 1)
    a.json.parent.mkdir(parents=True, exist_ok=True)
    a.json.write_text(json.dumps(res, indent=1, default=str) + "\n")
    print(f"wrote {a.json} in {res['seconds']} s")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
