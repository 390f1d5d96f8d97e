"""A dip of the speed bound narrower than the default grid's first scan, or than a zone scan.

Found by ``benchmarks/fuzz_zones.py`` (seed 3, case 51): a 4.5 km path with a 9 cm hairpin
(0.29 m/s for 0.3 m) between two points of the scan ``adaptive_grid`` reads the bound on
(0.97 m apart). The grid had 45 m steps there, the law crossed the hairpin too fast, and
three refinements of a quarter each left it at 1.76x ``j_max``: ``limits_exceeded``. The
joins of the path's pieces, where a clothoid chain's curvature peaks, and the zones' edges
(``bound_breakpoints``) now join the scan where the bound dips between its points.

A zone crossed between two points of the membership scan of ``zone_intervals`` (2 cm on a
4 km path) was not seen at all: a 1 cm zone at 0.29 m/s was crossed at 5.29 m/s and the
plan said ``optimal`` (its checks read the zone's edges from that scan). Steps next to a
zone are now scanned again, 64 times finer.
"""

from __future__ import annotations

import numpy as np
import pytest
from oracles import measure, no_jerk_lower_bound, ruckig_move, within_promise

from speedplan import Limits, Path, SpeedZone, plan
from speedplan.geometry import Arc, Line, SpeedBound, bound_breakpoints, zone_intervals

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
