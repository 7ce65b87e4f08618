"""affect_likert: seed 000 Table 2's four pose affective features of a walk, each on a 5-point scale (0..4)."""
from protocol.vocabulary import LIKERT, LIKERT_FEATURES

from .registry import Ask, SectionType, register

SPEC = register(SectionType(
    name="affect_likert", label="Pose affective features (5-point Likert)",
    summary="Seed 000 section 6.3.3: torso, arms, gait pace and gait flow of a walk, each rated 0..4.",
    modality="gait", questions=tuple(Ask(feature, LIKERT) for feature in LIKERT_FEATURES),
    simulator="round(intended @ likert_means + participant bias N(0, 0.3) + N(0, likert_sd)), clipped to 0..4",
    agreement="icc",
    analyses=("likert_consistency_ad", "likert_distribution", "mixed_models", "agreement"),
    figures=("fig_likert",), module=__name__))
