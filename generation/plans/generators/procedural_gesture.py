"""``procedural_gesture``: a SYNTHETIC seated gesture from VAD-driven parameters (generation.procedural); the
fallback of ``gesture_net``."""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from generation.core.motion import Motion
from generation.core.skeleton import gesture_skeleton
from generation.procedural.emotion import gesture_params_for_vad
from generation.procedural.gesture import seated_gesture
from protocol.vocabulary import GENDERS, GESTURE_VAD, HANDEDNESS

from .fields import FieldError, choice, gesture_label, number, vad
from .registry import GeneratorSpec, InputContext, MakeContext, PlanInputs, register

GESTURE_KINDS = ("beat", "pointing", "descriptive")


@dataclass(frozen=True)
class ProceduralGestureInputs(PlanInputs):
    """Exactly one of ``emotion_label`` (an NRC-VAD word) or ``vad``; the gesture ``kind`` (None: chosen by the
    seed), the agent's build and handedness, ``duration_s`` seconds."""

    PLAN_FIELDS = frozenset({"emotion_label", "vad", "kind", "gender", "handedness", "duration_s"})

    gender: str = "female"
    handedness: str = "right"
    duration_s: float = 6.0
    emotion_label: str | None = None
    vad: tuple[float, float, float] | None = None
    kind: str | None = None

    @classmethod
    def parse(cls, raw: dict, context: InputContext) -> ProceduralGestureInputs:
        if ("emotion_label" in raw) == ("vad" in raw):
            raise FieldError("emotion_label", "give exactly one of 'emotion_label' or 'vad' ([v, a, d] in 0..1)")
        kind = raw.get("kind")
        return cls(choice("gender", raw.get("gender", "female"), GENDERS),
                   choice("handedness", raw.get("handedness", "right"), HANDEDNESS),
                   number("duration_s", raw.get("duration_s", 6.0), 1.0, 60.0),
                   gesture_label("emotion_label", raw["emotion_label"]) if "emotion_label" in raw else None,
                   vad("vad", raw["vad"]) if "vad" in raw else None,
                   None if kind is None else choice("kind", kind, GESTURE_KINDS))


def make_procedural_gesture(entry, context: MakeContext) -> Motion:
    inp: ProceduralGestureInputs = entry.inputs
    v, a, d = GESTURE_VAD[inp.emotion_label] if inp.emotion_label is not None else inp.vad
    rng = np.random.default_rng(entry.seed)
    params = gesture_params_for_vad(v, a, d, rng, kind=inp.kind, handedness=inp.handedness)
    n_frames = int(round(inp.duration_s * context.fps))
    motion = seated_gesture(params, n_frames, context.fps, gesture_skeleton(build=inp.gender), seed=entry.seed)
    motion.metadata.update({"emotion_label": inp.emotion_label, "valence": v, "arousal": a, "dominance": d,
                            "gender": inp.gender, "handedness": inp.handedness})
    return motion


SPEC = register(GeneratorSpec(
    name="procedural_gesture", summary="SYNTHETIC seated gesture from VAD-driven parameters (fallback of gesture_net)",
    modality="gesture", origins=("source", "generated"), inputs=ProceduralGestureInputs,
    make=make_procedural_gesture))
