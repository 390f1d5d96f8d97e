"""Hypothesis properties: resampling, unit speed in s, reversal, G1 joints, for every kind."""

from __future__ import annotations

import itertools

import numpy as np
import pytest
from hypothesis import assume, given, settings
from hypothesis import strategies as st
from shared import examples

from speedplan import Path
from speedplan.geometry import Arc, Clothoid, Line

# Modest by default to keep the suite fast; SPEEDPLAN_HYPOTHESIS=deep for a deeper search.
SETTINGS = settings(max_examples=examples(25), deadline=None)

segment = st.one_of(
    st.builds(Line, st.floats(0.1, 50)),
    st.builds(Arc, st.floats(0.5, 50), st.floats(-3, 3).filter(lambda a: abs(a) > 1e-3)),
    st.builds(Clothoid, st.floats(0.1, 30), st.floats(-1, 1), st.floats(-1, 1)),
)


@st.composite
def waypoint_paths(draw):
    n = draw(st.integers(2, 7))
    pts = np.array(draw(st.lists(st.tuples(st.floats(-50, 50), st.floats(-50, 50)),
                                 min_size=n, max_size=n)))
    legs = np.linalg.norm(np.diff(pts, axis=0), axis=1)
    assume((legs > 1.0).all())
    heads = np.arctan2(np.diff(pts[:, 1]), np.diff(pts[:, 0]))
    assume((np.abs(np.angle(np.exp(1j * np.diff(heads)))) < 2.5).all())
    kind = draw(st.sampled_from(["g2", "clothoid", "spline", "polyline"]))
    return Path.from_waypoints(pts, kind=kind), kind


@st.composite
def nurbs_paths(draw):
    k = draw(st.integers(2, 3))
    m = draw(st.integers(k + 1, 7))
    # A wandering control polygon with forward steps, so the curve has no cusp.
    steps = np.array(draw(st.lists(st.tuples(st.floats(1, 5), st.floats(-2, 2)),
                                   min_size=m - 1, max_size=m - 1)))
    ctrl = np.vstack(([0.0, 0.0], np.cumsum(steps, axis=0)))
    w = np.array(draw(st.lists(st.floats(0.5, 2.0), min_size=m, max_size=m)))
    inner = np.linspace(0, 1, m - k + 1)[1:-1]
    knots = np.concatenate((np.zeros(k + 1), inner, np.ones(k + 1)))
    return Path.from_nurbs(k, knots, ctrl, w)


def joints(p):
    """Arc lengths where the curvature may jump: piece joints and the inner knots of spline
    and NURBS pieces (their second derivative jumps there, which finite differences see)."""
    out = [p.offsets[1:-1]]
    for piece, offset in zip(p.pieces, p.offsets, strict=False):
        if hasattr(piece, "curve"):  # a CurvePiece: its table holds the knots as nodes
            inner = np.asarray(piece.curve.breaks)[1:-1]
            out.append(offset + piece._arc[np.isin(piece._tau, inner)])
    return np.concatenate(out)


def off_joints(p, s, gap):
    """``s`` values farther than ``gap`` from every joint (curvature may jump there)."""
    return s[np.abs(s[:, None] - joints(p)[None, :]).min(axis=1, initial=np.inf) > gap]


def speed(p, s, h):
    """|dr/ds| by a fourth-order central difference (error ~ h⁴ |r⁽⁵⁾|)."""
    d = (8 * (p.point(s + h) - p.point(s - h)) - (p.point(s + 2 * h) - p.point(s - 2 * h)))
    return np.linalg.norm(d, axis=-1) / (12 * h)


def check_invariants(p, unit_tol, n):
    L = p.length
    # Resampling keeps the length and the end points.
    smp = p.resample(n=n)
    assert smp.s[0] == 0.0 and smp.s[-1] == L and smp.s.size == n
    np.testing.assert_allclose(smp.xy[[0, -1]], p.point(np.array([0.0, L])), rtol=0,
                               atol=1e-12 * max(L, 1))
    np.testing.assert_allclose(np.diff(smp.s), L / (n - 1), rtol=1e-9)
    # Unit speed in s.
    h = 1e-3 * min(1.0, L)
    s = off_joints(p, np.linspace(2 * h, L - 2 * h, 200), 2.5 * h)
    np.testing.assert_allclose(speed(p, s, h), 1.0, atol=unit_tol)
    # Reversal mirrors points and curvature (away from joints, where k may jump).
    r = p.reversed()
    assert r.length == pytest.approx(L, rel=1e-12)
    s = off_joints(p, np.linspace(0, L, 97), 1e-9 * L)
    np.testing.assert_allclose(r.point(L - s), p.point(s), atol=1e-9 * max(L, 1))
    np.testing.assert_allclose(r.curvature(L - s), -p.curvature(s), atol=1e-9)
    # Heading continuous at joints (G1), positions too.
    joints = p.offsets[1:-1]
    eps = 1e-12 * L
    if joints.size:
        # Across 2 eps the heading turns by up to 2 eps |k| (G2 corners reach |k| ~ 10 1/m).
        turn = 2 * eps * np.abs(p.curvature(np.concatenate((joints - eps, joints + eps)))).max()
        assert np.abs(p.heading(joints + eps) - p.heading(joints - eps)).max() < 1e-9 + turn
        gap = np.linalg.norm(p.point(joints + eps) - p.point(joints - eps), axis=1)
        assert gap.max() < 1e-9 * max(L, 1)


@SETTINGS
@given(segs=st.lists(segment, min_size=1, max_size=6), x=st.floats(-100, 100),
       th=st.floats(-4, 4), n=st.integers(2, 400))
def test_segment_paths(segs, x, th, n):
    p = Path.from_segments(segs, start=(x, -x), heading=th)
    expected = sum(s.length if not isinstance(s, Arc) else s.radius * abs(s.angle) for s in segs)
    assert p.length == pytest.approx(expected, rel=1e-12)
    check_invariants(p, unit_tol=1e-9, n=n)


@SETTINGS
@given(case=waypoint_paths(), n=st.integers(2, 400))
def test_waypoint_paths(case, n):
    p, kind = case
    # Clothoid chains and rounded polylines are primitives: exact unit speed.
    check_invariants(p, unit_tol=1e-6 if kind == "spline" else 1e-9, n=n)


@SETTINGS
@given(p=nurbs_paths(), n=st.integers(2, 400))
def test_nurbs_paths(p, n):
    check_invariants(p, unit_tol=1e-6, n=n)


@SETTINGS
@given(k=st.integers(2, 3), data=st.data())
def test_nurbs_arc_length_with_weights_over_five_decades(k, data):
    # |r'| may vary by orders of magnitude inside a polynomial piece; length and arc-length
    # inversion must still be right. scipy's adaptive quadrature is the reference; its own
    # error reaches 1e-10 on such curves, hence 1e-9 (one rule per cell was off by up to 42 %).
    from scipy.integrate import quad

    from speedplan import InvalidInputError

    m = data.draw(st.integers(k + 1, 7))
    steps = np.array(data.draw(st.lists(st.tuples(st.floats(1, 5), st.floats(-2, 2)),
                                        min_size=m - 1, max_size=m - 1)))
    ctrl = np.vstack(([0.0, 0.0], np.cumsum(steps, axis=0)))
    w = 10.0 ** np.array(data.draw(st.lists(st.floats(-2.5, 2.5), min_size=m, max_size=m)))
    knots = np.concatenate((np.zeros(k + 1), np.linspace(0, 1, m - k + 1)[1:-1], np.ones(k + 1)))
    try:
        p = Path.from_nurbs(k, knots, ctrl, w)
    except InvalidInputError as exc:  # only a (near-)cusp may be refused
        assert "reverses direction" in str(exc)
        assume(False)
    assert len(p.pieces) == 1
    if p.straight_between(0.0, p.length):  # control points in order on a line: that line
        assert p.length == pytest.approx(float(np.hypot(*(ctrl[-1] - ctrl[0]))), rel=1e-12)
        return
    piece = p.pieces[0]
    breaks = np.asarray(piece.curve.breaks)

    def arc(t):
        def speed(x):
            return float(np.linalg.norm(piece.curve(np.array([x]), 1)[0]))

        ends = np.append(breaks[breaks < t], t)
        return sum(quad(speed, a, b, epsabs=1e-13, epsrel=1e-13, limit=500)[0]
                   for a, b in itertools.pairwise(ends))

    assert p.length == pytest.approx(arc(breaks[-1]), rel=1e-9)
    s = np.linspace(0.0, p.length, 9)[1:-1]
    for si, ti in zip(s, piece.parameter(s), strict=True):
        assert arc(ti) == pytest.approx(si, abs=1e-9 * p.length)
