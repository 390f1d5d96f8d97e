"""The planning strategy: named attempts, their record on the profile, the time limit."""

from __future__ import annotations

import importlib
import multiprocessing
import os
import pickle
import signal
import time
import warnings
from concurrent.futures import ThreadPoolExecutor

import numpy as np
import pytest
from oracles import measure, ruckig_duration, within_promise
from shared import LGV

import speedplan as sp
from speedplan import strategy
from speedplan.core.deadline import deadline, remaining
from speedplan.geometry import Line
from speedplan.model import PlanRequest
from speedplan.route import Route, RouteEdge, RouteNode
from speedplan.solve import DiscreteProblem
from speedplan.solve.clarabel_ import solve_relaxation

plan_request = importlib.import_module("speedplan.plan").plan_request

STRAIGHT = sp.Path.from_segments([Line(30.0)])
# A 4 m G2 path whose tiny a_max makes every jerk phase ~8 ms long: its default grid hits
# the node cap and, without a limit, the plan takes minutes on a loaded machine.
G2_4M = sp.Path.from_waypoints([
    [0, 0], [0.12426521336474784, -0.11657631877453342],
    [3.021780629947684, 0.018193808385309485], [3.207499798766692, -0.2747489556759499],
    [3.9813199879850347, 0.1445236020023441]])
G2_4M_LIMITS = sp.Limits(v_max=16.418898422873855, a_max=0.11059941918961164,
                         a_lat_max=0.1453314309003239, j_max=13.58945597172854)


def test_a_plan_records_which_attempt_answered():
    profile = sp.plan(STRAIGHT, LGV)
    assert [(a.name, a.leg, a.outcome) for a in profile.attempts] == [
        ("model", None, "answered"), ("closed_form", 0, "answered")]
    assert all(a.name in strategy.ATTEMPTS for a in profile.attempts)
    profile = sp.plan(STRAIGHT, LGV, backend="banded")
    assert [(a.name, a.leg, a.outcome) for a in profile.attempts] == [
        ("model", None, "answered"), ("default_grid", 0, "answered")]
    assert all(a.name in strategy.ATTEMPTS for a in profile.attempts)
    assert all(a.seconds >= 0.0 for a in profile.attempts)


@pytest.fixture
def ungraded(monkeypatch):
    """User grids exactly uniform: their first law breaks the jerk tolerance at the rests."""
    build = importlib.import_module("speedplan.model.leg_grid")
    monkeypatch.setattr(build, "graded_ends", lambda s, ell_start, ell_end: s)


def test_a_refined_leg_records_the_law_it_replaced_and_why(ungraded):
    # A uniform 300-node grid: its first law breaks the jerk tolerance at the rests.
    profile = sp.plan(STRAIGHT, LGV, n=300)
    outcomes = [(a.name, a.outcome) for a in profile.attempts]
    assert outcomes[:2] == [("model", "answered"), ("given_grid", "replaced")]
    assert "jerk" in profile.attempts[1].reason
    assert outcomes[-1] == ("local_refinement", "answered")
    assert profile.verification.ok


def _on_uniform_grid(n, seconds=0.0):
    """A stand-in for a local refinement: the leg on a uniform ``n``-node grid instead."""
    def solve(request, leg, grid):
        time.sleep(seconds)
        s = np.linspace(0.0, float(grid[-1]), n)
        return strategy.solve_leg(strategy.leg_on_grid(request, leg.bound, s, leg.start, leg.v0,
                                                       leg.a0, leg.vf, leg.af))
    return solve


def test_a_refinement_whose_law_is_worse_is_dropped_and_not_refined_again(ungraded,
                                                                          monkeypatch):
    # Stand-in for a finer grid the backend solves less well: a 30-node grid instead.
    monkeypatch.setattr(strategy, "_solve_on_grid", _on_uniform_grid(30))
    with pytest.warns(sp.LimitWarning):
        profile = sp.plan(STRAIGHT, LGV, n=300)
    names = [(a.name, a.outcome) for a in profile.attempts]
    assert names == [("model", "answered"), ("given_grid", "answered"),
                     ("local_refinement", "replaced")]
    assert "more than the law it refined" in profile.attempts[-1].reason
    assert profile.s.size == 300  # the given grid's law, not the 30-node one
    assert 1.0 < strategy.excess(profile.verification) < 2.0


def test_a_tiny_time_limit_raises_plan_timeout_naming_the_attempts():
    with pytest.raises(sp.PlanTimeout) as info:
        sp.plan(STRAIGHT, LGV, time_limit=1e-9)
    err = info.value
    assert isinstance(err, sp.SpeedplanError)
    assert err.time_limit == 1e-9
    assert [(a.name, a.outcome) for a in err.attempts] == [("model", "skipped")]
    assert "time_limit=1e-09 s" in str(err) and "model skipped" in str(err)
    again = pickle.loads(pickle.dumps(err))  # plan_many ships it back from a worker
    assert isinstance(again, sp.PlanTimeout) and again.attempts == err.attempts


@pytest.mark.parametrize("bad", [0.0, -1.0, float("nan"), float("inf")])
def test_time_limit_is_checked(bad):
    with pytest.raises(sp.InvalidInputError, match="time_limit"):
        sp.plan(STRAIGHT, LGV, time_limit=bad)


class _RunsOutAfter(strategy.Budget):
    """A budget that expires after ``calls`` checks (a slow machine, made deterministic)."""

    def __init__(self, calls: int) -> None:
        super().__init__(time_limit=1.0)
        self.calls = calls

    def remaining(self) -> float:
        self.calls -= 1
        return 1.0 if self.calls >= 0 else 0.0


def test_a_budget_that_runs_out_before_the_law_passes_never_returns_it(ungraded):
    # n=300: the first law exceeds the jerk tolerance; the budget lets the model and the
    # first solve run, then not the refinement that would fix it.
    request = PlanRequest.create(STRAIGHT, LGV, n=300)
    with pytest.raises(sp.PlanTimeout) as info:
        plan_request(request, budget=_RunsOutAfter(2))
    names = [(a.name, a.outcome) for a in info.value.attempts]
    assert names == [("model", "answered"), ("given_grid", "answered"),
                     ("local_refinement", "skipped")]
    # With the time to refine, the same request is planned and verified.
    profile = plan_request(request, budget=_RunsOutAfter(100))
    assert profile.verification.ok


def test_refinements_stop_at_their_own_time_without_a_time_limit(ungraded, monkeypatch):
    # A stand-in for a relaxation backend that needs minutes on a refined grid (Clarabel as
    # the fallback of a 22 000-node comfort grid: 67 s): it runs until its deadline.
    monkeypatch.setattr(strategy, "MIN_REFINEMENT_SECONDS", 0.3)
    seen = []

    def runs_until_stopped(request, leg, grid):
        left = remaining()
        seen.append(left)
        assert left is not None, "a refinement runs without a deadline"
        time.sleep(left)
        raise sp.SolverError("Clarabel stopped with status MaxTime", backend="clarabel")

    monkeypatch.setattr(strategy, "_solve_on_grid", runs_until_stopped)
    t0 = time.perf_counter()
    with pytest.warns(sp.LimitWarning):
        profile = sp.plan(STRAIGHT, LGV, n=300)
    took = time.perf_counter() - t0
    first = sum(a.seconds for a in profile.attempts[:2])
    assert seen and seen[0] <= strategy.refinement_seconds(first) + 0.05
    assert took < first + strategy.refinement_seconds(first) + 0.5
    assert profile.limits_exceeded and profile.status == "limits_exceeded"
    assert [(a.name, a.outcome) for a in profile.attempts] == [
        ("model", "answered"), ("given_grid", "answered"), ("local_refinement", "failed")]


def test_a_refinement_that_would_not_end_in_the_time_left_is_not_started(ungraded,
                                                                         monkeypatch):
    monkeypatch.setattr(strategy, "MIN_REFINEMENT_SECONDS", 0.3)

    # 0.25 s each, and no better: the same uniform 300-node grid.
    monkeypatch.setattr(strategy, "_solve_on_grid", _on_uniform_grid(300, seconds=0.25))
    with pytest.warns(sp.LimitWarning):
        profile = sp.plan(STRAIGHT, LGV, n=300)
    rounds = [(a.outcome, a.reason) for a in profile.attempts if a.name == "local_refinement"]
    # The first refinement starts (the first solve was quick); it takes 0.25 s of the 0.3 s,
    # and a second one, judged to take as long, would end past them: not started.
    assert [o for o, _ in rounds] == ["answered", "skipped"]
    assert "would be spent before it ended" in rounds[-1][1]
    assert profile.limits_exceeded
    # With a caller's time limit the refinements have what it leaves: all three run.
    with pytest.warns(sp.LimitWarning):
        profile = sp.plan(STRAIGHT, LGV, n=300, time_limit=30.0)
    rounds = [a.outcome for a in profile.attempts if a.name == "local_refinement"]
    assert len(rounds) == strategy.MAX_REFINEMENTS and "skipped" not in rounds


def test_a_verified_plan_found_within_the_limit_is_returned():
    profile = sp.plan(STRAIGHT, LGV, time_limit=60.0)
    assert profile.status == "optimal" and profile.verification.ok
    assert profile.duration == pytest.approx(19.0, rel=1e-4)


def test_the_slow_4m_g2_path_answers_within_its_time_limit():
    # Without a limit this plan spends minutes in local refinements whose relaxations
    # Clarabel needs 50 s for; with one, the strategy stops between attempts and Clarabel
    # at the deadline (the banded kernel runs its ~1 s iterations to the end).
    t0 = time.perf_counter()
    try:
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            profile = sp.plan(G2_4M, G2_4M_LIMITS, time_limit=2.0)
    except sp.PlanTimeout as exc:
        assert exc.attempts and exc.attempts[0].name == "model"
    else:
        assert profile.verification.ok
    assert time.perf_counter() - t0 < 15.0


@pytest.mark.parametrize("n", [6000, 10000])
def test_a_fine_given_grid_along_a_yaw_rate_bound_is_answered_by_its_first_solve(n):
    # A right-angle corner at a yaw-rate limit on a uniform grid of 2-3.3 mm: with
    # Mehrotra's full second-order term and one step for both sides the banded method
    # advances one node per iteration and stops with NoProgress, and Clarabel needs 400
    # iterations (43 s) on the same grid (docs/banded-ipm.md).
    path = sp.Path.from_waypoints([[0, 0], [10, 0], [10, 10]])
    lim = sp.Limits(v_max=5.0, a_max=0.5, a_lat_max=1.0, j_max=20.0, yaw_rate_max=0.3)
    profile = sp.plan(path, lim, n=n, backend="banded")
    assert [a.name for a in profile.attempts] == ["model", "given_grid"]
    assert profile.legs[0].solution.relaxation.backend == "banded"
    assert profile.status == "optimal" and profile.verification.ok
    assert within_promise(measure(profile))
    # The yaw rate, from the sampled speed and the path's curvature.
    t = np.linspace(0.0, profile.duration, 20_001)
    state = profile.at(t)
    yaw = np.abs(state.v * path.curvature(state.s))
    assert yaw.max() <= lim.yaw_rate_max * (1 + 1e-3)


def test_the_deadline_stops_clarabel():
    n = 4000
    problem = DiscreteProblem(s=np.linspace(0.0, 100.0, n), w_max=np.full(n, 4.0),
                              accel=np.full(n - 1, 2.0), decel=np.full(n - 1, 2.0),
                              jerk=np.full(n - 2, 1.0))
    with deadline(time.perf_counter()), pytest.raises(sp.SolverError, match="MaxTime"):
        solve_relaxation(problem.scaled(100.0 / (n - 1), 4.0))


def test_a_solver_error_does_not_advise_the_grid_already_in_use():
    # A braking start whose speed dips to 9e-9 m/s: the default grid cannot resolve it.
    path = sp.Path.from_segments([Line(1888.1898887677708)])
    lim = sp.Limits(v_max=9.182910031427246, a_max=0.05542921908614846, a_lat_max=1.0,
                    j_max=12.25568225509851)
    try:
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            profile = sp.plan(path, lim, v0=1.491030987857941e-05, a0=-0.019111550739391747)
    except sp.SolverError as exc:
        assert "default grid" not in str(exc)
    else:
        assert profile.verification is not None


def test_a_given_grid_too_fine_to_refine_keeps_its_law_and_does_not_advise_a_finer_one():
    # A start at 0.1 m/s that must dip before reaching 2 m/s, on a user grid at the finest
    # step the relaxation resolves for j_max = 1: the law exceeds the jerk limit, and its
    # local refinement would be finer still. That refusal ("use n <= 4001") escaped from
    # plan(n=4000) as an InvalidInputError advising the grid already in use.
    lim = sp.Limits(v_max=3.0, a_max=10.0, a_lat_max=1.0, j_max=1.0)
    path = sp.Path.from_waypoints([[0, 0], [2.88, 0]], kind="polyline")
    with pytest.warns(sp.LimitWarning) as caught:
        profile = sp.plan(path, lim, v0=0.1, vf=2.0, n=4000)
    assert profile.status == "limits_exceeded" and profile.limits_exceeded
    (refinement,) = [a for a in profile.attempts if a.name == "local_refinement"]
    assert refinement.outcome == "failed" and "too fine" in refinement.reason
    (message,) = [str(w.message) for w in caught]
    assert "(1 failed)" in message and "default grid (without n or ds)" in message
    assert "finer grid" not in message
    # The default grid plans it exactly (closed form).
    best = sp.plan(path, lim, v0=0.1, vf=2.0)
    assert best.status == "optimal"
    assert best.duration == pytest.approx(ruckig_duration(2.88, lim, v0=0.1, vf=2.0),
                                          rel=1e-12)


def _one_edge_route(length: float) -> Route:
    edge = RouteEdge("AB", 1, "A", "B", sp.Path.from_segments([Line(length)]), v_max=1.0)
    return Route([RouteNode("A", 0, (0.0, 0.0)), RouteNode("B", 2, (length, 0.0))], [edge])


def test_plan_route_passes_the_time_limit():
    route = _one_edge_route(12.0)
    assert sp.plan_route(route, LGV, time_limit=60.0).status == "optimal"
    with pytest.raises(sp.PlanTimeout, match="on the leg"):
        sp.plan_route(route, LGV, time_limit=1e-9)


def test_plan_many_applies_the_time_limit_per_job():
    jobs = [(STRAIGHT, LGV), (STRAIGHT, LGV, {"time_limit": 60.0})]
    with ThreadPoolExecutor(2) as ex:
        results = sp.plan_many(jobs, ex, time_limit=1e-9)
    assert isinstance(results[0].error, sp.PlanTimeout)
    assert results[1].ok
    bad = sp.plan_many([(STRAIGHT, LGV, {"time_limit": -1})], ThreadPoolExecutor(1))
    assert isinstance(bad[0].error, sp.InvalidInputError)


def _kill_a_worker_once(done: int, total: int) -> None:
    if done == 1:
        workers = multiprocessing.active_children()
        assert workers, "no worker process to kill"
        os.kill(workers[0].pid, signal.SIGKILL)


def test_plan_many_survives_a_worker_killed_mid_batch():
    # SIGKILL one worker of the default process pool after the first result: every job it
    # held or had queued would fail with BrokenProcessPool; they run again on a fresh pool.
    jobs = [(sp.Path.from_segments([Line(5.0 + k)]), LGV) for k in range(24)]
    results = sp.plan_many(jobs, progress=_kill_a_worker_once)
    assert [r.index for r in results] == list(range(24))
    assert all(r.ok for r in results), [repr(r.error) for r in results if not r.ok]


def _u_turn_plan() -> tuple[sp.Path, sp.SpeedProfile]:
    from speedplan.io import read_path

    u_turn = read_path(os.path.join(os.path.dirname(__file__), "..", "..", "paths", "u_turn.json"))
    return u_turn, sp.plan(u_turn, LGV)


def _replanned(path: sp.Path, first: sp.SpeedProfile, t: float) -> sp.SpeedProfile:
    """The rest of ``path`` planned from ``first``'s state at ``t``: verified, no warning."""
    state = first.at(t)
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        again = sp.plan(path.sub(float(state.s[0])), LGV, v0=float(state.v[0]),
                        a0=float(state.a[0]))
    assert again.verification.ok, (t, again.verification.summary())
    assert within_promise(measure(again, samples=3_000)), t  # finite differences in time
    return again


def test_states_read_off_a_plan_replan_without_a_warning():
    # A controller replanning at 10 Hz from its own plan's state: e.g. the U-turn at t = 3 s,
    # whose state needs 2.6e-5 more jerk than j_max (the law's rounding), warned per cycle.

    u_turn, first = _u_turn_plan()
    rounded = 0
    for t in (*np.linspace(0.25, first.duration - 0.5, 13), 3.0):
        again = _replanned(u_turn, first, t)
        assert t + again.duration >= first.duration * (1 - 1e-4), t
        rounded += any(a.name.endswith("state_rounding") for a in again.attempts
                       if a.outcome == "answered")
    assert rounded > 0  # the case is exercised


def _road_comfort():
    from speedplan.io import read_path

    path = read_path(os.path.join(os.path.dirname(__file__), "..", "..", "paths",
                                  "road_s_curve.csv"))
    lim = sp.Limits(v_max=15.0, a_max=2.0, a_lat_max=3.0, j_max=1.0, j_lat_max=0.3,
                    yaw_rate_max=0.4)
    return path, lim, sp.plan(path, lim)


def _replan(path, lim, first, fraction):
    t = fraction * first.duration
    state = first.at(t)
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        again = sp.plan(path.sub(float(state.s[0])), lim, v0=float(state.v[0]),
                        a0=float(state.a[0]))
    assert again.status in ("optimal", "refined") and again.verification.ok
    assert within_promise(measure(again, samples=3_000))
    assert t + again.duration == pytest.approx(first.duration, rel=1e-4)
    return again


def test_a_state_on_the_edge_of_its_reach_replans_on_its_default_grid():
    # On the road S-curve with comfort limits, 0.1225 of the way through, the plan brakes at
    # -j_max: the slowest motion from there is nearly the only one that meets the
    # lateral-jerk caps further on, and the replan's refinement finds no feasible point on
    # the default grid. The same grid with rounded state rows answers; IPOPT is not run on
    # the default grid first (it spent its 5 s there and failed: 7.1 s in all).
    path, lim, first = _road_comfort()
    again = _replan(path, lim, first, 0.1225)
    attempts = {a.name: a for a in again.attempts}
    assert attempts["default_grid"].outcome == "failed"  # the case is exercised
    assert "ipopt" not in attempts["default_grid"].reason.split("feasible point")[-1]
    assert attempts["state_rounding_on_grid"].outcome == "answered"


@pytest.mark.parametrize("fraction", [0.15, 0.2, 0.5, 0.6])
def test_replans_along_a_road_with_close_joins_keep_steps_the_relaxation_resolves(fraction):
    # The road's G2 corners leave joins of clothoids 0.09-2.7 mm apart. The room for 25
    # nodes between every two joins made steps of 2.6 µm on the replans' default grids: the
    # banded relaxation stopped at its first iteration (NumericalError), and the replans
    # were answered on coarser grids (up to 5.8e-4 off the plan's remaining time), or after
    # 113 s by a SolverError. At 0.6 the refinement fails on the default grid and the
    # coarser grid answers, without an IPOPT run of 5 s before it.
    path, lim, first = _road_comfort()
    again = _replan(path, lim, first, fraction)
    assert float(np.min(np.diff(again.legs[0].s))) > 1e-4
    for attempt in again.attempts:
        assert "ipopt" not in attempt.reason


def test_states_read_off_a_plans_final_stop_replan_to_rest():
    # In the final max-jerk stop a state needs a little more jerk than j_max (the law's
    # rounding), and its own stop ends a hair before or past the path's end: that stop spans
    # the stretch left, rather than leaving a micrometre dip for the relaxation or sampling
    # the law past the path's end.
    u_turn, first = _u_turn_plan()
    for t in np.linspace(first.duration - 1.5, first.duration - 0.02, 25):
        again = _replanned(u_turn, first, t)
        assert abs(t + again.duration - first.duration) <= 1e-3 * first.duration, t


COMFORT = sp.Limits(v_max=2.0, a_max=1.0, a_lat_max=1.0, j_max=0.5, j_lat_max=0.3,
                    yaw_rate_max=0.4)


def _rest_times(profile: sp.SpeedProfile) -> list[float]:
    """When ``profile`` comes to rest: between its legs where the speed is 0, and its end."""
    ends = np.cumsum([leg.law.duration for leg in profile.legs])
    return [float(t) for t in ends if float(profile.at([t]).v[0]) <= 1e-9]


def test_states_read_off_the_approach_to_a_stop_replan_silently():
    # With lateral-jerk limits the aisle's corners (curvature jumps) are stops. In the last
    # second before each, the plan's law rides the max-jerk stop within its own rounding, and
    # its states need up to 0.1 % more jerk than j_max; 1.2 cm before one such stop the
    # slowest motion also stayed above the speed cap of the stop, which the looser jerk did
    # not relax. Those states were refused (InfeasibleError) or planned with the 2 % slack
    # and its warning.
    from speedplan.io import read_path

    path = read_path(os.path.join(os.path.dirname(__file__), "..", "..", "paths",
                                  "aisle_corners.csv"))
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")  # the stops at the corners are announced
        first = sp.plan(path, COMFORT)
    stops = _rest_times(first)
    assert len(stops) == 5
    rounded = 0
    for stop in stops:
        for back in (1.0, 0.6, 0.3):
            t = stop - back
            state = first.at(t)
            with warnings.catch_warnings():
                warnings.simplefilter("error")
                warnings.filterwarnings("ignore", message="the path's curvature jumps")
                again = sp.plan(path.sub(float(state.s[0])), COMFORT, v0=float(state.v[0]),
                                a0=float(state.a[0]))
            assert again.status in ("optimal", "refined") and again.verification.ok, t
            assert within_promise(measure(again, samples=3_000)), t
            assert t + again.duration == pytest.approx(first.duration, rel=1e-4), t
            rounded += any(a.name.endswith("law_rounding") for a in again.attempts
                           if a.outcome == "answered")
    assert rounded > 0  # the case is exercised


def test_the_looser_jerk_of_a_marginal_state_ends_at_its_first_stop():
    # A state planned with j_max (1 + STATE_JERK_LAW_ROUNDING) keeps that jerk in the legs
    # that touch it; every leg between two stops (the aisle's corners) is that of j_max, on
    # its default grid and on the coarser grids the strategy may build (a replan had taken
    # the looser jerk to the end of the path: 4e-4 early).
    from dataclasses import replace

    from speedplan.io import read_path
    from speedplan.model import Leg, build_model
    from speedplan.model.boundary import STATE_JERK_LAW_ROUNDING

    path = read_path(os.path.join(os.path.dirname(__file__), "..", "..", "paths",
                                  "aisle_corners.csv"))
    request = PlanRequest.create(path, COMFORT, v0=0.5, a0=0.2)
    looser = replace(request, state_jerk=COMFORT.j_max * (1 + STATE_JERK_LAW_ROUNDING))
    plain, loose = build_model(request), build_model(looser)
    assert len(plain.legs) == len(loose.legs) > 2
    for a, b in zip(plain.legs, loose.legs, strict=True):
        if not isinstance(a, Leg):
            continue
        moving = a.v0 > 0 or a.a0 != 0 or a.vf > 0 or a.af != 0
        assert np.array_equal(a.problem.s, b.problem.s)
        assert np.array_equal(a.problem.jerk, b.problem.jerk) != moving
        if not moving:
            np.testing.assert_array_equal(strategy.coarser_leg(request, a, 0.5).problem.jerk,
                                          strategy.coarser_leg(looser, b, 0.5).problem.jerk)


def test_a_replan_near_its_stop_keeps_the_relaxed_point_when_the_refinement_strays():
    # 0.71 m before the end of an 8.6 m G2 path the relaxed point is ruckig's motion, its
    # rows met within tolerance but 5.7e-5 under its own bound (the standstill's last
    # cells): not exact. The refinement's near starts stalled and its IPOPT-like start ended
    # 50 % slower, a bump before the stop whose law reached 7.4 j_max: limits_exceeded.
    path = sp.Path.from_waypoints(
        [[0.0352366750987696, 1.6563208815983477], [-1.155758154137697, 3.217861549888293],
         [-1.0068528422840095, 1.1788609334969564], [1.6945695166452337, 0.607375905692856],
         [0.5048982603963474, 2.6234064133549686]], max_deviation=0.12317847331561618)
    lim = sp.Limits(v_max=10.07870653667445, a_max=0.5789434471634837,
                    a_lat_max=0.5470089233305927, j_max=0.3660983048064032)
    first = sp.plan(path, lim)
    t = first.duration - 1.5 * lim.a_max / lim.j_max
    state = first.at(t)
    rest = path.sub(float(state.s[0]))
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        again = sp.plan(rest, lim, v0=float(state.v[0]), a0=float(state.a[0]))
    assert again.status in ("optimal", "refined") and again.verification.ok
    assert within_promise(measure(again, samples=3_000))
    # Along the path the motion is at most as fast as ruckig's on a line of its length.
    exact = ruckig_duration(float(rest.length), lim, v0=float(state.v[0]),
                            a0=float(state.a[0]))
    assert exact * (1 - 1e-9) <= again.duration <= exact * (1 + 1e-4)


def test_a_replan_whose_refinement_stops_short_next_to_its_bound_answers():
    # Polyline corners with lateral-jerk limits stop the vehicle at every corner. From the
    # state 0.6 a_max / j_max before a stop, the relaxation is a hair inexact (rows 1.5 %
    # over) and all three refinement starts end at their iteration limit on points that
    # meet every row, 3.6e-5 above the certified bound; none was used, IPOPT ran its 5 s
    # and failed, and plan() raised a SolverError.
    path = sp.Path.from_waypoints(
        [[-11.364816279779033, -25.78062435452708], [-19.30388252807136, -37.05147152866329],
         [6.940741353114233, -42.74608124004093], [-22.353768904108104, -12.831258930735563]],
        kind="polyline", corner_radius=2.75725057923656)
    lim = sp.Limits(v_max=1.828254323940728, a_max=1.87388981977622,
                    a_lat_max=0.35212370926750125, j_max=0.2143064326378752,
                    j_lat_max=0.02654771824222931, yaw_rate_max=1.1334318537162695)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")  # the stops at the corners are announced
        first = sp.plan(path, lim)
    for stop in _rest_times(first)[:2]:
        t = stop - 0.6 * lim.a_max / lim.j_max
        state = first.at(t)
        with warnings.catch_warnings():
            warnings.simplefilter("error")
            warnings.filterwarnings("ignore", message="the path's curvature jumps")
            again = sp.plan(path.sub(float(state.s[0])), lim, v0=float(state.v[0]),
                            a0=float(state.a[0]))
        assert again.status in ("optimal", "refined") and again.verification.ok, t
        assert within_promise(measure(again, samples=3_000)), t
        assert t + again.duration == pytest.approx(first.duration, rel=1e-4), t
        assert not any("ipopt" in a.reason for a in again.attempts), t


def test_a_leg_from_a_moving_state_runs_no_ipopt_on_any_grid(monkeypatch):
    # 1.5 a_max / j_max before a stop on a G2 comfort path, the replan's first leg finds no
    # feasible refined point on any grid. IPOPT ran on the coarser grid and with the other
    # backend (5.3 s, 2.2 s, 2.2 s) to fail the same way: 10 s before the SolverError.
    path = sp.Path.from_waypoints(
        [[-5.3696874721825845, -1.0806899260810363], [-9.340651477486684, -0.13153752593207813],
         [-12.739796376730684, 5.292436205848862], [-10.280385387960187, 2.2909414151822842],
         [-5.054883305693384, 6.066555696008243], [-9.23154158065904, 7.9032614054220405],
         [-5.111136856360281, 2.409186918189329]], max_deviation=0.23292422603967894)
    lim = sp.Limits(v_max=1.0912771302521995, a_max=0.9875847487242622,
                    a_lat_max=0.3882437637948343, j_max=1.497447258996227,
                    j_lat_max=0.19825777774963074)
    first = sp.plan(path, lim)
    stop = _rest_times(first)[1]
    state = first.at(stop - 1.5 * lim.a_max / lim.j_max)
    refine = importlib.import_module("speedplan.solve.refine")
    ran: list[int] = []

    def no_ipopt(problem, w0):
        ran.append(problem.n)
        raise AssertionError("IPOPT ran")

    monkeypatch.setattr(refine, "refine_ipopt", no_ipopt)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        try:
            again = sp.plan(path.sub(float(state.s[0])), lim, v0=float(state.v[0]),
                            a0=float(state.a[0]))
        except sp.SolverError:  # a named error, without a minute of work first
            again = None
    assert ran == []
    if again is not None:
        assert again.verification.ok and within_promise(measure(again, samples=3_000))


def test_a_state_in_the_last_jerk_phase_of_a_stop_keeps_its_acceleration_and_the_jerk():
    # 0.1 a_max / j_max before the end of a G2 path (1.6 mm left), the state needs 8.6e-5
    # more jerk than j_max: its stop, 0.05 % longer than the path left, spans it. Stretched
    # in s alone, the stop's acceleration was off the state's by that much, and the law
    # bent back to it within the first micrometre at 1.051 j_max: limits_exceeded.
    path = sp.Path.from_waypoints(
        [[2.939271017255021, -5.005102789080237], [-0.9048925339466045, -7.571756980673424],
         [-0.32540007567713314, -6.910604974673016], [-0.33707264426465944, -7.7805235738078125]],
        max_deviation=0.7118776039761722)
    lim = sp.Limits(v_max=26.17230371456213, a_max=1.9318473857446337,
                    a_lat_max=0.3467159272286036, j_max=0.873771228988403,
                    j_lat_max=0.21231711175244605, yaw_rate_max=0.8343543822546357)
    first = sp.plan(path, lim)
    t = first.duration - 0.1 * lim.a_max / lim.j_max
    state = first.at(t)
    v0, a0 = float(state.v[0]), float(state.a[0])
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        again = sp.plan(path.sub(float(state.s[0])), lim, v0=v0, a0=a0)
    assert again.status == "optimal" and again.verification.ok
    assert within_promise(measure(again, samples=3_000))
    assert float(again.at([0.0]).a[0]) == pytest.approx(a0, rel=1e-9)
    assert t + again.duration == pytest.approx(first.duration, rel=1e-6)


def _jerk_after(profile: sp.SpeedProfile, t0: float) -> float:
    """Largest finite-difference jerk from ``t0`` to the end of the profile [m/s³]."""
    dt = 1e-3
    v = profile.at(np.arange(t0, profile.duration, dt)).v
    return float(np.abs(np.diff(v, 2)).max() / dt**2)


def test_an_outside_state_is_planned_with_the_jerk_slack_only_in_its_turn():
    # Accelerating 0.4 % harder than the plan's own state at t = 3 s: the speed would
    # overshoot v_max under j_max. The least jerk that keeps it under v_max (0.8 % more
    # than j_max) brings the acceleration to 0 exactly at v_max; from there the move to rest
    # is ruckig's with j_max.
    first = sp.plan(STRAIGHT, LGV)
    state = first.at(3.0)
    length = 30.0 - float(state.s[0])
    v0, a0 = float(state.v[0]), float(state.a[0]) * 1.004
    rest = sp.Path.from_segments([Line(length)])
    with pytest.warns(sp.SpeedplanWarning, match="only while the state's acceleration"):
        again = sp.plan(rest, LGV, v0=v0, a0=a0)
    assert next(a.name for a in again.attempts if a.outcome == "answered") == "jerk_slack"
    assert again.verification.ok
    j = a0 * a0 / (2.0 * (LGV.v_max - v0))  # the turn, by hand
    assert LGV.j_max < j < LGV.j_max * 1.02
    t1 = a0 / j
    d1 = v0 * t1 + a0 * t1**2 / 2 - j * t1**3 / 6
    expected = t1 + ruckig_duration(length - d1, LGV, v0=LGV.v_max)
    assert again.duration == pytest.approx(expected, rel=1e-9)
    # Never faster than the whole move with the looser jerk (ruckig's optimum with it).
    looser = sp.Limits(v_max=2.0, a_max=1.0, a_lat_max=1.0, j_max=LGV.j_max * 1.02)
    assert again.duration >= ruckig_duration(length, looser, v0=v0, a0=a0) * (1 - 1e-12)
    # The looser jerk only in the turn: j_max after it (finite differences).
    assert _jerk_after(again, 0.0) <= j * (1 + 1e-3)
    assert _jerk_after(again, t1 + 0.01) <= LGV.j_max * (1 + 1e-3)


@pytest.mark.parametrize("curved", [False, True])
def test_a_braking_state_just_outside_reach_turns_with_the_slack_and_goes_on_with_j_max(curved):
    # v0 < a0²/(2 j_max): under j_max the speed would fall below 0 before the braking ends;
    # under 1.02 j_max it turns about 2 mm/s above rest. The rest of the move keeps j_max.
    path = (sp.Path.from_waypoints([[0, 0], [20, 0], [20, 15], [35, 15]]) if curved
            else sp.Path.from_segments([Line(30.0)]))
    v0, a0 = 0.247, -0.5
    with pytest.warns(sp.SpeedplanWarning, match="only while the state's acceleration"):
        profile = sp.plan(path, LGV, v0=v0, a0=a0)
    assert profile.verification.ok
    names = [a.name for a in profile.attempts if a.outcome == "answered"]
    assert names[:2] == ["jerk_slack", "forced_motion"]
    j = LGV.j_max * 1.02
    t1 = -a0 / j
    assert float(profile.at(t1).v[0]) == pytest.approx(v0 - a0 * a0 / (2 * j), rel=1e-9)
    assert _jerk_after(profile, 0.0) <= j * (1 + 1e-3)
    # After the turn: j_max, to the law's own tolerance on a grid (curved), exactly in
    # closed form (straight).
    after = _jerk_after(profile, t1 + 0.01)
    assert after <= LGV.j_max * (1.015 if curved else 1 + 1e-3)
    if not curved:
        d1 = v0 * t1 + a0 * t1**2 / 2 + j * t1**3 / 6
        expected = t1 + ruckig_duration(30.0 - d1, LGV, v0=v0 - a0 * a0 / (2 * j))
        assert profile.duration == pytest.approx(expected, rel=1e-9)


def test_a_backend_that_fails_on_a_grid_is_not_run_on_it_again(monkeypatch):
    # The banded backend stalls on every grid: the strategy tries it on the default grid
    # and on each coarser one once, then Clarabel on each in turn, never banded again.
    discrete = importlib.import_module("speedplan.solve.discrete")
    calls: list[int] = []

    def stalls(unit):
        calls.append(unit.n)
        raise sp.SolverError("stalled (test)", backend="banded", status="NoProgress")

    monkeypatch.setitem(discrete.RELAXATION_BACKENDS, "banded", stalls)
    profile = sp.plan(STRAIGHT, LGV, backend="banded")
    names = [(a.name, a.outcome) for a in profile.attempts]
    assert names[:5] == [("model", "answered"), ("default_grid", "failed"),
                         ("coarser_grid_1/2", "failed"), ("coarser_grid_1/4", "failed"),
                         ("other_backend", "answered")]
    assert len(calls) == len(set(calls)) == 3  # each grid (its own node count) once
    assert profile.solution.backend == "clarabel" and profile.verification.ok


def test_a_long_move_from_a_marginal_braking_state_answers_in_seconds():
    # A trust-fuzz move (27.8 km, braking start that j_max misses by a hair): with the jerk
    # slack held near the state in the jerk rows, the relaxation was inexact and the
    # refinement ran for minutes. The state's turn takes the slack (10 s, 10 m), the rest of
    # the move j_max.
    lim = sp.Limits(v_max=5.720500233946498, a_max=1.0997156178083936, a_lat_max=1,
                    j_max=0.04562513470868499, a_decel=1.1432836388457868)
    path = sp.Path.from_segments([Line(27781.810078116458)])
    with pytest.warns(sp.SpeedplanWarning, match="2% more jerk"):
        profile = sp.plan(path, lim, v0=2.7363134118689274, a0=-0.5026231549740972,
                          time_limit=30.0)
    assert profile.status == "optimal" and profile.verification.ok
    assert [a.name for a in profile.attempts if a.outcome == "answered"][:2] == [
        "jerk_slack", "forced_motion"]
    dt = 1e-3  # j_max right after the turn (finite differences)
    v = profile.at(np.arange(11.0, 60.0, dt)).v
    assert float(np.abs(np.diff(v, 2)).max()) / dt**2 <= lim.j_max * (1 + 1e-3)
