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

from dataclasses import dataclass, replace

import numpy as np
from numpy.typing import NDArray

from .columns import Columns, frame_force_columns
from .linkage import trajectory
from .linkage.inputs import InputState
from .linkage.loads import Reactions
from .mechanisms import Mechanism, mechanism_of
from .model import MechanismModel
from .model.motions import MotionSpec


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


@dataclass(frozen=True)
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
    gravity: tuple[float, float] = (0.0, 0.0)

    @property
    def name(self) -> str:
        """The motion's name."""
        return self.motion.name

    def columns(self) -> tuple[list[str], Columns]:
        """The columns of ``analyze --csv`` along a motion: names and values.

        ``t`` (s); each input's change from the reference pose, named by the input (rad);
        ``shaking_force_x``, ``shaking_force_y`` (N), ``shaking_moment`` (N·m),
        ``rocking_couple_x``, ``rocking_couple_y`` (N·m), ``torque_<input>`` per input
        (N·m); then the forces on the frame as the cycle analysis' columns
        (:func:`balancer.columns.frame_force_columns`).
        """
        r = self.reactions
        names = ["t", *self.inputs, "shaking_force_x", "shaking_force_y", "shaking_moment",
                 "rocking_couple_x", "rocking_couple_y",
                 *(f"torque_{name}" for name in self.inputs)]
        cols: Columns = [self.t, *self.changes, r.shaking_force.real, r.shaking_force.imag,
                         r.shaking_moment, r.rocking_couple.real, r.rocking_couple.imag,
                         *r.torques]
        frame_names, frame_cols = frame_force_columns(self.mechanism, r)
        return names + frame_names, cols + frame_cols

    def loads(self) -> dict[str, Load]:
        """RMS and maximum of each frame load.

        The shaking force, moment, rocking couple and each input's torque (``torque_<input>``).
        """
        r = self.reactions
        out = {"shaking_force": Load.of(r.shaking_force),
               "shaking_moment": Load.of(r.shaking_moment),
               "rocking_couple": Load.of(r.rocking_couple)}
        for name, torque in zip(self.inputs, r.torques, strict=True):
            out[f"torque_{name}"] = Load.of(torque)
        return out


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
    state = trajectory.input_state(structure, motion, t)
    mo = mech.motion_at(state)
    with np.errstate(all="ignore"):
        forces = mech.inverse_dynamics(mo, loads=loads, gravity=gravity)
        couple = mech.rocking_couple(mo, loads=loads, gravity=gravity)
    reactions = Reactions.of(replace(forces, rocking_couple=couple))
    changes = tuple(np.asarray(p, dtype=float) - structure.ref_angle[k]
                    for p, k in zip(state.positions, structure.inputs, strict=True))
    return MotionAnalysis(mechanism=mech, motion=motion, inputs=structure.linkage.inputs, t=t,
                          state=state, changes=changes, reactions=reactions, gravity=gravity)
