"""Balance conditions of the slider-crank.

- Stationary total centre of mass (Wunderlich 1964, Eq. 20a–b; his Eq. 14c): ``α1 = α2 = 0``,
  i.e. ``m1·s̄1/r + m2 + m3 = 0`` (the crank's centre of mass on the far side of A0) and
  ``m2·s̄2/L + m3 = 0`` (the rod's beyond the crank pin, the counterweight designers often
  cannot accept). Linear in the inertial parameters ``(m, m·e, m·f)``.
- The engine designer's alternative, partial balancing with a crank counterweight: at constant
  speed the counterweight's force is a pure first harmonic, so it can only act on the first
  harmonic of the shaking force (the cycle analysis' :meth:`~balancer.cycle.CycleAnalysis.
  harmonics` give the primary (1×) and secondary (2×) amplitudes), and
  :func:`classic_counterweight` the textbook balance of the rotating masses plus
  a fraction of the reciprocating ones (the rod split into two masses at its joints).
"""

from __future__ import annotations

from dataclasses import replace

import numpy as np
from numpy.typing import NDArray

from .model import SliderCrank

#: Relative residual of Eq. 20a–b below which the centre of mass counts as stationary.
FORCE_BALANCE_TOLERANCE = 1e-9


def force_balance_residuals(mech: SliderCrank) -> tuple[complex, complex]:
    """``(c1, c2)`` of Eq. 20a–b in kg: ``m1·s̄1/r + m2 + m3`` and ``m2·s̄2/L + m3``.

    They are ``m_tot·α1`` and ``m_tot·α2`` of Wunderlich's Eq. 16.
    """
    r, big_l, _ = mech.lengths
    c1, c2, c3 = mech.links
    return (complex(c1.mass * c1.com / r + c2.mass + c3.mass),
            complex(c2.mass * c2.com / big_l + c3.mass))


def force_balance_error(mech: SliderCrank) -> float:
    """Largest Eq. 20 residual relative to the total mass (dimensionless)."""
    a, b = force_balance_residuals(mech)
    return max(abs(a), abs(b)) / mech.total_mass


def is_force_balanced(mech: SliderCrank, tol: float = FORCE_BALANCE_TOLERANCE) -> bool:
    """Whether the total centre of mass is stationary (Eq. 20a–b within ``tol``)."""
    return force_balance_error(mech) <= tol


def force_balance_matrix(lengths: tuple[float, float, float]) -> NDArray[np.float64]:
    """Eq. 20a–b as a 4×13 matrix ``A`` with ``A·x = 0`` for a force-balanced design.

    Columns of ``x``: crank, rod and slider, each ``(m, m·e, m·f, J)`` (kg, kg·m, kg·m,
    kg·m²), then the crank's counter-rotor (kg·m², no part in the force balance).
    """
    r, big_l, _ = lengths
    a = np.zeros((4, 13))
    a[0, 1], a[0, 4], a[0, 8] = 1 / r, 1.0, 1.0  # Re: m1e1/r + m2 + m3
    a[1, 2] = 1 / r  # Im: m1f1/r
    a[2, 5], a[2, 8] = 1 / big_l, 1.0  # Re: m2e2/L + m3
    a[3, 6] = 1 / big_l  # Im: m2f2/L
    return a


def force_balanced_by_counterweights(mech: SliderCrank) -> SliderCrank:
    """Meet Eq. 20a–b by moving the centres of mass of crank and rod, masses kept.

    ``s̄2 = −(m3/m2)·L`` (beyond the crank pin) and ``s̄1 = −((m2 + m3)/m1)·r`` (beyond A0).
    """
    r, big_l, _ = mech.lengths
    c1, c2, c3 = mech.links
    s2 = -(c3.mass / c2.mass) * big_l
    s1 = -((c2.mass + c3.mass) / c1.mass) * r
    return mech.with_links({"crank": replace(c1, e=s1, f=0.0),
                            "rod": replace(c2, e=s2, f=0.0)})


def equivalent_masses(mech: SliderCrank) -> tuple[complex, float]:
    """The textbook split: the rotating unbalance and the reciprocating mass.

    The rod is replaced by ``m2·(1 − s̄2/L)`` at the crank pin and ``m2·s̄2/L`` at the slider's
    pin (exact for the linear momentum, Eq. 29). Returns the rotating first moment about A0
    ``m1·s̄1 + m2·(1 − s̄2/L)·r`` (kg·m, complex in the crank frame) and the reciprocating mass
    ``m3 + m2·e2/L`` (kg).
    """
    r, big_l, _ = mech.lengths
    c1, c2, c3 = mech.links
    rotating = c1.mass * c1.com + c2.mass * (1 - c2.com / big_l) * r
    return complex(rotating), float(c3.mass + c2.mass * c2.e / big_l)


def classic_counterweight(mech: SliderCrank, balance_factor: float) -> complex:
    """Crank first moment ``m1·s̄1`` (kg·m, crank frame) of the classic partial balance.

    The rotating masses fully balanced and the fraction ``balance_factor`` of the
    reciprocating mass: ``m1·s̄1 = −m2·(1 − s̄2/L)·r − k·(m3 + m2·e2/L)·r``. For an in-line
    engine with the rod's centre of mass on its line, minimising ``w_x·RMS(Fx)² + w_y·RMS(Fy)²``
    gives ``k = w_x/(w_x + w_y)`` (one half for equal weights): the counterweight's rotating
    force can cancel only the first harmonic, and of the reciprocating mass's
    ``m·r·ω²·cos θ1`` along the guide it trades the part it leaves against the part it adds
    across.
    """
    r, big_l, _ = mech.lengths
    c2 = mech.rod
    _, recip = equivalent_masses(mech)
    return complex(-c2.mass * (1 - c2.com / big_l) * r - balance_factor * recip * r)
