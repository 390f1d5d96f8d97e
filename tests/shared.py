"""Values shared by the tests: the LGV limits of the sample paths, also as CLI flags."""

from __future__ import annotations

import os

from speedplan import Limits

#: The forklift / LGV limits every sample path is planned with (README, docs, benchmarks).
LGV = Limits(v_max=2.0, a_max=1.0, a_lat_max=1.0, j_max=0.5)

#: :data:`LGV` as ``speedplan plan`` flags.
LGV_ARGS = ["--v-max", "2", "--a-max", "1", "--a-lat-max", "1", "--j-max", "0.5"]

#: The hypothesis profile of this run (registered in ``conftest.py``).
HYPOTHESIS_PROFILE = os.environ.get("SPEEDPLAN_HYPOTHESIS", "ci")
if HYPOTHESIS_PROFILE not in ("ci", "dev", "deep"):
    raise ValueError(f"SPEEDPLAN_HYPOTHESIS={HYPOTHESIS_PROFILE!r}: use 'ci', 'dev' or 'deep'")


def examples(n: int) -> int:
    """``n`` hypothesis examples, ten times as many under the ``deep`` profile."""
    return 10 * n if HYPOTHESIS_PROFILE == "deep" else n
