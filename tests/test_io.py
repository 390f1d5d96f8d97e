"""Path files: readers, writers, round trips, bad files, the shipped samples."""

from __future__ import annotations

import json
import re
from pathlib import Path as FsPath

import numpy as np
import pytest
import shapely

from speedplan import InvalidInputError, Path, SpeedZone
from speedplan.geometry import Arc, Clothoid, Line
from speedplan.io import (
    path_to_dict,
    read_path,
    read_zones,
    write_path,
    write_trajectory,
    write_waypoints,
)

ROOT = FsPath(__file__).resolve().parents[1]
SAMPLES = sorted(p for p in (ROOT / "paths").iterdir() if p.suffix in (".csv", ".json"))

TRAJ = {"degree": 2, "knotVector": [0, 0, 0, 1, 1, 1],
        "controlPoints": [{"x": 1, "y": 0, "weight": 1}, {"x": 1, "y": 1, "weight": 0.5**0.5},
                          {"x": 0, "y": 1}]}


def write(tmp_path, name, content):
    f = tmp_path / name
    f.write_text(content if isinstance(content, str) else json.dumps(content))
    return f


def test_samples_load_with_sane_lengths_and_are_documented():
    readme = (ROOT / "paths" / "README.md").read_text()
    assert len(SAMPLES) >= 6
    lengths = {}
    for f in SAMPLES:
        p = read_path(f)
        lengths[f.name] = p.length
        assert 10.0 <= p.length <= 500.0, f.name
        assert f"`{f.name}`" in readme, f"{f.name} is not described in paths/README.md"
        s = np.linspace(0, p.length, 2001)
        assert np.isfinite(p.curvature(s)).all()
        assert np.abs(p.curvature(s)).max() < 2.0, f.name  # drivable: radius > 0.5 m
    assert read_path(ROOT / "paths" / "warehouse_loop.json").is_closed
    zones = read_zones(ROOT / "paths" / "slow_zone.json")
    assert [z.v_max for z in zones] == [0.5]
    assert read_zones(ROOT / "paths" / "aisle_corners.csv") == []


def test_csv_waypoints_with_and_without_headings(tmp_path):
    f = write(tmp_path, "w.csv", "# comment\nx,y\n0,0\n\n10,0\n10,10\n")
    p = read_path(f)
    np.testing.assert_allclose(p.point(p.offsets), [[0, 0], [10, 0], [10, 10]], atol=1e-9)
    g = write(tmp_path, "h.csv", "Y, X ,heading\n0,0,0\n5,5,0\n0,10,0\n")  # any column order
    q = read_path(g)
    np.testing.assert_allclose(q.point(q.offsets), [[0, 0], [5, 5], [10, 0]], atol=1e-9)
    np.testing.assert_allclose(q.heading(q.offsets), 0.0, atol=1e-12)
    poly = read_path(f, kind="polyline")
    assert len(poly.pieces) == 3


def test_json_segments_waypoints_and_zones(tmp_path):
    doc = {"start": [1, 2], "heading": 0.5,
           "segments": [{"type": "line", "length": 3}, {"type": "arc", "radius": 2, "angle": 1},
                        {"type": "clothoid", "length": 2, "k0": 0.5, "k1": 0}],
           "zones": [{"polygon": [[0, 0], [5, 0], [5, 5], [0, 5]], "v_max": 0.3}]}
    p = read_path(write(tmp_path, "s.json", doc))
    ref = Path.from_segments([Line(3), Arc(2, 1), Clothoid(2, 0.5, 0)], start=(1, 2), heading=0.5)
    s = np.linspace(0, ref.length, 20)
    np.testing.assert_array_equal(p.point(s), ref.point(s))
    zones = read_zones(tmp_path / "s.json")
    assert zones[0].v_max == 0.3 and zones[0].polygon.area == 25.0
    w = read_path(write(tmp_path, "w.json", {"waypoints": [[0, 0], [4, 3]], "kind": "spline"}))
    assert w.length == pytest.approx(5.0, rel=1e-14)


# A whole order (`edges`) is a route: read_path refuses it (tests/test_route_io.py).
@pytest.mark.parametrize("wrap", [lambda t: t, lambda t: {"trajectory": t}])
def test_vda5050_trajectory_bare_or_nested(tmp_path, wrap):
    p = read_path(write(tmp_path, "edge.json", wrap(TRAJ)))
    assert p.length == pytest.approx(np.pi / 2, rel=1e-12)  # weight defaults to 1
    np.testing.assert_allclose(p.curvature([0.0, 1.0]), 1.0, rtol=1e-9)


def test_segment_json_round_trip_is_exact(tmp_path):
    p = Path.from_segments([Line(3), Arc(2, -1), Clothoid(2, -0.5, 0.25), Line(1)],
                           start=(4, -1), heading=2.0)
    zone = SpeedZone(shapely.box(0, 0, 1, 1), 0.5)
    for path in (p, p.reversed(), Path.from_waypoints([[0, 0], [5, 1], [7, 6]]),
                 Path.from_waypoints([[0, 0], [5, 0], [5, 5]], kind="polyline")):
        f = tmp_path / "rt.json"
        write_path(f, path, zones=[zone])
        back = read_path(f)
        s = np.linspace(0, path.length, 50)
        np.testing.assert_allclose(back.point(s), path.point(s), atol=1e-12)
        np.testing.assert_allclose(back.curvature(s), path.curvature(s), atol=1e-12)
        assert read_zones(f)[0].polygon.equals(zone.polygon)


def test_csv_round_trip_approximates_any_path(tmp_path):
    p = Path.from_nurbs(2, [0, 0, 0, 1, 1, 1], [[0, 0], [5, 5], [10, 0]], [1, 2, 1])
    f = tmp_path / "n.csv"
    write_path(f, p, ds=0.1)
    back = read_path(f)
    assert back.length == pytest.approx(p.length, rel=1e-6)
    s = np.linspace(0, p.length, 30)
    np.testing.assert_allclose(back.point(s * back.length / p.length), p.point(s), atol=1e-5)
    write_waypoints(tmp_path / "w.csv", [[0, 0], [3, 4]], headings=[0.9272952180016122] * 2)
    assert read_path(tmp_path / "w.csv").length == pytest.approx(5.0, rel=1e-14)


def test_write_trajectory_round_trip(tmp_path):
    f = tmp_path / "t.json"
    write_trajectory(f, 2, [0, 0, 0, 1, 1, 1], [[1, 0], [1, 1], [0, 1]], [1, 0.5**0.5, 1])
    assert read_path(f).length == pytest.approx(np.pi / 2, rel=1e-12)
    doc = json.loads(f.read_text())
    assert doc["trajectory"]["controlPoints"][1] == {"x": 1.0, "y": 1.0, "weight": 0.5**0.5}
    with pytest.raises(InvalidInputError, match="`knots`"):
        write_trajectory(f, 2, [0, 1, 0, 1, 1, 1], [[1, 0], [1, 1], [0, 1]])


def test_writers_refuse_what_they_cannot_store(tmp_path):
    spline = Path.from_waypoints([[0, 0], [3, 1], [5, 4]], kind="spline")
    with pytest.raises(InvalidInputError, match="spline or NURBS"):
        write_path(tmp_path / "s.json", spline)
    with pytest.raises(InvalidInputError, match="`file`"):
        write_path(tmp_path / "s.txt", spline)
    with pytest.raises(InvalidInputError, match="`path`"):
        path_to_dict("not a path")  # type: ignore[arg-type]
    with pytest.raises(InvalidInputError, match="`xy`"):
        write_waypoints(tmp_path / "w.csv", [1, 2, 3])


@pytest.mark.parametrize(
    ("name", "content", "what"),
    [
        ("a.json", "{not json", "not valid JSON"),
        ("b.json", [1, 2], "expected a JSON object"),
        ("c.json", {"segments": [{"type": "arc", "radius": 1.0}]}, "segments[0]"),
        ("d.json", {"segments": [{"type": "line", "length": "long"}]}, "segments[0].length"),
        ("e.json", {"segments": "line"}, "`segments`"),
        ("f.json", {"something": 1}, "no path found"),
        ("g.json", {"edges": [{"edgeId": "e1"}]}, "trajectory"),
        ("h.json", {"edges": "e1"}, "edges"),
        ("i.json", {"trajectory": {"degree": 2, "knotVector": [0, 0, 0, 1, 1, 1]}},
         "controlPoints"),
        ("j.json", {"trajectory": {**TRAJ, "controlPoints": [{"x": 1}, {"x": 1, "y": 1},
                                                             {"x": 0, "y": 1}]}}, "'y'"),
        ("k.json", {"trajectory": {**TRAJ, "knotVector": [0, 0, 1, 0, 1, 1]}}, "`knots`"),
        ("l.json", {"trajectory": {**TRAJ, "degree": "two"}}, "`degree`"),
        ("m.json", {"waypoints": [[0, 0], [0, 0]]}, "`xy`"),
        ("n.json", {"waypoints": [[0, 0], [1, 0]], "kind": "bezier"}, "`kind`"),
        ("o.json", {"segments": [{"type": "line", "length": 1}], "start": "origin"}, "`start`"),
        ("a.csv", "", "empty"),
        ("b.csv", "a,b\n1,2\n3,4\n", "'x' and 'y'"),
        ("c.csv", "x,y\n1,2\n", "at least two"),
        ("d.csv", "x,y\n0,0\n1,one\n", "row 2"),
        ("e.csv", "x,y\n0,0\n1\n", "row 2"),
        ("f.csv", "x,y\n0,0\n0,0\n", "`xy`"),
        ("g.csv", "x,y\n0,0\nnan,1\n", "NaN"),
        ("p.txt", "x,y\n0,0\n1,1\n", "unknown path file type"),
    ],
)
def test_bad_files_raise_invalid_input_naming_the_file(tmp_path, name, content, what):
    f = write(tmp_path, name, content)
    with pytest.raises(InvalidInputError) as info:
        read_path(f)
    msg = str(info.value)
    assert name in msg
    assert what in msg


@pytest.mark.parametrize(
    ("doc", "what"),
    [
        ({"zones": [{"polygon": [[0, 0], [1, 0]], "v_max": 1}]}, "`polygon`"),
        ({"zones": [{"polygon": [[0, 0], [1, 0], [1, 1]]}]}, "zones[0]"),
        ({"zones": [{"polygon": [[0, 0], [1, 0], [1, 1]], "v_max": -1}]}, "`v_max`"),
        ({"zones": {"polygon": []}}, "'zones' must be a list"),
    ],
)
def test_bad_zones_raise_invalid_input(tmp_path, doc, what):
    f = write(tmp_path, "z.json", {"segments": [{"type": "line", "length": 3}], **doc})
    with pytest.raises(InvalidInputError, match=re.escape(what)) as info:
        read_zones(f)
    assert "z.json" in str(info.value)


def test_missing_file():
    with pytest.raises(InvalidInputError, match="does not exist"):
        read_path("no/such/file.json")
    with pytest.raises(InvalidInputError, match="`kind`"):
        read_path(SAMPLES[0], kind="bezier")
