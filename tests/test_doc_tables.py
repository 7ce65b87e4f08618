"""benchmarks/doc_tables.py: tables rendered from benchmark JSON replace exactly their marked blocks in a doc."""
from __future__ import annotations

import json
import sys
from pathlib import Path

import pytest

sys.path.insert(0, str(Path(__file__).resolve().parent.parent / "benchmarks"))

import doc_tables  # noqa: E402

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


def test_the_gait_doc_marks_every_gait_table():
    text = (doc_tables.DOCS / "gait.md").read_text()
    marked = {m.group("name") for m in doc_tables.BLOCK_RE.finditer(text)}
    assert marked == set(doc_tables.TABLES["gait"])


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
