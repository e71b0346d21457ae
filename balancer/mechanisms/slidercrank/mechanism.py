"""The slider-crank as a mechanism: its general linkage, with Wunderlich's closed forms added.

Wunderlich (1964), Sect. 3: crank A0→A1, connecting rod A1→A2, the slider's pin A2 on a guide
along +x at the signed offset ``e`` from A0. The slider is a one-point link on a ground guide; a
gas force acts between it and the cylinder (internal to the machine). The mass-matrix route
of its inverse dynamics is the slider-crank's own (:mod:`balancer.mechanisms.slidercrank.dynamics`).
"""

from __future__ import annotations

import math
from dataclasses import replace
from functools import cached_property

import numpy as np
from numpy.typing import NDArray

from ...linkage.dynamics import Forces
from ...linkage.kinematics import Motion
from ...linkage.structure import Structure
from ...model import Body, Branch, Linkage, Slider
from ...model.assembly import AssemblyRange
from ..base import ROUTES, Mechanism, Route
from ..drawing import Drawing, piston_block
from ..presentation import Presentation
from . import kinematics as closed
from .conditions import force_balance_matrix
from .dynamics import mass_matrix
from .model import SliderCrank


def slider_crank_linkage(model: SliderCrank) -> Linkage:
    """The slider-crank as a general linkage, at a regular reference pose on its branch.

    The reference crank angle is the one of its range's samples where the rod is farthest from
    square to the guide (largest ``|cos θ2|``).
    """
    rng = closed.assembly_range(model.lengths)
    if rng.full:
        candidates = np.linspace(0.0, 2 * math.pi, 73)[:-1]
    else:
        lo, hi = rng.intervals[0]
        candidates = np.linspace(lo, hi, 74)[1:-1]
    with np.errstate(all="ignore"):
        mo = closed.motion_of(model, candidates, 0.0, 0.0)
    best = int(np.nanargmax(np.abs(np.real(mo.l2))))
    a1, a2 = complex(mo.A1[best]), complex(mo.A2[best])
    points = (("A0", (0.0, 0.0)), ("A1", (a1.real, a1.imag)), ("A2", (a2.real, a2.imag)))
    bodies = (Body(name="ground", points=("A0",)),
              Body(name="crank", points=("A0", "A1"), props=model.crank),
              Body(name="rod", points=("A1", "A2"), props=model.rod),
              Body(name="slider", points=("A2",), props=model.slider))
    slider = Slider(link="slider", guide="ground", point="A2", direction=(1.0, 0.0),
                    force=model.gas_force)
    return Linkage(points=points, bodies=bodies, inputs=("crank",), sliders=(slider,))


class SliderCrankMechanism(Mechanism):
    """The slider-crank (``type = "slider-crank"``)."""

    model: SliderCrank

    own_formulations = {"mass-matrix": "formulations.SliderMassMatrix",
                        "complex-masses": "formulations.SliderComplexMasses"}
    verify_method = "complex-masses"
    geometry_key = "mechanism.lengths"
    #: The guide's force as the four-bar's R̄A3 (DESIGN.md's fixed CSV columns).
    presentation = Presentation(force_balance_source="Wunderlich's conditions, Eq. 20a–b,",
                                named_states=False, guide_force_names={"slider": "A3"},
                                block_name="pistons")
    #: Without ``[simulation] theta1`` a simulation starts at θ1 = 0.
    start_angle = 0.0

    @cached_property
    def linkage(self) -> Linkage:
        return slider_crank_linkage(self.model)

    @cached_property
    def structure(self) -> Structure:
        r, big_l, _ = self.model.lengths
        return Structure.of(self.linkage, {"crank": r, "rod": big_l})

    def describe(self) -> str:
        return closed.classify(self.model.lengths)

    @property
    def branch(self) -> Branch:
        return self.model.branch

    def drawing(self) -> Drawing:
        """The slider drawn as a piston (a slider-crank is mostly an engine's cylinder)."""
        return replace(super().drawing(),
                       blocks={"slider": piston_block(self.model.lengths[0], None)})

    def assembly_range(self) -> AssemblyRange:
        return closed.assembly_range(self.model.lengths)

    def closed_form_force_balance(self) -> NDArray[np.float64]:
        """Wunderlich's Eq. 20a–b over the layout (crank, rod, slider, then a counter-rotor)."""
        ab = force_balance_matrix(self.model.lengths)
        assert not np.any(ab[:, 12]), "Eq. 20 is homogeneous"
        return np.hstack([ab[:, :12], np.zeros((ab.shape[0], self.layout.size - 12))])

    def _full_turn_rule(self) -> str:
        return " (crank + |offset| < rod)"

    def inverse_dynamics(self, mo: Motion, *, route: Route | None = None, loads: bool = True,
                         gravity: tuple[float, float] = (0.0, 0.0)) -> Forces:
        if (route or ROUTES[0]) != "mass-matrix":
            return super().inverse_dynamics(mo, route=route, loads=loads, gravity=gravity)
        smo = closed.motion_of(self.model, mo.theta1, mo.omega1, mo.alpha1)
        r = mass_matrix(self.model, smo, gravity=gravity, loads=loads)
        return r.forces(rocking_couple=self.rocking_couple(mo, loads=loads, gravity=gravity))


#: The class the registry builds for this folder (:data:`balancer.mechanisms.FOLDERS`).
MECHANISM = SliderCrankMechanism
