"""neutral_validation: seed 004's 7-way forced choice on the unstyled input walk (Table I)."""
from protocol.vocabulary import NEUTRAL_CHOICE

from .registry import Ask, SectionType, register

SPEC = register(SectionType(
    name="neutral_validation", label="Neutral validation (7-way forced choice)",
    summary="Seed 004 Table I: neutral or one of the six themes, whichever best describes a walk.",
    modality="gait", questions=(Ask("perceived", NEUTRAL_CHOICE),),
    simulator="categorical over the seven choices (neutral_probs)",
    agreement="kappa", analyses=("neutral_validation", "agreement", "clip_norms"), module=__name__))
