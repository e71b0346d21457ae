"""An engine's main-bearing loads: the crankshaft's loads shared by the lever rule.

The crankshaft is rigid and simply supported at its main bearings (``[mechanism]
main_bearings``, planes ``z_1 < … < z_m``); as engine designers share them, each load on it is
carried by the two bearings around its plane ``z`` (the bay ``z_j ≤ z ≤ z_{j+1}``; beyond an end
bearing, the end bay, the far bearing's share then negative) in inverse proportion to their
distances from it:

    share_j = (z_{j+1} − z)/(z_{j+1} − z_j),      share_{j+1} = (z − z_j)/(z_{j+1} − z_j).

The loads the crankshaft passes on, each at its plane (what it puts on the frame, N):

- each crank pin's force from its cylinder's rod and piston, from that chain's momentum:
  ``P_k = Σ m·(ḡ − ā)`` over the rod and the piston, less the guide's normal force on the frame
  ``N_k·n̂_k`` (its reaction holds the piston), plus the gas force on the piston ``F_k·û_k``
  (its reaction is on the head: it reaches the bearings only through the rod);
- the crankshaft link's own ``m·(ḡ − ā)``: its weight, its centre of mass on the axis in the
  plane ``z = 0`` (the spec gives its mass, not where along the crank it lies: mains placed
  about ``z = 0`` share it as the crankshaft does);
- each of its masses' (pin, webs, counterweights) centrifugal force at its plane
  (:meth:`~balancer.linkage.rotors.Rotor.loads`; a mass·radius carries no weight of its own:
  the crankshaft's mass holds it).

Their sum is the main bearings' summed reaction ``O`` that the inverse dynamics gives (the
crankshaft's Newton equation): the tests hold the split to it.
"""

from __future__ import annotations

from collections.abc import Callable, Collection, Sequence

import numpy as np
from numpy.typing import NDArray

from ...linkage.dynamics import Forces, inertial_columns
from ...linkage.kinematics import Motion
from ...linkage.loads import Reactions
from ...linkage.rotors import Rotor
from ...linkage.vectors import V
from ..base import Mechanism


def lever_shares(planes: Sequence[float], z: float) -> tuple[tuple[int, float], ...]:
    """The two bearings (indices into ``planes``) that carry a load at ``z``, and their shares.

    ``planes`` increasing, two or more; the shares sum to 1.
    """
    j = int(np.searchsorted(np.asarray(planes), z, side="right")) - 1
    j = min(max(j, 0), len(planes) - 2)
    low, high = planes[j], planes[j + 1]
    t = (z - low) / (high - low)
    return ((j, 1.0 - t), (j + 1, t))


def bearing_name(j: int) -> str:
    """Main bearing ``j``'s name (from 0): ``B1``, ``B2``, …."""
    return f"B{j + 1}"


def main_bearing_loads(mech: Mechanism, planes: Sequence[float], ground_point: str,
                       mo: Motion, reactions: Reactions, *, loads: bool = True,
                       gravity: tuple[float, float] = (0.0, 0.0), shaft: str | None = None,
                       pistons: Collection[str] | None = None,
                       teeth: Sequence[tuple[float, NDArray[np.complex128]]] = (),
                       names: Callable[[int], str] | None = None
                       ) -> dict[str, NDArray[np.complex128]]:
    """Each main bearing's load on the frame at a motion's states, complex ``x + i·y``, N.

    ``mech`` an engine's mechanism (its crankshaft the link ``shaft``, default the input,
    cylinder ``k``'s rod and piston ``rod<k>`` and ``piston<k>`` at its plane, the pistons on
    this crankshaft ``pistons``, default every one); ``mo`` its motion and ``reactions`` its
    frame loads there (their guides' normal forces: a cycle analysis's own, not computed
    again); ``ground_point`` the crankshaft's rotors' bearing (``O``). ``loads``: the gas
    forces included (as in ``reactions``). ``teeth``: the gear pairs' forces on this
    crankshaft, each at its plane (a geared engine's: ``(z, force)``). ``names``: bearing
    ``j``'s name (default :func:`bearing_name`).
    """
    theta, omega, alpha = (np.reshape(np.asarray(x, dtype=float) * np.ones(mo.count),
                                      mo.count) for x in (mo.theta1, mo.omega1, mo.alpha1))
    g = complex(*gravity)
    linkage, structure = mech.linkage, mech.structure
    out = [np.zeros(theta.size, complex) for _ in planes]

    def carried(name: str) -> NDArray[np.complex128]:
        """A link's ``m·(ḡ − ā)`` at its centre of mass."""
        link = linkage.link(name)
        a = mo.point_acceleration(structure.index(name), V(link.e, link.f)).complex()
        return link.mass * (g - np.reshape(a, theta.size))

    def add(z: float, load: NDArray[np.complex128]) -> None:
        for j, share in lever_shares(planes, z):
            out[j] = out[j] + share * load

    normals = mech.linkage.guide_normals()
    sliders = {s.link: s for s in linkage.sliders}
    for name in linkage.link_names:
        if name in sliders and (pistons is None or name in pistons):
            # a piston: its chain's force on its crank pin, at its plane
            rod = next(b.name for b in linkage.bodies
                       if sliders[name].point in b.points and b.name != name)
            s = sliders[name]
            pin = carried(rod) + carried(name)
            pin = pin - np.asarray(reactions.slider_normal[name], float) * normals[name]
            if loads:
                u = complex(*s.direction)
                pin = pin + np.asarray(s.force.at(theta), float) * (u / abs(u))
            add(linkage.link(rod).z, pin)
    own = linkage.input if shaft is None else shaft
    add(linkage.link(own).z, carried(own))
    for point, rotor in mech.rotors:
        if point != ground_point:
            continue
        for e in rotor.eccentrics:
            single = Rotor(ratio=rotor.ratio, inertia=0.0, axis=rotor.axis, eccentrics=(e,))
            add(e.z, single.loads(theta, omega, alpha, gravity).force)
    for z, force in teeth:  # (the gear's push on the shaft is what the shaft passes on)
        add(z, np.asarray(force, dtype=complex))
    naming = bearing_name if names is None else names
    return {naming(j): out[j] for j in range(len(planes))}


def main_bearing_regressors(mech: Mechanism, planes: Sequence[float], mo: Motion, *,
                            links: Collection[str] | None = None,
                            teeth: Sequence[tuple[float, NDArray[np.complex128]]] = (),
                            regressors: Forces | None = None
                            ) -> list[NDArray[np.complex128]]:
    """Each main bearing's inertial load as a linear map of the design vector, ``(N, P)``.

    As :func:`main_bearing_loads` without gas, weights or the crankshaft's masses (those are
    the balancing's mass·radius sites, shared by :func:`lever_shares`): each link's
    ``m·(ḡ − ā)`` per unit inertial parameter (:func:`~balancer.linkage.dynamics.
    inertial_columns`) at its plane, less each guide's normal force on the frame
    (:meth:`~balancer.mechanisms.base.Mechanism.regressors`) at its cylinder's; columns in the
    mechanism's :attr:`~balancer.mechanisms.base.Mechanism.layout`. ``links``: those this
    crankshaft carries (itself, its cylinders' rods and pistons; default every one);
    ``teeth``: its gear pairs' tooth forces on it, each as such a map at its plane;
    ``regressors``: the mechanism's at ``mo``, where the caller has them (else computed here).
    """
    linkage, structure, layout = mech.linkage, mech.structure, mech.layout
    n = mo.count
    out = [np.zeros((n, layout.size), complex) for _ in planes]
    columns = inertial_columns(structure, mo, V(0.0, 0.0))
    sliders = {s.link: s for s in linkage.sliders
               if links is None or s.link in links}
    plane = {name: linkage.link(name).z for name in linkage.link_names}
    for z, force in teeth:
        for j, share in lever_shares(planes, z):
            out[j] += share * np.asarray(force, dtype=complex)
    for name, cols in columns.items():
        if links is not None and name not in links:
            continue
        for param, (fx, fy, _) in cols:
            force = np.broadcast_to(np.asarray(fx) + 1j * np.asarray(fy), (n,))
            for j, share in lever_shares(planes, plane[name]):
                out[j][:, layout.index(name, param)] += share * force
    if sliders:
        if regressors is None:
            with np.errstate(all="ignore"):
                regressors = mech.regressors(mo)
        normal = regressors.slider_normal
        normals = mech.linkage.guide_normals()
        for name in sliders:
            if name not in normal:
                continue
            for j, share in lever_shares(planes, plane[name]):
                out[j] -= share * np.asarray(normal[name], float) * normals[name]
    return out


__all__ = ["bearing_name", "lever_shares", "main_bearing_loads", "main_bearing_regressors"]
