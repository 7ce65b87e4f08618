"""pyproject.toml and the pinned lock requirements.txt agree: every direct dependency (and the dev and cluster
extras) is pinned in the lock, inside the range pyproject.toml allows."""
from __future__ import annotations

import tomllib
from pathlib import Path

from packaging.requirements import Requirement

ROOT = Path(__file__).resolve().parent.parent


def lock_pins() -> dict[str, str]:
    pins = {}
    for line in (ROOT / "requirements.txt").read_text().splitlines():
        line = line.split("#")[0].strip()
        if line:
            req = Requirement(line)
            (spec,) = req.specifier
            assert spec.operator == "==", f"requirements.txt must pin exact versions: {line}"
            pins[req.name.lower()] = spec.version
    return pins


def test_direct_dependencies_are_pinned_within_their_ranges():
    project = tomllib.loads((ROOT / "pyproject.toml").read_text())["project"]
    pins = lock_pins()
    wanted = project["dependencies"] + project["optional-dependencies"]["dev"] + \
        project["optional-dependencies"]["cluster"]
    problems = []
    for req in map(Requirement, wanted):
        pin = pins.get(req.name.lower())
        if pin is None or not req.specifier.contains(pin, prereleases=True):
            problems.append(f"{req}: lock has {pin}")
    assert problems == []


def test_the_packages_and_their_data_are_declared():
    config = tomllib.loads((ROOT / "pyproject.toml").read_text())
    assert config["build-system"]["build-backend"] == "setuptools.build_meta"
    tool = config["tool"]["setuptools"]
    assert "py-modules" not in tool, "the project installs packages only, no top-level modules"
    assert set(tool["packages"]["find"]["include"]) == {"protocol*", "generation*", "analysis*", "studyapp*"}
    assert (ROOT / "analysis" / "data" / "planned_clips.csv").is_file()
