"""Lateral-jerk rows (a second stencil family) in the banded method, against Clarabel."""

from __future__ import annotations

import numpy as np
import pytest

from speedplan.solve.banded import solve_relaxation_banded
from speedplan.solve.clarabel_ import solve_relaxation
from speedplan.solve.discrete import solve_problem
from speedplan.solve.paper import paper_instance
from speedplan.solve.problem import DiscreteProblem, StencilRows

N = 200


def _lateral_problem(seed: int, *, jerk: bool = True, w_start: float = 0.0,
                     lateral_inf_every: int = 0) -> DiscreteProblem:
    """A paper instance with lateral-jerk rows ``|κ' w + κ w'| sqrt(w) <= B`` on a random κ."""
    rng = np.random.default_rng(seed)
    inst = paper_instance("rnd", "cnst", "cnst", n=N, seed=seed)
    h = 1.0
    s = np.arange(N) * h
    # A smooth random curvature (a few bends) and its derivative at interior nodes.
    freq = rng.uniform(0.01, 0.05, 3)
    phase = rng.uniform(0, 2 * np.pi, 3)
    kappa = sum(0.1 * np.sin(f * s + p) for f, p in zip(freq, phase, strict=True))
    dkappa = sum(0.1 * f * np.cos(f * s + p) for f, p in zip(freq, phase, strict=True))
    ki, dki = kappa[1:-1], dkappa[1:-1]
    # Central difference for w': (w_{i+1} - w_{i-1}) / 2h.
    coef = np.column_stack((-ki / (2 * h), dki, ki / (2 * h)))
    bound = rng.uniform(0.02, 0.5, N - 2)
    if lateral_inf_every:
        bound[::lateral_inf_every] = np.inf
    J = inst.J if jerk else np.full(N - 2, np.inf)
    return DiscreteProblem(s=s, w_max=inst.w_max, accel=inst.A, decel=inst.A, jerk=J,
                           w_start=w_start, lateral=StencilRows(coef=coef, bound=bound))


def _check(p: DiscreteProblem) -> None:
    assert p.has_lateral
    ref = solve_relaxation(p)
    res = solve_relaxation_banded(p)
    assert res.status in ("Solved", "AlmostSolved")
    scale = max(1.0, float(np.max(p.w_max)))
    assert p.linear_violation(res.w) <= 1e-8 * scale
    assert res.primal_objective == pytest.approx(ref.primal_objective, rel=1e-6)
    assert res.dual_objective == pytest.approx(ref.dual_objective, rel=1e-6)
    # The certified bound never exceeds Clarabel's objective (nor our own).
    assert res.dual_objective <= res.primal_objective
    assert res.dual_objective <= ref.primal_objective * (1 + 1e-9)
    assert res.primal_objective - res.dual_objective <= 1e-6 * res.primal_objective


@pytest.mark.parametrize("seed", range(4))
def test_jerk_and_lateral_rows_match_clarabel(seed):
    _check(_lateral_problem(seed))


@pytest.mark.parametrize("seed", range(3))
def test_only_lateral_rows_match_clarabel(seed):
    _check(_lateral_problem(10 + seed, jerk=False))


def test_some_lateral_rows_infinite_and_moving_start():
    p = _lateral_problem(21, lateral_inf_every=3, w_start=0.0)
    w_start = 0.5 * float(np.min(p.w_max[:5]))
    p = DiscreteProblem(s=p.s, w_max=p.w_max, accel=p.accel, decel=p.decel, jerk=p.jerk,
                        w_start=w_start, lateral=p.lateral)
    _check(p)


def test_lateral_rows_bind():
    # The lateral rows change the answer: without them the optimum is faster.
    p = _lateral_problem(2)
    free = DiscreteProblem(s=p.s, w_max=p.w_max, accel=p.accel, decel=p.decel, jerk=p.jerk)
    assert (solve_relaxation_banded(p).primal_objective
            > solve_relaxation_banded(free).primal_objective * (1 + 1e-3))


def test_solve_problem_accepts_banded_with_lateral_rows():
    p = _lateral_problem(3)
    fast = solve_problem(p, backend="banded")
    ref = solve_problem(p, backend="clarabel")
    assert fast.backend == "banded"  # answered by the banded method, no fallback
    assert fast.relaxation is not None and fast.relaxation.fallback is None
    assert fast.lower_bound == pytest.approx(ref.lower_bound, rel=1e-6)
    assert fast.lower_bound <= ref.objective * (1 + 1e-9)
    assert (fast.exact, fast.status) == (ref.exact, ref.status)
