"""Languages: every participant-facing string is marked and has a German translation; a German study's
pages are German from consent to the last page, while the stored and exported answers stay the protocol's labels;
the study's language never leaks into the next request."""
from __future__ import annotations

import ast
import csv
import gettext as gnu_gettext
import io
import re
from pathlib import Path

import pytest
from django.template import engines
from django.urls import reverse
from django.utils import translation
from django.utils.translation.template import templatize

from protocol.vocabulary import LABEL_CHOICES, SECTION_QUESTIONS, answer_values
from studyapp.data.export import stream_csv
from studyapp.i18n import activate_study_language, answer_label, label_msgids, likert_texts
from studyapp.models import Participant, Response, Study
from studyapp.questions import AnswerError, questions_for
from studyapp.staff.presets import create_study_from_preset
from studyapp.testing import make_catalogue

ROOT = Path(__file__).resolve().parents[2]
PO = ROOT / "locale" / "de" / "LC_MESSAGES" / "django.po"
MO = PO.with_suffix(".mo")
PARTICIPANT_TEMPLATES = sorted((ROOT / "templates" / "studyapp").glob("*.html"))
# call name -> index of the msgid argument (a plural's msgid is its singular, as in the .po)
MARKING_CALLS = {"gettext": 0, "gettext_lazy": 0, "gettext_noop": 0, "_": 0, "ngettext": 0, "ngettext_lazy": 0,
                 "pgettext": 1, "pgettext_lazy": 1, "npgettext": 1, "npgettext_lazy": 1}
CONTEXT_CALLS = {"pgettext", "pgettext_lazy", "npgettext", "npgettext_lazy"}


# -- a small .po reader (no polib dependency) ----------------------------------------------------------------
def read_po(path: Path) -> dict[tuple[str | None, str], list[str]]:
    """(msgctxt or None, msgid) -> msgstr list (one entry, or one per plural form) of a .po file."""
    entries: dict[tuple[str | None, str], list[str]] = {}
    for block in path.read_text(encoding="utf-8").strip().split("\n\n"):
        fields: dict[str, str] = {}
        current = None
        for line in block.splitlines():
            if line.startswith("#") or not line.strip():
                continue
            m = re.match(r'^(msgctxt|msgid_plural|msgid|msgstr(?:\[\d+\])?) (".*")$', line)
            if m:
                current = m.group(1)
                fields[current] = ast.literal_eval(m.group(2))
            else:
                fields[current] += ast.literal_eval(line)
        if fields.get("msgid"):
            strs = [v for k, v in sorted(fields.items()) if k.startswith("msgstr")]
            entries[(fields.get("msgctxt"), fields["msgid"])] = strs
    return entries


# -- what the sources mark ----------------------------------------------------------------------------------
def _literal(node) -> str | None:
    return node.value if isinstance(node, ast.Constant) and isinstance(node.value, str) else None


def python_msgids(path: Path) -> set[tuple[str | None, str]]:
    """(context, msgid) of every gettext-style call with literal arguments in a Python file."""
    found = set()
    for node in ast.walk(ast.parse(path.read_text(encoding="utf-8"))):
        if not isinstance(node, ast.Call):
            continue
        name = node.func.id if isinstance(node.func, ast.Name) else getattr(node.func, "attr", "")
        if name not in MARKING_CALLS:
            continue
        args = [_literal(a) for a in node.args]
        context = args[0] if name in CONTEXT_CALLS and args else None
        i = MARKING_CALLS[name]
        if i < len(args) and args[i]:
            found.add((context, args[i]))
    return found


def template_msgids(path: Path) -> set[tuple[str | None, str]]:
    """Msgids of a template as makemessages sees them: Django's templatize turns the template into gettext calls,
    which are read back with the Python reader above."""
    code = templatize(path.read_text(encoding="utf-8"), origin=str(path))
    calls = re.findall(r"\b(?:n?p?gettext)\((?:[^()]|\([^()]*\))*\)", code)
    found = set()
    for call in calls:
        found |= python_msgids_from_source(call)
    return found


def python_msgids_from_source(source: str) -> set[tuple[str | None, str]]:
    tmp = ast.parse(source)
    found = set()
    for node in ast.walk(tmp):
        if isinstance(node, ast.Call):
            name = node.func.id
            args = [_literal(a) for a in node.args]
            context = args[0] if name.startswith("p") or name.startswith("np") else None
            texts = args[1:] if context is not None else args
            if texts and texts[0]:
                found.add((context, texts[0]))
    return found


def all_marked() -> set[tuple[str | None, str]]:
    marked = set()
    for path in sorted((ROOT / "studyapp").rglob("*.py")):
        marked |= python_msgids(path)
    for path in PARTICIPANT_TEMPLATES:
        marked |= template_msgids(path)
    return marked


def test_reader_finds_the_strings_of_a_template_and_a_module():
    assert (None, "Save and continue") in template_msgids(ROOT / "templates/studyapp/item.html")
    assert (None, "Clip %(index)s of %(total)s") in template_msgids(ROOT / "templates/studyapp/item.html")
    assert ("emotion", "Afraid") in python_msgids(ROOT / "studyapp/i18n.py")
    assert (None, "How {theme} does this walk look?") in python_msgids(ROOT / "studyapp/questions.py")


def test_every_marked_string_has_a_german_translation():
    po = read_po(PO)
    marked = all_marked()
    assert len(marked) > 100
    missing = sorted(f"{c + ': ' if c else ''}{m}" for c, m in marked if not all(po.get((c, m)) or [""]))
    assert not missing, "no German msgstr (run makemessages -l de, translate, compilemessages):\n" + "\n".join(missing)


def test_every_protocol_label_and_likert_wording_is_translated():
    po = read_po(PO)
    for context, msgid in label_msgids():
        assert all(po.get((context, msgid), [""])), (context, msgid)
    for text in likert_texts():
        assert all(po.get((None, text), [""])), text


def test_compiled_catalogue_matches_the_po():
    """The committed .mo is compiled from the committed .po (nobody needs msgfmt at run time)."""
    po = read_po(PO)
    with MO.open("rb") as fh:
        mo = gnu_gettext.GNUTranslations(fh)
    for (context, msgid), strs in po.items():
        if len(strs) > 1:
            continue
        got = mo.pgettext(context, msgid) if context else mo.gettext(msgid)
        assert got == strs[0], f"{msgid!r}: .mo has {got!r}, .po {strs[0]!r} (run compilemessages)"


def test_messages_other_modules_show_are_in_the_catalogue():
    """The sentences of assignment.py and views.py that reach a participant (StudyUnavailable, error=...,
    module constants) are translated where they are shown, so they need msgids."""
    po = read_po(PO)
    texts = set()
    for name in ("participant/assignment.py", "participant/views.py"):
        tree = ast.parse((ROOT / "studyapp" / name).read_text(encoding="utf-8"))
        constants = {t.id: _literal(node.value) for node in tree.body if isinstance(node, ast.Assign)
                     for t in node.targets if isinstance(t, ast.Name)}
        for node in ast.walk(tree):
            if not isinstance(node, ast.Call):
                continue
            callee = getattr(node.func, "id", "")
            shown = [node.args[0]] if callee == "StudyUnavailable" and node.args else []
            shown += node.args[2:3] if callee == "_unavailable" else []
            shown += [k.value for k in node.keywords if k.arg in ("error", "message")]
            for arg in shown:
                text = _literal(arg) or (constants.get(arg.id) if isinstance(arg, ast.Name) else None)
                if text:
                    texts.add(text)
    assert len(texts) >= 3, texts
    missing = [t for t in texts if not all(po.get((None, t), [""]))]
    assert not missing, missing


# -- questions in German ------------------------------------------------------------------------------------
def test_german_questions_show_german_labels_and_keep_protocol_values():
    with translation.override("de"):
        q = questions_for("emotion_choice")[0]
        assert q.text == "Welche Emotion(en) nehmen Sie in diesem Gang wahr?"
        assert dict(q.choices)["happy"] == "Glücklich"
        assert [v for v, _ in q.choices] == list(answer_values(SECTION_QUESTIONS["emotion_choice"]["perceived"]))
        rating = questions_for("theme_rating", clip_theme="happy")[0]
        assert rating.text == "Wie fröhlich wirkt dieser Gang?"
        assert dict(rating.choices)["7"] == "sehr fröhlich"
        inversion = questions_for("theme_inversion", clip_theme="tired")[0]
        assert inversion.text == "Wirkt dieser Gang eher energiegeladen oder eher müde?"
        neutral = dict(questions_for("neutral_validation")[0].choices)
        assert neutral["happy"] == "Fröhlich" and neutral["energetic"] == "Energiegeladen"
        likert = questions_for("affect_likert")
        # a soft hyphen (U+00AD) lets the long compound break inside a narrow scale column
        assert likert[0].text == "Oberkörper"
        assert dict(likert[0].choices)["0"].replace("\xad", "") == "zusammengezogen, gebeugt"
        with pytest.raises(AnswerError, match="^Bitte beantworten Sie: Welche Emotion"):
            q.clean([])
        # a researcher-written question stays as entered
        custom = questions_for("naturalness", {"question": "Wie echt wirkt die Bewegung?"})[0]
        assert custom.text == "Wie echt wirkt die Bewegung?"
    assert questions_for("emotion_choice")[0].text == "Which emotion(s) do you perceive from this walk?"


def test_answer_label_covers_every_label_kind_and_rejects_others():
    with translation.override("de"):
        for kind, values in LABEL_CHOICES.items():
            labels = [answer_label(kind, v) for v in values]
            assert all(labels) and len(set(labels)) == len(labels), kind
    with pytest.raises(ValueError, match="not a label answer kind"):
        answer_label("likert", "1")


@pytest.mark.django_db
def test_activate_study_language_falls_back_to_the_default():
    with translation.override("en"):
        assert activate_study_language(Study(language="de")) == "de"
        assert activate_study_language(Study(language="xx")) == "en"
        assert activate_study_language(None) == "en"


# -- a German study through the participant pages -----------------------------------------------------------
@pytest.fixture
def german_study(settings, tmp_path):
    settings.MEDIA_ROOT = tmp_path / "media"
    make_catalogue(settings.MEDIA_ROOT)
    study = create_study_from_preset("demo", "demo-de", plan="test", status=Study.Status.OPEN)
    study.language = "de"
    study.consent_text = "Die Teilnahme ist freiwillig."
    study.save()
    study.sections.update(require_full_play=False)
    return study


def _choices_of(html: str) -> dict[str, str]:
    """name -> first value of every radio/checkbox of a page."""
    found: dict[str, str] = {}
    for tag in re.findall(r"<input[^>]+>", html):
        kind = re.search(r'type="(\w+)"', tag)
        if kind and kind.group(1) in ("radio", "checkbox"):
            name, value = re.search(r'name="([^"]+)"', tag).group(1), re.search(r'value="([^"]*)"', tag).group(1)
            found.setdefault(name, value)
    return found


def _take_study(client, study) -> tuple[Participant, dict[str, str]]:
    """Consent and answer every page with its first choices; returns the participant and one page's HTML per
    kind of page (consent, demographics, item, feedback, done)."""
    pages = {}
    r = client.get(reverse("studyapp:study_entry", args=[study.slug]))
    pages["consent"] = r.content.decode()
    r = client.post(reverse("studyapp:study_entry", args=[study.slug]), {"consent": "on"})
    token = r["Location"].rstrip("/").split("/")[-1]
    url = r["Location"]
    for _ in range(200):
        r = client.get(url)
        if r.status_code == 302:
            url = r["Location"]
            continue
        html = r.content.decode()
        kind = next(k for k in ("about-you", "clip", "feedback", "done") if f"/{k}/" in url)
        pages.setdefault(kind, html)
        if kind == "done":
            break
        data = _choices_of(html)
        if kind == "feedback":
            data.update({"comments": "Alles klar."})
        r = client.post(url, data)
        assert r.status_code == 302, (url, r.status_code, html[:300])
        url = r["Location"]
    return Participant.objects.get(token=token), pages


@pytest.mark.django_db
def test_a_german_study_is_german_and_its_answers_stay_protocol_labels(client, german_study):
    participant, pages = _take_study(client, german_study)
    assert set(pages) == {"consent", "about-you", "clip", "feedback", "done"}
    expect = {"consent": ["Information und Einwilligung", "Studie starten", "Die Teilnahme ist freiwillig."],
              "about-you": ["Zu Ihrer Person", "Weiblich", "Altersgruppe"],
              "clip": ["Speichern und weiter", "Welche Emotion(en) nehmen Sie in diesem Gang wahr?", "Glücklich",
                       "data-wait=\"Die Antworten werden freigeschaltet"],
              "feedback": ["Letzte Fragen", "Hat die Kamera Sie während der Studie abgelenkt?", "Ja"],
              "done": ["Vielen Dank!", "Ihr Abschlusscode:"]}
    for kind, texts in expect.items():
        assert '<html lang="de">' in pages[kind], kind
        for text in texts:
            assert text in pages[kind], (kind, text)
    assert 'value="happy"' in pages["clip"]          # the posted value is the protocol's label
    assert "Save and continue" not in pages["clip"] and "Thank you" not in pages["done"]
    answers = Response.objects.filter(participant=participant)
    assert answers.exists()
    rows = list(csv.DictReader(io.StringIO("".join(stream_csv(german_study, "responses")))))
    assert len(rows) == answers.count()
    for row in rows:
        kind = SECTION_QUESTIONS[row["section_type"]].get(row["question"])
        if kind is None:
            continue        # a question this protocol version does not know (not exported by this study)
        assert set(row["answer"].split(";")) <= set(answer_values(kind)), row
    participant.refresh_from_db()
    assert participant.gender == "female"


@pytest.mark.django_db
def test_german_errors_and_no_leak_into_the_next_request(client, german_study):
    r = client.post(reverse("studyapp:study_entry", args=[german_study.slug]), {})
    html = r.content.decode()
    assert "Bitte setzen Sie vor dem Start das Häkchen" in html
    assert r["Content-Language"] == "de"
    german_study.listed_publicly = True
    german_study.save(update_fields=["listed_publicly"])
    home = client.get("/")                    # same thread: the default language again
    assert home["Content-Language"] == "en" and "Open studies" in home.content.decode()
    assert translation.get_language() in (None, "en", "en-us")
    german_study.status = Study.Status.CLOSED
    german_study.save()
    closed = client.get(reverse("studyapp:study_entry", args=[german_study.slug])).content.decode()
    assert "Diese Studie ist geschlossen" in closed


@pytest.mark.django_db
def test_english_study_stays_english(client, german_study):
    german_study.language = "en"
    german_study.save()
    html = client.get(reverse("studyapp:study_entry", args=[german_study.slug])).content.decode()
    assert '<html lang="en">' in html and "Information and consent" in html


def test_templates_load_i18n_wherever_they_translate():
    for path in PARTICIPANT_TEMPLATES:
        source = path.read_text(encoding="utf-8")
        if "translate" in source:
            assert re.search(r"{% load [^%]*\bi18n\b", source), path.name
        engines["django"].from_string(source)        # parses
