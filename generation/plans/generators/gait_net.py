"""``gait_net``: seed 000's affect-based autoregression network walks an emotion (or a transition) along a path.

Falls back to ``procedural_walk`` (recorded as such, SYNTHETIC) while its weights are missing."""
from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path

import numpy as np

from generation.core.motion import Motion
from generation.core.paths import path_from_spec
from generation.gait.generate import emotion_transition, generate_gaits, load_default_model
from generation.gait.weights import NAMED_WEIGHTS, weights_path

from .fields import choice
from .procedural_walk import WalkInputs
from .registry import GeneratorSpec, InputContext, MakeContext, PlanInputs, register

#: Named weights of the network (generation.gait.weights): ``real`` (default, trained on real capture) or
#: ``procedural`` (trained on the SYNTHETIC corpus).
GAIT_WEIGHTS = tuple(NAMED_WEIGHTS)


@dataclass(frozen=True)
class GaitNetInputs(WalkInputs):
    """A walk's inputs plus the named ``weights`` (None: the default, real)."""

    PLAN_FIELDS = WalkInputs.PLAN_FIELDS | {"weights"}

    weights: str | None = None

    @classmethod
    def parse(cls, raw: dict, context: InputContext) -> GaitNetInputs:
        weights = choice("weights", raw["weights"], GAIT_WEIGHTS) if "weights" in raw else None
        return cls(**cls.walk_fields(raw, context), weights=weights)


def to_procedural_walk(inputs: GaitNetInputs, fallback: str) -> PlanInputs:
    return WalkInputs(inputs.trajectory, inputs.duration_s, inputs.emotion, inputs.transition)


def weights_file(inputs: GaitNetInputs | None) -> Path:
    """The file of the entry's named weights (None: the default weights)."""
    return weights_path(None if inputs is None else inputs.weights)


def make_gait_net(entry, context: MakeContext) -> Motion:

    inp: GaitNetInputs = entry.inputs
    net = load_default_model(context.device, weights=inp.weights)
    steps = int(np.ceil(inp.duration_s * net.fps)) + 1
    if inp.transition is not None:
        emotions = emotion_transition(list(inp.transition.initial), list(inp.transition.final), steps)[None]
    else:
        emotions = np.asarray([inp.emotion])
    return generate_gaits(None, [path_from_spec(inp["trajectory"])], emotions, steps=steps, fps_out=context.fps,
                          model=net, rng_seed=entry.seed)[0]


SPEC = register(GeneratorSpec(
    name="gait_net", summary="seed 000 gait network: an emotion or a transition along a path",
    modality="gait", origins=("generated",), inputs=GaitNetInputs, make=make_gait_net,
    requires=("generation.gait.generate",), fallbacks=("procedural_walk",), fallback_inputs=to_procedural_walk,
    weights=weights_file))
