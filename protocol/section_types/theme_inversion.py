"""theme_inversion: whether a walk at a negative RBF weight looks like the opposite theme, -7..+7 (seed 004 Fig. 8)."""
from protocol.vocabulary import INVERSION

from .registry import Ask, ClipNeed, SectionType, register

SPEC = register(SectionType(
    name="theme_inversion", label="Theme inversion (-7..+7)",
    summary="Seed 004 Fig. 8: a walk styled at a negative weight, from -7 (the opposite theme) to +7 (its theme).",
    modality="gait", questions=(Ask("rating", INVERSION),),
    clip_need=ClipNeed((("theme",),), "needs a theme in clips.csv"),
    simulator="round(inversion_mean[theme] + N(0, inversion_sd)), clipped to -7..7",
    analyses=("theme_inversion",), figures=("fig_inversion",), module=__name__))
