"""Validators of plan fields shared by the generators' inputs; each raises :class:`FieldError` naming the field."""
from __future__ import annotations

import math
from dataclasses import dataclass

from protocol.vocabulary import GAIT_EMOTIONS, GESTURE_VAD


class FieldError(Exception):
    """A bad plan field: ``field`` names it, ``message`` says what was expected (the schema adds the entry)."""

    def __init__(self, field_name: str, message: str):
        super().__init__(message)
        self.field = field_name
        self.message = message


def number(name: str, value, lo: float | None = None, hi: float | None = None) -> float:
    if isinstance(value, bool) or not isinstance(value, (int, float)) or not math.isfinite(value):
        raise FieldError(name, f"expected a number, got {value!r}")
    if (lo is not None and value < lo) or (hi is not None and value > hi):
        raise FieldError(name, f"expected a number in [{lo}, {hi}], got {value!r}")
    return float(value)


def integer(name: str, value, lo: int | None = None, hi: int | None = None) -> int:
    if isinstance(value, bool) or not isinstance(value, int):
        raise FieldError(name, f"expected an integer, got {value!r}")
    if (lo is not None and value < lo) or (hi is not None and value > hi):
        raise FieldError(name, f"expected an integer in [{lo}, {hi}], got {value!r}")
    return int(value)


def choice(name: str, value, choices) -> str:
    if not isinstance(value, str) or value not in choices:
        raise FieldError(name, f"expected one of {list(choices)}, got {value!r}")
    return value


def text(name: str, value) -> str:
    if not isinstance(value, str) or not value.strip():
        raise FieldError(name, f"expected non-empty text, got {value!r}")
    return value.strip()


def flag(name: str, value) -> bool:
    if not isinstance(value, bool):
        raise FieldError(name, f"expected true or false, got {value!r}")
    return value


def gait_emotion(name: str, value) -> tuple[float, ...]:
    """A gait emotion vector: non-negative numbers in GAIT_EMOTIONS order, a mapping or one emotion name;
    l1-normalised (6 decimals)."""
    if isinstance(value, str) and value in GAIT_EMOTIONS:
        value = [1.0 if e == value else 0.0 for e in GAIT_EMOTIONS]
    if isinstance(value, dict):
        unknown = set(value) - set(GAIT_EMOTIONS)
        if unknown:
            raise FieldError(name, f"unknown emotion(s) {sorted(unknown)}; expected keys of {list(GAIT_EMOTIONS)}")
        value = [value.get(e, 0.0) for e in GAIT_EMOTIONS]
    if not isinstance(value, (list, tuple)) or len(value) != len(GAIT_EMOTIONS):
        raise FieldError(name, f"expected {len(GAIT_EMOTIONS)} numbers ({', '.join(GAIT_EMOTIONS)}), got {value!r}")
    vec = [number(name, v, 0.0) for v in value]
    total = sum(vec)
    if total <= 0:
        raise FieldError(name, f"expected at least one positive component, got {value!r}")
    return tuple(round(v / total, 6) for v in vec)


def gesture_label(name: str, value) -> str:
    """An NRC-VAD emotion word of the gesture vocabulary (lower case)."""
    if not isinstance(value, str) or value.strip().lower() not in GESTURE_VAD:
        raise FieldError(name, f"expected an NRC-VAD emotion word ({', '.join(sorted(GESTURE_VAD))}), got {value!r}")
    return value.strip().lower()


def vad(name: str, value) -> tuple[float, float, float]:
    """[valence, arousal, dominance], each in 0..1."""
    if not isinstance(value, (list, tuple)) or len(value) != 3:
        raise FieldError(name, f"expected [valence, arousal, dominance] in 0..1, got {value!r}")
    return tuple(number(name, v, 0.0, 1.0) for v in value)


TRAJECTORY_KINDS = ("straight", "curved", "sharp_turn")
_TRAJECTORY_FIELDS = {"straight": {"kind", "length_m"}, "curved": {"kind", "length_m", "radius_m", "angle_deg"},
                      "sharp_turn": {"kind", "length_m", "angle_deg", "at_fraction"}}


@dataclass(frozen=True)
class Trajectory:
    """A walk's ground path: kind, length (m); curves: radius (m) and swept angle (degrees); sharp turns: the
    turn angle (degrees) and where along the path it happens (fraction of the length)."""

    kind: str = "straight"
    length_m: float = 14.0
    radius_m: float | None = None
    angle_deg: float | None = None
    at_fraction: float | None = None

    @classmethod
    def parse(cls, value) -> Trajectory:
        if value is None:
            value = {"kind": "straight"}
        if isinstance(value, str):
            value = {"kind": value}
        if not isinstance(value, dict):
            raise FieldError("trajectory", f"expected a mapping with 'kind', got {value!r}")
        kind = choice("trajectory.kind", value.get("kind", "straight"), TRAJECTORY_KINDS)
        allowed = _TRAJECTORY_FIELDS[kind]
        unknown = set(value) - allowed
        if unknown:
            raise FieldError(f"trajectory.{sorted(unknown)[0]}", f"not used by a {kind} trajectory "
                                                                f"(allowed: {sorted(allowed)})")
        length = number("trajectory.length_m", value.get("length_m", 14.0), 1.0, 200.0)
        if kind == "curved":
            return cls(kind, length, radius_m=number("trajectory.radius_m", value.get("radius_m", 4.0), 0.5, 100.0),
                       angle_deg=number("trajectory.angle_deg", value.get("angle_deg", 90.0), -720.0, 720.0))
        if kind == "sharp_turn":
            return cls(kind, length, angle_deg=number("trajectory.angle_deg", value.get("angle_deg", 90.0),
                                                      -179.0, 179.0),
                       at_fraction=number("trajectory.at_fraction", value.get("at_fraction", 0.5), 0.05, 0.95))
        return cls(kind, length)
