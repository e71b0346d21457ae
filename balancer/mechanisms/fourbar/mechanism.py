"""The four-bar as a mechanism: its general linkage, with the paper's closed forms added.

Meijaard & van der Wijk (2020): the kinematics in closed form (Eq. 1–11), which follow a
change-point linkage (a parallelogram) through its flat positions on the smooth motion — the
general core stops at such positions — and the equivalent-mass-matrix route of inverse dynamics
(Eq. 45–54) as the ``"mass-matrix"`` route. The links are A0→A1 (crank), A1→A2 (coupler),
A2→A3 (rocker) with the ground pivots A0 at the origin and A3 at ``(l4, 0)``.
"""

from __future__ import annotations

import math
from collections import OrderedDict
from functools import cached_property, lru_cache

import numpy as np
from numpy.typing import ArrayLike, NDArray

from ...linkage.constraints import Pose
from ...linkage.dynamics import Forces
from ...linkage.inputs import InputState
from ...linkage.kinematics import _MOTIONS_LOCK, MOTION_CACHE_STATES, MOTIONS_KEPT, Motion
from ...linkage.structure import Structure
from ...linkage.vectors import V
from ...model import Body, Branch, Linkage
from ...model.assembly import AssemblyRange
from ..base import ROUTES, Limit, Mechanism, Route, in_one_plane
from ..presentation import Presentation
from . import kinematics as fourbar
from .assembly import assembly_range, classify
from .conditions import force_balance_matrix
from .inverse import change_point_limits, mass_matrix, newton_euler
from .model import FourBar


def fourbar_linkage(model: FourBar) -> Linkage:
    """The four-bar as a general linkage, at a regular reference pose on its branch.

    The reference crank angle is 0 when the crank turns fully and the pose there is regular
    (``|sin(θ3 − θ2)| ≥ 0.3``), else the one of its range's samples farthest from a dead or
    change point (largest ``|sin(θ3 − θ2)|``). The pose depends on the geometry alone
    (:func:`_reference_points`: a design and its redesign share it).
    """
    points = _reference_points(model.lengths, model.branch)
    bodies = (Body(name="ground", points=("A0", "A3")),
              Body(name="crank", points=("A0", "A1"), props=model.crank),
              Body(name="coupler", points=("A1", "A2"), props=model.coupler),
              Body(name="rocker", points=("A2", "A3"), props=model.rocker))
    return Linkage(points=points, bodies=bodies, inputs=("crank",))


@lru_cache(maxsize=64)
def _reference_points(lengths: tuple[float, float, float, float], branch: Branch
                      ) -> tuple[tuple[str, tuple[float, float]], ...]:
    """:func:`fourbar_linkage`'s points A0…A3 at its reference pose, m."""
    rng = assembly_range(lengths)
    if rng.full:  # θ1 = 0 first: taken if it is regular (as the candidates' first would be)
        at_zero = _pose_points(lengths, branch, np.zeros(1), 0, least=0.3)
        if at_zero is not None:
            return at_zero
        candidates = np.linspace(0.0, 2 * math.pi, 73)[:-1]
    else:
        lo, hi = rng.intervals[0]
        candidates = np.linspace(lo, hi, 74)[1:-1]
    best = _pose_points(lengths, branch, candidates, None)
    assert best is not None  # (the most regular of the candidates)
    return best


def _pose_points(lengths: tuple[float, float, float, float], branch: Branch,
                 candidates: NDArray[np.float64], index: int | None, least: float = 0.0
                 ) -> tuple[tuple[str, tuple[float, float]], ...] | None:
    """The points A0…A3 at the candidate ``index``, or ``None`` if it is not regular.

    ``index`` ``None``: the candidate farthest from a dead or change point. Not regular: its
    ``|sin(θ3 − θ2)|`` below ``least``.
    """
    signs = fourbar.cycle_branch_signs(lengths, branch, candidates)
    pos = fourbar.position(lengths, candidates, signs, check=False)
    transmission = np.abs(pos.sin_transmission)
    best = int(np.nanargmax(transmission)) if index is None else index
    if not transmission[best] >= least:  # (NaN: not regular either)
        return None
    a1, a2 = complex(pos.A1[best]), complex(pos.A2[best])
    return (("A0", (0.0, 0.0)), ("A1", (a1.real, a1.imag)), ("A2", (a2.real, a2.imag)),
            ("A3", (lengths[3], 0.0)))


class FourBarMechanism(Mechanism):
    """The 4R four-bar (``type = "four-bar"``)."""

    model: FourBar

    own_formulations = {"opened-loop": "opened_loop.OpenedLoop",
                        "complex-masses": "complex_masses.ComplexMasses",
                        "mass-matrix": "mass_matrix.MassMatrix", "lie-group": "lie_group.LieGroup"}
    geometry_key = "mechanism.lengths"
    presentation = Presentation(force_balance_source="the conditions, Eq. 57–58,",
                                named_states=False)
    #: Without ``[simulation] theta1`` a simulation starts at θ1 = 0.
    start_angle = 0.0

    @property
    def verify_method(self) -> str:  # type: ignore[override]  # per design: a property here
        """The formulation :func:`balancer.verification.verify` uses by default.

        The paper's complex joint masses (Eq. 36–40) where the crank turns fully without change
        points: a route apart from the optimiser's, with its own reactions (Eq. 40), and three
        times as fast as the opened loop; the opened loop (Eq. 22–28), which passes dead points
        and change points, otherwise.
        """
        if self.assembly_range().full and not self.change_points():
            return "complex-masses"
        return "opened-loop"

    @cached_property
    def linkage(self) -> Linkage:
        return fourbar_linkage(self.model)

    @cached_property
    def structure(self) -> Structure:
        l1, l2, l3, _ = self.model.lengths
        return Structure.of(self.linkage, {"crank": l1, "coupler": l2, "rocker": l3})

    def describe(self) -> str:
        """The Grashof class."""
        return str(classify(self.model.lengths))

    @property
    def branch(self) -> Branch:
        return self.model.branch

    def assembly_range(self) -> AssemblyRange:
        return assembly_range(self.model.lengths)

    def change_points(self) -> tuple[float, ...]:
        return fourbar.change_point_angles(self.model.lengths)

    def motion(self, theta1: ArrayLike, omega1: ArrayLike = 0.0,
               alpha1: ArrayLike = 0.0) -> Motion:
        """The closed form (Eq. 2–10) on the smooth motion's branch, as a general motion."""
        return general_motion(self._closed_form_motion(theta1, omega1, alpha1))

    def pose(self, theta1: ArrayLike) -> Pose:
        """The closed form's frames (Eq. 2–4)."""
        return self.motion(theta1).pose

    def _closed_form_motion(self, theta1: ArrayLike, omega1: ArrayLike,
                            alpha1: ArrayLike) -> fourbar.FourBarMotion:
        """The closed form (Eq. 2–10) on the smooth motion's branch (arrays broadcast)."""
        t, w, a = (np.atleast_1d(np.asarray(x, dtype=float))
                   for x in np.broadcast_arrays(theta1, omega1, alpha1))
        key = None
        if t.size <= MOTION_CACHE_STATES:  # a cycle's samples, asked again (a design and
            # its redesign: the geometry's structure keeps them, as the general core does)
            key = ("closed form", t.shape, t.tobytes(), w.tobytes(), a.tobytes())
            with _MOTIONS_LOCK:
                motions = self.structure.kinematic.setdefault("closed-form motions",
                                                              OrderedDict())
                known = motions.get(key)
            if known is not None:
                return known
        signs = fourbar.cycle_branch_signs(self.model.lengths, self.model.branch, t)
        with np.errstate(divide="ignore", invalid="ignore"):
            mo = fourbar.motion(self.model.lengths, t, w, a, signs, check=False)
        if key is not None:
            with _MOTIONS_LOCK:
                motions[key] = mo
                while len(motions) > MOTIONS_KEPT:
                    motions.popitem(last=False)
        return mo

    def closed_form_force_balance(self) -> NDArray[np.float64]:
        """Eq. 57–58 over the layout (crank, coupler, rocker, then two counter-rotors)."""
        ab = force_balance_matrix(self.model.lengths)
        assert not np.any(ab[:, 12]), "Eq. 58 is homogeneous"
        return np.hstack([ab[:, :12], np.zeros((ab.shape[0], self.layout.size - 12))])

    def limits(self, theta1: NDArray[np.float64]) -> list[Limit]:
        return [Limit(mask, offsets, weights) for mask, offsets, weights
                in change_point_limits(self.model.lengths, theta1)]

    def inverse_dynamics(self, mo: Motion, *, route: Route | None = None, loads: bool = True,
                         gravity: tuple[float, float] = (0.0, 0.0)) -> Forces:
        """The paper's routes in closed form (the general core checks them in the tests).

        Newton–Euler on the links' free bodies with the principal vectors (Eq. 12–28), or the
        equivalent mass matrices (Eq. 45–54).
        """
        return self._closed_form_forces(fourbar_motion(self.model, mo), route, loads, gravity)

    def _uncompiled_forces(self, states: list[NDArray[np.float64]], *, route: Route,
                          loads: bool, gravity: tuple[float, float]) -> Forces:
        """The crank forces from the closed-form motion alone (Eq. 2–10, 12–28, 45–54).

        (Compiled, :meth:`crank_forces` runs the general core's groups' route instead: the
        same figures to rounding, which the closed forms check in the tests.)
        """
        return self._closed_form_forces(self._closed_form_motion(*states), route, loads,
                                        gravity)

    def _closed_form_forces(self, mo: fourbar.FourBarMotion, route: Route | None, loads: bool,
                            gravity: tuple[float, float]) -> Forces:
        route_fn = mass_matrix if (route or ROUTES[0]) == "mass-matrix" else newton_euler
        r = route_fn(self.model, mo, gravity=gravity, loads=loads)
        return r.forces(rocking_couple=self._rocking_couple(mo, loads, gravity))

    def _rocking_couple(self, mo: fourbar.FourBarMotion, loads: bool,
                        gravity: tuple[float, float]) -> V:
        """The rocking couple at the closed-form motion (the general core's, from its motion)."""
        if in_one_plane(self):
            zero = np.zeros((mo.size, 1))
            return V(zero, zero.copy())
        return self.rocking_couple(general_motion(mo), loads=loads, gravity=gravity)


def general_motion(mo: fourbar.FourBarMotion) -> Motion:
    """A four-bar's closed-form motion as the general core's (frames at A0, A1, A2)."""
    zero = 0.0 * mo.pos.theta1
    va1, va2 = mo.joint_velocities
    aa1, aa2 = mo.joint_accelerations
    origins = [V(zero, zero), V.of_array(mo.pos.A1), V.of_array(mo.pos.A2)]
    angles = list(mo.theta)
    cos = [np.real(v) / length for v, length in zip(mo.vectors, mo.lengths[:3], strict=True)]
    sin = [np.imag(v) / length for v, length in zip(mo.vectors, mo.lengths[:3], strict=True)]
    return Motion(state=InputState((mo.pos.theta1,), (mo.omega[0],), (mo.alpha[0],)),
                  pose=Pose(origins, angles, cos, sin),
                  velocity=(V(zero, zero), V.of_array(va1), V.of_array(va2)),
                  rate=tuple(mo.omega),
                  acceleration=(V(zero, zero), V.of_array(aa1), V.of_array(aa2)),
                  accel=tuple(mo.alpha), closed_form=mo)


def fourbar_motion(model: FourBar, mo: Motion) -> fourbar.FourBarMotion:
    """A general motion of a four-bar as the closed form's (angles and rates)."""
    if isinstance(mo.closed_form, fourbar.FourBarMotion):
        return mo.closed_form
    return fourbar.motion_from_angles(model.lengths, tuple(mo.pose.angles), tuple(mo.rate),
                                      tuple(mo.accel))


#: The class the registry builds for this folder (:data:`balancer.mechanisms.FOLDERS`).
MECHANISM = FourBarMechanism
