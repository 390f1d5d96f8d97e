"""verify() catches what lies between its samples: structure, not density.

A narrow dip of the speed bound between two sample points of a law piece is found through the
bound's breakpoints (:func:`speedplan.timing.verify.bound_breakpoints`); a jerk extreme inside
a piece through the law's exact per-piece extremes.
"""

from __future__ import annotations

from dataclasses import replace

import numpy as np
import pytest

import speedplan as sp
from speedplan.geometry import SpanLimit, SpeedBound
from speedplan.timing import TimeLaw
from speedplan.timing.verify import SAMPLES_PER_PIECE, TOLERANCES, bound_breakpoints, check_law

LIMITS = sp.Limits(v_max=2.0, a_max=1.0, a_lat_max=1.0, j_max=0.5)


@pytest.fixture(scope="module")
def straight():
    path = sp.Path.from_waypoints([[0, 0], [30, 0]], kind="polyline")
    return path, sp.plan(path, LIMITS)


def _cruise_piece(prof):
    """A law piece in the middle of the 30 m straight, where the optimum cruises at v_max."""
    law = prof.legs[0].law
    k = int(np.searchsorted(law.knots, 15.0))
    return law, law.knots[k], law.knots[k + 1] - law.knots[k]


def test_a_narrow_dip_of_the_speed_bound_between_samples_is_caught(straight):
    path, prof = straight
    assert prof.verify().ok
    law, x0, width = _cruise_piece(prof)
    samples = x0 + width * np.linspace(0.0, 1.0, SAMPLES_PER_PIECE)
    centre = x0 + 0.375 * width  # between the second and third sample
    half = 0.05 * width
    v_limit = ([0.0, centre - half, centre, centre + half, path.length],
               [5.0, 5.0, 1.0, 5.0, 5.0])
    dipped = replace(prof, speed_bound=SpeedBound(path, LIMITS, v_limit=v_limit),
                     verification=None)
    # The dip is invisible at the samples of its piece: the bound there is v_max² ...
    assert np.array_equal(dipped.speed_bound(samples), np.full(samples.size, 4.0))
    # ... and the vehicle cruises at v_max = 2 m/s there (rest-to-rest optimum on 30 m:
    # 4 s of jerk-limited acceleration over 4 m, 22 m of cruise, 4 m to stop).
    check = dipped.verify()
    assert not check.ok and "speed" in check.violations
    assert check.ratios["speed"] == pytest.approx(2.0 / 1.0, rel=1e-6)
    assert check.where["speed"] == pytest.approx(centre, abs=1e-9)
    # The piece with the dip is the one marked for grid refinement.
    leg_check = dipped.check_leg(0)
    assert leg_check.excess[np.searchsorted(law.knots, centre) - 1]
    assert leg_check.excess.sum() == 1


def test_a_speed_zone_shorter_than_a_piece_is_caught(straight):
    shapely = pytest.importorskip("shapely")
    path, prof = straight
    _, x0, width = _cruise_piece(prof)
    lo, hi = x0 + 0.3 * width, x0 + 0.45 * width  # between the second and third sample
    zone = sp.SpeedZone(shapely.box(lo, -1.0, hi, 1.0), 0.5)
    zoned = replace(prof, speed_bound=SpeedBound(path, LIMITS, zones=[zone]), verification=None)
    samples = x0 + width * np.linspace(0.0, 1.0, SAMPLES_PER_PIECE)
    assert np.array_equal(zoned.speed_bound(samples), np.full(samples.size, 4.0))
    check = zoned.verify()
    assert check.ratios["speed"] == pytest.approx(2.0 / 0.5, rel=1e-6)
    assert lo - 1e-6 <= check.where["speed"] <= hi + 1e-6


def test_a_span_shorter_than_a_piece_is_caught(straight):
    path, prof = straight
    _, x0, width = _cruise_piece(prof)
    lo, hi = x0 + 0.3 * width, x0 + 0.45 * width  # between the second and third sample
    spanned = replace(prof, speed_bound=SpeedBound(path, LIMITS, spans=(SpanLimit(lo, hi, 0.8),)),
                      verification=None)
    samples = x0 + width * np.linspace(0.0, 1.0, SAMPLES_PER_PIECE)
    assert np.array_equal(spanned.speed_bound(samples), np.full(samples.size, 4.0))
    check = spanned.verify()
    assert check.ratios["speed"] == pytest.approx(2.0 / 0.8, rel=1e-6)
    assert check.where["speed"] in (pytest.approx(lo, abs=1e-12), pytest.approx(hi, abs=1e-12))


def test_breakpoints_of_a_bound_read_from_an_offset():
    # A leg's bound reads the path from its start: its breakpoints are in path arc length.
    path = sp.Path.from_waypoints([[0, 0], [30, 0]], kind="polyline")
    bound = SpeedBound(path, LIMITS, v_limit=([5.0, 7.0], [2.0, 1.0]),
                       spans=(SpanLimit(10.0, 12.0, 1.0),))
    assert bound_breakpoints(path, bound).tolist() == [5.0, 7.0, 10.0, 12.0]
    assert bound_breakpoints(path, bound.at_offset(4.0)).tolist() == [1.0, 3.0, 6.0, 8.0]
    assert bound_breakpoints(path, lambda q: np.full(np.shape(q), 4.0)).size == 0


def test_a_jerk_extreme_inside_a_piece_is_caught():
    # A coarse hand-made law: on its piece 6 (a u-piece, where the jerk is quadratic in the
    # offset) the jerk peaks between the sample points, 11 % above the largest of them.
    w = np.array([0.0, 0.5, 2.0, 0.1, 2.0, 0.5, 0.0])
    s = np.arange(w.size, dtype=np.float64)
    law = TimeLaw(s, w)
    knots = law.knots
    # The oracle: the law evaluated densely, 4 000 points per piece.
    frac = np.linspace(0.0, 1.0, 4001)
    dense = (knots[:-1, None] + np.diff(knots)[:, None] * frac[None, :]).ravel()
    jerk = np.abs(law.kinematics(dense)[3]).reshape(knots.size - 1, -1)
    sampled = jerk[:, :: 4000 // (SAMPLES_PER_PIECE - 1)].max(axis=1)
    piece = int(np.argmax(jerk.max(axis=1) / np.maximum(sampled, 1e-300)))
    inner = jerk[piece].max()
    assert inner > 1.1 * sampled[piece]
    # A jerk limit that the samples of that piece respect (within tolerance) but its interior
    # peak exceeds.
    j_max = inner / 1.08
    assert sampled[piece] <= j_max * (1 + TOLERANCES["jerk"]) < inner
    path = sp.Path.from_waypoints([[0, 0], [s[-1], 0]], kind="polyline")
    limits = sp.Limits(v_max=10.0, a_max=100.0, a_lat_max=1.0, j_max=j_max)
    check = check_law(law, 0.0, path, lambda q: np.full(np.shape(q), 100.0), limits)
    assert check.verification.maxima["jerk"] >= jerk.max() * (1 - 1e-9)
    assert "jerk" in check.verification.violations
    assert check.excess[piece]
