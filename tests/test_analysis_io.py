"""Readers/validators of responses.csv, clips.csv and participants.csv: every problem named by file, line, column."""

import io

import pandas as pd
import pytest

from analysis.io import ValidationError, load_study, read_clips, read_participants
from analysis.simulate import simulate_study
from protocol.vocabulary import SECTION_QUESTIONS


@pytest.fixture(scope="module")
def study():
    return simulate_study(6, seed=2, completion_rate=1.0)


def _csv(df: pd.DataFrame) -> io.StringIO:
    buf = io.StringIO(df.to_csv(index=False))
    buf.name = "x.csv"
    return buf


def _named(df, name):
    buf = io.StringIO(df.to_csv(index=False))
    buf.name = name
    return buf


def test_valid_study_loads_from_file_objects(study):
    r, c, p = study
    data = load_study(_named(r, "responses.csv"), _named(c, "clips.csv"), _named(p, "participants.csv"))
    assert len(data.responses) == len(r)  # nothing dropped
    assert set(data.responses["section_type"].unique()) == set(SECTION_QUESTIONS)
    likert = data.responses[data.responses["section_type"] == "affect_likert"]
    assert likert["value"].between(0, 4).all()
    mixed = data.clips.loc["sim-seed000-single_happy_neutral", ["happy", "neutral"]]   # seed000.yaml's (.6, .4)
    assert mixed.tolist() == pytest.approx([0.6, 0.4])


def test_valid_study_loads_from_paths(study, tmp_path):
    r, c, p = study
    for name, df in (("responses", r), ("clips", c), ("participants", p)):
        df.to_csv(tmp_path / f"{name}.csv", index=False)
    data = load_study(tmp_path / "responses.csv", str(tmp_path / "clips.csv"), tmp_path / "participants.csv")
    assert data.participants["completed"].all()


def test_missing_column_is_named(study):
    r, c, p = study
    with pytest.raises(ValidationError) as e:
        load_study(_named(r.rename(columns={"answer": "answr"}), "responses.csv"), _named(c, "clips.csv"),
                   _named(p, "participants.csv"))
    assert "responses.csv header, column 'answer': required column is missing" in str(e.value)


def test_out_of_range_unknown_clip_and_bad_label_all_listed(study):
    r, c, p = study
    r = r.copy()
    i_lik = r.index[r["section_type"] == "affect_likert"][0]
    i_choice = r.index[r["section_type"] == "emotion_choice"][0]
    i_theme = r.index[r["section_type"] == "theme_rating"][3]
    r.loc[i_lik, "answer"] = "5"
    r.loc[i_choice, "answer"] = "happy;joyful"
    r.loc[i_theme, "clip_id"] = "no-such-clip"
    r.loc[i_theme + 1, "question"] = "torso"
    with pytest.raises(ValidationError) as e:
        load_study(_named(r, "responses.csv"), _named(c, "clips.csv"), _named(p, "participants.csv"))
    err = e.value
    assert err.total == 4
    text = str(err)
    assert f"responses.csv line {i_lik + 2}, column 'answer': '5' is not an integer in 0..4" in text
    assert f"line {i_choice + 2}, column 'answer': 'happy;joyful' is not gait emotions" in text
    assert f"line {i_theme + 2}, column 'clip_id': unknown clip 'no-such-clip'" in text
    assert f"line {i_theme + 3}, column 'question': 'torso' is not a question" in text


def test_only_first_twenty_listed_but_all_counted(study):
    r, c, p = study
    r = r.copy()
    r.loc[r["section_type"] == "naturalness", "answer"] = "9"
    n_bad = int((r["section_type"] == "naturalness").sum())
    with pytest.raises(ValidationError) as e:
        load_study(_named(r, "responses.csv"), _named(c, "clips.csv"), _named(p, "participants.csv"))
    assert e.value.total == n_bad > 20
    assert len(e.value.problems) == 20
    assert f"and {n_bad - 20} more" in str(e.value)


def test_unknown_participant_and_bad_response_ms(study):
    r, c, p = study
    r = r.copy()
    r.loc[0, "participant_id"] = "ghost"
    r["response_ms"] = r["response_ms"].astype(object)
    r.loc[1, "response_ms"] = "-3"
    with pytest.raises(ValidationError) as e:
        load_study(_named(r, "responses.csv"), _named(c, "clips.csv"), _named(p, "participants.csv"))
    text = str(e.value)
    assert "line 2, column 'participant_id': unknown participant 'ghost'" in text
    assert "line 3, column 'response_ms': '-3' is not a number of milliseconds" in text


def test_clip_problems():
    header = ("clip_id,modality,origin,happy,sad,angry,neutral,final_happy,final_sad,final_angry,final_neutral,"
              "emotion_label,valence,arousal,dominance,theme,weight,n_features,duration_s\n")
    rows = ("a,gait,generated,1,0,0,,,,,,,,,,,,,10\n"  # partial vector
            "b,walk,generated,,,,,,,,,,,,,,,,10\n"  # bad modality
            "c,gesture,source,,,,,,,,,grumpy,0.5,0.5,1.5,,,,8\n"  # label, dominance out of range
            "d,gait,generated,,,,,,,,,,,,,sleepy,,3,10\n"  # unknown theme, no weight
            "d,gait,generated,-1,1,0,0,,,,,,,,,,,,10\n")  # duplicate id, negative value
    with pytest.raises(ValidationError) as e:
        read_clips(io.StringIO(header + rows))
    text = str(e.value)
    for needle in ("line 2, column 'neutral': blank", "line 3, column 'modality': 'walk'",
                   "line 4, column 'emotion_label': 'grumpy'", "line 4, column 'dominance': '1.5' is not in 0..1",
                   "line 5, column 'theme': 'sleepy'", "line 5, column 'weight': a theme clip needs a weight",
                   "line 6, column 'clip_id': duplicate clip_id 'd'", "line 6, column 'happy': '-1'"):
        assert needle in text, needle


def test_participant_problems():
    text = ("participant_id,gender,age_group,started_at,completed_at,status,external_id\n"
            "p1,male,18-24,2026-11-01T10:00:00Z,yesterday,completed,\n"
            "p1,female,25-34,2026-11-01T10:00:00Z,2026-11-01T09:00:00Z,completed,\n")
    with pytest.raises(ValidationError) as e:
        read_participants(io.StringIO(text))
    msg = str(e.value)
    assert "line 2, column 'completed_at': 'yesterday' is not an ISO-8601 date-time" in msg
    assert "line 3, column 'participant_id': duplicate participant_id 'p1'" in msg
    assert "line 3, column 'completed_at': completed_at is before started_at" in msg


def test_empty_file():
    with pytest.raises(ValidationError, match="empty"):
        read_clips(io.StringIO(""))


def test_neutral_input_walk_is_a_valid_clip():
    """The plan writes the unstyled seed 004 walk with theme 'neutral', weight 0 and no features."""
    header = ("clip_id,modality,origin,happy,sad,angry,neutral,final_happy,final_sad,final_angry,final_neutral,"
              "emotion_label,valence,arousal,dominance,theme,weight,n_features,duration_s\n")
    clips = read_clips(io.StringIO(header + "n0,gait,generated,,,,,,,,,,,,,neutral,0,0,10\n"))
    assert clips.loc["n0", "theme"] == "neutral" and clips.loc["n0", "weight"] == 0
