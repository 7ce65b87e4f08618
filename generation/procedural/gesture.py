"""Procedural (synthetic) seated gestures on the 23-joint gesture skeleton.

Seed 003 shows its agents sitting on a chair and gesturing while they narrate or converse; its
start- and end-of-sequence poses are idle sitting poses. This module makes such motion
parametrically: a seated rest pose, and gestures (beat, pointing, descriptive) defined as wrist
targets in front of the trunk, solved with analytic two-bone arm IK, blended in and out of the rest
pose with smooth eases. Trunk slump, shoulder (collar) posture, head pitch and head movement come
from the parameters. Nothing here is captured motion: the metadata says
``{"origin": "procedural", "synthetic": True}``.

Units: metres, seconds, radians; world y-up, the agent faces +z, left = +x.
"""
from __future__ import annotations

import dataclasses
from dataclasses import dataclass

import numpy as np

from generation.core.motion import Motion
from generation.core.quaternion import np_qmul, np_qrot
from generation.core.rigging import axis_angle, hinge_rotations, locals_from_globals, smoothstep, two_bone_ik, yaw_quat
from generation.core.skeleton import GESTURE_JOINTS, Skeleton, gesture_skeleton
from protocol.vocabulary import HANDEDNESS

GESTURE_KINDS = ("beat", "pointing", "descriptive")

_J = {name: i for i, name in enumerate(GESTURE_JOINTS)}
_X = np.array([1.0, 0.0, 0.0])
_Y = np.array([0.0, 1.0, 0.0])
_Z = np.array([0.0, 0.0, 1.0])
_TRUNK = ("chest", "chest2", "chest3", "chest4")

# Seat: the thigh's top rests on the seat; the hip joint centre is this far above the seat surface
# (for a 1.75 m body; scaled with height).
HIP_ABOVE_SEAT_M = 0.07


@dataclass
class GestureParams:
    """One gesture's style.

    Attributes:
        kind: "beat" (rhythmic strokes of one hand), "pointing" (one arm extends toward a target,
            holds, retracts) or "descriptive" (both hands trace a shape in front of the body).
        speed: tempo multiplier, 1 = neutral (beats at 1.6 Hz); 0.3-2.5.
        amplitude: size multiplier of the hand excursions, 1 = neutral; 0.2-1.6.
        expansion: -1 (arms close to the body, rounded shoulders) .. 0 .. +1 (spread arms, elbows
            out, chest open).
        handedness: "left" or "right": the hand that performs one-handed gestures and leads
            two-handed ones.
        head_motion: amplitude in radians of head nods/turns that go with the gesture; 0-0.4.
        head_pitch: static head pitch in radians (+ = looking down); -0.5-0.8.
        torso_lean: trunk slump in radians (+ = collapsed forward, - = upright/leaning back); -0.25-0.5.
    """

    kind: str = "beat"
    speed: float = 1.0
    amplitude: float = 1.0
    expansion: float = 0.0
    handedness: str = "right"
    head_motion: float = 0.1
    head_pitch: float = 0.0
    torso_lean: float = 0.0

    _LIMITS = {"speed": (0.3, 2.5), "amplitude": (0.2, 1.6), "expansion": (-1.0, 1.0), "head_motion": (0.0, 0.4),
               "head_pitch": (-0.5, 0.8), "torso_lean": (-0.25, 0.5)}

    def validate(self) -> GestureParams:
        """Raise ValueError naming the field for an unknown kind/handedness or an out-of-range value."""
        if self.kind not in GESTURE_KINDS:
            raise ValueError(f"GestureParams.kind must be one of {GESTURE_KINDS}, got {self.kind!r}")
        if self.handedness not in HANDEDNESS:
            raise ValueError(f"GestureParams.handedness must be 'left' or 'right', got {self.handedness!r}")
        for name, (lo, hi) in self._LIMITS.items():
            value = getattr(self, name)
            if not isinstance(value, (int, float, np.floating)) or not np.isfinite(value) or not lo <= value <= hi:
                raise ValueError(f"GestureParams.{name}={value!r} must be a number in [{lo}, {hi}]")
        return self

    def to_dict(self) -> dict:
        return {f.name: (getattr(self, f.name) if f.name in ("kind", "handedness") else float(getattr(self, f.name)))
                for f in dataclasses.fields(self)}


def _check_skeleton(skeleton: Skeleton) -> None:
    if tuple(skeleton.joints) != GESTURE_JOINTS:
        raise ValueError(f"seated gestures need the 23-joint gesture skeleton, got {skeleton.name!r} "
                         f"with {skeleton.num_joints} joints")


def _seated_legs(skeleton: Skeleton):
    """Global leg rotations (J-indexed dict) and the root height for the seated pose."""
    off = skeleton.offsets
    ankle_h = -off[_J["left_toe"], 1]
    shin = off[_J["left_ankle"]]
    spread = 0.10
    rots = {}
    for side, prefix in ((1.0, "left_"), (-1.0, "right_")):
        yaw = yaw_quat(side * spread)
        # thigh: hip flexed 90 degrees (knee offset -y -> forward), knees slightly apart
        rots[prefix + "hip"] = np_qmul(yaw, axis_angle(_X, -np.pi / 2))
        # shin: vertical (knee flexed 90 degrees), tilted so the ankle sits under the knee
        tilt = np.arctan2(-shin[2], -shin[1])
        rots[prefix + "knee"] = np_qmul(yaw, axis_angle(_X, -tilt))
        rots[prefix + "ankle"] = yaw
        rots[prefix + "toe"] = yaw
    knee_h = ankle_h + np.linalg.norm(shin)
    hip_h = knee_h  # thigh horizontal
    root_h = hip_h - off[_J["left_hip"], 1]
    return rots, float(root_h), float(hip_h)


def seat_height(skeleton: Skeleton) -> float:
    """Height of the chair seat surface (metres) for the seated pose of ``skeleton``.

    The thighs are horizontal with the hip joints ``HIP_ABOVE_SEAT_M`` (scaled) above the seat;
    0.39 m for the default 1.75 m body (knee joint 0.46 m above the floor).
    """
    _, _, hip_h = _seated_legs(skeleton)
    return hip_h - HIP_ABOVE_SEAT_M * skeleton.height / 1.75


def _trunk_fk(skeleton: Skeleton, G: np.ndarray, root: np.ndarray) -> np.ndarray:
    """Global positions (T, J, 3) from global rotations (T, J, 4) for all joints."""
    T = G.shape[0]
    pos = np.zeros((T, skeleton.num_joints, 3))
    pos[:, 0] = root
    for j, p in enumerate(skeleton.parents):
        if p >= 0:
            pos[:, j] = pos[:, p] + np_qrot(G[:, p], np.broadcast_to(skeleton.offsets[j], (T, 3)))
    return pos


def _rest_wrist_targets(skeleton: Skeleton, pos: np.ndarray) -> dict[str, np.ndarray]:
    """Where the wrists rest on the thighs: half way along the thigh, on top of it."""
    scale = skeleton.height / 1.75
    out = {}
    for side, prefix in ((1.0, "left_"), (-1.0, "right_")):
        hip, knee = pos[..., _J[prefix + "hip"], :], pos[..., _J[prefix + "knee"], :]
        p = hip + 0.5 * (knee - hip)
        p = p + np.array([side * 0.02 * scale, 0.075 * scale, 0.0])
        out[prefix] = p
    return out


def _arm_rotations(shoulder, wrist_target, skeleton: Skeleton, prefix: str, pole):
    """Global upper-arm and forearm rotations (T, 4) reaching ``wrist_target`` with the elbow toward ``pole``."""
    off = skeleton.offsets
    l1 = float(np.linalg.norm(off[_J[prefix + "elbow"]]))
    l2 = float(np.linalg.norm(off[_J[prefix + "wrist"]]))
    elbow, wrist, _ = two_bone_ik(shoulder, wrist_target, l1, l2, pole)
    q_upper, q_fore = hinge_rotations(shoulder, elbow, wrist, off[_J[prefix + "elbow"]], off[_J[prefix + "wrist"]],
                                      _Z, -pole)
    return q_upper, q_fore


def seated_rest_pose(skeleton: Skeleton | None = None) -> tuple[np.ndarray, np.ndarray]:
    """Idle sitting pose of the 23-joint gesture skeleton.

    Hips and knees bent 90 degrees (thighs horizontal, shins vertical, feet flat on the floor),
    trunk upright, arms relaxed with the wrists resting on the middle of the thighs. The chair seat
    is at :func:`seat_height` (0.39 m for the default body); the agent faces +z.

    Returns:
        rotations (J, 4) local unit quaternions, root_position (3,) metres.
    """
    skeleton = skeleton or gesture_skeleton()
    _check_skeleton(skeleton)
    rot, root = _pose_frames(skeleton, [GestureParams()], n_frames=1, fps=30.0, rng=None, rest_only=True)
    return rot[0], root[0]


def _envelopes(n_frames: int, n_segments: int, fps: float, ease_s: float):
    """Global ease envelope E (T,) and per-segment weights C (K, T) that sum to 1.

    E rises from 0 to 1 over ``ease_s`` seconds after the start and falls back to 0 before the
    end (a short rest hold at both ends); segments share the active span equally and cross-fade.
    """
    t = np.arange(n_frames) / fps
    dur = n_frames / fps
    hold = min(0.25, 0.1 * dur)
    ease = min(ease_s, max(1.0 / fps, 0.25 * (dur - 2 * hold)))
    E = smoothstep((t - hold) / ease) * smoothstep((dur - hold - (1.0 / fps) - t) / ease)
    bounds = np.linspace(hold, dur - hold, n_segments + 1)
    fade = min(0.3, 0.25 * (bounds[1] - bounds[0])) if n_segments > 1 else 0.0
    C = np.zeros((n_segments, n_frames))
    for k in range(n_segments):
        lo = smoothstep((t - bounds[k] + fade / 2) / fade) if (k > 0 and fade > 0) else np.ones_like(t)
        hi = smoothstep((bounds[k + 1] + fade / 2 - t) / fade) if (k < n_segments - 1 and fade > 0) else np.ones_like(t)
        C[k] = lo * hi
    C /= np.maximum(C.sum(0, keepdims=True), 1e-9)
    local = np.zeros((n_segments, n_frames))
    for k in range(n_segments):
        local[k] = (t - bounds[k]) / max(bounds[k + 1] - bounds[k], 1e-6)
    return E, C, local, t


def _gesture_offsets(p: GestureParams, tau: np.ndarray, t: np.ndarray, rng_vals: dict, scale: float):
    """Hand targets for one gesture, in the thorax frame relative to each shoulder.

    Returns {"left_": (T, 3), "right_": (T, 3)} offsets (metres) and head (nod, yaw) signals (T,), (T,).
    """
    lead = p.handedness + "_"
    other = "left_" if lead == "right_" else "right_"
    A = p.amplitude * scale
    ex = p.expansion
    f_beat = 1.6 * p.speed
    out = {}
    # Neutral gesture space: in front of the lower chest.
    for prefix in ("left_", "right_"):
        side = 1.0 if prefix == "left_" else -1.0
        out[prefix] = np.tile(np.array([side * (-0.04 + 0.10 * ex) * scale, -0.33 * scale, 0.30 * scale]),
                              (len(t), 1))
    phase0 = rng_vals["phase"]
    nod = np.zeros_like(t)
    turn = np.zeros_like(t)
    side_lead = 1.0 if lead == "left_" else -1.0
    if p.kind == "beat":
        stroke = np.abs(np.sin(np.pi * f_beat * t + phase0)) ** 1.5
        out[lead] = out[lead] + np.stack([np.zeros_like(t) + side_lead * 0.04 * ex * scale,
                                          0.06 * scale - 0.10 * A * stroke,
                                          0.03 * A * (1 - stroke)], axis=1)
        # the other hand stays low, near its rest on the thigh side of the gesture space
        out[other] = out[other] + np.array([0.0, -0.10 * scale, -0.12 * scale])
        nod = np.sin(np.pi * f_beat * t + phase0) ** 2 - 0.5
    elif p.kind == "pointing":
        reach = np.clip(tau, 0.0, 1.0)
        extend = smoothstep(reach / 0.3) * smoothstep((1.0 - reach) / 0.25)
        direction = np.array([side_lead * (0.15 + 0.25 * max(ex, -0.5) + rng_vals["aim"]), 0.05, 1.0])
        direction /= np.linalg.norm(direction)
        target = direction * 0.50 * scale + np.array([0.0, (0.02 + 0.06 * A) * scale, 0.0])
        base = out[lead][0]
        wobble = 0.01 * A * np.sin(2 * np.pi * 0.8 * p.speed * t)
        out[lead] = base + extend[:, None] * (target - base) + np.stack([0 * t, wobble, 0 * t], axis=1)
        out[other] = out[other] + np.array([0.0, -0.10 * scale, -0.12 * scale])
        nod = extend * 0.5
        turn = extend * side_lead * 0.6
    elif p.kind == "descriptive":
        cycles = max(1.0, round(1.0 * p.speed * rng_vals["span_s"]))
        s = 0.5 - 0.5 * np.cos(2 * np.pi * cycles * np.clip(tau, 0, 1))
        width = (0.05 + 0.16 * A) * (1.0 + 0.5 * ex)
        for prefix, gain in ((lead, 1.0), (other, 0.75)):
            side = 1.0 if prefix == "left_" else -1.0
            out[prefix] = out[prefix] + np.stack([
                side * (width * gain * s - 0.02 * scale),
                0.04 * scale + 0.08 * A * gain * np.sin(np.pi * s),
                0.05 * A * gain * np.sin(2 * np.pi * cycles * np.clip(tau, 0, 1) + rng_vals["phase"]) + 0.02 * scale,
            ], axis=1)
        nod = 0.5 * np.sin(2 * np.pi * cycles * np.clip(tau, 0, 1))
        turn = 0.3 * np.sin(np.pi * cycles * np.clip(tau, 0, 1))
    return out, nod, turn


def _pose_frames(skeleton: Skeleton, params_list, n_frames: int, fps: float, rng, rest_only: bool = False):
    """Local rotations (T, J, 4) and root positions (T, 3) for a sequence of gestures."""
    T = n_frames
    scale = skeleton.height / 1.75
    legs, root_h, _ = _seated_legs(skeleton)
    root = np.tile(np.array([0.0, root_h, 0.0]), (T, 1))
    G = np.zeros((T, skeleton.num_joints, 4))
    G[..., 0] = 1.0
    for name, q in legs.items():
        G[:, _J[name]] = q
    if rest_only:
        E = np.zeros(T)
        C = np.ones((1, T))
        local_tau = np.zeros((1, T))
        t = np.arange(T) / fps
    else:
        E, C, local_tau, t = _envelopes(T, len(params_list), fps, ease_s=0.5)
    # Style values blend between segments with the same weights; posture eases in with E.
    def mix(name):
        return sum(C[k] * getattr(p, name) for k, p in enumerate(params_list))

    lean = E * mix("torso_lean")
    expansion = E * mix("expansion")
    head_pitch = E * mix("head_pitch")
    head_motion = E * mix("head_motion")
    # Trunk: slump split over the four chest joints; a slight lean back when upright.
    for i, name in enumerate(_TRUNK):
        # global pitch grows along the spine, so the chest4 (thorax) is pitched by the full lean
        G[:, _J[name]] = axis_angle(_X, lean * (i + 1) / len(_TRUNK))
    trunk_global = G[:, _J["chest4"]]
    # Collars: shoulders rolled forward and down when contracted, back and up when expanded.
    for side, prefix in ((1.0, "left_"), (-1.0, "right_")):
        roll = axis_angle(_Z, side * 0.10 * expansion)       # raise (+) / drop (-) the shoulder
        protract = axis_angle(_Y, side * 0.25 * np.minimum(expansion, 0.0) * -1.0)  # forward when contracted
        G[:, _J[prefix + "collar"]] = np_qmul(np_qmul(trunk_global, protract), roll)
    pos = _trunk_fk(skeleton, G, root)
    rest_wrists = _rest_wrist_targets(skeleton, pos)

    # Gesture hand targets.
    targets = {k: np.zeros((T, 3)) for k in ("left_", "right_")}
    nod = np.zeros(T)
    turn = np.zeros(T)
    rng = rng if rng is not None else np.random.default_rng(0)
    for k, p in enumerate(params_list):
        span_s = (np.count_nonzero(C[k] > 0.5) / fps) if not rest_only else 1.0
        rng_vals = {"phase": float(rng.uniform(0, np.pi)), "aim": float(rng.normal(0, 0.08)), "span_s": span_s}
        offsets, n_k, t_k = _gesture_offsets(p, local_tau[k], t, rng_vals, scale)
        for prefix in ("left_", "right_"):
            world = pos[:, _J[prefix + "shoulder"]] + np_qrot(trunk_global, offsets[prefix])
            targets[prefix] += C[k][:, None] * world
        nod += C[k] * n_k
        turn += C[k] * t_k
    for prefix in ("left_", "right_"):
        targets[prefix] = rest_wrists[prefix] + E[:, None] * (targets[prefix] - rest_wrists[prefix])

    # Arms by IK; elbows point down, back and out, more out when expanded
    for side, prefix in ((1.0, "left_"), (-1.0, "right_")):
        # (down and back, so it never lines up with an arm reaching forward or resting on the thigh)
        pole = np.stack([side * (0.4 + 0.6 * np.maximum(expansion, -0.3)), -np.ones(T), -0.6 * np.ones(T)], axis=1)
        pole = np_qrot(trunk_global, pole)
        q_up, q_fore = _arm_rotations(pos[:, _J[prefix + "shoulder"]], targets[prefix], skeleton, prefix, pole)
        G[:, _J[prefix + "shoulder"]] = q_up
        G[:, _J[prefix + "elbow"]] = q_fore
        G[:, _J[prefix + "wrist"]] = q_fore
    # Head: static pitch, nods and turns scaled by head_motion.
    neck_pitch = 0.4 * head_pitch - 0.5 * lean
    head_pitch_total = 0.6 * head_pitch + head_motion * 0.6 * nod
    G[:, _J["neck"]] = np_qmul(trunk_global, np_qmul(yaw_quat(0.4 * head_motion * turn), axis_angle(_X, neck_pitch)))
    G[:, _J["head"]] = np_qmul(G[:, _J["neck"]], np_qmul(yaw_quat(0.6 * head_motion * turn),
                                                         axis_angle(_X, head_pitch_total)))
    return locals_from_globals(G, skeleton.parents), root


def seated_gesture(params, n_frames: int = 120, fps: float = 30.0, skeleton: Skeleton | None = None,
                   seed: int | None = None) -> Motion:
    """A synthetic seated gesture sequence that starts and ends in :func:`seated_rest_pose`.

    Args:
        params: one :class:`GestureParams` or a sequence of them, performed one after the other
            (the active time is split equally, with cross-fades between them).
        n_frames: T, number of frames (at least 8).
        fps: frame rate.
        skeleton: 23-joint gesture skeleton (default 1.75 m male).
        seed: random details (beat phase, pointing aim); None = seed 0.

    Returns:
        Motion with rotations (T, 23, 4) and a fixed root; metadata {"origin": "procedural",
        "synthetic": True, "params": [...], "seat_height_m": ...}.
    """
    skeleton = skeleton or gesture_skeleton()
    _check_skeleton(skeleton)
    params_list = [params] if isinstance(params, GestureParams) else list(params)
    if not params_list:
        raise ValueError("seated_gesture needs at least one GestureParams")
    for i, p in enumerate(params_list):
        if not isinstance(p, GestureParams):
            raise TypeError(f"params[{i}] must be GestureParams, got {type(p).__name__}")
        p.validate()
    if int(n_frames) < 8:
        raise ValueError(f"n_frames must be at least 8, got {n_frames}")
    if not fps > 0:
        raise ValueError(f"fps must be positive, got {fps}")
    rng = np.random.default_rng(0 if seed is None else seed)
    rot, root = _pose_frames(skeleton, params_list, int(n_frames), float(fps), rng)
    metadata = {
        "origin": "procedural",
        "synthetic": True,
        "generator": "generation.procedural.gesture",
        "params": [p.to_dict() for p in params_list],
        "seat_height_m": seat_height(skeleton),
        "seed": seed,
    }
    return Motion(skeleton, rot, root, fps, metadata)
