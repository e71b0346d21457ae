"""Kinematics of a general linkage, vectorised over arrays of input states.

An input state (:class:`~.inputs.InputState`) gives each input's angle, rate and acceleration;
a one-input linkage's is its crank's ``(θ1, ω1, α1)``.

Positions, group by group (:mod:`.structure`): each input from its driver, dyads in closed form,
other groups by Newton's method from a continuation table; each on the branch of the reference
pose. Velocities and accelerations, group by group, from the constraints' time derivatives:
``Φ_S·q̇_S = −Φ_K·q̇_K`` and ``Φ_S·q̈_S = γ − Φ_K·q̈_K`` (``S`` the group's coordinates, ``K``
those of the links found before), one small linear solve per group and crank angle.

Closed forms of the dyads (links ``a`` and ``b``; ``P1``, ``P3`` the known ends):

RRR
    ``P2`` on the circles of radius ``|p̄a2 − p̄a1|`` about ``P1`` and ``|p̄b2 − p̄b3|`` about
    ``P3``: ``P2 = P1 + D·u/d + σ·h·D⊥/d``, ``D = P3 − P1``, ``u = (ra² − rb² + d²)/(2d)``,
    ``h = √(ra² − u²)``; ``σ = sign(D × (P2 − P1))`` at the reference pose.
RRP
    ``b`` keeps its angle to the guide (known); ``P2`` is on a known line ``Q + t·d̄`` and on
    the circle about ``P1``: ``t = (P1 − Q)·d̄ + σ·√(ra² − (d̄ × (P1 − Q))²)``.
RPR
    The guide's line through a pivot must pass the slider's point, offset ``c0`` from it:
    ``|ΔP|·sin(ψ − φ) = −c0`` for the line's direction ``φ`` (``ΔP`` from the guide's pivot to
    the slider's, at angle ``ψ``): ``φ = ψ − atan2(−c0/|ΔP|, σ·√(1 − c0²/|ΔP|²))``.

Where a group cannot be assembled the positions are NaN (see :func:`assembly_gap`).
"""

from __future__ import annotations

import threading
from collections import OrderedDict
from dataclasses import dataclass, field
from typing import Any

import numpy as np
from numpy.typing import NDArray

from . import numeric
from .constraints import (
    GROUND_INDEX,
    Group,
    Pose,
    group_jacobian,
)
from .dyads import Dyads, Frame, known_point
from .inputs import InputState
from .structure import Structure
from .vectors import NUMPY, Num, OpsLike, V, _minus


def _place(pose: Pose, k: int, frame: Frame | Num, origin_or_pivot: V, local: V | None,
           ops: OpsLike) -> None:
    """Set link ``k``'s frame from its angle and a point to place it by.

    ``frame`` is the angle or ``(angle, cos, sin)`` (``None`` cosine and sine computed from the
    angle). The point is its origin (``local`` None) or the global position of its local point
    ``local``.
    """
    theta, c, s = frame if isinstance(frame, tuple) else (frame, None, None)
    if c is None:
        c, s = ops.cos(theta), ops.sin(theta)
    pose.angles[k], pose.cos[k], pose.sin[k] = theta, c, s
    if local is None:
        pose.origins[k] = origin_or_pivot
    else:
        pose.origins[k] = origin_or_pivot - local.rotated(c, s)


def positions(structure: Structure, state: InputState, ops: OpsLike = NUMPY,
              gaps: list[Num] | None = None, guesses: dict[int, list[Num]] | None = None,
              residuals: list[Num] | None = None, steps: list[Num] | None = None) -> Pose:
    """Every link's frame at the inputs' positions (rad), on the reference pose's branch.

    Parameters
    ----------
    structure
        The linkage's structure.
    state
        The inputs' states (only their positions are read: arrays, or for CasADi symbols).
    ops
        Elementary functions (numpy by default).
    gaps
        If a list, receives each group's assembly gap (≥ 0 where it assembles; a numeric
        group's: :func:`balancer.linkage.numeric.assembly_gap`, with numpy only).
    guesses, residuals
        With symbols: each numeric group's starting coordinates for Newton's method, keyed
        by its place in ``structure.groups``; ``residuals`` (a list) receives each such
        group's equations at the result (:func:`~.numeric.solve_group_symbolic`).
    steps
        With symbols and a list: each numeric group takes one Newton step from its guess,
        its last cosines and sines by the step's Taylor polynomial, and the list receives its
        angles' changes (:func:`~.numeric.solve_group_symbolic`).

    Returns
    -------
    Pose
        Origins (m) and angles (rad; ``atan2`` values, the input's as given).
    """
    n = structure.size
    angles = (tuple(np.asarray(x, dtype=float) for x in state.positions) if ops is NUMPY
              else state.positions)
    pose = Pose([V(0.0, 0.0)] * n, [0.0] * n, [1.0] * n, [0.0] * n)
    for index, g in enumerate(structure.groups):
        if g.kind == "input":
            pivot, local = known_point(pose, g.pivot, g.links[0])
            _place(pose, g.links[0], angles[g.driver.index], pivot, local, ops)
            continue
        if g.kind == "geared":  # about its pivot, at its driver's angle times the ratio
            pivot, local = known_point(pose, g.pivot, g.links[0])
            _place(pose, g.links[0], g.mesh.driven_angle(pose.angles[g.mesh.a]), pivot, local,
                   ops)
            continue
        if g.kind == "slide":  # on its ground guide, at its input's place along it
            prism = g.slide
            along = prism.pg + prism.dg * angles[g.driver.index]
            _place(pose, g.links[0], prism.delta + 0.0 * angles[g.driver.index], along,
                   prism.ps, ops)
            continue
        if g.kind == "numeric":
            if ops is NUMPY:
                numeric.solve_group(structure, g, pose, state, positions, gaps)
            else:
                if guesses is None or index not in guesses:
                    raise ValueError("a numeric group on symbols needs a starting guess")
                found = (numeric.solve_group_symbolic(g, pose, guesses[index], ops)
                         if steps is None else
                         numeric.solve_group_symbolic(g, pose, guesses[index], ops, 1, steps))
                if residuals is not None:
                    residuals.extend(found)
            continue
        solver = {"RRR": Dyads.rrr, "RRP": Dyads.rrp, "RPR": Dyads.rpr}[g.kind]
        (ta, pa, la), (tb, pb, lb), gap = solver(ops, pose, g, g.sign)
        _place(pose, g.links[0], ta, pa, la, ops)
        _place(pose, g.links[1], tb, pb, lb, ops)
        if gaps is not None:
            gaps.append(gap)
    return pose


def numeric_table(structure: Structure, g: Group
                  ) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
    """Numeric group ``g``'s continuation table (:func:`balancer.linkage.numeric.table`)."""
    return numeric.table(structure, g, positions)


def numeric_start(structure: Structure, g: Group, theta1: NDArray[np.float64]
                  ) -> tuple[NDArray[np.float64], NDArray[np.bool_]]:
    """Where Newton's method starts for numeric group ``g`` of a one-input linkage.

    At crank angles ``theta1`` (:func:`~.numeric.start`).
    """
    return numeric.start(structure, g, theta1, positions)


@dataclass(frozen=True, eq=False)
class Motion:
    """Frames of every moving link and their rates at arrays of input states.

    Attributes
    ----------
    state
        The inputs' angles (rad), rates (rad/s) and accelerations (rad/s²), each of shape
        ``(N,)`` (or CasADi symbols, in the program of :mod:`.program`).
    pose
        Origins (m) and angles (rad) of the links' frames.
    velocity, rate
        Each link's origin velocity (m/s) and angular velocity (rad/s).
    acceleration, accel
        Each link's origin acceleration (m/s²) and angular acceleration (rad/s²).
    closed_form
        The motion as a mechanism's closed form computed it (the four-bar's), or ``None``.
    """

    state: InputState
    pose: Pose
    velocity: tuple[V, ...]
    rate: tuple[Num, ...]
    acceleration: tuple[V, ...]
    accel: tuple[Num, ...]
    #: The same motion in a mechanism's own closed form, when it made it (reused by its routes).
    closed_form: Any = field(default=None, repr=False, compare=False)

    @property
    def theta1(self) -> Num:
        """A one-input linkage's crank angle, rad (``ValueError`` for several inputs)."""
        return self.state.sole()[0]

    @property
    def omega1(self) -> Num:
        """A one-input linkage's crank rate, rad/s."""
        return self.state.sole()[1]

    @property
    def alpha1(self) -> Num:
        """A one-input linkage's crank acceleration, rad/s²."""
        return self.state.sole()[2]

    @property
    def count(self) -> int:
        """The number of states ``N``."""
        return int(np.size(self.state.positions[0]))

    def point(self, k: int, local: V) -> V:
        """Position of a point of link ``k`` (``local`` in its frame), m."""
        return self.pose.point(k, local)

    def point_velocity(self, k: int, local: V) -> V:
        """Velocity of a point of link ``k``, m/s."""
        if k == GROUND_INDEX:
            zero = 0.0 * self.state.positions[0]
            return V(zero, zero)
        return self.velocity[k] + self.pose.rotate(k, local).perp() * self.rate[k]

    def point_acceleration(self, k: int, local: V) -> V:
        """Acceleration of a point of link ``k``, m/s²."""
        if k == GROUND_INDEX:
            zero = 0.0 * self.state.positions[0]
            return V(zero, zero)
        r = self.pose.rotate(k, local)
        return self.acceleration[k] + r.perp() * self.accel[k] - r * (self.rate[k] ** 2)


def rates(structure: Structure, pose: Pose, state: InputState, ops: OpsLike = NUMPY, *,
          accelerations: bool = True) -> tuple[list[V], list[Num], list[V], list[Num]]:
    """Velocities and accelerations of every link's frame at ``pose`` (module docstring).

    ``state`` gives the inputs' rates and accelerations (its positions are ``pose``'s).
    Returns ``(velocity, rate, acceleration, accel)``, each a list over the links; with
    ``accelerations`` false the last two are zeros (the velocities alone are solved, the same
    figures).
    """
    n = structure.size
    zero = 0.0 * state.positions[0]
    vel: list[V] = [V(zero, zero)] * n
    rate: list[Num] = [zero] * n
    acc: list[V] = [V(zero, zero)] * n
    accel: list[Num] = [zero] * n
    for g in structure.groups:
        rows, known = group_jacobian(g, pose)
        prescribed = [x for c in g.constraints for x in c.prescribed_rates(state)]
        rhs_v = []
        for r, row_known in enumerate(known):
            v_term: Num = 0.0
            for link, coeffs in row_known:
                v_term = v_term + coeffs[0] * vel[link].x + coeffs[1] * vel[link].y \
                    + coeffs[2] * rate[link]
            # a driver θ_input − θ_i(t) = 0: its rates are the input's
            rhs_v.append(_minus(prescribed[r], v_term))
        # velocities first: γ of the group's own rows needs the group's velocities
        factor = ops.factor(rows)
        sol_v = factor.solve([[x] for x in rhs_v])
        for i, link in enumerate(g.links):
            vel[link] = V(zero + sol_v[3 * i][0], zero + sol_v[3 * i + 1][0])
            rate[link] = zero + sol_v[3 * i + 2][0]
        if not accelerations:
            continue
        gammas = [x for c in g.constraints for x in c.gamma(pose, vel, rate, state)]
        rhs_a = []
        for r, row_known in enumerate(known):
            a_term: Num = 0.0
            for link, coeffs in row_known:
                a_term = a_term + coeffs[0] * acc[link].x + coeffs[1] * acc[link].y \
                    + coeffs[2] * accel[link]
            rhs_a.append(gammas[r] - a_term)
        sol_a = factor.solve([[x] for x in rhs_a])
        for i, link in enumerate(g.links):
            acc[link] = V(zero + sol_a[3 * i][0], zero + sol_a[3 * i + 1][0])
            accel[link] = zero + sol_a[3 * i + 2][0]
    return vel, rate, acc, accel


#: Motions at up to this many states are kept with the geometry (a cycle's samples: the
#: cycle analysis, the regressors and the force-balance conditions of a design and of its
#: redesign ask for the same motion), the last :data:`MOTIONS_KEPT` of them.
MOTION_CACHE_STATES = 4096
MOTIONS_KEPT = 4
_MOTIONS_LOCK = threading.Lock()


def motion(structure: Structure, state: InputState) -> Motion:
    """Positions, velocities and accelerations at the inputs' states.

    The motion depends on the geometry alone: one at a few states is kept with it
    (:attr:`Structure.kinematic`) and given again for the same states. (Its arrays are
    shared: not to be written into.)

    Parameters
    ----------
    structure
        The linkage's structure.
    state
        Each input's angle (rad), rate (rad/s) and acceleration (rad/s²), numeric, one per
        input of ``structure``.
    """
    if state.size != len(structure.drivers):
        raise ValueError(f"the state has {state.size} inputs; the linkage has "
                         f"{len(structure.drivers)}")
    key = None
    if state.count <= MOTION_CACHE_STATES:  # a cycle's samples: the same ones, asked again
        key = state.key()
        with _MOTIONS_LOCK:
            motions = structure.kinematic.setdefault("motions", OrderedDict())
            known = motions.get(key)
        if known is not None:
            return known
    pose = positions(structure, state)
    vel, rate, acc, accel = rates(structure, pose, state)
    mo = Motion(state=state, pose=pose, velocity=tuple(vel), rate=tuple(rate),
                acceleration=tuple(acc), accel=tuple(accel))
    if key is not None:
        with _MOTIONS_LOCK:  # (threads may share a geometry)
            motions[key] = mo
            while len(motions) > MOTIONS_KEPT:
                motions.popitem(last=False)
    return mo
