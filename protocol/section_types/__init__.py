"""The section types a study section can be, one module each, registered in :mod:`.registry` on import.

``docs/section_types.md`` lists them with their questions, options, clip needs and analyses; it is written from the
registry (``python -m protocol.section_types``), so the registry is the one place a section type is described. The
order of the imports below is the protocol's order (the admin's choices, the docs); the page types
(instruction and break pages, :mod:`.pages`) come last.
"""
from .registry import (  # noqa: I001 - the registry first: the type modules import the vocabulary, which reads it
    Ask,
    ClipNeed,
    Found,
    OptionSpec,
    SectionType,
    UnknownSectionTypeError,
    find_section_type,
    get_section_type,
    is_page_type,
    page_types,
    register,
    registered,
    section_type_names,
    unregister,
)
from . import (  # noqa: F401 - importing a section type's module registers it
    emotion_choice,
    emotion_transition,
    affect_likert,
    naturalness,
    gesture_emotion,
    neutral_validation,
    theme_rating,
    theme_inversion,
    pages,
)

__all__ = ["Ask", "ClipNeed", "Found", "OptionSpec", "SectionType", "UnknownSectionTypeError", "find_section_type",
           "get_section_type", "is_page_type", "page_types", "register", "registered", "section_type_names",
           "unregister"]
