"""Local grid refinement where a planned law exceeds its limits."""

from __future__ import annotations

import numpy as np

from ..core.checks import FloatArray, grid_size
from .grid import GRADING, MIN_RELATIVE_STEP, graded_steps, nodes_from_steps

__all__ = ["PAD_CELLS", "refined_grid", "subdivided_grid"]

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
    m = s.size - 1
    split = np.zeros(m, dtype=bool)
    for k in np.flatnonzero(cells):
        split[max(k - PAD_CELLS, 0):min(k + PAD_CELLS + 1, m)] = True
    lo = s[:-1][split]
    width = np.diff(s)[split]
    inner = (lo[:, None] + width[:, None] * (np.arange(1, parts) / parts)[None, :]).ravel()
    grid = np.unique(np.concatenate((s, inner)))  # sorted; a cell of a few ulps adds none
    grid_size("n", grid.size)
    return grid
