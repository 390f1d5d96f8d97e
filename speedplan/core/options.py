"""The closed sets of option strings, and the shapes of loosely typed user input.

Each option is a `typing.Literal` of plain strings, so that ``refine="never"`` type-checks
and needs no import; the tuple of its valid values is derived from it with
`typing.get_args`, once, and `check_option` refuses anything else with a message that names
the argument and lists every valid value.

Examples
--------
>>> from speedplan.core.options import REFINE_MODES, check_option
>>> REFINE_MODES
('auto', 'always', 'never')
>>> from speedplan import InvalidInputError
>>> try:
...     check_option("refine", "sometimes", REFINE_MODES)
... except InvalidInputError as exc:
...     print(exc)
`refine` must be one of 'auto', 'always', 'never'; got 'sometimes'
"""

from __future__ import annotations

from collections.abc import Mapping
from typing import Literal, TypeAlias, TypeVar, get_args

from numpy.typing import ArrayLike

from .checks import choice

__all__ = [
    "BACKENDS", "FILE_FORMATS", "GRIP_MODELS", "PATH_KINDS", "REACH_MODES", "REFINE_MODES",
    "RELAXATION_BACKEND_NAMES", "REST_REASONS", "STANDSTILL_MODES", "Backend", "FileFormat",
    "Grip", "JsonObject", "JsonValue", "PathKind", "Reach", "Refine", "RelaxationBackend",
    "RestReason", "Standstill", "VLimit", "check_option",
]

Refine: TypeAlias = Literal["auto", "always", "never"]
"""When the IPOPT refinement runs: ``"auto"``, when the relaxation is not exact;
``"always"``; ``"never"`` (a non-exact result then has status ``"relaxed"``)."""
RelaxationBackend: TypeAlias = Literal["clarabel", "banded"]
"""A relaxation solver by name: Clarabel (the reference) or the banded interior-point
method (``solve.discrete.RELAXATION_BACKENDS`` maps each name to its solver)."""
Backend: TypeAlias = Literal["auto", "clarabel", "banded"]
"""A relaxation backend, or ``"auto"``: banded from 100 nodes on once its kernel is
compiled, else Clarabel."""
Standstill: TypeAlias = Literal["smooth", "free"]
"""``"smooth"``: acceleration 0 at a standstill, jerk-limited from the first instant;
``"free"``: the paper's model, where the acceleration may jump at a standstill."""
Reach: TypeAlias = Literal["max_jerk", "distance"]
"""The upper envelope capping ``w`` next to a moving boundary state: ``"max_jerk"``, the
fastest motion in time (``+j_max`` at once), tight and keeping the relaxation exact, but
below the speed of some feasible motions where the speed first dips; ``"distance"``, the
exact largest ``w`` at each distance, whose kinks can leave the relaxation inexact.
`speedplan.plan` uses the first and falls back to the second when the first refuses the
boundary states."""
Grip: TypeAlias = Literal["independent", "ellipse"]
"""How the tangential and the lateral acceleration share the grip: each within its own
limit (``"independent"``), or within one friction ellipse (``"ellipse"``)."""
PathKind: TypeAlias = Literal["g2", "clothoid", "spline", "polyline"]
"""How `speedplan.Path.from_waypoints` joins waypoints: straight legs with G2 corners, a G1
clothoid chain, a cubic spline, or a polyline."""
FileFormat: TypeAlias = Literal["csv", "json"]
"""The text format of a path, zones or trajectory file."""
RestReason: TypeAlias = Literal["cusp", "stop", "curvature jump"]
"""Why a model stops the vehicle inside a path: a cusp (it reverses), a stop asked for
(``stops=``), or a curvature jump under a lateral-jerk limit."""

REFINE_MODES: tuple[Refine, ...] = get_args(Refine)
RELAXATION_BACKEND_NAMES: tuple[RelaxationBackend, ...] = get_args(RelaxationBackend)
BACKENDS: tuple[Backend, ...] = get_args(Backend)
STANDSTILL_MODES: tuple[Standstill, ...] = get_args(Standstill)
REACH_MODES: tuple[Reach, ...] = get_args(Reach)
GRIP_MODELS: tuple[Grip, ...] = get_args(Grip)
PATH_KINDS: tuple[PathKind, ...] = get_args(PathKind)
FILE_FORMATS: tuple[FileFormat, ...] = get_args(FileFormat)
REST_REASONS: tuple[RestReason, ...] = get_args(RestReason)

JsonValue: TypeAlias = "str | int | float | bool | list[JsonValue] | dict[str, JsonValue] | None"
"""A value of a parsed JSON document (`json.loads`)."""
JsonObject: TypeAlias = Mapping[str, "JsonValue"]
"""A parsed JSON object: a VDA 5050 order, a path or zones document."""
VLimit: TypeAlias = tuple[ArrayLike, ArrayLike]
"""A per-position speed limit: knots ``(s [m], v [m/s])``, linear in between."""

_O = TypeVar("_O", bound=str)


def check_option(name: str, value: object, options: tuple[_O, ...]) -> _O:
    """``value`` if it is one of ``options``; else `InvalidInputError` listing them all.

    Parameters
    ----------
    name : str
        The argument's name, as the message quotes it.
    value : object
        What the caller passed.
    options : tuple of str
        The valid values (one of this module's tuples).

    Examples
    --------
    >>> check_option("standstill", "free", STANDSTILL_MODES)
    'free'
    """
    choice(name, value, options)
    return next(o for o in options if o == value)
