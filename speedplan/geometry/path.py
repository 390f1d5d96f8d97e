"""Path: an immutable, arc-length parametrised planar curve made of pieces."""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass
from functools import cached_property
from typing import Any

import numpy as np

from .._checks import FloatArray, as_array, as_scalar
from ..errors import InvalidInputError
from .pieces import ClothoidPiece, Piece, ReversedPiece

__all__ = ["Arc", "Clothoid", "Line", "Path", "PathSamples"]


@dataclass(frozen=True)
class Line:
    """Straight segment of ``length`` [m]."""

    length: float


@dataclass(frozen=True)
class Arc:
    """Circular arc of ``radius`` > 0 [m] turning by ``angle`` [rad] (positive: left)."""

    radius: float
    angle: float


@dataclass(frozen=True)
class Clothoid:
    """Clothoid of ``length`` [m] whose curvature goes linearly from ``k0`` to ``k1`` [1/m]."""

    length: float
    k0: float
    k1: float


Segment = Line | Arc | Clothoid


@dataclass(frozen=True)
class PathSamples:
    """A path sampled on a uniform arc-length grid."""

    s: FloatArray
    xy: FloatArray
    heading: FloatArray
    curvature: FloatArray


def _segment(seg: Any, i: int) -> tuple[float, float, float]:
    """``(length, k0, k1)`` of a segment given as a dataclass or a dict."""
    if isinstance(seg, dict):
        kind = seg.get("type")
        try:
            if kind == "line":
                seg = Line(seg["length"])
            elif kind == "arc":
                seg = Arc(seg["radius"], seg["angle"])
            elif kind == "clothoid":
                seg = Clothoid(seg["length"], seg["k0"], seg["k1"])
            else:
                raise InvalidInputError(
                    f"`segments[{i}]` has type {kind!r}; use 'line', 'arc' or 'clothoid'"
                )
        except KeyError as exc:
            raise InvalidInputError(f"`segments[{i}]` ({kind}) lacks the field {exc}") from exc
    name = f"segments[{i}]"
    if isinstance(seg, Line):
        return as_scalar(f"{name}.length", seg.length, positive=True), 0.0, 0.0
    if isinstance(seg, Arc):
        r = as_scalar(f"{name}.radius", seg.radius, positive=True)
        ang = as_scalar(f"{name}.angle", seg.angle)
        if ang == 0:
            raise InvalidInputError(f"`{name}.angle` must be non-zero; use a Line instead")
        return r * abs(ang), np.sign(ang) / r, np.sign(ang) / r
    if isinstance(seg, Clothoid):
        return (as_scalar(f"{name}.length", seg.length, positive=True),
                as_scalar(f"{name}.k0", seg.k0), as_scalar(f"{name}.k1", seg.k1))
    raise InvalidInputError(f"`{name}` must be a Line, Arc, Clothoid or a dict; got {seg!r}")


@dataclass(frozen=True, eq=False)
class Path:
    """Planar path parametrised by arc length ``s ∈ [0, length]``.

    Build it with :meth:`from_segments`, :meth:`from_waypoints`, :meth:`from_nurbs` or
    :meth:`from_linestring`. Positions in metres, headings in radians (counter-clockwise from
    +x), curvature in 1/m (positive turning left). Query positions outside ``[0, length]`` are
    clipped to the ends.

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
        if not self.pieces:
            raise InvalidInputError("a Path needs at least one piece")
        if not self.length > 0:
            raise InvalidInputError("the path has zero length; pass at least two distinct points")

    @cached_property
    def offsets(self) -> FloatArray:
        """Arc length at the start of each piece, and the total length last."""
        return np.concatenate(([0.0], np.cumsum([p.length for p in self.pieces])))

    @property
    def length(self) -> float:
        """Total length [m]."""
        return float(self.offsets[-1])

    @property
    def is_closed(self) -> bool:
        """Whether the end point coincides with the start point (to 1e-9 of the length)."""
        ends = self.point(np.array([0.0, self.length]))
        return bool(np.linalg.norm(ends[1] - ends[0]) <= 1e-9 * self.length)

    def _dispatch(self, s: Any, attr: str) -> FloatArray:
        q = np.clip(as_array("s", s), 0.0, self.length)
        flat = q.ravel()
        last = len(self.pieces) - 1
        idx = np.clip(np.searchsorted(self.offsets, flat, side="right") - 1, 0, last)
        trailing = (2,) if attr == "point" else ()
        out = np.empty(flat.shape + trailing)
        for k in np.unique(idx):
            sel = idx == k
            out[sel] = getattr(self.pieces[k], attr)(flat[sel] - self.offsets[k])
        return out.reshape(q.shape + trailing)

    def point(self, s: Any) -> FloatArray:
        """Positions ``(x, y)`` at arc lengths ``s``, shape ``s.shape + (2,)`` [m]."""
        return self._dispatch(s, "point")

    def heading(self, s: Any) -> FloatArray:
        """Heading [rad] at arc lengths ``s``."""
        return self._dispatch(s, "heading")

    def curvature(self, s: Any) -> FloatArray:
        """Signed curvature [1/m] at arc lengths ``s``."""
        return self._dispatch(s, "curvature")

    def resample(self, n: int | None = None, ds: float | None = None) -> PathSamples:
        """Uniform arc-length samples: ``n`` points, or a step of at most ``ds`` [m]."""
        if (n is None) == (ds is None):
            raise InvalidInputError("pass exactly one of `n` and `ds`")
        if n is None:
            step = as_scalar("ds", ds, positive=True)
            n = int(np.ceil(self.length / step)) + 1
        if isinstance(n, bool) or int(n) != n or n < 2:
            raise InvalidInputError(f"`n` must be an integer >= 2; got {n!r}")
        s = np.linspace(0.0, self.length, int(n))
        return PathSamples(s, self.point(s), self.heading(s), self.curvature(s))

    def reversed(self) -> Path:
        """The same path travelled from its end to its start."""
        return Path(tuple(p.piece if isinstance(p, ReversedPiece) else ReversedPiece(p)
                          for p in reversed(self.pieces)))

    def to_linestring(self, ds: float | None = None) -> Any:
        """A shapely ``LineString`` through points every ``ds`` [m] (default length/1000)."""
        import shapely

        samples = self.resample(ds=ds if ds is not None else self.length / 1000)
        return shapely.LineString(samples.xy)

    # ---- constructors -----------------------------------------------------------------------
    @classmethod
    def from_segments(
        cls, segments: Sequence[Any], start: Sequence[float] = (0.0, 0.0), heading: float = 0.0
    ) -> Path:
        """Chain of lines, arcs and clothoids, tangent-continuous (G1) by construction.

        Parameters
        ----------
        segments : sequence
            :class:`Line`, :class:`Arc`, :class:`Clothoid` or dicts
            ``{"type": "line"|"arc"|"clothoid", ...}`` with the same fields.
        start : (x, y)
            Start point [m].
        heading : float
            Initial heading [rad].
        """
        if len(segments) == 0:
            raise InvalidInputError("`segments` is empty; pass at least one segment")
        xy = as_array("start", start, ndim=1, length=2)
        theta = as_scalar("heading", heading)
        pieces: list[Piece] = []
        for i, seg in enumerate(segments):
            length, k0, k1 = _segment(seg, i)
            piece = ClothoidPiece((float(xy[0]), float(xy[1])), theta, length, k0, k1)
            pieces.append(piece)
            xy = piece.point(np.array(length))
            theta = float(piece.heading(np.array(length)))
        return cls(tuple(pieces))

    @classmethod
    def from_waypoints(cls, xy: Any, kind: str = "clothoid", **options: Any) -> Path:
        """Path through waypoints; see :func:`speedplan.geometry.fitting.fit_waypoints`."""
        from .fitting import fit_waypoints

        return cls(fit_waypoints(xy, kind, **options))

    @classmethod
    def from_nurbs(
        cls, degree: int, knots: Any, control_points: Any, weights: Any = None
    ) -> Path:
        """NURBS curve as in a VDA 5050 edge ``trajectory``; see :mod:`speedplan.geometry.nurbs`."""
        from .nurbs import nurbs_piece

        return cls((nurbs_piece(degree, knots, control_points, weights),))

    @classmethod
    def from_linestring(cls, line: Any, kind: str = "polyline", **options: Any) -> Path:
        """Path through the vertices of a shapely ``LineString``."""
        import shapely

        if not isinstance(line, shapely.LineString):
            raise InvalidInputError(
                f"`line` must be a shapely LineString; got {type(line).__name__}"
            )
        return cls.from_waypoints(np.asarray(line.coords)[:, :2], kind, **options)
