"""Bad input raises InvalidInputError whose message names the argument."""

from __future__ import annotations

import re

import numpy as np
import pytest
import shapely

from speedplan import InvalidInputError, Path
from speedplan.geometry import Arc, Clothoid, Line

LINE = Path.from_segments([Line(1.0)])
CTRL3 = [[0, 0], [1, 1], [2, 0]]


@pytest.mark.parametrize(
    ("call", "name"),
    [
        # waypoints
        (lambda: Path.from_waypoints([[0, 0], [np.nan, 1]]), "xy"),
        (lambda: Path.from_waypoints([[0, 0], [np.inf, 1]]), "xy"),
        (lambda: Path.from_waypoints([[0, 0]]), "xy"),
        (lambda: Path.from_waypoints([[1, 1], [1, 1], [1, 1]]), "xy"),
        (lambda: Path.from_waypoints([[0, 0], [1, 0], [1, 0], [2, 0]]), "xy"),
        (lambda: Path.from_waypoints(np.zeros((3, 3))), "xy"),
        (lambda: Path.from_waypoints([0, 1, 2, 3]), "xy"),
        (lambda: Path.from_waypoints("abc"), "xy"),
        (lambda: Path.from_waypoints([[0, 0], [1, 0]], kind="bezier"), "kind"),
        (lambda: Path.from_waypoints([[0, 0], [2, 0], [0, 0]], kind="polyline"), "xy"),
        (lambda: Path.from_waypoints([[0, 0], [1, 0], [1, 1]], kind="clothoid",
                                     headings=[0, 1]), "headings"),
        (lambda: Path.from_waypoints([[0, 0], [1, 0]], kind="clothoid", headings=[0, np.nan]),
         "headings"),
        (lambda: Path.from_waypoints([[0, 0], [1, 0]], kind="spline", headings=[0, 0]),
         "headings"),
        (lambda: Path.from_waypoints([[0, 0], [1, 0], [1, 1]], kind="polyline",
                                     corner_radius=-1.0), "corner_radius"),
        (lambda: Path.from_waypoints([[0, 0], [1, 0], [1, 1]], kind="polyline",
                                     max_deviation=0.0), "max_deviation"),
        (lambda: Path.from_waypoints([[0, 0], [1, 0], [1, 1]], kind="clothoid",
                                     max_deviation=0.1), "max_deviation"),
        (lambda: Path.from_linestring([(0, 0), (1, 0)]), "ls"),
        (lambda: Path.from_linestring(shapely.LineString([(0, 0), (1, 0), (1, 0), (2, 0)])),
         "ls"),
        # segments
        (lambda: Path.from_segments([Line(-1.0)]), "length"),
        (lambda: Path.from_segments([Line(0.0)]), "length"),
        (lambda: Arc(-2.0, 1.0), "radius"),
        (lambda: Arc(2.0, 0.0), "angle"),
        (lambda: Clothoid(1.0, np.nan, 0.0), "k0"),
        (lambda: Path.from_segments([{"type": "line", "length": -1}]), "segments[0].length"),
        (lambda: Path.from_segments([Line(1), {"type": "arc", "radius": 0, "angle": 1}]),
         "segments[1].radius"),
        (lambda: Path.from_segments([{"type": "arc", "radius": 1}]), "segments[0]"),
        (lambda: Path.from_segments([{"type": "line", "length": 1, "lenght": 2}]),
         "segments[0]"),
        (lambda: Path.from_segments([{"type": "spiral", "length": 1}]), "segments[0]"),
        (lambda: Path.from_segments([3.0]), "segments[0]"),
        (lambda: Path.from_segments([]), "segments"),
        (lambda: Path.from_segments(Line(1.0)), "segments"),
        (lambda: Path.from_segments([Line(1.0)], start=(0, 0, 0)), "start"),
        (lambda: Path.from_segments([Line(1.0)], heading=np.nan), "heading"),
        # NURBS
        (lambda: Path.from_nurbs(2, [0, 0, 1, 0.5, 1, 1], CTRL3), "knots"),
        (lambda: Path.from_nurbs(2, [0, 0, 0, 1, 1], CTRL3), "knots"),
        (lambda: Path.from_nurbs(2, [1, 1, 1, 1, 1, 1], CTRL3), "knots"),
        (lambda: Path.from_nurbs(2, [0, 0, 0, 1, 1, 1], CTRL3, [1, -1, 1]), "weights"),
        (lambda: Path.from_nurbs(2, [0, 0, 0, 1, 1, 1], CTRL3, [1, 0, 1]), "weights"),
        (lambda: Path.from_nurbs(2, [0, 0, 0, 1, 1, 1], CTRL3, [1, 1]), "weights"),
        (lambda: Path.from_nurbs(0, [0, 0, 1, 1], [[0, 0], [1, 1]]), "degree"),
        (lambda: Path.from_nurbs(2.5, [0, 0, 0, 1, 1, 1], CTRL3), "degree"),
        (lambda: Path.from_nurbs(2, [0, 0, 0, 1, 1, 1], [[0, 0], [1, 1]]), "control_points"),
        (lambda: Path.from_nurbs(2, [0, 0, 0, 1, 1, 1], [[0, 0], [1, np.nan], [2, 0]]),
         "control_points"),
        (lambda: Path.from_nurbs(2, [0, 0, 0, 1, 1, 1], [[1, 1]] * 3), "control_points"),
        # queries
        (lambda: LINE.point(np.nan), "s"),
        (lambda: LINE.heading(1.5), "s"),
        (lambda: LINE.curvature("x"), "s"),
        (lambda: LINE.resample(n=1), "n"),
        (lambda: LINE.resample(n=2.5), "n"),
        (lambda: LINE.resample(ds=0.0), "ds"),
        (lambda: LINE.to_linestring(ds=-1.0), "ds"),
        (lambda: Path(()), "pieces"),
    ],
)
def test_bad_input_names_the_argument(call, name):
    with pytest.raises(InvalidInputError, match=re.escape(f"`{name}")):
        call()


def test_invalid_input_is_a_value_error():
    with pytest.raises(ValueError, match="`kind`"):
        Path.from_waypoints([[0, 0], [1, 0]], kind="nope")
