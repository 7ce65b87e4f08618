"""Per-clip norms: speed on a large SIMULATED study, recovery of the simulated truth, and the norming design table.

    python -m benchmarks.bench_norms [--studies 200] [--json docs/benchmarks/norms.json]

1. Speed: a SIMULATED norming study of 10,000 participants x 40 ratings (400 simulated gait clips, the cyclic design
   of protocol.norming, each rating with its intensity and naturalness answers: 1.2 million rows of responses.csv):
   seconds to compute the norms (analysis.norms.clip_norms on validated data) and to read, validate and norm the
   three CSVs from text.
2. Recovery: 200 SIMULATED norming studies of the demo plan's candidate clips (the norming preset's sections, K
   ratings per clip): mean absolute error of the recovered shares against the simulated truth (the expected share
   vector, analysis.norms_simulate.expected_shares) and how often the 95 % Wilson interval of the intended share
   covers the true intended share; with multi-select answers as simulated by default (30 % of gait answers choose
   two labels) and with single-label answers only; the same for the seed000 plan's 22 walks, where each
   participant sees 8 (an incomplete design, N = 55).
3. The design table: for the demo, seed000 and seed003 plans, each norming section's candidate clips C, clips per
   participant M, ratings per clip K and the participants N = ceil(K C / M) needed (protocol.norming).
Nothing here is data from people.
"""
from __future__ import annotations

import argparse
import io
import time

import numpy as np
import pandas as pd

from analysis.design import pool_mask, read_planned_clips
from analysis.io import load_study
from analysis.norms import clip_norms
from analysis.norms_simulate import simulate_norming
from benchmarks.bench_record import record
from protocol.norming import min_ratings, ratings_per_clip, required_participants
from protocol.presets import PRESETS
from protocol.vocabulary import CLIP_COLUMNS, GAIT_EMOTIONS

DESIGN_PLANS = ("demo", "seed000", "seed003")


def _csv(df: pd.DataFrame) -> io.StringIO:
    return io.StringIO(df.to_csv(index=False))


def simulated_gait_clips(n: int, seed: int = 0) -> pd.DataFrame:
    """``n`` SIMULATED gait clips (clips.csv rows, ids ``sim-bench-<i>``) with one dominant intended emotion each."""
    rng = np.random.default_rng(seed)
    rows = []
    for i in range(n):
        v = np.zeros(len(GAIT_EMOTIONS))
        v[i % len(GAIT_EMOTIONS)] = 1.0
        rows.append({"clip_id": f"sim-bench-{i:04d}", "modality": "gait", "origin": "generated",
                     **dict(zip(GAIT_EMOTIONS, v)), "duration_s": float(rng.uniform(4, 8))})
    return pd.DataFrame(rows).reindex(columns=list(CLIP_COLUMNS))


def speed(n_participants: int = 10_000, m: int = 40, n_clips: int = 400) -> dict:
    sim = simulate_norming(simulated_gait_clips(n_clips), n_participants, m, seed=1)
    texts = {k: sim.__getattribute__(k).to_csv(index=False) for k in ("responses", "clips", "participants")}
    t0 = time.perf_counter()
    data = load_study(io.StringIO(texts["responses"]), io.StringIO(texts["clips"]), io.StringIO(texts["participants"]))
    t1 = time.perf_counter()
    norms = clip_norms(data.responses, data.clips)
    t2 = time.perf_counter()
    return {"participants": n_participants, "ratings_per_participant": m, "clips": n_clips,
            "response_rows": len(sim.responses), "norm_rows": len(norms),
            "norms_s": round(t2 - t1, 2), "read_validate_and_norms_s": round(t2 - t0, 2)}


def norming_candidates(plan: str) -> dict[str, pd.DataFrame]:
    """The norming preset's sections on ``plan``'s planned clips: section_type -> candidate clip rows."""
    clips = read_planned_clips()
    clips = clips[clips["plan"] == plan].reset_index(drop=True)
    return {sec["section_type"]: clips[pool_mask(clips, sec["pool"])] for sec in PRESETS["norming"]["sections"]}


def design_table() -> list[dict]:
    rows = []
    for plan in DESIGN_PLANS:
        for sec in PRESETS["norming"]["sections"]:
            c = len(norming_candidates(plan)[sec["section_type"]])
            if not c:          # the plan has no clips of this kind: the section would be deleted
                continue
            m, k = sec["clips_per_participant"], ratings_per_clip(sec["options"])
            rows.append({"plan": plan, "section_type": sec["section_type"], "C": c, "M": min(m, c), "K": k,
                         "N": required_participants(c, k, m)})
    return rows


def recovery(n_studies: int = 200, multi_select_prob: float = 0.3, plan: str = "demo") -> dict:
    """MAE of the shares and Wilson coverage of the intended share over ``n_studies`` SIMULATED norming studies of
    ``plan`` (N from the design table, so every clip gets at least K = 20 ratings)."""
    cands = norming_candidates(plan)
    clips = pd.concat([c for c in cands.values() if len(c)], ignore_index=True)
    n = max(r["N"] for r in design_table() if r["plan"] == plan)
    m = PRESETS["norming"]["sections"][0]["clips_per_participant"]
    errors, covered, total, widths, ratings = [], 0, 0, [], []
    for s in range(n_studies):
        sim = simulate_norming(clips, n, m, seed=1000 + s, multi_select_prob=multi_select_prob)
        data = load_study(_csv(sim.responses), _csv(sim.clips), _csv(sim.participants))
        norms = clip_norms(data.responses, data.clips)
        merged = norms.merge(sim.truth, on=["clip_id", "section_type", "question"], suffixes=("", "_true"))
        for c in [c for c in norms.columns if c.startswith("share_") and f"{c}_true" in merged]:
            errors.append((merged[c] - merged[f"{c}_true"]).abs().dropna().to_numpy())
        has = merged["intended"].notna()
        true_share = np.array([merged.loc[i, f"share_{lab}_true"] for i, lab in merged.loc[has, "intended"].items()])
        lo, hi = merged.loc[has, "intended_ci_low"].to_numpy(), merged.loc[has, "intended_ci_high"].to_numpy()
        covered += int(((lo <= true_share) & (true_share <= hi)).sum())
        total += int(has.sum())
        widths.append(hi - lo)
        ratings.append(norms["n_ratings"].to_numpy())
    err = np.concatenate(errors)
    ratings = np.concatenate(ratings)
    return {"plan": plan, "studies": n_studies, "participants": n, "clips_per_participant": m,
            "candidate_clips": len(clips),
            "multi_select_prob": multi_select_prob, "ratings_per_clip_min": int(ratings.min()),
            "ratings_per_clip_max": int(ratings.max()), "share_mae": round(float(err.mean()), 4),
            "share_abs_error_p95": round(float(np.quantile(err, 0.95)), 4),
            "intended_ci_coverage": round(covered / total, 4), "intervals": total,
            "mean_ci_width": round(float(np.concatenate(widths).mean()), 3)}


def write_sample(out_dir: str, seed: int = 0) -> dict:
    """One SIMULATED norming study of the demo plan (N and K of the design table) with its norms beside the
    simulated truth: ``simulated_clip_norms.csv`` (the public format) and ``simulated_truth.csv`` (expected
    shares), for the docs."""
    import os

    clips = pd.concat([c for c in norming_candidates("demo").values() if len(c)], ignore_index=True)
    n = max(r["N"] for r in design_table() if r["plan"] == "demo")
    m = PRESETS["norming"]["sections"][0]["clips_per_participant"]
    sim = simulate_norming(clips, n, m, seed=seed)
    data = load_study(_csv(sim.responses), _csv(sim.clips), _csv(sim.participants))
    norms = clip_norms(data.responses, data.clips)
    os.makedirs(out_dir, exist_ok=True)
    norms.to_csv(os.path.join(out_dir, "simulated_clip_norms.csv"), index=False)
    sim.truth.to_csv(os.path.join(out_dir, "simulated_truth.csv"), index=False)
    merged = norms.merge(sim.truth, on=["clip_id", "section_type", "question"], suffixes=("", "_true"))
    err = pd.concat([(merged[c] - merged[f"{c}_true"]).abs() for c in norms.columns
                     if c.startswith("share_") and f"{c}_true" in merged]).dropna()
    return {"participants": n, "rows": len(norms), "share_mae": round(float(err.mean()), 4)}


def main(argv=None) -> dict:
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--studies", type=int, default=200)
    ap.add_argument("--participants", type=int, default=10_000)
    ap.add_argument("--json", default=None)
    ap.add_argument("--sample", default=None, metavar="DIR",
                    help="only write one SIMULATED demo norming study's clip_norms.csv and its truth into DIR")
    args = ap.parse_args(argv)
    if args.sample:
        result = write_sample(args.sample)
        print(result)
        return result
    table = design_table()
    for row in table:
        assert min_ratings(row["C"], row["M"], row["N"]) >= row["K"]
    result = {"benchmark": "bench_norms (SIMULATED participants)", "design_table": table,
              "speed": speed(args.participants),
              "recovery_multi_select": recovery(args.studies, 0.3),
              "recovery_single_label": recovery(args.studies, 0.0),
              "recovery_seed000_incomplete": recovery(args.studies, 0.3, "seed000"),
              "recovery_seed000_single_label": recovery(args.studies, 0.0, "seed000")}
    return record(result, args.json)


if __name__ == "__main__":
    main()
