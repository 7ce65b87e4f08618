"""The generators a plan entry can name, one module each, registered in :mod:`.registry` on import.

``docs/generators.md`` lists them with their fields and defaults; it is written from the registry
(``python -m generation.plans.generators``), so the registry is the one place a generator is described.
"""
from . import (  # noqa: F401 - importing a generator's module registers it
    captured,
    captured_file,
    gait_net,
    gesture_net,
    neutral_walk,
    procedural_gesture,
    procedural_walk,
    rbf,
)
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

__all__ = ["ClipGenerationError", "GeneratorSpec", "InputContext", "MakeContext", "PlanInputs",
           "generator_names", "get_generator", "register", "registered", "unregister"]
