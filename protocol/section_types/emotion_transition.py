"""emotion_transition: the gait emotion(s) at the start and at the end of a walk (seed 000 section 6.3.2)."""
from protocol.vocabulary import FINAL_EMOTION_COLUMNS, GAIT_EMOTIONS, GAIT_MULTI

from .registry import Ask, ClipNeed, SectionType, register

SPEC = register(SectionType(
    name="emotion_transition", label="Gait emotion transition (initial and final)",
    summary="Seed 000's transition gaits: the emotions perceived at the start and at the end of one walk.",
    modality="gait", questions=(Ask("initial", GAIT_MULTI), Ask("final", GAIT_MULTI)),
    clip_need=ClipNeed(((*GAIT_EMOTIONS, *FINAL_EMOTION_COLUMNS),),
                       f"needs initial ({GAIT_EMOTIONS[0]}..{GAIT_EMOTIONS[-1]}) and final_* emotion vectors in "
                       "clips.csv"),
    simulator="as emotion_choice, 'initial' from the clip's initial vector and 'final' from its final_* vector",
    agreement="kappa",
    analyses=("transition_ad", "agreement"), figures=("fig_transitions",), module=__name__))
