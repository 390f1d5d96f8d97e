"""The kinematics evaluator and the typed verification records, against closed forms.

Oracles independent of the code under test: a constant-radius arc (``a_lat = v²/R``, yaw rate
``v/R``), a clothoid ``κ = c s`` at constant speed (``j_lat = c v³``), and finite differences
of a trajectory sampled in time.
"""

from __future__ import annotations

import pickle

import numpy as np
import pytest

from speedplan import Limits, Path, plan
from speedplan.core import kinematics
from speedplan.geometry import Arc, Clothoid, Line
from speedplan.timing import LimitCheck, PieceExtremes, TimeLaw, Verification
from speedplan.timing.verify import LIMIT_NAMES, TOLERANCES, curvature_rate

RNG = np.random.default_rng(7)


# --- the evaluator, closed forms ----------------------------------------------------------------


@pytest.mark.parametrize("radius", [0.5, 4.0, 120.0])
def test_an_arc_at_constant_speed(radius):
    v = RNG.uniform(0.1, 5.0, 50)
    kappa = np.full(v.shape, 1.0 / radius)
    np.testing.assert_allclose(kinematics.lateral_acceleration(kappa, v * v), v**2 / radius,
                               rtol=1e-15)
    np.testing.assert_allclose(kinematics.yaw_rate(kappa, v), v / radius, rtol=1e-15)
    # No change of curvature nor of speed: no lateral jerk.
    assert np.all(kinematics.lateral_jerk(kappa, 0.0, v * v, 0.0) == 0.0)


def test_a_clothoid_at_constant_speed():
    # κ = c s: a_lat = c s v² grows at c v² per metre, so at c v³ per second.
    c, v = 0.07, RNG.uniform(0.1, 5.0, 50)
    s = RNG.uniform(0.0, 30.0, 50)
    np.testing.assert_allclose(kinematics.lateral_jerk(c * s, c, v * v, 0.0), c * v**3,
                               rtol=1e-14)
    np.testing.assert_allclose(kinematics.lateral_acceleration_rate(c * s, c, v * v, 0.0),
                               c * v**2, rtol=1e-14)


def test_lateral_jerk_is_the_time_derivative_of_lateral_acceleration():
    # A made-up motion: κ(s) = sin(s)/3, constant acceleration a from v0; d(κ v²)/dt by
    # central differences in time against v (κ' w + 2 κ a).
    a, v0 = 0.4, 1.5
    t = np.linspace(0.0, 4.0, 4001)
    s, v = v0 * t + 0.5 * a * t * t, v0 + a * t

    def a_lat(tt):
        ss, vv = v0 * tt + 0.5 * a * tt * tt, v0 + a * tt
        return kinematics.lateral_acceleration(np.sin(ss) / 3.0, vv * vv)

    step = 1e-5
    fd = (a_lat(t + step) - a_lat(t - step)) / (2 * step)
    got = kinematics.lateral_jerk(np.sin(s) / 3.0, np.cos(s) / 3.0, v * v, a)
    np.testing.assert_allclose(got, fd, atol=1e-8)
    # The speed the caller passes is used as given (the law's own).
    assert np.array_equal(kinematics.lateral_jerk(np.sin(s) / 3.0, np.cos(s) / 3.0, v * v, a,
                                                  v), got)


def test_lateral_acceleration_rate_times_speed_is_the_lateral_jerk():
    # What the model's rows hold (per metre, linear in w and w') against the jerk: w' = 2 a.
    kappa, rate = RNG.normal(size=20), RNG.normal(size=20)
    w, a = RNG.uniform(0.0, 9.0, 20), RNG.normal(size=20)
    np.testing.assert_allclose(
        np.sqrt(w) * kinematics.lateral_acceleration_rate(kappa, rate, w, 2.0 * a),
        kinematics.lateral_jerk(kappa, rate, w, a), rtol=1e-12, atol=1e-14)


def test_the_row_weights_reproduce_the_lateral_rate_of_a_quadratic_law():
    # Three nodes of a quadratic w(s): the three-point difference is exact for it, and so the
    # weights give κ' w + κ w' at the middle node; the chord's at the cell midpoints.
    s = np.array([0.0, 0.3, 0.8])
    w = 1.0 + 2.0 * s - 1.5 * s * s
    h0, h1 = np.diff(s)
    first = np.array([-h1 / (h0 * (h0 + h1)), (h1 - h0) / (h0 * h1), h0 / (h1 * (h0 + h1))])
    kappa, rate = 0.4, -0.2
    weights = kinematics.lateral_rate_weights(np.array([kappa]), np.array([rate]),
                                              [0.0, 1.0, 0.0], first)
    exact = rate * w[1] + kappa * (2.0 - 3.0 * s[1])
    assert float((weights @ w)[0]) == pytest.approx(exact, rel=1e-13)
    assert float(kinematics.lateral_jerk_from_slope(kappa, rate, w[1], 2.0 - 3.0 * s[1])) == \
        pytest.approx(np.sqrt(w[1]) * exact, rel=1e-13)


def test_speed_acceleration_and_friction_ellipse():
    assert kinematics.speed(np.array([9.0, -1e-20])).tolist() == [3.0, 0.0]
    assert kinematics.acceleration(np.array([3.0])).tolist() == [1.5]
    # On the ellipse (cos, sin) times the semi-axes; braking uses a_decel.
    theta = np.linspace(-np.pi, np.pi, 41)
    a = np.where(np.cos(theta) >= 0, 1.5, 2.5) * np.cos(theta)
    radius = kinematics.friction_ellipse(a, 0.8 * np.sin(theta), 1.5, 2.5, 0.8)
    np.testing.assert_allclose(radius, 1.0, rtol=1e-15)


# --- the evaluator in a plan: the path's exact curvature rate ----------------------------------


def _clothoid_path():
    return Path.from_segments([Line(4.0), Clothoid(6.0, 0.0, 0.3), Arc(1 / 0.3, 0.8),
                               Clothoid(6.0, 0.3, 0.0), Line(4.0)])


def test_the_curvature_rate_of_verification_is_the_paths_exact_one():
    path = _clothoid_path()
    s = np.linspace(0.0, path.length, 997)
    exact = np.where((s > 4.0) & (s < 10.0), 0.05, 0.0)
    exact[(s > 10.0 + 0.8 / 0.3) & (s < 16.0 + 0.8 / 0.3)] = -0.05
    np.testing.assert_allclose(curvature_rate(path, s), exact, atol=1e-12)


def test_a_curvature_jump_is_a_dirac_of_the_rate():
    # A G1 path (line onto an arc of radius 4): the jump 0.25 / m over 2 δ, δ = 1e-7 length.
    path = Path.from_segments([Line(2.0), Arc(radius=4.0, angle=1.0)])
    delta = 1e-7 * path.length
    got = curvature_rate(path, np.array([1.0, 2.0, 3.0]))
    assert got[0] == 0.0 and got[2] == 0.0
    assert got[1] == pytest.approx(0.25 / (2 * delta), rel=1e-6)


def test_sampled_lateral_quantities_match_finite_differences():
    path = _clothoid_path()
    lim = Limits(v_max=3.0, a_max=1.0, a_lat_max=1.0, j_max=0.5, j_lat_max=0.4)
    prof = plan(path, lim)
    traj = prof.sample(1e-3)
    v = traj.v
    np.testing.assert_allclose(traj.a_lat, traj.curvature * v * v, rtol=1e-12, atol=1e-15)
    np.testing.assert_allclose(traj.yaw_rate, traj.curvature * v, rtol=1e-12, atol=1e-15)
    dt = np.diff(traj.t)
    mid = 0.5 * (traj.j_lat[1:] + traj.j_lat[:-1])
    fd = np.diff(traj.a_lat) / dt
    # Away from the joins of pieces, where κ' jumps (and so does j_lat).
    s_mid = 0.5 * (traj.s[1:] + traj.s[:-1])
    far = np.min(np.abs(s_mid[:, None] - path.offsets[None, :]), axis=1) > 0.05
    assert far.sum() > 0.8 * far.size
    np.testing.assert_allclose(fd[far], mid[far], atol=2e-3 * lim.j_lat_max)
    yaw_fd = np.diff(traj.heading) / dt
    np.testing.assert_allclose(yaw_fd, 0.5 * (traj.yaw_rate[1:] + traj.yaw_rate[:-1]),
                               atol=1e-4)


def test_verification_agrees_with_the_sampled_trajectory():
    path = _clothoid_path()
    lim = Limits(v_max=3.0, a_max=1.0, a_lat_max=1.0, j_max=0.5, j_lat_max=0.4,
                 yaw_rate_max=0.5)
    prof = plan(path, lim)
    check = prof.verify()
    traj = prof.sample(1e-3)
    # The check evaluates at least where the samples do (and at the pieces' extremes).
    for name, column in (("lateral", traj.a_lat), ("yaw_rate", traj.yaw_rate),
                         ("lateral_jerk", traj.j_lat)):
        record = check.checks[name]
        assert np.abs(column).max() <= record.maximum * (1 + 1e-3) + 1e-12
        assert record.ratio == pytest.approx(record.maximum / record.limit, rel=1e-12)


# --- the typed records -------------------------------------------------------------------------


def _plan_check():
    lim = Limits(v_max=2.0, a_max=1.0, a_lat_max=1.0, j_max=0.5)
    return plan(Path.from_waypoints([[0, 0], [10, 0], [10, 8]]), lim).verify(), lim


def test_each_limit_has_its_record_and_the_maps_are_views_of_them():
    check, lim = _plan_check()
    assert tuple(check.checks) == LIMIT_NAMES[:8]
    for name, record in check.checks.items():
        assert isinstance(record, LimitCheck) and record.name == name
        assert check.ratios[name] == record.ratio and check.maxima[name] == record.maximum
        assert check.where[name] == record.where_s
        assert record.tolerance == TOLERANCES[name]
        assert (name in check.unset) == record.unset == (not np.isfinite(record.limit))
    assert check.checks["jerk"].limit == lim.j_max
    assert check.checks["accel"].ratio == pytest.approx(check.max_accel / lim.a_max)
    assert check.unset == {"yaw_rate", "lateral_jerk", "grip"}
    assert check.ok and not check.violations


def test_records_are_read_only():
    check, _ = _plan_check()
    with pytest.raises(AttributeError):
        check.checks["jerk"].ratio = 2.0  # type: ignore[misc]
    with pytest.raises(AttributeError):
        check.checks = {}  # type: ignore[misc]
    check.ratios["jerk"] = 9.0  # a copy: the record stays
    assert check.checks["jerk"].ratio < 9.0


def test_a_violation_is_the_record_beyond_its_tolerance():
    at_edge = LimitCheck("jerk", ratio=1.05, maximum=0.525, limit=0.5, where_s=1.0)
    beyond = LimitCheck("lateral", ratio=1.0101, maximum=1.0101, limit=1.0, where_s=2.0)
    nan = LimitCheck("speed", ratio=float("nan"))
    check = Verification([at_edge, beyond, nan])
    assert not at_edge.exceeded and beyond.exceeded and nan.exceeded
    assert set(check.violations) == {"lateral", "speed"} and not check.ok
    lines = check.summary().splitlines()
    assert lines[1].endswith("VIOLATED") and "at s=2 m" in lines[1]
    assert lines[0].startswith("jerk") and "VIOLATED" not in lines[0]


def test_the_maps_build_records_too():
    check = Verification(maxima={"jerk": 0.5}, ratios={"jerk": 1.0, "speed": 0.5},
                         where={"jerk": 3.0}, unset={"speed"})
    assert check.checks["jerk"] == LimitCheck("jerk", ratio=1.0, maximum=0.5, where_s=3.0)
    assert check.checks["speed"].unset and check.checks["speed"].maximum is None
    assert check.maxima == {"jerk": 0.5} and check.where == {"jerk": 3.0}
    assert check.summary().splitlines()[1] == "speed         not set"


def test_merging_keeps_the_worst_record_of_each_limit():
    a = Verification([LimitCheck("jerk", ratio=0.9, maximum=0.45, limit=0.5, where_s=1.0),
                      LimitCheck("yaw_rate", ratio=0.0, maximum=0.1, limit=np.inf,
                                 where_s=1.0, unset=True)])
    b = Verification([LimitCheck("jerk", ratio=1.2, maximum=0.6, limit=0.5, where_s=7.0),
                      LimitCheck("yaw_rate", ratio=0.0, maximum=0.3, limit=np.inf,
                                 where_s=2.0, unset=True),
                      LimitCheck("yaw_acc", ratio=0.5, maximum=0.2, limit=0.4, where_s=7.0)])
    both = Verification.merged([a, b])
    assert list(both.checks) == ["jerk", "yaw_rate", "yaw_acc"]
    assert both.checks["jerk"] == b.checks["jerk"]
    assert both.maxima["yaw_rate"] == 0.3 and both.unset == {"yaw_rate"}
    assert both.checks["yaw_acc"] == b.checks["yaw_acc"]  # checked by one part only
    # A limit not set in one part but checked in another is set.
    c = Verification([LimitCheck("yaw_rate", ratio=0.2, maximum=0.2, limit=1.0, where_s=0.0)])
    assert Verification.merged([a, c]).unset == frozenset()


def test_the_extremes_of_a_law_are_a_typed_record():
    s = np.linspace(0.0, 2.0, 11)
    law = TimeLaw(s, 1.0 + 0.5 * s * (2.0 - s), accel_start=0.5, accel_end=-0.5)
    ex = law.extremes()
    assert isinstance(ex, PieceExtremes)
    pieces = law.knots.size - 1
    for quantity in ex:
        assert quantity.at.shape == quantity.maximum.shape == quantity.minimum.shape
        assert quantity.maximum.shape == (pieces,)
        assert np.all(quantity.maximum >= quantity.minimum)
    # w = 1 + s (2 - s) / 2: its maximum 1.5 at s = 1, acceleration w'/2 = (1 - s) / 2.
    k = int(np.argmax(ex.w.maximum))
    assert ex.w.maximum[k] == pytest.approx(1.5, rel=1e-3)
    assert ex.w.at[k] == pytest.approx(1.0, abs=0.1)
    assert ex.a.maximum.max() == pytest.approx(0.5, rel=0.05)
    assert ex.a.minimum.min() == pytest.approx(-0.5, rel=0.05)


def test_a_verification_survives_pickling():
    # plan_many sends profiles, their verification included, between processes.
    check, _ = _plan_check()
    again = pickle.loads(pickle.dumps(check))
    assert again == check and again.summary() == check.summary()
