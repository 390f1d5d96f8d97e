"""Test configuration: hypothesis profiles (shared values live in ``shared.py``).

Hypothesis profiles (``SPEEDPLAN_HYPOTHESIS=<name> python -m pytest``):

``ci`` (the default)
    derandomised: every run draws the same examples, so a red CI run reproduces locally.
``dev``
    random examples (hypothesis' own default), to explore while developing.
``deep``
    random, and ten times each test's own number of examples (:func:`shared.examples`),
    for an offline soak.
"""

from __future__ import annotations

from hypothesis import settings
from shared import HYPOTHESIS_PROFILE

settings.register_profile("ci", derandomize=True, deadline=None, print_blob=True)
settings.register_profile("dev", deadline=None)
settings.register_profile("deep", deadline=None)
settings.load_profile(HYPOTHESIS_PROFILE)

