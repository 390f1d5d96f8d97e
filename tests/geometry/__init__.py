"""Tests of ``speedplan.geometry``: primitives, paths, waypoint fitting, NURBS, speed bounds."""
