"""Set-up of a process that renders offscreen, for the settings its C libraries take only from the environment.

VTK picks its render window class (headless EGL here) when it makes the first window, Mesa's llvmpipe its thread
count when the GL driver loads, and the OpenMP and MKL runtimes theirs when they load; PyVista and these libraries
take no argument for them. So the edges of a process that renders (a command line, a render worker's initializer)
call :func:`prepare_render_process` once, before the first scene; the library itself never writes the environment.
A value already in the environment wins (``setdefault``). Without the call VTK 9.7 still renders: it tries an X
window first, warns and falls back to EGL.
"""
from __future__ import annotations

import os

OFFSCREEN_WINDOW = "vtkEGLRenderWindow"
THREAD_VARIABLES = ("OMP_NUM_THREADS", "MKL_NUM_THREADS", "LP_NUM_THREADS")
"""OpenMP, MKL and Mesa llvmpipe thread counts (llvmpipe starts one thread per core otherwise)."""


def prepare_render_process(threads: int | None = None) -> None:
    """Choose VTK's headless EGL window for this process and, with ``threads``, cap its numerical and GL thread
    pools (a render worker: one per core). Call before the first scene is built (before VTK, Mesa and, for the
    thread caps, torch load)."""
    # Environment, not arguments: these libraries read the variables once, when they load.
    os.environ.setdefault("VTK_DEFAULT_OPENGL_WINDOW", OFFSCREEN_WINDOW)
    if threads is not None:
        for name in THREAD_VARIABLES:
            os.environ.setdefault(name, str(threads))
