"""The redesign problem's data, and the parts of its design vector.

:class:`ProblemData` holds what :func:`~balancer.balance.problem.numeric_problem` computes once
(the regressors over the revolution, per-link bounds, the objective's rows, the force-balance
conditions) and answers what every other part of :class:`~balancer.balance.problem.NumericProblem`
asks of the design vector: where each link's entries are, what a counterweight's own entries are
(:meth:`ProblemData.own`) and whether it is there at all (:meth:`ProblemData.absent`), the
entries' typical magnitudes, the total mass.
"""

from __future__ import annotations

from dataclasses import dataclass
from functools import cached_property

import numpy as np
from numpy.typing import NDArray

from ..linkage.inputs import InputState
from ..mechanisms.base import Mechanism
from ..model import MechanismModel as Model
from ..model.balance import BalanceProblem, Objective, RotorBalanceProblem
from .bounds import LinkBounds
from .regressors import CycleRegressors
from .sites import Sites

#: A counterweight whose mass may be zero (``counterweight = { mass = [0, hi], … }``) and whose
#: own mass, first moments and inertia are all within this share of the link's scales (``m``,
#: ``m·l``, ``m·l²``) is none: the link is kept as it is (:meth:`ProblemData.absent`). An
#: interior-point solver approaches a counterweight of no mass only as the apex of its cone, with
#: a centre of mass that the ratio of two vanishing first moments puts anywhere.
ABSENT = 1e-9


@dataclass(frozen=True, kw_only=True, eq=False)
class ProblemData:
    """The redesign problem in numbers, built once by :func:`~.problem.numeric_problem`.

    The objective is ``J(x) = ‖K·x‖² + w_m·(Σm − Σm_original)`` with ``K`` the weighted
    regressor rows (shaking moment, driving torque, shaking force) divided by ``√N``;
    :attr:`factor` ``R`` (from a QR factorisation of ``K``) has ``‖R·x‖ = ‖K·x‖`` and only as
    many rows as the design vector has entries, which is what the optimisers use.

    Attributes
    ----------
    problem
        The spec-side problem.
    mechanism
        The original design's mechanism.
    speed
        Crank speed, rad/s (``None``: a linkage with several inputs, sampled along motions).
    states
        The sampled states: a one-input mechanism's crank angles over a revolution at
        :attr:`speed`, or the states along the spec's motions, one after another.
    regressors
        The inertial shaking at those states per unit entry (:class:`CycleRegressors`; a
        linkage with several inputs: each row weighted by its motion's share, the inputs'
        torques stacked, see :func:`~.problem.numeric_problem`).
    links
        Resolved bounds of every moving link.
    x0
        Design vector of the original.
    rows
        ``K`` above, ``(rows, P)``, N·m.
    factor
        ``R`` above, upper triangular, N·m.
    force_balance
        ``(A, b)``: ``A·x = b`` is shaking-force balance
        (:func:`balancer.force_balance.force_balance_conditions`), or ``None`` when force
        balance is not imposed.
    inert
        Entries of ``x`` (inertias about the frames' origins, counter-rotors) that change
        nothing the objective measures: their regressor columns vanish (a crank's at constant
        speed: ``α1 = 0``). The optimisers leave them out;
        :meth:`~.settling.Settling.settle` then gives them the value nearest the original's
        that the bounds allow.
    """

    problem: BalanceProblem | RotorBalanceProblem
    mechanism: Mechanism
    speed: float | None
    states: InputState
    regressors: CycleRegressors
    links: tuple[LinkBounds, ...]
    x0: NDArray[np.float64]
    rows: NDArray[np.float64]
    factor: NDArray[np.float64]
    force_balance: tuple[NDArray[np.float64], NDArray[np.float64]] | None
    inert: tuple[bool, ...]
    #: The regressors at rest under unit crank acceleration (``θ̇1 = 0``, ``θ̈1 = 1``) on the
    #: same angles, where they were computed with :attr:`regressors`
    #: (:attr:`~.settling.Settling.acceleration_factor` computes them otherwise); what it
    #: uses, their shaking moment (their driving torque is NaN where the crank turns at the
    #: operating speed: not computed).
    unit_acceleration: CycleRegressors | None = None
    #: An engine's mass·radius sites (:mod:`.sites`), whose two entries each follow the
    #: linkage's in the design vector; ``None`` for a linkage's redesign.
    sites: Sites | None = None

    @property
    def linkage(self) -> Model:
        """The original design's model."""
        return self.mechanism.model

    @property
    def size(self) -> int:
        """Number of entries of the design vector ``P``."""
        return self.x0.size

    @property
    def samples(self) -> int:
        """Number of sampled states ``N``."""
        return self.states.count

    @property
    def weights(self) -> Objective:
        """The objective's weights."""
        return self.problem.objective

    @property
    def support_bound(self) -> float | None:
        """The largest load a support (an engine's main bearing) may carry, N, or none."""
        problem = self.problem
        return problem.max_bearing_load if isinstance(problem, RotorBalanceProblem) else None

    @cached_property
    def preferred(self) -> NDArray[np.float64]:
        """The design the tie-break moves towards among optimal ones.

        The original (the least change), with an engine's chosen mass·radius sites none (the
        least mass·radius, as their bounds scale it).
        """
        if self.sites is None:
            return self.x0
        out = self.x0.copy()
        out[self.sites.chosen_entries(self.size)] = 0.0
        return out

    @cached_property
    def mass_entries(self) -> list[int]:
        """Positions of the links' masses in the design vector."""
        return [b.start for b in self.links]

    @cached_property
    def offset(self) -> NDArray[np.float64]:
        """The design vector's part that no bound concerns: the kept links' own entries.

        Zero except for a link with a counterweight, whose four entries hold the original
        link's (:attr:`LinkBounds.offset`).
        """
        out = np.zeros(self.size)
        for b in self.links:
            if b.offset is not None:
                out[b.entries] = b.offset
        return out

    @cached_property
    def _offset_values(self) -> list[float] | None:
        """:attr:`offset` as Python floats, or ``None`` where it is all zero (no counterweight)."""
        return self.offset.tolist() if self.offset.any() else None

    def own(self, x: NDArray[np.float64]) -> NDArray[np.float64]:
        """The entries the bounds concern: ``x`` less :attr:`offset` (a counterweight's own)."""
        return np.asarray(x, dtype=float) - self.offset

    def absent(self, b: LinkBounds, own: NDArray[np.float64] | list[float]) -> bool:
        """Whether link ``b``'s counterweight in ``own`` (:meth:`own`) is none at all.

        Only a counterweight whose mass may be zero; its own ``m``, ``m·e``, ``m·f`` and
        (unless it is :attr:`inert`, settled afterwards) ``J`` all within :data:`ABSENT` of the
        link's scales.
        """
        if b.offset is None or b.mass[0] > 0:
            return False
        k = b.start
        m, me, mf, j = (float(v) for v in own[k : k + 4])
        return (abs(m) <= ABSENT * b.mass_ref and abs(me) <= ABSENT * b.mass_ref * b.length
                and abs(mf) <= ABSENT * b.mass_ref * b.length
                and (self.inert[k + 3] or abs(j) <= ABSENT * b.inertia_ref))

    @cached_property
    def nullable(self) -> tuple[LinkBounds, ...]:
        """The links whose counterweight may be none (its mass may be zero).

        Those that :meth:`absent` can find without a counterweight; most problems have none.
        """
        return tuple(b for b in self.links if b.offset is not None and not b.mass[0] > 0)

    def without_absent(self, x: NDArray[np.float64]) -> tuple[NDArray[np.float64],
                                                             NDArray[np.bool_]]:
        """``x`` with every counterweight that is none (:meth:`absent`) exactly none.

        Returns the design vector and the mask of the entries so set (to be kept by what
        restores Eq. 58 afterwards).
        """
        x = np.array(x, dtype=float)
        if not self.nullable:
            return x, np.zeros(self.size, dtype=bool)
        own = self.own(x)
        mask = np.zeros(self.size, dtype=bool)
        for b in self.links:
            if self.absent(b, own):
                x[b.entries] = self.offset[b.entries]
                mask[b.entries] = True
        return x, mask

    @cached_property
    def rotor_links(self) -> list[LinkBounds]:
        """The links that have a counter-rotor entry."""
        return [b for b in self.links if b.rotor is not None]

    @cached_property
    def original_mass(self) -> float:
        """Total mass of the original moving links, kg."""
        return self.linkage.total_mass

    @cached_property
    def scales(self) -> NDArray[np.float64]:
        """Typical magnitude of each entry of ``x``, for scaling the optimisers' variables.

        ``m``, ``m·l``, ``m·l``, ``m·l²`` per link (original mass); counter-rotors like their
        link's ``m·l²``; a mass·radius site its bound (kg·m).
        """
        out = np.ones(self.size)
        for b in self.links:
            m, l = b.mass_ref, b.length
            out[b.entries] = (m, m * l, m * l, m * l * l)
            if b.rotor is not None:
                out[b.rotor] = b.inertia_ref
        if self.sites is not None:
            for i, site in enumerate(self.sites.sites):
                if site.max_mr > 0:
                    out[self.sites.entries(i)] = site.max_mr
        return out

    def total_mass(self, x: NDArray[np.float64]) -> float:
        """``Σm`` of a design vector, kg."""
        return float(np.sum(np.asarray(x)[self.mass_entries]))
