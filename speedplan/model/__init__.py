"""Model: a physical planning request becomes a discrete problem.

Modules, one job each:

* :mod:`~speedplan.model.request` — :class:`PlanRequest`, the validated arguments of
  :func:`speedplan.plan`;
* :mod:`~speedplan.model.boundary` — what jerk-limited motions can do from a boundary state
  (envelopes, reachability);
* :mod:`~speedplan.model.grid` — the default arc-length grids;
* :mod:`~speedplan.model.standstill` — jerk rows next to a standstill;
* :mod:`~speedplan.model.refine` — local grid refinement where a law exceeds a limit;
* :mod:`~speedplan.model.build` — :func:`build_model`: request -> :class:`Model` (speed bound,
  :class:`~speedplan.solve.DiscreteProblem`, time-law options); the problems are solved by
  :mod:`speedplan.strategy`, and :func:`~speedplan.model.build.explain_infeasible` restates
  their infeasibilities in physical terms.

This layer imports ``core``, ``geometry`` and ``solve``.
"""

from .build import ForcedLeg, Leg, Model, Rest, TimeLawSpec, build_model, rest_points
from .request import STANDSTILL_MODES, PlanRequest

__all__ = ["STANDSTILL_MODES", "ForcedLeg", "Leg", "Model", "PlanRequest", "Rest", "TimeLawSpec",
           "build_model", "rest_points"]
