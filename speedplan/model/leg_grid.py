"""The grid of one leg: the jerk-limited default grid, the no-jerk grid, a user grid's ends.

`leg_grid` chooses: a user grid (``n`` or ``ds``) graded at the boundary transients, the
adaptive default grid of a jerk-limited request (`speedplan.model.grid.adaptive_grid` under
the leg's envelopes, with nodes on the path's joins where lateral jerk is limited), or the
no-jerk grid, refined where its node bounds cost time.
"""

from __future__ import annotations

import numpy as np

from ..core.checks import FloatArray
from ..core.errors import InvalidInputError
from ..core.rates import largest_under_rates
from ..geometry import CellSamples, SpeedBound, bound_breakpoints
from .boundary import turnaround_speed
from .grid import (
    MAX_DEFAULT_NODES,
    adaptive_grid,
    dips_between,
    graded_ends,
    rest_phase_length,
    subdivided_grid,
    top_speed,
    uniform_grid,
)
from .request import PlanRequest
from .rows import Envelopes, node_minima

__all__ = ["KINK_PROBE", "NO_JERK_BOUND_LOSS", "NO_JERK_NODES", "NO_JERK_REFINEMENTS",
           "bound_kinks", "default_grid", "grid_anchors", "kink_anchors", "leg_grid",
           "no_jerk_grid"]

#: Uniform grid of a request without jerk limit (the O(n) pass is exact on any grid).
NO_JERK_NODES = 1001


#: A moving end's acceleration whose removal at ``j_max`` takes less than this fraction of
#: the end's jerk transition gets no steps of its own (`boundary_transient`): a first step
#: of the transition's (1 / `speedplan.model.grid.END_PER_PHASE` of it) absorbs it for at
#: most 1 % of ``j_max``. Sized by removal time instead, a state read with a rounding-level
#: acceleration (1e-12 of ``a_max``, or a subnormal 1e-311) would grade a user grid's end to
#: steps of 1e-11 of the move (`speedplan.model.grid.MIN_RELATIVE_STEP`, 1.6 nm on 161 m),
#: where ``w`` changes by 1e-16 from node to node and the law's jerk (1.08-1.57 of
#: ``j_max``) depends on the relaxation's last digits. At the threshold the grading switches:
#: just above it the end's first step is the removal's (2000 times finer on a 161 m move
#: from 0.026 m/s) and the grid has more nodes; both sides keep the law within 2 % of
#: ``j_max``.
NEGLIGIBLE_REMOVAL = 5e-4
#: Rounds in which the default no-jerk grid is refined (steps / 4) where the optimum rides a
#: node bound more than `NO_JERK_BOUND_LOSS` below the bound at the node itself: the
#: minimum over the adjacent cells (`node_bounds`) costs time there, like ``O(h)``.
NO_JERK_REFINEMENTS = 1


NO_JERK_BOUND_LOSS = 1e-3


def default_grid(request: PlanRequest, leg_bound: SpeedBound, lo: float, hi: float,
                  v0: float, a0: float, vf: float, af: float,
                  max_nodes: int = MAX_DEFAULT_NODES) -> FloatArray:
    """The jerk-limited default grid of the leg ``[lo, hi]`` (`adaptive_grid`)."""
    lim = request.limits
    length = hi - lo
    env = Envelopes.of(request, v0, a0, vf, af, length)
    low = [v for v in (v0, vf) if v > 0] + [
        turnaround_speed(v, a, lim.j_max) for v, a in ((v0, a0), (vf, -af))
        if v > 0 and a < 0]
    v_top = top_speed(leg_bound, length, lim.v_max, v0 * v0, vf * vf)
    breaks = bound_breakpoints(request.path, leg_bound)
    return adaptive_grid(length, lambda q: env.cap(q, leg_bound(q)), a_max=lim.a_max,
                         a_decel=lim.a_decel, v_max=lim.v_max, j_max=lim.j_max,
                         w_start=v0**2, w_end=vf**2,
                         v_low=min((v for v in low if v > 0), default=None),
                         anchors=grid_anchors(request, lo, hi), max_nodes=max_nodes,
                         breakpoints=breaks, v_top=v_top,
                         nodes_at=kink_anchors(request, leg_bound, length, breaks))


def no_jerk_grid(request: PlanRequest, bound: SpeedBound, length: float, v0: float,
                  vf: float) -> CellSamples:
    """`NO_JERK_NODES` uniform nodes, refined where the node bounds cost time; with the bound.

    Where the bound falls steeply (a corner's clothoid, a zone's edge) the node bound, the
    minimum over both adjacent cells, lies well below the bound at the node; where the no-jerk
    optimum rides it, those cells and their neighbours are cut in four
    (`subdivided_grid`; the no-jerk law is linear in ``w`` per cell and needs
    no smoothness of the steps). Every other cell is kept to the last bit, so the bound
    already evaluated inside it is kept, not evaluated again: the grid comes with the bound
    and the curvature at its `cell_points` (`CellSamples`), from which the leg takes its
    node bounds (`leg_on_grid`) and its law's check reads the bound. The O(n) pass makes each
    round cheap; on the serpentine of ``benchmarks/bench_all.py`` one round takes the duration
    from 3.9 % to 1.0 % above the exact optimum.
    """
    lim = request.limits
    s = uniform_grid(length, n=NO_JERK_NODES)
    breaks = bound_breakpoints(request.path, bound)
    breaks = breaks[breaks <= length]
    samples = CellSamples.of(bound, s, extra=breaks)  # the law's check reads the breakpoints too
    inside = (breaks > s[0]) & (breaks < s[-1])
    if inside.any():  # hidden_dips, from the values just evaluated
        k = np.minimum(np.maximum(np.searchsorted(s, breaks[inside]), 1), s.size - 1)
        dips = dips_between(s, breaks[inside], samples.extra_bound[inside],
                            samples.bound[k - 1], samples.bound[k], cells=True)
        if dips.size:
            s = _cut_out_dips(s, dips)
            samples = samples.on_grid(bound, s)
    for _ in range(NO_JERK_REFINEMENTS):
        if s.size > MAX_DEFAULT_NODES:
            break
        nodes = node_minima(samples.bound)
        own = samples.bound[:s.size]  # the bound at the nodes themselves (cell_points)
        w_max = nodes.copy()
        w_max[0], w_max[-1] = max(w_max[0], v0 * v0), max(w_max[-1], vf * vf)
        h = s[1:] - s[:-1]  # the exact no-jerk optimum on this grid (speedplan.solve.nojerk)
        w = largest_under_rates(w_max, lim.A * h, lim.A_decel * h)
        lossy = (w >= nodes * (1.0 - 1e-9)) & (nodes < (1.0 - NO_JERK_BOUND_LOSS) * own)
        if not lossy.any():
            break
        cells = lossy[:-1] | lossy[1:]  # the cells on either side of each lossy node
        s = subdivided_grid(s, cells, parts=4)
        samples = samples.on_grid(bound, s)
    return samples


def _cut_out_dips(s: FloatArray, edges: FloatArray) -> FloatArray:
    """``s`` with nodes on the ``edges`` of dips of the bound and steps doubling away from them.

    A dip narrower than a step of the no-jerk grid (a hairpin's arc, a narrow zone; its
    edges from `hidden_dips`) was found by the refinements only
    where a few quarterings reach it: a 0.55 mm arc on a 1.9 km path was crossed at 18x its
    speed. With nodes on its edges the dip's cells hold its own bound; the node bound of a
    neighbour (the minimum over its cells, the dip's edge included) is the dip's too, so the
    neighbours are brought in at steps growing from the dip's width, ``w 2^k``: what the
    node bounds lose is one such step on either side.
    """
    if edges.size == 0:
        return s
    cell = np.searchsorted(s, edges) - 1
    extra = [edges]
    for c in np.unique(cell):
        lo, hi = float(edges[cell == c].min()), float(edges[cell == c].max())
        h = float(s[c + 1] - s[c])
        width = hi - lo if hi > lo else h / 1024.0
        ladder: FloatArray = width * 2.0 ** np.arange(int(np.ceil(np.log2(h / width))),
                                                     dtype=np.float64)
        extra += [lo - ladder, hi + ladder]
    new = np.unique(np.clip(np.concatenate(extra), s[0], s[-1]))
    k = np.clip(np.searchsorted(s, new), 1, s.size - 1)
    apart = np.minimum(new - s[k - 1], s[k] - new) > 1e-12 * float(s[-1] - s[0])
    out: FloatArray = np.union1d(s, new[apart])  # no cell of a few ulps
    return out


#: Relative offset [of the leg's length] at which `bound_kinks` reads the bound's one-sided
#: values and slopes next to a breakpoint.
KINK_PROBE = 1e-7


def bound_kinks(bound: SpeedBound, breaks: FloatArray, length: float) -> FloatArray:
    """The ``breaks`` where the bound steps or kinks convexly (its slope increases).

    There the chord of a cell with the point inside lies above the bound by ``O(h)``
    (`chord_node_bounds`); a node on it costs nothing. A concave kink (the bound leaving
    ``v_max²`` into a curve) or a join where the bound is smooth needs none.

    Examples
    --------
    >>> import numpy as np
    >>> from speedplan import Limits
    >>> from speedplan.geometry import Arc, Clothoid, Line, Path, SpeedBound
    >>> p = Path.from_segments([Line(5.0), Clothoid(2.0, 0.0, 0.5), Arc(radius=2.0, angle=1.0)])
    >>> bound = SpeedBound(p, Limits(v_max=2, a_max=1, a_lat_max=1, j_max=0.5))
    >>> bound_kinks(bound, np.array([5.0, 7.0]), float(p.length)).tolist()  # the arc's start
    [7.0]
    """
    breaks = breaks[(breaks > 0.0) & (breaks < length)]
    if breaks.size == 0:
        return breaks
    eps = KINK_PROBE * length
    probe = breaks[:, None] + eps * np.array([-2.0, -1.0, 1.0, 2.0])[None, :]
    b = np.asarray(bound(probe.ravel()), dtype=np.float64).reshape(probe.shape)
    left_slope, right_slope = (b[:, 1] - b[:, 0]) / eps, (b[:, 3] - b[:, 2]) / eps
    left, right = b[:, 1] + eps * left_slope, b[:, 2] - eps * right_slope
    scale = np.maximum(np.abs(b).max(axis=1), 1e-300)
    step = np.abs(right - left) > 1e-6 * scale
    kink = right_slope - left_slope > 1e-3 * np.maximum(np.abs(left_slope), np.abs(right_slope))
    out: FloatArray = breaks[step | kink]
    return out


def kink_anchors(request: PlanRequest, leg_bound: SpeedBound, length: float,
                 breaks: FloatArray | None = None) -> FloatArray:
    """Where a jerk-limited leg's grids put nodes for its bound: `bound_kinks` (else none).

    With a node on each, the node bounds of `chord_node_bounds` lose only
    ``O(h²)`` of the bound, and the discrete optimum converges at second order in the step.
    Without a jerk or lateral-jerk limit the law is linear per cell and the no-jerk grid
    handles the bound by its own refinement (`no_jerk_grid`).
    """
    if not (request.jerk_limited or np.isfinite(request.limits.j_lat_max)):
        return np.zeros(0)
    if breaks is None:
        breaks = bound_breakpoints(request.path, leg_bound)
    return bound_kinks(leg_bound, breaks, length)


def boundary_transient(request: PlanRequest, v: float, a: float, a_limit: float,
               length: float, v_top: float) -> float | None:
    """Length of a leg's first boundary transient (its last one: ``v = vf``, ``a = -af``).

    At a smooth standstill the first jerk phase from rest (``None`` for the paper's free
    standstill, where the acceleration may jump). A moving state: the shorter of the
    distance covered while its acceleration is brought to 0, a jerk transition
    ``v min(t_j, √(v / j))`` at the lowest speed it passes (the default grid's scale) and,
    braking, the distance ``v² / (2 |a|)`` to rest at that deceleration. The phases are
    those under ``v_top``, the leg's top speed (`top_speed`). An acceleration removed in
    less than `NEGLIGIBLE_REMOVAL` of the jerk transition's time counts as none.
    """
    j = request.limits.j_max
    if v == 0.0 and a == 0.0:
        return (rest_phase_length(a_limit, v_top, j, length)
                if request.smooth_standstill else None)
    low = turnaround_speed(v, a, j) if a < 0 else v
    speed = low if low > 0 else v
    t_j = min(a_limit / j, float(np.sqrt(v_top / j)))
    transition = min(t_j, float(np.sqrt(speed / j)))
    scale = speed * transition
    if abs(a) / j >= NEGLIGIBLE_REMOVAL * transition:
        t = abs(a) / j
        removal = v * t + 0.5 * a * t * t - float(np.sign(a)) * j * t**3 / 6.0
        if removal > 0.0:
            scale = min(scale, removal)
    if a < 0.0:  # the first step well below the braking distance: see check_moving_ends_resolved
        scale = min(scale, 0.5 * v * v / -a)
    return scale if scale > 0.0 else None


def grid_anchors(request: PlanRequest, lo: float, hi: float) -> FloatArray:
    """Where a leg's default grids put nodes: the path's `rate_joins` inside ``(lo, hi)``.

    In the leg's arc length, and only with a lateral-jerk limit: the curvature rate jumps
    there (joins of pieces, knots of spline and NURBS pieces), and with a node on the join
    its two one-sided lateral-jerk rows hold the jump.
    """
    if not np.isfinite(request.limits.j_lat_max):
        return np.zeros(0)
    joins = request.path.rate_joins
    out: FloatArray = joins[(joins > lo) & (joins < hi)] - lo
    return out


def check_moving_ends_resolved(s: FloatArray, lo: float, v0: float, a0: float, vf: float,
                                af: float) -> None:
    """A user grid must let the speed stay positive over the first (last) half cell.

    The grading of user grids (`boundary_transient`, `graded_ends`) makes the end
    steps shorter than this; what remains refused is a transient below the finest step.

    The time law keeps the prescribed acceleration at a moving end; a braking start
    (accelerating arrival) then loses ``|a| h`` of ``w`` over the half cell, so a step
    ``h >= v² / |a|`` would bring the vehicle to rest inside the cell: that transient is
    shorter than the grid can resolve.
    """
    for name, v, slowing, h, where in (("start", v0, -a0, s[1] - s[0], lo),
                                       ("end", vf, af, s[-1] - s[-2], lo + s[-1])):
        if v > 0 and slowing > 0 and h >= 0.5 * v * v / slowing:
            h_max = 0.5 * v * v / slowing
            n_min = int(np.ceil(float(s[-1]) / h_max)) + 1
            state = (f"v0={v:.6g} m/s, a0={-slowing:.6g} m/s²" if name == "start"
                     else f"vf={v:.6g} m/s, af={slowing:.6g} m/s²")
            raise InvalidInputError(
                f"the grid step {h:.3g} m is too coarse for the {name} state {state} at "
                f"s={where:.6g} m: its transient lasts less than one step (steps below "
                f"{h_max:.3g} m resolve it); use the default grid (n=None and ds=None), "
                f"n >= {n_min} or ds < {h_max:.3g}"
            )


def leg_grid(request: PlanRequest, leg_bound: SpeedBound, lo: float, hi: float, v0: float,
             a0: float, vf: float, af: float) -> FloatArray:
    """The grid of the leg ``[lo, hi]`` (from 0 to its length), as the request asks for it.

    A user grid (``n`` or ``ds``) is uniform, graded at a jerk-limited request's boundary
    transients (`graded_ends`); otherwise the jerk-limited default grid (`default_grid`) or
    the no-jerk grid (`no_jerk_grid`).

    Raises
    ------
    InvalidInputError
        A user grid whose first (last) step is too coarse for a moving boundary state's
        transient (`check_moving_ends_resolved`).
    """
    lim = request.limits
    length = hi - lo
    if request.n is not None or request.ds is not None:
        s = uniform_grid(length, n=request.n, ds=request.ds)
        if request.jerk_limited:
            v_top = top_speed(leg_bound, length, lim.v_max, v0 * v0, vf * vf)
            s = graded_ends(s, boundary_transient(request, v0, a0, lim.a_max, length, v_top),
                            boundary_transient(request, vf, -af, lim.a_decel, length, v_top))
        check_moving_ends_resolved(s, lo, v0, a0, vf, af)
        return s
    if request.jerk_limited:
        return default_grid(request, leg_bound, lo, hi, v0, a0, vf, af)
    return no_jerk_grid(request, leg_bound, length, v0, vf).s
