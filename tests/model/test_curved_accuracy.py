"""The default grid's duration on curved paths: within 1e-4 of the converged duration.

Oracles: ruckig's exact straight move (a circle from rest to rest), and, on the sample paths,
the Richardson extrapolation of the same plan on its default grid with every cell cut into
two and four equal steps.
"""

from __future__ import annotations

import os

import numpy as np
import pytest
from oracles import ruckig_duration, subdivided_default_grids
from shared import LGV

import speedplan as sp
from speedplan.geometry import Arc
from speedplan.io import read_path, read_zones

PATHS = os.path.join(os.path.dirname(__file__), "..", "..", "paths")
ACCURACY = 1e-4


def _limits(v_max: float) -> sp.Limits:
    return sp.Limits(v_max=v_max, a_max=LGV.a_max, a_lat_max=LGV.a_lat_max, j_max=LGV.j_max)


@pytest.mark.parametrize(("radius", "angle"), [(1.5, np.pi), (4.0, 2.0), (0.6, 5.0)])
def test_a_circle_from_rest_to_rest_takes_the_straight_move_under_its_lateral_speed(radius,
                                                                                     angle):
    # On an arc the speed bound is the constant sqrt(a_lat_max R): the move is ruckig's
    # straight move of the arc's length under that speed.
    v_arc = min(LGV.v_max, np.sqrt(LGV.a_lat_max * radius))
    profile = sp.plan(sp.Path.from_segments([Arc(radius=radius, angle=angle)]), LGV)
    exact = ruckig_duration(radius * angle, _limits(v_arc))
    assert profile.duration == pytest.approx(exact, rel=ACCURACY)


def _converged(path: sp.Path, lim: sp.Limits, zones) -> tuple[float, float]:
    """Richardson's limit of the subdivided grids (second order) and its own spread."""
    durations = []
    for k in (2, 4):
        with subdivided_default_grids(k):
            durations.append(sp.plan(path, lim, zones=zones).duration)
    coarse, fine = durations
    return fine + (fine - coarse) / 3.0, abs(fine - coarse) / fine


COMFORT = sp.Limits(v_max=2.0, a_max=1.0, a_lat_max=1.0, j_max=0.5, j_lat_max=0.3,
                    yaw_rate_max=0.4)


@pytest.mark.filterwarnings("ignore:the path.s curvature jumps")  # aisle_corners.csv: stops
@pytest.mark.parametrize(("name", "lim"), [
    ("u_turn.json", LGV), ("warehouse_loop.json", LGV), ("aisle_corners.csv", LGV),
    ("slow_zone.json", LGV), ("nurbs_edge.json", LGV), ("u_turn.json", COMFORT),
    ("warehouse_loop.json", COMFORT), ("aisle_corners.csv", COMFORT)],
    ids=lambda x: x if isinstance(x, str) else "comfort" if x.j_lat_max < np.inf else "plain")
def test_sample_paths_plan_within_1e4_of_the_converged_duration(name, lim):
    # Before: 3.4e-4 (u_turn), 3.3e-4 (warehouse_loop), 9.8e-4 (aisle_corners), 2.8e-4
    # (slow_zone) above it: the node bounds took the least bound over both cells, O(h) where
    # it falls, and a kink of the bound (a clothoid onto an arc, a zone's edge) fell inside a
    # cell, at a place that changed with the grid.
    path = read_path(os.path.join(PATHS, name))
    zones = read_zones(os.path.join(PATHS, name)) or None
    duration = sp.plan(path, lim, zones=zones).duration
    converged, spread = _converged(path, lim, zones)
    assert spread < ACCURACY / 4  # the reference is converged far below the target
    assert duration == pytest.approx(converged, rel=ACCURACY)
