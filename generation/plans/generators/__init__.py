"""The generators a plan entry can name, one module each, registered in :mod:`.registry` on import.

=====================  ========  ==================================================================
generator              modality  module
=====================  ========  ==================================================================
gait_net               gait      :mod:`.gait_net` (seed 000 network; falls back to procedural_walk)
procedural_walk        gait      :mod:`.procedural_walk` (SYNTHETIC)
captured               gait      :mod:`.captured` (shipped real walks)
neutral_walk           gait      :mod:`.neutral_walk` (seed 004's unstyled base)
rbf                    gait      :mod:`.rbf` (seed 004 styles)
gesture_net            gesture   :mod:`.gesture_net` (seed 003 network; falls back to procedural_gesture)
procedural_gesture     gesture   :mod:`.procedural_gesture` (SYNTHETIC)
captured_file          any       :mod:`.captured_file` (an imported motion file)
=====================  ========  ==================================================================

``docs/generators.md`` is written from the registry (``python -m generation.plans.generators``).
"""
from . import captured, captured_file, gait_net, gesture_net, neutral_walk, procedural_gesture, procedural_walk, rbf
from .registry import (
    ClipGenerationError,
    GeneratorSpec,
    InputContext,
    MakeContext,
    PlanInputs,
    generator_names,
    get_generator,
    register,
    registered,
    unregister,
)

BUILTIN_MODULES = (gait_net, procedural_walk, captured, neutral_walk, rbf, gesture_net, procedural_gesture,
                   captured_file)

__all__ = ["BUILTIN_MODULES", "ClipGenerationError", "GeneratorSpec", "InputContext", "MakeContext", "PlanInputs",
           "generator_names", "get_generator", "register", "registered", "unregister"]
