"""The real-capture gait observer: trained on a tiny corpus of the shipped real walks, cached, its fallbacks, and
its reading in the quality gate."""
from __future__ import annotations

import numpy as np
import pytest

from generation.core.digest import file_sha256
from generation.mocap.real_corpus import RealCorpora, save_real_corpus
from generation.pipeline.plan_qa import observer_for, unread_line
from generation.quality import evaluate, resolve_thresholds
from generation.quality import real_observer as ro
from generation.quality.observers import OBSERVERS, Observers
from protocol.vocabulary import CAPTURE_GAIT_EMOTIONS


@pytest.fixture(scope="module")
def shipped():
    """The shipped real walks (8 takes, one per style) on the gait skeleton."""
    return ro.shipped_clips()


@pytest.fixture()
def fresh(monkeypatch, tmp_path):
    """An empty in-memory observer cache, a temporary pickle folder and no shipped calibrated observers (so that
    without both corpora the Bandai-only observer is read, as on a machine without those files)."""
    monkeypatch.setattr(ro, "CACHE_DIR", tmp_path / "cache")
    monkeypatch.setattr(OBSERVERS, "shipped_dir", tmp_path / "no-shipped-observers")
    OBSERVERS.clear()
    yield tmp_path
    OBSERVERS.clear()


def test_observer_trained_on_a_tiny_corpus_reads_its_takes_and_is_cached(shipped, fresh, monkeypatch):
    corpus = save_real_corpus(fresh / "tiny.npz", shipped, {"split_rule": "test corpus"})
    obs = OBSERVERS.gait("real", corpus)
    assert "tiny.npz" in obs.source and sum(obs.train_takes.values()) == 4
    for clip in shipped:
        if clip.style in CAPTURE_GAIT_EMOTIONS:
            label, p = obs.observe(clip.motion)
            assert label == CAPTURE_GAIT_EMOTIONS[clip.style] and 0.25 < p <= 1.0
            assert obs.proba(clip.motion).sum() == pytest.approx(1.0)
    by_style = {c.style: c for c in shipped}
    assert obs.theme_proba(by_style["masculinity"].motion, "feminine_vs_masculine") > 0.5
    assert obs.theme_proba(by_style["feminine"].motion, "feminine_vs_masculine") < 0.5
    assert obs.theme_proba(by_style["tired"].motion, "energetic_vs_tired") > 0.5
    pickles = list((fresh / "cache").glob("real_gait_observer_v*_*.pkl"))
    assert len(pickles) == 1 and file_sha256(corpus)[:12] in pickles[0].name
    # a new process (empty memory) loads the pickle instead of training again
    assert OBSERVERS.gait("real", corpus) is obs                                   # from memory
    monkeypatch.setattr(ro, "train_real_observer", lambda path: pytest.fail("trained again"))
    again = Observers().gait("real", corpus)
    np.testing.assert_allclose(again.proba(shipped[0].motion), obs.proba(shipped[0].motion))


def test_the_gate_flags_a_real_walk_read_as_another_emotion(shipped, fresh):
    obs = ro.RealGaitObserver(shipped, source="shipped test")
    sad = next(c for c in shipped if c.style == "sad")
    _, p = obs.observe(sad.motion)
    th = resolve_thresholds({"observer_mismatch_p": p - 1e-6})
    res = evaluate(sad.motion, th, intended=[1.0, 0.0, 0.0, 0.0], observer=obs)      # meant happy, reads sad
    assert res.values["observed"] == "sad" and res.values["observer"] == "real" and "observer" in res.flags
    assert "observer" not in evaluate(sad.motion, th, intended=[0.0, 1.0, 0.0, 0.0], observer=obs).flags


def test_without_a_corpus_it_falls_back_to_the_shipped_takes_or_says_there_is_none(shipped, fresh, monkeypatch):
    missing = fresh / "absent.npz"
    monkeypatch.setattr(ro, "shipped_clips", lambda: shipped)
    obs = OBSERVERS.gait("real", missing)
    assert "shipped real takes only" in obs.source and str(missing) in obs.source
    assert obs.observe(next(c for c in shipped if c.style == "angry").motion)[0] == "angry"

    def no_files():
        raise FileNotFoundError("generation/data/mocap/bandai-namco: gone")

    OBSERVERS.clear()
    monkeypatch.setattr(ro, "shipped_clips", no_files)
    nowhere = RealCorpora.of(missing, fresh / "absent-bml.npz")
    assert ro.load_real_observer(missing) is None and observer_for("gait", "real", nowhere) is None
    line = unread_line([{"modality": "gait", "qa": {"observed": None}}], "real")
    assert "no real-capture observer" in line


def test_a_stored_gait_record_from_another_observer_is_measured_again(shipped, tmp_path, monkeypatch):
    import json

    from generation.pipeline import runner
    from generation.pipeline.jobs import plan_jobs
    from generation.plans.schema import validate_plan

    plan = {"name": "p", "render": {"width": 160, "height": 120, "fps": 25, "duration_s": 3.0},
            "clips": [{"id": "w", "generator": "procedural_walk", "emotion": [0, 1, 0, 0], "seed": 1}]}
    (job,), _ = plan_jobs(validate_plan(plan))
    obs = ro.RealGaitObserver(shipped, source="test")
    monkeypatch.setattr(runner, "observer_for", lambda modality, kind=None, corpora=None: obs)
    # a record of version 2 (before the realism measures), read by the synthetic observer, with the render's camera
    done = {"clip_id": job.clip_id, "record_version": 2,
            "qa": {"foot_skate_cm_s": 1.0, "observed": "sad", "observed_p": 0.99, "flag": ""},
            "metadata": {"camera": {"rule": "fixed", "min_figure_fraction": 0.7, "seated": False}}}
    assert runner._stale_qa(done, job)
    batch = runner._Batch(tmp_path, tmp_path, lambda kind, info: None, runner.BatchResult())
    runner._remeasure_qa(done, job, batch)
    assert done["qa"]["observer"] == "real" and done["qa"]["skate_cm_s"] is not None
    assert done["record_version"] == runner.RECORD_VERSION
    assert done["qa"]["figure_height_frac"] == 0.7                      # the render's camera is kept
    assert json.loads((tmp_path / f"{job.clip_id}.json").read_text())["qa"] == done["qa"]
    assert not runner._stale_qa(done, job)
    (synthetic,), _ = plan_jobs(validate_plan({**plan, "qa": {"observer": "synthetic"}}))
    assert runner._stale_qa(done, synthetic)


def test_the_real_corpora_travel_with_the_job_to_the_observer(shipped, fresh, monkeypatch):
    """The corpora a command line or the settings name reach the observer of every clip inside its job (a render
    worker never looks them up itself); without both corpus files (and without the shipped calibrated observers)
    the Bandai one of ``corpora`` is read."""
    from generation.pipeline import runner
    from generation.pipeline.jobs import plan_jobs
    from generation.plans.schema import validate_plan

    corpus = save_real_corpus(fresh / "named.npz", shipped, {"split_rule": "test corpus"})
    corpora = RealCorpora.of(corpus, fresh / "no-bml.npz")
    plan = {"name": "p", "render": {"width": 160, "height": 120, "fps": 25, "duration_s": 3.0},
            "clips": [{"id": "w", "generator": "procedural_walk", "emotion": [0, 1, 0, 0], "seed": 1}]}
    (job,), _ = plan_jobs(validate_plan(plan), corpora=corpora)
    assert job.corpora == corpora and plan_jobs(validate_plan(plan))[0][0].corpora == RealCorpora()
    asked = []
    monkeypatch.setattr(runner, "observer_for", lambda modality, kind, corpora: asked.append(corpora))
    runner._add_qa({}, job, shipped[0].motion, None)
    assert asked == [corpora]
    assert "named.npz" in OBSERVERS.gait("real", corpora=corpora).source
    assert OBSERVERS.gait("real-perceived", corpora=corpora) is None   # needs both corpus files or the shipped one
