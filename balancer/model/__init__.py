"""Immutable model objects: links, the general linkage, operating conditions and a whole design.

The four-bar's and the slider-crank's data are their mechanisms' own
(:mod:`balancer.mechanisms.fourbar.model`, :mod:`balancer.mechanisms.slidercrank.model`); all
share :class:`MechanismModel`.

Notation (Meijaard & van der Wijk 2020, Sect. 2–3, Fig. 1): link ``k`` runs from its first joint
to its second; its centre of mass relative to the first joint, in the frame along the link, is
``s̄k = sk·exp(iσk) = ek + i·fk``; ``Ik`` is its moment of inertia about that centre of mass.
Applied loads are a constant force ``F̄k`` (global axes) at the centre of mass and a moment ``Mk``.
A counter-rotor is a disc coaxial with the link's ground pivot geared to turn at −1 times the
link's angular velocity; only its inertia counts.

All quantities are SI: m, kg, kg·m², rad, s, N, N·m. Objects are frozen; make variants with
:func:`dataclasses.replace` or the ``with_*`` helpers. Every object checks its values when it is
made (:mod:`balancer.validate`, the same checks as the spec loader's) and raises
:class:`~balancer.errors.SpecError` naming the field: a link, a mechanism or a design built in a
notebook is as safe as one read from a spec.
"""

from .assembly import AssemblyRange
from .design import (
    ATOL_MIN,
    DRIVES,
    RTOL_MIN,
    THETA1_MAX,
    Design,
    Drive,
    Operation,
    SimulationSettings,
    check_scales,
)
from .links import GROUND, RESERVED_LINK_NAMES, Body, GasForce, Gear, Link, Slider, Spring
from .mechanisms import Branch, ChainModel, Linkage, MechanismModel

__all__ = [
    "ATOL_MIN",
    "DRIVES",
    "GROUND",
    "RESERVED_LINK_NAMES",
    "RTOL_MIN",
    "THETA1_MAX",
    "AssemblyRange",
    "Body",
    "Branch",
    "Design",
    "Drive",
    "GasForce",
    "Gear",
    "Link",
    "Linkage",
    "ChainModel",
    "MechanismModel",
    "Operation",
    "SimulationSettings",
    "Slider",
    "Spring",
    "check_scales",
]
