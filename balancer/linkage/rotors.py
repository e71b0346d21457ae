"""A rotor geared to a link: what it costs the link and what the frame feels, written once.

A rotor is a disc on an axis fixed in the frame, geared to a link so that it turns at ``k``
times the link's angular velocity (``ω_r = k·ω``, ``k`` a non-zero ratio); its inertia about its
axis is ``J``. A counter-rotor (DESIGN.md) is ``k = −1``, coaxial with its link's ground pivot.
From the rotor's kinetic energy ``½·J·k²·ω²`` and angular momentum ``J·k·ω``:

- the link drives it: the power it takes from the link, ``J·k²·ω·α``, is that of a couple
  ``−J·k²·α`` on the link (:func:`link_couple`; its inertia seen by the link is ``J·k²``);
- the frame carries the rest of the rotor's change of momentum, ``−J·k·α`` in all
  (:func:`moment`): the gear train's reaction on the frame is ``J·k·(k − 1)·α``
  (:func:`ground_couple`; ``+2·J·α`` for a counter-rotor, whose link takes ``−J·α``).

The functions take numbers, arrays or CasADi symbols alike (the inertia may be a design entry).

:class:`Rotor` is the general one: at any ratio, its axis anywhere in the frame, with eccentric
masses (mass·radius at an angle, each in its plane along the crank's axis) — a balance shaft.
Its loads on the frame follow from its momentum (DESIGN.md, "Planes and the rocking couple"):
each eccentric's first moment ``ū = m·ρ·e^{iψ}``, ``ψ = k·θ + angle``, gives the force
``−d²ū/dt² = ū·(ψ̇² − i·ψ̈)``; its angular momentum about the origin is ``J·ψ̇ + ā × dū/dt``
(``ā`` the axis, ``J`` about the axis with the eccentrics); the counter-rotor is
``Rotor(ratio=−1, inertia=J, axis=its pivot)``.
"""

from __future__ import annotations

import cmath
from dataclasses import dataclass
from functools import cached_property

import numpy as np
from numpy.typing import ArrayLike, NDArray

from ..model.links import Link
from .vectors import NUMPY, Num, OpsLike, cross

#: The ratio of a counter-rotor: against its link, at its speed.
COUNTER = -1.0


def energy(inertia: Num, omega: Num, ratio: float = COUNTER) -> Num:
    """Kinetic energy ``½·J·k²·ω²`` of a rotor geared to a link turning at ``omega``, J."""
    return 0.5 * inertia * ratio * ratio * omega * omega


def momentum(inertia: Num, omega: Num, ratio: float = COUNTER) -> Num:
    """Angular momentum ``J·k·ω`` of the rotor about its axis, kg·m²/s."""
    return inertia * ratio * omega


def link_inertia(inertia: Num, ratio: float = COUNTER) -> Num:
    """The inertia the rotor adds to its link's, ``J·k²``, kg·m²."""
    return inertia * ratio * ratio


def link_couple(inertia: Num, alpha: Num, ratio: float = COUNTER) -> Num:
    """Couple of the rotor's gearing on its link, ``−J·k²·α``, N·m."""
    return -link_inertia(inertia, ratio) * alpha


def ground_couple(inertia: Num, alpha: Num, ratio: float = COUNTER) -> Num:
    """Couple of the rotor's gear train on the frame, ``J·k·(k − 1)·α``, N·m."""
    return inertia * ratio * (ratio - 1.0) * alpha


def moment(inertia: Num, alpha: Num, ratio: float = COUNTER) -> Num:
    """What the rotor adds to the shaking moment through its link and the frame, ``−J·k·α``."""
    return -inertia * ratio * alpha


def dynamic_link(link: Link) -> Link:
    """The link as the equations of motion see it: its counter-rotor's inertia added to ``I``.

    (:func:`link_inertia`: a counter-rotor's ``J·k²`` is ``J``.)
    """
    if link.counter_rotor == 0.0:
        return link
    return Link(
        mass=link.mass,
        inertia=link.inertia + link_inertia(link.counter_rotor),
        e=link.e,
        f=link.f,
        force=link.force,
        moment=link.moment,
        z=link.z,
    )


@dataclass(frozen=True, eq=False)
class FrameLoads:
    """What a rotor puts on the frame and takes from its link at crank states (arrays).

    ``force`` (complex, N) and ``moment`` about the origin (N·m) it adds to the shaking,
    ``couple`` to the rocking couple (complex ``Mx + i·My``, N·m), and ``link_couple``, its
    gearing's couple on its link (N·m).
    """

    force: NDArray[np.complex128]
    moment: NDArray[np.float64]
    couple: NDArray[np.complex128]
    link_couple: NDArray[np.float64]


@dataclass(frozen=True)
class Eccentric:
    """A mass off a rotor's axis: its mass·radius, angle and plane.

    Attributes
    ----------
    mr
        Mass times the distance of its centre from the axis, kg·m (at least 0).
    angle
        Its direction from the axis when the rotor's angle is 0, rad (from +x towards +y).
    z
        Its plane along the crank's axis, m.
    mass
        Its mass, kg, for its weight under gravity (0: its weight left out; the inertia forces
        need only ``mr``).
    """

    mr: float
    angle: float = 0.0
    z: float = 0.0
    mass: float = 0.0


@dataclass(frozen=True)
class Rotor:
    """A rotor geared to a link at ratio ``k``: the rotor's angle is ``k·θ`` of the link's ``θ``.

    Attributes
    ----------
    ratio
        ``k``, non-zero (−1: a counter-rotor; ±2: a Lanchester shaft on an engine's crank).
    inertia
        ``J`` about its axis, kg·m², its eccentrics included.
    axis
        Where its axis meets the plane, complex ``x + i·y``, m (fixed in the frame).
    eccentrics
        Its masses off the axis (none: a disc).

    Each method takes the link's angle, angular velocity and acceleration (arrays broadcast)
    and, where it matters, ``gravity`` ``(gx, gy)`` m/s²; each is what the rotor adds to the
    frame's loads (force and moments of the mechanism on the frame) or takes from its link.
    """

    ratio: float
    inertia: float
    axis: complex = 0j
    eccentrics: tuple[Eccentric, ...] = ()

    def __post_init__(self) -> None:
        if self.ratio == 0:
            raise ValueError("a rotor's ratio must not be zero")

    @cached_property
    def _sums(self) -> tuple[complex, complex, float, float]:
        """``Σ mr·e^{i·angle}``, ``Σ z·mr·e^{i·angle}`` (kg·m, kg·m²), ``Σ m``, ``Σ z·m``.

        Every eccentric turns with the rotor, ``ū = mr·e^{i·angle}·e^{iψ}``: each load is
        these sums times ``e^{iψ}`` (one complex exponential per state, not one per eccentric).
        """
        ecc = self.eccentrics
        return (complex(sum(e.mr * cmath.exp(1j * e.angle) for e in ecc)),
                complex(sum(e.z * e.mr * cmath.exp(1j * e.angle) for e in ecc)),
                float(sum(e.mass for e in ecc)), float(sum(e.z * e.mass for e in ecc)))

    def _turn(self, theta: ArrayLike) -> NDArray[np.complex128]:
        """``e^{iψ}``, ``ψ = k·θ``."""
        return np.exp(1j * (self.ratio * np.asarray(theta, dtype=float)))

    def first_moment(self, theta: ArrayLike) -> NDArray[np.complex128]:
        """Its masses' first moment about the origin, ``Σ ū + ā·Σ m``, complex, kg·m.

        (The eccentrics' masses where given: an eccentric's ``mr`` alone moves.)
        """
        u, _, mass, _ = self._sums
        return np.asarray(u * self._turn(theta) + self.axis * mass, dtype=complex)

    def loads(self, theta: ArrayLike, omega: ArrayLike, alpha: ArrayLike,
              gravity: tuple[float, float] = (0.0, 0.0)) -> FrameLoads:
        """Everything the rotor puts on the frame and takes from its link, at once.

        With ``ū = Σ mr·e^{i·angle}·e^{iψ}`` (``ψ = k·θ``) and ``s = ψ̇² − i·ψ̈``:

        - shaking force ``ū·s + m·ḡ`` (zero without eccentrics);
        - shaking moment about the origin, ``−dH/dt`` of its angular momentum plus the moment
          of its weights: ``−J·k·α + ā × F̄ + ū × ḡ``;
        - rocking couple, each eccentric's force share in its plane ``z`` (``Mx = −z·F_y``,
          ``My = z·F_x``, that is ``i·z·F``): ``i·(Σ z·ū·s + Σ z·m·ḡ)``;
        - couple of its gearing on its link, ``k·(−J·k·α + ū × ḡ)``: the rotor's own equation
          about its axis carried to the link at the ratio (by power,
          ``τ_link·ω = τ_rotor·k·ω``).
        """
        shape = np.broadcast(np.asarray(theta), np.asarray(omega), np.asarray(alpha)).shape
        ones = np.ones(shape)
        alpha_ = np.asarray(alpha, dtype=float)
        moment_ = np.asarray(moment(self.inertia, alpha_, self.ratio), dtype=float) * ones
        couple_on_link = np.asarray(link_couple(self.inertia, alpha_, self.ratio),
                                    dtype=float) * ones
        if not self.eccentrics:
            zero = np.zeros(shape, complex)
            return FrameLoads(force=zero, moment=moment_, couple=zero.copy(),
                              link_couple=couple_on_link)
        u_sum, uz_sum, mass, mass_z = self._sums
        g = complex(*gravity)
        turn = self._turn(theta)
        rate = self.ratio * np.asarray(omega, dtype=float)
        spin = rate * rate - 1j * (self.ratio * alpha_)
        u = u_sum * turn
        force = np.broadcast_to(u * spin + mass * g, shape).astype(complex)
        couple = np.broadcast_to(1j * (uz_sum * turn * spin + mass_z * g),
                                 shape).astype(complex)
        weights = cross(u, g) if g else 0.0
        return FrameLoads(force=force,
                          moment=np.asarray(moment_ + cross(self.axis, force) + weights,
                                            dtype=float) * ones,
                          couple=couple,
                          link_couple=np.asarray(couple_on_link + self.ratio * weights,
                                                 dtype=float) * ones)

    def weight_couple(self, angle: Num, gravity: complex, ops: OpsLike = NUMPY) -> Num:
        """Its eccentrics' weights' couple carried to its link, ``k·(ū × ḡ)``, N·m.

        ``angle`` the link's ``θ`` (a number, an array, or a CasADi symbol with ``ops``
        CasADi's functions): the generalized force the weights put on the link's coordinate,
        ``−dV/dθ`` of their potential ``V = −ḡ·ū`` (:meth:`loads`' ``link_couple`` under
        gravity less its inertia's part).
        """
        if not self.eccentrics or not gravity:
            return 0.0
        u = self._sums[0]
        psi = self.ratio * angle
        c, s = ops.cos(psi), ops.sin(psi)
        ux, uy = u.real * c - u.imag * s, u.real * s + u.imag * c
        return self.ratio * (ux * gravity.imag - uy * gravity.real)

    def shaking_force(self, theta: ArrayLike, omega: ArrayLike, alpha: ArrayLike,
                      gravity: tuple[float, float] = (0.0, 0.0)) -> NDArray[np.complex128]:
        """What the rotor adds to the shaking force, complex, N (:meth:`loads`)."""
        return self.loads(theta, omega, alpha, gravity).force

    def shaking_moment(self, theta: ArrayLike, omega: ArrayLike, alpha: ArrayLike,
                       gravity: tuple[float, float] = (0.0, 0.0)) -> NDArray[np.float64]:
        """What the rotor adds to the shaking moment about the origin, N·m (:meth:`loads`)."""
        return self.loads(theta, omega, alpha, gravity).moment

    def rocking_couple(self, theta: ArrayLike, omega: ArrayLike, alpha: ArrayLike,
                       gravity: tuple[float, float] = (0.0, 0.0)) -> NDArray[np.complex128]:
        """What the rotor adds to the rocking couple, ``Mx + i·My``, N·m (:meth:`loads`)."""
        return self.loads(theta, omega, alpha, gravity).couple

    def link_couple(self, theta: ArrayLike, omega: ArrayLike, alpha: ArrayLike,
                    gravity: tuple[float, float] = (0.0, 0.0)) -> NDArray[np.float64]:
        """Couple of the rotor's gearing on its link, N·m (:meth:`loads`)."""
        return self.loads(theta, omega, alpha, gravity).link_couple

    def kinetic_energy(self, omega: ArrayLike) -> NDArray[np.float64]:
        """``½·J·k²·ω²``, J."""
        return np.asarray(energy(self.inertia, np.asarray(omega, dtype=float), self.ratio))

    def angular_momentum(self, theta: ArrayLike, omega: ArrayLike) -> NDArray[np.float64]:
        """About the origin: ``J·k·ω + ā × dū/dt`` summed, kg·m²/s."""
        rate = self.ratio * np.asarray(omega, dtype=float)
        velocity = 1j * rate * self._sums[0] * self._turn(theta)
        shape = np.broadcast(np.asarray(theta), rate).shape
        return np.asarray(momentum(self.inertia, np.asarray(omega, dtype=float), self.ratio)
                          + cross(self.axis, np.broadcast_to(velocity, shape)))

    @staticmethod
    def counter(inertia: float, axis: complex = 0j) -> Rotor:
        """A counter-rotor (DESIGN.md): ratio −1, coaxial with its link's pivot, no eccentric."""
        return Rotor(ratio=COUNTER, inertia=inertia, axis=axis)


__all__ = ["COUNTER", "Eccentric", "FrameLoads", "Rotor", "dynamic_link", "energy", "ground_couple",
           "link_couple", "link_inertia", "moment", "momentum"]
