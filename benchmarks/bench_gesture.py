"""Benchmark of the seed 003 gesture network: pose error, liveliness, expressiveness, speed, contact sheets.

Pose error in the paper's Table 1 layout (with ablations and baselines), liveliness (wrist speed, generated vs
corpus), emotional expressiveness, generation and training speed, and two contact sheets.

    python -m benchmarks.bench_gesture                      # the shipped weights
    python -m benchmarks.bench_gesture --original-weights A.pt --previous-weights B.pt   # with two comparisons
    python -m benchmarks.bench_gesture --ablations --ablation-minutes 4 --skip-train    # + loss ablations (slow)

Everything is measured on held-out sentences of the SYNTHETIC corpus (procedural gestures), not captured motion.
Results go to docs/benchmarks/gesture.json (``--out``); the tables are printed and rendered into the marked blocks
of docs/benchmarks/gesture.md (benchmarks/doc_tables.py; the narrative there is written by hand). Figures:
docs/img/gesture_contact_sheet.png and docs/img/gesture_arousal_sheet.png.
"""
from __future__ import annotations

import argparse
import json
import os
import platform
import shlex
import subprocess
import sys
import time
from datetime import UTC, datetime
from pathlib import Path

import numpy as np
import torch
from scipy import stats

from benchmarks import doc_tables
from benchmarks.bench_record import one_thread
from generation.core.quaternion import np_qnormalize
from generation.core.skeleton import gesture_skeleton
from generation.gesture import config
from generation.gesture.data import GestureDataset, build_dataset, nrc_vad, with_emotions
from generation.gesture.generate import decode_examples, generate_gesture, load_model
from generation.gesture.losses import LossWeights
from generation.gesture.metrics import (
    dataset_pose_error,
    upper_body_acceleration,
    wrist_speed,
    wrist_speed_of_positions,
)
from generation.gesture.model import GestureNetConfig
from generation.gesture.train import TrainConfig, train
from generation.quality.gesture_observer import corpus_descriptors, motion_descriptors, positions_of
from generation.render.offscreen import prepare_render_process
from protocol.vocabulary import GESTURE_EMOTIONS

ROOT = Path(__file__).resolve().parents[1]

SHEET_SENTENCE = "I can't believe we finally made it to the top of the mountain!"
ABLATIONS = {
    "no angle loss": LossWeights(angle=0.0),
    "no pose loss": LossWeights(pose=0.0),
    "no affective loss": LossWeights(affective=0.0),
}


# ---- metrics ---------------------------------------------------------------------------------------
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
        same = np.array([(data.emotion[j], data.row(j).task, data.gender[j], data.handedness[j])
                         == (data.emotion[i], data.row(i).task, data.gender[i], data.handedness[i]) for j in tr])
        sim = E @ emb(i) - 10.0 * (~same)
        j = tr[int(np.argmax(sim))]
        src = data.rotations[j, : data.lengths[j]].astype(np.float64)
        L = int(data.lengths[i])
        pick = np.round(np.linspace(0, len(src) - 1, L)).astype(int)
        out.append(src[pick])
    return out


def fit_observers(data: GestureDataset) -> dict:
    """Synthetic observers: logistic regressions on :func:`generation.quality.gesture_observer.motion_descriptors`
    features of the procedural training gestures, one for high vs low arousal and one for high vs low dominance
    (VAD value > 0.5); the 11-way gesture observer of the quality gate uses the same features."""
    from sklearn.linear_model import LogisticRegression
    from sklearn.pipeline import make_pipeline
    from sklearn.preprocessing import StandardScaler

    tr = data.indices("train")
    X_tr = corpus_descriptors(data, tr)
    return {k: make_pipeline(StandardScaler(), LogisticRegression(max_iter=2000, C=1.0)).fit(X_tr,
                                                                                              data.vad[tr, dim] > 0.5)
            for k, dim in (("arousal", 1), ("dominance", 2))}


def all_emotion_examples(data: GestureDataset, idx: np.ndarray) -> tuple[list, GestureDataset]:
    """Each example of ``idx`` (its sentence, task, body and handedness) with each of the 11 emotions:
    ([(example index, emotion, vad)], a GestureDataset of those len(idx) x 11 inputs from
    :func:`generation.gesture.data.with_emotions`; its rotations are the example's own, not a gesture of the new
    emotion)."""
    rows = [(i, emo, nrc_vad(emo)) for i in idx for emo in GESTURE_EMOTIONS]
    return rows, with_emotions(data, idx, GESTURE_EMOTIONS)


def all_emotion_corpus_speeds(data: GestureDataset, rows: list) -> list[dict]:
    """Wrist speed of the procedural gesture the corpus would pair with each (example, emotion) of
    :func:`all_emotion_examples`: the example's sentence, body and handedness performed with that emotion, as
    the corpus's counterfactual variants are made (:func:`generation.gesture.data.procedural_gesture`)."""
    from generation.gesture.data import procedural_gesture

    out = []
    for n, (i, emo, _) in enumerate(rows):
        m = procedural_gesture(data.row(i), str(data.gender[i]), str(data.handedness[i]), seed=900_001 + n,
                               fps=data.fps, emotion=emo)
        out.append(wrist_speed(np_qnormalize(m.rotations), str(data.gender[i]), data.root[i], data.fps))
    return out


def liveliness_all_emotions(examples: tuple[list, GestureDataset], gen: list[np.ndarray], corpus: list[dict]) -> dict:
    """:func:`liveliness` over every held-out example x 11 emotions (``examples`` from :func:`all_emotion_examples`,
    ``gen`` their decoded gestures): per emotion len(idx) examples (99 on the test split) instead of the 8-12 that
    carry each emotion in the split itself, against the procedural gestures of :func:`all_emotion_corpus_speeds`
    (``corpus``)."""
    rows, fake = examples
    g = [wrist_speed(x, str(fake.gender[n]), fake.root[n], fake.fps) for n, x in enumerate(gen)]
    per, worst = speed_ratios([e for _, e, _ in rows], g, corpus)
    ratios = [v[f"gen_{m}"] / v[f"corpus_{m}"] for v in per.values() for m in ("mean", "peak")]
    return {"per_emotion": per, "n": len(rows), "cells_in_band": int(sum(0.75 <= x <= 1.25 for x in ratios)),
            "worst_ratio_gap": worst}


def expressiveness(examples: tuple[list, GestureDataset], gen: list[np.ndarray], data: GestureDataset,
                   idx: np.ndarray, observers: dict) -> dict:
    """Each held-out sentence said with each of the 11 emotions (``examples`` from :func:`all_emotion_examples`,
    ``gen`` their decoded gestures): Pearson r of speed with arousal and of expansion with dominance; the
    synthetic observers (:func:`fit_observers`) classify high vs low arousal and dominance (threshold 0.5) of the
    generated gestures (balanced accuracy)."""
    from sklearn.metrics import balanced_accuracy_score

    rows, fake = examples
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


# ---- liveliness ----------------------------------------------------------------------------------
def speed_ratios(emotions: list[str], gen: list[dict], corpus: list[dict]) -> tuple[dict, float]:
    """Per emotion present in ``emotions`` (one label per example): n and the mean over its examples of the
    generated and corpus clips' mean and peak wrist speed (``gen`` / ``corpus``: :func:`wrist_speed` dicts); and
    the largest |generated / corpus - 1| over those cells."""
    per = {}
    for emo in GESTURE_EMOTIONS:
        sel = [k for k, e in enumerate(emotions) if e == emo]
        if sel:
            per[emo] = {"n": len(sel), **{f"{who}_{m}": float(np.mean([src[k][m] for k in sel]))
                                          for who, src in (("gen", gen), ("corpus", corpus)) for m in ("mean", "peak")}}
    worst = max(abs(v[f"gen_{m}"] / v[f"corpus_{m}"] - 1) for v in per.values() for m in ("mean", "peak"))
    return per, float(worst)


def liveliness(net, data: GestureDataset, idx: np.ndarray) -> dict:
    """Wrist speed of generated vs corpus gestures for the same held-out sentences and attributes.

    Each held-out example is generated from its own text and attributes; per emotion, the mean over examples of
    the clip's mean and peak wrist speed (:func:`generation.gesture.metrics.wrist_speed`: the faster wrist's speed,
    its mean and 90th percentile over frames, m/s at 10 fps), for the generated and the procedural gestures; and
    Pearson r of the peak speed with arousal over the examples."""
    gen = decode_examples(net, data, idx)
    g = [wrist_speed(x, str(data.gender[i]), data.root[i], data.fps) for x, i in zip(gen, idx)]
    c = [wrist_speed(data.rotations[i, : data.lengths[i]], str(data.gender[i]), data.root[i], data.fps) for i in idx]
    per, worst = speed_ratios([str(data.emotion[i]) for i in idx], g, c)
    arousal = data.vad[idx, 1]
    return {"per_emotion": per, "n": int(len(idx)), "worst_ratio_gap": worst,
            "r_gen": float(stats.pearsonr([x["peak"] for x in g], arousal)[0]),
            "r_corpus": float(stats.pearsonr([x["peak"] for x in c], arousal)[0])}


def liveliness_report(nets: dict, data: GestureDataset, idx: np.ndarray, observers: dict) -> dict:
    """:func:`liveliness` and the all-emotion r(peak speed, arousal) of :func:`expressiveness` per network."""
    out = {}
    examples = all_emotion_examples(data, idx)
    corpus = all_emotion_corpus_speeds(data, examples[0])
    for name, net in nets.items():
        live = liveliness(net, data, idx)
        gen = decode_examples(net, examples[1], np.arange(len(examples[0])))
        expr = expressiveness(examples, gen, data, idx, observers)
        out[name] = {**live, "r_all_emotions": expr["r_speed_arousal"], "n_all_emotions": expr["n_generated"],
                     "all_emotions": liveliness_all_emotions(examples, gen, corpus), "expressiveness": expr}
        print(name, json.dumps({k: v for k, v in out[name].items() if k != "expressiveness"}, default=float),
              flush=True)
    return out


# ---- training speed ------------------------------------------------------------------------------
def epoch_timing(data: GestureDataset, preset: str, n_batches: int = 3) -> dict:
    """Seconds per training epoch of a preset on the CPU, extrapolated from ``n_batches`` timed batches (after one
    warm-up batch) with the training settings of the shipped run (all inputs self-fed, 3 no-grad passes)."""
    from generation.gesture.train import _run_epoch, preset_config

    cfg = preset_config(preset, device="cpu")
    torch.manual_seed(0)
    from generation.gesture.model import GestureNet

    net = GestureNet(cfg.model)
    opt = torch.optim.Adam(net.parameters(), lr=cfg.lr)
    corpus = data.on_device("cpu")
    tr = data.indices("train")
    gen = torch.Generator().manual_seed(0)
    _run_epoch(net, corpus, tr[: cfg.batch_size], cfg, opt, gen, sampling=cfg.sampling)  # warm-up
    t = time.perf_counter()
    _run_epoch(net, corpus, tr[: n_batches * cfg.batch_size], cfg, opt, gen, sampling=cfg.sampling)
    per_batch = (time.perf_counter() - t) / n_batches
    batches = int(np.ceil(len(tr) / cfg.batch_size))
    return {"preset": preset, "parameters": net.num_parameters(), "timed_batches": n_batches,
            "seconds_per_batch": per_batch, "batches_per_epoch": batches, "seconds_per_epoch": per_batch * batches,
            "epochs": cfg.epochs}


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


_BY_AROUSAL = sorted(GESTURE_EMOTIONS, key=lambda e: nrc_vad(e)[1])
AROUSAL_SHEET_ROWS = (("low arousal", tuple(_BY_AROUSAL[:3])), ("high arousal", tuple(_BY_AROUSAL[-3:])))
AROUSAL_SHEET_SENTENCE = "We waited at the station for hours, and then the last train finally arrived."


def onion_skin(frames: list[np.ndarray], key: int, n_ghosts: int = 16, tint=(40, 90, 220)) -> np.ndarray:
    """One picture of a clip: frame ``key`` over tinted ghosts of ``n_ghosts`` evenly spaced frames, so the space
    the arms swept shows as a blue trail. A pixel belongs to a ghost where that frame differs from the clip's
    per-pixel median (the still parts: chair, floor, trunk); the key frame's own moving parts are drawn last,
    crisp. frames: (H, W, 3) uint8 images -> (H, W, 3) uint8."""
    stack = np.stack(frames).astype(np.float32)
    median = np.median(stack, axis=0)
    out = stack[key].copy()
    tint = np.asarray(tint, dtype=np.float32)
    for t in np.linspace(0, len(frames) - 1, n_ghosts).round().astype(int):
        moved = np.abs(stack[t] - median).max(-1) > 24
        out[moved] = 0.6 * out[moved] + 0.4 * (0.5 * stack[t][moved] + 0.5 * tint)
    own = np.abs(stack[key] - median).max(-1) > 24
    out[own] = stack[key][own]
    return out.clip(0, 255).astype(np.uint8)


def arousal_sheet(net, path: Path, sentence: str = AROUSAL_SHEET_SENTENCE) -> list[dict]:
    """Mannequin renders of one sentence (not in the corpus) said with the three lowest- and three highest-arousal
    emotions (same agent: female, right-handed, narration), upper body: each tile is the frame of the fastest wrist
    movement over tinted ghosts of the whole clip (:func:`onion_skin`). Returns the per-tile wrist speeds."""
    import tempfile

    from PIL import Image

    from generation.render.clip import render_frames
    from generation.render.contact_sheet import contact_sheet as grid
    from generation.render.settings import RenderSettings

    settings = RenderSettings(width=560, height=560, fps=10.0, camera="fixed", anti_aliasing="none")
    tiles, labels, info = [], [], []
    with tempfile.TemporaryDirectory() as tmp:
        for _, emotions in AROUSAL_SHEET_ROWS:
            for emo in emotions:
                m = generate_gesture(sentence, task="narration", emotion=emo, gender="female", handedness="right",
                                     fps=10.0, model=net)
                P = m.positions()
                speed = np.linalg.norm(np.diff(P[:, [10, 14]], axis=0), axis=-1).max(1) * m.fps
                ws = wrist_speed_of_positions(P, m.fps)
                H, W = settings.height, settings.width  # keep the upper body: the arms are what differs
                frames = [f[: int(0.7 * H), int(0.16 * W): int(0.86 * W)] for f in render_frames(m, settings)]
                tile = Path(tmp) / f"{emo}.png"
                Image.fromarray(onion_skin(frames, int(np.argmax(speed)) + 1)).save(tile)
                tiles.append(tile)
                a = nrc_vad(emo)[1]
                labels.append(f"{emo} (arousal {a:.2f}): wrist speed mean {ws['mean']:.2f}, peak {ws['peak']:.2f} m/s")
                info.append({"emotion": emo, "arousal": a, **ws})
        grid(tiles, labels, path, columns=3, thumb_width=400)
    return info


# ---- main -------------------------------------------------------------------------------------------
SHIPPED = "shipped"
COMPARISONS = {"original_weights": "eqs. 8-10 only", "previous_weights": "previous weights"}
"""Comparison weights: option dest -> their label in the results (pose-table row, liveliness column), oldest first."""


def _args(argv):
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--weights", default=str(config.DEFAULT_WEIGHTS))
    ap.add_argument("--previous-weights", "--before-weights", dest="previous_weights", default=None,
                    help="weights to compare against (label 'previous weights'), e.g. an earlier shipped file: git "
                         "show <commit>:generation/data/weights/gesture_net_default.pt > var/gesture/previous.pt")
    ap.add_argument("--original-weights", default=None,
                    help="an older comparison (label 'eqs. 8-10 only'): weights trained with the angle, pose and "
                         "affective losses alone (docs/benchmarks/gesture.md says which file)")
    ap.add_argument("--ablations", action="store_true", help="train and evaluate the loss ablations (slow)")
    ap.add_argument("--ablation-minutes", type=float, default=20.0, help="wall-clock budget per ablation run")
    ap.add_argument("--ablation-epochs", type=int, default=35)
    ap.add_argument("--skip-train", action="store_true", help="reuse ablation weights already in var/")
    ap.add_argument("--sheet-only", action="store_true", help="only draw the contact sheets")
    ap.add_argument("--machine", default=f"{os.cpu_count()} CPUs ({platform.machine()}), no GPU used, 1 torch thread",
                    help="description of the machine recorded in the results")
    ap.add_argument("--out", default=str(doc_tables.DOCS / "gesture.json"), help="JSON results")
    ap.add_argument("--sheet", default=str(ROOT / "docs" / "img" / "gesture_contact_sheet.png"))
    ap.add_argument("--arousal-sheet", default=str(ROOT / "docs" / "img" / "gesture_arousal_sheet.png"))
    return ap.parse_args(argv)


def _comparisons(args) -> dict[str, str]:
    """Comparison weights given on the command line: {label: path}, oldest first."""
    return {label: getattr(args, dest) for dest, label in COMPARISONS.items() if getattr(args, dest)}


def _ablation_rows(data: GestureDataset, test: np.ndarray, blob: dict, args) -> dict:
    """Pose-error rows of the loss ablations (trained here unless ``--skip-train`` finds them in var/)."""
    abl_dir = args.var_dir / "ablations"
    rows = {}
    for name, weights in ABLATIONS.items():
        out = abl_dir / f"{name.replace(' ', '_')}.pt"
        if not (args.skip_train and out.is_file()):
            cfg = TrainConfig(epochs=args.ablation_epochs, max_minutes=args.ablation_minutes, loss=weights,
                              model=GestureNetConfig(**blob["config"]), out=str(out),
                              checkpoint=str(abl_dir / f"{name.replace(' ', '_')}_ckpt.pt"))
            s = train(cfg, data=data, progress=False)
            print(f"{name}: {s['epochs_run']} epochs in {s['seconds']:.0f} s", flush=True)
        b = torch.load(out, weights_only=False)
        rows[name] = {**pose_errors(decode_examples(load_model(out), data, test), data, test),
                      "epochs": b.get("epochs_run"), "seconds": b.get("seconds")}
    return rows


def _pose_table(net, data: GestureDataset, test: np.ndarray, blob: dict, args) -> dict:
    """Seed 003 Table 1 rows: the shipped weights, the comparisons, the ablations (when asked) and two baselines."""
    table = {"all losses (shipped weights)": pose_errors(decode_examples(net, data, test), data, test)}
    for label, path in _comparisons(args).items():
        table[label] = pose_errors(decode_examples(load_model(path), data, test), data, test)
    if args.ablations:
        table.update(_ablation_rows(data, test, blob, args))
    table["baseline: mean pose"] = pose_errors(mean_pose_baseline(data, test), data, test)
    table["baseline: nearest neighbour"] = pose_errors(nearest_neighbour_baseline(data, test), data, test)
    return table


def _rel(path: str) -> str:
    """``path`` relative to the repository when it is inside it."""
    p = Path(path).resolve()
    return str(p.relative_to(ROOT)) if p.is_relative_to(ROOT) else path


def _shipped(path: str, net, blob: dict) -> dict:
    """What the evaluated weights file says about its training."""
    return {"path": _rel(path), "parameters": net.num_parameters(), "epochs": blob.get("epochs_run"),
            "seconds": blob.get("seconds"), "best_val": blob.get("best_val"), "best_epoch": blob.get("best_epoch"),
            "selected_by": blob.get("selected_by"), "train_config": blob.get("train_config", {})}


def _git_commit() -> dict:
    """The checkout's commit and whether tracked files differ from it (None where git is not there)."""
    def git(*a):
        r = subprocess.run(["git", *a], cwd=ROOT, capture_output=True, text=True)
        return r.stdout.strip() if r.returncode == 0 else None

    status = git("status", "--porcelain", "--untracked-files=no")
    return {"commit": git("rev-parse", "HEAD"), "uncommitted_changes": None if status is None else bool(status)}


def _meta(args, argv: list[str], seconds: float) -> dict:
    return {"machine": args.machine, "date": datetime.now(UTC).date().isoformat(), **_git_commit(),
            "seconds": seconds, "command": " ".join(["python -m benchmarks.bench_gesture", *map(shlex.quote, argv)]),
            "weights": _rel(args.weights),
            "comparison_weights": {label: _rel(path) for label, path in _comparisons(args).items()}}


def _print_tables(results: dict, *names: str) -> None:
    tables = doc_tables.render_tables("gesture", results)
    for name in names:
        if name in tables:
            print(f"\n{name}\n" + "\n".join(tables[name]), flush=True)


def _measure(net, args, results: dict) -> None:
    """Every measurement of the shipped weights (and the comparisons) into ``results``."""
    data = build_dataset(cache_dir=args.var_dir)
    test = data.indices("test")
    blob = torch.load(args.weights, weights_only=False)
    results["split"] = {k: int(len(data.indices(k))) for k in ("train", "val", "test")}
    results["shipped"] = _shipped(args.weights, net, blob)
    results["emotion_vad"] = {e: dict(zip(("valence", "arousal", "dominance"), nrc_vad(e))) for e in GESTURE_EMOTIONS}
    results["pose_error_table"] = _pose_table(net, data, test, blob, args)
    if args.ablations:
        results["equal_epoch_validation"] = equal_epoch_validation(blob, args.var_dir / "ablations",
                                                                   args.ablation_epochs)
    results["gt_acceleration"] = float(np.mean([
        upper_body_acceleration(data.rotations[i, : data.lengths[i]], str(data.gender[i]), data.root[i], data.fps)
        for i in test]))
    _print_tables(results, "gesture.pose")
    nets = {**{label: load_model(path) for label, path in _comparisons(args).items()}, SHIPPED: net}
    results["liveliness"] = liveliness_report(nets, data, test, fit_observers(data))
    results["expressiveness"] = results["liveliness"][SHIPPED].pop("expressiveness")
    for v in results["liveliness"].values():
        v.pop("expressiveness", None)
    results["speed"] = speed_benchmark(net)
    results["epoch_timing"] = [epoch_timing(data, "small"), epoch_timing(data, "paper", n_batches=2)]
    contact_sheet(net, Path(args.sheet), SHEET_SENTENCE)
    results["arousal_sheet"] = arousal_sheet(net, Path(args.arousal_sheet))
    _print_tables(results, *(n for n in doc_tables.TABLES["gesture"] if n not in ("gesture.run", "gesture.pose")))


def _json_default(o):
    if isinstance(o, np.integer):
        return int(o)
    return float(o) if isinstance(o, np.floating) else str(o)


def main(argv=None) -> int:
    one_thread()
    prepare_render_process()
    argv = sys.argv[1:] if argv is None else list(argv)
    args = _args(argv)
    args.var_dir = config.var_dir(os.environ)   # caches and ablation weights: $GESTURE_VAR_DIR, else var/gesture
    torch.set_num_threads(1)
    torch.manual_seed(0)
    t_start = time.time()
    net = load_model(args.weights)
    if args.sheet_only:
        contact_sheet(net, Path(args.sheet), SHEET_SENTENCE)
        print(json.dumps(arousal_sheet(net, Path(args.arousal_sheet)), indent=1))
        return 0
    results: dict = {}
    _measure(net, args, results)
    results = {"meta": _meta(args, argv, time.time() - t_start), **results}
    doc_tables.write_results("gesture", args.out, results, results["meta"]["seconds"], default=_json_default)
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
