"""theme_rating: how strongly a styled walk shows its theme, 1..7 (seed 004 Table IV, Fig. 7)."""
from protocol.norming import NORMING_OPTION
from protocol.vocabulary import THEME_RATING

from .registry import Ask, ClipNeed, OptionSpec, SectionType, register

SPEC = register(SectionType(
    name="theme_rating", label="Theme rating (1..7)",
    summary="Seed 004 Table IV: how much of its RBF theme a styled walk shows, 1..7, by weight and feature count.",
    modality="gait", questions=(Ask("rating", THEME_RATING),),
    options=(OptionSpec(NORMING_OPTION, "norming section: {\"ratings_per_clip\": K} (protocol.norming)"),),
    norming=True,
    clip_need=ClipNeed((("theme", "weight", "n_features"),), "needs theme, weight and n_features in clips.csv"),
    simulator="round(theme_base + theme offset + weight_effect * (w - 0.4) / 0.9 + feature_effect * (1 - exp(-(n - "
              "1) / 3)) / (1 - exp(-3)) + participant N(0, theme_subject_sd) + N(0, theme_noise_sd)), clipped to 1..7",
    agreement="icc", agreement_by="theme",
    analyses=("theme_anova", "theme_descriptives", "mixed_models", "agreement", "clip_norms"),
    figures=("fig_theme_ratings",), module=__name__))
