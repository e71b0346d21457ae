"""An engine as a mechanism: a general linkage of slider-cranks on one crankshaft, and rotors.

The crankshaft is the input link, pivoted at the main bearings ``O`` at the origin, with a pin
for each cylinder; each cylinder's rod joins its pin to its piston, a one-point link on a guide
of the frame along the cylinder's axis, in the cylinder's plane. The general core (positions,
rates, accelerations, inverse dynamics by Newton–Euler or the mass matrix, the rocking couple
from momentum) computes the linkage exactly — not the two-term series. The crankshaft's masses
(a rotor at ratio 1 on ``O``) and the balance shafts (rotors at their ratios, on their own
bearings ``shaft<j>``) add their loads in closed form
(:class:`~balancer.linkage.rotors.Rotor`). Gas forces act along each cylinder's axis between
piston and head: internal to the machine.
"""

from __future__ import annotations

import cmath
import math
from dataclasses import replace
from functools import cached_property, partial

import numpy as np
from numpy.typing import ArrayLike, NDArray

from ...linkage.kinematics import Motion
from ...linkage.loads import Reactions, SupportLoad
from ...linkage.rotors import Rotor, link_inertia
from ...linkage.structure import Structure
from ...model import Body, Gear, Linkage, Slider
from ..base import Mechanism, RotorLoads
from ..drawing import Drawing, DrawnMass, piston_block
from ..presentation import Presentation
from .bearings import lever_shares, main_bearing_loads, main_bearing_regressors
from .model import COUNTERWEIGHT, Engine, crankshaft_name, idler_name

#: The main bearings' point (the crankshaft's axis at the origin).
MAIN_BEARINGS = "O"


def crank_pin(k: int) -> str:
    """The name of cylinder ``k``'s crank pin (a point of the crankshaft)."""
    return f"crankpin{k}"


def piston_pin(k: int) -> str:
    """The name of cylinder ``k``'s piston pin (the rod's small end, the piston's point)."""
    return f"pistonpin{k}"


def shaft_pivot(k: int) -> str:
    """The frame's point where crankshaft ``k`` turns: ``O`` (the main bearings), ``O2``…."""
    return MAIN_BEARINGS if k == 1 else f"{MAIN_BEARINGS}{k}"


def gear_name(k: int) -> str:
    """The gear pair that turns crankshaft ``k`` (2 and on) from the first: ``gear2``….

    Through an idler (at ratio +1), two pairs: ``gear2a`` (the first crankshaft and the
    idler) and ``gear2b`` (the idler and crankshaft 2).
    """
    return f"gear{k}"


def geared_bearing_name(k: int, j: int) -> str:
    """Geared crankshaft ``k``'s main bearing ``j`` (from 0): ``B2.1``, ``B2.2``…."""
    return f"B{k}.{j + 1}"


def idler_pivot(k: int) -> str:
    """The frame's point where the idler of crankshaft ``k`` turns: ``I2``…."""
    return f"I{k}"


def _marker_radius(model: Engine, k: int) -> float:
    """The radius of crankshaft ``k``'s frame marker: its first cylinder's crank, m."""
    on = [c for c in model.cylinders if c.crankshaft == k]
    return (on or model.cylinders)[0].crank


def engine_linkage(model: Engine) -> Linkage:
    """The engine as a general linkage at θ1 = 0.

    Each crankshaft's frame has its x-axis along its angle (a marker point ``X``, ``X2``, …
    on it at its first cylinder's crank radius on +x from its axis), so that the first's angle
    is θ1 and a geared one's ``ratio·θ1``; its pins at ``r·e^{i·phase}`` from its axis; the
    first's inertia with each balance shaft's as the crank feels it (``k²·J``, as a
    counter-rotor's is carried: :meth:`~balancer.mechanisms.base.Mechanism.rotor_loads`).
    Each geared crankshaft turns about its own pivot ``O2``, … by a gear pair with the first
    (:class:`~balancer.model.Gear` ``gear2``, …). Each piston pin on its line ``offset·i·u +
    s·u`` from its crankshaft's axis (``u`` its axis) at the root of ``|W − P| = rod`` farther
    from the crank (the piston on the head's side of its pin).
    """
    shafts = model.shafts
    points: list[tuple[str, tuple[float, float]]] = []
    shaft_points: dict[int, list[str]] = {}
    for k in shafts:
        axis = model.shaft_axis(k)
        marker = "X" if k == 1 else f"X{k}"
        points += [(shaft_pivot(k), (axis.real, axis.imag)),
                   (marker, (axis.real + _marker_radius(model, k), axis.imag))]
        shaft_points[k] = [shaft_pivot(k), marker]
    bodies: list[Body] = [Body(name="ground", points=tuple(shaft_pivot(k) for k in shafts))]
    rods: list[Body] = []
    pistons: list[Body] = []
    sliders: list[Slider] = []
    links = model.links
    n, first_rod = len(model.cylinders), len(shafts) + len(model.idled)
    for k, c in enumerate(model.cylinders, start=1):
        axis = model.shaft_axis(c.crankshaft)
        pin = cmath.rect(c.crank, c.phase)
        u = c.axis
        along = (pin * u.conjugate()).real
        across = (pin * (1j * u).conjugate()).real
        s = along + math.sqrt(c.rod * c.rod - (c.offset - across) ** 2)
        wrist = axis + c.offset * 1j * u + s * u
        pin = axis + pin
        points += [(crank_pin(k), (pin.real, pin.imag)), (piston_pin(k), (wrist.real, wrist.imag))]
        shaft_points[c.crankshaft].append(crank_pin(k))
        rods.append(Body(name=f"rod{k}", points=(crank_pin(k), piston_pin(k)),
                         props=links[first_rod + k - 1]))
        pistons.append(Body(name=f"piston{k}", points=(piston_pin(k),),
                            props=links[first_rod + n + k - 1]))
        sliders.append(Slider(link=f"piston{k}", guide="ground", point=piston_pin(k),
                              direction=(u.real, u.imag), force=model.gas_force(k)))
    geared = sum(link_inertia(s.inertia, s.ratio) for s in model.balance_shafts)
    crankshafts = [Body(name=crankshaft_name(k), points=tuple(shaft_points[k]),
                        props=(replace(links[0], inertia=links[0].inertia + geared) if k == 1
                               else links[k - 1]))
                   for k in shafts]
    gears: list[Gear] = []
    idlers: list[Body] = []
    for k in shafts[1:]:
        if k not in model.idled:
            gears.append(Gear(name=gear_name(k), driver=crankshaft_name(1),
                              driven=crankshaft_name(k), ratio=float(model.shaft_ratio(k))))
            continue
        middle = model.shaft_axis(k) / 2  # the idler, its pitch radius and theirs |at|/4
        tip = middle + abs(model.shaft_axis(k)) / 4
        points += [(idler_pivot(k), (middle.real, middle.imag)),
                   (f"Y{k}", (tip.real, tip.imag))]
        bodies[0] = replace(bodies[0], points=(*bodies[0].points, idler_pivot(k)))
        idlers.append(Body(name=idler_name(k), points=(idler_pivot(k), f"Y{k}"),
                           props=links[len(shafts) + model.idled.index(k)]))
        gears += [Gear(name=f"{gear_name(k)}a", driver=crankshaft_name(1),
                       driven=idler_name(k), ratio=-1.0),
                  Gear(name=f"{gear_name(k)}b", driver=idler_name(k),
                       driven=crankshaft_name(k), ratio=-1.0)]
    return Linkage(points=tuple(points), bodies=(*bodies, *crankshafts, *idlers, *rods,
                                                  *pistons),
                   inputs=("crankshaft",), sliders=tuple(sliders), gears=tuple(gears))


class EngineMechanism(Mechanism):
    """A piston engine (``type = "engine"``)."""

    model: Engine

    geometry_key = "mechanism.cylinders"
    #: Without ``[simulation] theta1`` a simulation starts at θ1 = 0.
    start_angle = 0.0
    presentation = Presentation(mount_torque=True, balanced_on_shafts=True, block_name="pistons",
                                support_words="main bearing", supports_key="main_bearings")

    @cached_property
    def linkage(self) -> Linkage:
        return engine_linkage(self.model)

    @cached_property
    def structure(self) -> Structure:
        exact = {crankshaft_name(k): _marker_radius(self.model, k) for k in self.model.shafts}
        exact.update({idler_name(k): abs(self.model.shaft_axis(k)) / 4 for k in self.model.idled})
        exact.update({f"rod{k}": c.rod for k, c in enumerate(self.model.cylinders, start=1)})
        return Structure.of(self.linkage, exact)

    @cached_property
    def rotors(self) -> tuple[tuple[str, Rotor], ...]:
        """Each crankshaft's masses on its pivot (the first's on the main bearings), each shaft's.

        A balance shaft's rotor turns on its own bearing ``shaft<j>``.
        """
        out: list[tuple[str, Rotor]] = []
        if self.model.crankshaft.masses:
            out.append((MAIN_BEARINGS, self.model.crankshaft.rotor))
        out += [(shaft_pivot(k), g.rotor)
                for k, g in zip(self.model.shafts[1:], self.model.crankshafts, strict=True)
                if g.masses]
        out += [(f"shaft{j}", s.rotor)
                for j, s in enumerate(self.model.balance_shafts, start=1)]
        return tuple(out)

    def rotor_loads(self, theta1: ArrayLike, omega1: ArrayLike, alpha1: ArrayLike,
                    gravity: tuple[float, float] = (0.0, 0.0), *,
                    weights_on_crank: bool = False) -> RotorLoads | None:
        """The rotors' loads (:meth:`Mechanism.rotor_loads`), a geared crankshaft's by its gears.

        A geared crankshaft's masses' weights turn it about its own axis with the couple
        ``C = ū × ḡ``, which its gear pair takes: the tooth force gains ``−C/ρ_b`` along the
        tangent (``ρ_b`` its signed pitch radius), its axis's reaction as much and the first
        crankshaft's as much less (the motor's torque, which the ratio carries, is the same
        either way).
        """
        out = super().rotor_loads(theta1, omega1, alpha1, gravity,
                                  weights_on_crank=weights_on_crank)
        if out is None or not any(gravity):
            return out
        theta = np.broadcast_arrays(*(np.atleast_1d(np.asarray(x, dtype=float))
                                      for x in (theta1, omega1, alpha1)))[0]
        meshes = {m.name: m for m in self.structure.meshes}
        for k, geared in zip(self.model.shafts[1:], self.model.crankshafts, strict=True):
            if not geared.masses:
                continue
            rotor = geared.rotor
            couple = np.asarray(rotor.weight_couple(theta, complex(*gravity)), float) / rotor.ratio
            idled = k in self.model.idled
            mesh = meshes[f"{gear_name(k)}b" if idled else gear_name(k)]
            tooth = (-couple / mesh.radii[1] * complex(mesh.tangent.complex())).astype(complex)
            # (through a massless idler its other pair's tooth force is the opposite, and its
            # bearing takes twice the change: the first crankshaft's then gains it)
            changes = ([(f"{gear_name(k)}b", out.teeth, 1.0), (f"{gear_name(k)}a", out.teeth, -1.0),
                        (shaft_pivot(k), out.bearings, 1.0), (idler_pivot(k), out.bearings, -2.0),
                        (MAIN_BEARINGS, out.bearings, 1.0)] if idled else
                       [(gear_name(k), out.teeth, 1.0), (shaft_pivot(k), out.bearings, 1.0),
                        (MAIN_BEARINGS, out.bearings, -1.0)])
            for key, into, sign in changes:
                into[key] = np.asarray(into.get(key, 0.0) + sign * tooth, dtype=complex)
        return out

    @cached_property
    def supports(self) -> MainBearings | None:
        """The main bearings where the spec places them (:class:`MainBearings`), else ``None``."""
        model = self.model
        return MainBearings(self) if any(model.shaft_bearings(k) for k in model.shafts) else None

    def describe(self) -> str:
        n = len(self.model.cylinders)
        cylinders = "one cylinder" if n == 1 else f"{n} cylinders"
        shafts = len(self.model.shafts)
        geared = "" if shafts == 1 else f" on {shafts} crankshafts geared together"
        return f"{cylinders}{geared}, {self.model.strokes}-stroke"

    def _full_turn_rule(self) -> str:
        return " (each rod longer than its crank + |offset|)"

    def drawing(self) -> Drawing:
        """The pistons, the crankshaft's counterweights and the balance shafts' eccentrics.

        Each piston by its cylinder's bore (without one, its stroke); the counterweights are
        the crankshaft's masses labelled so.
        """
        model = self.model
        blocks = {f"piston{k}": piston_block(c.crank, c.bore)
                  for k, c in enumerate(model.cylinders, start=1)}
        weights = [DrawnMass(axis=model.shaft_axis(k), ratio=float(model.shaft_ratio(k)),
                             angle=math.radians(m.phase_deg), mr=m.mr, what="counterweight")
                   for k in model.shafts for m in model.shaft_masses(k)
                   if m.label == COUNTERWEIGHT]
        eccentrics = [DrawnMass(axis=complex(*s.at), ratio=float(s.ratio),
                                angle=math.radians(m.phase_deg), mr=m.mr, what="eccentric")
                      for s in self.model.balance_shafts for m in s.eccentrics]
        return replace(super().drawing(), blocks=blocks, masses=(*weights, *eccentrics))


class MainBearings:
    """An engine's main bearings (:class:`~balancer.mechanisms.base.Supports`).

    Each crankshaft's bearings share its loads by the lever rule (:mod:`.bearings`). The
    first crankshaft's ``B1``, ``B2``, …; a geared crankshaft ``k``'s ``B<k>.1``, …, in that
    order throughout.
    """

    def __init__(self, engine: EngineMechanism) -> None:
        self.engine = engine

    def loads(self, mo: Motion, reactions: Reactions, *, loads: bool = True,
              gravity: tuple[float, float] = (0.0, 0.0)) -> tuple[SupportLoad, ...]:
        """Each main bearing's load (:mod:`.bearings`), where the spec places them.

        The first crankshaft's ``B1``, ``B2``, …; a geared crankshaft ``k``'s ``B<k>.1``, ….
        Each crankshaft carries its own cylinders' pins, its weight, its masses and its gear
        pairs' tooth forces at their plane (``gear_z``): the first, minus each pair's force on
        the gear it drives; a geared one, its own pair's.
        """
        model = self.engine.model
        out: list[SupportLoad] = []
        for k in model.shafts:
            planes = model.shaft_bearings(k)
            if not planes:
                continue
            pistons = {f"piston{i}" for i, c in enumerate(model.cylinders, start=1)
                       if c.crankshaft == k}
            teeth = [(z, np.asarray(sign * np.asarray(reactions.teeth[name]), dtype=complex))
                     for z, name, sign in self._gears_on(k)]
            found = main_bearing_loads(
                self.engine, planes, shaft_pivot(k), mo, reactions, loads=loads, gravity=gravity,
                shaft=crankshaft_name(k), pistons=pistons, teeth=teeth,
                names=None if k == 1 else partial(geared_bearing_name, k))
            out += [SupportLoad(name=name, z=z, force=force)
                    for (name, force), z in zip(found.items(), planes, strict=True)]
        return tuple(out)

    def _gears_on(self, k: int) -> list[tuple[float, str, float]]:
        """The gear pairs whose teeth push on crankshaft ``k``: (plane, pair, sign).

        The first crankshaft drives each geared one's pair (or its idler's first): minus the
        force on the gear it drives; a geared one is driven by its own (or its idler's
        second): plus it.
        """
        model = self.engine.model
        out = []
        for j, g in zip(model.shafts[1:], model.crankshafts, strict=True):
            idled = j in model.idled
            if k == 1:
                out.append((g.gear_z, f"{gear_name(j)}a" if idled else gear_name(j), -1.0))
            elif k == j:
                out.append((g.gear_z, f"{gear_name(j)}b" if idled else gear_name(j), 1.0))
        return out

    def _carried(self, k: int) -> set[str]:
        """The links crankshaft ``k`` carries: itself, its cylinders' rods and pistons."""
        on = [i for i, c in enumerate(self.engine.model.cylinders, start=1) if c.crankshaft == k]
        return {crankshaft_name(k), *(f"rod{i}" for i in on), *(f"piston{i}" for i in on)}

    def regressors(self, mo: Motion) -> tuple[NDArray[np.complex128], ...]:
        """Each main bearing's inertial load over the layout (:mod:`.bearings`).

        Every crankshaft's, in :meth:`loads`' order; its gears' tooth forces from the
        core's regressors.
        """
        model = self.engine.model
        with np.errstate(all="ignore"):  # (once for every crankshaft's bearings)
            regressors = self.engine.regressors(mo)
        teeth = regressors.teeth
        out: list[NDArray[np.complex128]] = []
        for k in model.shafts:
            planes = model.shaft_bearings(k)
            if planes:
                maps = [(z, sign * (np.asarray(teeth[name].x) + 1j * np.asarray(teeth[name].y)))
                        for z, name, sign in self._gears_on(k)]
                out += main_bearing_regressors(self.engine, planes, mo, links=self._carried(k),
                                               teeth=maps, regressors=regressors)
        return tuple(out)

    def shares(self, z: float, axis: complex = 0j) -> tuple[tuple[int, float], ...]:
        """The lever rule's shares of a load at ``z`` on the crankshaft about ``axis``.

        Its main bearings' indices in :meth:`loads`' order (:mod:`.bearings`); none
        where that crankshaft has none, or no crankshaft turns about ``axis``.
        """
        model = self.engine.model
        first = 0
        for k in model.shafts:
            planes = model.shaft_bearings(k)
            if model.shaft_axis(k) == axis:
                return tuple((first + j, share) for j, share in lever_shares(planes, z)
                             ) if planes else ()
            first += len(planes)
        return ()


#: The class the registry builds for this folder (:data:`balancer.mechanisms.FOLDERS`).
MECHANISM = EngineMechanism
