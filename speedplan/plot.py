"""Plots of a planned profile (matplotlib, from the ``plot`` extra, imported lazily)."""

from __future__ import annotations

from os import PathLike
from typing import TYPE_CHECKING, Any

import numpy as np

from .core.errors import SpeedplanError

if TYPE_CHECKING:
    from .timing import SpeedProfile, Trajectory

__all__ = ["plot_profile"]


def _pyplot() -> Any:
    try:
        import matplotlib

        if matplotlib.get_backend().lower() not in ("agg", "module://matplotlib_inline.backend_inline"):
            matplotlib.use("Agg", force=False)
        import matplotlib.pyplot as plt
    except ImportError as exc:  # pragma: no cover - exercised only without the extra
        raise SpeedplanError(
            "plotting needs matplotlib: pip install 'speedplan[plot]'"
        ) from exc
    return plt


def plot_profile(
    profile: SpeedProfile,
    file: str | PathLike[str] | None = None,
    *,
    trajectory: Trajectory | None = None,
    dt: float = 0.01,
) -> Any:
    """Draw a profile in four panels, optionally saved to ``file``.

    The path coloured by speed; ``v(s)`` against ``sqrt(mu+(s))``; ``a(t)`` and ``a_lat(t)``
    against their limits; ``j(t)`` against ``±j_max``.

    Parameters
    ----------
    profile : SpeedProfile
        The planned profile.
    file : path-like, optional
        Where to save the figure (PNG, SVG, PDF by extension).
    trajectory : Trajectory, optional
        A sampled trajectory to draw; default ``profile.sample(dt)``.
    dt : float
        Sampling period [s] when ``trajectory`` is not given.

    Returns
    -------
    matplotlib.figure.Figure
    """
    plt = _pyplot()
    traj = trajectory if trajectory is not None else profile.sample(dt)
    lim = profile.limits
    fig, axes = plt.subplots(2, 2, figsize=(11, 7.5), constrained_layout=True)
    ax = axes[0, 0]
    from matplotlib.collections import LineCollection

    pts = np.column_stack((traj.x, traj.y))
    segs = np.stack((pts[:-1], pts[1:]), axis=1)
    speed = 0.5 * (traj.v[:-1] + traj.v[1:])
    lc = LineCollection(list(segs), array=speed, cmap="viridis", linewidths=3)
    ax.add_collection(lc)
    ax.autoscale()
    ax.set_aspect("equal", adjustable="datalim")
    fig.colorbar(lc, ax=ax, label="speed v [m/s]")
    ax.plot(traj.x[0], traj.y[0], "go", label="start")
    ax.plot(traj.x[-1], traj.y[-1], "rs", label="end")
    ax.set(xlabel="x [m]", ylabel="y [m]", title="path coloured by speed")
    ax.legend(loc="best", fontsize=8)

    ax = axes[0, 1]
    s_fine = np.linspace(0.0, profile.path.length, 2000)
    ax.plot(s_fine, np.sqrt(profile.speed_bound(s_fine)), "k--", lw=1, label="bound sqrt(mu+(s))")
    ax.plot(traj.s, traj.v, "C0", lw=2, label="v(s)")
    ax.set(xlabel="s [m]", ylabel="v [m/s]", title=f"speed law, duration {profile.duration:.3f} s")
    ax.legend(loc="best", fontsize=8)

    ax = axes[1, 0]
    ax.plot(traj.t, traj.a, "C1", label="a(t) tangential")
    ax.plot(traj.t, traj.a_lat, "C2", label="a_lat(t) lateral")
    ax.axhline(lim.a_max, color="C1", ls="--", lw=1)
    ax.axhline(-lim.a_decel, color="C1", ls="--", lw=1)
    if np.isfinite(lim.a_lat_max):
        for sign in (1, -1):
            ax.axhline(sign * lim.a_lat_max, color="C2", ls=":", lw=1)
    ax.set(xlabel="t [s]", ylabel="acceleration [m/s²]", title="accelerations and limits")
    ax.legend(loc="best", fontsize=8)

    ax = axes[1, 1]
    ax.plot(traj.t, traj.j, "C3", label="j(t)")
    if np.isfinite(lim.j_max):
        for sign in (1, -1):
            ax.axhline(sign * lim.j_max, color="C3", ls="--", lw=1)
    ax.set(xlabel="t [s]", ylabel="jerk [m/s³]", title="jerk and limit")
    ax.legend(loc="best", fontsize=8)
    if file is not None:
        fig.savefig(file, dpi=110)
    return fig
