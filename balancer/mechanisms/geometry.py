"""Where a mechanism's points and masses are at a motion: from its kinematics and links alone.

Functions of any :class:`~balancer.mechanisms.base.Mechanism`, none of which a mechanism
overrides (so they are not members of its interface): every point's position and each ground
guide's line (what pictures draw), each link's centre of mass and first moment and the total
centre of mass (what force balance and the centre of mass's excursion measure); the links' angles
continued from the reference pose (where a simulation starts).
"""

from __future__ import annotations

import math

import numpy as np
from numpy.typing import NDArray

from ..linkage.constraints import GROUND_INDEX
from ..linkage.kinematics import Motion
from ..linkage.vectors import V
from .base import Mechanism


def centres_of_mass(mech: Mechanism, mo: Motion) -> list[V]:
    """Each moving link's centre of mass at the motion's states, m."""
    return [mo.point(k, V(link.e, link.f)) for k, link in enumerate(mech.linkage.links)]


def first_moments(mech: Mechanism, mo: Motion) -> list[NDArray[np.complex128]]:
    """Each moving link's first moment of mass about the origin, then each rotor's, kg·m.

    Complex ``x + i·y``; the shaking force is minus the second time derivative of their sum.
    """
    links = [c.complex() * link.mass
             for c, link in zip(centres_of_mass(mech, mo), mech.linkage.links, strict=True)]
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


def continued_angles(mech: Mechanism, theta1: float) -> NDArray[np.float64]:
    """The links' angles at crank angle ``theta1``, continuous from the reference pose.

    DESIGN.md: each link's angle is its principal value at the reference pose and
    continuous from there on; the crank is followed from the reference's angle to
    ``theta1`` in steps of at most 0.05 rad, each link's angle unwrapped along the way (the
    input's is ``theta1`` as given). A crank that turns fully is followed over the part of
    a turn only, and each whole turn adds what one revolution adds to each link's angle.
    """
    s = mech.structure
    start = s.ref_angle[s.input]
    turn = 2 * math.pi
    turns = math.floor((theta1 - start) / turn) if mech.assembly_range().full else 0
    out = _followed(mech, start, theta1 - turns * turn)
    if turns:
        out = out + turns * (_followed(mech, start, start + turn) - np.array(s.ref_angle))
    out[s.input] = theta1
    return out

def _followed(mech: Mechanism, start: float, end: float) -> NDArray[np.float64]:
    """The links' angles followed from the reference pose (at crank angle ``start``)."""
    s = mech.structure
    steps = max(2, int(math.ceil(abs(end - start) / 0.05)) + 1)
    with np.errstate(all="ignore"):
        mo = mech.motion(np.linspace(start, end, steps))
    out = np.empty(mech.structure.size)
    for k in range(mech.structure.size):
        path = np.concatenate([[s.ref_angle[k]], np.broadcast_to(
            np.asarray(mo.pose.angles[k], dtype=float), (steps,))])
        out[k] = np.unwrap(path)[-1] if np.all(np.isfinite(path)) else path[-1]
    return out


__all__ = ["centres_of_mass", "continued_angles", "drawing", "first_moments", "guides", "points",
           "total_centre_of_mass"]
