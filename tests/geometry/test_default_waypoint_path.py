"""The default waypoint path: within the deviation of its legs, in the aisle, driven back at
reversals, curvature-continuous.

The figures in the comments are those of a G1 clothoid chain with spline-estimated headings,
which leaves the aisle, loops at reversals and steps in curvature. Oracles: shapely distances,
hand-derived headings and lengths.
"""

from __future__ import annotations

import numpy as np
import pytest
import shapely

from speedplan import Path

SERPENTINE = [[0, 0], [20, 0], [20, 6], [0, 6], [0, 12]]
DOCK = [[0, 0], [30, 0], [32, 1.5], [40, 1.5]]
README = [[0, 0], [10, 0], [14, 4], [14, 12]]
ZIGZAG = [[0, 0], [3, 2], [4, 0], [7, 2], [8, 0]]


def leg_distance(p, pts):
    xy = p.point(np.linspace(0, p.length, 20001))
    return float(shapely.distance(shapely.points(xy), shapely.LineString(pts)).max())


@pytest.mark.parametrize("pts", [SERPENTINE, DOCK, README, ZIGZAG])
def test_default_path_stays_within_the_deviation_of_the_legs(pts):
    # The G1 chain dips 7.07 m (serpentine), 6.6 m (dock), 1.38 m (README) off them.
    p = Path.from_waypoints(pts)
    assert leg_distance(p, pts) <= 0.25 + 1e-12  # the documented default max_deviation


def test_default_path_keeps_to_the_aisle_and_its_first_leg():
    p = Path.from_waypoints(SERPENTINE)
    xy = p.point(np.linspace(0, p.length, 20001))
    assert xy[:, 1].min() >= 0.0 and xy[:, 0].min() >= -1e-12 and xy[:, 0].max() <= 20.0
    assert p.heading(0.0) == 0.0  # along the first leg (G1 chain: -1.19 rad)
    q = Path.from_waypoints(README)  # turns left only: never below its first leg
    assert q.point(np.linspace(0, q.length, 20001))[:, 1].min() >= 0.0  # G1 chain: -1.38 m


@pytest.mark.parametrize(("pts", "length"), [([[0, 0], [10, 0], [0, 0]], 20.0),
                                             ([[0, 0], [10, 0], [5, 0]], 15.0)])
def test_reversals_are_driven_back_not_looped(pts, length):
    p = Path.from_waypoints(pts)
    xy = p.point(np.linspace(0, p.length, 2001))
    assert np.abs(xy[:, 1]).max() == 0.0  # G1 chain: a loop of ±3.6 m / 4.3 m
    assert p.length == length  # G1 chain: 33.3 m / 22.0 m
    assert p.cusps.tolist() == [10.0]


@pytest.mark.parametrize("pts", [SERPENTINE, ZIGZAG, [[0, 0], [12, 0], [13.5, 1.5], [13.5, 10],
                                                      [15, 11.5], [27, 11.5]]])
def test_default_path_is_curvature_continuous(pts):
    # A G1 path's curvature jumps by 0.2 1/m (aisle) and 1.1 1/m (zigzag) at the waypoints.
    # Here: both sides of every join, via the path.
    p = Path.from_waypoints(pts)
    eps = 1e-10 * p.length
    joins = p.offsets[1:-1]
    jump = np.abs(p.curvature(joins + eps) - p.curvature(joins - eps))
    sharpness = max(abs(q.k1 - q.k0) / q.length for q in p.pieces)
    assert jump.max() <= 2 * eps * sharpness + 1e-9
