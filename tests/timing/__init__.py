"""Tests of ``speedplan.timing``: the time law, verification and trajectories."""
