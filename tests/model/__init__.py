"""Tests of ``speedplan.model``: boundary states, grids, envelopes and rows of a request."""
