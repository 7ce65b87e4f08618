"""write_report, the report folder, and the two CLIs."""

import io
import json
import subprocess
import sys

import pytest

from analysis.report import TABLE_KEYS, write_report
from analysis.simulate import simulate_study, write_study

DESIGN_FIELDS = {  # DESIGN.md "report.json ... top-level keys"
    "gait_emotion_ad": {"clip_id", "statistic", "p_value", "p_capped", "reject", "n"},
    "transition_ad": {"clip_id", "phase", "statistic", "p_value", "p_capped", "reject", "n"},
    "likert_consistency_ad": {"emotion", "feature", "statistic", "p_value", "k"},
    "likert_distribution": {"emotion", "feature", "value", "share"},
    "naturalness": {"origin", "modality", "counts", "share_at_least_3", "n"},
    "vad_pearson": {"dimension", "r", "p_value", "ci_low", "ci_high", "n"},
    "theme_anova": {"theme", "effect", "F", "df1", "df2", "p_value", "p_gg", "eta2_partial"},
    "theme_inversion": {"theme", "mean", "se", "n", "t", "p_value"},
    "neutral_validation": {"choice", "share", "n"},
}


@pytest.fixture(scope="module")
def report_dir(tmp_path_factory):
    src = tmp_path_factory.mktemp("in")
    paths = write_study(str(src), 24, seed=9)
    out = tmp_path_factory.mktemp("out")
    report = write_report(paths["responses"], paths["clips"], paths["participants"], out)
    return report, out


def test_report_keys_and_fields(report_dir):
    report, out = report_dir
    on_disk = json.loads((out / "report.json").read_text())
    assert on_disk.keys() == report.keys()
    for key, fields in DESIGN_FIELDS.items():
        assert report[key], key
        for rec in report[key]:
            assert fields <= rec.keys(), (key, fields - rec.keys())
    assert set(report["naturalness"][0]["counts"]) == {"1", "2", "3", "4", "5"}
    assert report["participants"]["n_participants"] == 24
    assert report["participants"]["synthetic"] is True and report["meta"]["synthetic"] is True
    assert report["meta"]["summary"][0].startswith("SYNTHETIC")
    assert {r["phase"] for r in report["transition_ad"]} == {"initial", "final"}
    assert len(report["theme_anova"]) == 18


def test_report_files(report_dir):
    _, out = report_dir
    for key in TABLE_KEYS:
        assert (out / f"{key}.csv").exists(), key
    for fig in ("fig_emotion_vectors", "fig_transitions", "fig_likert", "fig_vad", "fig_naturalness",
                "fig_theme_ratings", "fig_inversion"):
        assert (out / f"{fig}.png").read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
        assert "<svg" in (out / f"{fig}.svg").read_text()
    html = (out / "report.html").read_text()
    assert html.count("<svg") >= 7 and "SYNTHETIC DATA" in html
    assert "src=\"http" not in html and "href=\"http" not in html  # self-contained


def test_the_naturalness_figure_draws_imported_clips():
    """A report whose naturalness clips include imported ones draws them beside generated and source: one labelled
    set of bars per origin and modality, with the table's shares."""
    from analysis.figures import fig_naturalness
    from analysis.io import load_study
    from analysis.report import build_report

    responses, clips, participants = simulate_study(8, seed=1)
    rated = responses.loc[responses["section_type"] == "naturalness", "clip_id"].unique()
    gesture_sources = clips["clip_id"].isin(rated) & (clips["origin"] == "source") & (clips["modality"] == "gesture")
    clips.loc[gesture_sources, "origin"] = "imported"
    data = load_study(*(io.StringIO(df.to_csv(index=False)) for df in (responses, clips, participants)))
    nat = build_report(data)[1]["naturalness"]
    assert "imported" in set(nat["origin"])
    fig = fig_naturalness(nat)
    drawn = {}
    for ax in fig.axes:
        for bars in ax.containers:
            origin = bars.get_label().split(" (")[0]
            drawn[(origin, ax.get_title())] = [bar.get_height() for bar in bars]
    expected = {(r.origin, r.modality): [getattr(r, f"share_{k}") for k in range(1, 6)] for r in nat.itertuples()}
    assert drawn.keys() == expected.keys() and ("imported", "gesture") in drawn
    assert all(drawn[key] == pytest.approx(expected[key]) for key in expected)
    assert "imported" in fig._suptitle.get_text()


def test_write_report_accepts_file_objects(tmp_path):
    r, c, p = simulate_study(8, seed=1)
    bufs = [io.StringIO(df.to_csv(index=False)) for df in (r, c, p)]
    rep = write_report(*bufs, tmp_path, alpha=0.01, permutations=50, figures=False)
    assert rep["meta"]["alpha"] == 0.01
    assert all(rec["p_perm"] is not None for rec in rep["gait_emotion_ad"])


def test_bad_alpha(tmp_path):
    r, c, p = simulate_study(3, seed=1)
    bufs = [io.StringIO(df.to_csv(index=False)) for df in (r, c, p)]
    with pytest.raises(ValueError, match="alpha"):
        write_report(*bufs, tmp_path, alpha=1.5)


def test_clis(tmp_path):
    src = tmp_path / "in"
    res = subprocess.run([sys.executable, "-m", "analysis.simulate", "--participants", "5", "--out", str(src)],
                         capture_output=True, text=True, timeout=120)
    assert res.returncode == 0, res.stderr
    args = [str(src / "responses.csv"), str(src / "clips.csv"), str(src / "participants.csv")]
    res = subprocess.run([sys.executable, "-m", "analysis", *args, "--out", str(tmp_path / "rep"), "--no-figures"],
                         capture_output=True, text=True, timeout=300)
    assert res.returncode == 0, res.stderr
    assert "SYNTHETIC" in res.stdout
    assert (tmp_path / "rep" / "report.html").exists() and not (tmp_path / "rep" / "fig_vad.png").exists()
    # invalid input: exit status 2 and a message naming file, line and column
    text = (src / "responses.csv").read_text().splitlines()
    text[1] = text[1].replace("emotion_choice", "emotion_choise")
    (src / "responses.csv").write_text("\n".join(text) + "\n")
    res = subprocess.run([sys.executable, "-m", "analysis", *args, "--out", str(tmp_path / "rep2")],
                         capture_output=True, text=True, timeout=300)
    assert res.returncode == 2
    assert "responses.csv line 2, column 'section_type': 'emotion_choise' is not one of" in res.stderr
    res = subprocess.run([sys.executable, "-m", "analysis", "nope.csv", *args[1:], "--out", str(tmp_path / "r3")],
                         capture_output=True, text=True, timeout=120)
    assert res.returncode == 2 and "no such file" in res.stderr


@pytest.mark.parametrize("sections", [["emotion_choice"], ["theme_rating", "theme_inversion"], []])
def test_partial_study(tmp_path, sections):
    """A study with only some sections: the other tables are empty lists and noted, nothing fails."""
    r, c, p = simulate_study(6, seed=3)
    r = r[r["section_type"].isin(sections)]
    rep = write_report(*[io.StringIO(df.to_csv(index=False)) for df in (r, c, p)], tmp_path, figures=False)
    assert rep["vad_pearson"] == [] and rep["naturalness"] == []
    assert any("vad_pearson: no data" in n for n in rep["meta"]["notes"])
    assert bool(rep["gait_emotion_ad"]) == ("emotion_choice" in sections)
    assert bool(rep["theme_anova"]) == ("theme_rating" in sections)


def test_report_zip_bytes():
    import zipfile

    from analysis.report import report_zip_bytes

    r, c, p = simulate_study(4, seed=2)
    rep, data = report_zip_bytes(*[io.StringIO(df.to_csv(index=False)) for df in (r, c, p)], figures=False)
    names = zipfile.ZipFile(io.BytesIO(data)).namelist()
    assert "report/report.json" in names and "report/report.html" in names and rep["participants"]


def test_report_recognition_agreement_mixed_models(report_dir):
    report, out = report_dir
    for key in ("gait_emotion", "gesture_emotion"):
        rec = report["recognition"][key]
        assert {"labels", "confusion", "hit_rate", "unbiased_hit_rate", "chance_unbiased_hit_rate", "kappa",
                "n_answers", "participant_tests"} <= rec.keys()
        assert len(rec["confusion"]) == len(rec["labels"]) == len(rec["hit_rate"])
        assert sum(map(sum, rec["confusion"])) == pytest.approx(rec["n_answers"])
        assert (out / f"recognition_{key}.csv").exists()
    assert report["recognition"]["gait_emotion"]["labels"] == ["happy", "sad", "angry", "neutral"]
    assert report["meta"]["summary"][1].startswith("Gait emotion recognition")
    fields = {"section_type", "question", "statistic", "value", "ci_low", "ci_high", "n_raters", "n_items"}
    assert report["agreement"] and all(fields <= r.keys() for r in report["agreement"])
    assert {r["statistic"] for r in report["agreement"]} >= {"ICC2", "fleiss_kappa"}
    kinds = {(r["kind"], r["term"]) for r in report["mixed_models"]}
    assert {("variance", "participant"), ("variance", "clip"), ("variance", "residual"),
            ("fixed", "weight_c")} <= kinds
    html = (out / "report.html").read_text()
    assert html.index("id='recognition'") < html.index("id='gait_emotion_ad'")
    assert "label-blind" in html and "fig_confusion" not in html or (out / "fig_confusion.svg").exists()
