"""How the kernels are compiled: one signature each, callees first, in parts, same code.

Every kernel numba compiles on its own is listed with one explicit signature
(``signatures()``), after the kernels it calls: compiled in that order, a caller passing a
constant uses the kernel compiled for the constant's type instead of making numba compile
a copy for the value. A split family (`speedplan.core.jit.Kernels.parts`) is compiled by
several processes, one group of kernels each, and its entry points by the last one from
numba's cache: the kernel that runs is the same.
"""

from __future__ import annotations

import importlib
import json
import os
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

from speedplan.core import jit

ROOT = Path(__file__).parents[2]


def _kernels(module):
    """The module's dispatchers that numba compiles on their own (not inlined into callers)."""
    from numba.core.registry import CPUDispatcher

    return {name: d for name in dir(module) if isinstance(d := getattr(module, name), CPUDispatcher)
            and d.targetoptions.get("inline", "never") == "never"}


@pytest.mark.parametrize("family", list(jit.FAMILIES))
def test_every_kernel_is_listed_after_the_kernels_it_calls(family):
    kn = importlib.import_module(jit.FAMILIES[family].module_name)
    sigs = kn.signatures()
    assert set(sigs) == set(_kernels(kn))
    assert set(kn.ENTRY_POINTS) <= set(sigs)
    order = list(sigs)
    for name, below in jit._callees(kn, order).items():
        assert all(order.index(k) <= order.index(name) for k in below), name


@pytest.mark.parametrize("family", list(jit.FAMILIES))
@pytest.mark.parametrize("count", [1, 2, 3, 4])
def test_the_parts_cover_every_kernel_below_the_entry_points_with_its_callees(family, count):
    fam = jit.FAMILIES[family]
    kn = importlib.import_module(fam.module_name)
    order = list(kn.signatures())
    below = jit._callees(kn, order)
    groups = fam.parts(count)
    assert 1 <= len(groups) <= count
    assert set().union(*groups) == set(order) - set(kn.ENTRY_POINTS)
    for group in groups:
        assert group == [n for n in order if n in group]  # in the family's order
        for name in group:
            assert below[name] <= set(group), name


# Run in a fresh cache directory: compile the family in this process, then report how many
# specialisations numba made of each kernel.
_OVERLOADS = """
import importlib, json, sys
from numba.core.registry import CPUDispatcher
from speedplan.core.jit import FAMILIES
fam = FAMILIES[sys.argv[1]]
kn = fam.compile()
print(json.dumps({n: len(d.overloads) for n in dir(kn)
                  if isinstance(d := getattr(kn, n), CPUDispatcher)
                  and d.targetoptions.get("inline", "never") == "never"}))
"""


@pytest.mark.slow
@pytest.mark.parametrize("family", list(jit.FAMILIES))
def test_a_fresh_compilation_makes_one_specialisation_of_each_kernel(family, tmp_path):
    env = {**os.environ, "PYTHONPATH": str(ROOT), "NUMBA_CACHE_DIR": str(tmp_path)}
    out = subprocess.run([sys.executable, "-c", _OVERLOADS, family], env=env,
                         capture_output=True, text=True, timeout=900, check=True).stdout
    counts = json.loads(out.splitlines()[-1])
    assert counts and all(c == 1 for c in counts.values()), counts


# The relaxation compiled as `speedplan compile` and background compilations do it (worker
# processes for its parts, the entry point last, loading the parts from the cache), then
# loaded by a new process without compiling, which solves one instance.
_SPLIT = """
import sys
import speedplan.core.jit as jit
jit.MAX_PARTS = 2
jit.part_count = lambda: 2  # two processes whatever the machine
jit._main(["--no-lock", "relaxation"])
"""
_SOLVE = """
import sys
import numpy as np
from speedplan.core.jit import FAMILIES
assert FAMILIES["relaxation"].load(), "not in the cache"
from speedplan.solve.paper import paper_instance
from speedplan import solve_discrete
inst = paper_instance("rnd", "cnst", "logrnd", n=300, seed=1)
r = solve_discrete(inst.w_max, inst.A, inst.J, refine="never", backend="banded")
np.save(sys.argv[1], np.concatenate((r.w, [r.lower_bound])))
"""


@pytest.mark.slow
def test_a_kernel_compiled_in_parts_computes_what_one_compiled_at_once_does(tmp_path):
    env = {**os.environ, "PYTHONPATH": str(ROOT), "NUMBA_CACHE_DIR": str(tmp_path / "cache")}
    subprocess.run([sys.executable, "-c", _SPLIT], env=env, check=True, timeout=900)
    subprocess.run([sys.executable, "-c", _SOLVE, str(tmp_path / "split.npy")], env=env,
                   check=True, timeout=900)
    # The same instance with the kernel of this process (compiled at once, or loaded).
    env["NUMBA_CACHE_DIR"] = str(tmp_path / "whole")
    env["SPEEDPLAN_BACKGROUND_COMPILE"] = "0"
    code = _SOLVE.replace('assert FAMILIES["relaxation"].load(), "not in the cache"',
                          'FAMILIES["relaxation"].compile()')
    subprocess.run([sys.executable, "-c", code, str(tmp_path / "whole.npy")], env=env,
                   check=True, timeout=900)
    np.testing.assert_array_equal(np.load(tmp_path / "split.npy"), np.load(tmp_path / "whole.npy"))
