"""The crank's speed fluctuation as a bound of a linkage's balancing (``max_speed_fluctuation``).

At a constant operating speed ω the inertial driving torque is ``½·J'(θ)·ω²`` (``J(θ)`` the
inertia the crank sees: the driving torque at rest under unit crank acceleration, linear in the
design vector, :func:`~.regressors.cycle_regressors_at` at ``(0, 1)``), so the energy its
turning-moment diagram swings through over a revolution is ``ΔE = ½·ω²·(J_max − J_min)``, and
the classical estimate of the speed fluctuation with a flywheel ``I_f`` on the crank is

    δ = ΔE / ((I_f + J̄)·ω²) = (J_max − J_min) / (2·(I_f + J̄))

(``J̄`` the mean over the revolution: the estimate :mod:`balancer.speed_fluctuation` reports
beside its exact one). Balancing moves ``J``: heavier links and counter-rotors raise its swing
and its mean. The bound ``δ ≤ δ_max`` is, for every pair of sampled angles ``(i, j)``,

    J_i(x) − J_j(x) − 2·δ_max·J̄(x) ≤ 2·δ_max·I_f,

linear in the design vector ``x``: the balancing stays a convex program. Of the ``N²`` pairs
only those its optimum meets matter; they are found by cutting planes (the convex solver adds
the pair of the design's largest and least ``J`` while its optimum breaks the bound), each
program a relaxation of the next, the last one's optimum feasible for all: the certified bound
of that relaxation is one of the whole problem's. The loads (gravity, applied forces) are left
out, as the balancing's objective leaves them; so are the links' own inertias and the
counter-rotors', which change no shaking at constant speed (the objective does not see them):
they are held as the spec gives them, and the bound is kept by the masses and first moments —
a flywheel (``flywheel``) lowers ``δ`` for any design.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray


@dataclass(frozen=True)
class FluctuationBound:
    """The bound ``δ ≤ δ_max`` over a design vector (module docstring).

    Attributes
    ----------
    inertia
        ``J(θ_i)`` per unit entry of the design vector, ``(N, P)``, kg·m² (its linear map).
    bound
        ``δ_max``, dimensionless.
    flywheel
        ``I_f``, kg·m², on the crank beside the mechanism.
    scale
        A typical inertia of its rows, kg·m²: the flywheel's, or the original's largest ``J``.
    """

    inertia: NDArray[np.float64]
    bound: float
    flywheel: float
    scale: float

    def values(self, x: NDArray[np.float64]) -> NDArray[np.float64]:
        """``J(θ_i)`` of design ``x``, kg·m²."""
        return self.inertia @ np.asarray(x, dtype=float)

    def fluctuation(self, x: NDArray[np.float64]) -> float:
        """``δ`` of design ``x``: ``(J_max − J_min)/(2·(I_f + J̄))``."""
        j = self.values(x)
        return float((j.max() - j.min()) / (2.0 * (self.flywheel + j.mean())))

    def excess(self, x: NDArray[np.float64]) -> float:
        """How far ``x`` breaks the bound, kg·m² (≤ 0: it keeps it): the worst pair's row."""
        j = self.values(x)
        return float(j.max() - j.min() - 2.0 * self.bound * (self.flywheel + j.mean()))

    def worst_pair(self, x: NDArray[np.float64]) -> tuple[int, int]:
        """The samples of ``x``'s largest and least ``J``."""
        j = self.values(x)
        return int(np.argmax(j)), int(np.argmin(j))

    def row(self, pair: tuple[int, int]) -> tuple[NDArray[np.float64], float]:
        """Pair ``(i, j)``'s constraint ``a·x ≤ b``: ``a`` (P,) and ``b``, kg·m²."""
        i, j = pair
        a = self.inertia[i] - self.inertia[j] - 2.0 * self.bound * self.inertia.mean(axis=0)
        return a, 2.0 * self.bound * self.flywheel


@dataclass(frozen=True)
class FluctuationFigures:
    """The crank's speed fluctuation before and after a balancing that bounds it.

    Attributes
    ----------
    bound, flywheel
        ``δ_max`` and ``I_f`` (kg·m²), as the spec gives them.
    before, after
        ``δ`` of the original design and of the balanced one (the turning-moment estimate of
        their inertia, with the flywheel).
    """

    bound: float
    flywheel: float
    before: float
    after: float

    def as_dict(self) -> dict[str, float]:
        """``optimize --json``'s ``speed_fluctuation``."""
        return {"bound": self.bound, "flywheel": self.flywheel, "before": self.before,
                "after": self.after}


__all__ = ["FluctuationBound", "FluctuationFigures"]
