"""Who may open the researcher pages: the staff-plus-permission decorator, the custom permissions of the study
models, the permission set of the shipped "researcher" group (created by a data migration), and per-study access:
a researcher sees only the studies they own or collaborate on (superusers see all), everywhere a study's data is
shown (admin lists and pages, preview, progress, exports, reports)."""
from __future__ import annotations

from functools import wraps

from django.apps import apps
from django.contrib.admin.views.decorators import staff_member_required
from django.core.exceptions import PermissionDenied
from django.db.models import Q
from django.http import Http404

EXPORT_PERMISSION = "studyapp.export_participant_data"
"""Download a study's CSV exports and analysis report (participant data; external ids pseudonymised unless the
study asks for them: studyapp.data.privacy)."""

STUDY_PERMISSIONS = [
    ("export_participant_data", "Can download participant data (CSV exports and analysis reports)"),
    ("download_payment_ids", "Can download participants' external ids (Prolific IDs) for payment"),
]
"""Custom permissions declared in Study.Meta: what no add/change/delete/view model permission covers."""

RESEARCHER_GROUP = "researcher"
RESEARCHER_PERMISSIONS = [
    # studies and their sections: create (also from a preset), edit, open/close, preview, progress
    "add_study", "change_study", "view_study",
    "add_section", "change_section", "delete_section", "view_section",
    # the clip catalogue (pool editor's live count, contact sheets) and collected data, read only
    "view_clip", "view_participant", "view_response",
    "export_participant_data",
]
"""Codenames (app studyapp) the "researcher" group holds: run studies and read their data; no deleting
studies, participants or answers and no editing of the catalogue or of collected data. Not the payment download
(download_payment_ids): grant it to whoever pays participants."""


def has_staff_permission(user, perm: str) -> bool:
    """An active staff account holding ``perm`` ("app_label.codename"); superusers hold every permission."""
    return bool(user.is_authenticated and user.is_active and user.is_staff and user.has_perm(perm))


def staff_permission_required(perm: str):
    """View decorator: anonymous and non-staff users go to the admin login (like staff_member_required); a staff
    member without ``perm`` gets 403 (PermissionDenied)."""

    def decorator(view):
        @wraps(view)
        def checked(request, *args, **kwargs):
            if not request.user.has_perm(perm):
                raise PermissionDenied(f"this page needs the permission {perm}")
            return view(request, *args, **kwargs)

        return staff_member_required(checked)

    return decorator


def studies_for(user):
    """The studies ``user`` may see (a Study queryset): every study for an active superuser, else those the user
    owns or collaborates on; none for anyone else."""
    Study = apps.get_model("studyapp", "Study")  # noqa: N806 - studyapp.models imports this module

    if not (user.is_authenticated and user.is_active):
        return Study.objects.none()
    if user.is_superuser:
        return Study.objects.all()
    return Study.objects.filter(pk__in=Study.objects.filter(Q(owners=user) | Q(collaborators=user)).values("pk"))


def can_access_study(user, study) -> bool:
    """True when ``user`` may see ``study`` (a Study or its pk)."""
    pk = getattr(study, "pk", study)
    return pk is not None and studies_for(user).filter(pk=pk).exists()


def can_manage_study_access(user, study) -> bool:
    """True when ``user`` may change who owns and collaborates on ``study``: superusers and its owners."""
    if not (user.is_authenticated and user.is_active):
        return False
    return user.is_superuser or (study.pk is not None and study.owners.filter(pk=user.pk).exists())


def study_of(request, study_id: int):
    """The study of a researcher page's URL if the request's user may see it, else Http404 (a study of another
    lab is not confirmed to exist)."""
    study = studies_for(request.user).filter(pk=study_id).first()
    if study is None:
        raise Http404("No study with this id")
    return study
