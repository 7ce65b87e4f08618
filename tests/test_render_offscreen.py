"""The environment a rendering process needs is set at its edges, in one function; the library never writes it."""
from __future__ import annotations

import os
import subprocess
import sys
from pathlib import Path

import torch

from generation.render.offscreen import OFFSCREEN_WINDOW, THREAD_VARIABLES, prepare_render_process

ROOT = Path(__file__).resolve().parent.parent
WRITTEN_BEFORE = ("VTK_DEFAULT_OPENGL_WINDOW", "HF_HUB_OFFLINE", "TRANSFORMERS_OFFLINE", *THREAD_VARIABLES)


def test_importing_the_renderer_and_runner_writes_no_environment_variable():
    env = {k: v for k, v in os.environ.items() if k not in WRITTEN_BEFORE}
    code = ("import os; before = dict(os.environ); "
            "import generation.render.scene, generation.pipeline.runner, generation.gesture.text; "
            "print(sorted(set(os.environ) - set(before)))")
    proc = subprocess.run([sys.executable, "-c", code], cwd=ROOT, env=env, capture_output=True, text=True,
                          timeout=120)
    assert proc.returncode == 0, proc.stderr
    assert proc.stdout.strip() == "[]"


def test_prepare_render_process_sets_the_window_and_thread_caps_and_keeps_a_users_value(monkeypatch):
    env = {"LP_NUM_THREADS": "3"}
    monkeypatch.setattr(os, "environ", env)
    prepare_render_process()
    assert env == {"LP_NUM_THREADS": "3", "VTK_DEFAULT_OPENGL_WINDOW": OFFSCREEN_WINDOW}
    prepare_render_process(2)
    assert (env["OMP_NUM_THREADS"], env["MKL_NUM_THREADS"], env["LP_NUM_THREADS"]) == ("2", "2", "3")


def test_render_worker_initializer_prepares_its_process(monkeypatch):
    from generation.pipeline.runner import _init_worker

    env: dict[str, str] = {}
    monkeypatch.setattr(os, "environ", env)
    threads = torch.get_num_threads()   # the test process keeps its own torch threads
    _init_worker(None, threads)
    assert env["VTK_DEFAULT_OPENGL_WINDOW"] == OFFSCREEN_WINDOW
    assert all(env[name] == str(threads) for name in THREAD_VARIABLES)
