"""Turning on the spot: minimum-time rest-to-rest rotations within yaw limits.

A vehicle standing still (v = 0) turns its heading by ``angle`` [rad]: the yaw rate rises at
``acc_max`` until ``rate_max`` (or half the turn), cruises, and falls back to 0 — the
trapezoidal (or triangular) profile, the time-optimal one for a double integrator with
bounded speed and acceleration. The yaw rate is continuous; the yaw acceleration steps
between ``±acc_max`` and 0.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..core.checks import FloatArray, as_array, as_scalar

__all__ = ["Turn"]


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
    """

    start: float
    angle: float
    rate_max: float
    acc_max: float

    def __post_init__(self) -> None:
        set_ = object.__setattr__
        set_(self, "start", as_scalar("start", self.start))
        set_(self, "angle", as_scalar("angle", self.angle))
        set_(self, "rate_max", as_scalar("rate_max", self.rate_max, positive=True,
                                         allow_inf=True))
        set_(self, "acc_max", as_scalar("acc_max", self.acc_max, positive=True))

    @property
    def end(self) -> float:
        """Heading at the end of the turn [rad]: ``start + angle``."""
        return self.start + self.angle

    @property
    def _ramp(self) -> float:
        """Duration of the speed-up (and of the slow-down) [s]."""
        triangle = float(np.sqrt(abs(self.angle) / self.acc_max))
        return min(triangle, self.rate_max / self.acc_max)

    @property
    def peak_rate(self) -> float:
        """Largest ``|yaw rate|`` of the turn [rad/s]: ``rate_max``, or less on a short turn."""
        return self.acc_max * self._ramp

    @property
    def duration(self) -> float:
        """Time of the turn [s].

        ``2 sqrt(|angle| / acc_max)`` if it never reaches ``rate_max``, else
        ``|angle| / rate_max + rate_max / acc_max``.
        """
        ramp = self._ramp
        if ramp == 0.0:
            return 0.0
        cruise = (abs(self.angle) - self.acc_max * ramp**2) / (self.acc_max * ramp)
        return 2.0 * ramp + max(cruise, 0.0)

    def at(self, t: object) -> tuple[FloatArray, FloatArray, FloatArray]:
        """Heading [rad], yaw rate [rad/s] and yaw acceleration [rad/s²] at times ``t`` [s].

        ``t`` counts from the start of the turn and is clipped to ``[0, duration]``.
        """
        q = np.clip(np.atleast_1d(as_array("t", t)), 0.0, self.duration)
        sign = 1.0 if self.angle >= 0 else -1.0
        acc, ramp, total = self.acc_max, self._ramp, self.duration
        peak = acc * ramp
        rising, falling = q < ramp, q > total - ramp
        left = total - q
        rate = np.where(rising, acc * q, np.where(falling, acc * left, peak))
        done = np.where(rising, 0.5 * acc * q**2,
                        np.where(falling, abs(self.angle) - 0.5 * acc * left**2,
                                 0.5 * acc * ramp**2 + peak * (q - ramp)))
        yaw_acc = np.where(rising, acc, np.where(falling, -acc, 0.0))
        if ramp == 0.0:
            rate, done, yaw_acc = np.zeros_like(q), np.zeros_like(q), np.zeros_like(q)
        return self.start + sign * done, sign * rate, sign * yaw_acc
