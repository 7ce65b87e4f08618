"""emotion_choice: which gait emotion(s) a walk shows, several allowed (seed 000 section 6.3.1)."""
from protocol.norming import NORMING_OPTION
from protocol.vocabulary import GAIT_MULTI

from .registry import Ask, OptionSpec, SectionType, register

SPEC = register(SectionType(
    name="emotion_choice", label="Perceived gait emotion (multi-select)",
    summary="Seed 000's single-emotion gaits: every gait emotion the participant perceives in a walk.",
    modality="gait", questions=(Ask("perceived", GAIT_MULTI),),
    options=(OptionSpec(NORMING_OPTION, "norming section: {\"ratings_per_clip\": K} (protocol.norming)"),),
    norming=True,
    simulator="label probabilities (1 - emotion_noise) * intended + emotion_noise / 4; one label drawn, and with "
              "probability multi_select_prob a second, different one",
    agreement="kappa", demographics="perceived",
    analyses=("gait_emotion_ad", "demographic_differences", "agreement", "clip_norms", "recognition"),
    figures=("fig_emotion_vectors", "fig_confusion", "fig_clip_norms_gait"), module=__name__))
