"""``captured``: one of the real captured walks shipped with the DeepMimic data (generation.mocap.captured),
optionally chained ``cycles`` times with the feet planted at the seams."""
from __future__ import annotations

from dataclasses import dataclass

from generation.core.foot_contact import plant_feet
from generation.core.motion import Motion
from generation.mocap.captured import WALK_FILES, captured_walks, chain_clip_repeats

from .fields import choice, integer
from .registry import GeneratorSpec, InputContext, MakeContext, PlanInputs, register

#: The shipped captured walk clips (generation/data/deepmimic).
CAPTURED_CLIPS = tuple(name for name, _ in WALK_FILES)


@dataclass(frozen=True)
class CapturedInputs(PlanInputs):
    """A shipped captured walk ``clip`` repeated ``cycles`` times."""

    PLAN_FIELDS = frozenset({"clip", "cycles"})

    clip: str = "0walk_forward.txt"
    cycles: int = 1

    @classmethod
    def parse(cls, raw: dict, context: InputContext) -> CapturedInputs:
        return cls(choice("clip", raw.get("clip", "0walk_forward.txt"), CAPTURED_CLIPS),
                   integer("cycles", raw.get("cycles", 1), 1, 100))


def make_captured(entry, context: MakeContext) -> Motion:
    inp: CapturedInputs = entry.inputs
    motion = captured_walks()[CAPTURED_CLIPS.index(inp.clip)]
    if inp.cycles > 1:
        motion = chain_clip_repeats(motion, inp.cycles)
        # The walker clips do not loop exactly (last pose 17-38 deg from the first): at every seam the standing
        # foot jumped 6-9 cm. Plant the feet, and say so. lower_pelvis: locking the sliding source feet put the
        # stance knee fully straight in 17-27 % of the frames; lowering the pelvis where out of reach avoids that.
        motion = plant_feet(motion, lower_pelvis=True)
        motion.metadata.update({"foot_planting": True,
                                "foot_planting_reason": "seams of the chained repeats (chain_clip_repeats)"})
    return motion


SPEC = register(GeneratorSpec(
    name="captured", summary="a real captured walk shipped with the DeepMimic data",
    modality="gait", origins=("source",), inputs=CapturedInputs, make=make_captured, captured=True))
