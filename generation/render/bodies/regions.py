"""Material regions of a body mesh: clothing (a long-sleeved top, trousers, shoes), skin, hair and eyes.

Regions come from the rig in the rest pose, so they need no texture: each vertex belongs to the bone that weighs
most on it, and that bone's group (head, hands, arms, trunk, legs, feet) gives the region, with the waist (between
anny's ``spine04`` and ``spine03`` heads) splitting top from trousers, the ankle collar of the shoes a few
centimetres above the ankle, and a hair cap over the skull above the brows and behind the ears. Pure numpy.
"""
from __future__ import annotations

import numpy as np

#: Region names, in the order of the indices stored per vertex and face.
REGIONS = ("skin", "top", "trousers", "shoes", "hair", "eyes")


def _group(label: str) -> str:
    base = label.split(".")[0]
    if base in ("eye",):
        return "eyes"
    if base.startswith(("head", "neck")):
        return "head"
    if base.startswith(("wrist", "finger", "metacarpal")):
        return "hand"
    if base.startswith(("clavicle", "shoulder", "upperarm", "lowerarm")):
        return "arm"
    if base.startswith(("foot", "toe")):
        return "foot"
    if base.startswith(("upperleg", "lowerleg", "pelvis")):
        return "leg"
    return "trunk"  # root, spine05..spine01


def vertex_regions(vertices: np.ndarray, bone_labels, bone_heads: np.ndarray, weight_bones: np.ndarray,
                   weights: np.ndarray) -> np.ndarray:
    """(V,) region index (into :data:`REGIONS`) of each rest vertex.

    Args:
        vertices: (V, 3) rest positions, metres, y-up, facing +z.
        bone_labels: (B,) anny bone names; bone_heads: (B, 3) rest head positions.
        weight_bones, weights: (V, K) skinning bones and weights.
    """
    labels = list(bone_labels)
    idx = {name: i for i, name in enumerate(labels)}
    groups = np.array([_group(name) for name in labels])
    top_bone = weight_bones[np.arange(len(vertices)), np.argmax(weights, axis=1)]
    g = groups[top_bone]
    y, z = vertices[:, 1], vertices[:, 2]
    region = np.full(len(vertices), REGIONS.index("skin"))
    waist = 0.5 * (bone_heads[idx["spine04"], 1] + bone_heads[idx["spine03"], 1])
    region[(g == "trunk") & (y >= waist)] = REGIONS.index("top")
    region[(g == "trunk") & (y < waist)] = REGIONS.index("trousers")
    region[g == "arm"] = REGIONS.index("top")
    region[g == "leg"] = REGIONS.index("trousers")
    region[(g == "leg") & (y >= waist)] = REGIONS.index("top")
    ankle = 0.5 * (bone_heads[idx["foot.L"], 1] + bone_heads[idx["foot.R"], 1])
    region[g == "foot"] = REGIONS.index("shoes")
    region[(g == "leg") & (y < ankle + 0.035)] = REGIONS.index("shoes")
    region[g == "eyes"] = REGIONS.index("eyes")
    # Hair: a cap over the skull, from above the brows at the front to the nape behind the ears.
    head = g == "head"
    eye_y = 0.5 * (bone_heads[idx["eye.L"], 1] + bone_heads[idx["eye.R"], 1])
    eye_z = 0.5 * (bone_heads[idx["eye.L"], 2] + bone_heads[idx["eye.R"], 2])
    head_z = bone_heads[idx["head"], 2]
    cap = head & (((y > eye_y + 0.035) & (z < eye_z - 0.005)) | ((y > eye_y - 0.055) & (z < head_z - 0.035)))
    region[cap] = REGIONS.index("hair")
    return region


def face_regions(faces: np.ndarray, vertex_region: np.ndarray) -> np.ndarray:
    """(F,) region of each face: the region most of its three vertices have (the first vertex's on a tie)."""
    r = vertex_region[faces]
    out = r[:, 0].copy()
    out[r[:, 1] == r[:, 2]] = r[r[:, 1] == r[:, 2], 1]
    return out
