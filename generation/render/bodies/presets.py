"""Body presets: named sets of anny phenotype parameters, and their validation.

A preset is what a researcher names in a plan (``body_preset: female``); its parameters are anny's continuous
phenotype values in 0..1 (anny 0.6.2, ``Anny.phenotype_labels``): ``gender`` (0 male, 1 female), ``age`` (0.667 a
young adult, 1.0 old; below 0.667 children, which the studies do not use), ``muscle``, ``weight``, ``height`` and
``proportions`` (0.5 average). The shipped presets are exported once with ``python -m generation.render.bodies
build`` into ``generation/data/bodies/<name>.npz``; rendering reads only those files.
"""
from __future__ import annotations

import re

#: The phenotype parameters a preset may set, with anny's default 0.5 for those it leaves out.
PARAMETERS = ("gender", "age", "muscle", "weight", "height", "proportions")
DEFAULTS = {name: 0.5 for name in PARAMETERS}
#: Youngest age a study body may have (anny's "young" anchor: an adult).
MIN_AGE = 0.667

#: The shipped presets. Heights come out about 1.78 m (male) and 1.66 m (female) for adults.
PRESETS: dict[str, dict[str, float]] = {
    "female": {"gender": 1.0, "age": 0.70, "height": 0.40},
    "male": {"gender": 0.0, "age": 0.70, "height": 0.35},
    "female-older": {"gender": 1.0, "age": 1.0, "height": 0.40},
    "male-older": {"gender": 0.0, "age": 1.0, "height": 0.35},
    # anny's weight alone barely changes the build (1-2 cm); with low muscle it gives a heavy body (+5 cm at the waist)
    "female-heavy": {"gender": 1.0, "age": 0.70, "height": 0.40, "weight": 1.0, "muscle": 0.15},
    "male-heavy": {"gender": 0.0, "age": 0.70, "height": 0.35, "weight": 1.0, "muscle": 0.15},
}
#: The preset a gesture or gait gets for a gender when the plan names none (seed 003: the agent's gender picks the
#: body).
BY_GENDER = {"female": "female", "male": "male"}
DEFAULT_PRESET = "male"

_NAME = re.compile(r"^[a-z][a-z0-9-]{0,39}$")


class BodyPresetError(ValueError):
    """An unknown body preset or parameter, or a value out of range; the message names it."""


def check_name(name: str) -> str:
    """``name`` if it is a valid preset file name (lower-case letters, digits, dashes; up to 40), else an error."""
    if not isinstance(name, str) or not _NAME.match(name):
        raise BodyPresetError(f"body preset name {name!r}: expected lower-case letters, digits and dashes "
                              "(at most 40, starting with a letter)")
    return name


def check_parameters(params: dict) -> dict[str, float]:
    """All six phenotype parameters (defaults filled in) after checking names and ranges."""
    if not isinstance(params, dict):
        raise BodyPresetError(f"body parameters: expected a mapping, got {type(params).__name__}")
    unknown = sorted(set(params) - set(PARAMETERS))
    if unknown:
        raise BodyPresetError(f"unknown body parameter(s) {unknown}; expected some of {list(PARAMETERS)}")
    out = dict(DEFAULTS)
    for key, value in params.items():
        if not isinstance(value, (int, float)) or isinstance(value, bool) or not 0.0 <= float(value) <= 1.0:
            raise BodyPresetError(f"body parameter {key!r}: expected a number in 0..1, got {value!r}")
        out[key] = float(value)
    if out["age"] < MIN_AGE:
        raise BodyPresetError(f"body parameter 'age': {out['age']} is a child's body; study bodies are adults "
                              f"(age >= {MIN_AGE})")
    return out


def preset_parameters(name: str) -> dict[str, float]:
    """The full parameters of a shipped preset; an unknown name is refused, listing the known ones."""
    if name not in PRESETS:
        raise BodyPresetError(f"unknown body preset {name!r}; expected one of {sorted(PRESETS)}")
    return check_parameters(PRESETS[name])
