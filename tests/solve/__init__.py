"""Tests of ``speedplan.solve``: the discrete problem, its relaxation backends and refinement."""
