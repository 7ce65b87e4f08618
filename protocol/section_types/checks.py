"""Small checks the option validators of the section types share (plain Python)."""
from __future__ import annotations


def is_int(value) -> bool:
    """An int that is not a bool (JSON true/false are not counts)."""
    return isinstance(value, int) and not isinstance(value, bool)


def count_error(options: dict, key: str, low: int, high: int | None = None) -> str | None:
    """The message when ``options[key]`` is not an integer in low..high (high None: no upper bound), else None."""
    value = options[key]
    if not is_int(value) or value < low or (high is not None and value > high):
        bound = f"from {low} to {high}" if high is not None else f"{low} or more"
        return f"{key!r} must be an integer {bound}, got {value!r}"
    return None
