"""``neutral_walk``: seed 004's unstyled input walk, the neutral base cycle repeated at a speed (theme
``neutral``, weight 0 in the catalogue), feet planted like the styled walks it is compared with."""
from __future__ import annotations

import functools
from dataclasses import dataclass

from generation.core.motion import Motion
from generation.rbf.neutral_base import neutral_cycle
from generation.rbf.real_neutral import load_cycle
from protocol.vocabulary import NEUTRAL_THEME

from .fields import choice, integer, number
from .registry import GeneratorSpec, InputContext, MakeContext, PlanInputs, register

#: Neutral base cycle of the RBF styliser: "real" (averaged real normal walks, generation/data/rbf/neutral_real.npz)
#: or "procedural" (averaged SYNTHETIC walks, generation.rbf.neutral_base.neutral_cycle).
RBF_BASES = ("real", "procedural")


@functools.lru_cache(maxsize=2)
def base_cycle(base: str = "real") -> Motion:
    """The RBF styliser's neutral base cycle (cached): averaged real normal walks or averaged procedural walks."""
    return load_cycle() if base == "real" else neutral_cycle()


@dataclass(frozen=True)
class NeutralWalkInputs(PlanInputs):
    """``n_cycles`` repeats of the ``base`` cycle at ``speed`` times its own pace."""

    PLAN_FIELDS = frozenset({"n_cycles", "speed", "base"})

    n_cycles: int = 3
    speed: float = 1.0
    base: str = "real"

    @classmethod
    def parse(cls, raw: dict, context: InputContext) -> NeutralWalkInputs:
        return cls(integer("n_cycles", raw.get("n_cycles", 3), 1, 50), number("speed", raw.get("speed", 1.0), 0.2, 3.0),
                   choice("base", raw.get("base", RBF_BASES[0]), RBF_BASES))

    def intent(self, modality: str) -> dict:
        return {**super().intent(modality), "theme": NEUTRAL_THEME, "weight": 0.0, "n_features": 0}


def make_neutral_walk(entry, context: MakeContext) -> Motion:
    from generation.rbf.stylise import (  # torch; optional (clipgen.availability)
        cycle_stride,
        plant_walk_feet,
        warp_and_repeat_cycle,
    )

    inp: NeutralWalkInputs = entry.inputs
    base = base_cycle(inp.base)
    rot, root = warp_and_repeat_cycle(base.rotations, base.root_positions, cycle_stride(base), base.duration,
                                      inp.speed, inp.n_cycles, context.fps)
    meta = dict(base.metadata)
    meta.update({"generator": "neutral_walk", "n_cycles": inp.n_cycles, "speed": inp.speed, "base": inp.base})
    # planted like the RBF-styled walks it is compared with, so they differ by the features only
    return plant_walk_feet(Motion(base.skeleton, rot, root, context.fps, meta))


SPEC = register(GeneratorSpec(
    name="neutral_walk", summary="seed 004's unstyled neutral base walk (theme neutral, weight 0)",
    modality="gait", origins=("source", "generated"), inputs=NeutralWalkInputs, make=make_neutral_walk,
    requires=("generation.rbf.stylise",), loops=True))
