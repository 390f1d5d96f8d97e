"""Speed bounds along a path: ``mu+(s) = min(v_max², a_lat_max/|k(s)|, zones, v_limit)``."""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass
from typing import Any

import numpy as np
import shapely

from .._checks import FloatArray, as_array, as_scalar
from ..errors import InvalidInputError
from ..limits import Limits
from .path import Path

__all__ = ["SpeedZone", "speed_bounds", "zone_intervals"]


@dataclass(frozen=True)
class SpeedZone:
    """A polygon (shapely ``Polygon`` or a list of ``(x, y)`` vertices) with its speed limit.

    Examples
    --------
    >>> from speedplan.geometry import SpeedZone
    >>> z = SpeedZone([(0, -1), (5, -1), (5, 1), (0, 1)], v_max=0.5)
    >>> z.polygon.area, z.v_max
    (10.0, 0.5)
    """

    polygon: Any
    v_max: float

    def __post_init__(self) -> None:
        poly = self.polygon
        if not isinstance(poly, shapely.Polygon):
            pts = as_array("polygon", poly)
            if pts.ndim != 2 or pts.shape[1] != 2 or pts.shape[0] < 3:
                raise InvalidInputError(
                    f"`polygon` must be a shapely Polygon or (m, 2) vertices with m >= 3; "
                    f"got shape {pts.shape}"
                )
            poly = shapely.Polygon(pts)
        if not poly.is_valid or poly.area <= 0:
            raise InvalidInputError("`polygon` must be a valid polygon with positive area")
        object.__setattr__(self, "polygon", poly)
        object.__setattr__(self, "v_max", as_scalar("v_max", self.v_max, nonnegative=True))


def speed_bounds(
    path: Path,
    limits: Limits,
    s: Any,
    *,
    zones: Sequence[SpeedZone] | None = None,
    v_limit: Any = None,
) -> FloatArray:
    """Upper bound ``mu+(s)`` on ``w = v²`` [m²/s²] at arc lengths ``s``.

    ``min(v_max², a_lat_max / |k(s)|)``, further limited to ``zone.v_max²`` where the path point
    lies inside or on the boundary of a zone, and by ``v_limit = (s_knots, v_knots)``: a
    per-position speed limit interpolated linearly in ``s`` (held constant beyond its ends).

    Examples
    --------
    >>> import numpy as np
    >>> from speedplan import Limits, Path
    >>> from speedplan.geometry import Arc, speed_bounds
    >>> arc = Path.from_segments([Arc(radius=2.0, angle=np.pi)])
    >>> speed_bounds(arc, Limits(v_max=2, a_max=1, a_lat_max=1, j_max=0.5), [0.0, 3.0]).tolist()
    [2.0, 2.0]
    """
    q = as_array("s", s)
    w = np.full(q.shape, limits.v_max**2)
    kappa = np.abs(path.curvature(q))
    if np.isfinite(limits.a_lat_max):
        with np.errstate(divide="ignore"):
            w = np.minimum(w, np.where(kappa > 0, limits.a_lat_max / kappa, np.inf))
    if zones:
        xy = path.point(q)
        for zone in zones:
            inside = shapely.intersects_xy(zone.polygon, xy[..., 0], xy[..., 1])
            w = np.where(inside, np.minimum(w, zone.v_max**2), w)
    if v_limit is not None:
        try:
            sk, vk = v_limit
        except (TypeError, ValueError) as exc:
            raise InvalidInputError("`v_limit` must be a pair (s_knots, v_knots)") from exc
        sk = as_array("v_limit[0]", sk, ndim=1)
        vk = as_array("v_limit[1]", vk, ndim=1, length=sk.size, allow_inf=True)
        if (np.diff(sk) <= 0).any() or (vk < 0).any():
            raise InvalidInputError("`v_limit` needs increasing s knots and non-negative speeds")
        w = np.minimum(w, np.interp(q, sk, vk) ** 2)
    return w


def zone_intervals(path: Path, zones: Sequence[SpeedZone], *, tol: float = 1e-9
                   ) -> list[tuple[float, float, float]]:
    """Where the path is inside each zone: ``[(s_enter, s_exit, v_max), ...]`` sorted by entry.

    Entry and exit are located by bisection to ``tol`` metres.
    """
    n = max(2001, int(path.length / 0.01) + 1)
    s = np.linspace(0.0, path.length, min(n, 200_001))
    xy = path.point(s)
    out: list[tuple[float, float, float]] = []

    def inside(zone: SpeedZone, q: FloatArray) -> FloatArray:
        p = path.point(q)
        out_: FloatArray = shapely.intersects_xy(zone.polygon, p[..., 0], p[..., 1])
        return out_

    def refine(zone: SpeedZone, a: float, b: float, entering: bool) -> float:
        while b - a > tol:
            mid = 0.5 * (a + b)
            if bool(inside(zone, np.array(mid))) == entering:
                b = mid
            else:
                a = mid
        return b if entering else a

    for zone in zones:
        flags = shapely.intersects_xy(zone.polygon, xy[:, 0], xy[:, 1]).astype(int)
        change = np.flatnonzero(np.diff(flags))
        enter = [0.0] if flags[0] else []
        exits: list[float] = []
        for i in change:
            if flags[i + 1]:
                enter.append(refine(zone, s[i], s[i + 1], True))
            else:
                exits.append(refine(zone, s[i], s[i + 1], False))
        if flags[-1]:
            exits.append(path.length)
        out.extend((a, b, zone.v_max) for a, b in zip(enter, exits, strict=True))
    return sorted(out)
