"""What pictures draw of a mechanism: its frame, its links over a revolution, centres of mass.

Positions from the mechanism's kinematics at crank angles, for the figures and animations of
the other modules of :mod:`balancer.plots` (which compute nothing themselves).
"""

from __future__ import annotations

from collections.abc import Mapping
from typing import Protocol

import numpy as np
from numpy.typing import NDArray

from ..columns import TrajectoryLike
from ..cycle import sample_angles
from ..linkage.inputs import InputState
from ..linkage.vectors import V
from ..mechanisms import geometry, mechanism_of
from ..mechanisms.base import Mechanism, frame_positions
from ..mechanisms.drawing import DrawnMass
from ..model import GROUND
from ..model import MechanismModel as Model


class CounterweightLike(Protocol):
    """What a drawing reads of a counterweight (:class:`balancer.balance.Counterweight`)."""

    @property
    def kind(self) -> str:
        """``"add"`` for a body added to the link (the others are not drawn)."""
    @property
    def e(self) -> float:
        """Its centre along the link, m."""
    @property
    def f(self) -> float:
        """Its centre across the link, m."""
    @property
    def disc_radius(self) -> float | None:
        """Its steel disc's radius, m (``None``: a point)."""


def centre_of_mass_path(linkage: Model | Mechanism, traj: TrajectoryLike
                        ) -> NDArray[np.complex128]:
    """Total centre of mass along a simulated motion, complex, m.

    ``traj`` a simulated motion (:class:`balancer.simulation.Trajectory`: its links' names,
    angles, rates and accelerations); from the crank's angle (the pose of the smooth motion
    there).
    """
    mech = mechanism_of(linkage)
    crank = traj.links.index(mech.linkage.input)
    mo = mech.motion(traj.theta[crank], traj.omega[crank], traj.alpha[crank])
    return np.asarray(geometry.total_centre_of_mass(mech, mo), complex)


def revolution(frames: int) -> InputState:
    """A crank's states at ``frames`` equally spaced angles of a revolution, at 1 rad/s."""
    return InputState.crank(sample_angles(frames), 1.0)


def frame(linkage: Model | Mechanism, samples: int = 72, states: InputState | None = None
          ) -> tuple[NDArray[np.complex128], list[NDArray[np.complex128]]]:
    """What to draw of the frame: the ground points, and each ground guide's travel, m.

    Returns the ground points (complex) and, per slider on a ground guide, the two ends of
    the stretch of its line that its point covers over a revolution (or near the reference
    pose, for a crank that does not turn fully) — or over the input ``states`` given (a
    motion's).
    """
    mech = mechanism_of(linkage)
    pivots = np.array(list(frame_positions(mech).values()), complex)
    if states is None:
        rng = mech.assembly_range()
        angles = sample_angles(samples) if rng.full else np.linspace(*rng.intervals[0],
                                                                     samples)
        states = InputState.crank(angles)
    with np.errstate(all="ignore"):
        mo = mech.motion_at(states)
    points = geometry.points(mech, mo)
    guides: list[NDArray[np.complex128]] = []
    for slider in mech.linkage.sliders:
        if slider.guide == GROUND:
            path = points[slider.point][np.isfinite(points[slider.point])]
            if path.size:
                d = complex(*slider.direction) / abs(complex(*slider.direction))
                along = (path * np.conj(d)).real
                base = path[0] - (path[0] * np.conj(d)).real * d
                guides.append(base + d * np.array([along.min(), along.max()]))
    return pivots, guides


def pitch_circles(linkage: Model | Mechanism) -> list[tuple[complex, float]]:
    """Each gear pair's two pitch circles as (centre, radius), m: they touch at its pitch point.

    Centred on the gears' pivots, of the pair's pitch radii (:class:`~balancer.linkage.
    constraints.Mesh`); none for a mechanism without gears.
    """
    out: list[tuple[complex, float]] = []
    for mesh in mechanism_of(linkage).structure.meshes:
        rho_a, rho_b = mesh.radii
        out += [(complex(mesh.oa.complex()), abs(rho_a)), (complex(mesh.ob.complex()), abs(rho_b))]
    return out


def drawing_frames(linkage: Model | Mechanism, states: InputState
                   ) -> tuple[dict[str, NDArray[np.complex128]], dict[str, NDArray[np.complex128]],
                              NDArray[np.complex128]]:
    """What an animation draws at its frames' input states (a revolution's, or a motion's).

    Returns ``(links, coms, total)``: per link (the ground's left out) a ``(frames, k)``
    complex array of its points in drawing order (a ternary link closed into a triangle),
    per link its centre of mass ``(frames,)``, and ``(frames,)`` the total, m.
    """
    mech = mechanism_of(linkage)
    mo = mech.motion_at(states)
    points = geometry.points(mech, mo)
    links: dict[str, NDArray[np.complex128]] = {}
    for name, names in geometry.drawing(mech).items():
        if name == GROUND:
            continue
        ring = [*names, names[0]] if len(names) > 2 else list(names)
        links[name] = np.column_stack([points[p] for p in ring])
    coms = {name: np.asarray(c.complex() + 0 * mo.state.positions[0], complex)
            for name, c in zip(mech.linkage.link_names, geometry.centres_of_mass(mech, mo),
                               strict=True)}
    return links, coms, np.asarray(geometry.total_centre_of_mass(mech, mo), complex)


def counterweight_paths(linkage: Model | Mechanism,
                        counterweights: Mapping[str, CounterweightLike], states: InputState
                        ) -> dict[str, tuple[NDArray[np.complex128], float]]:
    """Where each counterweight to add is at the input ``states``: per link, its path.

    ``(centres, radius)``.

    ``centres`` a ``(frames,)`` complex array (m): the counterweight's centre ``(e, f)`` in its
    link's frame, carried by the link; ``radius`` its steel disc's (m; 0 for a point).
    """
    mech = mechanism_of(linkage)
    mo = mech.motion_at(states)
    out: dict[str, tuple[NDArray[np.complex128], float]] = {}
    for k, name in enumerate(mech.linkage.link_names):
        w = counterweights.get(name)
        if w is None or w.kind != "add":
            continue
        centre = mo.point(k, V(w.e, w.f)).complex() + 0 * mo.state.positions[0]
        out[name] = (np.asarray(centre, complex), w.disc_radius or 0.0)
    return out


def slider_block_outlines(linkage: Model | Mechanism, states: InputState
                          ) -> dict[str, NDArray[np.complex128]]:
    """Each sliding block's outline at the input ``states``: per link ``(frames, 5)``, m.

    The rectangle of the mechanism's :class:`~balancer.mechanisms.drawing.Drawing` (an
    engine's pistons, sized by their bore), centred on the link's point and along its
    slider, its four corners and the first again (complex), carried by the link.
    """
    mech = mechanism_of(linkage)
    mo = mech.motion_at(states)
    out: dict[str, NDArray[np.complex128]] = {}
    for name, (length, width) in mech.drawing().blocks.items():
        k = mech.linkage.link_names.index(name)
        corners = [(-0.5, -0.5), (0.5, -0.5), (0.5, 0.5), (-0.5, 0.5), (-0.5, -0.5)]
        out[name] = np.column_stack([
            mo.point(k, V(u * length, v * width)).complex() + 0 * mo.state.positions[0]
            for u, v in corners])
    return out


def drawn_mass_sectors(linkage: Model | Mechanism, states: InputState
                       ) -> list[tuple[DrawnMass, NDArray[np.float64], float]]:
    """The shafts' counterweights and eccentrics as sectors at the crank's ``states``.

    Per mass (the :class:`~balancer.mechanisms.drawing.Drawing`'s, a one-input mechanism's):
    the mass, its direction from its axis at the crank angles ``(frames,)`` (rad,
    ``ratio·θ1 + angle``), and the radius of the sector that shows it (m): sectors of one
    thickness and angle, so their radius goes as the cube root of their mass·radius, the
    largest reaching the crank's reach.
    """
    drawn = mechanism_of(linkage).drawing()
    masses, reach = drawn.masses, drawn.reach
    if not masses:
        return []
    largest = max((m.mr for m in masses), default=0.0)
    theta1 = np.asarray(states.positions[0], dtype=float)
    return [(m, m.ratio * theta1 + m.angle, reach * float(np.cbrt(m.mr / largest)))
            for m in masses if m.mr > 0]
