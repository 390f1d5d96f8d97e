"""The law of a motion given in time as constant-jerk phases (a straight leg's exact optimum).

Where `TimeLaw` interpolates a solved ``w(s)`` on a grid, `MotionLaw` holds a motion already
known in closed form (`speedplan.model.straight`): on each phase the position is a cubic in
time, the speed a quadratic, the acceleration linear, the jerk constant. Sampling in time is
direct; positions become times by inverting each piece's cubic (a safeguarded Newton iteration
inside the piece's bracket, from the piece's nearer end, so that offsets next to a standstill
keep full relative precision). It offers what `SpeedProfile` and the checks use of a
`TimeLaw`: nodes, pieces between them with their exact extremes, kinematics at arc lengths,
times and states.
"""

from __future__ import annotations

from dataclasses import dataclass
from functools import cached_property

import numpy as np

from ..core.checks import FloatArray, IntArray
from ..model.straight import JerkPhases
from .law import Extreme, PieceExtremes

__all__ = ["NODES_PER_MOTION", "MotionLaw"]

#: About how many nodes a motion is given at (each phase gets its share by duration, at least
#: one piece, two for a jerk phase): what ``SpeedProfile.s``, ``w`` and ``t`` list, and the
#: pieces the checks sample.
NODES_PER_MOTION = 32
#: Iterations of the inversion of a piece's cubic (it stops once every offset has converged).
_MAX_ITERATIONS = 100


def _subdivided(m: JerkPhases) -> JerkPhases:
    """``m`` with each phase cut into pieces of equal duration (see `NODES_PER_MOTION`)."""
    dt = np.diff(m.t)
    share = np.ceil(NODES_PER_MOTION * dt / max(m.duration, np.finfo(float).tiny))
    counts = np.maximum(share, np.where(m.jerk != 0.0, 2, 1)).astype(np.intp)
    t, s, v, a, jerk = [m.t[:1]], [m.s[:1]], [m.v[:1]], [m.a[:1]], []
    for k, count in enumerate(counts):
        frac = np.arange(1, count) / count
        # Each inner point from the phase's nearer end (relative precision at a standstill).
        left = frac <= 0.5
        tau = np.where(left, frac, 1.0 - frac) * dt[k]
        sv, av, sgn = (np.where(left, m.v[k], m.v[k + 1]), np.where(left, m.a[k], -m.a[k + 1]),
                       np.where(left, 1.0, -1.0))
        d = tau * (sv + tau * (0.5 * av + tau * m.jerk[k] / 6.0))
        t.append(np.concatenate((np.where(left, m.t[k] + tau, m.t[k + 1] - tau), m.t[k + 1:k + 2])))
        s.append(np.concatenate((np.where(left, m.s[k] + d, m.s[k + 1] - d), m.s[k + 1:k + 2])))
        v.append(np.concatenate((sv + tau * (av + 0.5 * tau * m.jerk[k]), m.v[k + 1:k + 2])))
        a.append(np.concatenate((sgn * (av + tau * m.jerk[k]), m.a[k + 1:k + 2])))
        jerk.append(np.full(count, m.jerk[k]))
    out = JerkPhases(t=np.concatenate(t), s=np.concatenate(s), v=np.concatenate(v),
                     a=np.concatenate(a), jerk=np.concatenate(jerk))
    return out


@dataclass(frozen=True, eq=False)
class MotionLaw:
    """Speed law of a motion given as constant-jerk phases in time.

    Parameters
    ----------
    motion : JerkPhases
        The motion (positions from 0).

    Examples
    --------
    >>> from speedplan.model.straight import straight_motion
    >>> from speedplan.timing.motion_law import MotionLaw
    >>> law = MotionLaw(straight_motion(30.0, 0.0, 0.0, 2.0, 1.0, 1.0, 0.5))
    >>> round(law.duration, 12), law.length
    (19.0, 30.0)
    >>> s, w, v, a, j = law.state_at([2.0, 9.5])
    >>> s.round(9).tolist(), v.round(9).tolist(), a.round(9).tolist()
    ([0.666666667, 15.0], [1.0, 2.0], [1.0, 0.0])
    >>> law.time_at([15.0]).round(9).tolist()
    [9.5]
    """

    motion: JerkPhases

    @cached_property
    def _pieces(self) -> JerkPhases:
        return _subdivided(self.motion)

    # ---- nodes ------------------------------------------------------------------------------
    @property
    def s(self) -> FloatArray:
        """Arc length of the nodes [m] (the pieces' ends)."""
        return self._pieces.s

    @property
    def w(self) -> FloatArray:
        """Squared speed at the nodes [m²/s²]."""
        out: FloatArray = self._pieces.v ** 2
        return out

    @property
    def knots(self) -> FloatArray:
        """Ends of the pieces [m]: the nodes."""
        return self._pieces.s

    @property
    def knot_times(self) -> FloatArray:
        """Times at the knots [s]."""
        return self._pieces.t

    @property
    def node_times(self) -> FloatArray:
        """Times at the nodes [s]."""
        return self._pieces.t

    @property
    def length(self) -> float:
        """Path length covered [m]."""
        return self.motion.length

    @property
    def duration(self) -> float:
        """Total travel time [s]."""
        return self.motion.duration

    # ---- evaluation in time -----------------------------------------------------------------
    def state_at(self, t: FloatArray) -> tuple[FloatArray, FloatArray, FloatArray, FloatArray,
                                                FloatArray]:
        """``s, w, v, a, jerk`` at times ``t`` [SI] (clipped to the motion)."""
        p = self._pieces
        tt = np.clip(np.atleast_1d(np.asarray(t, dtype=np.float64)), 0.0, self.duration)
        j = np.clip(np.searchsorted(p.t, tt, side="right") - 1, 0, p.jerk.size - 1)
        left = tt - p.t[j] <= p.t[j + 1] - tt
        tau = np.where(left, tt - p.t[j], p.t[j + 1] - tt)
        v0, a0, sgn = self._end(j, left)
        jerk = p.jerk[j]
        d = tau * (v0 + tau * (0.5 * a0 + tau * jerk / 6.0))
        s = np.where(left, p.s[j] + d, p.s[j + 1] - d)
        v = np.maximum(v0 + tau * (a0 + 0.5 * tau * jerk), 0.0)
        return s, v * v, v, sgn * (a0 + tau * jerk) + 0.0, jerk  # + 0.0: no -0.0

    def position_at(self, t: FloatArray) -> FloatArray:
        """Arc length ``s(t)`` at times ``t`` [m]."""
        return self.state_at(t)[0]

    def _end(self, j: IntArray, left: np.ndarray) -> tuple[FloatArray, FloatArray, FloatArray]:
        """Speed, acceleration and sign of time at the nearer end of pieces ``j``.

        From the right end time runs backwards: the acceleration's sign flips, the jerk's
        does not.
        """
        p = self._pieces
        return (np.where(left, p.v[j], p.v[j + 1]), np.where(left, p.a[j], -p.a[j + 1]),
                np.where(left, 1.0, -1.0))

    # ---- evaluation in arc length -----------------------------------------------------------
    def _invert(self, j: IntArray, dx: FloatArray, dr: FloatArray
                ) -> tuple[FloatArray, np.ndarray]:
        """Time ``τ`` from the nearer end of pieces ``j`` at offsets ``dx`` / ``dr``, and which end.

        The offset is the cubic ``τ (v + τ (a/2 + τ j/6))`` of the time from that end,
        non-decreasing (the speed is not negative): Newton steps kept inside the bracket, a
        bisection otherwise, starting from the dominant term.
        """
        p = self._pieces
        j, dx, dr = np.broadcast_arrays(j, dx, dr)
        left = (dx < dr) | ((dx == dr) & (j == 0))
        d = np.maximum(np.where(left, dx, dr), 0.0)
        v, a, _ = self._end(j, left)
        jerk = p.jerk[j]
        width = p.t[j + 1] - p.t[j]
        with np.errstate(all="ignore"):  # a subnormal speed overflows: the bracket decides
            guess = np.where(v > 0, d / v, np.where(a > 0, np.sqrt(2.0 * d / a),
                                                    np.cbrt(6.0 * d / jerk)))
        tau = np.clip(np.where(np.isfinite(guess), guess, 0.5 * width), 0.0, width)
        lo, hi = np.zeros(tau.shape), width.copy()
        for _ in range(_MAX_ITERATIONS):
            f = tau * (v + tau * (0.5 * a + tau * jerk / 6.0)) - d
            lo = np.where(f <= 0.0, tau, lo)
            hi = np.where(f >= 0.0, tau, hi)
            slope = v + tau * (a + 0.5 * tau * jerk)
            with np.errstate(all="ignore"):
                newton = tau - f / slope
            inside = (slope > 0) & (newton >= lo) & (newton <= hi)
            step = np.where(inside, newton, 0.5 * (lo + hi))
            done = (np.abs(step - tau) <= 4.0 * np.finfo(float).eps * width) | (f == 0.0)
            tau = np.where(f == 0.0, tau, step)
            if done.all():
                break
        return tau, left

    def _kinematics(self, j: IntArray, dx: FloatArray, dr: FloatArray
                    ) -> tuple[FloatArray, FloatArray, FloatArray, FloatArray]:
        """``w, v, a, jerk`` on pieces ``j``, ``dx`` past the left knot, ``dr`` before the right."""
        tau, left = self._invert(j, dx, dr)
        jb = np.broadcast_to(j, tau.shape)
        v0, a0, sgn = self._end(jb, left)
        jerk = self._pieces.jerk[jb]
        v = np.maximum(v0 + tau * (a0 + 0.5 * tau * jerk), 0.0)
        return v * v, v, sgn * (a0 + tau * jerk) + 0.0, jerk

    def _locate(self, q: FloatArray) -> IntArray:
        x = self._pieces.s
        out: IntArray = np.clip(np.searchsorted(x, q, side="right") - 1, 0, x.size - 2)
        return out

    def kinematics(self, q: FloatArray) -> tuple[FloatArray, FloatArray, FloatArray, FloatArray]:
        """``w, v, a, jerk`` at arc lengths ``q`` [m] (SI units)."""
        q = np.clip(np.asarray(q, dtype=np.float64), 0.0, self.length)
        j = self._locate(q)
        x = self._pieces.s
        return self._kinematics(j, q - x[j], x[j + 1] - q)

    def time_at(self, q: FloatArray) -> FloatArray:
        """Time ``t(s)`` at arc lengths ``q`` [s]."""
        q = np.clip(np.asarray(q, dtype=np.float64), 0.0, self.length)
        j = self._locate(q)
        x, t = self._pieces.s, self._pieces.t
        tau, left = self._invert(j, q - x[j], x[j + 1] - q)
        out: FloatArray = np.where(left, t[j] + tau, t[j + 1] - tau)
        return out

    # ---- extremes ---------------------------------------------------------------------------
    def extremes(self) -> PieceExtremes:
        """Exact extremes of each piece: ``(at, maximum, minimum)`` of ``w``, ``a`` and jerk.

        The acceleration is linear in time (extremes at the ends), the jerk constant, the
        speed a parabola whose vertex is where the acceleration crosses 0.
        """
        p = self._pieces
        width = np.diff(p.t)
        with np.errstate(all="ignore"):
            vertex = np.where(p.jerk != 0.0, -p.a[:-1] / p.jerk, -1.0)
        inside = (vertex > 0.0) & (vertex < width)
        tv = np.where(inside, vertex, 0.0)
        v_vertex = p.v[:-1] + tv * (p.a[:-1] + 0.5 * tv * p.jerk)
        s_vertex = p.s[:-1] + tv * (p.v[:-1] + tv * (0.5 * p.a[:-1] + tv * p.jerk / 6.0))
        speeds = np.stack((p.v[:-1], p.v[1:], np.where(inside, v_vertex, p.v[:-1])))
        spots = np.stack((p.s[:-1], p.s[1:], s_vertex))
        cols = np.arange(width.size)
        top = np.argmax(speeds, axis=0)
        w = Extreme(spots[top, cols], speeds[top, cols] ** 2,
                    np.maximum(speeds.min(axis=0), 0.0) ** 2)
        a_ends = np.stack((p.a[:-1], p.a[1:]))
        a = Extreme(np.where(p.a[1:] > p.a[:-1], p.s[1:], p.s[:-1]), a_ends.max(axis=0),
                    a_ends.min(axis=0))
        return PieceExtremes(w=w, a=a, jerk=Extreme(p.s[:-1], p.jerk.copy(), p.jerk.copy()))
