"""The command line through `python -m speedplan`: options, files, streams, exit codes."""

from __future__ import annotations

import csv
import io
import json
import subprocess
import sys
from dataclasses import replace

import numpy as np
import pytest
from shared import LGV_ARGS

import speedplan as sp
from speedplan import cli
from speedplan.io import read_path


def run(*args, cwd=None, stdin=None):
    return subprocess.run([sys.executable, "-m", "speedplan", *args], capture_output=True,
                          text=True, cwd=cwd, timeout=300, input=stdin)


@pytest.fixture
def root(request):
    return request.config.rootpath


def test_version_and_python_m():
    res = run("--version")
    assert res.returncode == 0
    assert res.stdout.strip() == f"speedplan {sp.__version__}"


def flat_help(*args):
    return " ".join(run(*args, "--help").stdout.split())  # independent of the line wrapping


def test_help_shows_defaults_exit_codes_and_new_options():
    plan_help = flat_help("plan")
    for text in ("(default: 0.01)", "(default: smooth)", "--standstill", "acceleration 0 at a",
                 "{auto,clarabel,banded}", "{auto,always,never}", "(default: 150)",
                 "standard input", "exit codes:", "limits_exceeded", "4 a solver failed"):
        assert text in plan_help, text
    demo_help = flat_help("demo")
    assert "(default: 2.0)" in demo_help and "(default: 0.5)" in demo_help
    assert "(default: speedplan-demo.csv)" in demo_help
    bench_help = flat_help("bench")
    assert "(default: 3)" in bench_help and "(default: 1000)" in bench_help


@pytest.mark.parametrize(
    ("args", "text"),
    [
        (["-o", "out.xlsx"], ".csv or .json"),
        (["-o", "out"], ".csv or .json"),
        (["--plot", "fig"], "unknown figure type (no extension)"),
        (["--plot", "fig.doc"], ".png"),
        (["--dt", "0"], "--dt"),
        (["--dt", "nan"], "--dt"),
        (["-o", "/nonexistent/dir/x.csv"], "does not exist"),
        (["--plot", "/nonexistent/dir/x.png"], "does not exist"),
        (["-o", "x.csv", "--output-format", "json"], "contradicts"),
    ],
)
def test_bad_outputs_are_refused_before_planning(args, text, root, tmp_path):
    res = run("plan", str(root / "paths" / "u_turn.json"), *LGV_ARGS, *args, cwd=tmp_path)
    assert res.returncode == 2, res.stderr
    assert text in res.stderr
    assert "duration" not in res.stdout  # nothing was planned
    assert "Traceback" not in res.stderr
    assert list(tmp_path.iterdir()) == []  # and nothing written


def test_plot_writes_exactly_the_announced_file(root, tmp_path):
    res = run("plan", str(root / "paths" / "u_turn.json"), *LGV_ARGS, "--plot", "fig.svg",
              cwd=tmp_path)
    assert res.returncode == 0, res.stderr
    assert "wrote     fig.svg" in res.stdout
    assert [p.name for p in tmp_path.iterdir()] == ["fig.svg"]


def test_json_output_carries_the_metadata(root, tmp_path):
    res = run("plan", str(root / "paths" / "u_turn.json"), *LGV_ARGS, "--a-decel", "0.8",
              "--dt", "0.02", "-o", "t.json", cwd=tmp_path)
    assert res.returncode == 0, res.stderr
    doc = json.loads((tmp_path / "t.json").read_text())
    meta = doc["metadata"]
    assert meta["speedplan_version"] == sp.__version__
    assert meta["path_file"] == "u_turn.json" and meta["status"] == "optimal"
    assert meta["dt"] == 0.02
    assert meta["limits"] == {"v_max": 2.0, "a_max": 1.0, "a_lat_max": 1.0, "j_max": 0.5,
                              "a_decel": 0.8, "j_lat_max": None, "yaw_rate_max": None,
                              "yaw_acc_max": 1.0, "yaw_jerk_max": None, "grip": "independent"}
    t = np.array(doc["columns"]["t"])
    assert meta["duration"] == pytest.approx(t[-1], abs=1e-12)
    assert 0 <= meta["gap"] < 1e-6 and meta["lower_bound"] <= meta["objective"]
    for line in res.stdout.splitlines():  # the same numbers as the printed summary
        if line.startswith("duration"):
            assert float(line.split()[1]) == pytest.approx(meta["duration"], abs=1e-4)


def test_backend_and_refine_reach_the_planner(root, tmp_path):
    for backend in ("clarabel", "banded"):
        res = run("plan", str(root / "paths" / "u_turn.json"), *LGV_ARGS, "--backend", backend,
                  "--refine", "always", "-o", f"{backend}.json", cwd=tmp_path)
        assert res.returncode == 0, res.stderr
        meta = json.loads((tmp_path / f"{backend}.json").read_text())["metadata"]
        assert meta["backend"] == backend and meta["refined"] is True
    res = run("plan", str(root / "paths" / "u_turn.json"), *LGV_ARGS, "--backend", "mosek")
    assert res.returncode == 2 and "invalid choice" in res.stderr


def test_stdin_path_and_stdout_trajectory(root):
    csv_path = (root / "paths" / "aisle_corners.csv").read_text()
    res = run("plan", "-", *LGV_ARGS, "-o", "-", stdin=csv_path)
    assert res.returncode == 0, res.stderr
    assert "realised maxima" in res.stderr and "realised maxima" not in res.stdout  # summary
    lines = [ln for ln in res.stdout.splitlines() if not ln.startswith("#")]
    assert lines[0].startswith("t [s],s [m],x [m]")
    data = np.loadtxt(lines[1:], delimiter=",")
    reference = sp.plan(read_path(root / "paths" / "aisle_corners.csv"),
                        sp.Limits(v_max=2, a_max=1, a_lat_max=1, j_max=0.5)).sample(0.01)
    assert np.array_equal(data[:, 0], reference.t) and np.array_equal(data[:, 6], reference.v)
    assert "# path_file: <stdin>" in res.stdout
    # JSON on stdin is sniffed; JSON on stdout on request.
    seg = (root / "paths" / "u_turn.json").read_text()
    res = run("plan", "-", *LGV_ARGS, "-o", "-", "--output-format", "json", stdin=seg)
    assert res.returncode == 0, res.stderr
    assert json.loads(res.stdout)["metadata"]["path_file"] == "<stdin>"
    res = run("plan", "-", "--format", "csv", *LGV_ARGS, stdin=seg)
    assert res.returncode == 2 and "<stdin>" in res.stderr


def test_strict_exits_5_on_any_verify_failure(root, tmp_path):
    # Comfort limits on the NURBS edge, planned on the relaxation alone (refine never): the
    # relaxation is not exact there, and its law exceeds the jerk and lateral-jerk limits
    # (plan() flags it, status limits_exceeded).
    limits = ["--v-max", "2", "--a-max", "1", "--a-lat-max", "1", "--j-max", "0.5",
              "--j-lat-max", "0.3", "--yaw-rate-max", "0.4"]
    res = run("plan", str(root / "paths" / "nurbs_edge.json"), *limits, "--refine", "never",
              "--strict", "-o", "t.csv", cwd=tmp_path)
    assert res.returncode == 5, res.stderr
    assert "limits exceeded" in res.stderr and "jerk" in res.stderr
    ok = run("plan", str(root / "paths" / "nurbs_edge.json"), *limits, "--strict", "-o",
             "t.csv", cwd=tmp_path)
    assert ok.returncode == 0, ok.stderr


def test_verbose_logs_files_to_stderr(root, tmp_path):
    res = run("plan", str(root / "paths" / "u_turn.json"), *LGV_ARGS, "-o", "t.csv", "-v",
              cwd=tmp_path)
    assert res.returncode == 0, res.stderr
    assert "speedplan DEBUG: read json file" in res.stderr
    assert "speedplan DEBUG: wrote trajectory CSV" in res.stderr
    quiet = run("plan", str(root / "paths" / "u_turn.json"), *LGV_ARGS, cwd=tmp_path)
    assert "DEBUG" not in quiet.stderr


def test_bench_says_what_it_times():
    res = run("bench", "--instances", "1", "--n", "60")
    assert res.returncode == 0, res.stderr
    assert "relaxation [s]: setup + solve of the convex relaxation" in res.stdout
    assert "median time [s]" not in res.stdout
    assert res.stdout.count("/18]") == 18


# ---- statuses -> exit codes (in process: the planner does not yet produce every status) -----
def test_exit_status_table():
    assert cli.exit_status("optimal", {}) == (0, None)
    assert cli.exit_status("refined", {}) == (0, None)
    assert cli.exit_status("refined", {"jerk": 1.2})[0] == 0
    assert cli.exit_status("refined", {"jerk": 1.2}, strict=True)[0] == 5
    code, why = cli.exit_status("limits_exceeded", {"lateral": 1.5})
    assert code == 5 and "lateral 1.500×" in why and "limits_exceeded" in why


def test_limits_exceeded_exits_5_without_strict(monkeypatch, capsys, root, tmp_path):
    real_plan = sys.modules["speedplan.plan"].plan

    def exceeded(*args, **kwargs):
        profile = real_plan(*args, **kwargs)
        return replace(profile, limits_exceeded=True)

    monkeypatch.setattr(sys.modules["speedplan.plan"], "plan", exceeded)
    out = tmp_path / "t.csv"
    code = cli.main(["plan", str(root / "paths" / "u_turn.json"), *LGV_ARGS, "-o", str(out)])
    captured = capsys.readouterr()
    assert code == 5
    assert "limits exceeded" in captured.err and "after local refinement" in captured.err
    assert "# status: limits_exceeded" in out.read_text()  # the files are still written


def test_main_reads_a_stream_in_process(monkeypatch, capsys, root):
    monkeypatch.setattr(sys, "stdin", io.StringIO((root / "paths" / "u_turn.json").read_text()))
    assert cli.main(["plan", "-", *LGV_ARGS]) == 0
    assert "path      <stdin>" in capsys.readouterr().out


def test_file_warnings_are_one_line_messages(tmp_path):
    f = tmp_path / "ros.csv"
    f.write_text("frame_id,x,y\nmap,0,0\nmap,10,0\n")
    res = run("plan", str(f), *LGV_ARGS)
    assert res.returncode == 0, res.stderr
    assert "warning: ros.csv: ignored columns ['frame_id']" in res.stderr
    assert "SpeedplanWarning" not in res.stderr  # not Python's file:line: Category: format


def test_an_order_is_planned_as_a_route_with_node_times(root, tmp_path):
    order = root / "paths" / "orders" / "order_v2.json"
    out, fig = tmp_path / "route.csv", tmp_path / "route.png"
    res = run("plan", str(order), *LGV_ARGS, "-o", str(out), "--plot", str(fig))
    assert res.returncode == 0, res.stderr
    route = sp.Route.from_vda5050(order)
    reference = sp.plan_route(route, sp.Limits(v_max=2, a_max=1, a_lat_max=1, j_max=0.5))
    for node, t_node in zip(route.base_nodes, reference.node_times, strict=True):
        assert f"{node.node_id:8s}" in res.stdout and f"{t_node:9.3f}" in res.stdout
    text = out.read_text()
    header = next(ln for ln in text.splitlines() if not ln.startswith("#"))
    assert header.endswith(",edge [1]")
    assert "# node_times: " in text and fig.stat().st_size > 10_000
    # The same order on standard input; an update part-way along it.
    res = run("plan", "-", *LGV_ARGS, "--start-s", "20", "--v0", "1.0", stdin=order.read_text())
    assert res.returncode == 0, res.stderr
    assert "passed" in res.stdout  # N0 and N1 lie behind the vehicle
    res = run("plan", str(root / "paths" / "u_turn.json"), *LGV_ARGS, "--start-s", "3")
    assert res.returncode == 2 and "--start-s applies to VDA 5050 orders" in res.stderr
    res = run("plan", str(order), *LGV_ARGS, "--vf", "1")
    assert res.returncode == 2 and "--vf/--af" in res.stderr


def test_comfort_limits_on_the_command_line(root):
    res = run("plan", str(root / "paths" / "u_turn.json"), *LGV_ARGS, "--j-lat-max", "0.3",
              "--yaw-rate-max", "0.4")
    assert res.returncode == 0, res.stderr
    ratio = {line.split()[0]: float(line.split()[1]) for line in res.stdout.splitlines()
             if line.startswith("  ") and "of limit" in line}
    assert 0.5 < ratio["yaw_rate"] <= 1.001 and 0.5 < ratio["lateral_jerk"] <= 1.05


def test_grip_ellipse_from_the_command_line(root, tmp_path):
    res = run("plan", str(root / "paths" / "u_turn.json"), *LGV_ARGS, "--grip", "ellipse",
              "-o", "t.json", cwd=tmp_path)
    assert res.returncode == 0, res.stderr
    assert "grip" in res.stdout
    meta = json.loads((tmp_path / "t.json").read_text())["metadata"]
    assert meta["limits"]["grip"] == "ellipse" and meta["backend"] == "clarabel"
    bad = run("plan", str(root / "paths" / "u_turn.json"), *LGV_ARGS, "--grip", "circle",
              cwd=tmp_path)
    assert bad.returncode == 2 and "ellipse" in bad.stderr


@pytest.mark.parametrize("name", ["aisle_corners.csv", "nurbs_edge.json", "slow_zone.json"])
def test_cli_plan_writes_trajectory_and_plot(tmp_path, name, request):
    root = request.config.rootpath
    out, fig = tmp_path / "traj.csv", tmp_path / "fig.png"
    res = run("plan", str(root / "paths" / name), *LGV_ARGS, "-o", str(out), "--plot", str(fig))
    assert res.returncode == 0, res.stderr
    assert "duration" in res.stdout and "status    optimal" in res.stdout
    rows = [r for r in csv.reader(out.open()) if not r[0].startswith("#")]
    assert rows[0][:3] == ["t [s]", "s [m]", "x [m]"] and len(rows) > 100
    data = np.array(rows[1:], dtype=float)
    assert np.all(np.diff(data[:, 0]) > 0) and data[:, 6].max() <= 2.0 * 1.005
    assert fig.stat().st_size > 20_000
    assert fig.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"


def test_cli_demo_runs_in_a_fresh_directory(tmp_path):
    res = run("demo", cwd=tmp_path)
    assert res.returncode == 0, res.stderr
    assert (tmp_path / "speedplan-demo.csv").stat().st_size > 0
    assert (tmp_path / "speedplan-demo.png").stat().st_size > 20_000


def test_cli_json_output(tmp_path, request):
    out = tmp_path / "t.json"
    res = run("plan", str(request.config.rootpath / "paths" / "u_turn.json"), *LGV_ARGS,
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
    res = run(*args, cwd=request.config.rootpath)
    assert res.returncode == code
    assert text in res.stderr
    assert "Traceback" not in res.stderr
