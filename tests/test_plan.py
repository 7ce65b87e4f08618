"""Stimulus plans: schema checks with messages naming entry and field, built-in plans, content hashes."""
from __future__ import annotations

import json

import pytest

from generation.plans.generators import get_generator
from generation.plans.schema import PlanError, builtin_plans, clip_hash, intent_fields, load_plan, validate_plan
from protocol.vocabulary import GESTURE_EMOTIONS, SECTION_TYPES


def _plan(*clips, render=None):
    data = {"name": "t", "clips": list(clips)}
    if render is not None:
        data["render"] = render
    return data


WALK = {"id": "w", "generator": "procedural_walk", "emotion": [1, 0, 0, 0]}
RBF = {"id": "r", "generator": "rbf", "theme": "sad", "weight": 0.7, "n_features": 4}


def test_bad_weight_names_entry_and_field():
    bad = dict(RBF, id="x", weight="abc")
    with pytest.raises(PlanError) as exc:
        validate_plan(_plan(WALK, dict(RBF, id="r2"), bad))
    assert str(exc.value) == "entry 3 (id 'x'): field 'weight': expected a number, got 'abc'"


@pytest.mark.parametrize("entry, message", [
    ({"id": "a", "generator": "warp_drive"}, "entry 1 (id 'a'): field 'generator': expected one of"),
    (dict(WALK, colour="red"), "field 'colour': not a field of a 'procedural_walk' entry"),
    (dict(WALK, emotion=[1, 0, 0]), "field 'emotion': expected 4 numbers"),
    (dict(WALK, emotion=[0, 0, 0, 0]), "field 'emotion': expected at least one positive component"),
    ({"id": "w", "generator": "procedural_walk"}, "field 'emotion': give exactly one of"),
    (dict(WALK, trajectory={"kind": "spiral"}), "field 'trajectory.kind'"),
    (dict(WALK, trajectory={"kind": "straight", "radius_m": 3}), "field 'trajectory.radius_m'"),
    (dict(WALK, modality="gesture"), "field 'modality': generator 'procedural_walk' makes gait clips"),
    (dict(WALK, origin="captured"), "field 'origin'"),
    (dict(WALK, fallback="gesture_net"), "field 'fallback'"),
    (dict(WALK, seed=-1), "field 'seed'"),
    (dict(WALK, seed=1.5), "field 'seed': expected an integer"),
    (dict(RBF, theme="grumpy"), "field 'theme'"),
    (dict(RBF, n_features=11), "field 'n_features'"),
    ({"id": "r", "generator": "rbf", "theme": "sad"}, "field 'weight': required"),
    ({"id": "g", "generator": "gesture_net", "sentence": "Hello there.", "emotion_label": "grumpy"},
     "field 'emotion_label': expected an NRC-VAD emotion word"),
    ({"id": "g", "generator": "gesture_net", "emotion_label": "sad"}, "field 'sentence'"),
    (dict(WALK, render={"width": 641}), "field 'render': field 'width'"),
    (dict(WALK, sections=["quiz"]), "field 'sections'"),
    (dict(WALK, loop="yes"), "field 'loop'"),
    ({"generator": "rbf", "theme": "sad", "weight": 1}, "entry 1 (id None): field 'id'"),
])
def test_bad_entries_are_refused(entry, message):
    with pytest.raises(PlanError) as exc:
        validate_plan(_plan(entry))
    assert message in str(exc.value)


def test_plan_level_checks():
    with pytest.raises(PlanError, match="field 'id': duplicate of entry 1"):
        validate_plan(_plan(WALK, dict(RBF, id="w")))
    with pytest.raises(PlanError, match="field 'pair': no entry with id 'ghost'"):
        validate_plan(_plan(dict(WALK, pair="ghost")))
    with pytest.raises(PlanError, match="same generator, inputs and seed as entry 1"):
        validate_plan(_plan(WALK, dict(WALK, id="w2")))
    with pytest.raises(PlanError, match="field 'clips'"):
        validate_plan({"name": "t", "clips": []})
    with pytest.raises(PlanError, match="field 'render'"):
        validate_plan(_plan(WALK, render={"camera": "drone"}))


def test_normalisation_and_defaults():
    plan = validate_plan(_plan(
        dict(WALK, emotion={"happy": 2, "neutral": 2}, trajectory={"kind": "curved", "angle_deg": -45}),
        {"id": "t", "generator": "gait_net", "fallback": "procedural_walk",
         "transition": {"initial": "sad", "final": [1, 0, 0, 1]}},
        RBF, render={"duration_s": 8}))
    w, t, r = plan.entries
    assert w.inputs["emotion"] == [0.5, 0.0, 0.0, 0.5]
    assert w.inputs["trajectory"] == {"kind": "curved", "length_m": 14.0, "radius_m": 4.0, "angle_deg": -45.0}
    assert w.inputs["duration_s"] == 8.0 and w.render.duration_s == 8.0
    assert t.inputs["transition"] == {"initial": [0, 1, 0, 0], "final": [0.5, 0, 0, 0.5]}
    assert t.fallback == "procedural_walk"
    assert r.loop is True and w.loop is False  # RBF walk cycles loop in the player
    fields = intent_fields(t)
    assert (fields["sad"], fields["final_happy"], fields["final_neutral"]) == (1.0, 0.5, 0.5)
    assert intent_fields(r)["theme"] == "sad" and intent_fields(r)["weight"] == 0.7
    assert intent_fields(w)["final_happy"] is None


def test_gesture_intent_uses_nrc_vad():
    entry = {"id": "g", "generator": "gesture_net", "sentence": "We won!", "emotion_label": "Proud"}
    plan = validate_plan(_plan(entry))
    fields = intent_fields(plan.entries[0])
    assert fields["emotion_label"] == "proud"
    assert (fields["valence"], fields["arousal"], fields["dominance"]) == pytest.approx((0.906, 0.700, 0.873))


def test_hash_follows_content_not_names():
    a = validate_plan(_plan(WALK)).entries[0]
    renamed = validate_plan(_plan(dict(WALK, id="other", sections=["naturalness"], note="x"))).entries[0]
    webm = validate_plan(_plan(dict(WALK, render={"webm": True}))).entries[0]
    seeded = validate_plan(_plan(dict(WALK, seed=2))).entries[0]
    bigger = validate_plan(_plan(dict(WALK, render={"width": 800}))).entries[0]
    h = clip_hash(a, "procedural_walk", "1")
    assert len(h) == 16 and int(h, 16) >= 0
    assert clip_hash(renamed, "procedural_walk", "1") == h
    assert clip_hash(webm, "procedural_walk", "1") == h
    assert clip_hash(a, "procedural_walk", "2") != h
    assert clip_hash(a, "gait_net", "1") != h
    assert clip_hash(seeded, "procedural_walk", "1") != h
    assert clip_hash(bigger, "procedural_walk", "1") != h


def test_load_plan_from_file_and_errors(tmp_path):
    path = tmp_path / "mine.json"
    path.write_text(json.dumps(_plan(WALK, dict(RBF, weight="abc"))))
    with pytest.raises(PlanError) as exc:
        load_plan(path)
    assert str(exc.value).startswith(f"{path}: entry 2 (id 'r'): field 'weight'")
    bad_yaml = tmp_path / "bad.yaml"
    bad_yaml.write_text("name: x\nclips: [\n")
    with pytest.raises(PlanError, match="cannot parse"):
        load_plan(bad_yaml)
    with pytest.raises(PlanError, match="not a file and not a built-in plan"):
        load_plan("no_such_plan")


def test_builtin_plans_cover_the_papers():
    assert {"demo", "seed000", "seed003", "seed004"} <= set(builtin_plans())
    demo = load_plan("demo")
    assert 12 <= len(demo.entries) <= 20        # small: the demo renders in a few minutes
    sections = {s for e in demo.entries for s in e.sections}
    assert sections == set(SECTION_TYPES)

    s000 = load_plan("seed000")
    singles = [e for e in s000.entries if "emotion" in e.inputs]
    transitions = [e for e in s000.entries if "transition" in e.inputs]
    sources = [e for e in s000.entries if e.origin == "source"]
    assert len(singles) >= 8 and len(transitions) == 12 and len(sources) == 6
    assert all(e.generator == "gait_net" and e.fallback == "procedural_walk" for e in singles + transitions)
    assert all(e.render.duration_s == 10 and e.render.camera == "auto"
               and (e.render.width, e.render.height) == (1280, 720)
               for e in s000.entries)

    s003 = load_plan("seed003")
    generated = [e for e in s003.entries if e.origin == "generated"]
    source = {e.id: e for e in s003.entries if e.origin == "source"}
    assert {e.inputs["emotion_label"] for e in generated} == set(GESTURE_EMOTIONS)
    assert all(e.pair in source and source[e.pair].inputs["emotion_label"] == e.inputs["emotion_label"]
               for e in generated)

    s004 = load_plan("seed004")
    themed = [e for e in s004.entries if e.generator == "rbf" and e.inputs["weight"] > 0]
    inverted = [e for e in s004.entries if e.generator == "rbf" and e.inputs["weight"] < 0]
    assert len(themed) == 96
    assert {(e.inputs["weight"], e.inputs["n_features"]) for e in themed} == {
        (w, n) for w in (0.4, 0.7, 1.0, 1.3) for n in (1, 4, 7, 10)}
    assert len(inverted) == 6 and all(e.inputs["weight"] == -0.7 and e.inputs["n_features"] == 10 for e in inverted)
    assert [e.generator for e in s004.entries].count("neutral_walk") == 1


def test_generator_version_follows_the_generator_code():
    from generation.plans import clipgen

    rbf = {p.name for p in clipgen.source_files("rbf")}
    assert {"stylise.py", "basis.py", "themes.py", "neutral_base.py", "motion.py", "clipgen.py"} <= rbf
    captured = {p.name for p in clipgen.source_files("captured")}
    assert "deepmimic.py" in captured and "stylise.py" not in captured
    assert "humanoid3d_walk.txt" in captured  # data files count too
    assert clipgen.generator_version("rbf").startswith(get_generator("rbf").version + "+src")
    assert clipgen.source_digest("rbf") != clipgen.source_digest("captured")
    # a data folder named after a package counts only for the generators that import it
    assert {"extended_intensities.json", "neutral_real.npz"} <= rbf
    for generator in ("gait_net", "gesture_net", "captured", "procedural_gesture"):
        assert not any("rbf" in p.parts[-2:-1] for p in clipgen.source_files(generator)), generator


def test_seed003_generates_gestures_from_held_out_sentences():
    """Every gesture_net entry of seed003 uses a sentence of the gesture network's test split and says so."""
    from generation.gesture.data import load_sentences, split_sentences
    from generation.gesture.train import TrainConfig

    rows = load_sentences()
    split = split_sentences(rows, TrainConfig().seed)
    split_of_text = {r.sentence: split[r.sentence_id] for r in rows}
    generated = [e for e in load_plan("seed003").entries if e.generator == "gesture_net"]
    assert generated
    for e in generated:
        assert e.inputs["sentence_split"] == "test", e.id
        assert split_of_text[e.inputs["sentence"]] == "test", e.id
    # the test split holds 3 sentences per emotion; the plan uses all of them
    assert len(generated) == 3 * len(GESTURE_EMOTIONS)


def test_sentence_split_field():
    gesture = {"id": "g", "generator": "gesture_net", "sentence": "I did it.", "emotion_label": "proud"}
    assert "sentence_split" not in validate_plan(_plan(gesture)).entries[0].inputs
    assert validate_plan(_plan(dict(gesture, sentence_split="test"))).entries[0].inputs["sentence_split"] == "test"
    with pytest.raises(PlanError, match="field 'sentence_split'"):
        validate_plan(_plan(dict(gesture, sentence_split="holdout")))
    with pytest.raises(PlanError, match="field 'sentence_split'"):
        validate_plan(_plan(dict(WALK, id="w2", sentence_split="test")))


def test_motion_kept_as_bvh_per_clip(tmp_path):
    from generation.formats.bvh import read_bvh
    from generation.plans.clipgen import make_motion, write_motion_bvh

    entry = validate_plan(_plan(dict(WALK, duration_s=1.0))).entries[0]
    motion = make_motion(entry)
    path = write_motion_bvh(motion, tmp_path / "motions", "0123456789abcdef")
    assert path == tmp_path / "motions" / "0123456789abcdef.bvh"
    assert [p.name for p in path.parent.iterdir()] == [path.name]
    back = read_bvh(path)
    assert back.num_frames == motion.num_frames
    assert abs(back.positions() - motion.positions()).max() < 1e-4
    with pytest.raises(ValueError, match="cannot name a file"):
        write_motion_bvh(motion, tmp_path, "../x")


def test_demo_source_walks_are_real_capture_with_their_licence():
    demo = load_plan("demo")
    sources = [e for e in demo.entries if e.modality == "gait" and e.origin == "source" and "naturalness" in e.sections]
    assert sources and all(e.generator == "captured_file" for e in sources)
    from generation.plans.clipgen import make_motion

    meta = make_motion(sources[0]).metadata
    assert meta["captured"] is True and meta["synthetic"] is False
    assert meta["licence"] == "CC BY-NC 4.0" and "arXiv:2306.08861" in meta["citation"] and meta["take"]


def test_a_plan_crosses_its_entries_with_bodies():
    from generation.plans.schema import PlanError, validate_plan

    walk = {"id": "w", "generator": "procedural_walk", "emotion": "happy"}
    plan = validate_plan({"name": "bodies", "bodies": ["female", "male"],
                          "clips": [walk, {**walk, "id": "v", "bodies": ["female-older"], "seed": 3}]})
    assert [(e.id, e.render.body, e.render.body_preset) for e in plan.entries] == [
        ("w-female", "human", "female"), ("w-male", "human", "male"), ("v-female-older", "human", "female-older")]
    with pytest.raises(PlanError, match="'bodies'"):
        validate_plan({"name": "bodies", "bodies": ["female", "female"], "clips": [walk]})
    with pytest.raises(PlanError, match="unknown body preset"):
        validate_plan({"name": "bodies", "bodies": ["giant"], "clips": [walk]})
