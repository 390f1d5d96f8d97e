"""Geometry layer, primitives and Path: closed forms, G1 joints, domain, pickling."""

from __future__ import annotations

import pickle

import numpy as np
import pytest
import shapely
from scipy.integrate import quad
from scipy.special import fresnel

from speedplan import InvalidInputError, Path
from speedplan.geometry import Arc, Clothoid, Line, PathSamples

TWO_PI = 2 * np.pi


def clothoid_end_by_quad(theta0, length, k0, k1):
    """Independent end point: adaptive quadrature of cos/sin of the quadratic heading."""
    c = (k1 - k0) / length

    def theta(u):
        return theta0 + k0 * u + 0.5 * c * u * u

    opts = {"epsabs": 1e-11, "epsrel": 1e-12, "limit": 1000}
    x = quad(lambda u: np.cos(theta(u)), 0, length, **opts)[0]
    y = quad(lambda u: np.sin(theta(u)), 0, length, **opts)[0]
    return np.array([x, y])


def test_line_is_exact():
    p = Path.from_segments([Line(7.5)], start=(1.0, -2.0), heading=np.pi / 6)
    s = np.linspace(0, 7.5, 11)
    expected = np.array([1.0, -2.0]) + s[:, None] * [np.cos(np.pi / 6), np.sin(np.pi / 6)]
    assert p.length == 7.5
    np.testing.assert_allclose(p.point(s), expected, rtol=0, atol=1e-14)
    assert (p.curvature(s) == 0).all() and np.allclose(p.heading(s), np.pi / 6, atol=0)


@pytest.mark.parametrize(("R", "angle"), [(3.0, 2.0), (0.4, -5.5), (150.0, 0.01), (2.5, TWO_PI)])
def test_arc_length_curvature_and_points_match_the_circle(R, angle):
    p = Path.from_segments([Arc(R, angle)], start=(1.0, 2.0), heading=0.3)
    assert p.length == pytest.approx(R * abs(angle), rel=1e-12)
    s = np.linspace(0, p.length, 57)
    np.testing.assert_allclose(p.curvature(s), np.sign(angle) / R, rtol=1e-12)
    np.testing.assert_allclose(p.heading(s), 0.3 + np.sign(angle) * s / R, atol=1e-12)
    # Every point lies on the circle through the start whose centre is R to the turning side.
    normal = np.sign(angle) * np.array([-np.sin(0.3), np.cos(0.3)])
    centre = np.array([1.0, 2.0]) + R * normal
    radius = np.linalg.norm(p.point(s) - centre, axis=1)
    np.testing.assert_allclose(radius, R, rtol=1e-12)
    phi = 0.3 + angle - np.sign(angle) * np.pi / 2
    end = centre + R * np.array([np.cos(phi), np.sin(phi)])
    np.testing.assert_allclose(p.point(p.length), end, atol=1e-11 * max(R, 1))


@pytest.mark.parametrize(
    ("theta0", "length", "k0", "k1"),
    [
        (0.0, 4.0, 0.0, 0.5),         # standard clothoid
        (1.0, 6.0, 1 / 3, -0.2),      # k0 != 0, sign change
        (-2.0, 10.0, 0.0, 5.0),       # tight: turns 25 rad
        (0.5, 20.0, 0.1, 0.1 + 1e-13),  # near-zero sharpness: an arc to rounding
        (0.0, 80.0, -0.01, 0.002),    # long and gentle, road-like
    ],
)
def test_clothoid_matches_independent_quadrature(theta0, length, k0, k1):
    p = Path.from_segments([Clothoid(length, k0, k1)], heading=theta0)
    assert p.length == pytest.approx(length, rel=1e-12)
    s = np.linspace(0, length, 41)
    np.testing.assert_allclose(p.curvature(s), k0 + (k1 - k0) * s / length, atol=1e-12)
    np.testing.assert_allclose(
        p.heading(s), theta0 + k0 * s + 0.5 * (k1 - k0) / length * s**2, atol=1e-12
    )
    end = clothoid_end_by_quad(theta0, length, k0, k1)
    np.testing.assert_allclose(p.point(length), end, rtol=0, atol=1e-9 * length)
    mid = clothoid_end_by_quad(theta0, length / 3, k0, k0 + (k1 - k0) / 3)
    np.testing.assert_allclose(p.point(length / 3), mid, rtol=0, atol=1e-9 * length)


def test_standard_clothoid_equals_scipy_fresnel_closed_form():
    c = 0.7  # sharpness [1/m²]: heading c s² / 2
    L = 5.0
    p = Path.from_segments([Clothoid(L, 0.0, c * L)])
    s = np.linspace(0, L, 23)
    S, C = fresnel(s * np.sqrt(c / np.pi))
    expected = np.sqrt(np.pi / c) * np.column_stack((C, S))
    np.testing.assert_allclose(p.point(s), expected, rtol=0, atol=1e-12)


def test_segments_are_g1_and_lengths_add_up():
    segs = [Line(1.0), Clothoid(2.0, 0.0, 0.5), Arc(2.0, 1.0), Clothoid(2.0, 0.5, -0.3),
            Arc(4.0, -0.7), Line(3.0)]
    p = Path.from_segments(segs, start=(3, 4), heading=-1.0)
    assert p.length == pytest.approx(1 + 2 + 2 + 2 + 4 * 0.7 + 3, rel=1e-12)
    joints = p.offsets[1:-1]
    eps = 1e-10
    jump_heading = p.heading(joints + eps) - p.heading(joints - eps)
    jump_point = np.linalg.norm(p.point(joints + eps) - p.point(joints - eps), axis=1)
    assert np.abs(jump_heading).max() < 1e-9
    assert jump_point.max() < 1e-9
    # Each piece's start pose equals the previous piece's end pose exactly (by construction).
    for prev, nxt in zip(p.pieces[:-1], p.pieces[1:], strict=True):
        end, theta = prev.end
        assert np.allclose(nxt.start, end, rtol=0, atol=1e-12) and nxt.theta0 == theta


def test_dict_segments_equal_dataclass_segments():
    a = Path.from_segments([Line(2.0), Arc(1.5, -1.0), Clothoid(3.0, 0.2, 0.0)])
    b = Path.from_segments([{"type": "line", "length": 2.0},
                            {"type": "arc", "radius": 1.5, "angle": -1.0},
                            {"type": "clothoid", "length": 3.0, "k0": 0.2, "k1": 0.0}])
    s = np.linspace(0, a.length, 50)
    np.testing.assert_array_equal(a.point(s), b.point(s))


def test_heading_is_continuous_beyond_pi_and_closed_loops_are_detected():
    circle = Path.from_segments([Arc(2.0, TWO_PI)])
    s = np.linspace(0, circle.length, 1001)
    assert (np.diff(circle.heading(s)) > 0).all()
    assert circle.heading(circle.length) == pytest.approx(TWO_PI, abs=1e-12)
    assert circle.is_closed
    assert not Path.from_segments([Arc(2.0, np.pi)]).is_closed


def test_out_of_range_s_raises_but_rounding_is_clipped():
    p = Path.from_segments([Line(10.0)])
    assert p.point(10.0 + 1e-9).tolist() == [10.0, 0.0]  # 1e-10 * length: rounding, clipped
    assert p.point(-5e-9).tolist() == [0.0, 0.0]
    for bad in (10.001, -0.001, [0.0, 11.0]):
        with pytest.raises(InvalidInputError, match="`s`"):
            p.point(bad)
    with pytest.raises(InvalidInputError, match="`s`"):
        p.curvature(np.inf)


def test_vectorised_shapes_and_evaluate_agree_with_separate_calls():
    p = Path.from_waypoints([[0, 0], [4, 1], [7, 5], [12, 5]], kind="spline")
    s = np.linspace(0, p.length, 12).reshape(3, 4)
    xy, th, k = p.evaluate(s)
    assert xy.shape == (3, 4, 2) and th.shape == (3, 4) and k.shape == (3, 4)
    np.testing.assert_array_equal(xy, p.point(s))
    np.testing.assert_array_equal(th, p.heading(s))
    np.testing.assert_array_equal(k, p.curvature(s))
    assert p.point(1.0).shape == (2,) and p.heading(1.0).shape == ()


def test_resample_grid_and_sample_values():
    p = Path.from_segments([Line(3.0), Arc(1.0, 1.0)])
    smp = p.resample(ds=0.3)
    assert isinstance(smp, PathSamples)
    assert smp.s[0] == 0.0 and smp.s[-1] == p.length
    assert np.diff(smp.s).max() <= 0.3 + 1e-15
    np.testing.assert_allclose(np.diff(smp.s), np.diff(smp.s)[0], rtol=1e-12)
    np.testing.assert_array_equal(smp.xy, p.point(smp.s))
    np.testing.assert_array_equal(smp.curvature, p.curvature(smp.s))
    assert p.resample(n=7).s.size == 7
    assert p.resample(ds=p.length).s.tolist() == [0.0, p.length]
    with pytest.raises(InvalidInputError, match="exactly one"):
        p.resample()
    with pytest.raises(InvalidInputError, match="exactly one"):
        p.resample(n=3, ds=0.1)
    with pytest.raises(InvalidInputError, match="`n`"):
        p.resample(n=1)
    with pytest.raises(InvalidInputError, match="`ds`"):
        p.resample(ds=-1.0)


def test_reversed_mirrors_point_heading_and_curvature():
    p = Path.from_segments([Line(2.0), Clothoid(3.0, 0.0, 0.6), Arc(5 / 3, -2.0)])
    r = p.reversed()
    s = np.linspace(0, p.length, 101)
    # At a joint with a curvature jump each path returns its following piece's value, i.e.
    # the other one-sided limit: compare away from joints.
    s = s[np.abs(s[:, None] - (p.length - p.offsets)[None, :]).min(axis=1) > 1e-9]
    np.testing.assert_allclose(r.point(s), p.point(p.length - s), atol=1e-12)
    np.testing.assert_allclose(r.curvature(s), -p.curvature(p.length - s), atol=1e-12)
    dh = r.heading(s) - p.heading(p.length - s) - np.pi
    np.testing.assert_allclose(np.angle(np.exp(1j * dh)), 0.0, atol=1e-12)
    twice = r.reversed()
    np.testing.assert_allclose(twice.point(s), p.point(s), atol=1e-12)


def test_linestring_round_trip_keeps_vertices():
    ls = shapely.LineString([(0, 0), (4, 0), (4, 3)])
    p = Path.from_linestring(ls, max_deviation=0.1)
    assert p.point(0.0).tolist() == [0.0, 0.0]
    np.testing.assert_allclose(p.point(p.length), [4, 3], atol=1e-12)
    back = p.to_linestring(ds=0.01)
    assert back.length == pytest.approx(p.length, rel=1e-5)  # chords on the arc
    assert back.hausdorff_distance(ls) == pytest.approx(0.1, rel=1e-3)  # the corner arc
    # Piece joints are vertices of the exported LineString (exact polylines stay exact).
    joints = shapely.points(p.point(p.offsets))
    assert shapely.distance(back, joints).max() < 1e-12
    assert Path.from_linestring(ls, kind="clothoid").point(p.offsets[:1]).shape == (1, 2)
    z = shapely.LineString([(0, 0, 5), (3, 4, 6)])
    assert Path.from_linestring(z).length == pytest.approx(5.0, rel=1e-15)


@pytest.mark.parametrize(
    "make",
    [
        lambda: Path.from_segments([Line(2.0), Arc(1.0, 1.0), Clothoid(1.0, 1.0, 0.0)]),
        lambda: Path.from_waypoints([[0, 0], [3, 1], [5, 4]], kind="spline"),
        lambda: Path.from_waypoints([[0, 0], [3, 1], [5, 4]]),
        lambda: Path.from_nurbs(2, [0, 0, 0, 1, 1, 1], [[0, 0], [1, 1], [2, 0]], [1, 2, 1]),
        lambda: Path.from_waypoints([[0, 0], [3, 1], [5, 4]], kind="spline").reversed(),
        lambda: Path.from_waypoints([[0, 0], [10, 0], [3, 1], [8, 4]]),  # with a cusp
        lambda: Path.from_waypoints([[0, 0], [3, 1], [5, 4]], kind="spline").reversed(
            swap_direction=True),
    ],
)
def test_paths_pickle(make):
    """plan_many ships paths to worker processes."""
    p = make()
    q = pickle.loads(pickle.dumps(p))
    s = np.linspace(0, p.length, 9)
    np.testing.assert_array_equal(q.point(s), p.point(s))
    np.testing.assert_array_equal(q.curvature(s), p.curvature(s))
    np.testing.assert_array_equal(q.heading(s), p.heading(s))
    np.testing.assert_array_equal(q.direction(s), p.direction(s))


def test_path_is_immutable_and_has_a_short_repr():
    p = Path.from_segments([Line(2.0)])
    with pytest.raises(AttributeError):
        p.pieces = ()  # type: ignore[misc]
    assert repr(p) == "Path(length=2 m, pieces=1, closed=False)"


def test_spline_that_doubles_back_is_rejected_as_a_cusp():
    with pytest.raises(InvalidInputError, match=r"`xy`.*cusp"):
        Path.from_waypoints([[1.0, 0.0], [0.0, 0.0], [1.0, 0.0]], kind="spline")


def _random_chain(rng: np.random.Generator, scale: float) -> Path:
    """Lines, arcs and clothoids of length ~``scale``, some reversed (cusps), any order."""
    segs: list[Line | Arc | Clothoid] = []
    for _ in range(int(rng.integers(1, 12))):
        kind, reverse = rng.integers(3), bool(rng.random() < 0.3)
        length = scale * 10 ** rng.uniform(-1, 1)
        if kind == 0:
            segs.append(Line(length, reverse=reverse))
        elif kind == 1:
            angle = rng.uniform(-7, 7)
            segs.append(Arc(length / abs(angle), angle, reverse=reverse))
        else:
            k0, k1 = rng.uniform(-7, 7, 2) / length
            segs.append(Clothoid(length, k0, k1, reverse=reverse))
    start = scale * rng.uniform(-100, 100, 2)
    return Path.from_segments(segs, start=start, heading=rng.uniform(-10, 10))


def _each_piece(p: Path, s: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Piece index and position of each ``s``, one point and one piece call at a time."""
    k = np.clip(np.searchsorted(p.offsets, s, side="right") - 1, 0, len(p.pieces) - 1)
    xy = [p.pieces[i].point(np.array(si - p.offsets[i])) for i, si in zip(k, s, strict=True)]
    return k, np.array(xy)


@pytest.mark.parametrize("scale", [1e-3, 1.0, 1e3])
def test_vectorised_points_agree_with_each_piece_on_random_chains(scale):
    # Path.point evaluates all clothoid pieces in one pass (a power series from each
    # quadrature cell's start); the oracle is each piece's own Gauss-Legendre rule.
    rng = np.random.default_rng(int(scale * 1000))
    worst = 0.0
    for _ in range(40):
        p = _random_chain(rng, scale)
        s = np.concatenate((rng.uniform(0, p.length, 500), p.offsets))
        got = p.point(s)
        k, want = _each_piece(p, s)
        extent = float(np.abs(want).max())
        worst = max(worst, float(np.abs(got - want).max()) / max(extent, 1.0))
        np.testing.assert_allclose(got, want, rtol=0, atol=1e-12 * max(1.0, extent / 1000.0))
        # Lines stay exact: start + u * direction, as in the piece.
        lines = [i for i, q in enumerate(p.pieces) if q.k0 == q.k1 == 0.0]
        on_line = np.isin(k, lines)
        np.testing.assert_array_equal(got[on_line], want[on_line])
    assert worst > 0.0 or scale == 1e-3  # the two methods differ, by rounding only


def test_vectorised_points_follow_cusps_of_waypoint_paths():
    # from_waypoints drives a reversal in reverse after the cusp (direction -1 pieces).
    p = Path.from_waypoints([[0, 0], [10, 0], [4, 0], [4, 5], [0, 9], [3, 20], [3, 10]])
    assert p.cusps.size == 2 and -1 in p.direction(p.offsets[:-1])
    s = np.linspace(0.0, p.length, 3001)
    _, want = _each_piece(p, s)
    np.testing.assert_allclose(p.point(s), want, rtol=0, atol=1e-12)
    np.testing.assert_allclose(p.evaluate(s)[0], want, rtol=0, atol=1e-12)


def test_arc_points_match_the_circle_at_every_scale():
    # Closed form: centre + R (sin(θ0 + s/R), -cos(θ0 + s/R)) for a left arc.
    for R in (1e-3, 0.7, 2e3):
        theta0 = 0.3
        p = Path.from_segments([Arc(R, 5.0)], start=(R, -R), heading=theta0)
        s = np.linspace(0.0, p.length, 1001)
        centre = np.array([R, -R]) + R * np.array([-np.sin(theta0), np.cos(theta0)])
        circle = centre + R * np.column_stack((np.sin(theta0 + s / R), -np.cos(theta0 + s / R)))
        np.testing.assert_allclose(p.point(s), circle, rtol=0, atol=4e-15 * max(R, 1.0))


def test_from_segments_pieces_equal_pieces_chained_one_by_one():
    # from_segments tabulates all pieces in one pass (clothoid_chain); the oracle builds each
    # ClothoidPiece alone from the previous one's end point and end heading.
    from speedplan.geometry.primitives import ClothoidPiece

    rng = np.random.default_rng(7)
    for scale in (1e-3, 1.0, 1e3):
        p = _random_chain(rng, scale)
        point, theta = p.pieces[0].start, p.pieces[0].theta0
        for q in p.pieces:
            alone = ClothoidPiece(point, theta, q.length, q.k0, q.k1, q.direction)
            assert (q.start, q.theta0) == (alone.start, alone.theta0)
            np.testing.assert_array_equal(q._knots, alone._knots)
            np.testing.assert_array_equal(q._knot_xy, alone._knot_xy)
            end, theta = alone.end
            point = (float(end[0]), float(end[1]))
