"""Forward dynamics of any linkage in its crank angle: Lagrange's equation of one coordinate.

A linkage with one degree of freedom moves as its crank angle ``θ1`` does: every link's
coordinates ``q_k = (x_k, y_k, θ_k)`` (:mod:`balancer.linkage.structure`) are functions of it,
``q̇ = u(θ1)·θ̇1`` and ``q̈ = u·θ̈1 + b(θ1)·θ̇1²``, with ``u = dq/dθ1`` and ``b = d²q/dθ1²``
the velocities and accelerations of the linkage core's group-by-group solves
(:func:`balancer.linkage.kinematics.rates`) at ``θ̇1 = 1, θ̈1 = 0``. Projecting the links'
equations ``M·q̈ = Q + Φ_qᵀ·λ`` (:func:`~balancer.formulations.compiled.link_equations`) on
``u``, which the constraints' forces do no work along (``Φ_q·u = 0``), leaves (Nikravesh
1988, Sect. 11.4; the reduced form of the paper's Eq. 58 for any linkage)::

    m(θ1)·θ̈1 = uᵀ·(Q − M·b·θ̇1²) + τ,        m(θ1) = uᵀ·M·u

with ``τ`` the motor's torque (none in free motion; with the crank driven at constant speed,
``θ̈1 = 0`` and ``τ = −uᵀ·(Q − M·b·θ̇1²)``). The state is ``(θ1, θ̇1)``: no constraint drifts,
and nothing is projected.

The positions are the dyads' closed forms on the reference pose's branch; a group without one
(a Stephenson chain's four links driven from a binary link) takes two Newton steps from a
cubic spline through its continuation table (:mod:`balancer.linkage.numeric`), checked to
have converged at every step of the integration. As the crank angle is its coordinate it
cannot pass a dead point of the crank, where ``u`` is unbounded — the simulation stops there
and names the formulations that can. ``m``, the generalized force and the least assembly gap
are one compiled CasADi function of ``(θ1, θ̇1)`` and the slider forces, built once. Outputs
(reactions, shaking force and moment) come from the linkage core's inverse dynamics at the
integrated states, vectorised (numpy, an independent solve of the same positions).
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from typing import TYPE_CHECKING

import numpy as np
from numpy.typing import NDArray

from ..errors import AssemblyError, SolverError
from ..linkage import rotors
from ..linkage.assembly import assembly_gaps
from ..linkage.inputs import InputState
from ..linkage.kinematics import numeric_table, positions, rates
from ..linkage.loads import Reactions
from ..linkage.numeric import TABLE_STEPS
from ..linkage.symbols import CasadiOps
from ..linkage.vectors import Num, V
from ..mechanisms import geometry
from ..mechanisms.base import Mechanism
from ..mechanisms.formulation import DEAD_POINT_THRESHOLD, DrivenRates, Evaluation
from .compiled import Compiled, LinkageFormulation, link_equations

if TYPE_CHECKING:  # annotations only: CasADi is imported where symbols are built
    import casadi as ca

#: Largest residual of a numeric group's equations after its Newton steps, relative to the
#: linkage's length scale: a few hundred roundings.
CLOSURE_TOLERANCE = 1e-12


class CrankAngle(LinkageFormulation):
    """Lagrange's equation in the crank angle (any linkage)."""

    name = "crank-angle"
    minimal = True
    passes_dead_points = False
    passes_change_points = False

    def __init__(self, mechanism: Mechanism, *, gravity: tuple[float, float] = (0.0, 0.0),
                 speed: float | None = None) -> None:
        super().__init__(mechanism, gravity=gravity, speed=speed)
        #: Each link's angle at the start less its principal value there (whole turns).
        self.turns = np.zeros(self.n)
        self._build()

    def _build(self) -> None:
        import casadi as ca  # heavy: only where symbols are built
        s = self.structure
        theta1, omega1 = ca.SX.sym("theta1"), ca.SX.sym("omega1")
        gas = ca.SX.sym("gas", max(1, len(s.prisms)))
        numeric = [i for i, g in enumerate(s.groups) if g.kind == "numeric"]
        sizes = [3 * len(s.groups[i].links) for i in numeric]
        guess = ca.SX.sym("guess", sum(sizes))
        starts = np.cumsum([0, *sizes])
        guesses = {i: [guess[j] for j in range(a, b)]
                   for i, a, b in zip(numeric, starts[:-1], starts[1:], strict=True)}
        gaps: list[Num] = []
        residuals: list[Num] = []
        unit = InputState.symbolic([theta1], [1.0], [0.0])
        pose = positions(s, unit, CasadiOps, gaps=gaps, guesses=guesses, residuals=residuals)
        u_vel, u_rate, b_acc, b_accel = rates(s, pose, unit, CasadiOps)
        u = ca.vertcat(*[x for k in range(self.n)
                         for x in (u_vel[k].x, u_vel[k].y, u_rate[k])])
        b = ca.vertcat(*[x for k in range(self.n)
                         for x in (b_acc[k].x, b_acc[k].y, b_accel[k])])
        rate = [u_rate[k] * omega1 for k in range(self.n)]
        g = V(self.gravity.real, self.gravity.imag)
        mass, force = link_equations(s, self.links, pose, rate, g, gas,
                                     [r for _, r in self.mech.rotors])
        inertia = ca.dot(u, ca.mtimes(mass, u))  # m(θ1)
        general = ca.dot(u, force - ca.mtimes(mass, b) * omega1**2)
        # The slider forces' generalized forces per newton (their power is θ̇1 times these).
        per_gas = ca.jacobian(general, gas)[:, : len(s.prisms)]
        least = gaps[0] if gaps else ca.SX(1.0)  # the dyads' (numeric groups: _numeric_gap)
        for gap in gaps[1:]:
            least = ca.fmin(least, gap)
        closure = ca.mmax(ca.fabs(ca.vertcat(*residuals))) if residuals else ca.SX(0.0)
        core = ca.Function("crank_angle_core", [theta1, omega1, gas, guess],
                           [inertia, general, least, closure, per_gas.T])
        # The numeric groups' Newton starts from their continuation tables (cubic splines).
        th, w = ca.MX.sym("theta1"), ca.MX.sym("omega1")
        gs = ca.MX.sym("gas", max(1, len(s.prisms)))
        start = (ca.vertcat(*[self._table_guess(i, th) for i in numeric]) if numeric
                 else ca.MX(0, 1))
        out = core(th, w, gs, start)
        self._sym = ca.Function("crank_angle", [th, w, gs], [out[0], out[1]])
        self._equation = Compiled(ca.Function(
            "crank_angle_flat", [ca.vertcat(th, w, gs)], [ca.densify(ca.vertcat(*out))]))
        self._prisms = len(s.prisms)
        self._numeric = bool(numeric)

    def _table_guess(self, index: int, theta1: ca.MX) -> ca.MX:
        """A numeric group's coordinates at ``theta1`` (MX) from its continuation table.

        A cubic spline through the table's rows (:func:`balancer.linkage.numeric.table`),
        with the crank angle brought into the table's window as the numpy route does.
        """
        import casadi as ca  # heavy: only where symbols are built
        s = self.structure
        angles, tab = numeric_table(s, s.groups[index])
        start = angles[TABLE_STEPS]
        step = angles[1] - angles[0]
        turn = 2 * math.pi
        finite = np.all(np.isfinite(tab), axis=1)
        if self.mech.assembly_range().full:
            rows = (angles >= start - 4 * step) & (angles <= start + turn + 4 * step) & finite
            d = theta1 - start
            t = start + d - turn * ca.floor(d / turn)
        else:
            rows = finite
            d = theta1 - start + math.pi
            t = start + d - turn * ca.floor(d / turn) - math.pi
        spline = ca.interpolant(f"table_{index}", "bspline", [angles[rows].tolist()],
                                tab[rows].ravel().tolist())
        return spline(t)

    def _numeric_gap(self, theta1: float) -> float:
        """The numeric groups' least assembly gap at ``theta1``, or a lower bound of it.

        Where the crank turns fully and no group comes near a dead point over the
        revolution (the least gap over it, found with the assembly range, has a square root
        ten times :data:`~balancer.formulations.DEAD_POINT_THRESHOLD`), that least gap: a
        bound valid at every angle, at no cost, that keeps the simulation's dead-point event
        from firing exactly when it must not. Otherwise the gap itself (the numpy route's
        singular values).
        """
        self.mech.assembly_range()  # (the least gap over a revolution, found with it)
        least = self.structure.kinematic.get("least gap")
        if least is not None and least > (10 * DEAD_POINT_THRESHOLD) ** 2:
            return least

        return float(assembly_gaps(self.structure, np.array([theta1]))[0])

    def symbolic_rhs(self) -> ca.Function | None:
        """``(t, y) → ẏ`` as a CasADi function (none with slider forces: tables in Python)."""
        import casadi as ca  # heavy: only where symbols are built
        s = self.structure
        if self.has_slider_forces:
            return None
        t = ca.MX.sym("t")
        gas = ca.MX.zeros(max(1, len(s.prisms)))
        if self.driven:
            speed = self._motor_speed
            y = ca.MX.sym("y", 3)  # θ1 integrated at the constant speed
            _, general = self._sym(y[0], speed, gas)
            dy = ca.vertcat(speed, 0, -general * speed)
        else:
            y = ca.MX.sym("y", 2)
            inertia, general = self._sym(y[0], y[1], gas)
            dy = ca.vertcat(y[1], general / inertia)
        return ca.Function("crank_angle_rhs", [t, y], [dy])

    def _at(self, theta1: float, omega1: float) -> NDArray[np.float64]:
        """``m``, the generalized force without the motor's, the least gap, per-newton gas."""
        return self._equation(np.concatenate([[theta1, omega1], self._gas(theta1)]))

    # -- the formulation's interface ----------------------------------------------------------

    def initial_state(self, theta1: float, omega1: float) -> NDArray[np.float64]:
        self.theta1_start = float(theta1)
        if self.driven:
            omega1 = self._motor_speed
        continued = geometry.continued_angles(self.mech, theta1)
        with np.errstate(all="ignore"):
            principal = self.mech.motion(theta1).pose.angles
        raw = np.array([float(np.ravel(x)[0]) for x in principal])
        if not np.all(np.isfinite(raw)):
            raise AssemblyError("the linkage cannot be assembled at the initial crank angle",
                                key="simulation.theta1", value=theta1)
        self.turns = continued - raw
        self.turns[self.structure.input] = 0.0
        y = np.array([theta1, omega1])
        return np.append(y, 0.0) if self.driven else y

    def theta1_of(self, t: float, y: NDArray[np.float64]) -> float:
        return self.crank_angle(t) if self.driven else float(y[0])

    def rhs(self, t: float, y: NDArray[np.float64]) -> NDArray[np.float64]:
        if self.driven:  # the prescribed angle (the state's, integrated, is the same)
            speed = self._motor_speed
            general = self._at(self.crank_angle(t), speed)[1]
            return np.array([speed, 0.0, -general * speed])  # the motor's power: τ = −F
        out = self._at(y[0], y[1])
        return np.array([y[1], out[1] / out[0]])

    def driven_rates(self, times: NDArray[np.float64]) -> DrivenRates | None:
        """:meth:`rhs`, :meth:`extra_power` and :meth:`transmission` at many times, driven.

        The compiled equation mapped over the prescribed crank angles
        (:meth:`~balancer.formulations.compiled.Compiled.columns`): the same numbers as the
        integrator's single calls of it (which, like these, do not check the numeric groups'
        closure: only :meth:`transmission_of_crank`, at the events, does).
        """
        if not self.driven:
            return None
        speed = self._motor_speed
        theta1 = self.crank_angle(np.asarray(times, dtype=float))
        gas = np.array([self._gas(x) for x in theta1]).reshape(theta1.size, -1)
        out = self._equation.columns(np.vstack([theta1, np.full(theta1.size, speed), gas.T]))
        general, least = out[1], out[2]
        if self._numeric:
            least = np.minimum(least, [self._numeric_gap(float(x)) for x in theta1])
        rates = np.column_stack([np.full(theta1.size, speed), np.zeros(theta1.size),
                                 -general * speed])  # the motor's power: τ = −F
        extra = speed * np.einsum("ij,ji->i", gas, out[4 : 4 + gas.shape[1]]) if (
            self._prisms) else np.zeros(theta1.size)
        return DrivenRates(rates=rates, extra_power=extra,
                           transmission=np.sqrt(np.maximum(least, 0.0)))

    def transmission(self, t: float, y: NDArray[np.float64]) -> float:
        return self.transmission_of_crank(self.theta1_of(t, y))

    def transmission_of_crank(self, theta1: float) -> float:
        """The square root of the groups' least assembly gap (0 at a dead point).

        Also where a numeric group's Newton steps (a fixed number, from its table) are
        checked: their residual must be at rounding.
        """
        out = self._at(theta1, 0.0)
        if self._numeric and not out[3] <= CLOSURE_TOLERANCE * self.structure.length_scale():
            raise SolverError(
                f"the positions of the linkage's numerically solved group did not converge at "
                f"θ1 = {theta1:.9g} rad (residual {out[3]:.3g} m); choose multibody")
        gap = float(out[2])
        if self._numeric:
            gap = min(gap, self._numeric_gap(theta1))
        return math.sqrt(max(gap, 0.0))

    def extra_power(self, t: float, y: NDArray[np.float64]) -> float:
        """The slider forces' power, W: ``θ̇1`` times their generalized forces."""
        if not self._prisms:
            return 0.0
        theta1 = self.theta1_of(t, y)
        gas = self._gas(theta1)
        if not np.any(gas):
            return 0.0
        omega1 = self._motor_speed if self.driven else float(y[1])
        per = self._at(theta1, 0.0)[4:]
        return float(omega1 * np.dot(gas, per))

    @staticmethod
    def _crank_states(states: Sequence[NDArray[np.float64]]) -> NDArray[np.float64]:
        """Crank angle and rate at states, ``(count, 2)`` (the driven state's θ1 integrated)."""
        return np.array(states, dtype=float).reshape(len(states), -1)[:, :2]

    def _crank_accelerations(self, states: Sequence[NDArray[np.float64]]
                             ) -> NDArray[np.float64]:
        """The crank's angular acceleration at states, rad/s² (zero when driven)."""
        if self.driven:
            return np.zeros(len(states))
        return np.array([self.rhs(0.0, y)[1] for y in self._crank_states(states)])

    def evaluate(self, t: float, y: NDArray[np.float64]) -> Evaluation:
        return self.evaluate_batch([t], [y]).at(0)

    def evaluate_batch(self, times: Sequence[float] | NDArray[np.float64],
                       states: Sequence[NDArray[np.float64]]) -> Evaluation:
        """The linkage core's motion and inverse dynamics at the states, vectorised."""
        theta1, omega1 = self._crank_states(states).T
        alpha1 = self._crank_accelerations(states)
        with np.errstate(all="ignore"):
            mo = self.mech.motion(theta1, omega1, alpha1)
            forces = self.mech.inverse_dynamics(mo, gravity=(self.gravity.real,
                                                             self.gravity.imag))
        count = theta1.size
        theta = np.array([np.broadcast_to(np.asarray(mo.pose.angles[k], float), (count,))
                          + self.turns[k] for k in range(self.n)])
        theta[self.structure.input] = theta1
        loads = Reactions.of(forces)
        torque = loads.driving_torque if self.driven else np.zeros(count)
        shaking_moment = loads.shaking_moment
        if not self.driven:  # the free motion's motor exerts nothing: its rounding left out
            shaking_moment = shaking_moment + loads.driving_torque
        return Evaluation(
            theta=theta,
            omega=np.array([np.broadcast_to(np.asarray(w, float), (count,)) for w in mo.rate]),
            alpha=np.array([np.broadcast_to(np.asarray(a, float), (count,)) for a in mo.accel]),
            ground=loads.ground,
            driving_torque=torque,
            shaking_force=loads.shaking_force,
            shaking_moment=shaking_moment,
            slider_normal=loads.slider_normal,
            slider_couple=loads.slider_couple)

    def energy(self, theta: NDArray[np.float64], omega: NDArray[np.float64],
               alpha: NDArray[np.float64], slider: NDArray[np.float64] | None = None,
               states: Sequence[NDArray[np.float64]] | None = None
               ) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
        """Kinetic energy and the work of loads, gravity and springs since the first state, J.

        The kinetic energy from each link's own motion at the output states (the linkage
        core's velocities, ``Σ m·|v_G|²/2 + J_G·ω²/2`` with the counter-rotors' ``J_c·ω²/2``),
        a route apart from the compiled ``m(θ1)·θ̇1²/2`` the motion was integrated with.
        """
        assert states is not None  # the simulation passes them
        theta1, omega1 = self._crank_states(states).T
        with np.errstate(all="ignore"):
            mo = self.mech.motion(theta1, omega1, 0.0)
        kin = np.zeros(theta1.size)
        for k, link in enumerate(self.links):
            v = mo.point_velocity(k, V(link.e, link.f))
            w = np.asarray(mo.rate[k], float)
            kin += (0.5 * link.mass * v.norm2() + 0.5 * link.inertia * w**2
                    + rotors.energy(link.counter_rotor, w))
        return kin, self.configuration_work(mo.pose, theta)


__all__ = ["CrankAngle"]
