"""The record of a planning strategy: which attempt answered, and why the others did not."""

from __future__ import annotations

from dataclasses import dataclass
from typing import Literal

__all__ = ["ATTEMPT_OUTCOMES", "Attempt", "AttemptOutcome", "describe_attempts"]

#: ``Attempt.outcome``: ``"answered"`` (its result is in the plan), ``"failed"`` (it raised or
#: was refused; ``reason`` says why), ``"replaced"`` (it produced a result that a later attempt
#: replaced; ``reason`` says why), ``"skipped"`` (the time budget ran out before it).
AttemptOutcome = Literal["answered", "failed", "replaced", "skipped"]
ATTEMPT_OUTCOMES: tuple[AttemptOutcome, ...] = ("answered", "failed", "replaced", "skipped")


@dataclass(frozen=True)
class Attempt:
    """One attempt of the planning strategy (`speedplan.strategy`).

    Attributes
    ----------
    name : str
        The attempt's name, one of `speedplan.strategy.ATTEMPTS`.
    leg : int or None
        The leg it planned (``None``: the whole request, e.g. its model).
    outcome : str
        One of `ATTEMPT_OUTCOMES`.
    reason : str
        Why it failed or was replaced (empty when it answered).
    seconds : float
        Wall-clock time it took [s].

    Examples
    --------
    >>> Attempt("default_grid", 0, "answered", "", 0.012).label
    'leg 0: default_grid'
    """

    name: str
    leg: int | None
    outcome: AttemptOutcome
    reason: str
    seconds: float

    @property
    def label(self) -> str:
        """``"leg i: name"``, or the name for an attempt on the whole request."""
        return self.name if self.leg is None else f"leg {self.leg}: {self.name}"

    def __str__(self) -> str:
        why = f" ({self.reason})" if self.reason else ""
        return f"{self.label} {self.outcome} in {self.seconds:.3g} s{why}"


def describe_attempts(attempts: tuple[Attempt, ...] | list[Attempt], limit: int = 12) -> str:
    """The attempts, one clause each, for an error message (at most ``limit``, then a count).

    Examples
    --------
    >>> describe_attempts([Attempt("model", None, "answered", "", 0.001),
    ...                    Attempt("default_grid", 0, "skipped", "", 0.0)])
    'model answered in 0.001 s; leg 0: default_grid skipped in 0 s'
    """
    shown = [str(a) for a in attempts[:limit]]
    if len(attempts) > limit:
        shown.append(f"... {len(attempts) - limit} more")
    return "; ".join(shown) if shown else "nothing"
