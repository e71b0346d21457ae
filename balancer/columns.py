"""The per-sample columns of the CSV files: a cycle analysis' and a simulation's, by name.

Names and units are fixed by DESIGN.md (``simulate``'s first columns) and documented in the
command line's help: ``t`` s; ``theta<k>`` rad, ``omega<k>`` rad/s, ``alpha<k>`` rad/s² per
moving link; ``R<point>x``, ``R<point>y``, ``N_<link>`` N; ``C_<link>`` N·m; ``x<k>`` m,
``v<k>`` m/s, ``a<k>`` m/s² along a slider's guide; the shaking, the driving torque and the
energy. A mechanism has the same columns whatever computed them (the cycle analysis, any
formulation's simulation).
"""

from __future__ import annotations

import math
from typing import Protocol

import numpy as np
from numpy.typing import ArrayLike, NDArray

from .linkage.kinematics import Motion
from .linkage.loads import Reactions, SupportLoad
from .mechanisms import mechanism_of
from .mechanisms.base import Mechanism
from .model import MechanismModel as Model

#: Columns of a CSV file: real arrays over its rows.
Columns = list[NDArray[np.floating]]


class AnalysisLike(Protocol):
    """What the columns read of a cycle analysis (:class:`balancer.cycle.CycleAnalysis`)."""

    @property
    def mechanism(self) -> Mechanism:
        """The analysed mechanism."""
    @property
    def motion(self) -> Motion:
        """Kinematics at the samples."""
    @property
    def reactions(self) -> Reactions:
        """The loads on the frame at the samples."""
    @property
    def time(self) -> NDArray[np.float64]:
        """Time at each sample, s."""
    @property
    def samples(self) -> int:
        """Number of samples."""
    @property
    def mount_torque(self) -> NDArray[np.float64] | None:
        """An engine's torque about z on its mounts, N·m (``None``: not an engine)."""
    @property
    def supports(self) -> tuple[SupportLoad, ...]:
        """The loads at supports sharing a ground point's reaction (an engine's main bearings)."""


class TrajectoryLike(Protocol):
    """What the columns read of a simulation (:class:`balancer.simulation.Trajectory`)."""

    @property
    def reactions(self) -> Reactions:
        """The loads on the frame at the output times."""
    @property
    def model(self) -> Model | None:
        """The simulated mechanism's model."""
    @property
    def links(self) -> tuple[str, ...]:
        """Names of the moving links, in the rows' order of :attr:`theta`."""
    @property
    def t(self) -> NDArray[np.float64]:
        """Output times, s."""
    @property
    def theta(self) -> NDArray[np.float64]:
        """Each link's angle, rad, shape ``(links, times)``."""
    @property
    def omega(self) -> NDArray[np.float64]:
        """Each link's angular velocity, rad/s."""
    @property
    def alpha(self) -> NDArray[np.float64]:
        """Each link's angular acceleration, rad/s²."""
    @property
    def kinetic_energy(self) -> NDArray[np.float64]:
        """Kinetic energy, J."""
    @property
    def work(self) -> NDArray[np.float64]:
        """Work done on the mechanism, J."""

#: The columns of ``simulate``'s CSV, fixed by DESIGN.md.
SIMULATION_COLUMNS = (
    "t",
    "theta1",
    "theta2",
    "theta3",
    "omega1",
    "omega2",
    "omega3",
    "alpha1",
    "alpha2",
    "alpha3",
    "RA0x",
    "RA0y",
    "RA3x",
    "RA3y",
)
#: What the frame feels and what drives the crank, after the state and reactions.
SHAKING_COLUMNS = ("shaking_force_x", "shaking_force_y", "shaking_moment", "rocking_couple_x",
                   "rocking_couple_y", "driving_torque")
#: Extra columns written after the fixed ones with ``simulate --all-columns``.
SIMULATION_EXTRA_COLUMNS = (*SHAKING_COLUMNS, "kinetic_energy", "work")
#: The columns of ``analyze --csv`` for a four-bar (:func:`analysis_columns`).
ANALYSIS_COLUMNS = (*SIMULATION_COLUMNS, *SHAKING_COLUMNS)


def analysis_columns(analysis: AnalysisLike) -> tuple[list[str], Columns]:
    """The columns of ``analyze --csv``: names and values (arrays over the samples).

    ``t``; per moving link ``k`` (1, 2, … in the spec's order) ``theta{k}``, ``omega{k}``,
    ``alpha{k}`` (rad, rad/s, rad/s²); the forces on the frame (:func:`frame_force_columns`);
    the sliders on the frame (:func:`slider_columns`); then the shaking force's components,
    the shaking moment, the rocking couple's components and the driving torque; an engine's
    ``mount_torque`` (N·m: the shaking moment plus the driving torque), then its main bearings'
    ``R<B>x``, ``R<B>y`` where its spec places them (N); each gear pair's tooth force on its
    driven gear ``G_<name>x``, ``G_<name>y`` (N). For every
    mechanism: the columns of ``simulate``'s CSV (whatever its formulation), then the shaking.
    """
    mo, r = analysis.motion, analysis.reactions
    n = len(mo.pose.angles)
    names = ["t"]
    cols: Columns = [analysis.time]
    for group, values in (("theta", mo.pose.angles), ("omega", mo.rate), ("alpha", mo.accel)):
        names += [f"{group}{k + 1}" for k in range(n)]
        cols += [np.asarray(v, float) * np.ones(analysis.samples) for v in values]
    frame_names, frame_cols = frame_force_columns(analysis.mechanism, r)
    names += frame_names
    cols += frame_cols
    slider_names, slider_cols = slider_columns(analysis.mechanism, mo.theta1, mo.omega1, mo.alpha1)
    names += slider_names
    cols += slider_cols
    names += list(SHAKING_COLUMNS)
    cols += [r.shaking_force.real, r.shaking_force.imag, r.shaking_moment,
             r.rocking_couple.real, r.rocking_couple.imag, r.driving_torque]
    if analysis.mount_torque is not None:  # an engine's, after the columns every one has
        names.append("mount_torque")
        cols.append(analysis.mount_torque)
    for support in analysis.supports:  # an engine's main bearings, where its spec places them
        names += [f"R{support.name}x", f"R{support.name}y"]
        cols += [support.force.real, support.force.imag]
    for name, force in r.teeth.items():  # each gear pair's, where the mechanism has them
        names += [f"G_{name}x", f"G_{name}y"]
        cols += [force.real, force.imag]
    return names, cols


def frame_force_columns(mech: Mechanism, reactions: Reactions) -> tuple[list[str], Columns]:
    """Columns of the forces on the frame of ``reactions``: names and values.

    Per ground point ``P`` the force on it ``R{P}x``, ``R{P}y`` (N); per slider on the frame
    its normal force and couple ``N_{link}`` (N), ``C_{link}`` (N·m) — or, for a guide that the
    mechanism names as a point (the slider-crank's A3), the force as ``R{name}x``, ``R{name}y``
    and the couple.
    """
    normal, couple = reactions.slider_normal, reactions.slider_couple
    names: list[str] = []
    cols: Columns = []
    for point, values in reactions.ground.items():
        names += [f"R{point}x", f"R{point}y"]
        cols += [values.real, values.imag]
    normals = mech.linkage.guide_normals()
    for link in normal:
        if link in mech.presentation.guide_force_names:
            point = mech.presentation.guide_force_names[link]
            force = normal[link] * normals[link]
            names += [f"R{point}x", f"R{point}y"]
            cols += [force.real, force.imag]
        else:
            names.append(f"N_{link}")
            cols.append(normal[link])
        names.append(f"C_{link}")
        cols.append(couple[link])
    return names, cols


def slider_columns(mech: Mechanism, theta1: ArrayLike, omega1: ArrayLike, alpha1: ArrayLike
                   ) -> tuple[list[str], Columns]:
    """Columns of each slider on the frame: where its point runs along the guide.

    For the sliding link ``k`` (numbered as in ``theta{k}``): ``x{k}``, ``v{k}``, ``a{k}``,
    the position (m), velocity (m/s) and acceleration (m/s²) of the slider's point along the
    guide's direction, the position measured from the foot of the origin on the guide's line
    (the slider-crank's ``x3``: the pin's x). From the mechanism's kinematics at the crank's
    states, so that every formulation and the cycle analysis give the same columns; none
    where the crank states do not fix the pose (a crank that does not turn fully, whose free
    motion may change branch at a dead point, or a linkage with change points).
    """
    sliders = [s for s in mech.linkage.sliders if s.link in mech.linkage.ground_sliders]
    if not sliders or mech.change_points() or not mech.assembly_range().full:
        return [], []
    with np.errstate(all="ignore"):
        mo = mech.motion(theta1, omega1, alpha1)
    names: list[str] = []
    cols: Columns = []
    for s in sliders:
        k = mech.linkage.link_names.index(s.link)
        local = mech.structure.local[(k, s.point)]
        d = complex(*s.direction) / math.hypot(*s.direction)
        for prefix, vector in (("x", mo.point(k, local)), ("v", mo.point_velocity(k, local)),
                               ("a", mo.point_acceleration(k, local))):
            names.append(f"{prefix}{k + 1}")
            cols.append(np.asarray(vector.x * d.real + vector.y * d.imag, float)
                        * np.ones(np.shape(theta1)))
    return names, cols


def simulation_columns(traj: TrajectoryLike, all_columns: bool = False
                       ) -> tuple[list[str], Columns]:
    """The columns of ``simulate``'s CSV: names and values (arrays over the output times).

    ``t``; per moving link ``k`` (1, 2, … in the mechanism's order) ``theta{k}``, ``omega{k}``,
    ``alpha{k}``; the forces on the frame (:func:`frame_force_columns`); the sliders on the
    frame (:func:`slider_columns`: the slider-crank's ``x3``, ``v3``, ``a3``); with
    ``all_columns`` the shaking, the driving torque and the energy. The same columns whatever
    the formulation; for the four-bar and the slider-crank the first are DESIGN.md's fixed
    ones (:data:`SIMULATION_COLUMNS`).
    """
    names = ["t"]
    cols: Columns = [traj.t]
    for group in ("theta", "omega", "alpha"):
        values = getattr(traj, group)
        names += [f"{group}{k + 1}" for k in range(len(values))]
        cols += list(values)
    assert traj.model is not None  # a simulation's trajectory names its model
    mech = mechanism_of(traj.model)
    frame_names, frame_cols = frame_force_columns(mech, traj.reactions)
    names += frame_names
    cols += frame_cols
    crank = list(traj.links).index(mech.linkage.input)
    slider_names, slider_cols = slider_columns(mech, traj.theta[crank], traj.omega[crank],
                                               traj.alpha[crank])
    names += slider_names
    cols += slider_cols
    if all_columns:
        r = traj.reactions
        sf, rc = r.shaking_force, r.rocking_couple
        cols += [sf.real, sf.imag, r.shaking_moment, rc.real, rc.imag, r.driving_torque,
                 traj.kinetic_energy, traj.work]
        names += SIMULATION_EXTRA_COLUMNS
    return names, cols
