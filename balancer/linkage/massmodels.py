"""Equivalent masses of a link between two joints (Meijaard & van der Wijk 2020, Sect. 3–5).

A link of length ``l`` from its first joint p to its second q, with mass ``m``, centre of mass
``s̄ = e + i·f`` in its frame and inertia ``I``, as masses at its joints: complex joint masses
(Eq. 29), real and virtual equivalent masses (text after Eq. 29), and the constant equivalent
mass matrix of a truss element (Eq. 41–44) with its inertia forces and the joint forces of its
loads. The seeds' closed forms of the four-bar and the slider-crank build on them.
"""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np
from numpy.typing import NDArray

from ..model.links import Link
from .vectors import Num


def complex_joint_masses(link: Link, length: float) -> tuple[complex, complex]:
    """Equivalent complex masses at the first and second joint (Eq. 29), kg.

    ``m̄p = m·(1 − s̄/l)`` and ``m̄q = m·s̄/l``; they sum to ``m`` and reproduce the link's
    linear momentum from the joint velocities, ``m·ṙ = m̄p·ṙp + m̄q·ṙq``.
    """
    zeta = link.com / length
    return link.mass * (1 - zeta), link.mass * zeta


def equivalent_masses(link: Link, length: float) -> tuple[float, float, float]:
    """Real and virtual equivalent masses ``(mᵃ, mᵇ, mᶜ)`` (text after Eq. 29), kg.

    ``mᵃ = m(1 − e/l)`` and ``mᵇ = m·e/l`` are real masses at the first and second joint;
    ``mᶜ = m·f/l`` is the virtual mass: ``m̄p = mᵃ − i·mᶜ``, ``m̄q = mᵇ + i·mᶜ``.
    """
    m = link.mass
    return m * (1 - link.e / length), m * link.e / length, m * link.f / length


def mass_matrix_coefficients(params: Sequence[Num], length: float
                             ) -> tuple[Num, Num, Num, Num]:
    """Entries ``(Ip, Iq, Ired, m·f·l)`` of the equivalent mass matrix from inertial parameters.

    ``Ip = I + m(e² + f²)``, ``Iq = I + m((l − e)² + f²)``, ``Ired = I − m·e(l − e) + m·f²``
    (text after Eq. 45), written linearly in ``π = (m, m·e, m·f, J)``. Works for numpy arrays
    and CasADi symbols.
    """
    m, me, mf, j = params
    ip = j
    iq = j - 2 * length * me + m * length * length
    ired = j - length * me
    return ip, iq, ired, mf * length


def equivalent_mass_matrix(params: Sequence[float], length: float) -> NDArray[np.float64]:
    """Constant 4×4 mass matrix of a link over ``(r_px, r_py, r_qx, r_qy)`` (Eq. 45), kg.

    Parameters
    ----------
    params
        Inertial parameters ``(m, m·e, m·f, J)`` (:attr:`balancer.model.Link.inertial_parameters`).
    length
        Distance between the joints ``l``, m.
    """
    ip, iq, ired, mfl = mass_matrix_coefficients(params, length)
    return (
        np.array(
            [
                [iq, 0.0, -ired, -mfl],
                [0.0, iq, mfl, -ired],
                [-ired, mfl, ip, 0.0],
                [-mfl, -ired, 0.0, ip],
            ]
        )
        / length**2
    )


def equivalent_inertia_forces(params: Sequence[Num], length: float, acc_p: Num, acc_q: Num
                              ) -> tuple[Num, Num]:
    """``Me·ẍ`` of Eq. 45 at the two joints, as complex numbers (N).

    ``(Iq·r̈p − (Ired − i·m·f·l)·r̈q)/l²`` at p and ``(Ip·r̈q − (Ired + i·m·f·l)·r̈p)/l²`` at q:
    the same matrix as :func:`equivalent_mass_matrix`, applied to complex accelerations.
    """
    ip, iq, ired, mfl = mass_matrix_coefficients(params, length)
    l2 = length * length
    at_p = (iq * acc_p - (ired - 1j * mfl) * acc_q) / l2
    at_q = (ip * acc_q - (ired + 1j * mfl) * acc_p) / l2
    return at_p, at_q


def equivalent_joint_forces(link: Link, length: float, vector: Num, moment: Num | None = None
                            ) -> tuple[Num, Num]:
    """Applied force and moment of a link reduced to its two joints (Eq. 46), complex, N.

    ``conj(1 − ζ)·F̄ − i·M·l̄/l²`` at the first joint and ``conj(ζ)·F̄ + i·M·l̄/l²`` at the second,
    ``ζ = s̄/l``.

    Parameters
    ----------
    link
        The link (its force and, unless ``moment`` is given, its moment).
    length
        ``l``, m.
    vector
        The link vector ``l̄ = r̄q − r̄p`` (complex array), m.
    moment
        Moment to use instead of ``link.moment`` (for example including a motor torque), N·m.
    """
    zeta = link.com / length
    force = link.force_complex
    mom = link.moment if moment is None else moment
    couple = 1j * mom * vector / length**2
    return np.conj(1 - zeta) * force - couple, np.conj(zeta) * force + couple
