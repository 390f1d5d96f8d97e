"""Figures of a planned profile (matplotlib, from the ``plot`` extra, imported lazily).

Everything is drawn on `matplotlib.figure.Figure` objects, never through
``matplotlib.pyplot``: plotting neither switches the caller's backend nor leaves figures open
in pyplot's registry. Pass your own figure (``fig=``) or axes (``ax=``) to draw into them;
in Jupyter a returned figure displays itself.
"""

from __future__ import annotations

from os import PathLike
from typing import TYPE_CHECKING, Any

import numpy as np

from .core.errors import InvalidInputError, SpeedplanError

if TYPE_CHECKING:
    from .core.limits import Limits
    from .route import RouteProfile
    from .timing import SpeedProfile, Trajectory

__all__ = [
    "plot_acceleration",
    "plot_jerk",
    "plot_lateral",
    "plot_path",
    "plot_profile",
    "plot_route",
    "plot_speed",
]

#: Resolution of saved raster figures [dots per inch].
DPI = 150
LIMIT_STYLE: dict[str, Any] = {"color": "0.3", "ls": "--", "lw": 1.0}
HEADROOM = 1.45  # y range above the largest limit, where the legend goes


def _figure(**kwargs: Any) -> Any:
    try:
        from matplotlib.figure import Figure
    except ImportError as exc:  # pragma: no cover - exercised only without the extra
        raise SpeedplanError(
            "plotting needs matplotlib: pip install 'speedplan[plot]'"
        ) from exc
    return Figure(**kwargs)


def _axes(ax: Any) -> Any:
    """``ax``, or the axes of a new single-panel figure."""
    if ax is None:
        return _figure(figsize=(6, 4), layout="constrained").subplots()
    if not hasattr(ax, "plot") or not hasattr(ax, "figure"):
        raise InvalidInputError(f"`ax` must be a matplotlib Axes; got {type(ax).__name__}")
    return ax


def _path_legend(ax: Any, title: str) -> None:
    """The legend in a row just above the axes, the title above that row.

    On narrow axes (a panel of a user's grid) a legend in the title's line would cover the
    title; any title the axes already had moves up too. Two columns on axes narrower than
    5 inches.
    """
    width = ax.get_window_extent().width / ax.figure.dpi
    ncol = 4 if width >= 5 else 2
    rows = -(-len(ax.get_legend_handles_labels()[0]) // ncol)
    ax.legend(loc="lower left", bbox_to_anchor=(0.0, 1.0), ncol=ncol, fontsize=8,
              frameon=False, borderaxespad=0.2)
    ax.set_title(title, loc="left", pad=6.0 + 13.0 * rows)


def _legend_on_top(ax: Any, top: float, bottom: float) -> None:
    """Room above the traces for the legend, so that it never covers them."""
    ax.set_ylim(bottom, top)
    ax.legend(loc="upper center", ncol=3, fontsize=8, frameon=False)


def plot_path(
    trajectory: Trajectory, ax: Any = None, *, v_max: float | None = None, zones: Any = None
) -> Any:
    """The path coloured by speed, with its start, its end, the direction of travel and zones.

    Parameters
    ----------
    trajectory : Trajectory
        Sampled states (``x``, ``y``, ``v``, ``s``).
    ax : matplotlib.axes.Axes, optional
        Where to draw; default a new figure.
    v_max : float, optional
        Top of the colour scale [m/s]; default the largest speed.
    zones : SpeedZone or sequence of SpeedZone, optional
        Speed zones to shade, each labelled with its limit.

    Returns
    -------
    matplotlib.axes.Axes
    """
    from matplotlib.collections import LineCollection

    ax = _axes(ax)
    traj = trajectory
    pts = np.column_stack((traj.x, traj.y))
    segs = np.stack((pts[:-1], pts[1:]), axis=1)
    speed = 0.5 * (traj.v[:-1] + traj.v[1:])
    top = float(v_max) if v_max is not None else float(max(traj.v.max(), 1e-9))
    lc = LineCollection(list(segs), array=speed, cmap="viridis", linewidths=3,
                        norm=_norm(0.0, top))
    ax.add_collection(lc)
    _draw_zones(ax, zones)
    ax.autoscale()
    ax.set_aspect("equal", adjustable="datalim")
    ax.figure.colorbar(lc, ax=ax, label="speed v [m/s]", shrink=0.9, pad=0.01)
    # The end hollow and larger, the start on top: on a closed loop both stay visible.
    ax.plot(traj.x[0], traj.y[0], "o", ms=7, color="tab:green", label="start", zorder=5)
    ax.plot(traj.x[-1], traj.y[-1], "s", ms=12, mfc="none", mec="tab:red", mew=2, label="end",
            zorder=4)
    ahead = int(np.searchsorted(traj.s, min(0.04 * traj.s[-1], traj.s[0] + 3.0)))
    if 0 < ahead < len(traj):
        from matplotlib.transforms import offset_copy

        # Beside the path (8 points to its left), not over the colours it would hide.
        h = float(traj.heading[0])
        beside = offset_copy(ax.transData, fig=ax.figure, x=-8 * np.sin(h), y=8 * np.cos(h),
                             units="points")
        ax.annotate("", xy=(traj.x[ahead], traj.y[ahead]), xytext=(traj.x[0], traj.y[0]),
                    xycoords=beside, textcoords=beside,
                    arrowprops={"arrowstyle": "-|>", "color": "tab:green", "lw": 2},
                    zorder=5)
    ax.plot([], [], color="tab:green", marker=r"$\rightarrow$", ls="none", ms=12,
            label="direction of travel")
    ax.set(xlabel="x [m]", ylabel="y [m]")
    # Above the axes: inside them it would hide part of the path.
    _path_legend(ax, "path coloured by speed")
    return ax


def _draw_zones(ax: Any, zones: Any) -> None:
    import shapely
    from matplotlib.patches import Polygon as Patch

    from .geometry.bounds import check_zones

    label: str | None = "speed zone"
    for zone in check_zones(zones):
        poly = zone.polygon
        for part in (poly.geoms if isinstance(poly, shapely.MultiPolygon) else [poly]):
            ax.add_patch(Patch(np.asarray(part.exterior.coords), closed=True, fc="tab:orange",
                               ec="tab:orange", alpha=0.25, zorder=1, label=label))
            label = None
        x0, _, x1, y1 = poly.bounds  # above the zone: inside, the path would cross the text
        ax.annotate(f"zone limit {zone.v_max:g} m/s", (0.5 * (x0 + x1), y1), ha="center",
                    va="bottom", fontsize=8, color="tab:brown", zorder=6)


def _norm(lo: float, hi: float) -> Any:
    from matplotlib.colors import Normalize

    return Normalize(vmin=lo, vmax=hi)


def _bound_curves(profile: Any, samples: int = 2000) -> list[tuple[Any, Any]]:
    """``(s, sqrt(mu+(s)))`` along a SpeedProfile, or per leg along a RouteProfile."""
    if hasattr(profile, "leg_starts"):  # a RouteProfile: its legs' bounds, end to end
        per_leg = max(samples // max(len(profile.legs), 1), 50)
        return [(lo + s, np.sqrt(leg.speed_bound(s)))
                for leg, lo in zip(profile.legs, profile.leg_starts, strict=True)
                for s in [np.linspace(0.0, leg.path.length, per_leg)]]
    s = np.linspace(0.0, profile.path.length, samples)
    return [(s, np.sqrt(profile.speed_bound(s)))]


def plot_speed(profile: SpeedProfile | RouteProfile, trajectory: Trajectory | None = None,
               ax: Any = None, *, dt: float = 0.01) -> Any:
    """Speed ``v(s)`` against the speed limit from ``v_max``, curvature, zones and edges.

    Parameters
    ----------
    profile : SpeedProfile or RouteProfile
        What [`speedplan.plan`][speedplan.plan] or `speedplan.plan_route` returned.
    trajectory : Trajectory, optional
        The sampled trajectory to draw; default ``profile.sample(dt)``.
    ax : matplotlib.axes.Axes, optional
        Where to draw; default a new figure.
    dt : float
        Sampling period [s] when ``trajectory`` is not given.

    Returns
    -------
    matplotlib.axes.Axes
    """
    if not hasattr(profile, "sample") or not hasattr(profile, "duration"):
        raise InvalidInputError(
            f"`profile` must be a SpeedProfile or a RouteProfile; got {type(profile).__name__}")
    trajectory = trajectory if trajectory is not None else profile.sample(dt)
    ax = _axes(ax)
    curves = _bound_curves(profile)
    label = "speed limit (v_max, lateral, " + (
        "edge limits)" if hasattr(profile, "leg_starts") else "zones)")
    for k, (s, bound) in enumerate(curves):
        ax.plot(s, bound, "k--", lw=1, label=label if k == 0 else None)
    ax.plot(trajectory.s, trajectory.v, "C0", lw=2, label="speed v(s)")
    ax.set(xlabel="s [m]", ylabel="v [m/s]",
           title=f"speed law, duration {profile.duration:.3f} s")
    finite = [b[np.isfinite(b)] for _, b in curves]
    top = float(max(max((np.max(b, initial=0.0) for b in finite), default=0.0),
                    trajectory.v.max()))
    _legend_on_top(ax, HEADROOM * top, -0.04 * top)
    return ax


def _limit_lines(ax: Any, upper: float, lower: float, label: str) -> None:
    ax.axhline(upper, **LIMIT_STYLE, label=label)
    ax.axhline(-lower, **LIMIT_STYLE)


def plot_acceleration(trajectory: Trajectory, limits: Limits, ax: Any = None) -> Any:
    """Tangential acceleration ``a(t)`` against ``a_max`` and ``-a_decel``.

    Returns
    -------
    matplotlib.axes.Axes
    """
    ax = _axes(ax)
    ax.plot(trajectory.t, trajectory.a, "C1", label="tangential a(t)")
    _limit_lines(ax, limits.a_max, limits.a_decel, "limits a_max, −a_decel")
    ax.set(xlabel="t [s]", ylabel="a [m/s²]", title="tangential acceleration")
    _legend_on_top(ax, HEADROOM * limits.a_max, -1.1 * limits.a_decel)
    return ax


def _symmetric(ax: Any, t: Any, y: Any, limit: float, limit_label: str, style: dict[str, Any],
               **labels: str) -> Any:
    """A trace ``y(t)`` against ``±limit`` (none when infinite), legend above the traces.

    ``ax`` as the public functions take it; ``labels`` are the ``ylabel`` and ``title``.
    """
    ax = _axes(ax)
    ax.set(xlabel="t [s]", **labels)
    ax.plot(t, y, **style)
    peak = float(np.abs(y).max())
    if np.isfinite(limit):
        _limit_lines(ax, limit, limit, limit_label)
        peak = max(peak, limit)
    peak = peak if peak > 0 else 1.0
    _legend_on_top(ax, HEADROOM * peak, -1.1 * peak)
    return ax


def plot_lateral(trajectory: Trajectory, limits: Limits, ax: Any = None) -> Any:
    """Lateral acceleration ``a_lat(t) = κ v²`` against ``±a_lat_max``.

    Returns
    -------
    matplotlib.axes.Axes
    """
    return _symmetric(ax, trajectory.t, trajectory.a_lat, limits.a_lat_max, "limits ±a_lat_max",
                      {"color": "C2", "label": "lateral a_lat(t)"}, ylabel="a_lat [m/s²]",
                      title="lateral acceleration (+ = left turn)")


def plot_jerk(trajectory: Trajectory, limits: Limits, ax: Any = None) -> Any:
    """Jerk ``j(t)`` against ``±j_max``.

    Drawn like `plot_lateral` (no limit lines when the limit is infinite).

    Returns
    -------
    matplotlib.axes.Axes
    """
    return _symmetric(ax, trajectory.t, trajectory.j, limits.j_max, "limits ±j_max",
                      {"color": "C3", "lw": 1.2, "label": "jerk j(t)"}, ylabel="jerk [m/s³]",
                      title="jerk")


def _panels(fig: Any, figsize: tuple[float, float], mosaic: list[list[str]],
            height_ratios: list[float]) -> tuple[Any, dict[str, Any]]:
    """``fig`` (or a new figure of ``figsize``) and its panels' axes by name."""
    if fig is None:
        fig = _figure(figsize=figsize, layout="constrained")
    elif not hasattr(fig, "subplot_mosaic"):
        raise InvalidInputError(
            f"`fig` must be a matplotlib Figure or SubFigure; got {type(fig).__name__}"
        )
    elif hasattr(fig, "set_layout_engine") and fig.get_layout_engine() is None:
        # A figure without a layout engine (pyplot's default) would overlap the panels'
        # labels; the panels fill it, so it gets the layout a new figure has.
        fig.set_layout_engine("constrained")
    return fig, fig.subplot_mosaic(mosaic, height_ratios=height_ratios)


def _saved(fig: Any, file: str | PathLike[str] | None, dpi: float) -> Any:
    """The figure holding ``fig`` (itself, or a SubFigure's parent), saved first if ``file``."""
    if file is not None:
        fig.savefig(file, dpi=dpi)
    return getattr(fig, "figure", None) or fig


#: Panel names of `plot_profile`, in ``fig.axes`` order (colour bar last).
PANELS = ("path", "speed", "lateral", "acceleration", "jerk")


def plot_profile(
    profile: SpeedProfile,
    file: str | PathLike[str] | None = None,
    *,
    trajectory: Trajectory | None = None,
    dt: float = 0.01,
    fig: Any = None,
    dpi: float = DPI,
) -> Any:
    """Draw a profile in five panels, optionally saved to ``file``.

    The path coloured by speed (start, end, direction of travel); ``v(s)`` against the speed
    limit; lateral acceleration, tangential acceleration and jerk in time against their
    limits.

    Parameters
    ----------
    profile : SpeedProfile
        The planned profile.
    file : path-like, optional
        Where to save the figure; the extension sets the format (PNG, SVG, PDF, ...).
    trajectory : Trajectory, optional
        A sampled trajectory to draw; default ``profile.sample(dt)``.
    dt : float
        Sampling period [s] when ``trajectory`` is not given.
    fig : matplotlib.figure.Figure or SubFigure, optional
        An empty figure to draw into; default a new ``Figure`` (not registered with pyplot,
        so nothing needs closing). A figure without a layout engine is given matplotlib's
        constrained layout, as a new one has, so that the panels' labels do not overlap.
    dpi : float
        Resolution of a saved raster figure [dots per inch].

    Returns
    -------
    matplotlib.figure.Figure
        The figure (``fig``, or the figure holding the SubFigure ``fig``); the panels' axes
        come first in ``fig.axes``, in the order of `PANELS`, then the colour bar.

    Examples
    --------
    >>> import io
    >>> from speedplan import Limits, Path, plan
    >>> from speedplan.plot import plot_profile
    >>> prof = plan(Path.from_waypoints([[0, 0], [10, 0], [10, 8]]),
    ...             Limits(v_max=2, a_max=1, a_lat_max=1, j_max=0.5))
    >>> fig = plot_profile(prof)
    >>> [ax.get_xlabel() for ax in fig.axes[:5]]
    ['x [m]', 's [m]', 't [s]', 't [s]', 't [s]']
    >>> fig.savefig(io.BytesIO(), format="svg")
    """
    traj = trajectory if trajectory is not None else profile.sample(dt)
    fig, axes = _panels(fig, (11, 9.5), [["path", "path"], ["speed", "lateral"],
                                         ["acceleration", "jerk"]], [1.25, 1, 1])
    lim = profile.limits
    zones = profile.request.zones if profile.request is not None else None
    plot_path(traj, axes["path"], v_max=lim.v_max, zones=zones)
    plot_speed(profile, traj, axes["speed"])
    plot_lateral(traj, lim, axes["lateral"])
    plot_acceleration(traj, lim, axes["acceleration"])
    plot_jerk(traj, lim, axes["jerk"])
    return _saved(fig, file, dpi)


#: Panel names of `plot_route`, in ``fig.axes`` order (colour bar last).
ROUTE_PANELS = ("path", "speed", "acceleration", "jerk")


def plot_route(profile: RouteProfile, file: str | PathLike[str] | None = None, *,
               trajectory: Trajectory | None = None, dt: float = 0.01, fig: Any = None,
               dpi: float = DPI) -> Any:
    """Draw a planned route in four panels, optionally saved to ``file``.

    The path with its nodes (labelled with their times) and stops; ``v(s)`` against the
    limits (edge speed limits included) with the nodes marked; acceleration and jerk in time.

    Parameters
    ----------
    profile : RouteProfile
        What [`speedplan.plan_route`][speedplan.plan_route] returned.
    file, trajectory, dt, fig, dpi
        As in [`plot_profile`][speedplan.plot.plot_profile].

    Returns
    -------
    matplotlib.figure.Figure
        The panels' axes first in ``fig.axes``, in the order of `ROUTE_PANELS`.

    Examples
    --------
    A route of one edge, from node A to node B:

    >>> from speedplan import Limits, plan_route
    >>> from speedplan.geometry import Line, Path
    >>> from speedplan.plot import plot_route
    >>> from speedplan.route import Route, RouteEdge, RouteNode
    >>> route = Route([RouteNode("A", 0, (0.0, 0.0)), RouteNode("B", 2, (6.0, 0.0))],
    ...               [RouteEdge("AB", 1, "A", "B", Path.from_segments([Line(6.0)]))])
    >>> fig = plot_route(plan_route(route, Limits(2, 1, 1, 0.5)))
    >>> [ax.get_xlabel() for ax in fig.axes[:4]]
    ['x [m]', 's [m]', 't [s]', 't [s]']
    """
    traj = trajectory if trajectory is not None else profile.sample(dt)
    fig, axes = _panels(fig, (11, 8.5), [["path", "path"], ["speed", "speed"],
                                         ["acceleration", "jerk"]], [1.3, 1, 1])
    lim = profile.legs[0].limits
    route = profile.route
    ax = plot_path(traj, axes["path"], v_max=lim.v_max)
    node_xy = route.path.point(route.node_s)
    stops = np.isin(np.round(route.node_s, 9), np.round(route.stop_s, 9))
    ax.plot(node_xy[~stops, 0], node_xy[~stops, 1], "o", ms=5, color="k", zorder=6,
            label="node (driven through)")
    ax.plot(node_xy[stops, 0], node_xy[stops, 1], "s", ms=7, color="tab:red", zorder=6,
            label="stop")
    for node, (x, y), t_node in zip(route.base_nodes, node_xy, profile.node_times, strict=True):
        when = "" if np.isnan(t_node) else f" {t_node:.1f} s"
        ax.annotate(f"{node.node_id}{when}", (x, y), xytext=(4, 4), textcoords="offset points",
                    fontsize=8, zorder=7)
    _path_legend(ax, "route coloured by speed")
    sp_ax = plot_speed(profile, traj, axes["speed"])
    for node, s in zip(route.base_nodes, route.node_s, strict=True):
        sp_ax.axvline(float(s), color="0.6", lw=0.8, zorder=0)
        sp_ax.annotate(node.node_id, (float(s), 0.0), xytext=(2, 2), textcoords="offset points",
                       fontsize=8, color="0.35")
    sp_ax.set_title(f"speed along the route, duration {profile.duration:.3f} s")
    plot_acceleration(traj, lim, axes["acceleration"])
    plot_jerk(traj, lim, axes["jerk"])
    return _saved(fig, file, dpi)
