"""The seeds' formulations' common ground: a chain of links given by its lengths.

:class:`ClosedForm` holds what the four-bar's formulations (Meijaard & van der Wijk 2020; Bai,
Xia & Ge 2024) and the slider-crank's share: the link lengths, the links as the dynamics see
them (counter-rotor inertia added), the loads with the weights, the centres of mass as fractions
of the link vectors (``ζk = s̄k/lk``). :class:`FourBarFormulation` adds the four-bar's closed-form
kinematics (Eq. 1–11): its assembly range, change points, the transmission at a crank angle, the
smooth motion's branch through a change point, and the energy from the link angles.
"""

from __future__ import annotations

import math
from collections.abc import Sequence

import numpy as np
from numpy.typing import NDArray

from ...model.assembly import AssemblyRange
from ..chains import ClosedForm
from .assembly import assembly_range
from .inverse import kinetic_energy, link_com_kinematics
from .kinematics import (
    branch_sign_along,
    change_point_angles,
    motion_from_angles,
    position_scalar,
    rates_scalar,
)
from .model import FourBar


class FourBarFormulation(ClosedForm):
    """The four-bar's formulations: its closed-form kinematics for the simulation driver."""

    linkage: FourBar
    lengths: tuple[float, float, float, float]

    def assembly_range(self) -> AssemblyRange:
        """Crank angles at which the mechanism assembles."""
        return assembly_range(self.lengths)

    def change_points(self) -> tuple[float, ...]:
        """Crank angles at which the assemblies meet (passed on the smooth motion)."""
        return change_point_angles(self.lengths)

    def transmission_of_crank(self, theta1: float) -> float:
        """|sin(θ3 − θ2)| on the motion's assembly at ``theta1``: zero at a dead point."""
        sign = branch_sign_along(self.lengths, self.sign0, self.theta1_start, theta1)
        _, v2, v3 = position_scalar(self.lengths, theta1, float(sign))
        return abs(v2.real * v3.imag - v2.imag * v3.real) / (self.lengths[1] * self.lengths[2])

    def energy(self, theta: NDArray[np.float64], omega: NDArray[np.float64],
               alpha: NDArray[np.float64], slider: NDArray[np.float64] | None = None,
               states: Sequence[NDArray[np.float64]] | None = None
               ) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
        """Kinetic energy and the work of loads and gravity since the first state, J.

        At output states (arrays over time; angles continuous).
        """
        mo = motion_from_angles(self.lengths, tuple(theta), tuple(omega), tuple(alpha))
        kin = kinetic_energy(self.linkage, mo)
        coms, _ = link_com_kinematics(self.linkage, mo)
        work = 0.0 * kin
        for k, r in enumerate(coms):
            work = work + np.real(np.conj(self.forces[k]) * (r - r[0])) + self.moments[k] * (
                theta[k] - theta[k][0])
        return kin, work

    def near_change_point(self, theta1: float, width: float = 0.1) -> bool:
        """Whether the crank angle (rad) is within ``width`` of a change point of the linkage.

        There all joints become collinear, the loop-closure Jacobian loses rank and the two
        assemblies cross: a least-norm projection cannot tell them apart, so the non-minimal
        formulations project onto the assembly of the smooth motion instead
        (:meth:`branch_vectors`).
        """
        points = change_point_angles(self.lengths)
        return any(abs(math.remainder(theta1 - p, 2 * math.pi)) < width for p in points)

    def branch_vectors(self, theta1: float, omega1: float
                       ) -> tuple[tuple[complex, complex, complex], float, float]:
        """Link vectors and dependent rates ``(l̄1, l̄2, l̄3), θ̇2, θ̇3`` of the smooth motion.

        On the assembly the motion is on at crank angle ``theta1`` (unwrapped, rad) (Eq. 2–7).
        """
        sign = branch_sign_along(self.lengths, self.sign0, self.theta1_start, theta1)
        vectors = position_scalar(self.lengths, theta1, float(sign))
        _, _, w2, w3, _, _ = rates_scalar(self.lengths, vectors, omega1)
        return vectors, w2, w3
