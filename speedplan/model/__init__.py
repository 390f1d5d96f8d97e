"""Model: a physical planning request becomes data — legs and their discrete problems.

Modules, one job each:

* `request` — `PlanRequest`, the validated arguments of
  [`speedplan.plan`][speedplan.plan];
* `boundary` — what jerk-limited motions can do from a boundary state
  (envelopes, reachability);
* `grid` — arc-length grids: uniform, graded, the adaptive default grid, and grids made
  finer where a planned law exceeds a limit;
* `leg_grid` — the grid of one leg, as the request asks for it (user, default, no-jerk);
* `rows` — node bounds, boundary envelopes, lateral-jerk rows and the speed caps they imply;
* `standstill` — jerk rows next to a standstill;
* `straight` — straight legs with a constant speed bound: their exact minimum-time motion in
  closed form (no grid);
* `legs` — the data of a model: `Leg`, `ForcedLeg`, `StraightLeg`, `TurnLeg`, `Rest`,
  `TimeLawSpec`,
  `Model`, and
  `explain_infeasible`, which restates a leg's infeasibility in physical terms;
* `build` — `build_model`: request -> `Model`. The problems are solved by
  `speedplan.strategy`; nothing here calls a solver.

This layer imports ``core``, ``geometry`` and the data of ``solve`` (`speedplan.solve.problem`).
"""

from .build import build_model, rest_points
from .legs import ForcedLeg, Leg, Model, ModelLeg, Rest, StraightLeg, TimeLawSpec, TurnLeg
from .request import STANDSTILL_MODES, PlanRequest

__all__ = ["STANDSTILL_MODES", "ForcedLeg", "Leg", "Model", "ModelLeg", "PlanRequest", "Rest",
           "StraightLeg", "TimeLawSpec", "TurnLeg", "build_model", "rest_points"]
