"""Path files: CSV waypoints, JSON segments (with optional speed zones), VDA 5050 NURBS.

Formats
-------
CSV waypoints (``.csv``)
    A header row naming ``x`` and ``y`` columns (an optional ``heading`` column [rad] gives the
    waypoint headings of a clothoid chain), then one waypoint per row, metres. Blank lines and
    lines starting with ``#`` are ignored.
JSON segments (``.json``)
    ``{"start": [x, y], "heading": θ, "segments": [{"type": "line", "length": L},
    {"type": "arc", "radius": R, "angle": α}, {"type": "clothoid", "length": L, "k0": k,
    "k1": k}, ...], "zones": [{"polygon": [[x, y], ...], "v_max": v}, ...]}`` (``start``,
    ``heading`` and ``zones`` optional). Instead of ``segments`` a file may give
    ``"waypoints": [[x, y], ...]`` with an optional ``"kind"``.
VDA 5050 trajectory (``.json``)
    An edge ``trajectory`` object ``{"degree": d, "knotVector": [...], "controlPoints":
    [{"x": .., "y": .., "weight": ..}, ...]}``, bare or under ``"trajectory"``; as in VDA 5050
    3.0, ``weight`` defaults to 1, ``degree`` to 1 and ``knotVector`` to uniform clamped knots.
VDA 5050 order (``.json``)
    A whole order (``nodes`` and ``edges``) is a route, not a path: :func:`read_route` reads it
    (each edge's geometry, speed limit and stops); :func:`read_path` refuses it and says so.

Every reader raises :class:`~speedplan.errors.InvalidInputError` naming the file and what is
wrong; never a raw ``KeyError`` or ``JSONDecodeError``.
"""

from __future__ import annotations

import csv
import io as _io
import json
from collections.abc import Sequence
from os import PathLike
from pathlib import Path as FsPath
from typing import Any

import numpy as np

from .core.checks import as_array
from .core.errors import InvalidInputError
from .geometry import Path, SpeedZone
from .geometry.fitting import KINDS
from .geometry.primitives import ClothoidPiece
from .route import Route
from .route.vda5050 import trajectory_path

__all__ = [
    "path_from_dict",
    "path_to_dict",
    "read_path",
    "read_route",
    "read_zones",
    "write_path",
    "write_trajectory",
    "write_waypoints",
    "zones_from_dict",
]

FileName = str | PathLike[str]


def _load(file: FileName) -> tuple[FsPath, Any]:
    """``(path, parsed JSON)``; the document is ``None`` for CSV files."""
    fs = FsPath(file)
    if not fs.is_file():
        raise InvalidInputError(f"path file {str(fs)!r} does not exist")
    suffix = fs.suffix.lower()
    if suffix == ".csv":
        return fs, None
    if suffix != ".json":
        raise InvalidInputError(
            f"{fs.name}: unknown path file type {fs.suffix!r}; use .csv (waypoints) or .json "
            "(segments, waypoints or a VDA 5050 trajectory)"
        )
    try:
        return fs, json.loads(fs.read_text(encoding="utf-8"))
    except (json.JSONDecodeError, UnicodeDecodeError) as exc:
        raise InvalidInputError(f"{fs.name}: not valid JSON ({exc})") from exc
    except OSError as exc:
        raise InvalidInputError(f"{fs.name}: cannot read ({exc})") from exc


def _read_csv(fs: FsPath, kind: str | None) -> Path:
    try:
        text = fs.read_text(encoding="utf-8")
    except (OSError, UnicodeDecodeError) as exc:
        raise InvalidInputError(f"{fs.name}: cannot read ({exc})") from exc
    lines = [ln for ln in text.splitlines() if ln.strip() and not ln.lstrip().startswith("#")]
    rows = list(csv.reader(lines))
    if not rows:
        raise InvalidInputError(f"{fs.name}: empty file; expected a header 'x,y' and waypoints")
    header = [h.strip().lower() for h in rows[0]]
    if "x" not in header or "y" not in header:
        raise InvalidInputError(
            f"{fs.name}: the header must name columns 'x' and 'y'; got {rows[0]}"
        )
    data = np.empty((len(rows) - 1, len(header)))
    for i, row in enumerate(rows[1:]):
        try:
            if len(row) != len(header):
                raise ValueError(f"{len(row)} values for {len(header)} columns")
            data[i] = [float(v) for v in row]
        except ValueError as exc:
            raise InvalidInputError(
                f"{fs.name}: data row {i + 1} ({','.join(row)!r}) must hold {len(header)} "
                f"numbers ({exc})"
            ) from exc
    if data.shape[0] < 2:
        raise InvalidInputError(f"{fs.name}: needs at least two waypoints; got {data.shape[0]}")
    xy = data[:, [header.index("x"), header.index("y")]]
    headings = data[:, header.index("heading")] if "heading" in header else None
    kind = "clothoid" if kind is None else kind
    try:
        if headings is not None and kind == "clothoid":
            return Path.from_waypoints(xy, kind, headings=headings)
        return Path.from_waypoints(xy, kind)
    except InvalidInputError as exc:
        raise InvalidInputError(f"{fs.name}: {exc}") from exc


def _vda5050(doc: Any) -> Any:
    """The VDA 5050 ``trajectory`` object inside ``doc``, or ``None``; refuses whole orders."""
    if not isinstance(doc, dict):
        return None
    if "edges" in doc or "nodes" in doc:
        # Reading one edge of an order as "the path" dropped the others, their speed limits and
        # the stops without a word.
        raise InvalidInputError(
            "this is a VDA 5050 order ('nodes'/'edges'), a route rather than one path: read it "
            "with speedplan.io.read_route, which keeps every edge, its speed limit and the "
            "stops (read_path reads a single trajectory)"
        )
    if "trajectory" in doc:
        return doc["trajectory"]
    if "knotVector" in doc or "controlPoints" in doc:
        return doc
    return None


def _nurbs_from_trajectory(traj: Any) -> Path:
    return trajectory_path(traj, "trajectory")


def path_from_dict(doc: Any, name: str = "document") -> Path:
    """Build a :class:`Path` from a parsed JSON document (segments, waypoints or VDA 5050).

    Parameters
    ----------
    doc : dict
        The parsed document (see the module docstring for the formats).
    name : str
        Name used in error messages (the file name when reading a file).

    Examples
    --------
    >>> from speedplan.io import path_from_dict
    >>> path_from_dict({"segments": [{"type": "line", "length": 2.5}]}).length
    2.5
    """
    try:
        traj = _vda5050(doc)
        if traj is not None:
            return _nurbs_from_trajectory(traj)
        if not isinstance(doc, dict):
            raise InvalidInputError(f"expected a JSON object; got {type(doc).__name__}")
        if "segments" in doc:
            return Path.from_segments(doc["segments"], start=doc.get("start", (0.0, 0.0)),
                                      heading=doc.get("heading", 0.0))
        if "waypoints" in doc:
            return Path.from_waypoints(doc["waypoints"], kind=doc.get("kind", "clothoid"))
    except InvalidInputError as exc:
        raise InvalidInputError(f"{name}: {exc}") from exc
    except (KeyError, TypeError, ValueError, AttributeError) as exc:  # safety net: odd JSON
        raise InvalidInputError(f"{name}: malformed path document ({exc!r})") from exc
    raise InvalidInputError(
        f"{name}: no path found; expected 'segments', 'waypoints' or a VDA 5050 'trajectory'"
    )


def zones_from_dict(doc: Any, name: str = "document") -> list[SpeedZone]:
    """Speed zones listed under ``"zones"`` (an empty list when there are none).

    Examples
    --------
    >>> from speedplan.io import zones_from_dict
    >>> z, = zones_from_dict({"zones": [{"polygon": [[0, 0], [1, 0], [1, 1]], "v_max": 0.3}]})
    >>> z.v_max, z.polygon.area
    (0.3, 0.5)
    """
    if not isinstance(doc, dict) or "zones" not in doc:
        return []
    zones = doc["zones"]
    if not isinstance(zones, list):
        raise InvalidInputError(f"{name}: 'zones' must be a list of {{polygon, v_max}} objects")
    out = []
    for i, z in enumerate(zones):
        if not isinstance(z, dict) or "polygon" not in z or "v_max" not in z:
            raise InvalidInputError(f"{name}: zones[{i}] must be an object with 'polygon' and "
                                    "'v_max'")
        try:
            out.append(SpeedZone(z["polygon"], z["v_max"]))
        except InvalidInputError as exc:
            raise InvalidInputError(f"{name}: zones[{i}]: {exc}") from exc
    return out


def read_path(file: FileName, *, kind: str | None = None) -> Path:
    """Read a path file: ``.csv`` waypoints, ``.json`` segments/waypoints or VDA 5050.

    Parameters
    ----------
    file : str or os.PathLike
        The file; its extension selects the format.
    kind : {"clothoid", "spline", "polyline"}, optional
        How CSV waypoints are joined (default ``"clothoid"``); see :meth:`Path.from_waypoints`.

    Raises
    ------
    InvalidInputError
        The file is missing or malformed; the message names the file and what is wrong.

    Examples
    --------
    >>> from speedplan.io import read_path
    >>> round(read_path("paths/slow_zone.json").length, 9)  # doctest: +SKIP
    40.0
    """
    if kind is not None and kind not in KINDS:
        raise InvalidInputError(
            f"`kind` must be one of {', '.join(map(repr, KINDS))}; got {kind!r}"
        )
    fs, doc = _load(file)
    if doc is None:
        return _read_csv(fs, kind)
    return path_from_dict(doc, fs.name)


def read_route(file: FileName) -> Route:
    """Read a VDA 5050 order file (versions 2.0, 2.1 and 3.0) as a :class:`~speedplan.route.Route`.

    Parameters
    ----------
    file : str or os.PathLike
        A JSON file holding one order message.

    Raises
    ------
    InvalidInputError
        The file is missing or the order malformed; the message names the file and the
        element (e.g. ``order.json: `edges[1].trajectory`: ...``).

    Examples
    --------
    >>> import json, os, tempfile
    >>> from speedplan.io import read_route
    >>> node = lambda i, x, actions: {"nodeId": f"N{i}", "sequenceId": 2 * i, "released": True,
    ...     "nodePosition": {"x": x, "y": 0.0, "mapId": "m"}, "actions": actions}
    >>> pick = [{"actionType": "pick", "actionId": "p1", "blockingType": "HARD"}]
    >>> edge = lambda i: {"edgeId": f"E{i}", "sequenceId": 2 * i + 1, "released": True,
    ...     "startNodeId": f"N{i}", "endNodeId": f"N{i + 1}", "maxSpeed": 1.0 + i, "actions": []}
    >>> f = os.path.join(tempfile.mkdtemp(), "order.json")
    >>> with open(f, "w") as fh:
    ...     json.dump({"version": "2.0.0", "nodes": [node(0, 0.0, []), node(1, 5.0, pick),
    ...                node(2, 10.0, [])], "edges": [edge(0), edge(1)]}, fh)
    >>> route = read_route(f)
    >>> route.length, [e.v_max for e in route.edges], route.stop_s.tolist()
    (10.0, [1.0, 2.0], [0.0, 5.0, 10.0])
    """
    return Route.from_vda5050(FsPath(file))


def read_zones(file: FileName) -> list[SpeedZone]:
    """Speed zones stored in a JSON path file (none for CSV files).

    Examples
    --------
    >>> from speedplan.io import read_zones
    >>> [z.v_max for z in read_zones("paths/slow_zone.json")]  # doctest: +SKIP
    [0.5]
    """
    fs, doc = _load(file)
    if doc is None:
        return []
    return zones_from_dict(doc, fs.name)


# ---- writers --------------------------------------------------------------------------------
def _zone_dicts(zones: Sequence[SpeedZone] | None) -> list[dict[str, Any]]:
    out = []
    for i, z in enumerate(zones or ()):
        if not isinstance(z, SpeedZone):
            raise InvalidInputError(f"`zones[{i}]` must be a SpeedZone; got {type(z).__name__}")
        ring = np.asarray(z.polygon.exterior.coords)[:-1]
        out.append({"polygon": ring.tolist(), "v_max": z.v_max})
    return out


def path_to_dict(path: Path, zones: Sequence[SpeedZone] | None = None) -> dict[str, Any]:
    """The JSON-segments document of a path made of lines, arcs and clothoids.

    Exact for paths from :meth:`Path.from_segments`, polylines and clothoid chains (and their
    reversals): every piece is written as a segment from the first piece's pose.

    Raises
    ------
    InvalidInputError
        The path has spline or NURBS pieces (write those as waypoints or keep the original
        VDA 5050 trajectory).

    Examples
    --------
    >>> import numpy as np
    >>> from speedplan.geometry import Arc, Line, Path
    >>> from speedplan.io import path_to_dict
    >>> path_to_dict(Path.from_segments([Line(2.0), Arc(1.0, -np.pi / 2)]))["segments"]
    [{'type': 'line', 'length': 2.0}, {'type': 'arc', 'radius': 1.0, 'angle': -1.5707963267948966}]
    """
    if not isinstance(path, Path):
        raise InvalidInputError(f"`path` must be a speedplan.Path; got {type(path).__name__}")
    pieces = [p for p in path.pieces if isinstance(p, ClothoidPiece)]
    if len(pieces) != len(path.pieces):
        raise InvalidInputError(
            "`path` has spline or NURBS pieces, which JSON segments cannot hold; write it as "
            "CSV waypoints (write_path('file.csv', path)) or keep its VDA 5050 trajectory"
        )
    segments: list[dict[str, Any]] = []
    for p in pieces:
        if p.k0 == p.k1 == 0.0:
            segments.append({"type": "line", "length": p.length})
        elif p.k0 == p.k1:
            segments.append({"type": "arc", "radius": 1.0 / abs(p.k0),
                             "angle": p.k0 * p.length})
        else:
            segments.append({"type": "clothoid", "length": p.length, "k0": p.k0, "k1": p.k1})
    first = pieces[0]
    doc: dict[str, Any] = {"start": [float(first.start[0]), float(first.start[1])],
                           "heading": float(first.theta0), "segments": segments}
    if zones:
        doc["zones"] = _zone_dicts(zones)
    return doc


def _write_text(file: FileName, text: str) -> None:
    try:
        FsPath(file).write_text(text, encoding="utf-8")
    except OSError as exc:
        raise InvalidInputError(f"cannot write {str(file)!r} ({exc})") from exc


def write_waypoints(file: FileName, xy: Any, headings: Any = None) -> None:
    """Write waypoints [m] (and headings [rad]) as CSV with an ``x,y[,heading]`` header.

    Examples
    --------
    >>> import tempfile, os
    >>> from speedplan.io import read_path, write_waypoints
    >>> f = os.path.join(tempfile.mkdtemp(), "w.csv")
    >>> write_waypoints(f, [[0, 0], [3, 4]])
    >>> read_path(f).length
    5.0
    """
    pts = as_array("xy", xy)
    if pts.ndim != 2 or pts.shape[1] != 2:
        raise InvalidInputError(f"`xy` must have shape (n, 2); got {pts.shape}")
    cols = [pts[:, 0], pts[:, 1]]
    header = ["x", "y"]
    if headings is not None:
        cols.append(as_array("headings", headings, ndim=1, length=pts.shape[0]))
        header.append("heading")
    buf = _io.StringIO()
    writer = csv.writer(buf, lineterminator="\n")
    writer.writerow(header)
    writer.writerows(np.column_stack(cols).tolist())  # repr-exact floats
    _write_text(file, buf.getvalue())


def write_path(
    file: FileName,
    path: Path,
    *,
    zones: Sequence[SpeedZone] | None = None,
    ds: float | None = None,
) -> None:
    """Write a path file; the extension selects the format.

    ``.json``: JSON segments (exact; lines, arcs and clothoids only, see :func:`path_to_dict`),
    with ``zones`` if given. ``.csv``: waypoints with headings sampled every ``ds`` metres
    (default ``length / 200``); read back, they give a clothoid chain through the samples with
    the sampled headings — an approximation whose error shrinks with ``ds`` (zones are not
    stored).

    Examples
    --------
    >>> import os, tempfile
    >>> import numpy as np
    >>> from speedplan.geometry import Arc, Line, Path
    >>> from speedplan.io import read_path, write_path
    >>> p = Path.from_segments([Line(2.0), Arc(1.0, np.pi / 2)])
    >>> f = os.path.join(tempfile.mkdtemp(), "p.json")
    >>> write_path(f, p)
    >>> abs(read_path(f).length - p.length) < 1e-12
    True
    """
    suffix = FsPath(file).suffix.lower()
    if suffix == ".json":
        _write_text(file, json.dumps(path_to_dict(path, zones), indent=1) + "\n")
    elif suffix == ".csv":
        if not isinstance(path, Path):
            raise InvalidInputError(f"`path` must be a speedplan.Path; got {type(path).__name__}")
        smp = path.resample(ds=path.length / 200 if ds is None else ds)
        write_waypoints(file, smp.xy, smp.heading)
    else:
        raise InvalidInputError(
            f"`file` must end in .json (segments) or .csv (waypoints); got {str(file)!r}"
        )


def write_trajectory(
    file: FileName,
    degree: int,
    knots: Any,
    control_points: Any,
    weights: Any = None,
) -> None:
    """Write a NURBS as a VDA 5050 edge ``trajectory`` JSON object (validated first).

    Examples
    --------
    >>> import os, tempfile
    >>> from speedplan.io import read_path, write_trajectory
    >>> f = os.path.join(tempfile.mkdtemp(), "edge.json")
    >>> write_trajectory(f, 1, [0, 0, 1, 1], [[0, 0], [3, 4]])
    >>> read_path(f).length
    5.0
    """
    Path.from_nurbs(degree, knots, control_points, weights)  # raises on bad input
    ctrl = np.asarray(control_points, dtype=np.float64)
    w = np.ones(ctrl.shape[0]) if weights is None else np.asarray(weights, dtype=np.float64)
    doc = {"trajectory": {
        "degree": int(degree),
        "knotVector": np.asarray(knots, dtype=np.float64).tolist(),
        "controlPoints": [{"x": float(x), "y": float(y), "weight": float(wi)}
                          for (x, y), wi in zip(ctrl, w, strict=True)],
    }}
    _write_text(file, json.dumps(doc, indent=1) + "\n")
