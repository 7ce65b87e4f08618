"""Tables of realism by emotion on render-length windows (benchmarks/bench_realism_by_emotion.py;
docs/benchmarks/gait.md)."""
from __future__ import annotations

from benchmarks.doc_renderers.common import Renderer, _run, table
from benchmarks.doc_renderers.gait_real import REALISM_DIGITS, REALISM_LABELS, _sha

SHOWN = ("stance_knee_deg", "pelvis_bounce_cm", "toe_skim", "speed_cv", "skate_cm_s", "skate_ratio")
"""Measures in table order: the four the target names first."""
DIGITS = {**REALISM_DIGITS, "speed_cv": 3}
"""Decimals per measure (default 2); speed CV needs 3 to tell 0.026 from 0.034."""


def _num(v, m: str) -> str:
    return "-" if v is None else f"{v:.{DIGITS.get(m, 2)}f}"


def _verdict(c: dict) -> str:
    """'in', 'in min-max only', '**out**', or 'no data'."""
    if c["p5_p95"] is None:
        return "no data"
    return "in" if c["p5_p95"] else ("in min-max only" if c["min_max"] else "**out**")


def _cell(ref: dict, c: dict, m: str) -> str:
    """``generated median`` vs ``real p5-p95 [min-max]``: verdict."""
    if not ref.get("n"):
        return f"{_num(c['generated_median'], m)} vs -"
    return (f"{_num(c['generated_median'], m)} vs {_num(ref['p5'], m)}-{_num(ref['p95'], m)} "
            f"[{_num(ref['min'], m)}-{_num(ref['max'], m)}]: {_verdict(c)}")


def realism_by_emotion_run(r: dict) -> list[str]:
    return _run(r, ("corpus", _sha(r.get("corpus"))),
                *((f"weights '{name}'", _sha(w)) for name, w in r.get("weights", {}).items()),
                ("generated clips", f"{r['generated_clips']} (seed000 pure-emotion clips + {r['extra_seeds']} "
                                    "other seeds each)"))


def realism_by_emotion_windows(r: dict) -> list[str]:
    """Per window length, per real reference: the windows on each side, then per measure the generated median vs
    the real p5-p95 [min-max] and whether it lies inside."""
    rows = []
    for w in r["windows"]:
        label = f"{w['length_s']:g} s / {w['hop_s']:g} s"
        for ref, per in w["real"].items():
            src = w["real_sources"][ref]
            gen = w["generated_sources"].get(w["generated_emotion_of"][ref], {"windows": 0, "sources": []})
            rows.append([label, ref, f"{src['windows']} ({len(src['sources'])})",
                         f"{gen['windows']} ({len(gen['sources'])})",
                         *(_cell(per[m], w["comparison"][ref][m], m) for m in SHOWN)])
        for ref in w["no_real_window"]:
            rows.append([label, ref, "0", "-", *("no real window" for _ in SHOWN)])
    return table(["window / hop", "emotion (real reference)", "real windows (takes)", "generated windows (clips)",
                  *(REALISM_LABELS[m] for m in SHOWN)], rows)


def _named(per: dict, test) -> str:
    """The labels of the measures whose comparison passes ``test``, comma-separated ('-' when none)."""
    return ", ".join(REALISM_LABELS[m] for m in SHOWN if test(per[m])) or "-"


def realism_by_emotion_outside(r: dict) -> list[str]:
    """Per window length and real reference: the measures whose generated median lies outside the real min-max,
    those outside only the p5-p95, and those inside the p5-p95."""
    rows = []
    for w in r["windows"]:
        for ref, per in w["comparison"].items():
            rows.append([f"{w['length_s']:g} s / {w['hop_s']:g} s", ref,
                         _named(per, lambda c: c["min_max"] is False),
                         _named(per, lambda c: c["p5_p95"] is False and c["min_max"] is True),
                         _named(per, lambda c: c["p5_p95"] is True)])
        rows += [[f"{w['length_s']:g} s / {w['hop_s']:g} s", ref, "no real window", "", ""]
                 for ref in w["no_real_window"]]
    return table(["window / hop", "emotion (real reference)", "generated median outside the real min-max",
                  "outside the p5-p95 only", "inside the p5-p95"], rows)


def realism_by_emotion_bml(r: dict) -> list[str]:
    """Per acted emotion: the BML walks measured whole (one looped stride each), median (p5-p95)."""
    b = r.get("bml_single_stride")
    if not b:
        return ["BML corpus not built: not measured."]
    rows = [[e, per[SHOWN[0]]["n"], *(f"{_num(per[m].get('p50'), m)} ({_num(per[m].get('p5'), m)}-"
                                      f"{_num(per[m].get('p95'), m)})" for m in SHOWN)]
            for e, per in b["per_emotion"].items()]
    return table(["acted emotion", "walks", *(REALISM_LABELS[m] for m in SHOWN)], rows)


TABLES: dict[str, tuple[str, Renderer]] = {
    "realism_by_emotion.run": ("date", realism_by_emotion_run),
    "realism_by_emotion.windows": ("windows", realism_by_emotion_windows),
    "realism_by_emotion.outside": ("windows", realism_by_emotion_outside),
    "realism_by_emotion.bml": ("bml_single_stride", realism_by_emotion_bml),
}
"""Table name -> (the JSON key it needs, renderer)."""
