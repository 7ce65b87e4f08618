"""Admin list filter and columns of clips by their quality record: passed, flagged, or failed one given
check; the synthetic observer's reading."""
from __future__ import annotations

from django.contrib import admin
from django.db.models import QuerySet

from protocol.vocabulary import QA_CHECKS

PASSED, FLAGGED = "passed", "flagged"


class QualityFlagFilter(admin.SimpleListFilter):
    """``?qa=passed`` (no failed check), ``?qa=flagged`` (any), ``?qa=<check>`` (that check failed)."""

    title = "quality check"
    parameter_name = "qa"

    def lookups(self, request, model_admin):
        """The filter's choices in the clip list's sidebar: passed, flagged (any check), and failed for each check."""
        return [(PASSED, "passed"), (FLAGGED, "flagged (any check)"),
                *[(check, f"failed: {check.replace('_', ' ')}") for check in QA_CHECKS]]

    def queryset(self, request, queryset: QuerySet) -> QuerySet:
        """The clips of the chosen choice (all for none or an unknown one); a check matches only as a whole name in the
        ';'-joined ``qa_flag``."""
        value = self.value()
        if value == PASSED:
            return queryset.filter(qa_flag="")
        if value == FLAGGED:
            return queryset.exclude(qa_flag="")
        if value in QA_CHECKS:
            # qa_flag joins check names with ';' and no name is a prefix of another's ';'-bounded text.
            return queryset.filter(qa_flag__regex=rf"(^|;){value}(;|$)")
        return queryset


def quality_flag(clip) -> str:
    """The admin column: 'passed' or the failed checks."""
    return clip.qa_flag.replace(";", ", ") if clip.qa_flag else PASSED


quality_flag.short_description = "quality"
quality_flag.admin_order_field = "qa_flag"


def observer_reading(clip) -> str:
    """The admin column: the synthetic observer's top label and probability ("sad 0.81"), for a gesture also the
    observed arousal the gesture check compares ("afraid 0.55, arousal 0.71"); "" when the clip has no reading."""
    qa = clip.qa or {}
    label, p = qa.get("observed"), qa.get("observed_p")
    if not label:
        return ""
    text = f"{label} {p:.2f}" if isinstance(p, (int, float)) else str(label)
    arousal = qa.get("observed_arousal")
    return f"{text}, arousal {arousal:.2f}" if isinstance(arousal, (int, float)) else text


observer_reading.short_description = "observer (synthetic)"
