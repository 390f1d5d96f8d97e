"""Default arc-length grids: fine where jerk-limited transitions happen, smoothly graded.

A jerk-limited change of speed at speed ``v`` takes ``min(t_j, sqrt(v / j))`` seconds
(``t_j = min(a / j, sqrt(v_max / j))``) and spans ``λ(v) = v min(t_j, sqrt(v / j))`` metres;
from rest the first transition spans ``ℓ = j t_j³ / 6``. The default grid puts ``per_phase``
nodes on each such length, with ``v(s)`` estimated by the exact no-jerk optimum under the
boundary envelopes (so a decelerating start that dips to a low speed gets a fine grid there).
Where ``λ(v)`` falls below ``ℓ`` on the stretches next to the ends (the speed rising from
rest), the steps stay at ``ℓ / per_phase``; a slow stretch farther inside (a slow zone, a
tight curve) is resolved at its own ``λ(v)``, however short.

Its properties (the time law, `speedplan.timing.law`, relies on the first):

* **smooth grading**: neighbouring steps differ by at most `GRADING` (1 %) wherever
  the speed may change, by `CRUISE_GRADING` (4 %) inside long stretches at a constant
  speed bound; the law's jerk error is the local step ratio minus one;
* **cruise is coarse**: far (``> 2 v_max t_j + 2 ℓ``, or more than `CRUISE_MARGIN_TIME`
  ``t_j`` in time) from any kink of the no-jerk profile
  (where it is linear in ``w``: a cruise, a constant acceleration or braking) the step grows,
  by 4 % per node, up to `CRUISE_STEP` of the length: a long move costs a few hundred
  nodes more than a short one, and does not hit the node cap with a coarse transition;
* **a followed bound is stepped by its shape**: where the no-jerk profile follows a curved
  bound (a clothoid at its yaw-rate or lateral limit) with a jerk and an acceleration well
  inside the limits, the law follows it too; more than `CRUISE_MARGIN_TIME` ``t_j`` from
  where either is large, the steps resolve the bound's shape (`SHAPE_SAG`), not its jerk
  transitions.

Nodes are placed by inverting the node count ``N(s) = ∫ ds / h(s)`` exactly for a step
``h(s)`` piecewise linear on a fine pre-grid: consecutive steps follow ``h(s)``, with no jump
where the pre-grid cells meet (the old grid inverted a piecewise-linear count and its steps
jumped by up to 19 % there).

Where a planned law exceeds a limit, `refined_grid` makes the steps finer around the flagged
cells (smoothly graded again) and `subdivided_grid` cuts cells in equal parts.
"""

from __future__ import annotations

import itertools
import math
from collections.abc import Callable
from dataclasses import dataclass, replace

import numpy as np

from ..core.checks import FloatArray, grid_size
from ..core.rates import largest_under_rates

__all__ = [
    "ANCHOR_ROOM",
    "CAPPED_GRADING",
    "CRUISE_GRADING",
    "CRUISE_MARGIN_TIME",
    "CRUISE_STEP",
    "DEFAULT_PER_PHASE",
    "END_PER_PHASE",
    "END_SHARE",
    "END_ZONE",
    "GRADING",
    "HIDDEN_DIP",
    "KINK_REFINE",
    "MAX_DEFAULT_NODES",
    "MIN_ANCHOR_NODES",
    "MIN_NODES",
    "MIN_RELATIVE_STEP",
    "PAD_CELLS",
    "PRE_GRID_APART",
    "PRE_GRID_POINTS",
    "SHAPE_SAG",
    "SMOOTH_ACCELERATION",
    "SMOOTH_JERK",
    "TOP_SPEED_PROBES",
    "adaptive_grid",
    "dips_between",
    "graded_ends",
    "graded_steps",
    "hidden_dips",
    "nodes_from_steps",
    "refined_grid",
    "rest_phase_length",
    "subdivided_grid",
    "top_speed",
    "uniform_grid",
]

#: The end zones a node cap keeps (see `adaptive_grid`): at most this fraction of the
#: length on each side, and of the nodes in all.
END_ZONE = 0.125
END_SHARE = 0.25
#: Nodes per jerk transition of the default grid.
DEFAULT_PER_PHASE = 80
#: Largest default grid; beyond, every step grows in proportion (the grading ratio with it).
MAX_DEFAULT_NODES = 20_000
#: Fewest nodes of a default grid.
MIN_NODES = 200
#: Finest step of a default grid, relative to the length: near the end of a path of length
#: L, positions are rounded to ~1e-16 L, so a step of 1e-11 L still has 5 correct digits (a
#: transition shorter than ~1e-9 L — a 1 nm final jerk phase on a 1 km move — is then not
#: resolved, and plan() reports it: status "limits_exceeded"). At 1e-9 L, 3 % of the trust
#: fuzz's plans (long moves, short jerk phases) were flagged; at 1e-11 L, 0.5 %.
MIN_RELATIVE_STEP = 1e-11
#: Largest relative change between neighbouring steps where the speed may change.
GRADING = 0.01
#: Fewest nodes between two grid anchors (points that must be nodes, e.g. joins of path
#: pieces where the curvature rate jumps, kinks of the speed bound): the count between two
#: anchors is made an integer by a scale that is 1 at both and bends in between, which
#: changes neighbouring steps by about ``3 / N²`` over ``N`` steps (0.5 % at 25), within the
#: grading.
MIN_ANCHOR_NODES = 25
#: The default grid's steps leave this many times `MIN_ANCHOR_NODES` between two anchors.
ANCHOR_ROOM = 1.5
#: The default grid's steps between two kinks of the speed bound (nodes where it fits) are at
#: most this many times finer than elsewhere to leave room for `MIN_ANCHOR_NODES`; those
#: between two anchors never finer than a jerk transition's steps divided by this.
KINK_REFINE = 4.0
#: Largest relative change between neighbouring steps inside long constant-bound stretches.
#: Below the jerk tolerance of `speedplan.timing.verify` (5 %): where the no-jerk estimate
#: takes a stretch for a cruise and the law still has a jerk phase there (a comfort limit
#: the estimate does not see), the law's jerk stays within it. At 10 % such laws reached
#: 1.10x ``j_max`` and were solved again on a refined grid (20 of 100 random comfort plans).
CRUISE_GRADING = 0.04
#: The cruise grading where a node cap binds (`adaptive_grid`'s ``max_nodes``, the coarser
#: grids of `speedplan.strategy`): there the transitions keep their steps first, and a cap
#: of a few hundred nodes leaves no room for a finer grading between them.
CAPPED_GRADING = 0.1
#: Nodes per boundary transient of a user grid (``n`` or ``ds``): the first jerk phase from
#: rest (last into rest), or the first change of a moving end's acceleration. At a rest the
#: law's jerk exceeds ``j_max`` by about ``0.4 h / ℓ`` (measured on straight moves; 12 % on
#: the 1 000-node uniform grids of three sample paths), so 20 nodes keep it near 2 %, half
#: the jerk tolerance with the grading's 1 %.
END_PER_PHASE = 20
#: Positions at which `adaptive_grid` evaluates the bound for the path's top speed.
TOP_SPEED_PROBES = 2001
#: A stretch where the no-jerk profile is linear in ``w`` is also cruise when it lies farther
#: than this many ``t_j`` in time from any kink of that profile (besides farther than the
#: margin in metres, which is sized at the top speed). The jerk-limited law leaves the
#: no-jerk one within a transition of each kink (at most ``t_j`` per jerk phase).
CRUISE_MARGIN_TIME = 3.0
#: A curved stretch of the no-jerk profile is smooth (`adaptive_grid` steps it by its shape,
#: `SHAPE_SAG`, not by its jerk transitions) farther than `CRUISE_MARGIN_TIME` ``t_j`` in
#: time from every point where following it takes more than this fraction of ``j_max``...
SMOOTH_JERK = 0.25
#: ... or more than this fraction of the acceleration limits (the law leaves the bound
#: where following it would take more than ``a_max``).
SMOOTH_ACCELERATION = 0.9
#: Largest sag of a chord under a smooth stretch of the no-jerk profile, relative to ``w``:
#: the steps there resolve the bound's shape.
SHAPE_SAG = 1e-6
#: Most points of the uniform part of the pre-grid on which `adaptive_grid` evaluates its
#: steps (four per end transition ``ℓ`` where that is fewer), before refining it where the
#: steps are finer than its cells. Evaluating the steps on 200 001 points took 0.4 s of a
#: 0.6 s plan with 6 600 nodes; on 20 001 and refined, the grid has the same steps to 0.1 %.
PRE_GRID_POINTS = 20_001
#: Largest step inside long constant-bound stretches, as a fraction of the length: nothing
#: changes there, the steps only grow (by `CRUISE_GRADING` per node) from the fine
#: transitions on either side.
CRUISE_STEP = 0.01


def uniform_grid(length: float, *, n: int | None = None, ds: float | None = None) -> FloatArray:
    """Uniform grid over ``[0, length]`` with ``n`` nodes or step at most ``ds``."""
    if n is None:
        if ds is None:
            raise ValueError("uniform_grid needs `n` or `ds`")
        n = int(np.ceil(length / ds)) + 1
    n = grid_size("n", max(int(n), 3))
    return np.linspace(0.0, length, n)


def rest_phase_length(a: float, v_max: float, j_max: float,
                      length: float = np.inf) -> float:
    """Length ``ℓ = j t³ / 6`` of the first jerk phase from rest.

    ``t = min(a / j, √(v_max / j), ∛(length / (2 j)))``: the phase ends at the largest
    acceleration, or when the speed reaches ``v_max``, or (a move too short for either:
    four jerk phases of ``t``, ``2 j t³`` long) half way to the move's peak acceleration.

    Examples
    --------
    >>> rest_phase_length(1.0, 2.0, 0.5)  # 2 s at 0.5 m/s³
    0.6666666666666666
    >>> round(rest_phase_length(1.0, 2.0, 0.5, length=1.2), 12)  # a 1.2 m move: length / 12
    0.1
    """
    t = min(a / j_max, float(np.sqrt(v_max / j_max)), float(np.cbrt(length / (2.0 * j_max))))
    return float(j_max * t**3 / 6.0)


def graded_ends(s: FloatArray, ell_start: float | None,
                     ell_end: float | None) -> FloatArray:
    """The uniform grid ``s`` with steps of ``ℓ / END_PER_PHASE`` at its ends.

    ``ell_start`` (``ell_end``) is the length ``ℓ`` of the first (last) boundary transient
    (`rest_phase_length` at a rest), ``None`` to keep that end's steps. Where the
    uniform step exceeds ``ℓ / END_PER_PHASE`` the steps are that over ``2 ℓ`` from the end
    and then grow by `GRADING` per node back to the uniform step; the other nodes stay
    those of ``s``. Without it the first law of a coarse grid exceeds ``j_max`` (or the
    speed bound) there and `speedplan.plan` refines the grid and solves again — or,
    where three refinements do not reach the transient, reports ``limits_exceeded``.

    Examples
    --------
    >>> import numpy as np
    >>> s = np.linspace(0.0, 30.0, 301)
    >>> g = graded_ends(s, 0.667, None)
    >>> float(np.diff(g)[0].round(4)), bool(np.all(g[-150:] == s[-150:]))
    (0.0333, True)
    >>> bool(np.max(np.diff(g)[1:] / np.diff(g)[:-1]) < 1.0101)  # graded back to 0.1
    True
    >>> bool(np.all(graded_ends(s, 4.0, 4.0) == s))
    True
    """
    h = float(s[1] - s[0])
    length = float(s[-1])
    # Per graded end: its distance function, its fine step, the uniform cells it replaces.
    zones: list[tuple[int, float, float]] = []
    cells = [0, 0]
    for end, ell in ((0, ell_start), (1, ell_end)):
        if ell is None or not h * END_PER_PHASE > ell:
            continue
        fine = max(ell / END_PER_PHASE, MIN_RELATIVE_STEP * length)
        zones.append((end, fine, 2.0 * ell))
        cells[end] = int(np.ceil((2.0 * ell + (h - fine) / GRADING) / h))
    if not zones:
        return s
    if sum(cells) >= s.size - 1:  # a short grid: the graded zones meet
        grid = _graded(0.0, length, h, zones, length)
    else:
        first, last = cells
        grid = np.concatenate((
            _graded(0.0, float(s[first]), h, zones, length)[:-1] if first else s[:0],
            s[first:s.size - last],
            _graded(float(s[-1 - last]), length, h, zones, length)[1:] if last else s[:0],
        ))
    grid_size("n", grid.size)
    return grid


def _graded(lo: float, hi: float, h: float, zones: list[tuple[int, float, float]],
            length: float) -> FloatArray:
    """Nodes on ``[lo, hi]``: steps ``fine`` up to ``reach`` from each graded end, then ``h``.

    In between, the steps grow by `GRADING` per node.
    """
    pre = [np.linspace(lo, hi, 2001)]
    for end, fine, _ in zones:
        near = np.geomspace(0.25 * fine, length, 400)
        pre.append(near if end == 0 else length - near)
    sf = np.unique(np.clip(np.concatenate(pre), lo, hi))
    step = np.full(sf.size, h)
    for end, fine, reach in zones:
        d = sf if end == 0 else length - sf
        step = np.minimum(step, fine + GRADING * np.maximum(d - reach, 0.0))
    return nodes_from_steps(sf, step)


def graded_steps(s: FloatArray, h: FloatArray, rate: FloatArray) -> FloatArray:
    """Largest steps ``<= h`` that change by at most ``rate`` per unit length.

    ``h_out(s_i) = min_j (h_j + |τ_i - τ_j|)`` with ``τ = ∫ rate ds``: two min-plus passes
    (``np.minimum.accumulate``), the same O(n) construction as the no-jerk profile.

    Examples
    --------
    >>> import numpy as np
    >>> s = np.linspace(0.0, 10.0, 11)
    >>> h = np.where(s == 5.0, 0.1, 10.0)
    >>> graded_steps(s, h, np.full(11, 0.1)).round(6).tolist()[3:8]
    [0.3, 0.2, 0.1, 0.2, 0.3]
    """
    tau = np.concatenate(([0.0], np.cumsum(0.5 * (rate[1:] + rate[:-1]) * np.diff(s))))
    fwd = tau + np.minimum.accumulate(h - tau)
    bwd = (-tau + np.minimum.accumulate((h + tau)[::-1])[::-1])
    out: FloatArray = np.minimum(np.minimum(fwd, bwd), h)
    return out


def nodes_from_steps(s: FloatArray, h: FloatArray,
                     anchors: FloatArray | None = None) -> FloatArray:
    """Grid with local step ``h(s)`` (piecewise linear over the pre-grid ``s``).

    ``N(s) = ∫ ds / h`` is inverted exactly in each pre-grid cell (``h`` linear there gives a
    logarithmic count), after scaling ``h`` so that ``N(length)`` is an integer: consecutive
    steps then follow ``h`` smoothly. With ``anchors`` (points of the pre-grid ``s``) the
    scaling is done between consecutive anchors, so that each anchor is a node; an anchor
    closer than `MIN_ANCHOR_NODES` steps to the previous one is skipped (the change of
    scale there would break the grading).

    Examples
    --------
    >>> import numpy as np
    >>> g = nodes_from_steps(np.array([0.0, 1.0]), np.array([0.25, 0.25]))
    >>> g.tolist()
    [0.0, 0.25, 0.5, 0.75, 1.0]
    >>> s = np.linspace(0.0, 1.0, 201)
    >>> h = np.linspace(0.004, 0.006, 201)
    >>> g = nodes_from_steps(s, h, anchors=np.array([s[77]]))
    >>> bool(s[77] in g), bool(np.all(np.diff(g) > 0))
    (True, True)
    """
    ds = np.diff(s)
    dh = np.diff(h)
    slope = dh / ds
    with np.errstate(divide="ignore", invalid="ignore"):
        cell = np.where(np.abs(dh) > 1e-12 * h[:-1], np.log(h[1:] / h[:-1]) / slope, ds / h[:-1])
    cum_raw = np.concatenate(([0.0], np.cumsum(cell)))
    cuts = [0]
    if anchors is not None:
        for a in np.unique(np.asarray(anchors, dtype=np.float64)):
            k = int(np.searchsorted(s, a))
            if 0 < k < s.size - 1 and s[k] == a \
                    and cum_raw[k] - cum_raw[cuts[-1]] >= MIN_ANCHOR_NODES \
                    and cum_raw[-1] - cum_raw[k] >= MIN_ANCHOR_NODES:
                cuts.append(k)
    cuts.append(s.size - 1)
    factor = np.empty(ds.size)  # N is scaled by this on each cell: integer between cuts
    if len(cuts) == 2:
        factor[:] = max(int(np.ceil(cum_raw[-1] - 1e-9)), 1) / cum_raw[-1]
    for k0, k1 in itertools.pairwise(cuts if len(cuts) > 2 else []):
        # Between anchors the scale is 1 at both ends and bends in between (a parabola in the
        # count): the steps change by ~3/N² per step over N steps, and not at the anchors.
        total = float(cum_raw[k1] - cum_raw[k0])
        u = (0.5 * (cum_raw[k0:k1] + cum_raw[k0 + 1:k1 + 1]) - cum_raw[k0]) / total
        bump = 4.0 * u * (1.0 - u)
        scale = (max(round(total), 1) - total) / float(np.sum(cell[k0:k1] * bump))
        factor[k0:k1] = 1.0 + scale * bump
    if len(cuts) == 2 and factor[0] * cum_raw[-1] < 2.0 - 1e-9:  # at least three nodes
        factor[:] = 2.0 / cum_raw[-1]
    cell = cell * factor
    cum = np.concatenate(([0.0], np.cumsum(cell)))
    count = round(float(cum[-1]))
    targets = np.arange(1, count, dtype=np.float64)
    i = np.clip(np.searchsorted(cum, targets, side="right") - 1, 0, ds.size - 1)
    frac = targets - cum[i]  # nodes counted into cell i
    # In cell i the scaled count is F log(1 + g x / h_i) / g: x = h_i expm1(g frac / F) / g.
    f = factor[i]
    h0, g = h[i] / f, slope[i] / f
    with np.errstate(divide="ignore", invalid="ignore", over="ignore"):
        inner = np.where(np.abs(g) * frac > 1e-12, h0 * np.expm1(g * frac) / g, h0 * frac)
    grid = np.concatenate(([s[0]], np.minimum(s[i] + inner, s[i + 1]), [s[-1]]))
    if len(cuts) > 2:  # the anchors exactly (their count is an integer to rounding)
        nearest = np.round(cum[cuts[1:-1]]).astype(np.intp)
        grid[nearest] = s[cuts[1:-1]]
    out: FloatArray = np.maximum.accumulate(grid)
    return out


def top_speed(w_bound: Callable[[FloatArray], FloatArray], length: float, v_max: float,
              w_start: float = 0.0, w_end: float = 0.0) -> float:
    """The fastest speed [m/s] the bound allows on ``[0, length]``, at most ``v_max``.

    The grids' transition lengths follow it, not ``v_max``: under a cap far below ``v_max``
    (a zone or span over the whole path, an edge's ``maxSpeed``, a yaw limit on an arc) the
    first jerk phase from rest is far shorter. Sized from ``v_max`` the default grid missed
    it: a 172.9 m move capped at 0.06 m/s (``v_max`` 4.9) took 1.2e-3 longer than the
    optimum. The bound is read at `TOP_SPEED_PROBES` positions: a narrow fast stretch
    between them is missed, and the transitions come out shorter (finer steps), the cruise
    margin of `adaptive_grid` narrower.

    Pass the path's own bound, not one capped by the boundary envelopes: a short move is
    slow because it is short, and its grid sized from that lower speed came out less
    accurate next to slow zones (measured: 8 of 40 short zone moves moved by
    more than 1e-4, six away from the fine-grid duration, up to 5.8e-4).

    Examples
    --------
    >>> import numpy as np
    >>> top_speed(lambda q: np.full(q.shape, 0.01), 10.0, v_max=2.0)
    0.1
    """
    probe = np.linspace(0.0, length, TOP_SPEED_PROBES)
    v_top = math.sqrt(max(float(np.max(w_bound(probe))), w_start, w_end, 0.0))
    return min(v_max, v_top) if v_top > 0.0 else v_max


def adaptive_grid(
    length: float,
    w_bound: Callable[[FloatArray], FloatArray],
    *,
    a_max: float,
    a_decel: float,
    v_max: float,
    j_max: float,
    w_start: float,
    w_end: float,
    v_low: float | None = None,
    per_phase: float = DEFAULT_PER_PHASE,
    max_nodes: int = MAX_DEFAULT_NODES,
    anchors: FloatArray | None = None,
    breakpoints: FloatArray | None = None,
    v_top: float | None = None,
    nodes_at: FloatArray | None = None,
) -> FloatArray:
    """Smoothly graded grid with about ``per_phase`` nodes per jerk transition.

    Parameters
    ----------
    length : float
        Path length [m].
    w_bound : callable
        ``s -> w`` upper bound [m²/s²] including the boundary envelopes.
    a_max, a_decel, v_max, j_max : float
        Limits [SI].
    w_start, w_end : float
        Boundary values of ``w``.
    v_low : float, optional
        Lowest positive speed [m/s] of a moving boundary state: its own speed, or the speed a
        decelerating start dips to, ``v0 - a0²/(2 j)``. The grid resolves the transitions at
        that speed (away from a standstill the max-jerk start is not there to follow).
    per_phase : float
        Nodes per transition length.
    max_nodes : int
        Node cap; beyond it every step grows in proportion.
    anchors : ndarray, optional
        Positions [m] that should be nodes (see `nodes_from_steps`).
    breakpoints : ndarray, optional
        Positions [m] where the bound may dip, step or kink
        (`bound_breakpoints`): those where the bound dips between
        two points of the first scan (a hairpin on a long path, `hidden_dips`) join
        the scan, so that the dip sets the steps around it.
    v_top : float, optional
        The fastest speed the path's own bound allows (`top_speed`, without the
        boundary envelopes); the transitions are sized under ``min(v_max, v_top)``.
    nodes_at : ndarray, optional
        Positions [m] that should be nodes at a bounded cost (kinks and steps of the speed
        bound, `speedplan.model.leg_grid.bound_kinks`): the steps between two of them leave
        room for `MIN_ANCHOR_NODES` when that makes them at most `KINK_REFINE` times finer;
        closer ones are nodes where they fit.
    """
    a = min(a_max, a_decel)
    v_max = v_max if v_top is None else min(v_max, v_top)
    t_j = min(a / j_max, np.sqrt(v_max / j_max))
    ell = rest_phase_length(a, v_max, j_max)
    rule = _StepRule(w_bound, length, a_max, a_decel, j_max, t_j, per_phase,
                     floor=min(ell, 0.25 * length), margin=2.0 * (v_max * t_j + ell))
    # A move shorter than its jerk phases is made of (up to) four of them: resolve each.
    if v_low is not None and v_low > 0:
        rule = replace(rule, floor=min(rule.floor, float(rule.scale(np.array(v_low)))))
    inner_anchors = np.zeros(0) if anchors is None else np.asarray(anchors, dtype=np.float64)
    inner_anchors = inner_anchors[(inner_anchors > 0.0) & (inner_anchors < length)]
    if inner_anchors.size:
        rule = replace(rule, anchors=np.concatenate(([0.0], np.sort(inner_anchors), [length])))
    extra = np.zeros(0) if nodes_at is None else np.asarray(nodes_at, dtype=np.float64)
    extra = extra[(extra > 0.0) & (extra < length)]
    if extra.size:
        rule = replace(rule, kinks=np.concatenate(([0.0], np.sort(extra), [length])))
    kept = np.union1d(inner_anchors, extra)
    sf = _pre_grid(length, rule.floor, kept)
    if breakpoints is not None:
        sf = np.union1d(sf, hidden_dips(sf, np.asarray(breakpoints, dtype=np.float64), w_bound))
    sf = _apart(sf, kept)
    sf, h, rate = _followed(sf, rule)
    if rule.anchors is not None and float(np.sum(_count(sf, h))) > max_nodes - 1:
        # At the node cap the room for every anchor takes nodes from the jerk transitions: the
        # anchors then become nodes where they fit (a random comfort path of 21 pieces at the
        # cap: limits exceeded after three refinements with the room, verified after one
        # without it).
        sf, h, rate = _followed(sf, replace(rule, anchors=None, kinks=None))
    # The first transitions next to each end (the max-jerk start from rest, a moving state's
    # first change of acceleration) keep their steps when the node cap binds: grown there,
    # the law's jerk at their end breaks its limit, and every finer grid tried after it costs
    # more than the whole plan. Not on a move made of a few transitions (grown evenly).
    zone = 2.0 * rule.floor if 2.0 * rule.floor <= END_ZONE * length else 0.0
    ends = (sf <= zone) | (sf >= length - zone)
    h = _capped(sf, h, rate, length, max_nodes, ends)
    grid = nodes_from_steps(sf, h, kept if kept.size else None)
    grid_size("n", grid.size)
    return grid


@dataclass(frozen=True)
class _StepRule:
    """The graded step of `adaptive_grid` on a pre-grid: ``λ(v) / per_phase``, coarse in cruise.

    ``floor``: the transition length the steps keep next to the ends; ``margin``: how far
    from any kink of the no-jerk profile a stretch counts as cruise.
    """

    w_bound: Callable[[FloatArray], FloatArray]
    length: float
    a_max: float
    a_decel: float
    j_max: float
    t_j: float
    per_phase: float
    floor: float
    margin: float
    anchors: FloatArray | None = None  # sorted, with both ends: every anchor becomes a node
    kinks: FloatArray | None = None  # sorted, with both ends: nodes at a bounded cost

    def scale(self, v: FloatArray) -> FloatArray:
        """``λ(v) = v min(t_j, sqrt(v / j))``: the length of a jerk transition at speed ``v``."""
        out: FloatArray = v * np.minimum(self.t_j, np.sqrt(v / self.j_max))
        return out

    def __call__(self, sf: FloatArray) -> tuple[FloatArray, FloatArray]:
        """The graded step on the pre-grid ``sf``, and the grading rate it was graded with.

        The rate is `CRUISE_GRADING` in cruise, `GRADING` elsewhere.
        """
        length = self.length
        wb = self.w_bound(sf)
        w_est = self._no_jerk_w(sf, wb)
        # The floor keeps the steps from vanishing where the speed falls to the ends' states:
        # on the stretches next to each end where λ(v) is below it. A slow stretch farther
        # inside (a zone, a tight curve) has transitions of its own, which may be shorter
        # than the floor: they are resolved like any other.
        lam = self.scale(np.sqrt(w_est))
        h = np.maximum(np.maximum(lam, np.where(_end_runs(lam < self.floor), self.floor, 0.0))
                       / self.per_phase, MIN_RELATIVE_STEP * length)
        far, smooth = self._stretches(sf, w_est, wb)
        h = np.where(far, np.maximum(h, CRUISE_STEP * length), h)
        h = np.where(smooth, np.maximum(h, self._shape_step(sf, w_est)), h)
        if self.anchors is not None:
            # Room for MIN_ANCHOR_NODES steps between neighbouring anchors, so that each one
            # is a node (`nodes_from_steps` skips an anchor closer than that to the last),
            # down to KINK_REFINE times finer than a jerk transition's steps: closer anchors
            # are nodes where they fit. Without that floor the joins of a road's G2 corners,
            # 0.09 mm apart, made steps of 2.6 µm at 6 m/s, a relaxation the interior-point
            # method could not start on.
            k = np.clip(np.searchsorted(self.anchors, sf, side="right"), 1,
                        self.anchors.size - 1)
            gap = self.anchors[k] - self.anchors[k - 1]
            finest = np.maximum(lam / (self.per_phase * KINK_REFINE), MIN_RELATIVE_STEP * length)
            h = np.minimum(h, np.maximum(gap / (ANCHOR_ROOM * MIN_ANCHOR_NODES), finest))
        if self.kinks is not None:
            # The same room between the kinks of the bound, at most KINK_REFINE times finer:
            # closer kinks are nodes where they fit.
            k = np.clip(np.searchsorted(self.kinks, sf, side="right"), 1, self.kinks.size - 1)
            gap = self.kinks[k] - self.kinks[k - 1]
            h = np.minimum(h, np.maximum(gap / (ANCHOR_ROOM * MIN_ANCHOR_NODES), h / KINK_REFINE))
        rate: FloatArray = np.where(far, CRUISE_GRADING, GRADING)
        return graded_steps(sf, h, rate), rate

    def _no_jerk_w(self, sf: FloatArray, wb: FloatArray) -> FloatArray:
        hf = np.diff(sf)  # the exact no-jerk optimum at twice the limits (speedplan.solve.nojerk)
        return largest_under_rates(wb, np.full(sf.size - 1, 2 * self.a_max) * hf,
                                   np.full(sf.size - 1, 2 * self.a_decel) * hf)

    def _stretches(self, sf: FloatArray, w_est: FloatArray, wb: FloatArray
                   ) -> tuple[np.ndarray, np.ndarray]:
        """Cruise and smooth stretches of ``sf``: far from every kink of the no-jerk profile.

        *Cruise*: where the profile is linear in ``w`` (a cruise, a constant acceleration
        or braking) farther than ``margin`` in metres, or `CRUISE_MARGIN_TIME` ``t_j`` in
        time, from where it is not. *Smooth*: not cruise, and farther than
        `CRUISE_MARGIN_TIME` ``t_j`` in time from every point where following the profile
        asks for more than `SMOOTH_JERK` ``j_max`` or `SMOOTH_ACCELERATION` of the
        acceleration limits (a bound the law follows: a clothoid at its yaw-rate or
        lateral limit).
        """
        # The no-jerk pass sums A h along the path, so it is linear (or meets a constant
        # bound) only to ~1e-16 of that sum, which on a long slow move is far above 1e-12 of
        # the bound.
        top = max(float(np.max(wb)), 1e-300)
        rounding = 1e-15 * 2.0 * max(self.a_max, self.a_decel) * self.length
        cells = np.diff(sf)
        slope = np.diff(w_est) / cells
        bend = np.abs(np.diff(slope)) * np.minimum(cells[1:], cells[:-1])
        flat = np.zeros(sf.size, dtype=bool)
        flat[1:-1] = bend <= 1e-9 * top + rounding
        cruise: np.ndarray = _distance_to(~flat, sf) > self.margin
        v = np.sqrt(w_est)
        with np.errstate(divide="ignore"):
            t = np.concatenate(([0.0], np.cumsum(2.0 * cells / (v[1:] + v[:-1]))))
        if not np.isfinite(t[-1]):
            return cruise, np.zeros(sf.size, dtype=bool)
        # The margin in metres is sized at the top speed: at a hairpin's or a zone's low
        # speed it spans many transitions (7 m at 1 m/s with t_j = 0.27 s is 27 of them),
        # all at fine steps. Measured in time along the no-jerk profile, a jerk-limited
        # law leaves it only within a transition or two of a kink. There, linear means to
        # 1e-9 of the local w: a bound curving gently at a low speed is not a cruise.
        local = np.maximum(np.maximum(w_est[:-2], w_est[2:]), w_est[1:-1])
        straight = np.zeros(sf.size, dtype=bool)
        straight[1:-1] = bend <= 1e-9 * local + rounding
        margin = CRUISE_MARGIN_TIME * self.t_j
        cruise |= _distance_to(~straight, t) > margin
        # Following a curved bound needs a jerk (v w'' / 2) and an acceleration (w' / 2):
        # where both lie well inside the limits, the law follows it too, and its jerk
        # phases lie at the kinks, where either is large or the bound is left.
        accel = 0.5 * np.abs(np.concatenate(([slope[0]], np.maximum(np.abs(slope[:-1]),
                                                                      np.abs(slope[1:])),
                                             [slope[-1]])))
        limit = np.where(np.concatenate(([slope[0]], slope[:-1] + slope[1:], [slope[-1]])) > 0,
                         self.a_max, self.a_decel)
        jerk = np.zeros(sf.size)
        jerk[1:-1] = 0.5 * np.abs(np.diff(slope)) * v[1:-1] / (0.5 * (cells[1:] + cells[:-1]))
        gentle = (jerk <= SMOOTH_JERK * self.j_max) & (accel <= SMOOTH_ACCELERATION * limit)
        gentle[[0, -1]] = False
        smooth = ~cruise & (_distance_to(~(straight | gentle), t) > margin)
        return cruise, smooth

    def _shape_step(self, sf: FloatArray, w_est: FloatArray) -> FloatArray:
        """Steps whose chords sag at most `SHAPE_SAG` of ``w`` below a curved ``w``.

        ``h² |w''| / 8 <= SHAPE_SAG w``, and at most `CRUISE_STEP` of the length.
        """
        cells = np.diff(sf)
        slope = np.diff(w_est) / cells
        curve = np.zeros(sf.size)
        curve[1:-1] = np.abs(np.diff(slope)) / (0.5 * (cells[1:] + cells[:-1]))
        curve[0], curve[-1] = curve[1], curve[-2]
        step = np.full(sf.size, CRUISE_STEP * self.length)
        bent = curve > 0.0
        step[bent] = np.minimum(step[bent], np.sqrt(8.0 * SHAPE_SAG * w_est[bent] / curve[bent]))
        out: FloatArray = step
        return out


def _pre_grid(length: float, floor: float, anchors: FloatArray) -> FloatArray:
    """Uniform, with geometric clusters at both ends and the anchors.

    The ends are where the standstill and the boundary states put the shortest transitions;
    elsewhere `_followed` refines the pre-grid where the steps need it.
    """
    n_pre = int(np.clip(4 * length / max(floor, 1e-12), 2001, PRE_GRID_POINTS))
    ends = np.geomspace(max(floor / 8.0, 1e-12 * length), 0.5 * length, 200)
    sf = np.unique(np.concatenate((np.linspace(0.0, length, n_pre), ends, length - ends,
                                   anchors)))
    out: FloatArray = sf[(sf >= 0.0) & (sf <= length)]
    return out


#: Points of a pre-grid closer than this fraction of the length are one point (see `_apart`).
PRE_GRID_APART = 1e-13


def _apart(sf: FloatArray, kept: FloatArray) -> FloatArray:
    """The sorted pre-grid ``sf`` without points a few ulps from the one before.

    The uniform points, the end clusters, the anchors and the breakpoints can meet at one
    position (the middle of a symmetric path) within a few ulps. On the cell between such
    points the profile's slope is rounding, and a kink of the no-jerk profile there passed
    for linear: its jerk transition was stepped as a cruise. Of two such points the one in
    ``kept`` (anchors: they must stay points) and the ends stay.
    """
    close = np.flatnonzero(np.diff(sf) <= PRE_GRID_APART * float(sf[-1] - sf[0]))
    if close.size == 0:
        return sf
    special = np.isin(sf, kept)
    special[[0, -1]] = True
    drop = np.where(special[close + 1], close, close + 1)
    out: FloatArray = np.delete(sf, drop[~special[drop]])
    return out


def _followed(sf: FloatArray, rule: _StepRule
              ) -> tuple[FloatArray, FloatArray, FloatArray]:
    """The pre-grid refined where its cells are too coarse to follow the steps.

    Returns the pre-grid, the steps on it and their grading rate (`_StepRule`).
    """
    h, rate = rule(sf)
    for _ in range(3):
        cell = np.diff(sf)
        need = np.ceil(cell / (2.0 * np.minimum(h[:-1], h[1:]))).astype(np.int64)
        coarse = np.flatnonzero(need > 1)
        if coarse.size == 0 or sf.size > 2_000_000:
            break
        extra = [sf[k] + cell[k] * np.arange(1, min(int(need[k]), 64)) / min(int(need[k]), 64)
                 for k in coarse]
        sf = np.unique(np.concatenate([sf, *extra]))
        h, rate = rule(sf)
    return sf, h, rate


def _count(sf: FloatArray, h: FloatArray) -> FloatArray:
    """Nodes per cell of ``sf`` at the steps ``h`` (their sum: the grid's node count - 1)."""
    out: FloatArray = np.diff(sf) * 0.5 * (1.0 / h[1:] + 1.0 / h[:-1])
    return out


def _capped(sf: FloatArray, h: FloatArray, rate: FloatArray, length: float, max_nodes: int,
            ends: np.ndarray) -> FloatArray:
    """Steps grown in proportion to count at most ``max_nodes`` (at least `MIN_NODES`).

    Cells within ``ends`` keep their steps while they hold at most `END_SHARE` of the nodes,
    the others grow (none beyond the cruise step) and ``rate`` grades them again. Where that
    does not bring the count under the cap (a cap of a few hundred nodes: the grading away
    from the kept steps alone needs more), every step grows in proportion instead.
    """
    h_max = np.maximum(h, CRUISE_STEP * length)
    budget = max_nodes - 1
    if float(np.sum(_count(sf, h))) <= budget:
        return _at_least_min_nodes(sf, h)
    inside = ends[:-1] & ends[1:]
    rate = np.maximum(rate, np.where(rate >= CRUISE_GRADING, CAPPED_GRADING, 0.0))
    kept = h
    for _ in range(8):
        cells = _count(sf, kept)
        count = float(np.sum(cells))
        if count <= budget:
            return _at_least_min_nodes(sf, kept)
        in_ends = float(np.sum(cells[inside]))
        target = 0.995 * budget  # the grading after the growth adds nodes: aim below the cap
        grow_ends = max(1.0, in_ends / (END_SHARE * target))
        grow_rest = max(1.0, (count - in_ends) / (target - in_ends / grow_ends))
        grown = np.where(ends, kept * grow_ends, np.minimum(kept * grow_rest, h_max))
        kept = graded_steps(sf, grown, rate)
    for _ in range(8):
        count = float(np.sum(_count(sf, h)))
        if count <= budget:
            break
        h = graded_steps(sf, np.minimum(h * (count / (0.995 * budget)), h_max),
                         np.full(sf.size, CAPPED_GRADING))
    return _at_least_min_nodes(sf, h)


def _at_least_min_nodes(sf: FloatArray, h: FloatArray) -> FloatArray:
    """``h``, or finer in proportion where it counts fewer than `MIN_NODES` nodes."""
    count = float(np.sum(_count(sf, h)))
    return h * (count / (MIN_NODES - 1)) if count < MIN_NODES - 1 else h


#: A breakpoint of the bound joins the first scan of `adaptive_grid` where the bound
#: there is below this fraction of the bound at both neighbouring scan points: a dip the
#: scan steps over (a dip of 0.1 % would change the steps by less than that).
HIDDEN_DIP = 1.0 - 1e-3


def hidden_dips(sf: FloatArray, breaks: FloatArray,
                w_bound: Callable[[FloatArray], FloatArray], cells: bool = False) -> FloatArray:
    """The ``breaks`` inside ``(sf[0], sf[-1])`` where the bound dips between scan points.

    Measured (zone fuzz seed 3, case 51): a 9 cm hairpin on a 4.5 km path, a bound of
    0.29 m/s for 0.3 m between scan points 0.97 m apart, got 45 m steps; its law exceeded
    ``j_max`` 1.76x after three refinements. Only such dips are added: a scan point at every
    join of the pieces changed the default grids of three sample paths and made them slightly
    less accurate (``warehouse_loop.json`` 55.1526 -> 55.1580 s; 55.1346 s at n = 30 000).
    With ``cells=True``, every breakpoint in a scan step that holds such a dip (the dip's
    other edge: the end of a hairpin's arc, a narrow zone's exit).
    """
    breaks = breaks[(breaks > sf[0]) & (breaks < sf[-1])]
    if breaks.size == 0:
        return breaks
    k = np.clip(np.searchsorted(sf, breaks), 1, sf.size - 1)
    at, left, right = np.split(w_bound(np.concatenate((breaks, sf[k - 1], sf[k]))), 3)
    return dips_between(sf, breaks, at, left, right, cells=cells)


def dips_between(sf: FloatArray, breaks: FloatArray, at: FloatArray, left: FloatArray,
                 right: FloatArray, cells: bool = False) -> FloatArray:
    """`hidden_dips` from the bound's values at the breakpoints and their scan points.

    ``at``: the bound at the ``breaks`` (all inside ``(sf[0], sf[-1])``); ``left`` and
    ``right``: at the scan points before and after each.
    """
    dip = at < HIDDEN_DIP * np.minimum(left, right)
    if cells and dip.any():
        k = np.searchsorted(sf, breaks)
        dip = np.isin(k, k[dip])
    out: FloatArray = breaks[dip]
    return out


def _end_runs(mask: np.ndarray) -> np.ndarray:
    """``mask`` on its leading and trailing runs of True, False elsewhere.

    Examples
    --------
    >>> import numpy as np
    >>> _end_runs(np.array([True, True, False, True, False, True])).tolist()
    [True, True, False, False, False, True]
    """
    out = np.zeros(mask.shape, dtype=bool)
    if mask.all():
        out[:] = True
        return out
    out[: int(np.argmin(mask))] = True
    out[mask.size - int(np.argmin(mask[::-1])):] = True
    return out


def _distance_to(mask: np.ndarray, s: FloatArray) -> FloatArray:
    """Distance from every ``s`` to the nearest ``s`` where ``mask`` holds (inf if none)."""
    if not mask.any():
        return np.full(s.shape, np.inf)
    left = np.maximum.accumulate(np.where(mask, s, -np.inf))
    right = np.minimum.accumulate(np.where(mask, s, np.inf)[::-1])[::-1]
    out: FloatArray = np.minimum(s - left, right - s)
    return out


#: Cells added on each side of a flagged stretch before halving the steps there.
PAD_CELLS = 4


def refined_grid(s: FloatArray, knots: FloatArray, excess: np.ndarray,
                 anchors: FloatArray | None = None, factor: float = 0.5,
                 grading: float = GRADING) -> FloatArray:
    """The grid ``s`` with its steps times ``factor`` around the pieces flagged in ``excess``.

    ``knots`` are the law's knots (nodes and cell midpoints) and ``excess`` flags each piece
    between them. The steps are multiplied by ``factor`` (in ``(0, 1)``) over the flagged
    cells padded by `PAD_CELLS` on each side (never below the default grids' finest
    step, `MIN_RELATIVE_STEP` of the length), and graded back to
    the old steps at the rate `GRADING`, so the new grid is as
    smooth as the old one; ``anchors`` (nodes of ``s``) stay nodes. A law without jerk rows
    needs no smoothness: ``grading`` may then be coarser.

    Examples
    --------
    >>> import numpy as np
    >>> s = np.linspace(0.0, 10.0, 101)
    >>> knots = np.sort(np.concatenate((s, s[:-1] + 0.05)))
    >>> flag = np.zeros(knots.size - 1, dtype=bool); flag[100] = True  # around s = 5
    >>> g = refined_grid(s, knots, flag)
    >>> bool(g.size > s.size and np.diff(g).min() < 0.06 and g[0] == 0 and g[-1] == 10)
    True
    """
    h = np.diff(s)
    node_h = np.concatenate(([h[0]], 0.5 * (h[:-1] + h[1:]), [h[-1]]))
    cell = (np.flatnonzero(excess) // 2).astype(np.intp)  # piece 2k, 2k+1 lie in cell k
    flagged = np.zeros(s.size, dtype=bool)
    for k in np.unique(cell):
        lo, hi = max(k - PAD_CELLS, 0), min(k + 1 + PAD_CELLS, s.size - 1)
        flagged[lo:hi + 1] = True
    # Never below the default grids' finest step: finer steps lose the digits of w.
    finest = MIN_RELATIVE_STEP * float(s[-1] - s[0])
    target = np.where(flagged, np.maximum(factor * node_h, np.minimum(node_h, finest)), node_h)
    target = graded_steps(s, target, np.full(s.size, grading))
    kept = None if anchors is None or not len(anchors) else np.intersect1d(anchors, s)
    grid = nodes_from_steps(s, target, kept)
    grid_size("n", grid.size)
    return grid


def subdivided_grid(s: FloatArray, cells: np.ndarray, parts: int = 4) -> FloatArray:
    """The grid ``s`` with the flagged ``cells`` and `PAD_CELLS` on each side split.

    Each such cell is cut into ``parts`` equal steps; every other node and cell of ``s`` is
    kept to the last bit, so what was evaluated on them (the speed bound inside the cells)
    still holds. For a law without jerk rows, which needs no smoothness of the steps.

    Examples
    --------
    >>> import numpy as np
    >>> s = np.linspace(0.0, 10.0, 11)
    >>> flag = np.zeros(10, dtype=bool); flag[5] = True
    >>> g = subdivided_grid(s, flag, parts=2)
    >>> g.size, bool(np.isin(s, g).all()), float(np.diff(g).min())
    (20, True, 0.5)
    """
    # Each flagged cell and PAD_CELLS on each side (shifted copies: an integer convolution
    # costs more).
    flags = np.asarray(cells, dtype=bool)
    split = flags.copy()
    for k in range(1, PAD_CELLS + 1):
        split[k:] |= flags[:-k]
        split[:-k] |= flags[k:]
    lo = s[:-1][split]
    width = np.diff(s)[split]
    inner = lo[:, None] + width[:, None] * (np.arange(1, parts) / parts)[None, :]
    # Each cell's nodes in place: its first node, then its inner points where split.
    grid_size("n", s.size + inner.size)
    start = np.empty(s.size, dtype=np.intp)
    start[0] = 0
    np.cumsum(np.where(split, parts, 1), out=start[1:])
    grid = np.empty(s.size + inner.size)
    grid[start] = s
    grid[(start[:-1][split][:, None] + np.arange(1, parts)[None, :]).ravel()] = inner.ravel()
    if not (grid[1:] > grid[:-1]).all():  # a cell of a few ulps: its points coincide
        grid = np.unique(grid)
    return grid
