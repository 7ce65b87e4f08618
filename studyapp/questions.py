"""Questions of each section type: wording (REFERENCE.md section 4, verbatim where the papers give it), answer
choices, and validation of posted answers. The question keys and answer values are protocol.vocabulary's
(SECTION_QUESTIONS, answer_values); only the sentences shown live here. The sentences and labels are marked for
translation (English msgids) and `questions_for` returns them in the active language (studyapp.i18n); the values
posted and stored never change with the language.

A question is asked once per (participant, section, clip); its answer is stored as text (DESIGN.md responses.csv):
emotion labels joined by ";" for multi-select, an integer for scales, a label for forced choice.
"""
from __future__ import annotations

from dataclasses import dataclass, field

from django.utils.translation import gettext
from django.utils.translation import gettext_noop as _

from protocol.norming import ratings_per_clip
from protocol.vocabulary import (
    GESTURE_EMOTIONS,
    INTEGER_RANGES,
    LIKERT_LEVELS,
    MULTI_SELECT_KINDS,
    NORMING_QUESTIONS,
    NORMING_SECTION_TYPES,
    OPPOSITE_THEME,
    SECTION_QUESTIONS,
    SECTION_TYPES,
    answer_values,
)

from .i18n import answer_label, display, theme_adjective

# Seed 000 section 6.3.4 anchors and seed 003 Table 2 markers (1..5), verbatim.
NATURALNESS_ANCHORS_GAIT = {"1": _("not natural at all"), "3": _("satisfactory"), "5": _("very natural")}
NATURALNESS_ANCHORS_GESTURE = {
    "1": _("Very Unnatural (e.g. broken arms or legs, torso at an impossible angle)"),
    "2": _("Not Realistic (e.g. limbs going inside the body or through the chair)"),
    "3": _("Looks OK (no serious problems, but does not look very appealing)"),
    "4": _("Looks good (no problems and the gestures look natural)"),
    "5": _("Looks great! (the gestures look like they could be from a real person)"),
}

@dataclass(frozen=True)
class SectionWording:
    """What a section type says: its name in the admin and, per question key, the (text, help) shown."""
    label: str
    questions: dict[str, tuple[str, str]]


# The keys and the answers are protocol.vocabulary.SECTION_QUESTIONS'; theme sections fill in {theme} and {opposite},
# naturalness may replace its text (Section.options["question"]).
WORDING: dict[str, SectionWording] = {
    "emotion_choice": SectionWording("Perceived gait emotion (multi-select)", {
        "perceived": (_("Which emotion(s) do you perceive from this walk?"),
                      _("Select every emotion you perceive; more than one is allowed."))}),
    "emotion_transition": SectionWording("Gait emotion transition (initial and final)", {
        "initial": (_("Which emotion(s) do you perceive at the start of the clip?"), _("More than one is allowed.")),
        "final": (_("Which emotion(s) do you perceive at the end of the clip?"), _("More than one is allowed."))}),
    "affect_likert": SectionWording("Pose affective features (5-point Likert)", {
        key: (label, "") for key, (label, _levels) in LIKERT_LEVELS.items()}),
    "naturalness": SectionWording("Naturalness (1..5)", {
        "naturalness": (_("How natural and smooth does this animation look?"), "")}),
    "gesture_emotion": SectionWording("Perceived gesture emotion (4 options)", {
        "perceived": (_("Which emotion do you perceive from the gestures?"), "")}),
    "neutral_validation": SectionWording("Neutral validation (7-way forced choice)", {
        "perceived": (_("Which of these best describes the walk?"), _("Choose one."))}),
    "theme_rating": SectionWording("Theme rating (1..7)", {
        "rating": (_("How {theme} does this walk look?"), _("Seven-point scale; choose one."))}),
    # seed 004: -7 the maximum opposite theme, 0 neutral, +7 the maximum original theme, said in the styles' words
    "theme_inversion": SectionWording("Theme inversion (-7..+7)", {
        "rating": (_("Does this walk look {opposite} or {theme}?"),
                   _("From -7 (very {opposite}) through 0 (neutral) to +7 (very {theme})."))}),
}


# The questions a norming section asks after its own (protocol.vocabulary.NORMING_QUESTIONS).
NORMING_WORDING: dict[str, tuple[str, str]] = {
    "intensity": (_("How intense is the emotion or style you perceive?"), ""),
    "naturalness": (_("How natural and smooth does this animation look?"), ""),
}
INTENSITY_ANCHORS = {"1": _("very weak"), "3": _("moderate"), "5": _("very strong")}


def section_type_choices() -> list[tuple[str, str]]:
    """(section type, admin label) for every protocol.vocabulary.SECTION_TYPES entry, in the protocol's order."""
    return [(t, WORDING[t].label if t in WORDING else t) for t in SECTION_TYPES]


ECHO_LIMIT = 20


def short(value: str, limit: int = ECHO_LIMIT) -> str:
    """At most `limit` characters of a submitted value, for an error message (never echo a whole submission)."""
    value = str(value)
    return value if len(value) <= limit else value[:limit] + "\u2026"


class AnswerError(ValueError):
    """A posted answer that is missing or out of range; the message names the question."""


@dataclass(frozen=True)
class Question:
    key: str                       # the `question` column of responses.csv
    text: str
    kind: str                      # how it is shown: "multi" | "single" | "scale"
    choices: list[tuple[str, str]] = field(default_factory=list)   # (value, label)
    help: str = ""
    answer_kind: str = ""          # protocol.vocabulary's answer kind (SECTION_QUESTIONS)

    def clean(self, raw: list[str]) -> str:
        """Validate the posted values of this question (a list, as from QueryDict.getlist) -> stored answer."""
        values = [v.strip() for v in raw if v is not None and v.strip() != ""]
        allowed = [c[0] for c in self.choices]
        if not values:
            raise AnswerError(gettext("Please answer: {question}").format(question=self.text))
        for v in values:
            if v not in allowed:
                raise AnswerError(gettext("'{value}' is not an allowed answer to: {question}").format(
                    value=short(v), question=self.text))
        if self.kind == "multi":
            chosen = set(values)
            return ";".join(v for v in allowed if v in chosen)   # canonical order, no duplicates
        if len(set(values)) != 1:
            raise AnswerError(gettext("Choose exactly one answer to: {question}").format(question=self.text))
        return values[0]


def _widget(kind: str) -> str:
    if kind in MULTI_SELECT_KINDS:
        return "multi"
    return "scale" if kind in INTEGER_RANGES else "single"


def _value_labels(section_type: str, key: str, options: dict, theme: str, opposite: str) -> dict[str, str]:
    """Labels of some answer values (a scale's anchors), in the active language; values without one show no
    label, choices their name. theme/opposite: already translated adjectives."""
    if section_type == "affect_likert":
        return {str(i): gettext(text) for i, text in enumerate(LIKERT_LEVELS[key][1])}
    if section_type == "naturalness":
        return {str(k): display(v) for k, v in (options.get("anchors") or NATURALNESS_ANCHORS_GAIT).items()}
    if section_type == "theme_rating":
        return {"1": gettext("not {theme} at all").format(theme=theme),
                "7": gettext("very {theme}").format(theme=theme)}
    if section_type == "theme_inversion":
        return {"-7": gettext("very {theme}").format(theme=opposite), "0": gettext("neutral"),
                "7": gettext("very {theme}").format(theme=theme)}
    return {}


def _values(section_type: str, kind: str, shown_options: list[str] | None) -> tuple[str, ...]:
    if section_type != "gesture_emotion":
        return answer_values(kind)
    if not shown_options:
        raise ValueError("gesture_emotion needs the options shown to the participant")
    unknown = [e for e in shown_options if e not in GESTURE_EMOTIONS]
    if unknown:
        raise ValueError(f"gesture_emotion options {unknown} are not gesture emotions ({', '.join(GESTURE_EMOTIONS)})")
    return tuple(shown_options)


def questions_for(section_type: str, options: dict | None = None, clip_theme: str = "",
                  shown_options: list[str] | None = None) -> list[Question]:
    """The questions asked about one clip in a section of `section_type`: the keys and answer values of
    protocol.vocabulary.SECTION_QUESTIONS with the wording above.

    options: Section.options (anchors and question for naturalness...); clip_theme: the clip's RBF theme (theme
    sections name it); shown_options: the emotions drawn for this participant and clip (gesture_emotion).
    """
    if section_type not in SECTION_QUESTIONS:
        raise ValueError(f"unknown section_type {section_type!r}")
    options = options or {}
    theme, opposite = _theme_words(section_type, clip_theme)
    questions = []
    for key, kind in SECTION_QUESTIONS[section_type].items():
        text, help_text = WORDING[section_type].questions[key]
        if section_type == "naturalness":
            text = options.get("question") or text
        labels = _value_labels(section_type, key, options, theme, opposite)
        widget = _widget(kind)
        choices = [(v, labels.get(v, "") if widget == "scale" else labels.get(v) or answer_label(kind, v))
                   for v in _values(section_type, kind, shown_options)]
        questions.append(Question(key, display(text).format(theme=theme, opposite=opposite), widget, choices,
                                  display(help_text).format(theme=theme, opposite=opposite), kind))
    if section_type in NORMING_SECTION_TYPES and ratings_per_clip(options) is not None:
        questions += _norming_questions(section_type)
    return questions


def _norming_questions(section_type: str) -> list[Question]:
    """Intensity (1..5) and naturalness (1..5, the modality's anchors) of a norming section's clip page."""
    out = []
    for key, kind in NORMING_QUESTIONS.items():
        text, help_text = NORMING_WORDING[key]
        if key == "intensity":
            anchors = INTENSITY_ANCHORS
        else:
            anchors = NATURALNESS_ANCHORS_GESTURE if section_type == "gesture_emotion" else NATURALNESS_ANCHORS_GAIT
        labels = {v: gettext(a) for v, a in anchors.items()}
        out.append(Question(key, gettext(text), "scale", [(v, labels.get(v, "")) for v in answer_values(kind)],
                            gettext(help_text) if help_text else "", kind))
    return out


def _theme_words(section_type: str, clip_theme: str) -> tuple[str, str]:
    """(theme, opposite) as the adjectives shown in the active language; neutral words when the clip has none."""
    theme = theme_adjective(clip_theme) if clip_theme else gettext("styled")
    opposite = OPPOSITE_THEME.get(clip_theme)
    return theme, theme_adjective(opposite) if opposite else gettext("plain")


def clean_answers(questions: list[Question], data) -> dict[str, str]:
    """Validate every question of a clip page. `data` maps question key -> list of posted strings
    (a Django QueryDict works: its getlist is used). Raises AnswerError naming the first bad question."""
    getlist = data.getlist if hasattr(data, "getlist") else (lambda k: list(data.get(k, [])))
    return {q.key: q.clean(getlist(q.key)) for q in questions}
