"""The study change page in steps: which fieldsets of the study and of its section forms each step shows.

The admin's study form is long (texts, recruitment, feedback, exclusion rules, and every section with its pool and
options). A step is one short page of it, chosen by the query parameter ``?step=<key>``; without the parameter
the page shows every step at once (the page as it always was: saved links and scripts that post the whole form
keep working). StudyAdmin and its SectionInline ask this module which fieldsets to show, so the form of a step
holds only that step's fields, and Django leaves every other field of the study as it is saved.

``STEPS`` is the one table; ``tests/studyapp/admin/test_study_steps.py`` fails when a fieldset of StudyAdmin or of the
section form belongs to no step, so a new fieldset cannot silently vanish from the stepped pages.
"""
from __future__ import annotations

from dataclasses import dataclass

STEP_PARAM = "step"


@dataclass(frozen=True)
class Step:
    """One step of the study page.

    Attributes:
        key: the ``?step=`` value.
        title: the step's name in the step bar.
        fieldsets: the titles of StudyAdmin's fieldsets on this step (None: the untitled first one).
        section_fieldsets: the titles of the section form's fieldsets on this step (None: its untitled first one);
            empty: the step shows no section forms.
        adds_sections: sections may be added and deleted on this step (only where their type is chosen).
    """

    key: str
    title: str
    fieldsets: tuple[str | None, ...] = ()
    section_fieldsets: tuple[str | None, ...] = ()
    adds_sections: bool = False


SECTION_MAIN = "Section"
SECTION_CLIPS = "Clips per participant"
SECTION_POOL = "Clip pool"
SECTION_HALVES_SUFFIX = ": generated and source halves"
SECTION_OPTIONS_SUFFIX = ": options"
SECTION_PRACTICE = "Practice and attention checks"
SECTION_RAW_POOL = "Advanced: raw JSON of the pool"
SECTION_RAW_OPTIONS = "Advanced: raw JSON of the options"

STEPS: tuple[Step, ...] = (
    Step("overview", "Overview and texts",
         fieldsets=(None, "Participant pages", "Participant data", "Access")),
    Step("sections", "Sections",
         section_fieldsets=(SECTION_MAIN, SECTION_OPTIONS_SUFFIX, SECTION_PRACTICE, SECTION_RAW_OPTIONS),
         adds_sections=True),
    Step("clips", "Clips",
         section_fieldsets=(SECTION_CLIPS, SECTION_POOL, SECTION_HALVES_SUFFIX, SECTION_RAW_POOL)),
    Step("recruitment", "Recruitment and completion",
         fieldsets=("Recruitment", "Screens and devices", "Pilot", "Feedback questions (the last page)",
                    "Advanced: feedback questions as JSON")),
    Step("exclusions", "Exclusions",
         fieldsets=("Analysis", "Advanced: exclusion rules as JSON")),
)
STEP_KEYS = tuple(step.key for step in STEPS)


class UnknownStepError(ValueError):
    """A ``?step=`` value that names no step."""


def find_step(key: str | None) -> Step | None:
    """The step of ``key``; None for no key (the whole page); UnknownStepError naming the steps otherwise."""
    if not key:
        return None
    for step in STEPS:
        if step.key == key:
            return step
    raise UnknownStepError(f"no step {key!r} (steps: {', '.join(STEP_KEYS)})")


def request_step(request) -> Step | None:
    """The step a request asks for (``?step=``, on GET and on the POST of that step's form); None: the whole
    page. UnknownStepError for a step that does not exist."""
    return find_step(request.GET.get(STEP_PARAM))


def page_step(request, study) -> Step | None:
    """The step of a study page: None on the add page (a new study is one form) and without ``?step=``."""
    return None if study is None or study.pk is None else request_step(request)


def _matches(title: str | None, wanted: tuple[str | None, ...]) -> bool:
    """Whether a fieldset title is one of ``wanted``; a wanted title starting with ':' matches every title that
    ends with it (the per-section-type option and half fieldsets, e.g. "Naturalness ...: options")."""
    return any(title == w or (w is not None and w.startswith(":") and title is not None and title.endswith(w))
               for w in wanted)


def step_fieldsets(fieldsets: list, wanted: tuple[str | None, ...]) -> list:
    """The fieldsets (Django admin's ``(title, options)`` pairs) whose titles ``wanted`` names, in page order."""
    return [fs for fs in fieldsets if _matches(fs[0], wanted)]


def steps_of(title: str | None, section: bool = False) -> list[str]:
    """The keys of the steps that show a fieldset of this title (of StudyAdmin; of the section form when
    ``section``)."""
    return [step.key for step in STEPS
            if _matches(title, step.section_fieldsets if section else step.fieldsets)]


def nav(current: Step | None, base_url: str) -> list[dict]:
    """The step bar: one link per step (``current``: marked as the page shown), then the whole page."""
    links = [{"key": step.key, "title": step.title, "url": f"{base_url}?{STEP_PARAM}={step.key}",
              "current": current is not None and step.key == current.key} for step in STEPS]
    return links + [{"key": "", "title": "All on one page", "url": base_url, "current": current is None}]
