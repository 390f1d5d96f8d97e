"""plan_many(): plan a batch of paths through any ``concurrent.futures.Executor``."""

from __future__ import annotations

import os
import sys
import threading
import warnings
from collections.abc import Callable, Iterable, Iterator, Mapping
from concurrent.futures import BrokenExecutor, Executor, Future, ProcessPoolExecutor, as_completed
from concurrent.futures.process import BrokenProcessPool
from contextlib import contextmanager
from dataclasses import dataclass
from typing import TYPE_CHECKING, Any, NamedTuple, TypeAlias

from .core.checks import as_scalar, shown
from .core.errors import InvalidInputError, SpeedplanError
from .core.log import logger
from .model import PlanRequest
from .plan import plan_request
from .timing import SpeedProfile

if TYPE_CHECKING:
    from .core.limits import Limits
    from .geometry import Path

__all__ = ["BatchResult", "Job", "JobWarning", "PlanJob", "plan_many"]


@dataclass(frozen=True)
class PlanJob:
    """One job of [`plan_many`][speedplan.plan_many], validated: what to plan, and for how long.

    Attributes
    ----------
    request : PlanRequest
        The validated arguments of [`speedplan.plan`][speedplan.plan].
    time_limit : float or None
        Seconds the job may take once it runs; ``None``: the batch's ``time_limit``.

    Examples
    --------
    >>> from concurrent.futures import ThreadPoolExecutor
    >>> from speedplan import Limits, Path, plan_many
    >>> from speedplan.batch import PlanJob
    >>> from speedplan.model import PlanRequest
    >>> req = PlanRequest.create(Path.from_waypoints([[0, 0], [5, 0]], kind="polyline"),
    ...                          Limits(v_max=2, a_max=1, a_lat_max=1, j_max=0.5))
    >>> with ThreadPoolExecutor(1) as ex:
    ...     results = plan_many([PlanJob(req, time_limit=30.0)], ex)
    >>> [r.ok for r in results]
    [True]
    """

    request: PlanRequest
    time_limit: float | None = None

    def __post_init__(self) -> None:
        if not isinstance(self.request, PlanRequest):
            raise InvalidInputError(
                f"`request` must be a PlanRequest (PlanRequest.create); got "
                f"{type(self.request).__name__}")
        if self.time_limit is not None:
            object.__setattr__(self, "time_limit",
                               as_scalar("time_limit", self.time_limit, positive=True))


#: A job as [`plan_many`][speedplan.plan_many] takes it: a dict ``{"path": ..., "limits": ...,
#: **plan_kwargs}``, a tuple ``(path, limits[, plan_kwargs])``, a `PlanRequest` or a `PlanJob`.
Job: TypeAlias = ("Mapping[str, object] | tuple[Path, Limits] "
                  "| tuple[Path, Limits, Mapping[str, object]] | PlanRequest | PlanJob")


@dataclass(frozen=True)
class BatchResult:
    """Outcome of one job: ``profile`` on success, else ``error`` (the exception raised).

    Attributes
    ----------
    index : int
        Position of the job in ``jobs``.
    profile : SpeedProfile or None
        The plan, when the job succeeded.
    error : BaseException or None
        The exception the job raised.
    warnings : tuple of JobWarning
        The warnings issued while the job ran (e.g. ``("LimitWarning", "...")``), captured
        in the worker, where they would otherwise go to the worker's stderr or nowhere.
        Empty for jobs refused before they were sent and for jobs that failed with an
        exception that is not a [`SpeedplanError`][speedplan.SpeedplanError] (a bug: its traceback
        is kept instead).
    """

    index: int
    profile: SpeedProfile | None
    error: BaseException | None
    warnings: tuple[JobWarning, ...] = ()

    @property
    def ok(self) -> bool:
        """Whether the job produced a profile."""
        return self.error is None


class JobWarning(NamedTuple):
    """A warning issued while a job ran: the name of its category and its message."""

    category: str
    message: str


class _Outcome(NamedTuple):
    profile: SpeedProfile | None
    error: SpeedplanError | None
    warnings: tuple[JobWarning, ...]


# ---- warnings of a job --------------------------------------------------------------------
# Before Python 3.14 the warnings filters and ``showwarning`` are process-wide, and
# ``catch_warnings`` saves and restores them: two threads using it at once (a thread pool, a
# dask worker's threads) may leave the process with a dead recorder in place of
# ``showwarning``. So one capture is installed while any job of this process runs, and
# routes each warning to the list of the thread that issued it.
_lock = threading.Lock()
_active = 0
_context: Any = None
_show_before: Callable[..., None] | None = None
_local = threading.local()


def _route(message: Warning | str, category: type[Warning], filename: str, lineno: int,
           file: Any = None, line: str | None = None) -> None:
    sink = getattr(_local, "sink", None)
    if sink is not None:
        sink.append(JobWarning(category.__name__, str(message)))
    elif _show_before is not None:  # another thread's warning: shown as it would have been
        _show_before(message, category, filename, lineno, file, line)


@contextmanager
def _captured_warnings() -> Iterator[list[JobWarning]]:
    """Record every warning this thread issues inside the block (filter ``"always"``)."""
    global _active, _context, _show_before
    records: list[JobWarning] = []
    if getattr(sys.flags, "context_aware_warnings", False):  # Python >= 3.14: per context
        with warnings.catch_warnings(record=True) as caught:
            warnings.simplefilter("always")
            yield records
        records.extend(JobWarning(w.category.__name__, str(w.message)) for w in caught)
        return
    with _lock:
        if _active == 0:
            _context = warnings.catch_warnings()
            _context.__enter__()
            warnings.simplefilter("always")  # a repeated warning is still this job's warning
            _show_before = warnings.showwarning
            warnings.showwarning = _route
        _active += 1
    outer = getattr(_local, "sink", None)
    _local.sink = records
    try:
        yield records
    finally:
        _local.sink = outer
        with _lock:
            _active -= 1
            if _active == 0:
                _context.__exit__(None, None, None)  # restores filters and showwarning
                _context = _show_before = None


def _run_job(job: PlanJob) -> _Outcome:
    """The worker: ``plan_request(job.request)`` with the warnings it issues."""
    with _captured_warnings() as caught:
        try:
            profile = plan_request(job.request, time_limit=job.time_limit)
        except SpeedplanError as exc:
            return _Outcome(None, exc, tuple(caught))
    return _Outcome(profile, None, tuple(caught))


# ---- the batch ------------------------------------------------------------------------------
def _normalise(job: object, index: int) -> dict[str, Any] | PlanJob:
    """A user's job as the keywords of `PlanRequest.create` (or the typed job it already is)."""
    if isinstance(job, PlanJob):
        return job
    if isinstance(job, PlanRequest):
        return PlanJob(job)
    if isinstance(job, Mapping):
        kwargs = dict(job)
    elif isinstance(job, tuple) and len(job) in (2, 3):
        kwargs = {"path": job[0], "limits": job[1], **(job[2] if len(job) == 3 else {})}
    else:
        raise InvalidInputError(
            f"`jobs[{index}]` must be a dict with 'path' and 'limits' (plus plan() keywords), a "
            f"tuple (path, limits[, kwargs]), a PlanRequest or a PlanJob; got "
            f"{type(job).__name__}"
        )
    if "path" not in kwargs or "limits" not in kwargs:
        raise InvalidInputError(f"`jobs[{index}]` needs both 'path' and 'limits'")
    return kwargs


def _job_list(jobs: Any) -> list[Any]:
    if isinstance(jobs, Mapping):
        raise InvalidInputError(
            "`jobs` must be an iterable of jobs; got a single dict: wrap it in a list, "
            "plan_many([job])"
        )
    if isinstance(jobs, str | bytes):
        raise InvalidInputError(f"`jobs` must be an iterable of jobs; got {shown(jobs)}")
    try:
        return list(jobs)
    except TypeError as exc:
        raise InvalidInputError(
            "`jobs` must be an iterable (list, generator) of dicts {'path': ..., 'limits': ..., "
            "**plan_kwargs} or tuples (path, limits[, kwargs]); got "
            f"{type(jobs).__name__}"
        ) from exc


def _typed_job(job: dict[str, Any] | PlanJob, time_limit: float | None) -> PlanJob:
    """The validated job; its time limit is its own ``time_limit``, else the batch's."""
    if isinstance(job, PlanJob):
        return job if job.time_limit is not None else PlanJob(job.request, time_limit)
    kw = dict(job)
    limit = kw.pop("time_limit", time_limit)
    return PlanJob(PlanRequest.create(kw.pop("path"), kw.pop("limits"), **kw), limit)


def _print_progress(done: int, total: int) -> None:
    print(f"\rplanned {done}/{total}", end="" if done < total else "\n", file=sys.stderr,
          flush=True)


def _common_failure(results: list[BatchResult], shipped: Iterable[int]) -> BaseException | None:
    """The error every shipped job failed with, if they all failed the same non-speedplan way.

    That is the executor failing (a pickling error, a process pool broken because workers
    cannot import the main module), not the jobs.
    """
    errors = [results[i].error for i in shipped]
    if not errors or any(e is None or isinstance(e, SpeedplanError) for e in errors):
        return None
    first = errors[0]
    same = all(type(e) is type(first) and str(e) == str(first) for e in errors)
    return first if same else None


def plan_many(
    jobs: Iterable[Job],
    executor: Executor | None = None,
    *,
    progress: bool | Callable[[int, int], None] = False,
    time_limit: float | None = None,
) -> list[BatchResult]:
    """Plan many paths in parallel; results come back in job order.

    Parameters
    ----------
    jobs : iterable
        Each a dict ``{"path": ..., "limits": ..., **plan_kwargs}``, a tuple
        ``(path, limits[, plan_kwargs])``, a validated `PlanRequest`, or a `PlanJob`
        (a request and its own time limit; `speedplan.route_plan.route_jobs` makes them).
    executor : concurrent.futures.Executor, optional
        Where to run: default a local ``ProcessPoolExecutor`` (one worker per core). A
        dask.distributed ``Client.get_executor()`` or a Ray executor work unchanged.
    progress : bool or callable
        ``True`` prints ``planned k/N`` to stderr; a callable receives ``(done, total)``.
    time_limit : float, optional
        Seconds each job may take once it runs (`speedplan.plan`'s ``time_limit``); a
        job's own ``time_limit`` keyword takes precedence. A job that runs out of it fails
        with [`PlanTimeout`][speedplan.PlanTimeout].

    Returns
    -------
    list of BatchResult
        One per job, in order; a failed job carries its exception and the others still run.
        Each result carries the warnings its job issued (``BatchResult.warnings``).

    Raises
    ------
    InvalidInputError
        ``jobs`` is not an iterable of jobs, or ``executor`` is not an executor.
    SpeedplanError
        Every job sent to the executor failed with the same error that is not a speedplan
        error: the executor could not run them (see Notes). The error is chained.

    Notes
    -----
    A process pool breaks when one of its workers dies (killed, or out of memory): every
    job it held or had queued then fails with ``BrokenProcessPool``. Those jobs are run once
    more on a fresh process pool (as many workers, the same start method); only the jobs
    that fail again are reported as failed, with the error of that second run. A pool that
    breaks before any job finished is not retried: it cannot run jobs at all (see below).

    Process pools under the ``spawn`` or ``forkserver`` start method (the default on macOS
    and Windows, and on Linux from Python 3.14) import the main module in every worker. A
    script must therefore call ``plan_many`` under ``if __name__ == "__main__":``; without
    it the workers fail to start and ``plan_many`` raises instead of returning a list of
    failures.

    With a thread-based executor, a warning issued by another thread of the program while
    jobs run is shown even if a filter would normally hide a repeat of it.

    Examples
    --------
    >>> from concurrent.futures import ThreadPoolExecutor
    >>> from speedplan import Limits, Path, plan_many
    >>> lim = Limits(v_max=2, a_max=1, a_lat_max=1, j_max=0.5)
    >>> jobs = [(Path.from_waypoints([[0, 0], [L, 0]], kind="polyline"), lim) for L in (5, 10)]
    >>> with ThreadPoolExecutor(2) as ex:
    ...     results = plan_many(jobs, ex, time_limit=30.0)
    >>> [r.ok for r in results], results[0].warnings
    ([True, True], ())
    """
    normalised = [_normalise(job, i) for i, job in enumerate(_job_list(jobs))]
    if executor is not None and not callable(getattr(executor, "submit", None)):
        raise InvalidInputError(
            "`executor` must be a concurrent.futures.Executor (something with submit()); got "
            f"{type(executor).__name__}"
        )
    if time_limit is not None:
        time_limit = as_scalar("time_limit", time_limit, positive=True)
    total = len(normalised)
    report = _print_progress if progress is True else (progress or None)
    results: list[BatchResult | None] = [None] * total
    # Check every job here, before shipping any: a bad argument costs no worker round trip.
    requests: dict[int, PlanJob] = {}
    for i, job in enumerate(normalised):
        try:
            requests[i] = _typed_job(job, time_limit)
        except (InvalidInputError, TypeError) as exc:
            logger.debug("plan_many: job %d refused before sending: %s", i, exc)
            results[i] = BatchResult(i, None, exc)
    done = total - len(requests)
    if report is not None and done:
        report(done, total)
    # A fresh pool after a worker died is built like the one that broke.
    workers = getattr(executor, "_max_workers", None)
    context = getattr(executor, "_mp_context", None)
    own = executor is None and bool(requests)
    ex = executor if executor is not None else (
        ProcessPoolExecutor(max_workers=os.cpu_count()) if requests else None)
    def tick() -> None:
        if report is not None:
            report(sum(r is not None for r in results), total)

    lost: list[int] = []  # jobs of a process pool that broke under them
    try:
        if ex is not None:
            lost = _run_batch(ex, requests, results, tick,
                              final=not isinstance(ex, ProcessPoolExecutor))
    finally:
        if own and ex is not None:
            ex.shutdown()
    if lost and len(lost) == len(requests):  # no job ran: the pool itself cannot work
        for i in lost:
            results[i] = BatchResult(i, None, BrokenProcessPool(
                "the process pool broke before any job finished"))
        tick()
    elif lost:
        logger.debug("plan_many: a worker died; %d jobs run again on a fresh pool", len(lost))
        with ProcessPoolExecutor(max_workers=workers or os.cpu_count(),
                                 mp_context=context) as fresh:
            _run_batch(fresh, {i: requests[i] for i in lost}, results, tick, final=True)
    out = [r for r in results if r is not None]
    common = _common_failure(out, requests)
    if common is not None:
        raise SpeedplanError(
            f"plan_many: all {len(requests)} jobs sent to the executor failed with the same "
            f"error, {type(common).__name__}: {str(common).rstrip('.')}. The executor could "
            "not run them. With "
            "a process pool under the 'spawn' or 'forkserver' start method (macOS, Windows), "
            'call plan_many under `if __name__ == "__main__":` in your script; also check that '
            "the jobs can be pickled"
        ) from common
    return out


def _run_batch(ex: Executor, requests: dict[int, PlanJob],
               results: list[BatchResult | None], tick: Callable[[], None], *, final: bool
               ) -> list[int]:
    """Run ``requests`` on ``ex`` into ``results``; the jobs lost to a broken executor.

    Unless ``final``, a lost job gets no result here (it is to be run again); otherwise its
    result is the ``BrokenExecutor`` error.
    """
    futures: dict[Future[_Outcome], int] = {
        ex.submit(_run_job, job): i for i, job in requests.items()}
    lost = []
    for fut in as_completed(futures):
        i = futures[fut]
        try:
            outcome = fut.result()
            result = BatchResult(i, outcome.profile, outcome.error, outcome.warnings)
        except BrokenExecutor as exc:  # the pool died under the job, not the job itself
            if not final:
                lost.append(i)
                continue
            result = BatchResult(i, None, exc)
        except Exception as exc:  # one job's failure must not lose the others
            result = BatchResult(i, None, exc)
        if result.error is not None:
            logger.debug("plan_many: job %d failed: %r", i, result.error)
        results[i] = result
        tick()
    return sorted(lost)
