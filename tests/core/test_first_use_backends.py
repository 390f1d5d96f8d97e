"""First use: whichever backend answers (compiled kernels or their fallbacks), the plan is the same.

In a fresh environment the first plans answer with Clarabel and the numpy time law while a
background process compiles the kernels (:mod:`speedplan.core.jit`); later plans use the
compiled kernels. Users must not see a different plan: the status is equal and the duration
within 1e-6 of it (relative: Clarabel may stop at its reduced tolerance, e.g. a certified gap
of 4.7e-6 on the 27.337 m straight, 2.1e-5 s of its 28.83 s).
"""

from __future__ import annotations

import os
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

import speedplan as sp
from speedplan.core import jit
from speedplan.geometry import Line
from speedplan.io import read_path

ROOT = Path(__file__).parents[2]
LGV = sp.Limits(v_max=2.0, a_max=1.0, a_lat_max=1.0, j_max=0.5)


class _Compiling:
    """Stands for a background compilation that is still running."""

    def poll(self) -> int | None:
        return None

    def wait(self) -> int:  # pragma: no cover - a plan below AUTO_WAIT_FROM never waits
        raise AssertionError("a small plan waited for the compilation")


@pytest.fixture
def cold(monkeypatch):
    """Every kernel family still compiling in the background (nothing loads, none starts)."""
    for family in jit.FAMILIES.values():
        monkeypatch.setattr(family, "module", None)
        monkeypatch.setattr(family, "background", _Compiling())


def _cases():
    yield "warehouse_loop", read_path(ROOT / "paths" / "warehouse_loop.json"), LGV, {}
    yield "u_turn", read_path(ROOT / "paths" / "u_turn.json"), LGV, {}
    # On a grid of the caller's: a straight move between rests is otherwise planned in
    # closed form, with no relaxation.
    yield "straight", sp.Path.from_segments([Line(27.337)]), sp.Limits(
        v_max=1.0903, a_max=0.3025, a_lat_max=1.0, j_max=1.9522), {"ds": 0.01}
    yield "moving start", sp.Path.from_segments([Line(12.0)]), LGV, {"v0": 1.2, "a0": -0.3,
                                                                    "ds": 0.005}


CASES = list(_cases())


@pytest.mark.parametrize("name, path, limits, kw", CASES, ids=[c[0] for c in CASES])
def test_fallbacks_and_compiled_kernels_give_the_same_plan(name, path, limits, kw, request):
    warm = sp.plan(path, limits, **kw)  # the conftest compiled every kernel
    assert "banded" in warm.solution.backend
    request.getfixturevalue("cold")
    first = sp.plan(path, limits, **kw)
    assert "clarabel" in first.solution.backend and "banded" not in first.solution.backend
    from speedplan.timing import law

    assert law.backend().__name__ == "speedplan.timing._law_numpy"  # the numpy time law
    assert first.status == warm.status
    assert abs(first.duration / warm.duration - 1.0) <= 1e-6
    assert first.verify().ok and warm.verify().ok


def test_the_compiled_time_law_matches_the_numpy_one(monkeypatch):
    from speedplan.timing import _law_numpy, law

    jit.FAMILIES["time law"].compile()  # loaded, or compiled here in a fresh cache
    path = read_path(ROOT / "paths" / "warehouse_loop.json")
    compiled = sp.plan(path, LGV)
    assert law.backend().__name__ == "speedplan.core._law_kernel"
    monkeypatch.setattr(law, "backend", lambda: _law_numpy)
    numpy_law = sp.plan(path, LGV)
    assert numpy_law.status == compiled.status
    assert abs(numpy_law.duration - compiled.duration) <= 1e-6
    a, b = compiled.sample(0.05), numpy_law.sample(0.05)
    np.testing.assert_allclose(a.v, b.v, atol=1e-9)


@pytest.mark.slow
def test_a_fresh_environment_answers_at_once_then_with_the_compiled_kernel(tmp_path):
    # An empty numba cache: the first plan must not wait for a compilation; the background
    # process started by it fills the cache, after which a new process loads the kernel.
    env = dict(os.environ, PYTHONPATH=str(ROOT), NUMBA_CACHE_DIR=str(tmp_path))
    code = ("import time, speedplan as sp; from speedplan.geometry import Line\n"
            "from speedplan.core.jit import FAMILIES\n"
            "lim = sp.Limits(v_max=2.0, a_max=1.0, a_lat_max=1.0, j_max=0.5)\n"
            "corner = sp.Path.from_waypoints([[0, 0], [20, 0], [20, 10]])\n"
            "t = time.perf_counter(); p = sp.plan(corner, lim)\n"
            "print(p.solution.backend, time.perf_counter() - t, repr(p.duration))\n"
            "b = FAMILIES['relaxation'].background\n"
            "b is not None and b.wait()\n")
    out = subprocess.run([sys.executable, "-c", code], env=env, capture_output=True, text=True,
                         timeout=900, check=True).stdout.split()
    assert out[0] == "clarabel" and float(out[1]) < 20.0
    again = subprocess.run([sys.executable, "-c", code], env=env, capture_output=True,
                           text=True, timeout=900, check=True).stdout.split()
    assert again[0] == "banded"
    assert abs(float(again[2]) - float(out[2])) <= 1e-6
