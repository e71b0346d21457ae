"""The one mechanism interface that everything downstream uses.

A :class:`Mechanism` wraps a model (:class:`~balancer.FourBar`,
:class:`~balancer.SliderCrank`, :class:`~balancer.Engine` or :class:`~balancer.model.Linkage`)
and tells the rest of the package what it needs: its general linkage and that linkage's
equations, the named layout of the design vector, the range of crank angles where it
assembles, the motion at input states, the forces on the ground and the driving torque (and
the same as linear maps of the design vector), its supports, the formulations of its equations
of motion, and for the layers that print its wording and what a drawing shows. The general
linkage implements it with the general core (:mod:`balancer.linkage`); the four-bar, the
slider-crank and the engine build their general linkage and add closed forms where those are
the seeds' own route or do what the general core does not (the four-bar's change points).
What the package derives from any mechanism is the functions at the end of this module (the
frame's points, whether it moves in one plane, its formulations' names, the refusals of a
purpose it cannot serve). Code downstream never asks which mechanism it has;
:func:`~balancer.mechanisms.mechanism_of` is the one registry.
"""

from __future__ import annotations

import threading
from collections.abc import Mapping
from dataclasses import dataclass, field, replace
from functools import cached_property
from typing import TYPE_CHECKING, ClassVar, Literal, Protocol

import numpy as np
from numpy.typing import ArrayLike, NDArray

from ..errors import AssemblyError, SpecError
from ..linkage import dynamics, kinematics
from ..linkage.assembly import assembly_range
from ..linkage.constraints import Pose
from ..linkage.dynamics import Forces, Layout
from ..linkage.inputs import InputState
from ..linkage.kinematics import Motion
from ..linkage.loads import Reactions, SupportLoad
from ..linkage.rotors import Rotor, ground_couple
from ..linkage.structure import Structure
from ..linkage.vectors import V
from ..model import Branch, Link, Linkage, MechanismModel
from ..model.assembly import AssemblyRange
from . import drawing
from .drawing import Drawing
from .presentation import Presentation

if TYPE_CHECKING:
    from ..linkage.program import CrankForcesProgram

#: The inverse-dynamics routes of every mechanism (``analyze --route``): the links' equations
#: group by group, or all at once with the mass matrices and the constraints' multipliers.
Route = Literal["newton-euler", "mass-matrix"]
#: The routes, the default first.
ROUTES: tuple[Route, ...] = ("newton-euler", "mass-matrix")
#: The formulations of the equations of motion that apply to every linkage: in absolute
#: coordinates with the constraints' multipliers, and in the crank angle.
MULTIBODY = "multibody"
CRANK_ANGLE = "crank-angle"
#: A linkage with several inputs: Lagrange's equations in its inputs (balancer.simulation.motions).
INPUT_COORDINATES = "input-coordinates"
#: From this many crank states on, :meth:`Mechanism.crank_forces` evaluates the groups' route
#: as a straight-line program (:mod:`balancer.linkage.program`): the same arithmetic in
#: fewer operations, whose one-time build (about 0.1 s) then pays off.
PROGRAM_STATES = 8192
#: From this many crank states on, the program runs compiled (:mod:`balancer.linkage.kernel`,
#: where numba is there): its compilation (about a second, then milliseconds from the disk
#: cache) and numba's import (0.3 s) pay off only over a long cycle.
KERNEL_STATES = 2**18
#: The general core's routes (:func:`balancer.linkage.dynamics.inverse_dynamics`) by the
#: mechanism's.
_GENERAL_ROUTES: dict[Route, Literal["groups", "global"]] = {
    "newton-euler": "groups", "mass-matrix": "global"}


#: One build of a program at a time (a cycle analysis runs its chunks on threads).
_PROGRAM_LOCK = threading.Lock()


@dataclass(eq=False)
class RotorLoads:
    """What a mechanism's rotors add to the frame's loads at crank states (arrays ``(N,)``).

    Attributes
    ----------
    bearings
        Force on the frame at each rotor's bearing point, complex, N.
    force, moment, couple
        The shaking force (complex, N), moment about the origin (N·m) and rocking couple
        (complex ``Mx + i·My``, N·m) they add.
    torque
        What they add to the driving torque, N·m.
    teeth
        What they add to gear pairs' tooth forces, complex, N, by pair (a rotor on a geared
        link whose weights' couple the gear carries).
    """

    bearings: dict[str, NDArray[np.complex128]]
    force: NDArray[np.complex128]
    moment: NDArray[np.float64]
    couple: NDArray[np.complex128]
    torque: NDArray[np.float64]
    teeth: dict[str, NDArray[np.complex128]] = field(default_factory=dict)


def _put(forces: Forces, part: Forces, where: NDArray[np.bool_] | slice) -> None:
    """Write ``part``'s rows into ``forces`` at the states ``where`` (in place)."""
    for mine, theirs in zip(forces.arrays(), part.arrays(), strict=True):
        mine[where] = theirs


@dataclass(frozen=True, eq=False)
class Limit:
    """Samples of a revolution that are exactly at a singular pose of the smooth motion.

    There the individual reactions are unbounded; the shaking force and moment and the driving
    torque are the limits of the motion, the weighted sum of evaluations at the offsets.
    """

    mask: NDArray[np.bool_]
    offsets: tuple[float, ...]
    weights: tuple[float, ...]


class Supports(Protocol):
    """Supports that share a ground point's reaction: what a mechanism with them gives.

    An engine's main bearings (:attr:`Mechanism.supports`), in one order throughout.
    """

    def loads(self, mo: Motion, reactions: Reactions, *, loads: bool = True,
              gravity: tuple[float, float] = (0.0, 0.0)) -> tuple[SupportLoad, ...]:
        """Each support's load at a motion's states.

        From the motion ``mo`` and the frame loads ``reactions`` computed there (with the
        applied ``loads`` and ``gravity`` they were computed with).
        """
        ...

    def regressors(self, mo: Motion) -> tuple[NDArray[np.complex128], ...]:
        """:meth:`loads` (inertial) as linear maps of the design vector, ``(N, P)`` each.

        Over the mechanism's layout; the rotors' masses are left out (a balancing's
        mass·radius sites, shared among the supports by :meth:`shares`).
        """
        ...

    def shares(self, z: float, axis: complex = 0j) -> tuple[tuple[int, float], ...]:
        """How the supports share a load at plane ``z`` on their shaft about ``axis``.

        ``(support, share)`` pairs; none where no shaft with supports turns about ``axis``.
        """
        ...


class Mechanism:
    """What a mechanism tells the rest of the package (see the module docstring).

    Parameters
    ----------
    model
        The mechanism's data.
    """

    #: How the layers that print name its figures (wording, columns, outputs); the core never
    #: reads it.
    presentation: ClassVar[Presentation] = Presentation()
    #: The mechanism's own formulations of the equations of motion by name, the default first:
    #: each a ``"module.Class"`` of its folder (a :class:`~balancer.mechanisms.formulation.
    #: Formulation`), imported when asked for (:func:`balancer.formulations.own_formulation`),
    #: so that analysing a mechanism does not load its formulations. The general ones
    #: (:mod:`balancer.formulations`) apply to every mechanism besides.
    own_formulations: ClassVar[Mapping[str, str]] = {}
    #: The formulation a check by simulation uses: one the optimiser's route does not share.
    verify_method: ClassVar[str] = "multibody"
    #: The spec key that holds the geometry (named by errors about it).
    geometry_key: ClassVar[str] = "mechanism.points"
    def __init__(self, model: MechanismModel) -> None:
        self.model = model

    # -- identity -----------------------------------------------------------------------------

    @cached_property
    def linkage(self) -> Linkage:
        """The mechanism as a general linkage."""
        assert isinstance(self.model, Linkage), "a seed's mechanism builds its general linkage"
        return self.model

    @cached_property
    def structure(self) -> Structure:
        """The general linkage's equations (:mod:`balancer.linkage.structure`)."""
        return Structure.of(self.linkage)

    @cached_property
    def layout(self) -> Layout:
        """The named layout of the design vector."""
        return Layout.of(self.structure)

    @property
    def rotors(self) -> tuple[tuple[str, Rotor], ...]:
        """Rotors geared to the input besides the links' counter-rotors (none in general).

        Each with the name of the frame's point that carries its bearing (a ground point of
        the linkage where its axis is one: an engine's crankshaft masses on the main bearings
        ``O``; else a point of its own: a balance shaft's). Their loads are added to the
        linkage's in :meth:`inverse_dynamics` and :meth:`crank_forces`
        (:class:`~balancer.linkage.rotors.Rotor`).
        """
        return ()

    @property
    def start_angle(self) -> float:
        """Crank angle at which a simulation starts when the spec gives none, rad.

        The reference pose's.
        """
        return float(self.structure.ref_angle[self.structure.input])

    def with_links(self, links: dict[str, Link]) -> Mechanism:
        """The same mechanism with some links' mass properties replaced."""
        return type(self)(self.model.with_links(links))

    def describe(self) -> str:
        """A short word on how it moves.

        Whether the crank turns fully, or how many inputs drive it.
        """
        count = len(self.linkage.inputs)
        if count > 1:
            return f"{count} inputs"
        return "full turn" if self.assembly_range().full else "swinging crank"

    @property
    def branch(self) -> Branch | None:
        """The assembly branch its spec names (``"+"`` or ``"-"``), or ``None``.

        ``None`` in general: the reference pose fixes the branch.
        """
        return None

    # -- kinematics ---------------------------------------------------------------------------

    def assembly_range(self) -> AssemblyRange:
        """Crank angles at which the linkage assembles, on the reference pose's branch."""
        shared = self.structure.kinematic  # (the same for every design of this geometry)
        if "assembly" not in shared:
            shared["assembly"] = assembly_range(self.structure)
        return shared["assembly"]

    def change_points(self) -> tuple[float, ...]:
        """Crank angles where the assemblies meet and the smooth motion passes (none in general).

        There every joint of a loop is in line: the constraints are dependent, and a
        formulation in absolute coordinates cannot tell the branches apart.
        """
        return ()

    def _full_turn_rule(self) -> str:
        return ""

    def motion(self, theta1: ArrayLike, omega1: ArrayLike = 0.0,
               alpha1: ArrayLike = 0.0) -> Motion:
        """Frames, rates and accelerations at crank states (arrays broadcast together)."""
        return kinematics.motion(self.structure, InputState.crank(theta1, omega1, alpha1))

    def motion_at(self, state: InputState) -> Motion:
        """Frames, rates and accelerations at the inputs' states (any number of inputs)."""
        return kinematics.motion(self.structure, state)

    def pose_at(self, state: InputState) -> Pose:
        """The links' frames at the inputs' positions of ``state`` (its rates unused).

        A one-input mechanism's by :meth:`pose` (its closed form, where it has one).
        """
        if state.size == 1:
            return self.pose(state.positions[0])
        return kinematics.positions(self.structure, state)

    def pose(self, theta1: ArrayLike) -> Pose:
        """The links' frames at crank angles (:attr:`Motion.pose` without the rates)."""
        return kinematics.positions(self.structure, InputState.crank(theta1))

    def limits(self, theta1: NDArray[np.float64]) -> list[Limit]:
        """Samples at singular poses that the smooth motion passes (none in general)."""
        return []

    # -- dynamics -----------------------------------------------------------------------------

    def inverse_dynamics(self, mo: Motion, *, route: Route | None = None, loads: bool = True,
                         gravity: tuple[float, float] = (0.0, 0.0)) -> Forces:
        """Forces on the ground and driving torque of the mechanism's own design (one column).

        ``route`` is one of :data:`ROUTES`: ``"newton-euler"`` the links' equations group by
        group (:func:`balancer.linkage.dynamics.kinetostatics`), ``"mass-matrix"`` all at once
        with the links' mass matrices and the constraints' multipliers.
        """
        route = route or ROUTES[0]
        general = _GENERAL_ROUTES[route]
        forces = dynamics.inverse_dynamics(self.structure, mo, self.linkage, gravity=gravity,
                                           loads=loads, route=general)
        if not self.rotors:  # (geared rotors turn with a crank: one-input mechanisms only)
            return forces
        return self._with_rotors(forces, mo.theta1, mo.omega1, mo.alpha1, gravity)

    def rotor_loads(self, theta1: ArrayLike, omega1: ArrayLike, alpha1: ArrayLike,
                    gravity: tuple[float, float] = (0.0, 0.0), *,
                    weights_on_crank: bool = False) -> RotorLoads | None:
        """What the :attr:`rotors` add to the frame's loads at crank states (arrays ``(N,)``).

        The linkage carries each rotor's inertia seen by the crank (``k²·J``, in its input
        link's, as a counter-rotor's: :meth:`linkage`); a rotor adds its force on its bearing,
        the force's moment about the origin, its weights' moment, its gear train's couple on the
        frame ``J·k·(k − 1)·α`` and its rocking couple; the driving torque gains what its
        weights take from the crank. ``None`` without rotors.

        ``weights_on_crank``: the linkage's own equations carry the weights' couple on the
        crank (a simulation's: :meth:`~balancer.linkage.rotors.Rotor.weight_couple` applied to
        it), so that its motor's torque has it already, and its loads on the frame count it as
        applied from outside: the driving torque then leaves it out and the moment takes it
        back.
        """
        if not self.rotors:
            return None
        theta, omega, alpha = np.broadcast_arrays(
            *(np.atleast_1d(np.asarray(x, dtype=float)) for x in (theta1, omega1, alpha1)))
        shape = theta.shape
        zero = np.zeros(shape)
        out = RotorLoads(bearings={}, force=zero.astype(complex), moment=zero.copy(),
                         couple=zero.astype(complex), torque=zero.copy())
        for point, rotor in self.rotors:
            bare = replace(rotor, inertia=0.0)  # (its inertia is the linkage's)
            loads = bare.loads(theta, omega, alpha, gravity)
            out.bearings[point] = out.bearings.get(point, 0.0) + loads.force
            out.force = out.force + loads.force
            out.moment = (out.moment + loads.moment
                          + ground_couple(rotor.inertia, alpha, rotor.ratio))
            out.couple = out.couple + loads.couple
            out.torque = out.torque - loads.link_couple
            if weights_on_crank:
                carried = rotor.weight_couple(theta, complex(*gravity))
                out.torque = out.torque + carried
                out.moment = out.moment - carried
        return out

    def _with_rotors(self, forces: Forces, theta1: ArrayLike, omega1: ArrayLike,
                     alpha1: ArrayLike, gravity: tuple[float, float], *,
                     in_place: bool = False) -> Forces:
        """``forces`` (one column) with the :attr:`rotors`' loads added (:meth:`rotor_loads`).

        ``in_place``: added into ``forces``' own arrays (writable, every ground point there),
        else into copies.
        """
        extra = self.rotor_loads(theta1, omega1, alpha1, gravity)
        if extra is None:
            return forces
        if not in_place:
            n = np.shape(extra.torque)[0]
            zero = V(np.zeros((n, 1)), np.zeros((n, 1)))
            reactions = {p: forces.reactions.get(p, zero) for p in frame_points(self)}
            forces = Forces(reactions=reactions, slider_normal=forces.slider_normal,
                            slider_couple=forces.slider_couple,
                            input_torques=forces.input_torques,
                            shaking_force=forces.shaking_force,
                            shaking_moment=forces.shaking_moment,
                            rocking_couple=forces.rocking_couple, teeth=forces.teeth)
            forces = forces.with_arrays([np.array(np.broadcast_to(a, (n, 1)), dtype=float)
                                         for a in forces.arrays()])

        def add(target: ArrayLike, value: ArrayLike) -> None:
            np.asarray(target)[:, 0] += np.asarray(value)

        def add_vector(target: V, value: ArrayLike) -> None:
            add(target.x, np.real(value))
            add(target.y, np.imag(value))

        for point, f in extra.bearings.items():
            add_vector(forces.reactions[point], f)
        for name, f in extra.teeth.items():
            add_vector(forces.teeth[name], f)
        add(forces.driving_torque, extra.torque)
        add_vector(forces.shaking_force, extra.force)
        add(forces.shaking_moment, extra.moment)
        add_vector(forces.rocking_couple, extra.couple)
        return forces

    def rocking_couple(self, mo: Motion, *, loads: bool = True,
                       gravity: tuple[float, float] = (0.0, 0.0)) -> V:
        """The rocking couple on the frame (:func:`balancer.linkage.dynamics.rocking_couple`).

        Arrays ``(N, 1)``, N·m: what a closed-form route, which works in the plane, adds to its
        forces; zeros for a mechanism in one plane.
        """
        if in_one_plane(self):
            zero = np.zeros((mo.count, 1))
            return V(zero, zero.copy())
        couple = dynamics.rocking_couple_of(self.structure, mo, self.linkage, gravity=gravity,
                                            loads=loads)
        if not self.rotors:
            return couple
        geared = self.rotor_loads(mo.theta1, mo.omega1, mo.alpha1, gravity)
        if geared is None:
            return couple
        return V.of_array(couple.complex() + np.reshape(geared.couple, (-1, 1)))

    def crank_forces(self, theta1: ArrayLike, omega1: ArrayLike = 0.0, alpha1: ArrayLike = 0.0,
                     *, route: Route | None = None, loads: bool = True,
                     gravity: tuple[float, float] = (0.0, 0.0),
                     compiled: bool | None = None, into: Forces | None = None) -> Forces:
        """:meth:`inverse_dynamics` of :meth:`motion` at crank states (arrays broadcast).

        A mechanism with a closed form may compute it without the general motion. At
        :data:`PROGRAM_STATES` states or more, the groups' route runs as a straight-line
        program (:class:`~balancer.linkage.program.CrankForcesProgram`, the same figures to
        rounding); the states it leaves out, the numpy route computes. ``compiled``: run the
        program compiled where it can be (``None``: at :data:`KERNEL_STATES` states or more;
        a long cycle analysis asks for it for each of its chunks). ``into``: forces at
        :func:`frame_points` and the linkage's ``ground_sliders`` whose arrays ``(N, 1)``
        (writable, any stride: views of a cycle's columns) receive the figures, and are
        returned — the compiled program writes there directly.
        """
        route = route or ROUTES[0]
        states = list(np.broadcast_arrays(*(np.atleast_1d(np.asarray(x, dtype=float))
                                            for x in (theta1, omega1, alpha1))))
        if compiled is None:
            compiled = states[0].size >= KERNEL_STATES
        if compiled and route == "newton-euler":
            program = self._program(loads, (gravity[0], gravity[1]))
            if program is not None and program.kernel is not None:
                return self._program_forces(program, states, loads, gravity, compiled=True,
                                            into=into)
        forces = self._uncompiled_forces(states, route=route, loads=loads, gravity=gravity)
        if into is None:
            return forces
        _put(into, forces.matching(into), slice(None))
        return into

    def _uncompiled_forces(self, states: list[NDArray[np.float64]], *, route: Route,
                          loads: bool, gravity: tuple[float, float]) -> Forces:
        """:meth:`crank_forces` without a compiled kernel, at states ``(θ1, ω1, α1)``.

        The straight-line program by numpy over :data:`PROGRAM_STATES` states or more, else
        the numpy route; a mechanism with closed forms gives its own.
        """
        if route == "newton-euler" and states[0].size >= PROGRAM_STATES:
            program = self._program(loads, (gravity[0], gravity[1]))
            if program is not None:
                return self._program_forces(program, states, loads, gravity, compiled=False)
        return self.inverse_dynamics(self.motion(*states), route=route, loads=loads,
                                     gravity=gravity)

    def _program_forces(self, program: CrankForcesProgram, states: list[NDArray[np.float64]],
                        loads: bool, gravity: tuple[float, float], *, compiled: bool,
                        into: Forces | None = None) -> Forces:
        """The groups' route by the straight-line ``program`` (compiled, where asked).

        The states the program leaves out, the numpy route computes. ``into``: as
        :meth:`crank_forces`'.
        """
        forces, ok = program.evaluate(*(np.ascontiguousarray(x) for x in states),
                                      compiled=compiled, into=into)
        if into is not None:
            for point in set(into.reactions) - set(program.forces.reactions):
                for a in (into.reactions[point].x, into.reactions[point].y):
                    np.asarray(a)[...] = 0.0  # (a rotor's bearing alone: its loads below)
        forces = self._with_rotors(forces, states[0], states[1], states[2], gravity,
                                   in_place=into is not None)
        if not ok.all():
            rest = self.inverse_dynamics(self.motion(*(x[~ok] for x in states)),
                                         route="newton-euler", loads=loads, gravity=gravity)
            _put(forces, rest.matching(forces), ~ok)
        return forces

    def _program(self, loads: bool, gravity: tuple[float, float]
                 ) -> CrankForcesProgram | None:
        """The mechanism's crank-forces program for these loads and gravity (built once)."""
        # (imported here: the program and its compiler are for long cycles, and a short
        # command's start-up should not pay for them)
        from ..linkage.program import CrankForcesProgram

        key = (loads, gravity)
        with _PROGRAM_LOCK:
            cache: dict[tuple[bool, tuple[float, float]], CrankForcesProgram | None] = (
                self.__dict__.setdefault("_programs", {}))  # of this design only
            if key not in cache:
                try:
                    cache[key] = CrankForcesProgram(self.structure, loads=loads,
                                                    gravity=gravity)
                except NotImplementedError:  # an operation numpy has no counterpart for
                    cache[key] = None
            return cache[key]

    def regressors(self, mo: Motion, gravity: tuple[float, float] = (0.0, 0.0)) -> Forces:
        """:meth:`inverse_dynamics` without loads as linear maps of the design vector.

        Arrays ``(N, P)`` with ``P`` the :attr:`layout`'s size.
        """
        forces, _ = dynamics.regressors(self.structure, mo, gravity)
        return forces

    @property
    def supports(self) -> Supports | None:
        """Supports that share ground points' reactions, or ``None`` (in general).

        An engine's main bearings where its spec places them (each carries its share of the
        crankshaft's loads by the lever rule).
        """
        return None

    def closed_form_force_balance(self) -> NDArray[np.float64] | None:
        """Shaking-force balance in closed form, ``A`` with ``A·π = 0`` over :attr:`layout`.

        ``None`` in general: :mod:`balancer.force_balance` finds the conditions from the
        linkage; the four-bar and the slider-crank give the seeds' (Eq. 57–58; Wunderlich's
        Eq. 20a–b), exact where sampled ones are exact only to rounding.
        """
        return None

    # -- what a drawing shows ------------------------------------------------------------------

    def drawing(self) -> Drawing:
        """What a drawing shows besides the links (:class:`~balancer.mechanisms.drawing.Drawing`).

        A general linkage's: each one-point sliding link a block, no shafts' masses; a piston
        engine's its pistons, counterweights and balance shafts' eccentrics.
        """
        return drawing.of_linkage(self.linkage)


# -- what the package derives from any mechanism ---------------------------------------------


def in_one_plane(mech: Mechanism) -> bool:
    """Whether every link and rotor's mass moves in the crank's plane (no rocking couple)."""
    return not (any(link.z for link in mech.linkage.links)
                or any(e.z for _, r in mech.rotors for e in r.eccentrics))


def frame_points(mech: Mechanism) -> tuple[str, ...]:
    """Points of the frame (where reactions act): the linkage's, and rotors' bearings."""
    own = mech.linkage.ground.points
    return (*own, *dict.fromkeys(p for p, _ in mech.rotors if p not in own))


def frame_positions(mech: Mechanism) -> dict[str, complex]:
    """Place of each of :func:`frame_points`, complex ``x + i·y``, m."""
    places = {p: complex(*xy) for p, xy in mech.linkage.points}
    places.update({p: rotor.axis for p, rotor in mech.rotors if p not in places})
    return {p: places[p] for p in frame_points(mech)}


def formulation_names(mech: Mechanism) -> tuple[str, ...]:
    """Every formulation of the equations of motion that applies, the default first.

    The mechanism's own (:attr:`Mechanism.own_formulations`), then the general ones, which
    apply to any linkage: the multibody formulation (:mod:`balancer.formulations.multibody`)
    and the crank-angle one (:mod:`balancer.formulations.crank_angle`), the latter first where
    the crank turns fully (no dead point of the crank to stop it).
    """
    own = tuple(mech.own_formulations)
    if len(mech.linkage.inputs) > 1:  # (driven along motions, or free: no crank)
        return (MULTIBODY, INPUT_COORDINATES)
    if mech.assembly_range().full:
        return (*own, CRANK_ANGLE, MULTIBODY)
    return (*own, MULTIBODY, CRANK_ANGLE)


def require_one_input(mech: Mechanism, purpose: str) -> None:
    """Nothing, if one input drives the mechanism (a crank).

    Raises
    ------
    SpecError
        Otherwise (exit code 2): ``purpose`` (e.g. "a simulation") turns a crank; a linkage
        with several inputs is analysed along its motions.
    """
    inputs = mech.linkage.inputs
    if len(inputs) > 1:
        raise SpecError(
            f"{purpose} turns one crank, and this linkage has {len(inputs)} inputs; "
            "along its motions ([[motion]]) `balancer analyze` gives its loads, `plot "
            "--cycle` and `--animate` draw them, `simulate` and `verify` run them, and "
            "`optimize`, `pareto` and `sweep` balance it", key="mechanism.inputs",
            value=list(inputs))


def require_full_revolution(mech: Mechanism, purpose: str) -> AssemblyRange:
    """The mechanism's assembly range, if its crank turns a full revolution.

    Raises
    ------
    SpecError
        With several inputs (:func:`require_one_input`).
    AssemblyError
        Otherwise (exit code 2): ``purpose`` (e.g. "a cycle analysis") needs a crank that
        turns.
    """
    require_one_input(mech, purpose)
    rng = mech.assembly_range()
    if not rng.full:
        raise AssemblyError(
            f"{purpose} needs a crank that turns a full revolution{mech._full_turn_rule()}, "
            f"but this {mech.model.type} assembles only for θ1 in {rng.describe()}",
            key=mech.geometry_key)
    return rng
