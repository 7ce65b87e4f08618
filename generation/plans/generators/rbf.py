"""``rbf``: seed 004's Gaussian RBF features style the neutral base walk with a theme at a weight (negative:
the inverted features); ``features: expert`` (the paper's Table III) or ``data`` (fitted to real themed walks)."""
from __future__ import annotations

from dataclasses import dataclass

from generation.core.motion import Motion
from protocol.vocabulary import THEMES

from .fields import FieldError, choice, integer, number
from .neutral_walk import RBF_BASES, base_cycle
from .registry import GeneratorSpec, InputContext, MakeContext, PlanInputs, register

RBF_FEATURES = ("expert", "data")
RBF_INTENSITIES = ("extended", "calibrated", "visual", "pooled")  # generation.rbf.themes.INTENSITY_SETS (torch-free)


@dataclass(frozen=True)
class RbfInputs(PlanInputs):
    """A ``theme`` at ``weight`` (-3..3; the paper uses 0.4, 0.7, 1.0, 1.3 and -0.7) with its first
    ``n_features`` features, over ``n_cycles`` of the ``base`` cycle at ``speed``; the expert features'
    ``intensities`` are ``extended`` (default: each row sized from real style differences, with our rows and the
    theme's real stride and cadence), ``calibrated`` (the 2026-12-06 default: w = 1 reproduces real actors' style
    differences, factors capped) or ``visual`` (the earlier hand-sized set), which rerender earlier studies, or
    ``pooled`` (as ``extended``, with happy and sad sized on Bandai Namco and the BML walks of Emotion-Gait
    together)."""

    PLAN_FIELDS = frozenset({"theme", "weight", "n_features", "n_cycles", "speed", "base", "features",
                             "intensities"})

    theme: str
    weight: float
    n_features: int = 10
    n_cycles: int = 3
    speed: float = 1.0
    base: str = "real"
    features: str = "expert"
    intensities: str = "extended"

    @classmethod
    def parse(cls, raw: dict, context: InputContext) -> RbfInputs:
        if "theme" not in raw:
            raise FieldError("theme", f"required; one of {list(THEMES)}")
        theme = choice("theme", raw["theme"], THEMES)
        if "weight" not in raw:
            raise FieldError("weight", "required (the paper uses 0.4, 0.7, 1.0, 1.3 and -0.7)")
        return cls(theme, number("weight", raw["weight"], -3.0, 3.0),
                   integer("n_features", raw.get("n_features", 10), 1, 10),
                   integer("n_cycles", raw.get("n_cycles", 3), 1, 50), number("speed", raw.get("speed", 1.0), 0.2, 3.0),
                   choice("base", raw.get("base", RBF_BASES[0]), RBF_BASES),
                   choice("features", raw.get("features", RBF_FEATURES[0]), RBF_FEATURES),
                   choice("intensities", raw.get("intensities", RBF_INTENSITIES[0]), RBF_INTENSITIES))

    def intent(self, modality: str) -> dict:
        return {**super().intent(modality), "theme": self.theme, "weight": self.weight, "n_features": self.n_features}


def make_rbf(entry, context: MakeContext) -> Motion:
    from generation.rbf.stylise import stylise  # torch; optional (clipgen.availability)

    inp: RbfInputs = entry.inputs
    motion = stylise(base_cycle(inp.base), inp.theme, inp.weight, inp.n_features, speed=inp.speed,
                     n_cycles=inp.n_cycles, fps=context.fps, features=inp.features, intensities=inp.intensities)
    motion.metadata["base"] = inp.base
    return motion


SPEC = register(GeneratorSpec(
    name="rbf", summary="seed 004 RBF styles: a theme at a weight (inverted when negative) on the neutral walk",
    modality="gait", origins=("generated",), inputs=RbfInputs, make=make_rbf,
    requires=("generation.rbf.stylise", "generation.rbf.data_features"), loops=True))
