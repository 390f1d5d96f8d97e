"""Input checks shared by every layer.

Each check raises `InvalidInputError` whose message names the
argument, shows the offending value and says what to do.
"""

from __future__ import annotations

import math
from collections.abc import Iterable
from typing import Any, TypeVar

import numpy as np
from numpy.typing import NDArray

from .errors import InvalidInputError

FloatArray = NDArray[np.float64]
IntArray = NDArray[np.intp]
T = TypeVar("T")

#: Largest grid a single solve accepts; beyond it memory, not the solver, becomes the limit.
MAX_GRID_POINTS = 5_000_000


def shown(value: Any) -> str:
    """``value`` as a message shows it: numpy scalars as plain numbers, long texts cut.

    ``repr`` of a numpy scalar is ``np.float64(-1.0)`` since numpy 2; a message should say
    ``-1.0``.

    Examples
    --------
    >>> import numpy as np
    >>> from speedplan.core.checks import shown
    >>> shown(np.float64(-1.0)), shown(np.int64(3)), shown("on"), shown([np.float64(1.5)])
    ('-1.0', '3', "'on'", '[1.5]')
    """
    if isinstance(value, np.generic):
        value = value.item()
    elif isinstance(value, list | tuple) and any(isinstance(v, np.generic) for v in value):
        value = type(value)(v.item() if isinstance(v, np.generic) else v for v in value)
    text = repr(value)
    return text if len(text) <= 60 else text[:57] + "..."




def as_array(
    name: str,
    value: Any,
    *,
    ndim: int | None = None,
    length: int | None = None,
    allow_inf: bool = False,
) -> FloatArray:
    """Return ``value`` as a float64 array after checking its shape and finiteness.

    ``allow_inf`` admits ``+inf`` (an absent bound) but never ``-inf`` or NaN.
    """
    try:
        arr = np.asarray(value, dtype=np.float64)
    except (TypeError, ValueError) as exc:
        raise InvalidInputError(
            f"`{name}` must be numeric (a number or an array of numbers); got {shown(value)}"
        ) from exc
    if ndim is not None and arr.ndim != ndim:
        raise InvalidInputError(
            f"`{name}` must be a {ndim}-D array; got shape {arr.shape}"
        )
    if length is not None and arr.shape[0] != length:
        raise InvalidInputError(f"`{name}` must have length {length}; got {arr.shape[0]}")
    if np.isfinite(arr).all():  # one pass in the common case; the culprit named otherwise
        return arr
    if np.isnan(arr).any():
        raise InvalidInputError(f"`{name}` contains NaN; pass finite numbers")
    if allow_inf:
        if np.isneginf(arr).any():
            raise InvalidInputError(f"`{name}` contains -inf; pass finite numbers or +inf")
    else:
        raise InvalidInputError(f"`{name}` contains inf; pass finite numbers")
    return arr


def as_scalar(
    name: str,
    value: Any,
    *,
    positive: bool = False,
    nonnegative: bool = False,
    allow_inf: bool = False,
) -> float:
    """Return ``value`` as a float after checking sign and finiteness."""
    if isinstance(value, bool):
        raise InvalidInputError(f"`{name}` must be a number; got {shown(value)}")
    if type(value) is float and math.isfinite(value):  # the common case, without an array
        x = value
    else:
        x = float(as_array(name, value, ndim=0, allow_inf=allow_inf))
    if positive and not x > 0:
        raise InvalidInputError(f"`{name}` must be > 0; got {x!r}")
    if nonnegative and not x >= 0:
        raise InvalidInputError(f"`{name}` must be >= 0; got {x!r}")
    return x


def broadcast_positive(
    name: str, value: Any, length: int, *, allow_inf: bool = False
) -> FloatArray:
    """Return a positive scalar-or-vector bound as an array of ``length``."""
    arr = as_array(name, value, allow_inf=allow_inf)
    if arr.ndim == 0:
        arr = np.full(length, float(arr))
    elif arr.ndim != 1 or arr.shape[0] != length:
        raise InvalidInputError(
            f"`{name}` must be a scalar or a 1-D array of length {length}; got shape {arr.shape}"
        )
    if not (arr > 0).all():
        bad = int(np.flatnonzero(~(arr > 0))[0])
        raise InvalidInputError(
            f"`{name}` must be > 0 everywhere; got {shown(arr[bad])} at index {bad}"
        )
    return arr


def instances(name: str, value: Any, kind: type[T]) -> list[T]:
    """``value`` as a list of ``kind``: ``None`` is empty, one instance a list of one.

    Examples
    --------
    >>> instances("x", None, int), instances("x", 3, int), instances("x", (1, 2), int)
    ([], [3], [1, 2])
    >>> instances("zones", [1, "a"], int)
    Traceback (most recent call last):
    ...
    speedplan.core.errors.InvalidInputError: `zones[1]` must be a int; got str
    """
    if value is None:
        return []
    if isinstance(value, kind):
        return [value]
    if isinstance(value, str | bytes) or not hasattr(value, "__iter__"):
        raise InvalidInputError(
            f"`{name}` must be a sequence of {kind.__name__}; got {type(value).__name__}"
        )
    items = list(value)
    for i, item in enumerate(items):
        if not isinstance(item, kind):
            raise InvalidInputError(
                f"`{name}[{i}]` must be a {kind.__name__}; got {type(item).__name__}"
            )
    return items


def choice(name: str, value: Any, options: Iterable[str]) -> str:
    """Check that ``value`` is one of ``options`` (a closed set of strings)."""
    opts = tuple(options)
    if not isinstance(value, str) or value not in opts:
        listed = ", ".join(repr(o) for o in opts)
        raise InvalidInputError(f"`{name}` must be one of {listed}; got {shown(value)}")
    return value


def grid_size(name: str, n: int) -> int:
    """Guard against grids too large to hold in memory."""
    if n > MAX_GRID_POINTS:
        raise InvalidInputError(
            f"`{name}` asks for {n} grid points, more than the {MAX_GRID_POINTS} one solve "
            "handles; use a coarser resolution or split the path"
        )
    return n
