"""Conventions a user meets: messages in the user's own terms, readable files, figures that
fit the user's layout, an install that says what it costs."""

from __future__ import annotations

import io
import re
import sys
import tomllib
from pathlib import Path

import numpy as np
import pytest
from shared import LGV, LGV_ARGS

import speedplan as sp
from speedplan import cli

ROOT = Path(__file__).resolve().parents[2]


@pytest.fixture(scope="module")
def corner_profile():
    return sp.plan(sp.Path.from_waypoints([[0, 0], [10, 0], [12, 3]]), LGV)


# ---- Verification.summary() --------------------------------------------------------------------
def test_summary_says_not_set_for_limits_that_are_not_set(corner_profile):
    lines = dict(line.split(None, 1) for line in corner_profile.verify().summary().splitlines())
    assert lines["yaw_rate"] == "not set" and lines["lateral_jerk"] == "not set"
    assert lines["jerk"].split()[1:3] == ["of", "limit"]  # set limits keep their ratio
    comfort = sp.Limits(2, 1, 1, 0.5, j_lat_max=0.8, yaw_rate_max=1.0, grip="ellipse")
    summary = sp.plan(sp.Path.from_waypoints([[0, 0], [10, 0], [12, 3]]), comfort).verify()
    assert "not set" not in summary.summary()
    no_jerk = sp.plan(sp.Path.from_waypoints([[0, 0], [10, 0]], kind="polyline"),
                      sp.Limits(2, 1, 1, np.inf))
    jerk_line = next(ln for ln in no_jerk.verify().summary().splitlines() if ln.startswith("jerk"))
    assert jerk_line.split(None, 1)[1] == "not set"


def test_a_set_limit_reached_at_zero_is_not_reported_as_unset():
    # A straight line with a yaw-rate limit: the ratio is 0 because the yaw rate is 0.
    prof = sp.plan(sp.Path.from_waypoints([[0, 0], [10, 0]], kind="polyline"),
                   sp.Limits(2, 1, 1, 0.5, yaw_rate_max=0.5))
    line = next(ln for ln in prof.verify().summary().splitlines() if ln.startswith("yaw_rate"))
    assert "not set" not in line and "0.0000 of limit" in line


# ---- the command line ------------------------------------------------------------------------
def _cli(capsys, *args):
    code = cli.main(list(args))
    out = capsys.readouterr()
    return code, out.out, out.err


def test_cli_errors_name_the_flag_typed(capsys, tmp_path):
    path = ROOT / "paths" / "u_turn.json"
    code, _, err = _cli(capsys, "plan", str(path), "--v-max", "-1", "--a-max", "1",
                        "--a-lat-max", "1", "--j-max", "0.5", "-o", "")
    assert code == 2 and "`--v-max`" in err and "`v_max`" not in err, err
    md = tmp_path / "route.md"
    md.write_text("x,y\n0,0\n1,0\n")
    code, _, err = _cli(capsys, "plan", str(md), *LGV_ARGS, "-o", "")
    assert code == 2 and "`--format`" in err and "`format`" not in err, err


def test_a_subcommands_error_shows_its_own_usage(capsys):
    with pytest.raises(SystemExit) as exc:
        cli.main(["plan", str(ROOT / "paths" / "u_turn.json"), *LGV_ARGS, "--bogus"])
    err = capsys.readouterr().err
    assert exc.value.code == 2
    assert err.startswith("usage: speedplan plan ") and "unrecognized arguments: --bogus" in err


def test_a_nan_waypoint_is_named_by_its_row(tmp_path, capsys):
    f = tmp_path / "w.csv"
    f.write_text("x,y\n0,0\n5,nan\n10,0\n")
    with pytest.raises(sp.InvalidInputError,
                       match=r"w\.csv: data row 2 .*'y' must be a finite number"):
        sp.io.read_path(f)
    code, _, err = _cli(capsys, "plan", str(f), *LGV_ARGS, "-o", "")
    assert code == 2 and "data row 2" in err


def test_demo_writes_its_csv_without_matplotlib(tmp_path, monkeypatch, capsys):
    monkeypatch.chdir(tmp_path)
    monkeypatch.setitem(sys.modules, "matplotlib", None)  # import matplotlib fails
    monkeypatch.setitem(sys.modules, "matplotlib.backend_bases", None)
    code, _, err = _cli(capsys, "demo")
    assert code == 0, err
    assert (tmp_path / "speedplan-demo.csv").stat().st_size > 10_000
    assert not (tmp_path / "speedplan-demo.png").exists()
    assert "pip install 'speedplan[plot]'" in err


# ---- files -----------------------------------------------------------------------------------
def test_csv_numbers_are_the_shortest_exact_decimals(corner_profile):
    traj = corner_profile.sample(0.01)
    buf = io.StringIO()
    traj.to_csv(buf)
    rows = [ln for ln in buf.getvalue().splitlines() if not ln.startswith("#")][1:]
    assert rows[4].split(",")[0] == "0.04"  # 4 * 0.01, not 0.040000000000000001
    fields = [v for r in rows[:200] for v in r.split(",")]
    # Each is the shortest decimal of its float: repr's digits (never more than %.17g's).
    assert all(v == repr(float(v)).removesuffix(".0") for v in fields)
    assert sum(map(len, fields)) < sum(len(f"{float(v):.17g}") for v in fields)
    back = np.loadtxt(rows, delimiter=",")
    for j, name in enumerate(traj.units):
        if name != "heading":
            assert np.array_equal(back[:, j], getattr(traj, name)), name
    short = io.StringIO()
    traj.to_csv(short, precision=5)
    last = [ln for ln in short.getvalue().splitlines() if not ln.startswith("#")][-1]
    assert all(len(v.lstrip("-").replace(".", "").split("e")[0].lstrip("0")) <= 5
               for v in last.split(","))
    with pytest.raises(sp.InvalidInputError, match="`precision`"):
        traj.to_csv(io.StringIO(), precision=0)


def test_the_sample_paths_table_is_one_table():
    lines = (ROOT / "paths" / "README.md").read_text(encoding="utf-8").splitlines()
    rows = [i for i, ln in enumerate(lines) if ln.startswith("|")]
    assert rows == list(range(rows[0], rows[-1] + 1)), "a blank line splits the table"


# ---- figures ---------------------------------------------------------------------------------
matplotlib = pytest.importorskip("matplotlib")
from matplotlib.backends.backend_agg import FigureCanvasAgg  # noqa: E402
from matplotlib.figure import Figure  # noqa: E402

from speedplan.plot import plot_path, plot_profile, plot_speed  # noqa: E402


def _overlap(a, b) -> bool:
    return a.x0 < b.x1 and b.x0 < a.x1 and a.y0 < b.y1 and b.y0 < a.y1


def test_plot_speed_takes_a_route_profile():
    route = sp.Route.from_vda5050(ROOT / "paths" / "orders" / "order_v2.json")
    profile = sp.plan_route(route, LGV)
    traj = profile.sample(0.05)
    ax = plot_speed(profile, traj)
    assert ax.get_xlabel() == "s [m]"
    limit = [ln for ln in ax.get_lines() if ln.get_linestyle() == "--"]
    assert len(limit) == len(profile.legs)
    assert np.isclose(max(ln.get_xdata().max() for ln in limit), route.length)
    assert plot_speed(profile).get_lines()  # the trajectory defaults to sample(0.01)
    with pytest.raises(sp.InvalidInputError, match="`profile`"):
        plot_speed(traj)


@pytest.mark.parametrize("layout", [None, "constrained"])
def test_plot_path_in_a_users_grid_covers_no_title(corner_profile, layout):
    fig = Figure(figsize=(8, 6), layout=layout)
    axes = fig.subplots(2, 2)
    traj = corner_profile.sample(0.05)
    for ax in axes.flat:
        ax.set_title("my title")
    plot_path(traj, axes[0, 0])
    plot_speed(corner_profile, traj, axes[0, 1])
    fig.suptitle("my figure")
    renderer = FigureCanvasAgg(fig).get_renderer()
    fig.draw(renderer)
    legend = axes[0, 0].get_legend().get_window_extent(renderer)
    titles = [ax.title.get_window_extent(renderer) for ax in axes.flat if ax.get_title()]
    titles.append(fig._suptitle.get_window_extent(renderer))
    own = [axes[0, 0].title, axes[0, 0]._left_title]
    assert not any(_overlap(legend, t.get_window_extent(renderer)) for t in own)
    if layout == "constrained":  # the layout keeps the other panels' titles clear too
        assert not any(_overlap(legend, t) for t in titles)


def test_plot_profile_lays_out_a_users_figure(corner_profile):
    fig = Figure(figsize=(11, 9.5))  # pyplot's plt.figure(): no layout engine
    plot_profile(corner_profile, trajectory=corner_profile.sample(0.05), fig=fig)
    assert fig.get_layout_engine() is not None
    renderer = FigureCanvasAgg(fig).get_renderer()
    fig.draw(renderer)
    panels = fig.axes[:5]
    boxes = [ax.get_tightbbox(renderer) for ax in panels]
    for i in range(len(boxes)):
        for k in range(i + 1, len(boxes)):
            assert not _overlap(boxes[i], boxes[k]), (panels[i].get_xlabel(), k)


# ---- packaging -------------------------------------------------------------------------------
def test_classifiers_name_the_python_that_runs_the_tests():
    meta = tomllib.loads((ROOT / "pyproject.toml").read_text(encoding="utf-8"))["project"]
    version = f"Programming Language :: Python :: {sys.version_info[0]}.{sys.version_info[1]}"
    assert version in meta["classifiers"]


def test_readme_states_the_install_footprint():
    readme = (ROOT / "README.md").read_text(encoding="utf-8")
    section = readme[readme.index("## Install"):]
    section = section[:section.index("\n## ", 4)]
    assert re.search(r"\d+ MB", section)
    for dependency in ("casadi", "numba", "llvmlite", "scipy", "numpy", "clarabel", "shapely"):
        assert dependency in section, dependency
