"""Seed 004 on real capture: the shipped averaged neutral walk, DTW alignment, data-driven RBF features, plan fields.

Uses the shipped real subset (generation/data/mocap/bandai-namco/, CC BY-NC 4.0, Kobayashi et al. 2023) and the
shipped derived files (generation/data/rbf/), never the full corpus.
"""
from __future__ import annotations

import numpy as np
import pytest

from generation.rbf import data_features as DF
from generation.rbf.basis import rbf_sum
from generation.rbf.compare import compare_theme
from generation.rbf.neutral_base import NormalisedCycle
from generation.rbf.real_neutral import dtw_align, load_cycle, real_neutral_from_clips, save_cycle, steady_cycles
from generation.rbf.stylise import stylise, theme_rbfs, walker_frame_positions
from generation.rbf.themes import all_features


@pytest.fixture(scope="module")
def shipped_walks():
    from generation.mocap.bandai_namco import shipped_takes
    from generation.mocap.dataset_import import import_take

    out = {}
    for take in shipped_takes():
        if take.skeleton == "gait" and take.content == "walk" and take.style in ("normal", "sad", "happy"):
            clip, row = import_take(take)
            assert clip is not None, row
            out[take.style] = clip
    return out


@pytest.fixture(scope="module")
def base():
    return load_cycle()


def test_shipped_neutral_is_real_averaged_and_loops(base):
    md = base.metadata
    assert md["synthetic"] is False and md["captured_base"] is True
    assert md["licence"] == "CC BY-NC 4.0" and "arXiv:2306.08861" in md["citation"]
    used = [s for s in md["captured_sources"] if s["cycles"]]
    assert md["n_cycles"] >= 16 and len(used) >= 3
    assert {s["dataset"] for s in used} == {"bandai-namco-1", "bandai-namco-2"}
    assert {s["split"] for s in used} == {"train"}
    assert "DTW" in md["time_warping"]
    assert md["dtw_spread"]["after"] <= md["dtw_spread"]["before"]
    # the cycle loops: frame m (= frame 0 moved by the stride) continues frame m-1 as smoothly as any other step
    P, _ = walker_frame_positions(base)
    steps = np.linalg.norm(np.diff(np.concatenate([P, P[:1]]), axis=0), axis=-1).max(axis=1)
    assert steps[-1] <= 1.5 * np.median(steps[:-1]) + 1e-3
    # a plausible walk: 0.9-1.4 s cycle, stride 1.1-1.6 m, bones exact (rotations) and feet on the floor
    assert 0.9 < base.duration < 1.4 and 1.1 < md["stride_m"][2] < 1.6
    assert abs(base.positions()[:, :, 1].min()) < 0.01


def test_save_and_load_round_trip(base, tmp_path):
    save_cycle(base, tmp_path / "c.npz")
    again = load_cycle(tmp_path / "c.npz")
    np.testing.assert_allclose(again.rotations, base.rotations)
    assert again.metadata == base.metadata and again.skeleton.height == base.skeleton.height
    with pytest.raises(FileNotFoundError, match="python -m generation.rbf neutral"):
        load_cycle(tmp_path / "missing.npz")


def _cycle(phase_warp: np.ndarray) -> NormalisedCycle:
    """A synthetic (m + 1, 2, 3) periodic cycle sampled at warped phases."""
    t = phase_warp * 2 * np.pi
    pos = np.zeros((len(t), 2, 3))
    pos[:, 0, 0] = np.sin(t)
    pos[:, 1, 1] = np.cos(2 * t)
    return NormalisedCycle(pos, 0.8, 1.0, "synthetic")


def test_dtw_aligns_time_warped_cycles():
    u = np.linspace(0.0, 1.0, 101)
    cycles = [_cycle(u), _cycle(u ** 1.3), _cycle(u ** 0.8), _cycle(0.5 - 0.5 * np.cos(np.pi * u))]
    aligned, spread = dtw_align(cycles)
    assert spread["after"] < 0.5 * spread["before"]
    assert all(c.positions.shape == (101, 2, 3) for c in aligned)
    np.testing.assert_allclose(aligned[0].positions[[0, -1]], cycles[0].positions[[0, -1]])  # ends stay strikes
    with pytest.raises(ValueError, match="at least two cycles"):
        dtw_align(cycles[:1])


def test_real_neutral_from_a_shipped_take(shipped_walks):
    normal = shipped_walks["normal"]
    steady = steady_cycles(normal.motion, 100, normal.name)
    assert len(steady) >= 2
    cycle = real_neutral_from_clips([normal], per_take=None)
    assert cycle.num_frames == 100 and cycle.metadata["n_cycles"] == len(steady)
    assert cycle.metadata["captured_sources"][0]["name"] == normal.name


@pytest.mark.parametrize("params", [
    [[0.03, 40.0, 120.0]],
    [[0.02, 20.0, 80.0], [-0.025, 70.0, 60.0]],
    [[0.01, 50.0, 400.0 ** 2], [0.02, 25.0, 50.0], [0.015, 75.0, 50.0]],
])
def test_fit_dof_recovers_known_rbfs(params):
    t = np.arange(100.0)
    y = rbf_sum(t, np.array(params), period=100)
    fitted, r2 = DF.fit_dof(y)  # the fewest RBFs reaching FIT_R2
    assert r2 >= DF.FIT_R2 and len(fitted) <= len(params)
    exact, r2 = DF.fit_dof(y, r2=0.9999)  # asked for more, it uses up to three and matches the curve
    assert r2 >= 0.9999 and len(exact) <= 3
    np.testing.assert_allclose(rbf_sum(t, exact, period=100), y, atol=0.01 * np.abs(y).max())
    if len(params) == 1:
        np.testing.assert_allclose(fitted, params, rtol=1e-3)


def test_theme_difference_from_shipped_takes(shipped_walks):
    clips = [shipped_walks["normal"], shipped_walks["sad"]]
    diff, info = DF.theme_difference(clips, "sad")
    assert diff.shape == (100, 21, 3) and info[0]["dataset"] == "bandai-namco-1" and info[0]["cycles"] >= 2
    with pytest.raises(ValueError, match="no dataset has both happy walks"):
        DF.theme_difference(clips, "happy")
    with pytest.raises(ValueError, match="unknown theme"):
        DF.theme_styles("angry")


def test_shipped_data_features_select_the_first_n_rows(base):
    data = DF.load_data_features()
    assert data["licence"] == "CC BY-NC 4.0" and data["split"] == "train"
    first = [tuple(k) for k in data["themes"]["sad"]["features"][:3]]
    dofs = DF.data_rbfs("sad", 3, 1.75, 100, data)
    assert dofs and {(DF.PART_OF[j], a) for j, a in dofs} <= set(first)
    twice = DF.data_rbfs("sad", 3, 3.5, 200, data)
    for key, p in dofs.items():
        np.testing.assert_allclose(twice[key], p * [2.0, 2.0, 4.0])


def test_data_features_style_the_real_base(base):
    zero_e = stylise(base, "sad", 0.0, 10, n_cycles=2, fps=30.0)
    zero_d = stylise(base, "sad", 0.0, 10, n_cycles=2, fps=30.0, features="data")
    np.testing.assert_allclose(zero_d.positions(), zero_e.positions(), atol=1e-6)
    styled = stylise(base, "sad", 1.0, 10, n_cycles=2, fps=30.0, features="data")
    moved = np.linalg.norm(styled.positions() - zero_d.positions(), axis=-1).max(axis=0)
    hand = base.skeleton.index("left_hand")
    assert moved[hand] > 0.05  # the real sad walks' arms barely swing: the hands move by many centimetres
    md = styled.metadata
    assert md["features"] == "data" and md["licence"] == "CC BY-NC 4.0" and md["synthetic_base"] is False
    with pytest.raises(ValueError, match="features must be one of"):
        stylise(base, "sad", 1.0, 10, features="crowd")


def test_comparison_of_expert_features_with_themselves(base):
    P, _ = walker_frame_positions(base)
    h = base.skeleton.height
    dofs = theme_rbfs(P, base.skeleton, "happy", 10, intensities="calibrated")  # compare_theme's set: Table III's rows
    rows = sorted({(DF.PART_OF[j], a) for j, a in dofs})
    as_data = {"cycle_frames": 100, "themes": {"happy": {"features": [list(r) for r in rows], "dofs": [
        {"joint": j, "axis": a, "part": DF.PART_OF[j], "rbfs": (p * [1 / h, 1, 1]).tolist()}
        for (j, a), p in dofs.items()]}}}
    c = compare_theme(base, "happy", as_data)
    assert c["sign_agreement"] == 1.0 and c["median_ratio"] == pytest.approx(1.0)
    assert c["used_overlap"] == len(c["expert_features"]) and c["shared_dofs"] == len(dofs)
    assert all(r["peak_shift"] in (None, 0.0) for r in c["rows"])


def test_plan_entries_name_base_and_features():
    from generation.plans.schema import PlanError, load_plan, validate_plan

    clip = {"id": "a", "generator": "rbf", "origin": "generated", "theme": "sad", "weight": 0.7}
    plan = validate_plan({"name": "t", "clips": [clip, dict(clip, id="b", features="data", base="procedural")]})
    assert [(e.inputs["base"], e.inputs["features"]) for e in plan.entries] == [("real", "expert"),
                                                                                 ("procedural", "data")]
    with pytest.raises(PlanError, match="features"):
        validate_plan({"name": "t", "clips": [dict(clip, features="crowd")]})
    data_plan = load_plan("seed004_data")
    assert sorted(e.inputs["features"] for e in data_plan.entries if e.generator == "rbf") == ["data"] * 6 + [
        "expert"] * 6


def test_a_damaged_features_file_is_an_error(tmp_path):
    import json

    data = DF.load_data_features()
    data["themes"]["sad"]["dofs"][0]["rbfs"] = [[0.01, 50.0, -1.0]]
    path = tmp_path / "bad.json"
    path.write_text(json.dumps(data))
    with pytest.raises(ValueError, match="variances must be positive"):
        DF.load_data_features(path)
    del data["themes"]["tired"]
    path.write_text(json.dumps(data))
    with pytest.raises(ValueError, match=r"no data-driven features for themes \['tired'\]"):
        DF.load_data_features(path)


def test_excluding_expert_features(base):
    P, _ = walker_frame_positions(base)
    skel = base.skeleton
    masculine = theme_rbfs(P, skel, "masculine", 10)
    without = theme_rbfs(P, skel, "masculine", 10, exclude=(5,))  # Ankles: increased swing along Y
    assert set(masculine) - set(without) == {("left_heel", "Y"), ("right_heel", "Y")}
    assert theme_rbfs(P, skel, "masculine", 10, exclude=tuple(range(1, 11)), intensities="calibrated") == {}
    # the default (extended) set's own rows (ranks 11 and up) are excluded by rank too
    every_rank = tuple(f.rank for f in all_features("masculine"))
    assert every_rank[-1] > 12 and theme_rbfs(P, skel, "masculine", 10, exclude=every_rank) == {}
    clip = stylise(base, "masculine", 1.0, 10, n_cycles=2, fps=30.0, exclude=(5,))
    assert clip.metadata["excluded_ranks"] == [5]
