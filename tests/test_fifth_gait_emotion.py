"""A fifth gait emotion in a test-only vocabulary: every report table either handles it or refuses it by name, and
the simulator's paper defaults refuse it by name instead of dropping it. The vocabulary is swapped in a fresh
interpreter (protocol.vocabulary loaded from its own source with GAIT_EMOTIONS extended), so every module reads the
five-emotion vocabulary from its first import."""
from __future__ import annotations

import json
import subprocess
import sys
from pathlib import Path

import pytest

from analysis.simulate import write_study

ROOT = Path(__file__).resolve().parents[1]
FIFTH = "fearful"

SCRIPT = r'''
import importlib.abc, importlib.util, json, sys
from pathlib import Path

ROOT, DATA, FIFTH = Path(sys.argv[1]), Path(sys.argv[2]), sys.argv[3]
PAPER = 'GAIT_EMOTIONS = ("happy", "sad", "angry", "neutral")'


class FiveEmotions(importlib.abc.MetaPathFinder, importlib.abc.Loader):
    """Loads protocol.vocabulary from its source with a fifth gait emotion appended."""

    def find_spec(self, name, path, target=None):
        if name != "protocol.vocabulary":
            return None
        return importlib.util.spec_from_file_location(name, ROOT / "protocol" / "vocabulary.py", loader=self)

    def create_module(self, spec):
        return None

    def exec_module(self, module):
        source = (ROOT / "protocol" / "vocabulary.py").read_text()
        assert PAPER in source, "the vocabulary's GAIT_EMOTIONS line moved"
        source = source.replace(PAPER, PAPER[:-1] + f', "{FIFTH}")')
        exec(compile(source, module.__file__, "exec"), module.__dict__)


sys.meta_path.insert(0, FiveEmotions())
import pandas as pd  # noqa: E402

from protocol.vocabulary import GAIT_EMOTIONS, FINAL_EMOTION_COLUMNS  # noqa: E402
assert GAIT_EMOTIONS[-1] == FIFTH, GAIT_EMOTIONS
from analysis import report  # noqa: E402
from analysis.io import load_study  # noqa: E402
from analysis.report_tables import TableInputs, report_tables  # noqa: E402

outcome = {}

# the exports of a four-emotion study, re-labelled: three walks now intend the fifth emotion, their answers name it
clips = pd.read_csv(DATA / "clips.csv", dtype=str, keep_default_na=False)
responses = pd.read_csv(DATA / "responses.csv", dtype=str, keep_default_na=False)
has = clips["happy"] != ""
clips[FIFTH] = ["0" if h else "" for h in has]
clips["final_" + FIFTH] = ["0" if f != "" else "" for f in clips["final_happy"]]
single = responses.loc[responses["section_type"] == "emotion_choice", "clip_id"].unique()[:3]
for clip in single:
    row = clips["clip_id"] == clip
    for e in GAIT_EMOTIONS:
        clips.loc[row, e] = "1" if e == FIFTH else "0"
    responses.loc[(responses["clip_id"] == clip) & (responses["section_type"] == "emotion_choice"), "answer"] = FIFTH
clips.to_csv(DATA / "clips5.csv", index=False)
responses.to_csv(DATA / "responses5.csv", index=False)
data = load_study(DATA / "responses5.csv", DATA / "clips5.csv", DATA / "participants.csv")
outcome["answers_naming_it"] = int((data.responses["answer"].astype(str) == FIFTH).sum())

inputs = TableInputs(data.responses, data.clips, data.participants)
tables = {}
for table in report_tables():
    if table.compute is None:
        continue
    try:
        tables[table.key] = df = table.compute(inputs)
        outcome[table.key] = {"handled": True, "mentions": bool(df.astype(str).apply(
            lambda c: c.str.contains(FIFTH)).to_numpy().any() or any(FIFTH in c for c in df.columns))}
    except Exception as exc:  # noqa: BLE001 - the outcome is what the test judges
        outcome[table.key] = {"handled": False, "error": f"{type(exc).__name__}: {exc}"}

try:
    rep = report.build_report(data)[0]
    outcome["report"] = {"handled": True, "keys": sorted(rep),
                         "recognition_names_it": FIFTH in json.dumps(rep["recognition"]["gait_emotion"])}
except Exception as exc:  # noqa: BLE001
    outcome["report"] = {"handled": False, "error": f"{type(exc).__name__}: {exc}"}

try:
    from analysis.simulate import PerceptionModel
    PerceptionModel()
    outcome["simulator_defaults"] = {"handled": True}
except Exception as exc:  # noqa: BLE001
    outcome["simulator_defaults"] = {"handled": False, "error": f"{type(exc).__name__}: {exc}"}
print(json.dumps(outcome))
'''


@pytest.fixture(scope="module")
def outcome(tmp_path_factory):
    data = tmp_path_factory.mktemp("five")
    write_study(str(data), 40, seed=7)
    run = subprocess.run([sys.executable, "-c", SCRIPT, str(ROOT), str(data), FIFTH], cwd=ROOT, capture_output=True,
                         text=True, timeout=600)
    assert run.returncode == 0, run.stderr[-3000:]
    return json.loads(run.stdout.strip().splitlines()[-1])


def test_the_fifth_emotion_reaches_the_analysis(outcome):
    assert outcome["answers_naming_it"] > 0


def test_every_table_handles_the_fifth_emotion_or_refuses_it_by_name(outcome):
    from analysis.report_tables import report_tables

    findings = [t.key for t in report_tables() if t.compute is not None]
    assert set(findings) <= set(outcome)
    for key in findings:
        result = outcome[key]
        assert result["handled"] or FIFTH in result["error"], (key, result)
    for key in ("gait_emotion_ad", "likert_consistency_ad", "mixed_models", "clip_norms"):  # tables naming emotions
        assert outcome[key]["handled"] and outcome[key]["mentions"], (key, outcome[key])


def test_the_report_is_built_or_refused_by_name(outcome):
    result = outcome["report"]
    assert result["handled"] or FIFTH in result["error"], result
    assert not result["handled"] or result["recognition_names_it"]


def test_the_simulator_refuses_paper_defaults_for_an_emotion_they_lack(outcome):
    result = outcome["simulator_defaults"]
    assert not result["handled"] and FIFTH in result["error"] and "likert_means" in result["error"], result

