"""Forward dynamics: formulations of the equations of motion that must agree.

Every mechanism has the general ``multibody`` formulation (:mod:`.multibody`: absolute
coordinates of every link with the constraints' multipliers, any linkage); the four-bar has the
paper's four (below), the slider-crank two of its own
(:mod:`balancer.mechanisms.slidercrank.formulations`);
each mechanism names its own (:attr:`balancer.mechanisms.base.Mechanism.formulation_table`).
The four-bar's:

=================  ==================================================  =========================
name               formulation                                         state
=================  ==================================================  =========================
``opened-loop``    principal vectors, loop opened at A3 (Meijaard &     θ1, θ2, θ3, θ̇1, θ̇2, θ̇3
                   van der Wijk 2020, Eq. 22–28): five linear
                   equations for θ̈1..3 and R̄A3, R̄A0 from Eq. 28
``complex-masses`` complex joint masses, closed loop (Eq. 36–40),     θ1, θ̇1
                   reduced to one equation in θ1
``mass-matrix``    constant equivalent mass matrices, truss elements   r̄A1, r̄A2 and their rates
                   (Eq. 41–55): Cartesian joint coordinates with
                   length constraints, reactions from Eq. 52–54
``lie-group``      attitude vectors on the rotation group, reduced     Π1, q_A, q_B, q_D
                   to Hamiltonian form without multipliers (Bai, Xia
                   & Ge 2024, Eq. 82–85)
=================  ==================================================  =========================

Each is a :class:`Formulation`: it turns a state into its time derivative and evaluates the link
angles, rates, accelerations and the forces on the ground at a state (an :class:`Evaluation`).
The seeds' formulations share :mod:`.closed_form` (a chain given by its lengths). The crank
either moves freely under the loads and gravity, or a motor on the ground holds it at constant
speed; then the last state component is the motor's work ``∫τ·θ̇1 dt`` and the driving torque
is reported. The integration itself (tolerances, projection of the non-minimal states, events,
outputs) is :mod:`balancer.simulation`.
"""

from __future__ import annotations

import importlib
from typing import Literal

from ..errors import SpecError
from ..mechanisms import base, mechanism_of
from ..mechanisms.base import Mechanism
from ..mechanisms.formulation import (
    DEAD_POINT_THRESHOLD,
    DrivenRates,
    Evaluation,
    Formulation,
    continuous_angles,
    least_norm,
    least_norm_many,
)
from ..model import MechanismModel as Model
from .crank_angle import CrankAngle
from .multibody import Multibody

#: A formulation of the equations of motion, by name (``simulate --method``).
Method = Literal["opened-loop", "complex-masses", "mass-matrix", "lie-group", "multibody",
                 "crank-angle"]
#: The formulations every linkage has, by name; each mechanism adds its own
#: (:attr:`~balancer.mechanisms.base.Mechanism.own_formulations`; the names a mechanism offers,
#: in its order, are :func:`balancer.mechanisms.base.formulation_names`).
GENERAL: dict[str, type[Formulation]] = {"multibody": Multibody, "crank-angle": CrankAngle}


def formulation_names(model: Model | Mechanism) -> tuple[str, ...]:
    """The formulations that apply to a mechanism, the default first.

    The mechanism's own (:attr:`balancer.mechanisms.base.Mechanism.own_formulations`), and the
    general ones every linkage has (:func:`balancer.mechanisms.base.formulation_names`).
    """
    return base.formulation_names(mechanism_of(model))


def default_method(model: Model | Mechanism) -> str:
    """The formulation used when none is asked for."""
    return formulation_names(model)[0]


def formulation_class(name: str, model: Model | Mechanism) -> type[Formulation]:
    """The formulation called ``name`` for a mechanism.

    Raises
    ------
    SpecError
        If the mechanism has no such formulation (naming those it has).
    """
    mech = mechanism_of(model)
    names = base.formulation_names(mech)
    if name not in names:
        raise SpecError(f"the {mech.model.type} has no such formulation; choose from "
                        f"{', '.join(names)}", key="method", value=name)
    return own_formulation(type(mech), name) or GENERAL[name]


def own_formulation(kind: type[Mechanism], name: str) -> type[Formulation] | None:
    """A mechanism class's own formulation ``name`` (its ``own_formulations``), or ``None``.

    Imported from the mechanism's folder when asked for, so that analysing a design loads no
    formulation.
    """
    where = kind.own_formulations.get(name)
    if where is None:
        return None
    module, _, attribute = where.rpartition(".")
    folder = kind.__module__.rpartition(".")[0]
    found: type[Formulation] = getattr(importlib.import_module(f"{folder}.{module}"),
                                       attribute)
    return found


def make(
    name: str,
    linkage: Model | Mechanism,
    *,
    gravity: tuple[float, float] = (0.0, 0.0),
    speed: float | None = None,
) -> Formulation:
    """The formulation called ``name`` for the mechanism.

    A formulation that compiles its equations (:attr:`Formulation.reusable`) is built once per
    mechanism, gravity and speed and kept with the mechanism; its state is set again by each
    :meth:`~Formulation.initial_state`.
    """
    mech = mechanism_of(linkage)
    cls = formulation_class(name, mech)
    if not cls.reusable:
        return cls(mech, gravity=gravity, speed=speed)
    cache = mech.structure.cache.setdefault("formulations", {})
    key = (name, complex(*gravity), speed)
    if key not in cache:
        cache[key] = cls(mech, gravity=gravity, speed=speed)
    return cache[key]


__all__ = [
    "DEAD_POINT_THRESHOLD",
    "GENERAL",
    "Method",
    "DrivenRates",
    "Evaluation",
    "Formulation",
    "continuous_angles",
    "default_method",
    "formulation_class",
    "formulation_names",
    "least_norm",
    "least_norm_many",
    "make",
    "own_formulation",
]
