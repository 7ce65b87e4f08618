"""``python -m generation.render.bodies``: build bodies from anny, or list the exported ones.

    python -m generation.render.bodies build                       # every shipped preset
    python -m generation.render.bodies build --preset female male  # some of them
    python -m generation.render.bodies build --name tall-female --param gender=1 --param height=0.9
    python -m generation.render.bodies list

Building needs the ``[bodies]`` extra (anny); listing and rendering need numpy only.
"""
from __future__ import annotations

import argparse
import sys
from pathlib import Path

from .build import anny_model, export_body  # anny itself is imported by anny_model() only
from .presets import PRESETS, BodyPresetError, check_name, check_parameters
from .store import BODY_DIR, available_presets, load_body_file


def _param(text: str) -> tuple[str, float]:
    if "=" not in text:
        raise argparse.ArgumentTypeError(f"{text!r}: expected NAME=VALUE, e.g. weight=0.8")
    key, value = text.split("=", 1)
    try:
        return key.strip(), float(value)
    except ValueError:
        raise argparse.ArgumentTypeError(f"{text!r}: the value must be a number in 0..1") from None


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(prog="python -m generation.render.bodies", description=__doc__,
                                 formatter_class=argparse.RawDescriptionHelpFormatter)
    sub = ap.add_subparsers(dest="command", required=True)
    b = sub.add_parser("build", help="export bodies from anny")
    b.add_argument("--preset", nargs="*", help=f"shipped presets to build (default: all of {sorted(PRESETS)})")
    b.add_argument("--name", help="build one custom body under this name from --param values")
    b.add_argument("--param", action="append", type=_param, default=[],
                   help="phenotype parameter NAME=VALUE (gender, age, muscle, weight, height, proportions)")
    b.add_argument("--out", type=Path, default=BODY_DIR, help=f"output folder (default {BODY_DIR})")
    sub.add_parser("list", help="list the exported bodies")
    args = ap.parse_args(argv)
    if args.command == "list":
        for name in available_presets():
            body = load_body_file(BODY_DIR / f"{name}.npz")
            print(f"{name}: {body.height:.2f} m, {len(body.vertices)} vertices, {body.meta.get('parameters')}")
        return 0
    try:
        if args.name:
            jobs = {check_name(args.name): check_parameters(dict(args.param))}
        else:
            if args.param:
                raise BodyPresetError("--param needs --name (the shipped presets have fixed parameters)")
            names = args.preset or sorted(PRESETS)
            unknown = sorted(set(names) - set(PRESETS))
            if unknown:
                raise BodyPresetError(f"unknown body preset(s) {unknown}; expected some of {sorted(PRESETS)}")
            jobs = {n: check_parameters(PRESETS[n]) for n in names}
    except BodyPresetError as exc:
        print(f"error: {exc}", file=sys.stderr)
        return 2
    model = anny_model()
    for name, params in jobs.items():
        body = export_body(model, name, params)
        path = body.save(args.out / f"{name}.npz")
        print(f"{path}: {body.height:.3f} m, {path.stat().st_size / 1024:.0f} KiB")
    return 0


if __name__ == "__main__":
    sys.exit(main())
