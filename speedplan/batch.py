"""plan_many(): plan a batch of paths through any ``concurrent.futures.Executor``."""

from __future__ import annotations

import os
import sys
from collections.abc import Callable, Iterable, Mapping
from concurrent.futures import Executor, ProcessPoolExecutor, as_completed
from dataclasses import dataclass
from typing import Any

from .core.errors import InvalidInputError
from .model import PlanRequest
from .plan import plan_request
from .timing import SpeedProfile

__all__ = ["BatchResult", "plan_many"]


@dataclass(frozen=True)
class BatchResult:
    """Outcome of one job: ``profile`` on success, else ``error`` (the exception raised)."""

    index: int
    profile: SpeedProfile | None
    error: BaseException | None

    @property
    def ok(self) -> bool:
        """Whether the job produced a profile."""
        return self.error is None


def _normalise(job: Any, index: int) -> dict[str, Any]:
    if isinstance(job, Mapping):
        kwargs = dict(job)
    elif isinstance(job, tuple) and len(job) in (2, 3):
        kwargs = {"path": job[0], "limits": job[1], **(job[2] if len(job) == 3 else {})}
    else:
        raise InvalidInputError(
            f"`jobs[{index}]` must be a dict with 'path' and 'limits' (plus plan() keywords) or a "
            f"tuple (path, limits[, kwargs]); got {type(job).__name__}"
        )
    if "path" not in kwargs or "limits" not in kwargs:
        raise InvalidInputError(f"`jobs[{index}]` needs both 'path' and 'limits'")
    return kwargs


def _request(kwargs: dict[str, Any]) -> PlanRequest:
    kw = dict(kwargs)
    return PlanRequest.create(kw.pop("path"), kw.pop("limits"), **kw)


def _print_progress(done: int, total: int) -> None:
    print(f"\rplanned {done}/{total}", end="" if done < total else "\n", file=sys.stderr,
          flush=True)


def plan_many(
    jobs: Iterable[Any],
    executor: Executor | None = None,
    *,
    progress: bool | Callable[[int, int], None] = False,
) -> list[BatchResult]:
    """Plan many paths in parallel; results come back in job order.

    Parameters
    ----------
    jobs : iterable
        Each a dict ``{"path": ..., "limits": ..., **plan_kwargs}`` or a tuple
        ``(path, limits[, plan_kwargs])``.
    executor : concurrent.futures.Executor, optional
        Where to run: default a local ``ProcessPoolExecutor`` (one worker per core). A
        dask.distributed ``Client.get_executor()`` or a Ray executor work unchanged.
    progress : bool or callable
        ``True`` prints ``planned k/N`` to stderr; a callable receives ``(done, total)``.

    Returns
    -------
    list of BatchResult
        One per job, in order; a failed job carries its exception and the others still run.

    Examples
    --------
    >>> from concurrent.futures import ThreadPoolExecutor
    >>> from speedplan import Limits, Path, plan_many
    >>> lim = Limits(v_max=2, a_max=1, a_lat_max=1, j_max=0.5)
    >>> jobs = [(Path.from_waypoints([[0, 0], [L, 0]], kind="polyline"), lim) for L in (5, 10)]
    >>> with ThreadPoolExecutor(2) as ex:
    ...     results = plan_many(jobs, ex)
    >>> [r.ok for r in results]
    [True, True]
    """
    normalised = [_normalise(job, i) for i, job in enumerate(jobs)]
    total = len(normalised)
    report = _print_progress if progress is True else (progress or None)
    results: list[BatchResult | None] = [None] * total
    # Check every job here, before shipping any: a bad argument costs no worker round trip.
    requests: dict[int, PlanRequest] = {}
    for i, kwargs in enumerate(normalised):
        try:
            requests[i] = _request(kwargs)
        except (InvalidInputError, TypeError) as exc:
            results[i] = BatchResult(i, None, exc)
    done = total - len(requests)
    if report is not None and done:
        report(done, total)
    own = executor is None and bool(requests)
    ex = executor if executor is not None else (
        ProcessPoolExecutor(max_workers=os.cpu_count()) if requests else None)
    try:
        if ex is not None:
            futures = {ex.submit(plan_request, req): i for i, req in requests.items()}
            for fut in as_completed(futures):
                i = futures[fut]
                try:
                    results[i] = BatchResult(i, fut.result(), None)
                except Exception as exc:  # one job's failure must not lose the others
                    results[i] = BatchResult(i, None, exc)
                done += 1
                if report is not None:
                    report(done, total)
    finally:
        if own and ex is not None:
            ex.shutdown()
    return [r for r in results if r is not None]
