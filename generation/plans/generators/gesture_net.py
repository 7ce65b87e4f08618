"""``gesture_net``: seed 003's text-to-gesture transformer gestures a sentence with an emotion (NRC-VAD word).

Falls back to ``procedural_gesture`` (recorded as such, SYNTHETIC) while its weights are missing."""
from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path

from generation.core.motion import Motion
from generation.core.splits import SPLITS
from generation.gesture.config import gesture_seconds
from generation.gesture.range_fit import fit_closest_range
from protocol.vocabulary import GENDERS, GESTURE_TASKS, HANDEDNESS

from .fields import FieldError, choice, gesture_label, number, text
from .procedural_gesture import ProceduralGestureInputs
from .registry import GeneratorSpec, InputContext, MakeContext, PlanInputs, register

WEIGHTS_FILE = Path(__file__).resolve().parents[2] / "data" / "weights" / "gesture_net_default.pt"
#: ``real_range``: ``closest`` (default) scales the gesture's amplitude about its mean pose into the real captured
#: range of the closest captured emotion where one factor can (generation.gesture.range_fit); ``off`` keeps the
#: network's output as it is.
REAL_RANGE = ("closest", "off")
#: Splits of the network's sentence corpus (generation.gesture.data.split_sentences): an entry may record which
#: one its sentence comes from (held-out inputs are "test").


@dataclass(frozen=True)
class GestureNetInputs(PlanInputs):
    """The spoken ``sentence``, the ``task``, the ``emotion_label``, the agent's build and handedness, latent
    ``noise`` (0..1), optionally the corpus split the sentence comes from, and ``real_range`` (``closest``: the
    amplitude and shoulder posture fitted into the real captured range of the closest captured emotion, or ``off``)."""

    PLAN_FIELDS = frozenset({"sentence", "task", "emotion_label", "gender", "handedness", "noise", "sentence_split",
                             "real_range"})

    sentence: str
    task: str
    emotion_label: str
    gender: str = "female"
    handedness: str = "right"
    noise: float = 0.0
    sentence_split: str | None = None
    real_range: str = "closest"

    @classmethod
    def parse(cls, raw: dict, context: InputContext) -> GestureNetInputs:
        sentence = text("sentence", raw.get("sentence"))
        task = choice("task", raw.get("task", GESTURE_TASKS[0]), GESTURE_TASKS)
        if "emotion_label" not in raw:
            raise FieldError("emotion_label", "required (an NRC-VAD word, e.g. proud)")
        return cls(sentence, task, gesture_label("emotion_label", raw["emotion_label"]),
                   choice("gender", raw.get("gender", "female"), GENDERS),
                   choice("handedness", raw.get("handedness", "right"), HANDEDNESS),
                   number("noise", raw.get("noise", 0.0), 0.0, 1.0),
                   choice("sentence_split", raw["sentence_split"], SPLITS) if "sentence_split" in raw
                   else None, choice("real_range", raw.get("real_range", REAL_RANGE[0]), REAL_RANGE))


def to_procedural_gesture(inputs: GestureNetInputs, fallback: str) -> PlanInputs:
    """As long as the network would gesture the sentence (2..60 s), same label, build and handedness."""
    seconds = float(gesture_seconds(len(inputs.sentence.split())))
    return ProceduralGestureInputs(inputs.gender, inputs.handedness, round(min(max(seconds, 2.0), 60.0), 3),
                                   emotion_label=inputs.emotion_label)


def make_gesture_net(entry, context: MakeContext) -> Motion:
    from generation.gesture.generate import generate_gesture  # torch; optional (clipgen.availability)

    inp: GestureNetInputs = entry.inputs
    motion = generate_gesture(inp.sentence, inp.task, inp.emotion_label, inp.gender, inp.handedness, fps=context.fps,
                              seed=entry.seed, noise=inp.noise)
    return motion if inp.real_range == "off" else fit_closest_range(motion, inp.emotion_label)


SPEC = register(GeneratorSpec(
    name="gesture_net", summary="seed 003 text-to-gesture transformer: a sentence gestured with an emotion",
    modality="gesture", origins=("generated",), inputs=GestureNetInputs, make=make_gesture_net,
    requires=("generation.gesture.generate",), fallbacks=("procedural_gesture",),
    fallback_inputs=to_procedural_gesture, weights=lambda inputs: WEIGHTS_FILE))
