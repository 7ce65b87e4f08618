"""Settings travel as arguments: the libraries never read environment variables except at their edges.

- an AST scan of every module of generation/ and analysis/ lists where ``os.environ`` / ``os.getenv`` (or a name
  imported from ``os`` for them) is used, by file and enclosing function, and compares it with
  :data:`EDGE_READS`, the explicit list of allowed places: command-line ``main`` functions and argparse parser
  builders (:func:`_is_edge_function`), plus the one documented exception (the render process set-up). A new read
  anywhere else fails, and so does an entry of the list that no longer reads anything (the list stays exact);
- the edges still honour the variables they read: REAL_CORPUS, BML_CORPUS, GESTURE_VAR_DIR and MEDIA_ROOT on the
  command lines (the observer export among them), and the settings REAL_CORPUS / BML_CORPUS / MEDIA_ROOT in the
  Django commands.
"""
from __future__ import annotations

import ast
import io
import subprocess
import sys
from pathlib import Path

import pytest
from django.core.management import call_command

from generation.gait import train as gait_train
from generation.gesture import config
from generation.gesture import train as gesture_train
from generation.mocap.real_corpus import RealCorpora
from generation.pipeline.runner import BatchResult
from studyapp.management.commands import generate_clips, train_gait

ROOT = Path(__file__).resolve().parents[1]
SCANNED = ("generation", "analysis")
ENV_NAMES = {"environ", "environb", "getenv", "getenvb", "putenv", "unsetenv"}

#: (file, enclosing function) -> what it reads there. Every place but the last is a command line's edge.
EDGE_READS = {
    ("generation/gait/train.py", "main"): "REAL_CORPUS (the corpus of --real), MEDIA_ROOT (rated clips' motions)",
    ("generation/gait/train_both.py", "main"): "REAL_CORPUS, BML_CORPUS",
    ("generation/gesture/average.py", "main"): "GESTURE_VAR_DIR (the corpus cache)",
    ("generation/gesture/train.py", "build_parser"): "GESTURE_VAR_DIR (--var-dir default)",
    ("generation/gesture/train.py", "main"): "MEDIA_ROOT (rated clips' motions)",
    ("generation/mocap/cli.py", "_add_dataset_parser"): "REAL_CORPUS, BML_CORPUS (where `dataset` writes "
                                                        "without --out)",
    ("generation/pipeline/plan_qa.py", "main"): "QA_GAIT_OBSERVER (--observer default), REAL_CORPUS, BML_CORPUS",
    ("generation/quality/calibrated_observer.py", "main"): "REAL_CORPUS, BML_CORPUS (--bandai / --bml defaults)",
    ("generation/quality/real_gestures.py", "main"): "REAL_CORPUS (--corpus default)",
    ("generation/quality/realism_ranges.py", "main"): "REAL_CORPUS (--corpus default)",
    ("generation/rbf/__main__.py", "main"): "REAL_CORPUS (--corpus default)",
    # VTK, Mesa and the OpenMP/MKL runtimes take these settings only from the environment, when they load; the
    # edges of a rendering process (a command, a render worker's initializer) call it once (setdefault: a value
    # already set wins)
    ("generation/render/offscreen.py", "prepare_render_process"): "writes VTK_DEFAULT_OPENGL_WINDOW, *_NUM_THREADS",
}


def _is_edge_function(name: str) -> bool:
    """A command line's ``main`` or a function that builds its argparse parser (``build_parser``, ``_parser``,
    ``_add_dataset_parser``), at module level."""
    return name == "main" or ("." not in name and name.endswith("parser"))


class _EnvironmentUses(ast.NodeVisitor):
    """(enclosing function's qualified name or ``<module>``, line) of every use of the process environment."""

    def __init__(self) -> None:
        self.os_names: set[str] = set()       # names bound to the os module in this file
        self.env_names: set[str] = set()      # names imported from os that are the environment or its accessors
        self.scope: list[str] = []
        self.found: list[tuple[str, int]] = []

    def _record(self, node: ast.AST) -> None:
        self.found.append((".".join(self.scope) or "<module>", node.lineno))

    def visit_Import(self, node: ast.Import) -> None:
        for alias in node.names:
            if alias.name == "os" or alias.name.startswith("os."):
                self.os_names.add(alias.asname or "os")

    def visit_ImportFrom(self, node: ast.ImportFrom) -> None:
        if node.module == "os":
            for alias in node.names:
                if alias.name in ENV_NAMES:
                    self.env_names.add(alias.asname or alias.name)
                    self._record(node)

    def _scoped(self, node) -> None:
        self.scope.append(node.name)
        self.generic_visit(node)
        self.scope.pop()

    visit_FunctionDef = visit_AsyncFunctionDef = visit_ClassDef = _scoped

    def visit_Attribute(self, node: ast.Attribute) -> None:
        if isinstance(node.value, ast.Name) and node.value.id in self.os_names and node.attr in ENV_NAMES:
            self._record(node)
        self.generic_visit(node)

    def visit_Name(self, node: ast.Name) -> None:
        if node.id in self.env_names:
            self._record(node)


def environment_uses(source: str) -> list[tuple[str, int]]:
    """(function, line) of every use of the environment in a module's source."""
    visitor = _EnvironmentUses()
    visitor.visit(ast.parse(source))
    return visitor.found


def library_environment_uses(root: Path = ROOT) -> dict[tuple[str, str], list[int]]:
    """{(file relative to ``root``, function): lines} over every module of the scanned libraries."""
    found: dict[tuple[str, str], list[int]] = {}
    for package in SCANNED:
        for path in sorted((root / package).rglob("*.py")):
            for function, line in environment_uses(path.read_text(encoding="utf-8")):
                found.setdefault((path.relative_to(root).as_posix(), function), []).append(line)
    return found


def test_the_scan_sees_every_way_of_reading_the_environment():
    source = '''
import os
import os as system
from os import environ, getenv as ge

A = os.environ.get("A")


def main():
    return os.getenv("B"), system.environ["C"]


class Settings:
    def load(self):
        def inner():
            return environ, ge("D")
        return inner


def innocent(environ_like):
    return environ_like.get("E"), os.path.join("a", "b")
'''
    assert sorted(environment_uses(source)) == [("<module>", 4), ("<module>", 4), ("<module>", 6),
                                               ("Settings.load.inner", 16), ("Settings.load.inner", 16), ("main", 10),
                                               ("main", 10)]


def test_the_libraries_read_the_environment_only_at_their_edges():
    found = library_environment_uses()
    unexpected = {f"{path}:{lines[0]} in {function}" for (path, function), lines in found.items()
                  if (path, function) not in EDGE_READS}
    assert not unexpected, ("library code reads the environment; take the value as an argument and read the "
                            f"variable in the command line's main or parser (or list the place here): {unexpected}")
    stale = set(EDGE_READS) - set(found)
    assert not stale, f"listed places that no longer read the environment: {stale}"
    exceptions = {place for place in EDGE_READS if not _is_edge_function(place[1])}
    assert exceptions == {("generation/render/offscreen.py", "prepare_render_process")}


# ---- the edges honour the variables ---------------------------------------------------------------------------


def test_gait_training_command_line_takes_the_corpus_and_motions_from_the_environment(tmp_path, monkeypatch):
    seen = []
    monkeypatch.setattr(gait_train, "run", seen.append)
    monkeypatch.setenv("REAL_CORPUS", str(tmp_path / "bandai.npz"))
    monkeypatch.setenv("MEDIA_ROOT", str(tmp_path / "media"))
    assert gait_train.main(["--real", "finetune"]) == 0
    assert (seen[0].corpus, seen[0].motions) == (str(tmp_path / "bandai.npz"), tmp_path / "media" / "motions")
    gait_train.main(["--real", "finetune", "--corpus", "given.npz", "--motions", "here"])
    gait_train.main([])                                   # the synthetic corpus: no real corpus is filled in
    assert (seen[1].corpus, seen[1].motions, seen[2].corpus) == ("given.npz", "here", None)
    monkeypatch.delenv("REAL_CORPUS")
    monkeypatch.delenv("MEDIA_ROOT")
    gait_train.main(["--real", "finetune"])
    assert (Path(seen[3].corpus), seen[3].motions) == (ROOT / "var" / "mocap" / "bandai-namco.npz", None)


def test_gesture_training_command_line_takes_its_folders_from_the_environment(tmp_path, monkeypatch):
    monkeypatch.delenv("GESTURE_VAR_DIR", raising=False)
    defaults = gesture_train.build_parser().parse_args([])
    assert defaults.var_dir == config.DEFAULT_VAR_DIR == ROOT / "var" / "gesture"
    assert gesture_train.config_from_args(defaults).checkpoint == gesture_train.TrainConfig().checkpoint
    monkeypatch.setenv("GESTURE_VAR_DIR", str(tmp_path / "gvar"))
    monkeypatch.setenv("MEDIA_ROOT", str(tmp_path / "media"))
    args = gesture_train.build_parser().parse_args([])
    assert args.var_dir == tmp_path / "gvar"
    assert gesture_train.config_from_args(args).checkpoint == str(tmp_path / "gvar" / "checkpoints" / "gesture_net.pt")
    assert config.var_dir() == config.DEFAULT_VAR_DIR                  # the library itself never reads it
    seen = {}
    monkeypatch.setattr(gesture_train, "soft_label_data", lambda cfg, a: seen.update(motions=a.motions) or (None, None))
    monkeypatch.setattr(gesture_train, "train", lambda cfg, **kw: seen.update(cache_dir=kw["cache_dir"]) or {
        "history": [], "epochs_run": 0, "seconds": 0.0, "device": "cpu", "best_val": 0.0, "out": cfg.out})
    gesture_train.main(["--soft-labels", "norms.csv", "--quiet"])
    assert seen == {"motions": tmp_path / "media" / "motions", "cache_dir": tmp_path / "gvar"}


def test_observer_export_takes_the_corpora_from_the_environment(tmp_path, monkeypatch):
    from generation.quality import calibrated_observer

    seen = []
    monkeypatch.setattr(calibrated_observer, "export_observers",
                        lambda out, bandai, bml, labels: seen.append((out, bandai, bml)) or [])
    for name in ("bandai.npz", "bml.npz", "given.npz"):
        (tmp_path / name).touch()
    monkeypatch.setenv("REAL_CORPUS", str(tmp_path / "bandai.npz"))
    monkeypatch.setenv("BML_CORPUS", str(tmp_path / "bml.npz"))
    out = ["export", "--out", str(tmp_path / "out")]
    assert calibrated_observer.main(out) == 0
    assert calibrated_observer.main([*out, "--bml", str(tmp_path / "given.npz")]) == 0
    assert seen == [(tmp_path / "out", tmp_path / "bandai.npz", tmp_path / "bml.npz"),
                    (tmp_path / "out", tmp_path / "bandai.npz", tmp_path / "given.npz")]


def test_manage_py_training_commands_take_the_settings_paths(tmp_path, monkeypatch, settings):
    settings.REAL_CORPUS = str(tmp_path / "bandai.npz")
    settings.MEDIA_ROOT = tmp_path / "media"
    seen = []
    monkeypatch.setattr(train_gait, "run", lambda ns, log: seen.append(ns))
    call_command("train_gait", "--real", "finetune", stdout=io.StringIO())
    assert (seen[0].corpus, seen[0].motions) == (str(tmp_path / "bandai.npz"), tmp_path / "media" / "motions")


def test_generate_clips_passes_the_settings_corpora_down(tmp_path, monkeypatch, settings):
    settings.MEDIA_ROOT = tmp_path / "media"
    settings.REAL_CORPUS, settings.BML_CORPUS = str(tmp_path / "bandai.npz"), ""
    seen = {}
    monkeypatch.setattr(generate_clips, "run_plan", lambda *a, **kw: seen.update(kw) or BatchResult())
    call_command("generate_clips", "--plan", "demo", "--no-db", "--no-progress", stdout=io.StringIO())
    assert seen["corpora"] == RealCorpora.of(tmp_path / "bandai.npz", None)


@pytest.mark.parametrize("variable", ["REAL_CORPUS", "BML_CORPUS"])
def test_the_settings_read_the_corpus_variables(variable):
    code = f"import django.conf as c; print(c.settings.{variable})"
    env = {"DJANGO_SETTINGS_MODULE": "studyapp.settings", variable: "/data/corpus.npz", "PATH": "/usr/bin:/bin"}
    out = subprocess.run([sys.executable, "-c", code], env=env, cwd=ROOT, capture_output=True, text=True, check=True)
    assert out.stdout.strip() == "/data/corpus.npz"
