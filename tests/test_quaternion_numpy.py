"""The numpy quaternion helpers (np_*) give the torch functions' results without loading torch."""
from __future__ import annotations

import subprocess
import sys

import numpy as np
import pytest
import torch

from generation.core import quaternion as Q

RNG = np.random.default_rng(7)


def unit(*shape) -> np.ndarray:
    q = RNG.normal(size=shape + (4,))
    return q / np.linalg.norm(q, axis=-1, keepdims=True)


def torch_of(fn, *args, **kwargs) -> np.ndarray:
    return fn(*(torch.from_numpy(np.asarray(a, dtype=np.float64)) if not isinstance(a, float) else a
                for a in args), **kwargs).numpy()


def walk_like(T=40, J=5) -> np.ndarray:
    """(T, J, 4) smooth rotations with random sign flips (what qfix repairs)."""
    q = Q.np_qnormalize(np.cumsum(RNG.normal(scale=0.1, size=(T, J, 4)), axis=0) + [1.0, 0, 0, 0])
    return q * RNG.choice([-1.0, 1.0], size=(T, J, 1))


CASES = [
    ("qmul", (unit(6, 3), unit(3)), {}),
    ("qconj", (unit(5),), {}),
    ("qnormalize", (RNG.normal(size=(7, 4)) * 3,), {}),
    ("qrot", (unit(6, 1), RNG.normal(size=(6, 9, 3))), {}),
    ("qfrom_axis_angle", (RNG.normal(size=(8, 3)), RNG.normal(size=8)), {}),
    ("qbetween", (RNG.normal(size=(6, 3)), RNG.normal(size=(6, 3))), {}),
    ("qbetween", (np.array([[1.0, 0, 0], [0, 2, 0]]), np.array([[-1.0, 0, 0], [0, -1, 0]])), {}),  # opposite
    ("qfix", (walk_like(),), {}),
    ("qslerp", (unit(9), unit(9), RNG.uniform(size=9)), {}),
    ("qslerp", (unit(4), unit(4), 0.3), {}),
    ("qto_matrix", (unit(3, 5),), {}),
    ("qangle", (unit(10), unit(10)), {}),
    *[("qeuler", (unit(12),), {"order": o}) for o in ("xyz", "yzx", "zxy", "xzy", "yxz", "zyx")],
    *[("qfrom_euler", (RNG.uniform(-1.5, 1.5, size=(12, 3)),), {"order": o}) for o in ("xyz", "zyx", "yxz")],
]


@pytest.mark.parametrize("name,args,kwargs", CASES, ids=[f"{c[0]}-{i}" for i, c in enumerate(CASES)])
def test_numpy_versions_match_torch(name, args, kwargs):
    got = getattr(Q, f"np_{name}")(*args, **kwargs)
    want = torch_of(getattr(Q, name), *args, **kwargs)
    assert got.dtype == np.float64 and got.shape == want.shape
    np.testing.assert_allclose(got, want, rtol=0, atol=1e-12)


def test_the_numpy_versions_compose_like_rotations():
    q, r, v = unit(4), unit(4), RNG.normal(size=(4, 3))
    np.testing.assert_allclose(Q.np_qrot(Q.np_qmul(q, r), v), Q.np_qrot(q, Q.np_qrot(r, v)), atol=1e-12)
    np.testing.assert_allclose(Q.np_qto_matrix(q) @ v[..., None], Q.np_qrot(q, v)[..., None], atol=1e-12)
    angles = RNG.uniform(-1.2, 1.2, size=(6, 3))
    np.testing.assert_allclose(Q.np_qeuler(Q.np_qfrom_euler(angles, "yxz"), "yxz"), angles, atol=1e-9)
    fixed = Q.np_qfix(walk_like())
    assert ((fixed[1:] * fixed[:-1]).sum(-1) >= 0).all()
    with pytest.raises(ValueError, match="unsupported Euler order"):
        Q.np_qeuler(unit(2), order="xxy")


def test_numpy_callers_never_load_torch():
    code = ("import sys, numpy as np; from generation.core import quaternion as Q; "
            "q = Q.np_qnormalize(np.ones((3, 2, 4))); Q.np_qfix(q); Q.np_qslerp(q, q, 0.5); Q.np_qeuler(q); "
            "Q.np_qrot(q, np.ones(3)); Q.np_qfrom_euler(np.zeros(3)); Q.np_qbetween(np.eye(3), -np.eye(3)); "
            "sys.exit('torch' in sys.modules)")
    assert subprocess.run([sys.executable, "-c", code]).returncode == 0
