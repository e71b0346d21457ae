"""What the compiled formulations of any linkage share: CasADi symbols for the linkage core.

The equations of :mod:`balancer.linkage` are evaluated on CasADi's symbols through
:class:`~balancer.linkage.symbols.CasadiOps`; :class:`Compiled` calls a compiled function
through its buffers; :func:`link_equations` and
:func:`spring_forces` are the links' mass matrices and applied forces in absolute coordinates
(Nikravesh 1988, ch. 11); :class:`LinkageFormulation` is what :mod:`.multibody` and
:mod:`.crank_angle` share as formulations of any linkage.
"""

from __future__ import annotations

from collections.abc import Callable, Sequence
from typing import TYPE_CHECKING

import numpy as np
from numpy.typing import ArrayLike, NDArray

from ..linkage import rotors
from ..linkage.constraints import GROUND_INDEX, Pose
from ..linkage.structure import Structure
from ..linkage.symbols import CasadiOps
from ..linkage.vectors import NUMPY, Num, OpsLike, V
from ..mechanisms.base import Mechanism
from ..mechanisms.formulation import Formulation
from ..model import Link, Spring

if TYPE_CHECKING:  # annotations only: CasADi is imported where symbols are built
    import casadi as ca

#: Columns per call of a function mapped by :meth:`Compiled.columns`.
BLOCK = 64


class Compiled:
    """A CasADi function of one dense vector to one dense vector, called through its buffers.

    CasADi's buffer interface evaluates in about a microsecond; its Python call converts every
    argument to and from a DM, a hundred times slower, which would dominate the integration.
    """

    def __init__(self, fn: ca.Function) -> None:
        self.fn = fn
        self.arg = np.zeros(fn.size1_in(0))
        self.res = np.zeros(fn.size1_out(0))
        self._buffer, self._eval = fn.buffer()
        # (CasADi's stubs ask a size its binding takes from the buffer; numpy's arrays are
        # buffers, typed so from Python 3.12.)
        self._buffer.set_arg(0, memoryview(self.arg))  # type: ignore[call-arg, arg-type]
        self._buffer.set_res(0, memoryview(self.res))  # type: ignore[call-arg, arg-type]
        #: The function mapped over BLOCK columns, when first needed: its buffer, its
        #: evaluation and its argument and result arrays.
        self._block: tuple[ca.FunctionBuffer, Callable[[], None], NDArray[np.float64],
                           NDArray[np.float64]] | None = None

    def __call__(self, x: NDArray[np.float64]) -> NDArray[np.float64]:
        self.arg[:] = x
        self._eval()
        return self.res.copy()

    def columns(self, x: NDArray[np.float64]) -> NDArray[np.float64]:
        """The function at each column of ``x`` (inputs × count): outputs × count.

        The function mapped over :data:`BLOCK` columns (built once; a map's construction
        grows faster than its size, milliseconds for a thousand) is called through its
        buffers block by block, the last block padded with its first column. (A call with a
        matrix argument maps it too, but converts the result from a DM element by element,
        several times the cost of the evaluation.)
        """
        if self._block is None:
            mapped = self.fn.map(BLOCK, "serial")
            arg = np.zeros((BLOCK, self.arg.size))  # row j: column j's inputs, as CasADi stores
            res = np.zeros((BLOCK, self.res.size))
            buffer, evaluate = mapped.buffer()
            buffer.set_arg(0, memoryview(arg.reshape(-1)))  # type: ignore[call-arg, arg-type]
            buffer.set_res(0, memoryview(res.reshape(-1)))  # type: ignore[call-arg, arg-type]
            self._block = (buffer, evaluate, arg, res)
        _, evaluate, arg, res = self._block
        count = x.shape[1]
        out = np.empty((self.res.size, count))
        for start in range(0, count, BLOCK):
            part = x[:, start : start + BLOCK]
            size = part.shape[1]
            arg[:size] = part.T
            if size < BLOCK:
                arg[size:] = part[:, 0]
            evaluate()
            out[:, start : start + size] = res[:size].T
        return out


def spring_forces(structure: Structure, spring: Spring, pose: Pose, ops: OpsLike
                  ) -> list[tuple[int, V, V]]:
    """The spring's forces on its two carriers: ``(link, force, point)`` twice (N, m)."""
    ends: list[tuple[int, V]] = []
    for p in spring.points:
        links = structure.point_links[p]
        k = GROUND_INDEX if GROUND_INDEX in links else links[0]
        ends.append((k, pose.point(k, structure.local[(k, p)])))
    (ka, a), (kb, b) = ends
    d = b - a
    length = ops.sqrt(d.norm2())
    tension = spring.stiffness * (length - spring.free_length)
    unit = d / length
    return [(ka, unit * tension, a), (kb, unit * (-tension), b)]


def link_equations(structure: Structure, links: Sequence[Link], pose: Pose, rate: Sequence[Num],
                   gravity: V, gas: ca.SX, geared: Sequence[rotors.Rotor] = ()
                   ) -> tuple[ca.SX, ca.SX]:
    """Mass matrix ``M`` and applied forces ``Q`` of the moving links (SX, 3n×3n and 3n).

    Per link ``k``, in its coordinates ``(x, y, θ)``, with ``S̄ = R(θ)·(m·s̄)`` its first
    moment about the frame's origin and ``J_O`` its inertia about it (a counter-rotor's
    added)::

        M_k = [[m, 0, −S_y], [0, m, S_x], [−S_y, S_x, J_O]]
        Q_k = [m·ḡ + F̄ + ω²·S̄,  S̄ × ḡ + (R·s̄) × F̄ + M]  + springs, slider forces

    (``ω²·S̄`` is what is left of the inertia force's velocity terms; ``rate`` the links'
    angular velocities, ``gas`` the slider forces along their guides, N, per prismatic pair).
    ``geared``: rotors geared to the input link (an engine's crankshaft masses and balance
    shafts; their inertia is in the link's already): their eccentrics' weights' couple on it,
    ``k·(ū × ḡ)`` (:meth:`~balancer.linkage.rotors.Rotor.weight_couple`).
    """
    import casadi as ca  # heavy: only where symbols are built
    n = structure.size
    mass = ca.SX.zeros(3 * n, 3 * n)
    force = ca.SX.zeros(3 * n)
    for k, link in enumerate(links):
        _, me, mf, j = link.inertial_parameters
        first = V(me, mf).rotated(pose.cos[k], pose.sin[k])
        j_origin = j + rotors.link_inertia(link.counter_rotor)
        i = 3 * k
        mass[i, i] = mass[i + 1, i + 1] = link.mass
        mass[i, i + 2] = mass[i + 2, i] = -first.y
        mass[i + 1, i + 2] = mass[i + 2, i + 1] = first.x
        mass[i + 2, i + 2] = j_origin
        w2 = rate[k] * rate[k]
        arm = V(link.e, link.f).rotated(pose.cos[k], pose.sin[k])
        force[i] += link.mass * gravity.x + link.force[0] + w2 * first.x
        force[i + 1] += link.mass * gravity.y + link.force[1] + w2 * first.y
        force[i + 2] += first.cross(gravity) + arm.cross(V(*link.force)) + link.moment

    g = complex(gravity.x, gravity.y)
    for rotor in geared:
        force[3 * structure.input + 2] += rotor.weight_couple(pose.angles[structure.input], g,
                                                              CasadiOps)

    def put(k: int, f_vec: V, at: V) -> None:
        if k != GROUND_INDEX:
            arm = at - pose.origin(k)
            force[3 * k] += f_vec.x
            force[3 * k + 1] += f_vec.y
            force[3 * k + 2] += arm.cross(f_vec)

    for spring in structure.linkage.springs:
        for k, f_vec, at in spring_forces(structure, spring, pose, CasadiOps):
            put(k, f_vec, at)
    for j, c in enumerate(structure.prisms):
        d = pose.rotate(c.g, c.dg)
        at = pose.point(c.s, c.ps)
        put(c.s, d * gas[j], at)
        put(c.g, d * (-gas[j]), at)
    return mass, force


class LinkageFormulation(Formulation):
    """What the compiled formulations of any linkage share.

    The mechanism and its general core's structure, the sliders' forces, the change points,
    and the work of the loads, gravity and springs for the energy balance. Built once per
    mechanism (:attr:`~balancer.formulations.Formulation.reusable`).
    """

    reusable = True

    def __init__(self, mechanism: Mechanism, *, gravity: tuple[float, float] = (0.0, 0.0),
                 speed: float | None = None) -> None:
        super().__init__(mechanism, gravity=gravity, speed=speed)
        self.mech = mechanism
        self.structure = self.mech.structure
        self.n = self.structure.size
        self.links = self.mech.linkage.links

    def change_points(self) -> tuple[float, ...]:
        """The mechanism's change points: the driver names them if the motion stalls there."""
        return self.mech.change_points()

    @property
    def has_slider_forces(self) -> bool:
        """Whether a slider force acts (a table of the crank angle, evaluated in Python)."""
        sliders = self.structure.linkage.sliders
        return any(not sliders[c.slider].force.is_zero for c in self.structure.prisms)

    def _gas(self, theta1: float) -> NDArray[np.float64]:
        """The slider forces along their guides at crank angle ``theta1``, N (one per pair)."""
        sliders = self.structure.linkage.sliders
        values = [float(sliders[c.slider].force.at(theta1)) for c in self.structure.prisms]
        return np.array(values if values else [0.0])

    def configuration_work(self, pose: Pose, angles: ArrayLike) -> NDArray[np.float64]:
        """:func:`configuration_work` of the formulation's mechanism under its gravity, J."""
        return configuration_work(self.mech, (self.gravity.real, self.gravity.imag), pose,
                                  angles)


def configuration_work(mech: Mechanism, gravity: tuple[float, float], pose: Pose,
                       angles: ArrayLike) -> NDArray[np.float64]:
    """Work of the loads and gravity less the springs' energy gained since the first state.

    ``pose`` holds the links' frames at the states (arrays over them) and ``angles`` their
    continuous angles, ``(n, count)``: the loads' and gravity's work from the centres of
    mass' and the angles' displacements (the rotors' eccentrics' from their first moments,
    turned with the input), the springs' from their potential energy, J. ``gravity``
    ``(gx, gy)``, m/s².
    """
    g = V(*gravity)
    theta = np.asarray(angles, dtype=float)
    count = theta.shape[1]
    work = np.zeros(count)
    for k, link in enumerate(mech.linkage.links):
        com = pose.point(k, V(link.e, link.f))
        work += (g * link.mass + V(*link.force)).dot(com - V(com.x[0], com.y[0]))
        work += link.moment * (theta[k] - theta[k, 0])
    for _, rotor in mech.rotors:  # its eccentrics' weights (a crank geared rotor's)
        turned = rotor.first_moment(theta[mech.structure.input])
        work += (np.conj(complex(*gravity)) * (turned - turned[0])).real
    energy: Num = 0.0
    for s in mech.structure.linkage.springs:
        (_, _, a), (_, _, b) = spring_forces(mech.structure, s, pose, NUMPY)
        energy = energy + 0.5 * s.stiffness * (np.sqrt((b - a).norm2()) - s.free_length) ** 2
    spring = np.asarray(energy, dtype=float) * np.ones(count)
    return work - (spring - spring[0])
