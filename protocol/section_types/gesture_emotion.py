"""gesture_emotion: which emotion a seated gesture shows, among a few offered categories (seed 003 section 6.3.1)."""
from __future__ import annotations

from protocol.norming import NORMING_OPTION
from protocol.vocabulary import GESTURE_CHOICE, GESTURE_EMOTIONS, VAD_DIMENSIONS

from .checks import count_error
from .registry import Ask, ClipNeed, Found, OptionSpec, SectionType, register

DEFAULT_OPTIONS = 4
"""Answer options shown when the section does not set ``n_options``."""


def check_options(options: dict, clips_per_participant: int | None) -> Found:
    """Problems of ``categories`` (gesture emotions offered) and ``n_options`` (2 .. the number of categories)."""
    found: Found = []
    categories = options.get("categories", list(GESTURE_EMOTIONS))
    if not isinstance(categories, list) or not categories or not all(isinstance(c, str) for c in categories):
        found.append((("categories",), f"'categories' must be a non-empty list of gesture emotions, got "
                                       f"{categories!r}"))
        categories = list(GESTURE_EMOTIONS)
    else:
        found += [(("categories",), f"'categories': {c!r} is not one of {', '.join(GESTURE_EMOTIONS)}")
                  for c in categories if c not in GESTURE_EMOTIONS]
        if len(set(categories)) != len(categories):
            found.append((("categories",), "'categories' lists an emotion twice"))
    if "n_options" in options:
        msg = count_error(options, "n_options", 2, len(set(categories)))
        found += [(("n_options",), msg)] if msg else []
    elif len(set(categories)) < DEFAULT_OPTIONS:
        found.append((("categories",), f"'categories' needs at least {DEFAULT_OPTIONS} emotions (or set "
                                       "'n_options')"))
    return found


SPEC = register(SectionType(
    name="gesture_emotion", label="Perceived gesture emotion (4 options)",
    summary="Seed 003 6.3.1: the emotion of a seated gesture, one of n_options categories drawn per participant "
            "and clip (the intended one among them).",
    modality="gesture", questions=(Ask("perceived", GESTURE_CHOICE),),
    options=(OptionSpec("n_options", f"answer options shown (default {DEFAULT_OPTIONS})"),
             OptionSpec("categories", "the gesture emotions offered (default all)"),
             OptionSpec(NORMING_OPTION, "norming section: {\"ratings_per_clip\": K} (protocol.norming)")),
    check_options=check_options, norming=True, drawn_choices=True,
    clip_need=ClipNeed((("emotion_label",), VAD_DIMENSIONS),
                       f"needs an NRC-VAD emotion_label or {'/'.join(VAD_DIMENSIONS)} in clips.csv"),
    simulator="among the offered choices, choice i with probability proportional to exp(-|VAD_i - VAD_intended| / "
              "gesture_temperature)",
    agreement="kappa", demographics="perceived",
    analyses=("vad_pearson", "demographic_differences", "agreement", "clip_norms", "recognition"),
    figures=("fig_vad", "fig_confusion", "fig_clip_norms_gesture"), module=__name__))
