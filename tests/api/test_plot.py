"""Figures: no pyplot state, the caller's backend untouched, readable panels."""

from __future__ import annotations

import io
import subprocess
import sys

import numpy as np
import pytest
from shared import LGV

import speedplan as sp
from speedplan.geometry import Line
from speedplan.io import read_path
from speedplan.plot import PANELS, plot_jerk, plot_path, plot_profile

matplotlib = pytest.importorskip("matplotlib")
from matplotlib.figure import Figure  # noqa: E402


@pytest.fixture(scope="module")
def loop_profile(request):
    path = read_path(request.config.rootpath / "paths" / "warehouse_loop.json")
    return sp.plan(path, LGV)


@pytest.fixture(scope="module")
def loop_fig(loop_profile):
    fig = plot_profile(loop_profile, dt=0.05)
    fig.draw_without_rendering()
    return fig


def test_the_callers_backend_is_left_alone(loop_profile):
    before = matplotlib.get_backend()
    try:
        matplotlib.use("svg")
        fig = plot_profile(loop_profile, dt=0.1)
        assert matplotlib.get_backend() == "svg"
        assert isinstance(fig, Figure)
    finally:
        matplotlib.use(before)


def test_no_pyplot_import_and_no_open_figures(tmp_path, request):
    code = (
        "import sys, speedplan as sp\n"
        "from speedplan.plot import plot_profile\n"
        "p = sp.plan(sp.Path.from_waypoints([[0, 0], [8, 0], [8, 6]]),"
        " sp.Limits(v_max=2, a_max=1, a_lat_max=1, j_max=0.5))\n"
        f"fig = plot_profile(p, {str(tmp_path / 'f.png')!r})\n"
        "print('pyplot' if 'matplotlib.pyplot' in sys.modules else 'no pyplot')\n"
    )
    res = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True,
                         timeout=300, cwd=request.config.rootpath)
    assert res.returncode == 0, res.stderr
    assert res.stdout.strip() == "no pyplot"
    assert (tmp_path / "f.png").stat().st_size > 10_000


def test_saved_png_has_150_dpi_and_svg_to_a_buffer_works(loop_profile, tmp_path):
    f = tmp_path / "demo.png"
    fig = plot_profile(loop_profile, f, dt=0.1)
    img = matplotlib.image.imread(f)
    w, h = fig.get_size_inches()
    assert img.shape[:2] == (round(h * 150), round(w * 150))
    buf = io.BytesIO()
    fig.savefig(buf, format="svg")  # what the tutorials do
    assert buf.getvalue().lstrip().startswith(b"<?xml")


def test_draws_into_a_given_figure_subfigure_or_axes(loop_profile):
    traj = loop_profile.sample(0.1)
    mine = Figure()
    assert plot_profile(loop_profile, trajectory=traj, fig=mine) is mine
    assert len(mine.axes) == len(PANELS) + 1  # the panels and the speed colour bar
    outer = Figure()
    left, _right = outer.subfigures(1, 2)
    assert plot_profile(loop_profile, trajectory=traj, fig=left) is outer
    ax = Figure().subplots()
    assert plot_jerk(traj, LGV, ax) is ax and ax.get_ylabel() == "jerk [m/s³]"
    with pytest.raises(sp.InvalidInputError, match="`fig`"):
        plot_profile(loop_profile, trajectory=traj, fig="figure")
    with pytest.raises(sp.InvalidInputError, match="`ax`"):
        plot_path(traj, ax=42)


def test_closed_loop_start_and_end_markers_both_show(loop_fig, loop_profile):
    ax = loop_fig.axes[PANELS.index("path")]
    lines = {ln.get_label(): ln for ln in ax.get_lines()}
    start, end = lines["start"], lines["end"]
    assert np.allclose(start.get_xydata(), end.get_xydata(), atol=1e-6)  # a loop
    assert start.get_zorder() > end.get_zorder()
    assert end.get_markerfacecolor() == "none"  # a hollow square around the dot ...
    assert end.get_markersize() > start.get_markersize()  # ... larger than it


def _legend_hides_data(ax):
    legend = ax.get_legend()
    box = legend.get_window_extent()
    for line in ax.get_lines():
        if line.get_label().startswith("_") or len(line.get_xdata()) < 3:
            continue  # limit lines (axhline) span the axes; the legend sits above them
        xy = ax.transData.transform(line.get_xydata())
        inside = ((xy[:, 0] > box.x0) & (xy[:, 0] < box.x1) & (xy[:, 1] > box.y0)
                  & (xy[:, 1] < box.y1))
        if inside.any():
            return True
    return False


@pytest.mark.parametrize("panel", ["speed", "lateral", "acceleration", "jerk"])
def test_legends_do_not_cover_the_traces(loop_fig, panel):
    ax = loop_fig.axes[PANELS.index(panel)]
    assert not _legend_hides_data(ax)


@pytest.mark.parametrize(("panel", "limits"), [("acceleration", (1.0, -1.0)),
                                                ("lateral", (1.0, -1.0)),
                                                ("jerk", (0.5, -0.5))])
def test_limit_lines_are_labelled_and_not_in_the_traces_colour(loop_fig, panel, limits):
    ax = loop_fig.axes[PANELS.index(panel)]
    trace = ax.get_lines()[0]
    flat = [ln for ln in ax.get_lines()[1:] if np.ptp(ln.get_ydata()) == 0]
    assert sorted(ln.get_ydata()[0] for ln in flat) == sorted(limits)
    assert all(ln.get_color() != trace.get_color() for ln in flat)
    labels = [t.get_text() for t in ax.get_legend().get_texts()]
    assert any(label.startswith("limits") for label in labels)


def test_tangential_and_lateral_limits_are_in_separate_panels(loop_fig):
    # With a_max == a_lat_max they used to be drawn on top of each other.
    acc = loop_fig.axes[PANELS.index("acceleration")]
    lat = loop_fig.axes[PANELS.index("lateral")]
    assert acc is not lat
    assert acc.get_ylabel() == "a [m/s²]" and lat.get_ylabel() == "a_lat [m/s²]"


def test_speed_panel_says_speed_limit(loop_fig):
    ax = loop_fig.axes[PANELS.index("speed")]
    labels = [t.get_text() for t in ax.get_legend().get_texts()]
    assert "speed limit (v_max, lateral, zones)" in labels
    assert not any("mu" in label or "sqrt" in label for label in labels)


def test_zones_are_drawn_on_the_path(request):
    root = request.config.rootpath / "paths"
    from speedplan.io import read_zones

    zones = read_zones(root / "slow_zone.json")
    prof = sp.plan(read_path(root / "slow_zone.json"), LGV, zones=zones)
    fig = plot_profile(prof, dt=0.1)
    ax = fig.axes[PANELS.index("path")]
    assert len(ax.patches) == 1
    assert any("0.5 m/s" in t.get_text() for t in ax.texts)


def test_plot_axes_are_sane(tmp_path):
    prof = sp.plan(sp.Path.from_segments([Line(10.0)]),
                   sp.Limits(v_max=2, a_max=1, a_lat_max=1, j_max=0.5))
    fig = plot_profile(prof, str(tmp_path / "p.png"))
    axes = dict(zip(PANELS, fig.axes, strict=False))
    assert axes["speed"].get_xlabel() == "s [m]" and axes["speed"].get_ylim()[1] >= 2.0
    assert axes["jerk"].get_ylabel() == "jerk [m/s³]"
    assert (tmp_path / "p.png").stat().st_size > 10_000
