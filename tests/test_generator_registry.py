"""The generator registry: one declaration per generator serves the schema, clip generation, the catalogue and the
docs; a new generator is one module plus one registration."""
from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path

import numpy as np
import pytest

from generation.core.motion import Motion
from generation.core.skeleton import gait_skeleton
from generation.plans import clipgen
from generation.plans.generators import (
    GeneratorSpec,
    InputContext,
    MakeContext,
    PlanInputs,
    generator_names,
    get_generator,
    register,
    unregister,
)
from generation.plans.generators.__main__ import render_page
from generation.plans.generators.fields import gait_emotion, number
from generation.plans.schema import PlanError, clip_hash, intent_fields, validate_plan

REPO = Path(__file__).resolve().parents[1]


@dataclass(frozen=True)
class StandStillInputs(PlanInputs):
    """A figure standing still for ``duration_s`` seconds, labelled with a gait ``emotion``."""

    PLAN_FIELDS = frozenset({"duration_s", "emotion"})

    emotion: tuple[float, ...]
    duration_s: float = 3.0

    @classmethod
    def parse(cls, raw, context: InputContext):
        return cls(gait_emotion("emotion", raw.get("emotion", "neutral")),
                   number("duration_s", raw.get("duration_s", context.duration_s), 1.0, 20.0))


def make_stand_still(entry, context: MakeContext) -> Motion:
    skeleton = gait_skeleton()
    n = int(round(entry.inputs.duration_s * context.fps))
    rotations = np.zeros((n, skeleton.num_joints, 4))
    rotations[..., 0] = 1.0
    root = np.tile([0.0, skeleton.root_height(), 0.0], (n, 1))
    return Motion(skeleton, rotations, root, context.fps, {"origin": "generated"})


@pytest.fixture
def stand_still():
    spec = register(GeneratorSpec(name="stand_still", summary="a toy: standing still", modality="gait",
                                  origins=("generated",), inputs=StandStillInputs, make=make_stand_still))
    yield spec
    unregister("stand_still")


def test_a_new_generator_is_one_registration(stand_still):
    plan = validate_plan({"name": "toy", "render": {"duration_s": 4}, "clips": [
        {"id": "still", "generator": "stand_still", "emotion": [0, 1, 0, 1], "seed": 2}]})
    entry = plan.entries[0]
    assert isinstance(entry.inputs, StandStillInputs)
    assert entry.inputs.duration_s == 4.0 and entry.inputs["emotion"] == [0.0, 0.5, 0.0, 0.5]
    assert entry.modality == "gait" and entry.origin == "generated" and entry.loop is False
    assert intent_fields(entry)["sad"] == 0.5 and intent_fields(entry)["theme"] is None     # the catalogue
    version = clipgen.generator_version("stand_still")
    assert version.startswith("1+src") and len(clip_hash(entry, "stand_still", version)) == 16
    assert "test_generator_registry.py" in {p.name for p in clipgen.source_files("stand_still")}
    run, reason = clipgen.resolve(entry)
    assert run is entry and reason is None
    motion = clipgen.make_motion(entry)
    assert motion.num_frames == 120 and motion.metadata["generator"] == "stand_still"
    assert motion.metadata["synthetic"] is True                                         # generated, not captured
    assert "## `stand_still`" in render_page()                                          # the docs
    with pytest.raises(PlanError, match="field 'duration_s': expected a number in"):
        validate_plan({"name": "toy", "clips": [{"id": "x", "generator": "stand_still", "duration_s": 99}]})
    with pytest.raises(PlanError, match="field 'speed': not a field of a 'stand_still' entry"):
        validate_plan({"name": "toy", "clips": [{"id": "x", "generator": "stand_still", "speed": 1}]})


def test_a_name_registers_once(stand_still):
    with pytest.raises(ValueError, match="registered already"):
        register(GeneratorSpec(name="stand_still", summary="again", modality="gait", origins=("generated",),
                               inputs=StandStillInputs, make=make_stand_still))


def test_builtin_generators_are_declared_in_the_registry():
    assert set(generator_names()) >= {"gait_net", "procedural_walk", "captured", "captured_file", "neutral_walk",
                                      "rbf", "gesture_net", "procedural_gesture"}
    for name in generator_names():
        spec = get_generator(name)
        assert spec.fields and spec.origins and spec.inputs.__doc__, name
        for fallback in spec.fallbacks:
            assert get_generator(fallback).modality == spec.modality
    with pytest.raises(PlanError, match="field 'generator': expected one of"):
        validate_plan({"name": "p", "clips": [{"id": "x", "generator": "no_such"}]})


def test_fallback_inputs_are_the_fallbacks_own_typed_inputs():
    plan = validate_plan({"name": "p", "clips": [
        {"id": "g", "generator": "gesture_net", "sentence": "I did it all by myself.", "emotion_label": "proud",
         "fallback": "procedural_gesture"},
        {"id": "w", "generator": "gait_net", "emotion": "happy", "weights": "procedural",
         "fallback": "procedural_walk"}]})
    gesture, walk = (clipgen.fallback_entry(e) for e in plan.entries)
    assert type(gesture.inputs).__name__ == "ProceduralGestureInputs" and gesture.generator == "procedural_gesture"
    assert gesture.inputs["emotion_label"] == "proud" and 2.0 <= gesture.inputs["duration_s"] <= 60.0
    assert type(walk.inputs).__name__ == "WalkInputs" and "weights" not in walk.inputs
    assert intent_fields(walk) == intent_fields(plan.entries[1])


def test_network_weights_name_the_file_of_the_entrys_named_weights():
    plan = validate_plan({"name": "p", "clips": [
        {"id": "r", "generator": "gait_net", "emotion": "happy"},
        {"id": "p", "generator": "gait_net", "emotion": "happy", "weights": "procedural"}]})
    real, procedural = (get_generator("gait_net").weights(e.inputs).name for e in plan.entries)
    assert (real, procedural) == ("gait_net_real.pt", "gait_net_default.pt")
    versions = {clipgen.generator_version("gait_net", e.inputs) for e in plan.entries}
    assert len(versions) == 2                    # a retrained procedural network re-renders its clips too


def test_the_generators_page_is_current():
    assert (REPO / "docs" / "generators.md").read_text(encoding="utf-8") == render_page(), \
        "run: python -m generation.plans.generators --out docs/generators.md"
