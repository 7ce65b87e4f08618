"""Plan entries of imported motion files (generator captured_file): a source clip with honest metadata, the
file's motion, labels from the file or the entry, and clear errors naming the entry."""
from __future__ import annotations

import json

import numpy as np
import pytest

from generation.core.motion import Motion
from generation.mocap import ImportOptions, import_file
from generation.mocap.labels import Label
from generation.plans import clipgen
from generation.plans.schema import PlanError, validate_plan
from protocol.vocabulary import GAIT_EMOTIONS
from tests.mocap_conventions import export_as

TINY = {"width": 160, "height": 120, "fps": 30, "duration_s": 1.0}


@pytest.fixture(scope="module")
def walk_files(tmp_path_factory):
    """A procedural walk re-exported as a Mixamo BVH (T-pose, centimetres) and imported back (labelled sad) as the
    importer's Motion .npz."""
    d = tmp_path_factory.mktemp("mocap")
    plan = validate_plan({"name": "w", "render": TINY, "clips": [
        {"id": "w", "generator": "procedural_walk", "emotion": "neutral", "duration_s": 3.0, "seed": 2}]})
    walk = clipgen.make_motion(plan.entries[0])
    export_as(walk, "mixamo", d / "walk.bvh")
    result = import_file(d / "walk.bvh", ImportOptions(skeleton="gait"), Label("sad"))
    assert result.motion is not None, result.row
    result.motion.save_npz(d / "walk.npz")
    return d


def _plan(*clips, render=TINY):
    return {"name": "cap", "render": render, "clips": list(clips)}


def _entry(path, **kw):
    return {"id": "walk_source", "generator": "captured_file", "file": str(path), **kw}


def test_captured_entry_makes_the_file_motion_with_honest_metadata(walk_files):
    plan = validate_plan(_plan(_entry(walk_files / "walk.npz")))
    e = plan.entries[0]
    assert (e.origin, e.modality) == ("source", "gait")
    assert e.inputs["emotion"] == [1.0 if g == "sad" else 0.0 for g in GAIT_EMOTIONS]   # the importer's label
    assert e.inputs["labels_from"] == "file" and len(e.inputs["sha256"]) == 16
    motion = clipgen.make_motion(e)
    original = Motion.load_npz(walk_files / "walk.npz")
    assert motion.num_frames == original.num_frames and motion.fps == original.fps
    np.testing.assert_allclose(motion.positions(), original.positions(), atol=1e-9)
    m = motion.metadata
    assert m["origin"] == "source" and m["generator"] == "captured_file" and m["captured"] is True
    assert m["synthetic"] is False and m["imported_file"] == str(walk_files / "walk.npz")
    assert m["rig"]["skeleton"] == "gait" and m["rig"]["source_format"] == "bvh" and m["rig"]["joint_map"]
    assert m["rig"]["source_file"] == "walk.bvh"
    json.dumps(m)
    # the entry's own label wins; start_s trims
    e2 = validate_plan(_plan(_entry(walk_files / "walk.npz", emotion="happy", start_s=1.0))).entries[0]
    assert e2.inputs["emotion"][GAIT_EMOTIONS.index("happy")] == 1.0 and e2.inputs["labels_from"] == "entry"
    assert clipgen.make_motion(e2).num_frames == original.num_frames - 30


def test_a_synthetic_file_is_not_called_captured(walk_files, tmp_path):
    m = Motion.load_npz(walk_files / "walk.npz")
    m.metadata = dict(m.metadata, synthetic=True)
    m.save_npz(tmp_path / "synthetic.npz")
    e = validate_plan(_plan(_entry(tmp_path / "synthetic.npz"))).entries[0]
    meta = clipgen.make_motion(e).metadata
    assert meta["captured"] is False and meta["synthetic"] is True


def test_plan_build_writes_a_source_clip_record(walk_files, tmp_path):
    """The captured entry and a generated walk paired with it, rendered: the record of the captured clip says
    source, carries the label and the import, and the generated clip names it as its source."""
    from generation.pipeline.runner import run_plan

    plan = validate_plan(_plan(
        _entry(walk_files / "walk.npz", sections=["naturalness"]),
        {"id": "generated_walk", "generator": "procedural_walk", "emotion": "sad", "duration_s": 1.0,
         "pair": "walk_source", "sections": ["naturalness"]}))
    result = run_plan(plan, tmp_path / "clips", tmp_path / "records")
    assert not result.failed, result.failed
    by_entry = {r["metadata"]["entry_id"]: r for r in result.records}
    src, gen = by_entry["walk_source"], by_entry["generated_walk"]
    assert src["origin"] == "source" and src["modality"] == "gait" and src["sad"] == 1.0
    assert src["metadata"]["generator"] == "captured_file" and src["metadata"]["inputs"]["file"].endswith("walk.npz")
    motion_meta = src["metadata"]["motion"]
    assert motion_meta["captured"] is True and motion_meta["rig"]["skeleton"] == "gait"
    assert src["metadata"]["synthetic"] is False
    assert gen["source_clip_id"] == src["clip_id"]
    assert (tmp_path / "motions" / f"{src['clip_id']}.bvh").is_file()
    assert (tmp_path / "clips" / f"{src['clip_id']}.mp4").stat().st_size > 0


def test_a_bvh_file_is_imported_on_the_fly(walk_files):
    e = validate_plan(_plan(_entry(walk_files / "walk.bvh", emotion="angry"))).entries[0]
    motion = clipgen.make_motion(e)
    assert motion.skeleton.name == "gait" and motion.num_frames > 60
    assert motion.metadata["imported_format"] == "bvh" and motion.metadata["captured"] is True


@pytest.mark.parametrize("change,field", [
    ({"file": "no/such/walk.npz"}, "file"),
    ({"file": "walk.txt"}, "file"),
    ({"modality": "gesture"}, "modality"),
    ({"start_s": 99.0}, "start_s"),
    ({"emotion": "proud"}, "emotion"),
    ({"emotion": "sad", "emotion_label": "sad"}, "emotion_label"),
    ({"origin": "generated"}, "origin"),
    ({"clip": "0walk_forward.txt"}, "clip"),
])
def test_bad_entries_name_the_entry_and_field(walk_files, change, field):
    entry = dict(_entry(walk_files / "walk.npz"), **change)
    with pytest.raises(PlanError) as err:
        validate_plan(_plan({"id": "other", "generator": "procedural_walk", "emotion": "sad"}, entry))
    assert f"entry 2 (id 'walk_source'): field {field!r}" in str(err.value)


def test_a_corrupt_file_is_a_clear_error(tmp_path):
    bad = tmp_path / "broken.npz"
    bad.write_bytes(b"not a zip")
    with pytest.raises(PlanError, match=r"entry 1 \(id 'walk_source'\): field 'file': .*broken.npz"):
        validate_plan(_plan(_entry(bad)))


def test_our_own_bvh_files_import_back(walk_files, tmp_path):
    """The BVH files the renderer keeps (motions/<clip_id>.bvh, generation.formats.bvh.write_bvh of our skeleton)
    import onto the same skeleton with every joint mapped and no retarget error."""
    from generation.formats.bvh import write_bvh

    walk = Motion.load_npz(walk_files / "walk.npz")
    write_bvh(walk, tmp_path / "ours.bvh")
    result = import_file(tmp_path / "ours.bvh", ImportOptions(skeleton="gait"))
    assert result.motion is not None, result.row
    assert result.row["unmapped_joints"] == "" and float(result.row["retarget_max_error_m"]) < 1e-3
    np.testing.assert_allclose(result.motion.positions(), walk.positions(), atol=2e-3)


def test_source_json_beside_the_file_gives_licence_citation_and_take(walk_files, tmp_path):
    folder = tmp_path / "takes"
    folder.mkdir()
    (folder / "dataset-1_walk_sad_002.npz").write_bytes((walk_files / "walk.npz").read_bytes())
    (folder / "SOURCE.json").write_text(json.dumps({
        "dataset": "Example dataset", "licence": "CC BY-NC 4.0", "citation": "A. Author. Title. 2023.",
        "name_pattern": r"dataset-(?P<dataset_part>\d)_(?P<content>[a-z-]+)_(?P<style>[a-z-]+)_(?P<take>\d{3})"}))
    plan = validate_plan(_plan(_entry(folder / "dataset-1_walk_sad_002.npz")))
    m = clipgen.make_motion(plan.entries[0]).metadata
    assert (m["licence"], m["citation"], m["dataset"]) == ("CC BY-NC 4.0", "A. Author. Title. 2023.",
                                                           "Example dataset")
    assert (m["content"], m["style"], m["take"]) == ("walk", "sad", "002") and m["captured"] is True
    (folder / "SOURCE.json").write_text("[1, 2]")
    with pytest.raises(PlanError, match="SOURCE.json"):
        validate_plan(_plan(_entry(folder / "dataset-1_walk_sad_002.npz")))


def test_relative_file_falls_back_to_the_repository_root(walk_files, monkeypatch, tmp_path):
    from generation.plans.generators import captured_file

    monkeypatch.chdir(tmp_path)
    monkeypatch.setattr(captured_file, "REPO_ROOT", walk_files)
    plan = validate_plan(_plan(_entry("walk.npz")))
    assert plan.entries[0].inputs["file"] == "walk.npz"
    assert clipgen.make_motion(plan.entries[0]).num_frames > 0
    with pytest.raises(PlanError, match="no such file"):
        validate_plan(_plan(_entry("missing.npz")))
