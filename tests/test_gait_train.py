"""Training the gait network: overfitting a batch, history splicing, uniform labels, checkpoints, resume, determinism,
free-running rollout, fine-tuning."""
from __future__ import annotations

from dataclasses import replace

import numpy as np
import pytest
import torch

from generation.gait.config import (
    GaitLossWeights,
    GaitNetConfig,
)
from generation.gait.generate import load_model
from generation.gait.losses import total_loss
from generation.gait.model import GaitNet
from generation.gait.train import (
    fit_normalizer,
    ground_truth_targets,
    load_checkpoint,
    rollout,
    save_checkpoint,
    splice_histories,
    train,
)
from generation.gait.upgrade_weights import upgrade_weights
from generation.gait.weights import NAMED_WEIGHTS, TrainingData, is_real, weights_path

torch.set_num_threads(1)
pytest_plugins = ("gait_fixtures",)   # the tiny_data and tiny_net fixtures


def test_tiny_network_overfits_a_tiny_batch(tiny_data):
    torch.manual_seed(0)
    # Without the style term: its walk-to-walk scale (Normalizer.aff_style_std) means nothing for two walks.
    cfg = GaitNetConfig.tiny(gru_hidden=64, versor_hidden=64, lambda_style=0.0)
    net = GaitNet(cfg.model)
    data = tiny_data.subset("train")
    norm = fit_normalizer(data)
    batch = data.batch([0, 1])
    target = ground_truth_targets(batch, norm)
    opt = torch.optim.Adam(net.parameters(), lr=3e-3)
    losses = []
    for _ in range(40):
        loss, _ = total_loss(rollout(net, norm, batch, 1.0, cfg.prefix_len), target, cfg.loss)
        opt.zero_grad()
        loss.backward()
        opt.step()
        losses.append(loss.item())
    assert losses[-1] < 0.6 * losses[0], losses[::10]


def test_splice_histories_switches_history_and_emotion(tiny_data):
    batch = tiny_data.batch(np.arange(6))
    P = GaitNetConfig().prefix_len
    out = splice_histories(batch, P, 1.0, np.random.default_rng(0))
    em = out["emotion"]
    assert em.shape == (6, batch["q"].shape[1], 4)
    assert torch.equal(em[:, P - 1:], batch["emotion"][:, None].expand(-1, em.shape[1] - P + 1, -1))
    dom = batch["emotion"].argmax(-1)
    for b in range(6):
        # The prefix comes from a walk with another dominant emotion, whose label it carries; the rest is b's own.
        src = next(i for i in range(6) if torch.equal(out["q"][b, :P], batch["q"][i, :P]))
        assert dom[src] != dom[b] and torch.equal(em[b, 0], batch["emotion"][src])
        assert torch.equal(out["q"][b, P:], batch["q"][b, P:])
        assert torch.equal(out["theta"][b, P:], batch["theta"][b, P:])
    none = splice_histories(batch, P, 0.0, np.random.default_rng(0))
    assert torch.equal(none["q"], batch["q"]) and torch.equal(none["emotion"][:, 0], batch["emotion"])
    # Per-step emotions go through the rollout.
    cfg = GaitNetConfig.tiny()
    pred = rollout(GaitNet(cfg.model), fit_normalizer(tiny_data.subset("train")), out, 0.5, P)
    assert pred["q"].shape == batch["q"][:, 1:].shape


def test_uniform_labels_replace_a_fraction_of_the_emotion_inputs(tiny_data):
    from generation.gait.train import uniform_labels
    batch = splice_histories(tiny_data.batch(np.arange(len(tiny_data))), 18, 0.0, np.random.default_rng(0))
    none = uniform_labels(batch, 0.0, np.random.default_rng(0))
    assert torch.equal(none["emotion"], batch["emotion"])
    every = uniform_labels(batch, 1.0, np.random.default_rng(0))
    assert torch.allclose(every["emotion"], torch.full_like(batch["emotion"], 0.25))
    assert torch.equal(every["q"], batch["q"])   # only the emotion input changes
    some = uniform_labels(batch, 0.5, np.random.default_rng(3))["emotion"]
    dropped = (some == 0.25).all(-1).all(-1)
    assert dropped.any() and not dropped.all()
    assert torch.equal(some[~dropped], batch["emotion"][~dropped])


def test_training_writes_checkpoint_and_resumes(tiny_data, tmp_path):
    cfg = GaitNetConfig.tiny(epochs=1, batch_size=2)
    out = tmp_path / "w.pt"
    ckpt = tmp_path / "state.ckpt"
    train(cfg, tiny_data, out, ckpt, progress=False, log=lambda *_: None)
    assert out.exists() and ckpt.exists()
    cfg2 = GaitNetConfig.tiny(epochs=2, batch_size=2)
    res = train(cfg2, tiny_data, out, ckpt, resume=True, progress=False, log=lambda *_: None)
    assert [h["epoch"] for h in res["history"]] == [1, 2]
    model, norm, payload = load_checkpoint(out)
    assert payload["trained_on"] == "synthetic procedural corpus" and payload["format"] == "gait_net/3"
    assert payload["training_data"]["kind"] == "procedural"
    assert GaitNetConfig.from_dict(payload["config"]) == cfg2 and model.config == cfg2.model
    bad = tmp_path / "bad.pt"
    bad.write_bytes(b"not a checkpoint")
    with pytest.raises(ValueError, match="bad.pt"):
        load_checkpoint(bad)


def test_keep_epochs_writes_the_weights_of_every_epoch(tiny_data, tmp_path):
    out = tmp_path / "run.pt"
    train(GaitNetConfig.tiny(epochs=2, batch_size=2), tiny_data, out, tmp_path / "run.ckpt", progress=False,
          log=lambda *_: None, keep_epochs=True)
    assert sorted(p.name for p in tmp_path.glob("run_e*.pt")) == ["run_e01.pt", "run_e02.pt"]
    _, _, first = load_checkpoint(tmp_path / "run_e01.pt")
    _, _, last = load_checkpoint(tmp_path / "run_e02.pt")
    assert [h["epoch"] for h in first["history"]] == [1] and [h["epoch"] for h in last["history"]] == [1, 2]
    assert first["trained_on"] == "synthetic procedural corpus"


def test_save_and_load_model(tiny_net, tmp_path):
    path = tmp_path / "m.pt"
    save_checkpoint(path, tiny_net.model, tiny_net.normalizer, tiny_net.config, training_data=TrainingData.procedural())
    loaded = load_model(path)
    for p, q in zip(loaded.model.parameters(), tiny_net.model.parameters()):
        assert torch.equal(p, q)
    assert loaded.config == tiny_net.config
    # A file of another format is refused, naming the format.
    payload = torch.load(path, weights_only=False)
    other = tmp_path / "other.pt"
    torch.save({**payload, "format": "gait_net/1"}, other)
    with pytest.raises(ValueError, match="checkpoint format 'gait_net/1', expected one of"):
        load_model(other)


def test_weights_files_say_what_they_were_trained_on_and_old_files_still_load(tiny_net, tiny_data, tmp_path):
    real = TrainingData.real("finetune", {"path": "c.npz", "sha256": "0" * 64, "stage": "finetune"})
    new = tmp_path / "new.pt"
    save_checkpoint(new, tiny_net.model, tiny_net.normalizer, tiny_net.config, training_data=real)
    assert load_model(new).training_data == real and is_real(load_model(new).training_data)
    payload = torch.load(new, weights_only=False)
    del payload["training_data"]
    for trained_on, kind in ((real.description, "real"), ("synthetic procedural corpus", "procedural")):
        old = tmp_path / f"old_{kind}.pt"                   # format gait_net/2: the prose field only
        torch.save({**payload, "format": "gait_net/2", "trained_on": trained_on}, old)
        net = load_model(old)
        assert net.training_data.kind == kind and net.info["trained_on"] == trained_on
        assert upgrade_weights(old) and not upgrade_weights(old)      # rewritten once, then already current
        upgraded = torch.load(old, weights_only=False)
        assert upgraded["format"] == "gait_net/3" and upgraded["training_data"]["kind"] == kind
        assert all(torch.equal(a, b) for a, b in zip(net.model.state_dict().values(),
                                                     load_model(old).model.state_dict().values()))
        assert load_model(old).training_data == net.training_data and load_model(old).info == net.info
    with pytest.raises(ValueError, match="training data kind"):
        TrainingData("synthetic", "x")
    with pytest.raises(ValueError, match="do not say what they are"):
        train(GaitNetConfig.tiny(epochs=1), replace(tiny_data, training_data=None), tmp_path / "x.pt",
              progress=False, log=lambda *_: None)


def test_training_is_deterministic_for_a_seed(tiny_data, tmp_path):
    cfg = GaitNetConfig.tiny(epochs=1, batch_size=2, tf_decay=0.5)
    a = train(cfg, tiny_data, tmp_path / "a.pt", tmp_path / "a.ckpt", progress=False, log=lambda *_: None)
    b = train(cfg, tiny_data, tmp_path / "b.pt", tmp_path / "b.ckpt", progress=False, log=lambda *_: None)
    for p, q in zip(a["model"].parameters(), b["model"].parameters()):
        assert torch.equal(p, q)


def test_rollout_continues_free_running_past_the_data(tiny_data):
    cfg = GaitNetConfig.tiny(extra_steps=5)
    net = GaitNet(cfg.model)
    norm = fit_normalizer(tiny_data.subset("train"))
    batch = tiny_data.batch([0, 1])
    pred = rollout(net, norm, batch, 0.5, cfg.prefix_len, extra_steps=5)
    assert pred["ext_aff"].shape == (2, 5, 18) and pred["ext_pos"].shape == (2, 5, 21, 3)
    assert pred["q"].shape == batch["q"][:, 1:].shape
    _, terms = total_loss(pred, ground_truth_targets(batch, norm), cfg.loss, style_from=cfg.prefix_len - 1)
    assert terms["style"] > 0
    _, none = total_loss(pred, ground_truth_targets(batch, norm), GaitLossWeights(style=0.0))
    assert "style" not in none and "class_style" not in terms
    targets = ground_truth_targets(batch, norm)
    assert targets["emotion"].shape == (2, batch["emotion"].shape[-1])
    _, with_class = total_loss(pred, targets, GaitLossWeights(class_style=2.0), style_from=cfg.prefix_len - 1)
    assert with_class["class_style"] >= 0
    assert GaitNetConfig.tiny(tf_start=0.3).train.tf_start == 0.3
    assert GaitNetConfig.tiny(lambda_class_style=4).loss.class_style == 4


def test_fine_tuning_starts_from_a_weights_file(tiny_data, tmp_path):
    cfg = GaitNetConfig.tiny(epochs=1, batch_size=2)
    first = train(cfg, tiny_data, tmp_path / "a.pt", tmp_path / "a.ckpt", progress=False, log=lambda *_: None)
    tuned = train(cfg.with_overrides(tf_start=0.2), tiny_data, tmp_path / "b.pt", tmp_path / "b.ckpt",
                  progress=False, log=lambda *_: None, init=tmp_path / "a.pt")
    assert tuned["history"][0]["tf"] == pytest.approx(0.2)
    assert load_checkpoint(tmp_path / "b.pt")[2]["initialised_from"]["path"] == str(tmp_path / "a.pt")
    assert not all(torch.equal(p, q) for p, q in zip(first["model"].parameters(), tuned["model"].parameters()))
    with pytest.raises(ValueError, match="architecture"):
        train(GaitNetConfig.tiny(epochs=1, gru_hidden=16), tiny_data, tmp_path / "c.pt", tmp_path / "c.ckpt",
              progress=False, log=lambda *_: None, init=tmp_path / "a.pt")


@pytest.mark.parametrize("name", sorted(NAMED_WEIGHTS))
def test_shipped_gait_weights_carry_their_typed_training_record(name):
    payload = torch.load(weights_path(name), map_location="cpu", weights_only=False)
    assert payload["format"] == "gait_net/3"
    record = TrainingData.from_record(payload["training_data"])
    assert record.kind == name and record.description == payload["trained_on"] and record.datasets
