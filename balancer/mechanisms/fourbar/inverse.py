"""Inverse dynamics of the four-bar with a prescribed crank motion, by two independent routes.

Given the crank's motion (θ1, θ̇1, θ̈1), find what the linkage does to its frame: the ground
reactions R̄A0 and R̄A3 (forces of the mechanism **on** the ground), the driving torque of a motor
on the ground that imposes the crank's motion, the shaking force ``R̄A0 + R̄A3`` and the shaking
moment about A0 (everything the mechanism exerts on the ground, the motor's reaction torque and
the counter-rotors' gear reactions included).

Routes:

``"newton-euler"``
    Free-body equations of each link, solved in closed form (rocker and coupler moment equations
    for the coupler–rocker pin force, then force balances down the chain).
``"mass-matrix"``
    Meijaard & van der Wijk's constant equivalent mass matrices (Eq. 45–54): nodal inertia and
    load forces ``G = F − M·r̈`` at A0…A3, then virtual displacements that respect the link
    lengths — a rotation of the crank for the driving torque (Eq. 47, 50), a translation of the
    whole for the shaking force (Eq. 59), a displacement of A3 for R̄A3 (Eq. 52), a rotation of
    the whole about A0 for the shaking moment (Sect. 5.2).

Counter-rotors: a counter-rotor of inertia J on link k's ground pivot, geared through a train
whose housing is the ground, acts on the link as extra inertia (``(Ik + J)·αk``) and puts a
reaction moment ``2·J·αk`` on the ground; its angular momentum is ``−J·ωk``.

Everything is vectorised over the states of a
:class:`~balancer.mechanisms.fourbar.kinematics.FourBarMotion`.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import replace
from typing import Literal

import numpy as np
from numpy.typing import NDArray

from ...linkage import rotors
from ...linkage.loads import Reactions
from ...linkage.massmodels import equivalent_inertia_forces, equivalent_joint_forces
from ...linkage.rotors import dynamic_link
from ...linkage.vectors import cross
from ...model import Link
from .assembly import Lengths
from .kinematics import FourBarMotion, change_point_angles
from .model import FourBar

Route = Literal["newton-euler", "mass-matrix"]
ROUTES: tuple[Route, ...] = ("newton-euler", "mass-matrix")






def link_com_kinematics(
    linkage: FourBar, mo: FourBarMotion
) -> tuple[tuple[NDArray[np.complex128], ...], tuple[NDArray[np.complex128], ...]]:
    """Positions and accelerations of the three links' centres of mass, m and m/s².

    ``r̄k = r̄p + s̄k·l̄k/lk`` and ``r̈k = r̈p + (i·αk − ωk²)·s̄k·l̄k/lk``.
    """
    l1, l2, l3, _ = linkage.lengths
    zeta = [link.com / length for link, length in zip(linkage.links, (l1, l2, l3), strict=True)]
    acc_a1, acc_a2 = mo.joint_accelerations
    joint_pos = (0.0, mo.pos.A1, mo.pos.A2)
    joint_acc = (0.0, acc_a1, acc_a2)
    pos = tuple(joint_pos[k] + zeta[k] * mo.vectors[k] for k in range(3))
    acc = tuple(joint_acc[k] + zeta[k] * mo.vector_acceleration(k) for k in range(3))
    return pos, acc


def _applied_forces(linkage: FourBar, gravity: complex, loads: bool) -> list[complex]:
    """Constant applied force on each link at its centre of mass (load plus weight), N."""
    return [
        (link.force_complex if loads else 0j) + link.mass * gravity for link in linkage.links
    ]


def _reactions(ra0: NDArray[np.complex128], ra3: NDArray[np.complex128],
               tau: NDArray[np.float64], moment: NDArray[np.float64],
               shaking: NDArray[np.complex128]) -> Reactions:
    """The frame loads of the forces at the pivots, the torque, the moment and the shaking force.

    ``R̄A0`` and ``R̄A3`` the ground's entries, the shaking moment about A0 (the origin); the
    rocking couple zero (the closed forms work in the plane).
    """
    return Reactions(ground={"A0": ra0, "A3": ra3}, slider_normal={}, slider_couple={},
                     shaking_force=shaking, shaking_moment=moment, torques=(tau,),
                     rocking_couple=np.zeros(np.shape(tau), complex))


def _counter_rotor_moment(linkage: FourBar, mo: FourBarMotion) -> NDArray[np.float64] | float:
    """Reaction moment of the counter-rotors' gear trains on the ground, ``2·Σ Jk·αk``, N·m."""
    total: NDArray[np.float64] | float = 0.0
    for k, link in enumerate(linkage.links):
        if link.counter_rotor:
            total = total + rotors.ground_couple(link.counter_rotor, mo.alpha[k])
    return total


def newton_euler(
    linkage: FourBar,
    mo: FourBarMotion,
    *,
    gravity: tuple[float, float] = (0.0, 0.0),
    loads: bool = True,
) -> Reactions:
    """Reactions, driving torque and shaking moment from the links' free-body equations.

    Pin forces: ``P̄0`` ground on crank at A0, ``P̄1`` crank on coupler at A1, ``P̄2`` coupler on
    rocker at A2, ``P̄3`` ground on rocker at A3. The coupler's moment equation about A1 and the
    rocker's about A3 give ``P̄2 = (c2·l̄3 + c3·l̄2)/(l̄2 × l̄3)``; the force balances then give
    ``P̄3``, ``P̄1``, ``P̄0``, and the crank's moment equation about A0 the driving torque.

    Parameters
    ----------
    linkage
        The four-bar.
    mo
        Its motion (the crank's acceleration is imposed by the motor).
    gravity
        Gravitational acceleration ``(gx, gy)``, m/s².
    loads
        Include the links' applied forces and moments.
    """
    dyn = [dynamic_link(link) for link in linkage.links]
    g = complex(*gravity)
    f1, f2, f3 = _applied_forces(linkage, g, loads)
    mom1, mom2, mom3 = (link.moment if loads else 0.0 for link in linkage.links)
    l1, l2, l3, _ = linkage.lengths
    z1, z2, z3 = (
        link.com / length for link, length in zip(linkage.links, (l1, l2, l3), strict=True)
    )
    v1, v2, v3 = mo.vectors
    al1, al2, al3 = mo.alpha
    acc1, acc2, acc3 = (mo.vector_acceleration(k) for k in range(3))
    # Centres of mass relative to A0, A1 and A3, and their accelerations (A3 = A2 + l̄3 is fixed).
    r1, r2_a1, r3_a3 = z1 * v1, z2 * v2, (z3 - 1) * v3
    a1, a2, a3 = z1 * acc1, acc1 + z2 * acc2, (z3 - 1) * acc3
    # Net force each link needs beyond its applied force: m·a − F.
    need1 = dyn[0].mass * a1 - f1
    need2 = dyn[1].mass * a2 - f2
    need3 = dyn[2].mass * a3 - f3
    c2 = -cross(r2_a1, need2) + mom2 - dyn[1].inertia * al2
    c3 = dyn[2].inertia * al3 + cross(r3_a3, need3) - mom3
    p2 = (c2 * v3 + c3 * v2) / cross(v2, v3)
    p3 = need3 - p2
    p1 = need2 + p2
    p0 = need1 + p1
    tau = dyn[0].inertia * al1 + cross(r1, need1) + cross(v1, p1) - mom1
    ra0 = -p0
    ra3 = -p3
    moment = linkage.lengths[3] * ra3.imag - tau + _counter_rotor_moment(linkage, mo)
    return _reactions(ra0, ra3, tau, moment, ra0 + ra3)


def _combine_nodal_forces(mo: FourBarMotion, nodes: Sequence[NDArray[np.complex128]],
                          l4: float) -> Reactions:
    """Reactions from nodal forces ``G_n`` at A0…A3 by length-keeping virtual displacements.

    The counter-rotors' gear reaction on the ground is not included.
    """
    g0, g1, g2, g3 = nodes
    v1, v2, v3 = mo.vectors
    big3 = mo.transfer[1]
    # Crank rotation δθ1 = 1: δA1 = i·l̄1, δA2 = −i·l̄3·Θ3;  ⟨i·x, G⟩ = x × G.
    tau = -(cross(v1, g1) - big3 * cross(v3, g2))
    shaking = g0 + g1 + g2 + g3  # translation of everything (Eq. 59)
    ra3 = g3 + v3 * cross(v2, g2) / cross(v2, v3)  # A3 moved, A0 and A1 held
    ra0 = shaking - ra3
    moment = cross(v1, g1) + cross(mo.pos.A2, g2) + l4 * g3.imag  # rotation about A0
    return _reactions(ra0, ra3, tau, moment, shaking)


def _inertial_nodal_forces(params: Sequence[float], lengths: Sequence[float], mo: FourBarMotion,
                           k: int) -> tuple[NDArray[np.complex128], NDArray[np.complex128]]:
    """Nodal inertia forces ``−(Me·r̈)`` of link ``k`` (0-based) at its two joints (Eq. 45)."""
    acc_a1, acc_a2 = mo.joint_accelerations
    node_acc = (0.0, acc_a1, acc_a2, 0.0)
    ip, iq = equivalent_inertia_forces(params, lengths[k], node_acc[k], node_acc[k + 1])
    return -ip, -iq


def mass_matrix(
    linkage: FourBar,
    mo: FourBarMotion,
    *,
    gravity: tuple[float, float] = (0.0, 0.0),
    loads: bool = True,
) -> Reactions:
    """Reactions, driving torque and shaking moment from the equivalent mass matrices (Eq. 45–54).

    The nodal forces ``G_n = F_n − (M·r̈)_n`` at the joints A0…A3 (Eq. 45–46, 48–49, 53–54)
    are combined by virtual displacements that keep the link lengths: rotating the crank
    (``δr̄A1 = i·l̄1``, ``δr̄A2 = −i·l̄3·Θ3``; Eq. 47, 50) gives the driving torque; translating
    everything gives the shaking force (Eq. 59); moving A3 with A0 and A1 held gives
    ``R̄A3 = G_A3 + l̄3·(l̄2 × G_A2)/(l̄2 × l̄3)`` (Eq. 52 with the lengths kept); rotating
    everything about A0 gives the shaking moment ``Σ r̄n × G_n`` (Sect. 5.2).

    Parameters are as for :func:`newton_euler`.
    """
    g = complex(*gravity)
    forces = _applied_forces(linkage, g, loads)
    lengths = linkage.lengths[:3]
    nodes = [np.zeros(mo.size, dtype=complex) for _ in range(4)]
    for k, link in enumerate(linkage.links):
        loaded = Link(
            mass=link.mass,
            inertia=link.inertia,
            e=link.e,
            f=link.f,
            force=(forces[k].real, forces[k].imag),
            moment=link.moment if loads else 0.0,
        )
        fp, fq = equivalent_joint_forces(loaded, lengths[k], mo.vectors[k])
        ip, iq = _inertial_nodal_forces(
            dynamic_link(link).inertial_parameters, lengths, mo, k
        )
        nodes[k] = nodes[k] + fp + ip
        nodes[k + 1] = nodes[k + 1] + fq + iq
    r = _combine_nodal_forces(mo, nodes, linkage.lengths[3])
    cr = _counter_rotor_moment(linkage, mo)
    if np.any(cr):
        r = replace(r, shaking_moment=r.shaking_moment + cr)
    return r


_ROUTE_FUNCTIONS = {"newton-euler": newton_euler, "mass-matrix": mass_matrix}


def inverse_dynamics(
    linkage: FourBar,
    mo: FourBarMotion,
    *,
    route: Route = "newton-euler",
    gravity: tuple[float, float] = (0.0, 0.0),
    loads: bool = True,
) -> Reactions:
    """Reactions of the four-bar for a prescribed motion by the chosen ``route``."""
    try:
        fn = _ROUTE_FUNCTIONS[route]
    except KeyError:
        raise ValueError(f"unknown route {route!r}; choose from {ROUTES}") from None
    return fn(linkage, mo, gravity=gravity, loads=loads)


def angular_momentum(linkage: FourBar, mo: FourBarMotion) -> NDArray[np.float64]:
    """Angular momentum of the moving parts about A0, counter-rotors included, kg·m²/s.

    ``H = Σ (Ik·ωk + mk·r̄k × ṙk) − Σ Jk·ωk``; the shaking moment without loads equals ``−dH/dt``.
    """
    l1, l2, l3, _ = linkage.lengths
    vel_a1, vel_a2 = mo.joint_velocities
    joint_pos = (0.0, mo.pos.A1, mo.pos.A2)
    joint_vel = (0.0, vel_a1, vel_a2)
    total = np.zeros(mo.size)
    for k, (link, length) in enumerate(zip(linkage.links, (l1, l2, l3), strict=True)):
        zeta = link.com / length
        r = joint_pos[k] + zeta * mo.vectors[k]
        v = joint_vel[k] + zeta * mo.vector_rate(k)
        total = (total + link.inertia * mo.omega[k]
                 + rotors.momentum(link.counter_rotor, mo.omega[k]) + link.mass * cross(r, v))
    return total


def kinetic_energy(linkage: FourBar, mo: FourBarMotion) -> NDArray[np.float64]:
    """Kinetic energy of the moving parts, counter-rotors included, J."""
    l1, l2, l3, _ = linkage.lengths
    vel_a1, vel_a2 = mo.joint_velocities
    joint_vel = (0.0, vel_a1, vel_a2)
    total = np.zeros(mo.size)
    for k, (link, length) in enumerate(zip(linkage.links, (l1, l2, l3), strict=True)):
        v = joint_vel[k] + link.com / length * mo.vector_rate(k)
        total = total + 0.5 * (link.mass * np.abs(v) ** 2 + link.inertia * mo.omega[k] ** 2) \
            + rotors.energy(link.counter_rotor, mo.omega[k])
    return total


def change_point_limits(lengths: Lengths, angles: NDArray[np.float64]
                        ) -> list[tuple[NDArray[np.bool_], tuple[float, ...], tuple[float, ...]]]:
    """How to evaluate a revolution's samples that fall exactly on a change point.

    There all joints are collinear and the transfer functions are 0/0; the shaking force, the
    shaking moment and the driving torque are the limits of the smooth motion, extrapolated
    with error O(δ⁴) (δ = 1e-4 rad): symmetrically at θ1 = π, which the motion passes through,
    one-sidedly at θ1 = 0, where the revolution starts. (The individual reactions grow without
    bound there.)

    Returns
    -------
    list of (mask, offsets, weights)
        For each change point hit by ``angles``: which samples, the crank-angle offsets (rad)
        at which to evaluate, and the weights of those evaluations.
    """
    delta = 1e-4
    out: list[tuple[NDArray[np.bool_], tuple[float, ...], tuple[float, ...]]] = []
    for theta_star in change_point_angles(lengths):
        hit = np.abs(np.angle(np.exp(1j * (angles - theta_star)))) < 1e-9
        if not hit.any():
            continue
        weights: tuple[float, ...]
        if theta_star == 0.0:
            steps, weights = (1, 2, 3, 4), (4.0, -6.0, 4.0, -1.0)
        else:
            steps, weights = (-2, -1, 1, 2), (-1 / 6, 2 / 3, 2 / 3, -1 / 6)
        out.append((hit, tuple(k * delta for k in steps), weights))
    return out

