"""plan(): physics of the planned trajectories, sampled at 1 ms and finite-differenced."""

from __future__ import annotations

import glob
import importlib
import itertools
import warnings

import numpy as np
import pytest
from oracles import measure, ruckig_move, within_promise
from ruckig import InputParameter, Result, Ruckig, Trajectory
from shared import LGV

from speedplan import (
    InfeasibleError,
    InvalidInputError,
    Limits,
    LimitWarning,
    Path,
    SpeedZone,
    plan,
)
from speedplan.geometry import Arc, Clothoid, Line
from speedplan.io import read_path, read_zones
from speedplan.model import PlanRequest, build_model
from speedplan.strategy import solve_leg
from speedplan.timing import TOLERANCES, law_for
from speedplan.timing.verify import check_law

ROAD = Limits(v_max=15.0, a_max=2.0, a_lat_max=3.0, j_max=1.0)
DT = 1e-3


def ruckig_duration(length, lim):
    otg = Ruckig(1)
    inp = InputParameter(1)
    inp.current_position, inp.current_velocity, inp.current_acceleration = [0.0], [0.0], [0.0]
    inp.target_position, inp.target_velocity, inp.target_acceleration = [length], [0.0], [0.0]
    inp.max_velocity, inp.max_acceleration, inp.max_jerk = [lim.v_max], [lim.a_max], [lim.j_max]
    inp.min_acceleration = [-lim.a_decel]
    traj = Trajectory(1)
    assert otg.calculate(inp, traj) == Result.Working
    return traj.duration


def assert_physics(profile, lim=None, tol=TOLERANCES):
    """Sample at 1 ms and finite-difference positions and speeds against the limits."""
    lim = lim or profile.limits
    traj = profile.sample(DT)
    t, xy = traj.t[:-1], np.column_stack((traj.x, traj.y))[:-1]  # uniform part only
    v_fd = np.linalg.norm(np.diff(xy, axis=0), axis=1) / DT
    v_mid = 0.5 * (traj.v[:-2] + traj.v[1:-1])
    assert np.abs(v_fd - v_mid).max() <= 1e-3 * lim.v_max  # positions and speeds agree
    a_fd = np.diff(traj.v[:-1]) / DT
    j_fd = np.diff(a_fd) / DT
    bound = np.sqrt(profile.speed_bound(traj.s))
    assert np.all(traj.v <= bound * (1 + tol["speed"]) + 1e-12)
    assert a_fd.max() <= lim.a_max * (1 + tol["accel"])
    assert -a_fd.min() <= lim.a_decel * (1 + tol["decel"])
    assert np.abs(traj.a_lat).max() <= lim.a_lat_max * (1 + tol["lateral"])
    assert np.abs(j_fd).max() <= lim.j_max * (1 + tol["jerk"])
    assert np.all(np.isfinite(np.column_stack(list(traj.to_dict().values()))))
    assert traj.t[0] == 0 and traj.t[-1] == pytest.approx(profile.duration)
    assert len(t) > 0
    return traj


@pytest.mark.parametrize(
    ("length", "lim"),
    [(30.0, LGV), (3.0, LGV), (0.5, LGV), (400.0, ROAD),
     (25.0, Limits(v_max=2.0, a_max=1.0, a_lat_max=1.0, j_max=0.5, a_decel=0.6))],
)
def test_straight_rest_to_rest_converges_to_the_true_jerk_limited_optimum(length, lim):
    reference = ruckig_duration(length, lim)
    profile = plan(Path.from_segments([Line(length)]), lim)
    assert profile.status == "optimal" and profile.exact
    assert profile.duration <= reference * 1.005
    assert profile.duration >= reference * (1 - 0.001)
    traj = assert_physics(profile)
    assert traj.v[0] == 0 and traj.v[-1] == pytest.approx(0, abs=1e-12)
    assert traj.a[0] == 0 and traj.a[-1] == pytest.approx(0, abs=1e-9)


def test_closed_form_thirty_metres_is_nineteen_seconds():
    # Jerk phases of a/j = 2 s reach v = a²/j = v_max exactly: 4 s + 22 m / 2 m/s + 4 s.
    profile = plan(Path.from_segments([Line(30.0)]), LGV)
    assert profile.duration == pytest.approx(19.0, rel=0.005)


def test_paper_free_standstill_model_is_faster_than_physics_allows():
    free = plan(Path.from_segments([Line(30.0)]), LGV, standstill="free", n=600)
    assert free.duration < 18.5  # the acceleration jumps at standstill (the paper's model)
    assert free.sample(0.01).a[0] > 0


@pytest.mark.parametrize("R", [0.5, 2.0, 8.0])
def test_constant_radius_arc_cruises_at_the_lateral_limit(R):
    profile = plan(Path.from_segments([Arc(R, 3 * np.pi)]), LGV)
    traj = assert_physics(profile)
    cruise = min(LGV.v_max, np.sqrt(LGV.a_lat_max * R))
    mid = traj.v[np.argmin(np.abs(traj.s - profile.path.length / 2))]
    assert mid == pytest.approx(cruise, rel=1e-3)


@pytest.mark.parametrize("transitions", [False, True])
def test_line_arc_line(transitions):
    segs = [Line(10.0), Arc(2.0, np.pi / 2), Line(10.0)]
    if transitions:
        segs = [Line(10.0), Clothoid(1.5, 0, 0.5), Arc(2.0, np.pi / 2 - 0.75),
                Clothoid(1.5, 0.5, 0), Line(10.0)]
    profile = plan(Path.from_segments(segs), LGV)
    assert profile.verification.ok
    assert_physics(profile)


@pytest.mark.parametrize("file", sorted(glob.glob("paths/*.csv") + glob.glob("paths/*.json")))
def test_every_sample_path(file):
    lim = ROAD if "road" in file else LGV
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        profile = plan(read_path(file), lim, zones=read_zones(file) or None)
    assert profile.status in ("optimal", "refined")
    assert_physics(profile)


def _law_check(path, lim, **kw):
    """The check of a plan's law on its initial grid, before any local refinement."""
    leg = build_model(PlanRequest.create(path, lim, **kw)).legs[0]
    law = law_for(leg.problem.s, solve_leg(leg).solution.w, leg.time_law)
    return check_law(law, 0.0, path, leg.bound, lim).verification, law.duration


@pytest.fixture
def ungraded(monkeypatch):
    """User grids exactly uniform: without the grading at the rests (``graded_ends``)."""
    build = importlib.import_module("speedplan.model.leg_grid")
    monkeypatch.setattr(build, "graded_ends", lambda s, ell_start, ell_end: s)


def test_limit_ratios_and_duration_converge_as_the_grid_is_refined(ungraded):
    # The law itself on uniform grids (a user grid is graded at the rests, test_user_grids).
    path = Path.from_segments([Line(30.0)])
    results = [_law_check(path, LGV, n=n) for n in (300, 600, 1200, 2400)]
    jerk = [check.ratios["jerk"] for check, _ in results]
    assert jerk[0] > 1.05 and all(b < a for a, b in itertools.pairwise(jerk))
    assert jerk[-1] <= 1.01
    # The durations settle (each refinement moves them less) onto ruckig's exact optimum. Not
    # every error is smaller than the last: the discretisation's error (the law faster than
    # the optimum by O(h²)) crosses the few 1e-6 above it that the finest grids keep.
    durations = [d for _, d in results]
    moves = [abs(b - a) for a, b in itertools.pairwise(durations)]
    assert all(b < a / 2 for a, b in itertools.pairwise(moves))
    assert durations[-1] == pytest.approx(ruckig_duration(30.0, LGV), rel=1e-5)


def test_coarse_grid_is_refined_where_the_limits_are_exceeded(ungraded):
    # The refinement behind the grading: a law that breaks a tolerance is refined there.
    path = Path.from_segments([Line(30.0)])
    before, _ = _law_check(path, LGV, n=300)
    assert "jerk" in before.violations  # the uniform 300-node law breaks the 5 % tolerance
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        profile = plan(path, LGV, n=300)
    assert profile.status == "optimal" and profile.verification.ok
    assert profile.s.size > 300
    cruise = (profile.s[:-1] > 12.0) & (profile.s[:-1] < 18.0)
    steps = np.diff(profile.s)
    assert steps[cruise] == pytest.approx(30.0 / 299, rel=1e-2)  # the cruise keeps its steps
    assert steps.min() < 0.6 * 30.0 / 299  # halved where the jerk was exceeded
    assert_physics(profile)
    assert profile.duration >= ruckig_duration(30.0, LGV) * (1 - 1e-4)


def test_moving_start_begins_exactly_at_the_given_state():
    profile = plan(Path.from_segments([Line(20.0)]), LGV, v0=1.2, a0=0.3)
    traj = assert_physics(profile)
    assert traj.v[0] == pytest.approx(1.2, abs=1e-12)
    assert traj.a[0] == pytest.approx(0.3, abs=1e-12)
    end_moving = plan(Path.from_segments([Line(20.0)]), LGV, vf=1.0, af=-0.2)
    traj = assert_physics(end_moving)
    assert traj.v[-1] == pytest.approx(1.0, abs=1e-9)
    assert traj.a[-1] == pytest.approx(-0.2, abs=1e-9)


def test_at_refuses_times_of_more_than_one_dimension():
    # A 2-D array of times ended in "truth value of an array is ambiguous" inside the law.
    prof = plan(Path.from_segments([Line(10.0)]), LGV)
    with pytest.raises(InvalidInputError, match=r"`t`.*1-D"):
        prof.at([[1.0, 2.0]])
    assert prof.at(1.0).t.shape == (1,) and prof.at([1.0, 2.0]).t.shape == (2,)


@pytest.mark.parametrize("where", ["start", "end"])
def test_states_above_a_limit_by_rounding_are_taken_at_the_limit(where):
    # A state read off a plan (an order update) can sit above a limit by the time law's
    # rounding: 4.4e-9 in speed, 1.9e-9 in acceleration were refused before. Taken at the
    # limit now; 1e-5 above is still refused.
    line = Path.from_segments([Line(20.0)])
    v_key, a_key = ("v0", "a0") if where == "start" else ("vf", "af")
    prof = plan(line, LGV, **{v_key: LGV.v_max * (1 + 4.4e-9)})
    end = prof.at([0.0 if where == "start" else prof.duration])
    assert end.v[0] == pytest.approx(LGV.v_max, rel=1e-12)
    assert end.v[0] <= LGV.v_max * (1 + 1e-12)  # at the bound, not 4.4e-9 above
    assert prof.status == "optimal"
    a_edge = LGV.a_max if where == "start" else -LGV.a_decel
    prof = plan(line, LGV, **{v_key: 1.0, a_key: a_edge * (1 + 1.9e-9)})
    end = prof.at([0.0 if where == "start" else prof.duration])
    assert abs(end.a[0]) <= abs(a_edge) * (1 + 1e-12)  # at the limit, not 1.9e-9 above
    assert prof.status == "optimal"
    with pytest.raises(InvalidInputError, match=f"`{v_key}`"):
        plan(line, LGV, **{v_key: LGV.v_max * (1 + 1e-5)})
    with pytest.raises(InvalidInputError, match=f"`{a_key}`"):
        plan(line, LGV, **{v_key: 1.0, a_key: a_edge * (1 + 1e-5)})


def test_impossible_boundary_states():
    line = Path.from_segments([Line(20.0)])
    with pytest.raises(InvalidInputError, match="`a0`"):
        plan(line, LGV, v0=1.0, a0=1.5)
    with pytest.raises(InvalidInputError, match="`v0`"):
        plan(line, LGV, v0=2.5)
    with pytest.raises(InvalidInputError, match="`a0`"):
        plan(line, LGV, v0=0.0, a0=0.3)
    with pytest.raises(InfeasibleError, match=r"falls to .* < 0") as info:
        plan(line, LGV, v0=0.2, a0=-0.9)
    assert info.value.constraint == "jerk" and info.value.s == 0.0
    # A zero knot of v_limit inside the path forces a standstill there: said in metres along
    # the path (it was the solver's rescaled position, 6441 on this 15.5 m path), with its
    # cause. The default grid has a node on the knot (a kink of the bound).
    bent = Path.from_waypoints([[0, 0], [10, 0], [14, 4]])
    with pytest.raises(InvalidInputError, match=r"bound is 0 at s=5 m .*a knot of v_limit at 0"):
        plan(bent, LGV, v_limit=([0.0, 5.0, 16.0], [1.0, 0.0, 1.0]))
    # Zero at the ends, rising in proportion to the distance: never left. It blamed curvature.
    with pytest.raises(InvalidInputError, match="a knot of v_limit at 0"):
        plan(Path.from_segments([Line(10.0)]), LGV, v_limit=([0, 5, 10], [0.0, 1.0, 0.0]))
    zone = SpeedZone([(1.0, -1.0), (5.0, -1.0), (5.0, 1.0), (1.0, 1.0)], v_max=0.5)
    with pytest.raises(InfeasibleError, match=r"from v0=2 m/s.* cannot slow down") as info:
        plan(line, LGV, v0=2.0, zones=[zone])
    assert info.value.constraint == "speed_bound"
    assert info.value.s == pytest.approx(1.0, abs=0.05)


@pytest.mark.parametrize("scale", [1.0, 1e3])
@pytest.mark.parametrize("length", [4e-156, 1e-40, 1e-12])
def test_nearly_zero_length_path_is_rejected_by_name_in_any_unit(length, scale):
    # Nearly coincident waypoints: the solvers used to fail here with misleading messages
    # (an InfeasibleError "at s=1" at 1e-40 m, a SolverError at 4e-156 m). The threshold is
    # 1e-9 v_max²/a_max: 4e-9 m for these limits, the same length in millimetres.
    tiny = Path.from_waypoints([[0.0, 0.0], [length * scale, 0.0]], kind="polyline")
    lim = Limits(v_max=2.0 * scale, a_max=1.0 * scale, a_lat_max=1.0 * scale,
                 j_max=0.5 * scale)
    with pytest.raises(InvalidInputError, match=r"`path` is .* shorter than"):
        plan(tiny, lim)


def test_ten_nanometre_move_matches_the_jerk_limited_closed_form():
    # Just above the threshold, rest to rest where only the jerk limit binds:
    # T = (32 L / J)^(1/3).
    prof = plan(Path.from_waypoints([[0.0, 0.0], [1e-8, 0.0]], kind="polyline"), LGV)
    assert prof.duration == pytest.approx((32 * 1e-8 / LGV.j_max) ** (1 / 3), rel=1e-4)
    assert prof.verify().ok


def test_millimetres_and_metres_give_the_same_trajectory():
    pts = np.array([[0, 0], [8, 0], [12, 3], [12, 9]], dtype=float)
    # The corners' max_deviation is a length too: scale it with the waypoints.
    m = plan(Path.from_waypoints(pts, max_deviation=0.25), LGV)
    k = 1000.0
    mm = plan(Path.from_waypoints(pts * k, max_deviation=0.25 * k),
              Limits(v_max=2 * k, a_max=1 * k, a_lat_max=1 * k, j_max=0.5 * k))
    assert mm.duration == pytest.approx(m.duration, rel=1e-6)
    a, b = m.sample(0.05), mm.sample(0.05)
    assert b.s / k == pytest.approx(a.s, rel=1e-6, abs=1e-9)


def test_same_inputs_give_bitwise_identical_outputs():
    path = Path.from_waypoints([[0, 0], [8, 0], [12, 3]])
    a, b = plan(path, LGV).sample(0.02), plan(path, LGV).sample(0.02)
    for name, col in a.to_dict().items():
        assert np.array_equal(col, b.to_dict()[name]), name


def test_bad_arguments_name_themselves():
    line = Path.from_segments([Line(5.0)])
    for kwargs, name in [({"n": 2}, "n"), ({"ds": -1.0}, "ds"), ({"refine": "x"}, "refine"),
                         ({"standstill": "x"}, "standstill"), ({"v0": np.nan}, "v0")]:
        with pytest.raises(InvalidInputError, match=f"`{name}`"):
            plan(line, LGV, **kwargs)
    with pytest.raises(InvalidInputError, match="`path`"):
        plan([[0, 0], [1, 0]], LGV)


def test_moving_start_that_must_brake_is_jerk_limited_from_its_first_instant():
    line = Path.from_segments([Line(20.0)])
    zone = SpeedZone([(6.0, -1.0), (9.0, -1.0), (9.0, 1.0), (6.0, 1.0)], v_max=0.3)
    profile = plan(line, LGV, v0=2.0, zones=[zone])
    traj = assert_physics(profile)
    assert traj.v[0] == pytest.approx(2.0) and traj.a[0] == 0.0
    assert traj.v[np.searchsorted(traj.s, 6.0)] <= 0.3 * 1.005
    near = Path.from_segments([Line(20.0)])
    close_zone = SpeedZone([(2.0, -1.0), (6.0, -1.0), (6.0, 1.0), (2.0, 1.0)], v_max=0.3)
    with pytest.raises(InfeasibleError, match="j_max") as info:
        plan(near, LGV, v0=2.0, zones=[close_zone])
    assert info.value.constraint == "speed_bound"
    assert info.value.s == pytest.approx(2.0, abs=0.05)


def test_verify_with_plans_bound_equals_verify_with_any_callable():
    # verify() hands plan()'s SpeedBound the curvature it already has; a plain callable
    # (which gets only s) must measure exactly the same on a zone path and a NURBS path.
    import dataclasses

    from speedplan.geometry import SpeedBound

    for name in ("slow_zone.json", "nurbs_edge.json"):
        prof = plan(read_path(f"paths/{name}"), LGV, zones=read_zones(f"paths/{name}"))
        assert isinstance(prof.speed_bound, SpeedBound)  # so verify() takes the shortcut
        generic = dataclasses.replace(prof, speed_bound=lambda s, b=prof.speed_bound: b(s))
        assert prof.verify() == generic.verify()


def test_verify_uses_the_bounds_own_path_when_the_profile_has_another():
    # The curvature shortcut is only right when bound and profile share the path.
    import dataclasses

    short = plan(Path.from_segments([Line(3.0), Arc(1.0, 1.0)]), LGV)
    other = Path.from_segments([Line(3.0), Arc(4.0, 0.25)])
    moved = dataclasses.replace(short, path=other)
    generic = dataclasses.replace(moved, speed_bound=lambda s, b=short.speed_bound: b(s))
    assert moved.verify() == generic.verify()


@pytest.mark.parametrize(
    ("length", "lim"),
    [  # final jerk phases of ~1e-9 of the length (flagged "limits_exceeded" on 1e-9 L steps)
        (3796.2123365577972, Limits(v_max=11.919834443652514, a_max=0.1952355625560269,
                                    a_lat_max=1, j_max=12.254342066055846,
                                    a_decel=0.16360203180194188)),
        (61732.559974150085, Limits(v_max=0.10403071386939479, a_max=0.05401326900394628,
                                    a_lat_max=1, j_max=0.5945897176701356,
                                    a_decel=0.056394461589217876)),
    ],
)
def test_long_moves_resolve_their_final_jerk_phase(length, lim):
    with warnings.catch_warnings():
        warnings.simplefilter("error")  # no LimitWarning
        profile = plan(Path.from_segments([Line(length)]), lim)
    assert profile.status == "optimal"
    assert profile.duration >= ruckig_duration(length, lim) * (1 - 1e-9)


def test_a_refinement_that_cannot_resolve_a_jerk_phase_keeps_the_flagged_law():
    # 27 km at a_max 0.054, j_max 11 (trust fuzz): the jerk phases (0.2 µm) lie below the
    # finest default step (1e-11 L). Refining towards them drove the steps to 1e-8 m, the law
    # came to rest on the way and plan() raised SolverError. Now the refinement stops at that
    # step and the profile comes back flagged, never faster than ruckig's optimum.
    length = 27373.408073555755
    lim = Limits(v_max=12.217721761422338, a_max=0.05420259524615834, a_lat_max=1,
                 j_max=11.189576218503156, a_decel=0.05420259524615834)
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        profile = plan(Path.from_segments([Line(length)]), lim)
    assert np.isfinite(profile.duration)
    assert profile.duration >= ruckig_duration(length, lim) * (1 - 1e-4)
    if profile.status == "limits_exceeded":
        assert any(issubclass(w.category, LimitWarning) for w in caught)


def test_coarse_user_grid_for_a_braking_start_is_graded_to_resolve_it():
    # 2 m at 1/16 mm/s, braking at the start: the law reached rest in the first half cell
    # of n=120 and the duration was infinite (a NaN-free but never-arriving trajectory);
    # then such grids were refused (InvalidInputError naming the step to use); now the user
    # grid is graded at its moving ends, to 1/20 of the transient.
    lim = Limits(v_max=6.25e-5, a_max=1e-3, a_lat_max=1e-3, j_max=2e-3)
    line = Path.from_segments([Line(2.0)])
    for states in ({"v0": 3.125e-5, "a0": -3e-4}, {"vf": 3.125e-5, "af": 3e-4}):
        profile = plan(line, lim, n=120, **states)
        assert profile.status == "optimal" and profile.s.size > 120
        assert within_promise(measure(profile))
        optimum = ruckig_move(2.0, lim, **states).duration
        assert optimum is not None and profile.duration == pytest.approx(optimum, rel=1e-5)
