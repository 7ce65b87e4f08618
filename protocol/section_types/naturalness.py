"""naturalness: how natural a clip looks, 1..5, any modality; generated and source clips mixed per participant
(seed 000 section 6.3.4, seed 003 section 6.3.2)."""
from __future__ import annotations

from protocol.vocabulary import NATURALNESS, answer_values

from .checks import count_error
from .registry import Ask, Found, OptionSpec, SectionType, register

HALVES = ("generated", "source")
"""The origin halves a naturalness section mixes: its ``generated`` and ``source`` sub-pools and counts."""


def check_options(options: dict, clips_per_participant: int | None) -> Found:
    """Problems of ``anchors`` (scale value -> label), ``question`` (text) and ``n_generated`` / ``n_source`` (how
    each participant's clips split; their sum is the clips per participant)."""
    found: Found = []
    anchors = options.get("anchors")
    scale = answer_values(NATURALNESS)
    if "anchors" in options:
        if not isinstance(anchors, dict):
            found.append((("anchors",), f"'anchors' must map scale values ({', '.join(scale)}) to labels, got "
                                        f"{anchors!r}"))
        else:
            found += [((f"anchors.{k}",), f"'anchors': {k!r} is not a value of the naturalness scale "
                                          f"({', '.join(scale)})") for k in anchors if str(k) not in scale]
            found += [((f"anchors.{k}",), f"'anchors': the label of {k!r} must be text") for k, v in anchors.items()
                      if not isinstance(v, str)]
    if "question" in options and not (isinstance(options["question"], str) and options["question"].strip()):
        found.append((("question",), f"'question' must be non-empty text, got {options['question']!r}"))
    counts = [k for k in ("n_generated", "n_source") if k in options]
    count_errors = [((k,), msg) for k in counts if (msg := count_error(options, k, 0))]
    found += count_errors
    if counts and not count_errors:
        given = {k: options[k] for k in counts}
        both = ("n_generated", "n_source")
        if len(counts) == 1 and not clips_per_participant:
            found.append((both, "give both 'n_generated' and 'n_source' when every clip of the pool is shown"))
        elif len(counts) == 2 and clips_per_participant and sum(given.values()) != clips_per_participant:
            found.append((both, f"'n_generated' + 'n_source' = {sum(given.values())} must equal the clips per "
                                f"participant ({clips_per_participant})"))
        elif len(counts) == 2 and sum(given.values()) == 0:
            found.append((both, "'n_generated' + 'n_source' must be at least 1"))
    return found


SPEC = register(SectionType(
    name="naturalness", label="Naturalness (1..5)",
    summary="Seed 000 6.3.4 and seed 003 6.3.2: how natural and smooth a clip looks, 1..5; generated and source "
            "clips mixed, never a generated clip beside its own source.",
    modality=None, questions=(Ask("naturalness", NATURALNESS),),
    options=(OptionSpec("anchors", "scale value -> label shown under it"),
             OptionSpec("question", "replaces the question's text"),
             OptionSpec("n_generated", "generated clips per participant"),
             OptionSpec("n_source", "source clips per participant")),
    check_options=check_options, sub_pools=HALVES,
    simulator="categorical over 1..5 per (modality, origin)",
    analyses=("naturalness", "naturalness_test", "clip_norms"), figures=("fig_naturalness",), module=__name__))
