"""Tables of the gesture network (benchmarks/bench_gesture.py; docs/benchmarks/gesture.md)."""
from __future__ import annotations

from benchmarks.doc_renderers.common import Renderer, table


def _by_arousal(r: dict, emotions) -> list[str]:
    """``emotions`` from the lowest to the highest arousal (``r["emotion_vad"]``; given order where it is absent)."""
    vad = r.get("emotion_vad", {})
    return sorted(emotions, key=lambda e: vad.get(e, {}).get("arousal", 0.0))


def _ratio(v: dict, m: str) -> float:
    return v[f"gen_{m}"] / v[f"corpus_{m}"]


def gesture_run(r: dict) -> list[str]:
    """Machine, date, commit, command and the evaluated weights."""
    m, sh, sp = r["meta"], r.get("shipped", {}), r.get("split", {})
    commit = (m.get("commit") or "not recorded")[:12] + (" + uncommitted changes" if m.get("uncommitted_changes")
                                                          else "")
    rows = [["machine", m["machine"]], ["date", m["date"]], ["commit", commit], ["command", f"`{m['command']}`"]]
    if m.get("seconds") is not None:
        rows.append(["duration", f"{m['seconds'] / 60:.1f} min"])
    for label, path in (m.get("comparison_weights") or {}).items():
        rows.append([f"weights '{label}'", f"`{path}`"])
    if sp:
        rows.append(["examples train / validation / test", f"{sp['train']} / {sp['val']} / {sp['test']}"])
    if sh:
        rows.append(["shipped weights", f"{sh['parameters']:,} parameters, {sh['epochs']} epochs in "
                     f"{sh['seconds'] / 60:.1f} min, the weights after epoch {sh['best_epoch'] + 1} kept"])
    if m.get("transcribed_from"):
        rows.append(["transcribed from", m["transcribed_from"]])
    return table(["run", "value"], rows)


def gesture_pose(r: dict) -> list[str]:
    """Seed 003 Table 1 layout, and the procedural ground truth's upper-body acceleration."""
    rows = [[name, f"{v['pose_error']:.4f}", f"{v['pose_error_upper']:.4f}", f"{v['rotation_error_deg']:.2f}",
             f"{v['acceleration']:.3f}", f"{v['speed_log_ratio']:.3f}"] for name, v in r["pose_error_table"].items()]
    if "gt_acceleration" in r:
        rows.append(["ground truth (procedural)", "-", "-", "-", f"{r['gt_acceleration']:.3f}", "-"])
    return table(["Method", "Mean pose error", "Upper body (8 joints)", "Rotation error (deg)",
                  "Upper-body accel. (m/s^2)", "Speed gap"], rows)


def gesture_liveliness(r: dict) -> list[str]:
    """Per emotion: corpus and generated mean / peak wrist speed (ratio) of the held-out examples, per network."""
    live = r["liveliness"]
    last = live[list(live)[-1]]["per_emotion"]
    rows = []
    for emo in _by_arousal(r, last):
        c = last[emo]
        row = [emo, f"{r['emotion_vad'][emo]['arousal']:.3f}", c["n"], f"{c['corpus_mean']:.3f}",
               f"{c['corpus_peak']:.3f}"]
        for v in (live[k]["per_emotion"][emo] for k in live):
            row += [f"{v['gen_mean']:.3f} ({v['gen_mean'] / c['corpus_mean']:.2f})",
                    f"{v['gen_peak']:.3f} ({v['gen_peak'] / c['corpus_peak']:.2f})"]
        rows.append(row)
    return table(["Emotion", "arousal", "n", "corpus mean", "corpus peak",
                  *(f"{k}: {m} (ratio)" for k in live for m in ("mean", "peak"))], rows)


def gesture_liveliness_summary(r: dict) -> list[str]:
    """r(peak wrist speed, arousal) and the largest ratio gap per network."""
    live = r["liveliness"]
    last = live[list(live)[-1]]
    procedural = r.get("expressiveness", {}).get("r_speed_arousal_procedural")
    return table(["Measure", "corpus", *live], [
        ["r(peak wrist speed, arousal), own attributes", f"{last['r_corpus']:.3f}",
         *(f"{v['r_gen']:.3f}" for v in live.values())],
        [f"r(peak wrist speed, arousal), each test sentence x 11 emotions ({last['n_all_emotions']})",
         "-" if procedural is None else f"{procedural:.3f} (held-out, own)",
         *(f"{v['r_all_emotions']:.3f}" for v in live.values())],
        ["largest per-emotion ratio gap (mean or peak)", "0", *(f"{v['worst_ratio_gap']:.2f}" for v in live.values())]])


def gesture_all_emotions(r: dict) -> list[str]:
    """Per emotion: generated / corpus wrist speed over every held-out example x 11 emotions, per network."""
    live = r["liveliness"]
    last = live[list(live)[-1]]["all_emotions"]["per_emotion"]
    rows = [[emo, f"{last[emo]['corpus_mean']:.3f}", f"{last[emo]['corpus_peak']:.3f}",
             *(f"{_ratio(v, 'mean'):.2f} / {_ratio(v, 'peak'):.2f}"
               for v in (live[k]["all_emotions"]["per_emotion"][emo] for k in live))]
            for emo in _by_arousal(r, last)]
    rows.append(["cells in band (of 22)", "", "", *(v["all_emotions"]["cells_in_band"] for v in live.values())])
    rows.append(["largest ratio gap", "", "", *(f"{v['all_emotions']['worst_ratio_gap']:.2f}" for v in live.values())])
    return table(["Emotion", "corpus mean", "corpus peak", *(f"{k}: mean / peak ratio" for k in live)], rows)


def gesture_arousal_sheet(r: dict) -> list[str]:
    """Wrist speeds of the clips on the arousal contact sheet."""
    return table(["Emotion", "arousal", "wrist speed mean (m/s)", "wrist speed peak (m/s)"],
                 [[t["emotion"], f"{t['arousal']:.3f}", f"{t['mean']:.2f}", f"{t['peak']:.2f}"]
                  for t in r["arousal_sheet"]])


def gesture_expressiveness(r: dict) -> list[str]:
    """Correlations and synthetic-observer accuracy, generated vs the procedural ground truth."""
    e = r["expressiveness"]
    return table(["Measure", "Generated", "Procedural ground truth (held-out)"], [
        ["Pearson r(speed, arousal)", f"{e['r_speed_arousal']:.3f} (p = {e['p_speed_arousal']:.2g})",
         f"{e['r_speed_arousal_procedural']:.3f}"],
        ["Pearson r(expansion, dominance)", f"{e['r_expansion_dominance']:.3f} (p = {e['p_expansion_dominance']:.2g})",
         f"{e['r_expansion_dominance_procedural']:.3f}"],
        *([f"Synthetic observer, high vs low {k} (balanced accuracy)", f"{e[f'observer_{k}_generated']:.3f}",
           f"{e[f'observer_{k}_procedural']:.3f}"] for k in ("arousal", "dominance"))])


def gesture_expressiveness_per_emotion(r: dict) -> list[str]:
    per, vad = r["expressiveness"]["per_emotion"], r["emotion_vad"]
    return table(["Emotion", "arousal", "dominance", "mean peak wrist speed (m/s)", "mean expansion"],
                 [[emo, f"{vad[emo]['arousal']:.3f}", f"{vad[emo]['dominance']:.3f}", f"{per[emo]['speed']:.3f}",
                   f"{per[emo]['expansion']:.3f}"] for emo in _by_arousal(r, per)])


def gesture_speed(r: dict) -> list[str]:
    """Generation speed of ``generate_gesture`` (30 fps output, one thread)."""
    s = r["speed"]
    return table(["sentences", "passes", "output frames per s (median)", "range over passes", "ms per output frame",
                  "network steps per s (10 fps)"],
                 [[s["sentences"], s["repeats"], f"{s['output_fps']:.0f}",
                   f"{s['output_fps_min']:.0f}-{s['output_fps_max']:.0f}", f"{s['ms_per_output_frame']:.2f}",
                   f"{s['network_steps_per_s']:.0f}"]])


def gesture_training_speed(r: dict) -> list[str]:
    return table(["Training preset", "parameters", "s per batch of 16 (CPU, 1 thread)", "batches per epoch",
                  "s per epoch (extrapolated)", "epochs"],
                 [[t["preset"], f"{t['parameters']:,}",
                   f"{t['seconds_per_batch']:.2f} (mean of {t['timed_batches']} timed batches)",
                   t["batches_per_epoch"], f"{t['seconds_per_epoch']:.0f}", t["epochs"]] for t in r["epoch_timing"]])


TABLES: dict[str, tuple[str, Renderer]] = {
    "gesture.run": ("meta", gesture_run),
    "gesture.pose": ("pose_error_table", gesture_pose),
    "gesture.liveliness": ("liveliness", gesture_liveliness),
    "gesture.liveliness_summary": ("liveliness", gesture_liveliness_summary),
    "gesture.all_emotions": ("liveliness", gesture_all_emotions),
    "gesture.arousal_sheet": ("arousal_sheet", gesture_arousal_sheet),
    "gesture.expressiveness": ("expressiveness", gesture_expressiveness),
    "gesture.expressiveness_per_emotion": ("expressiveness", gesture_expressiveness_per_emotion),
    "gesture.speed": ("speed", gesture_speed),
    "gesture.training_speed": ("epoch_timing", gesture_training_speed),
}
"""Table name -> (the JSON key it needs, renderer)."""
