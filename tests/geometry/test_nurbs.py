"""NURBS paths (VDA 5050 trajectories) against an independent de Boor evaluation."""

from __future__ import annotations

import numpy as np
import pytest
from scipy.integrate import quad

from speedplan import InvalidInputError, Path

K = 3
KNOTS = np.array([0, 0, 0, 0, 0.4, 0.7, 1, 1, 1, 1], dtype=float)
CTRL = np.array([[0, 0], [3, 0], [6, 0.5], [8, 2.5], [9, 5], [9, 8]], dtype=float)
W = np.array([1, 1, 1.2, 0.7, 1, 1.0])


def de_boor(k, t, c, x):
    """Independent de Boor evaluation of a B-spline with coefficients ``c`` at ``x``."""
    n = len(c)
    j = int(np.searchsorted(t, x, side="right") - 1)
    j = min(max(j, k), n - 1)
    d = [np.array(c[j + r - k], dtype=float) for r in range(k + 1)]
    for r in range(1, k + 1):
        for i in range(k, r - 1, -1):
            denom = t[i + 1 + j - r] - t[i + j - k]
            alpha = 0.0 if denom == 0 else (x - t[i + j - k]) / denom
            d[i] = (1 - alpha) * d[i - 1] + alpha * d[i]
    return d[k]


def nurbs_point(k, t, ctrl, w, x):
    h = de_boor(k, t, np.column_stack((ctrl * w[:, None], w)), x)
    return h[:2] / h[2]


def test_nurbs_points_equal_independent_de_boor_at_their_arc_length():
    p = Path.from_nurbs(K, KNOTS, CTRL, W)

    def speed(x, h=1e-6):
        lo, hi = max(x - h, 0.0), min(x + h, 1.0)
        return np.linalg.norm(nurbs_point(K, KNOTS, CTRL, W, hi)
                              - nurbs_point(K, KNOTS, CTRL, W, lo)) / (hi - lo)

    def arc(a, b):
        pts = [x for x in (0.4, 0.7) if a < x < b]
        return quad(speed, a, b, points=pts or None, epsabs=1e-11, epsrel=1e-11, limit=200)[0]

    assert p.length == pytest.approx(arc(0.0, 1.0), abs=1e-7)
    for x in np.linspace(0, 1, 17)[1:-1]:
        s = arc(0.0, x)  # independent arc length to parameter x
        np.testing.assert_allclose(p.point(s), nurbs_point(K, KNOTS, CTRL, W, x), atol=1e-7)
    np.testing.assert_allclose(p.point(0.0), CTRL[0], atol=1e-14)
    np.testing.assert_allclose(p.point(p.length), CTRL[-1], atol=1e-12)


def test_nurbs_path_points_match_de_boor_at_the_inverted_parameter():
    p = Path.from_nurbs(K, KNOTS, CTRL, W)
    piece = p.pieces[0]
    s = np.linspace(0, p.length, 31)
    tau = piece.parameter(s)
    assert (np.diff(tau) > 0).all()
    for si, ti in zip(s, tau, strict=True):
        np.testing.assert_allclose(p.point(si), nurbs_point(K, KNOTS, CTRL, W, ti), atol=1e-12)


@pytest.mark.parametrize("weights", [[1, 200, 0.01, 100, 0.01, 1], [1, 1e3, 1e-3, 1e3, 1e-3, 1]])
def test_extreme_weights_arc_length_is_resolved(weights):
    # |r'| varies by orders of magnitude inside one table cell: the table is refined until
    # each cell's arc length is resolved (one 16-point rule was off by up to 0.86 m here), and
    # the inversion still lands on σ(τ) = s.
    w = np.asarray(weights, dtype=float)
    p = Path.from_nurbs(K, KNOTS, CTRL, w)
    piece = p.pieces[0]

    def speed(x):
        return float(np.linalg.norm(piece.curve(np.array([x]), 1)[0]))

    def arc(a, b):
        pts = [x for x in (0.4, 0.7) if a < x < b]
        return quad(speed, a, b, points=pts or None, epsabs=1e-13, epsrel=1e-13, limit=500)[0]

    assert p.length == pytest.approx(arc(0.0, 1.0), rel=1e-10)
    s = np.linspace(0.0, p.length, 41)
    tau = piece.parameter(s)
    assert (np.diff(tau) > 0).all()
    for si, ti in zip(s[1:-1], tau[1:-1], strict=True):
        assert arc(0.0, ti) == pytest.approx(si, abs=1e-9)


def test_rational_quarter_circle_is_exact():
    c = np.sqrt(0.5)
    p = Path.from_nurbs(2, [0, 0, 0, 1, 1, 1], [[1, 0], [1, 1], [0, 1]], [1, c, 1])
    assert p.length == pytest.approx(np.pi / 2, rel=1e-12)
    s = np.linspace(0, p.length, 50)
    np.testing.assert_allclose(np.linalg.norm(p.point(s), axis=1), 1.0, rtol=1e-12)
    np.testing.assert_allclose(p.curvature(s), 1.0, rtol=1e-9)
    np.testing.assert_allclose(p.heading(s), np.pi / 2 + s, atol=1e-9)
    # Unit speed: the point at s is at angle s on the unit circle.
    np.testing.assert_allclose(p.point(s), np.column_stack((np.cos(s), np.sin(s))), atol=1e-12)


def test_full_circle_with_double_knots_is_smooth_not_a_corner():
    c = np.sqrt(0.5)
    ctrl = [[1, 0], [1, 1], [0, 1], [-1, 1], [-1, 0], [-1, -1], [0, -1], [1, -1], [1, 0]]
    w = [1, c, 1, c, 1, c, 1, c, 1]
    knots = [0, 0, 0, 0.25, 0.25, 0.5, 0.5, 0.75, 0.75, 1, 1, 1]
    p = Path.from_nurbs(2, knots, np.array(ctrl, float) * 2.0, w)
    assert p.length == pytest.approx(4 * np.pi, rel=1e-12)
    assert p.is_closed
    s = np.linspace(0, p.length, 101)
    np.testing.assert_allclose(p.curvature(s), 0.5, rtol=1e-9)
    assert p.heading(p.length) - p.heading(0.0) == pytest.approx(2 * np.pi, abs=1e-9)


def test_nurbs_with_a_corner_is_refused():
    with pytest.raises(InvalidInputError, match=r"`knots`.*corner"):
        Path.from_nurbs(1, [0, 0, 0.5, 1, 1], [[0, 0], [1, 0], [1, 1]])


def test_plain_bspline_default_weights():
    p = Path.from_nurbs(K, KNOTS, CTRL)
    q = Path.from_nurbs(K, KNOTS, CTRL, np.ones(6))
    s = np.linspace(0, p.length, 7)
    np.testing.assert_array_equal(p.point(s), q.point(s))


def test_unclamped_knots_whose_curve_starts_off_its_control_point_are_refused():
    # Uniform unclamped cubic knots: the curve starts at (3, 1/12) by de Boor, 3 m from the
    # first control point (0, 0) — a path that does not start at its VDA 5050 node.
    t = np.arange(10, dtype=float)
    start = nurbs_point(K, t, CTRL, np.ones(6), 3.0)
    assert np.linalg.norm(start - CTRL[0]) > 2.9  # the oracle agrees it is off
    with pytest.raises(InvalidInputError, match=r"`knots` are not clamped.*first knot"):
        Path.from_nurbs(K, t, CTRL)
    end_only = np.array([0, 0, 0, 0, 0.4, 0.7, 0.8, 1.0, 1.2, 1.4])  # clamped start only
    end = nurbs_point(K, end_only, CTRL, np.ones(6), 0.8 - 1e-15)  # domain ends at knots[6]
    assert np.linalg.norm(end - CTRL[-1]) > 0.1
    with pytest.raises(InvalidInputError, match=r"`knots` are not clamped.*last knot"):
        Path.from_nurbs(K, end_only, CTRL)
    # The last knot repeated only `degree` times still ends on the last control point (the
    # domain ends at knots[m]): accepted.
    Path.from_nurbs(K, np.concatenate((KNOTS[:-1], [1.5])), CTRL)


def test_unclamped_knots_whose_curve_meets_its_end_points_are_the_clamped_curve():
    # Degree 1 meets its end control points on any knot vector: accepted, and on its domain
    # the same curve (up to parametrisation) as with clamped knots — a straight 5 m segment.
    u = Path.from_nurbs(1, [0, 0.2, 0.5, 1], [[0, 0], [3, 4]])
    c = Path.from_nurbs(1, [0, 0, 1, 1], [[0, 0], [3, 4]])
    assert u.length == pytest.approx(5.0, rel=1e-14)
    s = np.linspace(0, 5.0, 11)
    np.testing.assert_allclose(u.point(s), c.point(s), atol=1e-12)
    np.testing.assert_allclose(u.point(s), np.outer(s / 5.0, [3, 4]), atol=1e-12)


def test_inner_knot_repeated_more_than_degree_with_a_position_jump_is_refused():
    # Degree 1, knot 0.5 twice: the left piece ends at control point 1 = (1, 0), the right one
    # starts at control point 2 = (5, 5) (de Boor on each side confirms it).
    t = np.array([0, 0, 0.5, 0.5, 1, 1], dtype=float)
    ctrl = np.array([[0, 0], [1, 0], [5, 5], [6, 5]], dtype=float)
    np.testing.assert_allclose(nurbs_point(1, t, ctrl, np.ones(4), 0.5 - 1e-12), [1, 0],
                               atol=1e-9)
    np.testing.assert_allclose(nurbs_point(1, t, ctrl, np.ones(4), 0.5), [5, 5], atol=1e-9)
    with pytest.raises(InvalidInputError,
                       match=r"`knots`: knot 0.5 is repeated 2 times.*from \(1, 0\) to \(5, 5\)"):
        Path.from_nurbs(1, t, ctrl)
    # Cubic, knot 0.5 four times, control points 3 and 4 apart: refused as well.
    t3 = np.array([0, 0, 0, 0, 0.5, 0.5, 0.5, 0.5, 1, 1, 1, 1], dtype=float)
    c3 = np.array([[0, 0], [1, 0], [2, 0], [3, 0], [3, 2], [4, 2], [5, 2], [6, 2]], dtype=float)
    with pytest.raises(InvalidInputError, match=r"`knots`: knot 0.5 is repeated 4 times"):
        Path.from_nurbs(3, t3, c3)


def test_inner_knot_repeated_more_than_degree_without_a_jump_is_only_a_corner_check():
    # The two sides meet (control points 1 and 2 coincide): no jump. Collinear: accepted, a
    # 6 m straight; turning there: refused as a corner, like a knot repeated `degree` times.
    t = [0, 0, 0.5, 0.5, 1, 1]
    p = Path.from_nurbs(1, t, [[0, 0], [1, 0], [1, 0], [6, 0]])
    assert p.length == pytest.approx(6.0, rel=1e-14)
    np.testing.assert_allclose(p.point([0.5, 1.0, 3.0]), [[0.5, 0], [1, 0], [3, 0]], atol=1e-12)
    with pytest.raises(InvalidInputError, match=r"`knots`.*corner"):
        Path.from_nurbs(1, t, [[0, 0], [1, 0], [1, 0], [1, 5]])


def circle_arc_nurbs(center, radius, start, spans, knots):
    """Rational quadratic NURBS of the circle arc from angle ``start`` through ``spans``.

    Each span (angle < π) is one quadratic Bézier arc (middle weight ``cos(span / 2)``);
    ``knots`` are the inner knots between spans, each doubled (any increasing values: they
    change the parametrisation, not the curve).
    """
    ctrl, w = [], []
    angle = start
    for i, span in enumerate(spans):
        mid = angle + 0.5 * span
        pts = [(radius, angle), (radius / np.cos(0.5 * span), mid), (radius, angle + span)]
        for j, (r, a) in enumerate(pts):
            if i and j == 0:
                continue  # the previous span's end
            ctrl.append(center + r * np.array([np.cos(a), np.sin(a)]))
            w.append(np.cos(0.5 * span) if j == 1 else 1.0)
        angle += span
    t = np.concatenate(([0.0] * 3, np.repeat(knots, 2), [1.0] * 3))
    return Path.from_nurbs(2, t, np.array(ctrl), np.array(w))


@pytest.mark.parametrize("seed", range(6))
def test_circle_arc_nurbs_at_arc_length_equals_the_closed_form(seed):
    # An independent oracle at every s: the circle's point, heading and curvature at angle
    # start + s / R, whatever the (non-uniform) knots and the cells of the arc-length table.
    rng = np.random.default_rng(seed)
    radius = 10.0 ** rng.uniform(-1, 2)
    center, start = rng.uniform(-50, 50, 2), rng.uniform(-np.pi, np.pi)
    spans = rng.uniform(0.2, 2.5, rng.integers(1, 5))
    knots = np.sort(rng.uniform(0.05, 0.95, spans.size - 1))
    p = circle_arc_nurbs(center, radius, start, spans, knots)
    assert p.length == pytest.approx(radius * spans.sum(), rel=1e-13)
    s = np.concatenate((np.linspace(0.0, p.length, 1001), rng.uniform(0, p.length, 1000)))
    angle = start + s / radius
    scale = max(radius, 1.0) * (1.0 + np.abs(center).max() / max(radius, 1.0))
    xy, theta, kappa = p.evaluate(s)
    exact = center + radius * np.column_stack((np.cos(angle), np.sin(angle)))
    np.testing.assert_allclose(xy, exact, rtol=0, atol=1e-13 * scale)
    np.testing.assert_allclose(p.point(s), xy, rtol=0, atol=0)
    # Continuous (unwrapped) from its start, which is the tangent's direction mod 2π.
    assert abs(np.angle(np.exp(1j * (theta[0] - start - np.pi / 2)))) < 1e-12
    np.testing.assert_allclose(theta - theta[0], s / radius, rtol=0, atol=1e-12)
    np.testing.assert_allclose(kappa, 1.0 / radius, rtol=1e-11)


@pytest.mark.parametrize("seed", range(6))
def test_straight_nurbs_with_non_uniform_knots_moves_at_unit_speed(seed):
    # Collinear control points in order and any positive weights: a straight segment
    # travelled monotonically, so the point at arc length s is start + s * direction exactly
    # (the parametrisation is far from uniform: weights over two decades, random knots).
    rng = np.random.default_rng(100 + seed)
    k = int(rng.integers(2, 5))
    m = int(rng.integers(k + 1, 10))
    along = np.concatenate(([0.0], np.cumsum(rng.uniform(0.1, 5.0, m - 1))))
    heading = rng.uniform(-np.pi, np.pi)
    direction = np.array([np.cos(heading), np.sin(heading)])
    origin = rng.uniform(-20, 20, 2)
    ctrl = origin + along[:, None] * direction
    w = 10.0 ** rng.uniform(-1, 1, m)
    knots = np.concatenate((np.zeros(k + 1), np.sort(rng.uniform(0, 1, m - k - 1)),
                            np.ones(k + 1)))
    p = Path.from_nurbs(k, knots, ctrl, w)
    assert p.length == pytest.approx(along[-1], rel=1e-13)
    s = np.concatenate((np.linspace(0.0, p.length, 1001), rng.uniform(0, p.length, 1000)))
    xy, theta, kappa = p.evaluate(s)
    scale = max(along[-1], 1.0) + np.abs(origin).max()
    np.testing.assert_allclose(xy, origin + s[:, None] * direction, rtol=0, atol=1e-13 * scale)
    np.testing.assert_allclose(np.angle(np.exp(1j * (theta - heading))), 0.0, rtol=0,
                               atol=1e-12)
    np.testing.assert_allclose(kappa, 0.0, rtol=0, atol=1e-12)


@pytest.mark.parametrize("weights", [[1, 1, 1.2, 0.7, 1, 1.0], [1, 1e3, 1e-3, 1e3, 1e-3, 1]])
def test_interpolated_inversion_equals_newton_to_rounding(weights):
    # The Chebyshev interpolants of τ(u) against Newton's method run until its steps stall:
    # within a few ulps of τ times |r'| (an arc length), even where |r'| varies by decades.
    p = Path.from_nurbs(K, KNOTS, CTRL, np.asarray(weights, dtype=float))
    piece = p.pieces[0]
    s = np.random.default_rng(7).uniform(0, p.length, 5000)
    flat, j = piece._cell(s)
    newton = piece._parameter(flat, j, rel_tol=0.0)
    speed = np.linalg.norm(piece.curve(newton, 1), axis=1)
    err = np.abs(piece.parameter(s) - newton) * speed
    assert (err <= 4e-15 * p.length + 2 * speed * np.spacing(newton)).all()


def _curvature_from_derivatives(piece, s):
    """κ from ``r'`` and ``r''`` (independent de Boor) at the parameter Newton inverts."""
    flat, j = piece._cell(s)
    tau = piece._parameter(flat, j, rel_tol=0.0)
    curve = piece.curve
    k, t, w = curve.degree, curve.knots, curve.weights
    homog = np.column_stack((curve.control_points * w[:, None], w))
    # The derivative splines' control points (degrees k-1 and k-2) give r' and r'' without
    # differencing; then the quotient rule.
    d1c = k * (homog[1:] - homog[:-1]) / np.maximum(t[k + 1:-1] - t[1:-k - 1], 1e-300)[:, None]
    d2c = (k - 1) * (d1c[1:] - d1c[:-1]) / np.maximum(t[k + 1:-2] - t[2:-k - 1], 1e-300)[:, None]
    out = np.empty(tau.size)
    for i, x in enumerate(tau):
        p0, p1 = de_boor(k, t, homog, x), de_boor(k - 1, t[1:-1], d1c, x)
        p2 = de_boor(k - 2, t[2:-2], d2c, x)
        r = p0[:2] / p0[2]
        r1 = (p1[:2] - r * p1[2]) / p0[2]
        r2 = (p2[:2] - 2 * r1 * p1[2] - r * p2[2]) / p0[2]
        out[i] = (r1[0] * r2[1] - r1[1] * r2[0]) / np.hypot(*r1) ** 3
    return out


@pytest.mark.parametrize("weights", [[1, 1, 1.2, 0.7, 1, 1.0], [1, 1e3, 1e-3, 1e3, 1e-3, 1]])
def test_interpolated_curvature_equals_the_curvature_of_the_derivatives(weights):
    # κ(u) is read from Chebyshev interpolants per cell; the oracle is the quotient rule on
    # an independent de Boor evaluation of the derivative splines at Newton's parameter.
    p = Path.from_nurbs(K, KNOTS, CTRL, np.asarray(weights, dtype=float))
    piece = p.pieces[0]
    s = np.concatenate(([0.0, p.length], np.random.default_rng(3).uniform(0, p.length, 400)))
    oracle = _curvature_from_derivatives(piece, s)
    scale = np.abs(oracle).max() + 1.0 / p.length
    np.testing.assert_allclose(p.curvature(s), oracle, rtol=0, atol=1e-12 * scale)
    np.testing.assert_array_equal(p.evaluate(s)[2], p.curvature(s))


def test_cells_whose_curvature_interpolant_fails_evaluate_the_curve(monkeypatch):
    # A cell whose interpolant missed its check answers from the derivatives at each query.
    p = Path.from_nurbs(K, KNOTS, CTRL, W)
    piece = p.pieces[0]
    s = np.random.default_rng(4).uniform(0, p.length, 300)
    direct = piece._direct_curvature(s)
    wrong = piece._kappa_coef + 1.0  # an interpolant that would be off everywhere
    object.__setattr__(piece, "_kappa_coef", wrong)
    object.__setattr__(piece, "_kappa_ok", np.zeros_like(piece._kappa_ok))
    np.testing.assert_array_equal(p.curvature(s), direct)


@pytest.mark.parametrize(("ctrl", "w"), [
    ([[1, 2], [4, 6]], [1, 1]),  # VDA 5050 3.0's straight edge: two control points
    ([[1, 2], [1.3, 2.4], [2.5, 4], [4, 6]], [1, 0.4, 2.5, 1]),  # more, uneven, rational
])
def test_a_nurbs_along_its_chord_is_that_line(ctrl, w):
    ctrl, w = np.array(ctrl, dtype=float), np.array(w, dtype=float)
    k = ctrl.shape[0] - 1
    knots = np.concatenate((np.zeros(k + 1), np.ones(k + 1)))
    p = Path.from_nurbs(k, knots, ctrl, w)
    assert p.straight_between(0.0, p.length) and p.length == pytest.approx(5.0, rel=1e-15)
    # Every point of the curve (independent de Boor) lies on the path, in order.
    x = np.linspace(0.0, 1.0, 41)
    pts = np.array([nurbs_point(k, knots, ctrl, w, xi) for xi in x])
    along = np.hypot(*(pts - ctrl[0]).T)
    assert np.all(np.diff(along) >= -1e-12)
    np.testing.assert_allclose(p.point(along), pts, atol=1e-12)
    assert float(np.abs(p.curvature(np.linspace(0, p.length, 9))).max()) == 0.0


def test_control_points_off_the_chord_or_out_of_order_are_not_a_line():
    from speedplan.geometry.nurbs import straight_chord

    assert straight_chord(np.array([[0.0, 0.0], [6.0, 0.0], [4.0, 0.0]])) is None
    assert straight_chord(np.array([[0.0, 0.0], [2.0, 1e-6], [4.0, 0.0]])) is None
    p = Path.from_nurbs(2, [0, 0, 0, 1, 1, 1], [[0, 0], [2, 1e-6], [4, 0]])
    assert not p.straight_between(0.0, p.length)


def test_the_curvature_rate_jumps_at_the_knots_and_is_read_on_each_side():
    # A cubic B-spline is C² at a simple knot: the curvature goes on, its rate jumps. The
    # oracle: one-sided differences of the curvature itself, a few micrometres either side.
    path = Path.from_nurbs(3, [0, 0, 0, 0, 0.4, 0.7, 1, 1, 1, 1],
                           [[0, 0], [3, 0], [6, 0.5], [8, 2.5], [9, 5], [9, 8]],
                           [1, 1, 1.2, 1, 1, 1])
    knots = path.rate_joins
    assert knots.size == 2 and np.all((knots > 0) & (knots < path.length))
    d = 1e-4
    for x in knots:
        left = (path.curvature([x])[0] - path.curvature([x - d])[0]) / d
        right = (path.curvature([x + d])[0] - path.curvature([x])[0]) / d
        assert abs(right - left) > 0.02  # the jump is there
        assert path.curvature_rate([x])[0] == pytest.approx(right, rel=1e-3)
        assert path.curvature_rate_before([x])[0] == pytest.approx(left, rel=1e-3)
    # Driven backwards the sides swap; a stretch starting on a knot reads the rate after it.
    back = path.reversed()
    x = path.length - knots[0]
    assert back.rate_joins == pytest.approx(path.length - knots[::-1])
    assert back.curvature_rate([x])[0] == pytest.approx(path.curvature_rate_before([knots[0]])[0])
    assert back.curvature_rate_before([x])[0] == pytest.approx(path.curvature_rate([knots[0]])[0])
    part = path.sub(float(knots[0]), float(knots[1]))
    assert part.rate_joins.size == 0
    assert part.curvature_rate([0.0, part.length]) == pytest.approx(
        [path.curvature_rate([knots[0]])[0], path.curvature_rate_before([knots[1]])[0]])
