"""Languages of the participant pages.

A study is shown in one language, chosen per study in the admin (Study.language, one of settings.LANGUAGES).
The views call `activate_study_language(study)` as soon as they know the study; `StudyLanguageMiddleware` starts
every request in the default language and resets it after the response, so a study's language never leaks into
the next request served by the same thread (the admin, another study).

Only what is *displayed* is translated. The answer values posted, stored and exported stay the protocol's labels
(protocol/vocabulary.py): `answer_label()` turns a value into the text shown next to it. Researcher-written text
(title, introduction, consent, section titles and instructions, custom questions and anchors) is shown as
entered; text that is one of this app's defaults (e.g. the naturalness anchors a preset copies into a section's
options) has a msgid and is translated.

The msgids of the protocol's display strings are marked below (`_MARKED_FOR_EXTRACTION`) so that `makemessages`
finds them; tests/studyapp/test_i18n.py checks that every protocol value and every marked string has a German msgstr.
"""
from __future__ import annotations

from django.conf import settings
from django.utils import translation
from django.utils.translation import gettext, gettext_noop, pgettext, pgettext_lazy

from protocol.vocabulary import LABEL_CHOICES, LIKERT_LEVELS, NEUTRAL_CHOICE

EMOTION_CONTEXT = "emotion"             # an emotion as an answer option ("Happy" -> "Glücklich")
THEME_CONTEXT = "theme"                 # a style theme as an answer option ("Happy" -> "Fröhlich")
THEME_ADJECTIVE_CONTEXT = "theme adjective"   # a theme inside a sentence ("How happy ..." -> "Wie fröhlich ...")


def study_languages() -> list[str]:
    """The language codes a study may use (settings.LANGUAGES)."""
    return [code for code, _name in settings.LANGUAGES]


def activate_study_language(study) -> str:
    """Activate the study's language for the rest of this request (the middleware resets it). A study without a
    known language (None, '', a code not in settings.LANGUAGES) gets the default. Returns the code activated."""
    code = getattr(study, "language", "") or ""
    if code not in study_languages():
        code = settings.LANGUAGE_CODE
    translation.activate(code)
    return code


class StudyLanguageMiddleware:
    """Every request starts in settings.LANGUAGE_CODE and ends with translation deactivated; the response says
    which language it was rendered in (Content-Language)."""

    def __init__(self, get_response):
        self.get_response = get_response

    def __call__(self, request):
        translation.activate(settings.LANGUAGE_CODE)
        try:
            response = self.get_response(request)
            response.headers.setdefault("Content-Language", translation.get_language())
        finally:
            translation.deactivate()
        return response


def _context_of(answer_kind: str) -> str:
    return THEME_CONTEXT if answer_kind == NEUTRAL_CHOICE else EMOTION_CONTEXT


def answer_label(answer_kind: str, value: str) -> str:
    """The text shown for one label answer (an emotion or a theme) in the active language. The msgid is the
    protocol value capitalised, in the context of its kind; the posted value stays `value`."""
    if answer_kind not in LABEL_CHOICES:
        raise ValueError(f"{answer_kind!r} is not a label answer kind ({', '.join(LABEL_CHOICES)})")
    return pgettext(_context_of(answer_kind), value.capitalize())


def theme_adjective(theme: str) -> str:
    """A style theme as the adjective of a question sentence ("How {theme} does this walk look?")."""
    return pgettext(THEME_ADJECTIVE_CONTEXT, theme)


def display(text: str) -> str:
    """`text` in the active language when it is one of this app's marked strings (a default anchor, the
    protocol's Likert wording); anything else (researcher-written text) unchanged."""
    return gettext(text) if text else text


def likert_texts() -> list[str]:
    """Every display string of protocol.vocabulary.LIKERT_LEVELS (feature names and the wording of the levels)."""
    texts = []
    for label, levels in LIKERT_LEVELS.values():
        texts.append(label)
        texts.extend(levels)
    return texts


def label_msgids() -> list[tuple[str, str]]:
    """(context, msgid) of every protocol label that can be shown as an answer option or inside a sentence."""
    pairs = []
    for kind, values in LABEL_CHOICES.items():
        pairs.extend((_context_of(kind), v.capitalize()) for v in values)
    pairs.extend((THEME_ADJECTIVE_CONTEXT, v) for v in LABEL_CHOICES[NEUTRAL_CHOICE])
    return sorted(set(pairs))


# Marked for makemessages only (never used at run time): the protocol's display strings, which live in
# protocol/vocabulary.py (no Django there), and the preset defaults that presets copy into studies.
_MARKED_FOR_EXTRACTION = (
    # LIKERT_LEVELS (seed 000 Table 2)
    gettext_noop("Torso"), gettext_noop("Arms"), gettext_noop("Gait pace"), gettext_noop("Gait flow"),
    gettext_noop("contracted, bowed"), gettext_noop("somewhat contracted"),
    gettext_noop("neither contracted nor expanded"), gettext_noop("somewhat expanded"),
    gettext_noop("expanded, stretched"), gettext_noop("contracted, close to the body"),
    gettext_noop("expanded, away from the body"), gettext_noop("sustained, leisurely, slow"),
    gettext_noop("somewhat sustained"), gettext_noop("neither sustained nor hurried"),
    gettext_noop("somewhat hurried"), gettext_noop("hurried, sudden, fast"),
    gettext_noop("free, relaxed, uncontrolled"), gettext_noop("somewhat free"), gettext_noop("neither free nor bound"),
    gettext_noop("somewhat bound"), gettext_noop("bound, tense, controlled"),
    # emotions as answer options (gait and gesture)
    pgettext_lazy("emotion", "Afraid"), pgettext_lazy("emotion", "Amused"), pgettext_lazy("emotion", "Angry"),
    pgettext_lazy("emotion", "Ashamed"), pgettext_lazy("emotion", "Disgusted"), pgettext_lazy("emotion", "Happy"),
    pgettext_lazy("emotion", "Joyous"), pgettext_lazy("emotion", "Neutral"), pgettext_lazy("emotion", "Proud"),
    pgettext_lazy("emotion", "Relieved"), pgettext_lazy("emotion", "Sad"), pgettext_lazy("emotion", "Surprised"),
    # themes as answer options (neutral validation) and inside sentences (theme rating, inversion)
    pgettext_lazy("theme", "Neutral"), pgettext_lazy("theme", "Happy"), pgettext_lazy("theme", "Sad"),
    pgettext_lazy("theme", "Energetic"), pgettext_lazy("theme", "Tired"), pgettext_lazy("theme", "Feminine"),
    pgettext_lazy("theme", "Masculine"),
    pgettext_lazy("theme adjective", "neutral"), pgettext_lazy("theme adjective", "happy"),
    pgettext_lazy("theme adjective", "sad"), pgettext_lazy("theme adjective", "energetic"),
    pgettext_lazy("theme adjective", "tired"), pgettext_lazy("theme adjective", "feminine"),
    pgettext_lazy("theme adjective", "masculine"),
    # preset defaults copied into studies (studyapp/staff/presets.py)
    gettext_noop("How natural do the gestures look?"),
    gettext_noop("Were you distracted by the camera during the study?"),
    gettext_noop("Were you distracted by the lack of facial expressions?"),
    gettext_noop("Any other comments (optional)?"),
    # messages of studyapp/participant/assignment.py and studyapp/participant/views.py, translated where they are shown
    gettext_noop("This study is closed and is not accepting participants. Thank you for your interest."),
    gettext_noop("This study is full: it has all the participants it needs. Thank you for your interest."),
    gettext_noop("This Prolific ID has already started this study in another browser, with a different "
                 "study or session link. Please continue in the browser where you started, or open the study "
                 "again from the same Prolific link. If you think this is a mistake, message the researchers "
                 "on Prolific."),
    gettext_noop("Please answer the clips in order: this is the clip you are on."),
    gettext_noop("Please watch the whole clip before answering."),
)
