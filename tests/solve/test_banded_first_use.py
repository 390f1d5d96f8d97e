"""First use of the banded kernel: loaded from numba's cache, or Clarabel while it compiles."""

from __future__ import annotations

import os
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

from speedplan.core import jit
from speedplan.solve import banded, discrete
from speedplan.solve.paper import paper_instance
from speedplan.solve.problem import DiscreteProblem

ROOT = Path(__file__).parents[2]


def _problem(n: int) -> DiscreteProblem:
    inst = paper_instance("rnd", "cnst", "cnst", n=n, seed=1)
    return DiscreteProblem(s=np.arange(n, dtype=float), w_max=inst.w_max, accel=inst.A,
                           decel=inst.A, jerk=inst.J)


class _FakeCompile:
    """Stands for the background process: running until ``code`` is set."""

    def __init__(self) -> None:
        self.code: int | None = None

    def poll(self) -> int | None:
        return self.code

    def wait(self) -> int:
        self.code = 0
        return 0


@pytest.fixture
def cold(monkeypatch, tmp_path):
    """A process whose kernel is neither compiled nor cached; spawns are recorded."""
    state = {"cached": False, "spawned": [], "compiled": 0}
    kernels = banded.KERNELS
    module = kernels.compile()  # the real kernel module, compiled by the conftest
    monkeypatch.setattr(kernels, "lock_path", lambda: str(tmp_path / "compile.lock"))
    monkeypatch.setattr(kernels, "module", None)
    monkeypatch.setattr(kernels, "background", None)
    monkeypatch.setattr(kernels, "spawn_failed", False)
    monkeypatch.setattr(kernels, "then", ())
    monkeypatch.delenv(jit.BACKGROUND_COMPILE_ENV, raising=False)

    def load():
        if state["cached"]:
            kernels.module = module
        return state["cached"]

    def spawn(names):
        assert names == ["relaxation"]
        (tmp_path / "compile.lock").unlink()  # as the real process does when it is done
        proc = _FakeCompile()
        state["spawned"].append(proc)
        return proc

    def compile_now():
        state["compiled"] += 1
        kernels.module = module
        return module

    monkeypatch.setattr(kernels, "load", load)
    monkeypatch.setattr(jit, "spawn_compile", spawn)
    monkeypatch.setattr(kernels, "compile", compile_now)
    return state


def test_auto_answers_with_clarabel_while_the_kernel_compiles(cold):
    p = _problem(200)
    first = discrete.solve_problem(p, backend="auto")
    assert first.backend == "clarabel" and len(cold["spawned"]) == 1
    second = discrete.solve_problem(p, backend="auto")  # still compiling: no second process
    assert second.backend == "clarabel" and len(cold["spawned"]) == 1
    cold["spawned"][0].code = 0  # done: the kernel is in the cache now
    cold["cached"] = True
    third = discrete.solve_problem(p, backend="auto")
    assert third.backend == "banded" and cold["compiled"] == 0
    # Same certified answer either way.
    assert third.lower_bound == pytest.approx(first.lower_bound, rel=1e-6)
    assert third.objective == pytest.approx(first.objective, rel=1e-6)


def test_a_failed_background_compilation_is_not_restarted(cold):
    p = _problem(200)
    assert discrete.solve_problem(p, backend="auto").backend == "clarabel"
    cold["spawned"][0].code = 1
    # The next call compiles in this process (background compilation is off now).
    assert discrete.solve_problem(p, backend="auto").backend == "banded"
    assert len(cold["spawned"]) == 1 and cold["compiled"] == 1


def test_auto_waits_for_the_kernel_on_large_grids(cold, monkeypatch):
    monkeypatch.setattr(discrete, "AUTO_WAIT_FROM", 300)
    assert discrete.solve_problem(_problem(300), backend="auto").backend == "banded"
    assert cold["compiled"] == 1 and not cold["spawned"]


def test_background_compilation_can_be_switched_off(cold, monkeypatch):
    monkeypatch.setenv(jit.BACKGROUND_COMPILE_ENV, "0")
    assert discrete.solve_problem(_problem(200), backend="auto").backend == "banded"
    assert cold["compiled"] == 1 and not cold["spawned"]


def test_only_one_process_compiles(cold, tmp_path, monkeypatch):
    # Another process (a plan_many worker) holds a fresh lock: answer with Clarabel, start
    # nothing; a lock older than COMPILE_LOCK_STALE is taken over.
    lock = tmp_path / "compile.lock"
    lock.touch()
    p = _problem(200)
    assert discrete.solve_problem(p, backend="auto").backend == "clarabel"
    assert not cold["spawned"] and cold["compiled"] == 0
    old = lock.stat().st_mtime - jit.COMPILE_LOCK_STALE - 1
    os.utime(lock, (old, old))
    assert discrete.solve_problem(p, backend="auto").backend == "clarabel"
    assert len(cold["spawned"]) == 1


def test_small_grids_never_need_the_kernel(cold):
    assert discrete.solve_problem(_problem(50), backend="auto").backend == "clarabel"
    assert not cold["spawned"] and cold["compiled"] == 0


def _ready_in_fresh_process(cache_dir: str | None) -> str:
    env = dict(os.environ, PYTHONPATH=str(ROOT))
    if cache_dir is not None:
        env["NUMBA_CACHE_DIR"] = cache_dir
    code = ("import time; from speedplan.solve import banded; t = time.perf_counter(); "
            "r = banded.kernel_ready(start=False); print(r, time.perf_counter() - t)")
    out = subprocess.run([sys.executable, "-c", code], env=env, capture_output=True,
                         text=True, timeout=120, check=True)
    return out.stdout


def test_the_cached_kernel_is_found_without_compiling(tmp_path):
    # The conftest compiled the kernel into numba's cache (NUMBA_CACHE_DIR if set, else
    # __pycache__); a new process loads it from there, and with an empty cache it reports
    # "not ready" at once instead of compiling.
    ready, seconds = _ready_in_fresh_process(os.environ.get("NUMBA_CACHE_DIR")).split()
    assert ready == "True"
    ready, seconds = _ready_in_fresh_process(str(tmp_path)).split()
    assert ready == "False" and float(seconds) < 5.0


def test_problems_without_jerk_rows_start_no_compilation(cold, monkeypatch):
    # The no-jerk pass needs no solver: "auto" must not start (or wait for) a compilation.
    monkeypatch.setattr(discrete, "AUTO_WAIT_FROM", 300)
    for n in (200, 400):
        p = _problem(n)
        free = DiscreteProblem(s=p.s, w_max=p.w_max, accel=p.accel, decel=p.decel,
                               jerk=np.full(n - 2, np.inf))
        assert discrete.solve_problem(free, backend="auto").backend == "pass"
    assert not cold["spawned"] and cold["compiled"] == 0
