"""The pool rule ``norms``: clips admitted by their norms (a clip_norms.csv or a study of the site), observer flags
advisory where people rated a clip, the pool editor's table, and bad input refused whole with file, line, column
or field named."""
from __future__ import annotations

import json

import pandas as pd
import pytest
from django.contrib.auth.models import User
from django.urls import reverse

from protocol.pools import pool_errors
from protocol.vocabulary import CLIP_NORMS_COLUMNS, GAIT_EMOTIONS
from studyapp.admin.norms import norms_table
from studyapp.data import norms_rule
from studyapp.data.catalogue import CatalogueError, pool_queryset
from studyapp.models import Clip, Participant, Response, Section, Study
from studyapp.staff.presets import create_study_from_preset
from studyapp.testing import make_catalogue
from studyapp.testing import section_form_errors as section_errors

pytestmark = pytest.mark.django_db
WALKS = {"modality": "gait", "origin": "generated", "transition": False, "rbf": False}


@pytest.fixture(autouse=True)
def catalogue(settings, tmp_path):
    settings.MEDIA_ROOT = tmp_path / "media"
    settings.DATA_DIR = tmp_path
    make_catalogue(settings.MEDIA_ROOT)
    norms_rule.clear()
    yield
    norms_rule.clear()


def norm_row(clip_id: str, intended: str, share: float, n: int, **extra) -> dict:
    """A clip_norms.csv row of an emotion_choice clip: ``share`` on the intended emotion, the rest spread evenly."""
    rest = (1 - share) / 3
    shares = {f"share_{e}": share if e == intended else rest for e in GAIT_EMOTIONS}
    row = {"clip_id": clip_id, "modality": "gait", "section_type": "emotion_choice", "question": "perceived",
           "n_ratings": n, "intended": intended, "top_label": intended, "top_share": share, "intended_share": share,
           "intended_ci_low": max(0, share - 0.2), "intended_ci_high": min(1, share + 0.2),
           "entropy_bits": 1.0 if share >= 0.5 else 1.9, "ad_statistic": "", "ad_p_value": "",
           "intensity_mean": 3, "naturalness_mean": 4, "naturalness_n": n, **shares}
    row.update(extra)
    return row


def write_norms(tmp_path, rows, name="clip_norms.csv") -> str:
    df = pd.DataFrame(rows)
    df = df[[*CLIP_NORMS_COLUMNS, *[c for c in df.columns if c.startswith("share_")]]]
    df.to_csv(tmp_path / name, index=False)
    return str(tmp_path / name)


def flag_observer(clip_id: str) -> None:
    Clip.objects.filter(clip_id=clip_id).update(qa_flag="observer")


def test_rule_structure_is_checked_by_field():
    errors = pool_errors({"norms": {"from": "", "min_intended_share": 2, "colour": 1}})
    assert any("'norms': 'from' must name a study" in e for e in errors)
    assert any("'min_intended_share' must be a number from 0 to 1, got 2" in e for e in errors)
    assert any("unknown field 'colour'" in e for e in errors)
    assert pool_errors({"norms": {"from": "pilot"}}) == [
        "'norms' needs at least one of min_ratings, min_intended_share, max_entropy_bits"]


def test_clips_admitted_by_their_norms_and_observer_flags_advisory(tmp_path):
    # gait_gen_00 happy, _01 sad, _02 angry, _03 neutral, _04 happy/neutral (studyapp.testing.GAIT_VECTORS)
    path = write_norms(tmp_path, [norm_row("gait_gen_00", "happy", 0.8, 20), norm_row("gait_gen_01", "sad", 0.4, 20),
                                  norm_row("gait_gen_02", "angry", 0.9, 6), norm_row("gait_gen_03", "neutral", 0.7, 20),
                                  norm_row("gait_gen_05", "sad", 0.3, 20, entropy_bits=1.2)])
    flag_observer("gait_gen_03")            # the observer read it as something else; people did not
    flag_observer("gait_gen_06")            # flagged and never rated: stays out
    pool = {**WALKS, "norms": {"from": path, "min_ratings": 10, "min_intended_share": 0.5}}
    assert set(pool_queryset(pool).values_list("clip_id", flat=True)) == {"gait_gen_00", "gait_gen_03"}
    without_rule = set(pool_queryset(WALKS).values_list("clip_id", flat=True))
    assert "gait_gen_03" not in without_rule and "gait_gen_06" not in without_rule
    html = norms_table(pool)
    assert "2 of 10 clips in the pool" in html
    assert "out: intended share 0.40 &lt; 0.5" in html and "out: 6 ratings &lt; 10" in html
    assert "out: no norms for this clip; failed quality check(s): observer" in html
    assert "in (observer flag advisory: people rated this clip)" in html
    entropy = {**WALKS, "norms": {"from": path, "max_entropy_bits": 1.5}}
    assert "gait_gen_01" not in set(pool_queryset(entropy).values_list("clip_id", flat=True))


@pytest.mark.parametrize("edit, message", [
    (lambda df: df.drop(columns="entropy_bits"), "bad.csv header, column 'entropy_bits': required column is "
                                                 "missing"),
    (lambda df: df.assign(clip_id=["gait_gen_00", "no_such_clip"]),
     "bad.csv line 3, column 'clip_id': unknown clip 'no_such_clip' (not in the catalogue)"),
    (lambda df: df.assign(share_sad=[0.5, 0.2]), "bad.csv line 2, columns 'share_happy', 'share_sad', "
     "'share_angry', 'share_neutral': shares of emotion_choice/perceived sum to 1.433, not 1 (0.8 + 0.5 + 0.06667 + "
     "0.06667)"),
])
def test_bad_norms_file_is_refused_whole(tmp_path, edit, message):
    good = write_norms(tmp_path, [norm_row("gait_gen_00", "happy", 0.8, 20), norm_row("gait_gen_01", "sad", 0.7, 20)])
    study = create_study_from_preset("demo", "main", plan="test")
    section = study.sections.get(section_type="emotion_choice")
    section.pool = {**WALKS, "norms": {"from": good, "min_intended_share": 0.5}}
    assert section_errors(section) == {}
    section.save()
    bad = tmp_path / "bad.csv"
    edit(pd.read_csv(good)).to_csv(bad, index=False)
    section.pool = {**WALKS, "norms": {"from": str(bad), "min_intended_share": 0.5}}
    section.full_clean()                         # the model layer checks the rule's form, not its source
    text = " ".join(section_errors(section)["pool"])
    assert "pool.norms.from" in text and message in text
    with pytest.raises(CatalogueError, match="pool.norms.from"):
        pool_queryset(section.pool).count()
    section.refresh_from_db()                    # nothing half-applied: the saved pool is the good one
    assert section.pool["norms"]["from"] == good
    assert set(pool_queryset(section.pool).values_list("clip_id", flat=True)) == {"gait_gen_00", "gait_gen_01"}


def test_a_norms_file_must_lie_in_the_data_folder(settings, tmp_path):
    data = tmp_path / "data"
    (data / "norms").mkdir(parents=True)
    settings.DATA_DIR = data
    rows = [norm_row("gait_gen_00", "happy", 0.8, 20)]
    outside = write_norms(tmp_path, rows, "outside.csv")
    write_norms(data / "norms", rows, "clip_norms.csv")
    write_norms(data / "norms", rows, "clip_norms.txt")
    (data / "link.csv").symlink_to(outside)
    ok = {**WALKS, "norms": {"from": "norms/clip_norms.csv", "min_ratings": 10}}
    assert set(pool_queryset(ok).values_list("clip_id", flat=True)) == {"gait_gen_00"}
    assert norms_rule.load_norms(str(data / "norms" / "clip_norms.csv"))       # absolute, but inside: fine
    for source, words in ((outside, "outside the data folder"), ("../outside.csv", "outside the data folder"),
                          ("link.csv", "outside the data folder"), ("/etc/passwd", "not a .csv file"),
                          ("norms/clip_norms.txt", "not a .csv file")):
        with pytest.raises(norms_rule.NormsSourceError) as err:
            norms_rule.load_norms(source)
        assert str(err.value).startswith(f"pool.norms.from: {source!r}") and words in str(err.value), source
        assert str(tmp_path) not in str(err.value).replace(source, "")           # the server's folders stay unnamed


def test_norms_from_a_study_of_the_site():
    pilot = create_study_from_preset("norming", "pilot", plan="test")
    section = Section(study=pilot, section_type="emotion_choice", pool={**WALKS,
                      "norms": {"from": "pilot", "min_intended_share": 0.5}})
    section.full_clean(exclude=["order"])
    assert "study 'pilot' has no norms yet" in " ".join(section_errors(section)["pool"])
    section.pool["norms"]["from"] = "no-such-study"
    assert "pool.norms.from: no study 'no-such-study' on this site" in " ".join(section_errors(section)["pool"])
    walks = pilot.sections.get(section_type="emotion_choice")
    answers = {"gait_gen_00": ["happy"] * 9 + ["sad"], "gait_gen_01": ["happy"] * 6 + ["sad"] * 4}
    for i in range(10):
        p = Participant.objects.create(study=pilot, status="completed")
        for clip_id, given in answers.items():
            Response.objects.create(participant=p, section=walks, clip=Clip.objects.get(clip_id=clip_id),
                                    question="perceived", answer=given[i], response_ms=5000)
    norms_rule.clear()
    section.pool["norms"]["from"] = "pilot"
    assert "pool" not in section_errors(section)
    # gait_gen_00 intended happy, 9 of 10 happy: in; gait_gen_01 intended sad, 4 of 10: out
    assert set(pool_queryset(section.pool).values_list("clip_id", flat=True)) == {"gait_gen_00"}


def test_pool_editor_page_shows_norms_and_why_a_clip_is_out(tmp_path, client):
    path = write_norms(tmp_path, [norm_row("gait_gen_00", "happy", 0.8, 20), norm_row("gait_gen_01", "sad", 0.4, 20)])
    study = create_study_from_preset("demo", "main", plan="test")
    Section.objects.filter(study=study, section_type="emotion_choice").update(
        pool={**WALKS, "norms": {"from": path, "min_intended_share": 0.5}})
    client.force_login(User.objects.create_superuser("admin", "a@example.org", "pw"))
    html = client.get(reverse("admin:studyapp_study_change", args=[study.pk])).content.decode()
    assert "Norms from <code>" in html and "out: intended share 0.40 &lt; 0.5" in html
    assert "1 clip in the catalogue matches" in html
    assert Study.objects.count() == 1
    # the live count (a fetch while the researcher edits) answers the same table, and the error of a bad source
    url = reverse("admin:studyapp_pool_count")
    pool = {**WALKS, "norms": {"from": path, "min_intended_share": 0.3}}
    live = client.get(url, {"section_type": "emotion_choice", "pool": json.dumps(pool)}).json()
    assert live["count"] == 2 and "2 of 10 clips in the pool" in live["norms_html"]
    pool["norms"]["from"] = "missing.csv"
    live = client.get(url, {"section_type": "emotion_choice", "pool": json.dumps(pool)}).json()
    assert live["count"] is None and "pool.norms.from: cannot read 'missing.csv'" in live["errors"][-1]["messages"][0]
