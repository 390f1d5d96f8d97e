"""Input checks of the geometry layer (waypoints, integers, angles)."""

from __future__ import annotations

from typing import Any

import numpy as np

from ..core.checks import FloatArray, as_array
from ..core.errors import InvalidInputError

__all__ = ["as_direction", "as_int", "as_reverse", "check_waypoints"]


def as_int(name: str, value: Any, *, minimum: int) -> int:
    """``value`` as an ``int`` >= ``minimum`` (bools and non-integral numbers rejected)."""
    ok = not isinstance(value, bool | str)
    try:
        ok = ok and int(value) == value
    except (TypeError, ValueError):
        ok = False
    if not ok or int(value) < minimum:
        raise InvalidInputError(f"`{name}` must be an integer >= {minimum}; got {value!r}")
    return int(value)


def as_reverse(name: str, value: Any) -> bool:
    """``value`` as a ``bool`` (only ``True``/``False``, numpy's included: ``1`` is ambiguous)."""
    if not isinstance(value, bool | np.bool_):
        raise InvalidInputError(f"`{name}` must be True or False; got {value!r}")
    return bool(value)


def as_direction(name: str, value: Any) -> int:
    """``value`` as a direction of travel: ``1`` (forward) or ``-1`` (reverse)."""
    if isinstance(value, bool | np.bool_) or value not in (1, -1):
        raise InvalidInputError(f"`{name}` must be 1 (forward) or -1 (reverse); got {value!r}")
    return int(value)


def check_waypoints(xy: Any, name: str = "xy") -> FloatArray:
    """Validate waypoints: shape (n, 2) with n >= 2, finite, no repeated consecutive points.

    Two points closer than ``1e-12`` times the extent of the point set count as repeated.
    """
    pts = as_array(name, xy)
    if pts.ndim != 2 or pts.shape[1] != 2 or pts.shape[0] < 2:
        raise InvalidInputError(f"`{name}` must have shape (n, 2) with n >= 2; got {pts.shape}")
    extent = float(np.ptp(pts, axis=0).max())
    if not extent > 0:
        raise InvalidInputError(f"`{name}` needs at least two distinct points; all are equal")
    legs = np.linalg.norm(np.diff(pts, axis=0), axis=1)
    short = np.flatnonzero(legs <= 1e-12 * extent)
    if short.size:
        i = int(short[0])
        raise InvalidInputError(
            f"`{name}` repeats a point at consecutive rows {i} and {i + 1} ({pts[i].tolist()}); "
            "remove the duplicate"
        )
    return pts
