"""Positions-only import of the Emotion-Gait BML walks: root travel from the stance foot, the fit and its checks,
the performer split, the CLI. Small synthetic data: procedural walks seen on a treadmill, written in the BML
file's layout (the real file stays in ../shared)."""
from __future__ import annotations

import csv
import json

import numpy as np
import pytest

from generation.mocap import emotion_gait_bml as eg
from generation.mocap.cli import main
from generation.mocap.real_corpus import load_real_corpus, read_meta
from generation.mocap.root_travel import compare_travel, loop_period, reconstruct_root_travel, strip_root_travel
from generation.procedural.emotion import gait_params_for_emotion
from generation.procedural.walk import walk

OURS_FOR_SOURCE = {"root": "root", "spine": "spine", "neck": "neck", "head": "head",
                   "l_shoulder": "left_shoulder", "l_elbow": "left_elbow", "l_hand": "left_hand",
                   "r_shoulder": "right_shoulder", "r_elbow": "right_elbow", "r_hand": "right_hand",
                   "l_hip": "left_hip", "l_knee": "left_knee", "l_foot": "left_heel",
                   "r_hip": "right_hip", "r_knee": "right_knee", "r_foot": "right_heel"}
EMOS = ("Happy", "Sad", "Angry", "Neutral")


@pytest.fixture(scope="module")
def walks():
    """Four procedural walks (one per emotion), 75 frames at 30 fps, as world positions on our gait skeleton."""
    out = {}
    for k, e in enumerate(EMOS):
        m = walk(gait_params_for_emotion(np.eye(4)[k]), n_frames=75, fps=30.0)
        out[e] = m
    return out


def _bml_positions(motion) -> np.ndarray:
    """(T, 16, 3) in the BML layout: root fixed, height normalised to about 1.03, walking towards -z."""
    P = strip_root_travel(motion.positions())
    sk = motion.skeleton
    Q = np.stack([P[:, sk.index(OURS_FOR_SOURCE[j])] for j in eg.SOURCE_JOINTS], axis=1)
    Q = Q - Q[:1, :1]
    Q = Q * np.array([-1.0, 1.0, -1.0])          # turned 180 degrees about y, as the BML figures face
    return Q / 1.70


def _write_npz(path, walks, performers=("BML_aaa", "BML_bbb"), tweak=None):
    P, keys, perf, acted, perceived = [], [], [], [], []
    for p in performers:
        for e in EMOS:
            q = _bml_positions(walks[e])
            if tweak is not None:
                q = tweak(p, e, q)
            P.append(q)
            keys.append(f"{p[4:]}_walk_{e[:2].lower()}_1_fin_positions.csv")
            perf.append(p)
            acted.append(e)
            perceived.append("Neutral" if e == "Angry" else e)
    np.savez(path, positions=np.asarray(P, np.float32), key=np.array(keys), performer=np.array(perf),
             acted_label=np.array(acted), perceived_label=np.array(perceived), joint_names=np.array(eg.SOURCE_JOINTS),
             fps_guess=np.float32(30.0))
    return path


def test_root_travel_recovers_a_known_walk(walks):
    m = walks["Neutral"]
    P = m.positions()
    sk = m.skeleton
    flat = strip_root_travel(P)
    assert np.allclose(flat[:, 0], flat[:1, 0])
    feet = ([sk.index("left_heel"), sk.index("left_toe")], [sk.index("right_heel"), sk.index("right_toe")])
    travel, w = reconstruct_root_travel(flat, m.fps, feet, blend=eg.BLEND_M, hips=(1, 5),
                                        speed_blend=eg.SPEED_BLEND_M_S)
    assert np.allclose(w.sum(1), 1.0)
    r = compare_travel(P[:, 0], flat[:, 0] + travel, m.fps)
    assert abs(r["speed_error_pct"]) < 10, r
    assert r["heading_error_deg"] < 5, r


def test_loop_period_finds_a_repeated_cycle():
    rng = np.random.default_rng(0)
    cycle = rng.normal(size=(30, 4, 3))
    assert loop_period(np.concatenate([cycle, cycle, cycle[:15]])) == 30
    assert loop_period(rng.normal(size=(75, 4, 3))) is None


def test_split_is_by_performer_and_stable():
    names = [f"BML_{i:03d}" for i in range(30)]
    splits = {p: eg.split_for(p, names) for p in names}
    assert sorted(splits.values()).count("test") == eg.TEST_PERFORMERS
    assert sorted(splits.values()).count("val") == eg.VAL_PERFORMERS
    assert all(eg.split_for(p, names + ["BML_zzz"]) in ("train", "val", "test") for p in names)
    assert eg.split_for(names[0], names) == eg.split_for(names[0], list(reversed(names)))


def test_dataset_command_writes_corpus_and_report(tmp_path, walks):
    src = tmp_path / "bml"
    src.mkdir()
    _write_npz(src / eg.FILE_NAME, walks)
    out = tmp_path / "corpus" / "bml.npz"
    assert main(["dataset", "emotion-gait-bml", str(src), "--out", str(out), "--quiet"]) == 0
    clips = load_real_corpus(out, skeleton="gait")
    assert len(clips) == 8
    c = clips[0]
    assert c.dataset == "emotion-gait-bml" and c.content == "walk" and c.style in ("happy", "sad", "angry", "neutral")
    assert c.motion.metadata["performer"] in ("BML_aaa", "BML_bbb")
    assert c.motion.metadata["perceived_label"] in ("happy", "sad", "angry", "neutral")
    assert "Pollick" in c.motion.metadata["citation"] and "STEP" in c.motion.metadata["citation"]
    # travel reconstructed: the root moves forward at a walking speed, the feet stay near the floor
    root = c.motion.root_positions
    speed = np.linalg.norm(np.diff(root[:, [0, 2]], axis=0), axis=-1).mean() * 30
    assert 0.3 < speed < 2.5
    meta = read_meta(out)
    assert meta["split_rule"] == eg.SPLIT_RULE and "Pollick" in meta["citation"]
    assert sorted(sum(meta["performer_split"].values(), [])) == ["BML_aaa", "BML_bbb"]
    by_perf = {}
    for cl in clips:
        by_perf.setdefault(cl.motion.metadata["performer"], set()).add(cl.split)
    assert all(len(s) == 1 for s in by_perf.values())          # never split within a performer
    with open(eg.report_path(out), newline="") as fh:
        rows = list(csv.DictReader(fh))
    assert [r["status"] for r in rows] == ["ok"] * 8
    assert set(eg.report_columns()) == set(rows[0])
    assert json.loads(json.dumps(rows[0]))["performer"] == "BML_aaa"


def test_bad_clips_are_error_rows_with_their_cause(tmp_path, walks):
    swap = [eg.SOURCE_JOINTS.index(j) for j in ("root", "spine", "neck", "head", "r_shoulder", "r_elbow", "r_hand",
                                                "l_shoulder", "l_elbow", "l_hand", "r_hip", "r_knee", "r_foot",
                                                "l_hip", "l_knee", "l_foot")]
    knee_foot = list(range(16))
    knee_foot[11], knee_foot[12] = 12, 11

    def tweak(p, e, q):
        if p == "BML_bbb" and e == "Happy":
            return q[:, swap]                       # left and right swapped
        if p == "BML_bbb" and e == "Sad":
            return q * 100.0                        # centimetres, not normalised
        if p == "BML_bbb" and e == "Angry":
            return q[:, knee_foot]                  # columns in the wrong order
        return q

    src = _write_npz(tmp_path / eg.FILE_NAME, walks, tweak=tweak)
    out = tmp_path / "bml.npz"
    assert eg.build_emotion_gait_bml(src, out, quiet=True) == 1
    with open(eg.report_path(out), newline="") as fh:
        rows = {(r["performer"], r["style"]): r for r in csv.DictReader(fh)}
    assert rows[("BML_bbb", "happy")]["status"] == "error" and "mirrored" in rows[("BML_bbb", "happy")]["message"]
    assert "wrong units" in rows[("BML_bbb", "sad")]["message"]
    bad = rows[("BML_bbb", "angry")]
    assert bad["status"] == "error" and "out of order" in bad["message"]
    assert len(load_real_corpus(out)) == 5


def test_unreadable_data_file_exits_2(tmp_path):
    assert eg.build_emotion_gait_bml(tmp_path, tmp_path / "x.npz", quiet=True) == 2
    np.savez(tmp_path / eg.FILE_NAME, positions=np.zeros((1, 75, 16, 3)))
    assert main(["dataset", "emotion-gait-bml", str(tmp_path), "--out", str(tmp_path / "x.npz"), "--quiet"]) == 2




def _shared_bml():
    from pathlib import Path
    here = Path(__file__).resolve().parents[1]
    for root in (here.parent / "shared", here.parents[1] / "shared", Path("/work/shared")):
        f = root / "mocap" / "emotion-gait-bml" / eg.FILE_NAME
        if f.is_file():
            return f
    return None


@pytest.mark.skipif(_shared_bml() is None, reason="the BML walks are not in ../shared/mocap/emotion-gait-bml")
def test_the_real_bml_walks_all_fit_within_the_bound():
    clips = eg.load_clips(_shared_bml())
    assert len(clips) == 120 and len({c.performer for c in clips}) == 30
    sample = [c for c in clips if c.performer in ("BML_ale", "BML_alx")]
    fitted, rows = eg.import_clips(sample)
    assert [r["status"] for r in rows] == ["ok"] * 8
    assert all(float(r["ik_error_p95_cm"]) < 100 * eg.MAX_IK_ERROR_M for r in rows)
    assert all(c.motion.metadata["loop_period_frames"] for c in fitted)
    assert {r["split"] for r in rows if r["performer"] == "BML_alx"} == {"test"}


def test_dataset_command_writes_where_the_variables_say(tmp_path, monkeypatch):
    """Without --out, `dataset` writes each corpus where its readers look: $REAL_CORPUS / $BML_CORPUS (read by the
    command line, passed down), else var/mocap/."""
    from generation.mocap import cli
    from generation.mocap.real_corpus import DEFAULT_BML_PATH, DEFAULT_PATH

    written = []
    monkeypatch.setattr(cli, "build_emotion_gait_bml", lambda root, out, *a: written.append(out) or 0)
    monkeypatch.setattr(cli, "build_bandai_namco", lambda root, out, *a: written.append(out) or 0)
    monkeypatch.delenv("REAL_CORPUS", raising=False)
    monkeypatch.delenv("BML_CORPUS", raising=False)
    assert main(["dataset", "emotion-gait-bml", str(tmp_path)]) == 0
    assert main(["dataset", "bandai-namco", str(tmp_path)]) == 0
    monkeypatch.setenv("REAL_CORPUS", str(tmp_path / "bandai.npz"))
    monkeypatch.setenv("BML_CORPUS", str(tmp_path / "bml.npz"))
    assert main(["dataset", "emotion-gait-bml", str(tmp_path)]) == 0
    assert main(["dataset", "bandai-namco", str(tmp_path)]) == 0
    assert main(["dataset", "bandai-namco", str(tmp_path), "--out", str(tmp_path / "given.npz")]) == 0
    assert written == [DEFAULT_BML_PATH, DEFAULT_PATH, tmp_path / "bml.npz", tmp_path / "bandai.npz",
                       tmp_path / "given.npz"]
