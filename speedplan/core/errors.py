"""Exceptions raised by speedplan.

Every error a user can meet derives from [`SpeedplanError`][speedplan.SpeedplanError], so one
``except SpeedplanError`` catches them all.
"""

from __future__ import annotations

__all__ = [
    "InfeasibleError",
    "InvalidInputError",
    "LimitWarning",
    "SolverError",
    "SpeedplanError",
    "SpeedplanWarning",
]


class SpeedplanError(Exception):
    """Base class of all speedplan errors."""


class InvalidInputError(SpeedplanError, ValueError):
    """An argument is malformed: wrong shape, NaN/inf, out of range or unknown option.

    The message names the argument, the offending value and what to do.
    """


class InfeasibleError(SpeedplanError):
    """The request is well formed but no speed law satisfies all constraints.

    Attributes
    ----------
    constraint : str
        The constraint that makes the request impossible (e.g. ``"decel"``, ``"w_start"``).
    s : float or None
        Position along the path [m] (grid position for `solve_discrete`) where it bites.
    """

    def __init__(self, message: str, *, constraint: str = "", s: float | None = None) -> None:
        super().__init__(message)
        self.constraint = constraint
        self.s = s


class SolverError(SpeedplanError):
    """A numerical backend ran and failed; ``status`` carries the backend's own status."""

    def __init__(self, message: str, *, backend: str = "", status: str = "") -> None:
        super().__init__(message)
        self.backend = backend
        self.status = status


class SpeedplanWarning(UserWarning):
    """A result was produced but something about it deserves attention (see the message)."""


class LimitWarning(SpeedplanWarning):
    """A planned trajectory exceeds a limit by more than its documented tolerance."""
