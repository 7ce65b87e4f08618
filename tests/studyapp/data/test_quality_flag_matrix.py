"""What the pool's quality switches let in, one flag kind at a time: unticked "include flagged" keeps every flagged
clip out, "keep advisory" keeps only the advisory (realism) kind, "observer advisory" only the observer's; and the
admin's live count is what a participant who sees every clip of the pool gets."""
from __future__ import annotations

import json

import pytest
from django.contrib.auth.models import Permission, User
from django.test import Client
from django.urls import reverse

from protocol.vocabulary import QA_ADVISORY_CHECKS, QA_CHECKS
from studyapp.data.catalogue import upsert_clips
from studyapp.models import Assignment, Participant, Section, Study
from studyapp.participant.assignment import start_participant

SWITCHES = {"none": {}, "keep_advisory": {"keep_advisory": True}, "observer_advisory": {"observer_advisory": True},
            "include_flagged": {"include_flagged": True}}


def admitted(flag: str, switch: str) -> bool:
    """The rule as the admin's boxes state it, written out per flag kind."""
    if flag == "" or switch == "include_flagged":
        return True
    if switch == "keep_advisory":
        return all(c in QA_ADVISORY_CHECKS for c in flag.split(";"))
    if switch == "observer_advisory":
        return flag == "observer"
    return False


FLAGS = ["", *QA_CHECKS, "observer;realism", "penetration;realism"]


def rec(clip_id: str, flag: str) -> dict:
    return {"clip_id": clip_id, "modality": "gait", "origin": "generated", "happy": 1.0, "sad": 0, "angry": 0,
            "neutral": 0, "duration_s": 2, "video": f"clips/{clip_id}.mp4", "poster": f"clips/{clip_id}.png",
            "plan": "matrix", "metadata": {"synthetic": True}, "qa": {"flag": flag}}


@pytest.fixture
def catalogue(db):
    upsert_clips([rec(f"clip_{i:02d}", flag) for i, flag in enumerate(FLAGS)])
    return {f"clip_{i:02d}": flag for i, flag in enumerate(FLAGS)}


@pytest.fixture
def staff(db):
    user = User.objects.create_user("researcher", password="pw-researcher-1", is_staff=True)
    user.user_permissions.add(Permission.objects.get(codename="view_clip"))
    c = Client()
    c.force_login(user)
    return c


def test_every_realism_check_is_advisory_and_the_rest_are_not():
    assert QA_ADVISORY_CHECKS == ("realism",)


@pytest.mark.parametrize("switch", list(SWITCHES))
def test_flag_matrix_editor_count_matches_a_participants_clips(catalogue, staff, switch):
    pool = {"modality": "gait", "plan": "matrix", **SWITCHES[switch]}
    expected = {clip_id for clip_id, flag in catalogue.items() if admitted(flag, switch)}
    params = {"section_type": "emotion_choice", "pool": json.dumps(pool),
              "clips_per_participant": 0}
    answer = staff.get(reverse("admin:studyapp_pool_count"), params).json()
    assert answer["count"] == len(expected), answer
    study = Study.objects.create(slug=f"m-{switch.replace('_', '-')}", title="matrix", status="open",
                                 ask_demographics=False)
    section = Section.objects.create(study=study, order=1, section_type="emotion_choice", pool=pool,
                                     clips_per_participant=0)
    participant = Participant.objects.create(study=study)
    assert start_participant(participant)
    shown = set(Assignment.objects.filter(participant=participant, section=section, kind="")
                .values_list("clip__clip_id", flat=True))
    assert shown == expected


@pytest.mark.parametrize("flag", [f for f in FLAGS if f])
def test_unticked_include_flagged_keeps_each_flag_kind_out(catalogue, flag):
    from studyapp.data.catalogue import pool_queryset
    ids = set(pool_queryset({"plan": "matrix"}).values_list("clip_id", flat=True))
    assert ids == {"clip_00"}
    kept = set(pool_queryset({"plan": "matrix", "keep_advisory": True}).values_list("clip_id", flat=True))
    flagged = [c for c, f in catalogue.items() if f == flag]
    assert (flagged[0] in kept) == (flag == "realism")


@pytest.mark.django_db(transaction=True)
def test_saved_pools_keep_drawing_realism_flagged_clips_after_the_migration():
    from django.db import connection
    from django.db.migrations.executor import MigrationExecutor

    before = [("studyapp", "0011_section_type_choices_from_registry")]
    after = [("studyapp", "0012_integrity_probe_and_privacy")]
    executor = MigrationExecutor(connection)
    executor.migrate(before)
    apps = executor.loader.project_state(before).apps
    Study, Section = apps.get_model("studyapp", "Study"), apps.get_model("studyapp", "Section")
    study = Study.objects.create(slug="old", title="old")
    kept = Section.objects.create(study=study, order=1, section_type="emotion_choice", pool={"modality": "gait"})
    flagged = Section.objects.create(study=study, order=2, section_type="emotion_choice",
                                     pool={"modality": "gait", "include_flagged": True})
    executor = MigrationExecutor(connection)
    executor.migrate(after)
    apps = executor.loader.project_state(after).apps
    Section = apps.get_model("studyapp", "Section")
    assert Section.objects.get(pk=kept.pk).pool == {"modality": "gait", "keep_advisory": True}
    assert Section.objects.get(pk=flagged.pk).pool == {"modality": "gait", "include_flagged": True}
    executor = MigrationExecutor(connection)         # back to the latest schema for the tests after this one
    executor.migrate(executor.loader.graph.leaf_nodes())
