"""Questions of each section type: wording (REFERENCE.md section 4, verbatim where the papers give it), answer
choices, and validation of posted answers. The question keys, answer values and everything else a section type is
come from its declaration (protocol.section_types); only the sentences shown live here, one
:class:`SectionWording` per type (:func:`register_wording`). The sentences and labels are marked for translation
(English msgids) and `questions_for` returns them in the active language (studyapp.i18n); the values posted and
stored never change with the language.

A question is asked once per (participant, section, clip); its answer is stored as text (DESIGN.md responses.csv):
emotion labels joined by ";" for multi-select, an integer for scales, a label for forced choice.
"""
from __future__ import annotations

from dataclasses import dataclass, field

from django.utils.translation import gettext
from django.utils.translation import gettext_noop as _

from protocol.norming import ratings_per_clip
from protocol.section_types import SectionType, get_section_type, registered
from protocol.vocabulary import (
    INTEGER_RANGES,
    LIKERT_LEVELS,
    MULTI_SELECT_KINDS,
    NORMING_QUESTIONS,
    OPPOSITE_THEME,
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
NATURALNESS_ANCHORS = {"gait": NATURALNESS_ANCHORS_GAIT, "gesture": NATURALNESS_ANCHORS_GESTURE}
"""The naturalness anchors of each modality (a section type of either modality shows the gait ones)."""


@dataclass(frozen=True)
class SectionWording:
    """What a section type says to participants.

    questions: question key -> (text, help) msgids; ``{theme}`` and ``{opposite}`` are filled in with the clip's
    theme and its opposite. anchors: question key -> answer value -> label msgid (a scale's anchors; the same
    placeholders). text_option / anchors_option: the ``Section.options`` key whose value replaces the question's
    text / its anchors (researcher text, shown as written). theme: the theme word when the clip has none."""

    questions: dict[str, tuple[str, str]]
    anchors: dict[str, dict[str, str]] = field(default_factory=dict)
    text_option: str = ""
    anchors_option: str = ""
    theme: str = _("styled")


WORDING: dict[str, SectionWording] = {}
"""section_type -> its wording (:func:`register_wording`)."""


def register_wording(section_type: str, wording: SectionWording) -> SectionWording:
    """Give a registered section type its wording; ValueError naming the question keys it lacks or adds."""
    spec = get_section_type(section_type)
    if set(wording.questions) != set(spec.wording_keys):
        raise ValueError(f"wording of {section_type!r}: questions {sorted(wording.questions)} must be its question "
                         f"keys {list(spec.wording_keys)}")
    unknown = set(wording.anchors) - set(spec.wording_keys)
    if unknown:
        raise ValueError(f"wording of {section_type!r}: anchors for unknown questions {sorted(unknown)}")
    WORDING[section_type] = wording
    return wording


def unregister_wording(section_type: str) -> None:
    """Remove a section type's wording (tests that register toy types clean up with this)."""
    WORDING.pop(section_type, None)


_THEME_ANCHORS = {"1": _("not {theme} at all"), "7": _("very {theme}")}
# seed 004: -7 the maximum opposite theme, 0 neutral, +7 the maximum original theme, said in the styles' words
_INVERSION_ANCHORS = {"-7": _("very {opposite}"), "0": _("neutral"), "7": _("very {theme}")}
_MULTI_HELP = _("More than one is allowed.")

register_wording("emotion_choice", SectionWording({
    "perceived": (_("Which emotion(s) do you perceive from this walk?"),
                  _("Select every emotion you perceive; more than one is allowed."))}))
register_wording("emotion_transition", SectionWording({
    "initial": (_("Which emotion(s) do you perceive at the start of the clip?"), _MULTI_HELP),
    "final": (_("Which emotion(s) do you perceive at the end of the clip?"), _MULTI_HELP)}))
register_wording("affect_likert", SectionWording(
    {key: (label, "") for key, (label, _levels) in LIKERT_LEVELS.items()},
    anchors={key: {str(i): text for i, text in enumerate(levels)} for key, (_label, levels) in LIKERT_LEVELS.items()}))
register_wording("naturalness", SectionWording(
    {"naturalness": (_("How natural and smooth does this animation look?"), "")},
    anchors={"naturalness": NATURALNESS_ANCHORS_GAIT}, text_option="question", anchors_option="anchors"))
register_wording("gesture_emotion", SectionWording({
    "perceived": (_("Which emotion do you perceive from the gestures?"), "")}))
register_wording("neutral_validation", SectionWording({
    "perceived": (_("Which of these best describes the walk?"), _("Choose one."))}))
register_wording("theme_rating", SectionWording(
    {"rating": (_("How {theme} does this walk look?"), _("Seven-point scale; choose one."))},
    anchors={"rating": _THEME_ANCHORS}))
register_wording("theme_inversion", SectionWording(
    {"rating": (_("Does this walk look {opposite} or {theme}?"),
                _("From -7 (very {opposite}) through 0 (neutral) to +7 (very {theme})."))},
    anchors={"rating": _INVERSION_ANCHORS}))


# The questions a norming section asks after its own (protocol.vocabulary.NORMING_QUESTIONS).
NORMING_WORDING: dict[str, tuple[str, str]] = {
    "intensity": (_("How intense is the emotion or style you perceive?"), ""),
    "naturalness": (_("How natural and smooth does this animation look?"), ""),
}
INTENSITY_ANCHORS = {"1": _("very weak"), "3": _("moderate"), "5": _("very strong")}


def section_type_choices() -> list[tuple[str, str]]:
    """(section type, admin label) for every registered section type (protocol.section_types), in the protocol's
    order, the instruction and break pages last. Read afresh on each call: a model or form field given the function
    sees types registered later."""
    return [(t.name, t.label) for t in registered(pages=True)]


def wording_of(section_type: str) -> SectionWording:
    """The wording of a registered section type; LookupError naming a type that has none."""
    try:
        return WORDING[section_type]
    except KeyError:
        raise LookupError(f"section type {section_type!r} has no wording (studyapp.questions.register_wording)") \
            from None


ECHO_LIMIT = 20


def short(value: str, limit: int = ECHO_LIMIT) -> str:
    """At most `limit` characters of a submitted value, for an error message (never echo a whole submission)."""
    value = str(value)
    return value if len(value) <= limit else value[:limit] + "\u2026"


class AnswerError(ValueError):
    """A posted answer that is missing or out of range; the message names the question."""


@dataclass(frozen=True)
class Question:
    """One question of a clip page: ``key`` (the responses.csv column), its text, how it is shown (``kind``: multi,
    single or scale), the allowed (value, label) choices, a help text and the answer kind of its declaration."""

    key: str                       # the `question` column of responses.csv
    text: str
    kind: str                      # how it is shown: "multi" | "single" | "scale"
    choices: list[tuple[str, str]] = field(default_factory=list)   # (value, label)
    help: str = ""
    answer_kind: str = ""          # the answer kind of the declaration (protocol.section_types)

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


def _value_labels(spec: SectionType, key: str, options: dict, theme: str, opposite: str) -> dict[str, str]:
    """Labels of some answer values (a scale's anchors), in the active language; values without one show no
    label, choices their name. theme/opposite: already translated adjectives."""
    wording = wording_of(spec.name)
    if wording.anchors_option and options.get(wording.anchors_option):
        return {str(k): display(v) for k, v in options[wording.anchors_option].items()}
    return {v: display(text).format(theme=theme, opposite=opposite)
            for v, text in wording.anchors.get(key, {}).items()}


def _values(spec: SectionType, kind: str, shown_options: list[str] | None) -> tuple[str, ...]:
    if not spec.drawn_choices:
        return answer_values(kind)
    if not shown_options:
        raise ValueError(f"{spec.name} needs the options shown to the participant")
    unknown = [e for e in shown_options if e not in answer_values(kind)]
    if unknown:
        raise ValueError(f"{spec.name} options {unknown} are not among its answers "
                         f"({', '.join(answer_values(kind))})")
    return tuple(shown_options)


def questions_for(section_type: str, options: dict | None = None, clip_theme: str = "",
                  shown_options: list[str] | None = None) -> list[Question]:
    """The questions asked about one clip in a section of `section_type`: the keys and answer values of its
    declaration (protocol.section_types) with its wording (:data:`WORDING`).

    options: Section.options (anchors and question for naturalness...); clip_theme: the clip's RBF theme (theme
    sections name it); shown_options: the choices drawn for this participant and clip (a type with drawn choices,
    gesture_emotion).
    """
    try:
        spec = get_section_type(section_type)
    except KeyError:
        raise ValueError(f"unknown section_type {section_type!r}") from None
    wording = wording_of(section_type)
    options = options or {}
    theme, opposite = _theme_words(wording, clip_theme)
    questions = []
    for key, kind in spec.question_kinds.items():
        text, help_text = wording.questions[key]
        if wording.text_option:
            text = options.get(wording.text_option) or text
        labels = _value_labels(spec, key, options, theme, opposite)
        widget = _widget(kind)
        choices = [(v, labels.get(v, "") if widget == "scale" else labels.get(v) or answer_label(kind, v))
                   for v in _values(spec, kind, shown_options)]
        questions.append(Question(key, display(text).format(theme=theme, opposite=opposite), widget, choices,
                                  display(help_text).format(theme=theme, opposite=opposite), kind))
    if spec.norming and ratings_per_clip(options) is not None:
        questions += _norming_questions(spec)
    return questions


def _norming_questions(spec: SectionType) -> list[Question]:
    """Intensity (1..5) and naturalness (1..5, the modality's anchors) of a norming section's clip page."""
    out = []
    for key, kind in NORMING_QUESTIONS.items():
        text, help_text = NORMING_WORDING[key]
        anchors = INTENSITY_ANCHORS if key == "intensity" else NATURALNESS_ANCHORS.get(spec.modality,
                                                                                       NATURALNESS_ANCHORS_GAIT)
        labels = {v: gettext(a) for v, a in anchors.items()}
        out.append(Question(key, gettext(text), "scale", [(v, labels.get(v, "")) for v in answer_values(kind)],
                            gettext(help_text) if help_text else "", kind))
    return out


def _theme_words(wording: SectionWording, clip_theme: str) -> tuple[str, str]:
    """(theme, opposite) as the adjectives shown in the active language; neutral words when the clip has none."""
    theme = theme_adjective(clip_theme) if clip_theme else gettext(wording.theme)
    opposite = OPPOSITE_THEME.get(clip_theme)
    return theme, theme_adjective(opposite) if opposite else gettext("plain")


def clean_answers(questions: list[Question], data) -> dict[str, str]:
    """Validate every question of a clip page. `data` maps question key -> list of posted strings
    (a Django QueryDict works: its getlist is used). Raises AnswerError naming the first bad question."""
    getlist = data.getlist if hasattr(data, "getlist") else (lambda k: list(data.get(k, [])))
    return {q.key: q.clean(getlist(q.key)) for q in questions}
