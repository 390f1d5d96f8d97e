"""Vehicle limits in SI units and their mapping to the paper's constants."""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from .checks import as_scalar
from .errors import InvalidInputError
from .options import GRIP_MODELS, Grip, check_option

__all__ = ["DEFAULT_YAW_ACC", "GRIP_MODELS", "LIMIT_RANGE", "Limits"]

#: Finite limits lie within nine decades either side of 1 (SI units): from a stage moving
#: nanometres per second to far beyond any vehicle. Outside it, the model's closed forms
#: (``v³ / j²`` and the like) overflow or underflow in double precision.
LIMIT_RANGE = (1e-9, 1e9)

#: Default yaw-acceleration limit [rad/s²] of a vehicle turning on the spot: a quarter turn
#: takes at least ``2 sqrt((π/2) / 1) = 2.5`` s, within what differential-drive and
#: omnidirectional AGVs/AMRs commonly reach (wheel accelerations of ``α b / 2`` for a track
#: width ``b`` of about 1 m). Pass the vehicle's own value for real plans.
DEFAULT_YAW_ACC = 1.0


@dataclass(frozen=True, init=False)
class Limits:
    """Kinematic limits of a vehicle, SI units.

    Parameters
    ----------
    v_max : float
        Speed limit [m/s].
    a_max : float
        Tangential acceleration limit [m/s²].
    a_lat_max : float
        Lateral (centripetal) acceleration limit [m/s²]; ``inf`` for none.
    j_max : float
        Jerk limit, the time derivative of tangential acceleration [m/s³]; ``inf`` for none.
    a_decel : float, optional
        Braking limit [m/s²]; defaults to ``a_max``.
    j_lat_max : float, optional
        Lateral jerk limit, the time derivative of the lateral acceleration ``κ v²`` [m/s³];
        ``None`` or ``inf`` for none (the default). Finite only on curvature-continuous (G2)
        paths: where the curvature jumps the vehicle has to stop.
    yaw_rate_max : float, optional
        Yaw-rate limit ``|κ| v`` [rad/s]; ``None`` or ``inf`` for none (the default). It also
        bounds the yaw rate of a turn on the spot (see `speedplan.plan_route`).
    yaw_acc_max : float, optional
        Yaw-acceleration limit of a turn on the spot [rad/s²], where a route makes the vehicle
        stop and rotate (a corner it may not cut, a node orientation): > 0, default
        `DEFAULT_YAW_ACC` (1 rad/s²; ``inf`` is refused, no vehicle turns in no time).
        While driving, the yaw acceleration ``d(κ v)/dt`` is bounded through ``j_lat_max``
        and the path's curvature instead.
    yaw_jerk_max : float, optional
        Limit on the rate of change of the yaw acceleration in a turn on the spot [rad/s³];
        ``None`` or ``inf`` for none (the default: the yaw acceleration steps between
        ``±yaw_acc_max`` and 0). Finite, the turn is an S-curve whose yaw acceleration is
        continuous.
    grip : {"independent", "ellipse"}
        ``"independent"`` (default): the tangential and the lateral acceleration each within
        its own limit. ``"ellipse"``: they share one friction ellipse,
        ``(a / a_max)² + (a_lat / a_lat_max)² <= 1`` with ``a_decel`` for ``a_max`` when
        braking — a road vehicle cannot brake fully while cornering at its lateral limit.
        A second-order cone in ``w``: the relaxation keeps its certificate. Needs a finite
        ``a_lat_max``.

    Notes
    -----
    With ``w = v²`` the paper's constants are ``A = 2 a_max`` (and ``2 a_decel`` when
    braking), ``J = 2 j_max`` and ``A_N = a_lat_max``.

    Examples
    --------
    >>> from speedplan import Limits
    >>> lim = Limits(v_max=2.0, a_max=1.0, a_lat_max=1.0, j_max=0.5)
    >>> lim.a_decel, lim.A, lim.J
    (1.0, 2.0, 1.0)
    """

    v_max: float
    a_max: float
    a_lat_max: float
    j_max: float
    a_decel: float
    j_lat_max: float
    yaw_rate_max: float
    yaw_acc_max: float
    yaw_jerk_max: float
    grip: Grip

    def __init__(self, v_max: float, a_max: float, a_lat_max: float, j_max: float,
                 a_decel: float | None = None, j_lat_max: float | None = None,
                 yaw_rate_max: float | None = None, yaw_acc_max: float = DEFAULT_YAW_ACC,
                 yaw_jerk_max: float | None = None, grip: Grip = "independent") -> None:
        # Written out so that the optional limits take None while the attributes are floats.
        set_ = object.__setattr__
        set_(self, "v_max", as_scalar("v_max", v_max, positive=True))
        set_(self, "a_max", as_scalar("a_max", a_max, positive=True))
        set_(self, "a_lat_max", as_scalar("a_lat_max", a_lat_max, positive=True,
                                          allow_inf=True))
        set_(self, "j_max", as_scalar("j_max", j_max, positive=True, allow_inf=True))
        decel = self.a_max if a_decel is None else a_decel
        set_(self, "a_decel", as_scalar("a_decel", decel, positive=True))
        for name, value in (("j_lat_max", j_lat_max), ("yaw_rate_max", yaw_rate_max),
                            ("yaw_jerk_max", yaw_jerk_max)):  # None: no limit, inf
            set_(self, name, np.inf if value is None else as_scalar(name, value, positive=True,
                                                                     allow_inf=True))
        set_(self, "yaw_acc_max", as_scalar("yaw_acc_max", yaw_acc_max, positive=True))
        set_(self, "grip", check_option("grip", grip, GRIP_MODELS))
        if self.grip == "ellipse" and not np.isfinite(self.a_lat_max):
            raise InvalidInputError(
                "`grip`='ellipse' shares the grip between `a_max` and `a_lat_max`: give a "
                "finite `a_lat_max`, or grip='independent'")

    @property
    def ellipse(self) -> bool:
        """Whether the accelerations share a friction ellipse (``grip="ellipse"``)."""
        return self.grip == "ellipse"

    def check_range(self) -> None:
        """Raise `InvalidInputError` unless every finite limit is in range.

        The range is `LIMIT_RANGE`. [`speedplan.plan`][speedplan.plan] checks the limits it is
        given; the limits it derives may pass the range's ends (a marginal boundary state
        planned with 2 % more jerk than ``j_max = 1e9``).

        Examples
        --------
        >>> from speedplan import InvalidInputError
        >>> try:
        ...     Limits(v_max=1e300, a_max=1, a_lat_max=1, j_max=1).check_range()
        ... except InvalidInputError as exc:
        ...     print(str(exc)[:40])
        `v_max`=1e+300 is outside [1e-09, 1e+09]
        """
        for name in ("v_max", "a_max", "a_lat_max", "j_max", "a_decel", "j_lat_max",
                     "yaw_rate_max", "yaw_acc_max", "yaw_jerk_max"):
            value = getattr(self, name)
            if math.isfinite(value) and not LIMIT_RANGE[0] <= value <= LIMIT_RANGE[1]:
                raise InvalidInputError(
                    f"`{name}`={value!r} is outside [{LIMIT_RANGE[0]:g}, {LIMIT_RANGE[1]:g}], "
                    "the range of finite limits planned for (SI units); pass inf for no "
                    "limit, or express the problem in other units (e.g. mm, ms)"
                )

    @property
    def A(self) -> float:
        """Paper's acceleration bound on ``w' = d(v²)/ds``: ``2 a_max`` [m/s²]."""
        return 2.0 * self.a_max

    @property
    def A_decel(self) -> float:
        """Braking bound on ``-w'``: ``2 a_decel`` [m/s²]."""
        return 2.0 * self.a_decel

    @property
    def J(self) -> float:
        """Paper's jerk bound on ``w'' sqrt(w)``: ``2 j_max`` [m/s³]."""
        return 2.0 * self.j_max
