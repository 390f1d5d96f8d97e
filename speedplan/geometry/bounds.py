"""Speed bounds along a path: ``mu+(s) = min(v_max², a_lat_max/|k(s)|, zones, v_limit)``."""

from __future__ import annotations

import weakref
from collections.abc import Callable, Sequence
from dataclasses import dataclass, field, replace
from functools import cached_property

import numpy as np
import shapely
from numpy.typing import ArrayLike

from ..core.checks import FloatArray, IntArray, as_array, as_scalar, instances
from ..core.errors import InvalidInputError
from ..core.limits import Limits
from ..core.numerics import CELL_POINTS, cell_points, cell_rows
from ..core.options import VLimit
from .path import Path

__all__ = ["ZONE_RESCAN", "CellSamples", "SpanLimit", "SpeedBound", "SpeedZone",
           "bound_breakpoints", "check_spans", "check_v_limit", "check_zones", "speed_bounds",
           "zone_intervals"]


@dataclass(frozen=True, init=False)
class SpeedZone:
    """A region with its own speed limit.

    Parameters
    ----------
    polygon : shapely.Polygon, shapely.MultiPolygon or array_like, shape (m, 2)
        The region (vertices [m], m >= 3, when not a shapely geometry); must be valid (a
        MultiPolygon's parts must not overlap) with positive area. Points on its boundary
        count as inside; holes are outside.
    v_max : float
        Speed limit inside [m/s], >= 0.

    Examples
    --------
    >>> from speedplan.geometry import SpeedZone
    >>> z = SpeedZone([(0, -1), (5, -1), (5, 1), (0, 1)], v_max=0.5)
    >>> z.polygon.area, z.v_max
    (10.0, 0.5)
    >>> import shapely
    >>> two = SpeedZone(shapely.MultiPolygon([shapely.box(0, 0, 1, 1), shapely.box(3, 0, 4, 1)]),
    ...                 v_max=0.3)
    >>> two.polygon.area
    2.0
    """

    polygon: shapely.Polygon | shapely.MultiPolygon
    v_max: float

    def __init__(self, polygon: shapely.Polygon | shapely.MultiPolygon | ArrayLike,
                 v_max: float) -> None:
        # The generated constructor would type ``polygon`` as the field (always a shapely
        # polygon once built); vertices are accepted too.
        poly = polygon
        if isinstance(poly, shapely.Geometry) and not isinstance(
                poly, shapely.Polygon | shapely.MultiPolygon):
            raise InvalidInputError(
                "`polygon` must be a shapely Polygon or MultiPolygon, or (m, 2) vertices; got a "
                f"{poly.geom_type}"
            )
        if not isinstance(poly, shapely.Geometry):
            pts = as_array("polygon", poly)
            if pts.ndim != 2 or pts.shape[1] != 2 or pts.shape[0] < 3:
                raise InvalidInputError(
                    "`polygon` must be a shapely Polygon or MultiPolygon, or (m, 2) vertices "
                    f"with m >= 3; got shape {pts.shape}"
                )
            poly = shapely.Polygon(pts)
        if poly.is_empty or not poly.is_valid or not poly.area > 0:
            raise InvalidInputError(
                "`polygon` must be a valid polygon with positive area (no self-intersections; "
                f"the parts of a MultiPolygon must not overlap): {shapely.is_valid_reason(poly)}"
            )
        shapely.prepare(poly)  # speeds up the vectorised point-in-polygon tests
        object.__setattr__(self, "polygon", poly)
        object.__setattr__(self, "v_max", as_scalar("v_max", v_max, nonnegative=True))


@dataclass(frozen=True)
class SpanLimit:
    """Limits over a stretch ``[start, end]`` of the path (e.g. one edge of a route).

    Parameters
    ----------
    start, end : float
        The stretch [m], ``0 <= start < end``; both ends included (where two spans meet, the
        lower limit applies at the join).
    v_max : float, optional
        Speed limit on the stretch [m/s], > 0 (``None``: none).
    yaw_rate_max : float, optional
        Yaw-rate limit on the stretch [rad/s], > 0: ``|κ| v <= yaw_rate_max`` (``None``: none).

    Examples
    --------
    >>> from speedplan.geometry import SpanLimit
    >>> SpanLimit(5.0, 12.0, v_max=1.2)
    SpanLimit(start=5.0, end=12.0, v_max=1.2, yaw_rate_max=None)
    """

    start: float
    end: float
    v_max: float | None = None
    yaw_rate_max: float | None = None

    def __post_init__(self) -> None:
        set_ = object.__setattr__
        set_(self, "start", as_scalar("start", self.start, nonnegative=True))
        set_(self, "end", as_scalar("end", self.end))
        if not self.end > self.start:
            raise InvalidInputError(
                f"a SpanLimit needs end > start; got start={self.start!r}, end={self.end!r}"
            )
        for name in ("v_max", "yaw_rate_max"):
            value = getattr(self, name)
            if value is not None:
                set_(self, name, as_scalar(name, value, positive=True, allow_inf=True))


def check_spans(spans: object, length: float | None = None) -> list[SpanLimit]:
    """``spans`` as a list of [`SpanLimit`][speedplan.SpanLimit] (one, a sequence, or ``None``).

    With the path's ``length`` [m]: a span ending within ``1e-9`` of it, on either side,
    ends at it (its end summed in another order, as a route's edges: one ulp short, the
    path's last point kept the path's own limit); one ending further beyond is refused.

    Examples
    --------
    >>> check_spans(SpanLimit(0.0, 39.79535182445759, v_max=1.5), 39.7953518244576)[0].end
    39.7953518244576
    """
    out = instances("spans", spans, SpanLimit)
    for i, span in enumerate(out):
        if length is None:
            continue
        if span.end > length * (1 + 1e-9):
            raise InvalidInputError(
                f"`spans[{i}]` ends at {span.end:.9g} m, beyond the path's length "
                f"{length:.9g} m"
            )
        if span.end != length and abs(span.end - length) <= 1e-9 * length \
                and span.start < length:
            out[i] = replace(span, end=length)
    return out


def speed_bounds(
    path: Path,
    limits: Limits,
    s: ArrayLike,
    *,
    zones: Sequence[SpeedZone] | SpeedZone | None = None,
    v_limit: VLimit | None = None,
    spans: Sequence[SpanLimit] | SpanLimit | None = None,
) -> FloatArray:
    """Upper bound ``mu+(s)`` on ``w = v²`` [m²/s²] at arc lengths ``s`` [m].

    ``mu+(s) = min(v_max², a_lat_max / |k(s)|, (yaw_rate_max / |k(s)|)²)``; where a limit is
    ``inf`` or the curvature is 0 that term is absent. It is further lowered to
    ``zone.v_max²`` wherever the path point lies inside or on the boundary of a zone's
    polygon, by ``v_limit``, and over each span by its own ``v_max`` and ``yaw_rate_max``.

    Parameters
    ----------
    path : Path
        The path.
    limits : Limits
        Uses ``v_max`` [m/s] and ``a_lat_max`` [m/s²].
    s : array_like
        Arc lengths [m] in ``[0, path.length]``.
    zones : SpeedZone or sequence of SpeedZone, optional
        Speed-limit regions (inside or on the boundary counts).
    v_limit : (s_knots, v_knots), optional
        Per-position speed limit [m, m/s]: ``s_knots`` strictly increasing, ``v_knots >= 0``
        (``inf`` allowed). **Piecewise linear** in ``s`` between knots and held constant beyond
        the ends (``numpy.interp``); for a step, repeat the position with a tiny offset. Linear
        because a limit sampled from another profile (a previous plan, a sensor map) is then
        reproduced without staircase artefacts.
    spans : SpanLimit or sequence of SpanLimit, optional
        Speed and yaw-rate limits over stretches of the path (a route's edges).

    Returns
    -------
    ndarray
        ``mu+(s)``, same shape as ``s`` [m²/s²].

    Examples
    --------
    >>> import numpy as np
    >>> from speedplan import Limits, Path
    >>> from speedplan.geometry import Arc, Line, speed_bounds
    >>> lim = Limits(v_max=2, a_max=1, a_lat_max=1, j_max=0.5)
    >>> p = Path.from_segments([Line(5.0), Arc(radius=2.0, angle=np.pi)])
    >>> speed_bounds(p, lim, [1.0, 6.0]).tolist()      # v_max², then a_lat_max * R
    [4.0, 2.0]
    >>> speed_bounds(p, lim, [1.0, 4.0], v_limit=([0.0, 5.0], [1.0, 0.0])).round(12).tolist()
    [0.64, 0.04]
    """
    if not isinstance(path, Path):
        raise InvalidInputError(f"`path` must be a speedplan.Path; got {type(path).__name__}")
    if not isinstance(limits, Limits):
        raise InvalidInputError(f"`limits` must be a speedplan.Limits; got {type(limits).__name__}")
    zone_list = check_zones(zones)
    span_list = check_spans(spans)
    q = as_array("s", s)
    # path.curvature also checks that s lies on the path.
    return _bounds(path, limits, q, path.curvature(q), zone_list, v_limit, span_list)


def _bounds(
    path: Path, limits: Limits, q: FloatArray, curvature: FloatArray,
    zone_list: list[SpeedZone], v_limit: VLimit | None, span_list: Sequence[SpanLimit] = (),
) -> FloatArray:
    """`speed_bounds` at ``q`` once the path's curvature there is known."""
    kappa = np.abs(curvature)
    curved = kappa > 0  # elsewhere (0 or NaN) no lateral term
    w = np.full(q.shape, limits.v_max**2)
    if np.isfinite(limits.a_lat_max):
        lateral = np.divide(limits.a_lat_max, kappa, out=np.full(q.shape, np.inf), where=curved)
        np.minimum(w, lateral, out=w)
    if np.isfinite(limits.yaw_rate_max):  # |κ| v <= ω
        yaw = np.divide(limits.yaw_rate_max, kappa, out=np.full(q.shape, np.inf), where=curved)
        np.minimum(w, yaw * yaw, out=w)
    if zone_list:
        xy = path.point(q)
        for zone in zone_list:
            inside = _inside_zone(zone, xy[..., 0], xy[..., 1])
            w = np.where(inside, np.minimum(w, zone.v_max**2), w)
    if v_limit is not None:
        sk, vk = check_v_limit(v_limit)
        v = np.interp(q, sk, vk)
        w = np.minimum(w, np.where(np.isnan(v), np.inf, v) ** 2)  # inf knots may give inf*0
    for span in span_list:
        inside = (q >= span.start) & (q <= span.end)
        cap = np.full(q.shape, np.inf if span.v_max is None else span.v_max**2)
        if span.yaw_rate_max is not None:
            with np.errstate(divide="ignore"):
                cap = np.minimum(cap, np.where(kappa > 0, (span.yaw_rate_max / kappa) ** 2,
                                               np.inf))
        w = np.where(inside, np.minimum(w, cap), w)
    return w


def _inside_zone(zone: SpeedZone, x: FloatArray, y: FloatArray) -> np.ndarray:
    """``shapely.intersects_xy(zone.polygon, x, y)``, tested only inside the zone's box.

    A point outside the polygon's bounding box (closed: a vertex lies on it) cannot touch
    the polygon, so the same flags come from the point-in-polygon test of the points in the
    box alone: a path that crosses a zone spends most of its points away from it (on
    ``paths/slow_zone.json`` three quarters), where the test is the bound's largest cost.
    """
    x_lo, y_lo, x_hi, y_hi = zone.polygon.bounds
    near = (x >= x_lo) & (x <= x_hi) & (y >= y_lo) & (y <= y_hi)
    inside = np.zeros(near.shape, dtype=bool)
    inside[near] = shapely.intersects_xy(zone.polygon, x[near], y[near])
    return inside


@dataclass(frozen=True)
class SpeedBound:
    """``s -> mu+(s)`` for one path, limits and zones: a picklable callable [m²/s²].

    Calling it is [`speed_bounds`][speedplan.speed_bounds] with the stored arguments.

    Examples
    --------
    >>> from speedplan import Limits, Path
    >>> from speedplan.geometry import Arc, Line, SpeedBound
    >>> p = Path.from_segments([Line(5.0), Arc(radius=2.0, angle=1.0)])
    >>> bound = SpeedBound(p, Limits(v_max=2, a_max=1, a_lat_max=1, j_max=0.5))
    >>> bound([1.0, 6.0]).tolist(), bound.given_curvature([6.0], [0.5]).tolist()
    ([4.0, 2.0], [2.0])
    """

    path: Path
    limits: Limits
    zones: list[SpeedZone] | None = None
    v_limit: VLimit | None = None
    offset: float = 0.0
    spans: tuple[SpanLimit, ...] = ()
    memo: BoundMemo | None = field(default=None, compare=False, repr=False)

    def at_offset(self, offset: float) -> SpeedBound:
        """The same bound read from ``offset`` [m] on: ``s -> mu+(offset + s)``.

        Shares the memo (`memoised`), which is keyed by the path's own arc length.
        """
        return replace(self, offset=self.offset + float(offset))

    def memoised(self) -> SpeedBound:
        """The same bound, remembering what it evaluated where evaluating is costly.

        A plan evaluates the bound at the nodes and inside the cells of a grid, again on a
        refined grid that keeps most cells, and again where it checks the law, at many of the
        same positions. On a spline or NURBS path each curvature is an arc-length inversion
        and, with speed zones, each position a point-in-polygon test; there the returned bound
        looks up the positions it has seen (exactly equal floats) and evaluates only the
        others (`BoundMemo`). On paths of lines, arcs and clothoids without zones a
        lookup costs more than the evaluation and ``self`` is returned.

        Examples
        --------
        >>> from speedplan import Limits, Path
        >>> from speedplan.geometry import SpeedBound, SpeedZone
        >>> p = Path.from_waypoints([(0, 0), (10, 0)])
        >>> zone = SpeedZone([(2, -1), (4, -1), (4, 1), (2, 1)], v_max=0.5)
        >>> lim = Limits(v_max=2, a_max=1, a_lat_max=1, j_max=0.5)
        >>> bound = SpeedBound(p, lim, [zone]).memoised()
        >>> bound([1.0, 3.0]).tolist(), bound.memo.size
        ([4.0, 0.25], 2)
        >>> SpeedBound(p, lim).memoised().memo is None
        True
        """
        costly = bool(self.zones) or not self.path.analytic
        if self.memo is not None or not costly:
            return self
        return replace(self, memo=BoundMemo())

    def __call__(self, s: FloatArray) -> FloatArray:
        """Bound at arc lengths ``s`` [m²/s²]."""
        if self.memo is not None:
            return self.curvature_and_bound(s)[1]
        q = as_array("s", s) + self.offset if self.offset else s
        return speed_bounds(self.path, self.limits, q, zones=self.zones, v_limit=self.v_limit,
                            spans=self.spans)

    def curvature_and_bound(self, s: ArrayLike) -> tuple[FloatArray, FloatArray]:
        """The path's curvature [1/m] and the bound [m²/s²] at arc lengths ``s`` [m]."""
        q = as_array("s", s) + self.offset
        if self.memo is None:
            kappa = np.asarray(self.path.curvature(q), dtype=np.float64)
            return kappa, self._given(q, kappa)
        return self.memo.lookup(q, self._fresh)

    def evaluate(self, s: FloatArray) -> tuple[FloatArray, FloatArray]:
        """The path's curvature [1/m] and the bound [m²/s²] at arc lengths ``s`` [m], computed.

        `curvature_and_bound` without its memo and its check of ``s`` (callers that evaluate
        every position once, such as `CellSamples`).
        """
        return self._fresh(np.asarray(s, dtype=np.float64) + self.offset)

    def _fresh(self, q: FloatArray) -> tuple[FloatArray, FloatArray]:
        kappa = np.asarray(self.path.curvature(q), dtype=np.float64)
        return kappa, self._given(q, kappa)

    def _given(self, q: FloatArray, kappa: FloatArray) -> FloatArray:
        return _bounds(self.path, self.limits, q, kappa, check_zones(self.zones), self.v_limit,
                       self.spans)

    @cached_property
    def _breakpoints(self) -> FloatArray:
        """`bound_breakpoints` on the bound's own path, computed once.

        A plan reads them for its grid and again for its check (and a zone's entries and
        exits cost a cache lookup each time); the bound is immutable, so they are its own.
        """
        return _computed_breakpoints(self.path, self)

    def given_curvature(self, s: ArrayLike, curvature: ArrayLike) -> FloatArray:
        """Bound at arc lengths ``s`` [m] where the path's ``curvature`` [1/m] is known.

        Saves evaluating the curvature again, which on spline and NURBS paths is an
        arc-length inversion (``SpeedProfile.verify`` has it already). Neither ``s`` nor
        ``curvature`` is checked against the path.
        """
        q = as_array("s", s) + self.offset
        kappa = np.asarray(curvature, dtype=np.float64)  # NaN passes: verify() reports it
        if kappa.shape != q.shape:
            raise InvalidInputError(
                f"`curvature` must have the shape of `s` {q.shape}; got {kappa.shape}"
            )
        return self._given(q, kappa)


class BoundMemo:
    """Curvature and speed bound already evaluated, keyed by the exact arc length [m].

    Sorted positions with their values; a lookup evaluates only the positions it has not seen
    (one call for all of them, deduplicated) and keeps them. The table is replaced by one
    assignment, so a lookup from another thread sees the old table or the new one, never a
    mix. Pickling keeps no entries: a memo is a cache of one process.
    """

    __slots__ = ("_table",)

    def __init__(self) -> None:
        empty = np.empty(0)
        self._table: tuple[FloatArray, FloatArray, FloatArray] = (empty, empty, empty)

    @property
    def size(self) -> int:
        """Number of positions remembered."""
        return int(self._table[0].size)

    def lookup(self, q: FloatArray,
               fresh: Callable[[FloatArray], tuple[FloatArray, FloatArray]]
               ) -> tuple[FloatArray, FloatArray]:
        """``(curvature, bound)`` at ``q``, with ``fresh(positions)`` for the unseen ones."""
        keys, kappa_k, w_k = self._table
        flat = q.ravel()
        at = np.minimum(np.searchsorted(keys, flat), max(keys.size - 1, 0))
        hit = keys[at] == flat if keys.size else np.zeros(flat.size, dtype=bool)
        kappa = np.empty(flat.size)
        w = np.empty(flat.size)
        kappa[hit], w[hit] = kappa_k[at[hit]], w_k[at[hit]]
        if not hit.all():
            new, back = np.unique(flat[~hit], return_inverse=True)
            kappa_n, w_n = fresh(new)
            kappa[~hit], w[~hit] = kappa_n[back], w_n[back]
            merged = np.concatenate((keys, new))
            order = np.argsort(merged, kind="stable")  # two sorted runs: linear
            self._table = (merged[order], np.concatenate((kappa_k, kappa_n))[order],
                           np.concatenate((w_k, w_n))[order])
        return kappa.reshape(q.shape), w.reshape(q.shape)

    def __reduce__(self) -> tuple[type[BoundMemo], tuple[()]]:
        return (BoundMemo, ())


@dataclass(frozen=True, eq=False)
class CellSamples:
    """A speed bound and the path's curvature at the `cell_points` of a grid.

    What a plan without jerk limit evaluates once and reads twice: its model takes the node
    bounds from it (the bound's minimum over each cell, `speedplan.model.rows.node_minima`)
    and its check reads the speed bound, lateral acceleration and yaw rate of the law at the
    same points (`speedplan.timing.verify.check_law`).

    Attributes
    ----------
    s : ndarray
        The grid [m], in the bound's own arc length (from its offset).
    offset : float
        The bound's offset on the path [m] (`SpeedBound.offset`): the points lie at
        ``offset + points`` of the path.
    points : ndarray
        ``cell_points(s)`` [m].
    curvature, bound : ndarray
        The path's curvature [1/m] and the bound [m²/s²] at the points.
    extra, extra_curvature, extra_bound : ndarray
        Further positions [m] (the bound's breakpoints, `bound_breakpoints`) and the same
        two quantities there; empty by default.

    Examples
    --------
    >>> import numpy as np
    >>> from speedplan import Limits
    >>> from speedplan.geometry import Arc, CellSamples, Line, Path, SpeedBound
    >>> p = Path.from_segments([Line(2.0), Arc(radius=2.0, angle=1.0)])
    >>> bound = SpeedBound(p, Limits(v_max=2, a_max=1, a_lat_max=1, j_max=0.5))
    >>> smp = CellSamples.of(bound, np.array([0.0, 1.0, 4.0]))
    >>> smp.points.size, smp.bound[:3].tolist()  # the nodes first (see cell_points)
    (17, [4.0, 4.0, 2.0])
    """

    s: FloatArray
    offset: float
    points: FloatArray
    curvature: FloatArray
    bound: FloatArray
    extra: FloatArray = field(default_factory=lambda: np.zeros(0))
    extra_curvature: FloatArray = field(default_factory=lambda: np.zeros(0))
    extra_bound: FloatArray = field(default_factory=lambda: np.zeros(0))

    @classmethod
    def of(cls, bound: SpeedBound, s: FloatArray, extra: FloatArray | None = None
           ) -> CellSamples:
        """The samples of ``bound`` on the grid ``s`` (and at ``extra``), all evaluated."""
        points = cell_points(s)
        more = np.zeros(0) if extra is None else extra
        kappa, w = bound.evaluate(np.concatenate((points, more)))
        m = points.size
        return cls(s, bound.offset, points, kappa[:m], w[:m], more, kappa[m:], w[m:])

    def on_grid(self, bound: SpeedBound, s: FloatArray) -> CellSamples:
        """The samples of ``bound`` on the grid ``s``, evaluated only where ``self`` lacks them.

        A node of ``s`` that is a node of ``self.s``, and a cell of ``s`` between two
        consecutive nodes of ``self.s``, have the same points to the last bit
        (`cell_points`): their values are taken from ``self``. ``bound`` must be the one
        ``self`` sampled.
        """
        if bound.offset != self.offset:
            raise InvalidInputError(
                f"`bound` is read from offset {bound.offset!r}; the samples from {self.offset!r}")
        old = self.s
        points = cell_points(s)
        at = np.minimum(np.searchsorted(old, s), old.size - 1)
        same = old[at] == s
        kept = same[:-1] & same[1:] & (at[1:] == at[:-1] + 1)
        new_nodes, new_cells = np.flatnonzero(~same), np.flatnonzero(~kept)
        nodes, inner = cell_rows(points)
        kappa, w = bound.evaluate(np.concatenate((nodes[new_nodes],
                                                  inner[:, new_cells].ravel())))
        kappa_s, w_s = (_regridded(own, fresh, at, new_nodes, new_cells)
                        for own, fresh in ((self.curvature, kappa), (self.bound, w)))
        return CellSamples(s, self.offset, points, kappa_s, w_s, self.extra,
                           self.extra_curvature, self.extra_bound)


def _regridded(own: FloatArray, fresh: FloatArray, at: IntArray, new_nodes: IntArray,
               new_cells: IntArray) -> FloatArray:
    """Values at the `cell_points` of a new grid from the old grid's and the fresh ones.

    ``own``: at the old grid's `cell_points`; ``at``: each new node's index in the old grid
    (where it is one of its nodes); ``fresh``: at the new nodes ``new_nodes``, then at the
    inner points of the new cells ``new_cells`` (`cell_rows` order). Each row is gathered
    from the old rows (a kept cell ``i`` is the old cell ``at[i]``), then the new nodes and
    cells are written over: two gathers and two scatters per row block, no index arrays of
    every point (on a grid of ~1 000 nodes that bookkeeping cost more than the evaluation).
    """
    n = at.size
    out = np.empty(CELL_POINTS * (n - 1) + 1)
    out_nodes, out_inner = cell_rows(out)
    own_nodes, own_inner = cell_rows(own)
    own_nodes.take(at, out=out_nodes)
    # A new cell's column is written over below; clipping keeps its index in range.
    own_inner.take(at[:-1], axis=1, out=out_inner, mode="clip")
    out_nodes[new_nodes] = fresh[:new_nodes.size]
    out_inner[:, new_cells] = fresh[new_nodes.size:].reshape(CELL_POINTS - 1, new_cells.size)
    return out


def check_v_limit(v_limit: VLimit) -> tuple[FloatArray, FloatArray]:
    """``v_limit``'s knots and speeds as arrays; raise naming what is malformed.

    Examples
    --------
    >>> [a.tolist() for a in check_v_limit(([0.0, 5.0], [1.0, 0.5]))]
    [[0.0, 5.0], [1.0, 0.5]]
    """
    try:
        sk, vk = v_limit
    except (TypeError, ValueError) as exc:
        raise InvalidInputError(
            "`v_limit` must be a pair (s_knots, v_knots) of 1-D arrays"
        ) from exc
    sk = as_array("v_limit[0]", sk, ndim=1)
    vk = as_array("v_limit[1]", vk, ndim=1, length=sk.size, allow_inf=True)
    if sk.size == 0:
        raise InvalidInputError("`v_limit` is empty; pass at least one knot")
    if (np.diff(sk) <= 0).any():
        raise InvalidInputError("`v_limit[0]` (s knots) must be strictly increasing")
    if (vk < 0).any():
        raise InvalidInputError("`v_limit[1]` (speeds) must be >= 0")
    return sk, vk


#: Points per scan step of `zone_intervals` where the path, outside a zone at both
#: ends of the step, comes within one step of it.
ZONE_RESCAN = 64
#: Bisection steps of `zone_intervals` per path query (2**depth - 1 points a bracket).
_BISECT_DEPTH = 5


def zone_intervals(
    path: Path, zones: Sequence[SpeedZone] | SpeedZone, *, tol: float = 1e-9
) -> list[tuple[float, float, float]]:
    """Where the path is inside each zone: ``[(s_enter, s_exit, v_max), ...]`` sorted by entry.

    A point on the polygon boundary counts as inside. Membership is scanned on a grid of
    spacing ``max(0.01 m, length / 200000)``; the steps between two points outside that
    come within one step of the polygon are scanned again, `ZONE_RESCAN` times finer
    (a zone corner or a narrow zone crossed between two points); every change is then
    located by bisection to ``tol`` metres (an excursion shorter than the finer spacing may
    still be missed). A path starting
    (ending) inside a zone enters at 0 (leaves at ``length``). The result is remembered per
    path and zones (both immutable): every plan with zones checks its law at these points.

    Parameters
    ----------
    path : Path
        The path.
    zones : SpeedZone or sequence of SpeedZone
        Speed-limit regions.
    tol : float
        Accuracy of the entry and exit positions [m].

    Examples
    --------
    >>> import shapely
    >>> from speedplan.geometry import Line, Path, SpeedZone, zone_intervals
    >>> p = Path.from_segments([Line(10.0)])
    >>> [(round(a, 9), round(b, 9), v) for a, b, v in
    ...  zone_intervals(p, [SpeedZone(shapely.box(2, -1, 5, 1), 0.5)])]
    [(2.0, 5.0, 0.5)]
    """
    zone_list = check_zones(zones)
    tol = as_scalar("tol", tol, positive=True)
    key = (tuple(id(z) for z in zone_list), tol)
    cached = _ZONE_CACHE.setdefault(path, {}).get(key)
    if cached is not None and all(a is b for a, b in zip(cached[0], zone_list, strict=True)):
        return list(cached[1])
    out = _zone_intervals(path, zone_list, tol)
    entries = _ZONE_CACHE[path]
    if len(entries) >= _ZONE_CACHE_SIZE:
        del entries[next(iter(entries))]  # the oldest
    entries[key] = (tuple(zone_list), tuple(out))  # holds the zones: their ids stay theirs
    return out


#: `zone_intervals` per path (weakly: the entries go with the path), then per zones
#: and ``tol``: paths and zones are immutable, and every plan with zones checks its law
#: against their entries and exits (``bound_breakpoints``), which cost 3 ms a plan on
#: ``paths/slow_zone.json``, a third of a plan without jerk limit.
_ZONE_CACHE: weakref.WeakKeyDictionary[
    Path, dict[tuple[tuple[int, ...], float],
               tuple[tuple[SpeedZone, ...], tuple[tuple[float, float, float], ...]]]
] = weakref.WeakKeyDictionary()
#: Zone sets remembered per path.
_ZONE_CACHE_SIZE = 8


def _zone_intervals(path: Path, zone_list: list[SpeedZone], tol: float
                    ) -> list[tuple[float, float, float]]:
    """`zone_intervals`, computed."""
    L = path.length
    s = np.linspace(0.0, L, int(np.clip(np.ceil(L / 0.01), 2000, 200_000)) + 1)
    xy = path.point(s)
    out: list[tuple[float, float, float]] = []
    for zone in zone_list:
        flags = shapely.intersects_xy(zone.polygon, xy[:, 0], xy[:, 1])
        change = np.flatnonzero(flags[1:] != flags[:-1])
        # Bisect every bracket at once; invariant: flags at a differ from flags at b.
        a, b = s[change], s[change + 1]
        entering = flags[change + 1]
        ra, rb, rent = _rescanned(path, zone, s, xy, flags)
        if ra.size:
            a, b, entering = (np.concatenate(x) for x in ((a, ra), (b, rb), (entering, rent)))
            order = np.argsort(a, kind="stable")
            a, b, entering = a[order], b[order], entering[order]
        steps = int(np.ceil(np.log2(max(s[1], tol) / tol))) + 1
        while steps > 0 and a.size:
            # Several bisection steps per path query: every midpoint the next `depth` steps
            # may visit (a binary tree, each node halving its own bracket as a step would),
            # tested at once, then the steps taken down the tree: the same brackets as one
            # step per query, a fraction of the queries.
            depth = min(steps, _BISECT_DEPTH)
            los, his, levels = [a], [b], []
            for _ in range(depth):  # the tree level by level: node i's children 2i, 2i + 1
                mids = [0.5 * (lo + hi) for lo, hi in zip(los, his, strict=True)]
                los = [x for lo, m in zip(los, mids, strict=True) for x in (lo, m)]
                his = [x for m, hi in zip(mids, his, strict=True) for x in (m, hi)]
                levels.append(np.stack(mids))
            flat = np.concatenate(levels)  # (nodes, brackets)
            p = path.point(flat.ravel())
            inside = shapely.intersects_xy(zone.polygon, p[:, 0], p[:, 1]).reshape(flat.shape)
            node = np.zeros(a.size, dtype=np.intp)  # index within the level
            cols = np.arange(a.size)
            start = 0
            for level in range(depth):
                row = start + node
                mid = flat[row, cols]
                to_b = inside[row, cols] == entering  # mid has the state after the crossing
                b = np.where(to_b, mid, b)
                a = np.where(to_b, a, mid)
                start += 2**level
                node = 2 * node + np.where(to_b, 0, 1)  # left child keeps a, right keeps b
            steps -= depth
        enters = list(b[entering]) if flags[0] == 0 else [0.0, *b[entering]]
        exits = list(a[~entering]) + ([L] if flags[-1] else [])
        out.extend((float(e), float(x), zone.v_max) for e, x in zip(enters, exits, strict=True))
    return sorted(out)


def _rescanned(path: Path, zone: SpeedZone, s: FloatArray, xy: FloatArray,
               flags: np.ndarray) -> tuple[FloatArray, FloatArray, np.ndarray]:
    """Brackets ``(a, b, entering)`` of crossings between two scan points outside ``zone``.

    Only steps with both ends outside and an end within one step of the polygon (a bounding
    box test first, then the distance) are scanned again, `ZONE_RESCAN` points each.
    """
    step = float(s[1] - s[0])
    x0, y0, x1, y1 = zone.polygon.bounds
    near = (~flags & (xy[:, 0] >= x0 - step) & (xy[:, 0] <= x1 + step)
            & (xy[:, 1] >= y0 - step) & (xy[:, 1] <= y1 + step))
    idx = np.flatnonzero(near)
    if idx.size:
        idx = idx[shapely.dwithin(zone.polygon, shapely.points(xy[idx]), step)]
    cells = np.union1d(idx[idx < s.size - 1], idx[idx > 0] - 1)
    cells = cells[~flags[cells] & ~flags[cells + 1]]
    empty = np.zeros(0)
    if cells.size == 0:
        return empty, empty, np.zeros(0, dtype=bool)
    fine = s[cells, None] + step * np.linspace(0.0, 1.0, ZONE_RESCAN + 1)[None, :]
    p = path.point(fine.ravel())
    inside = shapely.intersects_xy(zone.polygon, p[:, 0], p[:, 1]).reshape(fine.shape)
    row, col = np.nonzero(inside[:, 1:] != inside[:, :-1])
    return fine[row, col], fine[row, col + 1], inside[row, col + 1]


def bound_breakpoints(path: Path, bound: Callable[[FloatArray], FloatArray]) -> FloatArray:
    """Arc lengths [m] where the speed bound ``bound`` may have a kink, a step or a dip.

    The joins of the path's pieces (where the curvature may jump or change its law: the
    extremes of a clothoid chain's curvature lie there), the knots inside its spline and
    NURBS pieces (where the curvature rate jumps: `Path.rate_joins`) and, for a
    `SpeedBound`, the knots of its ``v_limit`` (piecewise linear: its minimum over any
    stretch is at a knot or an end), the ends of its spans and the entries and exits of its
    zones (`zone_intervals`, located to 1e-9 m on the inside). In the bound's own arc length
    (the path's minus `SpeedBound.offset`), sorted, within the path.

    Examples
    --------
    >>> from speedplan import Limits
    >>> from speedplan.geometry import Arc, Line, Path, SpeedBound, bound_breakpoints
    >>> p = Path.from_segments([Line(5.0), Arc(radius=2.0, angle=1.0)])
    >>> lim = Limits(v_max=2, a_max=1, a_lat_max=1, j_max=0.5)
    >>> bound_breakpoints(p, SpeedBound(p, lim, v_limit=([1.0, 2.0], [2.0, 1.0]))).tolist()
    [1.0, 2.0, 5.0]
    """
    if isinstance(bound, SpeedBound) and path is bound.path:
        return bound._breakpoints.copy()  # a copy: the caller may write to it
    return _computed_breakpoints(path, bound)


def _computed_breakpoints(path: Path, bound: Callable[[FloatArray], FloatArray]) -> FloatArray:
    """`bound_breakpoints`, computed."""
    parts = [path.rate_joins]
    shift = 0.0
    if isinstance(bound, SpeedBound):
        shift = bound.offset  # the bound reads the path at s + offset
        if bound.v_limit is not None:
            parts.append(check_v_limit(bound.v_limit)[0])
        parts += [np.array([span.start, span.end]) for span in bound.spans]
        if bound.zones:
            cuts = zone_intervals(bound.path, bound.zones)
            parts.append(np.array([x for a, b, _ in cuts for x in (a, b)]))
    out = np.unique(np.concatenate(parts))
    out = out[(out >= shift) & (out <= path.length)] - shift
    return out


def check_zones(zones: object) -> list[SpeedZone]:
    """``zones`` as a list of `SpeedZone`; raise naming the entry that is not one.

    A single zone counts as a list of one.

    Examples
    --------
    >>> from speedplan.geometry import SpeedZone
    >>> from speedplan.geometry.bounds import check_zones
    >>> z = SpeedZone([(0, 0), (1, 0), (1, 1)], v_max=0.5)
    >>> check_zones(z) == check_zones([z]) == [z]
    True
    """
    return instances("zones", zones, SpeedZone)
