"""VDA 5050 orders (2.0, 2.1, 3.0) to a [`Route`][speedplan.Route].

Field names follow the official JSON schemas and specification of the VDA5050/VDA5050
repository (``json_schemas/order.schema`` and ``VDA5050_EN.md``); where the versions differ:

============================  ==============================  ================================
                              2.0 / 2.1                       3.0
============================  ==============================  ================================
edge speed limit [m/s]        ``maxSpeed``                    ``maximumSpeed``
edge's nodes                  ``startNodeId``, ``endNodeId``  none (implied by the sequence)
                              (required)
node deviation [m]            ``allowedDeviationXY`` number   ``allowedDeviationXY`` ellipse
                              (``...Xy`` read too)            ``{a, b, theta}``
``trajectory``                ``degree``, ``knotVector``,     ``controlPoints`` only;
                              ``controlPoints`` required      ``degree`` 1, uniform clamped
                                                              knots by default
action ``blockingType``       NONE, SOFT, HARD                NONE, SOFT, SINGLE, HARD
============================  ==============================  ================================

Both: header ``version`` (required here: it selects the names above), ``orderId``,
``orderUpdateId`` (``headerId``, ``timestamp``, ``manufacturer``, ``serialNumber``: type
checked); nodes ``nodeId``, ``sequenceId``, ``released``, ``nodePosition{x, y, theta,
allowedDeviationTheta, mapId}``, ``actions[]{actionType, actionId, blockingType}``; edges
``edgeId``, ``sequenceId``, ``released``, ``maxRotationSpeed``, ``orientation``,
``orientationType`` (GLOBAL or TANGENTIAL, default TANGENTIAL), ``rotationAllowed``,
``reachOrientationBeforeEntering``, ``corridor{leftWidth, rightWidth}``, ``trajectory``,
``length``, ``actions``. A field of the other version (``maximumSpeed`` in a 2.0 order) is
refused rather than ignored.

Nothing is dropped without a word: every field the planner does not honour as written —
``direction`` (a line-guided vehicle's branch at a junction, not the driving direction), the
height fields, ``zoneSetId``, an ``orientation`` at an angle to the path (crabbing), a
``CONTOUR`` corridor, ``rotationAllowed`` false on an edge whose geometry turns, an unknown
field name, a field the schema requires but the order lacks (``actions`` lists, header
fields, ``mapId``; planned without) — is one line of `Route.notes`, and the reader warns
them once per order (`OrderWarning`). ``docs/vda5050.md`` lists every field.

What is derived:

* an edge with a ``trajectory`` is that NURBS (``weight`` default 1); it must start and end
  within ``max(allowedDeviationXY, 1 cm)`` of its nodes' positions (when they have one);
* an edge without one runs straight between its nodes' positions (both needed);
* ``stop`` on a node or an edge: an action with ``blockingType`` SOFT or HARD (driving not
  allowed while it runs);
* ``reverse``: ``orientationType`` TANGENTIAL and ``|orientation| > π/2``, or GLOBAL with an
  ``orientation`` opposite to a straight edge's direction;
* a node's deviation bounds how far a rounded corner passes from it: the 2.x radius, or the
  3.0 ellipse's radius along the corner's bisector (``allowed_deviation_xy`` keeps its
  semi-minor axis ``min(a, b)``); the edges' corridors bound it too;
* ``rotationAllowed`` false on either edge, or ``reachOrientationBeforeEntering`` on the next,
  keeps a corner from being rounded: the vehicle stops on the node and turns there;
* a node ``theta`` (within ``allowedDeviationTheta``) is met on the node: where the path's
  heading differs, the vehicle stops and turns to it.

The edge's ``length`` is checked for type only (the geometry gives the length). Consecutive
node positions must be on the same ``mapId``.
"""

from __future__ import annotations

import itertools
import json
import os
import warnings
from dataclasses import dataclass
from pathlib import Path as FsPath
from typing import Any, NamedTuple

import numpy as np

from ..core.errors import InvalidInputError, SpeedplanWarning
from ..core.numerics import wrap_angle
from ..geometry import Line, Path
from ._checks import (
    boolean,
    check_meets_node,
    check_released,
    check_sequence,
    integer,
    node_tolerance,
    number,
    positive,
    string,
)
from .elements import THETA_TOLERANCE, RouteEdge, RouteNode

__all__ = ["OrderRead", "OrderWarning", "load_order", "read_order", "trajectory_path",
           "uniform_clamped_knots"]


class OrderWarning(SpeedplanWarning):
    """An order holds fields the planner does not honour as written.

    One warning per order, one line per field naming its node or edge and why; the same
    lines are in [`Route.notes`][speedplan.Route].
    """


#: Fields read, per object; any other field is reported as unknown (a misspelt name would
#: otherwise be ignored without a word).
_KNOWN = {
    "order": {"headerId", "timestamp", "version", "manufacturer", "serialNumber", "orderId",
              "orderUpdateId", "orderDescription", "zoneSetId", "nodes", "edges"},
    "node": {"nodeId", "sequenceId", "nodeDescription", "nodeDescriptor", "released",
             "nodePosition", "actions"},
    "nodePosition": {"x", "y", "theta", "allowedDeviationXY", "allowedDeviationXy",
                     "allowedDeviationTheta", "mapId", "mapDescription"},
    "edge": {"edgeId", "sequenceId", "edgeDescription", "edgeDescriptor", "released",
             "startNodeId", "endNodeId", "maxSpeed", "maximumSpeed", "maxHeight", "minHeight",
             "maximumHeight", "minimumHeight", "maximumMobileRobotHeight",
             "minimumLoadHandlingDeviceHeight", "maximumLoadHandlingDeviceHeight",
             "orientation", "orientationType", "direction", "rotationAllowed",
             "reachOrientationBeforeEntering", "maxRotationSpeed", "length", "trajectory",
             "corridor", "actions"},
    "corridor": {"leftWidth", "rightWidth", "corridorRefPoint", "corridorReferencePoint",
                 "releaseRequired", "releaseLossBehavior"},
}
#: Edge fields about heights: no motion limit the planner knows (it plans in the plane).
_HEIGHTS = ("maxHeight", "minHeight", "maximumHeight", "minimumHeight",
            "maximumMobileRobotHeight", "minimumLoadHandlingDeviceHeight",
            "maximumLoadHandlingDeviceHeight")
#: Header fields the schemas require; an order without them is planned, with a note.
_HEADER = ("headerId", "timestamp", "manufacturer", "serialNumber", "orderId", "orderUpdateId")


def _unknown(obj: dict[str, Any], kind: str, where: str, notes: list[str]) -> None:
    for key in obj:
        if key not in _KNOWN[kind]:
            notes.append(f"`{where}.{key}`: not a field of a VDA 5050 {kind}; not read")


@dataclass(frozen=True)
class _Dialect:
    """The field names and rules of one VDA 5050 version."""

    version: str
    speed: str
    other_speed: str
    node_ids_required: bool
    ellipse: bool
    trajectory_defaults: bool
    blocking: tuple[str, ...]


def _v2(version: str) -> _Dialect:
    return _Dialect(version, "maxSpeed", "maximumSpeed", node_ids_required=True, ellipse=False,
                    trajectory_defaults=False, blocking=("NONE", "SOFT", "HARD"))


_DIALECTS = {
    "2.0": _v2("2.0"),
    "2.1": _v2("2.1"),
    "3.0": _Dialect("3.0", "maximumSpeed", "maxSpeed", node_ids_required=False, ellipse=True,
                    trajectory_defaults=True, blocking=("NONE", "SOFT", "SINGLE", "HARD")),
}
_ORIENTATION_TYPES = ("TANGENTIAL", "GLOBAL")


# ---- typed field access (messages name the element) ----------------------------------------------
def _obj(value: Any, where: str) -> dict[str, Any]:
    if not isinstance(value, dict):
        raise InvalidInputError(f"`{where}` must be a JSON object; got {type(value).__name__}")
    return value


def _list(value: Any, where: str) -> list[Any]:
    if not isinstance(value, list):
        raise InvalidInputError(f"`{where}` must be a JSON array; got {type(value).__name__}")
    return value


def _required(obj: dict[str, Any], key: str, where: str, why: str = "") -> Any:
    if key not in obj:
        raise InvalidInputError(f"`{where}.{key}` is missing{why}")
    return obj[key]


# ---- documents -----------------------------------------------------------------------------------
def load_order(order: Any) -> tuple[str, Any]:
    """``(name for messages, parsed document)`` of a dict, JSON text or JSON file."""
    if isinstance(order, dict):
        return "", order
    if isinstance(order, str) and order.lstrip().startswith("{"):
        try:
            return "", json.loads(order)
        except json.JSONDecodeError as exc:
            raise InvalidInputError(f"`order`: not valid JSON ({exc})") from exc
    if isinstance(order, str | os.PathLike):
        fs = FsPath(order)
        if not fs.is_file():
            raise InvalidInputError(f"order file {str(fs)!r} does not exist")
        try:
            return fs.name, json.loads(fs.read_text(encoding="utf-8"))
        except (json.JSONDecodeError, UnicodeDecodeError) as exc:
            raise InvalidInputError(f"{fs.name}: not valid JSON ({exc})") from exc
        except OSError as exc:
            raise InvalidInputError(f"{fs.name}: cannot read ({exc})") from exc
    raise InvalidInputError(
        "`order` must be a dict, a JSON string or the path of a JSON file; got "
        f"{type(order).__name__}"
    )


class OrderRead(NamedTuple):
    """What an order says about its route: the nodes, the edges and the header fields."""

    nodes: tuple[RouteNode, ...]
    edges: tuple[RouteEdge, ...]
    order_id: str | None
    order_update_id: int | None
    version: str
    notes: tuple[str, ...]


def read_order(order: Any) -> OrderRead:
    """The nodes, edges and header of a VDA 5050 order; see `Route.from_vda5050`.

    Fields not honoured as written are warned about (`OrderWarning`, once per order) and
    listed in ``notes``.

    Examples
    --------
    >>> from speedplan.route.vda5050 import read_order
    >>> read = read_order('''{"version": "2.1.0",
    ...   "nodes": [{"nodeId": "A", "sequenceId": 0, "released": true, "actions": [],
    ...              "nodePosition": {"x": 0, "y": 0, "allowedDeviationXY": 0.1, "mapId": "m"}},
    ...             {"nodeId": "B", "sequenceId": 2, "released": true, "actions": [],
    ...              "nodePosition": {"x": 6, "y": 8, "mapId": "m"}},
    ...             {"nodeId": "C", "sequenceId": 4, "released": false, "actions": [],
    ...              "nodePosition": {"x": 6, "y": 18, "mapId": "m"}}],
    ...   "edges": [{"edgeId": "AB", "sequenceId": 1, "released": true, "actions": [],
    ...              "startNodeId": "A", "endNodeId": "B", "maxSpeed": 0.5},
    ...             {"edgeId": "BC", "sequenceId": 3, "released": false, "actions": [],
    ...              "startNodeId": "B", "endNodeId": "C"}]}''')
    >>> [e.edge_id for e in read.edges], [e.released for e in read.edges], read.version
    (['AB', 'BC'], [True, False], '2.1.0')
    """
    name, doc = load_order(order)
    try:
        read = _read(doc)
    except InvalidInputError as exc:
        if name:
            raise InvalidInputError(f"{name}: {exc}") from exc
        raise
    if read.notes:
        lines = "\n".join(f"  - {note}" for note in read.notes)
        warnings.warn(f"{name or 'order'}: {len(read.notes)} field(s) not honoured as "
                      f"written:\n{lines}", OrderWarning, stacklevel=3)
    return read


def _dialect(doc: dict[str, Any]) -> _Dialect:
    version = string(_required(doc, "version", "order",
                                ' (the protocol version, e.g. "2.0.0" or "3.0.0", selects the '
                                "field names)"), "version")
    parts = version.split(".")
    key = ".".join(parts[:2])
    if len(parts) < 2 or key not in _DIALECTS:
        raise InvalidInputError(
            f"`version` {version!r} is not supported; VDA 5050 orders of version "
            f"{', '.join(k + '.x' for k in _DIALECTS)} are read"
        )
    return _DIALECTS[key]


def _read(doc: Any) -> OrderRead:
    doc = _obj(doc, "order")
    dialect = _dialect(doc)
    notes: list[str] = []
    _unknown(doc, "order", "order", notes)
    if "zoneSetId" in doc:
        string(doc["zoneSetId"], "zoneSetId")
        notes.append("`order.zoneSetId`: the zone set's zones (speed limits among them) are "
                     "not read; pass them to plan_route as `zones`")
    missing = [key for key in _HEADER if key not in doc]
    if missing:
        notes.append(f"`order`: {', '.join(missing)} missing (the schema requires them); "
                     "planned without")
    # Header fields are not needed to plan; when present they must still have their types.
    if "headerId" in doc:
        integer(doc["headerId"], "headerId")
    for key in ("timestamp", "manufacturer", "serialNumber"):
        if key in doc:
            string(doc[key], key)
    order_id = string(doc["orderId"], "orderId") if "orderId" in doc else None
    update = integer(doc["orderUpdateId"], "orderUpdateId") if "orderUpdateId" in doc else None
    raw_nodes = _list(_required(doc, "nodes", "order"), "nodes")
    raw_edges = _list(_required(doc, "edges", "order"), "edges")
    if len(raw_nodes) < 2:
        raise InvalidInputError(
            f"`nodes`: the order has {len(raw_nodes)} node(s); a route needs at least two "
            "nodes and the edge between them"
        )
    nodes_obj = [_obj(n, f"nodes[{i}]") for i, n in enumerate(raw_nodes)]
    edges_obj = [_obj(e, f"edges[{i}]") for i, e in enumerate(raw_edges)]
    check_sequence([integer(_required(n, "sequenceId", f"nodes[{i}]"), f"nodes[{i}].sequenceId")
                    for i, n in enumerate(nodes_obj)],
                   [integer(_required(e, "sequenceId", f"edges[{i}]"), f"edges[{i}].sequenceId")
                    for i, e in enumerate(edges_obj)], "sequenceId")
    check_released([boolean(_required(n, "released", f"nodes[{i}]"), f"nodes[{i}].released")
                    for i, n in enumerate(nodes_obj)],
                   [boolean(_required(e, "released", f"edges[{i}]"), f"edges[{i}].released")
                    for i, e in enumerate(edges_obj)])
    nodes = [_node(n, i, dialect, notes) for i, n in enumerate(nodes_obj)]
    _check_maps(nodes_obj)
    ids = {n.node_id for n in nodes}
    edges = [_edge(e, i, nodes[i], nodes[i + 1], ids, dialect, notes)
             for i, e in enumerate(edges_obj)]
    _note_rotations(edges, notes)
    return OrderRead(tuple(nodes), tuple(edges), order_id=order_id, order_update_id=update,
                     version=string(doc["version"], "version"), notes=tuple(notes))


def _turning(path: Path) -> float:
    """How far [rad] the heading of ``path`` turns in all (its range, unwrapped)."""
    heading = np.unwrap(np.asarray(path.heading(np.linspace(0.0, path.length, 257)),
                                   dtype=np.float64))
    return float(np.ptp(heading))


def _note_rotations(edges: list[RouteEdge], notes: list[str]) -> None:
    """Edges that forbid rotation but whose geometry turns the vehicle on them."""
    for i, edge in enumerate(edges):
        spread = 0.0 if edge.rotation_allowed else _turning(edge.path)
        if spread > THETA_TOLERANCE:
            notes.append(
                f"`edges[{i}].rotationAllowed` is false, but the edge's geometry turns the "
                f"vehicle by {spread:.3g} rad: the planner's vehicle faces the path's tangent, "
                "so it rotates on this edge as it follows it")


def _stops_driving(obj: dict[str, Any], where: str, dialect: _Dialect,
                   notes: list[str]) -> bool:
    """Whether ``obj.actions`` holds an action that forbids driving (SOFT or HARD)."""
    if "actions" not in obj:
        notes.append(f"`{where}.actions` is missing (the schema requires the list, empty if "
                     "there are no actions); taken as empty")
    actions = _list(obj.get("actions", []), f"{where}.actions")
    stop = False
    for j, raw in enumerate(actions):
        at = f"{where}.actions[{j}]"
        action = _obj(raw, at)
        for key in ("actionType", "actionId"):
            string(_required(action, key, at), f"{at}.{key}")
        blocking = string(_required(action, "blockingType", at), f"{at}.blockingType")
        if blocking not in dialect.blocking:
            raise InvalidInputError(
                f"`{at}.blockingType` must be one of {', '.join(dialect.blocking)} in VDA 5050 "
                f"{dialect.version}; got {blocking!r}"
            )
        stop = stop or blocking in ("SOFT", "HARD")
    return stop


def _deviation(pos: dict[str, Any], where: str, dialect: _Dialect, notes: list[str],
               ) -> tuple[float, tuple[float, float, float] | None]:
    """The allowed deviation [m] of a node position (0 when not given), and 3.0's ellipse."""
    keys = [k for k in ("allowedDeviationXY", "allowedDeviationXy") if k in pos]
    if not keys:
        return 0.0, None
    if dialect.ellipse:
        if keys != ["allowedDeviationXY"]:
            raise InvalidInputError(
                f"`{where}.allowedDeviationXy` is not a VDA 5050 3.0 field; use "
                "`allowedDeviationXY` {a, b, theta}"
            )
        at = f"{where}.allowedDeviationXY"
        if not isinstance(pos[keys[0]], dict):
            raise InvalidInputError(
                f"`{at}` must be an ellipse {{a, b, theta}} in VDA 5050 3.0 (a number in 2.x); "
                f"got {pos[keys[0]]!r}"
            )
        ellipse = pos[keys[0]]
        a, b = (number(_required(ellipse, k, at), f"{at}.{k}", minimum=0.0) for k in ("a", "b"))
        if "theta" in ellipse:
            angle = number(ellipse["theta"], f"{at}.theta")
        else:
            angle = 0.0
            notes.append(f"`{at}.theta` is missing (the schema requires it); taken as 0")
        return min(a, b), (a, b, angle)  # min: the largest circle inside the ellipse
    # Both spellings are read: VDA 5050 2.x specifies allowedDeviationXY, and orders written
    # to an early 2.0 schema spell it allowedDeviationXy.
    values = {k: number(pos[k], f"{where}.{k}", minimum=0.0) for k in keys}
    if len(set(values.values())) > 1:
        raise InvalidInputError(
            f"`{where}` gives both allowedDeviationXY and allowedDeviationXy with different "
            "values; give one"
        )
    return next(iter(values.values())), None


def _node(raw: dict[str, Any], i: int, dialect: _Dialect, notes: list[str]) -> RouteNode:
    where = f"nodes[{i}]"
    _unknown(raw, "node", where, notes)
    node_id = string(_required(raw, "nodeId", where), f"{where}.nodeId")
    position: tuple[float, float] | None = None
    theta = theta_dev = None
    deviation: float = 0.0
    ellipse = None
    if "nodePosition" in raw:
        at = f"{where}.nodePosition"
        pos = _obj(raw["nodePosition"], at)
        _unknown(pos, "nodePosition", at, notes)
        position = (number(_required(pos, "x", at), f"{at}.x"),
                    number(_required(pos, "y", at), f"{at}.y"))
        if "theta" in pos:
            theta = number(pos["theta"], f"{at}.theta")
        if "allowedDeviationTheta" in pos:
            theta_dev = number(pos["allowedDeviationTheta"], f"{at}.allowedDeviationTheta",
                               minimum=0.0)
            if theta is None:
                notes.append(f"`{at}.allowedDeviationTheta` is given without `theta`; "
                             "nothing to deviate from, not used")
        if "mapId" in pos:
            string(pos["mapId"], f"{at}.mapId")
        else:
            notes.append(f"`{at}.mapId` is missing (the schema requires it)")
        deviation, ellipse = _deviation(pos, at, dialect, notes)
    return RouteNode(node_id, int(raw["sequenceId"]), position, theta, deviation,
                     _stops_driving(raw, where, dialect, notes), raw["released"],
                     allowed_deviation_theta=theta_dev, deviation_ellipse=ellipse)


def _check_maps(nodes: list[dict[str, Any]]) -> None:
    """Consecutive node positions on different maps (an elevator) cannot be one path."""
    maps = [n["nodePosition"].get("mapId") if "nodePosition" in n else None for n in nodes]
    known = [(i, m) for i, m in enumerate(maps) if m is not None]
    for (i, a), (j, b) in itertools.pairwise(known):
        if a != b:
            raise InvalidInputError(
                f"`nodes[{j}].nodePosition.mapId` {b!r} differs from {a!r} of `nodes[{i}]`: "
                "a route crosses maps (e.g. by elevator) only between two orders; split it there"
            )


def _edge(raw: dict[str, Any], i: int, start: RouteNode, end: RouteNode, ids: set[str],
          dialect: _Dialect, notes: list[str]) -> RouteEdge:
    where = f"edges[{i}]"
    _unknown(raw, "edge", where, notes)
    edge_id = string(_required(raw, "edgeId", where), f"{where}.edgeId")
    for key, node, j in (("startNodeId", start, i), ("endNodeId", end, i + 1)):
        if key not in raw:
            if dialect.node_ids_required:
                raise InvalidInputError(
                    f"`{where}.{key}` is missing (required in VDA 5050 {dialect.version})"
                )
            continue
        named = string(raw[key], f"{where}.{key}")
        if named not in ids:
            raise InvalidInputError(
                f"`{where}.{key}` names node {named!r}, which is not in `nodes`"
            )
        if named != node.node_id:
            which = "the node before it" if key == "startNodeId" else "the node after it"
            raise InvalidInputError(
                f"`{where}.{key}` is {named!r} but {which} in the order is `nodes[{j}]` "
                f"({node.node_id!r}); an edge joins the nodes around it in list order"
            )
    if dialect.other_speed in raw:
        raise InvalidInputError(
            f"`{where}.{dialect.other_speed}` is not a VDA 5050 {dialect.version} field; the "
            f"edge speed limit is `{dialect.speed}` in this version"
        )
    v_max = positive(raw[dialect.speed], f"{where}.{dialect.speed}") \
        if dialect.speed in raw else None
    yaw = positive(raw["maxRotationSpeed"], f"{where}.maxRotationSpeed") \
        if "maxRotationSpeed" in raw else None
    if "length" in raw:
        number(raw["length"], f"{where}.length", minimum=0.0)
    for key in _HEIGHTS:
        if key in raw:
            number(raw[key], f"{where}.{key}")
            notes.append(f"`{where}.{key}`: a height, no limit on the planar motion the "
                         "planner plans; not checked")
    if "direction" in raw:
        string(raw["direction"], f"{where}.direction")
        notes.append(f"`{where}.direction` {raw['direction']!r}: the branch a line-guided "
                     "vehicle takes at a junction, not the driving direction; not used (to "
                     "drive the edge backwards give `orientation` π with `orientationType` "
                     "TANGENTIAL)")
    rotation = boolean(raw["rotationAllowed"], f"{where}.rotationAllowed") \
        if "rotationAllowed" in raw else True
    before = boolean(raw["reachOrientationBeforeEntering"],
                     f"{where}.reachOrientationBeforeEntering") \
        if "reachOrientationBeforeEntering" in raw else False
    path = _edge_path(raw, i, start, end, dialect)
    return RouteEdge(edge_id, int(raw["sequenceId"]), start.node_id, end.node_id, path,
                     v_max, yaw, _reverse(raw, where, path, notes), raw["released"],
                     _stops_driving(raw, where, dialect, notes), rotation_allowed=rotation,
                     turn_before_entering=before, corridor=_corridor(raw, where, notes))


def _corridor(raw: dict[str, Any], where: str, notes: list[str]) -> tuple[float, float] | None:
    """``(leftWidth, rightWidth)`` [m] of the edge's corridor, or ``None``."""
    if "corridor" not in raw:
        return None
    at = f"{where}.corridor"
    obj = _obj(raw["corridor"], at)
    _unknown(obj, "corridor", at, notes)
    left, right = (number(_required(obj, k, at), f"{at}.{k}", minimum=0.0)
                   for k in ("leftWidth", "rightWidth"))
    for key in ("corridorRefPoint", "corridorReferencePoint"):
        if key in obj:
            ref = string(obj[key], f"{at}.{key}")
            if ref not in ("KINEMATICCENTER", "KINEMATIC_CENTER", "CONTOUR"):
                raise InvalidInputError(
                    f"`{at}.{key}` must be KINEMATICCENTER or CONTOUR; got {ref!r}")
            if ref == "CONTOUR":
                notes.append(f"`{at}.{key}` CONTOUR: the planner knows no vehicle contour; "
                             "rounded corners keep the kinematic centre inside the corridor")
    if obj.get("releaseRequired") is True:
        notes.append(f"`{at}.releaseRequired`: the release is between fleet control and "
                     "vehicle; the plan uses the corridor as if released")
    return left, right


def _reverse(raw: dict[str, Any], where: str, path: Path, notes: list[str]) -> bool:
    """Whether the vehicle drives the edge backwards, from ``orientation``.

    TANGENTIAL (the default): ``|orientation| > π/2``. GLOBAL, on an edge whose geometry
    keeps one heading: backwards where the orientation points against it. Orientations the
    planner's vehicle (facing the path's tangent, or its opposite) cannot take are noted.
    """
    kind = raw.get("orientationType", "TANGENTIAL")
    if kind not in _ORIENTATION_TYPES:
        raise InvalidInputError(
            f"`{where}.orientationType` must be one of {', '.join(_ORIENTATION_TYPES)}; "
            f"got {kind!r}"
        )
    if "orientation" not in raw:
        return False
    orientation = number(raw["orientation"], f"{where}.orientation")
    at = f"`{where}.orientation` {orientation:.6g} rad ({kind})"
    if kind == "TANGENTIAL":
        reverse = bool(abs(wrap_angle(orientation)) > np.pi / 2)
        off = abs(float(wrap_angle(orientation - (np.pi if reverse else 0.0))))
        if off > THETA_TOLERANCE:
            notes.append(f"{at}: planned {'backwards' if reverse else 'forwards'} along the "
                         f"path; the planner's vehicle faces the path's tangent (or its "
                         f"opposite), it does not crab {off:.3g} rad off it")
        return reverse
    if _turning(path) > THETA_TOLERANCE:
        notes.append(f"{at}: the edge's geometry turns, so a fixed map orientation cannot be "
                     "kept by a vehicle facing the path's tangent; planned forwards")
        return False
    forward = abs(float(wrap_angle(orientation - float(path.heading(0.0)))))
    if forward <= THETA_TOLERANCE:
        return False
    if abs(forward - np.pi) <= THETA_TOLERANCE:
        return True
    notes.append(f"{at}: {forward:.3g} rad off the edge's direction; the planner's vehicle "
                 "faces the path's tangent (or its opposite); planned forwards")
    return False


def _edge_path(raw: dict[str, Any], i: int, start: RouteNode, end: RouteNode,
               dialect: _Dialect) -> Path:
    where = f"edges[{i}]"
    labels = f"`nodes[{i}]` ({start.node_id!r})", f"`nodes[{i + 1}]` ({end.node_id!r})"
    if "trajectory" in raw:
        at = f"{where}.trajectory"
        path = trajectory_path(raw["trajectory"], at, dialect)
        ends = path.point(np.array([0.0, path.length]))
        for point, node, verb, label in ((ends[0], start, "starts", labels[0]),
                                         (ends[1], end, "ends", labels[1])):
            if node.position is not None:
                check_meets_node(point, node.position,
                                 node_tolerance(node.allowed_deviation_xy), f"`{at}` {verb}",
                                 label)
        return path
    for node, label in ((start, labels[0]), (end, labels[1])):
        if node.position is None:
            raise InvalidInputError(
                f"`{where}` has no trajectory and {label} has no nodePosition: a straight edge "
                "runs between two node positions; give the position or a trajectory"
            )
    assert start.position is not None and end.position is not None  # checked above
    (x0, y0), (x1, y1) = start.position, end.position
    length = float(np.hypot(x1 - x0, y1 - y0))
    if not length > 0:
        raise InvalidInputError(
            f"`{where}` has no trajectory and its nodes {labels[0]} and {labels[1]} are at the "
            f"same position ({x0:.6g}, {y0:.6g}); a straight edge needs two distinct positions"
        )
    return Path.from_segments([Line(length)], start=(x0, y0),
                              heading=float(np.arctan2(y1 - y0, x1 - x0)))


# ---- trajectories --------------------------------------------------------------------------------
def uniform_clamped_knots(count: int, degree: int) -> list[float]:
    """VDA 5050 3.0's default ``knotVector``: uniform, first and last knot ``degree + 1`` times.

    Examples
    --------
    >>> from speedplan.route.vda5050 import uniform_clamped_knots
    >>> uniform_clamped_knots(5, 2)
    [0.0, 0.0, 0.0, 0.3333333333333333, 0.6666666666666666, 1.0, 1.0, 1.0]
    """
    inner = [j / (count - degree) for j in range(1, count - degree)]
    return [0.0] * (degree + 1) + inner + [1.0] * (degree + 1)


def trajectory_path(traj: Any, where: str = "trajectory", dialect: _Dialect | None = None) -> Path:
    """The path of a VDA 5050 ``trajectory`` object ``{degree, knotVector, controlPoints}``.

    Parameters
    ----------
    traj : dict
        The trajectory object; ``weight`` of a control point defaults to 1.
    where : str
        Its place in the document, for messages (``"edges[1].trajectory"``).
    dialect : optional
        The order's version rules; ``None`` (a bare trajectory) applies the 3.0 defaults
        (``degree`` 1, uniform clamped ``knotVector``) to absent fields, as 3.0 orders do;
        2.x orders require both fields.

    Examples
    --------
    >>> from speedplan.route.vda5050 import trajectory_path
    >>> trajectory_path({"controlPoints": [{"x": 0, "y": 0}, {"x": 3, "y": 4}]}).length
    5.0
    """
    traj = _obj(traj, where)
    try:
        return _nurbs(traj, dialect)
    except InvalidInputError as exc:
        # One form for every trajectory message, the NURBS checks' included:
        # "`edges[1].trajectory`: `knots` ...".
        raise InvalidInputError(f"`{where}`: {exc}") from exc


def _nurbs(traj: dict[str, Any], dialect: _Dialect | None) -> Path:
    """The NURBS path of a trajectory object; messages name fields relative to it."""
    if "controlPoints" not in traj:
        raise InvalidInputError("`controlPoints` is missing (the NURBS's {x, y, weight} points)")
    points = _list(traj["controlPoints"], "controlPoints")
    ctrl, weights = [], []
    for j, raw in enumerate(points):
        at = f"controlPoints[{j}]"
        p = _obj(raw, at)
        for key in ("x", "y"):
            if key not in p:
                raise InvalidInputError(f"`{at}` lacks '{key}'")
        ctrl.append([number(p["x"], f"{at}.x"), number(p["y"], f"{at}.y")])
        weights.append(positive(p["weight"], f"{at}.weight") if "weight" in p else 1.0)
    defaults = dialect is None or dialect.trajectory_defaults
    why = "" if dialect is None else f" (required in VDA 5050 {dialect.version})"
    if "degree" in traj:
        degree = integer(traj["degree"], "degree", minimum=1)
    elif defaults:
        degree = 1
    else:
        raise InvalidInputError(f"`degree` is missing{why}")
    if "knotVector" in traj:
        knots = [number(x, f"knotVector[{j}]")
                 for j, x in enumerate(_list(traj["knotVector"], "knotVector"))]
    elif defaults:
        if len(ctrl) < degree + 1:
            raise InvalidInputError(
                f"`controlPoints` holds {len(ctrl)} points; a NURBS of degree {degree} needs at "
                f"least degree + 1 = {degree + 1}"
            )
        knots = uniform_clamped_knots(len(ctrl), degree)
    else:
        raise InvalidInputError(f"`knotVector` is missing{why}")
    return Path.from_nurbs(degree, knots, np.array(ctrl).reshape(-1, 2), weights)
