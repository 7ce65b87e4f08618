"""Helpers shared by the management commands: mirroring a library's argparse options, finding a study."""
from __future__ import annotations

import argparse

from django.core.management.base import CommandError

from studyapp.models import Study


def mirror_arguments(parser: argparse.ArgumentParser, source: argparse.ArgumentParser) -> None:
    """Add every option of a library's parser (e.g. ``generation.gait.train.build_parser()``) to ``parser``."""
    for action in source._actions:
        if action.dest == "help":
            continue
        kwargs = {"dest": action.dest, "default": action.default, "help": action.help}
        if action.const is True and action.nargs == 0:
            kwargs["action"] = "store_true"
        elif isinstance(action, argparse._AppendAction):
            kwargs["action"] = "append"
        else:
            kwargs["type"] = action.type
        parser.add_argument(*action.option_strings, **kwargs)


def mirrored_namespace(source: argparse.ArgumentParser, options: dict) -> argparse.Namespace:
    """The library's own Namespace from a command's ``options`` (Django's extra options dropped)."""
    names = {a.dest for a in source._actions if a.dest != "help"}
    return argparse.Namespace(**{k: v for k, v in options.items() if k in names})


def study_by_slug(slug: str):
    """The Study with ``slug``, or a CommandError listing the known slugs."""

    study = Study.objects.filter(slug=slug).first()
    if study is None:
        known = list(Study.objects.values_list("slug", flat=True))
        raise CommandError(f"no study with slug {slug!r}; known: {known}")
    return study
