"""The time law on closed-form speed laws and synthetic discrete data (no solver involved)."""

from __future__ import annotations

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from shared import examples

from speedplan.model.boundary import max_jerk_envelope
from speedplan.model.grid import GRADING
from speedplan.timing import TimeLaw
from speedplan.timing.law import LawChain
from speedplan.timing.verify import TOLERANCES


def test_constant_speed_is_exact():
    s = np.linspace(0, 10, 21)
    law = TimeLaw(s, np.full(21, 4.0), accel_start=0.0, accel_end=0.0)
    assert law.duration == pytest.approx(5.0, rel=1e-13)
    t = np.array([0.0, 1.25, 5.0])
    assert law.position_at(t) == pytest.approx([0.0, 2.5, 10.0], rel=1e-12)
    _, v, a, j = law.kinematics(np.array([0.3, 7.7]))
    assert v == pytest.approx(2.0) and np.abs(a).max() < 1e-12 and np.abs(j).max() < 1e-12


def test_constant_acceleration_from_speed_is_exact():
    # w = v0² + 2 a s is linear: t = (v - v0) / a exactly, on a grid of arbitrary steps.
    s = np.sort(np.concatenate(([0.0, 8.0], np.random.default_rng(1).uniform(0, 8, 9))))
    w = 1.0 + 2 * 0.5 * s
    law = TimeLaw(s, w, accel_start=0.5, accel_end=0.5)
    assert law.duration == pytest.approx((3.0 - 1.0) / 0.5, rel=1e-12)
    _, _, a, j = law.kinematics(np.array([0.0, 4.0, 8.0]))
    assert a == pytest.approx(0.5, rel=1e-12) and np.abs(j).max() < 1e-12
    assert np.abs(law.node_offsets()).max() < 1e-12


@settings(max_examples=examples(20), deadline=None)
@given(j=st.floats(0.05, 20.0), length=st.floats(0.001, 5000.0))
def test_max_jerk_start_and_stop_are_reproduced(j, length):
    # A rest-to-rest move that is a max-jerk start followed by its mirror (jerk +j, then -j
    # then +j): u = w^(3/4) is linear near both ends, so the law follows the exact motion there
    # (up to the bend that anchors the w-region's node offsets: 1e-6 relative on this grid).
    s = np.linspace(0.0, length, 401)
    w = np.minimum(max_jerk_envelope(s, j), max_jerk_envelope(length - s, j))
    law = TimeLaw(s, w, j_max=j)
    lead, trail = law._regions
    assert lead > 0 and trail > 0
    d = s[: lead // 2]  # well inside the standstill region
    _, v, a, jerk = law.kinematics(d)
    t = (6 * d / j) ** (1 / 3)
    assert v == pytest.approx(j * t**2 / 2, rel=1e-5, abs=1e-15 * max(length, 1))
    assert a == pytest.approx(j * t, rel=1e-5, abs=1e-15 * max(length, 1))
    assert jerk == pytest.approx(np.full(d.size, j), rel=1e-4)
    assert law.kinematics(np.array([0.0, length]))[1] == pytest.approx([0.0, 0.0], abs=1e-300)


@pytest.mark.parametrize("shortfall", [2e-4, 4e-4, 8e-4])
def test_a_stop_slightly_under_the_max_jerk_motion_keeps_its_jerk(shortfall):
    # A discrete stop a little under the max-jerk motion, as on a capped grid whose last
    # jerk rows do not bind: w = K d^(4/3) (1 - c d) at distance d from rest. Its own jerk,
    # sqrt(w) w'' / 2, is j_max at the rest and less before it (closed form below), so the
    # law through its nodes must not exceed j_max beyond its grading. Built in w next to the
    # rest, the law cannot follow d^(4/3): the jerk rose 12-120 % above j_max there.
    j, h, nodes = 2.0, 1e-3, 60
    d = h * np.arange(nodes, -1, -1.0)
    c = shortfall / h
    w = max_jerk_envelope(d, j) * (1.0 - c * d)
    law = TimeLaw(d[0] - d, w, j_max=j)
    q = np.linspace(d[0] - 30 * h, d[0], 30_001)[:-1]  # the rest itself: 0 / 0 below
    jerk = law.kinematics(q)[3]
    k = (j**2 / 4) * (6 / j) ** (4 / 3)
    dq = d[0] - q
    exact = (np.sqrt(k * dq ** (4 / 3) * (1 - c * dq))
             * k * (4 / 9 * dq ** (-2 / 3) - c * 28 / 9 * dq ** (1 / 3)) / 2)
    assert exact.max() <= j * (1 + 1e-12)
    assert np.abs(jerk).max() <= j * (1 + GRADING)
    assert jerk == pytest.approx(exact, abs=0.02 * j)


@pytest.mark.parametrize("dip", [0.0, 0.16, 0.4])
@pytest.mark.parametrize("at", [3, 4, 10])
def test_a_stop_with_one_node_off_its_jerk_phase_keeps_its_jerk(dip, at):
    # A refined solution's stop of 2.4 µm: its discrete jerk sqrt(w) w'' / 2 is j_max at every
    # node of the final phase but one (a node `at` steps from the rest at `dip` j_max), after
    # a constant braking. The stop is still one jerk phase: built in w from that node on, the
    # law reached 1.16-2.2x j_max next to the rest with the node 3 or 4 steps from it (1.19x
    # on a 188 m comfort plan).
    j, h, nodes = 3.9, 4e-8, 120
    jd = np.where(np.arange(nodes + 1) <= 60, 1.0, 0.0)  # discrete jerk / j_max, from the rest
    jd[at] = dip
    w = np.zeros(nodes + 1)  # w[k] at k steps from the rest
    w[1] = float(max_jerk_envelope(np.array([h]), j)[0])
    for k in range(1, nodes):
        w[k + 1] = 2 * w[k] - w[k - 1] + h * h * 2 * jd[k] * j / np.sqrt(w[k])
    d = h * np.arange(nodes, -1, -1.0)
    law = TimeLaw(d[0] - d, w[::-1], j_max=j)
    assert law._regions[1] > 50
    q = np.linspace(d[0] - 30 * h, d[0], 30_001)[:-1]  # the rest itself: 0 / 0
    jerk = law.kinematics(q)[3]
    assert np.abs(jerk).max() <= j * (1 + TOLERANCES["jerk"])


def test_a_stop_softer_than_the_max_jerk_motion_keeps_its_jerk():
    # A refined stop of 0.15 µm whose discrete jerk falls from 0.66 j_max at the node next to
    # the rest to 0.07 j_max 80 nodes before it (as 1 / sqrt(k)), after a constant braking:
    # one node is near enough j_max to mark the stop's jerk phase. With only the last cell
    # built in u, the w-piece next to it took the law's jerk to 1.45x j_max (1.77x on a
    # 250 m comfort plan).
    j, h, nodes = 14.7, 2.5e-9, 160
    k = np.arange(nodes + 1)
    jd = np.where(k <= 80, 0.66 / np.sqrt(np.maximum(k, 1)), 0.0)  # from the rest
    w = np.zeros(nodes + 1)  # w[k] at k steps from the rest
    w[1] = 0.66 ** (2 / 3) * float(max_jerk_envelope(np.array([h]), j)[0])
    for i in range(1, nodes):
        w[i + 1] = 2 * w[i] - w[i - 1] + h * h * 2 * jd[i] * j / np.sqrt(w[i])
    d = h * k[::-1]
    law = TimeLaw(d[0] - d, w[::-1], j_max=j)
    q = np.linspace(d[0] - 30 * h, d[0], 30_001)[:-1]  # the rest itself: 0 / 0
    jerk = law.kinematics(q)[3]
    assert np.abs(jerk).max() <= j * (1 + TOLERANCES["jerk"])


def test_prescribed_end_accelerations_are_met_exactly():
    s = np.linspace(0, 5, 11)
    w = (1.0 + 0.1 * s) ** 2
    law = TimeLaw(s, w, accel_start=0.3, accel_end=-0.2)
    _, v, a, _ = law.kinematics(np.array([0.0, 5.0]))
    assert a == pytest.approx([0.3, -0.2], abs=1e-12)
    assert v == pytest.approx([1.0, 1.5], rel=1e-12)


def _abrupt_grid():
    # Steps that jump by 6x and back, as the old adaptive grid did at its node cap.
    h = np.concatenate((np.full(40, 0.01), np.full(30, 0.06), np.full(40, 0.01), np.full(50, 0.06)))
    return np.concatenate(([0.0], np.cumsum(h)))


def test_node_offsets_are_local_on_a_grid_with_abrupt_steps():
    # The trapezoid integration of midpoint slopes that main used drifted on such grids (a
    # 400 m move cruised 9.7 % above v_max). The dual-cell law's offset at node k is exactly
    # h_{k-1} h_k w''_k / 8 minus that of the first interior node (the local term telescopes).
    s = _abrupt_grid()
    w = 4.0 + np.sin(s) * 0.5  # curvature everywhere, so every step change could drift
    law = TimeLaw(s, w, accel_start=0.25 * np.cos(0.0), accel_end=0.25 * np.cos(s[-1]))
    h = np.diff(s)
    h0, h1 = h[:-1], h[1:]
    d2 = 2 * (w[:-2] / (h0 * (h0 + h1)) - w[1:-1] / (h0 * h1) + w[2:] / (h1 * (h0 + h1)))
    local = h0 * h1 * d2 / 8.0
    off = law.node_offsets()[1:-1]
    # Between the correction windows of the moving ends (20 cells each) they are the local
    # term exactly; in the windows they differ by the start's own local term, spread out.
    inner = slice(25, s.size - 25)
    assert np.abs(off[inner] - local[inner]).max() < 1e-13
    assert np.abs(off).max() < 2 * np.abs(local).max() + 1e-12
    assert law.node_offsets()[[0, -1]] == pytest.approx([0.0, 0.0], abs=1e-14)


def test_jerk_follows_the_discrete_rows_within_the_step_ratio():
    # w'' on each half dual cell is D2 h_k / h_{k-1} or D2 h_{k-1} / h_k: the law's jerk
    # exceeds the discrete jerk by at most the step ratio (and sqrt(w) inside the cell).
    rng = np.random.default_rng(3)
    h = 0.01 * np.exp(np.cumsum(rng.uniform(-GRADING, GRADING, 400)))
    s = np.concatenate(([0.0], np.cumsum(h)))
    w = 1.0 + 0.3 * np.sin(3 * s)
    law = TimeLaw(s, w, accel_start=0.45, accel_end=0.45 * np.cos(3 * s[-1]))
    hh = np.diff(s)
    h0, h1 = hh[:-1], hh[1:]
    d2 = 2 * (w[:-2] / (h0 * (h0 + h1)) - w[1:-1] / (h0 * h1) + w[2:] / (h1 * (h0 + h1)))
    discrete = np.abs(0.5 * d2 * np.sqrt(w[1:-1])).max()
    ex = law.extremes()
    realised = max(ex.jerk.maximum.max(), -ex.jerk.minimum.min())
    assert realised <= discrete * (1 + GRADING) * (1 + 1e-3)


def test_no_c1_interpolant_of_a_jerk_switch_stays_within_the_limit():
    # Why the law does not pass exactly through the nodes. Discrete data satisfying every
    # jerk row |D2| sqrt(w) <= 2 j: a cruise, then the braking jerk saturated from one node on.
    # Any C¹ curve through it with |w''| <= c (c = the limit's curvature) starting the cell
    # before the drop with zero slope can drop at most 0.914 c h² over the next cell (it may
    # first swing up and down: the best swing turns at h (1 - 1/√2)); the data drop c h².
    W, j, h = 225.0, 0.5, 0.4
    c = 2 * j / np.sqrt(W) * (1 - 1e-12)
    w = np.full(12, W)
    w[6] = W - c * h**2
    for k in range(7, 12):
        w[k] = 2 * w[k - 1] - w[k - 2] - c * h**2
    d2 = (w[:-2] - 2 * w[1:-1] + w[2:]) / h**2
    assert np.all(np.abs(d2) * np.sqrt(w[1:-1]) <= 2 * j * (1 + 1e-12))  # a valid solution
    tau = h * (1 - 1 / np.sqrt(2))
    slope = c * (2 * tau - h)  # the most negative slope at s_5 after a cell with equal ends
    best_drop = -slope * h + 0.5 * c * h**2
    assert best_drop == pytest.approx(0.914 * c * h**2, rel=1e-3)
    assert W - w[6] > best_drop * 1.09  # so any node-exact C¹ law needs > 1.09× the jerk
    # The dual-cell law stays within the limit instead (up to sqrt(w) in the cell) ...
    s = np.arange(12) * h
    law = TimeLaw(s, w, accel_start=0.0, accel_end=(w[-1] - w[-2]) / (2 * h))
    ex = law.extremes()
    assert max(ex.jerk.maximum.max(), -ex.jerk.minimum.min()) <= j * (1 + 1e-3)
    # ... at the price of a local node offset of at most h² |w''| / 8 (1e-6 relative here).
    assert np.abs(law.node_offsets()).max() <= h**2 * c / 8 * (1 + 1e-9) + 1e-12


def test_time_and_position_are_inverse_near_standstill():
    s = np.linspace(0, 3, 31)
    w = np.minimum(max_jerk_envelope(s, 0.5), max_jerk_envelope(3 - s, 0.5))
    law = TimeLaw(s, w, j_max=0.5)
    tt = np.linspace(0, law.duration, 2001)
    q = law.position_at(tt)
    assert np.all(np.diff(q) >= 0)
    assert q[0] == 0.0 and q[-1] == pytest.approx(3.0, abs=1e-12)
    inner = (tt > 1e-3) & (tt < law.duration - 1e-3)
    assert law.time_at(q[inner]) == pytest.approx(tt[inner], abs=1e-9)


def test_extremes_are_exact_maxima_of_each_piece():
    # Against dense sampling of the same law: the closed-form extremes bound every sample
    # and are attained (within sampling resolution).
    s = np.linspace(0, 4, 41)
    w = np.minimum(max_jerk_envelope(s, 0.5), max_jerk_envelope(4 - s, 0.5))
    w = np.minimum(w, 1.2)
    law = TimeLaw(s, w, j_max=0.5)
    ex = law.extremes()
    knots = law.knots
    frac = np.linspace(1e-9, 1 - 1e-9, 2001)  # inside each piece (a knot belongs to the next)
    q = knots[:-1, None] + np.diff(knots)[:, None] * frac[None, :]
    _, _, a, jerk = law.kinematics(q.ravel())
    a, jerk = a.reshape(q.shape), jerk.reshape(q.shape)
    for name, val in (("a", a), ("jerk", jerk)):
        top, bottom = getattr(ex, name).maximum, getattr(ex, name).minimum
        scale = np.abs(val).max()
        assert np.all(val.max(axis=1) <= top + 1e-12 * scale)
        assert np.all(val.min(axis=1) >= bottom - 1e-12 * scale)
        assert np.all(val.max(axis=1) >= top - 1e-3 * scale)  # u^(1/3) -> 0 at a stop


def test_chain_of_laws_meets_at_rest():
    s = np.linspace(0, 2, 41)
    w = np.minimum(max_jerk_envelope(s, 0.5), max_jerk_envelope(2 - s, 0.5))
    one = TimeLaw(s, w, j_max=0.5)
    chain = LawChain((one, one), np.array([0.0, 2.0]))
    assert chain.duration == pytest.approx(2 * one.duration, rel=1e-14)
    t = np.linspace(0, chain.duration, 101)
    q = chain.position_at(t)
    assert np.all(np.diff(q) >= -1e-15) and q[-1] == pytest.approx(4.0)
    assert chain.time_at(q) == pytest.approx(t, abs=1e-9)
    assert chain.kinematics(np.array([2.0]))[1] == pytest.approx([0.0], abs=1e-12)


def test_compiled_and_numpy_time_laws_agree():
    # The time law runs on numpy until numba is loaded (a fresh environment's first plan()),
    # then compiled: both give the same law to rounding, at standstills and moving ends too.
    from speedplan.core import _law_kernel
    from speedplan.timing import _law_numpy

    rng = np.random.default_rng(7)
    s = np.cumsum(rng.uniform(0.05, 0.15, 400))
    s -= s[0]
    cases = [
        # Max-jerk start, cruise, max-jerk stop: rest to rest, pieces in u and in w.
        TimeLaw(s, np.minimum(np.minimum(max_jerk_envelope(s, 0.5),
                                         max_jerk_envelope(s[-1] - s, 0.5)), 1.0), j_max=0.5),
        TimeLaw(s, 1.0 + np.sin(s) ** 2, accel_start=0.2, accel_end=-0.1),  # moving ends
    ]
    assert cases[0]._pieces.is_u.any()
    for law in cases:
        p = law._pieces
        m = p.c.size
        j = np.arange(m)
        right = (p.y_right <= 0.0) & (p.y[:-1] > 0.0)
        width = np.diff(p.x)
        args = (p, j, np.zeros(m), width, right)
        seg = (_law_kernel.integrals(*args), _law_numpy.integrals(*args))
        assert np.max(np.abs(seg[0] - seg[1]) / seg[1]) < 1e-13
        T = law.knot_times
        t = np.sort(rng.uniform(0.0, law.duration, 3000))
        k = np.clip(np.searchsorted(T, t, side="right") - 1, 0, m - 1)
        exact = law._exact_inverse
        (dx0, dr0), (dx1, dr1) = (_law_kernel.invert(p, T, k, t, exact),
                                  _law_numpy.invert(p, T, k, t, exact))
        assert np.max(np.abs(dx0 - dx1)) < 1e-13 * law.length
        assert np.max(np.abs(dr0 - dr1)) < 1e-13 * law.length
        dx = width[k] * rng.uniform(0.0, 1.0, k.size)
        for a, b in zip(_law_kernel.kinematics(p, k, dx, width[k] - dx),
                        _law_numpy.kinematics(p, k, dx, width[k] - dx), strict=True):
            assert np.max(np.abs(a - b)) <= 1e-13 * max(np.max(np.abs(b)), 1e-300)


@pytest.mark.parametrize("compiled", [True, False])
@pytest.mark.parametrize("seed", range(4))
def test_inversion_meets_its_time_tolerance(seed, compiled):
    # The inversion takes the closed-form offset on w-pieces moving at both ends (from the
    # knot nearer in time, where the rule gets their time to rounding) and skips the
    # integral that would confirm a Newton step when the step's predicted error is far
    # inside the tolerance: the times the offsets reach (the 16-point integral from the
    # piece's start, or its standstill end) must still be the requested ones to 1e-15 of the
    # piece's time, up to rounding. The last two laws move at both ends, but barely: in their
    # first and last pieces w grows 1e2-1e6 times, the rule is off there, and the closed
    # form would disagree with the knot times the rule placed (with w growing 1e8 times the
    # iteration itself no longer meets the tolerance: docs/failure-modes.md).
    from speedplan.core import _law_kernel
    from speedplan.timing import _law_numpy

    inverse = (_law_kernel if compiled else _law_numpy).invert

    rng = np.random.default_rng(seed)
    s = np.cumsum(rng.uniform(0.05, 0.15, 300) * 10 ** rng.uniform(-3, 3))
    s -= s[0]
    j_max = 10 ** rng.uniform(-2, 2)
    cap = 10 ** rng.uniform(-1, 1)
    envelope = np.minimum(np.minimum(max_jerk_envelope(s, j_max),
                                     max_jerk_envelope(s[-1] - s, j_max)), cap)
    laws = [
        TimeLaw(s, envelope, j_max=j_max),
        TimeLaw(s, cap * (1.0 + np.sin(s / s[-1] * 7.0) ** 2), accel_start=0.0,
                accel_end=0.0),
        TimeLaw(s, envelope + 1e-6 * cap, accel_start=0.0, accel_end=0.0),
        TimeLaw(s, envelope + 1e-4 * cap, accel_start=0.0, accel_end=0.0),
    ]
    for law in laws:
        p = law._pieces
        T = law.knot_times
        t = np.concatenate((np.arange(0.0, law.duration, law.duration / 5000),
                            rng.uniform(0.0, law.duration, 5000)))
        k = np.clip(np.searchsorted(T, t, side="right") - 1, 0, p.c.size - 1)
        dx, dr = inverse(p, T, k, t, law._exact_inverse)
        right = (p.y_right[k] <= 0.0) & (p.y[k] > 0.0)
        off = np.where(right, dr, dx)
        reached = _law_kernel.integrals(p, k, np.zeros(k.size), off, right)
        tau = np.where(right, T[k + 1] - t, t - T[k])
        span = T[k + 1] - T[k]
        slack = 4e-15 * span + 8 * np.spacing(np.maximum(T[k + 1], 1e-300))
        assert np.all(np.abs(reached - tau) <= slack)


@pytest.mark.parametrize("compiled", [True, False])
def test_closed_form_offsets_are_the_rules_inverse_to_a_few_ulps(compiled):
    # Where the offset is taken in closed form, it must be the rule's own inverse to the
    # last bits, measured from the knot nearer in time: there the offset keeps its relative
    # precision, next to a slow (not stopped) end too, where the left knot's value and
    # slope, carried across the piece, are off by the rounding of w's largest values.
    # Reference: the rule's time from that knot, inverted by bisection (scipy's brentq).
    from scipy.optimize import brentq

    from speedplan.core import _law_kernel
    from speedplan.timing import _law_numpy

    inverse = (_law_kernel if compiled else _law_numpy).invert
    rng = np.random.default_rng(0)
    s = np.concatenate(([0.0], np.cumsum(0.2 * 0.97 ** np.arange(200))))  # graded to the end
    s2 = np.cumsum(rng.uniform(0.05, 0.15, 300) * 10 ** rng.uniform(-3, 3))
    laws = [TimeLaw(s, 1e-6 + 4.0 * (1.0 - s / s[-1]) ** 2, accel_start=0.0),  # to 1 mm/s
            TimeLaw(s2 - s2[0], 3.0 * (1.0 + np.sin((s2 - s2[0]) / s2[-1] * 7.0) ** 2),
                    accel_start=0.0, accel_end=0.0)]
    for law in laws:
        p, T, exact = law._pieces, law.knot_times, law._exact_inverse
        k = np.concatenate((np.flatnonzero(exact)[-30:], rng.choice(np.flatnonzero(exact), 70)))
        span = T[k + 1] - T[k]
        half = 0.5 * span * rng.uniform(0.0, 1.0, k.size) ** 3  # many next to a knot
        from_left = rng.uniform(size=k.size) < 0.5
        t = np.where(from_left, T[k] + half, T[k + 1] - half)
        dx, dr = inverse(p, T, k, t, exact)
        for i in range(k.size):
            goal = t[i] - T[k[i]] if from_left[i] else T[k[i] + 1] - t[i]
            here = np.array([from_left[i] == 0])

            def missed(d, piece=k[i:i + 1], goal=goal, here=here, p=p):
                return _law_kernel.integrals(p, piece, np.zeros(1), np.array([d]), here)[0] - goal

            ref = brentq(missed, 0.0, p.x[k[i] + 1] - p.x[k[i]], xtol=1e-300, rtol=9e-16)
            got = dx[i] if from_left[i] else dr[i]
            assert abs(got - ref) <= 2e-15 * ref, (i, got, ref)
