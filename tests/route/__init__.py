"""Tests of ``speedplan.route`` and ``plan_route``: routes, VDA 5050 orders, turns, updates."""
