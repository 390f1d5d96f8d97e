"""Fine grids: those finer than the relaxation resolves are refused up front, the others
answered by the banded method within physics (ruckig's optimum, finite differences).
"""

from __future__ import annotations

import math
import time
import warnings

import numpy as np
import pytest
from oracles import assert_physical
from shared import LGV

import speedplan as sp
from speedplan import InvalidInputError, Limits, Path, plan
from speedplan.geometry import Line
from speedplan.solve.banded import MAX_RAMP_STEPS, ramp_steps
from speedplan.solve.discrete import solve_problem
from speedplan.solve.paper import paper_instance
from speedplan.solve.problem import DiscreteProblem


def _line(length: float) -> Path:
    return Path.from_segments([Line(length)])


def _straight(n: int, h: float, w_max: float, a: float, j: float) -> DiscreteProblem:
    return DiscreteProblem(s=np.arange(n) * h, w_max=np.full(n, w_max),
                           accel=np.full(n - 1, a), decel=np.full(n - 1, a),
                           jerk=np.full(n - 2, j))


def test_ramp_steps_closed_form():
    # Constant bounds: on the plateau w = w_max, w' changes by at most J h / sqrt(w_max) per
    # step, so changing it by A takes ceil(A sqrt(w_max) / (J h)) steps.
    h, w_max, a, j = 0.01, 4.0, 2.0, 0.5
    p = _straight(4000, h, w_max, a, j)
    expected = math.ceil(a * math.sqrt(w_max) / (j * h))
    assert abs(ramp_steps(p) - expected) <= 1
    assert ramp_steps(p.scaled(0.37, 2.9)) == ramp_steps(p)


def test_isolated_small_jerk_bound_is_a_short_ramp():
    # The log-uniform J family has single rows with tiny J: a few steps, not a long ramp.
    inst = paper_instance("rnd", "cnst", "logrnd", n=1000, seed=1)
    p = DiscreteProblem(s=np.arange(1000.0), w_max=inst.w_max, accel=inst.A, decel=inst.A,
                        jerk=inst.J)
    j_small = int(np.argmin(inst.J))
    single = inst.A[j_small] * np.sqrt(np.max(inst.w_max)) / inst.J[j_small]
    assert single > MAX_RAMP_STEPS  # a per-node estimate would refuse it
    assert ramp_steps(p) < 100


@pytest.mark.parametrize("backend", ["auto", "banded", "clarabel"])
def test_unresolvable_grid_is_refused_before_any_solve(backend):
    p = _straight(12000, 1e-3, 4.0, 2.0, 0.5)  # ramps of 8 000 steps
    t0 = time.perf_counter()
    with pytest.raises(sp.InvalidInputError, match=r"steps of at least 0\.002"):
        solve_problem(p, backend=backend)
    assert time.perf_counter() - t0 < 2.0


def test_plan_on_a_too_fine_grid_says_which_grid_works():
    # Reproduced on main: 55 s and a 0.875 % gap (status "refined") at n = 20 000; SolverError
    # after 10-82 s from n = 30 000 on. The ramp there is 8 000 steps of 0.5 mm.
    path = sp.Path.from_segments([Line(10.0)])
    t0 = time.perf_counter()
    with pytest.raises(sp.InvalidInputError, match=r"n <= 10000 .*ds >= 0\.001"):
        sp.plan(path, LGV, n=20000)
    assert time.perf_counter() - t0 < 5.0


def test_plan_at_one_millimetre_still_solves():
    # The same limits on a 100 m straight with the same 1 mm step (ramps of 4 000 steps) are
    # resolvable: they must not be refused. A shorter straight keeps the test fast.
    path = sp.Path.from_segments([Line(10.0)])
    prof = sp.plan(path, LGV, n=10001, refine="never")
    assert prof.status == "optimal"
    sol = prof.solution
    assert sol.objective - sol.lower_bound <= 1e-6 * sol.objective


def test_a_fine_grid_answers_or_refuses_at_once():
    # n = 20 000 .. 200 000 on 10 m ended refined with a 0.9 % gap after 55 s, or in
    # SolverError after 10-82 s.
    lgv = Limits(v_max=2.0, a_max=1.0, a_lat_max=1.0, j_max=0.5)
    for n in (20_000, 200_000):
        t0 = time.perf_counter()
        try:
            with warnings.catch_warnings():
                warnings.simplefilter("ignore")
                profile = plan(_line(10.0), lgv, n=n)
        except InvalidInputError as exc:
            assert "too fine" in str(exc) and "n <=" in str(exc)
            assert time.perf_counter() - t0 < 30  # refused before any solve, not after one
        else:
            assert_physical(profile, 10.0, lgv)


def test_a_short_move_with_tiny_jerk_phases_is_answered_by_the_banded_method():
    # 4.5 cm at a_max 0.08, j_max 16 (the straight-move fuzz): 20 000 nodes. The banded method
    # must not stall at a certified gap of 1.5e-6 (then refused at 1e-6) and hand the move to
    # Clarabel, which takes 45 s to answer the same.
    length = 0.044611350496684306
    lim = Limits(v_max=22.852322121492875, a_max=0.0796425278765493, a_lat_max=1,
                 j_max=16.108500214027394, a_decel=0.0796425278765493)
    profile = plan(_line(length), lim)
    assert all(leg.solution.relaxation is None or leg.solution.relaxation.fallback is None
               for leg in profile.legs)
    assert_physical(profile, length, lim)
