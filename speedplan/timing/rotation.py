"""Turning on the spot: minimum-time rest-to-rest rotations within yaw limits.

A vehicle standing still (v = 0) turns its heading by ``angle`` [rad]: the yaw rate rises to
``rate_max`` (or less, on a short turn), cruises, and falls back to 0, the yaw acceleration
within ``acc_max`` and, if given, its rate of change within ``jerk_max``. Without a jerk
limit that is the trapezoidal (or triangular) yaw-rate profile, the time-optimal one for a
double integrator with bounded speed and acceleration, whose yaw acceleration steps between
``±acc_max`` and 0; with one, the seven-phase S-curve, the time-optimal rest-to-rest motion of
a triple integrator, whose yaw acceleration is continuous.
"""

from __future__ import annotations

from dataclasses import dataclass
from functools import cached_property

import numpy as np

from ..core.checks import FloatArray, as_array, as_scalar

__all__ = ["Turn"]


def _ramp_angle(peak: float, acc: float, jerk: float) -> float:
    """Angle [rad] turned while the yaw rate rises from 0 to ``peak`` (and as much to stop)."""
    if not np.isfinite(jerk):
        return 0.5 * peak * peak / acc
    if peak >= acc * acc / jerk:  # the acceleration reaches acc and holds it
        return 0.5 * peak * (peak / acc + acc / jerk)
    return peak * float(np.sqrt(peak / jerk))


def _peak_rate(angle: float, rate: float, acc: float, jerk: float) -> float:
    """Largest yaw rate [rad/s] of the fastest turn by ``angle``.

    ``rate`` if there is room to reach it, else the rate whose speed-up and slow-down cover
    the angle.
    """
    if 2.0 * _ramp_angle(rate, acc, jerk) <= angle:
        return rate
    if not np.isfinite(jerk):
        return float(np.sqrt(angle * acc))
    c = acc * acc / jerk
    held = 0.5 * (-c + float(np.sqrt(c * c + 4.0 * acc * angle)))
    if held >= c:
        return held
    return float(np.cbrt(0.25 * angle * angle * jerk))


@dataclass(frozen=True)
class Turn:
    """A rest-to-rest turn on the spot from ``start`` by ``angle``.

    Parameters
    ----------
    start : float
        Heading at the start of the turn [rad] (continuous: any real number).
    angle : float
        Signed heading change [rad] (positive: counter-clockwise).
    rate_max : float
        Yaw-rate limit [rad/s], > 0; ``inf`` for none (the yaw acceleration alone then bounds
        the turn).
    acc_max : float
        Yaw-acceleration limit [rad/s²], > 0 and finite.
    jerk_max : float, optional
        Limit on the rate of change of the yaw acceleration [rad/s³], > 0; ``inf`` (the
        default) for none.

    Examples
    --------
    A quarter turn at 0.3 rad/s and 1 rad/s²: 0.3 s to reach 0.3 rad/s, then cruise.

    >>> import numpy as np
    >>> from speedplan.timing.rotation import Turn
    >>> turn = Turn(0.0, np.pi / 2, rate_max=0.3, acc_max=1.0)
    >>> round(turn.duration, 4), turn.peak_rate
    (5.536, 0.3)
    >>> heading, rate, acc = turn.at([0.0, turn.duration])
    >>> heading.round(6).tolist(), rate.tolist()
    ([0.0, 1.570796], [0.0, 0.0])

    With a yaw-jerk limit of 2 rad/s³ the yaw acceleration never reaches 1 rad/s²: it peaks
    at ``sqrt(0.3 · 2) = 0.775`` rad/s² after ``0.775 / 2 = 0.387`` s, and each speed-up takes
    ``2 · 0.387`` s instead of 0.3 s.

    >>> smooth = Turn(0.0, np.pi / 2, rate_max=0.3, acc_max=1.0, jerk_max=2.0)
    >>> tj = np.sqrt(0.3 * 2.0) / 2.0
    >>> round(smooth.duration, 4), round(float(smooth.at(tj)[2][0]), 4)
    (6.0106, 0.7746)
    """

    start: float
    angle: float
    rate_max: float
    acc_max: float
    jerk_max: float = np.inf

    def __post_init__(self) -> None:
        set_ = object.__setattr__
        set_(self, "start", as_scalar("start", self.start))
        set_(self, "angle", as_scalar("angle", self.angle))
        set_(self, "rate_max", as_scalar("rate_max", self.rate_max, positive=True,
                                         allow_inf=True))
        set_(self, "acc_max", as_scalar("acc_max", self.acc_max, positive=True))
        set_(self, "jerk_max", as_scalar("jerk_max", self.jerk_max, positive=True,
                                         allow_inf=True))

    @property
    def end(self) -> float:
        """Heading at the end of the turn [rad]: ``start + angle``."""
        return self.start + self.angle

    @cached_property
    def peak_rate(self) -> float:
        """Largest ``|yaw rate|`` of the turn [rad/s]: ``rate_max``, or less on a short turn."""
        return _peak_rate(abs(self.angle), self.rate_max, self.acc_max, self.jerk_max)

    @cached_property
    def _segments(self) -> tuple[FloatArray, FloatArray, FloatArray]:
        """The turn's constant-jerk pieces, for a positive angle.

        Their durations [s], yaw accelerations at their starts [rad/s²] and yaw jerks
        [rad/s³].
        """
        angle, peak = abs(self.angle), self.peak_rate
        if peak == 0.0:
            return np.zeros(1), np.zeros(1), np.zeros(1)
        cruise = max(angle - 2.0 * _ramp_angle(peak, self.acc_max, self.jerk_max), 0.0) / peak
        if not np.isfinite(self.jerk_max):
            ramp = peak / self.acc_max
            acc = self.acc_max
            return (np.array([ramp, cruise, ramp]), np.array([acc, 0.0, -acc]),
                    np.zeros(3))
        acc = min(self.acc_max, float(np.sqrt(peak * self.jerk_max)))
        tj = acc / self.jerk_max
        hold = max(peak / acc - tj, 0.0)
        j = self.jerk_max
        return (np.array([tj, hold, tj, cruise, tj, hold, tj]),
                np.array([0.0, acc, acc, 0.0, 0.0, -acc, -acc]),
                np.array([j, 0.0, -j, 0.0, -j, 0.0, j]))

    @cached_property
    def _starts(self) -> tuple[FloatArray, FloatArray, FloatArray]:
        """Start time [s], turned angle [rad] and yaw rate [rad/s] of each piece."""
        dur, acc, jerk = self._segments
        t = np.concatenate(([0.0], np.cumsum(dur)[:-1]))
        angle, rate = np.zeros(dur.size), np.zeros(dur.size)
        for k in range(1, dur.size):
            d = dur[k - 1]
            rate[k] = rate[k - 1] + acc[k - 1] * d + 0.5 * jerk[k - 1] * d * d
            angle[k] = (angle[k - 1] + rate[k - 1] * d + 0.5 * acc[k - 1] * d * d
                        + jerk[k - 1] * d**3 / 6.0)
        return t, angle, rate

    @property
    def breaks(self) -> FloatArray:
        """Times [s] where the turn's pieces start.

        The yaw jerk (without a jerk limit, the yaw acceleration) changes there.
        """
        return self._starts[0]

    @property
    def duration(self) -> float:
        """Time of the turn [s].

        Without a jerk limit ``2 sqrt(|angle| / acc_max)`` if it never reaches ``rate_max``,
        else ``|angle| / rate_max + rate_max / acc_max``.
        """
        return float(np.sum(self._segments[0]))

    def at(self, t: object) -> tuple[FloatArray, FloatArray, FloatArray]:
        """Heading [rad], yaw rate [rad/s] and yaw acceleration [rad/s²] at times ``t`` [s].

        ``t`` counts from the start of the turn and is clipped to ``[0, duration]``; the
        last instant is exactly at ``end`` with the yaw rate 0.
        """
        q = np.clip(np.atleast_1d(as_array("t", t)), 0.0, self.duration)
        _, acc, jerk = self._segments
        t0, angle0, rate0 = self._starts
        k = np.clip(np.searchsorted(t0, q, side="right") - 1, 0, t0.size - 1)
        tau = q - t0[k]
        yaw_acc = acc[k] + jerk[k] * tau
        rate = rate0[k] + acc[k] * tau + 0.5 * jerk[k] * tau**2
        done = angle0[k] + rate0[k] * tau + 0.5 * acc[k] * tau**2 + jerk[k] * tau**3 / 6.0
        end = q >= self.duration
        done = np.where(end, abs(self.angle), done)
        rate = np.where(end, 0.0, rate)
        yaw_acc = np.where(end, 0.0, yaw_acc)
        sign = 1.0 if self.angle >= 0 else -1.0
        return self.start + sign * done, sign * rate, sign * yaw_acc
