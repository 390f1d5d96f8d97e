"""The continuous speed law built from the discrete solution, and the time it implies.

The discrete problem controls, at each node ``k``, the three-point second difference
``D2_k`` of ``w = v²`` together with ``sqrt(w_k)``: that is the jerk. Its natural continuous
counterpart is the *dual-cell* interpolant: ``w'`` continuous and piecewise linear, equal to
the secant slope ``(w_{k+1} - w_k) / h_k`` at every cell midpoint, so that ``w''`` on the dual
cell around node ``k`` (from the midpoint before it to the midpoint after it) is ``D2_k``.
Acceleration ``w'/2`` then stays between the discrete secant accelerations, and the jerk
``w'' sqrt(w) / 2`` between the discrete jerk rows (times ``sqrt(w(s) / w_k)``): the law
inherits the discrete limits with no ringing, which a global spline through the nodes does
not (a cubic spline overshoots the jerk by ~40 %).

**Why the law does not pass exactly through the nodes.** The discrete optimum switches its
jerk between a cell and the next (e.g. a cruise node followed by a saturated braking node);
its values then admit no C¹ interpolant with the jerk within the limit: on a 400 m road move
the data need twice the limit's curvature over half a cell (``tests/timing/test_time_law.py``
shows it). The dual-cell law spreads the switch over the dual cell, which the jerk limit
allows, at the price of a *local* node offset ``≈ h_{k-1} h_k D2_k / 8``: zero wherever the
discrete ``w`` is locally linear (cruise, constant acceleration), O(h²) elsewhere, measured
below 1e-4 relative at the default resolution.

**No drift on any grid.** With the curvature ``D2_k`` split at the node as ``D2_k h_k /
h_{k-1}`` before it and ``D2_k h_{k-1} / h_k`` after it (the slope change across the dual
cell is unchanged), the node offsets telescope: each is the local term above, whatever the
steps; the trapezoid integration of midpoint slopes used before accumulated
``Σ D2_i (h_i² - h_{i-1}²) / 8`` instead, and on a grid whose step changed abruptly the
vehicle cruised 9.7 % above ``v_max``. The split changes the jerk by the grid's step ratio
``max(h_k / h_{k-1}, h_{k-1} / h_k) - 1``, which the default grids keep below 1 %.

**Standstill.** From rest with zero acceleration the jerk-limited optimum has
``w ∝ s^{4/3}`` (``w''`` singular at ``s = 0``); over the leading (trailing) nodes that follow
the max-jerk start (stop) the same construction runs on ``u = w^{3/4}``, which is linear
there: the law reproduces that motion exactly, acceleration starts at 0 and the jerk
``(2/9) u'² + (2/3) u u''`` stays bounded. Value and slope pass to ``w`` at the junction.
A last, local correction (piecewise quadratic over the final stretch, curvature
``O(offset / length²)``) makes the end value exact.

**Without a jerk limit** nothing asks for a continuous acceleration, and the dual-cell
smoothing would cost the speed bound: where the discrete ``w`` bends upwards (braking onto a
bound step, at a corner) the dual-cell law rises above both adjacent nodes over the half cell
after the kink, by up to an eighth of the neighbour's excess, so the node bounds (the
minimum of ``mu+`` over the two adjacent cells, `speedplan.model.rows.node_bounds`)
no longer keep it under the bound. The law is then ``w`` linear on each cell (``linear=True``,
constant acceleration per cell as in the discrete problem): it passes through every node, lies
on the chord, so under ``mu+`` wherever both ends are, and its time is the discrete problem's
own, ``2 h / (v_k + v_{k+1})`` per cell. Its time law is closed form (``σ = v τ + a τ²/2``
on each piece): no quadrature and no compiled kernel, so a process that plans only without
jerk limit never loads numba (loading the cached kernel costs ~1 s in a fresh process).

Everything is a chain of quadratic pieces in ``w`` or ``u``: speed, acceleration and jerk
follow in closed form, their extremes over each piece too (`TimeLaw.extremes`, what
`SpeedProfile.verify` checks), and ``t(s) = ∫ ds / v`` by Gauss–Legendre quadrature
(with the substitutions ``σ = y²`` and ``σ = y³`` on pieces ending at standstill, where the
integrand is singular).
"""

from __future__ import annotations

from dataclasses import dataclass
from functools import cached_property
from typing import NamedTuple, Protocol

import numpy as np

from ..core.checks import FloatArray, IntArray
from ..core.errors import InvalidInputError
from ._law_numpy import backend

__all__ = ["STANDSTILL_EXPONENT", "Extreme", "LawChain", "PieceExtremes", "SpeedLaw", "TimeLaw"]

class SpeedLaw(Protocol):
    """What a profile and its checks use of a leg's law: `TimeLaw`, or a motion known in time.

    Nodes ``s`` [m] with their ``w`` [m²/s²] and ``node_times`` [s]; pieces between ``knots``
    with exact extremes (`TimeLaw.extremes`); kinematics at arc lengths; times and states.
    """

    @property
    def s(self) -> FloatArray:
        """Arc length of the nodes [m]."""

    @property
    def w(self) -> FloatArray:
        """Squared speed at the nodes [m²/s²]."""

    @property
    def knots(self) -> FloatArray:
        """Ends of the pieces [m]."""

    @property
    def node_times(self) -> FloatArray:
        """Times at the nodes [s]."""

    @property
    def length(self) -> float:
        """Path length covered [m]."""

    @property
    def duration(self) -> float:
        """Total travel time [s]."""

    def extremes(self) -> PieceExtremes:
        """Exact extremes of ``w``, ``a`` and the jerk over each piece."""

    def kinematics(self, q: FloatArray) -> tuple[FloatArray, FloatArray, FloatArray, FloatArray]:
        """``w, v, a, jerk`` at arc lengths ``q``."""

    def _kinematics(self, j: IntArray, dx: FloatArray, dr: FloatArray
                    ) -> tuple[FloatArray, FloatArray, FloatArray, FloatArray]:
        """``w, v, a, jerk`` on pieces ``j`` at offsets ``dx`` (from the left), ``dr``."""

    def time_at(self, q: FloatArray) -> FloatArray:
        """Time at arc lengths ``q`` [s]."""

    def state_at(self, t: FloatArray) -> tuple[FloatArray, FloatArray, FloatArray, FloatArray,
                                                FloatArray]:
        """``s, w, v, a, jerk`` at times ``t``."""


#: Exponent ``p`` of ``u = w^p`` on standstill regions: ``w ∝ s^{4/3}`` makes ``u`` linear.
STANDSTILL_EXPONENT = 0.75
#: A node lies on the max-jerk start (stop) when its discrete jerk is at least this fraction of
#: ``j_max`` (standstill regions): nearer ``j_max`` than 0, the bang-bang control's phase it
#: belongs to. A tolerance of 1e-3 missed stops a few tenths of a per cent under the max-jerk
#: motion (a 20 000-node comfort grid: the last rows not binding): their ``u``-regions were
#: 1-3 nodes long, and ``w``-pieces next to the rest, which cannot follow ``w ∝ s^{4/3}``,
#: raised the jerk 12 % above ``j_max`` there.
_ON_JERK_PHASE = 0.5
#: Fewest nodes next to a rest whose dual cells are built in ``u``, whatever their discrete
#: jerk. A stop softer than the max-jerk motion (a refined stop whose jerk ramps from 0.07 to
#: 0.66 ``j_max`` over its last 80 nodes, 0.15 µm) had only its last node's cell in ``u``;
#: the ``w``-piece next to it cannot follow ``w ∝ d^{4/3}`` and took the jerk to 1.77x
#: ``j_max``. With two such cells it stays at 0.86x (0.79x on ``w = K d^{4/3}`` at
#: 0.66 ``j_max``, where one cell gave 1.45x).
_LEAST_STANDSTILL_NODES = 2
#: Pieces over which a moving end's correction is spread (20 cells).
_END_WINDOW = 40


@dataclass(frozen=True, eq=False)
class _Pieces:
    """Quadratic pieces ``y = Y + G x + C x² / 2`` between knots, in ``w`` or ``u``."""

    x: FloatArray  # knots, shape (m + 1,)
    y: FloatArray  # values at the knots (in each piece's own variable, see left/right)
    g: FloatArray  # slopes at the knots
    c: FloatArray  # curvature of each piece, shape (m,)
    is_u: np.ndarray  # bool per piece: variable u = w^{3/4}
    y_right: FloatArray  # value at each piece's right knot in the piece's own variable
    g_right: FloatArray  # slope at each piece's right knot in the piece's own variable


class Extreme(NamedTuple):
    """Exact extremes of one quantity over every piece of a law (arrays of one per piece)."""

    at: FloatArray
    """Arc length of each piece's maximum [m]."""
    maximum: FloatArray
    """Each piece's maximum (SI units)."""
    minimum: FloatArray
    """Each piece's minimum (SI units)."""


class PieceExtremes(NamedTuple):
    """`TimeLaw.extremes`: those of ``w`` [m²/s²], ``a`` [m/s²] and the jerk [m/s³]."""

    w: Extreme
    """Squared speed."""
    a: Extreme
    """Tangential acceleration."""
    jerk: Extreme
    """Jerk."""


@dataclass(frozen=True, eq=False)
class _Work:
    """The arrays of `_Pieces` under construction, filled region by region in place.

    Grid steps ``h``, node values ``w`` and ``u = w^{3/4}``; knots ``x``, their values ``y``
    and slopes ``g``, the pieces' curvatures ``c``, right-end values ``y_r`` and slopes ``g_r``.
    """

    x: FloatArray
    h: FloatArray
    w: FloatArray
    u: FloatArray
    y: FloatArray
    g: FloatArray
    c: FloatArray
    y_r: FloatArray
    g_r: FloatArray


@dataclass(frozen=True, eq=False)
class TimeLaw:
    """Speed law ``w(s)`` through the discrete solution and the exact time law it implies.

    C¹ (the dual-cell law of the module notes), or with ``linear`` piecewise linear.

    Parameters
    ----------
    s, w : ndarray, shape (n,)
        Grid [m] and squared speeds at the nodes [m²/s²].
    accel_start, accel_end : float or None
        Acceleration at a moving start (end) [m/s²]; ``None`` keeps the discrete slope.
    j_max : float or None
        Jerk limit [m/s³] of a smooth standstill: ends at rest then follow the max-jerk start
        (stop) in ``u = w^{3/4}`` over the nodes that lie on it. ``None``: the paper's free
        standstill (the acceleration may jump at rest).
    linear : bool
        ``w`` linear on every cell through the nodes (no jerk limit: the acceleration is the
        secant's, constant per cell, and jumps at nodes); needs ``accel_start``,
        ``accel_end`` and ``j_max`` to be ``None``.

    Examples
    --------
    A constant acceleration from 1 m/s: ``w`` linear in ``s`` is reproduced exactly.

    >>> import numpy as np
    >>> from speedplan.timing import TimeLaw
    >>> s = np.linspace(0.0, 2.0, 21)
    >>> law = TimeLaw(s, 1.0 + s, accel_start=0.5, accel_end=0.5)
    >>> w, v, a, j = law.kinematics(np.array([0.3, 1.7]))
    >>> np.round(w, 12).tolist(), np.round(a, 12).tolist(), np.abs(np.round(j, 12)).tolist()
    ([1.3, 2.7], [0.5, 0.5], [0.0, 0.0])
    >>> bool(abs(law.duration - 2 * (np.sqrt(3.0) - 1.0)) < 1e-12)  # ∫ ds / sqrt(1 + s)
    True

    Without a jerk limit: through the nodes, on the chords, the acceleration of each cell.

    >>> lin = TimeLaw(s, np.minimum(2.0 * s, 1.0), linear=True)
    >>> w, _, a, _ = lin.kinematics(np.array([0.45, 0.5, 0.55]))
    >>> np.round(w, 12).tolist(), np.round(a, 12).tolist()
    ([0.9, 1.0, 1.0], [1.0, 0.0, 0.0])
    """

    s: FloatArray
    w: FloatArray
    accel_start: float | None = None
    accel_end: float | None = None
    j_max: float | None = None
    linear: bool = False

    def __post_init__(self) -> None:
        if self.linear and not (self.accel_start is None and self.accel_end is None
                                and self.j_max is None):
            raise InvalidInputError(
                "a `linear` law keeps the secant slopes: `accel_start`, `accel_end` and "
                "`j_max` must be None")

    # ---- construction -------------------------------------------------------------------
    @cached_property
    def _regions(self) -> tuple[int, int]:
        """Number of leading and trailing nodes whose dual cells are built in ``u``.

        At an end at rest (smooth standstill), the nodes whose discrete jerk is at least
        `_ON_JERK_PHASE` ``j_max`` are the max-jerk start (stop); the ``u``-region covers them
        but the last two, so the junction to ``w`` lies inside that phase, away from its end,
        and at least `_LEAST_STANDSTILL_NODES` nodes whatever their jerk.
        """
        w, n = np.maximum(self.w, 0.0), self.s.size
        if self.j_max is None or not np.isfinite(self.j_max) or n < 3:
            return 0, 0
        h = np.diff(self.s)
        h0, h1 = h[:-1], h[1:]
        d2 = 2.0 * (w[:-2] / (h0 * (h0 + h1)) - w[1:-1] / (h0 * h1) + w[2:] / (h1 * (h0 + h1)))
        jerk = 0.5 * d2 * np.sqrt(w[1:-1])
        saturated = jerk >= _ON_JERK_PHASE * float(self.j_max)
        # A single node between two on the phase whose jerk falls short (a refined solution's
        # node, 0.16 j_max three steps from a rest) belongs to it too: the w-pieces from
        # there on raised the law's jerk 1.2-2.2x. One on the opposite phase (a reversal)
        # does not.
        saturated[1:-1] |= (saturated[:-2] & saturated[2:]
                            & (jerk[1:-1] > -_ON_JERK_PHASE * float(self.j_max)))

        def run(flags: np.ndarray) -> int:
            off = np.flatnonzero(~flags)
            return int(off[0]) if off.size else int(flags.size)

        if saturated.all() and (w[0] > 0) != (w[-1] > 0):
            # A forced stop (start), or its time reversal: the max-jerk motion to rest from a
            # moving state, where u is linear all along: all of it in u.
            return (0, n) if w[0] > 0 else (n, 0)
        least = max(1, min(_LEAST_STANDSTILL_NODES, (n - 1) // 2))  # both ends fit
        lead = max(least, run(saturated) - 1) if w[0] == 0.0 else 0
        trail = max(least, run(saturated[::-1]) - 1) if w[-1] == 0.0 else 0
        if lead + trail > n - 1:
            lead = min(lead, n - 1 - trail) if lead else 0
            trail = n - 1 - lead if trail else 0
        return lead, trail

    @cached_property
    def _pieces(self) -> _Pieces:
        """Build the pieces region by region, with every node offset local.

        1. Each region (leading ``u``, middle ``w``, trailing ``u``) is built by
           `_fill_region` from its first knot's slope (the start slope, or the previous
           region's end slope converted).
        2. The ``w``-region is anchored: its node offsets telescope to the local terms
           ``c⁺_k h_k² / 8`` plus one constant, which is removed (a uniform shift of the
           region). A leading ``u``-region then takes the value and slope it must reach at
           the junction through a curvature linear in ``s`` added to it, which keeps its
           value and slope at the rest (`_bend_to`); a moving start keeps its exact value
           and slope and takes the shift through a short window of two opposite curvatures
           (`_shift_after`).
        3. A trailing ``u``-region reaches ``u = 0`` through such a curvature, which keeps
           its value and slope at the junction and its slope at the rest; a moving end takes
           its exact value through a window at the end.
        """
        if self.linear:
            return self._linear_pieces()
        s, n = self.s, self.s.size
        w = np.maximum(self.w, 0.0)
        h = np.diff(s)
        lead, trail = self._regions
        # Knots s_0, m_0, s_1, ..., m_{n-2}, s_{n-1}; piece 2k = [s_k, m_k], 2k+1 = [m_k, s_{k+1}].
        x = np.empty(2 * n - 1)
        x[0::2], x[1::2] = s, s[:-1] + 0.5 * h
        m = x.size - 1
        node_u = np.zeros(n, dtype=bool)
        node_u[:lead] = True
        node_u[n - trail:] = trail > 0
        is_u = node_u[(np.arange(m) + 1) // 2]  # the node whose dual cell holds each piece
        wk = _Work(x=x, h=h, w=w, u=w**STANDSTILL_EXPONENT, y=np.zeros(m + 1),
                   g=np.zeros(m + 1), c=np.zeros(m), y_r=np.zeros(m), g_r=np.zeros(m))
        y, g, c, u = wk.y, wk.g, wk.c, wk.u
        y_r, g_r = wk.y_r, wk.g_r  # right ends, in each piece's own variable
        mid_k0, mid_k1 = lead, max(n - trail, lead)
        mid_p0 = 0 if lead == 0 else 2 * lead - 1
        mid_p1 = m if trail == 0 else max(2 * (n - trail) - 1, mid_p0)
        if lead == n:  # a forced start to a moving end: u all along, bent to meet the end
            self._forced_start(wk)
            return _Pieces(x=x, y=y, g=g, c=c, is_u=is_u, y_right=y[1:].copy(),
                           g_right=g[1:].copy())
        free_start = w[0] == 0.0  # at rest: the slope of u there is free
        if lead:  # 1. the leading u-region, natural
            y[0] = u[0]
            g[0] = ((u[1] - u[0]) / h[0] if free_start else
                    _convert(w[0], self._end_slope(w, h, False, start=True), from_u=False)[1])
            _fill_region(x, h, u, 0, lead, n, 0, mid_p0, y, g, c, None)
            g_junction = _convert(y[mid_p0], g[mid_p0], from_u=True)[1]
        else:
            g_junction = self._end_slope(w, h, False, start=True)
        if mid_k1 > mid_k0:  # 2. the w-region, from value 0, then anchored
            self._anchored_middle(wk, (mid_k0, mid_k1, mid_p0, mid_p1), g_junction,
                                  lead=lead, trail=trail, free_start=free_start)
        if trail == n:  # a forced stop: u from the moving start (slope from its acceleration)
            y[0], g[0] = _convert(w[0], g_junction, from_u=False)
            mid_p1 = 0
        if trail:  # 3. the trailing u-region, from the junction, bent to end at u = 0
            p0 = mid_p1
            if 0 < mid_k1 - mid_k0:
                y[p0], g[p0] = _convert(y[p0], g[p0], from_u=False)
            _fill_region(x, h, u, n - trail, n, n, p0, m, y, g, c, (u[-1] - u[-2]) / h[-1])
            _bend_to(x, c, g, y, p0, m, u[-1] - y[m], 0.0, rest_at_start=False)
            y[m] = u[-1]
            y_r[p0:], g_r[p0:] = y[p0 + 1:], g[p0 + 1:]
        elif mid_k1 > mid_k0:  # a moving end: its exact value through a window
            _shift_after(x, c, g, y, mid_p0, m, w[-1] - y[m], start=False)
            y[m] = w[-1]
            y_r[mid_p0:], g_r[mid_p0:] = y[mid_p0 + 1:], g[mid_p0 + 1:]
        return _Pieces(x=x, y=y, g=g, c=c, is_u=is_u, y_right=y_r, g_right=g_r)

    def _forced_start(self, wk: _Work) -> None:
        """A forced start to a moving end: ``u`` all along, bent to meet the end (in place)."""
        x, h, w, u, y, g, c = wk.x, wk.h, wk.w, wk.u, wk.y, wk.g, wk.c
        n, m = w.size, x.size - 1
        y[0], g[0] = u[0], (u[1] - u[0]) / h[0]
        end = _convert(w[-1], self._end_slope(w, h, False, start=False), from_u=False)
        _fill_region(x, h, u, 0, n, n, 0, m, y, g, c, end[1])
        _bend_to(x, c, g, y, 0, m, end[0] - y[m], end[1] - g[m], rest_at_start=True)
        y[m] = u[-1]

    def _anchored_middle(self, wk: _Work, span: tuple[int, int, int, int], g_junction: float,
                         *, lead: int, trail: int, free_start: bool) -> None:
        """Step 2 of `_pieces`: the ``w``-region's pieces, anchored (in place).

        ``span``: its first and last-plus-one node, first and last knot; ``g_junction`` its
        start slope in ``w``; ``lead``, ``trail`` the ``u``-regions' node counts.
        """
        x, h, w, y, g, c, y_r, g_r = wk.x, wk.h, wk.w, wk.y, wk.g, wk.c, wk.y_r, wk.g_r
        mid_k0, mid_k1, mid_p0, mid_p1 = span
        n = w.size
        y_u_end, g_u_end = y[mid_p0], g[mid_p0]
        y[mid_p0], g[mid_p0] = 0.0, g_junction
        _fill_region(x, h, w, mid_k0, mid_k1, n, mid_p0, mid_p1, y, g, c,
                     None if trail else self._end_slope(w, h, False, start=False))
        nodes = np.arange(max(mid_k0, 1) + (1 if lead else 0), min(mid_k1, n - 1))
        if nodes.size:
            local = c[2 * nodes] * h[nodes] ** 2 / 8.0
            residual = y[2 * nodes] - w[nodes] - local
            const = float(np.median(residual))
            if nodes.size > 1 and (lead or trail):
                _level_ends(wk, (mid_p0, mid_p1), 2 * nodes[[0, -1]],
                            (float(residual[0]) - const if lead else 0.0,
                             float(residual[-1]) - const if trail else 0.0))
        else:
            const = float(y[2 * mid_k0] - w[mid_k0]) if mid_k0 < n else 0.0
        if lead and free_start:
            y[mid_p0:mid_p1 + 1] -= const
            target = _convert(y[mid_p0], g[mid_p0], from_u=False)
            _bend_to(x, c, g, y, 0, mid_p0, target[0] - y_u_end, target[1] - g_u_end,
                     rest_at_start=True)
            y[mid_p0], g[mid_p0] = target  # the junction knot, in u for the left side
            y_r[:mid_p0], g_r[:mid_p0] = y[1:mid_p0 + 1], g[1:mid_p0 + 1]
            y[mid_p0], g[mid_p0] = _convert(target[0], target[1], from_u=True)
        else:  # exact start values: the shift through a window at the region's start
            start_value = _convert(y_u_end, g_u_end, from_u=True)[0] if lead else w[0]
            y[mid_p0:mid_p1 + 1] += start_value
            _shift_after(x, c, g, y, mid_p0, mid_p1, -(const + start_value), start=True)
            if lead:
                y_r[:mid_p0], g_r[:mid_p0] = y[1:mid_p0 + 1], g[1:mid_p0 + 1]
                y[mid_p0] = start_value
                y_r[:mid_p0][-1:] = y_u_end
                g_r[:mid_p0][-1:] = g_u_end
        y_r[mid_p0:mid_p1], g_r[mid_p0:mid_p1] = y[mid_p0 + 1:mid_p1 + 1], g[mid_p0 + 1:
                                                                               mid_p1 + 1]

    def _linear_pieces(self) -> _Pieces:
        """``w`` linear on each cell: the chord, split at the cell's midpoint knot."""
        s, n = self.s, self.s.size
        w = np.maximum(self.w, 0.0)
        x = np.empty(2 * n - 1)
        h = s[1:] - s[:-1]
        x[0::2], x[1::2] = s, s[:-1] + 0.5 * h
        y = np.empty(2 * n - 1)
        y[0::2], y[1::2] = w, 0.5 * (w[:-1] + w[1:])
        slope = np.repeat((w[1:] - w[:-1]) / h, 2)  # the cell's secant on both halves
        m = x.size - 1
        return _Pieces(x=x, y=y, g=np.append(slope, slope[-1]), c=np.zeros(m),
                       is_u=np.zeros(m, dtype=bool), y_right=y[1:].copy(), g_right=slope)

    def _end_slope(self, val: FloatArray, h: FloatArray, in_u: bool, *, start: bool) -> float:
        """Slope at an end: the prescribed acceleration at a moving end, else the secant."""
        accel = self.accel_start if start else self.accel_end
        w_end = self.w[0] if start else self.w[-1]
        if not in_u and accel is not None and w_end > 0:
            return 2.0 * float(accel)
        return float((val[1] - val[0]) / h[0] if start else (val[-1] - val[-2]) / h[-1])

    @property
    def length(self) -> float:
        """Path length covered [m]."""
        return float(self.s[-1] - self.s[0])

    # ---- evaluation -------------------------------------------------------------------------
    def _locate(self, q: FloatArray) -> IntArray:
        x = self._pieces.x
        out: IntArray = np.clip(np.searchsorted(x, q, side="right") - 1, 0, x.size - 2)
        return out

    def _kinematics(self, j: IntArray, dx: FloatArray, dr: FloatArray
                    ) -> tuple[FloatArray, FloatArray, FloatArray, FloatArray]:
        """``w, v, a, jerk`` on pieces ``j`` at ``dx`` after the left knot, ``dr`` before the right.

        The three broadcast together. Each piece is evaluated from the nearer knot: accurate
        relative to its own size next to a standstill, where ``y`` tends to 0. Compiled
        (`speedplan.core._law_kernel`; numpy before numba is loaded); a ``linear`` law
        is two lines of numpy.
        """
        if self.linear:
            p = self._pieces
            g = p.g[j]  # one slope per piece (the same at both knots)
            w = np.maximum(np.where(dx > dr, p.y_right[j] - g * dr, p.y[j] + g * dx), 0.0)
            shape = w.shape
            return w, np.sqrt(w), np.broadcast_to(0.5 * g, shape), np.zeros(shape)
        out: tuple[FloatArray, FloatArray, FloatArray, FloatArray] = backend().kinematics(
            self._pieces, j, dx, dr)
        return out

    def kinematics(self, q: FloatArray) -> tuple[FloatArray, FloatArray, FloatArray, FloatArray]:
        """Return ``w, v, a, jerk`` at arc lengths ``q`` [m] (SI units)."""
        q = np.asarray(q, dtype=np.float64)
        j = self._locate(q)
        x = self._pieces.x
        return self._kinematics(j, q - x[j], x[j + 1] - q)

    def node_offsets(self) -> FloatArray:
        """``w_law(s_k) - w_k`` at every node [m²/s²] (see the module notes)."""
        return self.kinematics(self.s)[0] - np.maximum(self.w, 0.0)

    # ---- extremes ---------------------------------------------------------------------------
    def extremes(self) -> PieceExtremes:
        """Exact extremes of each piece: ``(at, maximum, minimum)`` of ``w``, ``a`` and jerk.

        Over every piece (arrays of one entry per piece), from the closed forms: ``w`` and
        ``a`` are quadratic / linear in ``w``-pieces, and in ``u``-pieces ``a`` and the jerk
        are extremal at the ends or where their derivative, a polynomial in the piece's
        offset, vanishes.

        Examples
        --------
        >>> import numpy as np
        >>> from speedplan.timing import TimeLaw
        >>> law = TimeLaw(np.linspace(0.0, 1.0, 5), np.array([1.0, 1.5, 2.0, 2.5, 3.0]),
        ...               linear=True)
        >>> ex = law.extremes()
        >>> ex.a.maximum.tolist(), float(ex.w.maximum.max()), float(ex.w.at[-1])
        ([1.0, 1.0, 1.0, 1.0, 1.0, 1.0, 1.0, 1.0], 3.0, 1.0)
        """
        p = self._pieces
        if self.linear:  # extremes at the knots; constant acceleration, no jerk
            a = 0.5 * p.g[:-1]
            w_max, w_min = np.maximum(p.y[:-1], p.y_right), np.minimum(p.y[:-1], p.y_right)
            at = np.where(p.y_right > p.y[:-1], p.x[1:], p.x[:-1])
            zero = np.zeros_like(a)
            return PieceExtremes(w=Extreme(at, w_max, w_min), a=Extreme(p.x[:-1], a, a),
                                 jerk=Extreme(p.x[:-1], zero, zero))
        width = np.diff(p.x)
        cands = [np.zeros_like(width), width]
        with np.errstate(divide="ignore", invalid="ignore"):
            vertex = -p.g[:-1] / p.c  # y' = 0: extremum of y (so of w), and of the u-jerk
            # In u: a' ∝ y'² + 3 y y'' = 2.5 C² x² + 5 G C x + G² + 3 C Y = 0.
            qa, qb = 2.5 * p.c**2, 5.0 * p.g[:-1] * p.c
            qc = p.g[:-1] ** 2 + 3.0 * p.c * p.y[:-1]
            disc = np.sqrt(np.maximum(qb * qb - 4.0 * qa * qc, 0.0))
            r1, r2 = (-qb + disc) / (2.0 * qa), (-qb - disc) / (2.0 * qa)
        for r in (vertex, np.where(p.is_u, r1, np.nan), np.where(p.is_u, r2, np.nan)):
            inside = np.isfinite(r) & (r > 0) & (r < width)
            cands.append(np.where(inside, r, 0.0))
        dx = np.stack(cands)  # (candidates, pieces)
        # One piece per column: the piece data broadcast over the candidates.
        w, _, a, jerk = self._kinematics(np.arange(width.size), dx, width - dx)
        cols = np.arange(width.size)

        def extreme(val: FloatArray) -> Extreme:
            i_max = np.argmax(val, axis=0)
            return Extreme(p.x[:-1] + dx[i_max, cols], val[i_max, cols], val.min(axis=0))

        return PieceExtremes(w=extreme(w), a=extreme(a), jerk=extreme(jerk))

    @property
    def knots(self) -> FloatArray:
        """Knots of the pieces [m] (the grid nodes and the cell midpoints)."""
        return self._pieces.x

    # ---- time -------------------------------------------------------------------------------
    def _integral(self, j: IntArray, lo: FloatArray, hi: FloatArray,
                  from_right: np.ndarray | None = None) -> FloatArray:
        """``∫ ds / v`` over offsets ``[lo, hi]`` of pieces ``j`` (16-point Gauss–Legendre).

        Offsets are measured from the left knot, or from the right knot where ``from_right``
        (``lo`` nearer to it): next to a standstill at the right end the offsets then keep full
        relative precision. A stretch that starts at a standstill end is integrated with
        ``σ = y²`` (``w`` linear there, ``1/v ~ σ^{-1/2}``) or ``σ = y³`` (``u`` linear,
        ``1/v ~ σ^{-2/3}``): the integrand becomes smooth. Compiled
        (`speedplan.core._law_kernel`; numpy before numba is loaded).
        """
        right = np.zeros(j.shape, dtype=bool) if from_right is None else from_right
        if self.linear:  # w linear: 2 (hi - lo) / (v(lo) + v(hi)), from the anchoring knot
            p = self._pieces
            y0 = np.where(right, p.y_right[j], p.y[j])
            slope = np.where(right, -p.g[j], p.g[j])
            v_lo = np.sqrt(np.maximum(y0 + slope * lo, 0.0))
            v_hi = np.sqrt(np.maximum(y0 + slope * hi, 0.0))
            span = hi - lo
            with np.errstate(divide="ignore", invalid="ignore"):
                closed: FloatArray = np.where(span > 0, 2.0 * span / (v_lo + v_hi), 0.0)
            return closed
        out: FloatArray = backend().integrals(self._pieces, j, lo, hi, right)
        return out

    @cached_property
    def knot_times(self) -> FloatArray:
        """Times at the knots [s] (from 0 at the start)."""
        x = self._pieces.x
        p = self._pieces
        if self.linear:  # ∫ ds / sqrt(w) with w linear: 2 Δx / (v_a + v_b), in closed form
            v = np.sqrt(p.y)
            with np.errstate(divide="ignore"):
                seg = 2.0 * (x[1:] - x[:-1]) / (v[:-1] + v[1:])
            return np.concatenate(([0.0], np.cumsum(seg)))
        j = np.arange(x.size - 1)
        right = (p.y_right <= 0.0) & (p.y[:-1] > 0.0)
        seg = self._integral(j, np.zeros(j.size), np.diff(x), right)
        return np.concatenate(([0.0], np.cumsum(seg)))

    @property
    def duration(self) -> float:
        """Total travel time [s]."""
        return float(self.knot_times[-1])

    def time_at(self, q: FloatArray) -> FloatArray:
        """Time ``t(s)`` at arc lengths ``q`` [s]."""
        q = np.clip(np.asarray(q, dtype=np.float64), self.s[0], self.s[-1])
        x = self._pieces.x
        j = self._locate(q)
        width = x[j + 1] - x[j]
        off = q - x[j]
        # Integrate from the nearer knot: short spans, and the standstill end stays exact.
        from_right = off > 0.5 * width
        part = self._integral(j, np.zeros(j.size), np.where(from_right, width - off, off),
                              from_right)
        T = self.knot_times
        out: FloatArray = np.where(from_right, T[j + 1] - part, T[j] + part)
        return out

    @cached_property
    def node_times(self) -> FloatArray:
        """Times at the grid nodes ``s`` [s]."""
        return self.knot_times[0::2]

    @cached_property
    def _exact_inverse(self) -> np.ndarray:
        """Per piece: whether the offset reached at a time is taken in closed form.

        A ``w``-piece moving at both ends, whose knot times the 16-point rule computes to
        rounding: the nearest root of ``w`` lies outside the Bernstein ellipse of parameter
        `EXACT_RULE_RHO` around the piece (the rule's error on ``1/sqrt(w)`` then falls
        as ``ρ^{-32}``). Elsewhere the inversion iterates on the rule itself, which keeps the
        sampled positions continuous at the knots the rule placed (the exact offset would
        jump there where the rule is off). On ``plan()``'s grids the moving pieces have
        ``ρ`` of 260 or more (the sample paths, default grids).
        """
        p = self._pieces
        moving = (p.y[:-1] > 0.0) & (p.y_right > 0.0) & ~p.is_u
        rho = rule_rho(p.y[:-1], p.g[:-1], p.c, np.diff(p.x))
        out: np.ndarray = moving & (rho >= EXACT_RULE_RHO)
        return out

    def _invert(self, t: FloatArray) -> tuple[IntArray, FloatArray, FloatArray]:
        """Piece and offsets ``(j, dx, dr)`` reached at times ``t``.

        On a ``w``-piece moving at both ends, the exact solution of ``dσ/dτ = sqrt(w)``
        (closed form in ``sinh`` or ``sin``, from the knot nearer in time;
        `_exact_inverse`). Elsewhere a safeguarded Newton iteration on the time
        within each piece, in the offset from the piece's standstill end when it has one (else
        from its left knot): next to a stop the offset keeps full relative precision, where
        an arc length near a long path's end would be quantised to 1e-16 of the path (and
        the speed with it). It starts from the piece's own power law (``σ = τ³`` in ``u``,
        ``τ²`` in ``w`` at a standstill, else linear, or in the compiled kernel the
        third-order kinematic expansion at the left knot); Newton steps are kept only inside
        the bracket, bisection otherwise. Compiled (`speedplan.core._law_kernel`; numpy
        before numba is loaded).
        """
        p = self._pieces
        T = self.knot_times
        t = np.clip(np.asarray(t, dtype=np.float64), 0.0, self.duration)
        j = np.clip(np.searchsorted(T, t, side="right") - 1, 0, p.c.size - 1)
        if self.linear:
            dx, dr = _invert_linear(p, T, j, t)
        else:
            dx, dr = backend().invert(p, T, j, t, self._exact_inverse)
        return j, dx, dr

    def state_at(self, t: FloatArray) -> tuple[FloatArray, FloatArray, FloatArray, FloatArray,
                                                FloatArray]:
        """``s, w, v, a, jerk`` at times ``t`` [SI], the kinematics from the local offsets."""
        j, dx, dr = self._invert(np.atleast_1d(np.asarray(t, dtype=np.float64)))
        p = self._pieces
        w, v, a, jerk = self._kinematics(j, dx, dr)
        q = np.where(dx <= dr, p.x[j] + dx, p.x[j + 1] - dr)
        return q, w, v, a, jerk

    def position_at(self, t: FloatArray) -> FloatArray:
        """Arc length ``s(t)`` at times ``t`` [m] (see `state_at`)."""
        return self.state_at(t)[0]


#: Bernstein-ellipse parameter of a piece's nearest root of ``w`` above which the
#: 16-point Gauss–Legendre rule integrates ``1/sqrt(w)`` to rounding (``4^{-32} ≈ 5e-20``).
EXACT_RULE_RHO = 4.0


def rule_rho(y: FloatArray, g: FloatArray, c: FloatArray, width: FloatArray) -> FloatArray:
    """Bernstein parameter ``ρ`` of the nearest root of ``y + g σ + c σ²/2`` per piece.

    ``ρ = |z + sqrt(z² - 1)|`` (the branch above 1) of the root at ``σ = (z + 1) width / 2``:
    the largest ellipse with foci at the piece's ends in which ``1/sqrt(w)`` is analytic.
    ``inf`` when ``w`` has no finite root.

    Examples
    --------
    >>> import numpy as np
    >>> from speedplan.timing.law import rule_rho
    >>> # w linear from 1 to 4 over a unit piece: its root at σ = -1/3, z = -5/3, ρ = 3
    >>> rule_rho(np.array([1.0]), np.array([3.0]), np.array([0.0]), np.array([1.0])).round(12)
    array([3.])
    """
    a = 0.5 * c.astype(np.complex128)
    with np.errstate(all="ignore"):
        disc = np.sqrt(g.astype(np.complex128) ** 2 - 4.0 * a * y)
        q = -0.5 * (g + np.where(g >= 0.0, 1.0, -1.0) * disc)  # no cancellation
        rho = np.full(y.shape, np.inf)
        for root in (np.where(a != 0, q / a, np.inf), np.where(q != 0, y / q, np.inf)):
            z = 2.0 * root / width - 1.0
            u = np.abs(z + np.sqrt(z - 1.0) * np.sqrt(z + 1.0))
            r = np.maximum(u, 1.0 / u)
            rho = np.minimum(rho, np.where(np.isfinite(r), r, np.inf))
    return rho


def _invert_linear(p: _Pieces, T: FloatArray, j: IntArray, t: FloatArray
                   ) -> tuple[FloatArray, FloatArray]:
    """Offsets ``(dx, dr)`` reached at times ``t`` on linear pieces: constant acceleration.

    ``σ = v τ + a τ²/2`` with ``a = w'/2`` from the piece's left knot, or from its right knot
    when the piece ends at rest (the offset from the stop keeps full relative precision).
    ``v + a τ / 2 >= v / 2`` along the piece: no cancellation.
    """
    width = p.x[j + 1] - p.x[j]
    rest_right = (p.y_right[j] <= 0.0) & (p.y[j] > 0.0)
    tau = np.where(rest_right, T[j + 1] - t, t - T[j])
    v0 = np.sqrt(np.where(rest_right, p.y_right[j], p.y[j]))
    half_a = np.where(rest_right, -p.g[j], p.g[j]) / 4.0  # a / 2, a = ±w' / 2
    off = np.clip(tau * (v0 + half_a * tau), 0.0, width)
    off = np.where(tau >= T[j + 1] - T[j], width, np.where(tau <= 0.0, 0.0, off))
    return np.where(rest_right, width - off, off), np.where(rest_right, off, width - off)


def _fill_region(x: FloatArray, h: FloatArray, val: FloatArray, k0: int, k1: int, n: int,
                 p0: int, p1: int, y: FloatArray, g: FloatArray, c: FloatArray,
                 g_end: float | None) -> None:
    """Curvatures, knot values and slopes of the dual cells ``k0 <= k < k1`` (in place).

    ``y[p0]`` and ``g[p0]`` (the region's first knot) are given. The slope at each midpoint
    knot is the secant of its cell; across a dual cell with a node inside, the slope change is
    split at the node as ``D2 h_k / h_{k-1}`` before it and ``D2 h_{k-1} / h_k`` after it.
    """
    sec = np.diff(val) / h
    # Target slope at the right end of each dual cell k: the midpoint m_k, or the path end.
    targets = np.array(sec[k0:min(k1, n - 1)], dtype=np.float64)
    if k1 == n:
        targets = np.append(targets, 0.0 if g_end is None else g_end)
    slopes = np.concatenate(([g[p0]], targets))  # at the region's knots from p0 on
    dg = np.diff(slopes)
    ks = np.arange(k0, k1)
    inner = (ks > 0) & (ks < n - 1)
    ki = ks[inner]
    d2 = dg[inner] / (0.5 * (h[ki - 1] + h[ki]))
    c[2 * ki - 1] = d2 * h[ki] / h[ki - 1]
    c[2 * ki] = d2 * h[ki - 1] / h[ki]
    if k0 == 0:
        c[0] = dg[0] / (0.5 * h[0])
    if k1 == n:
        c[2 * n - 3] = dg[-1] / (0.5 * h[-1])
    span = np.diff(x[p0:p1 + 1])
    g[p0 + 1:p1 + 1] = g[p0] + np.cumsum(c[p0:p1] * span)
    y[p0 + 1:p1 + 1] = y[p0] + np.cumsum(span * 0.5 * (g[p0:p1] + g[p0 + 1:p1 + 1]))


def _recompute(x: FloatArray, c: FloatArray, g: FloatArray, y: FloatArray, p0: int,
               p1: int) -> None:
    """Slopes and values of knots ``p0 + 1 .. p1`` from knot ``p0`` and the curvatures."""
    span = np.diff(x[p0:p1 + 1])
    g[p0 + 1:p1 + 1] = g[p0] + np.cumsum(c[p0:p1] * span)
    y[p0 + 1:p1 + 1] = y[p0] + np.cumsum(span * 0.5 * (g[p0:p1] + g[p0 + 1:p1 + 1]))


def _bend_to(x: FloatArray, c: FloatArray, g: FloatArray, y: FloatArray, p0: int, p1: int,
             d_value: float, d_slope: float, *, rest_at_start: bool) -> None:
    """Change the value at ``x[p1]`` by ``d_value`` and its slope by ``d_slope`` (in place).

    The value and slope at ``x[p0]`` are kept: the curvature added to the pieces is linear in
    ``x``, ``α + β (x - x0) / length``. Next to a rest this keeps the slope of ``u`` at the
    rest (a leading region's ``x[p0]``, a trailing region's ``x[p1]`` with ``d_slope = 0``),
    which sets the jerk there, ``(2/9) u'²``, and the speed next to it in proportion: a
    change of that slope instead alters the speed all along the region, where a start spends
    most of its time. On a 9.3 m curved path whose start spans 7 nodes in ``u``, that put the
    law 0.3 % above the solved speeds next to each rest and 1.5e-4 under the converged
    duration; moves made of their four jerk phases came out 2.3e-5 faster than ruckig's
    optimum.

    A region of one piece has one curvature: at a rest at its start (``rest_at_start``) the
    start slope takes the rest of the change, ``σ (x - x0) + κ (x - x0)²/2``; else the end
    slope is free (``d_slope`` ignored).
    """
    length = x[p1] - x[p0]
    if p1 - p0 >= 2:
        lo, hi = x[p0:p1], x[p0 + 1:p1 + 1]
        span, arm = hi - lo, x[p1] - 0.5 * (lo + hi)
        ramp = (0.5 * (lo + hi) - x[p0]) / length
        # Slope and value at x[p1] from a constant curvature κ on [lo, hi]: κ span and
        # κ span arm; solved for the two coefficients.
        system = np.array([[span.sum(), (ramp * span).sum()],
                           [(span * arm).sum(), (ramp * span * arm).sum()]])
        alpha, beta = np.linalg.solve(system, np.array([d_slope, d_value]))
        c[p0:p1] += alpha + beta * ramp
    elif rest_at_start:
        kappa = 2.0 * (d_slope * length - d_value) / (length * length)
        g[p0] += d_slope - kappa * length
        c[p0:p1] += kappa
    else:
        c[p0:p1] += 2.0 * d_value / (length * length)
    _recompute(x, c, g, y, p0, p1)


def _shift_after(x: FloatArray, c: FloatArray, g: FloatArray, y: FloatArray, p0: int, p1: int,
                 shift: float, *, start: bool) -> None:
    """Shift the values by ``shift`` through a window at the start (end) of ``p0 .. p1``.

    Curvatures ``+c1`` then ``-c2`` over the window (`_END_WINDOW` pieces, or the
    region if shorter) change the value by ``shift`` and leave the slope at its far end
    unchanged; at the start, the values after the window move by ``shift``; at the end, the
    window ends on the exact end value. The added curvature is ``O(shift / window²)``.
    """
    if shift == 0.0 or p1 - p0 < 2:
        return
    size = min(p1 - p0, _END_WINDOW)
    a, b = (p0, p0 + size) if start else (p1 - size, p1)
    mid = (a + b) // 2
    l1, l2 = x[mid] - x[a], x[b] - x[mid]
    c1 = 2.0 * shift / (l1 * (l1 + l2))
    c[a:mid] += c1
    c[mid:b] -= c1 * l1 / l2
    _recompute(x, c, g, y, a, b)
    if start and b < p1:
        y[b + 1:p1 + 1] += shift


def _level_ends(wk: _Work, span: tuple[int, int], knots: IntArray,
                excess: tuple[float, float]) -> None:
    """Subtract ``excess`` at the two ``knots`` from the pieces of ``span``, smoothly.

    The ``w``-region's node offsets are its local terms plus one constant only up to what
    its values gather over thousands of cells (1e-9 on a 172 m leg whose largest ``w`` is
    11); next to a standstill ``w`` is that small too (4e-7 at the junction of a 1.9 µm
    stop), and a ``u``-region bent to absorb it raised the jerk 11 % above ``j_max``. The
    correction is a line between two standstill sides, which leaves every curvature; next
    to a moving end, whose value and slope are exact, a parabola flat there, which adds a
    curvature of ``2 excess / length²`` (1e-13 here) to every piece. An ``excess`` of 0
    marks a side kept exact.
    """
    x, c, g, y = wk.x, wk.c, wk.g, wk.y
    p0, p1 = span
    e0, e1 = excess
    if e0 == 0.0 and e1 == 0.0:
        return
    x0 = x[p0] if e0 == 0.0 else x[knots[0]]  # a moving end's own knot stays exact
    x1 = x[p1] if e1 == 0.0 else x[knots[1]]
    length = x1 - x0
    t = (x[p0:p1 + 1] - x0) / length
    if e0 != 0.0 and e1 != 0.0:
        value, slope, curv = e0 + (e1 - e0) * t, np.full(t.size, (e1 - e0) / length), 0.0
    elif e1 != 0.0:  # flat at the start
        value, slope, curv = e1 * t * t, 2.0 * e1 * t / length, 2.0 * e1 / length**2
    else:  # flat at the end
        value, slope, curv = e0 * (1 - t) ** 2, -2.0 * e0 * (1 - t) / length, 2.0 * e0 / length**2
    y[p0:p1 + 1] -= value
    g[p0:p1 + 1] -= slope
    c[p0:p1] -= curv


def _convert(y: float, g: float, from_u: bool) -> tuple[float, float]:
    """Value and slope at a junction, from ``u = w^{3/4}`` to ``w`` or back."""
    if from_u:
        cube = float(np.cbrt(max(y, 0.0)))
        return y * cube, (4.0 / 3.0) * cube * g
    u = max(y, 0.0) ** STANDSTILL_EXPONENT
    return u, 0.75 * g * (u / y if y > 0 else 0.0)


@dataclass(frozen=True, eq=False)
class LawChain:
    """Laws of consecutive legs that meet at rest, as one law along the whole path.

    Leg ``i`` covers ``[offsets[i], offsets[i] + laws[i].length]`` of the path and starts at
    time ``start_times[i]``; every method of `TimeLaw` is available with the path's arc
    length and the time from the start of the first leg.

    Examples
    --------
    >>> import numpy as np
    >>> from speedplan.timing.law import LawChain, TimeLaw
    >>> s = np.linspace(0.0, 1.0, 11)
    >>> one = TimeLaw(s, 1.0 + 0 * s, accel_start=0.0, accel_end=0.0)
    >>> chain = LawChain((one, one), np.array([0.0, 1.0]))
    >>> round(chain.duration, 12), chain.kinematics(np.array([1.5]))[1].tolist()
    (2.0, [1.0])
    """

    laws: tuple[SpeedLaw, ...]
    offsets: FloatArray

    @cached_property
    def start_times(self) -> FloatArray:
        """Time at which each leg starts [s]."""
        return np.concatenate(([0.0], np.cumsum([law.duration for law in self.laws])))[:-1]

    @property
    def duration(self) -> float:
        """Total travel time [s]."""
        return float(self.start_times[-1] + self.laws[-1].duration)

    @property
    def length(self) -> float:
        """Length covered [m]."""
        return float(self.offsets[-1] + self.laws[-1].length)

    def _leg(self, q: FloatArray) -> IntArray:
        out: IntArray = np.clip(np.searchsorted(self.offsets, q, side="right") - 1, 0,
                                len(self.laws) - 1)
        return out

    def _map(self, q: FloatArray, fn: str) -> tuple[FloatArray, ...]:
        q = np.atleast_1d(np.asarray(q, dtype=np.float64))
        leg = self._leg(q)
        outs: list[FloatArray] | None = None
        for i in np.unique(leg):
            sel = leg == i
            res = getattr(self.laws[i], fn)(q[sel] - self.offsets[i])
            res = res if isinstance(res, tuple) else (res,)
            if outs is None:
                outs = [np.empty(q.shape) for _ in res]
            for o, r in zip(outs, res, strict=True):
                o[sel] = r
        assert outs is not None
        return tuple(outs)

    def kinematics(self, q: FloatArray) -> tuple[FloatArray, FloatArray, FloatArray, FloatArray]:
        """``w, v, a, jerk`` at path arc lengths ``q`` [m]."""
        w, v, a, j = self._map(q, "kinematics")
        return w, v, a, j

    def time_at(self, q: FloatArray) -> FloatArray:
        """Time ``t(s)`` at path arc lengths ``q`` [s]."""
        q = np.atleast_1d(np.asarray(q, dtype=np.float64))
        (t,) = self._map(q, "time_at")
        return t + self.start_times[self._leg(q)]

    def state_at(self, t: FloatArray) -> tuple[FloatArray, FloatArray, FloatArray, FloatArray,
                                                FloatArray]:
        """``s, w, v, a, jerk`` at times ``t`` (see `TimeLaw.state_at`)."""
        t = np.atleast_1d(np.clip(np.asarray(t, dtype=np.float64), 0.0, self.duration))
        leg = np.clip(np.searchsorted(self.start_times, t, side="right") - 1, 0,
                      len(self.laws) - 1)
        if leg.size and leg[0] == leg[-1] == leg.min() == leg.max():
            # All in one leg (every path without cusps): no masks, no np.unique (~0.5 ms at
            # 10 000 times), the same values.
            i = int(leg[0])
            s, *rest = self.laws[i].state_at(t - self.start_times[i])
            return (s + self.offsets[i], *rest)
        out: tuple[FloatArray, FloatArray, FloatArray, FloatArray, FloatArray] = (
            np.empty(t.shape), np.empty(t.shape), np.empty(t.shape), np.empty(t.shape),
            np.empty(t.shape))
        for i in np.unique(leg):
            sel = leg == i
            res = self.laws[i].state_at(t[sel] - self.start_times[i])
            for o, r in zip(out, res, strict=True):
                o[sel] = r
            out[0][sel] += self.offsets[i]
        return out

    def position_at(self, t: FloatArray) -> FloatArray:
        """Path arc length ``s(t)`` at times ``t`` [m]."""
        return self.state_at(t)[0]

    @cached_property
    def node_times(self) -> FloatArray:
        """Times at the nodes of every leg, shared stop nodes once [s]."""
        parts = [law.node_times + t0 for law, t0 in zip(self.laws, self.start_times, strict=True)]
        return np.concatenate([parts[0]] + [p[1:] for p in parts[1:]])
