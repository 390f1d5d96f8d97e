"""Solver layer: the paper's problem, its relaxation, refinement and certificates."""

from __future__ import annotations

from pathlib import Path

import cvxpy as cp
import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from shared import examples

from speedplan import InfeasibleError, InvalidInputError, SpeedplanWarning, solve_discrete
from speedplan.solve import JERK_TOL, DiscreteProblem, solve_problem
from speedplan.solve.discrete import _scale_into_jerk_bounds
from speedplan.solve.nojerk import max_feasible_w
from speedplan.solve.paper import FAMILIES, paper_instance

N_CI = 200


def _assert_feasible(sol, w_max, A, J, h=1.0, tol=1e-7):
    w = sol.w
    assert w[0] == 0.0 and w[-1] == 0.0
    assert np.all(w >= 0)
    assert np.all(w <= w_max + 1e-12)
    assert np.all(np.abs(np.diff(w)) <= np.broadcast_to(A, w.size - 1) * h + tol * w_max.max())
    d2 = w[:-2] - 2 * w[1:-1] + w[2:]
    viol = np.abs(d2) - h**2 * np.broadcast_to(J, w.size - 2) / np.sqrt(w[1:-1])
    assert viol.max() <= JERK_TOL
    assert sol.objective == pytest.approx(np.sum(h / np.sqrt(w[1:-1])), rel=1e-12)


@pytest.mark.parametrize("family", [f for f in FAMILIES if f[1] == "cnst" and f[2] == "cnst"])
@pytest.mark.parametrize("seed", range(3))
def test_constant_bounds_relaxation_is_exact(family, seed):
    inst = paper_instance(*family, n=N_CI, seed=seed)
    sol = solve_discrete(inst.w_max, inst.A, inst.J)
    assert sol.exact and sol.status == "optimal" and not sol.refined
    assert sol.jerk_violation <= JERK_TOL
    assert abs(sol.gap) < 1e-6
    _assert_feasible(sol, inst.w_max, inst.A, inst.J)


@pytest.mark.parametrize("family", FAMILIES)
def test_every_paper_family_returns_feasible_certified_solution(family):
    inst = paper_instance(*family, n=N_CI, seed=11)
    sol = solve_discrete(inst.w_max, inst.A, inst.J)
    _assert_feasible(sol, inst.w_max, inst.A, inst.J)
    assert sol.lower_bound <= sol.objective * (1 + 1e-9)
    assert sol.gap < 0.01
    if family[1:] == ("cnst", "cnst"):
        assert sol.exact


def test_strongly_varying_jerk_is_mostly_inexact_and_refinement_closes_gap():
    results = [
        solve_discrete(*(lambda i: (i.w_max, i.A, i.J))(paper_instance("rnd", "cnst", "logrnd",
                                                                       n=N_CI, seed=s)))
        for s in range(6)
    ]
    inexact = [r for r in results if not r.exact]
    assert len(inexact) > len(results) / 2
    for r in inexact:
        assert r.refined and r.status == "refined"
        assert r.relaxation.jerk_violation > JERK_TOL
        assert r.jerk_violation <= JERK_TOL
        assert 0 <= r.gap < 0.01


def test_negative_jerk_rows_never_violated_with_constant_bounds():
    # Proposition 4.1 of the paper: relaxed solutions never violate negative jerk rows.
    for seed in range(4):
        inst = paper_instance("rnd", "cnst", "cnst", n=N_CI, seed=seed)
        sol = solve_discrete(inst.w_max, inst.A, inst.J, refine="always")
        w = sol.relaxation.w
        d2 = w[:-2] - 2 * w[1:-1] + w[2:]
        assert np.max(-d2 - inst.J / np.sqrt(w[1:-1])) <= JERK_TOL


def _cvxpy_relaxation(w_max, A, J, h=1.0, jerk=True):
    n = w_max.size
    w = cp.Variable(n)
    t = cp.Variable(n - 2)
    cons = [w[0] == 0, w[-1] == 0, w <= w_max, cp.abs(cp.diff(w)) <= A * h,
            t >= h * cp.power(w[1:-1], -0.5)]
    if jerk:
        d2 = w[:-2] - 2 * w[1:-1] + w[2:]
        cons += [t >= d2 / (h * J), t >= -d2 / (h * J)]
    prob = cp.Problem(cp.Minimize(cp.sum(t)), cons)
    prob.solve(solver=cp.CLARABEL, tol_gap_abs=1e-10, tol_gap_rel=1e-10, tol_feas=1e-10)
    return prob.value


@pytest.mark.parametrize("family", [("rnd", "cnst", "cnst"), ("pw lin", "rnd", "rnd"),
                                    ("pw cnst", "reg", "logrnd")])
def test_objective_matches_independent_cvxpy_formulation(family):
    inst = paper_instance(*family, n=60, seed=3)
    sol = solve_discrete(inst.w_max, inst.A, inst.J, refine="never") if family[2] != "logrnd" \
        else solve_discrete(inst.w_max, inst.A, inst.J)
    ref = _cvxpy_relaxation(inst.w_max, inst.A, inst.J)
    assert sol.lower_bound == pytest.approx(ref, rel=1e-6)


def test_no_jerk_pass_matches_cvxpy_and_socp_with_huge_jerk():
    inst = paper_instance("rnd", "rnd", "cnst", n=80, seed=5)
    sol = solve_discrete(inst.w_max, inst.A, np.inf)
    assert sol.backend == "pass" and sol.status == "optimal"
    assert sol.objective == pytest.approx(_cvxpy_relaxation(inst.w_max, inst.A, None, jerk=False),
                                          rel=1e-6)
    socp = solve_discrete(inst.w_max, inst.A, 1e9)
    assert socp.objective == pytest.approx(sol.objective, rel=1e-6)
    assert np.max(np.abs(socp.w - sol.w)) <= 1e-5 * inst.w_max.max()


def test_no_jerk_pass_is_pointwise_maximal_with_separate_braking():
    n = 400
    rng = np.random.default_rng(0)
    w_max = rng.uniform(0.5, 50, n)
    acc, dec = rng.uniform(0.5, 5, n - 1), rng.uniform(0.5, 5, n - 1)
    sol = solve_discrete(w_max, (acc, dec), np.inf)
    w = sol.w
    dw = np.diff(w)
    assert np.all(dw <= acc + 1e-12) and np.all(-dw <= dec + 1e-12)
    # Maximal: every node is held by its bound or by a tight acceleration/braking row.
    tight = (np.isclose(w, w_max)
             | np.isclose(np.r_[np.inf, dw], np.r_[np.inf, acc])
             | np.isclose(np.r_[-dw, np.inf], np.r_[dec, np.inf]))
    assert tight.all()


def test_no_jerk_pass_on_a_million_nodes_is_linear_and_exact():
    n = 1_000_000
    p = DiscreteProblem(s=np.arange(n, dtype=float), w_max=np.full(n, 9.0), accel=np.ones(n - 1),
                        decel=np.full(n - 1, 0.5), jerk=np.full(n - 2, np.inf))
    w = max_feasible_w(p)
    assert w.max() == 9.0
    assert np.argmax(w) == 9  # accelerates 1 per step from rest
    assert w[-19] == pytest.approx(9.0) and w[-20] == 9.0  # brakes 0.5 per step


@settings(max_examples=examples(25), deadline=None)
@given(rho=st.floats(0.05, 20.0), seed=st.integers(0, 10_000))
def test_paper_scaling_property(rho, seed):
    # (h, A, J) -> (ρh, A/ρ, J/ρ²) keeps w and multiplies the objective by ρ.
    inst = paper_instance("pw lin", "cnst", "cnst", n=40, seed=seed)
    base = solve_discrete(inst.w_max, inst.A, inst.J)
    scaled = solve_discrete(inst.w_max, inst.A / rho, inst.J / rho**2, h=rho)
    assert scaled.objective == pytest.approx(rho * base.objective, rel=1e-6)
    assert np.max(np.abs(scaled.w - base.w)) <= 1e-5 * inst.w_max.max()
    assert scaled.exact == base.exact


@settings(max_examples=examples(15), deadline=None)
@given(omega=st.floats(1e-3, 1e3), seed=st.integers(0, 10_000))
def test_speed_scaling_property(omega, seed):
    # (w_max, A, J) -> (ω w_max, ω A, ω^1.5 J) scales w by ω and time by 1/sqrt(ω).
    inst = paper_instance("rnd", "cnst", "cnst", n=40, seed=seed)
    base = solve_discrete(inst.w_max, inst.A, inst.J)
    scaled = solve_discrete(omega * inst.w_max, omega * inst.A, omega**1.5 * inst.J)
    assert (scaled.status, scaled.exact) == (base.status, base.exact)
    assert scaled.objective == pytest.approx(base.objective / np.sqrt(omega), rel=1e-6)


def test_a_priori_certificate_implies_exact():
    w_max = np.full(100, 4.0)
    sol = solve_discrete(w_max, 0.5, 0.2)
    assert sol.exact_a_priori and sol.exact
    bumpy = paper_instance("rnd", "cnst", "cnst", n=100, seed=1)
    sol = solve_discrete(bumpy.w_max, bumpy.A, bumpy.J)
    assert not sol.exact_a_priori  # a random w_max breaks positive jerk rows
    varying = solve_discrete(w_max, 0.5, np.linspace(0.1, 0.3, 98))
    assert not varying.exact_a_priori  # the corollary needs constant bounds


def test_refine_always_agrees_with_exact_relaxation():
    inst = paper_instance("pw cnst", "cnst", "cnst", n=100, seed=2)
    sol = solve_discrete(inst.w_max, inst.A, inst.J, refine="always")
    assert sol.refined and sol.exact and sol.status == "optimal"
    assert sol.refinement.objective == pytest.approx(sol.objective, rel=1e-5)
    assert sol.refinement.objective >= sol.lower_bound * (1 - 1e-9)


def test_refine_never_warns_and_reports_violation():
    inst = paper_instance("rnd", "cnst", "logrnd", n=N_CI, seed=0)
    with pytest.warns(SpeedplanWarning, match="relaxed"):
        sol = solve_discrete(inst.w_max, inst.A, inst.J, refine="never")
    assert sol.status == "relaxed" and not sol.feasible
    assert sol.jerk_violation > JERK_TOL


def test_scaling_fallback_is_feasible_and_bounded_by_relaxation():
    inst = paper_instance("rnd", "cnst", "logrnd", n=N_CI, seed=0)
    with pytest.warns(SpeedplanWarning, match="relaxed"):
        sol = solve_discrete(inst.w_max, inst.A, inst.J, refine="never")
    p = DiscreteProblem(s=np.arange(N_CI, dtype=float), w_max=inst.w_max, accel=inst.A,
                        decel=inst.A, jerk=inst.J)
    w = _scale_into_jerk_bounds(p, sol.w)
    assert w is not None
    assert p.jerk_violation(w) <= 1e-9 and p.linear_violation(w) <= 1e-9
    assert p.travel_time(w) >= sol.lower_bound


def test_nonuniform_grid_matches_uniform_problem_in_the_limit():
    # A rest-to-rest move on a graded grid agrees with the uniform grid to discretisation error.
    n = 301
    u = np.linspace(0, 1, n)
    graded = 30 * (u - 0.15 * np.sin(2 * np.pi * u) / (2 * np.pi))
    objectives = []
    for grid in (np.linspace(0, 30, n), graded):
        p = DiscreteProblem(s=grid, w_max=np.full(n, 4.0), accel=np.full(n - 1, 2.0),
                            decel=np.full(n - 1, 2.0), jerk=np.full(n - 2, 1.0))
        sol = solve_problem(p)
        assert sol.exact and p.linear_violation(sol.w) < 1e-6
        objectives.append(sol.objective)
    assert objectives[1] == pytest.approx(objectives[0], rel=5e-3)


def test_nonzero_boundary_values():
    w_max = np.full(100, 4.0)
    sol = solve_discrete(w_max, 0.5, 0.2, w_start=1.0, w_end=0.25)
    assert sol.w[0] == 1.0 and sol.w[-1] == 0.25 and sol.feasible


@pytest.mark.parametrize(
    ("kwargs", "name"),
    [
        ({"w_max": np.ones((3, 3)), "A": 1, "J": 1}, "w_max"),
        ({"w_max": [1, np.nan, 1], "A": 1, "J": 1}, "w_max"),
        ({"w_max": [1, -1, 1, 1], "A": 1, "J": 1}, "w_max"),
        ({"w_max": [1, 0, 1, 1], "A": 1, "J": 1}, "w_max"),
        ({"w_max": [1, 1], "A": 1, "J": 1}, "w_max"),
        ({"w_max": np.ones(5), "A": 0, "J": 1}, "A"),
        ({"w_max": np.ones(5), "A": np.ones(3), "J": 1}, "A"),
        ({"w_max": np.ones(5), "A": (1, 2, 3), "J": 1}, "A"),
        ({"w_max": np.ones(5), "A": 1, "J": -1}, "J"),
        ({"w_max": np.ones(5), "A": 1, "J": np.inf, "h": 0}, "h"),
        ({"w_max": np.ones(5), "A": 1, "J": 1, "refine": "sometimes"}, "refine"),
        ({"w_max": np.ones(5), "A": 1, "J": 1, "backend": "mosek"}, "backend"),
        ({"w_max": np.ones(5), "A": np.inf, "J": 1}, "A"),
    ],
)
def test_bad_input_names_the_argument(kwargs, name):
    with pytest.raises(InvalidInputError, match=f"`{name}"):
        solve_discrete(**kwargs)


def test_unreachable_boundary_is_infeasible_with_location():
    w_max = np.full(50, 4.0)
    w_max[10] = 0.1
    with pytest.raises(InfeasibleError, match="brake") as info:
        solve_discrete(w_max, 0.05, 1.0, w_start=4.0)
    assert info.value.constraint == "decel" and info.value.s == 10.0
    with pytest.raises(InfeasibleError, match="w_start"):
        solve_discrete(np.full(10, 1.0), 1.0, 1.0, w_start=2.0)


@pytest.mark.parametrize("J", [1.0, np.inf])
def test_unreachable_boundaries_name_the_constraint_with_and_without_jerk_rows(J):
    # Without jerk rows the pass answers alone; it must refuse the same boundary values.
    w_max = np.full(50, 4.0)
    w_max[10] = 0.1
    with pytest.raises(InfeasibleError, match="brake") as info:
        solve_discrete(w_max, 0.05, J, w_start=4.0)
    assert info.value.constraint == "decel" and info.value.s == 10.0
    with pytest.raises(InfeasibleError, match="accelerate") as info:
        solve_discrete(w_max, 0.05, J, w_end=4.0)
    assert info.value.constraint == "accel" and info.value.s == 10.0
    with pytest.raises(InfeasibleError, match="w_start") as info:
        solve_discrete(np.full(10, 1.0), 1.0, J, w_start=2.0)
    assert info.value.constraint == "w_start"
    with pytest.raises(InfeasibleError, match="w_end") as info:
        solve_discrete(np.full(10, 1.0), 1.0, J, w_end=2.0)
    assert info.value.constraint == "w_end"
    # Within the tolerance of the check, a boundary value just beyond reach is accepted.
    ok = solve_discrete(np.full(10, 1.0), 1.0, J, w_start=1.0 + 1e-12)
    assert ok.w[0] == pytest.approx(1.0, abs=1e-11)


@pytest.mark.parametrize("backend", ["banded", "clarabel"])
@pytest.mark.parametrize("h", [1e-3, 0.5, 40.0])
def test_forced_standstill_is_infeasible_at_its_own_position(h, backend):
    # A zero bound between nodes (or at one) that the acceleration rows carry onto the grid
    # leaves no positive w inside; the error names the node in the problem's own grid
    # positions. It named the solver's rescaled ones (unit mean step) before.
    n = 41
    w_max = np.full(n, 4.0)
    w_max[17] = 0.0  # solve_discrete refuses this input; plan() grids can carry it
    problem = DiscreteProblem(s=10.0 + h * np.arange(n), w_max=w_max, accel=np.ones(n - 1),
                              decel=np.ones(n - 1), jerk=np.ones(n - 2))
    with pytest.raises(InfeasibleError, match="w > 0") as info:
        solve_problem(problem, backend=backend)
    assert info.value.constraint == "w_max"
    assert info.value.s == pytest.approx(10.0 + 17 * h, rel=1e-12)
    assert f"s={10.0 + 17 * h:.6g}" in str(info.value)


@pytest.mark.parametrize("family", [("rnd", "cnst", "cnst"), ("rnd", "cnst", "logrnd")])
def test_banded_backend_gives_the_same_certified_answer(family):
    inst = paper_instance(*family, n=N_CI, seed=7)
    ref = solve_discrete(inst.w_max, inst.A, inst.J, backend="clarabel")
    fast = solve_discrete(inst.w_max, inst.A, inst.J, backend="banded")
    assert fast.backend == "banded"
    assert (fast.exact, fast.status) == (ref.exact, ref.status)
    assert fast.lower_bound == pytest.approx(ref.lower_bound, rel=1e-6)
    assert fast.objective == pytest.approx(ref.objective, rel=1e-5)


def test_a_failing_backend_falls_back_to_the_other(monkeypatch):
    from speedplan.core.errors import SolverError
    from speedplan.solve import discrete

    def jammed(problem):
        raise SolverError("stopped with status NoProgress", backend="banded", status="NoProgress")

    monkeypatch.setitem(discrete.RELAXATION_BACKENDS, "banded", jammed)
    inst = paper_instance("rnd", "cnst", "cnst", n=N_CI, seed=7)
    sol = solve_discrete(inst.w_max, inst.A, inst.J, backend="banded")
    ref = solve_discrete(inst.w_max, inst.A, inst.J, backend="clarabel")
    assert sol.backend == "clarabel"
    assert sol.relaxation.fallback == "banded: stopped with status NoProgress"
    assert sol.objective == pytest.approx(ref.objective, rel=1e-12)


def test_fine_uniform_grid_gets_the_same_answer_from_auto_and_clarabel():
    # Grid steps of a few millimetres make the relaxation hard (docs/performance.md): the
    # banded method may give up there; whichever backend answers, the answer is Clarabel's.
    import speedplan as sp
    from speedplan.io import read_path

    path = read_path(str(Path(__file__).parents[2] / "paths" / "u_turn.json"))
    limits = sp.Limits(v_max=2.0, a_max=1.0, a_lat_max=1.0, j_max=0.5)
    auto = sp.plan(path, limits, n=5000, refine="never")
    ref = sp.plan(path, limits, n=5000, refine="never", backend="clarabel")
    assert auto.status == ref.status == "optimal"
    # Each certificate holds against the other backend's answer. Clarabel's AlmostSolved
    # point may exceed a jerk row by its reduced tolerance (measured: 5.4e-5 of the row,
    # within the exactness test), which makes its travel time up to ~2e-6 shorter than the
    # relaxation's optimum: the banded method's bound may lie that far above it.
    assert ref.lower_bound <= auto.solution.objective
    assert auto.lower_bound <= ref.solution.objective * (1 + 5e-6)
    assert auto.duration == pytest.approx(ref.duration, rel=5e-6)
    # Whichever backend answered, its certificate is tight; Clarabel may stop at AlmostSolved
    # on this grid with its reduced tolerances, its bound then 1.3e-6 below (measured).
    assert auto.solution.objective - auto.lower_bound <= 1e-6 * auto.solution.objective
    assert auto.lower_bound == pytest.approx(ref.lower_bound, rel=1e-5)

def test_a_relaxation_stopped_short_of_its_optimum_is_polished():
    # A 27 m straight move on a 1 cm grid: Clarabel stops at reduced accuracy (AlmostSolved,
    # a certified gap of 1.5e-5) at a point 2.3e-6 slower than the relaxation's optimum,
    # which the banded method reaches with a gap of 1e-9. Exact either way; the refinement
    # from Clarabel's point brings the two backends' plans together.
    import speedplan as sp
    from speedplan.geometry.primitives import Line
    from speedplan.solve.discrete import POLISH_GAP

    path = sp.Path.from_segments([Line(27.337)])
    limits = sp.Limits(v_max=1.0903, a_max=0.3025, a_lat_max=1.0, j_max=1.9522)
    ref = sp.plan(path, limits, ds=0.01, backend="clarabel")
    banded = sp.plan(path, limits, ds=0.01, backend="banded")
    assert ref.status == banded.status == "optimal"
    assert ref.duration == pytest.approx(banded.duration, rel=POLISH_GAP)
    # Each certificate holds against the other backend's plan, Clarabel's within the
    # polish's tolerance: its polished point may exceed a row by that much (measured: 1.3e-7
    # shorter than the banded method's bound with clarabel 0.11).
    assert ref.lower_bound <= banded.solution.objective
    assert banded.lower_bound <= ref.solution.objective * (1 + POLISH_GAP)
    assert ref.verify().ok



@pytest.mark.parametrize("name", ["slow_zone.json", "u_turn.json"])
def test_very_fine_grid_gets_a_certified_answer(name):
    # At n = 20 000 (steps of 1-2 mm) the banded iterates' dual residual stalls near 1e-5
    # while the certified gap reaches 1e-11 (slow_zone; the rounded gap went negative and the
    # method used to run to max_iter), or the Newton matrix stops factoring one step after a
    # certified gap of 1e-7 (u_turn). Such answers are accepted on their certificate. Which
    # backend answered and in how many iterations is performance, printed by
    # benchmarks/bench_fine_grids.py, not checked here.
    import speedplan as sp
    from speedplan.io import read_path

    path = read_path(str(Path(__file__).parents[2] / "paths" / name))
    limits = sp.Limits(v_max=2.0, a_max=1.0, a_lat_max=1.0, j_max=0.5)
    prof = sp.plan(path, limits, n=20000, refine="never")
    sol = prof.solution
    assert prof.status == "optimal"
    assert sol.objective - sol.lower_bound <= 1e-6 * sol.objective
    assert prof.verify().ok


def test_a_relaxed_law_that_stops_inside_the_leg_falls_back_to_the_other_backend(monkeypatch):
    # Trust fuzz, first use: while the banded kernel compiled, Clarabel answered a 7 km move
    # (steps 1e-8..72 m) "AlmostSolved" with w = 0 next to the end; plan() then raised
    # SolverError ("comes to rest before its end"). Such an answer is a stall, not a solution.
    from dataclasses import replace

    from speedplan.solve import discrete

    inst = paper_instance(*FAMILIES[0], n=200, seed=0)
    reference = solve_discrete(inst.w_max, inst.A, inst.J, backend="banded", refine="never")
    clarabel = discrete.RELAXATION_BACKENDS["clarabel"]

    def stalled(unit):
        out = clarabel(unit)
        w = out.w.copy()
        w[-2] = 0.0
        return replace(out, w=w, status="AlmostSolved")

    monkeypatch.setitem(discrete.RELAXATION_BACKENDS, "clarabel", stalled)
    sol = solve_discrete(inst.w_max, inst.A, inst.J, backend="clarabel", refine="never")
    assert sol.relaxation.backend == "banded"
    assert "comes to rest inside the leg" in sol.relaxation.fallback
    assert np.isfinite(sol.objective)
    np.testing.assert_allclose(sol.w, reference.w, rtol=1e-12, atol=0)


def _bent(n=2001, length=2.0, k=0.1, excess=0.14):
    """A fine uniform grid and ``w = 0.5 + k (s - 1)² / 2`` whose curvature ``w'' = k`` is
    ``excess`` above the jerk rows where ``w`` is largest: ``k sqrt(max w) = (1 + excess) J``."""
    s = np.linspace(0.0, length, n)
    w = 0.5 + 0.5 * k * (s - 1.0) ** 2
    jerk = np.full(n - 2, k * np.sqrt(w[1:-1].max()) / (1.0 + excess))
    problem = DiscreteProblem(s=s, w_max=np.full(n, 1.0), accel=np.full(n - 1, 1.0),
                              decel=np.full(n - 1, 1.0), jerk=jerk, w_start=float(w[0]),
                              w_end=float(w[-1]))
    return problem, w


def test_a_row_exceeded_by_a_fraction_of_itself_is_seen_on_a_fine_grid():
    # The paper's measure τ² (|w''| - J / sqrt(w)) shrinks with the square of the step: a
    # 14 % excess on a 1 mm grid is 1e-8, inside its exactness threshold; relative to the
    # row it is the 14 %.
    problem, w = _bent()
    assert problem.jerk_violation(w) <= problem.jerk_tol
    assert problem.relative_row_excess(w) == pytest.approx(0.14, rel=1e-6)
    held, _ = _bent(excess=0.0)  # the same point against rows it meets
    assert held.relative_row_excess(w) <= 1e-8  # the second difference to rounding


def test_a_relaxed_point_over_its_rows_by_a_fraction_is_not_called_exact(monkeypatch):
    # A relaxation backend answering that point: the paper's test alone calls it exact
    # ('optimal'), although its law breaks the jerk limit 1.14x; it is 'relaxed'
    # (refine='never') with a warning.
    from speedplan.solve import discrete
    from speedplan.solve.clarabel_ import RelaxationResult

    problem, w = _bent()
    scale = discrete.unit_scales(problem)

    def answers_the_bent_point(unit):
        wu = w / scale[1]
        t = unit.travel_time(wu)
        return RelaxationResult(w=wu, t=np.full(unit.n - 1, t / (unit.n - 1)),
                                primal_objective=t, dual_objective=t, status="Solved",
                                iterations=1, solve_time=0.0, setup_time=0.0)

    monkeypatch.setitem(discrete.RELAXATION_BACKENDS, "clarabel", answers_the_bent_point)
    with pytest.warns(SpeedplanWarning, match="relaxation is not exact"):
        sol = solve_problem(problem, refine="never", backend="clarabel", fallback=False)
    assert not sol.exact and sol.status == "relaxed"
