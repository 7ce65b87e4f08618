"""Participants read plain words, researchers keep their own names: every section has a participant title and
text (the section type's defaults when blank) and a name for the researchers; scale ends say what to look for
("very feminine"), never "theme" or "inversion"; preset introductions count their sections."""
from __future__ import annotations

import re

import pytest
from django.test import Client
from django.urls import reverse
from django.utils import translation

from protocol.presets import PRESETS
from protocol.vocabulary import OPPOSITE_THEME, SECTION_TYPES, THEMES
from studyapp.models import Participant, Study
from studyapp.participant.section_wording import DEFAULT_WORDING, RESEARCHER_TERMS
from studyapp.questions import questions_for
from studyapp.staff.presets import create_study_from_preset
from studyapp.testing import make_catalogue

NUMBERS = {"one": 1, "two": 2, "three": 3, "four": 4, "five": 5, "six": 6, "seven": 7, "eight": 8, "nine": 9}


def researcher_terms(text: str) -> list[str]:
    return [t for t in RESEARCHER_TERMS if t in text.lower()]


@pytest.mark.parametrize("preset", sorted(PRESETS))
def test_preset_sections_have_a_name_and_plain_participant_wording(preset):
    spec = PRESETS[preset]
    assert not researcher_terms(spec["introduction"]), spec["introduction"]
    for sec in spec["sections"]:
        assert sec["name"] and sec["title"] and sec["name"] != sec["title"], sec
        for text in (sec["title"], sec.get("instructions", "")):
            assert not researcher_terms(text), (preset, text)
            assert not re.match(r"section \d", text, re.I), (preset, text)


@pytest.mark.parametrize("preset", sorted(PRESETS))
def test_introductions_count_their_sections(preset):
    intro = PRESETS[preset]["introduction"]
    said = re.findall(r"\b(\w+) sections?\b", intro)
    for word in said:
        assert NUMBERS.get(word.lower()) == len(PRESETS[preset]["sections"]), (preset, intro)
    if preset == "gait_ismar2020":
        assert said == ["four"]


def test_every_section_type_has_default_plain_wording():
    assert set(DEFAULT_WORDING) == set(SECTION_TYPES)
    for title, text in DEFAULT_WORDING.values():
        assert title and text and not researcher_terms(title + " " + text)


@pytest.mark.parametrize("language", ["en", "de"])
@pytest.mark.parametrize("theme", THEMES)
def test_style_scales_name_what_to_look_for(theme, language):
    very = {"en": "very", "de": "sehr"}[language]
    with translation.override(language):
        rating = questions_for("theme_rating", {}, theme)[0]
        inversion = questions_for("theme_inversion", {}, theme)[0]
        for q in (rating, inversion):
            shown = " ".join([q.text, q.help, *(label for _, label in q.choices)])
            assert not researcher_terms(shown) and "Thema" not in shown and "Umkehr" not in shown, shown
        adjective = translation.pgettext("theme adjective", theme)
        opposite = translation.pgettext("theme adjective", OPPOSITE_THEME[theme])
        assert dict(rating.choices)["7"] == f"{very} {adjective}"
        ends = dict(inversion.choices)
        assert (ends["-7"], ends["7"]) == (f"{very} {opposite}", f"{very} {adjective}")     # seed 004: +7 original
        assert f"-7 ({very} {opposite})" in inversion.help and f"+7 ({very} {adjective})" in inversion.help


@pytest.mark.django_db
def test_page_shows_participant_wording_never_the_researchers_name(settings, tmp_path):
    settings.MEDIA_ROOT = tmp_path / "media"
    make_catalogue(settings.MEDIA_ROOT)
    study = create_study_from_preset("rbf_thms2016", "styles", plan="test", status=Study.Status.OPEN)
    study.sections.update(require_full_play=False)
    first = study.sections.get(order=1)
    assert first.name.startswith("Neutral validation") and first.title == "Describe the walk"
    client = Client()
    r = client.post(reverse("studyapp:study_entry", args=[study.slug]), {"consent": "on"})
    p = Participant.objects.get(token=r["Location"].rstrip("/").split("/")[-1])
    client.post(reverse("studyapp:demographics", args=[p.token]), {"gender": "female", "age_group": "25-34"})
    client.get(reverse("studyapp:resume", args=[p.token]))
    page = client.get(reverse("studyapp:item", args=[p.token, 1])).content.decode()
    assert "<h1 class=\"section-title\">Describe the walk</h1>" in page and first.name not in page
    # blank title and text: the section type's plain words
    study.sections.update(title="", instructions="")
    page = client.get(reverse("studyapp:item", args=[p.token, 1])).content.decode()
    assert "<h1 class=\"section-title\">Describe the walk</h1>" in page
    assert "Choose the word that best describes each walk." in page
    for section in study.sections.all():
        assert not researcher_terms(section.title + section.instructions)
