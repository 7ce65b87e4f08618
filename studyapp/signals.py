"""Model signals: a participant deleted or withdrawn leaves no stored report behind
(studyapp.staff.reports.forget_reports)."""
from __future__ import annotations

from django.db.models.signals import post_delete, post_save, pre_save
from django.dispatch import receiver

from .models import Participant, Study
from .staff.reports import forget_reports


@receiver(pre_save, sender=Participant)
def _remember_status(sender, instance: Participant, **kwargs) -> None:
    instance._status_before = (Participant.objects.filter(pk=instance.pk).values_list("status", flat=True).first()
                               if instance.pk else None)


@receiver(post_save, sender=Participant)
def _withdrawn(sender, instance: Participant, created: bool, **kwargs) -> None:
    before = getattr(instance, "_status_before", None)
    if instance.status == Participant.Status.WITHDRAWN and before != Participant.Status.WITHDRAWN:
        instance._reports_forgotten = forget_reports(instance.study_id)


@receiver(post_delete, sender=Participant)
def _deleted(sender, instance: Participant, **kwargs) -> None:
    instance._reports_forgotten = forget_reports(instance.study_id)


@receiver(post_delete, sender=Study)
def _study_deleted(sender, instance: Study, **kwargs) -> None:
    forget_reports(instance.pk)
