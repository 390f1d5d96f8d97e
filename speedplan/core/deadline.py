"""The wall-clock deadline of the plan being computed, for solvers that can stop at one.

[`speedplan.plan`][speedplan.plan] with ``time_limit`` runs each attempt of its strategy under
`deadline`; a backend with a time limit of its own (Clarabel's ``time_limit``,
IPOPT's ``max_wall_time``) reads `remaining` and stops there instead of running on
past the caller's limit. A context variable, so that threads planning at once (a thread
pool in [`speedplan.plan_many`][speedplan.plan_many]) each keep their own.
"""

from __future__ import annotations

import time
from collections.abc import Iterator
from contextlib import contextmanager
from contextvars import ContextVar

__all__ = ["MIN_SOLVER_TIME", "deadline", "passed", "remaining"]

#: Shortest time limit handed to a backend [s]: below, it would stop before its first
#: iteration and report a failure that says nothing about the problem.
MIN_SOLVER_TIME = 1e-3

_DEADLINE: ContextVar[float | None] = ContextVar("speedplan_deadline", default=None)


@contextmanager
def deadline(at: float | None) -> Iterator[None]:
    """Run the block with the deadline ``at`` (a ``time.perf_counter()`` value; ``None``: none).

    Examples
    --------
    >>> import time
    >>> with deadline(time.perf_counter() + 10.0):
    ...     bool(5.0 < remaining() <= 10.0)
    True
    >>> remaining() is None
    True
    """
    token = _DEADLINE.set(at)
    try:
        yield
    finally:
        _DEADLINE.reset(token)


def remaining() -> float | None:
    """Seconds left before the current deadline (at least `MIN_SOLVER_TIME`), or ``None``."""
    at = _DEADLINE.get()
    if at is None:
        return None
    return max(at - time.perf_counter(), MIN_SOLVER_TIME)


def passed() -> bool:
    """Whether the current deadline (if any) has passed.

    Examples
    --------
    >>> import time
    >>> with deadline(time.perf_counter() - 1.0):
    ...     passed()
    True
    >>> passed()
    False
    """
    at = _DEADLINE.get()
    return at is not None and time.perf_counter() >= at
