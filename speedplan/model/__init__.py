"""Model: a physical planning request becomes a discrete problem.

Modules, one job each:

* `request` — `PlanRequest`, the validated arguments of
  [`speedplan.plan`][speedplan.plan];
* `boundary` — what jerk-limited motions can do from a boundary state
  (envelopes, reachability);
* `grid` — the default arc-length grids;
* `standstill` — jerk rows next to a standstill;
* `refine` — local grid refinement where a law exceeds a limit;
* `build` — `build_model`: request -> `Model` (speed bound,
  [`DiscreteProblem`][speedplan.DiscreteProblem], time-law options); the problems are solved by
  `speedplan.strategy`, and `explain_infeasible` restates
  their infeasibilities in physical terms.

This layer imports ``core``, ``geometry`` and ``solve``.
"""

from .build import ForcedLeg, Leg, Model, Rest, TimeLawSpec, build_model, rest_points
from .request import STANDSTILL_MODES, PlanRequest

__all__ = ["STANDSTILL_MODES", "ForcedLeg", "Leg", "Model", "PlanRequest", "Rest", "TimeLawSpec",
           "build_model", "rest_points"]
