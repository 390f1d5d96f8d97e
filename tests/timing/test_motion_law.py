"""`MotionLaw`: a motion of constant-jerk phases, evaluated in time and in arc length.

Judged against the motion's own definition (constant jerk per phase, integrated by finite
differences of dense samples) and against itself across evaluations (time -> position ->
time), never against its own extremes.
"""

from __future__ import annotations

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from speedplan.model.straight import straight_motion
from speedplan.timing.motion_law import MotionLaw

MOTIONS = st.builds(
    lambda L, v0, vf, top, a, d, j: straight_motion(10**L, v0 * 10**top, vf * 10**top,
                                                    10**top, 10**a, 10**d, 10**j),
    st.floats(-3, 5), st.floats(0, 1), st.floats(0, 1), st.floats(-1.3, 1.5),
    st.floats(-1.3, 0.7), st.floats(-1.3, 0.7), st.floats(-1.7, 1.7))


@settings(max_examples=60, deadline=None)
@given(motion=MOTIONS)
def test_times_and_positions_invert_each_other(motion):
    if motion is None:
        return
    law = MotionLaw(motion)
    t = np.linspace(0.0, law.duration, 2001)
    s = law.position_at(t)
    assert np.all(np.diff(s) >= 0) and s[0] == 0.0
    assert s[-1] == pytest.approx(law.length, rel=1e-12)
    # t(s(t)) = t wherever the vehicle moves (at rest a position has many times).
    _, _, v, _, _ = law.state_at(t)
    moving = v > 1e-6 * np.max(v)
    back = law.time_at(s)
    scale = law.length / max(np.max(v), 1e-300)  # a time's rounding through a position
    assert np.abs(back - t)[moving].max() <= 1e-9 * scale + 1e-12 * law.duration
    # Kinematics at a position are those at its time.
    _, vq, aq, _ = law.kinematics(s)
    _, _, v_t, a_t, _ = law.state_at(t)
    top_a = max(np.abs(a_t).max(), 1e-300)
    assert np.abs(vq - v_t)[moving].max() <= 1e-7 * np.max(v)
    assert np.abs(aq - a_t)[moving].max() <= 1e-6 * top_a


@settings(max_examples=40, deadline=None)
@given(motion=MOTIONS)
def test_the_sampled_motion_is_continuous_and_its_jerk_is_the_phases(motion):
    if motion is None:
        return
    law = MotionLaw(motion)
    T = law.duration
    t = np.linspace(0.0, T, 20001)
    s, _, v, a, j = law.state_at(t)
    dt = t[1] - t[0]
    # Speed and acceleration are what differences of position and speed say, to the
    # truncation error of the trapezoid rule (|j| dt² / 12 for the position; for the speed,
    # a switch of the jerk by at most 2 j inside a step leaves |Δj| dt / 8) and rounding.
    jmax = float(np.abs(motion.jerk).max())
    ulp = 8 * np.finfo(float).eps
    assert np.abs(np.diff(s) / dt - 0.5 * (v[1:] + v[:-1])).max() <= (
        jmax * dt**2 / 12 + ulp * (law.length + v.max() * T) / dt)
    assert np.abs(np.diff(v) / dt - 0.5 * (a[1:] + a[:-1])).max() <= (
        0.25 * jmax * dt + ulp * (v.max() + np.abs(a).max() * T) / dt)
    # The jerk column is the phase's, and no difference of a exceeds it.
    assert set(np.unique(j)) <= set(motion.jerk.tolist())
    assert np.abs(np.diff(a) / dt).max() <= jmax * (1 + 1e-9) + ulp * (
        np.abs(a).max() + jmax * T) / dt


@settings(max_examples=40, deadline=None)
@given(motion=MOTIONS)
def test_piece_extremes_bound_dense_samples_and_are_reached(motion):
    if motion is None:
        return
    law = MotionLaw(motion)
    ex = law.extremes()
    knots = law.knots
    for k in range(knots.size - 1):
        ts = np.linspace(law.node_times[k], law.node_times[k + 1], 201)
        _, w, _, a, _ = law.state_at(ts)
        top_w, top_a = max(w.max(), 1e-300), max(np.abs(a).max(), 1e-300)
        assert w.max() <= ex.w.maximum[k] * (1 + 1e-12) + 1e-15
        assert w.max() >= ex.w.maximum[k] - 1e-6 * top_w  # reached (to the sampling)
        assert a.max() <= ex.a.maximum[k] + 1e-12 * top_a
        assert a.min() >= ex.a.minimum[k] - 1e-12 * top_a


def test_the_double_s_move_of_a_known_example():
    # 30 m, v_max 2, a_max 1, j_max 0.5 from rest: 4 s to 2 m/s, 11 s cruise, 4 s to stop.
    law = MotionLaw(straight_motion(30.0, 0.0, 0.0, 2.0, 1.0, 1.0, 0.5))
    assert law.duration == pytest.approx(19.0, rel=1e-15)
    s, _, v, a, _ = law.state_at(np.array([1.0, 2.0, 4.0, 9.5, 17.0, 19.0]))
    np.testing.assert_allclose(s, [0.5 / 6, 2 / 3, 4.0, 15.0, 30 - 2 / 3, 30.0], rtol=1e-14)
    np.testing.assert_allclose(v, [0.25, 1.0, 2.0, 2.0, 1.0, 0.0], atol=1e-14)
    np.testing.assert_allclose(a, [0.5, 1.0, 0.0, 0.0, -1.0, 0.0], atol=1e-14)
