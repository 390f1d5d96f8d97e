"""Exceptions raised by speedplan.

Every error a user can meet derives from [`SpeedplanError`][speedplan.SpeedplanError], so one
``except SpeedplanError`` catches them all.
"""

from __future__ import annotations

from typing import TYPE_CHECKING

if TYPE_CHECKING:
    from .attempts import Attempt

__all__ = [
    "InfeasibleError",
    "InvalidInputError",
    "LimitWarning",
    "PlanTimeout",
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


class PlanTimeout(SpeedplanError):
    """No verified plan was found within ``plan(..., time_limit=...)``.

    Raised instead of returning a profile whose continuous trajectory has not passed its
    check: the message names every attempt of the strategy that ran and why each did not
    answer (`speedplan.strategy`).

    Attributes
    ----------
    time_limit : float
        The limit that ran out [s].
    attempts : tuple of Attempt
        The attempts made, in order ([`Attempt`][speedplan.core.attempts.Attempt]).
    """

    def __init__(self, message: str, *, time_limit: float, attempts: tuple[Attempt, ...] = ()
                 ) -> None:
        super().__init__(message)
        self.time_limit = time_limit
        self.attempts = attempts

    def __reduce__(self) -> tuple[object, ...]:  # picklable for plan_many's workers
        return (_plan_timeout, (str(self), self.time_limit, self.attempts))


def _plan_timeout(message: str, time_limit: float, attempts: tuple[Attempt, ...]) -> PlanTimeout:
    return PlanTimeout(message, time_limit=time_limit, attempts=attempts)


class SpeedplanWarning(UserWarning):
    """A result was produced but something about it deserves attention (see the message)."""


class LimitWarning(SpeedplanWarning):
    """A planned trajectory exceeds a limit by more than its documented tolerance."""
