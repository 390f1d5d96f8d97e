"""Trajectory exports: exact CSV/JSON round trips, metadata, wrapped heading, file objects."""

from __future__ import annotations

import io
import json
import pickle

import numpy as np
import pytest
from shared import LGV

import speedplan as sp
from speedplan.core.numerics import wrap_heading
from speedplan.io import read_path, read_trajectory
from speedplan.timing.trajectory import COLUMNS


@pytest.fixture(scope="module")
def loop_traj(request):
    # A closed loop: its continuous heading runs from 0 to 2π, beyond [-π, π).
    path = read_path(request.config.rootpath / "paths" / "warehouse_loop.json")
    return sp.plan(path, LGV).sample(0.05)


def numpy_read_csv(text):
    """Independent reader: drop '#' lines, take the header, parse the rest with numpy."""
    lines = [ln for ln in text.splitlines() if not ln.startswith("#")]
    return lines[0].split(","), np.loadtxt(lines[1:], delimiter=",", ndmin=2)


def test_csv_round_trip_is_bitwise_exact_except_the_wrapped_heading(loop_traj, tmp_path):
    f = tmp_path / "t.csv"
    loop_traj.to_csv(f)
    header, data = numpy_read_csv(f.read_text())
    assert header == [f"{k} [{u}]" for k, u in COLUMNS.items()]
    for j, name in enumerate(COLUMNS):
        original = getattr(loop_traj, name)
        if name == "heading":
            continue
        assert np.array_equal(data[:, j], original), name  # bit for bit
    h_file, h_mem = data[:, list(COLUMNS).index("heading")], loop_traj.heading
    assert h_mem.max() > 6.0  # the loop's continuous heading leaves [-π, π)
    assert np.all((h_file >= -np.pi) & (h_file < np.pi))
    # Same direction as the in-memory heading (a multiple of 2π apart) ...
    np.testing.assert_allclose(np.cos(h_file), np.cos(h_mem), atol=1e-12)
    np.testing.assert_allclose(np.sin(h_file), np.sin(h_mem), atol=1e-12)
    # ... and untouched where the in-memory heading was already in range.
    inside = (h_mem >= -np.pi) & (h_mem < np.pi)
    assert inside.any() and np.array_equal(h_file[inside], h_mem[inside])


def test_wrap_heading_against_atan2():
    theta = np.concatenate([np.linspace(-20, 20, 4001), [np.pi, -np.pi, 3 * np.pi, 1e-300]])
    w = wrap_heading(theta)
    assert np.all((w >= -np.pi) & (w < np.pi))
    # Same angle on the circle (compared as angular distance: at ±π a rounding-level
    # difference may land on either side of the cut).
    assert np.abs(np.angle(np.exp(1j * (w - theta)))).max() < 1e-12
    # Away from the cut, equal to atan2's wrapping.
    ref = np.arctan2(np.sin(theta), np.cos(theta))
    far = np.abs(np.abs(ref) - np.pi) > 1e-9
    np.testing.assert_allclose(w[far], ref[far], atol=1e-12)


def test_csv_metadata_lines_before_the_header(loop_traj):
    traj = sp.Trajectory(**loop_traj.to_dict(), metadata={"status": "optimal", "duration": 1.5,
                                                          "limits": LGV, "path_file": "a b.csv"})
    buf = io.StringIO()
    traj.to_csv(buf)
    lines = buf.getvalue().splitlines()
    comments = [ln for ln in lines if ln.startswith("#")]
    assert lines[: len(comments)] == comments  # all of them before the header
    meta = dict(ln[2:].split(": ", 1) for ln in comments)
    assert meta["status"] == "optimal" and meta["path_file"] == "a b.csv"
    assert float(meta["duration"]) == 1.5
    assert json.loads(meta["limits"]) == {"v_max": 2.0, "a_max": 1.0, "a_lat_max": 1.0,
                                          "j_max": 0.5, "a_decel": 1.0, "j_lat_max": None,
                                          "yaw_rate_max": None, "yaw_acc_max": 1.0,
                                          "yaw_jerk_max": None, "grip": "independent"}
    assert meta["speedplan_version"] == sp.__version__
    assert meta["heading_range"] == "[-pi, pi)"


def test_json_has_metadata_units_and_exact_columns(loop_traj, tmp_path):
    traj = sp.Trajectory(**loop_traj.to_dict(), metadata={"gap": np.float64(0.5), "dt": 0.05})
    f = tmp_path / "t.json"
    text = traj.to_json(f)
    assert f.read_text() == text
    doc = json.loads(text)
    assert doc["metadata"]["gap"] == 0.5 and doc["metadata"]["dt"] == 0.05
    assert doc["metadata"]["speedplan_version"] == sp.__version__
    assert doc["units"] == COLUMNS and list(doc["columns"]) == list(COLUMNS)
    assert np.array_equal(np.array(doc["columns"]["v"]), traj.v)
    assert np.all(np.array(doc["columns"]["heading"]) < np.pi)


def test_writers_take_file_objects_and_refuse_missing_directories(loop_traj, tmp_path):
    buf = io.StringIO()
    loop_traj.to_csv(buf)
    f = tmp_path / "t.csv"
    loop_traj.to_csv(f)
    assert buf.getvalue() == f.read_text()
    jbuf = io.StringIO()
    loop_traj.to_json(jbuf)
    assert jbuf.getvalue() == loop_traj.to_json()
    for write in (loop_traj.to_csv, loop_traj.to_json):
        with pytest.raises(sp.InvalidInputError, match="does not exist"):
            write(tmp_path / "no" / "such" / "dir" / "t.csv")


def test_metadata_is_a_read_only_picklable_mapping(loop_traj):
    meta = {"limits": {"v_max": 2.0}, "tags": ["a", "b"]}
    traj = sp.Trajectory(**loop_traj.to_dict(), metadata=meta)
    meta["limits"]["v_max"] = 99.0  # the caller's dict is copied, not shared
    assert traj.metadata["limits"]["v_max"] == 2.0
    with pytest.raises(TypeError):
        traj.metadata["status"] = "x"  # type: ignore[index]
    with pytest.raises(TypeError):
        traj.metadata["limits"]["v_max"] = 1.0
    assert traj.metadata["tags"] == ("a", "b")
    back = pickle.loads(pickle.dumps(traj))
    assert dict(back.metadata) == dict(traj.metadata)
    assert len(sp.Trajectory(**loop_traj.to_dict()).metadata) == 0  # default: empty


def test_a_sampled_trajectory_file_says_how_it_was_made(tmp_path):
    # A file written straight from the library (no CLI) must be interpretable later: version,
    # certificate, limits and inputs, as plan() was called and as the profile reports them.
    lim = sp.Limits(v_max=1.5, a_max=0.8, a_lat_max=0.9, j_max=0.4)
    profile = sp.plan(sp.Path.from_waypoints([[0, 0], [6, 0], [9, 3]]), lim, v0=0.5, a0=0.1)
    out = tmp_path / "t.json"
    profile.sample(0.02).to_json(out)
    meta = json.loads(out.read_text())["metadata"]
    assert meta["speedplan_version"] == sp.__version__
    assert meta["duration"] == profile.duration and meta["status"] == profile.status
    assert meta["gap"] == profile.gap and meta["dt"] == 0.02
    assert meta["limits"]["v_max"] == 1.5 and meta["limits"]["j_max"] == 0.4
    assert meta["boundary"] == {"v0": 0.5, "a0": 0.1, "vf": 0.0, "af": 0.0}
    assert meta["grid_nodes"] == profile.s.size


def test_read_trajectory_round_trip(loop_traj, tmp_path):
    traj = sp.Trajectory(**loop_traj.to_dict(), metadata={"status": "optimal", "gap": 0.25})
    for name in ("t.csv", "t.json"):
        f = tmp_path / name
        (traj.to_csv if name.endswith("csv") else traj.to_json)(f)
        back = read_trajectory(f)
        for c in COLUMNS:
            if c != "heading":
                assert np.array_equal(getattr(back, c), getattr(traj, c)), (name, c)
        # Unwrapped again: continuous, 2π-multiple away from the original.
        assert np.abs(np.diff(back.heading)).max() < 1.0
        k = (traj.heading - back.heading) / (2 * np.pi)
        np.testing.assert_allclose(k, np.round(k), atol=1e-9)
        assert back.metadata["status"] == "optimal" and back.metadata["gap"] == 0.25
    with pytest.raises(sp.InvalidInputError, match="missing"):
        read_trajectory(io.StringIO("x,y\n0,0\n1,1\n"))


def test_a_route_trajectory_comes_back_with_its_edges(tmp_path):
    # It came back as a plain Trajectory, its edge column dropped.
    route = sp.Route.from_vda5050("paths/orders/order_v2.json")
    traj = sp.plan_route(route, LGV).sample(0.05)
    assert np.unique(traj.edge).size > 1
    for name in ("r.csv", "r.json"):
        f = tmp_path / name
        (traj.to_csv if name.endswith("csv") else traj.to_json)(f)
        back = read_trajectory(f)
        assert isinstance(back, sp.route.RouteTrajectory), name
        assert np.array_equal(back.edge, traj.edge) and np.array_equal(back.v, traj.v)
        assert back.metadata["edge_ids"] == traj.metadata["edge_ids"]


def test_to_dict_keeps_the_continuous_heading(loop_traj):
    d = loop_traj.to_dict()
    assert list(d) == list(COLUMNS)
    assert d["heading"] is loop_traj.heading
