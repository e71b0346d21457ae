"""Where a mechanism's points and masses are at a motion: from its kinematics and links alone.

Functions of any :class:`~balancer.mechanisms.base.Mechanism`, none of which a mechanism
overrides (so they are not members of its interface): every point's position and each ground
guide's line (what pictures draw), each link's centre of mass and first moment and the total
centre of mass (what force balance and the centre of mass's excursion measure).
"""

from __future__ import annotations

import numpy as np
from numpy.typing import NDArray

from ..linkage.constraints import GROUND_INDEX
from ..linkage.kinematics import Motion
from ..linkage.vectors import V
from .base import Mechanism


def centres_of_mass(mech: Mechanism, mo: Motion) -> list[V]:
    """Each moving link's centre of mass at the motion's states, m."""
    return [mo.point(k, V(link.e, link.f)) for k, link in enumerate(mech.links)]


def first_moments(mech: Mechanism, mo: Motion) -> list[NDArray[np.complex128]]:
    """Each moving link's first moment of mass about the origin, then each rotor's, kg·m.

    Complex ``x + i·y``; the shaking force is minus the second time derivative of their sum.
    """
    links = [c.complex() * link.mass
             for c, link in zip(centres_of_mass(mech, mo), mech.links, strict=True)]
    return [*links, *(rotor.first_moment(mo.theta1) for _, rotor in mech.rotors)]


def total_centre_of_mass(mech: Mechanism, mo: Motion) -> NDArray[np.complex128]:
    """The moving links' total centre of mass, complex, m (rotors' moving masses in)."""
    mass = mech.linkage.total_mass + sum(e.mass for _, r in mech.rotors for e in r.eccentrics)
    total: NDArray[np.complex128] = np.sum(np.broadcast_arrays(*first_moments(mech, mo)),
                                           axis=0)
    return total / mass


def points(mech: Mechanism, mo: Motion) -> dict[str, NDArray[np.complex128]]:
    """Every point's position, complex, m (a point of the frame: its fixed place)."""
    structure = mech.structure
    out: dict[str, NDArray[np.complex128]] = {}
    for p, links in structure.point_links.items():
        k = GROUND_INDEX if GROUND_INDEX in links else links[0]
        out[p] = mo.point(k, structure.local[(k, p)]).complex() + 0 * mo.state.positions[0]
    return out


def drawing(mech: Mechanism) -> dict[str, tuple[str, ...]]:
    """What to draw: each link's points in the order to join them (the ground's too)."""
    return {b.name: b.points for b in mech.linkage.bodies}


def guides(mech: Mechanism, mo: Motion
           ) -> list[tuple[NDArray[np.complex128], NDArray[np.complex128]]]:
    """Each slider's guide as a point on the line and the line's unit direction, complex."""
    out: list[tuple[NDArray[np.complex128], NDArray[np.complex128]]] = []
    for c in mech.structure.prisms:
        base = mo.point(c.g, c.pg).complex() + 0 * mo.state.positions[0]
        d = mo.pose.rotate(c.g, c.dg)
        out.append((base, d.x + 1j * d.y + 0 * mo.state.positions[0]))
    return out


__all__ = ["centres_of_mass", "drawing", "first_moments", "guides", "points",
           "total_centre_of_mass"]
