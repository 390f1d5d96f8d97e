"""Speed bounds mu+(s): lateral acceleration, zones, per-position limits; zone intervals."""

from __future__ import annotations

import numpy as np
import pytest
import shapely

from speedplan import InvalidInputError, Limits, Path, SpeedZone, speed_bounds
from speedplan.geometry import Arc, Clothoid, Line, zone_intervals

LIM = Limits(v_max=2.0, a_max=1.0, a_lat_max=1.0, j_max=0.5)


def test_straight_line_bound_is_v_max_squared():
    p = Path.from_segments([Line(25.0)])
    w = speed_bounds(p, LIM, np.linspace(0, 25, 11))
    assert (w == 4.0).all()


@pytest.mark.parametrize("R", [0.25, 1.0, 3.999, 4.0, 10.0, 250.0])
def test_arc_bound_is_min_of_v_max_squared_and_a_lat_times_radius(R):
    p = Path.from_segments([Arc(R, -1.0)])
    w = speed_bounds(p, LIM, np.linspace(0, p.length, 9))
    np.testing.assert_allclose(w, min(4.0, 1.0 * R), rtol=1e-12)


def test_clothoid_bound_follows_curvature_and_inf_lateral_limit_means_none():
    p = Path.from_segments([Clothoid(10.0, 0.0, 2.0)])
    s = np.linspace(0, 10, 101)
    k = 0.2 * s
    w = speed_bounds(p, LIM, s)
    with np.errstate(divide="ignore"):
        np.testing.assert_allclose(w, np.minimum(4.0, 1.0 / k), rtol=1e-12)
    free = Limits(v_max=2.0, a_max=1.0, a_lat_max=np.inf, j_max=0.5)
    assert (speed_bounds(p, free, s) == 4.0).all()


def test_slow_zone_applies_exactly_inside_and_on_the_boundary():
    p = Path.from_segments([Line(10.0), Arc(0.5, np.pi / 2), Line(10.0)])
    zone = SpeedZone(shapely.box(3.0, -1.0, 6.0, 1.0), v_max=0.5)
    s = np.array([0.0, 2.999999, 3.0, 4.5, 6.0, 6.000001, 9.0])
    w = speed_bounds(p, LIM, s, zones=[zone])
    np.testing.assert_array_equal(w, [4.0, 4.0, 0.25, 0.25, 0.25, 4.0, 4.0])
    # A zone over the bend keeps the lower of the two bounds.
    bend = SpeedZone([(9, -1), (12, -1), (12, 2), (9, 2)], v_max=1.0)
    w = speed_bounds(p, LIM, [9.5, 10.5, 12.0], zones=[zone, bend])
    np.testing.assert_allclose(w, [1.0, 0.5, 1.0], rtol=1e-12)


def test_v_limit_is_piecewise_linear_and_held_beyond_its_ends():
    p = Path.from_segments([Line(10.0)])
    v_limit = ([2.0, 6.0], [1.0, 0.0])
    w = speed_bounds(p, LIM, [0.0, 2.0, 4.0, 6.0, 10.0], v_limit=v_limit)
    np.testing.assert_allclose(w, [1.0, 1.0, 0.25, 0.0, 0.0], rtol=1e-15)
    w = speed_bounds(p, LIM, [0.0, 5.0], v_limit=([0.0, 10.0], [np.inf, np.inf]))
    assert (w == 4.0).all()


def test_zone_intervals_on_a_straight_line_and_on_an_arc():
    line = Path.from_segments([Line(10.0), Arc(0.5, np.pi / 2), Line(10.0)])
    (a, b, v), = zone_intervals(line, [SpeedZone(shapely.box(3.0, -1.0, 6.0, 1.0), 0.5)])
    assert (a, b, v) == (pytest.approx(3.0, abs=1e-9), pytest.approx(6.0, abs=1e-9), 0.5)
    # Arc of radius R about (0, R) from the origin: enters the half plane x >= c at
    # s = R asin(c / R) and leaves it at s = R (π - asin(c / R)).
    R, c = 5.0, 2.0
    arc = Path.from_segments([Arc(R, 1.5 * np.pi)])
    zone = SpeedZone(shapely.box(c, -10, 10, 20), 0.3)
    (a, b, v), = zone_intervals(arc, [zone])
    assert a == pytest.approx(R * np.arcsin(c / R), abs=1e-6)
    assert b == pytest.approx(R * (np.pi - np.arcsin(c / R)), abs=1e-6)


def test_zone_intervals_start_inside_several_crossings_and_sorting():
    p = Path.from_segments([Line(30.0)])
    zones = [SpeedZone(shapely.box(20, -1, 25, 1), 0.2),
             SpeedZone(shapely.box(-5, -1, 2, 1), 0.4),
             SpeedZone(shapely.Polygon([(8, -1), (10, -1), (10, 1), (12, 1), (12, -1),
                                        (14, -1), (14, 2), (8, 2)]), 0.6)]
    got = zone_intervals(p, zones)
    expected = [(0.0, 2.0, 0.4), (8.0, 10.0, 0.6), (12.0, 14.0, 0.6), (20.0, 25.0, 0.2)]
    assert len(got) == len(expected)
    for (a, b, v), (ea, eb, ev) in zip(got, expected, strict=True):
        assert abs(a - ea) < 1e-8 and abs(b - eb) < 1e-8 and v == ev
    end_inside = zone_intervals(p, [SpeedZone(shapely.box(28, -1, 40, 1), 0.1)])
    assert end_inside[0][1] == 30.0
    assert zone_intervals(p, [SpeedZone(shapely.box(0, 5, 1, 6), 0.1)]) == []


def test_zone_intervals_are_remembered_per_path_and_zones_and_stay_exact():
    from speedplan.geometry import bounds

    p = Path.from_segments([Line(30.0)])
    slow = SpeedZone(shapely.box(20, -1, 25, 1), 0.2)
    other = SpeedZone(shapely.box(3, -1, 6, 1), 0.3)
    first = zone_intervals(p, [slow])
    assert bounds._zone_intervals(p, [slow], 1e-9) == first  # computed, not only remembered
    first.append((0.0, 1.0, 9.0))  # the caller's list: the remembered answer is unchanged
    assert zone_intervals(p, [slow]) == first[:1]
    # Other zones, another tolerance, another path: their own answers.
    assert [v for _, _, v in zone_intervals(p, [other])] == [0.3]
    assert zone_intervals(p, [other, slow]) == sorted(zone_intervals(p, [other])
                                                      + zone_intervals(p, [slow]))
    coarse = zone_intervals(p, [slow], tol=1e-3)
    assert abs(coarse[0][0] - 20.0) < 1e-3
    q = Path.from_segments([Line(22.0)])
    assert zone_intervals(q, [slow])[0][1] == 22.0
    # Many zone sets on one path: a bounded memory, every answer still right.
    for k in range(3 * bounds._ZONE_CACHE_SIZE):
        z = SpeedZone(shapely.box(k, -1, k + 0.5, 1), 0.1)
        (a, b, _), = zone_intervals(p, [z])
        assert abs(a - k) < 1e-8 and abs(b - k - 0.5) < 1e-8
    assert len(bounds._ZONE_CACHE[p]) <= bounds._ZONE_CACHE_SIZE


def test_speed_zone_validation():
    with pytest.raises(InvalidInputError, match="`polygon`"):
        SpeedZone([(0, 0), (1, 0)], 1.0)
    with pytest.raises(InvalidInputError, match="`polygon`"):
        SpeedZone([(0, 0), (1, 1), (1, 0), (0, 1)], 1.0)  # self-intersecting bow tie
    with pytest.raises(InvalidInputError, match="`v_max`"):
        SpeedZone(shapely.box(0, 0, 1, 1), -1.0)
    p = Path.from_segments([Line(1.0)])
    with pytest.raises(InvalidInputError, match=r"`zones\[0\]`"):
        speed_bounds(p, LIM, [0.5], zones=[shapely.box(0, 0, 1, 1)])
    with pytest.raises(InvalidInputError, match="`v_limit"):
        speed_bounds(p, LIM, [0.5], v_limit=([1.0, 0.0], [1.0, 1.0]))
    with pytest.raises(InvalidInputError, match="`v_limit"):
        speed_bounds(p, LIM, [0.5], v_limit=([0.0, 1.0], [1.0, -1.0]))
    with pytest.raises(InvalidInputError, match="`v_limit"):
        speed_bounds(p, LIM, [0.5], v_limit=[1.0, 2.0, 3.0])
    with pytest.raises(InvalidInputError, match="`s`"):
        speed_bounds(p, LIM, [2.0])
    with pytest.raises(InvalidInputError, match="`limits`"):
        speed_bounds(p, {"v_max": 1}, [0.5])


def test_speed_bound_given_curvature_is_the_same_bound():
    # SpeedProfile.verify passes the curvature it already has; the bound must not change.
    from speedplan.geometry import SpeedBound

    p = Path.from_segments([Line(5.0), Arc(2.0, 1.5), Clothoid(4.0, 0.5, -0.3)])
    zone = SpeedZone([(1, -1), (3, -1), (3, 1), (1, 1)], v_max=0.5)
    bound = SpeedBound(p, LIM, [zone], v_limit=([0.0, p.length], [2.0, 0.8]))
    s = np.linspace(0, p.length, 301)
    np.testing.assert_array_equal(bound.given_curvature(s, p.curvature(s)), bound(s))
    np.testing.assert_array_equal(bound(s), speed_bounds(p, LIM, s, zones=[zone],
                                                        v_limit=([0.0, p.length], [2.0, 0.8])))
    with pytest.raises(InvalidInputError, match="curvature"):
        bound.given_curvature(s, p.curvature(s)[:-1])
