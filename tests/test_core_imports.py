"""The numpy layers of generation/ (and the study protocol) import without torch, which is slow to import."""
from __future__ import annotations

import subprocess
import sys
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parent.parent

TORCH_FREE = (
    "protocol.vocabulary",
    "generation.core.skeleton",
    "generation.core.motion",
    "generation.core.features",
    "generation.core.ik",
    "generation.core.rigging",
    "generation.core.quaternion",
    "generation.core.kinematics",
    "generation.core.paths",
    "generation.formats.bvh",
    "generation.procedural.walk",
    "generation.procedural.gesture",
    "generation.procedural.emotion",
    "generation.procedural.corpus",
)


@pytest.mark.parametrize("module", TORCH_FREE)
def test_module_imports_without_torch(module):
    code = f"import {module}; import sys; assert 'torch' not in sys.modules, 'importing {module} loaded torch'"
    proc = subprocess.run([sys.executable, "-c", code], cwd=ROOT, capture_output=True, text=True, timeout=120)
    assert proc.returncode == 0, proc.stderr


def test_numpy_quaternions_work_without_torch():
    code = ("import sys, numpy as np; from generation.core.quaternion import np_qmul, identity; "
            "assert 'torch' not in sys.modules; q = np_qmul(identity((2,)), identity((2,))); "
            "assert np.allclose(q, identity((2,))) and 'torch' not in sys.modules")
    proc = subprocess.run([sys.executable, "-c", code], cwd=ROOT, capture_output=True, text=True, timeout=120)
    assert proc.returncode == 0, proc.stderr
