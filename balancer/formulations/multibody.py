"""Forward dynamics of any linkage: absolute coordinates, constraints and multipliers.

The generalisation of the paper's truss formulation (Meijaard & van der Wijk 2020, Sect. 4.2 and
5.1) to any pin-jointed linkage with prismatic pairs and springs (Nikravesh 1988, ch. 11): each
moving link has coordinates ``q_k = (x_k, y_k, θ_k)`` (its frame's origin and angle, as in
:mod:`balancer.linkage.structure`), and the equations of motion are, with the constraints'
Jacobian ``Φ_q`` (joints, and with the crank driven the driver ``θ_input − θ1(t) = 0``) and
their multipliers ``λ``::

    M(q)·q̈ + Φ_qᵀ·λ = Q(q, q̇),        Φ_q·q̈ = γ(q, q̇)

Per link, with ``S̄ = R(θ)·(m·s̄)`` its first moment about the frame's origin and ``J_O`` its
inertia about it (a counter-rotor's added)::

    M_k = [[m, 0, −S_y], [0, m, S_x], [−S_y, S_x, J_O]]
    Q_k = [m·ḡ + F̄ + ω²·S̄,  S̄ × ḡ + (R·s̄) × F̄ + M]  + springs, slider forces

(``ω²·S̄`` is what is left of the inertia force's velocity terms). The multipliers give every
joint's force; a constraint's generalized force on the ground (the ground as a link at rest)
is the force and moment the mechanism exerts on the frame, the driver's the motor's reaction.
The state ``(q, q̇)`` is not minimal: after each step it is projected back onto the
constraints and their derivative. It passes dead points of the crank.

The matrices are CasADi expressions of ``(q, q̇)`` built once (the constraints' equations are
:mod:`balancer.linkage.structure`'s and :mod:`balancer.linkage.kinematics`'s, evaluated on
symbols) and compiled into one function; the linear system is solved with numpy.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass
from types import ModuleType
from typing import TYPE_CHECKING

import numpy as np
from numpy.typing import NDArray

from ..errors import AssemblyError, SolverError
from ..linkage import rotors
from ..linkage.assembly import assembly_gaps
from ..linkage.constraints import GROUND_INDEX, Constraint, FrameTally, Pose
from ..linkage.inputs import InputState
from ..linkage.kinematics import Motion
from ..linkage.loads import Reactions
from ..linkage.symbols import CasadiOps
from ..linkage.vectors import Num, OpsLike, V, _is_zero
from ..mechanisms import geometry
from ..mechanisms.base import Mechanism
from ..mechanisms.formulation import Evaluation, continuous_angles, least_norm, least_norm_many
from .compiled import Compiled, LinkageFormulation, link_equations, spring_forces

if TYPE_CHECKING:  # annotations only: CasADi is imported where symbols are built
    import casadi as ca


@dataclass(frozen=True, eq=False)
class StateDynamics:
    """The multibody formulation's solve at many states, and what it exerts on the frame.

    Attributes
    ----------
    q, qd, qdd
        The links' frame coordinates ``(x, y, θ)``, their rates and accelerations, each
        ``(count, 3n)`` (m, rad; per s, per s²).
    multipliers
        The constraints' multipliers, ``(count, rows)``.
    reactions
        The loads on the frame (the formulation works in the plane: its rocking couple is
        zero, the caller's to add), each motor's torque minus its driver's multiplier.
    """

    q: NDArray[np.float64]
    qd: NDArray[np.float64]
    qdd: NDArray[np.float64]
    multipliers: NDArray[np.float64]
    reactions: Reactions


class Multibody(LinkageFormulation):
    """Absolute coordinates with the constraints' multipliers (any linkage)."""

    name = "multibody"
    minimal = False
    passes_dead_points = True
    #: At a change point its constraints are dependent and the saddle-point system singular.
    passes_change_points = False

    def __init__(self, mechanism: Mechanism, *, gravity: tuple[float, float] = (0.0, 0.0),
                 speed: float | None = None, prescribed: bool = False) -> None:
        super().__init__(mechanism, gravity=gravity, speed=speed)
        #: The mechanism as a general linkage (springs, sliders, ground points).
        self.general = self.mech.linkage
        s = self.structure
        if self.driven and len(s.drivers) != 1:
            raise ValueError("a crank at constant speed drives a linkage of one input")
        #: Every input driven (a crank at constant speed, or ``prescribed``: each input along
        #: a motion, its accelerations an argument of the dynamics).
        self.inputs_driven = self.driven or prescribed
        self.theta1_start = s.ref_angle[s.inputs[0]]
        self.constraints: list[Constraint] = [*s.constraints,
                                              *(s.drivers if self.inputs_driven else ())]
        #: The number of inputs (each driver's prescribed acceleration is an argument).
        self.input_count = len(s.drivers)
        self.rows = sum(c.rows for c in self.constraints)
        self.scale = s.length_scale()
        self._build()

    # -- the compiled equations ---------------------------------------------------------------

    def _pose(self, q: Num, ops: OpsLike | ModuleType) -> Pose:
        n = self.n
        angles = [q[3 * k + 2] for k in range(n)]
        return Pose([V(q[3 * k], q[3 * k + 1]) for k in range(n)], angles,
                    [ops.cos(t) for t in angles], [ops.sin(t) for t in angles])

    def _build(self) -> None:
        import casadi as ca  # heavy: only where symbols are built
        n, s = self.n, self.structure
        q = ca.SX.sym("q", 3 * n)
        qd = ca.SX.sym("qd", 3 * n)
        gas = ca.SX.sym("gas", max(1, len(s.prisms)))
        inputs = ca.SX.sym("inputs", self.input_count)  # the inputs' accelerations
        zero = [ca.SX(0)] * self.input_count
        prescribed = InputState.symbolic(zero, zero, [inputs[i] for i in range(self.input_count)])
        pose = self._pose(q, CasadiOps)
        vel = [V(qd[3 * k], qd[3 * k + 1]) for k in range(n)]
        rate = [qd[3 * k + 2] for k in range(n)]
        g = V(self.gravity.real, self.gravity.imag)
        mass, force = link_equations(self.structure, self.links, pose, rate, g, gas,
                                     [r for _, r in self.mech.rotors])
        jac = ca.SX.zeros(self.rows, 3 * n)
        gamma = ca.SX.zeros(self.rows)
        row = 0
        for c in self.constraints:
            for link, coeffs in c.jacobian(pose):
                if link == GROUND_INDEX:
                    continue
                for r in range(c.rows):
                    for col in range(3):
                        jac[row + r, 3 * link + col] += coeffs[r][col]
            gam = c.gamma(pose, vel, rate, prescribed)  # (a driver's: its input's)
            for r in range(c.rows):
                if not _is_zero(gam[r]):
                    gamma[row + r] = gam[r]
            row += c.rows
        self._equations = ca.Function("equations", [q, qd, gas, inputs],
                                      [mass, force, jac, gamma])
        self._kinetic = ca.Function("kinetic", [q, qd], [0.5 * ca.dot(qd, ca.mtimes(mass, qd))])
        self._build_frame(q, qd, gas, pose)
        self._build_dynamics()
        self._build_constraints(q, pose)

    def _build_frame(self, q: ca.SX, qd: ca.SX, gas: ca.SX, pose: Pose) -> None:
        """The forces on the frame from a state, its accelerations and multipliers (SX).

        A constraint's generalized force on the ground (the ground as a link at rest) is
        ``−Φ_gᵀ·λ``: the force and moment the mechanism exerts on the frame there.
        """
        import casadi as ca  # heavy: only where symbols are built
        n, s = self.n, self.structure
        lam = ca.SX.sym("lam", self.rows)
        acc = ca.SX.sym("acc", 3 * n)
        frame = FrameTally(0.0)
        fx = fy = mz = ca.SX(0)
        row = 0
        for c in self.constraints:
            for carrier, coeffs in c.jacobian(pose):
                if carrier != GROUND_INDEX:
                    continue
                gen = [-sum(coeffs[r][col] * lam[row + r] for r in range(c.rows))
                       for col in range(3)]
                fx, fy, mz = fx + gen[0], fy + gen[1], mz + gen[2]
                c.tally(frame, gen, [lam[row + r] for r in range(c.rows)])
            row += c.rows
        ground = {p: frame.reactions.get(p, V(0.0, 0.0)) for p in self.general.ground.points}
        normal = list(frame.normal.values())
        couple = list(frame.couple.values())
        for spring in self.general.springs:
            for k, f_vec, at in spring_forces(self.structure, spring, pose, CasadiOps):
                if k == GROUND_INDEX:
                    fx, fy, mz = fx + f_vec.x, fy + f_vec.y, mz + at.cross(f_vec)
        for j, c in enumerate(s.prisms):
            if c.g == GROUND_INDEX:
                f_vec = pose.rotate(c.g, c.dg) * (-gas[j])
                at = pose.point(c.s, c.ps)
                fx, fy, mz = fx + f_vec.x, fy + f_vec.y, mz + at.cross(f_vec)
        for k, link in enumerate(self.links):
            if link.counter_rotor:
                mz = mz + rotors.ground_couple(link.counter_rotor, acc[3 * k + 2])
        # Each motor's torque: minus its driver's multiplier (zero in free motion).
        torques = [frame.torques.get(i, ca.SX(0)) for i in range(self.input_count)]
        #: Names of the outputs of :attr:`_frame` and of the dynamics after ``q̈`` and ``λ``.
        self._ground_names = tuple(ground)
        self._slider_names = tuple(s.names[c.s] for c in s.prisms if c.g == GROUND_INDEX)
        flat = [x for p in ground for x in (ground[p].x, ground[p].y)]
        self._frame = ca.Function("frame", [q, qd, gas, lam, acc], [
            ca.vertcat(*flat) if flat else ca.SX(0, 1),
            ca.vertcat(*normal) if normal else ca.SX(0, 1),
            ca.vertcat(*couple) if couple else ca.SX(0, 1),
            ca.vertcat(fx, fy, mz, *torques)])

    def _build_dynamics(self) -> None:
        """One function from a state to ``q̈``, ``λ`` and the forces on the frame (MX).

        The saddle-point system ``[[M, Φ_qᵀ], [Φ_q, 0]]·[q̈; λ] = [Q; γ]`` is solved by
        CasADi's QR at each call: one compiled call per right-hand side. It is equilibrated
        first with constant diagonal scalings — ``D = diag(M)^(-1/2)`` on the coordinates (M's
        diagonal, the links' masses and inertias about their frames' origins, is constant) and
        ``R`` making the rows of ``Φ_q·D`` unit at the reference pose — so that links whose
        masses and inertias differ by orders of magnitude do not cost the solve its accuracy.
        """
        import casadi as ca  # heavy: only where symbols are built
        k = 3 * self.n
        q = ca.MX.sym("q", k)
        qd = ca.MX.sym("qd", k)
        gas = ca.MX.sym("gas", max(1, len(self.structure.prisms)))
        inputs = ca.MX.sym("inputs", self.input_count)
        mass, force, jac, gamma = self._equations(q, qd, gas, inputs)
        d, r = self._equilibration()
        dq, rl = ca.diag(ca.DM(d)), ca.diag(ca.DM(r))
        kkt = ca.blockcat([[dq @ mass @ dq, dq @ jac.T @ rl],
                           [rl @ jac @ dq, ca.MX(self.rows, self.rows)]])
        z = ca.solve(kkt, ca.vertcat(dq @ force, rl @ gamma), "qr")
        acc, lam = dq @ z[:k], rl @ z[k:]
        outputs = [acc, lam, *self._frame(q, qd, gas, lam, acc)]
        self._dynamics = ca.Function("dynamics", [q, qd, gas, inputs], outputs)
        #: Where each output sits in the flat vector of :attr:`_fast_dynamics`.
        sizes = np.cumsum([0, *(o.size1() for o in outputs)])
        self._slices = [slice(a, b) for a, b in zip(sizes[:-1], sizes[1:], strict=True)]
        flat = ca.vertcat(q, qd, gas, inputs)
        gas_end = 2 * k + gas.size1()
        self._fast_dynamics = Compiled(ca.Function(
            "dynamics_flat", [flat], [ca.densify(ca.vertcat(*self._dynamics(
                flat[:k], flat[k : 2 * k], flat[2 * k : gas_end], flat[gas_end:])))]))

    def _equilibration(self) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
        """The constant scalings ``D`` (coordinates) and ``R`` (constraint rows), diagonals."""
        k = 3 * self.n
        q0 = self.structure.reference_coordinates()
        mass, _, jac, _ = (np.array(x) for x in self._equations(
            q0, np.zeros(k), np.zeros(max(1, len(self.structure.prisms))),
            np.zeros(self.input_count)))
        diag = np.diag(mass)
        d = np.where(diag > 0, 1.0 / np.sqrt(np.where(diag > 0, diag, 1.0)), 1.0)
        norms = np.linalg.norm(jac * d[None, :], axis=1)
        r = np.where(norms > 0, 1.0 / np.where(norms > 0, norms, 1.0), 1.0)
        return d, r

    def _build_constraints(self, q: ca.SX, pose: Pose) -> None:
        """The constraints' residual and Jacobian at a pose and the inputs' positions (SX)."""
        import casadi as ca  # heavy: only where symbols are built
        angles = ca.SX.sym("angles", self.input_count)
        zero = [ca.SX(0)] * self.input_count
        at = InputState.symbolic([angles[i] for i in range(self.input_count)], zero, zero)
        phi = ca.vertcat(*(r for c in self.constraints for r in c.residual(pose, at)))
        jac = ca.densify(ca.jacobian(phi, q))
        self._constraints = Compiled(ca.Function(
            "constraints", [ca.vertcat(q, angles)],
            [ca.vertcat(phi, ca.reshape(jac, -1, 1))]))

    def _call(self, t: float, y: NDArray[np.float64]) -> list[NDArray[np.float64]]:
        """The compiled dynamics at a state: ``q̈``, ``λ``, then the forces on the frame."""
        k = 3 * self.n
        flat = self._fast_dynamics(np.concatenate([y[: 2 * k], self._gas(self.theta1_of(t, y)),
                                                   np.zeros(self.input_count)]))
        return [flat[s] for s in self._slices]

    # -- the formulation's interface ----------------------------------------------------------

    def transmission_of_crank(self, theta1: float) -> float:
        return math.sqrt(max(float(assembly_gaps(self.structure, np.array([theta1]))[0]), 0.0))

    def transmission(self, t: float, y: NDArray[np.float64]) -> float:
        return 1.0  # passes dead points: never stops for one

    def theta1_of(self, t: float, y: NDArray[np.float64]) -> float:
        if self.driven:
            return self.crank_angle(t)
        return float(y[3 * self.structure.inputs[0] + 2])

    def initial_state(self, theta1: float, omega1: float) -> NDArray[np.float64]:
        self.theta1_start = float(theta1)
        if self.driven:
            omega1 = self._motor_speed
        mo = self.mech.motion(theta1, omega1, 0.0)

        def first(x: Num) -> float:
            return float(np.ravel(x)[0])

        q, qd = np.empty(3 * self.n), np.empty(3 * self.n)
        for k in range(self.n):
            q[3 * k : 3 * k + 3] = (first(mo.pose.origins[k].x), first(mo.pose.origins[k].y),
                                    first(mo.pose.angles[k]))
            qd[3 * k : 3 * k + 3] = (first(mo.velocity[k].x), first(mo.velocity[k].y),
                                     first(mo.rate[k]))
        if not np.all(np.isfinite(q)):
            raise AssemblyError("the linkage cannot be assembled at the initial crank angle",
                                key="simulation.theta1", value=theta1)
        q[2::3] = geometry.continued_angles(self.mech, theta1)
        y = np.concatenate([q, qd])
        return np.append(y, 0.0) if self.driven else y

    def driven_motion(self, times: NDArray[np.float64],
                      start: NDArray[np.float64]) -> NDArray[np.float64] | None:
        """The frames' coordinates and rates from the mechanism's motion at the crank angles.

        The crank angle ``θ1(t)`` exactly; the other links' angles continuous from ``start``'s
        (:func:`~balancer.formulations.continuous_angles` over the times, in increasing order:
        the first time's branch nearest ``start``'s angle).
        """
        times = np.asarray(times, dtype=float)
        theta1 = self.crank_angle(times)
        with np.errstate(all="ignore"):
            mo = self.mech.motion(theta1, self._motor_speed, 0.0)
        q, qd = self.coordinates(mo, times.size)
        if not (np.all(np.isfinite(q)) and np.all(np.isfinite(qd))):
            return None
        n = self.n
        angles, rates = q[:, 2::3], qd[:, 2::3]
        angles += 2 * np.pi * np.round((start[2 : 3 * n : 3] - angles[0]) / (2 * np.pi))
        for k in range(n):
            angles[:, k] = continuous_angles(angles[:, k], rates[:, k], times)
        angles[:, self.structure.input] = theta1
        return np.hstack([q, qd])

    def coordinates(self, mo: Motion, count: int
                    ) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
        """The frames' coordinates and rates at ``count`` states of a motion, each ``(count, 3n)``.

        From the linkage core's position and rate analysis (the angles as it gives them).
        """
        n = self.n
        q, qd = np.empty((count, 3 * n)), np.empty((count, 3 * n))
        for k in range(n):
            q[:, 3 * k], q[:, 3 * k + 1] = mo.pose.origins[k].x, mo.pose.origins[k].y
            q[:, 3 * k + 2] = mo.pose.angles[k]
            qd[:, 3 * k], qd[:, 3 * k + 1] = mo.velocity[k].x, mo.velocity[k].y
            qd[:, 3 * k + 2] = mo.rate[k]
        return q, qd

    def prescribed_dynamics(self, state: InputState) -> StateDynamics:
        """The saddle-point system at states where every input is prescribed.

        The links' coordinates and rates ``(q, q̇)`` come from the linkage core's position and
        rate analysis at the inputs' positions and rates (on the constraints and their
        derivative); each driver's ``γ`` is its input's prescribed acceleration. The solve
        ``[[M, Φ_qᵀ], [Φ_q, 0]]·[q̈; λ] = [Q; γ]`` gives the links' accelerations and the
        multipliers: the forces on the frame and each motor's torque (minus its driver's
        multiplier). Needs the formulation built with ``prescribed=True``.

        Raises
        ------
        SolverError
            If the system is singular to working precision at a state (a singular pose).
        """
        assert self.inputs_driven and not self.driven, "built with prescribed=True"
        count = state.count
        with np.errstate(all="ignore"):
            mo = self.mech.motion_at(state)
        q, qd = self.coordinates(mo, count)
        # (slider forces: tables of the crank's angle, a one-input linkage's alone)
        crank = np.broadcast_to(np.asarray(state.positions[0], dtype=float), (count,))
        gas = np.array([self._gas(float(th)) for th in crank])
        acc_in = np.array([np.broadcast_to(a, (count,)) for a in state.accelerations]).T
        return self._solve(q, qd, gas, acc_in, "a state of the motion")

    def free_dynamics(self, times: NDArray[np.float64], ys: NDArray[np.float64]
                      ) -> StateDynamics:
        """The solve at the states ``ys`` ``(count, 6n)`` of a free run at ``times``.

        No driver; all in one call of the compiled dynamics.

        Raises
        ------
        SolverError
            If the system is singular to working precision at a state.
        """
        k = 3 * self.n
        gas = np.array([self._gas(self.theta1_of(float(t), y)) for t, y in zip(times, ys,
                                                                              strict=True)])
        return self._solve(ys[:, :k], ys[:, k : 2 * k], gas,
                           np.zeros((ys.shape[0], self.input_count)), "an output state")

    def _solve(self, q: NDArray[np.float64], qd: NDArray[np.float64], gas: NDArray[np.float64],
               acc_in: NDArray[np.float64], where: str) -> StateDynamics:
        """The compiled dynamics at the states' columns, as their record."""
        count = q.shape[0]
        flat = self._fast_dynamics.columns(np.hstack([q, qd, gas, acc_in]).T)
        if not np.all(np.isfinite(flat)):
            raise SolverError(
                "the multibody equations of motion are singular to working precision at "
                f"{where} (a singular pose)")
        acc, lam, ground, normal, couple, frame = (flat[s] for s in self._slices)
        ground = ground.reshape(-1, count)
        reactions = Reactions(
            ground={p: ground[2 * i] + 1j * ground[2 * i + 1]
                    for i, p in enumerate(self._ground_names)},
            slider_normal={name: normal[i] for i, name in enumerate(self._slider_names)},
            slider_couple={name: couple[i] for i, name in enumerate(self._slider_names)},
            shaking_force=frame[0] + 1j * frame[1], shaking_moment=frame[2],
            torques=tuple(frame[3 + i] for i in range(self.input_count)),
            rocking_couple=np.zeros(count, complex))
        return StateDynamics(q=q, qd=qd, qdd=acc.T, multipliers=lam.T, reactions=reactions)

    def kinetic_energy(self, q: NDArray[np.float64], qd: NDArray[np.float64]
                       ) -> NDArray[np.float64]:
        """``T = q̇ᵀ·M(q)·q̇/2`` at states ``(count, 3n)``, J (compiled)."""
        import casadi as ca  # heavy: only where symbols are built
        count = q.shape[0]
        return np.asarray(self._kinetic.map(count).call(
            [ca.DM(q.T), ca.DM(qd.T)])[0].full()).ravel()

    def symbolic_rhs(self) -> ca.Function | None:
        """``(t, y) → ẏ`` as a CasADi function (none with slider forces: tables in Python)."""
        import casadi as ca  # heavy: only where symbols are built
        s = self.structure
        if self.has_slider_forces:
            return None
        k = 3 * self.n
        t = ca.MX.sym("t")
        y = ca.MX.sym("y", 2 * k + (1 if self.driven else 0))
        out = self._dynamics(y[:k], y[k : 2 * k], ca.MX.zeros(max(1, len(s.prisms))),
                             ca.MX.zeros(self.input_count))
        acc, frame = out[0], out[-1]
        dy = [y[k : 2 * k], acc]
        if self.driven:
            dy.append(frame[3] * self._motor_speed)
        return ca.Function("multibody_rhs", [t, y], [ca.vertcat(*dy)])

    def rhs(self, t: float, y: NDArray[np.float64]) -> NDArray[np.float64]:
        k = 3 * self.n
        acc, _, _, _, _, frame = self._call(t, y)
        dy = np.concatenate([y[k : 2 * k], acc])
        if self.driven:
            return np.append(dy, frame[3] * self._motor_speed)
        return dy

    def _constraint_values(self, t: float, q: NDArray[np.float64]
                           ) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
        """Residual and Jacobian of the constraints (the driver's at time ``t``)."""
        angles = np.full(self.input_count, self.crank_angle(t) if self.driven else 0.0)
        out = self._constraints(np.append(q, angles))
        rows = self.rows
        return out[:rows], out[rows:].reshape(3 * self.n, rows).T  # column-major

    def _velocity_rhs(self) -> NDArray[np.float64]:
        out = np.zeros(self.rows)
        if self.driven:
            out[-1] = self._motor_speed
        return out

    def project(self, t: float, y: NDArray[np.float64]) -> NDArray[np.float64]:
        """Least-norm Newton steps onto the constraints, then onto their derivative."""
        y = np.array(y, dtype=float)
        n = 3 * self.n
        q = y[:n]
        for _ in range(6):
            res, jac = self._constraint_values(t, q)
            if np.max(np.abs(res), initial=0.0) <= 1e-15 * self.scale:
                break
            q = q - least_norm(jac, res)
        else:
            _, jac = self._constraint_values(t, q)
        qd = y[n : 2 * n]
        qd = qd - least_norm(jac, jac @ qd - self._velocity_rhs())
        y[:n], y[n : 2 * n] = q, qd
        return y

    def _constraint_values_many(self, times: Sequence[float] | NDArray[np.float64],
                                q: NDArray[np.float64]
                                ) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
        """:meth:`_constraint_values` at many states in one call.

        Residuals ``(k, rows)`` and Jacobians ``(k, rows, n)``.
        """
        count, n = q.shape
        angles = np.broadcast_to(self.crank_angle(np.asarray(times, dtype=float)) if self.driven
                                 else 0.0, (self.input_count, count))
        out = self._constraints.columns(np.vstack([q.T, angles]))  # one column each
        rows = self.rows
        return out[:rows].T, out[rows:].T.reshape(count, n, rows).transpose(0, 2, 1)

    def project_many(self, times: Sequence[float] | NDArray[np.float64],
                     states: Sequence[NDArray[np.float64]]) -> list[NDArray[np.float64]]:
        """:meth:`project` at many states, the Newton steps of all of them taken together.

        The same steps, state by state, with the constraints of all the states evaluated in one
        call of the compiled function and the small linear systems stacked into one call of
        numpy's solver (whose cost per call, not per system, dominated the projection of a
        verification's output times).
        """
        ys = np.array(states, dtype=float)
        times = np.asarray(times, dtype=float)
        n = 3 * self.n
        q, qd = ys[:, :n], ys[:, n : 2 * n]  # views: the steps land in ys
        jacs = np.empty((len(ys), self.rows, n))
        todo = np.arange(len(ys))
        for _ in range(6):
            res, jacs[todo] = self._constraint_values_many(times[todo], q[todo])
            moving = np.max(np.abs(res), axis=1, initial=0.0) > 1e-15 * self.scale
            todo = todo[moving]
            if not todo.size:
                break
            q[todo] -= least_norm_many(jacs[todo], res[moving])
        else:
            jacs[todo] = self._constraint_values_many(times[todo], q[todo])[1]
        qd -= least_norm_many(jacs, np.einsum("kri,ki->kr", jacs, qd) - self._velocity_rhs())
        return list(ys)

    def constraint_residuals(self, times: Sequence[float] | NDArray[np.float64],
                             states: Sequence[NDArray[np.float64]]) -> tuple[float, float]:
        """:meth:`constraint_residual` at many states, the constraints in one call."""
        n = 3 * self.n
        ys = np.array(states, dtype=float).reshape(len(states), -1)
        res, jacs = self._constraint_values_many(times, ys[:, :n])
        vel = np.einsum("kri,ki->kr", jacs, ys[:, n : 2 * n]) - self._velocity_rhs()
        return float(np.max(np.abs(res), initial=0.0)), float(np.max(np.abs(vel), initial=0.0))

    def like_components(self) -> tuple[NDArray[np.intp], ...]:
        """The frames' positions, their angles, their velocities, their rates."""
        k = 3 * self.n
        lengths = np.sort(np.concatenate([np.arange(0, k, 3), np.arange(1, k, 3)]))
        angles = np.arange(2, k, 3)
        return lengths, angles, lengths + k, angles + k

    def constraint_residual(self, t: float, y: NDArray[np.float64]) -> tuple[float, float]:
        n = 3 * self.n
        q, qd = y[:n], y[n : 2 * n]
        res, jac = self._constraint_values(t, q)
        pos = float(np.max(np.abs(res), initial=0.0))
        vel = float(np.max(np.abs(jac @ qd - self._velocity_rhs()), initial=0.0))
        return pos, vel

    def extra_power(self, t: float, y: NDArray[np.float64]) -> float:
        """The slider forces' power: each force times the sliding velocity along its guide, W."""
        if not self.structure.prisms:
            return 0.0
        n = self.n
        q, qd = y[: 3 * n], y[3 * n : 6 * n]
        gas = self._gas(self.theta1_of(t, y))
        if not np.any(gas):
            return 0.0
        pose = self._pose(q, np)
        total = 0.0
        for j, c in enumerate(self.structure.prisms):
            d = pose.rotate(c.g, c.dg)
            at = pose.point(c.s, c.ps)
            rel = self._point_velocity(pose, qd, c.s, at) - self._point_velocity(pose, qd, c.g,
                                                                                 at)
            total += gas[j] * d.dot(rel)
        return float(total)

    @staticmethod
    def _point_velocity(pose: Pose, qd: NDArray[np.float64], k: int, at: V) -> V:
        if k == GROUND_INDEX:
            return V(0.0, 0.0)
        arm = at - pose.origin(k)
        return V(qd[3 * k], qd[3 * k + 1]) + arm.perp() * qd[3 * k + 2]

    def evaluate(self, t: float, y: NDArray[np.float64]) -> Evaluation:
        return self.evaluate_batch([t], [y]).at(0)

    def evaluate_batch(self, times: Sequence[float] | NDArray[np.float64],
                       states: Sequence[NDArray[np.float64]]) -> Evaluation:
        """The compiled dynamics mapped over the states (one call)."""
        n = 3 * self.n
        count = len(times)
        ys = np.array(states, dtype=float).reshape(count, -1)
        gas = np.array([self._gas(self.theta1_of(t, y)) for t, y in zip(times, ys, strict=True)])
        flat = self._fast_dynamics.columns(np.hstack([ys[:, : 2 * n], gas.reshape(count, -1),
                                                      np.zeros((count, self.input_count))]).T)
        if not np.all(np.isfinite(flat)):  # QR of a system singular to working precision

            raise SolverError(
                "the multibody equations of motion are singular to working precision at an "
                "output state (a singular pose, or masses and inertias of very different "
                "magnitudes)") from None
        acc, _, ground, normal, couple, frame = (flat[s] for s in self._slices)
        ground = ground.reshape(-1, count)
        return Evaluation(
            theta=ys[:, 2:n:3].T, omega=ys[:, n + 2 : 2 * n : 3].T, alpha=acc[2::3],
            ground={p: ground[2 * i] + 1j * ground[2 * i + 1]
                    for i, p in enumerate(self._ground_names)},
            driving_torque=frame[3],
            shaking_force=frame[0] + 1j * frame[1],
            shaking_moment=frame[2],
            slider_normal={name: normal[i] for i, name in enumerate(self._slider_names)},
            slider_couple={name: couple[i] for i, name in enumerate(self._slider_names)})

    def energy(self, theta: NDArray[np.float64], omega: NDArray[np.float64],
               alpha: NDArray[np.float64], slider: NDArray[np.float64] | None = None,
               states: Sequence[NDArray[np.float64]] | None = None
               ) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
        """Kinetic energy and the work of loads, gravity and springs since the first state, J.

        From the states themselves (``states``), all at once: ``T = q̇ᵀ·M·q̇/2`` (compiled);
        the loads' and gravity's work from the centres of mass' and the angles'
        displacements; the springs' from their potential energy.
        """
        assert states is not None  # the simulation passes them
        n = 3 * self.n
        ys = np.array(states, dtype=float).reshape(len(states), -1)
        return self.energies(ys[:, :n], ys[:, n : 2 * n])

    def energies(self, q: NDArray[np.float64], qd: NDArray[np.float64]
                 ) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
        """Kinetic energy and the configuration's work since the first state at ``(count, 3n)``.

        ``T = q̇ᵀ·M·q̇/2`` (compiled) and the loads', gravity's and springs' work from the
        centres of mass' and the angles' displacements (angles continuous over the states), J.
        """
        return (self.kinetic_energy(q, qd),
                self.configuration_work(self._pose(q.T, np), q.T[2::3]))
