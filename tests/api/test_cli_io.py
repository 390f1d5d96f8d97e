"""The command line (real entry point, subprocess), path files, plots and plan_many."""

from __future__ import annotations

import csv
import json
import subprocess
import sys
from concurrent.futures import ThreadPoolExecutor

import numpy as np
import pytest
from shared import LGV_ARGS

import speedplan as sp
from speedplan.geometry import Line
from speedplan.io import read_path, read_zones
from speedplan.plot import PANELS, plot_profile


def run_cli(*args, cwd=None):
    return subprocess.run([sys.executable, "-m", "speedplan", *args], capture_output=True,
                          text=True, cwd=cwd, timeout=300)


@pytest.mark.parametrize("name", ["aisle_corners.csv", "nurbs_edge.json", "slow_zone.json"])
def test_cli_plan_writes_trajectory_and_plot(tmp_path, name, request):
    root = request.config.rootpath
    out, fig = tmp_path / "traj.csv", tmp_path / "fig.png"
    res = run_cli("plan", str(root / "paths" / name), *LGV_ARGS, "-o", str(out), "--plot", str(fig))
    assert res.returncode == 0, res.stderr
    assert "duration" in res.stdout and "status    optimal" in res.stdout
    rows = [r for r in csv.reader(out.open()) if not r[0].startswith("#")]
    assert rows[0][:3] == ["t [s]", "s [m]", "x [m]"] and len(rows) > 100
    data = np.array(rows[1:], dtype=float)
    assert np.all(np.diff(data[:, 0]) > 0) and data[:, 6].max() <= 2.0 * 1.005
    assert fig.stat().st_size > 20_000
    assert fig.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"


def test_cli_demo_runs_in_a_fresh_directory(tmp_path):
    res = run_cli("demo", cwd=tmp_path)
    assert res.returncode == 0, res.stderr
    assert (tmp_path / "speedplan-demo.csv").stat().st_size > 0
    assert (tmp_path / "speedplan-demo.png").stat().st_size > 20_000


def test_cli_json_output(tmp_path, request):
    out = tmp_path / "t.json"
    res = run_cli("plan", str(request.config.rootpath / "paths" / "u_turn.json"), *LGV_ARGS,
                  "-o", str(out))
    assert res.returncode == 0, res.stderr
    doc = json.loads(out.read_text())
    assert doc["units"]["v"] == "m/s" and len(doc["columns"]["t"]) > 100


@pytest.mark.parametrize(
    ("args", "code", "text"),
    [
        (["plan", "no_such_file.csv", *LGV_ARGS], 2, "does not exist"),
        (["plan", "paths/u_turn.json", "--v-max", "-1", "--a-max", "1", "--a-lat-max", "1",
          "--j-max", "1"], 2, "`--v-max`"),
        (["plan", "paths/slow_zone.json", *LGV_ARGS, "--v0", "2", "--a-decel", "0.01"], 3,
         "too short"),
        (["plan", "paths/u_turn.json", *LGV_ARGS, "--standstill", "bogus"], 2, "invalid choice"),
        (["frobnicate"], 2, "invalid choice"),
    ],
)
def test_cli_errors_are_one_line_with_documented_exit_codes(args, code, text, request):
    res = run_cli(*args, cwd=request.config.rootpath)
    assert res.returncode == code
    assert text in res.stderr
    assert "Traceback" not in res.stderr


def test_bad_files_raise_invalid_input(tmp_path):
    bad_json = tmp_path / "bad.json"
    bad_json.write_text("{not json")
    with pytest.raises(sp.InvalidInputError, match=r"bad\.json"):
        read_path(bad_json)
    no_xy = tmp_path / "w.csv"
    no_xy.write_text("a,b\n1,2\n3,4\n")
    with pytest.raises(sp.InvalidInputError, match="'x' and 'y'"):
        read_path(no_xy)
    seg = tmp_path / "s.json"
    seg.write_text(json.dumps({"segments": [{"type": "arc", "radius": 1.0}]}))
    with pytest.raises(sp.InvalidInputError, match="angle"):
        read_path(seg)
    zone = tmp_path / "z.json"
    zone.write_text(json.dumps({"segments": [{"type": "line", "length": 3}],
                                "zones": [{"polygon": [[0, 0], [1, 0]], "v_max": 1}]}))
    with pytest.raises(sp.InvalidInputError, match="polygon"):
        read_zones(zone)


def test_sample_files_load_with_sane_lengths(request):
    lengths = {}
    for f in sorted((request.config.rootpath / "paths").glob("*.*")):
        if f.suffix in (".csv", ".json"):
            lengths[f.name] = read_path(f).length
    assert len(lengths) >= 6
    assert all(5.0 < L < 1000.0 for L in lengths.values())
    assert read_zones(request.config.rootpath / "paths" / "slow_zone.json")[0].v_max == 0.5


def test_plot_axes_are_sane(tmp_path):
    prof = sp.plan(sp.Path.from_segments([Line(10.0)]),
                   sp.Limits(v_max=2, a_max=1, a_lat_max=1, j_max=0.5))
    fig = plot_profile(prof, str(tmp_path / "p.png"))
    axes = dict(zip(PANELS, fig.axes, strict=False))
    assert axes["speed"].get_xlabel() == "s [m]" and axes["speed"].get_ylim()[1] >= 2.0
    assert axes["jerk"].get_ylabel() == "jerk [m/s³]"
    assert (tmp_path / "p.png").stat().st_size > 10_000


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
