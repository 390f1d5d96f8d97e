"""The speed bound's memo: the same numbers, each position evaluated once per plan."""

from __future__ import annotations

import math
import pickle

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from shared import LGV

import speedplan as sp
from speedplan.geometry import CellSamples, SpeedBound
from speedplan.io import read_path, read_zones
from speedplan.model.grid import PAD_CELLS, subdivided_grid

NO_JERK = sp.Limits(v_max=LGV.v_max, a_max=LGV.a_max, a_lat_max=LGV.a_lat_max, j_max=math.inf)


def _bound(name: str) -> SpeedBound:
    return SpeedBound(read_path(f"paths/{name}"), LGV, read_zones(f"paths/{name}"))


@pytest.mark.parametrize("name", ["nurbs_edge.json", "slow_zone.json"])
@settings(max_examples=25, deadline=None)
@given(data=st.data())
def test_memoised_bound_gives_the_plain_bounds_numbers(name, data):
    plain = _bound(name)
    memo = plain.memoised()
    assert memo.memo is not None
    length = plain.path.length
    seen: list[np.ndarray] = []
    for _ in range(data.draw(st.integers(1, 5))):
        fresh = np.asarray(data.draw(st.lists(st.floats(0.0, length), min_size=1,
                                              max_size=40)))
        # Queries mix new positions, positions seen before (exactly), and repeats.
        q = np.concatenate([fresh, *seen[-2:], fresh[:3]])
        seen.append(fresh)
        offset = data.draw(st.sampled_from([0.0, 0.5 * length]))
        local = q[q >= offset] - offset
        kappa, w = memo.at_offset(offset).curvature_and_bound(local)
        np.testing.assert_array_equal(w, plain.at_offset(offset)(local))
        np.testing.assert_array_equal(kappa, plain.path.curvature(local + offset))
        np.testing.assert_array_equal(memo.at_offset(offset)(local), w)
    keys = memo.memo._table[0]
    assert np.all(np.diff(keys) > 0)  # sorted, each position once


@pytest.mark.parametrize("name", ["nurbs_edge.json", "slow_zone.json"])
@pytest.mark.parametrize("limits", [LGV, NO_JERK], ids=["jerk", "no_jerk"])
def test_plans_with_and_without_the_memo_are_bitwise_equal(name, limits, monkeypatch):
    path, zones = read_path(f"paths/{name}"), read_zones(f"paths/{name}")
    calls = {"n": 0}
    curvature = sp.Path.curvature

    def counted(self, s):
        calls["n"] += np.size(s)
        return curvature(self, s)

    monkeypatch.setattr(sp.Path, "curvature", counted)
    with_memo = sp.plan(path, limits, zones=zones)
    evaluated = calls["n"]
    monkeypatch.setattr(SpeedBound, "memoised", lambda self: self)
    calls["n"] = 0
    without = sp.plan(path, limits, zones=zones)
    assert with_memo.duration == without.duration
    for a, b in zip(with_memo.legs, without.legs, strict=True):
        np.testing.assert_array_equal(a.s, b.s)
        np.testing.assert_array_equal(a.solution.w, b.solution.w)
    assert with_memo.verification == without.verification
    if math.isfinite(limits.j_max):
        assert evaluated < calls["n"]
    else:  # the law's check reads the bound the model sampled: no position comes back
        assert evaluated <= calls["n"]
    # The profile a caller keeps does not carry the plan's memo.
    assert with_memo.speed_bound.memo is None


def test_memo_is_not_used_where_evaluating_is_cheap_and_pickles_empty():
    line = sp.Path.from_waypoints([(0, 0), (10, 0), (10, 5)])
    assert SpeedBound(line, LGV).memoised().memo is None
    bound = _bound("nurbs_edge.json").memoised()
    q = np.linspace(0.0, bound.path.length, 50)
    expected = bound(q)
    assert bound.memo.size == 50
    copy = pickle.loads(pickle.dumps(bound))
    assert copy.memo is not None and copy.memo.size == 0
    np.testing.assert_array_equal(copy(q), expected)


@settings(max_examples=50, deadline=None)
@given(n=st.integers(2, 200), flags=st.lists(st.integers(0, 198), max_size=5),
       parts=st.integers(2, 6), length=st.floats(1e-3, 1e4))
def test_subdivided_grid_keeps_every_other_cell_to_the_last_bit(n, flags, parts, length):
    s = np.linspace(0.0, length, n)
    cells = np.zeros(n - 1, dtype=bool)
    cells[[k for k in flags if k < n - 1]] = True
    g = subdivided_grid(s, cells, parts=parts)
    assert np.all(np.diff(g) > 0)
    assert np.isin(s, g).all()
    near = np.zeros(n - 1, dtype=bool)
    for k in np.flatnonzero(cells):
        near[max(k - PAD_CELLS, 0):k + PAD_CELLS + 1] = True
    # Inside each old cell: parts - 1 new nodes where flagged (or near), none elsewhere.
    inside = np.searchsorted(s, g[~np.isin(g, s)], side="right") - 1
    counts = np.bincount(inside, minlength=n - 1)
    np.testing.assert_array_equal(counts, np.where(near, parts - 1, 0))


@pytest.mark.parametrize("name", ["nurbs_edge.json", "slow_zone.json", "warehouse_loop.json"])
@settings(max_examples=10, deadline=None)
@given(n=st.integers(2, 300), flags=st.lists(st.integers(0, 298), max_size=6),
       offset=st.sampled_from([0.0, 0.25]))
def test_cell_samples_of_a_refined_grid_keep_the_cells_it_keeps(name, n, flags, offset):
    # What on_grid copies from the coarser grid's samples is what evaluating gives there.
    bound = _bound(name).at_offset(offset * _bound(name).path.length)
    length = (1.0 - offset) * bound.path.length
    s = np.linspace(0.0, length, n)
    cells = np.zeros(n - 1, dtype=bool)
    cells[[k for k in flags if k < n - 1]] = True
    grid = subdivided_grid(s, cells)
    extra = np.array([0.1 * length, 0.5 * length])
    refined = CellSamples.of(bound, s, extra=extra).on_grid(bound, grid)
    fresh = CellSamples.of(bound, grid, extra=extra)
    for field in ("s", "points", "curvature", "bound", "extra", "extra_curvature",
                  "extra_bound"):
        np.testing.assert_array_equal(getattr(refined, field), getattr(fresh, field))
    assert refined.offset == fresh.offset == bound.offset


def test_cell_samples_refuse_a_bound_read_from_another_offset():
    bound = _bound("slow_zone.json")
    samples = CellSamples.of(bound, np.linspace(0.0, 10.0, 11))
    with pytest.raises(sp.InvalidInputError, match="offset"):
        samples.on_grid(bound.at_offset(1.0), np.linspace(0.0, 10.0, 21))


SERPENTINE = np.array([(x, 3.0 * row) for row in range(10)
                       for x in ((0.0, 10.0) if row % 2 == 0 else (10.0, 0.0))])


@pytest.mark.parametrize("name", ["aisle_corners.csv", "nurbs_edge.json", "slow_zone.json",
                                  "u_turn.json", "warehouse_loop.json", "serpentine"])
def test_a_no_jerk_plan_evaluates_the_curvature_once_per_point(name, monkeypatch):
    # The model samples the bound at 8 points per cell of its grid (the node bounds), the
    # law's check reads them there: each point is evaluated once, plus the cells a refinement
    # of the first grid cut in four (evaluated on both grids), without the memo's lookups.
    # Paths of lines, arcs and clothoids (no memo) had their curvature evaluated three times
    # a point: the node bounds again on the refined grid, and the check on its own.
    if name == "serpentine":
        path, zones = sp.Path.from_waypoints(SERPENTINE), None
    else:
        path, zones = read_path(f"paths/{name}"), read_zones(f"paths/{name}")
    calls = {"n": 0}
    curvature = sp.Path.curvature

    def counted(self, s):
        calls["n"] += np.size(s)
        return curvature(self, s)

    monkeypatch.setattr(sp.Path, "curvature", counted)
    prof = sp.plan(path, NO_JERK, zones=zones)
    points = sum(8 * (leg.s.size - 1) + 1 for leg in prof.legs)
    assert prof.verification is not None and prof.verification.ok
    assert calls["n"] <= 1.2 * points
