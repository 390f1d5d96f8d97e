"""Path: an immutable, arc-length parametrised planar curve made of pieces."""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass
from functools import cached_property
from itertools import pairwise
from typing import TYPE_CHECKING

import numpy as np
from numpy.typing import ArrayLike

from ..core.checks import FloatArray, IntArray, as_array, as_scalar, grid_size
from ..core.errors import InvalidInputError
from ..core.options import JsonObject
from ._checks import as_int
from .pieces import Piece, SubPiece
from .primitives import (
    Arc,
    Clothoid,
    ClothoidPiece,
    Line,
    PieceSpec,
    as_segment,
    clothoid_chain,
    end_heading,
    segment_spec,
    turn_integral,
)

if TYPE_CHECKING:
    from shapely import LineString

__all__ = ["Arc", "Clothoid", "Line", "Path", "PathSamples"]

#: Queries this far outside ``[0, length]`` (relative to the length) are clipped, not rejected.
S_TOLERANCE = 1e-9


@dataclass(frozen=True)
class PathSamples:
    """A path sampled on a uniform arc-length grid (both ends included).

    Attributes
    ----------
    s : ndarray, shape (n,)
        Arc lengths [m], ``s[0] = 0`` and ``s[-1] = length``.
    xy : ndarray, shape (n, 2)
        Positions [m].
    heading : ndarray, shape (n,)
        Vehicle headings [rad], continuous (unwrapped) along the path, through cusps too.
    curvature : ndarray, shape (n,)
        Signed curvatures [1/m] (positive: turning left in the direction of travel).
    direction : ndarray of int, shape (n,)
        Direction of travel, ``+1`` forward or ``-1`` reverse (see `Path.direction`).

    Examples
    --------
    >>> from speedplan.geometry import Line, Path
    >>> smp = Path.from_segments([Line(4.0)]).resample(n=3)
    >>> smp.s.tolist(), smp.xy[:, 0].tolist(), smp.curvature.tolist(), smp.direction.tolist()
    ([0.0, 2.0, 4.0], [0.0, 2.0, 4.0], [0.0, 0.0, 0.0], [1, 1, 1])
    """

    s: FloatArray
    xy: FloatArray
    heading: FloatArray
    curvature: FloatArray
    direction: IntArray


@dataclass(frozen=True, eq=False, repr=False)
class Path:
    """Planar path parametrised by arc length ``s ∈ [0, length]``.

    Build it with [`from_segments`][speedplan.Path.from_segments], `from_waypoints`, `from_nurbs` or
    `from_linestring`; it is immutable. Positions in metres, headings in radians
    (counter-clockwise from +x, continuous along the path), curvature in 1/m (positive turning
    left). Every query is vectorised over ``s``.

    A path may be driven partly in reverse: each piece has a direction of travel (``+1``
    forward, ``-1`` reverse; `direction`), and the positions where it flips are
    `cusps`, where the vehicle stops. ``heading`` is the vehicle's heading (yaw): the
    direction of travel on forward pieces, that plus π on reverse ones, continuous through
    cusps (the travel tangent flips by π there); ``curvature`` is that of the curve traversed
    in the direction of travel.

    Query positions within ``1e-9 * length`` outside ``[0, length]`` (rounding) are clipped to
    the ends; further outside they raise `InvalidInputError`.

    Parameters
    ----------
    pieces : tuple of Piece
        The chain of pieces (internal; use the constructors).

    Examples
    --------
    >>> import numpy as np
    >>> from speedplan import Path
    >>> from speedplan.geometry import Arc, Line
    >>> p = Path.from_segments([Line(2.0), Arc(radius=1.0, angle=np.pi / 2)])
    >>> round(p.length, 6), p.point(p.length).round(6).tolist(), float(p.curvature(3.0))
    (3.570796, [3.0, 1.0], 1.0)
    """

    pieces: tuple[Piece, ...]

    def __post_init__(self) -> None:
        object.__setattr__(self, "pieces", tuple(self.pieces))
        if not self.pieces or not all(isinstance(p, Piece) for p in self.pieces):
            raise InvalidInputError(
                "`pieces` must be a non-empty sequence of pieces; build paths with "
                "Path.from_segments, from_waypoints, from_nurbs or from_linestring"
            )
        if not (np.isfinite(self.length) and self.length > 0):
            raise InvalidInputError("the path has zero length; pass at least two distinct points")

    def __repr__(self) -> str:
        return (f"Path(length={self.length:.6g} m, pieces={len(self.pieces)}, "
                f"closed={self.is_closed})")

    @cached_property
    def offsets(self) -> FloatArray:
        """Arc length at the start of each piece, then the total length [m]."""
        return np.concatenate(([0.0], np.cumsum([p.length for p in self.pieces])))

    @property
    def length(self) -> float:
        """Total length [m].

        Examples
        --------
        >>> from speedplan.geometry import Line, Path
        >>> Path.from_segments([Line(1.5), Line(2.5)]).length
        4.0
        """
        return float(self.offsets[-1])

    @property
    def is_closed(self) -> bool:
        """Whether the end point equals the start point (to ``1e-9 * length``).

        Examples
        --------
        >>> import numpy as np
        >>> from speedplan.geometry import Arc, Path
        >>> Path.from_segments([Arc(1.0, 2 * np.pi)]).is_closed
        True
        """
        ends = self.point(np.array([0.0, self.length]))
        return bool(np.linalg.norm(ends[1] - ends[0]) <= 1e-9 * self.length)

    # ---- evaluation -------------------------------------------------------------------------
    def _locate(self, s: ArrayLike) -> tuple[FloatArray, IntArray]:
        """Checked, clipped ``s`` and the index of the piece holding each value."""
        q = as_array("s", s)
        L = self.length
        tol = S_TOLERANCE * L
        if q.size:
            lo, hi = q.min(), q.max()
            if lo < -tol or hi > L + tol:
                bad = q[(q < -tol) | (q > L + tol)][0]
                raise InvalidInputError(
                    f"`s` must lie in [0, length] = [0, {L:.9g}] m; got {bad!r}"
                )
            if lo < 0.0 or hi > L:  # within the tolerance: clipped (else already inside)
                q = np.clip(q, 0.0, L)
        # Every q >= 0 = offsets[0] is right of the first offset: only the end needs a cap.
        return q, np.minimum(np.searchsorted(self.offsets, q, side="right") - 1,
                             len(self.pieces) - 1)

    @property
    def analytic(self) -> bool:
        """Whether every piece is a line, arc or clothoid (closed-form curvature and heading).

        Curvature and heading of such a path cost a few vector operations per query; a spline
        or NURBS piece inverts its arc length at every query.

        Examples
        --------
        >>> from speedplan import Path
        >>> Path.from_waypoints([(0, 0), (4, 0), (4, 3)]).analytic
        True
        """
        return self._clothoids is not None

    @cached_property
    def _clothoids(self) -> FloatArray | None:
        """Rows ``k0, k1 - k0, length, theta0`` of the pieces, if all are clothoid pieces.

        ``None`` unless every piece is a plain
        `ClothoidPiece` (lines, arcs, clothoids: every
        path but NURBS, splines and cut pieces). Curvature and heading are then one
        vectorised pass over all points, with each piece's own formula and operation order
        (bitwise the per-piece result): grouping 10 000 points by piece and calling 70 pieces
        cost ~1 ms a query, and a plan makes many. Positions likewise ([`_cells`][speedplan.Path],
        [`_clothoid_points`][speedplan.Path]), equal to the per-piece result to rounding.
        """
        if not all(type(p) is ClothoidPiece for p in self.pieces):
            return None
        pieces: list[ClothoidPiece] = [p for p in self.pieces if isinstance(p, ClothoidPiece)]
        return np.array([[p.k0, p.k1 - p.k0, p.length, p.theta0] for p in pieces]).T.copy()

    @cached_property
    def _cells(self) -> tuple[FloatArray, IntArray, IntArray, tuple[FloatArray, ...]] | None:
        """The quadrature cells of all pieces, for [`_clothoid_points`][speedplan.Path].

        ``(starts, first, last, rows)``: the cells' start on the path [m] (sorted), the index
        of each piece's first and last cell, and per cell the rows ``u, x, y, d cos θ,
        d sin θ, κ, dκ/ds, curved`` at its start (local arc length, position, travel
        direction ``d = ±1`` times the heading's unit vector, curvature, whether the cell
        is curved).
        ``None`` unless the pieces are all plain clothoid pieces.
        """
        if self._clothoids is None:
            return None
        pieces: list[ClothoidPiece] = [p for p in self.pieces if isinstance(p, ClothoidPiece)]
        counts = np.array([p._knots.size - 1 for p in pieces])
        last = np.cumsum(counts) - 1
        first = last - counts + 1
        knots = np.concatenate([p._knots[:-1] for p in pieces])
        xy = np.concatenate([p._knot_xy[:-1] for p in pieces])
        owner = np.repeat(np.arange(len(pieces)), counts)
        k0, dk, length, theta0 = (row[owner] for row in self._clothoids)
        sharpness = dk / length
        theta = theta0 + knots * (k0 + 0.5 * sharpness * knots)  # ClothoidPiece.heading
        kappa = k0 + dk * (knots / length)  # ClothoidPiece.curvature
        direction = self._directions[owner].astype(np.float64)  # ±1: products stay exact
        curved = (kappa != 0.0) | (sharpness != 0.0)
        # Separate contiguous rows: one gather each is ~10x faster than a (8, cells) take.
        rows = tuple(np.ascontiguousarray(r) for r in (
            knots, xy[:, 0], xy[:, 1], direction * np.cos(theta), direction * np.sin(theta),
            kappa, sharpness, curved))
        return self.offsets[owner] + knots, first, last, rows

    def _clothoid_points(self, q: FloatArray, idx: IntArray) -> FloatArray | None:
        """`ClothoidPiece.point` of each point's piece, in one pass over all points.

        Each point starts from the tabulated start of its quadrature cell and adds
        `turn_integral` of the step: the same position
        to rounding as the piece's Gauss–Legendre rule without its 32 cosines and sines a
        point, and no grouping by piece (10 000 points: 3.1 -> 1.2 ms on the serpentine).
        Lines are exact (``start + u · direction``), as in the piece. ``None`` when some
        step would turn by more than 1 rad (a piece of over 250 000 rad).
        """
        cells = self._cells
        assert cells is not None
        starts, first, last, rows = cells
        flat, fidx = q.ravel(), idx.ravel()
        table = self._clothoids
        assert table is not None
        u = np.minimum(np.maximum(flat - self.offsets[fidx], 0.0), table[2][fidx])
        # The cell holding u, kept within its piece where rounding of the path's positions
        # would put a point at a join into the neighbour's cell.
        j = np.minimum(np.maximum(np.searchsorted(starts, flat, side="right") - 1, first[fidx]),
                       last[fidx])
        u0, x0, y0, cos0, sin0, curved = (r[j] for r in rows[:5] + rows[7:])
        h = u - u0
        # Only points on curved cells need the series: on a line it is exactly 1 (lines are
        # most of a waypoint path's length).
        re, im = np.ones(h.size), np.zeros(h.size)
        jb = j[curved]
        hb = h[curved]
        try:
            re[curved], im[curved] = turn_integral(rows[5][jb] * hb, rows[6][jb] * (hb * hb))
        except ValueError:
            return None
        out = np.empty((flat.size, 2))
        out[:, 0] = x0 + h * (cos0 * re - sin0 * im)
        out[:, 1] = y0 + h * (sin0 * re + cos0 * im)
        return out.reshape(*q.shape, 2)

    def _clothoid_values(self, q: FloatArray, idx: IntArray, attr: str) -> FloatArray:
        """`ClothoidPiece.curvature` or ``heading`` of each point's piece (see above)."""
        table = self._clothoids
        assert table is not None
        u = q - self.offsets[idx]
        k0, dk, length = table[0][idx], table[1][idx], table[2][idx]
        if attr == "curvature":
            out = k0 + dk * (u / length)
        else:
            sharpness = dk / length
            out = table[3][idx] + u * (k0 + 0.5 * sharpness * u)
        return np.asarray(out, dtype=np.float64)

    def _dispatch(self, s: ArrayLike, attr: str) -> FloatArray:
        q, idx = self._locate(s)
        if self._clothoids is not None:
            if attr in ("curvature", "heading"):
                return self._clothoid_values(q, idx, attr)
            if attr == "point":
                xy = self._clothoid_points(q, idx)
                if xy is not None:
                    return xy
        return self._by_piece(q, idx, attr)

    def _by_piece(self, q: FloatArray, idx: IntArray, attr: str) -> FloatArray:
        """``attr`` of each piece at the points located on it (``q``, ``idx``: `_locate`)."""
        flat, fidx = q.ravel(), idx.ravel()
        trailing = (2,) if attr == "point" else ()
        if len(self.pieces) == 1:  # no grouping (a NURBS edge, a spline)
            one = np.asarray(getattr(self.pieces[0], attr)(flat - self.offsets[0]),
                             dtype=np.float64)
            return one.reshape(q.shape + trailing)
        out = np.empty(flat.shape + trailing)
        # Group by piece with one stable sort (a mask per piece is O(pieces x points)).
        order = np.argsort(fidx, kind="stable")
        cuts = np.flatnonzero(np.diff(fidx[order])) + 1
        for sel in np.split(order, cuts) if flat.size else ():
            k = int(fidx[sel[0]])
            out[sel] = getattr(self.pieces[k], attr)(flat[sel] - self.offsets[k])
        return out.reshape(q.shape + trailing)

    def point(self, s: ArrayLike) -> FloatArray:
        """Positions ``(x, y)`` [m] at arc lengths ``s`` [m], shape ``s.shape + (2,)``.

        Examples
        --------
        >>> from speedplan.geometry import Line, Path
        >>> Path.from_segments([Line(4.0)], start=(1, 2)).point([0.0, 4.0]).tolist()
        [[1.0, 2.0], [5.0, 2.0]]
        """
        return self._dispatch(s, "point")

    def heading(self, s: ArrayLike) -> FloatArray:
        """Vehicle heading (yaw) [rad] at arc lengths ``s`` [m], continuous along the path.

        The direction of travel on forward pieces, that plus π on reverse ones; continuous
        through cusps too (unwrapped).

        Examples
        --------
        >>> import numpy as np
        >>> from speedplan.geometry import Arc, Path
        >>> p = Path.from_segments([Arc(1.0, 3 * np.pi)])  # heading grows past π
        >>> round(float(p.heading(p.length)) / np.pi, 12)
        3.0
        """
        return self._dispatch(s, "heading")

    def curvature(self, s: ArrayLike) -> FloatArray:
        """Signed curvature [1/m] at arc lengths ``s`` [m] (positive: turning left).

        That of the curve traversed in the direction of travel.

        Examples
        --------
        >>> from speedplan.geometry import Arc, Line, Path
        >>> p = Path.from_segments([Line(1.0), Arc(radius=4.0, angle=-1.0)])
        >>> p.curvature([0.5, 2.0]).tolist()
        [0.0, -0.25]
        """
        return self._dispatch(s, "curvature")

    def curvature_rate(self, s: ArrayLike) -> FloatArray:
        """``dκ/ds`` [1/m²] at arc lengths ``s`` [m], within each piece.

        At a join the value is that of the piece after it; where the curvature jumps there
        (`curvature_jumps`) it is not defined, and a vehicle must stop to pass with a
        lateral-jerk limit.

        Examples
        --------
        >>> from speedplan.geometry import Clothoid, Line, Path
        >>> p = Path.from_segments([Line(1.0), Clothoid(2.0, 0.0, 0.5)])
        >>> p.curvature_rate([0.5, 2.0]).tolist()
        [0.0, 0.25]
        """
        return self._dispatch(s, "curvature_rate")

    def curvature_rate_before(self, s: ArrayLike) -> FloatArray:
        """`curvature_rate` on the side before ``s`` [1/m²].

        Where the rate jumps (a join of pieces, a knot of a spline or NURBS piece:
        `rate_joins`), the rate the stretch before ``s`` ends with.

        Examples
        --------
        >>> from speedplan.geometry import Clothoid, Line, Path
        >>> p = Path.from_segments([Clothoid(2.0, 0.0, 0.5), Line(1.0)])
        >>> p.curvature_rate([2.0]).tolist(), p.curvature_rate_before([2.0]).tolist()
        ([0.0], [0.25])
        """
        q, _ = self._locate(s)
        idx = np.maximum(np.searchsorted(self.offsets, q, side="left") - 1, 0)
        idx = np.minimum(idx, len(self.pieces) - 1)
        return self._by_piece(q, idx, "curvature_rate_before")

    @cached_property
    def rate_joins(self) -> FloatArray:
        """Arc lengths [m] inside the path where the curvature rate may jump, sorted.

        The joins of its pieces (`offsets`) and the knots inside its spline and NURBS pieces,
        where a cubic curve is C²: the curvature goes on, its rate jumps, and so does the
        lateral jerk at a given speed. A lateral-jerk limit is held on both sides of each
        (`curvature_rate`, `curvature_rate_before`).

        Examples
        --------
        >>> from speedplan.geometry import Path
        >>> p = Path.from_nurbs(3, [0, 0, 0, 0, 0.5, 1, 1, 1, 1],
        ...                     [[0, 0], [2, 0], [4, 1], [5, 3], [5, 5]])
        >>> p.rate_joins.size, bool(0 < p.rate_joins[0] < p.length)
        (1, True)
        """
        parts = [self.offsets[1:-1]]
        parts += [self.offsets[k] + piece.rate_breaks for k, piece in enumerate(self.pieces)]
        out: FloatArray = np.unique(np.concatenate(parts))
        return out

    def curvature_jumps(self, tol: float = 1e-9) -> tuple[FloatArray, FloatArray]:
        """Joins of pieces where the curvature jumps: ``(s [m], jump [1/m])``.

        A jump is a change larger than ``tol × (1/length + |κ|)`` from the end of one piece
        to the start of the next (a G1 path: a line onto an arc, a clothoid chain's joins);
        cusps are not listed. G2 paths (the default of `from_waypoints`) have none.

        Examples
        --------
        >>> from speedplan.geometry import Arc, Line, Path
        >>> s, jump = Path.from_segments([Line(2.0), Arc(radius=4.0, angle=1.0)]).curvature_jumps()
        >>> s.tolist(), jump.tolist()
        ([2.0], [0.25])
        """
        joins = []
        jumps = []
        for k in range(1, len(self.pieces)):
            before, after = self.pieces[k - 1], self.pieces[k]
            if before.direction != after.direction:
                continue
            k_end = float(before.curvature(np.array(before.length)))
            k_start = float(after.curvature(np.array(0.0)))
            scale = 1.0 / self.length + max(abs(k_end), abs(k_start))
            if abs(k_start - k_end) > tol * scale:
                joins.append(float(self.offsets[k]))
                jumps.append(k_start - k_end)
        return np.array(joins, dtype=np.float64), np.array(jumps, dtype=np.float64)

    def direction(self, s: ArrayLike) -> IntArray:
        """Direction of travel at arc lengths ``s`` [m]: ``+1`` forward, ``-1`` reverse.

        At a cusp the value is that of the piece after it.

        Examples
        --------
        >>> from speedplan.geometry import Line, Path
        >>> p = Path.from_segments([Line(2.0), Line(1.0, reverse=True)])
        >>> p.direction([0.0, 1.0, 2.0, 3.0]).tolist()
        [1, 1, -1, -1]
        """
        _, idx = self._locate(s)
        out: IntArray = self._directions[idx]
        return out

    @cached_property
    def _directions(self) -> IntArray:
        return np.array([p.direction for p in self.pieces], dtype=np.intp)

    @cached_property
    def cusps(self) -> FloatArray:
        """Arc lengths [m] where the direction of travel flips (empty when there is none).

        Examples
        --------
        >>> from speedplan.geometry import Line, Path
        >>> Path.from_segments([Line(2.0), Line(1.0, reverse=True), Line(4.0)]).cusps.tolist()
        [2.0, 3.0]
        """
        flips = np.flatnonzero(np.diff(self._directions) != 0) + 1
        out: FloatArray = self.offsets[flips]
        return out

    def split_at_cusps(self) -> tuple[Path, ...]:
        """The maximal single-direction sub-paths, in order, each with ``s`` from 0.

        One element (the path itself) when there is no cusp.

        Examples
        --------
        >>> from speedplan.geometry import Line, Path
        >>> p = Path.from_segments([Line(2.0), Line(1.0, reverse=True), Line(4.0)])
        >>> [(q.length, int(q.direction(0.0))) for q in p.split_at_cusps()]
        [(2.0, 1), (1.0, -1), (4.0, 1)]
        """
        flips = np.flatnonzero(np.diff(self._directions) != 0) + 1
        if flips.size == 0:
            return (self,)
        bounds = np.concatenate(([0], flips, [len(self.pieces)]))
        return tuple(Path(self.pieces[a:b]) for a, b in pairwise(bounds.tolist()))

    def sub(self, lo: float, hi: float | None = None) -> Path:
        """The stretch ``[lo, hi]`` [m] of the path (to the end by default), ``s`` from 0.

        Pieces cut by ``lo`` or ``hi`` become `SubPiece`
        views of the originals: positions, headings and curvature are the path's, exactly.

        Examples
        --------
        >>> from speedplan.geometry import Arc, Line, Path
        >>> p = Path.from_segments([Line(2.0), Arc(radius=1.0, angle=1.0)])
        >>> q = p.sub(1.5, 2.5)
        >>> q.length, q.point(0.0).tolist(), float(q.curvature(0.75))
        (1.0, [1.5, 0.0], 1.0)
        """
        length = self.length
        lo_v = as_scalar("lo", lo, nonnegative=True)
        hi_v = length if hi is None else as_scalar("hi", hi)
        if not lo_v < hi_v <= length * (1 + S_TOLERANCE):
            raise InvalidInputError(
                f"`lo` and `hi` must satisfy 0 <= lo < hi <= length = {length:.9g} m; got "
                f"lo={lo_v!r}, hi={hi_v!r}"
            )
        hi_v = min(hi_v, length)
        out: list[Piece] = []
        for k, piece in enumerate(self.pieces):
            a, b = float(self.offsets[k]), float(self.offsets[k + 1])
            cut_lo, cut_hi = max(a, lo_v), min(b, hi_v)
            if cut_hi - cut_lo <= 1e-15 * length:
                continue
            if cut_lo == a and cut_hi == b:
                out.append(piece)
            else:
                out.append(SubPiece(piece, cut_lo - a, cut_hi - cut_lo))
        return Path(tuple(out))

    def straight_between(self, lo: float, hi: float) -> bool:
        """Whether the stretch ``[lo, hi]`` [m] is straight: every piece it crosses is a line.

        Pieces that only touch the stretch at one end do not count. Lines driven in reverse
        count as straight (the stretch of a path between two cusps).

        Examples
        --------
        >>> from speedplan.geometry import Arc, Line, Path
        >>> p = Path.from_segments([Line(2.0), Arc(radius=1.0, angle=1.0), Line(1.0)])
        >>> p.straight_between(0.0, 2.0), p.straight_between(1.0, 2.5), p.straight_between(3.0, 4.0)
        (True, False, True)
        """
        ends = self.offsets
        crossed = (ends[1:] > lo) & (ends[:-1] < hi)
        return all(piece.straight for piece, hit in zip(self.pieces, crossed, strict=True)
                   if hit)

    def evaluate(self, s: ArrayLike) -> tuple[FloatArray, FloatArray, FloatArray]:
        """``(point, heading, curvature)`` at arc lengths ``s`` in one pass.

        Cheaper than three calls for spline and NURBS pieces (one arc-length inversion).

        Examples
        --------
        >>> from speedplan.geometry import Line, Path
        >>> xy, theta, kappa = Path.from_segments([Line(2.0)], heading=0.5).evaluate([1.0])
        >>> xy.shape, theta.tolist(), kappa.tolist()
        ((1, 2), [0.5], [0.0])
        """
        q, idx = self._locate(s)
        if self._clothoids is not None:  # nothing shared between the three: vectorised
            xy = self._clothoid_points(q, idx)
            return (self._by_piece(q, idx, "point") if xy is None else xy,
                    self._clothoid_values(q, idx, "heading"),
                    self._clothoid_values(q, idx, "curvature"))
        flat, fidx = q.ravel(), idx.ravel()
        xy, theta, kappa = np.empty((flat.size, 2)), np.empty(flat.size), np.empty(flat.size)
        order = np.argsort(fidx, kind="stable")  # grouped by piece, as in _by_piece
        cuts = np.flatnonzero(np.diff(fidx[order])) + 1
        for sel in np.split(order, cuts) if flat.size else ():
            k = int(fidx[sel[0]])
            xy[sel], theta[sel], kappa[sel] = self.pieces[k].evaluate(flat[sel] - self.offsets[k])
        return xy.reshape((*q.shape, 2)), theta.reshape(q.shape), kappa.reshape(q.shape)

    def resample(self, n: int | None = None, ds: float | None = None) -> PathSamples:
        """Samples on a uniform arc-length grid including both ends.

        Parameters
        ----------
        n : int, optional
            Number of samples (>= 2).
        ds : float, optional
            Largest step [m]; the grid has ``ceil(length / ds) + 1`` samples. Pass exactly one
            of ``n`` and ``ds``.

        Returns
        -------
        PathSamples

        Examples
        --------
        >>> from speedplan.geometry import Line, Path
        >>> smp = Path.from_segments([Line(10.0)]).resample(ds=3.0)
        >>> smp.s.tolist()
        [0.0, 2.5, 5.0, 7.5, 10.0]
        """
        if (n is None) == (ds is None):
            raise InvalidInputError("pass exactly one of `n` and `ds`")
        if n is None:
            step = as_scalar("ds", ds, positive=True)
            count = grid_size("ds", int(np.ceil(self.length / step * (1 - 1e-12))) + 1)
        else:
            count = grid_size("n", as_int("n", n, minimum=2))
        s = np.linspace(0.0, self.length, max(count, 2))
        xy, theta, kappa = self.evaluate(s)
        return PathSamples(s, xy, theta, kappa, self.direction(s))

    def reversed(self, *, swap_direction: bool = False) -> Path:
        """The same path travelled from its end to its start.

        ``point_rev(s) = point(L - s)`` and ``curvature_rev(s) = -curvature(L - s)``; the cusps
        move to ``L - cusps``. What happens to the vehicle's heading and gear:

        * default: each piece keeps its direction flag and the vehicle is turned around,
          ``heading_rev(s) = heading(L - s) + π`` and ``direction_rev(s) = direction(L - s)``
          — the same manoeuvre driven from the other end, e.g. a forward path stays forward;
        * ``swap_direction=True``: the flags flip and the heading is kept,
          ``heading_rev(s) = heading(L - s)`` and ``direction_rev(s) = -direction(L - s)`` —
          the vehicle retraces its poses backwards, e.g. backs out of a rack the way it drove
          in.

        Either way the heading stays continuous through the cusps.

        Examples
        --------
        >>> from speedplan.geometry import Arc, Line, Path
        >>> p = Path.from_segments([Line(1.0), Arc(radius=2.0, angle=1.0)])
        >>> r = p.reversed()
        >>> float(r.curvature(0.5)), (r.point(r.length).round(12) + 0.0).tolist()
        (-0.5, [0.0, 0.0])
        >>> b = p.reversed(swap_direction=True)
        >>> int(b.direction(0.0)), round(float(b.heading(b.length)), 12)
        (-1, 0.0)
        """
        return Path(tuple(p.reversed(swap_direction) for p in reversed(self.pieces)))

    def to_linestring(self, ds: float | None = None) -> LineString:
        """A shapely ``LineString`` through the path.

        Parameters
        ----------
        ds : float, optional
            Largest spacing of the vertices [m] (default ``length / 1000``). The joins between
            pieces (e.g. polyline vertices) are always vertices.

        Examples
        --------
        >>> from speedplan.geometry import Line, Path
        >>> ls = Path.from_segments([Line(3.0)]).to_linestring(ds=1.0)
        >>> ls.length, len(ls.coords)
        (3.0, 4)
        """
        import shapely

        step = self.length / 1000 if ds is None else as_scalar("ds", ds, positive=True)
        count = grid_size("ds", int(np.ceil(self.length / step * (1 - 1e-12))) + 1)
        s = np.union1d(np.linspace(0.0, self.length, max(count, 2)), self.offsets)
        return shapely.LineString(self.point(s))

    # ---- constructors -----------------------------------------------------------------------
    @classmethod
    def from_segments(
        cls,
        segments: Sequence[Line | Arc | Clothoid | JsonObject],
        start: Sequence[float] = (0.0, 0.0),
        heading: float = 0.0,
    ) -> Path:
        """Chain of lines, arcs and clothoids, tangent-continuous (G1) by construction.

        Parameters
        ----------
        segments : sequence
            [`Line`][speedplan.geometry.Line], `Arc`, `Clothoid`, or dicts ``{"type": "line" |
            "arc" | "clothoid", ...}`` with the same fields (and optionally ``"reverse":
            true``). Arcs take a positive radius and a signed angle (positive turns left).
            A segment with ``reverse=True`` is driven in reverse; one that follows a segment
            of the other direction starts with a cusp: the travel tangent flips by π, the
            vehicle's heading is unchanged.
        start : (x, y)
            Start point [m].
        heading : float
            Initial vehicle heading [rad] (the direction of travel if the first segment is
            driven forward, its opposite if in reverse).

        Returns
        -------
        Path
            Each segment starts where the previous one ends, with its end heading.

        Examples
        --------
        >>> import numpy as np
        >>> from speedplan.geometry import Arc, Clothoid, Line, Path
        >>> p = Path.from_segments([Line(5.0), Clothoid(2.0, 0.0, 0.5), Arc(2.0, 0.5),
        ...                         {"type": "clothoid", "length": 2.0, "k0": 0.5, "k1": 0.0}])
        >>> round(p.length, 12), round(float(p.heading(p.length)), 12)
        (10.0, 1.5)
        >>> back = Path.from_segments([Line(5.0), Arc(2.0, -0.5, reverse=True)])  # a cusp at 5
        >>> back.cusps.tolist(), back.direction([1.0, 6.0]).tolist()
        ([5.0], [1, -1])
        """
        given: object = segments  # untyped callers pass anything: refuse a string too
        if isinstance(given, str | bytes) or not isinstance(given, Sequence):
            raise InvalidInputError(
                f"`segments` must be a list of segments; got {type(given).__name__}"
            )
        if len(segments) == 0:
            raise InvalidInputError("`segments` is empty; pass at least one segment")
        xy = as_array("start", start, ndim=1, length=2)
        theta = as_scalar("heading", heading)
        specs: list[PieceSpec] = []
        point: tuple[float, float] | None = (float(xy[0]), float(xy[1]))
        for i, seg in enumerate(segments):
            spec = segment_spec(as_segment(seg, f"segments[{i}]"), point, theta)
            specs.append(spec)
            theta, point = end_heading(*spec[1:5]), None  # the next starts where this ends
        return cls(tuple(clothoid_chain(specs)))

    @classmethod
    def from_waypoints(
        cls,
        xy: ArrayLike,
        kind: str = "g2",
        *,
        headings: ArrayLike | None = None,
        corner_radius: float | None = None,
        max_deviation: float | None = None,
        transition: float | None = None,
    ) -> Path:
        """Path through waypoints.

        Parameters
        ----------
        xy : array_like, shape (n, 2)
            Waypoints [m]; n >= 2, finite, no repeated consecutive points.
        kind : {"g2", "clothoid", "spline", "polyline"}
            ``"g2"`` (default): straight legs joined by clothoid–arc–clothoid corners that
            cut each interior waypoint by at most ``max_deviation``, curvature continuous
            (G2), exactly through the first and last waypoints; a waypoint where the path
            turns back by more than 150° is a cusp, driven in reverse after it (see
            `corners`).
            ``"clothoid"``: one clothoid per leg, through every waypoint, tangent continuous
            (G1); see `clothoid_chain`.
            ``"spline"``: chord-length cubic spline reparametrised by true arc length (C²).
            ``"polyline"``: straight legs with corners rounded by tangent circular arcs (G1);
            see `rounded_polyline` for the default rounding.
            Only ``"g2"`` drives reversals; the other kinds refuse them.
        headings : array_like, shape (n,), optional
            ``"clothoid"`` only: headings at the waypoints [rad] (default: the bisectors of
            the adjacent legs, the leg directions at the ends).
        corner_radius : float, optional
            ``"polyline"`` only: radius of the corner arcs [m] (reduced where the legs are too
            short).
        max_deviation : float, optional
            ``"g2"`` and ``"polyline"``: largest distance between a waypoint and the path [m]
            (``"g2"``: default 0.25 m, reduced where the legs are short; ``inf`` rounds as
            much as the legs allow).
        transition : float, optional
            ``"g2"`` only: share of each corner's turn taken by its two clothoids, in
            ``(0, 1]`` (default 0.5; 1 is a clothoid pair without arc).

        Raises
        ------
        InvalidInputError
            Bad waypoints, an option that does not apply to ``kind``, or a reversal in a kind
            other than ``"g2"`` (the message names the row).

        Examples
        --------
        >>> import numpy as np
        >>> from speedplan import Path
        >>> pts = [[0, 0], [10, 0], [10, 10]]
        >>> p = Path.from_waypoints(pts)                      # G2 corner
        >>> p.point([0.0, p.length]).round(12).tolist(), round(float(p.curvature(10.0)), 4)
        ([[0.0, 0.0], [10.0, 10.0]], 1.8014)
        >>> c = Path.from_waypoints(pts, kind="clothoid")     # G1, through every waypoint
        >>> c.point(c.offsets).round(9).tolist() == [[0, 0], [10, 0], [10, 10]]
        True
        >>> q = Path.from_waypoints(pts, kind="polyline", corner_radius=2.0)
        >>> round(float(q.curvature(10.0)), 12), round(q.length, 6)
        (0.5, 19.141593)
        >>> r = Path.from_waypoints([[0, 0], [10, 0], [4, 0]])  # back out: a cusp at x = 10
        >>> r.cusps.tolist(), r.direction([5.0, 12.0]).tolist()
        ([10.0], [1, -1])
        """
        from .fitting import fit_waypoints

        return cls(fit_waypoints(xy, kind, headings=headings, corner_radius=corner_radius,
                                 max_deviation=max_deviation, transition=transition))

    @classmethod
    def from_nurbs(
        cls, degree: int, knots: ArrayLike, control_points: ArrayLike,
        weights: ArrayLike | None = None,
    ) -> Path:
        """NURBS curve, as in a VDA 5050 edge ``trajectory``, reparametrised by arc length.

        Parameters
        ----------
        degree : int
            Degree (>= 1).
        knots : array_like
            Non-decreasing knot vector, length ``len(control_points) + degree + 1``
            (VDA 5050 ``knotVector``).
        control_points : array_like, shape (m, 2)
            Control points [m].
        weights : array_like, shape (m,), optional
            Positive weights (default 1: a plain B-spline).

        Examples
        --------
        >>> from speedplan import Path
        >>> p = Path.from_nurbs(2, [0, 0, 0, 1, 1, 1], [[0, 0], [1, 1], [2, 0]])
        >>> p.point([0.0, p.length]).round(12).tolist(), round(p.length, 9)
        ([[0.0, 0.0], [2.0, 0.0]], 2.295587149)

        A NURBS whose control points lie in order on the segment between its ends is that
        segment (VDA 5050 3.0 gives straight edges as two control points): a line.

        >>> Path.from_nurbs(1, [0, 0, 1, 1], [[0, 0], [3, 4]]).straight_between(0.0, 5.0)
        True
        """
        from .nurbs import nurbs_piece, straight_chord

        piece = nurbs_piece(degree, knots, control_points, weights)
        chord = straight_chord(np.asarray(control_points, dtype=np.float64))
        if chord is not None:  # the same points, in the same order: exactly a line
            start, heading, length = chord
            return cls.from_segments([Line(length)], start=start, heading=heading)
        return cls((piece,))

    @classmethod
    def from_linestring(cls, ls: LineString, kind: str = "g2", *,
                        headings: ArrayLike | None = None,
                        corner_radius: float | None = None, max_deviation: float | None = None,
                        transition: float | None = None) -> Path:
        """Path through the vertices of a shapely ``LineString`` (z ignored).

        ``kind`` and the keyword options are those of `from_waypoints`, with the same
        default ``"g2"``: the straight legs of the LineString, its corners cut by at most
        ``max_deviation``.

        Examples
        --------
        >>> import shapely
        >>> from speedplan import Path
        >>> p = Path.from_linestring(shapely.LineString([(0, 0), (4, 0)]))
        >>> p.length
        4.0
        """
        import shapely

        if not isinstance(ls, shapely.LineString):
            raise InvalidInputError(
                f"`ls` must be a shapely LineString; got {type(ls).__name__}"
            )
        if ls.is_empty:
            raise InvalidInputError("`ls` is empty")
        from .fitting import fit_waypoints

        return cls(fit_waypoints(np.asarray(ls.coords)[:, :2], kind, headings=headings,
                                 corner_radius=corner_radius, max_deviation=max_deviation,
                                 transition=transition, name="ls"))
