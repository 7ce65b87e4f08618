"""``procedural_walk``: a SYNTHETIC walk from emotion-driven gait parameters (generation.procedural), straight,
curved or with a sharp turn; a transition changes the parameters along the walk. The fallback of ``gait_net``."""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from generation.core.motion import Motion
from generation.core.paths import path_from_spec
from generation.procedural.emotion import gait_params_for_emotion
from generation.procedural.transition import transition_walk
from generation.procedural.walk import walk

from .fields import FieldError, Trajectory, gait_emotion, number
from .registry import GeneratorSpec, InputContext, MakeContext, PlanInputs, register


@dataclass(frozen=True)
class Transition:
    """A walk's emotion changing linearly from ``initial`` to ``final`` (l1-normalised gait emotion vectors)."""

    initial: tuple[float, ...]
    final: tuple[float, ...]


@dataclass(frozen=True)
class WalkInputs(PlanInputs):
    """An emotive walk: exactly one of ``emotion`` (happy, sad, angry, neutral; l1-normalised) or
    ``transition``, along ``trajectory`` for ``duration_s`` seconds."""

    PLAN_FIELDS = frozenset({"emotion", "transition", "trajectory", "duration_s"})

    trajectory: Trajectory
    duration_s: float
    emotion: tuple[float, ...] | None = None
    transition: Transition | None = None

    @classmethod
    def walk_fields(cls, raw: dict, context: InputContext) -> dict:
        has_e, has_t = "emotion" in raw, "transition" in raw
        if has_e == has_t:
            raise FieldError("emotion", "give exactly one of 'emotion' (4 numbers) or 'transition' "
                                        "({initial: [...], final: [...]})")
        out = {"trajectory": Trajectory.parse(raw.get("trajectory")),
               "duration_s": number("duration_s", raw.get("duration_s", context.duration_s), 1.0, 120.0)}
        if has_e:
            out["emotion"] = gait_emotion("emotion", raw["emotion"])
        else:
            t = raw["transition"]
            if not isinstance(t, dict) or set(t) != {"initial", "final"}:
                raise FieldError("transition", f"expected a mapping with 'initial' and 'final', got {t!r}")
            out["transition"] = Transition(gait_emotion("transition.initial", t["initial"]),
                                           gait_emotion("transition.final", t["final"]))
        return out

    @classmethod
    def parse(cls, raw: dict, context: InputContext) -> WalkInputs:
        return cls(**cls.walk_fields(raw, context))


def make_procedural_walk(entry, context: MakeContext) -> Motion:
    inp: WalkInputs = entry.inputs
    fps = context.fps
    rng = np.random.default_rng(entry.seed)
    n_frames = int(round(inp.duration_s * fps)) + 1
    path = path_from_spec(inp["trajectory"])
    if inp.transition is not None:
        initial, final = list(inp.transition.initial), list(inp.transition.final)
        a = gait_params_for_emotion(initial, rng)
        b = gait_params_for_emotion(final, rng)
        motion = transition_walk(a, b, path, n_frames, fps, seed=entry.seed)
        motion.metadata["final_emotion"] = final
        motion.metadata["emotion"] = initial
    else:
        params = gait_params_for_emotion(list(inp.emotion), rng)
        motion = walk(params, path, n_frames, fps, seed=entry.seed)
        motion.metadata["emotion"] = list(inp.emotion)
    return motion


SPEC = register(GeneratorSpec(
    name="procedural_walk",
    summary="SYNTHETIC emotive walk from procedural gait parameters (fallback of gait_net)",
    modality="gait", origins=("generated", "source"), inputs=WalkInputs, make=make_procedural_walk))
