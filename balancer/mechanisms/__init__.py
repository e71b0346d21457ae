"""The mechanism interface and its one registry (:func:`mechanism_of`).

See :mod:`.base` for the interface; :mod:`.general` (any linkage), :mod:`.fourbar` and
:mod:`.slidercrank` implement it. The functions below the registry belong to the shape that the
interface replaces and go as their callers move to it.
"""

from __future__ import annotations

from functools import lru_cache

import numpy as np
from numpy.typing import NDArray

from ..errors import AssemblyError
from ..kinematics import AssemblyRange
from ..model import FourBar, SliderCrank

#: The mechanism classes by model type: (module, class).
REGISTRY: dict[str, tuple[str, str]] = {
    "four-bar": ("balancer.mechanisms.fourbar", "FourBarMechanism"),
    "slider-crank": ("balancer.mechanisms.slidercrank", "SliderCrankMechanism"),
    "linkage": ("balancer.mechanisms.general", "LinkageMechanism"),
}


def mechanism_of(model):
    """The :class:`~.base.Mechanism` of a model (a FourBar, SliderCrank or Linkage).

    Built once per model (models are frozen and hashable); a mechanism is returned as it is.

    Raises
    ------
    SpecError
        If the model is not a mechanism the package knows, or a general linkage is not a valid
        one (mobility, reference pose; see :class:`balancer.linkage.structure.Structure`).
    """
    from .base import Mechanism

    if isinstance(model, Mechanism):
        return model
    try:
        return _cached(model)
    except TypeError:  # unhashable: build it every time
        return _build(model)


@lru_cache(maxsize=64)
def _cached(model):
    return _build(model)


def _build(model):
    import importlib

    from ..errors import SpecError

    kind = getattr(model, "type", None)
    if kind not in REGISTRY:
        raise SpecError("must be a mechanism (a FourBar, SliderCrank or Linkage)",
                        key="mechanism", value=type(model).__name__)
    module, cls = REGISTRY[kind]
    mech = getattr(importlib.import_module(module), cls)(model)
    mech.structure  # noqa: B018 - build (and so check) the equations now
    return mech


#: Formulation a check by simulation uses: one the optimiser (mass-matrix regressors) did not.
VERIFY_METHOD = {"four-bar": "opened-loop", "slider-crank": "complex-masses"}


def assembly_range(mechanism: FourBar | SliderCrank) -> AssemblyRange:
    """Crank angles at which the mechanism assembles."""
    if mechanism.type == "slider-crank":
        from ..slider_crank.kinematics import assembly_range as slider_range

        return slider_range(mechanism.lengths)
    from ..kinematics import assembly_range as fourbar_range

    return fourbar_range(mechanism.lengths)


def require_full_revolution(mechanism: FourBar | SliderCrank, purpose: str) -> AssemblyRange:
    """The assembly range, if the crank turns a full revolution.

    Raises
    ------
    AssemblyError
        Otherwise (exit code 2, naming ``mechanism.lengths``): ``purpose`` (e.g. "a cycle
        analysis") needs a crank that turns.
    """
    rng = assembly_range(mechanism)
    if not rng.full:
        condition = " (crank + |offset| < rod)" if mechanism.type == "slider-crank" else ""
        raise AssemblyError(
            f"{purpose} needs a crank that turns a full revolution{condition}, but this "
            f"{mechanism.type} assembles only for θ1 in {rng.describe()}",
            key="mechanism.lengths",
        )
    return rng


def centre_of_mass_path(mechanism, theta, omega=None, alpha=None) -> NDArray[np.complex128]:
    """Total centre of mass at the given link angles (arrays of shape (3, n)), m."""
    if mechanism.type == "slider-crank":
        from ..slider_crank.kinematics import motion_of
        from ..slider_crank.massmodels import total_com_direct

        return total_com_direct(mechanism, motion_of(mechanism, theta[0], check=False))
    from ..inverse import link_com_kinematics
    from ..kinematics import motion_from_angles

    zeros = tuple(np.zeros_like(np.asarray(theta[0], float)) for _ in range(3))
    mo = motion_from_angles(mechanism.lengths, tuple(theta), omega or zeros, alpha or zeros)
    (r1, r2, r3), _ = link_com_kinematics(mechanism, mo)
    m1, m2, m3 = (link.mass for link in mechanism.links)
    return (m1 * r1 + m2 * r2 + m3 * r3) / mechanism.total_mass


def frame_points(mechanism) -> list[complex]:
    """Points of the frame to draw: the ground pivots (and the guide's ends), m."""
    if mechanism.type == "slider-crank":
        r, big_l, e = mechanism.lengths
        return [0j, complex(big_l - r, e), complex(big_l + r, e)]
    return [0j, complex(mechanism.lengths[3], 0.0)]


def drawing_frames(mechanism, frames: int):
    """Joint positions, link centres of mass and the total centre of mass over a revolution.

    Returns ``(joints, coms, total)``: ``(frames, k)`` complex arrays of the joints in drawing
    order, ``(frames, 3)`` the links' centres of mass and ``(frames,)`` the total, m.
    """
    from ..inverse import sample_angles

    angles = sample_angles(frames)
    if mechanism.type == "slider-crank":
        from ..slider_crank.kinematics import motion_of
        from ..slider_crank.massmodels import link_centres_of_mass

        mo = motion_of(mechanism, angles, 1.0)
        joints = np.column_stack([np.zeros(frames, complex), mo.A1, mo.A2])
        coms = np.column_stack(link_centres_of_mass(mechanism, mo))
    else:
        from ..inverse import link_com_kinematics
        from ..kinematics import cycle_branch_signs, motion

        signs = cycle_branch_signs(mechanism.lengths, mechanism.branch, angles)
        mo = motion(mechanism.lengths, angles, 1.0, 0.0, signs, check=False)
        a3 = np.full(frames, complex(mechanism.lengths[3], 0.0))
        joints = np.column_stack([np.zeros(frames, complex), mo.pos.A1, mo.pos.A2, a3])
        (r1, r2, r3), _ = link_com_kinematics(mechanism, mo)
        coms = np.column_stack([r1, r2, r3])
    m = np.array([link.mass for link in mechanism.links])
    return joints, coms, coms @ m / m.sum()
