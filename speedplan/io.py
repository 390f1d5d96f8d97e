"""Path files (CSV waypoints, JSON segments and zones, VDA 5050 NURBS) and trajectory files.

Formats
-------
CSV waypoints (``.csv``)
    A header row naming the columns, then one waypoint per row, metres; joined by the default
    kind of `Path.from_waypoints` (``"g2"``). Blank lines and lines starting with ``#``
    are ignored. Column names are matched case-insensitively, with surrounding spaces and a
    bracketed unit (``x [m]``) stripped. Read are: ``x`` and ``y`` (required, unit ``m`` if
    given) and at most one of ``heading``, ``yaw`` or ``theta`` (optional, unit ``rad`` if
    given): the waypoint headings of a clothoid chain (``kind="clothoid"``) through those
    poses. **Every other column is ignored**, whatever it holds (numbers, or text such as
    ROS's ``frame_id``), with a [`SpeedplanWarning`][speedplan.SpeedplanWarning] naming the ignored
    columns so that a misspelt heading column does not go unnoticed. The columns that are read
    must hold numbers in every row.
JSON segments (``.json``)
    ``{"start": [x, y], "heading": θ, "segments": [{"type": "line", "length": L},
    {"type": "arc", "radius": R, "angle": α}, {"type": "clothoid", "length": L, "k0": k,
    "k1": k}, ...], "zones": [{"polygon": [[x, y], ...], "holes": [[[x, y], ...]],
    "v_max": v}, ...]}`` (``start``, ``heading``, ``zones`` and ``holes`` optional; a segment
    with ``"reverse": true`` is driven in reverse, ``heading`` is the vehicle's). Instead of
    ``segments`` a file may give ``"waypoints": [[x, y], ...]`` with an optional ``"kind"``
    (default ``"g2"``).
VDA 5050 trajectory (``.json``)
    An edge ``trajectory`` object ``{"degree": d, "knotVector": [...], "controlPoints":
    [{"x": .., "y": .., "weight": ..}, ...]}``, bare or under ``"trajectory"``; as in VDA 5050
    3.0, ``weight`` defaults to 1, ``degree`` to 1 and ``knotVector`` to uniform clamped knots.
VDA 5050 order (``.json``)
    A whole order (``nodes`` and ``edges``) is a route, not a path: `read_route` reads it
    (each edge's geometry, speed limit and stops); `read_path` refuses it and says so.

The readers take a file name or an open text stream (``sys.stdin``, ``io.StringIO``); the
format comes from ``format=``, else the file extension, else (a stream without a name) the
first character: ``{`` or ``[`` is JSON, anything else CSV.

Every reader raises `InvalidInputError` naming the file and what is
wrong; never a raw ``KeyError`` or ``JSONDecodeError``.
"""

from __future__ import annotations

import csv
import io as _io
import json
import re
import warnings
from collections.abc import Sequence
from os import PathLike
from pathlib import Path as FsPath
from typing import IO, Any

import numpy as np
import shapely
from numpy.typing import ArrayLike

from .core.checks import as_array, choice
from .core.errors import InvalidInputError, SpeedplanWarning
from .core.log import logger
from .core.options import FILE_FORMATS, FileFormat, JsonValue, PathKind
from .geometry import Path, SpeedZone
from .geometry.bounds import check_zones
from .geometry.fitting import DEFAULT_KIND, KINDS
from .geometry.primitives import ClothoidPiece
from .route import Route
from .route.profile import RouteTrajectory
from .route.vda5050 import trajectory_path
from .timing.trajectory import COLUMNS, Trajectory, text_output

__all__ = [
    "FORMATS",
    "HEADING_COLUMNS",
    "path_from_dict",
    "path_to_dict",
    "read_path",
    "read_route",
    "read_trajectory",
    "read_zones",
    "write_nurbs",
    "write_path",
    "write_trajectory",
    "write_waypoints",
    "zones_from_dict",
]

FileName = str | PathLike[str]
Source = str | PathLike[str] | IO[str]

#: Path file formats, by the name ``format=`` takes.
FORMATS = FILE_FORMATS

#: Accepted names of the heading column of CSV waypoints [rad] (at most one per file).
HEADING_COLUMNS = ("heading", "yaw", "theta")


def _load_text(file: Source, format: str | None) -> tuple[str, str, str]:
    """``(name, format, text)`` of a path file or an open text stream."""
    if format is not None:
        choice("format", format, FORMATS)
    if hasattr(file, "read"):
        name = str(getattr(file, "name", "<stream>"))
        try:
            text = file.read()
        except (OSError, UnicodeDecodeError) as exc:
            raise InvalidInputError(f"{name}: cannot read ({exc})") from exc
        if not isinstance(text, str):
            raise InvalidInputError(f"{name}: open the stream in text mode, not binary")
        suffix = FsPath(name).suffix.lower().lstrip(".")
        if format is None:
            format = suffix if suffix in FORMATS else (
                "json" if text.lstrip()[:1] in ("{", "[") else "csv")
        logger.debug("read %s from stream %s (%d characters)", format, name, len(text))
        return name, format, text
    fs = FsPath(file)
    if fs.is_dir():
        raise InvalidInputError(f"path file {str(fs)!r} is a directory, not a file")
    if not fs.is_file():
        raise InvalidInputError(f"path file {str(fs)!r} does not exist")
    suffix = fs.suffix.lower()
    if format is None:
        if suffix not in (".csv", ".json"):
            raise InvalidInputError(
                f"{fs.name}: unknown path file type {fs.suffix!r}; use .csv (waypoints) or "
                ".json (segments, waypoints or a VDA 5050 trajectory), or pass `format` "
                "('csv' or 'json')"
            )
        format = suffix[1:]
    try:
        text = fs.read_text(encoding="utf-8")
    except (OSError, UnicodeDecodeError) as exc:
        raise InvalidInputError(f"{fs.name}: cannot read ({exc})") from exc
    logger.debug("read %s file %s (%d characters)", format, fs, len(text))
    return fs.name, format, text


def _parse_json(name: str, text: str) -> Any:
    try:
        return json.loads(text)
    except json.JSONDecodeError as exc:
        raise InvalidInputError(f"{name}: not valid JSON ({exc})") from exc


_COLUMN_NAME = re.compile(r"\s*(.*?)\s*(?:\[\s*(.*?)\s*\])?\s*")


def _csv_table(text: str, name: str) -> tuple[list[str], list[str], list[list[str]]]:
    """``(names, units, rows)`` of a CSV text: ``#`` and blank lines dropped, names lowered."""
    lines = [ln for ln in text.splitlines() if ln.strip() and not ln.lstrip().startswith("#")]
    rows = list(csv.reader(lines))
    if not rows:
        raise InvalidInputError(f"{name}: empty file; expected a header 'x,y' and waypoints")
    names, units = [], []
    for h in rows[0]:
        m = _COLUMN_NAME.fullmatch(h)
        names.append((m.group(1) if m else h).strip().lower())
        units.append((m.group(2) or "") if m else "")
    for i, row in enumerate(rows[1:]):
        if len(row) != len(names):
            raise InvalidInputError(
                f"{name}: data row {i + 1} ({','.join(row)!r}) has {len(row)} values for "
                f"{len(names)} columns"
            )
    return names, units, rows[1:]


def _numeric_column(name: str, rows: list[list[str]], j: int, column: str) -> Any:
    out = np.empty(len(rows))
    for i, row in enumerate(rows):
        try:
            out[i] = float(row[j])
        except ValueError as exc:
            raise InvalidInputError(
                f"{name}: data row {i + 1} ({','.join(row)!r}): column {column!r} must hold a "
                f"number; got {row[j]!r}"
            ) from exc
        if not np.isfinite(out[i]):
            raise InvalidInputError(
                f"{name}: data row {i + 1} ({','.join(row)!r}): column {column!r} must be a "
                f"finite number, not NaN or infinite; got {row[j].strip()!r}"
            )
    return out


def _read_csv(text: str, name: str, kind: str | None) -> Path:
    names, units, rows = _csv_table(text, name)
    if "x" not in names or "y" not in names:
        raise InvalidInputError(
            f"{name}: the header must name columns 'x' and 'y'; got {names}"
        )
    found = [h for h in HEADING_COLUMNS if h in names]
    if len(found) > 1:
        raise InvalidInputError(
            f"{name}: columns {found} both give the heading; keep one of "
            f"{', '.join(map(repr, HEADING_COLUMNS))}"
        )
    wanted = {"x": "m", "y": "m", **{h: "rad" for h in found}}
    for col, unit in wanted.items():
        got = units[names.index(col)]
        if got and got.lower() != unit:
            raise InvalidInputError(
                f"{name}: column {col!r} must be in {unit}; got [{got}] (convert it first)"
            )
    ignored = [names[j] for j in range(len(names)) if names[j] not in wanted]
    if ignored:
        warnings.warn(
            f"{name}: ignored columns {ignored}; only 'x', 'y' and one of "
            f"{', '.join(map(repr, HEADING_COLUMNS))} are read",
            SpeedplanWarning, stacklevel=3,
        )
    if len(rows) < 2:
        raise InvalidInputError(f"{name}: needs at least two waypoints; got {len(rows)}")
    cols = {c: _numeric_column(name, rows, names.index(c), c) for c in wanted}
    xy = np.column_stack((cols["x"], cols["y"]))
    headings = cols[found[0]] if found else None
    # Given headings mean a clothoid chain through those poses; otherwise the one default.
    if kind is None:
        kind = "clothoid" if headings is not None else DEFAULT_KIND
    try:
        if headings is not None and kind == "clothoid":
            return Path.from_waypoints(xy, kind, headings=headings)
        return Path.from_waypoints(xy, kind)
    except InvalidInputError as exc:
        raise InvalidInputError(f"{name}: {exc}") from exc


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


def path_from_dict(doc: JsonValue, name: str = "document") -> Path:
    """Build a `Path` from a parsed JSON document (segments, waypoints or VDA 5050).

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
        fields: dict[str, Any] = doc  # each field is checked by the constructor it goes to
        if "segments" in fields:
            return Path.from_segments(fields["segments"], start=fields.get("start", (0.0, 0.0)),
                                      heading=fields.get("heading", 0.0))
        if "waypoints" in fields:
            return Path.from_waypoints(fields["waypoints"],
                                       kind=fields.get("kind", DEFAULT_KIND))
    except InvalidInputError as exc:
        raise InvalidInputError(f"{name}: {exc}") from exc
    except (KeyError, TypeError, ValueError, AttributeError) as exc:  # safety net: odd JSON
        raise InvalidInputError(f"{name}: malformed path document ({exc!r})") from exc
    raise InvalidInputError(
        f"{name}: no path found; expected 'segments', 'waypoints' or a VDA 5050 'trajectory'"
    )


def zones_from_dict(doc: JsonValue, name: str = "document") -> list[SpeedZone]:
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
            out.append(SpeedZone(_zone_polygon(z), z["v_max"]))  # type: ignore[arg-type]  # checked there
        except InvalidInputError as exc:
            raise InvalidInputError(f"{name}: zones[{i}]: {exc}") from exc
    return out


def _ring(name: str, value: Any) -> Any:
    pts = as_array(name, value)
    if pts.ndim != 2 or pts.shape[1] != 2 or pts.shape[0] < 3:
        raise InvalidInputError(f"`{name}` must be (m, 2) vertices with m >= 3; got shape "
                                f"{pts.shape}")
    return pts


def _zone_polygon(z: dict[str, Any]) -> Any:
    """The zone's ``polygon`` vertices, or a shapely Polygon when it lists ``holes``."""
    if "holes" not in z:
        return z["polygon"]
    holes = z["holes"]
    if not isinstance(holes, list):
        raise InvalidInputError("`holes` must be a list of vertex lists")
    return shapely.Polygon(_ring("polygon", z["polygon"]),
                           [_ring(f"holes[{k}]", h) for k, h in enumerate(holes)])


def read_path(file: Source, *, kind: PathKind | None = None,
              format: FileFormat | None = None) -> Path:
    r"""Read a path file: CSV waypoints, JSON segments/waypoints or a VDA 5050 trajectory.

    Parameters
    ----------
    file : str, os.PathLike or text stream
        The file, or an open text stream such as ``sys.stdin``.
    kind : {"g2", "clothoid", "spline", "polyline"}, optional
        How CSV waypoints are joined; see `Path.from_waypoints`. Default ``"g2"``, or
        ``"clothoid"`` through the given poses when the file has a heading column.
    format : {"csv", "json"}, optional
        The format; default from the file extension, or sniffed from a stream's first
        character (``{`` or ``[``: JSON).

    Raises
    ------
    InvalidInputError
        The file is missing, a directory or malformed; the message names the file and what is
        wrong.

    Warns
    -----
    SpeedplanWarning
        A CSV file has columns that are not read (they are named).

    Examples
    --------
    >>> import io
    >>> from speedplan.io import read_path
    >>> read_path(io.StringIO("x,y\n0,0\n3,4\n")).length
    5.0
    >>> read_path(io.StringIO('{"segments": [{"type": "line", "length": 2.5}]}')).length
    2.5
    """
    if kind is not None and kind not in KINDS:
        raise InvalidInputError(
            f"`kind` must be one of {', '.join(map(repr, KINDS))}; got {kind!r}"
        )
    name, fmt, text = _load_text(file, format)
    path = (_read_csv(text, name, kind) if fmt == "csv"
            else path_from_dict(_parse_json(name, text), name))
    logger.debug("path from %s: %d pieces, %.6g m", name, len(path.pieces), path.length)
    return path


def read_route(file: Source) -> Route:
    """Read a VDA 5050 order file (versions 2.0, 2.1 and 3.0) as a [`Route`][speedplan.Route].

    Parameters
    ----------
    file : str, os.PathLike or text stream
        A JSON file (or an open stream) holding one order message.

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
    if not hasattr(file, "read"):
        return Route.from_vda5050(FsPath(file))
    name, _, text = _load_text(file, "json")
    try:
        return Route.from_vda5050(_parse_json(name, text))
    except InvalidInputError as exc:
        raise InvalidInputError(f"{name}: {exc}") from exc


def read_zones(file: Source, *, format: FileFormat | None = None) -> list[SpeedZone]:
    """Speed zones stored in a JSON path file (none for CSV files).

    ``file`` and ``format`` as in [`read_path`][speedplan.io.read_path].

    Examples
    --------
    >>> import io
    >>> from speedplan.io import read_zones
    >>> doc = '{"zones": [{"polygon": [[0, 0], [4, 0], [4, 1]], "v_max": 0.5}]}'
    >>> [z.v_max for z in read_zones(io.StringIO(doc))]
    [0.5]
    """
    name, fmt, text = _load_text(file, format)
    if fmt == "csv":
        return []
    return zones_from_dict(_parse_json(name, text), name)


# ---- writers --------------------------------------------------------------------------------
def _zone_dicts(zones: Any) -> list[dict[str, Any]]:
    """JSON zone objects; a MultiPolygon zone becomes one object per part (same ``v_max``)."""
    out = []
    for z in check_zones(zones):
        parts = z.polygon.geoms if isinstance(z.polygon, shapely.MultiPolygon) else [z.polygon]
        for poly in parts:
            doc: dict[str, Any] = {"polygon": np.asarray(poly.exterior.coords)[:-1].tolist()}
            if poly.interiors:
                doc["holes"] = [np.asarray(r.coords)[:-1].tolist() for r in poly.interiors]
            doc["v_max"] = z.v_max
            out.append(doc)
    return out


def path_to_dict(path: Path, zones: Sequence[SpeedZone] | None = None
                 ) -> dict[str, JsonValue]:
    """The JSON-segments document of a path made of lines, arcs and clothoids.

    Exact for paths from `Path.from_segments`, G2 corner paths, polylines and clothoid
    chains (and their reversals): every piece is written as a segment from the first piece's
    pose (its vehicle heading); pieces driven in reverse carry ``"reverse": true``.

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
        seg: dict[str, Any]
        if p.k0 == p.k1 == 0.0:
            seg = {"type": "line", "length": p.length}
        elif p.k0 == p.k1:
            seg = {"type": "arc", "radius": 1.0 / abs(p.k0), "angle": p.k0 * p.length}
        else:
            seg = {"type": "clothoid", "length": p.length, "k0": p.k0, "k1": p.k1}
        if p.direction < 0:
            seg["reverse"] = True
        segments.append(seg)
    first = pieces[0]
    doc: dict[str, Any] = {"start": [float(first.start[0]), float(first.start[1])],
                           "heading": float(first.theta0), "segments": segments}
    if zones:
        doc["zones"] = _zone_dicts(zones)
    return doc


def _write_text(file: FileName, text: str, what: str) -> None:
    with text_output(file, what) as fh:
        fh.write(text)


def write_waypoints(file: FileName, xy: ArrayLike, headings: ArrayLike | None = None) -> None:
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
    _write_text(file, buf.getvalue(), "waypoints CSV")


def write_path(
    file: FileName,
    path: Path,
    *,
    zones: Sequence[SpeedZone] | None = None,
    ds: float | None = None,
) -> None:
    """Write a path file; the extension selects the format.

    ``.json``: JSON segments (exact; lines, arcs and clothoids only, see `path_to_dict`),
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
        _write_text(file, json.dumps(path_to_dict(path, zones), indent=1) + "\n", "path JSON")
    elif suffix == ".csv":
        if not isinstance(path, Path):
            raise InvalidInputError(f"`path` must be a speedplan.Path; got {type(path).__name__}")
        smp = path.resample(ds=path.length / 200 if ds is None else ds)
        write_waypoints(file, smp.xy, smp.heading)
    else:
        raise InvalidInputError(
            f"`file` must end in .json (segments) or .csv (waypoints); got {str(file)!r}"
        )


def write_nurbs(
    file: FileName,
    degree: int,
    knots: ArrayLike,
    control_points: ArrayLike,
    weights: ArrayLike | None = None,
) -> None:
    """Write a NURBS path as a VDA 5050 edge ``trajectory`` JSON object (validated first).

    VDA 5050 calls the geometry of an edge its ``trajectory``; it holds no timing. For a
    planned trajectory in time use [`speedplan.Trajectory.to_csv`][speedplan.Trajectory.to_csv] or
    [`to_json`][speedplan.Trajectory.to_json].

    Parameters
    ----------
    file : str or os.PathLike
        The ``.json`` file to write.
    degree, knots, control_points, weights
        As in [`speedplan.Path.from_nurbs`][speedplan.Path.from_nurbs] (``weights`` default 1).

    Examples
    --------
    >>> import os, tempfile
    >>> from speedplan.io import read_path, write_nurbs
    >>> f = os.path.join(tempfile.mkdtemp(), "edge.json")
    >>> write_nurbs(f, 1, [0, 0, 1, 1], [[0, 0], [3, 4]])
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
    _write_text(file, json.dumps(doc, indent=1) + "\n", "VDA 5050 NURBS JSON")


def write_trajectory(file: FileName, degree: int, knots: ArrayLike, control_points: ArrayLike,
                     weights: ArrayLike | None = None) -> None:
    """Deprecated name of `write_nurbs` (it writes a path, not a trajectory in time).

    Warns
    -----
    DeprecationWarning
        Always; call [`write_nurbs`][speedplan.io.write_nurbs] instead.
    """
    warnings.warn(
        "speedplan.io.write_trajectory writes a VDA 5050 NURBS path, not a trajectory in time, "
        "and is renamed write_nurbs; call speedplan.io.write_nurbs (same arguments)",
        DeprecationWarning, stacklevel=2,
    )
    write_nurbs(file, degree, knots, control_points, weights)


# ---- trajectories ---------------------------------------------------------------------------
def _metadata_value(text: str) -> Any:
    try:
        return json.loads(text)
    except json.JSONDecodeError:
        return text  # a plain string (status, version, file name)


def _trajectory_from_columns(name: str, cols: dict[str, Any], metadata: dict[str, Any]
                             ) -> Trajectory:
    missing = [c for c in COLUMNS if c not in cols]
    if missing:
        raise InvalidInputError(f"{name}: not a speedplan trajectory; columns {missing} missing")
    arrays = {c: as_array(f"{name}: column {c!r}", cols[c], ndim=1) for c in COLUMNS}
    sizes = {a.size for a in arrays.values()}
    if len(sizes) != 1 or 0 in sizes:
        raise InvalidInputError(f"{name}: the columns must be non-empty and of equal length")
    arrays["heading"] = np.unwrap(arrays["heading"])  # the file holds it wrapped
    if "edge" in cols:  # a route's trajectory (RouteTrajectory writes the edge last)
        edge = as_array(f"{name}: column 'edge'", cols["edge"], ndim=1)
        if edge.size != arrays["t"].size:
            raise InvalidInputError(f"{name}: the columns must be non-empty and of equal length")
        return RouteTrajectory(**arrays, edge=edge, metadata=metadata)
    return Trajectory(**arrays, metadata=metadata)


def read_trajectory(file: Source, *, format: FileFormat | None = None) -> Trajectory:
    """Read a trajectory written by `Trajectory.to_csv` or `Trajectory.to_json`.

    The values come back bit for bit, except the heading: the files hold it wrapped to
    ``[-π, π)`` and it is unwrapped again (``numpy.unwrap``), so it is continuous and starts
    in ``[-π, π)``. The metadata (``# key: value`` lines of a CSV file) is in
    ``Trajectory.metadata``. A route's trajectory (with an ``edge`` column) comes back as a
    [`RouteTrajectory`][speedplan.route.RouteTrajectory].

    Parameters
    ----------
    file : str, os.PathLike or text stream
        The file; format from ``format``, the extension or the first character.
    format : {"csv", "json"}, optional
        The format.

    Raises
    ------
    InvalidInputError
        The file is missing or is not a speedplan trajectory (a column is missing).

    Examples
    --------
    >>> import io
    >>> import numpy as np
    >>> from speedplan import Limits, Path, plan
    >>> from speedplan.io import read_trajectory
    >>> prof = plan(Path.from_waypoints([[0, 0], [10, 0]], kind="polyline"),
    ...             Limits(v_max=2, a_max=1, a_lat_max=1, j_max=0.5))
    >>> traj = prof.sample(0.1)
    >>> buf = io.StringIO()
    >>> traj.to_csv(buf)
    >>> back = read_trajectory(io.StringIO(buf.getvalue()))
    >>> bool(np.array_equal(back.v, traj.v)), back.metadata["heading_range"]
    (True, '[-pi, pi)')
    """
    name, fmt, text = _load_text(file, format)
    if fmt == "json":
        doc = _parse_json(name, text)
        if not isinstance(doc, dict) or not isinstance(doc.get("columns"), dict):
            raise InvalidInputError(f"{name}: not a speedplan trajectory; no 'columns' object")
        meta = doc.get("metadata", {})
        return _trajectory_from_columns(name, doc["columns"], meta if isinstance(meta, dict)
                                        else {})
    metadata: dict[str, Any] = {}
    for line in text.splitlines():
        if line.startswith("#") and ":" in line:
            key, _, value = line[1:].partition(":")
            metadata[key.strip()] = _metadata_value(value.strip())
    names, _units, rows = _csv_table(text, name)
    cols = {c: _numeric_column(name, rows, names.index(c), c) for c in (*COLUMNS, "edge")
            if c in names}
    return _trajectory_from_columns(name, cols, metadata)
