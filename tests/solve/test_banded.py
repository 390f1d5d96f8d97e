"""The banded interior-point backend against the Clarabel reference."""

from __future__ import annotations

import numpy as np
import pytest

from speedplan.core.errors import InfeasibleError, SolverError
from speedplan.solve.banded import solve_relaxation_banded
from speedplan.solve.clarabel_ import solve_relaxation
from speedplan.solve.paper import FAMILIES, paper_instance
from speedplan.solve.problem import DiscreteProblem


def _py(kernel):
    """A kernel of the banded iteration, callable from Python."""
    from speedplan.solve._banded_ipm import python_callable

    return python_callable(kernel)

N = 200
EXACT_TOL = 1e-5  # the paper's exactness threshold on a jerk row


def _problem(w_max, A, J, s=None, w_start=0.0, w_end=0.0, w_min=None):
    n = w_max.size
    s = np.arange(n, dtype=float) if s is None else s
    return DiscreteProblem(
        s=s,
        w_max=np.asarray(w_max, float),
        accel=np.broadcast_to(np.asarray(A, float), (n - 1,)).copy(),
        decel=np.broadcast_to(np.asarray(A, float), (n - 1,)).copy(),
        jerk=np.broadcast_to(np.asarray(J, float), (n - 2,)).copy(),
        w_start=w_start,
        w_end=w_end,
        w_min=w_min,
    )


def _check_against_clarabel(p: DiscreteProblem, statuses=("Solved",)) -> None:
    ref = solve_relaxation(p)
    res = solve_relaxation_banded(p)
    assert res.status in statuses
    w = res.w
    # Feasible for the linear rows and the fixed ends, to rounding.
    scale = max(1.0, float(np.max(p.w_max)))
    assert w[0] == p.w_start and w[-1] == p.w_end
    assert np.all(w[1:-1] > 0)
    assert p.linear_violation(w) <= 1e-8 * scale
    # Same optimum; our bound is below our objective and the reference's.
    assert res.primal_objective == pytest.approx(ref.primal_objective, rel=1e-6)
    assert res.dual_objective <= res.primal_objective
    # Clarabel's objective is not a rigorous upper bound (its w may exceed bounds by ~1e-8).
    assert res.dual_objective <= ref.primal_objective * (1 + 1e-7)
    # Certified gap: as tight as Clarabel's default (1e-8) when "Solved"; when the method
    # stalls short of tol it says "AlmostSolved", whose contract is a certified gap <= 1e-5.
    gap_tol = 1e-8 if res.status == "Solved" else 1e-5
    assert res.primal_objective - res.dual_objective <= gap_tol * res.primal_objective
    assert res.primal_objective == pytest.approx(p.travel_time(w), rel=1e-6) or (
        p.jerk_violation(w) > 0  # when not exact, t exceeds τ/sqrt(w) at some nodes
    )
    # Same exactness verdict.
    assert (p.jerk_violation(res.w) <= EXACT_TOL) == (p.jerk_violation(ref.w) <= EXACT_TOL)


@pytest.mark.parametrize("family", FAMILIES)
@pytest.mark.parametrize("seed", [3, 4])
def test_paper_families_match_clarabel(family, seed):
    inst = paper_instance(*family, n=N, seed=seed)
    _check_against_clarabel(_problem(inst.w_max, inst.A, inst.J))


@pytest.mark.parametrize("seed", range(4))
def test_strongly_varying_jerk_matches_clarabel(seed):
    # These may stall a little short of tol=1e-8 on the internal gap (status "AlmostSolved",
    # certified gap observed 1e-9..2e-8); the objective must still match Clarabel to 1e-6.
    inst = paper_instance("rnd", "cnst", "logrnd", n=N, seed=seed)
    _check_against_clarabel(_problem(inst.w_max, inst.A, inst.J), ("Solved", "AlmostSolved"))


def test_log_uniform_jerk_is_mostly_inexact():
    # The non-exact path must be exercised: most of these relaxations violate jerk rows.
    verdicts = []
    for seed in range(4):
        inst = paper_instance("rnd", "cnst", "logrnd", n=N, seed=seed)
        p = _problem(inst.w_max, inst.A, inst.J)
        verdicts.append(p.jerk_violation(solve_relaxation_banded(p).w) > EXACT_TOL)
    assert sum(verdicts) >= 2


def test_non_uniform_grid():
    rng = np.random.default_rng(7)
    n = N
    s = np.concatenate(([0.0], np.cumsum(rng.uniform(0.3, 2.0, n - 1))))
    w_max = rng.uniform(0.5, 50.0, n)
    A = rng.uniform(0.5, 20.0, n - 1)
    J = rng.uniform(0.05, 20.0, n - 2)
    _check_against_clarabel(_problem(w_max, A, J, s=s))


def test_positive_boundary_values():
    inst = paper_instance("pw lin", "cnst", "cnst", n=N, seed=1)
    w_max = inst.w_max.copy()
    w_start, w_end = 0.5 * w_max[0], 0.3 * w_max[-1]
    _check_against_clarabel(_problem(w_max, inst.A, inst.J, w_start=w_start, w_end=w_end))


@pytest.mark.parametrize("seed", range(3))
def test_lower_bounds_match_clarabel(seed):
    # Moving starts are planned with lower jerk-limited envelopes (w_min rows): a floor on
    # the first nodes that forces the optimum to brake no faster than allowed, plus floors
    # inside that bind.
    from speedplan.solve.nojerk import max_feasible_w

    inst = paper_instance("rnd", "cnst", "cnst", n=N, seed=seed)
    w_max = inst.w_max.copy()
    # A start speed the braking bound can still bring down to every w_max ahead.
    w_start = 0.8 * min(w_max[0], float(np.min(w_max[1:] + np.cumsum(inst.A))))
    # Floors under the fastest feasible profile: feasible by construction, and binding.
    fastest = max_feasible_w(_problem(w_max, inst.A, inst.J, w_start=w_start))
    w_min = np.zeros(N)
    w_min[:20] = 0.9 * fastest[:20]
    w_min[0] = w_start
    mid = slice(N // 2 - 5, N // 2 + 5)
    w_min[mid] = 0.8 * fastest[mid]
    p = _problem(w_max, inst.A, inst.J, w_start=w_start, w_min=w_min)
    _check_against_clarabel(p)
    res = solve_relaxation_banded(p)
    assert np.all(res.w >= w_min - 1e-9)
    # The floors bind somewhere: without them the optimum is different.
    free = solve_relaxation_banded(_problem(w_max, inst.A, inst.J, w_start=w_start))
    assert np.any(free.w < w_min - 1e-6)


def test_infinite_jerk_rows_are_skipped():
    inst = paper_instance("rnd", "rnd", "rnd", n=N, seed=2)
    J = inst.J.copy()
    J[::3] = np.inf
    _check_against_clarabel(_problem(inst.w_max, inst.A, J))


def test_no_jerk_rows_gives_the_forward_backward_pass():
    from speedplan.solve.nojerk import max_feasible_w

    inst = paper_instance("rnd", "rnd", "cnst", n=N, seed=5)
    p = _problem(inst.w_max, inst.A, np.full(N - 2, np.inf))
    res = solve_relaxation_banded(p)
    assert np.allclose(res.w, max_feasible_w(p), rtol=1e-6, atol=1e-8)


@pytest.mark.parametrize("w_level", [0.01, 100.0])
def test_extreme_speed_bounds(w_level):
    rng = np.random.default_rng(11)
    w_max = np.full(N, w_level)
    J = 10.0 ** rng.uniform(-2, 2, N - 2)
    A = rng.uniform(0.1, 100.0, N - 1)
    _check_against_clarabel(_problem(w_max, A, J), ("Solved", "AlmostSolved"))


def test_nonconvergence_raises_solver_error():
    inst = paper_instance("rnd", "cnst", "cnst", n=N, seed=0)
    with pytest.raises(SolverError) as info:
        solve_relaxation_banded(_problem(inst.w_max, inst.A, inst.J), max_iter=3)
    assert info.value.backend == "banded"
    assert info.value.status == "MaxIterations"


def test_zero_speed_bound_inside_is_infeasible():
    w_max = np.full(20, 4.0)
    w_max[7] = 0.0
    with pytest.raises(InfeasibleError):
        solve_relaxation_banded(_problem(w_max, 1.0, 1.0))


@pytest.mark.parametrize("code", ["NUMERICAL_ERROR", "MAX_ITERATIONS", "NO_PROGRESS"])
def test_banded_stop_is_accepted_on_its_certificate_whatever_stopped_it(monkeypatch, code):
    # The kernel's stop reason does not decide: a feasible w with a certified gap <= 1e-5 is
    # "AlmostSolved" (here a converged iterate reported as a failure); a poor one raises.
    from speedplan.solve import _banded_ipm as ipm

    inst = paper_instance("rnd", "cnst", "cnst", n=N, seed=7)
    problem = _problem(inst.w_max, inst.A, inst.J)
    ref = solve_relaxation_banded(problem)
    assert ref.status == "Solved"
    real = ipm.iterate

    def relabelled(*args):
        it, _ = real(*args)
        return it, getattr(ipm, code)

    monkeypatch.setattr(ipm, "iterate", relabelled)
    res = solve_relaxation_banded(problem)
    assert res.status == "AlmostSolved"
    assert res.primal_objective == ref.primal_objective
    assert res.primal_objective - res.dual_objective <= 1e-5 * res.primal_objective
    with pytest.raises(SolverError, match=ipm.STATUS_NAMES[getattr(ipm, code)]):
        solve_relaxation_banded(problem, max_iter=2)


def _newton_state(seed: int):
    """A Newton system of the kernel at a random interior point (sizes of an n=60 problem)."""
    from speedplan.solve import _banded_ipm as ipm
    from speedplan.solve.banded import _prepare, unit_scales
    from speedplan.solve.nojerk import positive_feasible_w

    inst = paper_instance("rnd", "cnst", "cnst", n=60, seed=seed)
    p = _problem(inst.w_max, inst.A, inst.J)
    unit = p.scaled(*unit_scales(p))
    d = _prepare(unit, positive_feasible_w(unit)[1:-1])
    lay = d.lay
    rng = np.random.default_rng(seed)
    pt = ipm.empty(ipm.Point, lay)
    pt.sl[:], pt.yl[:] = 10.0 ** rng.uniform(-2, 2, (2, lay.n_lin))
    # Both cones of every node strictly interior: z² < w and t z > 1.
    pt.w[:] = 10.0 ** rng.uniform(-1, 1, lay.m)
    pt.z[:] = np.sqrt(pt.w) * rng.uniform(0.05, 0.95, lay.m)
    pt.t[:] = (1.0 + 10.0 ** rng.uniform(-2, 0, lay.m)) / pt.z
    pt.ys[:] = rng.normal(size=(3, lay.nc))
    pt.ys[0] = np.hypot(pt.ys[1], pt.ys[2]) * (1.0 + 10.0 ** rng.uniform(-2, 0, lay.nc))
    sc = ipm.Scaling.identity(lay)
    _py(ipm.scaling_into)(pt, sc)
    fac = ipm.empty(ipm.Factor, lay)
    assert _py(ipm.factor_into)(d, sc, pt.yl, pt.sl, fac)
    res = ipm.empty(ipm.Residual, lay)
    _py(ipm.dual_residual_into)(d, pt, res)  # newton_into's bx is the iterate's dual residual
    return ipm, d, sc, fac, pt, res, float(rng.normal())


@pytest.mark.parametrize("seed", [0, 1, 2])
def test_newton_refines_only_above_its_residual_threshold(seed):
    # One round of iterative refinement runs iff the residual of G'Δy = bx exceeds
    # refine_above; below the threshold the unrefined direction is returned as it is.
    ipm, d, sc, fac, pt, res, rp = _newton_state(seed)
    lay = d.lay

    def direction(refine_above):
        dn = ipm.empty(ipm.Direction, lay)
        bx = [a.copy() for a in res]
        _py(ipm.newton_into)(d, sc, fac, pt, res, rp, False, 0.0, 0.0,
                             refine_above, dn)
        # The refinement forms its right-hand side in res and puts bx back, bit for bit.
        for a, b in zip(res, bx, strict=True):
            np.testing.assert_array_equal(a, b)
        gx = (np.zeros(lay.m), np.zeros(lay.m), np.zeros(lay.m))
        _py(ipm.g_adjoint_into)(d, dn.dyl, dn.dys, *gx, ipm.ADJ_SET)
        residual = np.sqrt(sum(float(np.sum((b - g) ** 2))
                               for b, g in zip((res.gw, res.gt, res.gz), gx, strict=True)))
        return dn, residual

    plain, residual = direction(np.inf)
    refined, _ = direction(0.0)
    assert residual > 0.0
    assert any(not np.array_equal(a, b) for a, b in zip(plain, refined, strict=True))
    for a, b in zip(direction(2.0 * residual)[0], plain, strict=True):
        np.testing.assert_array_equal(a, b)
    for a, b in zip(direction(0.5 * residual)[0], refined, strict=True):
        np.testing.assert_array_equal(a, b)
