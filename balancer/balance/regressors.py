"""The inertial shaking over a revolution as linear maps of the design vector (the regressors).

With the crank at constant speed every reaction, the shaking force, the shaking moment and the
driving torque are linear in the design vector of the mechanism's layout
(:class:`balancer.linkage.dynamics.Layout`): per link ``m``, ``m·e``, ``m·f``, ``J`` about the
frame's origin, then the counter-rotors' inertias; and a link's physical values
``(m, e, f, I)`` map to those entries and back.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass
from typing import Any

import numpy as np
from numpy.typing import NDArray

from ..linkage.dynamics import shaking_regressors
from ..mechanisms.base import Mechanism


@dataclass(frozen=True, eq=False)
class CycleRegressors:
    """The inertial shaking over a revolution as linear maps of the design vector.

    Arrays ``(N, P)``: shaking force (complex, N), shaking moment and driving torque (N·m),
    rocking couple (complex ``Mx + i·My``, N·m), per unit of each entry; and where the
    mechanism has supports that share a ground point's reaction (an engine's main bearings),
    their loads one support after another, ``(S·N, P)`` complex, N.
    """

    shaking_force: NDArray[np.complex128]
    shaking_moment: NDArray[np.float64]
    driving_torque: NDArray[np.float64]
    rocking_couple: NDArray[np.complex128]
    supports: NDArray[np.complex128] | None = None


def cycle_regressors(mech: Mechanism, angles: NDArray[np.float64], omega: float,
                     alpha: float = 0.0) -> CycleRegressors:
    """Regressors at crank states ``(θ1, ω, α)``, as the cycle analysis samples them.

    At a sample exactly at a singular pose that the smooth motion passes (a four-bar's change
    points) the rows are the limits of that motion (:meth:`Mechanism.limits`).
    """
    return cycle_regressors_at(mech, angles, [(omega, alpha)])[0]


def cycle_regressors_at(mech: Mechanism, angles: NDArray[np.float64],
                        rates: Sequence[tuple[float, float]], *,
                        torque_at_rest: bool = True) -> list[CycleRegressors]:
    """:func:`cycle_regressors` at each crank rate and acceleration ``(ω, α)`` of ``rates``.

    Computed in one pass over the angles repeated for each (the numpy route's cost is mostly
    per operation, not per state): each is what :func:`cycle_regressors` gives alone, bit
    for bit. With ``torque_at_rest`` false the driving torque of a set at rest (``ω = 0``)
    is not computed (NaN; see :func:`balancer.linkage.dynamics.shaking_regressors`).
    """
    count, n = len(rates), angles.size
    omegas, alphas = (np.array([r[i] for r in rates], dtype=float) for i in (0, 1))

    def evaluate(theta: NDArray[np.float64]) -> tuple[NDArray[Any], ...]:
        m = theta.size
        with np.errstate(all="ignore"):
            mo = mech.motion(np.tile(theta, count), np.repeat(omegas, m), np.repeat(alphas, m))
            f = shaking_regressors(mech.structure, mo, torque_at_rest=torque_at_rest)
        return (f.shaking_force.complex(), np.asarray(f.shaking_moment),
                np.asarray(f.driving_torque), f.rocking_couple.complex())

    values = [np.array(v) for v in evaluate(angles)]  # (copies: the limits are written in)
    for limit in mech.limits(angles):
        parts = [evaluate(angles[limit.mask] + d) for d in limit.offsets]
        mask = np.tile(limit.mask, count)
        for i, target in enumerate(values):
            target[mask] = sum(w * p[i] for w, p in zip(limit.weights, parts, strict=True))
    return [CycleRegressors(*(v[k * n:(k + 1) * n] for v in values)) for k in range(count)]
