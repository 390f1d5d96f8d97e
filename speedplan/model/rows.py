"""The rows and bounds of a leg's discrete problem, beyond its grid.

* `node_bounds` — the speed bound at each node (its minimum over the adjacent cells);
* `Envelopes` — what jerk-limited motions can reach from a moving (or smooth) start and
  into the end: caps on ``w`` and, for moving states, floors;
* `lateral_jerk_rows` and `lateral_speed_caps` — the lateral-jerk rows at the nodes and
  the cells' midpoints, and the speed caps they imply.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass

import numpy as np

from ..core.checks import FloatArray
from ..core.errors import InfeasibleError
from ..core.kinematics import lateral_rate_weights
from ..core.limits import Limits
from ..core.numerics import CELL_POINTS, cell_points, cell_rows
from ..geometry import Path
from ..solve.problem import StencilRows
from .boundary import fastest_w, jerk_motion_w
from .request import PlanRequest

__all__ = ["Envelopes", "NodeCurvature", "check_floor", "curvature_at_nodes",
           "lateral_jerk_rows", "lateral_speed_caps", "node_bounds", "node_minima"]

#: ``κ``, and ``κ'`` after and before each interior node of a leg's grid.
NodeCurvature = tuple[FloatArray, FloatArray, FloatArray]


#: Newton steps for `lateral_speed_caps` (converged to rounding from its start within
#: about 40 on the sample paths) and the relative margin added to each cap, so that rounding
#: never cuts a feasible point.
CAP_NEWTON_STEPS = 60


CAP_MARGIN = 1e-9


def node_bounds(bound: Callable[[FloatArray], FloatArray], s: FloatArray,
                per_interval: int = CELL_POINTS) -> FloatArray:
    """Bound at each node: the minimum of ``bound`` over its two adjacent intervals.

    The discrete problem sees the bound only at nodes; taking the minimum over the neighbouring
    intervals keeps the interpolated speed under a bound that drops between nodes (a zone
    entry, a curvature peak) at an ``O(h)`` cost where the bound is smooth. Interpolated
    linearly (the law without a jerk limit) ``w`` stays under the larger node value of each
    cell, so under the bound; the jerk-limited law bends away from the chords only by its
    curvature, ``O(j h²)`` (`speedplan.timing.law`). The bound is evaluated once, at
    `cell_points` (every node among them); `node_minima` takes the minima.
    """
    return node_minima(np.asarray(bound(cell_points(s, per_interval)), dtype=np.float64),
                       per_interval)


def node_minima(values: FloatArray, per_interval: int = CELL_POINTS) -> FloatArray:
    """`node_bounds` from the bound's ``values`` at the grid's `cell_points`.

    Examples
    --------
    >>> import numpy as np
    >>> from speedplan.core.numerics import cell_points
    >>> points = cell_points(np.array([0.0, 1.0, 2.0]), 4)  # a dip inside the second cell
    >>> node_minima(np.where(points == 1.5, 1.0, 4.0), per_interval=4).tolist()
    [4.0, 1.0, 1.0]
    """
    nodes, inner = cell_rows(values, per_interval)
    interval_min = np.minimum(inner.min(axis=0), nodes[:-1])
    np.minimum(interval_min, nodes[1:], out=interval_min)  # each cell with both its ends
    w = nodes.copy()
    w[:-1] = np.minimum(w[:-1], interval_min)  # each node and both its cells
    w[1:] = np.minimum(w[1:], interval_min)
    return w


def chord_node_bounds(bound: Callable[[FloatArray], FloatArray], s: FloatArray,
                      breakpoints: FloatArray | None = None,
                      per_interval: int = 8) -> FloatArray:
    """Bound at each node such that every cell's chord lies under the bound.

    On each cell ``[s_i, s_{i+1}]`` the node bounds ``(B_i, B_{i+1})`` span a line under the
    bound ``b``: a ``w`` under them and linear on the cell stays under ``b`` (to the sampling
    of ``b``), as with the minimum over the cell (`node_bounds`). Of these lines the cell
    takes the one that costs the least time to first order: a line under ``b`` maximising
    ``B_i / b_i^{3/2} + B_{i+1} / b_{i+1}^{3/2}`` (the sensitivity of ``h / sqrt(w)``), which
    is the lower convex hull of ``b`` over the cell at a point between its ends. Each node
    takes the smaller of its two cells' values. Where ``b`` is smooth the bound is then lost
    only where it is convex, by ``O(b'' h²)``; the minimum over the cells loses
    ``O(|b'| h)`` wherever the bound falls. A kink or a step of the bound inside a cell (a
    clothoid onto an arc, a zone's edge) still costs ``O(h)``: a node on it costs nothing
    (`speedplan.model.leg_grid.bound_kinks`).

    ``b`` is read at ``per_interval`` points per cell and at the ``breakpoints`` [m] of the
    bound inside the cells, where it may kink, step or dip (`bound_breakpoints`).

    Examples
    --------
    >>> import numpy as np
    >>> s = np.linspace(0.0, 4.0, 5)
    >>> falling = lambda q: 10.0 - np.asarray(q)  # linear: the chords lie on it
    >>> chord_node_bounds(falling, s).tolist(), node_bounds(falling, s).tolist()
    ([10.0, 9.0, 8.0, 7.0, 6.0], [9.0, 8.0, 7.0, 6.0, 6.0])
    >>> step = lambda q: np.where(np.asarray(q) < 2.5, 4.0, 1.0)  # a step inside cell 2
    >>> chord_node_bounds(step, s, breakpoints=np.array([2.5])).tolist()
    [4.0, 4.0, 1.0, 1.0, 1.0]
    """
    m = s.size - 1
    h = np.diff(s)
    theta = np.tile(np.linspace(0.0, 1.0, per_interval + 1), (m, 1))
    if breakpoints is not None and breakpoints.size:
        brk = breakpoints[(breakpoints > s[0]) & (breakpoints < s[-1])]
        k = np.clip(np.searchsorted(s, brk, side="right") - 1, 0, m - 1)
        inside = (brk > s[k]) & (brk < s[k + 1])
        brk, k = brk[inside], k[inside]
        if brk.size:  # one more column per breakpoint of the busiest cell, the others at 1
            rank = np.arange(brk.size) - np.searchsorted(k, k)
            extra = np.ones((m, int(rank.max()) + 1))
            extra[k, rank] = (brk - s[k]) / h[k]
            theta = np.hstack((theta, extra))
    # One call to the bound: the nodes, then the points inside the cells.
    inside = np.ones(theta.shape, dtype=bool)
    inside[:, [0, per_interval]] = False
    inside &= theta < 1.0
    points = (s[:-1, None] + h[:, None] * theta)[inside]
    val = np.asarray(bound(np.concatenate((s, points))), dtype=np.float64)
    at = val[:s.size]
    b = np.where(theta >= 1.0, at[1:, None], at[:-1, None])
    b[inside] = val[s.size:]
    # The weights b^{-3/2} of the ends, as the share of the right one (bounds of 0 allowed).
    ends = np.log(np.maximum(at, 1e-300))
    star = 1.0 / (1.0 + np.exp(np.clip(1.5 * (ends[1:] - ends[:-1]), -50.0, 50.0)))
    star = np.clip(star, 1e-6, 1.0 - 1e-6)
    # The lower convex hull at `star`: the least value there of a chord between two samples
    # on either side of it.
    best_val = np.full(m, np.inf)
    slope, left = np.zeros(m), b[:, 0].copy()
    for i, j in zip(*np.triu_indices(theta.shape[1], 1), strict=True):
        ti, tj, bi, bj = theta[:, i], theta[:, j], b[:, i], b[:, j]
        with np.errstate(divide="ignore", invalid="ignore"):
            sl = (bj - bi) / (tj - ti)
            value = bi + sl * (star - ti)
        spans = (np.minimum(ti, tj) <= star) & (star <= np.maximum(ti, tj)) & (ti != tj)
        better = spans & (value < best_val)
        best_val = np.where(better, value, best_val)
        slope = np.where(better, sl, slope)
        left = np.where(better, bi - sl * ti, left)
    # The line through the hull's edge at `star` lies under every sample; rounding aside.
    left = left - np.maximum((left[:, None] + slope[:, None] * theta - b).max(axis=1), 0.0)
    right = left + slope
    # A bound of 0 at a node is never left in finite time where it rises like s² (a v_limit
    # knot at 0 m/s): no line from 0 lies under it. The cell is flat at 0, as the minimum.
    zero = np.minimum(at[:-1], at[1:]) <= 0.0
    left, right = np.where(zero, 0.0, left), np.where(zero, 0.0, right)
    out = at.copy()
    out[:-1] = np.minimum(out[:-1], left)
    out[1:] = np.minimum(out[1:], right)
    return out


@dataclass(frozen=True)
class Envelopes:
    """Jerk-limited envelopes of the motions leaving the start state and reaching the end."""

    limits: Limits
    smooth: bool
    jerk_limited: bool
    v0: float
    a0: float
    vf: float
    af: float
    length: float
    in_distance: bool = False
    state_j: float | None = None  # the leg's jerk (`PlanRequest.leg_jerk`; default j_max)

    @classmethod
    def of(cls, request: PlanRequest, v0: float, a0: float, vf: float, af: float,
           length: float) -> Envelopes:
        """The envelopes of one leg of ``request`` between the given states."""
        return cls(request.limits, request.smooth_standstill, request.jerk_limited, v0, a0,
                   vf, af, length, in_distance=request.reach == "distance",
                   state_j=request.leg_jerk(v0, a0, vf, af))

    def cap(self, s: FloatArray, w: FloatArray) -> FloatArray:
        """``w`` capped by the largest ``w`` reachable from (v0, a0) and reaching (vf, af).

        At rest the cap is the max-jerk start only for a smooth standstill (the paper's free
        standstill lets the acceleration jump there); a moving state is always capped: by
        the max-jerk motion, or with ``in_distance`` by the envelope in distance
        (`fastest_w`), which is above it where the vehicle
        could brake to rest and start again (``PlanRequest.reach``).
        """
        lim = self.limits
        if not self.jerk_limited:
            return w
        if self.smooth or self.v0 > 0:
            w = np.minimum(w, self._fastest(s, self.v0, self.a0, lim.a_max, lim.a_decel))
        if self.smooth or self.vf > 0:
            w = np.minimum(w, self._fastest(self.length - s, self.vf, -self.af, lim.a_decel,
                                            lim.a_max))
        return w

    def _fastest(self, d: FloatArray, v: float, a: float, a_limit: float,
                 a_brake: float) -> FloatArray:
        # The leg's jerk at a rest too: a marginal state's stop into it takes its looser
        # jerk (1.2 cm before a stop, the state's slowest motion stayed over a cap of j_max).
        j = self.state_j if self.state_j is not None else self.limits.j_max
        if self.in_distance:
            return fastest_w(d, v, a, j, a_limit, a_brake)
        return jerk_motion_w(d, v, a, j, a_limit)

    def floor(self, s: FloatArray) -> FloatArray | None:
        """The slowest motion leaving a moving start (and arriving at a moving end)."""
        lim = self.limits
        if not self.jerk_limited or (self.v0 == 0.0 and self.vf == 0.0):
            return None
        lo = np.zeros_like(s)
        j = lim.j_max if self.state_j is None else self.state_j
        if self.v0 > 0:
            lo = np.maximum(lo, jerk_motion_w(s, self.v0, self.a0, -j, -lim.a_decel))
        if self.vf > 0:
            lo = np.maximum(lo, jerk_motion_w(self.length - s, self.vf, -self.af, -j,
                                              -lim.a_max))
        return lo


def check_floor(floor: FloatArray, w_max: FloatArray, s: FloatArray, lo: float, v0: float,
                 a0: float, vf: float, af: float) -> None:
    """The slowest motion from the start (into the end) must stay under the speed bound."""
    over = floor[1:-1] > w_max[1:-1] * (1 + 1e-9) + 1e-300
    if over.any():
        i = int(np.flatnonzero(over)[0]) + 1
        near_start = s[i] < 0.5 * s[-1]
        state = (f"v0={v0:.6g} m/s, a0={a0:.6g} m/s²" if near_start else
                 f"vf={vf:.6g} m/s, af={af:.6g} m/s²")
        verb = "cannot slow down to" if near_start else "cannot come from"
        raise InfeasibleError(
            f"from {state} a jerk-limited vehicle {verb} the speed bound "
            f"{np.sqrt(w_max[i]):.6g} m/s at s={lo + s[i]:.6g} m: even its slowest motion is "
            f"at {np.sqrt(floor[i]):.6g} m/s there (j_max, a_decel, a_max)",
            constraint="speed_bound", s=float(lo + s[i]),
        )


def lateral_jerk_rows(path: Path, lo: float, s: FloatArray, j_lat_max: float, *,
                      node_curvature: NodeCurvature | None = None
                      ) -> tuple[StencilRows, ...] | None:
    """Rows ``|κ' w + κ w'| sqrt(w) <= j_lat_max`` at the nodes and the cells' midpoints.

    Lateral jerk is ``d(κ v²)/dt = sqrt(w) (κ' w + κ w')``; ``κ`` and ``κ' = dκ/ds`` are the
    path's at ``lo + s``. Two kinds of rows, each a second-order discretisation at its point:

    * **at each interior node**, ``w'`` the three-point first difference of the (non-uniform)
      grid, exact for quadratic ``w``. At a node on a join of pieces ``κ'`` jumps (a clothoid
      onto an arc): the lateral jerk takes both one-sided values there, so a second family
      holds the rows with the rate before the join (elsewhere it has none);
    * **at each cell's midpoint**, ``w' = (w_{i+1} - w_i) / h_i`` and ``w = (w_i + w_{i+1}) / 2``
      with ``κ, κ'`` at the midpoint, times ``sqrt(w)`` at either end of the cell (two families:
      the row is held with both, which bounds it with ``sqrt`` of the midpoint's ``w``).

    The node rows alone cannot see the node-to-node (odd/even) zigzag of ``w``: the centred
    difference of an alternating sequence is 0, so only the tangential jerk rows limit it and
    the discrete optimum drives it to the jerk cap (the jerk chatters between ``±j_max`` from
    node to node in curves, for a gain of ~1e-5 of the duration). The one-sided difference of
    the midpoint rows sees it. Held at twice as many points, the rows also bound the lateral
    jerk of the continuous law between the nodes (measured: 3.9 % above the limit with the
    node rows alone on a random G2 path, 0.4 % with both).
    """
    if not np.isfinite(j_lat_max):
        return None
    kappa, after, before = node_curvature or curvature_at_nodes(path, lo, s)
    h = np.diff(s)
    h0, h1 = h[:-1], h[1:]
    first = np.column_stack((-h1 / (h0 * (h0 + h1)), (h1 - h0) / (h0 * h1),
                             h0 / (h1 * (h0 + h1))))
    bound = np.full(s.size - 2, float(j_lat_max))
    families = []
    for rate, rows in ((after, bound), (before, np.where(before != after, bound, np.inf))):
        if not np.isfinite(rows).any():
            continue
        coef = lateral_rate_weights(kappa, rate, [0.0, 1.0, 0.0], first)  # w at the node
        families.append(StencilRows(coef=coef, bound=rows))
    families.extend(_midpoint_rows(path, lo, s, bound))
    families.extend(_join_rows(path, lo, s, float(j_lat_max)))
    return tuple(families)


def _join_rows(path: Path, lo: float, s: FloatArray, j_lat_max: float) -> list[StencilRows]:
    """Rows at the joins of pieces inside cells, with the law's ``w'`` there (none elsewhere).

    A grid at its node cap keeps joins as nodes only where they fit; inside a cell the
    lateral jerk jumps at the join (``κ'`` does) and neither the node nor the midpoint rows
    see the side they are not on (a law 1.13× over ``j_lat_max`` next to such a join). Two
    families hold each such join's row with the rate before and after it, at the node whose
    dual cell holds the join; a second join in the same dual cell (the ends of a line of a
    few millimetres between two clothoids) has two families of its own: without them its
    rate after it was not held, and the law reached 1.012× ``j_lat_max`` there.
    ``w'`` is the time law's (`speedplan.timing.TimeLaw`: the cell's secant slope at its
    midpoint, bent by the second difference of the node on the join's side of it, split by
    the step ratio), a stencil around that node; ``w`` the cell's linear interpolation.
    """
    joins = path.rate_joins
    if joins.size == 0 or s.size < 4:
        return []
    at = lo + s
    margin = 1e-12 * max(float(path.length), 1.0)
    h = np.diff(s)
    n = s.size
    coefs: list[list[FloatArray]] = []  # per slot (k-th join of a dual cell): two families
    bounds: list[FloatArray] = []
    for x in joins:
        c = int(np.searchsorted(at, x)) - 1  # the cell [at[c], at[c + 1]] holding x
        if not (0 <= c < n - 1 and at[c] + margin < x < at[c + 1] - margin):
            continue  # a node, or outside the leg
        theta = (x - at[c]) / h[c]
        offset = x - 0.5 * (at[c] + at[c + 1])
        # The node whose dual cell holds x, and its second difference's weights.
        node = c + 1 if offset >= 0.0 else c
        if not 1 <= node <= n - 2:
            continue  # next to the leg's end
        slot = next((k for k, b in enumerate(bounds) if not np.isfinite(b[node - 1])),
                    len(bounds))
        if slot == len(bounds):
            coefs.append([np.zeros((n - 2, 3)), np.zeros((n - 2, 3))])
            bounds.append(np.full(n - 2, np.inf))
        h0, h1 = h[node - 1], h[node]
        d2 = np.array([2.0 / (h0 * (h0 + h1)), -2.0 / (h0 * h1), 2.0 / (h1 * (h0 + h1))])
        split = h1 / h0 if node == c + 1 else h0 / h1  # the law's curvature on x's side
        if node == c + 1:  # stencil (w_c, w_{c+1}, w_{c+2})
            value = np.array([1.0 - theta, theta, 0.0])
            secant = np.array([-1.0, 1.0, 0.0]) / h[c]
        else:  # stencil (w_{c-1}, w_c, w_{c+1})
            value = np.array([0.0, 1.0 - theta, theta])
            secant = np.array([0.0, -1.0, 1.0]) / h[c]
        slope = secant + offset * split * d2
        kappa = float(path.curvature(np.array([x]))[0])
        for family, rate in ((0, float(path.curvature_rate(np.array([x]))[0])),
                             (1, float(path.curvature_rate_before(np.array([x]))[0]))):
            coefs[slot][family][node - 1] = lateral_rate_weights(
                np.array([kappa]), np.array([rate]), value, slope)[0]
        bounds[slot][node - 1] = j_lat_max
    return [StencilRows(coef=coef, bound=bound)
            for pair, bound in zip(coefs, bounds, strict=True) for coef in pair]


def curvature_at_nodes(path: Path, lo: float, s: FloatArray) -> NodeCurvature:
    """``κ``, and ``κ'`` after and before each interior node (they differ on piece joins)."""
    q = lo + s[1:-1]
    kappa = np.asarray(path.curvature(q), dtype=np.float64)
    after = np.asarray(path.curvature_rate(q), dtype=np.float64)
    before = after.copy()
    joins = path.rate_joins
    if joins.size:
        k = np.searchsorted(joins, q)  # nearest join to each node
        on = np.zeros(q.size, dtype=bool)
        for cand in (np.clip(k - 1, 0, joins.size - 1), np.clip(k, 0, joins.size - 1)):
            on |= np.abs(joins[cand] - q) <= 1e-12 * max(float(path.length), 1.0)
        if on.any():
            before[on] = path.curvature_rate_before(q[on])
    return kappa, after, before


def lateral_speed_caps(path: Path, lo: float, s: FloatArray, j_lat_max: float,
                       accel: FloatArray, decel: FloatArray, *,
                       node_curvature: NodeCurvature | None = None) -> FloatArray:
    """Upper bounds on interior ``w`` that the lateral-jerk and acceleration rows imply.

    The node row ``|κ' w_i + κ w'_i| sqrt(w_i) <= j_lat_max`` (`lateral_jerk_rows`) has
    ``w'_i`` a convex combination of the slopes of the two adjacent cells, each within
    ``[-D, A]`` by the acceleration rows. So ``|κ' w_i + κ w'_i| >= |κ'| w_i - |κ| M_i`` with
    ``M_i`` the larger braking bound ``D`` of the two cells where ``κ' κ > 0`` (braking eases
    a curvature that grows in magnitude), the larger ``A`` elsewhere, and every feasible ``w``
    has ``sqrt(w_i) (|κ'| w_i - |κ| M_i) <= j_lat_max``: ``w_i <= x²``, with ``x`` the positive
    root of ``|κ'| x³ - |κ| M_i x - j_lat_max``. The bound removes no feasible point of the
    discrete problem (its optimum is unchanged), but the relaxation can no longer drive
    ``w`` past it and pay for the lateral-jerk excess at one node: on comfort plans the
    certified gap falls from a few per cent to about 0.1 % (``benchmarks/bench_comfort.py``).
    ``inf`` where the curvature rate is 0.
    """
    kappa, after, before = node_curvature or curvature_at_nodes(path, lo, s)
    caps = np.full(s.size - 2, np.inf)
    for rate in (after, before):
        eases = rate * kappa > 0
        m = np.where(eases, np.maximum(decel[:-1], decel[1:]),
                     np.maximum(accel[:-1], accel[1:]))
        a = np.abs(rate)
        on = a > 0
        if not on.any():
            continue
        a, km = a[on], np.abs(kappa[on]) * m[on]
        # f(x) = a x³ - km x - B is convex and increasing right of its root: Newton from an
        # upper bound of the root converges from the right, monotonically.
        x = np.maximum(np.cbrt(2.0 * j_lat_max / a), np.sqrt(2.0 * km / a))
        for _ in range(CAP_NEWTON_STEPS):
            x = x - (a * x**3 - km * x - j_lat_max) / (3.0 * a * x * x - km)
        caps[on] = np.minimum(caps[on], x * x * (1.0 + CAP_MARGIN))
    return caps


def _midpoint_rows(path: Path, lo: float, s: FloatArray, bound: FloatArray
                   ) -> tuple[StencilRows, StencilRows]:
    """The midpoint rows of `lateral_jerk_rows`, with ``sqrt(w)`` of either end of a cell.

    The first family's row at node ``i`` is the cell ``(i, i+1)``'s, the second's the cell
    ``(i-1, i)``'s.
    """
    h = np.diff(s)
    mid = lo + 0.5 * (s[:-1] + s[1:])
    kappa = path.curvature(mid)
    rate = path.curvature_rate(mid)
    # w' = (w_{i+1} - w_i) / h with the 1/h taken into the curvature (κ/h, not κ (1/h)).
    left, right = lateral_rate_weights(kappa / h, rate, [0.5, 0.5], [-1.0, 1.0]).T
    zero = np.zeros(s.size - 2)
    ahead = StencilRows(coef=np.column_stack((zero, left[1:], right[1:])), bound=bound)
    behind = StencilRows(coef=np.column_stack((left[:-1], right[:-1], zero)), bound=bound)
    return ahead, behind
