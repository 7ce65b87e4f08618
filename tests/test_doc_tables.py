"""benchmarks/doc_tables.py: tables rendered from benchmark JSON replace exactly their marked blocks in a doc."""
from __future__ import annotations

import importlib
import json
import pkgutil

import pytest

from benchmarks import doc_renderers, doc_tables

RESULTS = {
    "prediction": {"full": {"pose_error_body_diag": 0.0231, "pose_error_cm": 3.94, "pose_error_first10_cm": 1.26,
                            "pose_error_last10_cm": 6.71, "rotation_error_deg": 5.83, "rotation_error_rad": 0.1017}},
    "long_horizon": {"windows": [{"steps": "0-50", "root_speed_m_s": 1.234, "pose_variance_cm2": 196.4,
                                  "path_distance_m": 0.0171, "root_height_m": 0.8951}]},
}
DOC = """# Gait

Narrative stays.

<!-- table: gait.prediction -->
| stale | table |
<!-- /table -->

<!-- table: gait.speed -->
kept: no speed figures in these results
<!-- /table -->

<!-- table: gait.long_horizon -->
<!-- /table -->
"""


def test_marked_blocks_get_the_rendered_tables(tmp_path):
    (tmp_path / "gait.json").write_text(json.dumps(RESULTS))
    (tmp_path / "gait.md").write_text(DOC)
    done = doc_tables.update_doc("gait", tmp_path / "gait.json", tmp_path / "gait.md")
    text = (tmp_path / "gait.md").read_text()
    assert sorted(done) == ["gait.long_horizon", "gait.prediction"]
    assert "| full | 0.023 | 3.9 | 1.3 / 6.7 | 5.8 (0.102) |" in text and "stale" not in text
    assert "| 0-50 | 1.23 | 196 | 0.017 | 0.895 |" in text
    assert "kept: no speed figures in these results" in text and "Narrative stays." in text
    # rendering again changes nothing
    doc_tables.update_doc("gait", tmp_path / "gait.json", tmp_path / "gait.md")
    assert (tmp_path / "gait.md").read_text() == text


def test_the_gait_doc_marks_every_gait_table_and_matches_its_json():
    """gait.md marks each gait table once; what the committed gait.json renders is what the blocks hold (the
    JSON holds no run yet, so the blocks stay as they are)."""
    results, doc = doc_tables.area_files("gait")
    text = doc.read_text()
    names = [m.group("name") for m in doc_tables.BLOCK_RE.finditer(text) if m.group("name").startswith("gait.")]
    assert sorted(names) == sorted(doc_tables.TABLES["gait"])
    assert doc_tables.fill_doc(text, doc_tables.render_tables("gait", json.loads(results.read_text())))[0] == text


def test_each_renderer_module_is_one_area_of_the_tables():
    """Every area module of benchmarks/doc_renderers/ gives doc_tables.TABLES the area named after it, and its table
    names start with that area; doc_tables still exports every name it lists."""
    areas = sorted(m.name for m in pkgutil.iter_modules(doc_renderers.__path__) if m.name != "common")
    assert areas == sorted(doc_tables.TABLES)
    for area in areas:
        module = importlib.import_module(f"benchmarks.doc_renderers.{area}")
        assert doc_tables.TABLES[area] is module.TABLES
        assert module.TABLES and all(name.startswith(area + ".") for name in module.TABLES)
    assert all(hasattr(doc_tables, name) for name in doc_tables.__all__)


def test_unknown_area_and_missing_results(tmp_path, capsys):
    with pytest.raises(ValueError, match="no tables for 'dance'"):
        doc_tables.render_tables("dance", {})
    assert doc_tables.main(["gait", "--results", str(tmp_path / "none.json")]) == 2
    assert "run the area's benchmark first" in capsys.readouterr().err


def _speeds(gen_mean, gen_peak, corpus_mean=0.5, corpus_peak=1.0, n=9):
    return {"n": n, "gen_mean": gen_mean, "gen_peak": gen_peak, "corpus_mean": corpus_mean, "corpus_peak": corpus_peak}


def _network(gen_mean, r_gen):
    """Liveliness results of one network for two emotions (neutral is the calmer)."""
    per = {"angry": _speeds(gen_mean, 1.2, 0.45, 0.9, n=8), "neutral": _speeds(0.25, 0.5, 0.3, 0.4)}
    return {"per_emotion": per, "n": 17, "worst_ratio_gap": 0.333, "r_gen": r_gen, "r_corpus": 0.51,
            "r_all_emotions": r_gen - 0.02, "n_all_emotions": 22,
            "all_emotions": {"per_emotion": {"angry": _speeds(0.9, 0.66, 1.0, 0.6, n=11),
                                             "neutral": _speeds(0.2, 0.5, 0.25, 0.5, n=11)},
                             "n": 22, "cells_in_band": 3, "worst_ratio_gap": 0.2}}


GESTURE = {
    "meta": {"machine": "test VM", "date": "2026-12-04", "commit": "0123456789abcdef", "uncommitted_changes": True,
             "seconds": 300.0, "command": "python benchmarks/bench_gesture.py", "comparison_weights": {"old": "o.pt"}},
    "split": {"train": 792, "val": 99, "test": 99},
    "shipped": {"parameters": 269772, "epochs": 63, "seconds": 1512.6, "best_epoch": 54},
    "emotion_vad": {"angry": {"valence": 0.122, "arousal": 0.83, "dominance": 0.204},
                    "neutral": {"valence": 0.469, "arousal": 0.184, "dominance": 0.357}},
    "pose_error_table": {"all losses (shipped weights)": {"pose_error": 0.00651, "pose_error_upper": 0.01744,
                                                          "rotation_error_deg": 1.5312, "acceleration": 0.9771,
                                                          "speed_log_ratio": 0.2273}},
    "gt_acceleration": 1.2261,
    "liveliness": {"old": _network(0.3, 0.115), "shipped": _network(0.4, 0.687)},
    "expressiveness": {"r_speed_arousal": 0.6601, "p_speed_arousal": 6.04e-137, "r_expansion_dominance": 0.699,
                       "p_expansion_dominance": 3.3e-160, "r_speed_arousal_procedural": 0.5104,
                       "r_expansion_dominance_procedural": 0.652, "observer_arousal_generated": 0.93,
                       "observer_arousal_procedural": 0.953, "observer_dominance_generated": 0.998,
                       "observer_dominance_procedural": 1.0,
                       "per_emotion": {"angry": {"speed": 1.049, "expansion": 0.629},
                                       "neutral": {"speed": 0.505, "expansion": 0.489}}},
    "speed": {"sentences": 20, "repeats": 3, "output_fps": 3114.2, "output_fps_min": 1851.0, "output_fps_max": 3207.4,
              "ms_per_output_frame": 0.3211, "network_steps_per_s": 1052.3},
    "epoch_timing": [{"preset": "small", "parameters": 269772, "timed_batches": 3, "seconds_per_batch": 0.1234,
                      "batches_per_epoch": 50, "seconds_per_epoch": 6.17, "epochs": 400}],
    "arousal_sheet": [{"emotion": "sad", "arousal": 0.333, "mean": 0.281, "peak": 0.422}],
}


def test_gesture_tables_render_the_figures():
    t = doc_tables.render_tables("gesture", GESTURE)
    assert set(t) == set(doc_tables.TABLES["gesture"])
    assert "| commit | 0123456789ab + uncommitted changes |" in t["gesture.run"]
    assert "| shipped weights | 269,772 parameters, 63 epochs in 25.2 min, the weights after epoch 55 kept |" \
        in t["gesture.run"]
    assert "| examples train / validation / test | 792 / 99 / 99 |" in t["gesture.run"]
    assert "| weights 'old' | `o.pt` |" in t["gesture.run"]
    assert t["gesture.pose"][2:] == ["| all losses (shipped weights) | 0.0065 | 0.0174 | 1.53 | 0.977 | 0.227 |",
                                     "| ground truth (procedural) | - | - | - | 1.226 | - |"]
    # rows from the lowest to the highest arousal; generated speed with its ratio to the corpus, per network
    live = t["gesture.liveliness"]
    assert live[0] == ("| Emotion | arousal | n | corpus mean | corpus peak | old: mean (ratio) | old: peak (ratio) "
                       "| shipped: mean (ratio) | shipped: peak (ratio) |")
    assert live[2:] == ["| neutral | 0.184 | 9 | 0.300 | 0.400 | 0.250 (0.83) | 0.500 (1.25) | 0.250 (0.83) "
                        "| 0.500 (1.25) |",
                        "| angry | 0.830 | 8 | 0.450 | 0.900 | 0.300 (0.67) | 1.200 (1.33) | 0.400 (0.89) "
                        "| 1.200 (1.33) |"]
    assert t["gesture.liveliness_summary"][2:] == [
        "| r(peak wrist speed, arousal), own attributes | 0.510 | 0.115 | 0.687 |",
        "| r(peak wrist speed, arousal), each test sentence x 11 emotions (22) | 0.510 (held-out, own) | 0.095 "
        "| 0.667 |",
        "| largest per-emotion ratio gap (mean or peak) | 0 | 0.33 | 0.33 |"]
    assert t["gesture.all_emotions"][2:] == ["| neutral | 0.250 | 0.500 | 0.80 / 1.00 | 0.80 / 1.00 |",
                                             "| angry | 1.000 | 0.600 | 0.90 / 1.10 | 0.90 / 1.10 |",
                                             "| cells in band (of 22) |  |  | 3 | 3 |",
                                             "| largest ratio gap |  |  | 0.20 | 0.20 |"]
    assert t["gesture.arousal_sheet"][2:] == ["| sad | 0.333 | 0.28 | 0.42 |"]
    assert t["gesture.expressiveness"][2:4] == ["| Pearson r(speed, arousal) | 0.660 (p = 6e-137) | 0.510 |",
                                                "| Pearson r(expansion, dominance) | 0.699 (p = 3.3e-160) | 0.652 |"]
    assert t["gesture.expressiveness"][5] == ("| Synthetic observer, high vs low dominance (balanced accuracy) | 0.998 "
                                              "| 1.000 |")
    assert t["gesture.expressiveness_per_emotion"][2:] == ["| neutral | 0.184 | 0.357 | 0.505 | 0.489 |",
                                                           "| angry | 0.830 | 0.204 | 1.049 | 0.629 |"]
    assert t["gesture.speed"][2:] == ["| 20 | 3 | 3114 | 1851-3207 | 0.32 | 1052 |"]
    assert t["gesture.training_speed"][2:] == ["| small | 269,772 | 0.12 (mean of 3 timed batches) | 50 | 6 | 400 |"]


def test_the_gesture_doc_marks_every_gesture_table_and_matches_its_json():
    """Every gesture table is marked once in gesture.md, and the blocks there are what gesture.json renders."""
    text = (doc_tables.DOCS / "gesture.md").read_text()
    names = [m.group("name") for m in doc_tables.BLOCK_RE.finditer(text)]
    assert sorted(names) == sorted(doc_tables.TABLES["gesture"])
    tables = doc_tables.render_tables("gesture", json.loads((doc_tables.DOCS / "gesture.json").read_text()))
    assert doc_tables.fill_doc(text, tables)[0] == text


def test_area_files_name_the_json_and_doc_of_each_area():
    assert doc_tables.area_files("gait") == (doc_tables.DOCS / "gait.json", doc_tables.DOCS / "gait.md")
    assert doc_tables.area_files("rbf_real") == (doc_tables.DOCS / "rbf_real.json", doc_tables.DOCS / "rbf.md")
    assert doc_tables.area_files("real_observer") == (doc_tables.DOCS / "real_observer.json",
                                                      doc_tables.DOCS / "mocap.md")
    assert doc_tables.area_files("gait_real") == (doc_tables.DOCS / "gait_real.json", doc_tables.DOCS / "gait.md")


@pytest.mark.parametrize("area", ["rbf_features", "rbf_real", "real_observer", "gait_real", "upsampling"])
def test_each_doc_marks_every_table_of_the_area_once_and_matches_its_json(area):
    """The area's doc marks each of its tables once, and the blocks there are what the committed JSON renders."""
    results, doc = doc_tables.area_files(area)
    text = doc.read_text()
    names = [m.group("name") for m in doc_tables.BLOCK_RE.finditer(text) if m.group("name").startswith(area + ".")]
    assert sorted(names) == sorted(doc_tables.TABLES[area])
    tables = doc_tables.render_tables(area, json.loads(results.read_text()))
    assert set(tables) == set(doc_tables.TABLES[area])
    assert doc_tables.fill_doc(text, tables)[0] == text


def _dof(joint, axis, expert, data, agree, shift, ratio, corr):
    return {"joint": joint, "axis": axis, "expert_peak": expert, "data_peak": data, "sign_agree": agree,
            "peak_shift": shift, "ratio": ratio, "corr": corr}


def _ablated(rank, p_without, sides_with):
    return {"rank": rank, "feature": f"feature {rank}", "why": "data reverse its sign", "p_without": p_without,
            "sides_with": sides_with}


RBF_REAL = {
    "machine": "test VM", "date": "2026-12-03", "command": "python benchmarks/bench_rbf_real.py --doc d.md",
    "meta": {"transcribed_fields": ["command"], "transcribed_from": "a doc"},
    "neutral": {
        "metadata": {"n_cycles": 6, "n_takes": 3, "time_warping": "DTW", "dtw_spread": {"before": 0.00912,
                                                                                     "after": 0.00833},
                     "stride_m": [0.0, 0.0, 1.3482], "cycle_duration_s": 1.10185, "ik_error_max_m": 0.00667,
                     "captured_sources": [{"dataset": "bandai-namco-2", "cycles": 4},
                                          {"dataset": "bandai-namco-1", "cycles": 2},
                                          {"dataset": "bandai-namco-2", "cycles": 0}]},
        "bases": {"real (averaged)": {
            "speed_m_s": 1.2294, "cadence_steps_min": 109.0909, "stance_knee_deg": 39.903, "pelvis_bounce_cm": 3.7915,
            "observer": {"happy": 0.181, "sad": 0.135, "angry": 0.176, "neutral": 0.508},
            "inside": {"speed_m_s": True, "cadence_steps_min": True, "stance_knee_deg": False,
                       "pelvis_bounce_cm": True}}},
        "real_ranges": {"speed_m_s": [1.12, 1.34], "cadence_steps_min": [106.4, 112.5],
                        "stance_knee_deg": [32.96, 41.71], "pelvis_bounce_cm": [3.18, 4.79]},
        "real_takes": 26, "real_test_normal_read": {"happy": 0.171, "sad": 0.144, "angry": 0.175, "neutral": 0.509}},
    "accuracy": {"happy_vs_sad": {"takes": 2, "accuracy": 1.0}, "empty": {"takes": 0, "accuracy": None}},
    "compare": {"happy": {"used_overlap": 3, "expert_features": [["wrists", "Z"]] * 10, "shared_dofs": 6,
                          "sign_agreement": 0.6667, "median_ratio": None,
                          "data_features": [["wrists", "Y"], ["elbows", "Z"]],
                          "rows": [_dof("left_hand", "Y", None, 0.129, None, None, None, None),
                                   _dof("right_hand", "X", -0.025, 0.078, False, 0.22, 3.12, -0.32)]}},
    "observers": {
        "happy": {"pair": "happy_vs_sad", "neutral": 0.61, "real_test": 0.8175, "real_test_takes": 1,
                  "expert_0.7": 0.64, "expert_0.7_emotion_p": 0.18, "data_0.7": 0.67, "data_0.7_emotion_p": 0.276,
                  "expert_1.0": 0.676, "expert_1.0_emotion_p": 0.174, "data_1.0": 0.71, "data_1.0_emotion_p": 0.314,
                  "real_test_emotion_p": 0.799},
        "tired": {"pair": "energetic_vs_tired", "neutral": 0.909, "real_test": 0.933, "real_test_takes": 5,
                  "expert_0.7": 0.916, "data_0.7": 0.717, "expert_1.0": 0.5, "data_1.0": 0.555}},
    "ablation": {"happy": {"p_full": 0.676, "rows": [_ablated(1, 0.656, "neither"), _ablated(4, 0.61, "expert")]},
                 "masculine": {"p_full": 0.592, "rows": [_ablated(5, 0.914, "data")]}},
}


def test_rbf_real_tables_render_the_figures():
    t = doc_tables.render_tables("rbf_real", RBF_REAL)
    assert set(t) == set(doc_tables.TABLES["rbf_real"])
    assert t["rbf_real.run"][2:] == ["| machine | test VM |", "| date | 2026-12-03 |",
                                     "| command | `python benchmarks/bench_rbf_real.py --doc d.md` |",
                                     "| transcribed from | a doc |"]
    cycle = t["rbf_real.neutral_cycle"]
    assert "| steady two-step cycles | 6 from 3 train-split normal walks |" in cycle
    # sources without a steady cycle are not counted; datasets in name order
    assert "| per dataset | bandai-namco-1: 2 cycles from 1 takes, bandai-namco-2: 4 cycles from 1 takes |" in cycle
    assert cycle[-4:] == ["| cycle spread (mean per-frame standard deviation, walker heights) after contact warping / "
                          "after DTW | 0.0091 / 0.0083 |", "| cycle | 1.102 s |", "| stride | 1.348 m |",
                          "| IK re-fit error (max) | 6.7 mm |"]
    assert t["rbf_real.neutral_checks"][2:] == [
        "| real (averaged) | 1.23 | 109.09 | 39.90 **(outside)** | 3.79 | 0.18/0.14/0.18/0.51 |",
        "| real normal walks (range of 26) | 1.12-1.34 | 106.40-112.50 | 32.96-41.71 | 3.18-4.79 "
        "| test takes: 0.17/0.14/0.17/0.51 |"]
    assert t["rbf_real.accuracy"][2:] == ["| happy_vs_sad | 2 | 1.00 |", "| empty | 0 | - |"]
    assert t["rbf_real.compare"][2:] == ["| happy | 3 of 10 | 6 | 0.67 | - | wrists Y, elbows Z |"]
    assert t["rbf_real.top_dofs"][2:] == ["| happy | left_hand Y | - | +0.129 | - | - | - | - |",
                                          "| happy | right_hand X | -0.025 | +0.078 | **no** | 0.22 | 3.12 | -0.32 |"]
    # data preferred only where they win at every weight
    assert t["rbf_real.observers"][0] == ("| theme (pair) | neutral | expert 0.7 | data 0.7 | expert 1.0 | data 1.0 "
                                          "| real test takes | observer prefers |")
    assert t["rbf_real.observers"][2:] == [
        "| happy (happy_vs_sad) | 0.61 | 0.64 | 0.67 | 0.68 | 0.71 | 0.82 (1) | data |",
        "| tired (energetic_vs_tired) | 0.91 | 0.92 | 0.72 | 0.50 | 0.56 | 0.93 (5) | mixed |"]
    assert t["rbf_real.ablation"][2:] == [
        "| happy | 0.68 | feature 1 (1) | data reverse its sign | 0.66 | neither |",
        "| happy | 0.68 | feature 4 (4) | data reverse its sign | 0.61 | expert |",
        "| masculine | 0.59 | feature 5 (5) | data reverse its sign | 0.91 | data |"]
    assert t["rbf_real.ablation_totals"][2:] == ["| disputed expert features | 1 | 1 | 1 | 3 |"]
    # only themes that are emotions have the four-emotion observer's reading
    assert t["rbf_real.emotion_observer"][0] == ("| theme | expert 0.7 | data 0.7 | expert 1.0 | data 1.0 "
                                                 "| real dataset-1 test take |")
    assert t["rbf_real.emotion_observer"][2:] == ["| happy | 0.18 | 0.28 | 0.17 | 0.31 | 0.80 |"]


def _check(feature, sign, change, holds):
    return {"feature": feature, "aggregate": "mean", "expected_sign": sign, "change": change, "holds": holds,
            "reason": "head down"}


RBF_FEATURES = {
    "machine": "test VM", "date": "2026-12-03", "command": "python benchmarks/bench_rbf_features.py",
    "feature_names": ["ang:a-b-c", "dist:d-e/f-g"],
    "rows": [{"theme": "sad", "weight": 0.7, "mean_change": [-0.0, 0.01234],
              "checks": [_check("ang:a-b-c", -1, -0.02131, True)],
              "measures": [{"measure": "head_height", "expected_sign": -1, "change_m": -0.01234, "holds": True}],
              "bone_error_before_m": 0.0266, "bone_error_after_m": 4.2e-16, "ik_direction_only_after_m": 1.7e-16,
              "lowest_foot_m": -1e-6, "lowest_foot_direction_only_m": -0.0184, "ground_lift_m": 0.0},
             {"theme": "sad", "weight": -0.7, "mean_change": [0.0, -0.5],
              "checks": [_check("ang:a-b-c", 1, -0.001, False)],
              "measures": [{"measure": "head_height", "expected_sign": 1, "change_m": 0.0021, "holds": True}],
              "bone_error_before_m": 0.0295, "bone_error_after_m": 5.3e-16, "ik_direction_only_after_m": 1.7e-16,
              "lowest_foot_m": 0.0012, "lowest_foot_direction_only_m": 0.0184, "ground_lift_m": 0.0423}],
    "summary": {"checks_held": 1, "checks": 2, "measures_held": 2, "measures": 2,
                "failed": ["sad w = -0.7: ang:a-b-c"], "bone_error_before_max_m": 0.0295,
                "bone_error_after_max_m": 5.3e-16, "lowest_foot_m": -1e-6, "lowest_foot_direction_only_m": -0.0184},
    "base_function": "generation.rbf.real_neutral.load_cycle()",
    "timing": {"stylise_clip_s": 0.1504, "clip_frames": 132, "neutral_base_s": 0.0123},
    "neutral_base": {"n_cycles": 72, "cycle_duration_s": 1.1019, "stride_m": [0.0, 0.0, 1.348], "synthetic": False,
                     "captured_sources": [{"name": "a", "cycles": 4}, {"name": "b", "cycles": 0,
                                                                        "rejected_cycles": 2}]},
    "scaling": {"sad": [[0.3, 0.5], [1.0, 1.5]]}, "scaling_axes": {"n": [1, 10], "w": [0.4, 1.3]},
}


def test_rbf_features_tables_render_the_figures():
    t = doc_tables.render_tables("rbf_features", RBF_FEATURES)
    assert set(t) == set(doc_tables.TABLES["rbf_features"])
    assert "| command | `python benchmarks/bench_rbf_features.py` |" in t["rbf_features.run"]
    base = t["rbf_features.neutral_base"]
    assert "| function | `generation.rbf.real_neutral.load_cycle()` |" in base
    assert base[4:] == ["| cycles rejected as glitches | 2 |", "| cycle | 1.10 s |", "| stride | 1.35 m |",
                        "| synthetic | False |", "| sources used (cycles) | a (4) |"]
    assert t["rbf_features.summary"][2:] == [
        "| expected directions that hold, 18 gait affective features | 1 of 2 |",
        "| expected directions that hold, direct geometric measures | 2 of 2 |",
        "| not holding | sad w = -0.7: ang:a-b-c |",
        "| largest bone-length deviation of the edited positions Y | 30 mm |",
        "| largest bone-length deviation after the fit | 5.3e-13 mm |",
        "| lowest foot joint relative to the neutral floor: our fit / `generation.core.ik.fit_positions_to_skeleton` "
        "(direction-only) | -0.0 mm / -18.4 mm |",
        "| stylising one 4-cycle clip at 30 fps | 150 ms (132 frames) |",
        "| loading the neutral base | 0.01 s |"]
    assert t["rbf_features.feature_key"] == ["Feature key: f0 = ang:a-b-c; f1 = dist:d-e/f-g"]
    assert t["rbf_features.mean_change"] == ["| theme | w | f0 | f1 |", "|---|---|---|---|",
                                             "| sad | +0.7 | -0.000 | +0.012 |", "| sad | -0.7 | +0.000 | -0.500 |"]
    assert t["rbf_features.feature_checks"][2:] == [
        "| sad | +0.7 | ang:a-b-c | mean | - | -0.0213 | yes | head down |",
        "| sad | -0.7 | ang:a-b-c | mean | + | -0.0010 | **no** | inverse of: head down |"]
    assert t["rbf_features.measure_checks"][2:] == ["| sad | +0.7 | head_height | - | -12.3 | yes |",
                                                    "| sad | -0.7 | head_height | + | +2.1 | yes |"]
    assert t["rbf_features.bones_floor"][2:] == ["| sad | +0.7 | 26.6 | 4.2e-13 | 1.7e-13 | -0.0 | -18.4 | 0.0 |",
                                                 "| sad | -0.7 | 29.5 | 5.3e-13 | 1.7e-13 | +1.2 | +18.4 | 42.3 |"]
    assert t["rbf_features.scaling"] == ["| theme | n | w 0.4 | w 1.3 |", "|---|---|---|---|",
                                         "| sad | 1 | 0.30 | 0.50 |", "| sad | 10 | 1.00 | 1.50 |"]
    procedural = dict(RBF_FEATURES, base_function="generation.rbf.neutral_base.neutral_cycle()",
                      summary=dict(RBF_FEATURES["summary"], failed=[]))
    t = doc_tables.render_tables("rbf_features", procedural)
    assert "| not holding | none |" in t["rbf_features.summary"]
    assert t["rbf_features.summary"][-1] == "| building the neutral base | 0.01 s |"


def _group(real_read, real_p, synthetic_read, synthetic_p, origins, flags):
    return {"n": len(real_read), "origins": origins, "real_read": real_read, "real_p": real_p,
            "synthetic_read": synthetic_read, "synthetic_p": synthetic_p, "flag_observer_real": flags}


def _stats(n, median, lo, hi, p5, p95):
    return {"n": n, "median": median, "min": lo, "max": hi, "p5": p5, "p95": p95}


REAL_OBSERVER = {
    "date": "2026-12-03", "commit": "commit abc1234 + uncommitted changes", "machine": "test VM", "seconds": 107.8,
    "corpus": "c.npz", "observer_source": "real corpus", "synthetic_source": "synthetic corpus",
    "train_takes": {"happy": 3, "sad": 2},
    "held_out": {"n_takes": 8, "accuracy_takes": 0.875, "accuracy_windows": 0.846,
                 "confusion_takes": [[2, 0, 0, 0], [0, 2, 0, 0], [0, 0, 1, 1], [0, 0, 0, 0]],
                 "confusion_windows": [[14, 0, 0, 0], [0, 49, 0, 0], [0, 0, 7, 14], [0, 0, 0, 7]],
                 "themes": {"energetic_vs_tired": {"n": 44, "accuracy": 0.977, "wrong": ["t1"],
                                                   "per_dataset": {"bandai-namco-1": 4, "bandai-namco-2": 40}}}},
    "leave_one_take_out": {"n_takes": 20, "accuracy": 0.75,
                           "confusion": [[4, 0, 0, 1], [0, 4, 0, 1], [1, 0, 3, 1], [0, 1, 0, 4]]},
    "themes_in_plans": {"demo": [{"entry": "tired_w0.7", "generator": "rbf", "theme": "tired", "weight": 0.7,
                                  "pair": "energetic_vs_tired", "p_theme": 0.948}], "seed000": []},
    "plans": {"demo": {
        "sad": _group(["sad", "neutral"], [0.45, 0.49], [None, None], [None, None],
                      ["source captured_file", "generated gait_net"], 1),
        "(none)": _group(["neutral", "angry", "neutral"], [0.4, 0.5, 0.3], ["sad", None, "sad"], [0.7, None, 0.9],
                         ["generated gait_net", "source neutral_walk", "generated gait_net"], 0)}},
    "thresholds": {"skate_cm_s_max": 100.8371, "speed_cv_min": 0.0164}, "not_applied": {"speed_cv_min": "why"},
    "ranges_rule": "pooled percentiles", "ranges_test_flagged": 0.1046,
    "realism": {"real 1: happy": {"skate_cm_s": _stats(5, 26.491, 19.263, 74.39, 20.474, 73.027),
                                  "speed_cv": _stats(3, 0.034, 0.021, 0.035, 0.022, 0.035)},
                "demo generated (gait_net 6)": {"skate_cm_s": {"n": 0},
                                                "speed_cv": _stats(9, 0.013, 0.005, 0.143, 0.007, 0.107),
                                                "realism_flagged": 7, "bounds_broken": {"toe_skim>": 4,
                                                                                        "speed_cv<": 6}}},
}


def test_real_observer_tables_render_the_figures():
    t = doc_tables.render_tables("real_observer", REAL_OBSERVER)
    assert set(t) == set(doc_tables.TABLES["real_observer"])
    assert t["real_observer.run"][2:] == ["| machine | test VM |", "| date | 2026-12-03 |",
                                          "| commit | abc1234 + uncommitted changes |", "| duration | 108 s |",
                                          "| corpus | c.npz |", "| real-capture observer | real corpus |",
                                          "| synthetic observer | synthetic corpus |"]
    assert t["real_observer.emotion_accuracy"][2:] == ["| held out (test split) | 5 | 8 | 0.88 | 0.85 |",
                                                       "| leave one take out (train and test split) | 19 | 20 | 0.75 "
                                                       "| - |"]
    assert t["real_observer.confusion_takes"] == ["| intended \\ read | happy | sad | angry | neutral | recall |",
                                                  "|---|---|---|---|---|---|",
                                                  "| happy | 2 | 0 | 0 | 0 | 1.00 |", "| sad | 0 | 2 | 0 | 0 | 1.00 |",
                                                  "| angry | 0 | 0 | 1 | 1 | 0.50 |", "| neutral | 0 | 0 | 0 | 0 | - |"]
    assert t["real_observer.confusion_windows"][4] == "| angry | 0 | 0 | 7 | 14 | 0.33 |"
    assert t["real_observer.confusion_loto"][4] == "| angry | 1 | 0 | 3 | 1 | 0.60 |"
    assert t["real_observer.themes"][2:] == ["| energetic vs tired | 44 | 0.98 | bandai-namco-1: 4, bandai-namco-2: 40 "
                                             "| t1 |"]
    assert t["real_observer.plan_themes"][2:] == ["| demo | tired_w0.7 | rbf | tired | 0.7 | energetic vs tired "
                                                  "| 0.95 |"]
    # groups in name order; labels most frequent first, a missing label as 'none'; median of the known p
    assert t["real_observer.plans"][2:] == [
        "| demo | (none) | 3 | generated gait_net 2, source neutral_walk 1 | neutral 2, angry 1 (0.40) "
        "| sad 2, none 1 (0.80) | 0 |",
        "| demo | sad | 2 | generated gait_net 1, source captured_file 1 | sad 1, neutral 1 (0.47) | no reading | 1 |"]
    assert t["real_observer.thresholds"][2:] == ["| rule | pooled percentiles |", "| skate_cm_s_max | 100.837 |",
                                                 "| speed_cv_min | 0.0164 (not applied) |",
                                                 "| held-out real takes outside the bounds | 10% |"]
    # median (p5-p95), or (min-max) under 5 values; bounds broken in name order
    assert t["real_observer.realism"] == [
        "| group | skate_cm_s | speed_cv | realism flags (bounds broken: clips) |", "|---|---|---|---|",
        "| real 1: happy | 26.5 (20.5-73) | 0.034 (0.021-0.035) |  |",
        "| demo generated (gait_net 6) | - | 0.013 (0.007-0.107) | 7 (speed_cv< 6, toe_skim> 4) |"]


def test_two_areas_share_a_doc_without_touching_each_others_blocks(tmp_path):
    doc = tmp_path / "rbf.md"
    doc.write_text("<!-- table: rbf_features.feature_key -->\nold key\n<!-- /table -->\n\n"
                   "<!-- table: rbf_real.ablation_totals -->\nold totals\n<!-- /table -->\n")
    (tmp_path / "rbf_real.json").write_text(json.dumps(RBF_REAL))
    assert doc_tables.update_doc("rbf_real", tmp_path / "rbf_real.json", doc) == ["rbf_real.ablation_totals"]
    assert "old key" in doc.read_text() and "old totals" not in doc.read_text()
    (tmp_path / "rbf_features.json").write_text(json.dumps(RBF_FEATURES))
    assert doc_tables.update_doc("rbf_features", tmp_path / "rbf_features.json", doc) == ["rbf_features.feature_key"]
    assert "Feature key: f0 = ang:a-b-c" in doc.read_text() and "| disputed expert features | 1 | 1 | 1 | 3 |" \
        in doc.read_text()


def _errors(diag, step1, steps2_5, later, cm, deg):
    return {"pose_error_body_diag": diag, "pose_error_body_diag_step1": step1,
            "pose_error_body_diag_steps2_5": steps2_5, "pose_error_body_diag_later": later, "pose_error_cm": cm,
            "rotation_error_deg": deg}


def _recognition(ns, own, as_neutral):
    return {"per_class": {e: {"n": n, "own": o, "as_neutral": a}
                          for e, n, o, a in zip(doc_tables.EMOTIONS, ns, own, as_neutral)}}


def _realism(n, medians, inside):
    return {"n": n, "measures": {m: None if v is None else {"min": 0.0, "median": v, "max": 9.0}
                                 for m, v in zip(("skate_cm_s", "speed_cv"), medians)},
            "inside_share": dict(zip(("skate_cm_s", "speed_cv"), inside))}


GAIT_REAL = {
    "date": "2026-12-05", "machine": "test VM", "commit": "commit abc1234", "seconds": 241.4,
    "command": "python benchmarks/bench_gait_real.py --before old.pt",
    "corpus": {"path": "var/mocap/c.npz", "sha256": "0123456789abcdef"},
    "weights": {"real-trained": {"path": "new.pt", "sha256": "fedcba9876543210"},
                "real-trained (before)": {"path": "old.pt", "sha256": None}},
    "prefix": 9, "horizon": 21,
    "prediction": {"all held-out forward locomotion": {"n": 567, "takes": 138, "methods": {
        "real-trained": _errors(0.0524, 0.0226, 0.0384, 0.0575, 9.74, 14.46),
        "real-trained (before)": _errors(0.061, 0.03, 0.04, 0.07, 11.0, None)}},
        "held-out emotion walks": {"n": 54, "takes": 8, "methods": {
            "last pose held": _errors(0.066, 0.039, 0.082, 0.064, 12.2, 8.4)}}},
    "recognition": {"real-trained, held-out seed walks": _recognition([6, 6, 6, 6], [0.0, 0.5, 1.0, 0.8333],
                                                                      [1 / 3, 0.5, 0.0, 0.8333]),
                    "real-trained (before), seed000 plan": _recognition([8, 8, 6, None], [0.0, 0.25, 2 / 3, None],
                                                                        [0.625, 0.75, 1 / 3, None])},
    "real_realism": {"happy": {"skate_cm_s": {"min": 67.61, "median": 70.0, "max": 74.44}, "speed_cv": None,
                               "takes": 2},
                     "sad": {"skate_cm_s": {"min": 30.4, "median": None, "max": 46.5},
                             "speed_cv": {"min": 0.061, "median": 0.08, "max": 0.114}, "takes": None}},
    "realism": {"real-trained, seed000 plan": {"happy": _realism(8, [36.04, 0.0312], [1.0, 0.625]),
                                               "sad": _realism(8, [52.3, None], [0.875, None])},
                "real-trained (before), seed000 plan": {"sad": _realism(8, [50.0, 0.06], [None, 0.375])}},
    "mixture_response": {"happy": {"0": {"n": 2, "p_emotion": 0.131, "p_neutral": 0.503, "as_emotion": 0.0,
                                         "as_neutral": 1.0},
                                   "0.8": {"n": 2, "p_emotion": 0.352, "p_neutral": 0.318, "as_emotion": 0.5,
                                           "as_neutral": 0.5}}},
    "real_take_reading": {"real takes, test split": _recognition([1, 1, 1, 1], [1.0, 1.0, 0.0, 1.0],
                                                                 [0.0, 0.0, 1.0, 1.0])},
    "plan_reading": {"real-trained": {
        **_recognition([10, 10, 9, 11], [0.4, 0.7, 4 / 9, 1.0], [0.6, 0.3, 5 / 9, 1.0]),
        "by_kind": {"pure": {"n": 8, "read_as_asked": 1.0}, "mixture": {"n": 8, "read_as_asked": 0.625},
                    "transition": {"n": 24, "read_as_asked": 0.5}},
        "parts": [{"clip": "single_happy_loop", "kind": "pure", "part": "whole", "asked": "happy",
                   "components": ["happy"], "read": "happy", "p": [0.361, 0.082, 0.27, 0.288]},
                  {"clip": "single_happy_angry", "kind": "mixture", "part": "whole", "asked": None,
                   "components": ["happy", "angry"], "read": "angry", "p": [0.307, 0.065, 0.34, 0.288]},
                  {"clip": "transition_sad_to_happy", "kind": "transition", "part": "last 4 s", "asked": "happy",
                   "components": ["happy", "neutral"], "read": "neutral", "p": [0.247, 0.207, 0.173, 0.372]}]}},
}


def test_gait_real_tables_render_the_figures():
    t = doc_tables.render_tables("gait_real", GAIT_REAL)
    assert set(t) == set(doc_tables.TABLES["gait_real"])
    assert t["gait_real.run"][2:] == [
        "| machine | test VM |", "| date | 2026-12-05 |", "| commit | abc1234 |",
        "| command | `python benchmarks/bench_gait_real.py --before old.pt` |", "| duration | 241 s |",
        "| corpus | `var/mocap/c.npz` (sha256 0123456789ab...) |",
        "| weights 'real-trained' | `new.pt` (sha256 fedcba987654...) |",
        "| weights 'real-trained (before)' | `old.pt` |"]
    # each subset its own table, methods in the JSON's order, a missing figure as '-'
    assert t["gait_real.prediction_all"][0] == "567 windows of 138 test takes; 9 network steps given, 21 predicted:"
    assert t["gait_real.prediction_all"][4:] == ["| real-trained | 0.052 | 0.023 | 0.038 | 0.058 | 9.7 | 14.5 |",
                                                 "| real-trained (before) | 0.061 | 0.030 | 0.040 | 0.070 | 11.0 | - |"]
    assert t["gait_real.prediction_emotion"][0] == "54 windows of 8 test takes; 9 network steps given, 21 predicted:"
    assert t["gait_real.prediction_emotion"][4:] == ["| last pose held | 0.066 | 0.039 | 0.082 | 0.064 | 12.2 | 8.4 |"]
    # one row per set of walks; read as asked / as neutral, neutral only as asked; n as a range
    assert t["gait_real.emotion"][0] == ("| walks | n per emotion | happy: as asked / as neutral "
                                         "| sad: as asked / as neutral | angry: as asked / as neutral | neutral |")
    assert t["gait_real.emotion"][2:] == [
        "| real-trained, held-out seed walks | 6 | 0.00 / 0.33 | 0.50 / 0.50 | 1.00 / 0.00 | 0.83 |",
        "| real-trained (before), seed000 plan | 6-8 | 0.00 / 0.62 | 0.25 / 0.75 | 0.67 / 0.33 | - |"]
    # grouped by emotion: the real takes' range first, then each set of walks' median (share inside)
    assert t["gait_real.realism"] == [
        "| emotion | walks | n | foot skate cm/s | speed CV |", "|---|---|---|---|---|",
        "| happy | real takes (min-max) | 2 | 67.6-74.4 | - |",
        "| happy | real-trained, seed000 plan | 8 | 36.0 (1.00) | 0.03 (0.62) |",
        "| sad | real takes (min-max) | - | 30.4-46.5 | 0.06-0.11 |",
        "| sad | real-trained, seed000 plan | 8 | 52.3 (0.88) | - |",
        "| sad | real-trained (before), seed000 plan | 8 | 50.0 | 0.06 (0.38) |"]


def test_gait_real_mixture_table_has_a_column_per_share():
    t = doc_tables.render_tables("gait_real", GAIT_REAL)["gait_real.mixture_response"]
    assert t == ["| emotion | share 0 | share 0.8 |", "|---|---|---|",
                 "| happy | 0.13 / 0.50 (0 of 2) | 0.35 / 0.32 (1 of 2) |"]


def test_gait_real_plan_tables_put_the_real_takes_first_and_name_each_part():
    t = doc_tables.render_tables("gait_real", GAIT_REAL)
    assert t["gait_real.plan_reading"][0] == (
        "| walks | happy: as asked / as neutral | sad: as asked / as neutral | angry: as asked / as neutral "
        "| neutral | pure clips | mixtures | transition ends |")
    assert t["gait_real.plan_reading"][2:] == [
        "| real takes, test split | 1.00 / 0.00 (n 1) | 1.00 / 0.00 (n 1) | 0.00 / 1.00 (n 1) | 1.00 | - | - | - |",
        "| real-trained | 0.40 / 0.60 (n 10) | 0.70 / 0.30 (n 10) | 0.44 / 0.56 (n 9) | 1.00 | 1.00 (n 8) "
        "| 0.62 (n 8) | 0.50 (n 24) |"]
    assert t["gait_real.plan_parts"][2:] == [
        "| single_happy_loop | whole | happy | happy | 0.36 0.08 0.27 0.29 |",
        "| single_happy_angry | whole | tie: happy/angry | angry | 0.31 0.07 0.34 0.29 |",
        "| transition_sad_to_happy | last 4 s | happy | neutral | 0.25 0.21 0.17 0.37 |"]


def test_upsampling_tables_compare_the_two_methods():
    r = {"date": "2026-12-05", "seconds": 9.6,
         "real_round_trip": {"angry": {"take": "walk_angry_001.bvh", "seconds": 4.73, "capture": {"jerk": 398.4},
                                       "slerp": {"jerk": 711.2, "position_error_cm": 1.918},
                                       "spline": {"jerk": 284.6, "position_error_cm": 0.994}}},
         "generated": {"sad": {"straight 10 m": {"slerp": {"jerk": 61.7, "toe_skim": 0.342, "skate_cm_s": 54.4},
                                                 "spline": {"jerk": 25.2, "toe_skim": None, "skate_cm_s": 53.1}}}},
         "gestures": {"afraid": {"slerp": {"jerk": 17.6, "peak_hand_speed": 1.361},
                                 "spline": {"jerk": 5.8, "peak_hand_speed": 1.528}}},
         "call_ms": {"slerp": 1.04, "spline": 2.26, "frames_in": 49}}
    t = doc_tables.render_tables("upsampling", r)
    assert t["upsampling.run"][2:] == ["| date | 2026-12-05 |", "| duration | 10 s |",
                                       "| one call, 10 s walk at 7.5 Hz to 30 fps | slerp 1.0 ms / spline 2.3 ms |"]
    assert t["upsampling.gestures"][2:] == ["| afraid | 18 -> 6 | 1.36 -> 1.53 |"]
    assert t["upsampling.real"][2:] == ["| angry | walk_angry_001.bvh (4.7 s) | 398 | 1.92 | 0.99 | 711 | 285 |"]
    assert t["upsampling.generated"][2:] == ["| sad | straight 10 m | 62 -> 25 | 0.34 -> - | 54 -> 53 |"]


def test_the_gait_doc_holds_the_real_capture_tables_in_their_section():
    """The gait_real blocks sit in gait.md's 'Trained on real capture' section, the synthetic gait blocks outside."""
    text = (doc_tables.DOCS / "gait.md").read_text()
    start = text.index("### Trained on real capture")
    end = text.index("\n### ", start + 1)
    for m in doc_tables.BLOCK_RE.finditer(text):
        inside = start < m.start() < end
        assert inside == m.group("name").startswith("gait_real."), m.group("name")


def test_write_results_renders_the_doc_only_for_the_areas_own_json(tmp_path, monkeypatch):
    own, doc = tmp_path / "gait.json", tmp_path / "gait.md"
    doc.write_text(DOC)
    monkeypatch.setattr(doc_tables, "area_files", lambda area: (own, doc))
    doc_tables.write_results("gait", tmp_path / "candidate.json", RESULTS, 1.0)
    assert json.loads((tmp_path / "candidate.json").read_text()) == RESULTS
    assert doc.read_text() == DOC                                  # a candidate's run leaves the doc alone
    doc_tables.write_results("gait", own, RESULTS, 1.0)
    assert "| stale | table |" not in doc.read_text() and "0.023" in doc.read_text()
