"""The frame's loads along a fixed path, as functions of how fast it is run.

On a path ``q(τ)`` of the inputs, run at any time law ``τ(t)``, the inputs' rates are
``q̇ = q'·τ̇`` and accelerations ``q̈ = q''·τ̇² + q'·τ̈``. Every frame load — the shaking force,
the moment, the rocking couple, each input's torque — is linear in the accelerations and
quadratic in the rates (the inverse dynamics of rigid links, with forces that depend on the
pose alone: gravity, springs, applied loads), so at each argument ``τ``

``L = A(τ)·τ̈ + B(τ)·τ̇² + C(τ)``:

``C`` the loads at rest (``q̇ = q̈ = 0``), ``A + C`` at ``q̈ = q'`` from rest, ``B + C`` at
``q̇ = q'``, ``q̈ = q''`` — three inverse dynamics of the one core, at once. (The time-optimal
path-tracking literature's form: Bobrow, Dubowsky & Gibson 1985; Verscheure et al. 2009.) A
fourth state, ``q̇ = 2q'``, ``q̈ = 4q''`` (``4B + C``), checks the form where it is used.
"""

from __future__ import annotations

from dataclasses import dataclass, replace
from typing import Any

import numpy as np
from numpy.typing import NDArray

from ..errors import SolverError
from ..linkage import trajectory
from ..linkage.inputs import InputState
from ..linkage.loads import Reactions
from ..mechanisms import Mechanism, geometry
from ..model.motions import MotionSpec
from ..motion_analysis import frame_reactions

#: The form ``A·τ̈ + B·τ̇² + C`` must give the fourth state's loads to this share of their scale.
FORM_TOLERANCE = 1e-9


@dataclass(frozen=True, eq=False)
class PathLoads:
    """The frame loads along a path at arguments ``tau``, as ``A·τ̈ + B·τ̇² + C``.

    Attributes
    ----------
    tau
        The path's arguments, s, increasing, ``(K,)``.
    names
        Each load's column name (``shaking_force_x``, ``shaking_force_y``,
        ``shaking_moment``, ``rocking_couple_x``, ``rocking_couple_y``, ``torque_<input>``).
    inertial, centripetal, static
        ``A`` (per unit ``τ̈``), ``B`` (per unit ``τ̇²``) and ``C`` of each load at each
        argument, ``(len(names), K)``, in the load's unit (N, N·m; a slide's force N).
    slope, curvature
        Each input's ``dq/dτ`` and ``d²q/dτ²`` at each argument, ``(inputs, K)``.
    first_moment
        The moving masses' total first moment about the origin at each argument, complex,
        kg·m (the total mass times its centre).
    mass
        The moving masses' total, kg.
    left
        The same at each argument from the path's piece before it (where the pieces join, at
        a waypoint, the path's curvature jumps: ``B`` and ``q''`` with it), or ``None`` where
        no argument is a waypoint inside the path.
    """

    tau: NDArray[np.float64]
    names: tuple[str, ...]
    inertial: NDArray[np.float64]
    centripetal: NDArray[np.float64]
    static: NDArray[np.float64]
    slope: NDArray[np.float64]
    curvature: NDArray[np.float64]
    first_moment: NDArray[np.complex128]
    mass: float
    left: PathLoads | None = None

    @property
    def arriving(self) -> PathLoads:
        """The coefficients an interval ending at each argument sees (:attr:`left`'s)."""
        return self if self.left is None else self.left

    def at(self, rate2: NDArray[np.float64], acceleration: NDArray[np.float64]
           ) -> NDArray[np.float64]:
        """The loads at each argument where ``τ̇² = rate2`` and ``τ̈ = acceleration``."""
        return self.inertial * acceleration + self.centripetal * rate2 + self.static

    def index(self, name: str) -> int:
        """A load's row."""
        return self.names.index(name)


def load_rows(inputs: tuple[str, ...], reactions: Reactions) -> tuple[tuple[str, ...],
                                                                      NDArray[np.float64]]:
    """The loads' names and rows ``(loads, N)`` of a record (:class:`PathLoads`' order)."""
    r = reactions
    names = ("shaking_force_x", "shaking_force_y", "shaking_moment", "rocking_couple_x",
             "rocking_couple_y", *(f"torque_{name}" for name in inputs))
    rows = [r.shaking_force.real, r.shaking_force.imag, r.shaking_moment,
            r.rocking_couple.real, r.rocking_couple.imag, *r.torques]
    return names, np.array([np.asarray(x, dtype=float) for x in rows])


def path_loads(mech: Mechanism, motion: MotionSpec, tau: NDArray[np.float64],
               gravity: tuple[float, float] = (0.0, 0.0)) -> PathLoads:
    """The loads along ``motion``'s path at arguments ``tau`` (module docstring).

    With their left limits where an argument is a waypoint inside the path (:attr:`PathLoads.
    left`).

    Raises
    ------
    AssemblyError
        If the path leaves the workspace.
    SolverError
        If the loads are not of the form (a force that depends on the rates other than
        quadratically).
    """
    tau = np.asarray(tau, dtype=float)
    after = _path_loads(mech, motion, tau, gravity, "right")
    joins = np.isin(tau, np.asarray(motion.times[1:-1], dtype=float))
    if not joins.any():
        return after
    before = _path_loads(mech, motion, tau[joins], gravity, "left")

    def spliced(name: str) -> NDArray[Any]:
        whole = np.array(getattr(after, name), copy=True)
        whole[..., joins] = getattr(before, name)
        return whole
    left = replace(after, inertial=spliced("inertial"), centripetal=spliced("centripetal"),
                   static=spliced("static"), slope=spliced("slope"),
                   curvature=spliced("curvature"))
    return replace(after, left=left)


def _path_loads(mech: Mechanism, motion: MotionSpec, tau: NDArray[np.float64],
                gravity: tuple[float, float], side: trajectory.Side) -> PathLoads:
    """:func:`path_loads` at arguments ``tau``, each from the path's piece on ``side``."""
    along = trajectory.path_derivatives(mech.structure, motion, tau, side)
    q, d1, d2 = (np.array([np.asarray(x, dtype=float) for x in part])
                 for part in (along.positions, along.rates, along.accelerations))
    zero = np.zeros_like(q)
    states = InputState.join([InputState.of(list(q), list(zero), list(zero)),
                              InputState.of(list(q), list(zero), list(d1)),
                              InputState.of(list(q), list(d1), list(d2)),
                              InputState.of(list(q), list(2 * d1), list(4 * d2))])
    mo = mech.motion_at(states)
    names, rows = load_rows(mech.linkage.inputs, frame_reactions(mech, mo, gravity=gravity))
    count = tau.size
    rest, pushed, moving, fast = (rows[:, i * count:(i + 1) * count] for i in range(4))
    inertial, centripetal = pushed - rest, moving - rest
    scale = np.max(np.abs(rows), axis=1, keepdims=True) + np.finfo(float).tiny
    if not np.all(np.abs(4 * centripetal + rest - fast) <= FORM_TOLERANCE * scale):
        raise SolverError("the loads are not quadratic in the inputs' rates (a force that "
                          "depends on the speed otherwise): a time law cannot be planned")
    # (the first moments at the states at rest: the joined motion's first ones)
    first = np.sum(np.broadcast_arrays(*geometry.first_moments(mech, mo)), axis=0)[:count]
    mass = mech.linkage.total_mass + sum(e.mass for _, r in mech.rotors for e in r.eccentrics)
    return PathLoads(tau=tau, names=names, inertial=inertial, centripetal=centripetal,
                     static=rest, slope=d1, curvature=d2,
                     first_moment=np.broadcast_to(np.asarray(first, np.complex128),
                                                  tau.shape).copy(),
                     mass=float(mass))
