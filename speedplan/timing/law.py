"""The continuous time law built from the discrete solution.

Why not a spline of ``w(s)``? A global cubic spline rings at profile kinks and overshoots the
jerk limit by ~40 %. We interpolate ``u = w^p`` instead, with ``p = 3/4`` by default:

* ``u'`` is piecewise linear through the discrete slopes ``(u_{k+1} - u_k) / h_k`` placed at
  the cell midpoints, so ``u''`` is piecewise constant and equal to the discrete second
  difference — a local construction with no ringing; ``u`` is C¹, hence ``s(t)`` is C².
* From rest with zero acceleration the jerk-limited optimum has ``w ∝ s^{4/3}``, i.e. ``u``
  linear in ``s``: the construction reproduces it exactly, acceleration starts at 0 and the
  jerk ``(2/9) u'² + (2/3) u u''`` stays bounded at standstill.
* Speed, acceleration and jerk follow in closed form from ``w = u^{1/p}``:
  ``v = u^{1/(2p)}``, ``a = w'/2``, ``j = w'' v / 2``; time is ``t(s) = ∫ ds / v`` by
  Gauss–Legendre quadrature, with the substitution ``σ = y³`` on pieces that start or end at
  standstill (the integrand is singular there).

The discrete slopes are not re-interpolated at the nodes: ``u(s_k)`` differs from ``u_k`` by
``h² Δu''/8``, a local term that vanishes as the grid is refined. A smooth correction with zero
slope at both ends makes the end value exact.
"""

from __future__ import annotations

from dataclasses import dataclass
from functools import cached_property

import numpy as np

from ..core.checks import FloatArray, IntArray
from ._quadrature import piece_integrals

__all__ = ["TimeLaw"]


@dataclass(frozen=True)
class TimeLaw:
    """C¹ interpolant ``u(s) = w(s)^p`` and the exact time law it implies.

    Parameters
    ----------
    s, w : ndarray, shape (n,)
        Grid and squared speeds at the nodes.
    p : float
        Exponent of the interpolated variable: 3/4 (smooth standstill) or 1 (interpolate w).
    accel_start, accel_end : float or None
        Prescribed acceleration at the ends (only where the speed is positive); ``None`` keeps
        the discrete slope there.
    """

    s: FloatArray
    w: FloatArray
    p: float = 0.75
    accel_start: float | None = None
    accel_end: float | None = None

    # ---- construction -------------------------------------------------------------------
    @cached_property
    def _knots(self) -> tuple[FloatArray, FloatArray, FloatArray, float]:
        """Knots ``x``, slopes ``u'(x)``, values ``u(x)`` and the end-correction amplitude."""
        s, p = self.s, self.p
        u = np.maximum(self.w, 0.0) ** p
        h = np.diff(s)
        g = np.diff(u) / h
        g_start, g_end = g[0], g[-1]
        if self.accel_start is not None and u[0] > 0:
            g_start = 2 * p * self.accel_start * u[0] ** (1 - 1 / p)
        if self.accel_end is not None and u[-1] > 0:
            g_end = 2 * p * self.accel_end * u[-1] ** (1 - 1 / p)
        x = np.concatenate(([s[0]], s[:-1] + 0.5 * h, [s[-1]]))
        gk = np.concatenate(([g_start], g, [g_end]))
        U = u[0] + np.concatenate(([0.0], np.cumsum(0.5 * (gk[1:] + gk[:-1]) * np.diff(x))))
        c = float(u[-1] - U[-1])
        # Knot values including the correction; the ends exactly, so standstill stays at 0.
        Uc = U + c * self._smoothstep(x)
        Uc[0], Uc[-1] = u[0], u[-1]
        return x, gk, Uc, c

    def _smoothstep(self, q: FloatArray) -> FloatArray:
        z = (q - self.s[0]) / self.length
        out: FloatArray = z * z * (3 - 2 * z)
        return out

    @property
    def length(self) -> float:
        """Path length covered [m]."""
        return float(self.s[-1] - self.s[0])

    def _u_piece(
        self, j: IntArray, dx: FloatArray, dr: FloatArray
    ) -> tuple[FloatArray, FloatArray, FloatArray]:
        """``u, u', u''`` on piece ``j``, ``dx`` after its left knot and ``dr`` before its right.

        ``u`` is evaluated from the nearer knot, so it stays accurate relative to its own size
        next to a standstill end, where it tends to 0.
        """
        x, gk, Uc, c = self._knots
        curv = (gk[j + 1] - gk[j]) / (x[j + 1] - x[j])
        right = dx > dr
        u = np.where(right, Uc[j + 1] - gk[j + 1] * dr + 0.5 * curv * dr * dr,
                     Uc[j] + gk[j] * dx + 0.5 * curv * dx * dx)
        du = gk[j] + curv * dx
        ddu = curv
        if c != 0.0:  # smoothstep correction: zero slope at both ends keeps end accelerations
            L = self.length
            q = x[j] + dx
            z = (q - self.s[0]) / L
            u = u + c * (self._smoothstep(q) - self._smoothstep(np.where(right, x[j + 1], x[j])))
            du = du + c * 6 * z * (1 - z) / L
            ddu = ddu + c * (6 - 12 * z) / L**2
        return np.maximum(u, 0.0), du, ddu

    def _piece(self, q: FloatArray) -> IntArray:
        x = self._knots[0]
        out: IntArray = np.clip(np.searchsorted(x, q, side="right") - 1, 0, x.size - 2)
        return out

    def _u(self, q: FloatArray) -> tuple[FloatArray, FloatArray, FloatArray]:
        """``u, u', u''`` at positions ``q`` (vectorised)."""
        x = self._knots[0]
        j = self._piece(q)
        return self._u_piece(j, q - x[j], x[j + 1] - q)

    # ---- kinematics along s ---------------------------------------------------------------
    def kinematics(self, q: FloatArray) -> tuple[FloatArray, FloatArray, FloatArray, FloatArray]:
        """Return ``w, v, a, jerk`` at arc lengths ``q`` [m]."""
        p = self.p
        u, du, ddu = self._u(np.asarray(q, dtype=np.float64))
        inv = 1.0 / p
        w = u**inv
        v = u ** (0.5 * inv)
        if p == 1.0:  # interpolating w itself: a = w'/2, j = w'' v / 2
            return w, v, 0.5 * du, 0.5 * ddu * v
        with np.errstate(divide="ignore", invalid="ignore"):
            a = 0.5 * inv * u ** (inv - 1) * du
            # j = w'' v / 2 with the powers of u combined so that p = 3/4 is regular at u = 0.
            jerk = 0.5 * (inv * (inv - 1) * u ** (1.5 * inv - 2) * du * du
                          + inv * u ** (1.5 * inv - 1) * ddu)
        a = np.where(u > 0, a, 0.0)
        jerk = np.where(np.isfinite(jerk), jerk, np.inf)
        return w, v, a, jerk

    # ---- time -------------------------------------------------------------------------------
    def _integral(self, j: IntArray, lo: FloatArray, hi: FloatArray,
                  singular_at: FloatArray) -> FloatArray:
        """∫ ds / v over offsets ``[lo, hi]`` of piece ``j``.

        ``singular_at`` is -1 when the piece starts at standstill (then ``lo = 0``), +1 when it
        ends there (then ``hi`` is the piece width) and 0 otherwise. Offsets are measured from
        the singular end, so the integrand is evaluated without cancellation; the substitution
        ``σ = y³`` removes the ``1/v`` singularity (compiled loop:
        :func:`speedplan.timing._quadrature.piece_integrals`).
        """
        x, gk, uc, c = self._knots
        return piece_integrals(
            np.ascontiguousarray(j, dtype=np.intp), np.ascontiguousarray(lo, dtype=np.float64),
            np.ascontiguousarray(hi, dtype=np.float64),
            np.ascontiguousarray(singular_at, dtype=np.float64), x, gk, uc, float(c),
            float(self.s[0]), self.length, float(self.p),
        )

    def _speed(self, q: FloatArray) -> FloatArray:
        u, _, _ = self._u(q)
        out: FloatArray = u ** (0.5 / self.p)
        return out

    @cached_property
    def _rest(self) -> tuple[bool, bool]:
        x, _, _, _ = self._knots
        u_ends, _, _ = self._u(np.array([x[0], x[-1]]))
        return bool(u_ends[0] <= 0.0), bool(u_ends[1] <= 0.0)

    def _singularity(self, j: IntArray) -> FloatArray:
        x = self._knots[0]
        rest_start, rest_end = self._rest
        sing = np.zeros(j.shape, dtype=np.float64)
        if rest_start:
            sing = np.where(j == 0, -1.0, sing)
        if rest_end:
            sing = np.where(j == x.size - 2, 1.0, sing)
        return sing

    @cached_property
    def knot_times(self) -> FloatArray:
        """Times at the interpolation knots [s]."""
        x = self._knots[0]
        j = np.arange(x.size - 1)
        seg = self._integral(j, np.zeros(j.size), np.diff(x), self._singularity(j))
        return np.concatenate(([0.0], np.cumsum(seg)))

    @property
    def duration(self) -> float:
        """Total travel time [s]."""
        return float(self.knot_times[-1])

    def time_at(self, q: FloatArray) -> FloatArray:
        """Time ``t(s)`` at arc lengths ``q`` [s]."""
        q = np.clip(np.asarray(q, dtype=np.float64), self.s[0], self.s[-1])
        x = self._knots[0]
        j = self._piece(q)
        sing = self._singularity(j)
        to_end = sing > 0
        # On a piece ending at standstill integrate to its end; elsewhere from its start.
        width = x[j + 1] - x[j]
        off = q - x[j]
        lo = np.where(to_end, off, 0.0)
        hi = np.where(to_end, width, off)
        part = self._integral(j, lo, hi, np.where(to_end, 1.0, np.minimum(sing, 0.0)))
        T = self.knot_times
        out: FloatArray = np.where(to_end, T[j + 1] - part, T[j] + part)
        return out

    @cached_property
    def node_times(self) -> FloatArray:
        """Times at the grid nodes ``s`` [s]."""
        return self.time_at(self.s)

    def position_at(self, t: FloatArray, *, tol: float = 1e-13) -> FloatArray:
        """Arc length ``s(t)`` at times ``t``: Newton on ``t(s) = t`` safeguarded by bisection.

        Starts from linear interpolation between the grid nodes; Newton steps are taken only
        while they at least halve the previous step (the Numerical Recipes ``rtsafe`` rule), so
        convergence is guaranteed near standstill too.
        """
        t = np.clip(np.asarray(t, dtype=np.float64), 0.0, self.duration)
        T, grid = self.node_times, self.s
        j = np.clip(np.searchsorted(T, t, side="right") - 1, 0, grid.size - 2)
        lo, hi = grid[j].copy(), grid[j + 1].copy()
        q = np.interp(t, T, grid)
        step_old = hi - lo
        ttol = tol * max(self.duration, 1.0)
        stol = 4e-16 * max(self.length, 1.0)
        active = np.arange(t.size)
        for _ in range(200):
            if active.size == 0:
                break
            qa = q[active]
            f = self.time_at(qa) - t[active]
            keep = (np.abs(f) > ttol) & (hi[active] - lo[active] > stol)
            active, qa, f = active[keep], qa[keep], f[keep]
            la = np.where(f < 0, qa, lo[active])
            ha = np.where(f > 0, qa, hi[active])
            newton_step = f * self._speed(qa)
            use_newton = ((qa - newton_step > la) & (qa - newton_step < ha)
                          & (np.abs(2 * newton_step) <= np.abs(step_old[active])))
            new_q = np.where(use_newton, qa - newton_step, 0.5 * (la + ha))
            step_old[active] = np.abs(new_q - qa)
            lo[active], hi[active], q[active] = la, ha, new_q
            moving = step_old[active] > stol
            active = active[moving]
        out: FloatArray = q
        return out
