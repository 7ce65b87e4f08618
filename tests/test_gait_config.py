"""Configuration of the gait network: sections, flat names, the paper's size, the command line."""
from __future__ import annotations

import pytest
import torch

from generation.gait.config import (
    GaitDataConfig,
    GaitLossWeights,
    GaitModelConfig,
    GaitNetConfig,
    GaitTrainConfig,
)
from generation.gait.model import GaitNet

torch.set_num_threads(1)


def test_config_dicts_round_trip_by_section_and_name_bad_keys():
    odd = GaitNetConfig().with_overrides(gru_hidden=64, lambda_root=0.0, tf_decay=0.5, frame_step=2,
                                         pos_scale_m=0.2, notes={"run": "x"})
    assert odd.model == GaitModelConfig(gru_hidden=64)
    assert odd.loss == GaitLossWeights(root=0.0, pos_scale_m=0.2)
    assert odd.train == GaitTrainConfig(tf_decay=0.5) and odd.data == GaitDataConfig(frame_step=2)
    # The split form round-trips, tuples included.
    assert GaitNetConfig.from_dict(odd.to_dict()) == odd
    assert set(odd.to_dict()) == {"model", "data", "train", "loss", "notes"}
    assert GaitNetConfig.from_dict(GaitNetConfig.tiny().to_dict()).model.enc1_sizes == (8, 8)
    # A field missing from a stored section takes its default.
    partial = GaitNetConfig.tiny().to_dict()
    del partial["loss"]["class_style"]
    assert GaitNetConfig.from_dict(partial).loss.class_style == GaitLossWeights().class_style
    with pytest.raises(ValueError, match="unknown GaitModelConfig fields"):
        GaitNetConfig.from_dict({"model": {"gru_hiden": 3}})
    with pytest.raises(ValueError, match="unknown GaitNetConfig fields"):
        GaitNetConfig.from_dict({"model": {}, "optimiser": {}})
    # A flat dict (not split by section) is not a config.
    with pytest.raises(ValueError, match=r"unknown GaitNetConfig fields \['enc1_sizes'"):
        GaitNetConfig.from_dict({"enc1_sizes": [16, 16, 8], "gru_hidden": 256, "lambda_root": 1.0})
    with pytest.raises(ValueError, match=r"sections \['model'\] must be mappings"):
        GaitNetConfig.from_dict({"model": [1, 2]})


def test_config_overrides_take_flat_and_section_names():
    cfg = GaitNetConfig().with_overrides(gru_hidden=64, lambda_pose=0.5, **{"loss.fctc": 2.0, "train.lr": 0.01,
                                                                           "model.enc2_sizes": [4, 4]})
    assert (cfg.model.gru_hidden, cfg.model.enc2_sizes, cfg.loss.pose, cfg.loss.fctc, cfg.train.lr) == \
        (64, (4, 4), 0.5, 2.0, 0.01)
    assert GaitNetConfig() == GaitNetConfig()   # the default is not changed in place
    with pytest.raises(ValueError, match="unknown GaitNetConfig fields"):
        GaitNetConfig().with_overrides(**{"loss.lambda_pose": 1.0})
    assert GaitNetConfig.paper(epochs=3).train.epochs == 3
    assert GaitNetConfig.paper().model == GaitModelConfig.paper()
    assert GaitNetConfig().prefix_len == GaitDataConfig().prefix_len == 18
    with pytest.raises(TypeError, match="GaitModelConfig"):
        GaitNet(GaitNetConfig.tiny())


def test_paper_config_has_released_size_and_ablation_drops_affective_branch():
    assert 9.5e6 < GaitNet(GaitNetConfig.paper().model).num_parameters() < 10.5e6
    assert 9.5e6 < GaitNet(GaitModelConfig.paper()).num_parameters() < 10.5e6
    assert GaitNet(GaitNetConfig().model).num_parameters() < 1e6   # the CPU default
    ablated = GaitNet(GaitModelConfig.tiny(use_affective=False))
    assert ablated.fc_enc1 is None
    with pytest.raises(ValueError, match="unknown GaitNetConfig fields"):
        GaitNetConfig.from_dict({"gru_hiden": 3})


def test_command_line_options_build_the_config():
    from generation.gait.train import build_parser, config_from_args
    args = build_parser().parse_args(["--no-root-loss", "--no-affective", "--epochs", "3",
                                      "--set", "gru_hidden=64", "--set", "enc1_sizes=[4, 4]"])
    cfg = config_from_args(args)
    assert cfg.loss.root == 0.0 and not cfg.model.use_affective and cfg.train.epochs == 3
    assert cfg.model.gru_hidden == 64 and cfg.model.enc1_sizes == (4, 4)
    assert cfg.loss == GaitLossWeights(root=0.0) and cfg.data == GaitDataConfig()
    dotted = config_from_args(build_parser().parse_args(["--set", "loss.pose=0.5", "--set", "splice_frac=0",
                                                         "--set", "emotion_skip=false", "--seed", "2"]))
    assert dotted.loss.pose == 0.5 and dotted.train.splice_frac == 0 and not dotted.model.emotion_skip
    assert dotted.train.seed == 2
    paper = config_from_args(build_parser().parse_args(["--paper-size", "--epochs", "5"]))
    assert paper.model == GaitModelConfig.paper() and paper.train.epochs == 5
    with pytest.raises(SystemExit):
        config_from_args(build_parser().parse_args(["--set", "no_such_field=1"]))


def test_loss_weights_and_set_values_refuse_junk():
    from generation.gait.config import GaitLossWeights
    from generation.gait.train import build_parser, config_from_args
    assert GaitLossWeights(bounce=40.0).bounce == 40.0
    for bad in ({"bounce": -1.0}, {"style": float("nan")}, {"pos_scale_m": 0.0}, {"pose": "1"}):
        with pytest.raises(ValueError, match="loss"):
            GaitLossWeights(**bad)
    with pytest.raises(SystemExit, match="bounce must be a finite number >= 0"):
        config_from_args(build_parser().parse_args(["--set", "loss.bounce=-1"]))
    with pytest.raises(SystemExit, match="must be JSON"):
        config_from_args(build_parser().parse_args(["--set", "loss.bounce=abc"]))
