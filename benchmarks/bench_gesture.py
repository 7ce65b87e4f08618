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

from generation.core.quaternion import np_qnormalize  # noqa: E402
from generation.core.skeleton import gesture_skeleton  # noqa: E402
from generation.gesture import config  # noqa: E402
from generation.gesture.data import GestureDataset, attribute_vector, build_dataset, nrc_vad  # noqa: E402
from generation.gesture.generate import decode_examples, generate_gesture, load_model  # noqa: E402
from generation.gesture.losses import LossWeights  # noqa: E402
from generation.gesture.metrics import (  # noqa: E402
    dataset_pose_error,
    upper_body_acceleration,
    wrist_speed,
    wrist_speed_of_positions,
)
from generation.gesture.model import GestureNetConfig  # noqa: E402
from generation.gesture.train import TrainConfig, train  # noqa: E402
from generation.quality.gesture_observer import corpus_descriptors, motion_descriptors, positions_of  # noqa: E402
from study_protocol import GESTURE_EMOTIONS  # noqa: E402

MACHINE = "2-core CI VM, no GPU, shared with parallel jobs"
DATE = "2026-12-02"
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
    ([(example index, emotion, vad)], a GestureDataset of those len(idx) x 11 inputs; its rotations are the
    example's own, not a gesture of the new emotion)."""
    rows = [(i, emo, nrc_vad(emo)) for i in idx for emo in GESTURE_EMOTIONS]
    tokens = np.stack([data.tokens[i] for i, _, _ in rows])
    attrs = np.stack([attribute_vector(data.row(i).task, vad, str(data.gender[i]), str(data.handedness[i]))
                      for i, _, vad in rows]).astype(np.float32)
    src = np.array([i for i, _, _ in rows])
    fake = GestureDataset(tokens=tokens, token_lengths=data.token_lengths[src], rotations=data.rotations[src],
                          lengths=data.lengths[src], attributes=attrs, offsets=data.offsets[src], rest=data.rest[src],
                          root=data.root[src], vad=np.array([v for _, _, v in rows], dtype=np.float32),
                          sentence_index=data.sentence_index[src], split=np.array(["test"] * len(rows)),
                          gender=data.gender[src], handedness=data.handedness[src], rows=data.rows, fps=data.fps,
                          emotion=np.array([e for _, e, _ in rows]))
    return rows, fake


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


# ---- liveliness (issue 14) ------------------------------------------------------------------------------
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


# ---- device timing (issue 19) ----------------------------------------------------------------------------
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


REAL_SECTION_MARKER = "<!-- real-capture section (benchmarks/bench_gesture_real.py); kept by bench_gesture.py -->"


def keep_real_section(old: str, new: str) -> str:
    """``new`` followed by the real-capture section of ``old`` (from REAL_SECTION_MARKER on), so a rerun of this
    benchmark keeps the section written from benchmarks/bench_gesture_real.py's measurements."""
    at = old.find(REAL_SECTION_MARKER)
    return new if at < 0 else new.rstrip("\n") + "\n\n" + old[at:]


# ---- main -------------------------------------------------------------------------------------------
def _args(argv):
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--weights", default=str(config.DEFAULT_WEIGHTS))
    ap.add_argument("--before-weights", default=None,
                    help="weights to compare against (column 'before'), e.g. the previous shipped file: git show "
                         "<commit>:generation/data/weights/gesture_net_default.pt > var/gesture/before.pt")
    ap.add_argument("--original-weights", default=None,
                    help="a second comparison (column 'before issue 14'): the weights before issue 14 (git show "
                         "0a1ffd3:generation/data/weights/gesture_net_default.pt > "
                         "var/gesture/gesture_net_before_issue14.pt)")
    ap.add_argument("--ablations", action="store_true", help="train and evaluate the loss ablations (slow)")
    ap.add_argument("--ablation-minutes", type=float, default=20.0, help="wall-clock budget per ablation run")
    ap.add_argument("--ablation-epochs", type=int, default=35)
    ap.add_argument("--skip-train", action="store_true", help="reuse ablation weights already in var/")
    ap.add_argument("--sheet-only", action="store_true", help="only draw the contact sheets")
    ap.add_argument("--out", default=str(ROOT / "docs" / "benchmarks" / "gesture.md"))
    ap.add_argument("--sheet", default=str(ROOT / "docs" / "img" / "gesture_contact_sheet.png"))
    ap.add_argument("--arousal-sheet", default=str(ROOT / "docs" / "img" / "gesture_arousal_sheet.png"))
    return ap.parse_args(argv)


COMPARISON_NAMES = {"before issue 14": "eqs. 8-10 only (git 0a1ffd3)",
                    "before": "previous shipped weights (first issue-14 fix)"}


def _comparisons(args) -> dict[str, str]:
    """Comparison weights by column label, oldest first: {"before issue 14": path, "before": path} as given."""
    pairs = (("before issue 14", args.original_weights), ("before", args.before_weights))
    return {label: path for label, path in pairs if path}


def _pose_table(net, data: GestureDataset, test: np.ndarray, blob: dict, args) -> dict:
    """Seed 003 Table 1 rows: the shipped weights, the ablations (when asked) and the two baselines."""
    table = {"all losses (shipped weights)": pose_errors(decode_examples(net, data, test), data, test)}
    for label, path in _comparisons(args).items():
        table[f"{label}: {COMPARISON_NAMES[label]}"] = pose_errors(decode_examples(load_model(path), data, test),
                                                                   data, test)
    if args.ablations:
        abl_dir = config.VAR_DIR / "ablations"
        for name, weights in ABLATIONS.items():
            out = abl_dir / f"{name.replace(' ', '_')}.pt"
            if not (args.skip_train and out.is_file()):
                cfg = TrainConfig(epochs=args.ablation_epochs, max_minutes=args.ablation_minutes, loss=weights,
                                  model=GestureNetConfig(**blob["config"]), out=str(out),
                                  checkpoint=str(abl_dir / f"{name.replace(' ', '_')}_ckpt.pt"))
                s = train(cfg, data=data, progress=False)
                print(f"{name}: {s['epochs_run']} epochs in {s['seconds']:.0f} s", flush=True)
            b = torch.load(out, weights_only=False)
            table[name] = {**pose_errors(decode_examples(load_model(out), data, test), data, test),
                           "epochs": b.get("epochs_run"), "seconds": b.get("seconds")}
    table["baseline: mean pose"] = pose_errors(mean_pose_baseline(data, test), data, test)
    table["baseline: nearest neighbour"] = pose_errors(nearest_neighbour_baseline(data, test), data, test)
    return table


def main(argv=None):
    args = _args(argv)
    torch.set_num_threads(1)
    torch.manual_seed(0)
    net = load_model(args.weights)
    if args.sheet_only:
        contact_sheet(net, Path(args.sheet), SHEET_SENTENCE)
        print(json.dumps(arousal_sheet(net, Path(args.arousal_sheet)), indent=1))
        return
    data = build_dataset()
    test = data.indices("test")
    blob = torch.load(args.weights, weights_only=False)
    results: dict = {"machine": MACHINE, "date": DATE, "n_test": int(len(test)),
                     "n_train": int(len(data.indices("train"))), "n_val": int(len(data.indices("val"))),
                     "shipped": {"epochs": blob.get("epochs_run"), "seconds": blob.get("seconds"),
                                 "parameters": net.num_parameters(), "best_val": blob.get("best_val"),
                                 "best_epoch": blob.get("best_epoch"),
                                 "train_config": blob.get("train_config", {})}}
    results["comparisons"] = {k: v for k, v in (("original_weights", args.original_weights),
                                                 ("before_weights", args.before_weights)) if v}
    results["pose_error_table"] = _pose_table(net, data, test, blob, args)
    results["gt_acceleration"] = float(np.mean([
        upper_body_acceleration(data.rotations[i, : data.lengths[i]], str(data.gender[i]), data.root[i], data.fps)
        for i in test]))
    print(json.dumps(results["pose_error_table"], indent=1), flush=True)
    observers = fit_observers(data)
    nets = {**{label: load_model(path) for label, path in _comparisons(args).items()}, "after": net}
    results["liveliness"] = liveliness_report(nets, data, test, observers)
    results["expressiveness"] = results["liveliness"]["after"].pop("expressiveness")
    for label in nets:
        results["liveliness"][label].pop("expressiveness", None)
    results["speed"] = speed_benchmark(net)
    results["epoch_timing"] = [epoch_timing(data, "small"), epoch_timing(data, "paper", n_batches=2)]
    print(json.dumps({k: results[k] for k in ("speed", "epoch_timing")}, indent=1), flush=True)
    contact_sheet(net, Path(args.sheet), SHEET_SENTENCE)
    results["arousal_sheet"] = arousal_sheet(net, Path(args.arousal_sheet))
    config.VAR_DIR.mkdir(parents=True, exist_ok=True)
    (config.VAR_DIR / "bench.json").write_text(json.dumps(results, indent=1, default=float))
    out = Path(args.out)
    out.write_text(keep_real_section(out.read_text() if out.is_file() else "", render_markdown(results)))
    print(f"wrote {args.out}")


def render_markdown(r: dict) -> str:
    lines = _md_intro(r) + _md_pose(r) + _md_liveliness(r) + _md_expressiveness(r) + _md_speed(r)
    return "\n".join(lines)


def _md_intro(r: dict) -> list[str]:
    sh = r["shipped"]
    tc = sh.get("train_config") or {}
    init = (f" Fine-tuned from the previous shipped weights (`{tc['init_from']}`, themselves fine-tuned from the "
            "230-epoch weights of eqs. 8-10 only, git 0a1ffd3)" if tc.get("init_from") else "")
    if tc.get("augment"):
        init += (f" with {tc['augment']} phrase-recombination training sentences added (`--augment "
                 f"{tc['augment']}`, section \"Third pass\")")
    return [
        "## Gesture network (seed 003 Text2Gestures)",
        "",
        f"Machine: {r['machine']}; date {r['date']}; produced by `python benchmarks/bench_gesture.py "
        + " ".join(f"--{k.replace('_', '-')} {v}" for k, v in (r.get("comparisons") or {}).items()) + "`.",
        "",
        "All numbers are on the **synthetic** corpus: 330 project-written sentences (11 MPI emotions x 30, narration "
        "and conversation), each paired with 2 procedural seated gestures of its own emotion and 1 of another, "
        "randomly drawn emotion (the counterfactual variant, so that the emotion attributes and not only the wording "
        "decide the style), random gender and handedness; split 80/10/10 by sentence "
        f"({r['n_train']} / {r['n_val']} / {r['n_test']} examples). The ground truth is procedural motion, not "
        "motion capture, so the numbers say how well the network learns the text/attribute -> gesture mapping of "
        "the procedural generator, not how human the gestures are. In that corpus each phrase of a sentence (cut "
        "at punctuation) gets one gesture whose kind follows its words (deictic words -> pointing, aroused or "
        "exclaimed -> beat, else descriptive), whose style follows the emotion's VAD (arousal -> speed, amplitude, "
        "head motion; dominance -> expansion, upright trunk) and the task (narration 1.2x, conversation 0.8x "
        "amplitude), with small per-example variation; the length is 0.5 s + 0.4 s per word + 1 s.",
        "",
        f"Shipped weights: {sh['parameters']:,} parameters, {sh['epochs']} epochs in {sh['seconds'] / 60:.1f} min on "
        f"one thread (network at 10 fps; the weights after epoch {(sh.get('best_epoch') or 0) + 1} are kept)."
        f"{init}, with the velocity and liveliness losses, all decoder inputs self-fed (3 no-grad passes) and the "
        "weights chosen by validation pose error x (1 + wrist-speed gap). Until this version that choice did "
        "nothing on the CPU (the kept \"best\" state shared the parameters' storage, so every CPU run saved its last "
        "epoch; fixed in `generation.core.device.cpu_state_dict`, which now always copies): the previous shipped "
        "file holds its last epoch (31 of 31), not the epoch 15 it named, and so do runs A-G of the second pass.",
        "",
    ]


def _md_pose(r: dict) -> list[str]:
    lines = [
        "### Mean pose error on held-out sentences (seed 003 Table 1 layout)",
        "",
        "Mean over test sequences of (mean joint distance over all frames and joints) / (ground truth's bounding-box "
        "diagonal); the network generates from text and attributes alone (autoregressive, never sees the ground "
        "truth). Paper: 0.05 for all losses, 0.06-0.07 for the ablations, 1.57 for Yoon et al. Speed gap = mean "
        "over sequences of |log(generated / corpus)| of the mean and peak wrist speed (0 = as lively as the corpus).",
        "",
        "| Method | Mean pose error | Upper body (8 joints) | Rotation error (deg) | Upper-body accel. (m/s^2) "
        "| Speed gap |",
        "|---|---|---|---|---|---|",
    ]
    for name, v in r["pose_error_table"].items():
        lines.append(f"| {name} | {v['pose_error']:.4f} | {v['pose_error_upper']:.4f} | "
                     f"{v['rotation_error_deg']:.2f} | {v['acceleration']:.3f} | {v['speed_log_ratio']:.3f} |")
    lines += ["", f"Ground truth (procedural) upper-body acceleration: {r['gt_acceleration']:.3f} m/s^2 (a jerkiness "
              "measure: mean magnitude of the second time difference of the 8 upper-body joints at 10 fps).", "",
              "The loss ablations (eqs. 8-10, one term removed each) were measured for the previous losses and are "
              "in this file's git history; they were not retrained with the velocity and liveliness terms on this "
              "shared CPU (`--ablations` does it).", ""]
    return lines


def _md_liveliness(r: dict) -> list[str]:
    live = r["liveliness"]
    after = live["after"]
    lines = [
        "### Liveliness (issue 14): wrist speed, generated vs corpus",
        "",
        "Cause of the sluggish gestures before: the network regressed to the mean pose. Its losses (eqs. 8-10) "
        "weigh the wrists as 2 of 23 joints, and where the stroke phase is uncertain a damped, averaged stroke has "
        "the smallest squared error; and the weights were chosen by pose error alone, which rewards the same thing. "
        "Teacher-forced on training sentences (ground-truth history) the old network was already as slow as when "
        "generating (afraid: mean wrist speed 0.19 m/s vs 0.40 in the corpus), so the objective, not the "
        "teacher-forcing mismatch, was the main cause. Output smoothing was not: only the first 0.2 s and last "
        "0.3 s are eased onto the rest pose. Fix: a joint-velocity loss (seed 003 trains on velocities too) and a "
        "liveliness loss on each sequence's wrist-speed statistics (mean and RMS; phase-independent); all decoder "
        "inputs self-fed during training (3 no-grad passes), so those losses act on inputs like the ones the "
        "decoder feeds itself when generating; weights chosen by pose error x (1 + speed gap); and "
        "counterfactual-emotion variants in the corpus, so the emotion attributes, not only the wording, carry "
        "arousal (the r over 11 emotions per sentence needs that). The parts were not ablated one by one (CPU time).",
        "",
        f"Held-out examples ({after['n']}: the test sentences with their own and counterfactual attributes), each "
        "generated from its own text and attributes and compared with its procedural gesture. Wrist speed = the "
        "faster wrist's speed per frame (m/s, 10 fps); mean = its clip mean, peak = its 90th percentile; each cell "
        "the mean over the emotion's examples; ratio = generated / corpus (goal: within 0.75-1.25).",
        "",
    ]
    who = list(live)  # comparisons oldest first, then "after"
    head = "| Emotion | arousal | n | corpus mean | corpus peak |"
    for k in who:
        head += f" {k}: mean (ratio) | {k}: peak (ratio) |"
    lines += [head, "|" + "---|" * (5 + 2 * len(who))]
    for emo, c in sorted(after["per_emotion"].items(), key=lambda kv: nrc_vad(kv[0])[1]):
        row = f"| {emo} | {nrc_vad(emo)[1]:.3f} | {c['n']} | {c['corpus_mean']:.3f} | {c['corpus_peak']:.3f} |"
        for k in who:
            v = live[k]["per_emotion"][emo]
            row += (f" {v['gen_mean']:.3f} ({v['gen_mean'] / c['corpus_mean']:.2f}) |"
                    f" {v['gen_peak']:.3f} ({v['gen_peak'] / c['corpus_peak']:.2f}) |")
        lines.append(row)
    lines += ["", "| Measure | corpus | " + " | ".join(who) + " |", "|---|---|" + "---|" * len(who),
              "| r(peak wrist speed, arousal), own attributes | " + f"{after['r_corpus']:.3f} | "
              + " | ".join(f"{live[k]['r_gen']:.3f}" for k in who) + " |",
              f"| r(peak wrist speed, arousal), each test sentence x 11 emotions ({after['n_all_emotions']}) | "
              f"{r['expressiveness']['r_speed_arousal_procedural']:.3f} (held-out, own) | "
              + " | ".join(f"{live[k]['r_all_emotions']:.3f}" for k in who) + " |",
              "| largest per-emotion ratio gap (mean or peak) | 0 | "
              + " | ".join(f"{live[k]['worst_ratio_gap']:.2f}" for k in who) + " |", ""]
    lines += _md_all_emotions(live, who)
    sheet = r.get("arousal_sheet") or []
    if sheet:
        lines += ["`docs/img/gesture_arousal_sheet.png`: one sentence (\"" + AROUSAL_SHEET_SENTENCE + "\") said by "
                  "the same seated agent with the three lowest-arousal emotions (top row) and the three "
                  "highest-arousal ones (bottom row), upper body; each tile is the mannequin at the moment of the "
                  "fastest wrist movement over blue-tinted ghosts of 16 frames of the whole clip, so the space the "
                  "arms swept shows as a trail. "
                  "Wrist speeds of those clips: " + "; ".join(f"{t['emotion']} mean {t['mean']:.2f} / peak "
                                                               f"{t['peak']:.2f} m/s" for t in sheet) + ". "
                  "Seen on the sheet (shipped weights): in the top row the forearms stay forward over the lap and "
                  "the ghost trails are short, around the hands (sad also lowers and turns the head); in the bottom "
                  "row the trunk is more upright and the right arm swings out and down beside the body in a wide "
                  "arc, so its trail fans over a much larger area.", ""]
    return lines + _md_second_pass() + _md_third_pass()


def _md_all_emotions(live: dict, who: list[str]) -> list[str]:
    """The liveliness table over every test example x 11 emotions (:func:`liveliness_all_emotions`)."""
    after = live["after"]["all_emotions"]
    lines = [
        f"The same ratio over every held-out example with each of the 11 emotions ({after['n']} gestures, "
        f"{after['n'] // 11} per emotion instead of the 8-12 examples that carry each emotion in the test split): "
        "each generated from the example's sentence, task, body and handedness with the emotion's attributes, "
        "against the procedural gesture the corpus makes for the same sentence and attributes (as its "
        "counterfactual variants are made). With 8-12 examples a cell moves by about 0.05 between equally good "
        "runs, as much as the margins that decide it; with 99 the figure is steadier.",
        "",
        "| Emotion | corpus mean | corpus peak | " + " | ".join(f"{k}: mean / peak ratio" for k in who) + " |",
        "|---|---|---|" + "---|" * len(who),
    ]
    for emo, c in sorted(after["per_emotion"].items(), key=lambda kv: nrc_vad(kv[0])[1]):
        row = f"| {emo} | {c['corpus_mean']:.3f} | {c['corpus_peak']:.3f} |"
        for k in who:
            v = live[k]["all_emotions"]["per_emotion"][emo]
            row += f" {v['gen_mean'] / v['corpus_mean']:.2f} / {v['gen_peak'] / v['corpus_peak']:.2f} |"
        lines.append(row)
    lines += ["| cells in band (of 22) | | | " + " | ".join(str(live[k]["all_emotions"]["cells_in_band"])
                                                    for k in who) + " |",
              "| largest ratio gap | | | " + " | ".join(f"{live[k]['all_emotions']['worst_ratio_gap']:.2f}"
                                                  for k in who) + " |", ""]
    return lines


# Runs of the second issue-14 pass (2026-12-02), each fine-tuned from the shipped weights on the same 2 shared
# cores (training histories in the weights files, var/gesture/candidates/): test split, as the table above.
SECOND_PASS_RUNS = [
    # run, liveliness loss and options, minutes / epochs, kept epoch, cells in 0.75-1.25, joyous mean ratio,
    # neutral peak ratio, worst |ratio - 1|, r(peak, arousal) own attributes, mean pose error, validation cells
    ("shipped (first fix)", "mean + RMS, (m/s)^2, weight 2", "20 / 31", 15, 20, 0.669, 1.266, 0.33, 0.630, 0.0093,
     21),
    ("A", "log_peak, weight 2, select-emotion-gap", "18 / 30", 5, 21, 0.746, 1.150, 0.25, 0.547, 0.0086, 21),
    ("B", "log_peak, weight 6, select-emotion-gap", "18 / 30", 30, 21, 0.687, 1.200, 0.31, 0.504, 0.0093, 20),
    ("C", "6 statistics incl. peak, (m/s)^2, weight 3, gap, rollout every 2", "15 / 27", 8, 19, 0.642, 1.204, 0.36,
     0.593, 0.0087, 18),
    ("D", "as C, weight 8", "15 / 27", 4, 20, 0.637, 1.252, 0.36, 0.555, 0.0088, 19),
    ("E", "as A, from A, lr 3e-4, rollout every epoch", "12 / 30", 18, 21, 0.711, 1.172, 0.29, 0.544, 0.0079, 19),
    ("G", "as A, 15% of word tokens hidden per batch, rollout every 2", "14 / 71", 58, 20, 0.695, 1.195, 0.31,
     0.470, 0.0084, 19),
]


def _md_second_pass() -> list[str]:
    lines = [
        "#### Joyous and neutral (second pass): cause and runs",
        "",
        "After the first fix two cells stayed outside 0.75-1.25: joyous' mean speed (0.67) and neutral's peak (1.27). "
        "Cause, in the corpus: each phrase's gesture kind follows its words (deictic words -> pointing; arousal "
        ">= 0.6 or a final '!' -> beat; otherwise descriptive), its speed and amplitude follow arousal and its "
        "expansion dominance. Joyous (arousal 0.58, dominance 0.73) is the most aroused, expansive emotion below the "
        "beat threshold, so its descriptive phrases are the fastest motion in the corpus (training sentences: 0.88 "
        "m/s mean) while its pointing phrases move at 0.45 m/s, the largest difference between kinds of any emotion; "
        "emotions above 0.6 make smaller beats, which is why joyous (0.84 m/s on the test sentences) is faster than "
        "proud or angry (about 0.47). Neutral is the mirror case: descriptive peak 0.44 m/s, pointing peak 0.95. "
        "Nothing the network cannot see decides this: the kind follows the words, which it reads, and the style "
        "follows the VAD attributes, which identify the emotion (a linear probe on the MiniLM token vectors finds "
        "the deictic words of held-out sentences with 99.5% accuracy, 82% recall). What fails is generalisation "
        "from 264 training sentences: on training sentences the shipped network's joyous descriptive gestures reach "
        "0.93 of the corpus mean speed, on held-out sentences 0.68, and neutral's held-out descriptive gestures "
        "peak toward its pointing peak; on unseen text the network hedges between the kinds. The held-out joyous "
        "examples are 7 of 8 descriptive and neutral's all descriptive, which exposes the hedge; the validation "
        "split shows the same joyous shortfall (0.70).",
        "",
        "Tried (all fine-tuned from the shipped weights, niced on the shared 2 cores): the liveliness loss on the "
        "faster wrist's clip mean and 90th percentile as well (the statistics this table reports) and as squared "
        "log ratios (`--liveliness-form log_peak`), or as squared m/s differences; weights chosen by pose error x "
        "(1 + speed gap + worst per-emotion speed gap on the validation split) (`--select-emotion-gap`). "
        "Neutral's peak came into the band in every run but D; joyous' mean did not (0.64-0.746), and r fell to "
        "0.47-0.59. Between runs the cells move by about 0.05, as much as the changes did; the epoch counts differ "
        "with the load of the shared CPU (11-40 s per epoch). "
        "The goal (all 22 cells) was not reached then, so those weights were not shipped and these options are off "
        "by default.",
        "",
        "Kept epoch: the one each file names; because of the selection bug (above), each holds its last epoch.",
        "",
        "| Run | liveliness loss, options | min / epochs | kept epoch (named) | cells in band | joyous mean "
        "| neutral peak | worst gap | r (own) | pose error | cells in band, validation |",
        "|---|---|---|---|---|---|---|---|---|---|---|",
    ]
    for run in SECOND_PASS_RUNS:
        name, loss, budget, kept, cells, joy, neu, worst, r, pose, val = run
        lines.append(f"| {name} | {loss} | {budget} | {kept} | {cells}/22 | {joy:.3f} | {neu:.3f} | {worst:.2f} | "
                     f"{r:.3f} | {pose:.4f} | {val}/22 |")
    return lines + [
        "",
        "Commands: `python -m generation.gesture.train --init-from <shipped weights> --lr 5e-4 --sampling-ramp 2 "
        "--max-minutes 18 --device cpu --liveliness-form log_peak --liveliness-weight 2 --select-emotion-gap` (A; "
        "C and D used a squared-m/s form with the peak terms, G a token dropout; neither was kept). Note that "
        "`--seed` also changes the sentence split, so a run with another seed cannot be compared on this test "
        "split. Next steps: more "
        "(or paraphrased) training sentences so the network learns the kind from the words rather than the "
        "sentence, or a gesture-kind input; the margin is small (run A: joyous 0.746).",
        "",
    ]


# Runs of the third issue-14 pass (2026-12-02): each fine-tuned from the second pass's shipped weights with the
# shipped recipe (plus the options named), weight selection fixed; histories in the weights files
# (var/gesture/aug/). Columns: run, options, epochs (kept), test cells (8-12 per emotion), validation cells, test
# cells over 11 emotions (99 per emotion), validation cells over 11 emotions, r own / 11 emotions (test),
# pose error test / validation. None = not measured.
THIRD_PASS_RUNS = [
    ("previous shipped (second pass)", "-", "31 (31)", 20, 21, 22, 21, "0.630 / 0.610", "0.0093 / 0.0085"),
    ("control", "--augment 0", "146 (115)", 20, 22, 22, 22, "0.622 / 0.580", "0.0080 / 0.0073"),
    ("**aug1000 (shipped)**", "--augment 1000", "63 (55)", 21, 22, 22, 22, "0.687 / 0.660", "0.0065 / 0.0057"),
    ("aug1000, 30 min more", "--augment 1000 --resume", "186 (125)", 21, 21, 22, 22, "0.681 / 0.588",
     "0.0074 / 0.0056"),
    ("aug1000 + run A's options", "--augment 1000 --liveliness-form log_peak --select-emotion-gap", "121 (115)", 20,
     22, None, None, "0.553 / 0.539", "0.0068 / 0.0065"),
    ("aug2000", "--augment 2000", "64 (60)", 22, 21, 22, 22, "0.642 / 0.547", "0.0086 / 0.0062"),
]


def _md_third_pass() -> list[str]:
    lines = [
        "#### Third pass: more training sentences (phrase recombination)",
        "",
        "The second pass traced the two cells to generalisation from 264 training sentences. "
        "`build_dataset(augment=N)` / `train --augment N` (`data.augment_rows`) adds N SYNTHETIC training sentences, "
        "each joining a run of phrases of one training sentence with a run of another's (e.g. \"Did you hear that "
        "noise coming from the basement? I'm so glad that's over.\"), with an emotion drawn evenly over the 11, so "
        "wording and emotion are decorrelated and every emotion meets every gesture kind (joyous gets 147 "
        "descriptive phrases among 1000 new sentences; the training split has 16). Each gets one procedural gesture "
        "of its emotion. Validation and test sentences are never sources; the split and the held-out examples are "
        "those of `augment=0`, so the tables compare like with like.",
        "",
        "Chosen on the validation split (every cell in band on both validation measures, then the lowest validation "
        "pose error): **aug1000**, now shipped. On the test split it has 21 of 22 cells in band with 8-12 examples "
        "per emotion (proud mean 0.744) and 22 of 22 with 99 per emotion (largest gap 0.23); r(peak wrist speed, "
        "arousal) 0.687 (own attributes) and 0.660 (11 emotions); mean pose error 0.0065 (before 0.0093). What "
        "moved the two cells is the augmentation, not the selection fix: the control with the fix and no "
        "augmentation leaves joyous mean (0.703) and neutral peak (1.341) out, every augmented run with the shipped "
        "loss brings them in (joyous mean 0.761-0.785, neutral peak 1.135-1.249). On 99 examples per emotion the "
        "previous weights were already in band on the test split (largest gap 0.22) but not on validation "
        "(joyous mean 0.7497).",
        "",
        "| Run | options | epochs (kept) | test cells, 8-12 per emotion | validation cells | test cells, 99 per "
        "emotion | validation cells, 99 per emotion | r own / 11 emotions | pose error test / validation |",
        "|---|---|---|---|---|---|---|---|---|",
    ]
    cell = lambda v: "-" if v is None else f"{v}/22"  # noqa: E731
    for name, opts, epochs, test, val, test99, val99, r, pose in THIRD_PASS_RUNS:
        lines.append(f"| {name} | `{opts}` | {epochs} | {cell(test)} | {cell(val)} | {cell(test99)} | {cell(val99)} "
                     f"| {r} | {pose} |")
    return lines + [
        "",
        "Commands: `python -m generation.gesture.train --init-from <previous shipped weights> --lr 5e-4 "
        "--sampling-ramp 2 --max-minutes 25 --device cpu --threads 1 --augment 1000` (aug1000; 10-28 s per epoch "
        "on the shared cores; building the 1000 sentences' gestures and token vectors takes 19 s). One run per "
        "setting: whether 2000 sentences beat 1000 or were luckier on test is not known; measuring the spread "
        "needs an augmentation seed apart from `--seed` (which also moves the split).",
        "",
    ]


def _md_expressiveness(r: dict) -> list[str]:
    e = r["expressiveness"]
    lines = [
        "### Emotional expressiveness",
        "",
        f"Each held-out example's sentence generated with each of the 11 emotions ({e['n_generated']} gestures). "
        "Speed = peak wrist speed as above; expansion = mean wrist spread d(l_wrist, r_wrist) / d(root, head).",
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
    return lines + [""]


def _md_speed(r: dict) -> list[str]:
    s = r["speed"]
    lines = [
        "### Generation and training speed",
        "",
        f"`generate_gesture` on {s['sentences']} corpus sentences, one at a time, output at 30 fps, one CPU thread, "
        f"median of {s['repeats']} passes: **{s['output_fps']:.0f} output frames per second** "
        f"({s['ms_per_output_frame']:.2f} ms per frame; {s['network_steps_per_s']:.0f} network steps per second at "
        f"10 fps, text encoding and resampling included; passes ranged {s['output_fps_min']:.0f}-"
        f"{s['output_fps_max']:.0f} fps). Paper: 312.5 fps (3.2 ms per frame) on a GTX 1080Ti. The 2 cores are shared "
        "with other jobs, so the figure depends on their load.",
        "",
        "| Training preset | parameters | s per batch of 16 (CPU, 1 thread) | batches per epoch | s per epoch "
        "(extrapolated) | epochs |",
        "|---|---|---|---|---|---|",
    ]
    for t in r.get("epoch_timing", []):
        lines.append(f"| {t['preset']} | {t['parameters']:,} | {t['seconds_per_batch']:.2f} (mean of "
                     f"{t['timed_batches']} timed batches) | {t['batches_per_epoch']} | {t['seconds_per_epoch']:.0f} | "
                     f"{t['epochs']} |")
    lines += ["", "A batch is a training step as the shipped run takes it: 3 no-grad self-feeding passes, the "
              "teacher-forced pass and the backward pass; an epoch also runs the validation pass and, every 5 "
              "epochs, generates the validation gestures (not included). GPU: not measured, no GPU lent this "
              "session (`--device cuda` and `--amp` are there; see docs/benchmarks/device.md).", "",
              "### Contact sheets", "",
              "`docs/img/gesture_contact_sheet.png`: one sentence said with seven emotions (sad, neutral, relieved, "
              "afraid, angry, amused, proud) by a right-handed agent, and proud by a left-handed one (last row); "
              "`docs/img/gesture_arousal_sheet.png`: see the liveliness section. Seen on the contact sheet "
              "(shipped weights): sad, neutral and relieved hold the right forearm forward at lap height and move "
              "it little (sad with a slumped trunk and lowered head); afraid keeps the arm low and close; angry, "
              "amused and proud raise the right arm out in front with the elbow away from the body, proud the "
              "widest; the left-handed proud agent leads with the left arm; every row starts and ends at the "
              "seated rest pose.", "",
              "Reproduce: `git show 0a1ffd3:generation/data/weights/gesture_net_default.pt > "
              "var/gesture/gesture_net_before_issue14.pt`, then `python -m generation.gesture.train --init-from "
              "var/gesture/gesture_net_before_issue14.pt --lr 5e-4 --sampling-ramp 2 --max-minutes 20 --device cpu` "
              "(the epochs reached in 20 minutes depend on the machine's load), then `python "
              "benchmarks/bench_gesture.py --original-weights var/gesture/gesture_net_before_issue14.pt`.", ""]
    return lines


if __name__ == "__main__":
    main()
