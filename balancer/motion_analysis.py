"""What a linkage does to its frame along a motion (DESIGN.md, "Mechanisms with several inputs").

A motion of the spec (:class:`balancer.model.motions.MotionSpec`) gives the inputs' states at
its sampled times (:func:`balancer.linkage.trajectory.input_state`: its waypoints, its time
law, inverse kinematics for a point's path); the mechanism's inverse dynamics gives at each
the loads on the frame — the shaking force, the moment about the origin (with every motor's
reaction), the rocking couple, each input's torque and the force at every ground point — as
the one record of frame loads (:class:`balancer.linkage.loads.Reactions`). The cycle analysis
(:mod:`balancer.cycle`) is its counterpart for a crank turning at constant speed.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass, replace
from functools import cached_property
from typing import Any

import numpy as np
from numpy.typing import NDArray

from .columns import Columns, frame_force_columns
from .cycle import CycleSummary, Figure
from .force_balance import RESIDUAL_FLOOR, force_balance_residual
from .linkage import trajectory
from .linkage.inputs import InputState
from .linkage.kinematics import Motion
from .linkage.loads import Reactions
from .mechanisms import Mechanism, geometry, mechanism_of
from .model import MechanismModel
from .model.motions import MotionSpec, Workspace


@dataclass(frozen=True)
class Load:
    """One frame load's RMS and largest magnitude along a motion, in its unit."""

    rms: float
    max: float

    @classmethod
    def of(cls, values: NDArray[np.float64] | NDArray[np.complex128]) -> Load:
        """Of samples (a complex load's magnitude), the RMS over the samples."""
        size = np.abs(np.asarray(values))
        return cls(rms=float(np.sqrt(np.mean(size**2))), max=float(np.max(size)))


@dataclass(frozen=True, eq=False)
class MotionAnalysis:
    """The frame's loads along one motion.

    Attributes
    ----------
    mechanism
        The analysed mechanism.
    motion
        The motion.
    inputs
        The inputs' names, in the mechanism's order.
    t
        The sampled times, s.
    state
        The inputs' angles (rad, absolute: the driven links' frame angles), rates (rad/s) and
        accelerations (rad/s²) at those times.
    changes
        Each input's change from the reference pose, rad (what the spec's paths and
        workspace give).
    reactions
        The loads on the frame at those times.
    centre_of_mass
        The moving links' total centre of mass at those times, complex, m.
    gravity
        ``(gx, gy)``, m/s², that the loads include.
    """

    mechanism: Mechanism
    motion: MotionSpec
    inputs: tuple[str, ...]
    t: NDArray[np.float64]
    state: InputState
    changes: tuple[NDArray[np.float64], ...]
    reactions: Reactions
    centre_of_mass: NDArray[np.complex128]
    gravity: tuple[float, float] = (0.0, 0.0)

    @property
    def name(self) -> str:
        """The motion's name."""
        return self.motion.name

    def columns(self) -> tuple[list[str], Columns]:
        """The columns of ``analyze --csv`` along a motion (:func:`motion_columns`)."""
        return motion_columns(self.mechanism, self.t, self.changes, self.reactions)

    @property
    def centre_of_mass_excursion(self) -> float:
        """The largest distance of the total centre of mass from its mean place, m."""
        return excursion(self.centre_of_mass)

    def natural_scales(self) -> dict[str, float]:
        """The natural scale of a force (N) and of a moment (N·m) along the motion.

        As a cycle's (:func:`balancer.cycle.natural_scales`): the largest force on the frame
        at one ground point or guide, times the mechanism's size for a moment — or, where they
        are larger, the inputs' torques over the size: a robot whose motors share one pivot has
        one ground point, whose force is the shaking force itself (a balanced one's is
        rounding), and its motors' torques are made of the inertial forces that it sums.
        """
        size = self.mechanism.structure.length_scale()
        torques = max((float(np.nanmax(np.abs(t), initial=0.0)) for t in self.reactions.torques),
                      default=0.0)
        force = max(self.reactions.largest_force(), torques / size)
        return {"N": force, "N·m": force * size}

    def loads(self) -> dict[str, Load]:
        """RMS and maximum of each frame load.

        The shaking force, moment, rocking couple and each input's torque (``torque_<input>``).
        """
        return frame_loads(self.inputs, self.reactions)


#: What a report calls each frame load along a motion, and its unit (the inputs' own:
#: :func:`load_words`).
LOAD_WORDS = {"shaking_force": ("shaking force", "N"),
              "shaking_moment": ("shaking moment", "N·m"),
              "rocking_couple": ("rocking couple", "N·m")}


def load_words(mech: Mechanism, key: str) -> tuple[str, str]:
    """A frame load's words and unit.

    ``torque_<input>`` is a motor's torque on its link (N·m), or an actuator's force on its
    slider along a slide (N).
    """
    if not key.startswith("torque_"):
        return LOAD_WORDS[key]
    name = key[len("torque_"):]
    driver = mech.structure.drivers[mech.linkage.inputs.index(name)]
    if driver.load_unit == "N":
        return f"force on {name}", "N"
    return f"torque on {name}", "N·m"


def frame_loads(inputs: Sequence[str], reactions: Reactions) -> dict[str, Load]:
    """RMS and maximum of each frame load of a record along a motion (its samples alike).

    ``shaking_force``, ``shaking_moment``, ``rocking_couple`` and ``torque_<input>`` per input.
    """
    r = reactions
    out = {"shaking_force": Load.of(r.shaking_force),
           "shaking_moment": Load.of(r.shaking_moment),
           "rocking_couple": Load.of(r.rocking_couple)}
    for name, torque in zip(inputs, r.torques, strict=True):
        out[f"torque_{name}"] = Load.of(torque)
    return out


def motion_columns(mech: Mechanism, t: NDArray[np.float64],
                   changes: Sequence[NDArray[np.float64]], reactions: Reactions
                   ) -> tuple[list[str], Columns]:
    """The columns of the loads along a motion (:meth:`MotionAnalysis.columns`).

    ``t`` (s); each input's change from the reference pose, named by the input (rad);
    ``shaking_force_x``, ``shaking_force_y`` (N), ``shaking_moment`` (N·m),
    ``rocking_couple_x``, ``rocking_couple_y`` (N·m), ``torque_<input>`` per input (N·m);
    then the forces on the frame as the cycle analysis' columns
    (:func:`balancer.columns.frame_force_columns`). An analysis and a simulation write these.
    """
    r = reactions
    inputs = mech.linkage.inputs
    names = ["t", *inputs, "shaking_force_x", "shaking_force_y", "shaking_moment",
             "rocking_couple_x", "rocking_couple_y", *(f"torque_{name}" for name in inputs)]
    cols: Columns = [t, *changes, r.shaking_force.real, r.shaking_force.imag,
                     r.shaking_moment, r.rocking_couple.real, r.rocking_couple.imag,
                     *r.torques]
    frame_names, frame_cols = frame_force_columns(mech, r)
    return names + frame_names, cols + frame_cols


def frame_reactions(mech: Mechanism, mo: Motion, *, gravity: tuple[float, float] = (0.0, 0.0),
                    loads: bool = True) -> Reactions:
    """The frame's loads at a motion's states: the inverse dynamics and the rocking couple.

    With the applied loads (``loads``) and ``gravity`` (m/s²); one record
    (:class:`~balancer.linkage.loads.Reactions`).
    """
    with np.errstate(all="ignore"):
        forces = mech.inverse_dynamics(mo, loads=loads, gravity=gravity)
        couple = mech.rocking_couple(mo, loads=loads, gravity=gravity)
    return Reactions.of(replace(forces, rocking_couple=couple))


def motion_analysis(model: MechanismModel | Mechanism, motion: MotionSpec, *,
                    gravity: tuple[float, float] = (0.0, 0.0), loads: bool = True
                    ) -> MotionAnalysis:
    """The frame's loads along ``motion`` (module docstring).

    Raises
    ------
    SpecError
        If the motion does not fit the linkage (its waypoints' width, an unknown point).
    AssemblyError
        If a point's path leaves the workspace.
    """
    mech = model if isinstance(model, Mechanism) else mechanism_of(model)
    structure = mech.structure
    t = trajectory.sample_times(motion)
    state = trajectory.input_state(structure, motion)  # (at t: its samples, kept)
    mo = mech.motion_at(state)
    reactions = frame_reactions(mech, mo, gravity=gravity, loads=loads)
    with np.errstate(all="ignore"):
        centre = np.broadcast_to(np.asarray(geometry.total_centre_of_mass(mech, mo), np.complex128),
                                 t.shape).copy()
    changes = tuple(np.asarray(p, dtype=float) - ref
                    for p, ref in zip(state.positions, structure.input_references, strict=True))
    return MotionAnalysis(mechanism=mech, motion=motion, inputs=structure.linkage.inputs, t=t,
                          state=state, changes=changes, reactions=reactions,
                          centre_of_mass=centre, gravity=gravity)


def excursion(centre: NDArray[np.complex128]) -> float:
    """The largest distance of points (complex, m) from their mean, m (NaN left out)."""
    centre = np.asarray(centre)[np.isfinite(centre)]
    return float(np.max(np.abs(centre - centre.mean()), initial=0.0)) if centre.size else 0.0


@dataclass(frozen=True)
class WorkspaceCheck:
    """The total centre of mass over the workspace's grid.

    Attributes
    ----------
    states
        The grid's states that assemble and keep the passive joints within their limits.
    grid
        The grid's size (``samples`` per input, every combination).
    centre_of_mass_excursion
        The largest distance of the total centre of mass from its mean place over those
        states, m.
    """

    states: int
    grid: int
    centre_of_mass_excursion: float


def workspace_states(mech: Mechanism, workspace: Workspace) -> tuple[InputState, int]:
    """The states of the workspace's grid where the linkage assembles within its joint limits.

    Each input over its range (its change from the reference pose), ``samples`` values from
    one end to the other, every combination; a passive joint's angle is the second link's
    angle less the first's (in the spec's order of ``[links]``; the ground's is 0), its change
    from the reference pose taken within ±π. Returns the states and the grid's size.
    """
    structure = mech.structure
    names = structure.linkage.inputs
    axes = []
    for name, start in zip(names, structure.input_references, strict=True):
        r = workspace.range_of(name)
        low, high = (r.low, r.high) if r is not None else (0.0, 0.0)
        count = workspace.samples if r is not None else 1
        axes.append(start + np.linspace(low, high, count))
    grid = np.meshgrid(*axes, indexing="ij")
    q = [g.ravel() for g in grid]
    state = InputState.of(q)
    with np.errstate(all="ignore"):
        pose = mech.pose_at(state)
    kept = np.all([np.isfinite(a) for a in pose.angles], axis=0)
    for joint in workspace.joints:
        a, b = _joint_links(mech, joint.name)
        angle = [np.zeros(state.count) if k < 0 else np.asarray(pose.angles[k]) for k in (a, b)]
        ref = [0.0 if k < 0 else structure.ref_angle[k] for k in (a, b)]
        change = np.remainder(angle[1] - angle[0] - (ref[1] - ref[0]) + np.pi, 2 * np.pi) - np.pi
        kept &= (change >= joint.low) & (change <= joint.high)
    return state.at(kept), int(q[0].size)


def _joint_links(mech: Mechanism, point: str) -> tuple[int, int]:
    """The two links a passive joint joins, in the spec's order (the ground as -1)."""
    structure = mech.structure
    order = [b.name for b in structure.linkage.bodies]
    links = sorted((b.name for b in structure.linkage.bodies if point in b.points),
                   key=order.index)
    return structure.index(links[0]), structure.index(links[1])


def workspace_check(model: MechanismModel | Mechanism, workspace: Workspace) -> WorkspaceCheck:
    """The total centre of mass over the workspace (:func:`workspace_states`)."""
    mech = model if isinstance(model, Mechanism) else mechanism_of(model)
    state, grid = workspace_states(mech, workspace)
    centre = (geometry.total_centre_of_mass(mech, mech.motion_at(state)) if state.count
              else np.zeros(0, dtype=complex))
    return WorkspaceCheck(states=state.count, grid=grid,
                          centre_of_mass_excursion=excursion(centre))


@dataclass(frozen=True)
class AlongMotions:
    """A linkage's analysis along its motions, with its force balance over its workspace.

    Attributes
    ----------
    motions
        The loads along each motion analysed, in the spec's order.
    force_balance_residual
        How far the design is from the force-balance conditions, relative to their terms
        (:func:`balancer.force_balance.force_balance_residual`; 0: balanced).
    workspace_spec
        The spec's workspace (``None``: none), over which :attr:`workspace` checks the total
        centre of mass when asked.
    """

    motions: tuple[MotionAnalysis, ...]
    force_balance_residual: float
    workspace_spec: Workspace | None = None
    #: Each motion's weight as a balancing weighs it (:meth:`load`; ``None``: alike).
    weights: tuple[float, ...] | None = None

    @cached_property
    def workspace(self) -> WorkspaceCheck | None:
        """The total centre of mass over the workspace's grid, if the spec gives a workspace.

        Computed when first asked: an inertial analysis that no report reads makes none.
        """
        if self.workspace_spec is None:
            return None
        return workspace_check(self.mechanism, self.workspace_spec)

    @property
    def force_balanced(self) -> bool:
        """Whether the conditions hold to rounding.

        Then the total centre of mass stands still for every motion.
        """
        return self.force_balance_residual <= RESIDUAL_FLOOR

    @property
    def mechanism(self) -> Mechanism:
        """The analysed mechanism."""
        return self.motions[0].mechanism

    @property
    def orders(self) -> tuple[()]:
        """No orders: a motion is no revolution at constant speed."""
        return ()

    @property
    def linkage(self) -> MechanismModel:
        """The analysed design's model."""
        return self.motions[0].mechanism.model

    @cached_property
    def reactions(self) -> Reactions:
        """The frame's loads along every motion, one after another."""
        return Reactions.join([m.reactions for m in self.motions])

    @cached_property
    def summary(self) -> CycleSummary:
        """Each load's RMS and largest magnitude along the motions.

        The RMS as a balancing weighs it (:meth:`load`: each motion alike; the driving torque's
        the root of the inputs' mean squares summed), the maximum over every sample (the
        driving torque's over every input's).
        """
        r = self.reactions

        def figure(key: str, values: NDArray[Any]) -> Figure:
            return Figure(rms=Figure.of(self.load(key)).rms, max=Figure.of(values).max)

        return CycleSummary(
            shaking_force=figure("shaking_force", r.shaking_force),
            shaking_moment=figure("shaking_moment", r.shaking_moment),
            driving_torque=figure("driving_torque", np.concatenate(r.torques)),
            rocking_couple=figure("rocking_couple", r.rocking_couple),
            ground={p: Figure.of(v) for p, v in r.ground.items()},
            slider_normal={k: Figure.of(v) for k, v in r.slider_normal.items()},
            slider_couple={k: Figure.of(v) for k, v in r.slider_couple.items()})

    def load(self, key: str) -> NDArray[Any]:
        """A frame load as a balancing weighs it.

        Each motion's samples weighted by its share (:func:`motion_weights`), every input's
        torque stacked for ``driving_torque`` (its mean square the sum of theirs).
        """
        scale = motion_weights([m.t.size for m in self.motions], self.weights)
        r = self.reactions
        if key == "driving_torque":
            return stacked_torques(r.torques, scale)
        return np.asarray(getattr(r, key)) * scale


def stacked_torques(torques: Sequence[NDArray[Any]], scale: NDArray[np.float64]
                    ) -> NDArray[Any]:
    """Every input's torque weighted by ``scale`` and stacked, times ``√m`` for ``m`` inputs.

    Samples, or maps of a design vector whose rows are samples: their mean square is the sum
    of the inputs' mean squares, as the balancing's ``driving_torque`` term weighs them.
    """
    return np.concatenate([np.asarray(t) * scale for t in torques]) * math.sqrt(len(torques))


def motion_weights(counts: Sequence[int], weights: Sequence[float] | None = None
                   ) -> NDArray[np.float64]:
    """Each sample's factor when motions of ``counts`` samples are weighted by ``weights``.

    Motion ``k``'s samples are multiplied by ``√(N·w_k/(W·N_k))`` (``N`` in all, ``W`` the
    weights' sum; equal weights by default), so that the mean square over all samples is the
    weighted mean over the motions of each one's.
    """
    total = sum(counts)
    w = [1.0] * len(counts) if weights is None else [float(x) for x in weights]
    whole = sum(w)
    return np.concatenate([np.full(n, math.sqrt(total * wk / (whole * n)))
                           for n, wk in zip(counts, w, strict=True)])


def along_motions(model: MechanismModel | Mechanism, motions: Sequence[MotionSpec], *,
                  workspace: Workspace | None = None, gravity: tuple[float, float] = (0.0, 0.0),
                  loads: bool = True, weights: Sequence[float] | None = None) -> AlongMotions:
    """:func:`motion_analysis` of each motion, with the force balance and the workspace's."""
    mech = model if isinstance(model, Mechanism) else mechanism_of(model)
    analyses = tuple(motion_analysis(mech, m, gravity=gravity, loads=loads) for m in motions)
    return AlongMotions(motions=analyses, force_balance_residual=force_balance_residual(mech),
                        workspace_spec=workspace,
                        weights=None if weights is None else tuple(weights))
