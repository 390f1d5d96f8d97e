"""Option strings: one closed set per option, checked everywhere it is taken, with a message
that names the argument and lists every valid value; public signatures say what they take."""

from __future__ import annotations

import inspect
import re
from dataclasses import replace
from typing import get_args

import numpy as np
import pytest
from shared import LGV

import speedplan as sp
import speedplan.io
from speedplan.batch import PlanJob
from speedplan.core import options
from speedplan.geometry import Line
from speedplan.geometry.fitting import KINDS
from speedplan.model import rest_points
from speedplan.model.request import PlanRequest
from speedplan.route_plan import RouteOptions, plan_route_update, route_jobs
from speedplan.solve import discrete

STRAIGHT = sp.Path.from_segments([Line(5.0)])


def _listing(values: tuple[str, ...]) -> str:
    return re.escape(", ".join(repr(v) for v in values))


@pytest.mark.parametrize(("name", "values"), [
    ("refine", options.REFINE_MODES),
    ("standstill", options.STANDSTILL_MODES),
    ("backend", options.BACKENDS),
])
def test_plan_refuses_an_unknown_option_listing_the_valid_ones(name, values):
    with pytest.raises(sp.InvalidInputError, match=rf"`{name}` must be one of "
                                                   rf"{_listing(values)}; got 'bogus'"):
        sp.plan(STRAIGHT, LGV, **{name: "bogus"})


@pytest.mark.parametrize(("name", "values"), [
    ("refine", options.REFINE_MODES),
    ("backend", options.BACKENDS),
])
def test_solve_discrete_refuses_an_unknown_option_listing_the_valid_ones(name, values):
    with pytest.raises(sp.InvalidInputError, match=rf"`{name}` must be one of "
                                                   rf"{_listing(values)}; got 'bogus'"):
        sp.solve_discrete(np.full(10, 1.0), A=1.0, J=1.0, **{name: "bogus"})


@pytest.mark.parametrize("bad", ["Ellipse", None, 1])
def test_limits_refuse_an_unknown_grip_listing_the_valid_ones(bad):
    with pytest.raises(sp.InvalidInputError,
                       match=rf"`grip` must be one of {_listing(options.GRIP_MODELS)}; got"):
        sp.Limits(2, 1, 1, 0.5, grip=bad)


def test_an_option_that_is_not_a_string_is_refused_by_name():
    with pytest.raises(sp.InvalidInputError, match=r"`refine` must be one of .*; got True"):
        sp.plan(STRAIGHT, LGV, refine=True)  # type: ignore[arg-type]


def test_plan_many_refuses_a_job_with_an_unknown_option_before_sending_it():
    (result,) = sp.plan_many([(STRAIGHT, LGV, {"standstill": "stiff"})], executor=None)
    assert isinstance(result.error, sp.InvalidInputError)
    assert _listing(options.STANDSTILL_MODES).replace("\\", "") in str(result.error)


def test_plan_route_names_the_leg_and_lists_the_valid_values():
    route = sp.Route.from_vda5050(_order())
    with pytest.raises(sp.InvalidInputError, match=r"on the leg from s=0 m .*`backend` must be "
                                                   rf"one of {_listing(options.BACKENDS)}"):
        sp.plan_route(route, LGV, backend="fast")  # type: ignore[typeddict-item]


@pytest.mark.parametrize(("name", "values"), [
    ("kind", options.PATH_KINDS),
    ("format", options.FILE_FORMATS),
])
def test_read_path_refuses_an_unknown_option_listing_the_valid_ones(tmp_path, name, values):
    file = tmp_path / "p.csv"
    file.write_text("x,y\n0,0\n3,4\n")
    with pytest.raises(sp.InvalidInputError, match=rf"`{name}` must be one of "
                                                   rf"{_listing(values)}; got 'xml'"):
        speedplan.io.read_path(file, **{name: "xml"})


def test_the_reach_modes_are_a_closed_set():
    assert options.check_option("reach", "distance", options.REACH_MODES) == "distance"
    with pytest.raises(sp.InvalidInputError, match=r"`reach` must be one of 'max_jerk', "
                                                   r"'distance'; got 'exact'"):
        options.check_option("reach", "exact", options.REACH_MODES)


def test_the_value_tuples_are_the_literals_values():
    for alias, values in [(options.Refine, options.REFINE_MODES),
                          (options.Backend, options.BACKENDS),
                          (options.Standstill, options.STANDSTILL_MODES),
                          (options.Reach, options.REACH_MODES),
                          (options.Grip, options.GRIP_MODELS),
                          (options.PathKind, options.PATH_KINDS),
                          (options.FileFormat, options.FILE_FORMATS),
                          (options.RestReason, options.REST_REASONS)]:
        assert values == get_args(alias) and len(set(values)) == len(values)
    # The re-exports of the older homes are the same objects.
    assert sp.solve.BACKENDS is options.BACKENDS and sp.solve.REFINE_MODES is options.REFINE_MODES
    assert sp.model.STANDSTILL_MODES is options.STANDSTILL_MODES
    assert sp.core.limits.GRIP_MODELS is options.GRIP_MODELS
    assert speedplan.io.FORMATS is options.FILE_FORMATS
    assert options.PATH_KINDS == KINDS  # the kinds Path.from_waypoints takes


def test_every_relaxation_backend_has_a_name_and_auto_comes_first():
    assert tuple(discrete.RELAXATION_BACKENDS) == options.RELAXATION_BACKEND_NAMES
    assert options.BACKENDS == ("auto", *options.RELAXATION_BACKEND_NAMES)


def test_the_models_rest_reasons_are_the_literals():
    # A reversal (cusp) and a stop asked for on one path; with j_lat_max, a G1 corner's
    # curvature jump on another.
    reverse = sp.Path.from_segments([Line(4.0), Line(3.0, reverse=True)])
    corner = sp.Path.from_waypoints([[0, 0], [10, 0], [10, 10]], kind="polyline")
    limits = sp.Limits(2, 1, 1, 0.5, j_lat_max=1.0)
    reasons = {r.reason for p, stops in [(reverse, [6.0]), (corner, None)]
               for r in rest_points(PlanRequest.create(p, limits, stops=stops))}
    assert reasons == set(options.REST_REASONS)


def test_limits_take_none_for_the_optional_limits_and_hold_floats():
    lim = sp.Limits(2, 1, 1, 0.5, a_decel=None, j_lat_max=None, yaw_jerk_max=None)
    assert lim.a_decel == 1.0 and lim.j_lat_max == np.inf and lim.yaw_jerk_max == np.inf
    params = inspect.signature(sp.Limits).parameters
    assert params["a_decel"].annotation == "float | None" and params["a_decel"].default is None
    assert params["grip"].annotation == "Grip"
    assert replace(lim, v_max=1.0) == sp.Limits(1, 1, 1, 0.5)


PUBLIC_FUNCTIONS = [
    sp.plan, sp.plan_many, sp.plan_route, sp.plan_route_update, sp.solve_discrete,
    route_jobs, plan_route_update, sp.Limits, PlanRequest.create, PlanJob,
    speedplan.io.path_from_dict, speedplan.io.zones_from_dict, speedplan.io.path_to_dict,
    speedplan.io.read_path, speedplan.io.read_zones, speedplan.io.read_trajectory,
    speedplan.io.write_waypoints, speedplan.io.write_nurbs, speedplan.io.write_trajectory,
]


@pytest.mark.parametrize("fn", PUBLIC_FUNCTIONS, ids=lambda f: f.__qualname__)
def test_public_signatures_say_what_they_take(fn):
    sig = inspect.signature(fn)
    annotations = [p.annotation for p in sig.parameters.values()] + [sig.return_annotation]
    assert not [a for a in annotations if re.search(r"\bAny\b", str(a))]


def test_the_route_options_are_the_plan_keywords_a_route_leaves_open():
    keys = set(RouteOptions.__optional_keys__)
    assert keys == {"n", "ds", "zones", "refine", "standstill", "backend", "time_limit"}
    assert keys <= set(inspect.signature(sp.plan).parameters)


def _order() -> dict[str, object]:
    def node(k: int, x: float) -> dict[str, object]:
        return {"nodeId": f"n{k}", "sequenceId": 2 * k, "released": True,
                "nodePosition": {"x": x, "y": 0.0, "mapId": "m"}, "actions": []}
    return {"headerId": 0, "timestamp": "2024-01-01T00:00:00Z", "version": "2.0.0",
            "manufacturer": "m", "serialNumber": "s", "orderId": "o", "orderUpdateId": 0,
            "nodes": [node(0, 0.0), node(1, 6.0)],
            "edges": [{"edgeId": "e0", "sequenceId": 1, "released": True, "startNodeId": "n0",
                       "endNodeId": "n1", "actions": []}]}
