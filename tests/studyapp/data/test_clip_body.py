"""The human body a clip shows is a study factor: the catalogue keeps its preset, a pool can filter on it, the
study's clips.csv exports it and the analysis breaks results down by it."""
from __future__ import annotations

import csv
import io

import pytest

from analysis.io import load_study
from studyapp.data.catalogue import CatalogueError, pool_queryset, upsert_clips
from studyapp.data.export import stream_csv
from studyapp.models import Clip
from studyapp.staff.presets import create_study_from_preset
from studyapp.testing import make_catalogue

pytestmark = pytest.mark.django_db


def walk(clip_id: str, body) -> dict:
    return {"clip_id": clip_id, "modality": "gait", "origin": "generated", "video": f"{clip_id}.mp4",
            "plan": "bodies", "happy": 1.0, "sad": 0.0, "angry": 0.0, "neutral": 0.0, "body": body}


def test_the_catalogue_keeps_the_body_preset_and_a_pool_filters_on_it(settings, tmp_path):
    settings.MEDIA_ROOT = tmp_path
    upsert_clips([walk("a", {"preset": "female", "licence": "CC0-1.0"}), walk("b", "male-older"),
                  walk("c", None)])
    assert dict(Clip.objects.values_list("clip_id", "body")) == {"a": "female", "b": "male-older", "c": ""}
    assert set(pool_queryset({"plan": "bodies", "body": "female"}).values_list("clip_id", flat=True)) == {"a"}
    assert set(pool_queryset({"plan": "bodies", "body__startswith": "male"}).values_list("clip_id", flat=True)) \
        == {"b"}
    with pytest.raises(CatalogueError, match="'body' is longer"):
        upsert_clips([walk("d", "x" * 61)])


def test_the_study_export_carries_the_body_to_the_analysis(settings, tmp_path):
    settings.MEDIA_ROOT = tmp_path / "media"
    make_catalogue(settings.MEDIA_ROOT)
    Clip.objects.filter(modality="gait").update(body="female-heavy")
    study = create_study_from_preset("demo", "bodies", plan="test")
    clips = list(csv.DictReader(io.StringIO("".join(stream_csv(study, "clips")))))
    assert clips and {row["body"] for row in clips if row["modality"] == "gait"} == {"female-heavy"}
    data = load_study(*(io.StringIO("".join(stream_csv(study, kind)))
                        for kind in ("responses", "clips", "participants")))
    assert set(data.clips["body"].dropna()) >= {"female-heavy"}
