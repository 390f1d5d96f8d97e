"""Without a jerk limit the continuous law stays under the speed bound between nodes.

The law of a request without jerk (or lateral-jerk) limit is ``w`` linear on each cell: it
passes through the nodes and stays on the chords, which the node bounds (the bound's minimum
over both adjacent cells) keep under ``mu+``. The C¹ dual-cell law, built to spread a jerk
switch, rose above both nodes after a braking node onto a bound step (a corner, a zone) and
made the first check of a uniform grid fail there (``aisle_corners.csv``: 1.0015× its speed
bound at n = 1000), so every such plan solved and checked twice.

Oracles: the bound itself on dense samples, and the exact continuous no-jerk optimum
(:func:`oracles.no_jerk_lower_bound`), which no feasible law beats.
"""

from __future__ import annotations

import math
from dataclasses import replace
from pathlib import Path as FsPath

import numpy as np
import pytest
from oracles import no_jerk_lower_bound
from shared import LGV

import speedplan as sp
from speedplan.io import read_path, read_zones
from speedplan.model import PlanRequest, build_model
from speedplan.timing import SpeedProfile, TimeLaw
from speedplan.timing.verify import bound_breakpoints

PATHS = FsPath(__file__).resolve().parents[2] / "paths"
NO_JERK = replace(LGV, j_max=math.inf)
ROAD = sp.Limits(v_max=15.0, a_max=2.0, a_lat_max=3.0, j_max=math.inf)


def sample_cases():
    out = []
    for f in sorted(p for p in PATHS.iterdir() if p.suffix in (".csv", ".json")):
        if f.name.startswith("nurbs"):
            continue  # its arc-length inversion makes the dense oracle slow; no bound steps
        zones = read_zones(str(f))
        out.append(pytest.param(read_path(str(f)), ROAD if "road" in f.name else NO_JERK,
                                {"zones": zones} if zones else {}, id=f.name))
    serp = [(x, 3.0 * row) for row in range(10)
            for x in ((0.0, 10.0) if row % 2 == 0 else (10.0, 0.0))]
    out.append(pytest.param(sp.Path.from_waypoints(np.array(serp)), NO_JERK, {},
                            id="serpentine"))
    return out


def first_profile(path, lim, kw, n):
    """The profile of the first solve on the uniform grid, before any refinement."""
    from speedplan.strategy import solve_leg

    req = PlanRequest.create(path, lim, n=n, **kw)
    model = build_model(req)
    legs = tuple(solve_leg(leg) for leg in model.legs)
    return SpeedProfile(path=path, limits=lim, legs=legs, speed_bound=model.bound, request=req)


def dense_ratio(prof, per_cell=16):
    """Largest ``w_law / mu+`` over dense samples of every cell and the bound's breakpoints."""
    worst = 0.0
    for leg in prof.legs:
        s = leg.s
        frac = np.linspace(0.0, 1.0, per_cell + 1)
        q = (s[:-1, None] + np.diff(s)[:, None] * frac).ravel()
        breaks = bound_breakpoints(prof.path, prof.speed_bound) - leg.start
        eps = 1e-9 * max(float(s[-1]), 1.0)
        around = np.concatenate((breaks - eps, breaks, breaks + eps))
        q = np.concatenate((q, around[(around >= 0) & (around <= s[-1])]))
        w = leg.law.kinematics(q)[0]
        mu = prof.speed_bound(leg.start + q)
        with np.errstate(divide="ignore", invalid="ignore"):
            ratio = np.where(mu > 0, w / mu, np.where(w > 0, np.inf, 0.0))
        worst = max(worst, float(ratio.max()))
    return worst


@pytest.mark.parametrize("n", [1000, 1001, 1237])
def test_the_first_law_of_a_uniform_grid_passes_its_check_at_corners(n):
    path = read_path(str(PATHS / "aisle_corners.csv"))  # line-arc joins: bound steps
    prof = first_profile(path, NO_JERK, {}, n)
    assert prof.legs[0].law.linear
    assert all(prof.check_leg(i).verification.ok for i in range(len(prof.legs)))
    # Independently of verify(): the law under the bound everywhere, to rounding.
    assert dense_ratio(prof) <= 1.0 + 1e-12
    # plan() keeps that grid: nothing to refine.
    planned = sp.plan(path, NO_JERK, n=n)
    assert planned.status == "optimal" and planned.verify().ok
    assert [leg.s.size for leg in planned.legs] == [n]


@pytest.mark.parametrize(("path", "lim", "kw"), sample_cases())
def test_no_jerk_plans_are_under_the_bound_and_never_beat_the_exact_optimum(path, lim, kw):
    prof = first_profile(path, lim, kw, 1001)
    assert dense_ratio(prof) <= 1.0 + 1e-12
    planned = sp.plan(path, lim, **kw)
    assert planned.verify().ok
    # Durations: a feasible law cannot beat the exact continuous optimum; the uniform grid
    # costs O(h) where the bound falls steeply (a node takes the minimum over both adjacent
    # cells): 3.9 % on the serpentine, so the default grid is refined once where the optimum
    # rides such a node bound (model.leg_grid.no_jerk_grid): 1.0 % there.
    bound = planned.speed_bound
    t_exact, _, _ = no_jerk_lower_bound(bound, path.length, lim.a_max, lim.a_decel)
    assert t_exact <= planned.duration
    assert planned.duration <= 1.02 * t_exact


def test_the_linear_law_on_a_straight_matches_the_closed_form():
    # Rest to rest over 30 m at v_max = 2, a = 1: 2 s up, 13 s cruise, 2 s down = 17 s.
    path = sp.Path.from_waypoints([[0, 0], [30, 0]], kind="polyline")
    prof = sp.plan(path, NO_JERK, n=301)  # h = 0.1: the kinks at 2 m and 28 m are nodes
    assert prof.duration == pytest.approx(17.0, rel=1e-12)
    coarse = sp.plan(path, NO_JERK, n=298)  # kinks between nodes: the chord there is slower
    t_exact, _, _ = no_jerk_lower_bound(prof.speed_bound, 30.0, 1.0, 1.0)
    # A lower bound: between its samples the oracle's law may rise above v_max by 2 a Δ.
    assert 17.0 * (1 - 1e-5) <= t_exact <= 17.0
    assert 17.0 < coarse.duration < 17.0 * (1 + 1e-3)
    traj = coarse.sample(0.01)
    assert traj.v.max() <= 2.0 * (1 + 1e-12) and np.abs(traj.a).max() <= 1.0 * (1 + 1e-9)


def test_a_linear_law_is_the_chord_through_the_nodes():
    s = np.linspace(0.0, 3.0, 31)
    w = np.minimum(np.minimum(2.0 * s, 1.5), 2.0 * (3.0 - s)) + 0.1
    law = TimeLaw(s, w, linear=True)
    q = np.linspace(0.0, 3.0, 3001)
    ww, _, a, j = law.kinematics(q)
    assert np.allclose(ww, np.interp(q, s, w), rtol=0, atol=1e-14)
    assert np.allclose(law.node_offsets(), 0.0, atol=1e-15)
    assert np.abs(a).max() <= 1.0 + 1e-12 and not j.any()
    cell_time = 2.0 * np.diff(s) / (np.sqrt(w[:-1]) + np.sqrt(w[1:]))
    assert law.duration == pytest.approx(cell_time.sum(), rel=1e-14)
    # time_at (Gauss-Legendre within a piece) against the closed form 2 d / (v_a + v(s)).
    k = np.searchsorted(s, q[1:-1], side="right") - 1
    d = q[1:-1] - s[k]
    closed = (np.concatenate(([0.0], np.cumsum(cell_time)))[k]
              + 2.0 * d / (np.sqrt(w[k]) + np.sqrt(np.interp(q[1:-1], s, w))))
    assert law.time_at(q[1:-1]) == pytest.approx(closed, rel=1e-13)
    t = np.linspace(0.0, law.duration, 501)
    assert np.allclose(law.time_at(law.position_at(t)), t, rtol=0, atol=1e-12)
    with pytest.raises(sp.InvalidInputError, match="linear"):
        TimeLaw(s, w, accel_start=0.0, linear=True)


def test_the_linear_law_in_time_is_constant_acceleration_per_cell():
    # Rest to rest through a slow stretch: both standstill ends, accelerating and braking cells.
    s = np.linspace(0.0, 12.0, 61)
    mu = np.where(np.abs(s - 6.0) < 1.0, 0.5, 4.0)
    mu[0] = mu[-1] = 0.0
    w = (mu[None, :] + 2.0 * np.abs(s[:, None] - s[None, :])).min(axis=1)  # |a| <= 1
    law = TimeLaw(s, w, linear=True)
    t = np.linspace(0.0, law.duration, 4001)
    q, ww, v, a, _ = law.state_at(t)
    # The time law against the closed form of each cell: s(t) from the node times.
    T = law.node_times
    k = np.clip(np.searchsorted(T, t, side="right") - 1, 0, s.size - 2)
    tau = t - T[k]
    acc = (w[k + 1] - w[k]) / (2.0 * np.diff(s)[k])
    expected = s[k] + np.sqrt(w[k]) * tau + 0.5 * acc * tau**2
    assert np.allclose(q, expected, rtol=0, atol=1e-12)
    assert np.allclose(ww, np.interp(q, s, w), rtol=0, atol=1e-12)
    assert np.allclose(v, np.sqrt(w[k]) + acc * tau, rtol=0, atol=1e-9)
    inside = (tau > 1e-9) & (T[k + 1] - t > 1e-9)
    assert np.allclose(a[inside], acc[inside], rtol=0, atol=1e-12)
    # Finite differences of the sampled states: the trapezoid rule is off by at most
    # |Δa| dt / 8 where the acceleration jumps (|Δa| <= 2), the speed changes by <= a dt.
    dt = t[1] - t[0]
    assert np.abs(np.diff(q) / dt - 0.5 * (v[1:] + v[:-1])).max() <= 2.0 * dt / 8 + 1e-9
    assert np.abs(np.diff(v) / dt).max() <= 1.0 + 1e-9
    assert law.position_at(np.array([law.duration]))[0] == 12.0
    # Next to the final stop the offset from it keeps its relative precision.
    eps = 1e-9
    _, dr = law._invert(np.array([law.duration - eps]))[1:]
    assert dr[0] == pytest.approx(0.5 * eps**2, rel=1e-9)  # a = -1: dr = a τ² / 2
