"""Procedural (synthetic) walking on the 21-joint gait skeleton, with planted feet.

This is a parametric walk cycle, not captured motion; everything it makes is marked
``{"origin": "procedural", "synthetic": True}`` in the metadata.

How a walk is made (all in metres, seconds, radians):

1. Timing. The gait cycle phase is ``phi(t) = phase + t * cadence / 120`` cycles (a cycle is two
   steps). The left heel strikes at integer ``phi``, the right heel half a cycle later. Each foot
   is on the ground for the first 60 % of its cycle: heel rocker (toe lowering onto the ground,
   heel joint fixed) for 10 %, foot flat until 30 %, then heel rise about the fixed toe until
   toe-off at 60 %; the remaining 40 % is swing.
2. Path. The root moves along a corner-rounded copy of the :class:`~generation.core.paths.GroundPath`
   at constant speed ``stride_m * cadence / 120`` m/s (a stride is two steps), facing the path
   tangent. Footprints are put on the path, half a step width to either side, so the walker
   follows straight, curved and sharp-turn paths.
3. Feet. During contact a foot stays exactly on its footprint (heel joint fixed, then toe fixed);
   in swing it travels to the next footprint on a minimum-jerk curve lifted by the knee lift.
4. Pelvis. Lateral sway toward the stance foot, vertical bounce (highest at mid-stance), pelvic
   rotation; its height is then lowered wherever a leg could not reach its foot target.
5. Legs. Analytic two-bone IK (hip-knee-ankle) with the knee bending toward the foot's facing
   direction; the foot orientation is set directly. Because every foot target is reachable,
   the feet land exactly on the footprints and foot skate is limited to numerical error.
6. Upper body. Torso pitch split over the lower back and spine, thorax counter-rotation, head
   pitch relative to the world vertical plus an optional nod, arms swinging opposite to the legs
   with abduction (expansion) and elbow flexion.
"""
from __future__ import annotations

import dataclasses
import json
from dataclasses import dataclass

import numpy as np

from generation.core.motion import Motion
from generation.core.paths import GroundPath, straight
from generation.core.quaternion import np_qmul, np_qrot
from generation.core.rigging import (
    axis_angle,
    hinge_rotations,
    locals_from_globals,
    minjerk,
    smoothstep,
    two_bone_ik,
    yaw_quat,
)
from generation.core.skeleton import GAIT_JOINTS, Skeleton, gait_skeleton

# Fractions of the gait cycle for one foot (0 = its heel strike).
HEEL_ROCKER_END = 0.10
HEEL_OFF = 0.30
TOE_OFF = 0.60

_J = {name: i for i, name in enumerate(GAIT_JOINTS)}
_X = np.array([1.0, 0.0, 0.0])
_Y = np.array([0.0, 1.0, 0.0])
_Z = np.array([0.0, 0.0, 1.0])


@dataclass
class WalkParams:
    """Parameters of a procedural walk. Angles in radians, lengths in metres (for a 1.75 m body;
    lengths are scaled with the skeleton's height).

    Attributes:
        cadence_spm: steps per minute (a gait cycle is two steps); 60-160.
        stride_m: stride length, distance between successive contacts of the same foot; 0.4-2.2.
        arm_swing_rad: amplitude of the shoulder flexion swing (forward/back) of each arm.
        elbow_bend_rad: mean elbow flexion; the elbow bends a further 40 % of the arm's forward swing.
        torso_pitch_rad: forward lean of the trunk from vertical (+ = bowed forward, - = leaning back).
        head_pitch_rad: head pitch from the world vertical (+ = looking down, - = chin up).
        shoulder_raise_m: shoulder elevation (+ = raised, tense; - = dropped). The 21-joint skeleton has
            no clavicle joint, so a raise is realised as the arm elevation it would cause: extra
            abduction of ``asin(raise / upper_arm_length)`` and a matching extra elbow bend.
        knee_lift_rad: swing knee flexion scale; sets the swing foot clearance
            ``0.02 + 0.18 * (1 - cos(knee_lift_rad))`` metres (about 0.10 m at 1.0 rad).
        lateral_sway_m: amplitude of the pelvis' side-to-side sway toward the stance foot.
        arm_abduction_rad: arms held out from the body (expansion); 0 = hanging at the sides.
        bounce_m: peak-to-peak vertical pelvis oscillation, highest at mid-stance (before reach limits).
        step_width_m: lateral distance between the left and right footprints.
        toe_out_rad: outward yaw of each foot.
        pelvis_rotation_rad: amplitude of the pelvis' yaw oscillation (the swinging hip leads).
        head_nod_rad: amplitude of a head nod at the step frequency.
        knee_bend_m: how much lower than standing the nominal pelvis height is (crouch).
    """

    cadence_spm: float = 110.0
    stride_m: float = 1.40
    arm_swing_rad: float = 0.30
    elbow_bend_rad: float = 0.25
    torso_pitch_rad: float = 0.04
    head_pitch_rad: float = 0.05
    shoulder_raise_m: float = 0.0
    knee_lift_rad: float = 1.0
    lateral_sway_m: float = 0.025
    arm_abduction_rad: float = 0.10
    bounce_m: float = 0.02
    step_width_m: float = 0.16
    toe_out_rad: float = 0.10
    pelvis_rotation_rad: float = 0.06
    head_nod_rad: float = 0.02
    knee_bend_m: float = 0.005

    _LIMITS = {
        "cadence_spm": (60.0, 160.0), "stride_m": (0.4, 2.2), "arm_swing_rad": (0.0, 1.2),
        "elbow_bend_rad": (0.0, 2.2), "torso_pitch_rad": (-0.4, 0.8), "head_pitch_rad": (-0.6, 1.0),
        "shoulder_raise_m": (-0.08, 0.08), "knee_lift_rad": (0.2, 2.0), "lateral_sway_m": (0.0, 0.15),
        "arm_abduction_rad": (-0.1, 1.2), "bounce_m": (0.0, 0.12), "step_width_m": (0.0, 0.5),
        "toe_out_rad": (-0.3, 0.5), "pelvis_rotation_rad": (0.0, 0.4), "head_nod_rad": (0.0, 0.4),
        "knee_bend_m": (0.0, 0.2),
    }

    @classmethod
    def neutral(cls) -> WalkParams:
        """An unremarkable walk: 110 steps/min, 1.4 m stride (1.28 m/s)."""
        return cls()

    @property
    def speed_mps(self) -> float:
        """Walking speed in m/s for the reference body height."""
        return self.stride_m * self.cadence_spm / 120.0

    def validate(self) -> WalkParams:
        """Raise ValueError naming the field when a value is not finite or outside its range."""
        for f in dataclasses.fields(self):
            value = getattr(self, f.name)
            lo, hi = self._LIMITS[f.name]
            if not isinstance(value, (int, float, np.floating)) or not np.isfinite(value):
                raise ValueError(f"WalkParams.{f.name} must be a finite number, got {value!r}")
            if not lo <= value <= hi:
                raise ValueError(f"WalkParams.{f.name}={value} outside [{lo}, {hi}]")
        return self

    def to_dict(self) -> dict:
        return {f.name: float(getattr(self, f.name)) for f in dataclasses.fields(self)}

    @classmethod
    def from_dict(cls, data: dict) -> WalkParams:
        names = {f.name for f in dataclasses.fields(cls)}
        unknown = set(data) - names
        if unknown:
            raise ValueError(f"WalkParams: unknown field(s) {sorted(unknown)}")
        return cls(**{k: float(v) for k, v in data.items()}).validate()

    def blend(self, other: WalkParams, w: float) -> WalkParams:
        """Linear mix (1 - w) * self + w * other."""
        return WalkParams(**{f.name: (1 - w) * getattr(self, f.name) + w * getattr(other, f.name)
                             for f in dataclasses.fields(self)})


# ---------------------------------------------------------------------------------------------
@dataclass
class WalkResult:
    """A walk and its ground-truth contact labels.

    Attributes:
        motion: the synthetic Motion.
        heel_contact: (T, 2) bool, heel joint planted (left, right).
        toe_contact: (T, 2) bool, toe joint planted (left, right).
        footprints: list (left, right) of (K, 3) arrays (x, z, yaw) of the planted heel joints.
    """

    motion: Motion
    heel_contact: np.ndarray
    toe_contact: np.ndarray
    footprints: list


def _check_skeleton(skeleton: Skeleton) -> None:
    if tuple(skeleton.joints) != GAIT_JOINTS:
        raise ValueError(f"procedural walk needs the 21-joint gait skeleton, got {skeleton.name!r} "
                         f"with {skeleton.num_joints} joints")


def walk_with_contacts(params: WalkParams, path: GroundPath | None = None, n_frames: int = 240, fps: float = 30.0,
                       skeleton: Skeleton | None = None, phase: float = 0.0, seed: int | None = None,
                       corner_sigma_m: float = 0.35) -> WalkResult:
    """Like :func:`walk` but also returns the ground-truth foot contacts and footprints.

    The steps: plan the timing, path and leg geometry (:func:`_plan_walk`), place the footprints
    (:func:`_footprints`), move each foot through stance and swing (:func:`_foot_track`), fit the pelvis
    height to the feet (:func:`_fit_pelvis`), then set the legs' and the upper body's global rotations.
    """
    params = WalkParams(**dataclasses.asdict(params)).validate()
    skeleton = skeleton or gait_skeleton()
    _check_skeleton(skeleton)
    if int(n_frames) < 2:
        raise ValueError(f"n_frames must be at least 2, got {n_frames}")
    if not fps > 0:
        raise ValueError(f"fps must be positive, got {fps}")
    rng = np.random.default_rng(seed)
    plan, path = _plan_walk(params, path, int(n_frames), fps, skeleton, phase, corner_sigma_m)
    feet = _footprints(plan, rng, jitter=seed is not None)
    ankle, foot_q, foot_yaw, heel_contact, toe_contact = _feet(plan, feet)
    root, q_root, h_t, hip_rel = _fit_pelvis(plan, ankle, heel_contact, toe_contact)
    G = np.zeros((len(plan.t), 21, 4))
    G[:, _J["root"]] = q_root
    _set_leg_rotations(plan, G, root, hip_rel, ankle, foot_q, foot_yaw, h_t)
    _set_upper_body_rotations(plan, G, h_t)
    local = locals_from_globals(G, skeleton.parents)
    metadata = {
        "origin": "procedural",
        "synthetic": True,
        "generator": "generation.procedural.walk",
        "params": params.to_dict(),
        "path_kind": path.kind,
        "phase": float(phase),
        "seed": seed,
        "speed_mps": float(plan.speed),
    }
    json.dumps(metadata)  # fail early if anything is not JSON-serialisable
    motion = Motion(skeleton, local, root, fps, metadata)
    footprints = [np.column_stack([xz, yaw]) for _, xz, yaw, _, _ in feet]
    return WalkResult(motion, heel_contact, toe_contact, footprints)


# ---- the steps of walk_with_contacts ------------------------------------------------------------
@dataclass(frozen=True, eq=False)
class _WalkPlan:
    """Timing, smoothed ground path and leg geometry of one walk, shared by its steps (metres, radians)."""

    params: WalkParams
    fps: float
    phase: float
    scale: float            # skeleton height / 1.75 m
    off: np.ndarray         # (21, 3) skeleton offsets
    t: np.ndarray           # (T,) frame times
    phi: np.ndarray         # (T,) gait phase in cycles
    f_cycle: float          # cycles per second
    speed: float            # m/s along the path
    lead: float             # metres of straight extension before the path start
    smooth: GroundPath      # the path with rounded corners, from -lead
    ankle_h: float          # heel-joint height when the foot is flat
    toe_off_vec: np.ndarray  # heel -> toe in the foot frame
    strike_pitch: float     # toe-up angle at heel strike
    pitch_max: float        # heel-rise pitch at toe-off
    lift: float             # swing-foot lift
    half_width: float       # half the step width
    footprint_at: float     # pelvis is over the heel this fraction into stance
    stand: float            # nominal root height
    len_thigh: float
    len_shin: float
    reach: float            # usable leg length


_PITCH_GRID = np.linspace(0.0, 1.2, 61)


def _plan_walk(params: WalkParams, path: GroundPath | None, n_frames: int, fps: float, skeleton: Skeleton,
               phase: float, corner_sigma_m: float) -> tuple[_WalkPlan, GroundPath]:
    """The walk's timing, smoothed path and leg geometry; also the path (a straight one when None)."""
    off = skeleton.offsets
    scale = skeleton.height / 1.75
    t = np.arange(n_frames) / fps
    f_cycle = params.cadence_spm / 120.0
    stride = params.stride_m * scale
    speed = stride * f_cycle
    phi = phase + t * f_cycle
    walked = speed * t[-1]
    if path is None:
        path = straight(walked + 1.0)
    lead = 3.0
    smooth = path.smoothed(corner_sigma_m, start=-lead, stop=max(path.length, walked) + 3.0)
    ankle_h = -off[_J["left_toe"], 1]
    len_thigh = float(np.linalg.norm(off[_J["left_knee"]]))
    len_shin = float(np.linalg.norm(off[_J["left_heel"]]))
    plan = _WalkPlan(
        params=params, fps=fps, phase=phase, scale=scale, off=off, t=t, phi=phi, f_cycle=f_cycle, speed=speed,
        lead=lead, smooth=smooth, ankle_h=ankle_h, toe_off_vec=off[_J["left_toe"]], strike_pitch=0.25,
        pitch_max=float(np.clip(0.85 + 0.4 * (params.stride_m - 1.4), 0.4, 1.2)),
        lift=(0.02 + 0.18 * (1.0 - np.cos(params.knee_lift_rad))) * scale,
        half_width=0.5 * params.step_width_m * scale, footprint_at=0.16,
        stand=-(off[_J["left_hip"], 1] + off[_J["left_knee"], 1] + off[_J["left_heel"], 1]) + ankle_h,
        len_thigh=len_thigh, len_shin=len_shin, reach=0.97 * (len_thigh + len_shin))
    return plan, path


def _path_s(plan: _WalkPlan, time):
    """Arc length on the smoothed path at ``time``."""
    return plan.lead + plan.speed * time


def _heading(plan: _WalkPlan, s):
    """Path heading at arc length ``s``, from a central difference over +-5 cm of the smoothed path."""
    d = plan.smooth.point_at(s + 0.05) - plan.smooth.point_at(s - 0.05)
    return np.arctan2(d[..., 0], d[..., 1])


def _left_normal(h):
    return np.stack([np.cos(h), -np.sin(h)], axis=-1)


def _pelvis_at(plan: _WalkPlan, time):
    """Nominal root position (n, 3), root rotation (n, 4) and path heading (n,) at times (n,)."""
    params, scale = plan.params, plan.scale
    ph = plan.phase + time * plan.f_cycle
    s = _path_s(plan, time)
    h = _heading(plan, s)
    xz = plan.smooth.point_at(s) + (params.lateral_sway_m * scale * np.sin(2 * np.pi * ph))[:, None] * _left_normal(h)
    y = (plan.stand - params.knee_bend_m * scale
         - 0.5 * params.bounce_m * scale * (1.0 - np.cos(4 * np.pi * (ph - 0.2))))
    q = yaw_quat(h - params.pelvis_rotation_rad * np.cos(2 * np.pi * ph))
    return np.column_stack([xz[:, 0], y, xz[:, 1]]), q, h


def _required_pitch(plan: _WalkPlan, time, hip_name, toe_pos, yaw):
    """Smallest heel-rise pitch (n,), at most 1.2 rad, that brings the ankle within 95 % of the leg's reach of the
    nominal hip when the foot pivots about its planted toe (so the trailing leg, not the pelvis, gives way)."""
    off = plan.off
    root_n, q_n, _ = _pelvis_at(plan, time)
    hip = root_n + np_qrot(q_n, np.broadcast_to(off[_J[hip_name]], root_n.shape))
    q = np_qmul(yaw_quat(yaw)[:, None], axis_angle(_X, np.broadcast_to(_PITCH_GRID, (len(time), len(_PITCH_GRID)))))
    ankles = toe_pos[:, None] - np_qrot(q, np.broadcast_to(plan.toe_off_vec, q.shape[:-1] + (3,)))
    ok = np.linalg.norm(ankles - hip[:, None], axis=-1) <= 0.95 * (plan.len_thigh + plan.len_shin)
    first = np.where(ok.any(1), ok.argmax(1), len(_PITCH_GRID) - 1)
    return _PITCH_GRID[first]


def _footprints(plan: _WalkPlan, rng: np.random.Generator, jitter: bool) -> list:
    """Per foot (left, right): stance indices ks, footprint (x, z), yaw, the foot's phase offset and the heel-rise
    pitch at each toe-off (raised where the hip has already moved far ahead)."""
    params, phi = plan.params, plan.phi
    feet = []
    for side, foot_offset in ((+1.0, 0.0), (-1.0, 0.5)):
        k0 = int(np.floor(phi[0] - foot_offset)) - 2
        k1 = int(np.ceil(phi[-1] - foot_offset)) + 2
        ks = np.arange(k0, k1 + 1)
        t_fp = (ks + foot_offset + plan.footprint_at - plan.phase) / plan.f_cycle
        s_fp = _path_s(plan, t_fp)
        h_fp = _heading(plan, s_fp)
        noise = rng.normal(0.0, 0.01 * plan.scale, size=(len(ks), 2)) if jitter else np.zeros((len(ks), 2))
        xz = plan.smooth.point_at(s_fp) + side * plan.half_width * _left_normal(h_fp) + noise
        yaw = h_fp + side * params.toe_out_rad
        t_off = (ks + foot_offset + TOE_OFF - plan.phase) / plan.f_cycle
        flat = np.column_stack([xz[:, 0], np.full(len(ks), plan.ankle_h), xz[:, 1]])
        toe_fp = flat + np_qrot(yaw_quat(yaw), np.broadcast_to(plan.toe_off_vec, flat.shape))
        p_off = np.maximum(plan.pitch_max,
                           _required_pitch(plan, t_off, "left_hip" if side > 0 else "right_hip", toe_fp, yaw))
        feet.append((ks, xz, yaw, foot_offset, p_off))
    return feet


def _feet(plan: _WalkPlan, feet: list):
    """Both feet's heel-joint positions (2, T, 3), global rotations (2, T, 4), yaws (2, T) and the heel and toe
    contacts (T, 2)."""
    T = len(plan.t)
    ankle = np.zeros((2, T, 3))
    foot_q = np.zeros((2, T, 4))
    foot_yaw = np.zeros((2, T))
    heel_contact = np.zeros((T, 2), dtype=bool)
    toe_contact = np.zeros((T, 2), dtype=bool)
    for f, foot in enumerate(feet):
        ankle[f], foot_yaw[f], pitch, heel_contact[:, f], toe_contact[:, f] = _foot_track(plan, f, foot)
        foot_q[f] = np_qmul(yaw_quat(foot_yaw[f]), axis_angle(_X, pitch))
    return ankle, foot_q, foot_yaw, heel_contact, toe_contact


def _foot_track(plan: _WalkPlan, f: int, foot: tuple):
    """One foot (f = 0 left, 1 right) through heel rocker, flat foot and heel rise, and swing.

    Returns its heel-joint positions (T, 3), yaw (T,), pitch (T,), heel contact and toe contact (T,).
    """
    ks, xz, yaw, foot_offset, p_off = foot
    T, ankle_h, toe_off_vec, strike_pitch = len(plan.t), plan.ankle_h, plan.toe_off_vec, plan.strike_pitch
    k = np.floor(plan.phi - foot_offset).astype(int)
    u = plan.phi - foot_offset - k
    i = k - ks[0]
    # Planted foot pose at stance k.
    fp_xz, fp_yaw = xz[i], yaw[i]
    nxt_xz, nxt_yaw = xz[i + 1], yaw[i + 1]
    pitch = np.zeros(T)
    pos = np.zeros((T, 3))
    yaw_t = fp_yaw.copy()
    # heel rocker: the toe lowers onto the ground about the planted heel joint
    heel = u < HEEL_ROCKER_END
    pitch[heel] = -strike_pitch * (1.0 - smoothstep(u[heel] / HEEL_ROCKER_END))
    pos[heel] = np.column_stack([fp_xz[heel, 0], np.full(heel.sum(), ankle_h), fp_xz[heel, 1]])
    # flat foot, then the heel rises about the fixed toe. The rise starts at HEEL_OFF, or earlier when the hip
    # has moved so far ahead that the flat foot would be out of reach; one pivot formula for both keeps the
    # heel (and so the knee) continuous where the heel leaves the ground.
    toe = (u >= HEEL_ROCKER_END) & (u < TOE_OFF)
    flat_heel = np.column_stack([fp_xz[toe, 0], np.full(toe.sum(), ankle_h), fp_xz[toe, 1]])
    q_flat = yaw_quat(fp_yaw[toe])
    toe_pos = flat_heel + np_qrot(q_flat, np.broadcast_to(toe_off_vec, flat_heel.shape))
    ramp = smoothstep(np.clip((u[toe] - HEEL_OFF) / (TOE_OFF - HEEL_OFF), 0.0, 1.0))
    p_toe = np.maximum(p_off[i[toe]] * ramp,
                       _required_pitch(plan, plan.t[toe], "left_hip" if f == 0 else "right_hip", toe_pos, fp_yaw[toe]))
    p_toe = np.minimum(p_toe, p_off[i[toe]])   # reach p_off exactly at toe-off, continuous into swing
    q_p = np_qmul(q_flat, axis_angle(_X, p_toe))
    pos[toe] = toe_pos - np_qrot(q_p, np.broadcast_to(toe_off_vec, flat_heel.shape))
    pitch[toe] = p_toe
    heel = heel.copy()
    heel[toe] = p_toe <= 1e-9
    # swing: from the toe-off pose of stance k to the heel strike of stance k+1
    sw = u >= TOE_OFF
    w = (u[sw] - TOE_OFF) / (1.0 - TOE_OFF)
    heel0 = np.column_stack([fp_xz[sw, 0], np.full(sw.sum(), ankle_h), fp_xz[sw, 1]])
    p0 = p_off[i[sw]]
    q0 = np_qmul(yaw_quat(fp_yaw[sw]), axis_angle(_X, p0))
    toe0 = heel0 + np_qrot(yaw_quat(fp_yaw[sw]), np.broadcast_to(toe_off_vec, heel0.shape))
    start = toe0 - np_qrot(q0, np.broadcast_to(toe_off_vec, heel0.shape))
    end = np.column_stack([nxt_xz[sw, 0], np.full(sw.sum(), ankle_h), nxt_xz[sw, 1]])
    e = minjerk(w)
    pos[sw] = start + e[:, None] * (end - start)
    pos[sw, 1] += plan.lift * np.sin(np.pi * w ** 0.7)
    pitch[sw] = p0 + (-strike_pitch - p0) * smoothstep(w * 1.2)
    dyaw = np.angle(np.exp(1j * (nxt_yaw[sw] - fp_yaw[sw])))
    yaw_t[sw] = fp_yaw[sw] + dyaw * smoothstep(w)
    return pos, yaw_t, pitch, heel, (u >= HEEL_ROCKER_END) & (u < TOE_OFF)


def _fit_pelvis(plan: _WalkPlan, ankle: np.ndarray, heel_contact: np.ndarray, toe_contact: np.ndarray):
    """Root positions (T, 3), root rotations (T, 4), path headings (T,) and hip offsets (2, T, 3) from the root.

    Planted feet limit the pelvis height; a swinging foot that would be out of reach is lifted instead (the
    knee flexes more), as in early swing: ``ankle`` is raised in place.
    """
    T, off, reach = len(plan.t), plan.off, plan.reach
    nominal_root, q_root, h_t = _pelvis_at(plan, plan.t)
    root_xz = nominal_root[:, [0, 2]]
    nominal = nominal_root[:, 1]
    hip_rel = np.stack([np_qrot(q_root, np.broadcast_to(off[_J[n]], (T, 3))) for n in ("left_hip", "right_hip")])
    max_y = np.full(T, np.inf)
    horiz = [np.linalg.norm((root_xz + hip_rel[f][:, [0, 2]]) - ankle[f][:, [0, 2]], axis=-1) for f in range(2)]
    for f in range(2):
        stance = heel_contact[:, f] | toe_contact[:, f] | (ankle[f][:, 1] <= plan.ankle_h + 1e-9)
        dy = np.sqrt(np.maximum(reach ** 2 - horiz[f] ** 2, 0.0))
        max_y = np.minimum(max_y, np.where(stance, ankle[f][:, 1] + dy - hip_rel[f][:, 1], np.inf))
    root_y = np.minimum(nominal, max_y)
    root_y = _smooth_below(root_y, radius=max(1, int(round(0.08 * plan.fps))))
    root = np.column_stack([root_xz[:, 0], root_y, root_xz[:, 1]])
    for f in range(2):
        swing = ~(heel_contact[:, f] | toe_contact[:, f])
        dy = np.sqrt(np.maximum(reach ** 2 - horiz[f] ** 2, 0.0))
        lowest = root_y + hip_rel[f][:, 1] - dy
        ankle[f][swing, 1] = np.maximum(ankle[f][swing, 1], lowest[swing])
    return root, q_root, h_t, hip_rel


def _set_leg_rotations(plan: _WalkPlan, G: np.ndarray, root, hip_rel, ankle, foot_q, foot_yaw, h_t) -> None:
    """Global rotations of the thighs, shins and feet into ``G`` (T, 21, 4), by two-bone IK onto the ankles."""
    off, T = plan.off, len(plan.t)
    for f, (hip, knee, heel_j, toe_j) in enumerate((("left_hip", "left_knee", "left_heel", "left_toe"),
                                                    ("right_hip", "right_knee", "right_heel", "right_toe"))):
        hip_pos = root + hip_rel[f]
        # The knee bends toward the foot's facing direction, mixed with the trunk heading.
        knee_yaw = h_t + np.angle(np.exp(1j * (foot_yaw[f] - h_t))) * 0.5
        fwd = np.column_stack([np.sin(knee_yaw), np.zeros(T), np.cos(knee_yaw)])
        knee_pos, ankle_pos, _ = two_bone_ik(hip_pos, ankle[f], plan.len_thigh, plan.len_shin, fwd)
        G[:, _J[hip]], G[:, _J[knee]] = hinge_rotations(hip_pos, knee_pos, ankle_pos, off[_J[knee]],
                                                        off[_J[heel_j]], -_Z, -fwd)
        G[:, _J[heel_j]] = foot_q[f]
        G[:, _J[toe_j]] = foot_q[f]


def _set_upper_body_rotations(plan: _WalkPlan, G: np.ndarray, h_t: np.ndarray) -> None:
    """Global rotations of the trunk, head and arms into ``G`` (T, 21, 4)."""
    params, phi, off, T = plan.params, plan.phi, plan.off, len(plan.t)
    thorax_yaw = 0.5 * params.pelvis_rotation_rad * np.cos(2 * np.pi * phi)
    q_yaw = yaw_quat(h_t)
    G[:, _J["lower_back"]] = np_qmul(q_yaw, axis_angle(_X, np.full(T, 0.4 * params.torso_pitch_rad)))
    q_thorax = np_qmul(yaw_quat(h_t + thorax_yaw), axis_angle(_X, np.full(T, params.torso_pitch_rad)))
    G[:, _J["spine"]] = q_thorax
    nod = params.head_nod_rad * np.sin(4 * np.pi * phi)
    G[:, _J["neck"]] = np_qmul(yaw_quat(h_t + 0.5 * thorax_yaw), axis_angle(_X, params.head_pitch_rad + nod))
    G[:, _J["head"]] = G[:, _J["neck"]]
    len_upper_arm = float(np.linalg.norm(off[_J["left_elbow"]]))
    raise_angle = float(np.arcsin(np.clip(params.shoulder_raise_m * plan.scale / len_upper_arm, -0.5, 0.5)))
    for side, (sh, el, ha, ix), sign in ((0, ("left_shoulder", "left_elbow", "left_hand", "left_hand_index"), 1.0),
                                         (1, ("right_shoulder", "right_elbow", "right_hand", "right_hand_index"),
                                          -1.0)):
        flex = params.arm_swing_rad * (-np.cos(2 * np.pi * phi)) * (1.0 if side == 0 else -1.0)
        flex = flex + 0.5 * params.torso_pitch_rad * 0.3  # arms hang slightly ahead of a bowed trunk
        abd = np.full(T, params.arm_abduction_rad + max(raise_angle, 0.0))
        q_up = np_qmul(np_qmul(yaw_quat(h_t + thorax_yaw), axis_angle(_Z, sign * abd)), axis_angle(_X, -flex))
        elbow = params.elbow_bend_rad + 0.4 * np.maximum(flex, 0.0) + abs(raise_angle)
        q_fore = np_qmul(q_up, axis_angle(_X, -elbow))
        q_hand = np_qmul(q_fore, axis_angle(_X, np.full(T, -0.1)))
        G[:, _J[sh]] = q_up
        G[:, _J[el]] = q_fore
        G[:, _J[ha]] = q_hand
        G[:, _J[ix]] = q_hand


def walk(params: WalkParams, path: GroundPath | None = None, n_frames: int = 240, fps: float = 30.0,
         skeleton: Skeleton | None = None, phase: float = 0.0, seed: int | None = None) -> Motion:
    """A synthetic walk following ``path`` with planted feet.

    Args:
        params: gait parameters (validated; ValueError names a bad field).
        path: ground path to follow from its first point (default: straight along +z). The
            walker starts at arc length 0 facing the path tangent and walks at constant speed;
            if the path is too short it continues straight past its end.
        n_frames: number of frames T.
        fps: frame rate.
        skeleton: 21-joint gait skeleton (default 1.75 m male); lengths scale with its height.
        phase: gait cycle phase at frame 0, in cycles (0 = left heel strike, 0.5 = right).
        seed: adds small random footprint jitter (1 cm) when given; None is fully deterministic.

    Returns:
        Motion with rotations (T, 21, 4), root_positions (T, 3); metadata {"origin": "procedural",
        "synthetic": True, "params": {...}, "path_kind": ...}.
    """
    return walk_with_contacts(params, path, n_frames, fps, skeleton, phase, seed).motion


def _smooth_below(y: np.ndarray, radius: int) -> np.ndarray:
    """Smooth a signal without exceeding it anywhere: min filter then a blur of the same support."""
    pad = np.pad(y, radius, mode="edge")
    windows = np.lib.stride_tricks.sliding_window_view(pad, 2 * radius + 1)
    eroded = windows.min(axis=-1)
    half = radius // 2
    k2 = np.hanning(2 * half + 3)[1:-1]
    k2 /= k2.sum()
    padded = np.pad(eroded, half, mode="edge")
    return np.convolve(padded, k2, mode="valid")


def planted_foot_slide(positions: np.ndarray, heel_contact: np.ndarray, toe_contact: np.ndarray,
               fps: float = 30.0) -> dict:
    """Horizontal slide of planted feet.

    Args:
        positions: (T, 21, 3) joint positions in metres.
        heel_contact, toe_contact: (T, 2) bool contact labels (left, right).

    Returns:
        dict with mean_mm_per_frame, max_mm_per_frame (over frame pairs where the joint is in
        contact in both frames), and n_pairs.
    """
    slides = []
    for f, (heel, toe) in enumerate((("left_heel", "left_toe"), ("right_heel", "right_toe"))):
        for joint, contact in ((heel, heel_contact[:, f]), (toe, toe_contact[:, f])):
            p = positions[:, _J[joint]][:, [0, 2]]
            both = contact[1:] & contact[:-1]
            d = np.linalg.norm(np.diff(p, axis=0), axis=-1)[both]
            slides.append(d)
    all_d = np.concatenate(slides) * 1000.0
    if all_d.size == 0:
        return {"mean_mm_per_frame": 0.0, "max_mm_per_frame": 0.0, "n_pairs": 0}
    return {"mean_mm_per_frame": float(all_d.mean()), "max_mm_per_frame": float(all_d.max()),
            "n_pairs": int(all_d.size)}
