"""Random instances of the paper's experiment (its Section "Performed tests").

Three generators for ``w_max`` (``"rnd"``, ``"pw cnst"``, ``"pw lin"``), three for ``A``
(``"cnst"``, ``"rnd"``, ``"reg"``) and two for ``J`` (``"cnst"``, ``"rnd"``): 18 families, with
``h = 1``. ``"reg"`` is a random walk whose steps respect the paper's condition
``|A_{i+1} - A_i| / h <= J / w_max_i`` (eq. condacc). ``J_kind="logrnd"`` is our addition:
log-uniform over ``[1e-2, 1e2]``, which makes the relaxation non-exact on most instances.
"""

from __future__ import annotations

from dataclasses import dataclass
from itertools import product

import numpy as np

from ..core.checks import FloatArray, choice

__all__ = ["FAMILIES", "PaperInstance", "paper_instance"]

W_KINDS = ("rnd", "pw cnst", "pw lin")
A_KINDS = ("cnst", "rnd", "reg")
J_KINDS = ("cnst", "rnd", "logrnd")
#: The paper's 18 families in the order of its table: (W, A, J).
FAMILIES: tuple[tuple[str, str, str], ...] = tuple(
    (w, a, j) for j, a, w in product(("cnst", "rnd"), A_KINDS, W_KINDS)
)


@dataclass(frozen=True)
class PaperInstance:
    """One random instance: ``w_max`` (n,), ``A`` (n-1,), ``J`` (n-2,), ``h = 1``."""

    w_max: FloatArray
    A: FloatArray
    J: FloatArray
    family: tuple[str, str, str]


def _w_max(kind: str, n: int, rng: np.random.Generator) -> FloatArray:
    blocks = 10
    if kind == "rnd":
        return rng.uniform(0.01, 100.0, n)
    if kind == "pw cnst":
        values = rng.uniform(0.01, 100.0, blocks)
        return np.asarray(values[np.minimum(np.arange(n) * blocks // n, blocks - 1)])
    knots = np.linspace(0, n - 1, blocks + 1)
    return np.interp(np.arange(n), knots, rng.uniform(0.1, 100.0, blocks + 1))


def paper_instance(
    w_kind: str, a_kind: str, j_kind: str, n: int = 1000, *, seed: int | None = None
) -> PaperInstance:
    """Draw one instance of the family ``(w_kind, a_kind, j_kind)``.

    The end values of ``w_max`` are irrelevant: the problem pins ``w_1 = w_n = 0``.

    Examples
    --------
    >>> from speedplan.solve.paper import paper_instance
    >>> inst = paper_instance("pw lin", "reg", "cnst", n=100, seed=0)
    >>> inst.w_max.shape, inst.A.shape, inst.J.shape
    ((100,), (99,), (98,))
    """
    choice("w_kind", w_kind, W_KINDS)
    choice("a_kind", a_kind, A_KINDS)
    choice("j_kind", j_kind, J_KINDS)
    rng = np.random.default_rng(seed)
    w_max = _w_max(w_kind, n, rng)
    if j_kind == "cnst":
        J = np.full(n - 2, rng.uniform(0.01, 100.0))
    elif j_kind == "rnd":
        J = rng.uniform(0.01, 100.0, n - 2)
    else:
        J = 10.0 ** rng.uniform(-2.0, 2.0, n - 2)
    if a_kind == "cnst":
        A = np.full(n - 1, rng.uniform(0.1, 100.0))
    elif a_kind == "rnd":
        A = rng.uniform(0.1, 100.0, n - 1)
    else:
        # Step bound at segment i from the jerk bound of the nearest interior node.
        j_seg = np.concatenate((J[:1], J))
        step = j_seg / w_max[:-1]
        increments = rng.uniform(-1.0, 1.0, n - 2) * step[1:]
        A = np.empty(n - 1)
        A[0] = rng.uniform(0.1, 100.0)
        for i, d in enumerate(increments):  # clipped random walk: sequential by nature
            A[i + 1] = min(max(A[i] + d, 0.1), 100.0)
    return PaperInstance(w_max=w_max, A=A, J=J, family=(w_kind, a_kind, j_kind))
