"""Recognition and naturalness by the human body a clip shows (clips.csv ``body``)."""
from __future__ import annotations

import numpy as np
import pandas as pd

from analysis.by_body import by_body
from analysis.io import load_study
from analysis.recognition import gait_recognition
from analysis.report import write_report
from analysis.simulate import write_study


def _study(tmp_path, with_body: bool):
    paths = write_study(str(tmp_path), 24, seed=9)
    if with_body:
        clips = pd.read_csv(paths["clips"])
        clips["body"] = np.where(np.arange(len(clips)) % 2, "female", "male")
        clips.to_csv(paths["clips"], index=False)
    return paths


def test_rows_per_body_and_measure_match_the_subsets(tmp_path):
    paths = _study(tmp_path, True)
    data = load_study(paths["responses"], paths["clips"], paths["participants"])
    table = by_body(data.responses, data.clips)
    assert set(table["body"]) == {"female", "male"}
    assert {"gait_emotion", "naturalness"} <= set(table["measure"])
    row = table[(table["body"] == "female") & (table["measure"] == "gait_emotion")].iloc[0]
    ids = data.clips.index[data.clips["body"] == "female"]
    res = gait_recognition(data.responses[data.responses["clip_id"].isin(ids)], data.clips.loc[ids])
    conf = res["confusion"].to_numpy()
    assert row["n"] == res["n_answers"] and row["value"] == np.trace(conf) / conf.sum()
    nat = table[table["measure"] == "naturalness"]
    assert ((nat["value"] >= 0) & (nat["value"] <= 1)).all() and (nat["mean"].between(1, 5)).all()


def test_no_body_column_gives_an_empty_table_in_the_report(tmp_path):
    paths = _study(tmp_path / "in", False)
    report = write_report(paths["responses"], paths["clips"], paths["participants"], tmp_path / "out")
    assert report["by_body"] == []
    paths = _study(tmp_path / "in2", True)
    report = write_report(paths["responses"], paths["clips"], paths["participants"], tmp_path / "out2")
    assert {r["body"] for r in report["by_body"]} == {"female", "male"}
