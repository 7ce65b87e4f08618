"""What a section says to participants: its title and text on every clip page. The researcher writes them
(Section.title, Section.instructions) in the participants' words and keeps a name of their own for the section
(Section.name: admin, previews, reports; never shown to participants). A blank title or text shows the section
type's plain-words default below, in the participant's language.

Participant wording avoids the researchers' terms ("theme", "inversion", "perceived", "affective", "stimulus"):
it says what to look at and what to answer.
"""
from __future__ import annotations

from django.utils.translation import gettext
from django.utils.translation import gettext_noop as _

DEFAULT_WORDING: dict[str, tuple[str, str]] = {
    "emotion_choice": (_("Emotions in walks"), _("Watch each walk and choose every emotion you see in it.")),
    "emotion_transition": (_("Emotions that change"),
                           _("In these walks the emotion may change during the clip. Choose the emotion(s) you see "
                             "at the start and at the end.")),
    "affect_likert": (_("Posture and movement"), _("Rate the torso, the arms, the pace and the flow of each walk.")),
    "naturalness": (_("How natural the motion looks"), _("Rate how natural and smooth each animation looks.")),
    "gesture_emotion": (_("Emotions in gestures"), _("Watch each clip and choose the emotion you see in the "
                                                     "gestures.")),
    "neutral_validation": (_("Describe the walk"), _("Choose the word that best describes each walk.")),
    "theme_rating": (_("Walking styles"), _("Rate how strongly each walk shows the style named in the question, "
                                            "from 1 (not at all) to 7 (very).")),
    "theme_inversion": (_("Walking styles: one or the other"),
                        _("Each walk may look like one of two opposite styles. Rate it from -7 (very much the "
                          "first style named) through 0 (neither) to +7 (very much the second).")),
}
"""Section type -> (title, text) shown when the researcher leaves them blank (msgids, translated when shown)."""

RESEARCHER_TERMS = ("theme", "inversion", "inverted", "affective", "stimul", "likert")
"""Words of the researchers' vocabulary that participant wording avoids (checked by the tests for every preset)."""


def participant_wording(section) -> tuple[str, str]:
    """(title, text) a participant sees for ``section`` in the active language: the researcher's, else the
    section type's default."""
    title, text = DEFAULT_WORDING.get(section.section_type, ("", ""))
    return (section.title or (gettext(title) if title else gettext("Watch the clip")),
            section.instructions or (gettext(text) if text else ""))
