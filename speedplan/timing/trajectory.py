"""A time-sampled trajectory and its export to CSV, JSON and plain arrays."""

from __future__ import annotations

import csv
import json
from dataclasses import dataclass, fields
from os import PathLike
from typing import Any

import numpy as np

from ..core.checks import FloatArray

__all__ = ["COLUMNS", "Trajectory"]

#: Column names with their units, in export order.
COLUMNS: dict[str, str] = {
    "t": "s",
    "s": "m",
    "x": "m",
    "y": "m",
    "heading": "rad",
    "curvature": "1/m",
    "v": "m/s",
    "a": "m/s^2",
    "j": "m/s^3",
    "a_lat": "m/s^2",
    "yaw_rate": "rad/s",
    "j_lat": "m/s^3",
    "direction": "1",
}


@dataclass(frozen=True)
class Trajectory:
    """States of the vehicle sampled in time; every array has the same length.

    Attributes
    ----------
    t : time [s]; s : arc length [m]; x, y : position [m]; heading [rad] (the vehicle's
    yaw, continuous, also through cusps); curvature [1/m] (of the curve in the direction of
    travel); v : speed [m/s] (>= 0, along the direction of travel); a : tangential
    acceleration [m/s²]; j : jerk [m/s³]; a_lat : lateral acceleration ``curvature · v²``
    [m/s²]; yaw_rate : ``curvature · v`` [rad/s]; j_lat : lateral jerk
    ``d(curvature · v²)/dt`` [m/s³]; direction : +1 driving forward, -1 in reverse.
    """

    t: FloatArray
    s: FloatArray
    x: FloatArray
    y: FloatArray
    heading: FloatArray
    curvature: FloatArray
    v: FloatArray
    a: FloatArray
    j: FloatArray
    a_lat: FloatArray
    yaw_rate: FloatArray
    j_lat: FloatArray
    direction: FloatArray

    def __len__(self) -> int:
        return int(self.t.size)

    @property
    def duration(self) -> float:
        """Time of the last sample [s]."""
        return float(self.t[-1])

    def to_dict(self) -> dict[str, FloatArray]:
        """Arrays by column name (see :data:`COLUMNS` for units)."""
        return {f.name: getattr(self, f.name) for f in fields(self)}

    def to_csv(self, file: str | PathLike[str]) -> None:
        """Write a CSV file whose header names each column with its unit, e.g. ``v [m/s]``."""
        data = np.column_stack([getattr(self, name) for name in COLUMNS])
        with open(file, "w", newline="") as fh:
            writer = csv.writer(fh)
            writer.writerow([f"{name} [{unit}]" for name, unit in COLUMNS.items()])
            writer.writerows([[repr(float(x)) for x in row] for row in data])

    def to_json(self, file: str | PathLike[str] | None = None) -> str:
        """Return (and optionally write) ``{"units": {...}, "columns": {name: [values]}}``."""
        doc: dict[str, Any] = {
            "units": dict(COLUMNS),
            "columns": {k: v.tolist() for k, v in self.to_dict().items()},
        }
        text = json.dumps(doc)
        if file is not None:
            with open(file, "w") as fh:
                fh.write(text)
        return text
