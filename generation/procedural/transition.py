"""Procedural emotion transitions: a SYNTHETIC walk whose gait parameters blend from one emotion's to another's."""
from __future__ import annotations

import numpy as np

from generation.core.motion import Motion
from generation.core.paths import GroundPath
from generation.core.quaternion import np_qfix, np_qslerp
from generation.core.skeleton import gait_skeleton

from .walk import walk


def transition_walk(a, b, path, n_frames: int, fps: float, seed: int | None = None, hold: float = 0.3,
                    n_blend: int = 3, overlap_s: float = 0.4) -> Motion:
    """A procedural walk whose parameters change from ``a`` to ``b`` (WalkParams) along ``path``.

    ``procedural_walk.walk`` keeps its parameters constant, so the walk is made of segments: pure ``a`` for
    the first ``hold`` of the time, ``n_blend`` segments with parameters blended linearly in between, pure
    ``b`` for the last ``hold``. Each segment starts where the previous one stood at that moment (arc
    length along the path and gait phase carried over), and consecutive segments are cross-faded over
    ``overlap_s`` seconds (slerp of rotations, lerp of root positions), so there is no jump. Feet may slide
    slightly during a cross-fade. Synthetic, like every procedural walk (used as the clearly marked
    fallback for gait_net transitions).

    Returns a Motion of ``n_frames`` frames at ``fps`` on the gait skeleton.
    """
    T = int(n_frames)
    weights = [0.0] + [(k + 1) / (n_blend + 1) for k in range(n_blend)] + [1.0]
    mid = (1.0 - 2 * hold) / n_blend
    fractions = [hold] + [mid] * n_blend + [hold]
    bounds = np.round(np.cumsum([0.0] + fractions) * (T - 1)).astype(int)
    overlap = max(1, int(round(overlap_s * fps)))
    arc, phase = 0.0, 0.0
    rot = np.zeros((T, 21, 4))
    root = np.zeros((T, 3))
    done = 0
    segments_meta = []
    for k, w in enumerate(weights):
        params = a.blend(b, w).validate()
        start, stop = int(bounds[k]), (T if k == len(weights) - 1 else int(bounds[k + 1]) + overlap)
        stop = min(stop, T)
        n = stop - start
        if n < 2:
            continue
        # The rest of the path from where this segment starts (the walker continues straight past its end).
        sub = GroundPath(path.point_at(np.arange(arc, arc + params.speed_mps * n / fps + 3.0, 0.02)), path.kind)
        m = walk(params, sub, n, fps, phase=phase, seed=None if seed is None else seed + k)
        seg_rot, seg_root = np_qfix(m.rotations), m.root_positions
        if k == 0:
            rot[start:stop], root[start:stop] = seg_rot, seg_root
        else:
            n_fade = min(overlap, done - start, n)
            if n_fade > 0:
                ramp = (np.arange(1, n_fade + 1) / (n_fade + 1))
                prev = rot[start:start + n_fade]
                cur = seg_rot[:n_fade]
                cur = np.where((prev * cur).sum(-1, keepdims=True) < 0, -cur, cur)
                rot[start:start + n_fade] = np_qslerp(prev, cur, np.broadcast_to(ramp[:, None], prev.shape[:-1]))
                root[start:start + n_fade] = (1 - ramp[:, None]) * root[start:start + n_fade] + \
                    ramp[:, None] * seg_root[:n_fade]
            rot[start + n_fade:stop], root[start + n_fade:stop] = seg_rot[n_fade:], seg_root[n_fade:]
        done = stop
        seg_len = (int(bounds[k + 1]) - start) if k < len(weights) - 1 else n
        arc += params.speed_mps * (m.skeleton.height / 1.75) * seg_len / fps
        phase += seg_len / fps * params.cadence_spm / 120.0
        segments_meta.append({"blend": round(w, 4), "start_frame": start, "params": params.to_dict()})
    meta = {"origin": "procedural", "synthetic": True, "path_kind": path.kind, "transition_segments": segments_meta,
            "transition_method": "segmented procedural walk with cross-fades (generation.procedural.transition)"}
    return Motion(gait_skeleton(), np_qfix(rot), root, fps, meta)
