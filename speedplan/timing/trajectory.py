"""A time-sampled trajectory and its export to CSV, JSON and plain arrays.

Every writer iterates over `COLUMNS`, the single list of columns and their units: a
column added there is exported everywhere.
"""

from __future__ import annotations

import dataclasses
import json
from collections.abc import Iterator, Mapping
from contextlib import contextmanager
from dataclasses import dataclass, field
from os import PathLike
from pathlib import Path as FsPath
from typing import IO, Any

import numpy as np

from .._version import __version__
from ..core.checks import FloatArray
from ..core.errors import InvalidInputError
from ..core.log import logger
from ..core.numerics import wrap_heading

__all__ = ["COLUMNS", "HEADING_RANGE", "Trajectory"]

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

#: Range of the ``heading`` column in exported files (in memory the heading is continuous).
HEADING_RANGE = "[-pi, pi)"

TextFile = str | PathLike[str] | IO[str]


class _FrozenDict(Mapping[str, object]):
    """A read-only mapping (nested mappings and lists frozen too) that pickles."""

    __slots__ = ("_data",)

    def __init__(self, data: Mapping[str, object] | None = None) -> None:
        self._data = {str(k): _freeze(v) for k, v in (data or {}).items()}

    def __getitem__(self, key: str) -> object:
        return self._data[key]

    def __iter__(self) -> Iterator[str]:
        return iter(self._data)

    def __len__(self) -> int:
        return len(self._data)

    def __repr__(self) -> str:
        return repr(self._data)

    def __reduce__(self) -> tuple[Any, ...]:
        return (_FrozenDict, (self._data,))


def _freeze(value: Any) -> Any:
    if isinstance(value, Mapping):
        return value if isinstance(value, _FrozenDict) else _FrozenDict(value)
    if isinstance(value, list | tuple):
        return tuple(_freeze(v) for v in value)
    if isinstance(value, np.ndarray):
        return tuple(value.tolist())
    if isinstance(value, np.generic):
        return value.item()
    return value


def _jsonable(value: Any) -> Any:
    """``value`` as plain JSON data; non-finite floats (an absent limit) become ``None``."""
    if isinstance(value, Mapping):
        return {str(k): _jsonable(v) for k, v in value.items()}
    if dataclasses.is_dataclass(value) and not isinstance(value, type):
        return {f.name: _jsonable(getattr(value, f.name)) for f in dataclasses.fields(value)}
    if isinstance(value, list | tuple | np.ndarray):
        return [_jsonable(v) for v in value]
    if isinstance(value, np.generic):
        value = value.item()
    if isinstance(value, float):
        return value if np.isfinite(value) else None
    if value is None or isinstance(value, bool | int | str):
        return value
    return str(value)


def _write_rows(fh: IO[str], data: FloatArray, precision: int | None = None,
                chunk: int = 4096) -> None:
    """The rows of ``data`` as CSV, one ``%`` operation per block of rows.

    Each number is the shortest decimal that reads back bit for bit (``repr``: ``0.04``, not
    ``0.040000000000000001``), or has ``precision`` significant digits.
    """
    fmt = "%r" if precision is None else f"%.{precision}g"
    row = ",".join([fmt] * data.shape[1]) + "\n"
    for k in range(0, data.shape[0], chunk):
        block = data[k : k + chunk]
        text = (row * block.shape[0]) % tuple(block.ravel().tolist())
        if precision is None:  # a whole number's repr ends in ".0" (1.0, -0.0): drop it
            text = text.replace(".0,", ",").replace(".0\n", "\n")
        fh.write(text)


def _comment_value(value: Any) -> str:
    """A metadata value on one CSV comment line: strings as they are, the rest as JSON."""
    if isinstance(value, str) and "\n" not in value:
        return value
    return json.dumps(value)


@contextmanager
def text_output(file: TextFile, what: str) -> Iterator[IO[str]]:
    """An open text handle: ``file`` itself when it has ``write``, else the file it names.

    A missing directory or an unwritable file raises `InvalidInputError` naming
    ``what`` is being written and where.
    """
    if hasattr(file, "write"):
        yield file  # type: ignore[misc]
        return
    fs = FsPath(file)
    if not fs.parent.is_dir():
        raise InvalidInputError(
            f"cannot write the {what} to {str(fs)!r}: directory {str(fs.parent)!r} does not "
            "exist; create it first"
        )
    try:
        fh = fs.open("w", encoding="utf-8", newline="")
    except OSError as exc:
        raise InvalidInputError(f"cannot write the {what} to {str(fs)!r} ({exc})") from exc
    with fh:
        yield fh
    logger.debug("wrote %s %s", what, fs)


@dataclass(frozen=True)
class Trajectory:
    """States of the vehicle sampled in time; every array has the same length.

    Attributes
    ----------
    t : time [s]; s : arc length [m]; x, y : position [m]; heading [rad] (the vehicle's
    yaw, continuous: unwrapped, also through cusps); curvature [1/m] (of the curve in the
    direction of travel); v : speed [m/s] (>= 0, along the direction of travel); a :
    tangential acceleration [m/s²]; j : jerk [m/s³]; a_lat : lateral acceleration
    ``curvature · v²`` [m/s²]; yaw_rate : ``curvature · v`` [rad/s]; j_lat : lateral jerk
    ``d(curvature · v²)/dt`` [m/s³]; direction : +1 driving forward, -1 in reverse.
    metadata : Mapping
        Read-only facts about how the trajectory was made (e.g. ``duration``, ``status``,
        ``gap``, ``lower_bound``, ``limits``, ``dt``, ``path_file``); the writers store it.
        Default empty.

    Notes
    -----
    The exports (`to_csv`, `to_json`) write the heading wrapped to ``[-π, π)``,
    the yaw convention of ROS and most controllers; `to_dict` and the attribute keep
    it continuous, which is what differentiating or interpolating it needs.
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
    metadata: Mapping[str, object] = field(default_factory=_FrozenDict, compare=False)

    def __post_init__(self) -> None:
        object.__setattr__(self, "metadata", _freeze(dict(self.metadata)))

    def __len__(self) -> int:
        return int(self.t.size)

    @property
    def duration(self) -> float:
        """Time of the last sample [s]."""
        return float(self.t[-1])

    @property
    def units(self) -> dict[str, str]:
        """Column names with their units, in export order.

        `COLUMNS`; a subclass such as `speedplan.route.RouteTrajectory` appends
        its own.
        """
        return dict(COLUMNS)

    def to_dict(self) -> dict[str, FloatArray]:
        """Arrays by column name, heading continuous (see [`units`][speedplan.Trajectory.units])."""
        return {name: getattr(self, name) for name in self.units}

    def _export_columns(self) -> dict[str, FloatArray]:
        cols = self.to_dict()
        cols["heading"] = wrap_heading(cols["heading"])
        return cols

    def _export_metadata(self) -> dict[str, Any]:
        meta: dict[str, Any] = {"speedplan_version": __version__}
        meta.update(_jsonable(self.metadata))
        meta["heading_range"] = HEADING_RANGE
        return meta

    def to_csv(self, file: TextFile, *, precision: int | None = None) -> None:
        """Write CSV: ``# key: value`` metadata lines, a header ``t [s],s [m],...``, the rows.

        By default each number is the shortest decimal that reads back as the same float64
        bit for bit (``0.04``, not ``0.040000000000000001``); ``precision`` writes that many
        significant digits instead (smaller files, values rounded). The heading is wrapped to
        ``[-π, π)``. Metadata values
        that are not strings are JSON (``null`` for an absent limit). To read the file:
        `speedplan.io.read_trajectory`, ``pandas.read_csv(f, comment="#")``, or in
        plain numpy skip the ``#`` lines and the header (``numpy.genfromtxt(names=True)``
        would take the first comment line for the header).

        Parameters
        ----------
        file : str, os.PathLike or text file object
            Where to write; a path's directory must exist.
        precision : int, optional
            Significant digits of every number (1 to 17); default the shortest exact form.

        Raises
        ------
        InvalidInputError
            The directory does not exist or the file cannot be written, or ``precision`` is
            not an integer from 1 to 17.

        Examples
        --------
        >>> import io
        >>> import numpy as np
        >>> from speedplan import Limits, Path, plan
        >>> prof = plan(Path.from_waypoints([[0, 0], [10, 0]], kind="polyline"),
        ...             Limits(v_max=2, a_max=1, a_lat_max=1, j_max=0.5))
        >>> traj = prof.sample(0.1)
        >>> buf = io.StringIO()
        >>> traj.to_csv(buf)
        >>> lines = buf.getvalue().splitlines()
        >>> lines[-len(traj) - 1].split(",")[:3]
        ['t [s]', 's [m]', 'x [m]']
        >>> back = np.loadtxt(lines[-len(traj):], delimiter=",")
        >>> bool(np.array_equal(back[:, 6], traj.v))
        True
        """
        if precision is not None and not (isinstance(precision, int | np.integer)
                                          and not isinstance(precision, bool)
                                          and 1 <= precision <= 17):
            raise InvalidInputError(
                f"`precision` must be an integer from 1 to 17 (significant digits) or None; "
                f"got {precision!r}")
        cols = self._export_columns()
        data = np.column_stack(list(cols.values()))
        lines = [f"# {k}: {_comment_value(v)}" for k, v in self._export_metadata().items()]
        lines.append(",".join(f"{name} [{unit}]" for name, unit in self.units.items()))
        with text_output(file, "trajectory CSV") as fh:
            fh.write("\n".join(lines) + "\n")
            _write_rows(fh, data, None if precision is None else int(precision))

    def to_json(self, file: TextFile | None = None) -> str:
        """Return (and optionally write) the trajectory as JSON.

        ``{"metadata": {...}, "units": {name: unit}, "columns": {name: [values]}}``; the
        values read back bit for bit, the heading is wrapped to ``[-π, π)`` and an absent
        limit in the metadata is ``null``.

        Parameters
        ----------
        file : str, os.PathLike or text file object, optional
            Where to write, as for `to_csv`; by default only the string is returned.

        Raises
        ------
        InvalidInputError
            As [`to_csv`][speedplan.Trajectory.to_csv] raises it, when ``file`` cannot be written.

        Examples
        --------
        >>> import json
        >>> from speedplan import Limits, Path, plan
        >>> prof = plan(Path.from_waypoints([[0, 0], [10, 0]], kind="polyline"),
        ...             Limits(v_max=2, a_max=1, a_lat_max=1, j_max=0.5))
        >>> doc = json.loads(prof.sample(0.1).to_json())
        >>> doc["units"]["v"], len(doc["columns"]["t"]) > 10
        ('m/s', True)
        """
        doc: dict[str, Any] = {
            "metadata": self._export_metadata(),
            "units": self.units,
            "columns": {k: v.tolist() for k, v in self._export_columns().items()},
        }
        text = json.dumps(doc)
        if file is not None:
            with text_output(file, "trajectory JSON") as fh:
                fh.write(text)
        return text
