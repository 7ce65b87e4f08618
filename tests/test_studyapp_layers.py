"""The rooms of studyapp, checked on every import statement (function-local ones included), like tests/test_layers.py
checks the libraries.

studyapp's modules live in rooms by who uses them, bottom first (ROOMS): data (clips, norms, exports; no request in
sight) < participant (the pages a participant sees) < staff (the researcher pages outside the admin) < admin (the
Django admin). A room imports only the rooms below it; the floor modules (FLOOR: the models and what they need,
permissions, questions, i18n, the middleware) import no room at all. The wiring modules (urls, urls_study, signals,
management commands, testing) may import any room.
"""
from __future__ import annotations

from pathlib import Path

from scripts.import_graph import ROOT, imports_of, module_name

#: the rooms of studyapp, bottom first: each may import only those before it
ROOMS = ("data", "participant", "staff", "admin")
#: top-level modules of studyapp that every room builds on: they import no room
FLOOR = ("models", "permissions", "questions", "i18n", "redirects", "inputs", "security", "login_throttle",
         "gunicorn_logging", "views_health", "settings")
#: top-level modules that put the rooms together: they may import any room
WIRING = ("__init__", "apps", "asgi", "wsgi", "urls", "urls_study", "signals", "testing")


def room_of(module: str) -> str | None:
    """The room of a dotted module name below studyapp, 'floor' for a FLOOR module, None for anything else."""
    parts = module.split(".")
    if parts[0] != "studyapp" or len(parts) < 2:
        return None
    if parts[1] in ROOMS:
        return parts[1]
    return "floor" if parts[1] in FLOOR else None


def room_violations(root: Path = ROOT) -> list[str]:
    """'file:line: room imports room' for every import of a room that the layers forbid."""
    found = []
    for path in sorted((root / "studyapp").rglob("*.py")):
        if "migrations" in path.parts:
            continue
        source = room_of(module_name(path, root))
        if source is None:
            continue
        for target, line, local in imports_of(path, root):
            dest = room_of(target)
            if dest not in ROOMS or dest == source:
                continue
            if source == "floor" or ROOMS.index(dest) > ROOMS.index(source):
                found.append(f"{path.relative_to(root)}:{line}: {source} imports {dest}"
                             + (" (inside a function)" if local else ""))
    return found


def unplaced_modules(root: Path = ROOT) -> list[str]:
    """Top-level modules of studyapp that are in no room and neither FLOOR nor WIRING."""
    return sorted(p.stem for p in (root / "studyapp").glob("*.py") if p.stem not in FLOOR + WIRING)


def test_no_room_imports_a_room_above_it():
    assert room_violations() == []


def test_models_import_no_room():
    found = [target for target, _line, _local in imports_of(ROOT / "studyapp" / "models.py")
             if room_of(target) in ROOMS]
    assert found == []


def test_every_room_is_a_package():
    assert [room for room in ROOMS if not (ROOT / "studyapp" / room / "__init__.py").is_file()] == []


def test_every_top_level_module_has_a_place():
    """A new module goes into a room (or, when the rooms all need it, into FLOOR)."""
    assert unplaced_modules() == []


def test_the_room_check_finds_wrong_way_imports(tmp_path):
    """Relative, absolute and function-local imports up the rooms are found; imports down are not."""
    files = {
        "studyapp/__init__.py": "",
        "studyapp/models.py": "def f():\n    from .staff import views\n",
        "studyapp/data/__init__.py": "",
        "studyapp/data/export.py": "from ..participant.views import x\nfrom ..models import Study\n",
        "studyapp/participant/__init__.py": "",
        "studyapp/participant/views.py": "from ..data import export\nfrom studyapp.admin import forms\n",
        "studyapp/staff/__init__.py": "",
        "studyapp/staff/views.py": "from ..participant import views\nfrom ..data.export import y\n",
        "studyapp/admin/__init__.py": "from . import model_admins\n",
        "studyapp/admin/model_admins.py": "from ..staff import views\n",
        "studyapp/urls.py": "from .admin import model_admins\n",
        "studyapp/extra.py": "",
    }
    for name, text in files.items():
        (tmp_path / name).parent.mkdir(parents=True, exist_ok=True)
        (tmp_path / name).write_text(text)
    assert room_violations(tmp_path) == [
        "studyapp/data/export.py:1: data imports participant",
        "studyapp/models.py:2: floor imports staff (inside a function)",
        "studyapp/participant/views.py:2: participant imports admin",
    ]
    assert unplaced_modules(tmp_path) == ["extra"]
