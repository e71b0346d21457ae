"""Balance conditions of the four-bar.

- Shaking-force balance (Meijaard & van der Wijk 2020, Eq. 57–58; Wunderlich 1964, Eq. 10d): the
  principal vectors about the frame, ``ā14`` and ``ā34``, vanish, so the total centre of mass
  is stationary. Given as residuals of a design and as the linear equations they are in the
  links' inertial parameters ``(m, m·e, m·f, J)``.
- The closed-form force balancing of a given design by moving the centres of mass of crank and
  rocker (what the paper did for its Fig. 9).
- Berkof's conditions for complete (force and moment) balancing with counter-rotors (Sect. 5.2).
"""

from __future__ import annotations

from dataclasses import dataclass, replace

import numpy as np
from numpy.typing import NDArray

from .model import FourBar

#: Relative residual of Eq. 57 below which a design counts as force-balanced.
FORCE_BALANCE_TOLERANCE = 1e-9


def force_balance_residuals(linkage: FourBar) -> tuple[complex, complex]:
    """The two complex conditions of Eq. 57, ``(c14, c34)``, in kg.

    ``c14 = m1·s̄1/l1 + m2·(1 − s̄2/l2)`` and ``c34 = m2·s̄2/l2 + m3·(1 − s̄3/l3)``; real and
    imaginary parts are the four scalar conditions of Eq. 58. They equal ``−m_tot·ā14/l̄1`` and
    ``m_tot·ā34/l̄3`` (Eq. 30).
    """
    (l1, l2, l3, _), (c1, c2, c3) = linkage.lengths, linkage.links
    c14 = c1.mass * c1.com / l1 + c2.mass * (1 - c2.com / l2)
    c34 = c2.mass * c2.com / l2 + c3.mass * (1 - c3.com / l3)
    return complex(c14), complex(c34)


def force_balance_error(linkage: FourBar) -> float:
    """Largest force-balance residual of Eq. 57 relative to the total mass (dimensionless).

    (A slider-crank's, Wunderlich's Eq. 20a–b: :func:`balancer.mechanisms.slidercrank.conditions.
    force_balance_error`; any mechanism's: :mod:`balancer.balance.conditions`.)
    """
    c14, c34 = force_balance_residuals(linkage)
    return max(abs(c14), abs(c34)) / linkage.total_mass


def is_force_balanced(linkage: FourBar, tol: float = FORCE_BALANCE_TOLERANCE) -> bool:
    """Whether the total centre of mass is stationary (Eq. 57 within ``tol`` relative)."""
    return force_balance_error(linkage) <= tol


def force_balance_matrix(lengths: tuple[float, float, float, float]) -> NDArray[np.float64]:
    """Eq. 58 as ``A·π = b`` in the stacked inertial parameters of crank, coupler and rocker.

    ``π = (m1, m1e1, m1f1, J1, m2, m2e2, m2f2, J2, m3, m3e3, m3f3, J3)``. Returns the 4×13
    matrix ``[A | b]``: rows are the real and imaginary parts of the two conditions of Eq. 57.
    """
    l1, l2, l3, _ = lengths
    a = np.zeros((4, 13))
    # Re c14 = m1e1/l1 + m2 − m2e2/l2 ; Im c14 = m1f1/l1 − m2f2/l2
    a[0, 1], a[0, 4], a[0, 5] = 1 / l1, 1.0, -1 / l2
    a[1, 2], a[1, 6] = 1 / l1, -1 / l2
    # Re c34 = m2e2/l2 + m3 − m3e3/l3 ; Im c34 = m2f2/l2 − m3f3/l3
    a[2, 5], a[2, 8], a[2, 9] = 1 / l2, 1.0, -1 / l3
    a[3, 6], a[3, 10] = 1 / l2, -1 / l3
    return a


def force_balanced_by_crank_and_rocker(linkage: FourBar) -> FourBar:
    """Force-balance a design by moving the centres of mass of crank and rocker (Eq. 57).

    Keeps all masses, inertias and the coupler; solves Eq. 57 for ``s̄1`` and ``s̄3``:
    ``s̄1 = −(m2/m1)·(1 − s̄2/l2)·l1`` and ``s̄3 = l3·(1 + (m2/m3)·s̄2/l2)``. This is how the
    paper obtained the balanced example of its Fig. 9.
    """
    (l1, l2, l3, _), (c1, c2, c3) = linkage.lengths, linkage.links
    s1 = -(c2.mass / c1.mass) * (1 - c2.com / l2) * l1
    s3 = l3 * (1 + (c2.mass / c3.mass) * c2.com / l2)
    return linkage.with_links(
        {
            "crank": replace(c1, e=s1.real, f=s1.imag),
            "rocker": replace(c3, e=s3.real, f=s3.imag),
        }
    )


@dataclass(frozen=True)
class BerkofResiduals:
    """How far a design is from Berkof's complete balance (all zero when it is met).

    Attributes
    ----------
    force
        Relative force-balance residual (see :func:`force_balance_error`).
    coupler_offset
        ``f2/l2``: the coupler's centre of mass must lie on the line A1A2.
    coupler_inertia
        ``(I2 − m2·e2·(l2 − e2))/(m2·l2²)``: the coupler must be dynamically equivalent to two
        point masses at its joints.
    crank_rotor, rocker_rotor
        ``(J_k − I_k,red)/(m_tot·l_k²)`` with the reduced inertias of Sect. 5.2 that the
        counter-rotors must cancel.
    """

    force: float
    coupler_offset: float
    coupler_inertia: float
    crank_rotor: float
    rocker_rotor: float

    def max(self) -> float:
        """Largest absolute residual."""
        return max(
            abs(self.force),
            abs(self.coupler_offset),
            abs(self.coupler_inertia),
            abs(self.crank_rotor),
            abs(self.rocker_rotor),
        )


def berkof_counter_rotors(linkage: FourBar) -> tuple[float, float]:
    """Counter-rotor inertias that complete Berkof's balance, kg·m² (Sect. 5.2).

    With force balance, ``f2 = 0`` and ``I2 = m2·e2·(l2 − e2)``, the coupler is two point masses,
    ``m2ᵃ = m2·(1 − e2/l2)`` at A1 and ``m2ᵇ = m2·e2/l2`` at A2. The crank then turns about A0
    as a body of inertia ``I1 + m1·s1² + m2ᵃ·l1²`` and the rocker about A3 as one of inertia
    ``I3 + m3·|l̄3 − s̄3|² + m2ᵇ·l3²``; a counter-rotor of the same inertia on each ground pivot
    cancels their angular momentum. (With force balance the first equals the paper's
    ``I1 − m1·e1·(l1 − e1)``, the second ``I3 + m3·e3·(e3 − l3)``.)
    """
    (l1, l2, l3, _), (c1, c2, c3) = linkage.lengths, linkage.links
    crank = c1.inertia + c1.mass * (c1.e**2 + c1.f**2) + c2.mass * (1 - c2.e / l2) * l1**2
    rocker = (
        c3.inertia
        + c3.mass * ((l3 - c3.e) ** 2 + c3.f**2)
        + c2.mass * (c2.e / l2) * l3**2
    )
    return crank, rocker


def berkof_residuals(linkage: FourBar) -> BerkofResiduals:
    """Residuals of Berkof's complete-balance conditions for a design."""
    (l1, l2, l3, _), (c1, c2, c3) = linkage.lengths, linkage.links
    j1, j3 = berkof_counter_rotors(linkage)
    mt = linkage.total_mass
    return BerkofResiduals(
        force=force_balance_error(linkage),
        coupler_offset=c2.f / l2,
        coupler_inertia=(c2.inertia - c2.mass * c2.e * (l2 - c2.e)) / (c2.mass * l2**2),
        crank_rotor=(c1.counter_rotor - j1) / (mt * l1**2),
        rocker_rotor=(c3.counter_rotor - j3) / (mt * l3**2),
    )
