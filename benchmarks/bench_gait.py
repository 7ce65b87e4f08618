"""Benchmarks of the seed 000 gait network (docs/benchmarks/gait.md).

Measures, on the held-out test split of the synthetic gait corpus:
1. prediction error (seed 000 Table 1 layout): first 18 of 60 steps given, 42 predicted on the ground-truth
   trajectory; mean joint position error relative to the body's bounding-box diagonal and mean joint rotation
   error, for the network, its ablations (no affective inputs/loss = QuaterNet-like; no root loss) and two
   trivial baselines (last pose held; nearest neighbour continuation from the training split);
2. emotion expressiveness: a synthetic observer (logistic regression on the 18 affective features averaged
   over time, trained on the corpus training split) classifies 200-step generated gaits: own emotion, other
   (unseen, fixed) mixtures, transitions;
3. trajectory following on unseen paths, with and without the root loss;
4. long horizon (400 steps): root speed, pose variance and path distance per window; foot skate;
5. speed in ms per agent per step / per 30 fps frame for 1 and 10 agents;
6. the contact sheet docs/img/gait_contact_sheet.png and docs/img/gait_trajectories.png.

Usage: python -m benchmarks.bench_gait [--full W.pt] [--no-affect W.pt] [--no-root W.pt] [--quick]
Results go to docs/benchmarks/gait.json (``--out``); the tables are printed and rendered into the marked blocks of
docs/benchmarks/gait.md (benchmarks/doc_tables.py; the narrative there is written by hand).
"""
from __future__ import annotations

import argparse
import math
import time
from pathlib import Path

import numpy as np
import torch

from benchmarks import doc_tables
from generation.core.kinematics import forward_kinematics
from generation.core.motion import Motion
from generation.core.paths import random_path, straight
from generation.core.quaternion import qangle
from generation.core.skeleton import GAIT_PARENTS
from generation.gait.data import load_corpus_sequences, world_rotations
from generation.gait.generate import distance_to_path, emotion_transition, load_model
from generation.gait.generate import generate_gaits as _generate_gaits
from generation.gait.train import DEFAULT_WEIGHTS, rollout
from generation.procedural.corpus import GaitCorpus
from generation.quality.gait_guidance import (
    HELDOUT_SEED,
    heldout_corpus,
    seed_walks,
    single_dominant,
    unseen_mixtures,
)
from generation.quality.observer import GaitObserver
from protocol.vocabulary import GAIT_EMOTIONS

PREFIX, HORIZON = 18, 42


def generate_gaits(*args, **kwargs):
    """The network's raw output (no foot clean-up): this benchmark measures the network itself; the clean-up is
    measured by bench_motion_quality.py."""
    return _generate_gaits(*args, foot_cleanup=False, **kwargs)


# ---- 1. prediction error ------------------------------------------------------------------------
def world_positions(q_heading, ref, root_xz, root_y, offsets):
    """(N, L, J, 3) world positions from heading-frame rotations and a given ground track."""
    rot = world_rotations(q_heading, ref)
    root = torch.stack((root_xz[..., 0], root_y, root_xz[..., 1]), dim=-1)
    return forward_kinematics(rot, root, offsets[:, None], GAIT_PARENTS), rot


def pose_rotation_errors(q_pred, h_pred, test, prefix: int = PREFIX, horizon: int = HORIZON) -> dict:
    """Errors over the ``horizon`` (42) predicted steps after ``prefix`` (18) given ones. q_pred (N, horizon, J, 4)
    heading frame; h_pred (N, horizon) metres. Also the error of the first predicted step and of steps 2-5."""
    sl = slice(prefix, prefix + horizon)
    ref = test.ref[:, sl]
    xz = test.root_pos[:, sl][..., [0, 2]]
    pos_p, rot_p = world_positions(q_pred, ref, xz, test.mean_height[:, None] + h_pred, test.offsets)
    pos_t, rot_t = world_positions(test.q[:, sl], ref, xz, test.root_pos[:, sl, 1], test.offsets)
    err = (pos_p - pos_t).norm(dim=-1).mean(-1)                       # (N, 42) metres
    span = pos_t.amax(-2) - pos_t.amin(-2)                             # per-frame body box
    diag = span.norm(dim=-1)                                           # (N, 42)
    clip_span = pos_t.reshape(len(pos_t), -1, 3)
    clip_diag = (clip_span.amax(1) - clip_span.amin(1)).norm(dim=-1)    # (N,) whole 42-step clip
    ang = qangle(rot_p, rot_t)                                         # (N, 42, J) radians
    return {"pose_error_body_diag": float((err / diag).mean()),
            "pose_error_clip_diag": float((err.mean(1) / clip_diag).mean()),
            "pose_error_cm": float(100 * err.mean()),
            "rotation_error_deg": float(torch.rad2deg(ang).mean()), "rotation_error_rad": float(ang.mean()),
            "rotation_error_deg_per_joint": torch.rad2deg(ang).mean((0, 1)).tolist(),
            "pose_error_body_diag_step1": float((err / diag)[:, 0].mean()),
            "pose_error_body_diag_steps2_5": float((err / diag)[:, 1:5].mean()),
            "pose_error_body_diag_later": float((err / diag)[:, 5:].mean()),
            "pose_error_first10_cm": float(100 * err[:, :10].mean()),
            "pose_error_last10_cm": float(100 * err[:, -10:].mean())}


def network_errors(net, test, prefix: int = PREFIX, horizon: int = HORIZON) -> dict:
    with torch.no_grad():
        pred = rollout(net.model, net.normalizer, test.batch(np.arange(len(test))), 0.0, prefix)
    return pose_rotation_errors(pred["q"][:, prefix - 1:], pred["h"][:, prefix - 1:], test, prefix, horizon)


def zero_velocity_errors(test, prefix: int = PREFIX, horizon: int = HORIZON) -> dict:
    q = test.q[:, prefix - 1:prefix].expand(-1, horizon, -1, -1)
    h = test.root[:, prefix - 1:prefix, 0].expand(-1, horizon)
    return pose_rotation_errors(q, h, test, prefix, horizon)


def nearest_neighbour_errors(train, test, window: int = 6, prefix: int = PREFIX, horizon: int = HORIZON) -> dict:
    """Continue each test prefix with the training sequence window whose last ``window`` poses match best."""
    T = train.q.shape[1]
    ends = list(range(window - 1, T - horizon))                        # window end index j, copy j+1..j+42
    lib = torch.stack([train.q[:, j - window + 1:j + 1].reshape(len(train), -1) for j in ends], 1)  # (M, E, D)
    lib = lib.reshape(-1, lib.shape[-1])
    qs, hs = [], []
    for i in range(len(test)):
        key = test.q[i, prefix - window:prefix].reshape(-1)
        # quaternion sign: compare absolute dot products per joint via squared distance of both signs
        d = torch.minimum(((lib - key) ** 2).sum(-1), ((lib + key) ** 2).sum(-1))
        k = int(d.argmin())
        m, e = divmod(k, len(ends))
        j = ends[e]
        qs.append(train.q[m, j + 1:j + 1 + horizon])
        hs.append(train.root[m, j + 1:j + 1 + horizon, 0])
    return pose_rotation_errors(torch.stack(qs), torch.stack(hs), test, prefix, horizon)


# ---- 2. emotion expressiveness --------------------------------------------------------------------
# The synthetic observer lives in generation.quality.observer (moved there from this file).
Observer = GaitObserver


# Seed walks (the first 18 network steps of corpus walks) and the four unseen mixtures (dominant 0.55, the rest
# 0.15 each) are the library's, so that the guidance selection and this benchmark use the same ones.
test_seeds = seed_walks
fixed_mixtures = unseen_mixtures


def accuracy_table(pred: np.ndarray, intended: np.ndarray) -> dict:
    """Overall and per-class accuracy, plus the confusion matrix (rows intended, columns predicted)."""
    out = {"overall": float((pred == intended).mean()), "n": int(len(pred)),
           "confusion": np.array([[int(((intended == i) & (pred == j)).sum()) for j in range(4)]
                                  for i in range(4)]).tolist()}
    for k, e in enumerate(GAIT_EMOTIONS):
        sel = intended == k
        out[e] = float((pred[sel] == k).mean()) if sel.any() else None
    return out


def heldout_recognition(net, observer, corpus, walks, steps) -> dict:
    """Own-emotion recognition with the walks of the second held-out corpus as seeds
    (:func:`generation.quality.gait_guidance.heldout_corpus`): every walk, the walks with one dominant label, and the
    latter's even / odd halves (the halves used for choosing and for confirming candidates)."""
    emotions = walks.emotion.numpy().astype(np.float64)
    seeds = test_seeds(corpus, walks.base_index)
    pred = observer.predict_motions(generate_gaits(seeds, [straight(60.0)] * len(seeds), emotions, steps=steps,
                                                   model=net))
    single = single_dominant(emotions)
    even = walks.base_index % 2 == 0
    out = {"all": accuracy_table(pred, emotions.argmax(1))}
    for name, sel in (("untied", single), ("untied_even", single & even), ("untied_odd", single & ~even)):
        out[name] = accuracy_table(pred[sel], emotions[sel].argmax(1))
    out["left_out_tied"] = int((~single).sum())
    itself = observer.clf.predict(observer.summarise_seq(walks.aff.numpy()))
    out["walks_themselves_untied"] = accuracy_table(itself[single], emotions[single].argmax(1))
    return out


def expressiveness(net, observer, corpus, test_rows, test_emotion, steps, rng) -> dict:
    seeds = test_seeds(corpus, test_rows)
    N = len(seeds)
    paths = [straight(60.0) for _ in range(N)]
    res = {}
    own = generate_gaits(seeds, paths, test_emotion, steps=steps, model=net)
    own_pred = observer.predict_motions(own)
    res["own_emotion"] = accuracy_table(own_pred, test_emotion.argmax(1))
    single = single_dominant(test_emotion)
    res["own_emotion_untied"] = accuracy_table(own_pred[single], test_emotion[single].argmax(1))
    res["own_emotion_untied"]["left_out_tied"] = int((~single).sum())
    # Other emotions: each seed gets a fixed mixture whose dominant emotion differs from the seed's.
    mix = fixed_mixtures()
    target = np.array([(int(e.argmax()) + 1 + int(rng.integers(3))) % 4 for e in test_emotion])
    other = generate_gaits(seeds, paths, mix[target], steps=steps, model=net)
    res["other_mixture"] = accuracy_table(observer.predict_motions(other), target)
    res["other_mixture_last_third"] = accuracy_table(
        observer.predict_motions(other, slice(-(steps * 4) // 3, None)), target)
    # Transitions: seed emotion -> a different pure emotion over the steps; classify the first and last 50 steps.
    final = np.eye(4)[target]
    sched = np.stack([emotion_transition(test_emotion[i], final[i], steps) for i in range(N)])
    trans = generate_gaits(seeds, paths, sched, steps=steps, model=net)
    res["transition_end"] = accuracy_table(observer.predict_motions(trans, slice(-200, None)), target)
    res["transition_start"] = accuracy_table(observer.predict_motions(trans, slice(0, 200)),
                                             test_emotion.argmax(1))
    rows = np.arange(N)
    res["transition_p_target"] = {
        "first_50_steps": float(observer.proba_motions(trans, slice(0, 200))[rows, target].mean()),
        "last_50_steps": float(observer.proba_motions(trans, slice(-200, None))[rows, target].mean()),
        "constant_seed_emotion_last_50": float(observer.proba_motions(own, slice(-200, None))[rows, target].mean())}
    res["_motions"] = {"own": own, "trans": trans, "other": other}
    return res


def expressiveness_procedural_seeds(net, observer, steps, per_class=10) -> dict:
    """Seeds made from the intended emotion itself (``seeds=None``:
    generation.procedural.emotion.gait_params_for_emotion), for the pure emotions and for four mixtures not in
    the corpus (dominant 0.55)."""
    out = {}
    for name, vecs in (("pure", np.eye(4)), ("unseen_mixture", fixed_mixtures())):
        emo = np.repeat(vecs, per_class, axis=0)
        ms = generate_gaits(None, [straight(60.0)] * len(emo), emo, steps=steps, model=net, rng_seed=11)
        out[name] = accuracy_table(observer.predict_motions(ms), emo.argmax(1))
    return out


# ---- 3/4. trajectories, long horizon, foot skate ---------------------------------------------------
def foot_skate_cm_s(m: Motion, height_thr: float = 0.03) -> float:
    """Mean ground-plane speed (cm/s) of heel and toe joints while within ``height_thr`` m of their lowest height."""
    P = m.positions()
    speeds = []
    for j in (3, 4, 7, 8):
        y = P[:, j, 1]
        low = (y - y.min()) < height_thr
        v = np.linalg.norm(np.diff(P[:, j][:, [0, 2]], axis=0), axis=-1) * m.fps
        both = low[1:] & low[:-1]
        speeds.append(v[both])
    s = np.concatenate(speeds)
    return float(100 * s.mean()) if s.size else float("nan")


def trajectory_following(net, seeds, emotions, paths, steps) -> dict:
    ms = generate_gaits(seeds, paths, emotions, steps=steps, model=net)
    d_all, face = [], []
    for m, p in zip(ms, paths):
        xz = m.root_positions[:, [0, 2]]
        d_all.append(distance_to_path(p, xz[::2]))
        fwd = m.positions()[:, 0]  # root
        del fwd
    d = np.concatenate(d_all)
    end = np.array([x[-1] for x in d_all])
    # facing vs travel direction (the paper's observation on the ablation: "not facing the direction of motion")
    for m in ms:
        from generation.gait.data import facing_yaw
        alpha = facing_yaw(m.rotations[::4, 0])
        dxz = np.diff(m.root_positions[::4][:, [0, 2]], axis=0)
        travel = np.arctan2(dxz[:, 0], dxz[:, 1])
        face.append(np.abs((travel - alpha[1:] + np.pi) % (2 * np.pi) - np.pi))
    return {"mean_m": float(d.mean()), "p95_m": float(np.percentile(d, 95)), "max_m": float(d.max()),
            "end_mean_m": float(end.mean()), "facing_vs_travel_deg": float(np.degrees(np.concatenate(face).mean())),
            "n": len(ms), "_motions": ms}


def long_horizon(net, seeds, emotions, steps, window=50) -> dict:
    paths = [straight(120.0) for _ in seeds]
    ms = generate_gaits(seeds, paths, emotions, steps=steps, model=net)
    rows = []
    for w0 in range(0, steps, window):
        sl = slice(w0 * 4, (w0 + window) * 4)
        sp, var, dist, h = [], [], [], []
        for m, p in zip(ms, paths):
            r = m.root_positions[sl]
            sp.append(np.linalg.norm(np.diff(r[:, [0, 2]], axis=0), axis=-1).mean() * m.fps)
            P = m.positions()[sl]
            rel = P - P[:, :1]
            var.append(1e4 * rel.var(0).sum(-1).mean())
            dist.append(distance_to_path(p, r[::4, [0, 2]]).mean())
            h.append(r[:, 1].mean())
        rows.append({"steps": f"{w0}-{w0 + window}", "root_speed_m_s": float(np.mean(sp)),
                     "pose_variance_cm2": float(np.mean(var)), "path_distance_m": float(np.mean(dist)),
                     "root_height_m": float(np.mean(h))})
    skate = [foot_skate_cm_s(m) for m in ms]
    return {"windows": rows, "foot_skate_cm_s": float(np.mean(skate))}


# ---- 5. speed ----------------------------------------------------------------------------------------
def speed(net, seed, steps=100, repeats=3) -> dict:
    out = {}
    for n in (1, 10):
        times = []
        for _ in range(repeats):
            t0 = time.perf_counter()
            ms = generate_gaits([seed] * n, [straight(40.0)] * n, np.tile([0.25, 0.25, 0.25, 0.25], (n, 1)),
                                steps=steps, model=net)
            times.append(time.perf_counter() - t0)
        t = min(times)
        frames = ms[0].num_frames
        out[f"{n}_agents"] = {"ms_per_agent_per_step": 1000 * t / (n * steps),
                              "ms_per_agent_per_frame_30fps": 1000 * t / (n * frames),
                              "ms_per_frame_all_agents_30fps": 1000 * t / frames, "steps": steps, "frames": frames}
    return out


# ---- 6. figures ----------------------------------------------------------------------------------
def side_view(ax, P, color):
    """Stick figure (J, 3) in a side view: forward (z after yaw removal) right, up."""
    for j, p in enumerate(GAIT_PARENTS):
        if p >= 0:
            ax.plot([P[p, 2], P[j, 2]], [P[p, 1], P[j, 1]], color=color, lw=1.6)
    ax.plot(P[12, 2], P[12, 1], "o", color=color, ms=4)


def body_frame(m: Motion, t: int) -> np.ndarray:
    """Positions at frame t with the root's ground point at the origin and its facing along +z."""
    from generation.gait.data import facing_yaw
    P = m.positions()[t]
    a = facing_yaw(m.rotations[t, 0])
    c, s = math.cos(-a), math.sin(-a)
    x, z = P[:, 0] - P[0, 0], P[:, 2] - P[0, 2]
    out = P.copy()
    out[:, 0], out[:, 2] = x * c + z * s, -x * s + z * c
    out[:, 1] = P[:, 1] - P[:, 1].min() + 0.0
    return out


def contact_sheet(rows: list[tuple[str, Motion]], path: Path, n_cols: int = 6):
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    colors = dict(zip(GAIT_EMOTIONS, ("#d08c00", "#3366aa", "#c0392b", "#555555")))
    fig, axes = plt.subplots(len(rows), n_cols, figsize=(1.6 * n_cols, 2.2 * len(rows)))
    for r, (label, m) in enumerate(rows):
        T = m.num_frames
        for c in range(n_cols):
            t = int((c + 0.5) * T / n_cols)
            ax = axes[r, c]
            key = label.split()[0] if label.split()[0] in colors else "neutral"
            if label.startswith("transition"):
                key = "sad" if c < n_cols // 2 else "happy"
            side_view(ax, body_frame(m, t), colors[key])
            ax.set_xlim(-0.7, 0.7)
            ax.set_ylim(-0.05, 1.95)
            ax.set_aspect("equal")
            ax.set_xticks([])
            ax.set_yticks([])
            ax.set_title(f"t={t / m.fps:.1f}s", fontsize=7)
            if c == 0:
                ax.set_ylabel(label, fontsize=8)
    fig.suptitle("Generated gaits (gait net trained on a SYNTHETIC procedural corpus), side view, facing right",
                 fontsize=8)
    fig.tight_layout()
    fig.savefig(path, dpi=110)
    plt.close(fig)


def trajectory_figure(paths, runs: dict, path: Path):
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    n = len(paths)
    fig, axes = plt.subplots(1, n, figsize=(3.0 * n, 3.6))
    for i, p in enumerate(paths):
        ax = axes[i]
        pts = p.point_at(np.linspace(0, p.length, 200))
        ax.plot(pts[:, 0], pts[:, 1], "k--", lw=1, label="desired path")
        lo, hi = np.full(2, np.inf), np.full(2, -np.inf)
        for (name, ms), col in zip(runs.items(), ("#1f77b4", "#ff7f0e", "#2ca02c", "#d62728")):
            r = ms[i].root_positions
            ax.plot(r[:, 0], r[:, 2], color=col, lw=1.0, label=name)
            lo, hi = np.minimum(lo, r[:, [0, 2]].min(0)), np.maximum(hi, r[:, [0, 2]].max(0))
        ax.set_xlim(lo[0] - 1, hi[0] + 1)
        ax.set_ylim(lo[1] - 1, hi[1] + 1)
        ax.set_aspect("equal")
        ax.set_title(p.kind, fontsize=8)
        ax.tick_params(labelsize=6)
    axes[0].legend(fontsize=6)
    fig.suptitle("Root tracks of generated gaits on unseen paths (metres, top view)", fontsize=8)
    fig.tight_layout()
    fig.savefig(path, dpi=110)
    plt.close(fig)


def _args(argv):
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--full", default=str(DEFAULT_WEIGHTS))
    ap.add_argument("--full-short", default="var/gait_runs/full12.pt", help="full model on the ablations' schedule")
    ap.add_argument("--no-affect", default="var/gait_runs/no_affect.pt")
    ap.add_argument("--no-root", default="var/gait_runs/no_root.pt")
    ap.add_argument("--corpus", default="var/corpus/gait_corpus_synthetic.npz")
    ap.add_argument("--steps", type=int, default=200)
    ap.add_argument("--quick", action="store_true", help="fewer sequences (smoke run)")
    ap.add_argument("--out", default=str(doc_tables.DOCS / "gait.json"), help="JSON results")
    return ap.parse_args(argv)


def _print_table(title: str, name: str, results: dict) -> None:
    print(f"\n## {title}")
    print("\n".join(doc_tables.render_tables("gait", results)[name]))


def _load(args) -> tuple[dict, dict]:
    """The networks that exist (by row name) and the results' model and corpus records."""
    paths = {"full": args.full, "full, 12 epochs": args.full_short, "no affective (QuaterNet-like)": args.no_affect,
             "no root loss": args.no_root}
    nets = {k: load_model(v) for k, v in paths.items() if Path(v).exists()}
    results: dict = {"models": {k: {"path": n.path, "epochs": n.info.get("epochs"),
                                    "parameters": n.model.num_parameters()} for k, n in nets.items()}}
    return nets, results


def _prediction(nets, train, test, results) -> None:
    """1. prediction error (18 steps given, 42 predicted) of the networks and two baselines."""
    table = {name: network_errors(net, test) for name, net in nets.items()}
    table["last pose held"] = zero_velocity_errors(test)
    table["nearest neighbour (train)"] = nearest_neighbour_errors(train, test)
    results["prediction"] = table
    _print_table(f"prediction (18 given, 42 predicted), test split n = {len(test)}", "gait.prediction", results)


def _expressiveness(nets, observer, corpus, test, args, results) -> dict:
    """2. the synthetic observer's reading of generated gaits; returns the full model's motions by kind."""
    gt_pred = observer.clf.predict(Observer.summarise_seq(test.aff.numpy()))
    results["observer_on_test_corpus"] = accuracy_table(gt_pred, test.emotion.numpy().argmax(1))
    test_emotion = test.emotion.numpy().astype(np.float64)
    expr, motions = {}, {}
    for name, net in nets.items():
        if name == "no root loss":
            continue
        r = expressiveness(net, observer, corpus, test.base_index, test_emotion, args.steps,
                           np.random.default_rng(3))
        motions[name] = r.pop("_motions")
        expr[name] = r
    results["expressiveness"] = expr
    results["expressiveness_procedural_seeds"] = {
        name: expressiveness_procedural_seeds(net, observer, args.steps, 4 if args.quick else 10)
        for name, net in nets.items() if name != "no root loss"}
    _print_table("synthetic observer accuracy (chance 0.25)", "gait.expressiveness", results)
    return motions


def _heldout(nets, observer, args, results) -> None:
    """Own-emotion recognition seeded by the walks of the second held-out corpus."""
    held_path = heldout_corpus(Path(__file__).resolve().parents[1])
    held_corpus, held = GaitCorpus.load(held_path), load_corpus_sequences(held_path)
    held = held.subset(np.flatnonzero(held.offset == 0)[: 40 if args.quick else None])
    results["own_emotion_heldout_corpus"] = {name: heldout_recognition(net, observer, held_corpus, held, args.steps)
                                             for name, net in nets.items() if name != "no root loss"}
    results["heldout_corpus_seed"] = HELDOUT_SEED
    _print_table(f"own emotion per class (second held-out corpus: seed {HELDOUT_SEED}, {len(held)} walks)",
                 "gait.own_emotion", results)


def _trajectory(nets, corpus, test, args, results) -> tuple[list, dict]:
    """3. distance from unseen random paths; returns the paths and each model's motions."""
    path_rng = np.random.default_rng(2026)
    n_traj = 12 if args.quick else 30
    kinds = ["straight", "curved", "sharp_turn"]
    # 50 m paths: longer than 200 steps of the fastest gaits, so the walk ends on the path itself.
    tpaths = [random_path(path_rng, 50.0, kinds[i % 3]) for i in range(n_traj)]
    rows = np.arange(n_traj) % len(test.base_index)
    tseeds = test_seeds(corpus, test.base_index[rows])
    temo = test.emotion.numpy().astype(np.float64)[rows]
    traj, traj_motions = {}, {}
    for name, net in nets.items():
        r = trajectory_following(net, tseeds, temo, tpaths, args.steps)
        traj_motions[name] = r.pop("_motions")
        traj[name] = r
    results["trajectory"] = traj
    results["corpus_facing_vs_travel_deg"] = float(torch.rad2deg(test.root[:, 1:, 2].abs()).mean())
    _print_table("distance of the root from the desired path (unseen random paths, 200 steps)", "gait.trajectory",
                 results)
    print(f"corpus test walks, facing vs travel: {results['corpus_facing_vs_travel_deg']:.1f} deg")
    return tpaths, traj_motions


def _long_horizon_and_speed(net, corpus, test, args, results) -> None:
    """4. 400 steps on a straight path, foot skate; 5. speed."""
    n_long = 4 if args.quick else 8
    lseeds = test_seeds(corpus, test.base_index[:n_long])
    results["long_horizon"] = long_horizon(net, lseeds, test.emotion.numpy().astype(np.float64)[:n_long],
                                           2 * args.steps)
    results["foot_skate_corpus_cm_s"] = float(np.mean([foot_skate_cm_s(corpus.motion(int(i)))
                                                       for i in test.base_index[:20]]))
    _print_table("long horizon (full model, straight path, 400 steps = 53 s)", "gait.long_horizon", results)
    print(f"foot skate (low feet ground speed): generated {results['long_horizon']['foot_skate_cm_s']:.1f} cm/s, "
          f"corpus {results['foot_skate_corpus_cm_s']:.1f} cm/s")
    results["speed"] = speed(net, lseeds[0])
    _print_table("speed", "gait.speed", results)


def _figures(net, corpus, test, motions, tpaths, traj_motions, args) -> None:
    """6. the contact sheet (own emotions and a sad -> happy transition) and the trajectory figure."""
    test_emotion = test.emotion.numpy().astype(np.float64)
    rows = []
    for k, e in enumerate(GAIT_EMOTIONS):
        idx = int(np.flatnonzero(test_emotion.argmax(1) == k)[np.argmax(test_emotion[test_emotion.argmax(1) == k, k])])
        rows.append((f"{e} (own)", motions["own"][idx]))
    sad_seed = int(np.flatnonzero(test_emotion.argmax(1) == 1)[0])
    tr = generate_gaits(test_seeds(corpus, [test.base_index[sad_seed]]), [straight(60.0)],
                        emotion_transition(test_emotion[sad_seed], [1, 0, 0, 0], args.steps)[None], steps=args.steps,
                        model=net)[0]
    rows.append(("transition sad->happy\n(colour = intended)", tr))
    contact_sheet(rows, Path("docs/img/gait_contact_sheet.png"))
    pick = [1, 2, 4, 5]  # two curved and two sharp-turn paths
    trajectory_figure([tpaths[i] for i in pick], {k: [v[i] for i in pick] for k, v in traj_motions.items()},
                      Path("docs/img/gait_trajectories.png"))


def main(argv=None) -> int:
    args = _args(argv)
    torch.set_num_threads(1)
    t_start = time.time()
    nets, results = _load(args)
    corpus = GaitCorpus.load(args.corpus)
    data = load_corpus_sequences(args.corpus)
    results["corpus"] = data.training_data.corpus
    for name, net in nets.items():
        trained = (net.info.get("corpus") or {}).get("sha256")
        if trained != data.training_data.corpus["sha256"]:
            print(f"WARNING: model {name!r} was trained on corpus {str(trained)[:12]}, evaluated on "
                  f"{data.training_data.corpus['sha256'][:12]}")
    train = data.subset((data.split == "train") & (data.offset == 0))
    test = data.subset((data.split == "test") & (data.offset == 0))
    if args.quick:
        test = test.subset(np.arange(12))
    _prediction(nets, train, test, results)
    observer = Observer(train)
    motions = _expressiveness(nets, observer, corpus, test, args, results)
    _heldout(nets, observer, args, results)
    tpaths, traj_motions = _trajectory(nets, corpus, test, args, results)
    _long_horizon_and_speed(nets["full"], corpus, test, args, results)
    _figures(nets["full"], corpus, test, motions["full"], tpaths, traj_motions, args)
    results["seconds"] = time.time() - t_start
    doc_tables.write_results("gait", args.out, results, results["seconds"])
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
