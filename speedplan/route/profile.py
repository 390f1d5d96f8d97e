"""RouteProfile: the stop-to-stop speed profiles of a route, stitched into one motion."""

from __future__ import annotations

from dataclasses import dataclass, field, replace
from functools import cached_property
from typing import Any

import numpy as np

from .._version import __version__
from ..core.checks import FloatArray, as_array
from ..core.errors import InvalidInputError
from ..timing import SpeedProfile, Trajectory, Verification
from ..timing.profile import sample_times
from ..timing.trajectory import COLUMNS
from .route import Route

__all__ = ["RouteProfile", "RouteTrajectory"]


@dataclass(frozen=True)
class RouteTrajectory(Trajectory):
    """A [`Trajectory`][speedplan.Trajectory] along a route, with the edge each sample is on.

    Attributes
    ----------
    edge : ndarray
        Index into ``route.edges`` of the edge under the vehicle (at a node, the edge after
        it); the ids are in ``metadata["edge_ids"]``. Exported as the last column.
    """

    edge: FloatArray = field(default_factory=lambda: np.zeros(0))

    @property
    def units(self) -> dict[str, str]:
        """`COLUMNS` and ``edge``."""
        return {**COLUMNS, "edge": "1"}


@dataclass(frozen=True, eq=False)
class RouteProfile:
    """The minimum-time motion along a route: one [`SpeedProfile`][speedplan.SpeedProfile] per leg.

    The vehicle stops between legs (at `Route.stop_s`) and drives through every other
    node; each leg was planned on its own (see [`speedplan.plan_route`][speedplan.plan_route]).

    Attributes
    ----------
    route : Route
        What was planned.
    legs : tuple of SpeedProfile
        One per stop-to-stop leg from [`start_s`][speedplan.RouteProfile] on, in order.
    leg_starts : tuple of float
        Where each leg starts along ``route.path`` [m]; the last leg ends at the route's end.
    start_s : float
        Where the motion starts along the route [m] (0, or where an order update took over).
    """

    route: Route
    legs: tuple[SpeedProfile, ...]
    leg_starts: tuple[float, ...]
    start_s: float = 0.0

    def __post_init__(self) -> None:
        if not self.legs or len(self.legs) != len(self.leg_starts):
            raise InvalidInputError("a RouteProfile needs one leg start per leg, and a leg")

    @property
    def duration(self) -> float:
        """Time from [`start_s`][speedplan.RouteProfile] to the end of the route [s]."""
        return float(self.leg_times[-1])

    @cached_property
    def leg_times(self) -> FloatArray:
        """Start time of each leg, then the duration [s]."""
        out = np.concatenate(([0.0], np.cumsum([leg.duration for leg in self.legs])))
        out.flags.writeable = False
        return out

    @cached_property
    def node_times(self) -> FloatArray:
        """When the vehicle is on each released node [s from the start], in order.

        ``NaN`` for the nodes behind `start_s` (already passed when an order update
        took over); increasing from there to `duration` at the last node. At a stop,
        the time of arrival.
        """
        node_s = self.route.node_s
        out = np.full(node_s.size, np.nan)
        tol = 1e-9 * max(self.route.length, 1.0)
        for k, s in enumerate(node_s):
            if s < self.start_s - tol:
                continue
            j = self._leg_holding(float(s))
            leg = self.legs[j]
            local = np.clip(float(s) - self.leg_starts[j], 0.0, leg.path.length)
            out[k] = self.leg_times[j] + float(leg.law.time_at(np.array([local]))[0])
        out.flags.writeable = False
        return out

    def _leg_holding(self, s: float) -> int:
        """The leg whose stretch holds ``s`` (the earlier at a stop between two legs)."""
        starts = np.asarray(self.leg_starts)
        return int(np.clip(np.searchsorted(starts, s, side="left") - 1, 0, len(self.legs) - 1))

    @property
    def status(self) -> str:
        """The worst status of the legs.

        ``"limits_exceeded"``, else ``"relaxed"``, ``"scaled"`` or ``"refined"`` if a leg has
        it, else ``"optimal"``.
        """
        statuses = {leg.status for leg in self.legs}
        for worst in ("limits_exceeded", "relaxed", "scaled", "refined"):
            if worst in statuses:
                return worst
        return "optimal"

    @property
    def gap(self) -> float:
        """Certified relative gap of the whole motion.

        ``(Σ objective - Σ lower bound) / Σ lower bound`` over the legs' discrete problems.
        """
        lower = sum(leg.solution.lower_bound for leg in self.legs)
        upper = sum(leg.solution.objective for leg in self.legs)
        return float((upper - lower) / lower) if lower > 0 else 0.0

    def verify(self) -> Verification:
        """The legs' checks of the continuous trajectory against every limit, merged."""
        return Verification.merged([leg.verify() for leg in self.legs])

    @property
    def verification(self) -> Verification:
        """The checks [`speedplan.plan`][speedplan.plan] made of each leg, merged."""
        return Verification.merged([leg.verification or leg.verify() for leg in self.legs])

    # ---- sampling in time -------------------------------------------------------------------
    def edge_at(self, s: Any) -> FloatArray:
        """Index into ``route.edges`` of the edge at arc lengths ``s`` along the route."""
        q = as_array("s", s)
        node_s = self.route.node_s
        n_edges = len(self.route.base_edges)
        idx = np.clip(np.searchsorted(node_s, q, side="right") - 1, 0, n_edges - 1)
        out: FloatArray = idx.astype(np.float64)
        return out

    def at(self, t: Any) -> RouteTrajectory:
        """States at times ``t`` [s from the start] (clipped to ``[0, duration]``)."""
        times = np.clip(np.atleast_1d(as_array("t", t)), 0.0, self.duration)
        j = np.clip(np.searchsorted(self.leg_times, times, side="right") - 1, 0,
                    len(self.legs) - 1)
        parts: dict[str, list[FloatArray]] = {}
        order = np.argsort(j, kind="stable")
        for k in np.unique(j):
            sel = order[j[order] == k]
            leg_traj = self.legs[k].at(times[sel] - self.leg_times[k])
            for name, values in leg_traj.to_dict().items():
                parts.setdefault(name, []).append(values)
            parts.setdefault("_index", []).append(sel.astype(np.float64))
        index = np.concatenate(parts.pop("_index")).astype(np.intp)
        inverse = np.empty_like(index)
        inverse[index] = np.arange(index.size)
        cols = {name: np.concatenate(values)[inverse] for name, values in parts.items()}
        starts = np.asarray(self.leg_starts)[j]
        cols["t"] = times
        cols["s"] = cols["s"] + starts
        return RouteTrajectory(**cols, edge=self.edge_at(cols["s"]),
                               metadata=self._metadata())

    def sample(self, dt: float = 0.01) -> RouteTrajectory:
        """The motion sampled every ``dt`` seconds from 0; the last sample is at the end.

        Parameters
        ----------
        dt : float
            Sampling period [s], > 0.
        """
        traj = self.at(sample_times(self.duration, dt))
        return replace(traj, metadata={**traj.metadata, "dt": float(dt)})

    def _metadata(self) -> dict[str, Any]:
        route = self.route
        return {
            "speedplan_version": __version__,
            "duration": self.duration,
            "status": self.status,
            "gap": self.gap,
            "start_s": self.start_s,
            "order_id": route.order_id,
            "order_update_id": route.order_update_id,
            "node_ids": [n.node_id for n in route.base_nodes],
            "node_s": route.node_s.tolist(),
            "node_times": [None if np.isnan(x) else float(x) for x in self.node_times],
            "stop_s": route.stop_s.tolist(),
            "edge_ids": [e.edge_id for e in route.base_edges],
            "limits": self.legs[0].limits,
        }

    def __repr__(self) -> str:
        return (f"RouteProfile(duration={self.duration:.6g} s, length={self.route.length:.6g} m, "
                f"legs={len(self.legs)}, status={self.status!r})")
