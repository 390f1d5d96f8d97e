"""Numerics shared by the layers, one definition each.

Quadrature rules, angle wrapping, the points inside the cells of a grid.
"""

from __future__ import annotations

from typing import Any, TypeVar

import numpy as np
import numpy.typing as npt

from .checks import FloatArray

__all__ = ["CELL_FRACTIONS", "CELL_POINTS", "GAUSS_NODES", "GAUSS_WEIGHTS", "SHORT_NODES",
           "SHORT_WEIGHTS", "cell_points", "cell_rows", "gauss_legendre", "wrap_angle",
           "wrap_heading"]


def gauss_legendre(points: int) -> tuple[np.ndarray, np.ndarray]:
    """Nodes and weights of the ``points``-point Gauss–Legendre rule on ``[0, 1]``.

    Exact for polynomials of degree ``2 points - 1``.

    Examples
    --------
    >>> x, w = gauss_legendre(2)
    >>> round(float(w @ x**3), 15)
    0.25
    """
    x, w = np.polynomial.legendre.leggauss(points)
    return 0.5 * (x + 1.0), 0.5 * w


#: 16-point rule on [0, 1]: exact for polynomials of degree 31.
GAUSS_NODES, GAUSS_WEIGHTS = gauss_legendre(16)
#: 4-point rule on [0, 1] (degree 7), for short spans.
SHORT_NODES, SHORT_WEIGHTS = gauss_legendre(4)


def wrap_angle(theta: Any) -> FloatArray:
    """Angles [rad] wrapped into ``[-π, π)`` by ``(θ + π) mod 2π - π`` (for angle differences).

    Examples
    --------
    >>> import numpy as np
    >>> from speedplan.core.numerics import wrap_angle
    >>> wrap_angle([0.5, 1.5 * np.pi, -3.5 * np.pi]).round(12).tolist()
    [0.5, -1.570796326795, 1.570796326795]
    """
    out: FloatArray = (np.asarray(theta, dtype=np.float64) + np.pi) % (2.0 * np.pi) - np.pi
    return out


def wrap_heading(theta: Any) -> FloatArray:
    """Angles [rad] wrapped to ``[-π, π)``; values already in that range are returned unchanged.

    The exported ``heading`` column: a heading the law computed in range keeps its last bits.

    Examples
    --------
    >>> import numpy as np
    >>> from speedplan.core.numerics import wrap_heading
    >>> wrap_heading([0.5, np.pi, 1.5 * np.pi, -np.pi]).round(12).tolist()
    [0.5, -3.14159265359, -1.570796326795, -3.14159265359]
    """
    th = np.asarray(theta, dtype=np.float64)
    wrapped = np.where((th >= -np.pi) & (th < np.pi), th, wrap_angle(th))
    # Rounding can bring a wrapped value up to π itself.
    out: FloatArray = np.where(wrapped >= np.pi, -np.pi, wrapped)
    return out


_Scalar = TypeVar("_Scalar", bound=np.generic)

#: Points per grid cell at which the speed bound is evaluated: the model's node bounds (the
#: bound's minimum over each cell) and the check of a law without jerk limit.
CELL_POINTS = 8


def cell_points(s: FloatArray, per_cell: int = CELL_POINTS) -> FloatArray:
    """``per_cell`` equally spaced points of every cell of the grid ``s``, nodes first.

    The nodes ``s`` (every cell's first point, and the grid's end), then for each
    ``k = 1 .. per_cell - 1`` the ``k``-th point ``s_i + h_i k / per_cell`` of every cell
    ``i`` (``h = diff(s)``): ``per_cell (n - 1) + 1`` points, each row of ``n - 1`` in the
    cells' order (`cell_rows` views them so). A cell's points depend only on its own two
    nodes: a grid that keeps a cell keeps its points to the last bit.

    Examples
    --------
    >>> import numpy as np
    >>> cell_points(np.array([0.0, 1.0, 3.0]), 4).tolist()
    [0.0, 1.0, 3.0, 0.25, 1.5, 0.5, 2.0, 0.75, 2.5]
    """
    n = s.size
    out = np.empty(per_cell * (n - 1) + 1)
    out[:n] = s
    rows = out[n:].reshape(per_cell - 1, n - 1)
    fractions = CELL_FRACTIONS if per_cell == CELL_POINTS else _fractions(per_cell)
    np.multiply(fractions, s[1:] - s[:-1], out=rows)
    rows += s[:-1]
    return out


def _fractions(per_cell: int) -> FloatArray:
    """``k / per_cell`` for ``k = 1 .. per_cell - 1``, as a column (one row per point)."""
    out: FloatArray = (np.arange(1, per_cell) / per_cell)[:, None]
    return out


#: The fractions ``k / CELL_POINTS`` of a cell at its inner points, a column (one row per
#: point of `cell_rows`), made once: every plan builds cell points several times.
CELL_FRACTIONS = _fractions(CELL_POINTS)
CELL_FRACTIONS.flags.writeable = False


def cell_rows(values: npt.NDArray[_Scalar], per_cell: int = CELL_POINTS
              ) -> tuple[npt.NDArray[_Scalar], npt.NDArray[_Scalar]]:
    """``values`` at the `cell_points` of a grid as ``(nodes, inner)``.

    Shapes ``(n,)`` and ``(per_cell - 1, n - 1)``; views, not copies: ``inner[k - 1, i]`` is
    the value at the ``k``-th point of cell ``i``.

    Examples
    --------
    >>> import numpy as np
    >>> nodes, inner = cell_rows(cell_points(np.array([0.0, 1.0, 3.0]), 4), 4)
    >>> nodes.tolist(), inner[:, 1].tolist()
    ([0.0, 1.0, 3.0], [1.5, 2.0, 2.5])
    """
    n = (values.size - 1) // per_cell + 1
    return values[:n], values[n:].reshape(per_cell - 1, n - 1)
