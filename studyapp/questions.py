"""Questions of each section type: wording (REFERENCE.md section 4, verbatim where the papers give it), answer
choices, and validation of posted answers. No Django import: views and tests share it.

A question is asked once per (participant, section, clip); its answer is stored as text (DESIGN.md responses.csv):
emotion labels joined by ";" for multi-select, an integer for scales, a label for forced choice.
"""
from __future__ import annotations

from dataclasses import dataclass, field

GAIT_EMOTIONS = ("happy", "sad", "angry", "neutral")
THEMES = ("happy", "sad", "energetic", "tired", "feminine", "masculine")
# The 11 categories of the MPI Emotional Body Expressions database (seed 003 section 6.1).
GESTURE_EMOTIONS = ("afraid", "amused", "angry", "ashamed", "disgusted", "joyous", "neutral", "proud", "relieved",
                    "sad", "surprised")
OPPOSITE_THEME = {"happy": "sad", "sad": "happy", "energetic": "tired", "tired": "energetic",
                  "feminine": "masculine", "masculine": "feminine"}

# Seed 000 Table 2 (values 0..4), verbatim.
LIKERT_FEATURES = {
    "torso": ("Torso", ["contracted, bowed", "somewhat contracted", "neither contracted nor expanded",
                        "somewhat expanded", "expanded, stretched"]),
    "arms": ("Arms", ["contracted, close to the body", "somewhat contracted", "neither contracted nor expanded",
                      "somewhat expanded", "expanded, away from the body"]),
    "pace": ("Gait pace", ["sustained, leisurely, slow", "somewhat sustained", "neither sustained nor hurried",
                           "somewhat hurried", "hurried, sudden, fast"]),
    "flow": ("Gait flow", ["free, relaxed, uncontrolled", "somewhat free", "neither free nor bound",
                           "somewhat bound", "bound, tense, controlled"]),
}

# Seed 000 section 6.3.4 anchors and seed 003 Table 2 markers (1..5), verbatim.
NATURALNESS_ANCHORS_GAIT = {"1": "not natural at all", "3": "satisfactory", "5": "very natural"}
NATURALNESS_ANCHORS_GESTURE = {
    "1": "Very Unnatural (e.g. broken arms or legs, torso at an impossible angle)",
    "2": "Not Realistic (e.g. limbs going inside the body or through the chair)",
    "3": "Looks OK (no serious problems, but does not look very appealing)",
    "4": "Looks good (no problems and the gestures look natural)",
    "5": "Looks great! (the gestures look like they could be from a real person)",
}


class AnswerError(ValueError):
    """A posted answer that is missing or out of range; the message names the question."""


@dataclass(frozen=True)
class Question:
    key: str                       # the `question` column of responses.csv
    text: str
    kind: str                      # "multi" | "single" | "scale"
    choices: list[tuple[str, str]] = field(default_factory=list)   # (value, label)
    help: str = ""

    def clean(self, raw: list[str]) -> str:
        """Validate the posted values of this question (a list, as from QueryDict.getlist) -> stored answer."""
        values = [v.strip() for v in raw if v is not None and v.strip() != ""]
        allowed = [c[0] for c in self.choices]
        if not values:
            raise AnswerError(f"Please answer: {self.text}")
        for v in values:
            if v not in allowed:
                raise AnswerError(f"'{v}' is not an allowed answer to: {self.text}")
        if self.kind == "multi":
            chosen = set(values)
            return ";".join(v for v in allowed if v in chosen)   # canonical order, no duplicates
        if len(set(values)) != 1:
            raise AnswerError(f"Choose exactly one answer to: {self.text}")
        return values[0]


def _scale(lo: int, hi: int, labels: dict[str, str]) -> list[tuple[str, str]]:
    return [(str(v), labels.get(str(v), "")) for v in range(lo, hi + 1)]


def questions_for(section_type: str, options: dict | None = None, clip_theme: str = "",
                  shown_options: list[str] | None = None) -> list[Question]:
    """The questions asked about one clip in a section of `section_type`.

    options: Section.options (anchors for naturalness, categories...); clip_theme: the clip's RBF theme (theme
    sections name it); shown_options: the four emotions drawn for this participant and clip (gesture_emotion).
    """
    options = options or {}
    emotions = [(e, e.capitalize()) for e in GAIT_EMOTIONS]
    if section_type == "emotion_choice":
        return [Question("perceived", "Which emotion(s) do you perceive from this walk?", "multi", emotions,
                         "Select every emotion you perceive; more than one is allowed.")]
    if section_type == "emotion_transition":
        return [
            Question("initial", "Which emotion(s) do you perceive at the start of the clip?", "multi", emotions,
                     "More than one is allowed."),
            Question("final", "Which emotion(s) do you perceive at the end of the clip?", "multi", emotions,
                     "More than one is allowed."),
        ]
    if section_type == "affect_likert":
        return [Question(key, label, "scale", [(str(i), text) for i, text in enumerate(levels)])
                for key, (label, levels) in LIKERT_FEATURES.items()]
    if section_type == "naturalness":
        anchors = {str(k): v for k, v in (options.get("anchors") or NATURALNESS_ANCHORS_GAIT).items()}
        text = options.get("question") or "How natural and smooth does this animation look?"
        return [Question("naturalness", text, "scale", _scale(1, 5, anchors))]
    if section_type == "gesture_emotion":
        if not shown_options:
            raise ValueError("gesture_emotion needs the options shown to the participant")
        return [Question("perceived", "Which emotion do you perceive from the gestures?", "single",
                         [(e, e.capitalize()) for e in shown_options])]
    if section_type == "neutral_validation":
        labels = ["neutral", *THEMES]
        return [Question("perceived", "Which of these best describes the walk?", "single",
                         [(t, t.capitalize()) for t in labels], "Choose one.")]
    if section_type == "theme_rating":
        theme = clip_theme or "styled"
        return [Question("rating", f"How {theme} does this walk look?", "scale",
                         _scale(1, 7, {"1": "not at all", "7": f"maximum {theme}"}),
                         "Seven-point scale; choose one.")]
    if section_type == "theme_inversion":
        theme = clip_theme or "original theme"
        opposite = OPPOSITE_THEME.get(clip_theme, "opposite theme")
        labels = {"-7": f"maximum {opposite} (opposite theme)", "0": "neutral",
                  "7": f"maximum {theme} (original theme)"}
        return [Question("rating", f"Does this walk look {opposite} or {theme}?", "scale",
                         [(str(v), labels.get(str(v), "")) for v in range(-7, 8)],
                         f"From -7 (maximum opposite theme) through 0 (neutral) to +7 (maximum {theme}).")]
    raise ValueError(f"unknown section_type {section_type!r}")


def clean_answers(questions: list[Question], data) -> dict[str, str]:
    """Validate every question of a clip page. `data` maps question key -> list of posted strings
    (a Django QueryDict works: its getlist is used). Raises AnswerError naming the first bad question."""
    getlist = data.getlist if hasattr(data, "getlist") else (lambda k: list(data.get(k, [])))
    return {q.key: q.clean(getlist(q.key)) for q in questions}
