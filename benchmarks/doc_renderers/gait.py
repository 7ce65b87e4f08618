"""Tables of the gait network on synthetic walks (benchmarks/bench_gait.py; docs/benchmarks/gait.md)."""
from __future__ import annotations

from benchmarks.doc_renderers.common import EMOTIONS, Renderer, table


def gait_prediction(r: dict) -> list[str]:
    return table(["method", "pose err / body diag", "pose err cm", "first 10 / last 10 steps cm", "rot err deg (rad)"],
                 [[k, f"{v['pose_error_body_diag']:.3f}", f"{v['pose_error_cm']:.1f}",
                   f"{v['pose_error_first10_cm']:.1f} / {v['pose_error_last10_cm']:.1f}",
                   f"{v['rotation_error_deg']:.1f} ({v['rotation_error_rad']:.3f})"]
                  for k, v in r["prediction"].items()])


def gait_expressiveness(r: dict) -> list[str]:
    rows = []
    for k, v in r["expressiveness"].items():
        pt = v["transition_p_target"]
        rows.append([k, f"{v['own_emotion']['overall']:.2f}",
                     f"{v['other_mixture']['overall']:.2f} / {v['other_mixture_last_third']['overall']:.2f}",
                     f"{v['transition_start']['overall']:.2f} / {v['transition_end']['overall']:.2f}",
                     f"{pt['first_50_steps']:.2f} / {pt['last_50_steps']:.2f} "
                     f"({pt['constant_seed_emotion_last_50']:.2f})"])
    return table(["model", "own emotion", "other mixture (whole / last third)", "transition start / end",
                  "P(target) transition first / last 50 steps (no transition)"], rows)


def _per_class(t: dict) -> list[str]:
    return [f"{t[e]:.2f}" for e in EMOTIONS]


def gait_own_emotion(r: dict) -> list[str]:
    """Own-emotion recognition per class: test walks, the second held-out corpus, procedural seeds."""
    rows = []
    for model, v in r["expressiveness"].items():
        rows.append([model, "test walks", v["own_emotion"].get("n", ""), *_per_class(v["own_emotion"]),
                     f"{v['own_emotion']['overall']:.2f}"])
        untied = v["own_emotion_untied"]
        rows.append([model, "test walks, one dominant label", untied.get("n", ""), *_per_class(untied),
                     f"{untied['overall']:.2f}"])
    for model, v in r.get("own_emotion_heldout_corpus", {}).items():
        for part in ("all", "untied"):
            t = v[part]
            rows.append([model, f"second held-out corpus, {part}", t["n"], *_per_class(t), f"{t['overall']:.2f}"])
    for model, v in r.get("expressiveness_procedural_seeds", {}).items():
        for kind, t in v.items():
            rows.append([model, f"procedural seeds, {kind}", t.get("n", ""), *_per_class(t), f"{t['overall']:.2f}"])
    return table(["model", "seeds", "n", *EMOTIONS, "all"], rows)


def gait_trajectory(r: dict) -> list[str]:
    return table(["model", "mean m", "p95 m", "max m", "at end m", "facing vs travel deg"],
                 [[k, f"{v['mean_m']:.3f}", f"{v['p95_m']:.3f}", f"{v['max_m']:.3f}", f"{v['end_mean_m']:.3f}",
                   f"{v['facing_vs_travel_deg']:.1f}"] for k, v in r["trajectory"].items()])


def gait_long_horizon(r: dict) -> list[str]:
    return table(["steps", "root speed m/s", "pose variance cm^2", "path distance m", "root height m"],
                 [[w["steps"], f"{w['root_speed_m_s']:.2f}", f"{w['pose_variance_cm2']:.0f}",
                   f"{w['path_distance_m']:.3f}", f"{w['root_height_m']:.3f}"] for w in r["long_horizon"]["windows"]])


def gait_speed(r: dict) -> list[str]:
    keys = sorted({k for v in r["speed"].values() for k in v})
    return table(["agents", *keys], [[name, *(f"{v[k]:.2f}" if isinstance(v.get(k), float) else v.get(k, "")
                                             for k in keys)] for name, v in r["speed"].items()])


TABLES: dict[str, tuple[str, Renderer]] = {
    "gait.prediction": ("prediction", gait_prediction),
    "gait.expressiveness": ("expressiveness", gait_expressiveness),
    "gait.own_emotion": ("expressiveness", gait_own_emotion),
    "gait.trajectory": ("trajectory", gait_trajectory),
    "gait.long_horizon": ("long_horizon", gait_long_horizon),
    "gait.speed": ("speed", gait_speed),
}
"""Table name -> (the JSON key it needs, renderer)."""
