"""plan_many: argument checks, results and warnings per job, loud executor failures, spawn,
process pools and a dask cluster."""

from __future__ import annotations

import subprocess
import sys
import textwrap
import threading
import warnings
from concurrent.futures import Future, ThreadPoolExecutor
from dataclasses import replace

import numpy as np
import pytest
from shared import LGV

import speedplan as sp
import speedplan.batch as batch
from speedplan.geometry import Line


@pytest.mark.parametrize("jobs", [5, None, 2.5])
def test_jobs_that_are_not_iterable_are_named(jobs):
    with pytest.raises(sp.InvalidInputError, match="`jobs`"):
        sp.plan_many(jobs)


def test_a_single_job_dict_is_refused_with_a_hint():
    with pytest.raises(sp.InvalidInputError, match="wrap it in a list"):
        sp.plan_many({"path": sp.Path.from_segments([Line(3.0)]), "limits": LGV})


def test_executor_must_be_an_executor():
    with pytest.raises(sp.InvalidInputError, match="`executor`"):
        sp.plan_many([(sp.Path.from_segments([Line(3.0)]), LGV)], executor="local")


def _warning_job():
    # A G1 corner (arc onto a line) with a lateral-jerk limit: plan() warns that the vehicle
    # stops at the curvature jump (SpeedplanWarning), on any grid.
    path = sp.Path.from_waypoints([[0, 0], [10, 0], [10, 10]], kind="polyline")
    return {"path": path, "limits": replace(LGV, j_lat_max=1.0), "n": 200}


def _warnings_in_process(job):
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        sp.plan(**job)
    return [(w.category.__name__, str(w.message)) for w in caught]


def test_warnings_of_each_job_come_back_with_its_result():
    expected = _warnings_in_process(_warning_job())  # oracle: the same job in this thread
    assert expected, "the job must warn for this test to mean anything"
    clean = {"path": sp.Path.from_segments([Line(10.0)]), "limits": LGV}
    jobs = [_warning_job(), clean, _warning_job()]
    with ThreadPoolExecutor(3) as pool:
        results = sp.plan_many(jobs, pool)
    assert [list(r.warnings) for r in results] == [expected, [], expected]
    assert all(isinstance(w, sp.batch.JobWarning) for w in results[0].warnings)
    local = sp.plan_many(jobs)  # the default process pool: the warnings cross processes
    assert [list(r.warnings) for r in local] == [expected, [], expected]


def test_thread_pool_capture_leaves_the_warnings_machinery_as_it_was():
    show, filters = warnings.showwarning, list(warnings.filters)
    with ThreadPoolExecutor(4) as pool:
        sp.plan_many([_warning_job() for _ in range(8)], pool)
    assert warnings.showwarning is show
    assert warnings.filters == filters


def test_concurrent_captures_route_each_warning_to_its_own_thread():
    barrier = threading.Barrier(4)
    got = {}

    def worker(k):
        with batch._captured_warnings() as caught:
            barrier.wait()
            for i in range(50):
                warnings.warn(f"job {k} warning {i}", UserWarning, stacklevel=1)
            barrier.wait()
        got[k] = [w.message for w in caught]

    threads = [threading.Thread(target=worker, args=(k,)) for k in range(4)]
    for t in threads:
        t.start()
    for t in threads:
        t.join()
    for k in range(4):
        assert got[k] == [f"job {k} warning {i}" for i in range(50)]


class _BrokenExecutor:
    """Every future fails the way a process pool does when its workers cannot start."""

    def submit(self, fn, *args):
        fut = Future()
        fut.set_exception(RuntimeError("worker could not import the main module"))
        return fut


def test_every_job_failing_the_same_way_raises():
    jobs = [(sp.Path.from_segments([Line(L)]), LGV) for L in (3.0, 4.0)]
    with pytest.raises(sp.SpeedplanError, match="__name__") as info:
        sp.plan_many(jobs, _BrokenExecutor())
    assert isinstance(info.value.__cause__, RuntimeError)


def test_per_job_speedplan_errors_still_come_back_as_results():
    bad = {"path": sp.Path.from_segments([Line(1.0)]), "limits": LGV, "vf": 1.99}
    with ThreadPoolExecutor(2) as pool:
        results = sp.plan_many([bad, bad], pool)
    assert not any(r.ok for r in results)
    assert all(isinstance(r.error, sp.InfeasibleError) for r in results)  # raised in the worker


SCRIPT = """
import multiprocessing
from concurrent.futures import ProcessPoolExecutor
import speedplan as sp
from speedplan.geometry import Line

def main():
    lim = sp.Limits(v_max=2, a_max=1, a_lat_max=1, j_max=0.5)
    jobs = [(sp.Path.from_segments([Line(L)]), lim) for L in (4.0, 6.0)]
    with ProcessPoolExecutor(2, mp_context=multiprocessing.get_context("spawn")) as pool:
        results = sp.plan_many(jobs, pool)
    print("ok", [r.ok for r in results])

{guard}
    main()
"""


@pytest.mark.parametrize("guarded", [True, False])
def test_spawn_start_method_needs_the_main_guard(tmp_path, guarded):
    script = tmp_path / "many.py"
    guard = 'if __name__ == "__main__":' if guarded else "if True:  # no guard"
    script.write_text(textwrap.dedent(SCRIPT).replace("{guard}", guard))
    res = subprocess.run([sys.executable, str(script)], capture_output=True, text=True,
                         timeout=300, cwd=tmp_path)
    if guarded:
        assert res.returncode == 0, res.stderr
        assert res.stdout.strip() == "ok [True, True]"
    else:  # loud, with the fix in the message, instead of a list of failures and exit 0
        assert res.returncode != 0
        assert "__name__" in res.stderr and "spawn" in res.stderr


def _jobs():
    lim = sp.Limits(v_max=2, a_max=1, a_lat_max=1, j_max=0.5)
    good = [(sp.Path.from_segments([Line(L)]), lim) for L in (4.0, 9.0)]
    bad = {"path": sp.Path.from_segments([Line(5.0)]), "limits": lim, "v0": 5.0}
    return [good[0], bad, good[1]]


def test_plan_many_matches_one_by_one_and_reports_errors_per_job():
    jobs = _jobs()
    seen = []
    with ThreadPoolExecutor(2) as ex:
        results = sp.plan_many(jobs, ex, progress=lambda d, t: seen.append((d, t)))
    assert [r.ok for r in results] == [True, False, True]
    assert isinstance(results[1].error, sp.InvalidInputError)
    single = sp.plan(*jobs[2])
    assert results[2].profile.duration == single.duration
    assert seen[-1] == (3, 3)


def test_plan_many_on_a_process_pool_and_a_dask_cluster():
    distributed = pytest.importorskip("distributed")
    jobs = _jobs()
    local = sp.plan_many(jobs)  # default: local process pool
    with distributed.LocalCluster(n_workers=2, threads_per_worker=1, processes=True,
                                  dashboard_address=None) as cluster, \
            distributed.Client(cluster) as client:
        remote = sp.plan_many(jobs, client.get_executor())
    assert [r.ok for r in local] == [r.ok for r in remote] == [True, False, True]
    for a, b in zip(local, remote, strict=True):
        if a.ok:
            assert a.profile.duration == b.profile.duration
            assert np.array_equal(a.profile.w, b.profile.w)


def test_a_validated_request_or_job_plans_as_its_dict_does():
    from speedplan.batch import PlanJob
    from speedplan.model import PlanRequest

    path = sp.Path.from_waypoints([[0, 0], [6, 0], [9, 4]])
    options = {"v0": 0.5, "refine": "never", "n": 120}
    request = PlanRequest.create(path, LGV, **options)
    jobs = [{"path": path, "limits": LGV, **options}, (path, LGV, options), request,
            PlanJob(request), PlanJob(request, time_limit=60.0)]
    with ThreadPoolExecutor(2) as ex:
        results = sp.plan_many(jobs, ex)
    assert all(r.ok for r in results)
    reference = sp.plan(path, LGV, **options)
    assert {r.profile.duration for r in results} == {reference.duration}
    np.testing.assert_array_equal(results[2].profile.w, reference.w)


def test_a_jobs_own_time_limit_takes_precedence_over_the_batchs():
    from speedplan.batch import PlanJob
    from speedplan.model import PlanRequest

    request = PlanRequest.create(sp.Path.from_segments([Line(3.0)]), LGV)
    with ThreadPoolExecutor(2) as ex:
        tight, own = sp.plan_many([PlanJob(request), PlanJob(request, time_limit=60.0)], ex,
                                  time_limit=1e-9)
    assert isinstance(tight.error, sp.PlanTimeout) and own.ok


@pytest.mark.parametrize(("kwargs", "match"), [
    ({"request": "path"}, "`request` must be a PlanRequest"),
    ({"time_limit": 0.0}, "`time_limit` must be > 0"),
])
def test_a_plan_job_checks_its_fields(kwargs, match):
    from speedplan.batch import PlanJob
    from speedplan.model import PlanRequest

    fields = {"request": PlanRequest.create(sp.Path.from_segments([Line(3.0)]), LGV), **kwargs}
    with pytest.raises(sp.InvalidInputError, match=match):
        PlanJob(**fields)
