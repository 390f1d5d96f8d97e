"""Waypoint fitting: G1 clothoid chain, arc-length cubic spline, rounded polyline."""

from __future__ import annotations

from itertools import pairwise

import numpy as np
import pytest
import shapely
from hypothesis import assume, given, settings
from hypothesis import strategies as st
from scipy.integrate import quad
from scipy.interpolate import CubicSpline
from shared import examples

from speedplan import InvalidInputError, Path
from speedplan.geometry.fitting import CORNER_FRACTION, fit_clothoid


def clothoid_end_by_quad(theta0, length, k0, k1):
    """Independent end point: adaptive quadrature of cos/sin of the quadratic heading."""
    c = (k1 - k0) / length
    opts = {"epsabs": 1e-11, "epsrel": 1e-12, "limit": 1000}
    x = quad(lambda u: np.cos(theta0 + k0 * u + 0.5 * c * u * u), 0, length, **opts)[0]
    y = quad(lambda u: np.sin(theta0 + k0 * u + 0.5 * c * u * u), 0, length, **opts)[0]
    return np.array([x, y])


def wrapped(a):
    return np.angle(np.exp(1j * np.asarray(a)))


# ---- G1 Hermite clothoid --------------------------------------------------------------------
@settings(max_examples=examples(60), deadline=None)
@given(
    x=st.floats(-20, 20), y=st.floats(-20, 20), dist=st.floats(0.1, 50),
    chord=st.floats(-np.pi, np.pi),
    phi0=st.floats(-np.pi + 0.05, np.pi - 0.05), phi1=st.floats(-np.pi + 0.05, np.pi - 0.05),
)
def test_g1_hermite_clothoid_hits_any_target_pose(x, y, dist, chord, phi0, phi1):
    p0 = np.array([x, y])
    p1 = p0 + dist * np.array([np.cos(chord), np.sin(chord)])
    c = fit_clothoid(p0, chord + phi0, p1, chord + phi1)
    end = c.point(np.array(c.length))
    np.testing.assert_allclose(end, p1, rtol=0, atol=1e-9 * max(dist, 1.0))
    assert abs(wrapped(c.heading(np.array(c.length)) - (chord + phi1))) < 1e-12
    assert c.heading(np.array(0.0)) == chord + phi0
    # The piece's own quadrature agrees with an independent one.
    indep = p0 + clothoid_end_by_quad(chord + phi0, c.length, c.k0, c.k1)
    np.testing.assert_allclose(end, indep, rtol=0, atol=1e-9 * max(dist, 1.0))


def test_g1_hermite_special_cases():
    line = fit_clothoid([0, 0], 0.3, [4 * np.cos(0.3), 4 * np.sin(0.3)], 0.3)
    assert (line.k0, line.k1) == (0.0, 0.0) and line.length == pytest.approx(4.0, rel=1e-15)
    # Symmetric headings: a circular arc (A = 0). Semicircle of radius 1.5 (a U-turn).
    u = fit_clothoid([0, 0], 0.0, [0, 3], np.pi)
    assert u.k0 == pytest.approx(1 / 1.5, rel=1e-12) and u.k1 == pytest.approx(1 / 1.5, rel=1e-12)
    assert u.length == pytest.approx(1.5 * np.pi, rel=1e-12)
    # Both headings pointing back along the chord: a loop, still exact.
    loop = fit_clothoid([0, 0], np.pi, [1, 0], np.pi)
    np.testing.assert_allclose(loop.point(np.array(loop.length)), [1, 0], atol=1e-12)
    assert loop.k0 == pytest.approx(-loop.k1, rel=1e-12) and loop.length > 2.0


# ---- clothoid chain -------------------------------------------------------------------------
AISLE = np.array([[0, 0], [12, 0], [13.5, 1.5], [13.5, 10], [15, 11.5], [27, 11.5]], float)
SERPENTINE = [[0, 0], [20, 0], [20, 6], [0, 6], [0, 12]]


@pytest.mark.parametrize("pts", [AISLE, AISLE * 1e-3 + 5.0, AISLE[::-1],
                                 np.array([[0, 0], [10, 0], [14, 4], [14, 12], [8, 16]], float)])
def test_clothoid_chain_passes_through_every_waypoint_g1(pts):
    p = Path.from_waypoints(pts, kind="clothoid")
    assert len(p.pieces) == len(pts) - 1
    scale = np.ptp(pts, axis=0).max()
    np.testing.assert_allclose(p.point(p.offsets), pts, rtol=0, atol=1e-9 * scale)
    for prev, nxt in zip(p.pieces[:-1], p.pieces[1:], strict=True):  # unwrapped, exact
        assert abs(prev.heading(np.array(prev.length)) - nxt.theta0) < 1e-9
    eps = 1e-12 * p.length
    joints = p.offsets[1:-1]
    assert np.abs(p.heading(joints + eps) - p.heading(joints - eps)).max() < 1e-9
    for piece in p.pieces:  # curvature linear on every leg
        u = np.linspace(0, piece.length, 7)
        k = piece.curvature(u)
        np.testing.assert_allclose(np.diff(k, 2), 0.0, atol=1e-12 * max(1, np.abs(k).max()))


def test_clothoid_chain_collinear_points_give_zero_curvature():
    pts = np.column_stack((np.linspace(0, 30, 7), np.linspace(0, 10, 7)))
    p = Path.from_waypoints(pts, kind="clothoid")
    s = np.linspace(0, p.length, 200)
    assert np.abs(p.curvature(s)).max() < 1e-12
    assert p.length == pytest.approx(np.hypot(30, 10), rel=1e-14)


def test_clothoid_chain_uses_given_headings():
    pts = [[0, 0], [5, 5], [10, 0]]
    heads = [np.pi / 2, 0.0, -np.pi / 2]
    p = Path.from_waypoints(pts, kind="clothoid", headings=heads)
    np.testing.assert_allclose(wrapped(p.heading(p.offsets) - heads), 0, atol=1e-12)
    np.testing.assert_allclose(p.point(p.offsets), pts, atol=1e-9)


def test_clothoid_chain_headings_follow_the_leg_bisectors():
    # Legs of the serpentine point 0, π/2, π, π/2: bisectors π/4, 3π/4, 3π/4; leg directions at
    # the ends (headings estimated from a spline, -1.19 rad at the start, swing the chain
    # 7 m out).
    p = Path.from_waypoints(SERPENTINE, kind="clothoid")
    expected = np.array([0, 1, 3, 3, 2]) * np.pi / 4
    np.testing.assert_allclose(p.heading(p.offsets), expected, rtol=0, atol=1e-12)
    np.testing.assert_allclose(p.point(p.offsets), SERPENTINE, rtol=0, atol=1e-9)


def test_closed_waypoints_give_a_closed_smooth_loop():
    t = np.linspace(0, 2 * np.pi, 9)
    pts = np.column_stack((10 * np.cos(t), 6 * np.sin(t)))
    for kind in ("clothoid", "spline"):
        p = Path.from_waypoints(pts, kind=kind)
        assert p.is_closed
        assert abs(wrapped(p.heading(p.length) - p.heading(0.0))) < 1e-9


# ---- arc-length cubic spline ----------------------------------------------------------------
SPLINE_PTS = np.array([[0, 0], [3, 1], [5, 4], [9, 5], [12, 2]], dtype=float)


def test_spline_length_and_waypoints_match_high_accuracy_quadrature():
    p = Path.from_waypoints(SPLINE_PTS, kind="spline")
    tau = np.concatenate(([0], np.cumsum(np.linalg.norm(np.diff(SPLINE_PTS, axis=0), axis=1))))
    cs = CubicSpline(tau, SPLINE_PTS)

    def arc(a, b):
        return quad(lambda t: float(np.linalg.norm(cs(t, 1))), a, b, epsabs=1e-13,
                    epsrel=1e-13, limit=200)[0]

    s_knots = np.concatenate(([0.0], np.cumsum([arc(a, b) for a, b in pairwise(tau)])))
    assert p.length == pytest.approx(s_knots[-1], abs=1e-6)
    assert abs(p.length - s_knots[-1]) < 1e-10  # in fact to rounding
    # The waypoint i sits at arc length s_knots[i]: the s -> tau inversion is exact.
    np.testing.assert_allclose(p.point(s_knots), SPLINE_PTS, rtol=0, atol=1e-9)
    # Curvature equals (x'y'' - y'x'')/|r'|³ of the spline at those parameters.
    d1, d2 = cs(tau, 1), cs(tau, 2)
    k = (d1[:, 0] * d2[:, 1] - d1[:, 1] * d2[:, 0]) / np.linalg.norm(d1, axis=1) ** 3
    np.testing.assert_allclose(p.curvature(s_knots), k, rtol=1e-9, atol=1e-12)


def test_spline_heading_derivative_is_curvature():
    p = Path.from_waypoints(SPLINE_PTS, kind="spline")
    s = np.linspace(0.5, p.length - 0.5, 50)
    h = 1e-4
    dtheta = (p.heading(s + h) - p.heading(s - h)) / (2 * h)
    np.testing.assert_allclose(dtheta, p.curvature(s), atol=1e-6)


def test_spline_heading_is_unwrapped_through_a_spiral():
    t = np.linspace(0, 4 * np.pi, 30)
    pts = np.column_stack(((5 + t) * np.cos(t), (5 + t) * np.sin(t)))
    p = Path.from_waypoints(pts, kind="spline")
    th = p.heading(np.linspace(0, p.length, 3000))
    assert (np.diff(th) > 0).all() and th[-1] - th[0] > 3.5 * np.pi


# ---- rounded polyline -----------------------------------------------------------------------
def test_polyline_corner_radius_gives_the_tangent_arc():
    R = 2.0
    p = Path.from_waypoints([[0, 0], [10, 0], [10, 10]], kind="polyline", corner_radius=R)
    lengths = [piece.length for piece in p.pieces]
    np.testing.assert_allclose(lengths, [10 - R, R * np.pi / 2, 10 - R], rtol=1e-14)
    assert p.curvature(10 - R + 1.0) == pytest.approx(1 / R, rel=1e-14)
    assert p.length == pytest.approx(20 - 2 * R + R * np.pi / 2, rel=1e-14)
    # Deviation from the corner: R (1/cos 45° - 1).
    ls = p.to_linestring(ds=1e-3)
    dev = ls.distance(shapely.Point(10, 0))
    assert dev == pytest.approx(R * (np.sqrt(2) - 1), rel=1e-6)


@pytest.mark.parametrize("turn_deg", [20.0, 90.0, 135.0])
def test_polyline_max_deviation_is_met_exactly(turn_deg):
    a = np.deg2rad(turn_deg)
    pts = np.array([[0, 0], [20, 0], [20 + 20 * np.cos(a), 20 * np.sin(a)]])
    p = Path.from_waypoints(pts, kind="polyline", max_deviation=0.3)
    dev = p.to_linestring(ds=1e-3).distance(shapely.Point(20, 0))
    assert dev == pytest.approx(0.3, rel=1e-5)


def test_polyline_default_rounding_and_half_leg_cap():
    pts = np.array([[0, 0], [8, 0], [8, 4]], dtype=float)
    p = Path.from_waypoints(pts, kind="polyline")
    t = CORNER_FRACTION * 4.0  # a quarter of the shorter leg, for a 90° corner R = t
    assert p.curvature(8.0 - t + 0.1) == pytest.approx(1 / t, rel=1e-12)
    assert p.pieces[0].length == pytest.approx(8.0 - t, rel=1e-14)
    # A huge requested radius is reduced so the arc starts at most mid-leg.
    q = Path.from_waypoints(pts, kind="polyline", corner_radius=100.0)
    assert q.curvature(7.0) == pytest.approx(1 / 2.0, rel=1e-12)  # tangent = half of 4 m
    assert len(q.pieces) == 3 and q.pieces[2].length == pytest.approx(0.0 + 2.0, rel=1e-12)


def test_polyline_is_g1_and_straight_legs_are_exact():
    pts = np.array([[0, 0], [5, 0], [5, 5], [0, 5], [0, 1]], dtype=float)
    p = Path.from_waypoints(pts, kind="polyline", max_deviation=0.2)
    eps = 1e-10
    joints = p.offsets[1:-1]
    assert np.abs(p.heading(joints + eps) - p.heading(joints - eps)).max() < 1e-9
    assert p.heading(p.length) == pytest.approx(3 * np.pi / 2, abs=1e-12)  # unwrapped
    assert p.point(0.0).tolist() == [0.0, 0.0]
    np.testing.assert_allclose(p.point(p.length), [0, 1], atol=1e-12)
    collinear = Path.from_waypoints([[0, 0], [1, 0], [3, 0]], kind="polyline")
    assert collinear.length == pytest.approx(3.0, rel=1e-15)
    assert np.abs(collinear.curvature(np.linspace(0, 3, 10))).max() == 0.0


def test_polyline_rejects_sharp_corners_and_cusps():
    with pytest.raises(InvalidInputError, match=r"`max_deviation`.*stop"):
        Path.from_waypoints([[0, 0], [1, 0], [1, 1]], kind="polyline", max_deviation=0)
    with pytest.raises(InvalidInputError, match="`xy` reverses direction at row 1"):
        Path.from_waypoints([[0, 0], [2, 0], [1, 0]], kind="polyline")


# ---- all kinds ------------------------------------------------------------------------------
@settings(max_examples=examples(30), deadline=None)
@given(
    pts=st.lists(st.tuples(st.floats(-50, 50), st.floats(-50, 50)), min_size=2, max_size=7),
    kind=st.sampled_from(["g2", "clothoid", "spline", "polyline"]),
)
def test_every_kind_starts_and_ends_at_the_end_waypoints(pts, kind):
    xy = np.array(pts)
    legs = np.linalg.norm(np.diff(xy, axis=0), axis=1)
    assume((legs > 1.0).all())
    heads = np.arctan2(np.diff(xy[:, 1]), np.diff(xy[:, 0]))
    assume((np.abs(wrapped(np.diff(heads))) < 2.5).all())  # no near-reversals
    p = Path.from_waypoints(xy, kind=kind)
    np.testing.assert_allclose(p.point(0.0), xy[0], atol=1e-9)
    np.testing.assert_allclose(p.point(p.length), xy[-1], atol=1e-8)
    chord = np.linalg.norm(xy[-1] - xy[0])
    assert p.length >= chord * (1 - 1e-12)
