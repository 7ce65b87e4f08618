"""Generated gestures measured against REAL captured ones (seated), before and after the real-range training, and the
real-capture gesture observer's held-out accuracy.

    python -m benchmarks.bench_gesture_real --before var/gesture/realrange/before.pt \
        --after generation/data/weights/gesture_net_default.pt [--sheet docs/img/gesture_real_contact_sheet.png]

Real: the real corpus's dataset-1 gesture takes (bow, bye, byebye, guide) in the styles that name a gesture emotion
(happy = joyous, sad, angry, proud, normal = neutral), seated (generation.mocap.seated_gesture). Generated: every
held-out test example of the sentence corpus (99) said with each of those five emotions (495 per network). Also the
pose error on the test split, r(peak wrist speed, arousal) and generation speed (the 10 % criteria). Writes
``var/gesture/bench_real.json`` and prints markdown tables. Needs the real corpus (var/mocap/bandai-namco.npz).
Real capture: Bandai Namco Research Motion Dataset (Kobayashi et al. 2023, arXiv:2306.08861), CC BY-NC 4.0.
"""
from __future__ import annotations

import argparse
import json
from pathlib import Path

import numpy as np
import torch

from benchmarks.bench_gesture import liveliness, onion_skin, speed_benchmark
from benchmarks.bench_record import one_thread
from generation.gesture.data import build_dataset, with_emotions
from generation.gesture.generate import decode_examples, generate_gesture, load_model
from generation.gesture.metrics import dataset_pose_error, positions
from generation.gesture.real_stats import STAT_NAMES, gesture_stats, in_range_shares, real_ranges
from generation.quality.real_gesture_observer import (
    STYLES_15,
    RealGestureObserver,
    features_of_positions,
    gate_ready,
    held_out_accuracy,
    real_gesture_dataset,
)
from generation.quality.real_gestures import real_gesture_clips, real_stats_table
from generation.render.offscreen import prepare_render_process
from protocol.vocabulary import CAPTURE_GESTURE_EMOTIONS

ROOT = Path(__file__).resolve().parents[1]

EMOTIONS = ("joyous", "sad", "angry", "proud", "neutral")
SHEET_EMOTIONS = ("afraid", "sad", "angry", "joyous", "proud", "neutral")
SHEET_SENTENCE = "We waited at the station for hours, and then the last train finally arrived."
TABLE_STATS = ("wrist_mean", "wrist_p90", "elbow_mean", "reach_p90", "lean_mean", "head_speed", "hold_share")


def generated_stats(net, data, idx) -> list[dict]:
    """Each example of ``idx`` said with each of EMOTIONS: [{"emotion", **gesture_stats}] (len(idx) x 5)."""
    fake = with_emotions(data, idx, EMOTIONS)
    gen = decode_examples(net, fake, np.arange(len(fake)))
    out = []
    for n, g in enumerate(gen):
        P = positions(g, str(fake.gender[n]), fake.root[n])
        out.append({"emotion": str(fake.emotion[n]), "P": P, **gesture_stats(P, fake.fps)})
    return out


def medians(rows: list[dict]) -> dict:
    return {e: {k: float(np.median([r[k] for r in rows if r["emotion"] == e])) for k in STAT_NAMES}
            for e in EMOTIONS if any(r["emotion"] == e for r in rows)}


def network_report(path: str, data, real_obs: RealGestureObserver, ranges: dict,
                   limit: int | None = None) -> dict:
    """The real-vs-generated statistics, pose error, r and speed of one weights file on the test split (its first
    ``limit`` examples when given, for a quick check)."""
    torch.set_num_threads(1)
    net = load_model(path)
    test = data.indices("test")[:limit]
    gen = generated_stats(net, data, test)
    pose = dataset_pose_error(decode_examples(net, data, test), data, test)
    live = liveliness(net, data, test)
    X = np.stack([features_of_positions(r["P"], data.fps) for r in gen])
    read = real_obs.predict(X)
    truth = np.array([r["emotion"] for r in gen])
    return {"weights": path, "medians": medians(gen), "in_range": in_range_shares(gen, ranges),
            "pose_error": pose["pose_error"], "r_peak_arousal": live["r_gen"],
            "real_observer_on_generated": {"accuracy": float((read == truth).mean()),
                                           "per_emotion": {e: {lab: int(((truth == e) & (read == lab)).sum())
                                                               for lab in real_obs.labels} for e in EMOTIONS}}}


def interleaved_speed(report: dict, passes: int) -> None:
    """Generation speed (bench_gesture.speed_benchmark, 10 sentences, output 30 fps) of every measured network,
    one pass of each in turn, ``passes`` times, so that the shared CPU's load falls alike on all; adds
    output_fps (median over passes) and output_fps_range to each network's report."""
    entries = {"before": report["before"], "after": report["after"], **report["candidates"]}
    nets = {k: load_model(v["weights"]) for k, v in entries.items()}
    runs: dict[str, list[float]] = {k: [] for k in entries}
    for _ in range(passes):
        for k, net in nets.items():
            runs[k].append(speed_benchmark(net, n_sentences=10, repeats=1)["output_fps"])
    for k, v in entries.items():
        v["output_fps"], v["output_fps_range"] = float(np.median(runs[k])), [min(runs[k]), max(runs[k])]


def contact_sheet(nets: dict, real: dict, path: Path) -> list[str]:
    """Rows = SHEET_EMOTIONS; columns = the real seated bye take of that emotion, each network's gesture of
    SHEET_SENTENCE with that emotion (female, right-handed, narration); each tile the frame of the fastest wrist
    movement over ghosts of the clip (bench_gesture.onion_skin), upper body."""
    import tempfile

    from PIL import Image, ImageDraw

    from generation.render.clip import render_frames
    from generation.render.contact_sheet import contact_sheet as grid
    from generation.render.settings import RenderSettings

    settings = RenderSettings(width=480, height=480, fps=10.0, camera="fixed", anti_aliasing="none")
    tiles, labels = [], []
    H, W = settings.height, settings.width

    def tile_of(motion, name):
        m = motion.resample(10.0)
        P = m.positions()
        speed = np.linalg.norm(np.diff(P[:, [10, 14]], axis=0), axis=-1).max(1) * m.fps
        frames = [f[: int(0.72 * H), int(0.14 * W): int(0.86 * W)] for f in render_frames(m, settings)]
        out = Path(tmp) / f"{name}.png"
        Image.fromarray(onion_skin(frames, int(np.argmax(speed)) + 1)).save(out)
        return out, gesture_stats(P, m.fps)

    with tempfile.TemporaryDirectory() as tmp:
        for emo in SHEET_EMOTIONS:
            if emo in real:
                t, s = tile_of(real[emo][1], f"real_{emo}")
                tiles.append(t)
                labels.append(f"{emo}: REAL {real[emo][0]} (seated); wrist {s['wrist_mean']:.2f}/{s['wrist_p90']:.2f}"
                              f" m/s, hold {s['hold_share']:.2f}")
            else:
                blank = Path(tmp) / f"none_{emo}.png"
                im = Image.new("RGB", (int(0.72 * W), int(0.72 * H)), "white")
                ImageDraw.Draw(im).text((20, 20), f"no real capture of {emo}", fill=(0, 0, 0))
                im.save(blank)
                tiles.append(blank)
                labels.append(f"{emo}: no real take")
            for who, net in nets.items():
                m = generate_gesture(SHEET_SENTENCE, task="narration", emotion=emo, gender="female",
                                     handedness="right", fps=10.0, model=net)
                t, s = tile_of(m, f"{who}_{emo}")
                tiles.append(t)
                labels.append(f"{emo}: generated {who}; wrist {s['wrist_mean']:.2f}/{s['wrist_p90']:.2f} m/s, "
                              f"hold {s['hold_share']:.2f}")
        grid(tiles, labels, path, columns=1 + len(nets), thumb_width=300)
    return labels


def main(argv=None) -> dict:
    one_thread()
    prepare_render_process()
    p = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    p.add_argument("--before", required=True)
    p.add_argument("--after", required=True)
    p.add_argument("--sheet", default=None, help="write the contact sheet PNG here")
    p.add_argument("--candidates", nargs="*", default=[], help="more weights to measure (the runs not chosen)")
    p.add_argument("--fps-passes", type=int, default=3)
    p.add_argument("--limit", type=int, default=None, help="only the first N test examples (a quick check)")
    p.add_argument("--out", default=str(ROOT / "var" / "gesture" / "bench_real.json"))
    args = p.parse_args(argv)

    real_all = real_gesture_clips(styles=STYLES_15)
    real = [c for c in real_all if c[1] in CAPTURE_GESTURE_EMOTIONS]
    rows = real_stats_table(real)
    ranges = real_ranges(rows)
    X, y, groups = real_gesture_dataset(real_all, "emotion")
    obs_eval = held_out_accuracy(X, y, groups)
    Xs, ys, gs = real_gesture_dataset(real_all, "style")
    style_eval = held_out_accuracy(Xs, ys, gs)
    real_obs = RealGestureObserver(X, y)
    data = build_dataset(augment=0)
    report = {"real": {"n": len(rows), "medians": medians(rows), "ranges": ranges, "takes": [r["name"] for r in rows]},
              "observer_emotions": obs_eval, "observer_styles": style_eval, "gate_ready": gate_ready(obs_eval)}
    for who in ("before", "after"):
        report[who] = network_report(getattr(args, who), data, real_obs, ranges, args.limit)
    report["candidates"] = {c: network_report(c, data, real_obs, ranges, args.limit) for c in args.candidates}
    interleaved_speed(report, args.fps_passes)
    if args.sheet:
        nets = {"before": load_model(args.before), "after": load_model(args.after)}
        bye = {CAPTURE_GESTURE_EMOTIONS[s]: (n, m) for n, s, m in real if n.split("_")[1] == "bye"}
        report["sheet_labels"] = contact_sheet(nets, bye, Path(args.sheet))
    Path(args.out).parent.mkdir(parents=True, exist_ok=True)
    Path(args.out).write_text(json.dumps(report, indent=1, default=float), encoding="utf-8")
    print(render_markdown(report))
    for c, v in report["candidates"].items():
        share = np.mean([x for e in EMOTIONS for x in v["in_range"][e].values()])
        print(f"candidate {c}: share in real range {share:.3f}, pose error {v['pose_error']:.4f}, "
              f"r {v['r_peak_arousal']:.3f}, fps {v['output_fps']:.0f}")
    return report


def render_markdown(r: dict) -> str:
    lines = ["| Emotion | statistic | real median [min, max] (n takes) | before: median (share in real range) | "
             "after: median (share in real range) |", "|---|---|---|---|---|"]
    n_real = {e: sum(1 for t in r["real"]["takes"] if CAPTURE_GESTURE_EMOTIONS.get(t.split("_")[2]) == e)
              for e in EMOTIONS}
    for e in EMOTIONS:
        for k in TABLE_STATS:
            lo, hi = r["real"]["ranges"][e][k]
            cells = [f"{r[w]['medians'][e][k]:.3f} ({r[w]['in_range'][e][k]:.2f})" for w in ("before", "after")]
            lines.append(f"| {e} | {k} | {r['real']['medians'][e][k]:.3f} [{lo:.3f}, {hi:.3f}] ({n_real[e]}) | "
                         + " | ".join(cells) + " |")
    lines += ["", "| Measure | before | after |", "|---|---|---|"]
    for k, label in (("pose_error", "mean pose error (test split)"), ("r_peak_arousal", "r(peak wrist speed, arousal)"),
                     ("output_fps", "generation speed (output fps, median)")):
        lines.append(f"| {label} | {r['before'][k]:.4f} | {r['after'][k]:.4f} |")
    share = {w: np.mean([v for e in EMOTIONS for v in r[w]["in_range"][e].values()]) for w in ("before", "after")}
    lines.append(f"| share in real range (all 5 emotions x 10 statistics) | {share['before']:.3f} | "
                 f"{share['after']:.3f} |")
    acc = {w: r[w]["real_observer_on_generated"]["accuracy"] for w in ("before", "after")}
    lines.append(f"| real observer reads the intended emotion | {acc['before']:.3f} | {acc['after']:.3f} |")
    o, s = r["observer_emotions"], r["observer_styles"]
    lines += ["", f"Real-capture observer, leave one content out: 5 emotions {o['accuracy']:.3f} ({o['n']} takes, "
              f"chance 0.2), per content {o['per_group']}, per class {o['per_class']}; 15 styles {s['accuracy']:.3f} "
              f"({s['n']} takes, chance 0.067); gate ready: {r['gate_ready']}", "",
              "Confusion (rows true, columns predicted, " + ", ".join(o["labels"]) + "): " + str(o["confusion"])]
    return "\n".join(lines)


if __name__ == "__main__":
    main()
