"""Tables of the gait network on real capture (benchmarks/bench_gait_real.py; docs/benchmarks/gait.md)."""
from __future__ import annotations

from benchmarks.doc_renderers.common import EMOTIONS, Renderer, _opt, _run, table

REALISM_LABELS = {"skate_cm_s": "foot skate cm/s", "skate_ratio": "skate ratio", "toe_skim": "toe skim",
                  "stance_knee_deg": "stance knee deg", "pelvis_bounce_cm": "pelvis bounce cm", "speed_cv": "speed CV"}
REALISM_DIGITS = {"skate_cm_s": 1, "stance_knee_deg": 1, "pelvis_bounce_cm": 1}
"""Column label and decimals (default 2) of each realism measure (generation.quality.realism.MEASURES)."""
GAIT_REAL_SUBSETS = {"all": "all held-out forward locomotion", "emotion": "held-out emotion walks"}
"""Table suffix -> the prediction subset of bench_gait_real.py."""


def _sha(record: dict | None) -> str:
    """``path (sha256 <12 hex>)`` of a {path, sha256} record."""
    if not record:
        return "-"
    sha = record.get("sha256")
    return f"`{record['path']}`" + (f" (sha256 {sha[:12]}...)" if sha else "")


def gait_real_run(r: dict) -> list[str]:
    return _run(r, ("corpus", _sha(r.get("corpus"))),
                *((f"weights '{name}'", _sha(w)) for name, w in r.get("weights", {}).items()))


def _gait_real_prediction(r: dict, subset: str) -> list[str]:
    """One prediction subset: a line with its windows, takes and steps, then the error of each method."""
    t = r["prediction"][subset]
    return [f"{t['n']} windows of {t['takes']} test takes; {r['prefix']} network steps given, {r['horizon']} "
            "predicted:", "",
            *table(["method", "pose error / body diagonal", "step 1", "steps 2-5", "later steps", "cm",
                    "rotation deg"],
                   [[name, *(_opt(e[k], "{:.3f}") for k in ("pose_error_body_diag", "pose_error_body_diag_step1",
                                                            "pose_error_body_diag_steps2_5",
                                                            "pose_error_body_diag_later")),
                     _opt(e["pose_error_cm"], "{:.1f}"), _opt(e["rotation_error_deg"], "{:.1f}")]
                    for name, e in t["methods"].items()])]


def gait_real_prediction_all(r: dict) -> list[str]:
    return _gait_real_prediction(r, GAIT_REAL_SUBSETS["all"])


def gait_real_prediction_emotion(r: dict) -> list[str]:
    return _gait_real_prediction(r, GAIT_REAL_SUBSETS["emotion"])


def _n_range(ns) -> str:
    ns = [n for n in ns if n is not None]
    if not ns:
        return "-"
    return str(min(ns)) if min(ns) == max(ns) else f"{min(ns)}-{max(ns)}"


def gait_real_emotion(r: dict) -> list[str]:
    """Per set of generated walks (weights, seeds), per asked emotion: the share read as asked / read as neutral
    (neutral: read as asked only)."""
    rows = []
    for name, rec in r["recognition"].items():
        per = rec["per_class"]
        cells = [_opt(per[e]["own"]) if e == "neutral" else f"{_opt(per[e]['own'])} / {_opt(per[e]['as_neutral'])}"
                 for e in EMOTIONS]
        rows.append([name, _n_range(per[e].get("n") for e in EMOTIONS), *cells])
    return table(["walks", "n per emotion", *(f"{e}: as asked / as neutral" if e != "neutral" else e
                                              for e in EMOTIONS)], rows)


def _measure(m: str, v) -> str:
    return _opt(v, f"{{:.{REALISM_DIGITS.get(m, 2)}f}}")


def gait_real_realism(r: dict) -> list[str]:
    """Per emotion: the real takes' min-max of each realism measure, then per set of generated walks the median and
    (in brackets) the share of walks inside the quality gate's widened range."""
    real = r["real_realism"]
    measures = [m for m in next(iter(real.values())) if m != "takes"]
    rows = []
    for e in EMOTIONS:
        if e in real:
            rows.append([e, "real takes (min-max)", _opt(real[e].get("takes"), "{}"),
                         *("-" if not real[e].get(m) else f"{_measure(m, real[e][m]['min'])}-"
                           f"{_measure(m, real[e][m]['max'])}" for m in measures)])
        for name, per in r["realism"].items():
            if e not in per:
                continue
            v, cells = per[e], []
            for m in measures:
                g, inside = v["measures"].get(m), v["inside_share"].get(m)
                cells.append(_measure(m, g and g["median"]) + ("" if inside is None else f" ({inside:.2f})"))
            rows.append([e, name, _opt(v.get("n"), "{}"), *cells])
    return table(["emotion", "walks", "n", *(REALISM_LABELS.get(m, m) for m in measures)], rows)


def gait_real_plan_reading(r: dict) -> list[str]:
    """The real takes (read whole), then per weights the seed000 plan's clips read for what each asks (transitions
    by their first and last window): per asked emotion (as asked / as neutral) and per kind of clip (share read as
    asked)."""
    rows = []
    for name, rec in {**r.get("real_take_reading", {}), **r["plan_reading"]}.items():
        per, kinds = rec["per_class"], rec.get("by_kind", {})
        rows.append([name, *(_opt(per[e]["own"]) if e == "neutral" else
                             f"{_opt(per[e]['own'])} / {_opt(per[e]['as_neutral'])} (n {per[e]['n']})"
                             for e in EMOTIONS),
                     *(f"{_opt(kinds[k]['read_as_asked'])} (n {kinds[k]['n']})" if k in kinds else "-"
                       for k in ("pure", "mixture", "transition"))])
    return table(["walks", *(f"{e}: as asked / as neutral" if e != "neutral" else e for e in EMOTIONS),
                  "pure clips", "mixtures", "transition ends"], rows)


def gait_real_plan_parts(r: dict) -> list[str]:
    """Each part of the plan's clips read by the real-capture observer (the first weights of ``plan_reading``)."""
    name, rec = next(iter(r["plan_reading"].items()))
    rows = [[p["clip"], p["part"], p["asked"] or "tie: " + "/".join(p["components"]), p["read"],
             " ".join(f"{v:.2f}" for v in p["p"])] for p in rec["parts"]]
    return table(["clip", "part", "asked", f"read ({name})", "p " + " ".join(EMOTIONS)], rows)


def gait_real_mixture_response(r: dict) -> list[str]:
    """Per emotion mixed with neutral, per share of the emotion: the observer's mean p of the emotion / of
    neutral, and how many walks are read as the emotion."""
    resp = r["mixture_response"]
    shares = list(next(iter(resp.values())))
    rows = [[e, *(f"{c['p_emotion']:.2f} / {c['p_neutral']:.2f} ({round(c['as_emotion'] * c['n'])} of {c['n']})"
                  for c in (per[w] for w in shares))] for e, per in resp.items()]
    return table(["emotion", *(f"share {w}" for w in shares)], rows)


TABLES: dict[str, tuple[str, Renderer]] = {
    "gait_real.run": ("date", gait_real_run),
    "gait_real.prediction_all": ("prediction", gait_real_prediction_all),
    "gait_real.prediction_emotion": ("prediction", gait_real_prediction_emotion),
    "gait_real.emotion": ("recognition", gait_real_emotion),
    "gait_real.realism": ("realism", gait_real_realism),
    "gait_real.plan_reading": ("plan_reading", gait_real_plan_reading),
    "gait_real.plan_parts": ("plan_reading", gait_real_plan_parts),
    "gait_real.mixture_response": ("mixture_response", gait_real_mixture_response),
}
"""Table name -> (the JSON key it needs, renderer)."""
