"""Pilot data: the participants who consented while a study was in pilot mode (Participant.pilot), and their
removal before the study opens. Deleting them removes their answers and assignments (cascade) and recounts how
often each clip was given in each section (SectionClipCount, which balances the clips of later participants) from
the assignments that remain."""
from __future__ import annotations

from django.db import transaction
from django.db.models import Count

from ..models import Assignment, Participant, SectionClipCount, Study


def pilot_count(study: Study) -> int:
    """How many participants of the study consented in pilot mode (shown on the progress page)."""
    return Participant.objects.filter(study=study, pilot=True).count()


def delete_pilot_data(study: Study) -> int:
    """Delete the study's pilot participants with their answers and assignments; returns how many participants."""
    with transaction.atomic():
        n = Participant.objects.filter(study=study, pilot=True).count()
        Participant.objects.filter(study=study, pilot=True).delete()
        recount_clip_counts(study)
    return n


def recount_clip_counts(study: Study) -> None:
    """Set the study's SectionClipCount rows to the trial assignments that remain, as the start counts them
    (studyapp.participant.assignment._count_trials: trials only, sections that reuse another's clips not counted)."""
    counts = (Assignment.objects.filter(section__study=study, kind="", section__reuse_section__isnull=True)
              .values("section_id", "clip_id").annotate(n=Count("id")))
    SectionClipCount.objects.filter(section__study=study).update(n=0)
    for c in counts:
        SectionClipCount.objects.update_or_create(section_id=c["section_id"], clip_id=c["clip_id"],
                                                  defaults={"n": c["n"]})
