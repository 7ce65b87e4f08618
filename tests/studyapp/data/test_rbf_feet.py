"""Foot planting of the RBF-styled walks (the visual intensities, whose large foot edits slide unplanted) and of the
chained captured source walks (quality gate thresholds)."""
import numpy as np
import pytest

from generation.core.foot_contact import legs
from generation.quality.metrics import motion_metrics
from generation.rbf.neutral_base import neutral_cycle
from generation.rbf.stylise import neutral_walk, stylise
from generation.rbf.themes import BODY_PARTS, theme_features
from protocol.vocabulary import QA_THRESHOLDS

FPS = 25.0  # the paper plans' render rate


@pytest.fixture(scope="module")
def neutral():
    return neutral_cycle()


def _leg_joints(skeleton) -> set[int]:
    return {j for leg in legs(skeleton) for j in (leg.hip, leg.knee, leg.ankle, leg.toe)}


def test_tired_seven_features_is_planted_and_above_the_floor(neutral):
    raw = stylise(neutral, "tired", 1.0, 7, fps=FPS, intensities="visual", plant=False)
    planted = stylise(neutral, "tired", 1.0, 7, fps=FPS, intensities="visual")
    before, after = motion_metrics(raw), motion_metrics(planted)
    assert before["foot_skate_cm_s"] > QA_THRESHOLDS["foot_skate_cm_s"]      # the styliser alone slides (~26)
    assert after["foot_skate_cm_s"] < 0.2 * QA_THRESHOLDS["foot_skate_cm_s"]
    assert after["penetration_cm"] == pytest.approx(0.0, abs=0.05)
    assert after["bone_error_mm"] < QA_THRESHOLDS["bone_error_mm"]
    assert after["jerk"] < QA_THRESHOLDS["jerk"]
    assert planted.metadata["foot_planting"] is True and planted.metadata["theme"] == "tired"
    assert planted.num_frames == raw.num_frames


def test_planting_keeps_the_upper_body_features(neutral):
    """Only hips, knees and ankles (and the root height, by < 1 cm) change: every feature of the upper body
    keeps its displacement from the neutral walk."""
    base = neutral_walk(neutral, fps=FPS, plant=False).positions()
    raw = stylise(neutral, "tired", 1.0, 7, fps=FPS, intensities="visual", plant=False)
    planted = stylise(neutral, "tired", 1.0, 7, fps=FPS, intensities="visual")
    sk = raw.skeleton
    legs_ = _leg_joints(sk)
    p_raw, p_planted = raw.positions(), planted.positions()
    checked = 0
    for feature in theme_features("tired", 7, "visual"):
        joints = [sk.index(n) for n in BODY_PARTS[feature.part]]
        if set(joints) & legs_:
            continue
        d_raw, d_planted = p_raw[:, joints] - base[:, joints], p_planted[:, joints] - base[:, joints]
        assert np.abs(d_planted - d_raw).max() < 0.01, feature
        checked += 1
    assert checked >= 5


def test_masculine_inverted_no_longer_sinks_into_the_floor(neutral):
    raw = motion_metrics(stylise(neutral, "masculine", -0.7, 10, fps=FPS, intensities="visual", plant=False))
    out = motion_metrics(stylise(neutral, "masculine", -0.7, 10, fps=FPS, intensities="visual"))
    assert raw["penetration_cm"] > QA_THRESHOLDS["penetration_cm"]           # 2.5 cm before
    assert out["penetration_cm"] <= QA_THRESHOLDS["penetration_cm"]
    assert out["foot_skate_cm_s"] < QA_THRESHOLDS["foot_skate_cm_s"]


@pytest.mark.parametrize("theme, weight, n", [("tired", -0.7, 10), ("energetic", 1.3, 10), ("tired", 0.4, 4)])
def test_flagged_paper_settings_pass(neutral, theme, weight, n):
    m = motion_metrics(stylise(neutral, theme, weight, n, fps=FPS))
    assert m["foot_skate_cm_s"] < QA_THRESHOLDS["foot_skate_cm_s"]
    assert m["penetration_cm"] <= QA_THRESHOLDS["penetration_cm"]


def test_neutral_walk_is_planted_like_the_styled_ones(neutral):
    walk = neutral_walk(neutral, fps=FPS)
    assert walk.metadata["foot_planting"] is True
    assert motion_metrics(walk)["foot_skate_cm_s"] < 1.0


def test_chained_captured_source_walk_is_planted_and_labelled():
    from generation.plans.clipgen import make_motion
    from generation.plans.schema import load_plan

    plan = load_plan("seed000")
    entry = next(e for e in plan.entries if e.id == "source_0walk_forward")
    motion = make_motion(entry)
    meta = motion.metadata
    assert meta["foot_planting"] is True and "seams" in meta["foot_planting_reason"]
    assert meta["synthetic"] is False and "motion capture" in meta["credit"]        # real mocap, said so
    assert motion_metrics(motion)["foot_skate_cm_s"] < QA_THRESHOLDS["foot_skate_cm_s"]
    # locking the feet must not lock the knees straight (the pelvis is lowered instead, by a few cm at most)
    from generation.core.features import GAIT_FEATURE_NAMES, np_gait_affective_features

    knees = [i for i, n in enumerate(GAIT_FEATURE_NAMES) if n.endswith("hip-left_knee-left_heel")
             or n.endswith("hip-right_knee-right_heel")]
    assert len(knees) == 2
    angles = np.degrees(np_gait_affective_features(motion.positions())[:, knees])
    assert (angles > 179.0).mean() < 0.02
    assert meta["foot_cleanup"]["pelvis_drop_max_m"] < 0.04


@pytest.mark.django_db
def test_sub_pools_keep_the_flagged_clips_their_section_pool_includes():
    """A naturalness section whose pool includes flagged clips (e.g. a sliding source walk) keeps them in its
    source/generated sub-pools: a sub-pool only narrows the section's pool (studyapp.data.pool_cache)."""
    from protocol.pools import INCLUDE_FLAGGED, SUB_POOLS
    from studyapp.admin.pool_editor import SUB_POOL_SECTION_TYPE
    from studyapp.data.catalogue import upsert_clips
    from studyapp.data.pool_cache import load_section_pool
    from studyapp.models import Section

    generated, source = SUB_POOLS

    def rec(clip_id, origin, flag=""):
        return {"clip_id": clip_id, "modality": "gait", "origin": origin, "happy": 0, "sad": 0, "angry": 0,
                "neutral": 1.0, "duration_s": 2, "video": f"clips/{clip_id}.mp4", "poster": f"clips/{clip_id}.png",
                "plan": "feet", "metadata": {}, "qa": {"foot_skate_cm_s": 11.0 if flag else 1.0, "flag": flag}}

    upsert_clips([rec("gen", generated), rec("src_ok", source), rec("src_sliding", source, "foot_skate")])
    pool = {"modality": "gait", INCLUDE_FLAGGED: True, source: {"modality": "gait"}, generated: {"modality": "gait"}}
    loaded = load_section_pool(Section(section_type=SUB_POOL_SECTION_TYPE, pool=pool, options={}))
    by_pk = {c.pk: c.clip_id for c in loaded.clips}
    assert set(by_pk.values()) == {"gen", "src_ok", "src_sliding"}
    assert {by_pk[pk] for pk in loaded.sub_pools[source]} == {"gen", "src_ok", "src_sliding"}  # modality filter
    pool[INCLUDE_FLAGGED] = False
    loaded = load_section_pool(Section(section_type=SUB_POOL_SECTION_TYPE, pool=pool, options={}))
    assert {c.clip_id for c in loaded.clips} == {"gen", "src_ok"}
