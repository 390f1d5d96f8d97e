"""Structural checks of a route, shared by [`Route`][speedplan.Route] and the VDA 5050 reader.

Each check takes the field names to put in its messages, so that a route built in Python
names ``nodes[2].sequence_id`` and an order names ``nodes[2].sequenceId``.
"""

from __future__ import annotations

from collections.abc import Sequence
from typing import Any

import numpy as np

from ..core.checks import FloatArray
from ..core.errors import InvalidInputError

__all__ = ["NODE_TOLERANCE", "boolean", "check_meets_node", "check_released", "check_sequence",
           "integer", "node_tolerance", "number", "positive", "string"]

#: Smallest distance [m] within which an edge's geometry must meet its nodes: the default when
#: a node gives no (or a zero) allowed deviation — "within the normal tolerance of the
#: vehicle", VDA 5050 2.x.
NODE_TOLERANCE = 0.01


# ---- typed fields: `where` names the field in the message ------------------------------------
def number(value: Any, where: str, *, minimum: float | None = None) -> float:
    """A finite number (not a bool), at least ``minimum`` if given."""
    if isinstance(value, bool | np.bool_) or not isinstance(value, int | float | np.number):
        raise InvalidInputError(f"`{where}` must be a number; got {value!r}")
    x = float(value)
    if not np.isfinite(x):
        raise InvalidInputError(f"`{where}` must be a finite number; got {value!r}")
    if minimum is not None and not x >= minimum:
        raise InvalidInputError(f"`{where}` must be >= {minimum}; got {value!r}")
    return x


def positive(value: Any, where: str) -> float:
    """A finite number > 0."""
    x = number(value, where)
    if not x > 0:
        raise InvalidInputError(f"`{where}` must be > 0; got {value!r}")
    return x


def integer(value: Any, where: str, minimum: int = 0) -> int:
    """An integer >= ``minimum``.

    Integral floats count: JSON Schema's rule, and VDA 5050 2.x even types ``degree`` as float64.
    """
    ok = not isinstance(value, bool | np.bool_) and isinstance(value, int | float | np.number)
    if not ok or not np.isfinite(value) or int(value) != value or value < minimum:
        raise InvalidInputError(f"`{where}` must be an integer >= {minimum}; got {value!r}")
    return int(value)


def string(value: Any, where: str) -> str:
    """A string."""
    if not isinstance(value, str):
        raise InvalidInputError(f"`{where}` must be a string; got {value!r}")
    return value


def boolean(value: Any, where: str) -> bool:
    """``True`` or ``False`` (no 0/1, no strings)."""
    if not isinstance(value, bool | np.bool_):
        raise InvalidInputError(f"`{where}` must be true or false; got {value!r}")
    return bool(value)


def node_tolerance(allowed_deviation_xy: float) -> float:
    """Distance [m] within which an edge must start / end at a node."""
    return max(allowed_deviation_xy, NODE_TOLERANCE)


def check_sequence(node_seq: Sequence[int], edge_seq: Sequence[int], key: str) -> None:
    """Sequence ids: nodes even, edges odd, strictly alternating node–edge–node from node 0.

    ``key`` is the field name used in the messages (``sequenceId`` or ``sequence_id``).
    """
    if len(edge_seq) != len(node_seq) - 1:
        raise InvalidInputError(
            f"`edges`: {len(node_seq)} nodes need {len(node_seq) - 1} edges (one between each "
            f"pair of consecutive nodes); got {len(edge_seq)}"
        )
    first = node_seq[0]
    if first % 2:
        raise InvalidInputError(
            f"`nodes[0].{key}` must be even (nodes take even, edges odd sequence ids); "
            f"got {first}"
        )
    for i, seq in enumerate(node_seq):
        if seq != first + 2 * i:
            raise InvalidInputError(
                f"`nodes[{i}].{key}` must be {first + 2 * i} (nodes and edges alternate "
                f"node–edge–node from `nodes[0].{key}` = {first}, in list order); got {seq}"
            )
    for i, seq in enumerate(edge_seq):
        if seq != first + 2 * i + 1:
            raise InvalidInputError(
                f"`edges[{i}].{key}` must be {first + 2 * i + 1} (the edge between "
                f"`nodes[{i}]` and `nodes[{i + 1}]`); got {seq}"
            )


def check_released(node_released: Sequence[bool], edge_released: Sequence[bool]) -> None:
    """The released base is a prefix ``node, edge, node, …`` that starts and ends with a node.

    After the first element of the horizon (``released`` false) nothing is released again, and
    an edge is released only together with its end node.
    """
    if not node_released[0]:
        raise InvalidInputError(
            "`nodes[0].released` must be true: the first node of an order is part of the base"
        )
    chain = [(f"nodes[{i // 2}]" if i % 2 == 0 else f"edges[{i // 2}]",
              node_released[i // 2] if i % 2 == 0 else edge_released[i // 2])
             for i in range(len(node_released) + len(edge_released))]
    horizon = next((i for i, (_, rel) in enumerate(chain) if not rel), len(chain))
    for name, rel in chain[horizon:]:
        if rel:
            raise InvalidInputError(
                f"`{name}.released` is true after `{chain[horizon][0]}`, which is in the "
                "horizon (released false); the base must be one unbroken start of the order"
            )
    if horizon % 2 == 0 and horizon < len(chain):
        raise InvalidInputError(
            f"`{chain[horizon - 1][0]}` is released but its end node `{chain[horizon][0]}` is "
            "not; release both or neither"
        )
    if not any(edge_released):
        raise InvalidInputError(
            "`edges`: no edge is released; the base holds only the first node, so there is "
            "nothing to drive yet"
        )


def check_meets_node(
    point: FloatArray,
    position: tuple[float, float],
    tolerance: float,
    what: str,
    node: str,
) -> None:
    """``point`` (an edge's start or end) must lie within ``tolerance`` [m] of ``position``.

    ``what`` says which end of which element (``"`edges[1].trajectory` starts"``), ``node``
    names the node (``"`nodes[1]` ('N1')"``).
    """
    gap = float(np.hypot(point[0] - position[0], point[1] - position[1]))
    if not gap <= tolerance:
        raise InvalidInputError(
            f"{what} at ({point[0]:.6g}, {point[1]:.6g}), {gap:.3g} m from {node} at "
            f"({position[0]:.6g}, {position[1]:.6g}); it must meet the node within "
            f"{tolerance:.3g} m (the node's allowed deviation, at least {NODE_TOLERANCE} m)"
        )
