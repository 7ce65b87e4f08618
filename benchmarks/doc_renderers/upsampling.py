"""Tables of upsampling the networks' output (benchmarks/bench_upsampling.py; docs/benchmarks/gait.md)."""
from __future__ import annotations

from benchmarks.doc_renderers.common import Renderer, _opt, _run, table

UPSAMPLING = ("slerp", "spline")


def upsampling_run(r: dict) -> list[str]:
    ms = r.get("call_ms")
    extra = [("one call, 10 s walk at 7.5 Hz to 30 fps", " / ".join(f"{m} {ms[m]:.1f} ms" for m in UPSAMPLING))
             ] if ms else []
    return _run(r, *extra)


def upsampling_gestures(r: dict) -> list[str]:
    """Per gesture emotion: jerk and peak hand speed, slerp -> spline."""
    rows = [[emotion, f"{v['slerp']['jerk']:.0f} -> {v['spline']['jerk']:.0f}",
             f"{v['slerp']['peak_hand_speed']:.2f} -> {v['spline']['peak_hand_speed']:.2f}"]
            for emotion, v in r["gestures"].items()]
    return table(["emotion", "jerk m/s^3, slerp -> spline", "peak hand speed m/s"], rows)


def upsampling_real(r: dict) -> list[str]:
    """Per real take: its capture's jerk, then per method the position error and jerk after the round trip."""
    rows = []
    for emotion, row in r["real_round_trip"].items():
        rows.append([emotion, f"{row['take']} ({row['seconds']:.1f} s)", f"{row['capture']['jerk']:.0f}",
                     *(f"{row[m]['position_error_cm']:.2f}" for m in UPSAMPLING),
                     *(f"{row[m]['jerk']:.0f}" for m in UPSAMPLING)])
    return table(["emotion", "real take", "jerk of the capture", *(f"error cm, {m}" for m in UPSAMPLING),
                  *(f"jerk, {m}" for m in UPSAMPLING)], rows)


def upsampling_generated(r: dict) -> list[str]:
    """Per emotion and path: jerk, toe skim and skate of the generated walk, slerp -> spline."""
    rows = []
    for emotion, per_path in r["generated"].items():
        for path, row in per_path.items():
            rows.append([emotion, path, *(f"{_opt(row['slerp'][k], fmt)} -> {_opt(row['spline'][k], fmt)}"
                                          for k, fmt in (("jerk", "{:.0f}"), ("toe_skim", "{:.2f}"),
                                                         ("skate_cm_s", "{:.0f}")))])
    return table(["emotion", "path", "jerk m/s^3, slerp -> spline", "toe skim", "skate cm/s"], rows)


TABLES: dict[str, tuple[str, Renderer]] = {
    "upsampling.run": ("date", upsampling_run),
    "upsampling.real": ("real_round_trip", upsampling_real),
    "upsampling.generated": ("generated", upsampling_generated),
    "upsampling.gestures": ("gestures", upsampling_gestures),
}
"""Table name -> (the JSON key it needs, renderer)."""
