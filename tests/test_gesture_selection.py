"""Choosing the kept gesture-network epoch by the real captured range (generation.gesture.selection)."""
from __future__ import annotations

import numpy as np
import pytest
import torch

from generation.gesture.data import nrc_vad, with_emotions
from generation.gesture.model import GestureNetConfig
from generation.gesture.real_stats import in_range_shares, mean_share
from generation.gesture.selection import chosen_epoch, real_range_score
from generation.gesture.train import TrainConfig, build_parser, config_from_args, train


def _entry(epoch, pose, share, r=0.7):
    return {"epoch": epoch, "val_rollout": {"pose_error": pose, "r_peak_arousal": r},
            "val_real_range": {"share": share}}


def test_rule_keeps_the_largest_share_within_the_pose_bound():
    history = [_entry(-1, 0.0060, 0.70),   # the lowest pose error: what the pose rule would keep
               _entry(0, 0.0069, 0.80),    # within the bound, the largest share there: kept
               _entry(1, 0.0080, 0.90),    # the largest share overall, but outside the bound
               _entry(2, 0.0065, 0.75),
               {"epoch": 3, "val": {}}]    # not measured this epoch
    assert chosen_epoch(history, max_pose_error=0.007) == 0
    assert chosen_epoch(history, max_pose_error=0.009) == 1
    assert chosen_epoch(history, max_pose_error=0.0062) == -1
    # equal shares: the first one stays (training replaces the kept state only on a strictly lower score)
    assert chosen_epoch(history + [_entry(4, 0.0061, 0.80)], max_pose_error=0.007) == 0


def test_rule_can_also_bound_the_arousal_correlation():
    history = [_entry(0, 0.0060, 0.70, r=0.75), _entry(1, 0.0062, 0.85, r=0.55), _entry(2, 0.0064, 0.78, r=0.68),
               _entry(3, 0.0061, 0.90, r=float("nan"))]
    assert chosen_epoch(history, max_pose_error=0.007) == 3
    assert chosen_epoch(history, max_pose_error=0.007, min_r=0.6) == 2
    assert chosen_epoch(history, max_pose_error=0.0063, min_r=0.6) == 0
    assert chosen_epoch(history, max_pose_error=0.007, min_r=0.8) == 0  # none within: the lowest pose error


def test_rule_falls_back_to_the_lowest_pose_error():
    history = [_entry(0, 0.0090, 0.95), _entry(1, 0.0075, 0.60), _entry(2, 0.0080, 0.99)]
    assert chosen_epoch(history, max_pose_error=0.007) == 1
    assert real_range_score(0.0060, 0.0, 0.007) < real_range_score(0.0071, 1.0, 0.007)
    assert real_range_score(0.0060, float("nan"), 0.007) == 0.0
    assert chosen_epoch([{"epoch": 0}], 0.007) == -1


def test_in_range_shares_per_emotion_and_statistic():
    ranges = {"all": {"a": (0, 10), "b": (0, 10)}, "sad": {"a": (0.0, 1.0), "b": (2.0, 3.0)},
              "proud": {"a": (5.0, 6.0), "b": (0.0, 1.0)}}
    rows = [{"emotion": "sad", "a": 0.5, "b": 2.5}, {"emotion": "sad", "a": 1.5, "b": 2.0},
            {"emotion": "proud", "a": 5.0, "b": 4.0}, {"emotion": "afraid", "a": 0.0, "b": 0.0}]
    shares = in_range_shares(rows, ranges, stats=("a", "b"))
    assert shares == {"sad": {"a": 0.5, "b": 1.0}, "proud": {"a": 1.0, "b": 0.0}}  # afraid: no range of its own
    assert mean_share(shares) == pytest.approx(0.625)


def test_with_emotions_says_each_example_with_each_emotion(tiny_data):
    idx = tiny_data.indices("val")[:2]
    fake = with_emotions(tiny_data, idx, ("sad", "angry", "joyous"))
    assert len(fake) == 6 and list(fake.emotion) == ["sad", "angry", "joyous"] * 2
    assert list(fake.sentence_index) == list(np.repeat(tiny_data.sentence_index[idx], 3))
    np.testing.assert_allclose(fake.vad[1], nrc_vad("angry"), atol=1e-6)
    np.testing.assert_allclose(fake.attributes[1, 2:5], nrc_vad("angry"), atol=1e-6)
    other = np.r_[0:2, 5:9]  # task, gender and handedness stay the example's own
    np.testing.assert_array_equal(fake.attributes[3][other], tiny_data.attributes[idx[1]][other])


def test_cli_real_range_selection_needs_rollouts():
    cfg = config_from_args(build_parser().parse_args(["--device", "cpu", "--select", "real-range",
                                                      "--max-pose-error", "0.0063"]))
    assert (cfg.select, cfg.max_pose_error, cfg.min_arousal_r) == ("real-range", 0.0063, None)
    assert config_from_args(build_parser().parse_args(["--device", "cpu"])).select == "pose"
    with pytest.raises(ValueError, match="rollout-every"):
        config_from_args(build_parser().parse_args(["--device", "cpu", "--select", "real-range",
                                                    "--rollout-every", "0"]))


@pytest.fixture(scope="module")
def tiny_data(tmp_path_factory):
    from generation.gesture.data import build_dataset, load_sentences

    rows = [r for r in load_sentences() if r.emotion in ("sad", "proud")][::6]  # 10 sentences
    return build_dataset(variants=1, seed=0, cache_dir=tmp_path_factory.mktemp("gesture_cache"), rows=rows)


def test_training_keeps_the_epoch_the_rule_chooses_and_records_the_real_statistics(tmp_path, tiny_data):
    from generation.gesture.real_range import load_ranges

    model = GestureNetConfig(d_model=16, d_ff=32, dropout=0.0)
    start = TrainConfig(epochs=1, batch_size=4, max_minutes=None, rollout_every=1, model=model, device="cpu",
                        out=str(tmp_path / "start.pt"), checkpoint=str(tmp_path / "ck0.pt"))
    train(start, data=tiny_data, progress=False)
    cfg = TrainConfig(epochs=3, batch_size=4, max_minutes=None, rollout_every=1, model=model, device="cpu", lr=3e-3,
                      init_from=start.out, select="real-range", max_pose_error=1.0, keep_rollouts=str(tmp_path / "ep"),
                      out=str(tmp_path / "w.pt"), checkpoint=str(tmp_path / "ck.pt"))
    summary = train(cfg, data=tiny_data, progress=False)
    history = summary["history"]
    assert [h["epoch"] for h in history] == [-1, 0, 1, 2]  # the starting weights are a candidate
    shares = [h["val_real_range"]["share"] for h in history]
    assert all(0.0 <= s <= 1.0 for s in shares)
    n_val = len(tiny_data.indices("val"))
    assert history[0]["val_real_range"]["n"] == n_val * (len(load_ranges()["ranges"]) - 1)
    assert summary["best_epoch"] == chosen_epoch(history, 1.0) == history[int(np.argmax(shares))]["epoch"]
    blob = torch.load(tmp_path / "w.pt", map_location="cpu", weights_only=False)
    kept = (torch.load(tmp_path / "ep" / f"epoch{summary['best_epoch']:03d}.pt", weights_only=False)
            if summary["best_epoch"] >= 0 else torch.load(start.out, weights_only=False))
    assert all(torch.equal(blob["state_dict"][k], kept["state_dict"][k]) for k in blob["state_dict"])
    assert blob["trained_on"] == "synthetic procedural gestures"
    real = blob["real_statistics"]
    assert real["used_for"] == ["epoch selection"] and real["licence"] == "CC BY-NC 4.0"
    assert "arXiv:2306.08861" in real["citation"]
    assert summary["selected_by"].startswith("val_rollout_real_range_share")


def test_weight_average_is_the_share_weighted_mean():
    from generation.gesture.average import average_states

    a = {"w": torch.tensor([0.0, 2.0]), "b": torch.tensor(1.0)}
    b = {"w": torch.tensor([4.0, 6.0]), "b": torch.tensor(3.0)}
    out = average_states([a, b], [3.0, 1.0])  # shares are normalised: 0.75 a + 0.25 b
    torch.testing.assert_close(out["w"], torch.tensor([1.0, 3.0]))
    torch.testing.assert_close(out["b"], torch.tensor(1.5))
    with pytest.raises(ValueError):
        average_states([a, b], [1.0])
    with pytest.raises(ValueError):
        average_states([a], [0.0])


def test_shipped_weights_record_the_real_statistics_they_were_chosen_with():
    from generation.gesture import config
    from generation.gesture.real_range import provenance

    blob = torch.load(config.DEFAULT_WEIGHTS, map_location="cpu", weights_only=False)
    assert blob["trained_on"] == "synthetic procedural gestures"
    if blob["loss_weights"].get("real_range") or "real_statistics" in blob:
        real = blob["real_statistics"]
        assert real["licence"] == "CC BY-NC 4.0" and "arXiv:2306.08861" in real["citation"]
        assert real["sha256"] == provenance()["sha256"]  # the shipped ranges are the ones it was trained with


def test_weight_average_command_names_missing_inputs(tmp_path):
    from generation.gesture.average import main
    with pytest.raises(SystemExit, match="--run: no such file"):
        main(["--run", str(tmp_path / "none.pt"), "--epochs-dir", str(tmp_path), "--out", str(tmp_path / "o.pt")])
    (tmp_path / "run.pt").write_bytes(b"")
    with pytest.raises(SystemExit, match="--epochs-dir: no such file or folder"):
        main(["--run", str(tmp_path / "run.pt"), "--epochs-dir", str(tmp_path / "nope"), "--out", str(tmp_path / "o")])
