"""Geometry layer: closed forms, G1 continuity, arc-length parametrisation, bad input."""

from __future__ import annotations

import re

import numpy as np
import pytest
import shapely
from hypothesis import given, settings
from hypothesis import strategies as st
from scipy.integrate import quad

from speedplan import InvalidInputError, Limits, Path, SpeedZone, speed_bounds
from speedplan.geometry import Arc, Clothoid, Line, zone_intervals
from speedplan.geometry.fitting import fit_clothoid

LIM = Limits(v_max=2.0, a_max=1.0, a_lat_max=1.0, j_max=0.5)


def test_primitive_lengths_curvatures_and_end_points_match_closed_forms():
    R, ang = 3.0, 2.0
    p = Path.from_segments([Line(5.0), Arc(R, ang), Clothoid(4.0, 1 / R, -0.2)])
    assert p.length == pytest.approx(5.0 + R * ang + 4.0, rel=1e-12)
    assert p.curvature(5.0 + 1.0) == pytest.approx(1 / R, rel=1e-12)
    # The arc ends at the centre + R (sin, -cos) rotated by the angle turned.
    end_arc = p.point(5.0 + R * ang)
    centre = np.array([5.0, R])
    assert end_arc == pytest.approx(centre + R * np.array([np.sin(ang), -np.cos(ang)]), abs=1e-12)
    # Clothoid: curvature linear in s, end point equal to an independent quadrature.
    s = 5.0 + R * ang + np.linspace(0, 4, 9)
    assert p.curvature(s) == pytest.approx(1 / R + (-0.2 - 1 / R) * np.linspace(0, 1, 9),
                                           abs=1e-12)
    th0 = ang

    def theta(u):
        return th0 + u / R + 0.5 * (-0.2 - 1 / R) * u * u / 4.0

    x = quad(lambda u: np.cos(theta(u)), 0, 4, epsabs=1e-13, epsrel=1e-13)[0]
    y = quad(lambda u: np.sin(theta(u)), 0, 4, epsabs=1e-13, epsrel=1e-13)[0]
    assert p.point(p.length) == pytest.approx(end_arc + np.array([x, y]), abs=1e-11)


def test_heading_is_continuous_across_g1_joints():
    p = Path.from_segments([Line(1.0), Clothoid(2.0, 0.0, 0.5), Arc(2.0, 1.0),
                            Clothoid(2.0, 0.5, 0.0)])
    for joint in p.offsets[1:-1]:
        before, after = p.heading(joint - 1e-12), p.heading(joint + 1e-12)
        assert abs(after - before) < 1e-9


def test_clothoid_chain_passes_through_every_waypoint_g1():
    pts = np.array([[0, 0], [10, 0], [14, 4], [14, 12], [8, 16]], dtype=float)
    p = Path.from_waypoints(pts)
    assert p.point(p.offsets) == pytest.approx(pts, abs=1e-9)
    for joint in p.offsets[1:-1]:
        jump = p.heading(joint + 1e-12) - p.heading(joint - 1e-12)
        assert abs(np.angle(np.exp(1j * jump))) < 1e-9


def test_g1_hermite_clothoid_hits_the_target_pose():
    piece = fit_clothoid(np.array([1.0, 2.0]), 0.3, np.array([6.0, 4.0]), 1.4)
    assert piece.point(np.array(piece.length)) == pytest.approx([6.0, 4.0], abs=1e-10)
    assert float(piece.heading(np.array(piece.length))) == pytest.approx(1.4, abs=1e-12)


def test_spline_is_parametrised_by_true_arc_length():
    from scipy.interpolate import CubicSpline

    pts = np.array([[0, 0], [3, 1], [5, 4], [9, 5]], dtype=float)
    p = Path.from_waypoints(pts, kind="spline")
    tau = np.concatenate(([0], np.cumsum(np.linalg.norm(np.diff(pts, axis=0), axis=1))))
    cs = CubicSpline(tau, pts)
    ref = quad(lambda t: float(np.linalg.norm(cs(t, 1))), 0, tau[-1], points=tau[1:-1],
               epsabs=1e-13, epsrel=1e-13)[0]
    assert p.length == pytest.approx(ref, abs=1e-6)
    s = np.linspace(0, p.length, 401)
    speed = np.linalg.norm(np.diff(p.point(s), axis=0), axis=1) / np.diff(s)
    assert speed == pytest.approx(1.0, abs=1e-4)  # chord/arc ratio over a 2.5 cm step


def _de_boor(k, t, c, x):
    """Independent de Boor evaluation of a B-spline (for the NURBS test)."""
    j = np.searchsorted(t, x, side="right") - 1
    j = min(max(j, k), len(c) - 1)
    d = [c[j + r - k].copy() for r in range(k + 1)]
    for r in range(1, k + 1):
        for i in range(k, r - 1, -1):
            alpha = (x - t[i + j - k]) / (t[i + 1 + j - r] - t[i + j - k])
            d[i] = (1 - alpha) * d[i - 1] + alpha * d[i]
    return d[k]


def test_nurbs_points_equal_independent_de_boor():
    k, knots = 3, np.array([0, 0, 0, 0, 0.4, 0.7, 1, 1, 1, 1], dtype=float)
    ctrl = np.array([[0, 0], [3, 0], [6, 0.5], [8, 2.5], [9, 5], [9, 8]], dtype=float)
    w = np.array([1, 1, 1.2, 1, 1, 1.0])
    p = Path.from_nurbs(k, knots, ctrl, w)
    piece = p.pieces[0]
    for u in np.linspace(0, p.length, 13):
        tau = float(piece.parameter(np.array([u]))[0])
        h = _de_boor(k, knots, np.column_stack((ctrl * w[:, None], w)), min(tau, 1 - 1e-15))
        assert p.point(u) == pytest.approx(h[:2] / h[2], abs=1e-9)
    assert p.point(0.0) == pytest.approx([0, 0]) and p.point(p.length) == pytest.approx([9, 8])


@settings(max_examples=25, deadline=None)
@given(
    pts=st.lists(st.tuples(st.floats(-50, 50), st.floats(-50, 50)), min_size=2, max_size=6),
    kind=st.sampled_from(["clothoid", "spline", "polyline"]),
    n=st.integers(2, 300),
)
def test_properties_resample_unit_speed_and_reversal(pts, kind, n):
    xy = np.array(pts)
    legs = np.linalg.norm(np.diff(xy, axis=0), axis=1)
    if (legs < 1.0).any():
        return
    turns = np.diff(np.unwrap(np.arctan2(np.diff(xy[:, 1]), np.diff(xy[:, 0]))))
    if (np.abs(turns) > 2.5).any():
        return
    try:
        p = Path.from_waypoints(xy, kind=kind)
    except InvalidInputError:
        return  # e.g. no clothoid with those headings: rejected with a clear message
    samples = p.resample(n=n)
    assert samples.s[0] == 0 and samples.s[-1] == pytest.approx(p.length)
    assert samples.xy[0] == pytest.approx(xy[0], abs=1e-9)
    assert samples.xy[-1] == pytest.approx(xy[-1], abs=1e-8)
    s = np.linspace(0, p.length, 200)
    h = 1e-4 * p.length
    fd = np.linalg.norm(p.point(np.clip(s + h, 0, p.length)) - p.point(np.clip(s - h, 0, p.length)),
                        axis=1) / (np.clip(s + h, 0, p.length) - np.clip(s - h, 0, p.length))
    assert fd == pytest.approx(1.0, abs=1e-4)
    r = p.reversed()
    assert r.length == pytest.approx(p.length)
    assert r.curvature(s) == pytest.approx(-p.curvature(p.length - s), abs=1e-9)
    assert r.point(0.0) == pytest.approx(p.point(p.length), abs=1e-9)


def test_speed_bounds_line_arc_and_zone():
    R = 0.5
    p = Path.from_segments([Line(10.0), Arc(R, np.pi / 2), Line(10.0)])
    w = speed_bounds(p, LIM, [5.0, 10.0 + R, 15.0])
    assert w == pytest.approx([4.0, 1.0 * R, 4.0])
    zone = SpeedZone(shapely.box(3.0, -1.0, 6.0, 1.0), v_max=0.5)
    w = speed_bounds(p, LIM, [2.9, 3.0, 4.5, 6.0, 6.1], zones=[zone])
    assert w == pytest.approx([4.0, 0.25, 0.25, 0.25, 4.0])
    (a, b, v), = zone_intervals(p, [zone])
    assert (a, b, v) == (pytest.approx(3.0, abs=1e-6), pytest.approx(6.0, abs=1e-6), 0.5)
    w = speed_bounds(p, LIM, [0.0, 5.0], v_limit=([0.0, 10.0], [1.0, 0.5]))
    assert w == pytest.approx([1.0, 0.75**2])


def test_linestring_round_trip():
    ls = shapely.LineString([(0, 0), (4, 0), (4, 3)])
    p = Path.from_linestring(ls)
    assert p.point(0.0) == pytest.approx([0, 0]) and p.point(p.length) == pytest.approx([4, 3])
    back = p.to_linestring(ds=0.01)
    assert back.length == pytest.approx(p.length, rel=1e-4)


@pytest.mark.parametrize(
    ("call", "name"),
    [
        (lambda: Path.from_waypoints([[0, 0], [np.nan, 1]]), "xy"),
        (lambda: Path.from_waypoints([[0, 0]]), "xy"),
        (lambda: Path.from_waypoints([[1, 1], [1, 1]]), "xy"),
        (lambda: Path.from_waypoints([[0, 0], [1, 0], [1, 0], [2, 0]]), "xy"),
        (lambda: Path.from_waypoints(np.zeros((3, 3))), "xy"),
        (lambda: Path.from_waypoints([[0, 0], [1, 0]], kind="bezier"), "kind"),
        (lambda: Path.from_waypoints([[0, 0], [2, 0], [0, 0]], kind="polyline"), "xy"),
        (lambda: Path.from_segments([Line(-1.0)]), "segments[0].length"),
        (lambda: Path.from_segments([Arc(-2.0, 1.0)]), "segments[0].radius"),
        (lambda: Path.from_segments([{"type": "spiral", "length": 1}]), "segments[0]"),
        (lambda: Path.from_segments([]), "segments"),
        (lambda: Path.from_nurbs(2, [0, 0, 1, 0.5, 1, 1], [[0, 0], [1, 1], [2, 0]]), "knots"),
        (lambda: Path.from_nurbs(2, [0, 0, 0, 1, 1, 1], [[0, 0], [1, 1], [2, 0]], [1, -1, 1]),
         "weights"),
        (lambda: Path.from_segments([Line(1.0)]).point(np.nan), "s"),
    ],
)
def test_bad_input_names_the_argument(call, name):
    with pytest.raises(InvalidInputError, match=re.escape(f"`{name}")):
        call()
