"""The study protocol, the ground floor of the project: plain Python that imports nothing of the project.

- :mod:`protocol.vocabulary`: emotions, themes, answer domains and kinds, the public CSV columns, quality checks;
- :mod:`protocol.pools`: a section's pool (catalogue filters) and options, checked without Django;
- :mod:`protocol.presets`: the built-in study designs (sections, pools, texts) and the plans that render their clips;
- :mod:`protocol.norming`: the balanced incomplete design of a norming study.

``generation``, ``analysis`` and ``studyapp`` import from here; nothing here imports them.
"""
from . import section_types  # noqa: F401,E402 - fills the section-type registry the vocabulary's views read
