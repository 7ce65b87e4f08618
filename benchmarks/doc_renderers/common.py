"""Formatting shared by the renderers of every area: a renderer maps an area's JSON results (dict) to Markdown lines."""
from __future__ import annotations

from collections.abc import Callable

Renderer = Callable[[dict], list[str]]
"""An area's JSON results -> the lines of one Markdown table (or of a line of text)."""
EMOTIONS = ("happy", "sad", "angry", "neutral")


def table(header: list[str], rows: list[list]) -> list[str]:
    """Markdown table lines."""
    return ["| " + " | ".join(header) + " |", "|" + "---|" * len(header),
            *("| " + " | ".join(str(c) for c in row) + " |" for row in rows)]


def _run(r: dict, *extra: tuple[str, str]) -> list[str]:
    """Machine, date, commit, command and duration where recorded, then ``extra`` (label, value) rows and the
    source of transcribed figures (``r["meta"]["transcribed_from"]``)."""
    rows = [[key, r[key]] for key in ("machine", "date") if r.get(key)]
    if r.get("commit"):
        rows.append(["commit", r["commit"].removeprefix("commit ")])
    if r.get("command"):
        rows.append(["command", f"`{r['command']}`"])
    if r.get("seconds") is not None:
        rows.append(["duration", f"{r['seconds']:.0f} s"])
    rows += [list(row) for row in extra]
    if r.get("meta", {}).get("transcribed_from"):
        rows.append(["transcribed from", r["meta"]["transcribed_from"]])
    return table(["run", "value"], rows)


def _opt(v, fmt: str = "{:.2f}") -> str:
    """``v`` formatted with ``fmt``, or '-' where it is None."""
    return "-" if v is None else fmt.format(v)


def _yes(holds: bool) -> str:
    """'yes', or a bold '**no**'."""
    return "yes" if holds else "**no**"
