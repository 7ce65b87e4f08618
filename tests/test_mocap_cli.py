"""``python -m generation.mocap import``: folders, report CSV, labels, joint maps, exit codes."""
from __future__ import annotations

import csv
import json
import subprocess
import sys
from pathlib import Path

import pytest

from generation.core.motion import Motion
from generation.formats.bvh import write_bvh
from generation.mocap.cli import main
from generation.mocap.importer import REPORT_COLUMNS
from generation.procedural.walk import WalkParams, walk
from tests.mocap_conventions import convention_motion, export_as

ROOT = Path(__file__).resolve().parents[1]


@pytest.fixture(scope="module")
def walk_motion():
    return walk(WalkParams(), n_frames=20)


def _report(out: Path) -> list[dict]:
    with open(out / "import_report.csv", newline="") as fh:
        reader = csv.DictReader(fh)
        assert tuple(reader.fieldnames) == REPORT_COLUMNS
        return list(reader)


def test_folder_with_a_bad_file_exits_1_and_writes_the_others(tmp_path, walk_motion):
    src = tmp_path / "takes"
    (src / "actor1").mkdir(parents=True)
    export_as(walk_motion, "mixamo", src / "actor1" / "walk_happy_01.bvh")
    export_as(walk_motion, "biped", src / "walk_sad_02.bvh")
    (src / "broken_angry_03.bvh").write_text("HIERARCHY\nROOT Hips\n{\n\tOFFSET 0 0\n}\n")
    (src / "notes.txt").write_text("ignored")
    out = tmp_path / "out"
    code = main(["import", str(src), "--skeleton", "gait", "--out", str(out), "--quiet",
                 "--label-pattern", r"_(?P<emotion>[a-z]+)_\d+"])
    assert code == 1
    rows = _report(out)
    assert [Path(r["source"]).name for r in rows] == ["walk_happy_01.bvh", "broken_angry_03.bvh", "walk_sad_02.bvh"]
    assert [r["status"] for r in rows] == ["ok", "error", "ok"]
    assert "broken_angry_03.bvh: line 5" in rows[1]["message"]
    ok = rows[0]
    assert ok["frames"] == "20" and float(ok["fps"]) == 30
    assert float(ok["duration_s"]) == pytest.approx(20 / 30, abs=1e-3)
    assert ok["mapped_joints"] == "21" and float(ok["retarget_max_error_m"]) < 0.02 and float(ok["height_m"]) > 1
    happy = Motion.load_npz(out / "walk_happy_01.npz")
    assert happy.metadata["emotion"]["happy"] == 1.0 and happy.metadata["synthetic"] is False
    assert happy.metadata["origin"] == "captured" and happy.metadata["source"] == "walk_happy_01.bvh"
    assert sorted(p.name for p in out.glob("*.npz")) == ["walk_happy_01.npz", "walk_sad_02.npz"]


def test_all_good_exit_0_with_labels_csv_and_joint_map(tmp_path, walk_motion):
    # a rig with names of our own invention: only a --joint-map makes it importable
    m = convention_motion(walk_motion, "cmu")
    odd = {n: f"jnt{k:02d}" for k, n in enumerate(m.skeleton.joints)}
    renamed = Motion(m.skeleton.__class__(m.skeleton.name, tuple(odd[n] for n in m.skeleton.joints),
                                          m.skeleton.parents, m.skeleton.offsets), m.rotations, m.root_positions,
                     m.fps, {})
    write_bvh(renamed, tmp_path / "odd.bvh", scale=100.0)
    out = tmp_path / "out"
    assert main(["import", str(tmp_path / "odd.bvh"), "--skeleton", "gesture", "--out", str(out), "--quiet"]) == 1
    assert "Joints found in the file: jnt00, jnt01" in _report(out)[0]["message"]
    cmu_names = {"root": "Hips", "left_hip": "LeftUpLeg", "left_knee": "LeftLeg", "left_ankle": "LeftFoot",
                 "right_hip": "RightUpLeg", "right_knee": "RightLeg", "right_ankle": "RightFoot", "chest4": "Spine1",
                 "left_shoulder": "LeftArm", "left_elbow": "LeftForeArm", "left_wrist": "LeftHand",
                 "right_shoulder": "RightArm", "right_elbow": "RightForeArm", "right_wrist": "RightHand"}
    (tmp_path / "map.json").write_text(json.dumps({ours: odd[theirs] for ours, theirs in cmu_names.items()}))
    (tmp_path / "labels.csv").write_text("source,emotion\nodd.bvh,proud\n")
    code = main(["import", str(tmp_path / "odd.bvh"), "--skeleton", "gesture", "--out", str(out), "--quiet",
                 "--joint-map", str(tmp_path / "map.json"), "--labels", str(tmp_path / "labels.csv"),
                 "--fps", "60"])
    assert code == 0
    row = _report(out)[0]
    assert row["status"] == "ok" and row["mapped_joints"] == "14" and float(row["fps"]) == 60
    motion = Motion.load_npz(out / "odd.npz")
    assert motion.skeleton.name == "gesture" and motion.metadata["emotion_label"] == "proud"
    assert len(motion.metadata["vad"]) == 3


def test_bad_arguments(tmp_path):
    (tmp_path / "map.json").write_text("[1, 2]")
    assert main(["import", str(tmp_path), "--skeleton", "gait", "--out", str(tmp_path / "o"), "--quiet",
                 "--joint-map", str(tmp_path / "map.json")]) == 2
    assert main(["import", str(tmp_path / "empty"), "--skeleton", "gait", "--out", str(tmp_path / "o"),
                 "--quiet"]) == 1


def test_module_entry_point(tmp_path, walk_motion):
    export_as(walk_motion, "kinect", tmp_path / "k.bvh")
    proc = subprocess.run([sys.executable, "-m", "generation.mocap", "import", str(tmp_path / "k.bvh"),
                           "--skeleton", "gait", "--out", str(tmp_path / "out")],
                          cwd=ROOT, capture_output=True, text=True, timeout=120)
    assert proc.returncode == 0, proc.stderr
    assert "imported 1 of 1 files" in proc.stderr
    assert (tmp_path / "out" / "k.npz").exists()
