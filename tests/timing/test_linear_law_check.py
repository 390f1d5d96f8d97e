"""The check of a law linear in ``w`` (no jerk limit) against the check of any law.

`check_linear_law` reads the nodes' ``w`` cell by cell; `check_pieces` walks the law's
pieces with their exact extremes and samples. On random paths, limits, zones, speed limits
and legs, with the planned law and with laws that exceed the speed bound, the acceleration,
the braking, the lateral acceleration or the yaw rate, both must give the same verdicts, the
same ratios and maxima (to rounding), the same pieces to refine, and report a position where
the ratio is largest.
"""

from __future__ import annotations

import math
import warnings

import numpy as np
import pytest
import shapely
from hypothesis import given, settings
from hypothesis import strategies as st
from shared import examples

import speedplan as sp
from speedplan.core.numerics import cell_points, cell_rows
from speedplan.geometry import CellSamples, SpeedBound
from speedplan.timing import TimeLaw
from speedplan.timing.verify import (
    LIMIT_NAMES,
    _first_peak,
    bound_breakpoints,
    check_law,
    check_linear_law,
    check_pieces,
)

KINDS = ("g2", "spline", "clothoid", "polyline")


def _case(seed: int):
    """A random no-jerk plan: its path, limits, speed bound and profile."""
    rng = np.random.default_rng(seed)
    pts = np.cumsum(rng.uniform(-10.0, 10.0, size=(int(rng.integers(2, 7)), 2)), axis=0)
    try:
        path = sp.Path.from_waypoints(pts, kind=KINDS[seed % 4])
    except sp.InvalidInputError:  # a waypoint that turns back: g2 drives it in reverse
        path = sp.Path.from_waypoints(pts)
    lim = sp.Limits(v_max=rng.uniform(0.5, 5.0), a_max=rng.uniform(0.2, 2.0),
                    a_lat_max=rng.uniform(0.3, 3.0), j_max=math.inf,
                    a_decel=rng.uniform(0.2, 2.0),
                    yaw_rate_max=rng.uniform(0.3, 2.0) if seed % 3 == 0 else math.inf)
    kw: dict = {}
    if seed % 5 == 1:
        centre = path.point(path.length * rng.uniform(0.2, 0.8))
        kw["zones"] = [sp.SpeedZone(shapely.Point(centre).buffer(rng.uniform(0.3, 3.0)),
                                    rng.uniform(0.1, 1.0))]
    if seed % 5 == 2:
        kw["v_limit"] = (np.linspace(0.0, path.length, 6), rng.uniform(0.2, 3.0, 6))
    if seed % 7 == 3:
        kw["stops"] = [path.length * rng.uniform(0.3, 0.7)]  # two legs: an offset
    if seed % 2:
        kw["n"] = int(rng.integers(20, 400))
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        return path, lim, sp.plan(path, lim, **kw), rng


def _variants(w: np.ndarray, rng: np.random.Generator) -> list[np.ndarray]:
    """The planned ``w`` and laws that exceed its limits in places."""
    spike = w.copy()
    k = int(rng.integers(1, w.size - 1))
    spike[k] *= 1.0 + rng.uniform(0.01, 0.5)
    noisy = np.maximum(w * (1.0 + rng.normal(0.0, 0.02, w.size)), 0.0)
    return [w, w * rng.uniform(1.0005, 1.3), spike, noisy, w * 0.999]


def _assert_same(lin, gen, length):
    a, b = lin.verification, gen.verification
    assert tuple(a.checks) == tuple(b.checks) == LIMIT_NAMES[:8]
    assert a.ok == b.ok
    for name in a.checks:
        x, y = a.checks[name], b.checks[name]
        assert (x.exceeded, x.unset, x.limit) == (y.exceeded, y.unset, y.limit), name
        assert x.ratio == pytest.approx(y.ratio, rel=1e-12, abs=1e-300), name
        assert x.maximum == pytest.approx(y.maximum, rel=1e-12, abs=1e-300), name
    np.testing.assert_array_equal(lin.excess, gen.excess)
    np.testing.assert_array_equal(lin.knots, gen.knots)
    return a, b


def _where_holds_the_peak(law, offset, path, bound, limits, name, where):
    """The ratio ``name`` at ``where`` (from its own samples) is the largest, to rounding."""
    q = np.array([where - offset])
    w = law.kinematics(q)[0]
    kappa = np.abs(path.curvature(q + offset))
    wb = np.asarray(bound(q + offset))
    if name == "speed":
        return float(np.sqrt(w[0]) / np.sqrt(wb[0]))
    if name == "lateral":
        return float(kappa[0] * w[0] / limits.a_lat_max)
    return float(kappa[0] * np.sqrt(w[0]) / limits.yaw_rate_max)


@settings(max_examples=examples(40), deadline=None)
@given(seed=st.integers(0, 10**6))
def test_linear_check_agrees_with_the_check_of_the_pieces(seed):
    path, lim, prof, rng = _case(seed)
    bound = prof.speed_bound
    breaks = bound_breakpoints(path, bound)
    for leg in prof.legs:
        for w in _variants(leg.solution.w, rng):
            law = TimeLaw(leg.s, w, linear=True)
            lin = check_linear_law(law, leg.start, path, bound, lim, breaks)
            assert lin is not None
            gen = check_pieces(law, leg.start, path, bound, lim, breaks)
            a, b = _assert_same(lin, gen, path.length)
            for name in ("speed", "lateral", "yaw_rate"):
                if a.checks[name].unset or a.where[name] == pytest.approx(b.where[name],
                                                                          abs=1e-9):
                    continue
                # Another point of the same (largest) ratio: equal values along a cruise.
                got = _where_holds_the_peak(law, leg.start, path, bound, lim, name,
                                            a.where[name])
                assert got == pytest.approx(b.ratios[name], rel=1e-9), name
            # check_law dispatches a linear law to the linear check.
            assert check_law(law, leg.start, path, bound, lim, breaks).verification == a


@pytest.mark.parametrize("seed", range(8))
def test_linear_check_reads_the_models_samples_to_the_same_verdict(seed):
    # The plan's own check reads the bound the model sampled at the grid's cell points; the
    # same check evaluating the bound itself gives the same numbers, bit for bit.
    path, lim, prof, _ = _case(seed)
    from speedplan.model import Leg, PlanRequest, build_model

    req = prof.request
    model = build_model(PlanRequest.create(path, lim, n=req.n, zones=req.zones,
                                           v_limit=req.v_limit, stops=req.stops or None))
    breaks = bound_breakpoints(path, prof.speed_bound)
    for i, leg in enumerate(model.legs):
        assert isinstance(leg, Leg) and leg.samples is not None
        law = prof.legs[i].law
        read = check_linear_law(law, leg.start, path, prof.speed_bound, lim, breaks,
                                leg.samples)
        fresh = check_linear_law(law, leg.start, path, prof.speed_bound, lim, breaks)
        assert read is not None and fresh is not None
        assert read.verification == fresh.verification
        np.testing.assert_array_equal(read.excess, fresh.excess)


def _straight(length=20.0, n=201):
    path = sp.Path.from_waypoints([[0.0, 0.0], [length, 0.0]], kind="polyline")
    return path, np.linspace(0.0, length, n)


@pytest.mark.parametrize("name", ["speed", "accel", "decel", "lateral", "yaw_rate"])
def test_a_law_beyond_one_limit_is_flagged_there(name):
    # A hand-made law on line - arc (radius 5 m, from 10 m to 20 m) - line, at most 2 m/s,
    # changed so that exactly one limit is exceeded, and where (the oracle).
    path = sp.Path.from_segments([sp.geometry.Line(10.0), sp.geometry.Arc(5.0, 2.0),
                                  sp.geometry.Line(10.0)])
    s = np.linspace(0.0, path.length, 301)  # h = 0.1 m
    w = np.minimum(np.minimum(2.0 * s, 2.0 * (s[-1] - s)), 4.0)  # 1 m/s² both ways
    limits = {"a_lat_max": 1.0, "yaw_rate_max": 0.5}  # on the arc: 0.8 and 0.4 of them
    where = {"lateral": (10.0, 20.0), "yaw_rate": (10.0, 20.0), "speed": (5.0, 6.0),
             "accel": (0.9, 1.1), "decel": (29.3, 30.0)}[name]
    cap = 9.0
    if name == "speed":
        cap = 3.9  # a bound below w = 4 over [5, 6]: 1.013 of it
    elif name == "accel":
        w[10] += 0.3  # (2.3 - 1.8) / 0.2 = 2.5 m/s² into s = 1, then -0.5
    elif name == "decel":
        w = np.minimum(np.minimum(2.0 * s, 6.0 * (s[-1] - s)), 4.0)  # the last 0.67 m at 3 m/s²
    elif name == "lateral":
        limits["a_lat_max"] = 0.7
    else:
        limits["yaw_rate_max"] = 0.35
    lim = sp.Limits(v_max=3.0, a_max=1.0, j_max=math.inf, a_decel=1.0, **limits)
    law = TimeLaw(s, w, linear=True)

    def bound(q):  # the speed bound alone, without the curvature's terms
        q = np.asarray(q)
        return np.where((q >= 5.0) & (q <= 6.0), cap, 9.0)

    lin = check_linear_law(law, 0.0, path, bound, lim, np.zeros(0))
    gen = check_pieces(law, 0.0, path, bound, lim, np.zeros(0))
    a, _ = _assert_same(lin, gen, path.length)
    assert set(a.violations) == {name}
    assert where[0] - 0.1 <= a.where[name] <= where[1] + 0.1
    flagged = 0.5 * (lin.knots[:-1] + lin.knots[1:])[lin.excess]
    assert flagged.size and where[0] - 0.1 <= flagged.min() <= flagged.max() <= where[1] + 0.1


def test_a_dip_between_the_points_of_a_cell_is_caught_at_the_breakpoints():
    # A v_limit dip narrower than an eighth of a cell, between two of its points: only the
    # breakpoints see it.
    path, s = _straight()
    law = TimeLaw(s, np.minimum(np.minimum(2.0 * s, 2.0 * (s[-1] - s)), 4.0), linear=True)
    cell = s[100], s[101]
    centre = cell[0] + 0.3 * (cell[1] - cell[0])
    v_limit = ([0.0, centre - 1e-4, centre, centre + 1e-4, 20.0], [5.0, 5.0, 1.0, 5.0, 5.0])
    lim = sp.Limits(v_max=2.0, a_max=1.0, a_lat_max=1.0, j_max=math.inf)
    bound = SpeedBound(path, lim, v_limit=v_limit)
    breaks = bound_breakpoints(path, bound)
    lin = check_linear_law(law, 0.0, path, bound, lim, breaks)
    gen = check_pieces(law, 0.0, path, bound, lim, breaks)
    a, _ = _assert_same(lin, gen, path.length)
    assert a.ratios["speed"] == pytest.approx(2.0, rel=1e-9)
    assert a.where["speed"] == pytest.approx(centre, abs=1e-12)
    assert lin.excess.sum() == 1 and lin.excess[200]  # the first half of cell 100


def test_samples_of_another_grid_or_offset_are_not_read():
    # The samples of a slower bound: read, they fail the law; from another grid or another
    # offset they give way to the bound itself, which the law meets.
    path, _ = _straight()
    s = np.linspace(0.0, 19.0, 191)
    lim = sp.Limits(v_max=2.0, a_max=1.0, a_lat_max=1.0, j_max=math.inf)
    bound = SpeedBound(path, lim)
    slow = SpeedBound(path, sp.Limits(1.0, 1.0, 1.0, math.inf))
    law = TimeLaw(s, np.minimum(np.minimum(2.0 * s, 2.0 * (s[-1] - s)), 4.0), linear=True)
    for offset in (0.0, 1.0):
        plain = check_linear_law(law, offset, path, bound, lim, np.zeros(0))
        assert plain is not None and plain.verification.ok
        for other in (CellSamples.of(slow, np.linspace(0.0, 19.0, 101)),
                      CellSamples.of(slow.at_offset(1.0 - offset), s)):
            got = check_linear_law(law, offset, path, bound, lim, np.zeros(0), other)
            assert got is not None and got.verification == plain.verification
        read = check_linear_law(law, offset, path, bound, lim, np.zeros(0),
                                CellSamples.of(slow.at_offset(offset), s))
        assert read is not None and read.verification.ratios["speed"] == pytest.approx(2.0)


def test_a_bound_of_zero_is_left_to_the_check_of_the_pieces():
    path, s = _straight()
    lim = sp.Limits(v_max=2.0, a_max=1.0, a_lat_max=1.0, j_max=math.inf)
    law = TimeLaw(s, np.minimum(np.minimum(2.0 * s, 2.0 * (s[-1] - s)), 4.0), linear=True)

    def bound(q):
        return np.where(np.abs(np.asarray(q) - 10.0) < 0.05, 0.0, 4.0)

    assert check_linear_law(law, 0.0, path, bound, lim, np.zeros(0)) is None
    check = check_law(law, 0.0, path, bound, lim, np.zeros(0))
    assert check.verification.ratios["speed"] == math.inf
    assert not check.verification.ok


def _rows_first_tie(values: np.ndarray, points: np.ndarray) -> int:
    """The first largest of ``values`` along the path: the first tie of each row of
    `cell_points`, then the one at the least point (the first such row's)."""
    at = values == values.max()
    nodes, inner = cell_rows(at)
    n = nodes.size
    first = np.concatenate(([np.argmax(nodes)], n + np.arange(inner.shape[0]) * (n - 1)
                            + np.argmax(inner, axis=1)))
    first = first[at[first]]
    return int(first[np.argmin(points[first])])


@pytest.mark.parametrize("seed", range(40))
def test_the_peak_is_the_first_tie_along_the_path(seed):
    rng = np.random.default_rng(seed)
    s = np.cumsum(np.concatenate(([0.0], rng.uniform(1e-3, 1.0, int(rng.integers(2, 60))))))
    if seed % 4 == 0:  # steps of a few ulps too
        s[1] = np.nextafter(s[0], 1.0)
    points = cell_points(s)
    values = rng.integers(0, 3 if seed % 2 else 40, points.size).astype(np.float64)
    peak = _first_peak(values, values.size, points)
    assert peak == _rows_first_tie(values, points)
    # The breakpoints follow the points: one that ties with the peak does not move it, the
    # first of those above it is the peak.
    top = float(values.max())
    m = values.size
    assert _first_peak(np.concatenate((values, [top])), m, points) == peak
    assert _first_peak(np.concatenate((values, [top, top + 1.0, top + 1.0])), m, points) == m + 1
    assert _first_peak(np.concatenate((values, [np.nan])), m, points) is None
