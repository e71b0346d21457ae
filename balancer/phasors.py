"""Phasors: each plane's share of the shaking force and rocking couple, order by order.

The picture engine designers reason with: at each order ``n`` of the crank speed, the force a
plane along the crankshaft puts on the frame (a cylinder's rod and piston, a crank pin, a web's
counterweight, a balance shaft's eccentric) is a forward whirl turning with the crank and a
backward one turning against it,

    F_plane(θ1) = Σ_n  f_n·e^{i·n·θ1} + b_n·e^{−i·n·θ1}        (complex ``x + i·y``, N),

and its couple about x and y the same times ``i·z`` (``Mx + i·My``, as
:meth:`balancer.linkage.rotors.Rotor.loads` writes it). The phasors are ``f_n`` and ``b_n`` (the
arrows at θ1 = 0); summed over the planes, head to tail, they are the free force's and couple's
order ``n`` — the cycle analysis's order table (:mod:`balancer.orders`), which the tests hold
them to.

Each plane's force is the inertial load of what moves in it at constant crank speed, from the
exact kinematics (not the two-term series): every link whose plane ``z`` it is, ``−m·ā`` at its
centre of mass, and every rotor mass there (:meth:`~balancer.linkage.rotors.Rotor.loads`); its
coefficients by the discrete Fourier transform of equally spaced samples over a revolution
(exact for orders below half the samples of a motion with no higher content; a slider-crank's
decay geometrically).
"""

from __future__ import annotations

import math
from dataclasses import dataclass, replace

import numpy as np
from numpy.typing import NDArray

from .errors import SpecError
from .linkage.vectors import V
from .mechanisms.base import Mechanism, in_one_plane, require_full_revolution

#: Samples per revolution of each plane's load: its orders are exact far above the picture's.
SAMPLES = 720
#: Planes closer than this (m) are one.
SAME_PLANE = 1e-9


@dataclass(frozen=True)
class PlanePhasors:
    """One plane's phasors.

    Attributes
    ----------
    z
        The plane along the crank's axis, m.
    what
        What moves in it (link names and rotor masses), for a legend.
    force
        By order: ``(forward, backward)`` at θ1 = 0, complex, N.
    """

    z: float
    what: tuple[str, ...]
    force: dict[int, tuple[complex, complex]]

    def couple(self, order: int) -> tuple[complex, complex]:
        """The plane's couple ``i·z·F`` at ``order``: ``(forward, backward)``, N·m."""
        forward, backward = self.force[order]
        return 1j * self.z * forward, 1j * self.z * backward


@dataclass(frozen=True)
class Phasors:
    """Every plane's phasors at a speed, and their sums.

    Attributes
    ----------
    speed
        The crank speed, rad/s.
    orders
        The orders drawn (multiples of the crank speed).
    planes
        Along the axis, by ``z``.
    in_one_plane
        Whether everything moves in one plane (no couple).
    """

    speed: float
    orders: tuple[int, ...]
    planes: tuple[PlanePhasors, ...]
    in_one_plane: bool

    def total_force(self, order: int) -> tuple[complex, complex]:
        """The free force's ``(forward, backward)`` phasors at ``order``, N."""
        return (complex(sum(p.force[order][0] for p in self.planes)),
                complex(sum(p.force[order][1] for p in self.planes)))

    def total_couple(self, order: int) -> tuple[complex, complex]:
        """The free couple's ``(forward, backward)`` phasors at ``order``, N·m."""
        return (complex(sum(p.couple(order)[0] for p in self.planes)),
                complex(sum(p.couple(order)[1] for p in self.planes)))


def phasors(mech: Mechanism, speed: float, orders: tuple[int, ...] = (1, 2),
            samples: int = SAMPLES) -> Phasors:
    """Each plane's inertial force by order at ``speed`` (see the module docstring).

    Raises
    ------
    SpecError
        For an order that is not a whole number from 1 to below half the samples.
    """
    for n in orders:
        if not (isinstance(n, int) and 1 <= n < samples // 2):
            raise SpecError(f"must be whole numbers from 1 to {samples // 2 - 1}",
                            key="--phasor-orders", value=list(orders))
    require_full_revolution(mech, "a phasor picture")
    theta = 2 * math.pi * np.arange(samples) / samples
    with np.errstate(all="ignore"):
        mo = mech.motion(theta, speed, 0.0)
    by_plane: dict[float, tuple[list[str], NDArray[np.complex128]]] = {}

    def add(z: float, what: str, load: NDArray[np.complex128]) -> None:
        key = next((k for k in by_plane if abs(k - z) <= SAME_PLANE), z)
        names, total = by_plane.get(key, ([], np.zeros(samples, complex)))
        by_plane[key] = ([*names, what], total + load)

    structure = mech.structure
    for name, link in zip(mech.linkage.link_names, mech.linkage.links, strict=True):
        if link.mass == 0:
            continue
        a = mo.point_acceleration(structure.index(name), V(link.e, link.f)).complex()
        load = np.reshape(np.asarray(a, dtype=np.complex128), samples)
        add(link.z, name, -link.mass * load)
    for point, rotor in mech.rotors:
        for e in rotor.eccentrics:
            single = replace(rotor, inertia=0.0, eccentrics=(e,))
            add(e.z, f"{point} mass", np.asarray(single.loads(theta, speed, 0.0).force))
    planes = []
    for z in sorted(by_plane):
        names, load = by_plane[z]
        if not np.any(load):  # (a link on the axis: the crankshaft's own mass puts none)
            continue
        coefficients = {}
        for n in orders:
            forward = complex(np.mean(load * np.exp(-1j * n * theta)))
            backward = complex(np.mean(load * np.exp(1j * n * theta)))
            coefficients[n] = (forward, backward)
        planes.append(PlanePhasors(z=z, what=tuple(names), force=coefficients))
    return Phasors(speed=speed, orders=tuple(orders), planes=tuple(planes),
                   in_one_plane=in_one_plane(mech))


__all__ = ["PlanePhasors", "Phasors", "phasors"]
