"""Neutral base cycle and applying seed 004 themes: Y = P + w S, bone lengths, timing, metadata."""
from __future__ import annotations

import numpy as np
import pytest

from generation.core.motion import Motion
from generation.core.quaternion import np_qfrom_axis_angle, np_qrot
from generation.core.skeleton import gait_skeleton
from generation.rbf.basis import mirrored
from generation.rbf.neutral_base import (
    MAX_JOINT_SPEED_M_S,
    average_cycles,
    cut_cycles,
    default_sources,
    neutral_cycle_from_motions,
    normalise_cycle,
    warp_times,
)
from generation.rbf.stylise import (
    _horn_rotation,
    bone_length_error,
    fit_to_skeleton,
    stylise,
    stylised_cycle,
    theme_rbfs,
    walker_frame_positions,
)
from generation.rbf.themes import THEME_NAMES, THEMES

pytestmark = pytest.mark.filterwarnings("ignore:The given NumPy array is not writable")


def tiny_cycle(height: float = 1.75, build: str = "male", m: int = 100, stride: float = 1.4,
               duration: float = 1.1) -> Motion:
    """A small analytic walk cycle of our own (synthetic): sinusoidal hip, knee, arm and elbow angles.

    Periodic over m frames, walking along +z by ``stride`` per cycle, lowest foot joint on y = 0. Its feet are
    not planted; it exists so these tests do not depend on the procedural walker's current state.
    """
    skel = gait_skeleton(height, build)
    J = skel.num_joints
    phi = np.arange(m) / m * 2 * np.pi  # left heel strike at 0, right at pi
    x_axis = np.array([1.0, 0.0, 0.0])
    rot = np.tile([1.0, 0.0, 0.0, 0.0], (m, J, 1))

    def about_x(angle):
        return np_qfrom_axis_angle(np.tile(x_axis, (m, 1)), angle)

    for side, shift in (("left", 0.0), ("right", np.pi)):
        hip_flex = 0.35 * np.cos(phi - shift)  # leg forward at its own heel strike
        knee = 0.15 + 0.5 * np.clip(np.sin(phi - shift - 1.2 * np.pi) * 1.5, 0.0, None) ** 1.5  # swing flexion
        rot[:, skel.index(f"{side}_hip")] = about_x(-hip_flex)  # -x rotation swings the leg to +z
        rot[:, skel.index(f"{side}_knee")] = about_x(knee)
        rot[:, skel.index(f"{side}_shoulder")] = about_x(0.3 * np.cos(phi - shift))  # arm opposite to its leg
        rot[:, skel.index(f"{side}_elbow")] = about_x(-0.3 - 0.1 * np.cos(phi - shift))
    # thorax counter-rotation: the right shoulder leads when the left leg does
    rot[:, skel.index("spine")] = np_qfrom_axis_angle(np.tile([0.0, 1.0, 0.0], (m, 1)), 0.08 * np.cos(phi))
    root = np.zeros((m, 3))
    root[:, 1] = 0.02 * height / 1.75 * np.cos(2 * phi)
    root[:, 2] = stride * np.arange(m) / m
    motion = Motion(skel, rot, root, m / duration, {"synthetic": True, "stride_m": [0.0, 0.0, stride]})
    root[:, 1] -= motion.positions()[:, [3, 4, 7, 8], 1].min()
    return Motion(skel, rot, root, m / duration, {"synthetic": True, "stride_m": [0.0, 0.0, stride],
                                                  "origin": "tiny test walk (synthetic)"})


@pytest.fixture(scope="module")
def neutral() -> Motion:
    """Our tiny analytic cycle, independent of the procedural walker."""
    return tiny_cycle()


# ---- neutral base -----------------------------------------------------------------------------------
def test_warp_maps_strikes_to_cycle_frames():
    t = warp_times(10, 40, 110, 100)
    assert t[0] == 10 and t[50] == 40 and t[100] == 110
    assert np.all(np.diff(t) > 0)


def test_cut_cycles_needs_one_right_strike_between_left_strikes():
    cycles = cut_cycles(np.array([0, 33, 66, 99]), np.array([16, 50, 60, 83]), fps=30.0)
    assert cycles == [(0, 16, 33), (66, 83, 99)]  # the middle cycle has two right strikes


def test_normalise_and_average_remove_body_size():
    # the same walk at two sizes: after height normalisation the cycles agree and the average reproduces it
    cycles = []
    for height in (1.6, 1.9):
        c = tiny_cycle(height, stride=1.4 * height / 1.75)
        walk = Motion(c.skeleton, np.concatenate([c.rotations] * 3),
                      np.concatenate([c.root_positions + [0, 0, k * 1.4 * height / 1.75] for k in range(3)]),
                      c.fps)  # three cycles, stride scaled with the body
        cycles.append(normalise_cycle(walk.positions(), walk.skeleton, walk.fps, (100, 150, 200), m=100))
    np.testing.assert_allclose(cycles[0].positions, cycles[1].positions, atol=1e-9)
    assert cycles[0].stride == pytest.approx(1.4 / 1.75)
    mean, stride, duration = average_cycles(cycles)
    assert mean.shape == (100, 21, 3) and duration == pytest.approx(1.1)
    P, _ = walker_frame_positions(tiny_cycle())
    np.testing.assert_allclose(mean * 1.75, P - [0, P[:, [3, 4, 7, 8], 1].min(), 0], atol=1e-9)
    with pytest.raises(ValueError, match="no walk cycles"):
        average_cycles([])


def test_neutral_base_from_the_captured_walk():
    """Real data path: the DeepMimic straight walks (turns left out), loop repeated but counted once."""
    from generation.rbf.neutral_base import captured_sources

    sources = captured_sources()
    assert sources and all("turn" not in mo.metadata["source"] for mo in sources)
    neutral = neutral_cycle_from_motions(sources)
    assert neutral.metadata["synthetic"] is False  # captured cycles only
    assert 1 <= neutral.metadata["n_cycles"] <= len(sources)
    assert 0.8 < neutral.duration < 1.6 and 0.9 < neutral.metadata["stride_m"][2] < 1.8
    out = stylise(neutral, "happy", 0.7, 10)
    assert out.metadata["synthetic_base"] is False
    assert bone_length_error(out.positions(), neutral.skeleton) < 1e-3


def _procedural_walk_glitch() -> float:
    """Fastest joint speed (m/s) in a 2 s procedural neutral walk at 100 fps (walking peaks near 6 m/s)."""
    from generation.procedural.walk import WalkParams, walk

    p = walk(WalkParams.neutral(), None, 200, 100.0).positions()
    return float(np.linalg.norm(np.diff(p, axis=0), axis=-1).max() * 100.0)


def test_neutral_base_from_procedural_walks():
    """Integration with generation.procedural.walk: several body sizes averaged into one periodic cycle."""
    # A glitch in generation.procedural.walk (e.g. a knee jumping ~13 cm in one frame each cycle) would make
    # neutral_base reject every procedural cycle as too fast: the walk must stay under the rejection speed.
    fastest = _procedural_walk_glitch()
    assert fastest <= MAX_JOINT_SPEED_M_S, f"procedural walk: a joint moves {fastest:.1f} m/s between two frames"
    neutral = neutral_cycle_from_motions(default_sources(include_captured=False))
    meta = neutral.metadata
    assert neutral.num_frames == 100 and meta["cycle_frames"] == 100
    assert meta["n_cycles"] >= 8  # 8 bodies x about 2 cycles (the paper averaged 16)
    assert meta["synthetic"] is True and meta["generator"] == "neutral_base"
    assert len({(s["height"], s["build"]) for s in meta["sources"] if s["cycles"]}) >= 4  # several body sizes
    stride = meta["stride_m"][2]
    assert 1.2 < stride < 1.6 and neutral.duration == pytest.approx(meta["cycle_duration_s"])
    P, _ = walker_frame_positions(neutral)
    step = np.abs(P[0] - P[-1]).max()  # loop closed: the first frame continues the last one
    assert step <= 1.5 * np.abs(np.diff(P, axis=0)).max()
    assert neutral.positions()[:, [3, 4, 7, 8], 1].min() == pytest.approx(0.0, abs=1e-9)  # feet on the floor
    out = stylise(neutral, "sad", 0.7, 10)
    assert bone_length_error(out.positions(), neutral.skeleton) < 1e-3


def test_neutral_base_rejects_other_skeletons():
    from generation.core.skeleton import gesture_skeleton

    J = gesture_skeleton().num_joints
    motion = Motion(gesture_skeleton(), np.tile([1.0, 0, 0, 0], (40, J, 1)), np.zeros((40, 3)), 30.0)
    with pytest.raises(ValueError, match="21-joint gait skeleton"):
        neutral_cycle_from_motions([motion])


# ---- the paper's model: w, n, inversion ----------------------------------------------------------------
def test_weight_zero_returns_the_neutral_walk(neutral):
    for theme in THEME_NAMES:
        out = stylise(neutral, theme, 0.0, 10, n_cycles=1, fps=neutral.fps, plant=False)
        assert out.num_frames == neutral.num_frames
        np.testing.assert_allclose(out.positions(), neutral.positions(), atol=1e-5)  # 0.01 mm


def test_displacement_scales_linearly_with_weight(neutral):
    base = stylised_cycle(neutral, "happy", 1.0, 10)
    for w in (0.4, 0.7, 1.3, -0.7):
        r = stylised_cycle(neutral, "happy", w, 10)
        np.testing.assert_allclose(r["Y"] - r["P"], w * base["S"], atol=1e-12)
    # after putting the edit back on the skeleton the displacement stays close to linear for small weights
    def edit(w):
        return stylised_cycle(neutral, "sad", w, 10, intensities="visual")["positions"]
    d1, d2 = edit(0.1) - edit(0.0), edit(0.2) - edit(0.0)
    assert np.abs(d2 - 2 * d1).max() < 0.1 * np.abs(d2).max()


def test_negative_weight_mirrors_the_displacement(neutral):
    for theme in THEME_NAMES:
        plus = stylised_cycle(neutral, theme, 0.7, 10)
        minus = stylised_cycle(neutral, theme, -0.7, 10)
        np.testing.assert_allclose(minus["Y"] - minus["P"], -(plus["Y"] - plus["P"]), atol=1e-12)
        # the RBF centres and widths are the same: only the amplitudes are inverted
        for key, params in theme_rbfs(plus["P"], neutral.skeleton, theme, 10).items():
            assert params[:, 1:].tolist() == theme_rbfs(minus["P"], neutral.skeleton, theme, 10)[key][:, 1:].tolist()


def test_n_features_uses_exactly_the_first_n(neutral):
    P, _ = walker_frame_positions(neutral)
    skel = neutral.skeleton
    for theme in THEME_NAMES:
        full = theme_rbfs(P, skel, theme, 10)
        for n in (1, 4, 7):
            part = theme_rbfs(P, skel, theme, n)
            wanted = {(joint, f.axis) for f in THEMES[theme][:n] for joint, _ in f.joint_signs()}
            assert set(part) == wanted
            for key, params in part.items():  # same RBFs as in the full set, in order
                np.testing.assert_array_equal(params, full[key][: len(params)])
        # joints no feature of the first n touches (and not below one) do not move before the fit
        r1 = stylised_cycle(neutral, theme, 1.0, 1)
        moved = np.abs(r1["S"]).max(axis=(0, 2)) > 0
        first = {skel.index(j) for j, _ in THEMES[theme][0].joint_signs()}
        for j in np.flatnonzero(moved):
            chain, k = set(), int(j)
            while k >= 0:
                chain.add(k)
                k = skel.parents[k]
            assert chain & first, f"{theme}: joint {skel.joints[j]} moved by a feature beyond the first"


def test_left_right_swings_are_mirrored_versions(neutral):
    # antiphase swing along Z: the right shoulder's RBFs are the left's with -alpha (section V-C1)
    P, _ = walker_frame_positions(neutral)
    rbfs = theme_rbfs(P, neutral.skeleton, "happy", 1)
    left = rbfs[("left_shoulder", "Z")]
    right = rbfs[("right_shoulder", "Z")]
    m_left = mirrored(left)
    m_left = m_left[np.argsort(m_left[:, 1])]
    right = right[np.argsort(right[:, 1])]
    np.testing.assert_allclose(right[:, 0], m_left[:, 0])
    np.testing.assert_allclose(right[:, 1], m_left[:, 1], atol=3.0)  # frames of a 100-frame cycle


# ---- bone lengths --------------------------------------------------------------------------------------
@pytest.mark.parametrize("theme", THEME_NAMES)
def test_bone_lengths_kept_within_1mm(neutral, theme):
    for w in (1.3, -0.7):
        out = stylise(neutral, theme, w, 10, n_cycles=2, intensities="visual")  # edits large enough to stretch
        assert bone_length_error(out.positions(), neutral.skeleton) < 1e-3
        assert out.metadata["bone_length_error_before_m"] > 5e-3  # the Cartesian edit did stretch bones
        calibrated = stylise(neutral, theme, w, 10, n_cycles=2)
        assert bone_length_error(calibrated.positions(), neutral.skeleton) < 1e-3
        assert out.metadata["bone_length_error_after_m"] < 1e-3
        feet = out.positions()[:, [3, 4, 7, 8], 1]
        assert feet.min() > -2e-3  # no foot through the floor


def test_fit_reproduces_unedited_positions_and_keeps_reachable_feet():
    skel = gait_skeleton()
    rng = np.random.default_rng(0)
    T = 6
    axis = rng.normal(size=(T, skel.num_joints, 3))
    rot = np_qfrom_axis_angle(axis, rng.uniform(0.0, 0.3, size=(T, skel.num_joints)))
    root = np.tile([0.0, 0.95, 0.0], (T, 1))
    pos = Motion(skel, rot, root, 30.0).positions()
    fitted_rot, fitted_root = fit_to_skeleton(pos, skel, rot)
    np.testing.assert_allclose(Motion(skel, fitted_rot, fitted_root, 30.0).positions(), pos, atol=1e-9)
    # move the left heel 3 cm up: the leg IK reaches it exactly, bones stay exact
    target = pos.copy()
    target[:, 3, 1] += 0.03
    target[:, 4, 1] += 0.03
    fitted = Motion(skel, *fit_to_skeleton(target, skel, rot), 30.0).positions()
    np.testing.assert_allclose(fitted[:, 3], target[:, 3], atol=1e-9)
    assert bone_length_error(fitted, skel) < 1e-9


def test_horn_rotation_recovers_a_rotation():
    rng = np.random.default_rng(3)
    q = np_qfrom_axis_angle(rng.normal(size=(5, 3)), rng.uniform(0, 2.5, size=5))
    src = rng.normal(size=(5, 4, 3))
    dst = np_qrot(np.repeat(q[:, None], 4, axis=1), src)
    got = _horn_rotation(src, dst)
    np.testing.assert_allclose(np.abs((got * q).sum(-1)), 1.0, atol=1e-9)


# ---- timing, path, metadata, errors ------------------------------------------------------------------
def test_speed_warps_time_uniformly_and_walks_forward(neutral):
    # the calibrated set: the default (extended) set changes tempo with the weight too (next test)
    slow = stylise(neutral, "tired", 0.7, 10, speed=1.0, n_cycles=4, fps=30.0, intensities="calibrated")
    fast = stylise(neutral, "tired", 0.7, 10, speed=1.25, n_cycles=4, fps=30.0, intensities="calibrated")
    assert slow.num_frames == round(4 * neutral.duration * 30.0)
    assert fast.num_frames == round(4 * neutral.duration / 1.25 * 30.0)
    stride = neutral.metadata["stride_m"][2]
    for clip in (slow, fast):
        z = clip.root_positions[:, 2]
        assert z[-1] - z[0] == pytest.approx(4 * stride, rel=0.03)
        assert np.all(np.diff(z) > 0)
        assert np.abs(clip.root_positions[:, 0]).max() < 0.1  # straight path
    # uniform time warp: speed 1.25 at 30 fps shows the same poses as speed 1 sampled at 30 / 1.25 = 24 fps
    # (before foot planting, which works in m/s and frames)
    fast = stylise(neutral, "tired", 0.7, 10, speed=1.25, n_cycles=4, fps=30.0, plant=False)
    sparse = stylise(neutral, "tired", 0.7, 10, speed=1.0, n_cycles=4, fps=24.0, plant=False)
    assert sparse.num_frames == fast.num_frames
    np.testing.assert_allclose(fast.positions(), sparse.positions(), atol=1e-9)


def test_extended_set_changes_stride_and_cadence_with_the_weight(neutral):
    """The extended set's stride and cadence (levers of ours): s = max(0.5, 1 + w * stride), c = max(0.5, 1 + w *
    cadence), only with all ten features; the cycle plays c times faster and walks s times further per cycle."""
    from generation.rbf.themes import extended_stride_cadence

    stride, cadence = extended_stride_cadence("energetic")
    assert stride > 0 and cadence > 0 and extended_stride_cadence("sad")[0] < 0 > extended_stride_cadence("sad")[1]
    for w in (-0.7, 0.7):
        clip = stylise(neutral, "energetic", w, 10, n_cycles=4, fps=30.0, plant=False)
        assert clip.metadata["stride_scale"] == pytest.approx(1 + w * stride)
        assert clip.metadata["cadence_scale"] == pytest.approx(1 + w * cadence)
        assert clip.num_frames == round(4 * neutral.duration / (1 + w * cadence) * 30.0)
        advance = clip.root_positions[-1, 2] - clip.root_positions[0, 2]
        per_frame = (1 + w * stride) * neutral.metadata["stride_m"][2] * (1 + w * cadence) / (neutral.duration * 30)
        assert advance == pytest.approx(per_frame * (clip.num_frames - 1), rel=0.02)
    for kept in (stylise(neutral, "energetic", 0.7, 7, n_cycles=4), stylise(neutral, "energetic", 0.0, 10, n_cycles=4),
                 stylise(neutral, "energetic", 0.7, 10, n_cycles=4, intensities="calibrated")):
        assert "stride_scale" not in kept.metadata and "cadence_scale" not in kept.metadata
    slow = stylise(neutral, "sad", 1.9, 10, n_cycles=1)
    assert slow.metadata["stride_scale"] == 0.5 and slow.metadata["cadence_scale"] == 0.5


def test_neutral_walk_equals_weight_zero(neutral):
    from generation.rbf.stylise import neutral_walk

    base = neutral_walk(neutral, speed=1.1, n_cycles=3)
    zero = stylise(neutral, "sad", 0.0, 10, speed=1.1, n_cycles=3)
    np.testing.assert_allclose(base.positions(), zero.positions(), atol=1e-5)
    assert base.metadata["theme"] == "neutral" and base.metadata["generator"] == "neutral_base"


def test_metadata(neutral):
    out = stylise(neutral, "feminine", -0.7, 7, speed=1.1)
    meta = out.metadata
    assert {k: meta[k] for k in ("origin", "generator", "theme", "weight", "n_features", "speed",
                                 "synthetic_base")} == {
        "origin": "generated", "generator": "rbf", "theme": "feminine", "weight": -0.7, "n_features": 7,
        "speed": 1.1, "synthetic_base": True}


@pytest.mark.parametrize("kwargs, message", [
    ({"theme": "angry"}, "unknown theme"),
    ({"n_features": 11}, "n_features"),
    ({"speed": 0.0}, "speed"),
    ({"n_cycles": 0}, "n_cycles"),
    ({"weight": float("nan")}, "weight"),
])
def test_bad_arguments_are_rejected(neutral, kwargs, message):
    args = {"theme": "happy", "weight": 0.7, "n_features": 4} | kwargs
    with pytest.raises(ValueError, match=message):
        stylise(neutral, **args)


def test_cycle_must_walk_along_z(neutral):
    turned = Motion(neutral.skeleton, neutral.rotations, neutral.root_positions, neutral.fps,
                    dict(neutral.metadata, stride_m=[1.4, 0.0, 0.0]))
    with pytest.raises(ValueError, match="walk along \\+z"):
        stylise(turned, "sad", 0.7, 4)
