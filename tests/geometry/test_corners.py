"""G2 corner paths (kind="g2"): geometry against independent oracles, over six decades of scale.

Oracles: scipy's Fresnel integrals for the corner shape, shapely distances on densely sampled
points for the deviation from the waypoints and their polyline, finite differences of the
positions for tangents, hand-derived headings.
"""

from __future__ import annotations

import numpy as np
import pytest
import shapely
from hypothesis import given, settings
from hypothesis import strategies as st
from scipy.special import fresnel
from shared import examples

from speedplan import InvalidInputError, Path
from speedplan.geometry.corners import (
    CUSP_ANGLE,
    DEFAULT_DEVIATION,
    DEFAULT_TRANSITION,
    corner_shape,
)

SETTINGS = settings(max_examples=examples(40), deadline=None)


def wrapped(a):
    return np.angle(np.exp(1j * np.asarray(a, dtype=float)))


def turns_of(pts):
    d = np.diff(pts, axis=0)
    return wrapped(np.diff(np.arctan2(d[:, 1], d[:, 0])))


def polyline_from(heading0, legs, turns, scale):
    """Waypoints from leg lengths and turns (so the turns are drawn, not filtered)."""
    head = heading0 + np.concatenate(([0.0], np.cumsum(turns)))
    steps = scale * np.asarray(legs)[:, None] * np.column_stack((np.cos(head), np.sin(head)))
    return np.vstack(([0.0, 0.0], np.cumsum(steps, axis=0)))


def piece_ends(p, attr):
    """Values of ``attr`` at the end of each piece and at the start of the next one."""
    left = np.array([getattr(a, attr)(np.array(a.length)) for a in p.pieces[:-1]])
    right = np.array([getattr(b, attr)(np.array(0.0)) for b in p.pieces[1:]])
    return left, right


def corner_spans(p):
    """``(s_start, s_end)`` of each corner: a run of curved pieces that starts with κ = 0."""
    spans, start = [], None
    for k, piece in enumerate(p.pieces):
        curved = piece.k0 != 0.0 or piece.k1 != 0.0
        if start is not None and (not curved or piece.k0 == 0.0):
            spans.append((start, p.offsets[k]))
            start = None
        if curved and piece.k0 == 0.0:
            start = p.offsets[k]
    if start is not None:
        spans.append((start, p.offsets[-1]))
    return spans


def dense(p, a, b, m=2001):
    return p.point(np.linspace(a, b, m))


def check_g2(p, pts, max_dev):
    """Every property of a G2 corner path through ``pts`` without cusps."""
    scale = float(np.ptp(pts, axis=0).max())
    tol = 1e-9 * scale
    legs = np.linalg.norm(np.diff(pts, axis=0), axis=1)
    turns = turns_of(pts)
    # Exactly through the first and last waypoints, along the legs, curvature 0 there.
    np.testing.assert_allclose(p.point([0.0, p.length]), pts[[0, -1]], rtol=0, atol=1e-12 * scale)
    d0, d1 = np.diff(pts[:2], axis=0)[0], np.diff(pts[-2:], axis=0)[0]
    assert abs(wrapped(p.heading(0.0) - np.arctan2(d0[1], d0[0]))) < 1e-12
    assert abs(wrapped(p.heading(p.length) - np.arctan2(d1[1], d1[0]))) < 1e-9
    assert p.curvature(0.0) == 0.0 and p.pieces[-1].curvature(np.array(p.pieces[-1].length)) == 0
    assert (p.direction(np.linspace(0, p.length, 50)) == 1).all() and p.cusps.size == 0
    # Continuous position, heading and curvature at every join (to rounding).
    kmax = max(max(abs(q.k0), abs(q.k1)) for q in p.pieces)
    for attr, atol in (("point", 1e-12 * scale), ("heading", 1e-9), ("curvature", 1e-9 * kmax)):
        left, right = piece_ends(p, attr)
        np.testing.assert_allclose(left, right, rtol=0, atol=atol, err_msg=attr)
    # Within max_deviation of the polyline everywhere (shapely on dense samples of each piece).
    line = shapely.LineString(pts)
    xy = np.vstack([dense(p, a, b, 201) for a, b in zip(p.offsets[:-1], p.offsets[1:],
                                                         strict=True)])
    assert shapely.distance(shapely.points(xy), line).max() <= max_dev + tol
    # Corners: one per turning waypoint, tangent to both legs, within their share of the legs.
    turning = [i + 1 for i, t in enumerate(turns) if abs(t) > 1e-12]
    spans = corner_spans(p)
    assert len(spans) == len(turning)
    used_after = np.zeros(len(pts))  # tangent length each corner takes on the leg after it
    used_before = np.zeros(len(pts))
    for (a, b), i in zip(spans, turning, strict=True):
        pa, pb = p.point(a), p.point(b)
        ta, tb = p.heading(a), p.heading(b) if b < p.length else p.heading(p.length)
        u_in, u_out = pts[i] - pts[i - 1], pts[i + 1] - pts[i]
        assert abs(wrapped(ta - np.arctan2(u_in[1], u_in[0]))) < 1e-9
        assert abs(wrapped(tb - np.arctan2(u_out[1], u_out[0]))) < 1e-9
        assert shapely.distance(shapely.Point(pa), shapely.LineString(pts[i - 1:i + 1])) <= tol
        assert shapely.distance(shapely.Point(pb), shapely.LineString(pts[i:i + 2])) <= tol
        used_before[i], used_after[i] = np.linalg.norm(pa - pts[i]), np.linalg.norm(pb - pts[i])
        assert used_before[i] == pytest.approx(used_after[i], rel=1e-9, abs=tol)  # symmetric
        k = p.curvature(np.linspace(a, b, 101)[1:-1])
        assert (np.sign(k) == np.sign(turns[i - 1])).all()
        # The waypoint is at most max_deviation from the path; exactly that unless the corner
        # was reduced for room (then it takes at least half of a leg, or a whole end leg).
        dev = shapely.distance(shapely.Point(pts[i]), shapely.LineString(dense(p, a, b)))
        assert dev <= max_dev * (1 + 1e-6) + tol
        room_limited = used_before[i] >= 0.5 * min(legs[i - 1], legs[i]) * (1 - 1e-9)
        assert room_limited or dev == pytest.approx(max_dev, rel=1e-6)
    # No two corners overlap on a leg.
    assert (used_after[:-1] + used_before[1:] <= legs * (1 + 1e-12) + tol).all()


# ---- the corner shape against scipy's Fresnel integrals ----------------------------------------
def fresnel_corner(turn, f):
    """Deviation and tangent length of a unit-radius clothoid–arc–clothoid corner."""
    lc = f * turn  # each clothoid turns f*turn/2 = lc / 2 at radius 1
    a = np.sqrt(np.pi * lc)
    S, C = fresnel(lc / a)
    x1, y1 = a * C, a * S
    th = lc / 2
    cx, cy = x1 - np.sin(th), y1 + np.cos(th)  # arc centre
    mx, my = cx + np.sin(turn / 2), cy - np.cos(turn / 2)  # midpoint, heading turn/2
    return my / np.cos(turn / 2), mx + my * np.tan(turn / 2)


@pytest.mark.parametrize("turn_deg", [0.5, 10, 45, 90, 120, 149.9])
@pytest.mark.parametrize("f", [0.05, DEFAULT_TRANSITION, 1.0])
def test_corner_shape_matches_fresnel_integrals(turn_deg, f):
    turn = np.radians(turn_deg)
    shape = corner_shape(turn, f)
    dev, tangent = fresnel_corner(turn, f)
    assert shape.deviation == pytest.approx(dev, rel=1e-12)
    assert shape.tangent == pytest.approx(tangent, rel=1e-12)


def test_right_angle_corner_has_the_largest_radius_the_deviation_allows():
    p = Path.from_waypoints([[0, 0], [10, 0], [10, 10]])
    dev, tangent = fresnel_corner(np.pi / 2, DEFAULT_TRANSITION)
    R = DEFAULT_DEVIATION / dev
    assert np.abs(p.curvature(np.linspace(0, p.length, 5001))).max() == pytest.approx(1 / R,
                                                                                       rel=1e-12)
    assert p.pieces[0].length == pytest.approx(10 - R * tangent, rel=1e-12)
    corner = p.to_linestring(ds=1e-4).distance(shapely.Point(10, 0))
    assert corner == pytest.approx(DEFAULT_DEVIATION, rel=1e-7)
    # Shapes: transition=1 is a clothoid pair (no arc), the default has an arc in the middle.
    pair = Path.from_waypoints([[0, 0], [10, 0], [10, 10]], transition=1.0)
    assert [q.k0 == q.k1 for q in pair.pieces] == [True, False, False, True]
    assert [q.k0 == q.k1 for q in p.pieces] == [True, False, True, False, True]


# ---- properties over six decades of scale -------------------------------------------------------
@st.composite
def corner_waypoints(draw, max_turn=CUSP_ANGLE - 0.01):
    n = draw(st.integers(2, 7))
    scale = 10.0 ** draw(st.floats(-2.5, 3.0))  # legs from ~1 mm to ~3 km
    legs = draw(st.lists(st.floats(0.3, 3.0), min_size=n - 1, max_size=n - 1))
    turn = st.one_of(st.floats(-max_turn, max_turn),
                     st.sampled_from([0.0, 1e-13, -1e-9, 1e-6, max_turn, -max_turn]))
    turns = draw(st.lists(turn, min_size=n - 2, max_size=n - 2))
    pts = polyline_from(draw(st.floats(-np.pi, np.pi)), legs, turns, scale)
    dev = draw(st.one_of(st.none(), st.floats(1e-3, 3.0).map(lambda x: x * scale)))
    f = draw(st.one_of(st.none(), st.floats(0.01, 1.0)))
    return pts, dev, f


@SETTINGS
@given(case=corner_waypoints())
def test_g2_paths_are_curvature_continuous_tangent_and_within_the_deviation(case):
    pts, dev, f = case
    p = Path.from_waypoints(pts, max_deviation=dev, transition=f)
    check_g2(p, pts, DEFAULT_DEVIATION if dev is None else dev)


@SETTINGS
@given(case=corner_waypoints())
def test_g2_path_in_reverse_order_is_the_mirror_image(case):
    pts, dev, f = case
    p = Path.from_waypoints(pts, max_deviation=dev, transition=f)
    q = Path.from_waypoints(pts[::-1], max_deviation=dev, transition=f)
    scale = float(np.ptp(pts, axis=0).max())
    assert q.length == pytest.approx(p.length, rel=1e-12)
    s = np.linspace(0, p.length, 301)
    np.testing.assert_allclose(q.point(p.length - s), p.point(s), rtol=0, atol=1e-9 * scale)


# ---- cusps --------------------------------------------------------------------------------------
def test_straight_reversal_stops_at_the_waypoint_and_backs_out():
    p = Path.from_waypoints([[0, 0], [10, 0], [5, 0]])
    assert p.length == pytest.approx(15.0, rel=1e-15)
    assert p.cusps.tolist() == [10.0]
    assert p.direction([0.0, 9.0, 10.0, 15.0]).tolist() == [1, 1, -1, -1]
    np.testing.assert_array_equal(p.point([10.0, 12.0]), [[10.0, 0.0], [8.0, 0.0]])
    assert (p.heading(np.linspace(0, 15, 31)) == 0.0).all()  # faces +x while backing up
    assert [q.length for q in p.split_at_cusps()] == [10.0, 5.0]
    assert [int(q.direction(0.0)) for q in p.split_at_cusps()] == [1, -1]


@st.composite
def cusp_waypoints(draw):
    scale = 10.0 ** draw(st.floats(-2.5, 3.0))
    n = draw(st.integers(3, 6))
    legs = draw(st.lists(st.floats(0.3, 3.0), min_size=n - 1, max_size=n - 1))
    back = st.floats(CUSP_ANGLE + 1e-3, np.pi)
    sign = st.sampled_from([-1.0, 1.0])
    turns = [draw(back) * draw(sign)]
    turns += draw(st.lists(st.one_of(st.floats(-2.5, 2.5), back), min_size=n - 3,
                           max_size=n - 3))
    order = draw(st.permutations(range(n - 2)))
    turns = [turns[i] for i in order]
    pts = polyline_from(draw(st.floats(-np.pi, np.pi)), legs, turns, scale)
    dev = draw(st.one_of(st.none(), st.floats(1e-3, 1.0).map(lambda x: x * scale)))
    return pts, dev


@SETTINGS
@given(case=cusp_waypoints())
def test_cusps_flip_the_tangent_keep_the_heading_and_stay_near_the_waypoint(case):
    pts, dev = case
    max_dev = DEFAULT_DEVIATION if dev is None else dev
    p = Path.from_waypoints(pts, max_deviation=dev)
    scale = float(np.ptp(pts, axis=0).max())
    turns = turns_of(pts)
    rows = [i + 1 for i, t in enumerate(turns) if abs(t) > CUSP_ANGLE]
    assert p.cusps.size == len(rows)
    np.testing.assert_allclose(p.point([0.0, p.length]), pts[[0, -1]], rtol=0, atol=1e-9 * scale)
    # Directions alternate, starting forward.
    parts = p.split_at_cusps()
    assert [int(q.direction(0.0)) for q in parts] == [(-1) ** k for k in range(len(rows) + 1)]
    assert sum(q.length for q in parts) == pytest.approx(p.length, rel=1e-12)
    # Vehicle heading and curvature continuous at every join, cusps included.
    kmax = max(max(abs(q.k0), abs(q.k1)) for q in p.pieces)
    for attr, atol in (("point", 1e-9 * scale), ("heading", 1e-9), ("curvature", 1e-9 * kmax)):
        left, right = piece_ends(p, attr)
        np.testing.assert_allclose(left, right, rtol=0, atol=atol, err_msg=attr)
    for c, i in zip(p.cusps, rows, strict=True):
        assert p.curvature(c) == 0.0
        # The stop is within max_deviation of its waypoint.
        assert np.linalg.norm(p.point(c) - pts[i]) <= max_dev * (1 + 1e-9) + 1e-12 * scale
        # Finite differences: the travel tangent flips by π there.
        h = 1e-6 * min(max_dev, scale)
        before = p.point(c) - p.point(c - h)
        after = p.point(c + h) - p.point(c)
        cos = before @ after / (np.linalg.norm(before) * np.linalg.norm(after))
        assert cos < -1 + 1e-6
    # The vehicle heading is the travel tangent (finite differences), turned by π in reverse.
    h = 1e-7 * p.length
    s = np.linspace(2 * h, p.length - 2 * h, 400)
    s = s[np.abs(s[:, None] - p.cusps[None, :]).min(axis=1, initial=np.inf) > 4 * h]
    travel = (p.point(s + h) - p.point(s - h)) / (2 * h)
    facing = p.direction(s)[:, None] * np.column_stack((np.cos(p.heading(s)), np.sin(p.heading(s))))
    np.testing.assert_allclose(travel, facing, atol=1e-5)
    # Within max_deviation of the polyline.
    xy = p.point(np.linspace(0, p.length, 20001))
    assert shapely.distance(shapely.points(xy), shapely.LineString(pts)).max() <= (
        max_dev + 1e-9 * scale)


def test_cusp_threshold_is_150_degrees():
    for deg, cusps in ((149.9, 0), (150.1, 1), (180.0, 1)):
        a = np.radians(deg)
        p = Path.from_waypoints([[0, 0], [10, 0], [10 + 5 * np.cos(a), 5 * np.sin(a)]])
        assert p.cusps.size == cusps, deg


def test_angled_cusp_stops_beyond_the_waypoint_on_the_bisector():
    # 160° left: the heading must turn by -20°; the stop lies beyond (10, 0), between the
    # extensions of the two legs, at most max_deviation away.
    a = np.radians(160)
    pts = [[0, 0], [10, 0], [10 + 6 * np.cos(a), 6 * np.sin(a)]]
    p = Path.from_waypoints(pts, max_deviation=0.2)
    q = p.point(p.cusps[0])
    assert np.linalg.norm(q - [10, 0]) == pytest.approx(0.2, rel=1e-12)
    bisector = np.radians(-10)  # halfway between 0 and 160° - 180°
    assert np.arctan2(q[1], q[0] - 10) == pytest.approx(bisector, rel=1e-9)
    assert float(p.heading(p.length)) == pytest.approx(np.radians(-20), abs=1e-12)


def test_several_cusps_and_reversed_paths():
    p = Path.from_waypoints([[0, 0], [10, 0], [5, 0], [12, 0]])
    assert p.cusps.tolist() == [10.0, 15.0] and p.length == 22.0
    assert [int(q.direction(0.0)) for q in p.split_at_cusps()] == [1, -1, 1]
    s = np.linspace(0, p.length, 45)
    # Default reversal: same gear per piece, vehicle turned round.
    r = p.reversed()
    np.testing.assert_allclose(r.point(s), p.point(p.length - s), atol=1e-12)
    np.testing.assert_array_equal(np.sort(r.cusps), np.sort(p.length - p.cusps))
    inner = s[np.abs(s[:, None] - r.cusps[None, :]).min(axis=1) > 1e-9]
    np.testing.assert_array_equal(r.direction(inner), p.direction(p.length - inner))
    np.testing.assert_allclose(r.heading(s), p.heading(p.length - s) + np.pi, atol=1e-12)
    # swap_direction: the poses retraced backwards, gears swapped.
    b = p.reversed(swap_direction=True)
    np.testing.assert_array_equal(b.direction(inner), -p.direction(p.length - inner))
    np.testing.assert_allclose(b.heading(s), p.heading(p.length - s), atol=1e-12)
    np.testing.assert_allclose(b.curvature(s), -p.curvature(p.length - s), atol=1e-12)
    twice = b.reversed(swap_direction=True)
    np.testing.assert_array_equal(twice.point(s), p.point(s))
    np.testing.assert_array_equal(twice.direction(s), p.direction(s))


# ---- reverse segments ---------------------------------------------------------------------------
def test_reverse_arc_after_a_line_is_a_cusp_with_the_expected_geometry():
    # Backing up from (2, 0) facing +x, travelling -x and turning left (as travelled): the
    # centre is left of the travel direction, at (2, -1); a quarter turn ends at (1, -1),
    # the vehicle then faces +y (heading 0 + π/2) while travelling -y.
    p = Path.from_segments([{"type": "line", "length": 2.0},
                            {"type": "arc", "radius": 1.0, "angle": np.pi / 2, "reverse": True}])
    assert p.cusps.tolist() == [2.0]
    np.testing.assert_allclose(p.point(p.length), [1.0, -1.0], atol=1e-12)
    assert float(p.heading(p.length)) == pytest.approx(np.pi / 2, abs=1e-12)
    assert float(p.heading(2.0)) == 0.0  # unchanged through the cusp
    s = np.linspace(2.0, p.length, 9)
    np.testing.assert_allclose(np.linalg.norm(p.point(s) - [2.0, -1.0], axis=1), 1.0, rtol=1e-12)
    np.testing.assert_allclose(p.curvature(s[1:-1]), 1.0, rtol=1e-12)


def test_samples_carry_the_direction_and_queries_are_vectorised():
    p = Path.from_waypoints([[0, 0], [10, 0], [4, 0]])
    smp = p.resample(n=17)
    np.testing.assert_array_equal(smp.direction, p.direction(smp.s))
    assert p.direction(np.zeros((2, 3))).shape == (2, 3)
    assert p.direction(3.0).shape == ()
    assert Path.from_waypoints([[0, 0], [1, 0]]).cusps.shape == (0,)


def test_reverse_flag_is_validated():
    from speedplan.geometry import Line

    with pytest.raises(InvalidInputError, match=r"`segments\[0\]\.reverse`"):
        Path.from_segments([{"type": "line", "length": 1, "reverse": "yes"}])
    with pytest.raises(InvalidInputError, match="`reverse`"):
        Line(1.0, reverse=1)  # type: ignore[arg-type]


# ---- refusals and options ------------------------------------------------------------------------
@pytest.mark.parametrize("kind", ["clothoid", "spline", "polyline"])
@pytest.mark.parametrize("pts", [[[0, 0], [10, 0], [0, 0]], [[0, 0], [10, 0], [5, 0]],
                                 [[0, 0], [4, 4], [10, 0], [4, 1.5]]])
def test_kinds_that_cannot_reverse_refuse_with_the_row(kind, pts):
    row = len(pts) - 2
    with pytest.raises(InvalidInputError,
                       match=rf"`xy` reverses direction at row {row} .*kind='g2' \(the default\)"):
        Path.from_waypoints(pts, kind=kind)
    with pytest.raises(InvalidInputError, match=rf"`ls` reverses direction at row {row}"):
        Path.from_linestring(shapely.LineString(pts), kind=kind)


@pytest.mark.parametrize(
    ("kwargs", "message"),
    [
        ({"headings": [0, 0, 0]}, r"`headings` applies to kind='clothoid' only; got kind='g2'"),
        ({"corner_radius": 1.0}, r"`corner_radius` applies to kind='polyline' only"),
        ({"kind": "clothoid", "transition": 0.5}, r"`transition` applies to kind='g2' only"),
        ({"kind": "spline", "max_deviation": 0.5},
         r"`max_deviation` applies to kind='g2' and kind='polyline' only"),
        ({"transition": 0.0}, r"`transition` must be > 0"),
        ({"transition": 1.5}, r"`transition` is the share .* in \(0, 1\]"),
        ({"transition": np.nan}, r"`transition`"),
        ({"max_deviation": 0.0}, r"`max_deviation`=0 keeps sharp corners"),
        ({"max_deviation": -1.0}, r"`max_deviation` must be >= 0"),
        ({"kind": "g1"}, r"`kind` must be one of 'g2', 'clothoid', 'spline', 'polyline'"),
    ],
)
def test_options_are_validated_per_kind(kwargs, message):
    with pytest.raises(InvalidInputError, match=message):
        Path.from_waypoints([[0, 0], [5, 0], [5, 5]], **kwargs)


def test_infinite_deviation_rounds_as_much_as_the_legs_allow():
    pts = np.array([[0, 0], [10, 0], [10, 4]], float)
    p = Path.from_waypoints(pts, max_deviation=np.inf)
    check_g2(p, pts, np.inf)
    # The corner is symmetric: it takes all of the 4 m leg, hence 4 m of the 10 m one.
    assert p.pieces[0].length == pytest.approx(6.0, rel=1e-15)
    assert p.pieces[-1].k1 == 0.0 and p.pieces[-1].k0 != 0.0  # no straight left on the last leg


# ---- files --------------------------------------------------------------------------------------
def test_reverse_pieces_round_trip_through_json_documents():
    from speedplan.io import path_from_dict, path_to_dict

    p = Path.from_waypoints([[0, 0], [10, 0], [3, 1], [8, 4]])
    for path in (p, p.reversed(), p.reversed(swap_direction=True)):
        doc = path_to_dict(path)
        flags = [seg.get("reverse", False) for seg in doc["segments"]]
        assert flags == [q.direction < 0 for q in path.pieces]
        back = path_from_dict(doc)
        s = np.linspace(0, path.length, 301)
        np.testing.assert_allclose(back.point(s), path.point(s), rtol=0, atol=1e-12)
        np.testing.assert_allclose(back.heading(s), path.heading(s), rtol=0, atol=1e-12)
        np.testing.assert_array_equal(back.direction(s), path.direction(s))
        np.testing.assert_allclose(back.cusps, path.cusps, rtol=1e-15)


def test_profile_from_waypoints_takes_the_path_options():
    import speedplan as sp

    limits = {"v_max": 2.0, "a_max": 1.0, "a_lat_max": 1.0, "j_max": 0.5}
    pts = [[0, 0], [8, 0], [8, 6]]
    traj = sp.profile_from_waypoints(pts, max_deviation=0.1, dt=0.05, **limits)
    xy = np.column_stack((traj.x, traj.y))
    assert shapely.distance(shapely.points(xy), shapely.LineString(pts)).max() <= 0.1 + 1e-9
    assert shapely.Point(8, 0).distance(shapely.LineString(xy)) > 0.05  # the corner is cut
    with pytest.raises(InvalidInputError, match="`max_deviation` applies to"):
        sp.profile_from_waypoints(pts, kind="spline", max_deviation=0.1, **limits)
    with pytest.raises(InvalidInputError, match="`headings` applies to kind='clothoid'"):
        sp.profile_from_waypoints(pts, headings=[0, 0.7, 1.5], **limits)


@pytest.mark.parametrize("pts", [
    [[0, 0], [10, 0], [10, 10], [0, 10], [0, 20]],
    [[0, 0], [10, 0], [4, 0], [4, 5], [0, 9], [3, 20], [3, 10]],  # two cusps
    (np.random.default_rng(3).uniform(0, 1e3, (25, 2))).tolist(),
    (np.random.default_rng(4).uniform(0, 1e-2, (25, 2))).tolist(),
])
def test_pieces_built_in_one_pass_equal_pieces_built_one_by_one(pts):
    # g2_chain tabulates all pieces at once (clothoid_chain); each must be the piece its
    # own constructor builds, and each corner piece must start where the previous one ends.
    from speedplan.geometry.primitives import ClothoidPiece

    pieces = Path.from_waypoints(pts, max_deviation=float(np.ptp(pts)) / 50).pieces
    for before, p in zip((None, *pieces[:-1]), pieces, strict=True):
        alone = ClothoidPiece(p.start, p.theta0, p.length, p.k0, p.k1, p.direction)
        np.testing.assert_array_equal(p._knots, alone._knots)
        np.testing.assert_allclose(p._knot_xy, alone._knot_xy, rtol=0,
                                   atol=1e-15 * max(1.0, float(np.abs(alone._knot_xy).max())))
        if before is not None:
            end, heading = before.end
            assert np.linalg.norm(end - np.asarray(p.start)) <= 1e-12 * max(1.0, np.ptp(pts))
            if p.direction == before.direction:
                assert abs(heading - p.theta0) <= 1e-12
