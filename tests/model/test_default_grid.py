"""The default grid: graded ends that neither cruise fast nor arrive early, end transients
sized from the speed cap, and dips of the speed bound narrower than its first scan or a zone
scan.

Straight moves are judged by ruckig's exact optimum of the same move and finite differences of
the sampled trajectory (``oracles.measure``).

A dip drawn by ``benchmarks/fuzz_zones.py`` (seed 3, case 51): a 4.5 km path with a 9 cm
hairpin (0.29 m/s for 0.3 m) between two points of the scan ``adaptive_grid`` reads the bound
on (0.97 m apart). A grid of 45 m steps there crosses the hairpin too fast, and three
refinements of a quarter each leave it at 1.76x ``j_max``: ``limits_exceeded``. The joins of
the path's pieces, where a clothoid chain's curvature peaks, and the zones' edges
(``bound_breakpoints``) join the scan where the bound dips between its points.

A zone crossed between two points of the membership scan of ``zone_intervals`` (2 cm on a
4 km path) is not seen at all: a 1 cm zone at 0.29 m/s crossed at 5.29 m/s, with a plan
saying ``optimal`` (its checks read the zone's edges from that scan). Steps next to a zone are
scanned again, 64 times finer.
"""

from __future__ import annotations

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from oracles import (
    PROMISED,
    assert_physical,
    measure,
    no_jerk_lower_bound,
    ruckig_duration,
    ruckig_move,
    subdivided_default_grids,
    within_promise,
)
from shapely.geometry import box
from shared import examples

from speedplan import Limits, Path, SpanLimit, SpeedZone, plan
from speedplan.geometry import Arc, Line, SpeedBound, bound_breakpoints, zone_intervals


def _line(length: float) -> Path:
    return Path.from_segments([Line(length)])


@pytest.mark.parametrize(("length", "lim"), [
    (400.0, Limits(v_max=0.2, a_max=3.0, a_lat_max=1.0, j_max=10.0)),  # was 1822.8 s < 2000 s
    (100.0, Limits(v_max=0.2, a_max=0.5, a_lat_max=1.0, j_max=5.0)),  # was -0.23 %, silent
    (10_000.0, Limits(v_max=2.0, a_max=1.0, a_lat_max=1.0, j_max=0.5)),  # was -0.35 %
])
def test_graded_default_grids_neither_cruise_fast_nor_arrive_early(length, lim):
    profile = plan(_line(length), lim)
    assert_physical(profile, length, lim)
    assert profile.duration >= length / lim.v_max  # L / v_max alone bounds it from below


@pytest.mark.parametrize(("length", "cap", "lim"), [
    # Capped far below v_max by a span, a zone or v_limit (an edge's maxSpeed in a route):
    # the default grid sized its end transients from v_max and came out 1.2e-3 slower than
    # ruckig at the cap (benchmarks/fuzz_caps.py draws such moves) ...
    (172.9, 0.06039, Limits(v_max=4.93, a_max=0.4172, a_lat_max=1.0, j_max=0.03581)),
    (32.54, 0.06776, Limits(v_max=3.383, a_max=3.707, a_lat_max=1.0, j_max=0.08693)),
    # ... or 2.2e-4 *faster*, with the jerk 4.3 % over j_max.
    (1.848, 0.1455, Limits(v_max=7.125, a_max=0.2465, a_lat_max=1.0, j_max=0.02665)),
])
@pytest.mark.parametrize("how", ["span", "v_limit"])
@pytest.mark.parametrize("n", [None, 300])
def test_a_cap_far_below_v_max_is_planned_to_its_own_optimum(length, cap, lim, how, n):
    # A user grid's graded ends had the same cause: 7.6e-3 above at n = 300 (the first move).
    path = _line(length)
    kw = ({"spans": [SpanLimit(0.0, length, v_max=cap)]} if how == "span"
          else {"v_limit": ([0.0, length], [cap, cap])})
    profile = plan(path, lim, n=n, **kw)
    capped = Limits(v_max=cap, a_max=lim.a_max, a_lat_max=1.0, j_max=lim.j_max)
    exact = ruckig_duration(length, capped)
    assert profile.status == "optimal"
    below = 2e-5 if n is None else 1e-4  # the jerk tolerance on a coarse grid
    assert exact * (1 - below) <= profile.duration <= exact * (1 + 1e-4)
    m = measure(profile, samples=12_000)
    assert m.speed <= 1 + PROMISED["speed"] and m.jerk <= 1 + 0.02, m


LIM = Limits(v_max=5.29, a_max=1.79, a_lat_max=0.948, j_max=0.273)


def test_a_hairpin_between_the_scan_points_is_resolved() -> None:
    # A 1 cm arc of radius 1 cm at 1.2 km of a 4 km straight: 0.097 m/s there. On the scan
    # of 0.97 m no point falls on it (before: limits_exceeded, speed 54x, lateral 2952x).
    before, radius, angle = 1234.567, 0.01, 1.0
    path = Path.from_segments([Line(before), Arc(radius=radius, angle=angle),
                               Line(4000.0 - before)])
    prof = plan(path, LIM)
    assert prof.status in ("optimal", "refined"), prof.verification
    m = measure(prof)
    assert within_promise(m), m
    v_arc = float(np.sqrt(LIM.a_lat_max * radius))
    t = np.linspace(0.0, prof.duration, 400_001)
    traj = prof.at(t)
    on_arc = (traj.s >= before) & (traj.s <= before + radius * angle)
    assert on_arc.sum() > 10  # the samples see the arc
    assert traj.v[on_arc].max() <= v_arc * (1 + 1e-3)
    assert np.max(np.abs(traj.curvature[on_arc]) * traj.v[on_arc] ** 2) <= LIM.a_lat_max * 1.01
    # No motion beats the exact no-jerk optimum; one motion that exists: ruckig's fastest
    # move to the arc at its speed, the arc at that speed, ruckig's fastest stop.
    lower, _, _ = no_jerk_lower_bound(SpeedBound(path, LIM), path.length, LIM.a_max,
                                      LIM.a_decel)
    to_arc = ruckig_move(before, LIM, vf=v_arc).duration
    from_arc = ruckig_move(4000.0 - before, LIM, v0=v_arc).duration
    assert to_arc is not None and from_arc is not None
    feasible = to_arc + radius * angle / v_arc + from_arc
    assert lower * (1 - 1e-9) <= prof.duration <= feasible * (1 + 1e-6)


def test_breakpoints_are_read_in_the_bound_own_arc_length() -> None:
    path = Path.from_segments([Line(10.0), Arc(radius=1.0, angle=1.0), Line(5.0)])
    bound = SpeedBound(path, LIM)
    assert bound_breakpoints(path, bound).tolist() == [10.0, 11.0]
    assert bound_breakpoints(path, bound.at_offset(4.0)).tolist() == [6.0, 7.0]
    assert bound_breakpoints(path, bound.at_offset(10.5)).tolist() == [0.5]


def test_a_zone_narrower_than_the_membership_scan_is_respected() -> None:
    entry, width, v_zone = 1234.567, 0.01, 0.29
    path = Path.from_waypoints([[0.0, 0.0], [4000.0, 0.0]], kind="polyline")
    zone = SpeedZone([(entry, -1.0), (entry + width, -1.0), (entry + width, 1.0),
                      (entry, 1.0)], v_max=v_zone)
    found = zone_intervals(path, [zone])
    assert len(found) == 1 and found[0][:2] == pytest.approx((entry, entry + width), abs=1e-8)
    prof = plan(path, LIM, zones=[zone])
    assert prof.status in ("optimal", "refined"), prof.verification
    assert within_promise(measure(prof))
    # The positions themselves while the vehicle is near the zone, 20 µs apart.
    coarse = prof.at(np.linspace(0.0, prof.duration, 100_001))
    t_entry = float(np.interp(entry, coarse.s, coarse.t))
    near = prof.at(np.linspace(t_entry - 1.0, t_entry + 1.0, 100_001))
    inside = (near.x >= entry) & (near.x <= entry + width)
    assert inside.sum() > 20  # even at v_max
    assert near.v[inside].max() <= v_zone * (1 + 1e-3)
    lower, _, _ = no_jerk_lower_bound(SpeedBound(path, LIM, [zone]), path.length, LIM.a_max,
                                      LIM.a_decel)
    to_zone = ruckig_move(entry, LIM, vf=v_zone).duration
    from_zone = ruckig_move(4000.0 - entry - width, LIM, v0=v_zone).duration
    assert to_zone is not None and from_zone is not None
    feasible = to_zone + width / v_zone + from_zone
    assert lower * (1 - 1e-9) <= prof.duration <= feasible * (1 + 1e-6)


def _no_jerk_optimum_line_arc_line(before: float, arc: float, after: float, w_arc: float,
                                   lim: Limits) -> float:
    """Exact minimum time without a jerk limit, rest to rest, over line - arc - line.

    The fastest ``w`` is the minimum of ``v_max²``, the acceleration cones from both rests
    and from the arc, and ``w_arc`` on the arc: piecewise linear in ``s``, so on a grid that
    holds every kink ``2 h / (v_0 + v_1)`` per step is exact.
    """
    total = before + arc + after
    a, d, top = 2 * lim.a_max, 2 * lim.a_decel, lim.v_max**2
    end = before + arc

    def w(s: np.ndarray) -> np.ndarray:
        on = (s >= before) & (s <= end)
        cone = np.where(s < before, w_arc + d * (before - s), w_arc + a * (s - end))
        return np.where(on, w_arc, np.minimum.reduce([np.full(s.shape, top), a * s,
                                                      d * (total - s), cone]))

    kinks = [top / a, before - (top - w_arc) / d, end + (top - w_arc) / a, total - top / d,
             (w_arc + d * before) / (a + d), (d * total + a * end - w_arc) / (a + d)]
    s = np.union1d(np.linspace(0.0, total, 200_001), [before, end, *kinks])
    s = s[(s >= 0) & (s <= total)]
    v = np.sqrt(w(s))
    return float(np.sum(2 * np.diff(s) / (v[1:] + v[:-1])))


def test_a_hairpin_narrower_than_a_no_jerk_grid_step_is_cut_out() -> None:
    # A 0.55 mm arc 1.7 km along a 1.9 km path, no jerk limit (found by a hairpin fuzz:
    # limits_exceeded, 18x the speed on the arc, after the grid's refinements).
    before, radius, angle, total = 1711.0, 0.00117, 0.47, 1912.0
    lim = Limits(v_max=0.7955, a_max=0.1442, a_lat_max=1.657, j_max=np.inf)
    path = Path.from_segments([Line(before), Arc(radius=radius, angle=angle),
                               Line(total - before - radius * angle)])
    prof = plan(path, lim)
    assert prof.status == "optimal", prof.verification
    w_arc = min(lim.a_lat_max * radius, lim.v_max**2)
    exact = _no_jerk_optimum_line_arc_line(before, radius * angle,
                                           total - before - radius * angle, w_arc, lim)
    assert exact * (1 - 1e-9) <= prof.duration <= exact * (1 + 1e-3)
    coarse = prof.at(np.linspace(0.0, prof.duration, 100_001))
    t_arc = float(np.interp(before, coarse.s, coarse.t))
    near = prof.at(np.linspace(t_arc - 0.5, t_arc + 0.5, 100_001))
    on_arc = (near.s >= before) & (near.s <= before + radius * angle)
    assert on_arc.sum() > 10
    assert near.v[on_arc].max() <= np.sqrt(w_arc) * (1 + 1e-3)


def test_a_grid_at_its_node_cap_keeps_the_first_transitions_at_the_ends_resolved() -> None:
    # Jerk phases of 8 ms on a 4 m path (a_max 0.11 m/s², j_max 13.6 m/s³): the default grid
    # wants several thousand nodes; under a cap of half of them it grows its steps, and the
    # max-jerk start from rest (1.2 µm long) must keep its own steps, or the law's jerk at its
    # end goes over the limit and every finer grid tried after it costs tens of seconds.
    from speedplan.model import PlanRequest, build_model
    from speedplan.model.grid import DEFAULT_PER_PHASE, rest_phase_length
    from speedplan.model.leg_grid import default_grid

    path = Path.from_waypoints([
        [0, 0], [0.12426521336474784, -0.11657631877453342],
        [3.021780629947684, 0.018193808385309485], [3.207499798766692, -0.2747489556759499],
        [3.9813199879850347, 0.1445236020023441]])
    lim = Limits(v_max=16.418898422873855, a_max=0.11059941918961164,
                 a_lat_max=0.1453314309003239, j_max=13.58945597172854)
    request = PlanRequest.create(path, lim)
    leg = build_model(request).legs[0]
    cap = leg.problem.n // 2
    s = default_grid(request, leg.bound, 0.0, path.length, 0.0, 0.0, 0.0, 0.0, max_nodes=cap)
    assert 0.9 * cap <= s.size <= cap  # the cap binds
    ell = rest_phase_length(lim.a_max, lim.v_max, lim.j_max)
    for nodes in (np.sum(s <= ell), np.sum(s >= s[-1] - ell)):
        assert nodes >= 0.5 * DEFAULT_PER_PHASE
    profile = plan(path, lim)
    assert profile.verification.ok and not profile.limits_exceeded


def test_a_stop_of_micrometres_at_the_end_of_a_long_capped_leg_keeps_its_jerk() -> None:
    # 172 m with a slow zone, jerk phases of 8.5 ms: the final stop spans 1.9 µm, where w is
    # 1e-7 of its cruise value. The law's values gather 1e-9 over the leg's 20 000 cells; bent
    # into the stop, that took its jerk 1.11x over j_max, which no refinement removed.
    from speedplan.model.grid import GRADING

    path = Path.from_waypoints([
        [0.0, 0.0], [32.90716888884577, -6.692431771353052],
        [57.84437470267518, -25.955765291856817], [72.44320142124874, -19.64020414007242],
        [107.09552365321909, -17.778012755072474], [130.6361893417902, -39.21086907340705],
        [154.50011197840368, -46.53012829696773]])
    zone = SpeedZone(box(77.77066181467825, -1e4, 128.6095293996484, 1e4), 0.03916759237268164)
    lim = Limits(v_max=3.337685311937242, a_max=0.15716401945518907,
                 a_lat_max=1.5141606808319439, j_max=18.40764709655499)
    profile = plan(path, lim, zones=[zone], v0=0.137224887994673, a0=0.0005480408910801183)
    assert profile.verification.ok and not profile.limits_exceeded
    # The acceleration sampled over the last 30 ms, finite-differenced in time.
    t = np.linspace(profile.duration - 0.03, profile.duration, 30_001)
    accel = profile.law.state_at(t)[3]
    assert np.abs(np.diff(accel) / np.diff(t)).max() <= lim.j_max * (1 + GRADING) * (1 + 1e-3)


@settings(max_examples=examples(10), deadline=None)
@given(length=st.floats(0.5, 2_000.0), a_max=st.floats(0.02, 2.0), j_max=st.floats(5.0, 100.0),
       v_max=st.floats(0.5, 20.0), max_nodes=st.sampled_from([200, 2_000, 20_000]))
def test_a_capped_default_grid_is_graded_and_keeps_its_end_transitions(length, a_max, j_max,
                                                                       v_max, max_nodes):
    # Ten slow-downs along the move (a speed bound dipping to 10 % of v_max²) with jerk phases
    # of milliseconds: more nodes wanted than the cap allows. The grid stays a grid (from 0
    # to the length, increasing, about the cap's size: no step grows beyond the cruise step,
    # so a cap of a few hundred nodes may be exceeded) and, when its end zones fit a quarter
    # of the cap, keeps their steps.
    from speedplan.model.grid import END_SHARE, END_ZONE, adaptive_grid, rest_phase_length

    def bound(q):
        return v_max**2 * (0.55 + 0.45 * np.cos(20.0 * np.pi * np.asarray(q) / length))

    def grid(cap):
        return adaptive_grid(length, bound, a_max=a_max, a_decel=a_max, v_max=v_max,
                             j_max=j_max, w_start=0.0, w_end=0.0, max_nodes=cap)

    s = grid(max_nodes)
    assert s[0] == 0.0 and s[-1] == length and np.all(np.diff(s) > 0)
    if max_nodes >= 2_000:  # a cap of a few hundred is bounded below by the cruise steps
        assert s.size <= 1.02 * max_nodes + 5
    ell = rest_phase_length(a_max, v_max, j_max, length)
    uncapped = grid(10**7)
    wanted = int(np.sum(uncapped <= ell))
    if (uncapped.size > max_nodes and 2.0 * ell <= END_ZONE * length and wanted >= 20
            and 4 * wanted <= END_SHARE * max_nodes):
        assert np.sum(s <= ell) >= 0.9 * wanted
        assert np.sum(s >= length - ell) >= 0.9 * wanted


def _agrees_with_its_grid_cut_in_two(path: Path, lim: Limits) -> None:
    """The default grid's plan within every limit, finite-differenced, no faster than the
    exact optimum without jerk limit, and within 1e-6 of the same grid cut in two."""
    profile = plan(path, lim)
    assert within_promise(measure(profile))
    fastest, _, _ = no_jerk_lower_bound(SpeedBound(path, lim), path.length, lim.a_max,
                                        lim.a_decel)
    assert profile.duration >= fastest
    with subdivided_default_grids(2):
        finer = plan(path, lim)
    assert finer.legs[0].s.size > 1.9 * profile.legs[0].s.size  # answered on the finer grid
    assert profile.verification.ok and finer.verification.ok
    assert abs(profile.duration / finer.duration - 1.0) < 1e-6


def test_a_slow_stretch_is_coarse_a_few_transitions_away_from_its_kinks() -> None:
    # 628 m through six bends, jerk phases of 0.27 s: the bends slow the vehicle to about
    # 0.7 m/s, where the margin around a kink sized at the top speed (7.3 m) spans some 30
    # transitions. Counted in metres it kept them all at fine steps and the grid at its node
    # cap; counted in time (a few transitions) the grid needs a third of it, and cutting every
    # cell in two moves the duration by less than 1e-6.
    from speedplan.model import PlanRequest, build_model
    from speedplan.model.grid import MAX_DEFAULT_NODES

    path = Path.from_waypoints([
        [0.0, 0.0], [115.841, 19.429], [188.241, -12.719], [289.366, -47.828],
        [399.486, -92.515], [453.451, -38.052], [574.008, -83.844]])
    lim = Limits(v_max=13.37, a_max=0.0985, a_lat_max=0.205, j_max=0.36)
    assert build_model(PlanRequest.create(path, lim)).legs[0].problem.n < MAX_DEFAULT_NODES / 2
    _agrees_with_its_grid_cut_in_two(path, lim)


def test_a_bound_followed_with_little_jerk_is_stepped_by_its_shape() -> None:
    # A right-angle corner at a yaw rate of 0.3 rad/s: along its clothoids the speed follows
    # the bound ω/κ(s) down to 0.17 m/s, which takes 1–10 % of j_max = 20 m/s³. Its jerk
    # phases (25 ms) span millimetres there; stepped by them along the whole bound, the grid
    # had 10 486 nodes. Stepped by the bound's shape a few phases away from its kinks it needs
    # far fewer, and cutting every cell in two moves the duration by less than 1e-6.
    from speedplan.model import PlanRequest, build_model

    path = Path.from_waypoints([[0.0, 0.0], [10.0, 0.0], [10.0, 10.0]])
    lim = Limits(v_max=5.0, a_max=0.5, a_lat_max=1.0, j_max=20.0, yaw_rate_max=0.3)
    assert build_model(PlanRequest.create(path, lim)).legs[0].problem.n < 8_000
    _agrees_with_its_grid_cut_in_two(path, lim)


@pytest.mark.parametrize("points", [20_001, 200_001])
def test_a_kink_on_points_a_few_ulps_apart_is_stepped_as_a_kink(monkeypatch, points) -> None:
    # A symmetric move peaks at its middle, where the uniform points and both end clusters of
    # the pre-grid meet within a few ulps. The no-jerk profile's kink on that 1e-16 m cell
    # passed for linear, and the top-speed transition (jerk phases of 6.6 ms, 2.3 mm at
    # 0.345 m/s) got a cruise step of 18 mm (3.9e-6 of the duration) with 200 001 points.
    from speedplan.model import PlanRequest, build_model, grid

    monkeypatch.setattr(grid, "PRE_GRID_POINTS", points)
    path = Path.from_waypoints([[0.0, 0.0], [0.9, 0.05], [1.8, 0.0]])
    lim = Limits(v_max=0.9, a_max=0.0648, a_lat_max=0.1566, j_max=9.77)
    profile = plan(path, lim)
    s = profile.legs[0].s
    w = profile.legs[0].solution.w
    top = int(np.argmax(w))
    v = float(np.sqrt(w[top]))
    transition = v * min(lim.a_max / lim.j_max, np.sqrt(v / lim.j_max))
    assert np.diff(s)[top - 1:top + 1].max() < 4 * transition / grid.DEFAULT_PER_PHASE
    assert build_model(PlanRequest.create(path, lim)).legs[0].problem.n == s.size
    assert within_promise(measure(profile))
