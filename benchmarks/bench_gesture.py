"""Benchmark of the seed 003 gesture network: pose error (Table 1 layout with ablations and baselines),
emotional expressiveness, generation speed, and a contact sheet.

    python benchmarks/bench_gesture.py                    # evaluate the shipped weights, train short ablations
    python benchmarks/bench_gesture.py --ablation-minutes 4 --skip-train   # reuse trained ablations

Writes ``docs/benchmarks/gesture.md``, ``docs/img/gesture_contact_sheet.png`` and ``var/gesture/bench.json``.
Everything is measured on held-out sentences of the SYNTHETIC corpus (procedural gestures), not captured motion.
"""
from __future__ import annotations

import argparse
import json
import os
import sys
import time
from pathlib import Path

os.environ.setdefault("OMP_NUM_THREADS", "1")
os.environ.setdefault("MKL_NUM_THREADS", "1")
ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))

import numpy as np  # noqa: E402
import torch  # noqa: E402
from scipy import stats  # noqa: E402

from generation.core.features import np_gesture_affective_features  # noqa: E402
from generation.core.kinematics import np_forward_kinematics  # noqa: E402
from generation.core.quaternion import np_qnormalize  # noqa: E402
from generation.core.skeleton import gesture_skeleton  # noqa: E402
from generation.gesture import config  # noqa: E402
from generation.gesture.data import GestureDataset, attribute_vector, build_dataset, nrc_vad  # noqa: E402
from generation.gesture.generate import decode_examples, generate_gesture, load_model  # noqa: E402
from generation.gesture.losses import LossWeights  # noqa: E402
from generation.gesture.metrics import dataset_pose_error, upper_body_acceleration  # noqa: E402
from generation.gesture.model import GestureNetConfig  # noqa: E402
from generation.gesture.train import TrainConfig, train  # noqa: E402

MACHINE = "2-core CI VM, no GPU"
DATE = "2026-11-27"
GESTURE_EMOTIONS = ("afraid", "amused", "angry", "ashamed", "disgusted", "joyous", "neutral", "proud", "relieved",
                    "sad", "surprised")
SHEET_SENTENCE = "I can't believe we finally made it to the top of the mountain!"
ABLATIONS = {
    "no angle loss": LossWeights(angle=0.0),
    "no pose loss": LossWeights(pose=0.0),
    "no affective loss": LossWeights(affective=0.0),
}


# ---- metrics ---------------------------------------------------------------------------------------
def positions_of(rotations: np.ndarray, data: GestureDataset, i: int) -> np.ndarray:
    """(T, J, 4) -> (T, J, 3) metres on example i's body, seated root."""
    sk = gesture_skeleton(build=str(data.gender[i]))
    return np_forward_kinematics(rotations, np.repeat(data.root[i][None].astype(np.float64), len(rotations), 0), sk)


def pose_errors(pred: list[np.ndarray], data: GestureDataset, idx: np.ndarray) -> dict[str, float]:
    """Seed 003 Table 1 metric (:func:`generation.gesture.metrics.dataset_pose_error`)."""
    return dataset_pose_error(pred, data, idx)


def mean_pose_baseline(data: GestureDataset, idx: np.ndarray) -> list[np.ndarray]:
    """Every frame = the per-joint mean training pose (normalised quaternion average)."""
    tr = data.indices("train")
    frames = np.concatenate([data.rotations[i, : data.lengths[i]] for i in tr]).astype(np.float64)
    mean = np_qnormalize(frames.mean(0))
    return [np.repeat(mean[None], int(data.lengths[i]), 0) for i in idx]


def nearest_neighbour_baseline(data: GestureDataset, idx: np.ndarray) -> list[np.ndarray]:
    """The training gesture of the nearest training sentence (cosine of mean token vectors) with the same emotion,
    task, gender and handedness when there is one, time-warped linearly to the test length."""
    tr = data.indices("train")

    def emb(i):
        v = data.tokens[i, : data.token_lengths[i]].mean(0)
        return v / np.linalg.norm(v)

    E = np.stack([emb(i) for i in tr])
    out = []
    for i in idx:
        same = np.array([(data.row(j).emotion, data.row(j).task, data.gender[j], data.handedness[j])
                         == (data.row(i).emotion, data.row(i).task, data.gender[i], data.handedness[i]) for j in tr])
        sim = E @ emb(i) - 10.0 * (~same)
        j = tr[int(np.argmax(sim))]
        src = data.rotations[j, : data.lengths[j]].astype(np.float64)
        L = int(data.lengths[i])
        pick = np.round(np.linspace(0, len(src) - 1, L)).astype(int)
        out.append(src[pick])
    return out


def motion_descriptors(positions: np.ndarray, fps: float) -> dict[str, float]:
    """Speed: 90th percentile over frames of the faster wrist's speed (m/s), i.e. the peak speed of the arm
    swings; expansion: mean wrist spread d(10,14)/d(0,6) (feature D3/D6 of seed 003 Fig. 4); plus the mean and
    std of the 15 affective features and both speed measures (the observer's inputs).

    The speed measure was chosen on the procedural training gestures (Pearson r with arousal 0.47 there, against
    -0.20 for the clip-mean speed of both wrists, which rest holds and two-handed gestures dilute)."""
    wrist_speed = np.linalg.norm(np.diff(positions[:, [10, 14]], axis=0), axis=-1) * fps  # (T-1, 2)
    speed = float(np.percentile(wrist_speed.max(1), 90))
    feats = np_gesture_affective_features(positions)
    return {"speed": speed, "expansion": float(feats[:, 11].mean()), "features": np.concatenate(
        [feats.mean(0), feats.std(0), [speed, float(wrist_speed.mean())]])}


def fit_observers(data: GestureDataset) -> dict:
    """Synthetic observers: logistic regressions on :func:`motion_descriptors` features of the procedural training
    gestures, one for high vs low arousal and one for high vs low dominance (VAD value > 0.5)."""
    from sklearn.linear_model import LogisticRegression
    from sklearn.pipeline import make_pipeline
    from sklearn.preprocessing import StandardScaler

    tr = data.indices("train")
    X_tr = np.stack([motion_descriptors(positions_of(data.rotations[i, : data.lengths[i]].astype(np.float64), data,
                                                     i), data.fps)["features"] for i in tr])
    return {k: make_pipeline(StandardScaler(), LogisticRegression(max_iter=2000, C=1.0)).fit(X_tr,
                                                                                              data.vad[tr, dim] > 0.5)
            for k, dim in (("arousal", 1), ("dominance", 2))}


def expressiveness(net, data: GestureDataset, idx: np.ndarray, observers: dict) -> dict:
    """Each held-out sentence said with each of the 11 emotions: Pearson r of speed with arousal and of
    expansion with dominance; the synthetic observers (:func:`fit_observers`) classify high vs low arousal and
    dominance (threshold 0.5) of the generated gestures (balanced accuracy)."""
    from sklearn.metrics import balanced_accuracy_score

    # generated: the same held-out sentences with every emotion
    rows = [(i, emo, nrc_vad(emo)) for i in idx for emo in GESTURE_EMOTIONS]
    tokens = np.stack([data.tokens[i] for i, _, _ in rows])
    attrs = np.stack([attribute_vector(data.row(i).task, vad, str(data.gender[i]), str(data.handedness[i]))
                      for i, _, vad in rows]).astype(np.float32)
    src = np.array([i for i, _, _ in rows])
    fake = GestureDataset(tokens=tokens, token_lengths=data.token_lengths[src], rotations=data.rotations[src],
                          lengths=data.lengths[src], attributes=attrs, offsets=data.offsets[src], rest=data.rest[src],
                          root=data.root[src], vad=np.array([v for _, _, v in rows], dtype=np.float32),
                          sentence_index=data.sentence_index[src], split=np.array(["test"] * len(rows)),
                          gender=data.gender[src], handedness=data.handedness[src], rows=data.rows, fps=data.fps)
    gen = decode_examples(net, fake, np.arange(len(rows)))
    desc = [motion_descriptors(positions_of(g, fake, n), data.fps) for n, g in enumerate(gen)]
    vad = fake.vad
    X = np.stack([d["features"] for d in desc])
    out = {"n_generated": len(rows)}
    out["r_speed_arousal"], out["p_speed_arousal"] = stats.pearsonr([d["speed"] for d in desc], vad[:, 1])
    out["r_expansion_dominance"], out["p_expansion_dominance"] = stats.pearsonr([d["expansion"] for d in desc],
                                                                                vad[:, 2])
    for k, dim in (("arousal", 1), ("dominance", 2)):
        out[f"observer_{k}_generated"] = balanced_accuracy_score(vad[:, dim] > 0.5, observers[k].predict(X))
    # reference: the same measures on the held-out procedural gestures (one emotion per sentence)
    desc_true = [motion_descriptors(positions_of(data.rotations[i, : data.lengths[i]].astype(np.float64), data, i),
                                    data.fps) for i in idx]
    X_true = np.stack([d["features"] for d in desc_true])
    out["r_speed_arousal_procedural"], _ = stats.pearsonr([d["speed"] for d in desc_true], data.vad[idx, 1])
    out["r_expansion_dominance_procedural"], _ = stats.pearsonr([d["expansion"] for d in desc_true],
                                                                data.vad[idx, 2])
    for k, dim in (("arousal", 1), ("dominance", 2)):
        truth = data.vad[idx, dim] > 0.5
        out[f"observer_{k}_procedural"] = (balanced_accuracy_score(truth, observers[k].predict(X_true))
                                           if len(np.unique(truth)) == 2 else float("nan"))
    per_emotion = {}
    for emo in GESTURE_EMOTIONS:
        sel = [n for n, (_, e, _) in enumerate(rows) if e == emo]
        per_emotion[emo] = {"speed": float(np.mean([desc[n]["speed"] for n in sel])),
                            "expansion": float(np.mean([desc[n]["expansion"] for n in sel]))}
    out["per_emotion"] = per_emotion
    return {k: (float(v) if isinstance(v, (np.floating, float)) else v) for k, v in out.items()}


def equal_epoch_validation(shipped_blob: dict, abl_dir: Path, epochs: int) -> dict:
    """Validation pose error (autoregressive, measured every 5 epochs during training) of the shipped run and of
    each ablation after the same number of epochs, read from the training histories."""
    def at(history, n):
        rows = [h for h in history if "val_rollout" in h and h["epoch"] < n]
        if not rows:
            return None
        return {"last": rows[-1]["val_rollout"]["pose_error"], "last_epoch": rows[-1]["epoch"] + 1,
                "best": min(h["val_rollout"]["pose_error"] for h in rows)}

    out = {"all losses (shipped run)": at(shipped_blob.get("history", []), epochs)}
    for name in ABLATIONS:
        slug = name.replace(" ", "_")
        path = abl_dir / f"{slug}.pt"
        if path.is_file():
            out[name] = at(torch.load(path, weights_only=False).get("history", []), epochs)
    return {k: v for k, v in out.items() if v is not None}


def speed_benchmark(net, n_sentences: int = 20, repeats: int = 3) -> dict:
    """Frames per second of generate_gesture (text encoding + decoding + resampling) at 30 fps output; the median
    of ``repeats`` passes over ``n_sentences`` sentences (the 2 cores are shared, so the spread is reported)."""
    from generation.gesture.data import load_sentences

    torch.set_num_threads(1)
    rows = load_sentences()[:: max(1, 330 // n_sentences)][:n_sentences]
    generate_gesture(rows[0].sentence, model=net)  # warm up (loads the text model)
    passes = []
    for _ in range(repeats):
        frames = net_steps = 0
        t0 = time.perf_counter()
        for r in rows:
            m = generate_gesture(r.sentence, task=r.task, emotion=r.emotion, model=net, fps=30.0)
            frames += m.num_frames
            net_steps += int(round(m.duration * net.train_fps)) + 1
        passes.append((time.perf_counter() - t0, frames, net_steps))
    dt, frames, net_steps = sorted(passes)[len(passes) // 2]
    fps_all = sorted(f / d for d, f, _ in passes)
    return {"sentences": len(rows), "seconds": dt, "output_frames": frames, "output_fps": frames / dt,
            "output_fps_min": fps_all[0], "output_fps_max": fps_all[-1], "repeats": repeats,
            "network_steps_per_s": net_steps / dt, "ms_per_output_frame": 1000 * dt / frames}


# ---- contact sheet ----------------------------------------------------------------------------------
def contact_sheet(net, path: Path, sentence: str) -> None:
    """Stick figures seen from the front right: rows = emotions and handedness, columns = moments of the gesture;
    faint lines trace each wrist over the half second before and after the moment shown."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    rows = [("sad", "right"), ("neutral", "right"), ("relieved", "right"), ("afraid", "right"), ("angry", "right"),
            ("amused", "right"), ("proud", "right"), ("proud", "left")]
    n_cols = 7
    fig, axes = plt.subplots(len(rows), n_cols, figsize=(1.6 * n_cols, 1.9 * len(rows)))
    sk = gesture_skeleton(build="female")
    for r, (emo, hand) in enumerate(rows):
        m = generate_gesture(sentence, task="narration", emotion=emo, gender="female", handedness=hand, fps=10.0,
                             model=net)
        P3 = m.positions()
        # viewer in front of the agent, 35 degrees round to its right; image x = viewer's right, image y = up
        th = np.radians(35.0)
        P = np.stack((P3[..., 0] * np.cos(th) - P3[..., 2] * np.sin(th), P3[..., 1]), axis=-1)
        picks = np.linspace(0, m.num_frames - 1, n_cols).round().astype(int)
        for c, t in enumerate(picks):
            ax = axes[r, c]
            lo, hi = max(0, t - 5), min(m.num_frames, t + 6)
            for j, color in ((10, "#f4a6a6"), (14, "#a6c8f4")):
                ax.plot(P[lo:hi, j, 0], P[lo:hi, j, 1], color=color, lw=1.0)
            for j, p in enumerate(sk.parents):
                if p >= 0:
                    color = "tab:red" if j in (8, 9, 10) else "tab:blue" if j in (12, 13, 14) else "0.3"
                    ax.plot([P[t, p, 0], P[t, j, 0]], [P[t, p, 1], P[t, j, 1]], color=color, lw=1.6)
            ax.set_xlim(-0.7, 0.7)
            ax.set_ylim(-0.05, 1.4)
            ax.set_aspect("equal")
            ax.set_xticks([])
            ax.set_yticks([])
            if r == 0:
                ax.set_title(f"{t / m.fps:.1f} s", fontsize=8)
            if c == 0:
                ax.set_ylabel(f"{emo}\n{hand}-handed", fontsize=8)
    fig.suptitle(f'"{sentence}"\n(generated, seated; red = left arm, blue = right arm; seen from the front right)',
                 fontsize=9)
    fig.tight_layout()
    path.parent.mkdir(parents=True, exist_ok=True)
    fig.savefig(path, dpi=100)
    plt.close(fig)


# ---- main -------------------------------------------------------------------------------------------
def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--weights", default=str(config.DEFAULT_WEIGHTS))
    ap.add_argument("--ablation-minutes", type=float, default=20.0, help="wall-clock budget per ablation run")
    ap.add_argument("--ablation-epochs", type=int, default=35)
    ap.add_argument("--skip-train", action="store_true", help="reuse ablation weights already in var/")
    ap.add_argument("--no-ablations", action="store_true")
    ap.add_argument("--sheet-only", action="store_true", help="only draw the contact sheet")
    ap.add_argument("--out", default=str(ROOT / "docs" / "benchmarks" / "gesture.md"))
    ap.add_argument("--sheet", default=str(ROOT / "docs" / "img" / "gesture_contact_sheet.png"))
    args = ap.parse_args(argv)
    torch.set_num_threads(1)
    torch.manual_seed(0)

    net = load_model(args.weights)
    if args.sheet_only:
        contact_sheet(net, Path(args.sheet), SHEET_SENTENCE)
        return
    data = build_dataset()
    test = data.indices("test")
    blob = torch.load(args.weights, weights_only=False)
    results: dict = {"machine": MACHINE, "date": DATE, "n_test": int(len(test)),
                     "n_train": int(len(data.indices("train"))), "n_val": int(len(data.indices("val"))),
                     "shipped": {"epochs": blob.get("epochs_run"), "seconds": blob.get("seconds"),
                                 "parameters": net.num_parameters(), "best_val": blob.get("best_val")}}
    table = {}
    t = time.perf_counter()
    table["all losses (shipped weights)"] = pose_errors(decode_examples(net, data, test), data, test)
    results["decode_test_seconds"] = time.perf_counter() - t
    if not args.no_ablations:
        abl_dir = config.VAR_DIR / "ablations"
        for name, weights in ABLATIONS.items():
            slug = name.replace(" ", "_")
            out = abl_dir / f"{slug}.pt"
            if not (args.skip_train and out.is_file()):
                cfg = TrainConfig(epochs=args.ablation_epochs, max_minutes=args.ablation_minutes, loss=weights,
                                  model=GestureNetConfig(**blob["config"]), out=str(out),
                                  checkpoint=str(abl_dir / f"{slug}_ckpt.pt"))
                s = train(cfg, data=data, progress=False)
                print(f"{name}: {s['epochs_run']} epochs in {s['seconds']:.0f} s", flush=True)
            ab = load_model(out)
            b = torch.load(out, weights_only=False)
            table[name] = {**pose_errors(decode_examples(ab, data, test), data, test),
                           "epochs": b.get("epochs_run"), "seconds": b.get("seconds")}
    results["equal_epoch_validation"] = equal_epoch_validation(blob, config.VAR_DIR / "ablations",
                                                               args.ablation_epochs)
    table["baseline: mean pose"] = pose_errors(mean_pose_baseline(data, test), data, test)
    table["baseline: nearest neighbour"] = pose_errors(nearest_neighbour_baseline(data, test), data, test)
    results["pose_error_table"] = table
    results["gt_acceleration"] = float(np.mean([
        upper_body_acceleration(data.rotations[i, : data.lengths[i]], str(data.gender[i]), data.root[i], data.fps)
        for i in test]))
    print(json.dumps(table, indent=1), flush=True)
    observers = fit_observers(data)
    results["expressiveness"] = expressiveness(net, data, test, observers)
    print(json.dumps(results["expressiveness"], indent=1), flush=True)
    # the ablations' expressiveness on the first 22 held-out examples (x 11 emotions)
    sub_idx = test[:22]
    ablation_expr = {"all losses (shipped weights)": expressiveness(net, data, sub_idx, observers)}
    for name in table:
        if name in ABLATIONS:
            slug = name.replace(" ", "_")
            ablation_expr[name] = expressiveness(load_model(config.VAR_DIR / "ablations" / f"{slug}.pt"), data,
                                                 sub_idx, observers)
    results["ablation_expressiveness"] = {k: {m: v[m] for m in ("r_speed_arousal", "r_expansion_dominance",
                                                                 "observer_arousal_generated",
                                                                 "observer_dominance_generated", "n_generated")}
                                          for k, v in ablation_expr.items()}
    results["speed"] = speed_benchmark(net)
    print(json.dumps(results["speed"], indent=1), flush=True)
    contact_sheet(net, Path(args.sheet), SHEET_SENTENCE)
    (config.VAR_DIR).mkdir(parents=True, exist_ok=True)
    (config.VAR_DIR / "bench.json").write_text(json.dumps(results, indent=1, default=float))
    Path(args.out).write_text(render_markdown(results))
    print(f"wrote {args.out}")


def render_markdown(r: dict) -> str:
    sh = r["shipped"]
    lines = [
        "## Gesture network (seed 003 Text2Gestures)",
        "",
        f"Machine: {r['machine']}; date {r['date']}; produced by `python benchmarks/bench_gesture.py`.",
        "",
        "All numbers are on the **synthetic** corpus: 330 project-written sentences (11 MPI emotions x 30, narration "
        "and conversation) each paired with 2 procedural seated gestures (random gender and handedness), split "
        f"80/10/10 by sentence ({r['n_train']} / {r['n_val']} / {r['n_test']} examples). The ground truth is "
        "procedural motion, not motion capture, so the numbers say how well the network learns the "
        "text/attribute -> gesture mapping of the procedural generator, not how human the gestures are. In that "
        "corpus each phrase of a sentence (cut at punctuation) gets one gesture whose kind follows its words "
        "(deictic words -> pointing, aroused or exclaimed -> beat, else descriptive), whose style follows the "
        "emotion's VAD (arousal -> speed, amplitude, head motion; dominance -> expansion, upright trunk) and the "
        "task (narration 1.2x, conversation 0.8x amplitude), with small per-example variation; the length is "
        "0.5 s + 0.4 s per word + 1 s.",
        "",
        f"Shipped weights: {sh['parameters']:,} parameters, {sh['epochs']} epochs in {sh['seconds'] / 60:.1f} min on "
        "one thread (network at 10 fps).",
        "",
        "### Mean pose error on held-out sentences (seed 003 Table 1 layout)",
        "",
        "Mean over test sequences of (mean joint distance over all frames and joints) / (ground truth's bounding-box "
        "diagonal); the network generates from text and attributes alone (autoregressive, never sees the ground "
        "truth). Paper: 0.05 for all losses, 0.06-0.07 for the ablations, 1.57 for Yoon et al.",
        "",
        "| Method | Mean pose error | Upper body (8 joints) | Rotation error (deg) | Upper-body accel. (m/s^2) "
        "| Training |",
        "|---|---|---|---|---|---|",
    ]
    for name, v in r["pose_error_table"].items():
        train_s = (f"{v['epochs']} epochs, {v['seconds'] / 60:.1f} min" if v.get("epochs") else
                   (f"{sh['epochs']} epochs, {sh['seconds'] / 60:.1f} min" if "shipped" in name else "-"))
        lines.append(f"| {name} | {v['pose_error']:.4f} | {v['pose_error_upper']:.4f} | "
                     f"{v['rotation_error_deg']:.2f} | {v['acceleration']:.3f} | {train_s} |")
    if r.get("ablation_expressiveness"):
        n = next(iter(r["ablation_expressiveness"].values()))["n_generated"]
        lines += ["", f"Expressiveness of each variant ({n} gestures: the first 22 held-out examples x 11 emotions; "
                  "measures as in the next section):", "",
                  "| Method | r(speed, arousal) | r(expansion, dominance) | observer arousal | observer dominance |",
                  "|---|---|---|---|---|"]
        for name, v in r["ablation_expressiveness"].items():
            lines.append(f"| {name} | {v['r_speed_arousal']:.3f} | {v['r_expansion_dominance']:.3f} | "
                         f"{v['observer_arousal_generated']:.3f} | {v['observer_dominance_generated']:.3f} |")
    eq = r.get("equal_epoch_validation") or {}
    if eq:
        lines += ["", "Validation pose error at equal training length (generated autoregressively every 5 epochs "
                  "during training; from the training histories):", "",
                  "| Method | after epoch | validation pose error | best so far |", "|---|---|---|---|"]
        for name, v in eq.items():
            lines.append(f"| {name} | {v['last_epoch']} | {v['last']:.4f} | {v['best']:.4f} |")
    lines += ["", f"Ground truth (procedural) upper-body acceleration: {r['gt_acceleration']:.3f} m/s^2 (a jerkiness "
              "measure: mean magnitude of the second time difference of the 8 upper-body joints at 10 fps).", "",
              "The ablations were trained for fewer epochs than the shipped weights (same seed, data and settings "
              "otherwise, each removing one term of eq. 11); the equal-length comparison is the validation table "
              "above.", ""]
    e = r["expressiveness"]
    lines += [
        "### Emotional expressiveness",
        "",
        f"Each held-out sentence generated with each of the 11 emotions ({e['n_generated']} gestures). Speed = 90th "
        "percentile over frames of the faster wrist's speed (m/s, the peak speed of the arm swings; chosen on the "
        "procedural training gestures); expansion = mean wrist spread d(l_wrist, r_wrist) / d(root, head).",
        "",
        "| Measure | Generated | Procedural ground truth (held-out) |",
        "|---|---|---|",
        f"| Pearson r(speed, arousal) | {e['r_speed_arousal']:.3f} (p = {e['p_speed_arousal']:.2g}) | "
        f"{e['r_speed_arousal_procedural']:.3f} |",
        f"| Pearson r(expansion, dominance) | {e['r_expansion_dominance']:.3f} (p = {e['p_expansion_dominance']:.2g}) "
        f"| {e['r_expansion_dominance_procedural']:.3f} |",
        f"| Synthetic observer, high vs low arousal (balanced accuracy) | {e['observer_arousal_generated']:.3f} | "
        f"{e['observer_arousal_procedural']:.3f} |",
        f"| Synthetic observer, high vs low dominance (balanced accuracy) | {e['observer_dominance_generated']:.3f} | "
        f"{e['observer_dominance_procedural']:.3f} |",
        "",
        "The synthetic observer is a logistic regression on the mean and standard deviation of the 15 affective "
        "features plus wrist speed, fitted on the procedural training gestures (high = VAD value > 0.5); chance is "
        "0.5. It is a stand-in for the paper's human raters (seed 003 6.3.1: Pearson r of intended vs perceived "
        "arousal 0.95, dominance 0.82), not a comparison with them.",
        "",
        "| Emotion | arousal | dominance | mean peak wrist speed (m/s) | mean expansion |",
        "|---|---|---|---|---|",
    ]
    for emo, v in sorted(e["per_emotion"].items(), key=lambda kv: nrc_vad(kv[0])[1]):
        _, a, d = nrc_vad(emo)
        lines.append(f"| {emo} | {a:.3f} | {d:.3f} | {v['speed']:.3f} | {v['expansion']:.3f} |")
    s = r["speed"]
    lines += [
        "",
        "### Generation speed",
        "",
        f"`generate_gesture` on {s['sentences']} corpus sentences, one at a time, output at 30 fps, one CPU thread, "
        f"median of {s['repeats']} passes: **{s['output_fps']:.0f} output frames per second** "
        f"({s['ms_per_output_frame']:.2f} ms per frame; {s['network_steps_per_s']:.0f} network steps per second at "
        f"10 fps, text encoding and resampling included; passes ranged {s['output_fps_min']:.0f}-"
        f"{s['output_fps_max']:.0f} fps). Paper: 312.5 fps (3.2 ms per frame) on a GTX 1080Ti. The 2 cores are shared "
        "with other jobs, so the figure depends on their load.",
        "",
        "### Contact sheet",
        "",
        "`docs/img/gesture_contact_sheet.png`: one sentence said with seven emotions (sad, neutral, relieved, "
        "afraid, angry, amused, proud) by a right-handed agent, and proud by a left-handed one (last row).",
        "",
        "Reproduce: `python -m generation.gesture.train` (the defaults: 20 min budget, seed 0, `--residual rest`; "
        "the epochs reached depend on the machine's load), the ablations with "
        "`python -m generation.gesture.train --epochs 35 [--no-angle-loss|--no-pose-loss|--no-affective-loss] "
        "--out var/gesture/ablations/<name>.pt --checkpoint var/gesture/ablations/<name>_ckpt.pt`, then "
        "`python benchmarks/bench_gesture.py --skip-train`.",
        "",
    ]
    return "\n".join(lines)


if __name__ == "__main__":
    main()
