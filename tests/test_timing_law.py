"""The time law on closed-form speed laws (no solver involved)."""

from __future__ import annotations

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from speedplan.model.boundary import max_jerk_envelope
from speedplan.timing import TimeLaw


def test_constant_speed_is_exact():
    s = np.linspace(0, 10, 21)
    law = TimeLaw(s, np.full(21, 4.0))
    assert law.duration == pytest.approx(5.0, rel=1e-13)
    t = np.array([0.0, 1.25, 5.0])
    assert law.position_at(t) == pytest.approx([0.0, 2.5, 10.0], rel=1e-12)
    _, v, a, j = law.kinematics(np.array([0.3, 7.7]))
    assert v == pytest.approx(2.0) and np.abs(a).max() < 1e-12 and np.abs(j).max() < 1e-12


def test_constant_acceleration_from_speed_is_exact_with_w_interpolation():
    # w = v0² + 2 a s is linear: t = (v - v0) / a exactly.
    s = np.linspace(0, 8, 9)
    w = 1.0 + 2 * 0.5 * s
    law = TimeLaw(s, w, p=1.0)
    assert law.duration == pytest.approx((3.0 - 1.0) / 0.5, rel=1e-12)
    _, _, a, _ = law.kinematics(np.array([0.0, 4.0, 8.0]))
    assert a == pytest.approx(0.5, rel=1e-12)


@settings(max_examples=20, deadline=None)
@given(j=st.floats(0.05, 20.0), length=st.floats(0.1, 50.0))
def test_max_jerk_start_reproduced_exactly(j, length):
    # From rest with jerk j: s = j t³/6, v = j t²/2, a = j t. u = w^(3/4) is linear in s,
    # so the interpolant reproduces it exactly on any grid.
    s = np.sort(np.concatenate(([0.0, length], np.random.default_rng(0).uniform(0, length, 7))))
    law = TimeLaw(s, max_jerk_envelope(s, j))
    t_end = (6 * length / j) ** (1 / 3)
    assert law.duration == pytest.approx(t_end, rel=1e-10)
    tt = np.linspace(0, t_end, 11)
    q = law.position_at(tt)
    assert q == pytest.approx(j * tt**3 / 6, rel=1e-9, abs=1e-12 * length)
    _, v, a, jerk = law.kinematics(q)
    assert v == pytest.approx(j * tt**2 / 2, rel=1e-8, abs=1e-12)
    assert a == pytest.approx(j * tt, rel=1e-8, abs=1e-12)
    assert jerk == pytest.approx(np.full(11, j), rel=1e-8)


def test_prescribed_end_accelerations_are_met_exactly():
    s = np.linspace(0, 5, 11)
    w = (1.0 + 0.1 * s) ** 2
    law = TimeLaw(s, w, accel_start=0.3, accel_end=-0.2)
    _, _, a, _ = law.kinematics(np.array([0.0, 5.0]))
    assert a == pytest.approx([0.3, -0.2], abs=1e-12)
    _, v, _, _ = law.kinematics(np.array([0.0, 5.0]))
    assert v == pytest.approx([1.0, 1.5], rel=1e-12)


def test_time_and_position_are_inverse_near_standstill():
    s = np.linspace(0, 3, 31)
    w = np.minimum(max_jerk_envelope(s, 0.5), max_jerk_envelope(3 - s, 0.5))
    law = TimeLaw(s, w)
    tt = np.linspace(0, law.duration, 2001)
    q = law.position_at(tt)
    assert np.all(np.diff(q) >= 0)
    assert q[0] == 0.0 and q[-1] == pytest.approx(3.0, abs=1e-12)
    # Near the stop, s is resolved to ~1e-15 m while v -> 0: the time error ds/v is bounded by
    # float resolution, ~3e-10 s at 3 ms before the stop.
    inner = (tt > 1e-3) & (tt < law.duration - 1e-3)
    assert law.time_at(q[inner]) == pytest.approx(tt[inner], abs=1e-9)
