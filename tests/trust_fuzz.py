"""The trust fuzz: straight moves over decades of scale, judged by ruckig and finite differences.

Shared by the CI test (``tests/api/test_fuzz.py``, a few hundred cases) and the offline command
(``python benchmarks/fuzz_trust.py --plans 20000``). A case draws a length from 1 mm to
100 km, limits over decades (``v_max`` 0.05–30 m/s, ``a_max`` 0.05–5 m/s², ``j_max``
0.02–50 m/s³) and boundary states on both sides of feasibility; :func:`run_case` plans it and
classifies the outcome. Failures are the categories in :data:`FAILURES`.
"""

from __future__ import annotations

import time
import warnings
from dataclasses import dataclass, field, replace

import numpy as np
from oracles import measure, ruckig_move, within_promise

import speedplan as sp
from speedplan.geometry import Line

#: Outcome categories that are defects.
FAILURES = ("silent_violation", "below_optimum", "false_refusal", "false_accept",
            "solver_error", "crash")
#: Largest relative undercut of ruckig's optimum tolerated (the README's promise).
BELOW = 1e-4
#: Moving boundary states ruckig reaches only with this much more jerk are planned (with a
#: warning) instead of refused — the documented contract (docs/failure-modes.md).
STATE_SLACK = 0.02
#: ... and states ruckig reaches with this much more jerk are planned silently (a state read
#: off a plan lies a rounding outside what j_max reaches; docs/failure-modes.md).
STATE_ROUNDING = 1e-4


@dataclass(frozen=True)
class Case:
    """One straight move."""

    length: float
    limits: sp.Limits
    v0: float = 0.0
    a0: float = 0.0
    vf: float = 0.0
    af: float = 0.0

    def describe(self) -> str:
        """The case as Python arguments."""
        lim = self.limits
        return (f"L={self.length!r}, Limits(v_max={lim.v_max!r}, a_max={lim.a_max!r}, "
                f"a_lat_max=1, j_max={lim.j_max!r}, a_decel={lim.a_decel!r}), v0={self.v0!r}, "
                f"a0={self.a0!r}, vf={self.vf!r}, af={self.af!r}")


@dataclass
class Outcome:
    """What happened to one case."""

    case: Case
    kind: str
    detail: str = ""
    ratios: dict[str, float] = field(default_factory=dict)
    duration_ratio: float | None = None
    seconds: float = 0.0


def draw_case(rng: np.random.Generator) -> Case:
    """A random straight move (see the module docstring for the ranges)."""
    def log(lo: float, hi: float) -> float:
        return float(10 ** rng.uniform(np.log10(lo), np.log10(hi)))

    v_max, a_max, j_max = log(0.05, 30.0), log(0.05, 5.0), log(0.02, 50.0)
    a_decel = a_max if rng.random() < 0.5 else a_max * float(rng.uniform(0.5, 2.0))
    lim = sp.Limits(v_max=v_max, a_max=a_max, a_lat_max=1.0, j_max=j_max, a_decel=a_decel)
    length = log(1e-3, 1e5)
    states = {}
    for v_name, a_name, p_moving in (("v0", "a0", 0.6), ("vf", "af", 0.4)):
        if rng.random() < p_moving:
            v = float(rng.uniform(0.0, 1.05 * v_max))
            a = float(rng.uniform(-1.05 * a_decel, 1.05 * a_max)) if v > 0 else 0.0
            if rng.random() < 0.15 and v > 0:  # near a turnaround: the speed dips close to 0
                a = -np.sqrt(2 * j_max * v) * float(rng.uniform(0.95, 1.05))
                a = a if v_name == "v0" else -a
            states[v_name], states[a_name] = v, a
    return Case(length=length, limits=lim, **states)


def run_case(case: Case, *, samples: int = 20_000) -> Outcome:
    """Plan ``case`` and classify the outcome against ruckig and finite differences."""
    t0 = time.perf_counter()
    lim = case.limits
    path = sp.Path.from_segments([Line(case.length)])
    states = {"v0": case.v0, "a0": case.a0, "vf": case.vf, "af": case.af}
    out_of_range = (case.v0 > lim.v_max or case.vf > lim.v_max
                    or not -lim.a_decel <= case.a0 <= lim.a_max
                    or not -lim.a_decel <= case.af <= lim.a_max)
    try:
        with warnings.catch_warnings(record=True) as caught:
            warnings.simplefilter("always")
            profile = sp.plan(path, lim, **states)
    except sp.InvalidInputError as exc:
        kind = "refused_input" if out_of_range or "too short" in str(exc) else "false_refusal"
        if "path` is" in str(exc) and "shorter than" in str(exc):
            kind = "refused_input"  # below the documented minimum length
        return Outcome(case, kind, str(exc), seconds=time.perf_counter() - t0)
    except sp.InfeasibleError as exc:
        reference = ruckig_move(case.length, lim, **states)
        kind = "refused_infeasible" if reference.duration is None else "false_refusal"
        return Outcome(case, kind, str(exc), seconds=time.perf_counter() - t0)
    except sp.SolverError as exc:
        return Outcome(case, "solver_error", str(exc), seconds=time.perf_counter() - t0)
    except Exception as exc:  # anything else is a crash
        return Outcome(case, "crash", f"{type(exc).__name__}: {exc}",
                       seconds=time.perf_counter() - t0)
    if out_of_range:
        return Outcome(case, "false_accept", "states beyond the limits were accepted")
    if not np.isfinite(profile.duration):
        return Outcome(case, "crash", f"duration {profile.duration}")
    loud = any(issubclass(w.category, sp.LimitWarning) for w in caught)
    if profile.status == "limits_exceeded":
        kind = "flagged" if loud else "silent_violation"
        return Outcome(case, kind, profile.verification.summary() if profile.verification
                       else "", seconds=time.perf_counter() - t0)
    try:
        m = measure(profile, samples=samples)
    except AssertionError as exc:
        return Outcome(case, "silent_violation", f"{exc}", seconds=time.perf_counter() - t0)
    except Exception as exc:
        return Outcome(case, "crash", f"{type(exc).__name__}: {exc}")
    ratios = {"speed": m.speed, "accel": max(m.accel, m.decel), "jerk": m.jerk}
    reference = ruckig_move(case.length, lim, **states)
    ratio = None if reference.duration is None else profile.duration / reference.duration
    seconds = time.perf_counter() - t0
    ends_ok = _ends_match(profile, case)
    if not within_promise(m) or not ends_ok:
        return Outcome(case, "silent_violation", f"status {profile.status}, ends {ends_ok}",
                       ratios, ratio, seconds)
    if reference.duration is None:
        # ruckig found no valid motion but ours meets every limit: ruckig's own failure when
        # it raised. Otherwise it proves there is none under j_max: acceptable only for a
        # state that ruckig reaches with the documented 2 % boundary-state slack, said aloud.
        if reference.error:
            return Outcome(case, "ruckig_error", reference.error, ratios, ratio, seconds)
        said = any("reachable only with" in str(w.message) for w in caught)
        rounding = ruckig_move(case.length,
                               replace(lim, j_max=lim.j_max * (1 + STATE_ROUNDING)), **states)
        if rounding.duration is not None and not said:  # documented: planned silently
            ratio = profile.duration / rounding.duration
            kind = "below_optimum" if ratio < 1 - BELOW else "planned_with_state_rounding"
            return Outcome(case, kind, f"{ratio - 1:+.3e}", ratios, ratio, seconds)
        slack = ruckig_move(case.length, replace(lim, j_max=lim.j_max * (1 + STATE_SLACK)),
                            **states)
        if slack.duration is None or not said:
            return Outcome(case, "false_accept", "", ratios, ratio, seconds)
        ratio = profile.duration / slack.duration
        kind = "below_optimum" if ratio < 1 - BELOW else "planned_with_state_slack"
        return Outcome(case, kind, f"{ratio - 1:+.3e}", ratios, ratio, seconds)
    if ratio is not None and ratio < 1 - BELOW:
        return Outcome(case, "below_optimum", f"{ratio - 1:+.3e}", ratios, ratio, seconds)
    return Outcome(case, "planned", "", ratios, ratio, seconds)


def _ends_match(profile: sp.SpeedProfile, case: Case) -> bool:
    """The sampled trajectory starts and ends in the requested states."""
    traj = profile.at([0.0, profile.duration])
    scale_v, scale_a = case.limits.v_max, case.limits.a_max
    return bool(abs(traj.v[0] - case.v0) <= 1e-9 * scale_v
                and abs(traj.v[-1] - case.vf) <= 1e-9 * scale_v
                and abs(traj.a[0] - case.a0) <= 1e-6 * scale_a
                and abs(traj.a[-1] - case.af) <= 1e-6 * scale_a
                and abs(traj.s[-1] - case.length) <= 1e-9 * case.length)


def summarise(outcomes: list[Outcome]) -> str:
    """Counts per outcome, the worst ratios of planned cases, the worst duration ratio."""
    kinds: dict[str, int] = {}
    for o in outcomes:
        kinds[o.kind] = kinds.get(o.kind, 0) + 1
    planned = [o for o in outcomes if o.kind == "planned"]
    lines = [f"{len(outcomes)} plans: " + ", ".join(f"{k} {v}" for k, v in sorted(kinds.items()))]
    if planned:
        lines.append("measured / limit over the planned cases (median, 99th percentile, max):")
        for name in ("speed", "accel", "jerk"):
            ratios = np.array([o.ratios[name] for o in planned])
            worst = max(planned, key=lambda o: o.ratios[name])
            lines.append(f"  {name:5s} {np.median(ratios):.4f}  {np.quantile(ratios, 0.99):.4f}  "
                         f"{ratios.max():.4f}  (max at {worst.case.describe()})")
        with_ref = [o for o in planned if o.duration_ratio is not None]
        if with_ref:
            ratios = np.array([o.duration_ratio for o in with_ref])
            lo = min(with_ref, key=lambda o: o.duration_ratio)
            hi = max(with_ref, key=lambda o: o.duration_ratio)
            lines.append(f"duration / ruckig's optimum ({len(with_ref)} cases): min "
                         f"{lo.duration_ratio:.8f} (at {lo.case.describe()}), 1st percentile "
                         f"{np.quantile(ratios, 0.01):.8f}, median {np.median(ratios):.8f}, "
                         f"99th percentile {np.quantile(ratios, 0.99):.8f}, max "
                         f"{hi.duration_ratio:.8f}  (max at {hi.case.describe()})")
        secs = np.array([o.seconds for o in planned])
        lines.append(f"seconds per planned case: median {np.median(secs):.3f}, "
                     f"max {secs.max():.3f}")
    return "\n".join(lines)
