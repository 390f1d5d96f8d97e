"""Vehicle limits in SI units and their mapping to the paper's constants."""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from .checks import as_scalar
from .errors import InvalidInputError

__all__ = ["LIMIT_RANGE", "Limits"]

#: Finite limits lie within nine decades either side of 1 (SI units): from a stage moving
#: nanometres per second to far beyond any vehicle. Outside it, the model's closed forms
#: (``v³ / j²`` and the like) overflow or underflow in double precision.
LIMIT_RANGE = (1e-9, 1e9)


@dataclass(frozen=True)
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
        Yaw-rate limit ``|κ| v`` [rad/s]; ``None`` or ``inf`` for none (the default).

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
    a_decel: float = field(default=None)  # type: ignore[assignment]
    j_lat_max: float = field(default=None)  # type: ignore[assignment]
    yaw_rate_max: float = field(default=None)  # type: ignore[assignment]

    def __post_init__(self) -> None:
        set_ = object.__setattr__
        set_(self, "v_max", as_scalar("v_max", self.v_max, positive=True))
        set_(self, "a_max", as_scalar("a_max", self.a_max, positive=True))
        set_(self, "a_lat_max", as_scalar("a_lat_max", self.a_lat_max, positive=True,
                                          allow_inf=True))
        set_(self, "j_max", as_scalar("j_max", self.j_max, positive=True, allow_inf=True))
        decel = self.a_max if self.a_decel is None else self.a_decel
        set_(self, "a_decel", as_scalar("a_decel", decel, positive=True))
        for name in ("j_lat_max", "yaw_rate_max"):  # None: no limit, stored as inf
            value = getattr(self, name)
            set_(self, name, np.inf if value is None else as_scalar(name, value, positive=True,
                                                                     allow_inf=True))

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
                     "yaw_rate_max"):
            value = getattr(self, name)
            if np.isfinite(value) and not LIMIT_RANGE[0] <= value <= LIMIT_RANGE[1]:
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
