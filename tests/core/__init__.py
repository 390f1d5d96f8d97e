"""Tests of ``speedplan.core``: compiling the kernels, their cache and fallbacks."""
