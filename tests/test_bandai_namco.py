"""The Bandai Namco dataset importer: layout, held-out split by take, shipped subset, bad files, the command."""
from __future__ import annotations

import csv
import shutil
from collections import defaultdict

import pytest

from generation.mocap import bandai_namco as bn
from generation.mocap.cli import main
from generation.mocap.real_corpus import load_real_corpus, read_meta

D1_STYLES = ("normal", "happy", "sad", "angry", "proud", "not-confident", "masculinity", "feminine", "childish",
             "old", "tired", "active", "musical", "giant", "chimpira")
D2_STYLES = ("active", "elderly", "exhausted", "feminine", "masculine", "normal", "youthful")
SHIPPED_DATA = bn.SHIPPED_DIR / "Bandai-Namco-Research-Motiondataset-1"


def real_layout_names() -> list[str]:
    """File stems as the two datasets name them (take counts as in the real data, per content and style)."""
    names = [f"dataset-1_walk_{s}_{t:03d}" for s in D1_STYLES for t in (1, 2)]
    names += [f"dataset-1_{c}_{s}_001" for s in D1_STYLES
              for c in ("walk-left", "walk-right", "walk-back", "run", "dash", "bow", "bye", "byebye", "guide")]
    names += ["dataset-1_respond_normal_001", "dataset-1_punch_normal_001", "dataset-1_punch_normal_002"]
    d2_takes = {"walk": 17, "walk-turn-left": 30, "walk-turn-right": 30, "wave-left-hand": 27,
                "raise-up-both-hands": 39}
    names += [f"dataset-2_{c}_{s}_{t:03d}" for c, n in d2_takes.items() for s in D2_STYLES for t in range(1, n + 1)]
    return names


def test_parse_name_and_bad_names():
    t = bn.parse_name("dataset-2_walk-turn-left_not-confident_017.bvh")
    assert (t.dataset, t.content, t.style, t.take, t.name) == (
        "bandai-namco-2", "walk-turn-left", "not-confident", 17, "dataset-2_walk-turn-left_not-confident_017")
    for bad in ("walk_happy_001", "dataset-1_walk_happy", "dataset-1_walk_happy_x01", "dataset-1_Walk_happy_001"):
        with pytest.raises(bn.LayoutError, match="file name"):
            bn.parse_name(bad)


def test_split_is_a_stable_pure_function_of_the_name():
    names = real_layout_names()
    first = {n: bn.split_for(n) for n in names}
    assert {n: bn.split_for(n) for n in reversed(names)} == first
    assert {n: bn.split_for(n + ".bvh") for n in names} == first
    # the documented anchors
    assert first["dataset-1_walk_happy_002"] == "test" and first["dataset-1_walk_happy_001"] == "train"
    assert first["dataset-2_walk_normal_005"] == "test" and first["dataset-2_walk_normal_013"] == "val"
    assert first["dataset-2_walk_normal_001"] == "train" and first["dataset-1_respond_normal_001"] == "train"


def test_every_style_has_held_out_takes():
    by = defaultdict(lambda: defaultdict(set))
    for n in real_layout_names():
        t = bn.parse_name(n)
        by[(t.number, t.content, t.style)][bn.split_for(n)].add(t.take)
    for (number, content, style), splits in by.items():
        if number == "2":   # every content and style: test and val takes, most for training
            assert splits["test"] and splits["val"] and len(splits["train"]) > len(splits["test"]), (content, style)
    for style in D1_STYLES:
        assert by[("1", "walk", style)]["test"] == {2}
        for group in bn.SINGLE_TAKE_GROUPS:  # exactly one content of each group held out per style
            held = [c for c in group if by[("1", c, style)]["test"]]
            assert len(held) == 1, (style, group, held)
    for group in bn.SINGLE_TAKE_GROUPS:      # and the held-out contents are spread over the group
        tests = [c for s in D1_STYLES for c in group if by[("1", c, s)]["test"]]
        assert max(tests.count(c) for c in group) - min(tests.count(c) for c in group) <= 1


def test_shipped_takes_follow_the_layout_and_carry_the_licence():
    takes = bn.shipped_takes()
    walks = {t.style: t for t in takes if t.content == "walk"}
    assert set(walks) == {"normal", "happy", "sad", "angry", "active", "tired", "feminine", "masculinity"}
    assert {t.label for t in walks.values()} == {"neutral", "happy", "sad", "angry", "energetic", "tired",
                                                "feminine", "masculine"}
    assert all(t.skeleton == "gait" and t.dataset == "bandai-namco-1" for t in walks.values())
    gestures = sorted((t.content, t.style, t.skeleton) for t in takes if t.content != "walk")
    assert gestures == [("bow", "sad", "gesture"), ("bye", "angry", "gesture"), ("bye", "happy", "gesture"),
                        ("bye", "normal", "gesture"), ("bye", "proud", "gesture"), ("bye", "sad", "gesture")]
    assert all(t.split == bn.split_for(t.name) for t in takes)
    assert "Attribution-NonCommercial 4.0" in (bn.SHIPPED_DIR / "LICENSE").read_text(encoding="utf-8")
    notice = (bn.SHIPPED_DIR / "NOTICE.md").read_text(encoding="utf-8")
    assert "CC BY-NC 4.0" in notice and "Non-commercial use only" in notice
    assert "2306.08861" in (bn.SHIPPED_DIR / "CITATION").read_text(encoding="utf-8")
    assert sum(p.stat().st_size for p in bn.SHIPPED_DIR.rglob("*") if p.is_file()) < 4_000_000


def _copy_layout(tmp_path, stems):
    """A dataset-1 folder in the upstream layout with the shipped takes ``stems``."""
    root = tmp_path / "ds" / "Bandai-Namco-Research-Motiondataset-1"
    shutil.copytree(SHIPPED_DATA / "cfg", root / "cfg")
    (root / "data").mkdir()
    for stem in stems:
        for ext in (".bvh", ".json"):
            shutil.copy(SHIPPED_DATA / "data" / (stem + ext), root / "data")
    return root


def test_bad_files_are_reported_not_taken(tmp_path):
    root = _copy_layout(tmp_path, ["dataset-1_walk_sad_001", "dataset-1_bow_sad_001", "dataset-1_walk_happy_001"])
    data = root / "data"
    (data / "dataset-1_walk_happy_001.json").write_text('{"content": 0, "style": 2}')  # style 2 is sad
    (data / "dataset-1_bow_sad_001.json").unlink()
    shutil.copy(data / "dataset-1_walk_sad_001.bvh", data / "walk-copy.bvh")
    takes, bad = bn.find_takes(root.parent)
    assert [t.name for t in takes] == ["dataset-1_walk_sad_001"]
    messages = {p.name: m for p, m in bad}
    assert "'sad' in cfg but the file name says 'happy'" in messages["dataset-1_walk_happy_001.bvh"]
    assert "no readable label file dataset-1_bow_sad_001.json" in messages["dataset-1_bow_sad_001.bvh"]
    assert "not a dataset-N_" in messages["walk-copy.bvh"]
    shutil.rmtree(root / "cfg")
    takes, bad = bn.find_takes(root.parent)
    assert not takes and all("no cfg/content_label.txt" in m for p, m in bad if p.name.startswith("dataset"))
    with pytest.raises(bn.LayoutError, match="not a folder"):
        bn.find_takes(tmp_path / "missing")


def _report(path):
    with open(path, newline="", encoding="utf-8") as fh:
        return {r["source"].rsplit("/", 1)[-1]: r for r in csv.DictReader(fh)}


def test_command_builds_the_corpus_and_reports_every_file(tmp_path):
    root = _copy_layout(tmp_path, ["dataset-1_walk_sad_001", "dataset-1_bye_happy_001", "dataset-1_walk_angry_001"])
    (root / "data" / "dataset-1_walk_angry_001.bvh").write_text("HIERARCHY\nROOT Hips\n{\n  OFFSET 0 0\n")
    out = tmp_path / "corpus" / "real.npz"
    assert main(["dataset", "bandai-namco", str(root.parent), "--out", str(out), "--quiet", "--workers", "2"]) == 1
    rows = _report(out.parent / "import_report.csv")
    assert rows["dataset-1_walk_angry_001.bvh"]["status"] == "error" and rows["dataset-1_walk_angry_001.bvh"]["message"]
    ok = rows["dataset-1_walk_sad_001.bvh"]
    assert ok["status"] == "ok" and (ok["dataset"], ok["content"], ok["style"], ok["take"], ok["split"]) == (
        "bandai-namco-1", "walk", "sad", "1", "train")
    assert rows["dataset-1_bye_happy_001.bvh"]["skeleton"] == "gesture"
    clips = load_real_corpus(out)
    assert [(c.name, c.skeleton, c.label, c.split) for c in clips] == [
        ("dataset-1_bye_happy_001", "gesture", "happy", "test"), ("dataset-1_walk_sad_001", "gait", "sad", "train")]
    walk = clips[1]
    assert walk.motion.fps == 30 and walk.motion.num_frames > 100 and 1.2 < walk.height_m < 2.3
    assert walk.import_error_cm < 3.0
    md = walk.motion.metadata
    assert md["captured"] is True and md["licence"] == "CC BY-NC 4.0" and md["take"] == 1
    assert md["emotion"]["sad"] == 1.0
    assert "take % 5 == 0" in read_meta(out)["split_rule"]
    # the good files alone: exit 0, --contents and --limit select
    (root / "data" / "dataset-1_walk_angry_001.bvh").unlink()
    (root / "data" / "dataset-1_walk_angry_001.json").unlink()
    assert main(["dataset", "bandai-namco", str(root.parent), "--out", str(out), "--quiet",
                 "--contents", "walk", "bow", "--limit", "1"]) == 0
    assert [c.name for c in load_real_corpus(out)] == ["dataset-1_walk_sad_001"]


def test_command_exit_codes_for_bad_arguments(tmp_path, capsys):
    assert main(["dataset", "bandai-namco", str(tmp_path / "none"), "--out", str(tmp_path / "c.npz")]) == 2
    assert "not a folder" in capsys.readouterr().err
    assert main(["dataset", "bandai-namco", str(tmp_path), "--out", str(tmp_path / "c.npz"), "--quiet"]) == 1
    assert "no takes" in capsys.readouterr().err and not (tmp_path / "c.npz").exists()
    assert main(["dataset", "bandai-namco", str(tmp_path), "--out", str(tmp_path / "c.npz"), "--workers", "0"]) == 2
    with pytest.raises(SystemExit) as exc:
        main(["dataset", "bandai-namco", str(tmp_path), "--contents", "punch"])
    assert exc.value.code == 2
