"""Orders in files: read_route, read_path's refusal, the shipped sample orders."""

from __future__ import annotations

import json
from pathlib import Path as FsPath

import pytest

from speedplan import InvalidInputError
from speedplan.io import read_path, read_route
from speedplan.route import Route

ROOT = FsPath(__file__).resolve().parents[2]
ORDERS = sorted((ROOT / "paths" / "orders").glob("*.json"))


def test_sample_orders_load_are_documented_and_sane():
    readme = (ROOT / "paths" / "README.md").read_text()
    assert [f.name for f in ORDERS] == ["order_v2.json", "order_v3.json"]
    for f in ORDERS:
        route = read_route(f)
        assert isinstance(route, Route)
        assert f"`orders/{f.name}`" in readme, f"{f.name} is not described in paths/README.md"
        assert 10.0 <= route.length <= 500.0
        assert len(route.legs()) == 2  # stop at the HARD pick on N1
        for e in route.edges:
            s = [0.0, e.path.length / 2, e.path.length]
            assert abs(e.path.curvature(s)).max() < 2.0  # drivable: radius > 0.5 m
        assert f"{route.length:.2f} m" in readme


def test_read_path_refuses_an_order_and_points_to_read_route(tmp_path):
    for f in ORDERS:
        with pytest.raises(InvalidInputError, match=rf"{f.name}: .*VDA 5050 order.*read_route"):
            read_path(f)
    # Before: the first edge carrying a trajectory came back as "the path", 5 m of 10.
    doc = json.loads(ORDERS[0].read_text())
    single = tmp_path / "one_edge.json"
    single.write_text(json.dumps({"edges": doc["edges"][:1]}))
    with pytest.raises(InvalidInputError, match="read_route"):
        read_path(single)


def test_read_route_names_the_file_and_the_element(tmp_path):
    doc = json.loads(ORDERS[1].read_text())
    doc["edges"][0]["trajectory"]["knotVector"][5] = 0.1  # decreasing
    f = tmp_path / "broken.json"
    f.write_text(json.dumps(doc))
    with pytest.raises(InvalidInputError,
                       match=r"^broken\.json: `edges\[0\]\.trajectory`: `knots` must be "
                             r"non-decreasing"):
        read_route(f)
    f.write_text(json.dumps([doc]))
    with pytest.raises(InvalidInputError, match=r"^broken\.json: `order` must be a JSON object"):
        read_route(f)
    f.write_text("{not json")
    with pytest.raises(InvalidInputError, match=r"broken\.json: not valid JSON"):
        read_route(f)
    with pytest.raises(InvalidInputError, match="does not exist"):
        read_route(tmp_path / "missing.json")


def test_read_path_reads_a_controlpoints_only_trajectory_with_the_3_0_defaults(tmp_path):
    # VDA 5050 3.0: degree 1 and uniform clamped knots when absent (main refused the file).
    f = tmp_path / "edge.json"
    f.write_text(json.dumps({"trajectory": {"controlPoints": [{"x": 0, "y": 0}, {"x": 3, "y": 4},
                                                              {"x": 6, "y": 8}]}}))
    path = read_path(f)
    assert path.length == pytest.approx(10.0, rel=1e-14)  # collinear: no corner at knot 0.5
    assert path.point(5.0).tolist() == pytest.approx([3.0, 4.0], abs=1e-12)
