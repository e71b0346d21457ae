"""Inverse dynamics of the slider-crank by two independent routes.

What the mechanism exerts on its frame: the force ``R̄A0`` at the crank pivot; the guide's
normal force ``R̄A3 = −i·N`` (the slider on its guide, frictionless) with its line of action
``x_N`` along the guide (the guide also resists the slider's turning); the gas force's reaction
on the cylinder head; and the motor's reaction torque. The shaking force is the sum of the
forces on the frame, the gas force cancelling out (it is internal to the machine); the shaking
moment is their moment about A0.

Routes:

``"newton-euler"``
    The free-body equations of slider, rod and crank in that order.
``"mass-matrix"``
    Crank and rod as truss elements with the equivalent mass matrix (Meijaard & van der Wijk
    2020, Eq. 45–46), the slider as a mass at its pin, combined by virtual displacements that
    keep the lengths and the guide: a rotation of the crank for the driving torque, a
    translation of the whole for the shaking force, a turn of the rod about A1 for the guide's
    normal force, a rotation of the whole about A0 for the shaking moment.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import replace

import numpy as np
from numpy.typing import NDArray

from ...linkage import rotors
from ...linkage.loads import Reactions
from ...linkage.massmodels import equivalent_inertia_forces, equivalent_joint_forces
from ...linkage.rotors import dynamic_link
from ...linkage.vectors import cross
from ...model import Link
from .kinematics import Lengths, SliderMotion
from .model import SliderCrank


def _loads(mech: SliderCrank, mo: SliderMotion, gravity: complex, loads: bool
           ) -> tuple[list[complex], list[float], NDArray[np.float64]]:
    """Forces at the centres of mass (weight included), moments and the gas force."""
    forces = [(link.force_complex if loads else 0j) + link.mass * gravity for link in mech.links]
    moments = [link.moment if loads else 0.0 for link in mech.links]
    gas = mech.gas_force.at(mo.theta1) if loads else np.zeros(mo.size)
    return forces, moments, np.asarray(gas, dtype=float)


def _finish(mech: SliderCrank, mo: SliderMotion, ra0: NDArray[np.complex128],
            n_guide: NDArray[np.float64], m_guide: NDArray[np.float64],
            tau: NDArray[np.float64], gas: NDArray[np.float64],
            shaking: NDArray[np.complex128], alpha1: NDArray[np.float64]) -> Reactions:
    """Frame loads from the pin and guide forces, the motor torque and the gas force.

    ``n_guide`` and ``m_guide`` are the guide's normal force and couple on the slider; the
    record carries the slider's on its guide (``R̄A3 = −i·N``: the normal force
    ``Im R̄A3``), under the slider's link name, and the force ``R̄A0`` at A0. The rocking couple
    is zero (the closed forms work in the plane).
    """
    h = mech.lengths[2]
    ra3 = np.asarray(-1j * n_guide, dtype=complex)  # the slider on its guide
    moment = -mo.x * n_guide - m_guide + h * gas - tau
    if mech.crank.counter_rotor:
        moment = moment + rotors.ground_couple(mech.crank.counter_rotor, alpha1)
    slider = mech.chain_links[2]
    return Reactions(ground={"A0": ra0}, slider_normal={slider: np.imag(ra3)},
                     slider_couple={slider: -m_guide + 0 * mo.x}, shaking_force=shaking,
                     shaking_moment=moment, torques=(tau,),
                     rocking_couple=np.zeros(np.shape(tau), complex))


def newton_euler(
    mech: SliderCrank,
    mo: SliderMotion,
    *,
    gravity: tuple[float, float] = (0.0, 0.0),
    loads: bool = True,
) -> Reactions:
    """Frame loads from the free-body equations of slider, rod and crank.

    Pin forces: ``P̄0`` ground on crank, ``P̄1`` crank on rod, ``P̄2`` rod on slider. The slider's
    x-equation gives ``P2x``; the rod's moment equation about A1 gives ``P2y``
    (``L·cos θ2·P2y = c + L·sin θ2·P2x``); the slider's y-equation the guide's normal force
    ``N``, its moment equation the guide's couple; the force balances then ``P̄1``, ``P̄0``; the
    crank's moment equation about A0 the driving torque.
    """
    r, big_l, _ = mech.lengths
    g = complex(*gravity)
    forces, moments, gas = _loads(mech, mo, g, loads)
    dyn = [dynamic_link(link) for link in mech.links]
    z1, z2 = mech.crank.com / r, mech.rod.com / big_l
    v1, v2 = mo.l1, mo.l2
    acc1, acc2 = mo.vector_acceleration(0), mo.vector_acceleration(1)
    a1, a2, a3 = z1 * acc1, acc1 + z2 * acc2, mo.a + 0j
    need1 = dyn[0].mass * a1 - forces[0]
    need2 = dyn[1].mass * a2 - forces[1]
    need3 = dyn[2].mass * a3 - forces[2]
    p2x = need3.real - gas
    c = -cross(z2 * v2, need2) + moments[1] - dyn[1].inertia * mo.alpha[1]
    p2y = (c + v2.imag * p2x) / v2.real
    p2 = p2x + 1j * p2y
    n_guide = need3.imag - p2y
    m_guide = cross(mech.slider.com, need3) - moments[2]
    p1 = need2 + p2
    p0 = need1 + p1
    tau = dyn[0].inertia * mo.alpha[0] + cross(z1 * v1, need1) + cross(v1, p1) - moments[0]
    shaking = np.asarray(-p0 - 1j * n_guide - gas, dtype=complex)
    return _finish(mech, mo, -p0, n_guide, m_guide, tau, gas, shaking, mo.alpha[0])


def _nodal(params_crank: Sequence[float], params_rod: Sequence[float], m3: float,
           mo: SliderMotion, lengths: Lengths
           ) -> tuple[NDArray[np.complex128], NDArray[np.complex128], NDArray[np.complex128]]:
    """Nodal inertia forces ``−M·r̈`` at A0, A1, A2 (Eq. 45 for crank and rod, a mass at A2)."""
    r, big_l, _ = lengths
    acc_a1 = mo.vector_acceleration(0)
    acc_a2 = mo.a + 0j
    c0, c1 = equivalent_inertia_forces(params_crank, r, 0.0, acc_a1)
    r1, r2 = equivalent_inertia_forces(params_rod, big_l, acc_a1, acc_a2)
    return -c0, -c1 - r1, -r2 - m3 * acc_a2


def _combine(mech_lengths: Lengths, mo: SliderMotion,
             nodes: tuple[NDArray[np.complex128], NDArray[np.complex128],
                          NDArray[np.complex128]],
             gas: NDArray[np.float64], slider_moment: NDArray[np.float64],
             rotor_alpha: NDArray[np.float64] | float
             ) -> tuple[NDArray[np.float64], NDArray[np.complex128], NDArray[np.float64],
                        NDArray[np.complex128], NDArray[np.float64]]:
    """Torque, shaking force, guide force, crank-pivot force and shaking moment.

    From the nodal forces ``G`` at A0, A1, A2 (gas excluded) by virtual displacements that keep
    the lengths and the guide.
    """
    g0, g1, g2 = nodes
    v1, v2 = mo.l1, mo.l2
    big_x = mo.transfer[1]
    # Crank rotation δθ1 = 1: δA1 = i·l̄1, δA2 = dx/dθ1 along the guide; the gas force works too.
    tau = -(cross(v1, g1) + big_x * (g2.real + gas))
    shaking = g0 + g1 + g2  # translation of everything (the gas force is internal)
    # A turn of the rod about A1 (A0, A1 held): δA2 = i·l̄2; the guide resists its y-part.
    n_guide = -cross(v2, g2 + gas) / v2.real
    ra0 = shaking + gas + 1j * n_guide
    # Rotation of the whole about A0 (the gas force and its reaction cancel).
    moment = cross(v1, g1) + cross(mo.A2, g2) + slider_moment + rotor_alpha
    return tau, shaking, n_guide, ra0, moment


def mass_matrix(
    mech: SliderCrank,
    mo: SliderMotion,
    *,
    gravity: tuple[float, float] = (0.0, 0.0),
    loads: bool = True,
) -> Reactions:
    """Frame loads from the equivalent mass matrices (Eq. 45–46) by virtual displacements.

    Crank and rod as truss elements, the slider a mass at its pin (see the module docstring).
    """
    r, big_l, _ = mech.lengths
    g = complex(*gravity)
    forces, moments, gas = _loads(mech, mo, g, loads)
    crank, rod, slider = (dynamic_link(link) for link in mech.links)
    n0, n1, n2 = _nodal(crank.inertial_parameters, rod.inertial_parameters, slider.mass, mo,
                        mech.lengths)
    f = []
    for k, (link, length, vec) in enumerate(((crank, r, mo.l1), (rod, big_l, mo.l2))):
        loaded = Link(mass=link.mass, inertia=link.inertia, e=link.e, f=link.f,
                      force=(forces[k].real, forces[k].imag), moment=moments[k])
        f.append(equivalent_joint_forces(loaded, length, vec))
    g0 = n0 + f[0][0]
    g1 = n1 + f[0][1] + f[1][0]
    g2 = n2 + f[1][1] + forces[2]
    # The slider's own moment about its pin (loads and inertia), resisted by the guide.
    slider_moment = moments[2] + cross(slider.com, forces[2] - slider.mass * mo.a)
    rotor = (rotors.ground_couple(mech.crank.counter_rotor, mo.alpha[0])
             if mech.crank.counter_rotor else 0.0)
    tau, shaking, n_guide, ra0, moment = _combine(mech.lengths, mo, (g0, g1, g2), gas,
                                                  slider_moment, rotor)
    m_guide = -slider_moment
    reactions = _finish(mech, mo, ra0, n_guide, m_guide, tau, gas, shaking, mo.alpha[0])
    return replace(reactions, shaking_moment=moment)


ROUTES = {"newton-euler": newton_euler, "mass-matrix": mass_matrix}


def inverse_dynamics(mech: SliderCrank, mo: SliderMotion, *, route: str = "newton-euler",
                     gravity: tuple[float, float] = (0.0, 0.0), loads: bool = True
                     ) -> Reactions:
    """Frame loads of the slider-crank for a prescribed motion by the chosen ``route``."""
    try:
        fn = ROUTES[route]
    except KeyError:
        raise ValueError(f"unknown route {route!r}; choose from {tuple(ROUTES)}") from None
    return fn(mech, mo, gravity=gravity, loads=loads)


def angular_momentum(mech: SliderCrank, mo: SliderMotion) -> NDArray[np.float64]:
    """Angular momentum of the moving parts about A0 (counter-rotor included), kg·m²/s."""
    r, big_l, _ = mech.lengths
    c1, c2, c3 = mech.links
    z1, z2 = c1.com / r, c2.com / big_l
    pos = (z1 * mo.l1, mo.l1 + z2 * mo.l2, mo.A2 + c3.com)
    vel = (z1 * mo.vector_rate(0), mo.vector_rate(0) + z2 * mo.vector_rate(1), mo.v + 0j)
    spin = (c1.inertia * mo.omega[0] + rotors.momentum(c1.counter_rotor, mo.omega[0])
            + c2.inertia * mo.omega[1])
    return spin + sum(link.mass * cross(p, v) for link, p, v in zip(mech.links, pos, vel,
                                                                      strict=True))


def kinetic_energy(mech: SliderCrank, mo: SliderMotion) -> NDArray[np.float64]:
    """Kinetic energy of the moving parts (counter-rotor included), J."""
    r, big_l, _ = mech.lengths
    c1, c2, c3 = mech.links
    z1, z2 = c1.com / r, c2.com / big_l
    v1 = z1 * mo.vector_rate(0)
    v2 = mo.vector_rate(0) + z2 * mo.vector_rate(1)
    return 0.5 * (c1.mass * np.abs(v1) ** 2 + c2.mass * np.abs(v2) ** 2 + c3.mass * mo.v**2
                  + c1.inertia * mo.omega[0] ** 2 + c2.inertia * mo.omega[1] ** 2) \
        + rotors.energy(c1.counter_rotor, mo.omega[0])
