"""The section-type registry: one declaration per kind of study section, read by the study app (forms, questions,
admin, pools, assignment), the analysis (validation, simulation, agreement, report) and the docs.

A section type is a :class:`SectionType`: its name, the modality of the clips it shows, its questions with their
answer kinds (``protocol.vocabulary``'s answer domains), the option keys it takes and the function that checks
them, the clips.csv fields a clip needs to be shown in it, how the simulator answers it and the report tables and
figures it feeds. A module declares one and calls :func:`register`; ``protocol.section_types`` imports the built-in
modules, so importing it (or anything in ``protocol``) fills the registry. A new section type is one declaration
here, its participant wording (``studyapp.questions.register_wording``) and its analysis (an answer model for
``analysis.simulate`` and, if it has its own table, a report table)::

    register(SectionType(name="arousal", label="Arousal (1..3)", summary="...", modality="gait",
                         questions=(Ask("arousal", AROUSAL),), simulator="1..3, higher for angry walks",
                         analyses=("arousal_means",)))

A *page* type (``page=True``: an instruction page, a break) is a section that shows no clip and asks nothing: the
participant reads it and continues. It is registered here so the admin offers it and ``protocol.pools`` checks its
options, but every list of question-bearing types leaves it out: :func:`registered`, :func:`section_type_names` and
the live views (``protocol.vocabulary.SECTION_TYPES``, ``SECTION_QUESTIONS``, ...) hold the question types only, so
the analysis, the simulator, pools and the answer exports never meet one; :func:`page_types` lists the pages and
``registered(pages=True)`` every type.

Shaped after the generator registry (``generation.plans.generators.registry``). Plain Python: imports nothing of the
project, so ``protocol.vocabulary`` can import it.
"""
from __future__ import annotations

from collections.abc import Callable, Iterator, Mapping, Sequence
from dataclasses import dataclass

Found = list[tuple[tuple[str, ...], str]]
"""(keys, message) pairs: the problems of one field's JSON, each with the keys it is about."""


@dataclass(frozen=True)
class Ask:
    """One question asked about each clip: its key (responses.csv ``question``) and answer kind (the vocabulary's
    answer domain: an integer range or a label set)."""

    key: str
    kind: str


@dataclass(frozen=True)
class OptionSpec:
    """One key of ``Section.options`` a section type takes besides the options of every section, and what it does."""

    key: str
    doc: str


@dataclass(frozen=True)
class ClipNeed:
    """What a clip must carry in clips.csv to be shown in a section: every field of one of ``any_of`` (each a tuple
    of clips.csv columns, non-blank; a label column counts only with a value of its vocabulary), and the sentence a
    validation error ends with."""

    any_of: tuple[tuple[str, ...], ...]
    text: str


@dataclass(frozen=True)
class SectionType:
    """One section type, described once.

    Attributes:
        name: ``Section.section_type`` and responses.csv ``section_type``.
        label: its name in the admin (English).
        summary: one line for the docs: what it asks and where it comes from.
        modality: ``gait`` or ``gesture``, the clips it shows; None: either (and ``other`` imported videos).
        questions: its questions in page order (question key, answer kind).
        options: the ``Section.options`` keys it takes besides every section's (``protocol.pools.COMMON_OPTIONS``).
        check_options: ``check_options(options, clips_per_participant) -> Found``: the problems of its own options
            (each naming its key); None when its options need no check beyond being known.
        norming: it may run as a norming section (``options["norming"]``: intensity and naturalness asked after its
            own questions; ``protocol.norming``).
        sub_pools: the origin halves (``generated``, ``source``) its pool may filter separately and its options
            count (``n_generated``, ``n_source``); empty for none.
        drawn_choices: its one question's choices are drawn per participant and clip from ``options["categories"]``
            (``n_options`` of them, the intended one among them); the answer domain is then the categories.
        clip_need: what a clip must carry in clips.csv (None: nothing beyond a clip id).
        simulator: how ``analysis.simulate`` answers it (one sentence, for the docs); the answer model is registered
            in ``analysis.answer_models`` under the type's name.
        agreement: ``icc`` (intraclass correlation of each question's ratings), ``kappa`` (Fleiss' kappa of each label
            question) or ""; ``agreement_by``: a clips.csv column whose values split the clips into separate rater
            sets (theme_rating: one ICC per theme).
        demographics: the label question whose answers are compared across gender and age group ("": none).
        analyses: the report tables (``analysis.report`` keys) its answers feed.
        figures: the report figures its answers feed.
        page: a page between sections (no clip, no question; the participant continues): no questions, no
            modality, no analyses; left out of every list of question-bearing types.
    """

    name: str
    label: str
    summary: str
    modality: str | None
    questions: tuple[Ask, ...]
    options: tuple[OptionSpec, ...] = ()
    check_options: Callable[[dict, int | None], Found] | None = None
    norming: bool = False
    sub_pools: tuple[str, ...] = ()
    drawn_choices: bool = False
    clip_need: ClipNeed | None = None
    simulator: str = ""
    agreement: str = ""
    agreement_by: str = ""
    demographics: str = ""
    analyses: tuple[str, ...] = ()
    figures: tuple[str, ...] = ()
    module: str = ""
    page: bool = False

    @property
    def question_kinds(self) -> dict[str, str]:
        """question key -> answer kind, in page order."""
        return {ask.key: ask.kind for ask in self.questions}

    @property
    def option_keys(self) -> tuple[str, ...]:
        """Its own ``Section.options`` keys, in declaration order."""
        return tuple(spec.key for spec in self.options)

    @property
    def wording_keys(self) -> tuple[str, ...]:
        """The keys its participant wording must give a text for (studyapp.questions): its question keys."""
        return tuple(ask.key for ask in self.questions)


class UnknownSectionTypeError(KeyError):
    """A section type name that is not registered."""


_REGISTRY: dict[str, SectionType] = {}
AGREEMENT = ("", "icc", "kappa")
MODALITY_VALUES = (None, "gait", "gesture")


def register(spec: SectionType) -> SectionType:
    """Add ``spec`` to the registry (a name registers once); returns it. ValueError naming the declaration's
    problem (no questions, a question key twice, an unknown modality or agreement)."""
    if spec.name in _REGISTRY and _REGISTRY[spec.name] is not spec:
        raise ValueError(f"section type {spec.name!r} is registered already (by {_REGISTRY[spec.name].module})")
    if not spec.name.isidentifier() or len(spec.name) > 30:
        raise ValueError(f"section type {spec.name!r}: the name must be an identifier of at most 30 characters")
    if spec.page:
        _check_page(spec)
    elif not spec.questions:
        raise ValueError(f"section type {spec.name!r}: give at least one question")
    keys = [ask.key for ask in spec.questions]
    if len(set(keys)) != len(keys):
        raise ValueError(f"section type {spec.name!r}: a question key is given twice ({', '.join(keys)})")
    if spec.modality not in MODALITY_VALUES:
        raise ValueError(f"section type {spec.name!r}: modality {spec.modality!r} is not gait, gesture or None")
    if spec.agreement not in AGREEMENT:
        raise ValueError(f"section type {spec.name!r}: agreement {spec.agreement!r} is not icc, kappa or ''")
    if spec.drawn_choices and len(spec.questions) != 1:
        raise ValueError(f"section type {spec.name!r}: drawn choices need exactly one question")
    _REGISTRY[spec.name] = spec
    return spec


def _check_page(spec: SectionType) -> None:
    """ValueError when a page type declares what only a question-bearing type has."""
    extra = [what for what, there in (("questions", spec.questions), ("a modality", spec.modality),
                                      ("analyses", spec.analyses or spec.figures), ("norming", spec.norming),
                                      ("sub-pools", spec.sub_pools), ("drawn choices", spec.drawn_choices),
                                      ("clip needs", spec.clip_need), ("agreement", spec.agreement)) if there]
    if extra:
        raise ValueError(f"section type {spec.name!r} is a page: it takes no {', '.join(extra)}")


def unregister(name: str) -> None:
    """Remove a section type (tests that register toy types clean up with this)."""
    _REGISTRY.pop(name, None)


def get_section_type(name: str) -> SectionType:
    """The declaration of ``name``; UnknownSectionTypeError listing the registered types."""
    try:
        return _REGISTRY[name]
    except KeyError:
        raise UnknownSectionTypeError(f"no section type {name!r} (registered: {', '.join(_REGISTRY)})") from None


def find_section_type(name: str | None) -> SectionType | None:
    """The declaration of ``name``, or None for an unknown (or no) name."""
    return _REGISTRY.get(name or "")


def section_type_names(pages: bool = False) -> tuple[str, ...]:
    """Registered section type names, in registration order: the question-bearing ones (``pages``: every one)."""
    return tuple(t.name for t in registered(pages))


def registered(pages: bool = False) -> tuple[SectionType, ...]:
    """The declarations in registration order (the protocol's order): the question-bearing types, or with ``pages``
    every type, the page types included."""
    return tuple(t for t in _REGISTRY.values() if pages or not t.page)


def page_types() -> tuple[SectionType, ...]:
    """The page types (instruction and break pages), in registration order."""
    return tuple(t for t in _REGISTRY.values() if t.page)


def is_page_type(name: str | None) -> bool:
    """Whether ``name`` is a registered page type (an unknown name is not)."""
    spec = _REGISTRY.get(name or "")
    return spec is not None and spec.page


# ---- live views: the vocabulary's old names, always reading the registry as it is now --------------------------------
def _kept(keep: Callable[[SectionType], bool] | None, pages: bool) -> Iterator[SectionType]:
    """The registered types that pass ``keep`` (all when None), page types only when ``pages``."""
    return (t for t in _REGISTRY.values() if (pages or not t.page) and (keep is None or keep(t)))


class NamesView(Sequence):
    """A read-only tuple-like view of the registered question-bearing names that pass ``keep`` (all when None);
    ``pages``: the page types too."""

    def __init__(self, keep: Callable[[SectionType], bool] | None = None, pages: bool = False):
        self._keep, self._pages = keep, pages

    def _names(self) -> tuple[str, ...]:
        return tuple(t.name for t in _kept(self._keep, self._pages))

    def __getitem__(self, i):
        return self._names()[i]

    def __len__(self) -> int:
        return len(self._names())

    def __contains__(self, name) -> bool:
        return name in self._names()

    def __eq__(self, other) -> bool:
        return tuple(self) == tuple(other) if isinstance(other, (tuple, list, Sequence)) else NotImplemented

    __hash__ = None

    def __repr__(self) -> str:
        return repr(self._names())


class LiveTuple(Sequence):
    """A read-only tuple-like view whose items ``items()`` computes on each use (a name derived from the registry
    that must follow later registrations)."""

    def __init__(self, items: Callable[[], tuple]):
        self._items = items

    def __getitem__(self, i):
        return self._items()[i]

    def __len__(self) -> int:
        return len(self._items())

    def __iter__(self) -> Iterator:
        return iter(self._items())

    def __contains__(self, item) -> bool:
        return item in self._items()

    def __eq__(self, other) -> bool:
        return tuple(self) == tuple(other) if isinstance(other, (tuple, list, Sequence)) else NotImplemented

    __hash__ = None

    def __repr__(self) -> str:
        return repr(self._items())


class TypeMapView(Mapping):
    """A read-only mapping view: registered question-bearing name (passing ``keep``) -> ``value(section type)``;
    ``pages``: the page types too."""

    def __init__(self, value: Callable[[SectionType], object], keep: Callable[[SectionType], bool] | None = None,
                 pages: bool = False):
        self._value, self._keep, self._pages = value, keep, pages

    def _types(self) -> dict[str, SectionType]:
        return {t.name: t for t in _kept(self._keep, self._pages)}

    def __getitem__(self, name: str):
        types = self._types()
        if name not in types:
            raise KeyError(name)
        return self._value(types[name])

    def __iter__(self) -> Iterator[str]:
        return iter(self._types())

    def __len__(self) -> int:
        return len(self._types())

    def __eq__(self, other) -> bool:
        return dict(self) == dict(other) if isinstance(other, Mapping) else NotImplemented

    __hash__ = None

    def __repr__(self) -> str:
        return repr(dict(self))
