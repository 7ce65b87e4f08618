"""The generator registry: one declaration per generator, read by the plan schema, clip generation, the
catalogue and the docs.

A generator is a :class:`GeneratorSpec`: its name, the modality it makes, the origins a plan may give its clips,
its typed inputs (a :class:`PlanInputs` subclass that parses and validates the plan fields), the generators it
may fall back to, its network weights, and the function that makes the motion. A module declares one and calls
:func:`register`; ``generation.plans.generators`` imports the built-in modules, so importing it fills the
registry. A new generator is one module plus one registration::

    @dataclass(frozen=True)
    class StandStillInputs(PlanInputs):
        PLAN_FIELDS = frozenset({"duration_s"})
        duration_s: float = 5.0

        @classmethod
        def parse(cls, raw, context):
            return cls(number("duration_s", raw.get("duration_s", context.duration_s), 1.0, 60.0))

    register(GeneratorSpec(name="stand_still", summary="...", modality="gait", origins=("generated",),
                           inputs=StandStillInputs, make=make_stand_still))

Shaped after torchvision's ``register_model``: the registration is the one place a generator is described.
"""
from __future__ import annotations

import dataclasses
import functools
from collections.abc import Callable, Iterator, Mapping
from dataclasses import dataclass
from pathlib import Path
from typing import Any, ClassVar

from generation.core.motion import Motion
from protocol.vocabulary import FINAL_EMOTION_COLUMNS, GAIT_EMOTIONS, GESTURE_VAD, VAD_DIMENSIONS

from .fields import FieldError


class ClipGenerationError(RuntimeError):
    """A plan entry could not be turned into motion; the message names the entry and the cause."""


#: Intent columns of clips.csv that a generator fills (DESIGN.md "Interchange formats"); blank = None.
INTENT_COLUMNS = (*GAIT_EMOTIONS, *FINAL_EMOTION_COLUMNS, "emotion_label", *VAD_DIMENSIONS, "theme", "weight",
                  "n_features")


@dataclass(frozen=True)
class InputContext:
    """What a generator's inputs may default to: the entry's render duration (seconds) and modality."""

    duration_s: float
    modality: str


def _plain(value):
    """Tuples as lists, nested dataclasses as dicts, None-valued fields dropped (JSON- and hash-ready)."""
    if dataclasses.is_dataclass(value) and not isinstance(value, type):
        return {f.name: _plain(getattr(value, f.name)) for f in dataclasses.fields(value)
                if getattr(value, f.name) is not None}
    if isinstance(value, (list, tuple)):
        return [_plain(v) for v in value]
    return value


@dataclass(frozen=True)
class PlanInputs(Mapping):
    """Typed, validated inputs of one generator; read-only mapping of the plan fields for hashes and records.

    Subclasses are frozen dataclasses that declare ``PLAN_FIELDS`` (the fields a plan entry may give) and
    ``parse`` (raw plan fields -> instance, raising :class:`FieldError` that names the field). The mapping view
    (:meth:`as_dict`) holds the normalised values with None-valued fields left out; it is what the clip hash and
    the clip record store.
    """

    PLAN_FIELDS: ClassVar[frozenset[str]] = frozenset()

    @classmethod
    def parse(cls, raw: dict, context: InputContext) -> PlanInputs:
        raise NotImplementedError

    @functools.cached_property
    def _view(self) -> dict:
        return _plain(self)

    def as_dict(self) -> dict:
        """A copy of the normalised inputs: numbers, strings, lists and dicts only."""
        return _plain(self)

    def __getitem__(self, key: str):
        return self._view[key]

    def __iter__(self) -> Iterator[str]:
        return iter(self._view)

    def __len__(self) -> int:
        return len(self._view)

    def intent(self, modality: str) -> dict:
        """The clips.csv intent columns (:data:`INTENT_COLUMNS`, blank = None) these inputs ask for: a gait
        emotion vector or transition, a gesture's NRC-VAD label and VAD."""
        out = dict.fromkeys(INTENT_COLUMNS)
        emotion, transition = self.get("emotion"), self.get("transition")
        if emotion is not None:
            out.update(zip(GAIT_EMOTIONS, emotion, strict=True))
        elif transition is not None:
            out.update(zip(GAIT_EMOTIONS, transition["initial"], strict=True))
            out.update(zip(FINAL_EMOTION_COLUMNS, transition["final"], strict=True))
        if modality == "gesture":
            if self.get("emotion_label") is not None:
                out["emotion_label"] = self["emotion_label"]
                out.update(zip(VAD_DIMENSIONS, GESTURE_VAD[self["emotion_label"]], strict=True))
            elif self.get("vad") is not None:
                out.update(zip(VAD_DIMENSIONS, self["vad"], strict=True))
        return out


@dataclass(frozen=True)
class MakeContext:
    """How a motion is made: the output frame rate (frames/s) and the torch device of network generators."""

    fps: float
    device: str = "cpu"


@dataclass(frozen=True)
class GeneratorSpec:
    """One generator, described once.

    Attributes:
        name: the plan's ``generator`` value.
        summary: one line for the docs.
        modality: ``gait`` or ``gesture``; None when the entry's ``modality`` says (an imported file).
        origins: the clips.csv origins a plan may give its clips; the first is the default.
        inputs: the typed inputs class (parses and validates the plan fields).
        make: ``make(entry, context) -> Motion`` for an entry of this generator.
        requires: modules that must import for the generator to run (checked before rendering; heavy ones such
            as the networks are imported only there and in ``make``); with the module of ``make`` they are the
            roots of the generator's source digest.
        fallbacks: generators a plan may name as ``fallback`` while this one is unavailable.
        fallback_inputs: ``fallback_inputs(inputs, fallback_name) -> PlanInputs`` re-expresses the inputs for a
            fallback (the intent unchanged); None keeps them as they are.
        weights: ``weights(inputs) -> Path``, the network weights file an entry's motion is made with (``inputs``
            None: the default file); its digest goes into the clip hash, and a missing file makes the generator
            unavailable.
        version: bump to re-render every clip of the generator (code changes re-render by themselves).
        loops: the player loops its clips by default (walk cycles).
        captured: its output is captured motion, not synthesised (the clip is not marked synthetic).
    """

    name: str
    summary: str
    modality: str | None
    origins: tuple[str, ...]
    inputs: type[PlanInputs]
    make: Callable[[Any, MakeContext], Motion]  # (generation.plans.schema.ClipEntry, context) -> Motion
    requires: tuple[str, ...] = ()
    fallbacks: tuple[str, ...] = ()
    fallback_inputs: Callable[[PlanInputs, str], PlanInputs] | None = None
    weights: Callable[[PlanInputs | None], Path] | None = None
    version: str = "1"
    loops: bool = False
    captured: bool = False

    @property
    def fields(self) -> frozenset[str]:
        """The generator's own plan fields (beside the fields every entry has)."""
        return self.inputs.PLAN_FIELDS

    @property
    def module(self) -> str:
        """The module that declares ``make``."""
        return self.make.__module__


_REGISTRY: dict[str, GeneratorSpec] = {}


class UnknownGeneratorError(KeyError):
    """A generator name that is not registered."""


def register(spec: GeneratorSpec) -> GeneratorSpec:
    """Add ``spec`` to the registry (a name registers once); returns it."""
    if spec.name in _REGISTRY and _REGISTRY[spec.name] is not spec:
        raise ValueError(f"generator {spec.name!r} is registered already (by {_REGISTRY[spec.name].module})")
    if not spec.origins:
        raise ValueError(f"generator {spec.name!r}: give at least one origin")
    _REGISTRY[spec.name] = spec
    return spec


def unregister(name: str) -> None:
    """Remove a generator (tests that register toy generators clean up with this)."""
    _REGISTRY.pop(name, None)


def get_generator(name: str) -> GeneratorSpec:
    try:
        return _REGISTRY[name]
    except KeyError:
        raise UnknownGeneratorError(f"no generator {name!r} (registered: {', '.join(generator_names())})") from None


def generator_names() -> tuple[str, ...]:
    """Registered generator names, in registration order."""
    return tuple(_REGISTRY)


def registered() -> tuple[GeneratorSpec, ...]:
    return tuple(_REGISTRY.values())


__all__ = ["ClipGenerationError", "FieldError", "GeneratorSpec", "INTENT_COLUMNS", "InputContext", "MakeContext",
           "PlanInputs", "UnknownGeneratorError", "generator_names", "get_generator", "register", "registered",
           "unregister"]
