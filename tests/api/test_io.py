"""Path files: readers, writers, round trips, bad files, the shipped samples."""

from __future__ import annotations

import io
import json
import re
import warnings
from pathlib import Path as FsPath

import numpy as np
import pytest
import shapely

import speedplan as sp
from speedplan import InvalidInputError, Limits, Path, SpeedplanWarning, SpeedZone, plan
from speedplan.core.checks import as_array, as_scalar, broadcast_positive, choice
from speedplan.geometry import Arc, Clothoid, Line, speed_bounds, zone_intervals
from speedplan.io import (
    path_to_dict,
    read_path,
    read_zones,
    write_nurbs,
    write_path,
    write_trajectory,
    write_waypoints,
)

ROOT = FsPath(__file__).resolve().parents[2]
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
    p = read_path(f)  # no headings: the default G2 corners, exact ends, corner within 0.25 m
    np.testing.assert_allclose(p.point([0.0, p.length]), [[0, 0], [10, 10]], atol=1e-12)
    corner = p.to_linestring(ds=1e-3).distance(shapely.Point(10, 0))
    assert 0.2 < corner <= 0.25 + 1e-9
    assert Path.from_waypoints([[0, 0], [10, 0], [10, 10]]).length == p.length
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


# A whole order (`edges`) is a route: read_path refuses it (tests/route/test_order_files.py).
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


def test_write_nurbs_round_trip(tmp_path):
    f = tmp_path / "t.json"
    write_nurbs(f, 2, [0, 0, 0, 1, 1, 1], [[1, 0], [1, 1], [0, 1]], [1, 0.5**0.5, 1])
    assert read_path(f).length == pytest.approx(np.pi / 2, rel=1e-12)
    doc = json.loads(f.read_text())
    assert doc["trajectory"]["controlPoints"][1] == {"x": 1.0, "y": 1.0, "weight": 0.5**0.5}
    with pytest.raises(InvalidInputError, match="`knots`"):
        write_nurbs(f, 2, [0, 1, 0, 1, 1, 1], [[1, 0], [1, 1], [0, 1]])


def test_write_trajectory_is_a_deprecated_alias_of_write_nurbs(tmp_path):
    with pytest.warns(DeprecationWarning, match="write_nurbs"):
        write_trajectory(tmp_path / "old.json", 1, [0, 0, 1, 1], [[0, 0], [3, 4]])
    write_nurbs(tmp_path / "new.json", 1, [0, 0, 1, 1], [[0, 0], [3, 4]])
    assert (tmp_path / "old.json").read_text() == (tmp_path / "new.json").read_text()


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


# ---- CSV columns: heading/yaw/theta, units, ignored columns ---------------------------------
@pytest.mark.parametrize("column", ["heading", "yaw", "theta", "Yaw [rad]", " THETA "])
def test_csv_heading_column_may_be_named_yaw_or_theta(tmp_path, column):
    f = write(tmp_path, "w.csv", f"x,y,{column}\n0,0,0.5\n5,5,0.5\n0,10,0.5\n")
    p = read_path(f)
    np.testing.assert_allclose(p.heading(p.offsets), 0.5, atol=1e-12)  # the headings are used


def test_csv_with_two_heading_columns_is_refused(tmp_path):
    f = write(tmp_path, "w.csv", "x,y,yaw,heading\n0,0,0,0\n5,0,0,0\n")
    with pytest.raises(InvalidInputError, match="keep one of"):
        read_path(f)


def test_csv_extra_columns_are_ignored_with_a_warning_naming_them(tmp_path):
    f = write(tmp_path, "ros.csv", "frame_id,x,y,z,yaw\nmap,0,0,0,0\nmap,5,0,0,0\n"
                                   "map,5,5,0,1.5707963267948966\n")
    with pytest.warns(SpeedplanWarning, match=r"ros\.csv: ignored columns \['frame_id', 'z'\]"):
        p = read_path(f)
    ref = Path.from_waypoints([[0, 0], [5, 0], [5, 5]], "clothoid",
                                 headings=[0, 0, np.pi / 2])
    s = np.linspace(0, ref.length, 30)
    np.testing.assert_array_equal(p.point(s), ref.point(s))
    with warnings.catch_warnings():
        warnings.simplefilter("error")  # no warning when every column is read
        read_path(write(tmp_path, "plain.csv", "x,y\n0,0\n1,0\n"))


def test_csv_units_in_the_header(tmp_path):
    p = read_path(write(tmp_path, "u.csv", "x [m],y [m],heading [rad]\n0,0,0\n4,0,0\n"))
    assert p.length == pytest.approx(4.0, rel=1e-12)
    with pytest.raises(InvalidInputError, match="column 'heading' must be in rad"):
        read_path(write(tmp_path, "deg.csv", "x,y,heading [deg]\n0,0,0\n4,0,0\n"))


def test_a_planned_trajectory_csv_reads_back_as_a_path(tmp_path):
    prof = plan(Path.from_waypoints([[0, 0], [6, 0], [6, 4]]),
                Limits(v_max=2, a_max=1, a_lat_max=1, j_max=0.5))
    f = tmp_path / "traj.csv"
    prof.sample(0.2).to_csv(f)
    with pytest.warns(SpeedplanWarning, match="ignored columns"):
        back = read_path(f)
    assert back.length == pytest.approx(prof.path.length, rel=1e-3)


def test_text_in_a_column_that_is_read_names_row_and_column(tmp_path):
    f = write(tmp_path, "bad.csv", "x,y,frame_id\n0,0,map\n1,oops,map\n")
    with pytest.warns(SpeedplanWarning), pytest.raises(InvalidInputError,
                                                       match=r"row 2 .*column 'y'"):
        read_path(f)


# ---- streams and directories ----------------------------------------------------------------
def test_streams_with_format_or_sniffing():
    assert read_path(io.StringIO("x,y\n0,0\n3,4\n")).length == pytest.approx(5.0)
    doc = json.dumps({"segments": [{"type": "line", "length": 2}],
                      "zones": [{"polygon": [[0, -1], [1, -1], [1, 1]], "v_max": 0.2}]})
    assert read_path(io.StringIO(doc)).length == 2.0
    assert read_path(io.StringIO("  \n" + doc), format="json").length == 2.0
    assert [z.v_max for z in read_zones(io.StringIO(doc))] == [0.2]
    assert read_zones(io.StringIO("x,y\n0,0\n3,4\n")) == []
    with pytest.raises(InvalidInputError, match="`format`"):
        read_path(io.StringIO(doc), format="yaml")
    with pytest.raises(InvalidInputError, match="binary"):
        read_path(io.BytesIO(b"x,y\n0,0\n1,1\n"))


def test_a_directory_is_named_as_such(tmp_path):
    with pytest.raises(InvalidInputError, match="is a directory"):
        read_path(tmp_path)


def test_writers_name_a_missing_directory(tmp_path):
    with pytest.raises(InvalidInputError, match="does not exist"):
        write_waypoints(tmp_path / "no" / "w.csv", [[0, 0], [1, 1]])
    with pytest.raises(InvalidInputError, match="does not exist"):
        write_nurbs(tmp_path / "no" / "e.json", 1, [0, 0, 1, 1], [[0, 0], [3, 4]])


# ---- zones ----------------------------------------------------------------------------------
LIM = Limits(v_max=2, a_max=1, a_lat_max=1, j_max=0.5)


def test_a_single_zone_is_a_list_of_one():
    p = Path.from_segments([Line(10.0)])
    zone = SpeedZone(shapely.box(2, -1, 5, 1), 0.5)
    s = np.linspace(0, 10, 101)
    np.testing.assert_array_equal(speed_bounds(p, LIM, s, zones=zone),
                                  speed_bounds(p, LIM, s, zones=[zone]))
    assert zone_intervals(p, zone) == zone_intervals(p, [zone])
    one = plan(p, LIM, zones=zone)
    assert one.duration == plan(p, LIM, zones=[zone]).duration


def test_multipolygon_zones_limit_speed_in_every_part():
    parts = shapely.MultiPolygon([shapely.box(2, -1, 3, 1), shapely.box(6, -1, 7, 1)])
    zone = SpeedZone(parts, 0.5)
    p = Path.from_segments([Line(10.0)])
    s = np.linspace(0, 10, 1001)
    inside = ((s >= 2) & (s <= 3)) | ((s >= 6) & (s <= 7))  # oracle: the boxes themselves
    np.testing.assert_array_equal(speed_bounds(p, LIM, s, zones=[zone]),
                                  np.where(inside, 0.25, 4.0))
    got = zone_intervals(p, [zone])
    assert [(round(a, 9), round(b, 9), v) for a, b, v in got] == [(2.0, 3.0, 0.5),
                                                                    (6.0, 7.0, 0.5)]
    overlapping = shapely.MultiPolygon([shapely.box(0, 0, 2, 2), shapely.box(1, 1, 3, 3)])
    with pytest.raises(InvalidInputError, match="must not overlap"):
        SpeedZone(overlapping, 0.5)
    with pytest.raises(InvalidInputError, match="LineString"):
        SpeedZone(shapely.LineString([(0, 0), (1, 1)]), 0.5)


def test_zones_with_parts_and_holes_round_trip_through_json(tmp_path):
    ring = shapely.Polygon(shapely.box(0, 0, 10, 10).exterior, [shapely.box(4, 4, 6, 6)
                                                                 .exterior.coords])
    parts = shapely.MultiPolygon([shapely.box(20, 0, 21, 1), shapely.box(30, 0, 31, 1)])
    f = tmp_path / "z.json"
    write_path(f, Path.from_segments([Line(3.0)]), zones=[SpeedZone(ring, 0.3),
                                                          SpeedZone(parts, 0.4)])
    back = read_zones(f)
    assert [z.v_max for z in back] == [0.3, 0.4, 0.4]
    assert back[0].polygon.equals(ring) and back[0].polygon.area == 96.0
    assert shapely.union_all([z.polygon for z in back[1:]]).equals(parts)


# ---- messages -------------------------------------------------------------------------------
@pytest.mark.parametrize(
    ("call", "shown"),
    [
        (lambda: broadcast_positive("A", np.array([1.0, -1.0]), 2), "got -1.0 at index 1"),
        (lambda: choice("refine", np.float64(2.5), ("auto",)), "got 2.5"),
        (lambda: as_array("xy", [np.float64(1.0), "a"]), "got [1.0, 'a']"),
        (lambda: as_scalar("v_max", np.float64(-1.0), positive=True), "got -1.0"),
    ],
)
def test_messages_show_numpy_scalars_as_plain_numbers(call, shown):
    with pytest.raises(InvalidInputError) as info:
        call()
    assert shown in str(info.value)
    assert "np.float64" not in str(info.value)


def test_bad_files_raise_invalid_input(tmp_path):
    bad_json = tmp_path / "bad.json"
    bad_json.write_text("{not json")
    with pytest.raises(sp.InvalidInputError, match=r"bad\.json"):
        read_path(bad_json)
    no_xy = tmp_path / "w.csv"
    no_xy.write_text("a,b\n1,2\n3,4\n")
    with pytest.raises(sp.InvalidInputError, match="'x' and 'y'"):
        read_path(no_xy)
    seg = tmp_path / "s.json"
    seg.write_text(json.dumps({"segments": [{"type": "arc", "radius": 1.0}]}))
    with pytest.raises(sp.InvalidInputError, match="angle"):
        read_path(seg)
    zone = tmp_path / "z.json"
    zone.write_text(json.dumps({"segments": [{"type": "line", "length": 3}],
                                "zones": [{"polygon": [[0, 0], [1, 0]], "v_max": 1}]}))
    with pytest.raises(sp.InvalidInputError, match="polygon"):
        read_zones(zone)


def test_sample_files_load_with_sane_lengths(request):
    lengths = {}
    for f in sorted((request.config.rootpath / "paths").glob("*.*")):
        if f.suffix in (".csv", ".json"):
            lengths[f.name] = read_path(f).length
    assert len(lengths) >= 6
    assert all(5.0 < L < 1000.0 for L in lengths.values())
    assert read_zones(request.config.rootpath / "paths" / "slow_zone.json")[0].v_max == 0.5
