"""Benchmark of the gait network on held-out REAL captured walks (docs/benchmarks/gait.md, "Trained on real capture").

Real data: the Bandai Namco Research Motion Dataset (Kobayashi et al. 2023, arXiv:2306.08861, CC BY-NC 4.0), via
the real-capture corpus (``generation.mocap.real_corpus``); only its held-out ``test`` takes are measured here.

1. Prediction error (seed 000 Table 1 layout) on windows of every held-out forward-locomotion take (both datasets):
   the first ``prefix`` network steps given, the rest predicted free-running on the true ground track; mean joint
   error over the body's bounding-box diagonal at the first predicted step, steps 2-5 and the later steps, for the
   real-trained network, the procedural-trained network and three baselines: nearest-neighbour continuation from
   the real training windows, constant velocity (each joint rotation and the root height continue at the last
   step's rate) and the last pose held. Also on the emotion takes alone (dataset 1 happy/sad/angry take 2 and
   dataset 2 normal test takes).
2. Emotion carried, read by the real-capture observer (``generation.quality.real_observer``): generated walks of the
   seed000 plan's gait_net entries, and walks generated from held-out seed walks (each held-out emotion take's
   first seconds as seed, each of the four emotions asked): recognition per class, and how often each class is read
   as neutral. Also how the reading follows the share of an emotion mixed with neutral (0 to 1, real-trained
   weights).
3. Realism (``generation.quality.realism``) per asked emotion of those generated walks, beside the real takes of
   that emotion (dataset 1 walks, both takes; dataset 2 normal walks for neutral) and the corpus's pooled range.

Usage: python -m benchmarks.bench_gait_real [--real W.pt] [--before W.pt] [--procedural W.pt] [--steps 100]
       [--skip-plan]
``--before`` measures a previous real-trained weights file in the same run (rows "real-trained (before)").
Results: docs/benchmarks/gait_real.json (``--out``) with the run's machine, date, commit, command, duration, weights
and corpus hashes; the tables are printed and, with the default ``--out``, rendered into the marked ``gait_real.*``
blocks of docs/benchmarks/gait.md (benchmarks/doc_tables.py; the narrative there is written by hand).
"""
from __future__ import annotations

import argparse
import datetime
import math
import os
import shlex
import sys
import time
from collections import defaultdict
from contextlib import contextmanager, nullcontext
from pathlib import Path

import numpy as np
import torch

from benchmarks import doc_tables
from benchmarks.bench_gait import nearest_neighbour_errors, network_errors, pose_rotation_errors, zero_velocity_errors
from benchmarks.bench_record import commit_label, machine_label
from generation.core.digest import file_sha256
from generation.core.paths import path_from_spec as make_path
from generation.core.quaternion import qmul
from generation.gait.generate import generate_gaits, load_model
from generation.gait.real_data import RealAugment, clip_sequences, stage_clips
from generation.gait.weights import weights_path
from generation.mocap.real_corpus import RealCorpora, load_real_corpus
from generation.quality.observers import OBSERVERS
from generation.quality.realism import MEASURES, realism_measures
from generation.quality.realism_ranges import load_ranges
from protocol.vocabulary import CAPTURE_GAIT_EMOTIONS, GAIT_EMOTIONS

ROOT = Path(__file__).resolve().parents[1]


# ---- 1. prediction error -------------------------------------------------------------------------
def constant_velocity_errors(test, prefix: int, horizon: int) -> dict:
    """Each joint rotation keeps turning by its last step's rotation q_{P-1} q_{P-2}^-1, the root height keeps its
    last step's rate."""
    q1, q0 = test.q[:, prefix - 1].double(), test.q[:, prefix - 2].double()
    conj = q0 * torch.tensor([1.0, -1.0, -1.0, -1.0], dtype=q0.dtype)
    dq = qmul(q1, conj)
    dq = dq * torch.sign(dq[..., :1] + 1e-12)                          # shortest arc
    angle = 2 * torch.atan2(dq[..., 1:].norm(dim=-1), dq[..., 0])    # (N, J)
    axis = dq[..., 1:] / dq[..., 1:].norm(dim=-1, keepdim=True).clamp_min(1e-12)
    qs = []
    for k in range(1, horizon + 1):
        half = 0.5 * angle * k
        qs.append(qmul(torch.cat((torch.cos(half)[..., None], torch.sin(half)[..., None] * axis), -1), q1))
    h1, h0 = test.root[:, prefix - 1, 0].double(), test.root[:, prefix - 2, 0].double()
    h = torch.stack([h1 + (h1 - h0) * k for k in range(1, horizon + 1)], 1)
    return pose_rotation_errors(torch.stack(qs, 1).float(), h.float(), test, prefix, horizon)


def prediction_table(nets: dict, train, test, prefix: int) -> dict:
    horizon = test.q.shape[1] - prefix
    out = {name: network_errors(net, test, prefix, horizon) for name, net in nets.items()}
    out["nearest neighbour (real training windows)"] = nearest_neighbour_errors(train, test, 6, prefix, horizon)
    out["constant velocity"] = constant_velocity_errors(test, prefix, horizon)
    out["last pose held"] = zero_velocity_errors(test, prefix, horizon)
    return out


# ---- 2. emotion carried ------------------------------------------------------------------------
def heldout_emotion_takes(corpus: Path, max_neutral: int = 3) -> list:
    """Held-out takes of the four emotions: dataset 1 walk take 2 (happy, sad, angry, normal where long enough) and
    the first ``max_neutral`` dataset-2 normal walk test takes."""
    clips = load_real_corpus(corpus, skeleton="gait", split="test", contents="walk",
                             styles=tuple(CAPTURE_GAIT_EMOTIONS))
    d1 = [c for c in clips if c.dataset == "bandai-namco-1"]
    d2 = [c for c in clips if c.dataset == "bandai-namco-2"][:max_neutral]
    return d1 + d2


def generated_from_seeds(net, takes: list, steps: int, seed_s: float = 1.2) -> list[dict]:
    """One walk per (held-out take, asked emotion): the take's first ``seed_s`` seconds as seed, a straight path."""
    rows, seeds, paths, emotions = [], [], [], []
    need = net.config.data.frame_step * (net.config.prefix_len - 1) + 1
    for take in takes:
        n = max(need, int(round(seed_s * take.motion.fps)))
        if take.motion.num_frames < n:
            continue
        for k, emotion in enumerate(GAIT_EMOTIONS):
            seeds.append(take.motion.slice(0, n))
            paths.append(make_path({"kind": "straight", "length_m": 30.0}))
            emotions.append(np.eye(4)[k])
            rows.append({"seed": take.name, "seed_label": take.label, "asked": emotion})
    motions = generate_gaits(seeds, paths, np.array(emotions), steps=steps, model=net)
    for r, m in zip(rows, motions):
        r["motion"] = m
    return rows


@contextmanager
def _named_weights(name: str, net):
    """While inside, the named shipped weights ``name`` are ``net`` (a LoadedGaitNet of another file) for
    everything that loads them by name (plan clips); the cached shipped network comes back afterwards."""
    from generation.gait import generate

    missing = object()
    saved = generate._DEFAULT.get(name, missing)
    generate._DEFAULT[name] = net
    try:
        yield
    finally:
        if saved is missing:
            generate._DEFAULT.pop(name, None)
        else:
            generate._DEFAULT[name] = saved


def plan_walks(weights: str, net=None, keep=None, seed_offset: int = 0) -> list[dict]:
    """The seed000 plan's gait_net clips made with the named weights (not rendered), as ``plan_qa`` makes them;
    with ``net``, that network in place of the named one; with ``keep``, only the plan entries (raw dicts) it
    accepts; with ``seed_offset``, each entry's seed moved by it (other walks of the same entries)."""
    import yaml

    from generation.plans.clipgen import make_motion
    from generation.plans.schema import plan_path, validate_plan

    plan = yaml.safe_load(plan_path("seed000").read_text())
    raw = [{**e, "weights": weights, "seed": e.get("seed", 0) + seed_offset} for e in plan["clips"]
           if e.get("generator") == "gait_net" and (keep is None or keep(e))]
    sub = validate_plan({"name": "seed000-gait", "render": plan.get("render", {}), "clips": raw})
    rows = []
    with _named_weights(weights, net) if net is not None else nullcontext():
        for entry in sub.entries:
            inp = entry.inputs
            vec = inp["emotion"] if "emotion" in inp else inp["transition"]["final"]
            rows.append({"seed": entry.id, "asked": GAIT_EMOTIONS[int(np.argmax(vec))],
                         "motion": make_motion(entry), "transition": "transition" in inp,
                         "vectors": [inp["emotion"]] if "emotion" in inp else
                         [inp["transition"]["initial"], inp["transition"]["final"]]})
    return rows


def dominant(vec) -> str | None:
    """The emotion of the largest share of an emotion vector (4,); None when the two largest shares tie."""
    v = np.asarray(vec, dtype=float)
    top = np.sort(v)[-2:]
    return None if np.isclose(top[0], top[1]) else GAIT_EMOTIONS[int(np.argmax(v))]


def clip_kind(vectors: list) -> str:
    """"transition" (two vectors), "pure" (one emotion only) or "mixture"."""
    if len(vectors) == 2:
        return "transition"
    return "pure" if np.count_nonzero(np.asarray(vectors[0], dtype=float)) == 1 else "mixture"


def plan_readings(rows: list[dict], window_s: float = 4.0) -> list[dict]:
    """The parts of the plan's clips read for what each asks, as the seed 000 study compares intended with
    perceived emotion per clip (section 6.3) and a transition's initial and final emotions separately (6.3.2):
    a pure or mixed clip whole, asked = its dominant emotion; a transition's first and last ``window_s`` seconds,
    asked = the initial / final vector's dominant emotion. A part whose vector has no single dominant emotion (a
    50/50 mixture) has ``asked`` None and is scored by whether it is read as one of its components."""
    parts = []
    for r in rows:
        m, kind = r["motion"], clip_kind(r["vectors"])
        n = min(m.num_frames, int(round(window_s * m.fps)))
        pieces = ([("whole", m, r["vectors"][0])] if kind != "transition" else
                  [(f"first {window_s:g} s", m.slice(0, n), r["vectors"][0]),
                   (f"last {window_s:g} s", m.slice(m.num_frames - n, m.num_frames), r["vectors"][1])])
        for part, motion, vec in pieces:
            parts.append({"clip": r["seed"], "kind": kind, "part": part, "asked": dominant(vec),
                          "components": [e for e, v in zip(GAIT_EMOTIONS, vec) if v > 0], "motion": motion})
    return parts


def plan_recognition(observer, rows: list[dict], window_s: float = 4.0) -> dict:
    """:func:`recognition` of :func:`plan_readings` (parts with a dominant emotion), the share read as asked per
    kind of clip, and each part's reading."""
    parts = plan_readings(rows, window_s)
    asked = [p for p in parts if p["asked"] is not None]
    out = recognition(observer, asked)
    for p in parts:
        if p["asked"] is None:
            prob = observer.proba(p["motion"])
            p["read"], p["p"] = GAIT_EMOTIONS[int(np.argmax(prob))], prob.round(3).tolist()
    by_kind = {}
    for kind in ("pure", "mixture", "transition"):
        mine = [p for p in parts if p["kind"] == kind]
        hit = [p["read"] == p["asked"] if p["asked"] else p["read"] in p["components"] for p in mine]
        by_kind[kind] = {"n": len(mine), "read_as_asked": float(np.mean(hit)) if hit else None}
    out["by_kind"] = by_kind
    out["window_s"] = window_s
    out["parts"] = [{k: v for k, v in p.items() if k != "motion"} for p in parts]
    return out


def recognition(observer, rows: list[dict]) -> dict:
    """Per asked emotion: share read as itself, share read as neutral, n; plus the confusion matrix."""
    conf = np.zeros((4, 4), dtype=int)
    for r in rows:
        p = observer.proba(r["motion"] if "motion" in r else r)
        r["read"] = GAIT_EMOTIONS[int(np.argmax(p))]
        r["p"] = p.round(3).tolist()
        conf[GAIT_EMOTIONS.index(r["asked"]), int(np.argmax(p))] += 1
    per = {}
    for k, e in enumerate(GAIT_EMOTIONS):
        n = int(conf[k].sum())
        per[e] = {"n": n, "own": conf[k, k] / n if n else None,
                  "as_neutral": conf[k, 3] / n if n else None}
    return {"per_class": per, "confusion": conf.tolist(),
            "all_ge_0.8": all(v["own"] is not None and v["own"] >= 0.8 for v in per.values()),
            "none_neutral_over_own": all(v["own"] is None or v["as_neutral"] <= v["own"] for k, v in per.items()
                                         if k != "neutral")}


MIX_SHARES = (0.0, 0.2, 0.4, 0.5, 0.6, 0.8, 1.0)
MIX_PATHS = ({"kind": "straight", "length_m": 10.0},
             {"kind": "curved", "radius_m": 2.5, "angle_deg": 300.0, "length_m": 10.0})


def mixture_response(net, observer, steps: int = 76, shares=MIX_SHARES) -> dict:
    """How much of an emotion a walk must be asked for before the observer reads it: per emotion (happy, sad,
    angry) and share w, walks asked w of the emotion and 1 - w neutral (real seeds as in plans: the dominant
    emotion's shipped take; one straight and one curved 10 m path) -> the mean observer probability of the emotion
    and of neutral, and the share of walks read as the emotion / as neutral."""
    asks = [(e, w, path) for e in GAIT_EMOTIONS[:3] for w in shares for path in MIX_PATHS]
    vecs = [np.eye(4)[GAIT_EMOTIONS.index(e)] * w + np.eye(4)[3] * (1 - w) for e, w, _ in asks]
    motions = generate_gaits([None] * len(asks), [make_path(p) for _, _, p in asks], np.array(vecs), steps=steps,
                             model=net)
    out: dict = {}
    for (emotion, w, _), m in zip(asks, motions):
        p = observer.proba(m)
        cell = out.setdefault(emotion, {}).setdefault(f"{w:g}", {"p_emotion": [], "p_neutral": [], "read": []})
        cell["p_emotion"].append(float(p[GAIT_EMOTIONS.index(emotion)]))
        cell["p_neutral"].append(float(p[3]))
        cell["read"].append(GAIT_EMOTIONS[int(np.argmax(p))])
    return {e: {w: {"n": len(c["read"]), "p_emotion": float(np.mean(c["p_emotion"])),
                    "p_neutral": float(np.mean(c["p_neutral"])),
                    "as_emotion": float(np.mean([r == e for r in c["read"]])),
                    "as_neutral": float(np.mean([r == "neutral" for r in c["read"]]))} for w, c in per.items()}
            for e, per in out.items()}


def real_take_recognition(observer, corpus: Path) -> dict:
    """Per split (test, train): :func:`recognition` of dataset 1's real happy / sad / angry / normal forward walks
    read whole: what the observer makes of the actors themselves (the reference for the generated walks; the
    observer is trained on the ``train`` split)."""
    clips = load_real_corpus(corpus, skeleton="gait", split=("test", "train"), contents="walk",
                             styles=tuple(CAPTURE_GAIT_EMOTIONS))
    out = {}
    for split in ("test", "train"):
        rows = [{"seed": c.name, "asked": c.label, "motion": c.motion} for c in clips
                if c.dataset == "bandai-namco-1" and c.split == split]
        rec = recognition(observer, rows)
        rec["parts"] = [{"clip": r["seed"], "kind": "real take", "part": "whole", "asked": r["asked"],
                         "components": [r["asked"]], "read": r["read"], "p": r["p"]} for r in rows]
        out[f"real takes, {split} split"] = rec
    return out


# ---- 3. realism --------------------------------------------------------------------------------
def real_realism(corpus: Path) -> dict:
    """Per emotion, the realism measures of the real forward walks of that style (all splits) as min / median /
    max."""
    clips = load_real_corpus(corpus, skeleton="gait", contents="walk", styles=tuple(CAPTURE_GAIT_EMOTIONS))
    out = {}
    for style, emotion in CAPTURE_GAIT_EMOTIONS.items():
        vals = [realism_measures(c.motion) for c in clips if c.style == style]
        out[emotion] = summarise(vals) | {"takes": len(vals)}
    return out


def summarise(vals: list[dict]) -> dict:
    out = {}
    for m in MEASURES:
        v = np.array([x[m] for x in vals if x.get(m) is not None], dtype=float)
        out[m] = None if not v.size else {"min": float(v.min()), "median": float(np.median(v)), "max": float(v.max())}
    return out


def generated_realism(rows: list[dict], real: dict) -> dict:
    """Per asked emotion: the measures' medians over the generated walks, and the share of walks whose value lies in
    the real takes' [min, max] of that emotion widened to the quality gate's bounds (the corpus's pooled 1st-99th
    percentiles; no lower bound for the one-sided skate, skate ratio and toe skim)."""
    thresholds = load_ranges()["thresholds"]
    by = defaultdict(list)
    for r in rows:
        by[r["asked"]].append(realism_measures(r["motion"]))
    out = {}
    for emotion, vals in by.items():
        s = summarise(vals)
        inside = {}
        for m in MEASURES:
            ref = real[emotion].get(m)
            # one-sided measures (skate, toe skim) have no lower bound: less sliding is never unrealistic
            lo = -math.inf if ref is None or f"{m}_min" not in thresholds else min(ref["min"], thresholds[f"{m}_min"])
            hi = math.inf if ref is None else max(ref["max"], thresholds.get(f"{m}_max", -math.inf))
            v = [x[m] for x in vals if x.get(m) is not None]
            inside[m] = float(np.mean([lo <= x <= hi for x in v])) if v else None
        out[emotion] = {"n": len(vals), "measures": s, "inside_share": inside}
    return out


# ---- run ---------------------------------------------------------------------------------------
def _file_record(path) -> dict:
    """{path (relative to the repository where inside it), sha256} of a file."""
    p = Path(path).resolve()
    rel = p.relative_to(ROOT) if p.is_relative_to(ROOT) else p
    return {"path": str(rel), "sha256": file_sha256(p)}


def _args(argv):
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--real", default=str(weights_path("real")))
    ap.add_argument("--before", default=None, help="a previous real-trained weights file, measured in the same run "
                    "(rows 'real-trained (before)')")
    ap.add_argument("--procedural", default=str(weights_path("procedural")))
    ap.add_argument("--steps", type=int, default=100, help="network steps of each generated walk (7.5 per second)")
    ap.add_argument("--skip-plan", action="store_true")
    ap.add_argument("--out", default=str(doc_tables.area_files("gait_real")[0]),
                    help="JSON results; the default also renders the gait_real tables of docs/benchmarks/gait.md")
    ap.add_argument("--threads", type=int, default=1)
    return ap.parse_args(argv)


def load_nets(a) -> dict:
    """Row name -> network: the real-trained weights, the previous real-trained ones (``--before``) and the
    procedural-trained ones."""
    paths = {"real-trained": a.real, "real-trained (before)": a.before, "procedural-trained": a.procedural}
    return {name: load_model(path) for name, path in paths.items() if path}


def _plan(name: str, net) -> list[dict]:
    """seed000 plan walks of the network named ``name``: the plan's named weights (procedural for the
    procedural-trained row, real otherwise), replaced by ``net`` when it is another file than the named one."""
    named = "procedural" if name == "procedural-trained" else "real"
    same = Path(net.path).resolve() == weights_path(named).resolve()
    return plan_walks(named, None if same else net)


def run(a, argv) -> dict:
    """Every measurement into one results dict (the run's record first)."""
    t0 = time.time()
    nets = load_nets(a)
    corpora = RealCorpora.from_environ(os.environ)   # $REAL_CORPUS and $BML_CORPUS, else var/mocap/
    corpus = corpora.bandai
    res = {"date": datetime.date.today().isoformat(), "commit": commit_label(),
           "command": shlex.join(["python", "-m", "benchmarks.bench_gait_real", *argv]),
           "machine": machine_label(f"{a.threads} torch thread(s)"),
           "corpus": _file_record(corpus) if corpus.is_file() else {"path": str(corpus), "sha256": None},
           "weights": {name: _file_record(net.path) for name, net in nets.items()}}
    data_cfg = nets["real-trained"].config.data
    prefix = data_cfg.prefix_len
    # nearest-neighbour library: every training take's windows as captured, a window every 16 frames
    train = clip_sequences(stage_clips("pretrain", "train", corpus), data_cfg,
                           RealAugment(mirror=False, speed_factors=(1.0,), stride_frames=16, offsets=(0,)))
    test_clips = stage_clips("pretrain", "test", corpus)
    emotion_clips = [c for c in test_clips if c.style in CAPTURE_GAIT_EMOTIONS and c.content == "walk"]
    res |= {"prefix": prefix, "horizon": data_cfg.seq_len - prefix, "prediction": {}, "recognition": {},
            "realism": {}}
    for subset, clips in ((doc_tables.GAIT_REAL_SUBSETS["all"], test_clips),
                          (doc_tables.GAIT_REAL_SUBSETS["emotion"], emotion_clips)):
        test = clip_sequences(clips, data_cfg, RealAugment.none())
        res["prediction"][subset] = {"n": len(test), "takes": len(clips),
                                     "methods": prediction_table(nets, train, test, prefix)}
        print(f"prediction {subset}: {time.time() - t0:.0f} s", flush=True)
    observer = OBSERVERS.gait("real", corpora=corpora)
    res["observer"] = observer.source
    res["real_realism"] = real_realism(corpus)
    takes = heldout_emotion_takes(corpus)
    res["seed_takes"] = [t.name for t in takes]
    res["real_take_reading"] = real_take_recognition(observer, corpus)
    res["mixture_response"] = mixture_response(nets["real-trained"], observer)
    for name, net in nets.items():
        rows = generated_from_seeds(net, takes, a.steps)
        res["recognition"][f"{name}, held-out seed walks"] = recognition(observer, rows)
        res["recognition"][f"{name}, held-out seed walks, seed of another emotion"] = recognition(
            observer, [r for r in rows if r["seed_label"] != r["asked"]])
        res["realism"][f"{name}, held-out seeds"] = generated_realism(rows, res["real_realism"])
        res.setdefault("walks", {})[name] = [{k: v for k, v in r.items() if k != "motion"} for r in rows]
        if not a.skip_plan:
            plan = _plan(name, net)
            res["recognition"][f"{name}, seed000 plan"] = recognition(observer, plan)
            res.setdefault("plan_reading", {})[name] = plan_recognition(observer, plan)
            res["realism"][f"{name}, seed000 plan"] = generated_realism(plan, res["real_realism"])
        print(f"{name}: {time.time() - t0:.0f} s", flush=True)
    res["seconds"] = time.time() - t0
    return res


def main(argv=None) -> int:
    argv = sys.argv[1:] if argv is None else list(argv)
    a = _args(argv)
    torch.set_num_threads(a.threads)
    res = run(a, argv)
    for name, lines in doc_tables.render_tables("gait_real", res).items():
        print(f"\n{name}\n" + "\n".join(lines))
    doc_tables.write_results("gait_real", a.out, res, res["seconds"])
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
