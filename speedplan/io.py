"""Path files: CSV waypoints, JSON segments (with optional speed zones), VDA 5050 NURBS.

Formats
-------
CSV waypoints
    A header row with ``x`` and ``y`` columns (an optional ``heading`` column gives the
    waypoint headings of a clothoid chain), then one waypoint per row, metres.
JSON segments
    ``{"start": [x, y], "heading": θ, "segments": [{"type": "line", "length": L},
    {"type": "arc", "radius": R, "angle": α}, {"type": "clothoid", "length": L, "k0": k, "k1": k},
    ...], "zones": [{"polygon": [[x, y], ...], "v_max": v}, ...]}``. Instead of ``segments`` a
    file may give ``"waypoints": [[x, y], ...]`` and ``"kind"``.
VDA 5050
    An edge ``trajectory`` object ``{"degree": d, "knotVector": [...], "controlPoints":
    [{"x": .., "y": .., "weight": ..}, ...]}``, bare, under ``"trajectory"``, or in the first
    entry of ``"edges"`` carrying one.
"""

from __future__ import annotations

import csv
import json
from os import PathLike
from pathlib import Path as FsPath
from typing import Any

import numpy as np

from .errors import InvalidInputError
from .geometry import Path, SpeedZone

__all__ = ["path_from_dict", "read_path", "read_zones", "zones_from_dict"]


def _load(file: str | PathLike[str]) -> tuple[FsPath, Any]:
    fs = FsPath(file)
    if not fs.is_file():
        raise InvalidInputError(f"path file {str(fs)!r} does not exist")
    if fs.suffix.lower() == ".csv":
        return fs, None
    try:
        return fs, json.loads(fs.read_text())
    except (json.JSONDecodeError, UnicodeDecodeError) as exc:
        raise InvalidInputError(f"{fs.name}: not valid JSON ({exc})") from exc


def _read_csv(fs: FsPath) -> Path:
    try:
        with open(fs, newline="") as fh:
            rows = list(csv.reader(line for line in fh if line.strip()
                                   and not line.lstrip().startswith("#")))
    except (OSError, UnicodeDecodeError) as exc:
        raise InvalidInputError(f"{fs.name}: cannot read ({exc})") from exc
    if not rows:
        raise InvalidInputError(f"{fs.name}: empty file")
    header = [h.strip().lower() for h in rows[0]]
    if "x" not in header or "y" not in header:
        raise InvalidInputError(
            f"{fs.name}: the header must name columns 'x' and 'y'; got {rows[0]}"
        )
    try:
        data = np.array([[float(r[i]) for i in range(len(header))] for r in rows[1:]])
    except (ValueError, IndexError) as exc:
        raise InvalidInputError(
            f"{fs.name}: every row needs {len(header)} numbers ({exc})"
        ) from exc
    if data.ndim != 2 or data.shape[0] < 2:
        raise InvalidInputError(f"{fs.name}: needs at least two waypoints")
    xy = data[:, [header.index("x"), header.index("y")]]
    headings = data[:, header.index("heading")] if "heading" in header else None
    try:
        return Path.from_waypoints(xy, kind="clothoid", headings=headings)
    except InvalidInputError as exc:
        raise InvalidInputError(f"{fs.name}: {exc}") from exc


def _vda5050(doc: Any) -> Any:
    if isinstance(doc, dict) and "edges" in doc:
        for edge in doc["edges"]:
            if isinstance(edge, dict) and "trajectory" in edge:
                return edge["trajectory"]
    if isinstance(doc, dict) and "trajectory" in doc:
        return doc["trajectory"]
    if isinstance(doc, dict) and "knotVector" in doc:
        return doc
    return None


def path_from_dict(doc: Any, name: str = "document") -> Path:
    """Build a :class:`Path` from a parsed JSON document (segments, waypoints or VDA 5050)."""
    try:
        traj = _vda5050(doc)
        if traj is not None:
            pts = traj["controlPoints"]
            ctrl = [[p["x"], p["y"]] for p in pts]
            weights = [p.get("weight", 1.0) for p in pts]
            return Path.from_nurbs(traj["degree"], traj["knotVector"], ctrl, weights)
        if not isinstance(doc, dict):
            raise InvalidInputError("expected a JSON object")
        if "segments" in doc:
            return Path.from_segments(doc["segments"], start=doc.get("start", (0.0, 0.0)),
                                      heading=doc.get("heading", 0.0))
        if "waypoints" in doc:
            return Path.from_waypoints(doc["waypoints"], kind=doc.get("kind", "clothoid"))
    except (KeyError, TypeError) as exc:
        raise InvalidInputError(f"{name}: missing or malformed field {exc}") from exc
    except InvalidInputError as exc:
        raise InvalidInputError(f"{name}: {exc}") from exc
    raise InvalidInputError(
        f"{name}: no path found; expected 'segments', 'waypoints' or a VDA 5050 'trajectory'"
    )


def zones_from_dict(doc: Any, name: str = "document") -> list[SpeedZone]:
    """Speed zones listed under ``"zones"`` (empty list when there are none)."""
    if not isinstance(doc, dict) or "zones" not in doc:
        return []
    try:
        return [SpeedZone(z["polygon"], z["v_max"]) for z in doc["zones"]]
    except (KeyError, TypeError) as exc:
        raise InvalidInputError(f"{name}: malformed zone ({exc})") from exc
    except InvalidInputError as exc:
        raise InvalidInputError(f"{name}: {exc}") from exc


def read_path(file: str | PathLike[str]) -> Path:
    """Read a path file (``.csv`` waypoints, ``.json`` segments/waypoints or VDA 5050).

    Raises
    ------
    InvalidInputError
        The file is missing or malformed; the message names the file and what is wrong.
    """
    fs, doc = _load(file)
    if doc is None:
        return _read_csv(fs)
    return path_from_dict(doc, fs.name)


def read_zones(file: str | PathLike[str]) -> list[SpeedZone]:
    """Speed zones stored in a JSON path file (none for CSV files)."""
    fs, doc = _load(file)
    if doc is None:
        return []
    return zones_from_dict(doc, fs.name)
