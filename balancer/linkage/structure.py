"""The structure of a general linkage: frames, constraints, mobility and Assur groups.

Coordinates. Each moving link ``k`` has absolute coordinates ``(x_k, y_k, θ_k)``: the position of
its frame's origin (its first point) and the angle of its frame's x-axis (towards its second
point at the reference pose; a one-point link's is its slider's direction). A point ``p`` of
the link, at ``p̄`` in its frame, is at ``r̄_k + R(θ_k)·p̄``. The ground is link ``-1`` with
``r̄ = 0``, ``θ = 0`` (its frame is the spec's).

Constraints (Nikravesh, *Computer-Aided Analysis of Mechanical Systems*, 1988, ch. 3–4):

- a revolute joint between links ``a`` and ``b`` at a point: ``r̄_a + R_a·p̄_a − r̄_b − R_b·p̄_b
  = 0`` (two rows); at a point named by ``k`` links, ``k − 1`` such pairs;
- a prismatic pair, link ``s`` sliding on a line fixed in link ``g`` (direction ``d̄ =
  R_g·d̄_g``, through ``R_g·ḡ``): the relative angle ``θ_s − θ_g − δ = 0`` and the slider point
  on the line, ``d̄ × (r̄_s + R_s·s̄ − r̄_g − R_g·ḡ) = 0``;
- a gear pair's mesh, link ``b`` turned at ``k`` times link ``a`` about their ground pivots:
  one row, the pitch circles rolling at the pitch point (:class:`~.constraints.Mesh`);
- a driver per input ``i``: ``θ_input_i − θ_ground − θ_i = 0`` (a one-input linkage's
  ``θ1``).

A linkage with ``m`` inputs is accepted when it has exactly ``m`` degrees of freedom (``3·n``
coordinates, ``3·n − m`` independent constraints) and its reference pose is regular: the
constraints' Jacobian has full rank, and with the drivers' rows it is invertible (the inputs
drive every link).

Assur groups. Starting from the ground and the inputs, the links are found in groups that,
given the links found before, have no freedom left: dyads (two links, three joints) in closed
form — RRR (two circles), RRP and PRR (a circle and a line), RPR (the angle of a line through a
point) —, a geared link by its pivot and its driver's angle, and any other group (a triad of
a Stephenson chain) by Newton's method. The same order solves velocities, accelerations and,
in reverse, the joint forces (kinetostatics).
"""

from __future__ import annotations

import itertools
import math
import threading
from collections import OrderedDict
from collections.abc import Sequence
from dataclasses import dataclass, field, replace
from typing import Any

import numpy as np
from numpy.typing import NDArray

from ..errors import SpecError
from ..model import GROUND, Linkage
from .constraints import (
    GROUND_INDEX,
    Driver,
    Group,
    Mesh,
    Pin,
    Prism,
    SlideDriver,
    pose_of,
    unit,
)
from .dyads import dyad_branch
from .vectors import V

#: Singular values below this share of the largest (columns in common units) make the
#: reference pose's Jacobian singular.
RANK_TOLERANCE = 1e-10
#: Geometries whose structures are kept (:meth:`Structure.of`): a sweep's point and its
#: redesign share one; the least recently used goes.
SKELETONS = 64
_SKELETONS: OrderedDict[Any, Structure] = OrderedDict()
_SKELETON_LOCK = threading.Lock()


@dataclass(frozen=True)
class Structure:
    """A linkage as equations: frames, constraints, groups (see the module docstring).

    Build it with :meth:`of`; that checks mobility and the reference pose.

    Attributes
    ----------
    linkage
        The model.
    names
        Names of the moving links; link ``k`` is ``names[k]``.
    local
        ``(link, point) → p̄``: each point in the frame of each link that carries it (the
        ground's points in the spec's frame).
    ref_angle, ref_origin
        Each moving link's frame at the reference pose: angle (rad, principal value) and
        origin.
    pins, prisms, meshes
        The joints as constraints (a mesh per gear pair).
    drivers
        The inputs' drivers, in the order of the linkage's inputs.
    groups
        The order in which the links are found, the inputs' groups first.
    """

    linkage: Linkage
    names: tuple[str, ...]
    local: dict[tuple[int, str], V]
    ref_angle: tuple[float, ...]
    ref_origin: tuple[V, ...]
    pins: tuple[Pin, ...]
    prisms: tuple[Prism, ...]
    drivers: tuple[Driver | SlideDriver, ...]
    groups: tuple[Group, ...]
    meshes: tuple[Mesh, ...]
    point_links: dict[str, tuple[int, ...]] = field(repr=False)
    #: Results computed once per structure.
    cache: dict[str, Any] = field(default_factory=dict, repr=False, compare=False)
    #: What depends on the geometry alone — the assembly range, the numeric groups'
    #: continuation tables, motions at a few crank states — shared by every structure of the
    #: same geometry (a design and its redesign, which changes masses only: :meth:`of`).
    kinematic: dict[str, Any] = field(default_factory=dict, repr=False, compare=False)

    @property
    def size(self) -> int:
        """Number of moving links ``n``."""
        return len(self.names)

    @property
    def inputs(self) -> tuple[int, ...]:
        """Indices of the input links, in the order of the linkage's inputs."""
        return tuple(d.link for d in self.drivers)

    @property
    def input(self) -> int:
        """A one-input linkage's input link (its crank); ``ValueError`` for several."""
        if len(self.drivers) != 1:
            raise ValueError(f"the linkage has {len(self.drivers)} inputs, not one")
        return self.drivers[0].link

    @property
    def constraints(self) -> tuple[Pin | Prism | Mesh, ...]:
        """All constraints but the drivers (``3·n − m`` rows for ``m`` inputs)."""
        return (*self.pins, *self.prisms, *self.meshes)

    def index(self, name: str) -> int:
        """Index of the link called ``name`` (``-1`` for the ground)."""
        return GROUND_INDEX if name == GROUND else self.names.index(name)

    def point_position(self, point: str) -> V:
        """A point's position at the reference pose."""
        return V.of(self.linkage.point_positions[point])

    # -- building -----------------------------------------------------------------------------

    @classmethod
    def of(cls, linkage: Linkage, lengths: dict[str, float] | None = None) -> Structure:
        """The structure of ``linkage``; raises :class:`SpecError` if it is not a valid one.

        ``lengths`` gives, by link, the exact distance from its first point to its second
        (a four-bar's lengths, which its reference pose's positions carry only to rounding).

        Raises
        ------
        SpecError
            If the mobility is not the number of inputs (naming it and how it is counted), the
            reference pose is singular or the inputs do not drive the linkage there, or no
            order of groups finds every link.
        """
        key = (linkage.points, tuple((b.name, b.points) for b in linkage.bodies),
               linkage.sliders, linkage.inputs, linkage.gears,
               tuple(sorted((lengths or {}).items())))
        with _SKELETON_LOCK:
            known = _SKELETONS.get(key)
            if known is not None:
                _SKELETONS.move_to_end(key)
        if known is not None:  # the same geometry: its equations, with this design's links
            return replace(known, linkage=linkage, cache={})
        structure = cls._build(linkage, lengths)
        with _SKELETON_LOCK:
            _SKELETONS[key] = structure
            while len(_SKELETONS) > SKELETONS:
                _SKELETONS.popitem(last=False)
        return structure

    @classmethod
    def _build(cls, linkage: Linkage, lengths: dict[str, float] | None) -> Structure:
        """:meth:`of` from the linkage's points, bodies and sliders."""
        names = linkage.link_names
        index = {name: k for k, name in enumerate(names)}
        index[GROUND] = GROUND_INDEX
        positions = linkage.point_positions
        sliders_of = {s.link: s for s in linkage.sliders}
        ref_angle: list[float] = []
        ref_origin: list[V] = []
        local: dict[tuple[int, str], V] = {}
        for body in linkage.moving:
            k = index[body.name]
            origin = positions[body.points[0]]
            if len(body.points) > 1:
                axis = positions[body.points[1]] - origin
            else:
                axis = complex(*sliders_of[body.name].direction)
            angle = math.atan2(axis.imag, axis.real)
            ref_angle.append(angle)
            ref_origin.append(V.of(origin))
            turn = complex(math.cos(angle), -math.sin(angle))
            for i, p in enumerate(body.points):
                if i == 1:  # on the frame's x-axis: exactly
                    exact = (lengths or {}).get(body.name)
                    local[(k, p)] = V(abs(positions[p] - origin) if exact is None else exact,
                                      0.0)
                else:
                    local[(k, p)] = V.of((positions[p] - origin) * turn)
        for p in linkage.ground.points:
            local[(GROUND_INDEX, p)] = V.of(positions[p])
        point_links: dict[str, list[int]] = {}
        for body in linkage.bodies:
            for p in body.points:
                point_links.setdefault(p, []).append(index[body.name])
        pins = []
        for p, links in point_links.items():
            if len(links) < 2:
                continue
            partner = GROUND_INDEX if GROUND_INDEX in links else links[0]
            for k in links:
                if k != partner:
                    pins.append(Pin(p, k, local[(k, p)], partner, local[(partner, p)]))
        prisms = []
        for i, s in enumerate(linkage.sliders):
            ks, kg = index[s.link], index[s.guide]
            theta_g = 0.0 if kg == GROUND_INDEX else ref_angle[kg]
            theta_s = ref_angle[ks]
            d = unit(*s.direction)
            rot_g = complex(math.cos(theta_g), -math.sin(theta_g))
            origin_g = 0j if kg == GROUND_INDEX else ref_origin[kg].complex()
            prisms.append(Prism(
                slider=i, s=ks, ps=local[(ks, s.point)], g=kg,
                pg=V.of((positions[s.point] - origin_g) * rot_g), dg=V.of(d * rot_g),
                delta=theta_s - theta_g))
        drivers = tuple(_driver(linkage, index[name], i, pins, prisms)
                        for i, name in enumerate(linkage.inputs))
        meshes = []
        for gear in linkage.gears:
            a, b = index[gear.driver], index[gear.driven]
            pivot_a, pivot_b = (linkage.moving[k].points[0] for k in (a, b))
            meshes.append(Mesh(gear.name, a, local[(a, pivot_a)], V.of(positions[pivot_a]),
                               b, local[(b, pivot_b)], V.of(positions[pivot_b]),
                               gear.ratio, ref_angle[a], ref_angle[b]))
        structure = cls(
            linkage=linkage, names=names, local=local, ref_angle=tuple(ref_angle),
            ref_origin=tuple(ref_origin), pins=tuple(pins), prisms=tuple(prisms),
            drivers=drivers, groups=(), meshes=tuple(meshes),
            point_links={p: tuple(v) for p, v in point_links.items()})
        structure._check_mobility()
        object.__setattr__(structure, "groups", structure._find_groups())
        return structure

    def _check_mobility(self) -> None:
        n = self.size
        rows = sum(c.rows for c in self.constraints)
        joints = len(self.pins)
        mobility = 3 * n - rows
        count = len(self.drivers)
        if mobility != count:
            driven = ("the input must drive every link" if count == 1 else
                      f"one per input ({', '.join(self.linkage.inputs)}): the inputs must "
                      "drive every link")
            raise SpecError(
                f"the linkage has {mobility} degrees of freedom, not {count}: {n} moving "
                f"links (3·{n} = {3 * n} coordinates) less {joints} revolute pairs and "
                f"{len(self.prisms)} prismatic pairs (2 each)"
                + (f" and {len(self.meshes)} gear pairs (1 each)" if self.meshes else "")
                + f" — {driven}, and nothing may be locked", key="mechanism", value=mobility)
        # Rows and columns in common units: angle rows (a prism's, the drivers') times a
        # length, angle columns over it.
        scale = self.length_scale()
        full = np.vstack([self.jacobian(self.reference_coordinates()), self.driver_rows()])
        kinds = [*self.row_kinds(), *(d.row_kinds[0] for d in self.drivers)]
        full[[i for i, kind in enumerate(kinds) if kind == "angle"]] *= scale
        full[:, 2::3] /= scale
        sv = np.linalg.svd(full[:-count], compute_uv=False)
        if sv.size and sv[-1] <= RANK_TOLERANCE * sv[0]:
            raise SpecError(
                "the reference pose is singular (joints in line: a dead point, a change point "
                "or a locked position) or the linkage has redundant constraints; move the "
                "points to a regular pose of the same assembly",
                key="mechanism.points")
        sv = np.linalg.svd(full, compute_uv=False)
        if sv[-1] <= RANK_TOLERANCE * sv[0]:
            if count == 1:
                raise SpecError(
                    "the input does not drive the linkage at the reference pose (turning it "
                    "would not move the others, or they could move without it)",
                    key="mechanism.input", value=self.linkage.inputs[0])
            raise SpecError(
                "the inputs do not drive the linkage at the reference pose (some links could "
                "move with every input held, or the inputs cannot be turned independently)",
                key="mechanism.inputs", value=list(self.linkage.inputs))

    def row_kinds(self) -> list[str]:
        """``"length"`` or ``"angle"`` for each row of :meth:`jacobian`."""
        out: list[str] = []
        for c in self.constraints:
            out += c.row_kinds
        return out

    def length_scale(self) -> float:
        """The largest distance between points, m (a common unit for angles)."""
        pts = np.array(list(self.linkage.point_positions.values()))
        span = float(np.max(np.abs(pts[:, None] - pts[None, :]))) if pts.size > 1 else 0.0
        return span if span > 0 else 1.0

    # -- groups -------------------------------------------------------------------------------

    def _closing(self, group: set[int], known: set[int]) -> list[Pin | Prism] | None:
        """The constraints that close ``group`` given ``known`` links, if it is a group.

        Attachments of a group link at a point to a known link there (the ground first), pairs
        within the group at a point with no known link, prismatic pairs among group and known
        links. ``None`` unless their rows equal the group's coordinates and every link takes
        part.
        """
        out: list[Pin | Prism] = []
        for p, links in self.point_links.items():
            inside = [k for k in links if k in group]
            if not inside:
                continue
            outside = [k for k in links if k in known]
            if outside:
                partner = GROUND_INDEX if GROUND_INDEX in outside else outside[0]
                out += [Pin(p, k, self.local[(k, p)], partner, self.local[(partner, p)])
                        for k in inside]
            elif len(inside) > 1:
                out += [Pin(p, k, self.local[(k, p)], inside[0], self.local[(inside[0], p)])
                        for k in inside[1:]]
        for c in self.prisms:
            if (c.s in group or c.g in group) and {c.s, c.g} <= group | known:
                out.append(c)
        rows = sum(c.rows for c in out)
        touched: set[int] = set()
        for joint in out:
            touched |= set(joint.members)
        if rows != 3 * len(group) or not group <= touched:
            return None
        return out

    def _find_groups(self) -> tuple[Group, ...]:
        known = {GROUND_INDEX, *self.inputs}
        groups = []
        several = len(self.drivers) > 1
        for driver in self.drivers:
            own = driver.own_group(self.pins, self.linkage.moving[driver.link].points[0])
            if own is None:
                raise SpecError(
                    "the input must be pinned to the ground at its first point",
                    key="mechanism.inputs" if several else "mechanism.input",
                    value=list(self.linkage.inputs) if several else self.linkage.inputs[0])
            groups.append(own)
        unknown = set(range(self.size)) - known
        q_ref = self.reference_coordinates()
        while unknown:
            geared = self._geared(known)
            if geared is not None:
                groups.append(geared)
                known.add(geared.links[0])
                unknown.discard(geared.links[0])
                continue
            found: tuple[tuple[int, ...], list[Pin | Prism]] | None = None
            for size in range(2, len(unknown) + 1):
                for combo in itertools.combinations(sorted(unknown), size):
                    closing = self._closing(set(combo), known)
                    if closing is not None:
                        found = (combo, closing)
                        break
                if found:
                    break
            if found is None:
                raise SpecError(
                    "the links cannot be found one group after another from the "
                    f"{'inputs' if several else 'input'}: "
                    f"{', '.join(self.names[k] for k in sorted(unknown))} are not determined "
                    f"by the {'inputs' if several else 'input'}", key="mechanism")
            combo, closing = found
            groups.append(self._classify(combo, closing, q_ref))
            known |= set(combo)
            unknown -= set(combo)
        return tuple(groups)

    def _geared(self, known: set[int]) -> Group | None:
        """A link turned by a gear pair whose driver is known: its pivot and its mesh."""
        for mesh in self.meshes:
            if mesh.a in known and mesh.b not in known:
                pivot = next(c for c in self.pins if c.a == mesh.b and c.b == GROUND_INDEX
                             and c.point == self.linkage.moving[mesh.b].points[0])
                return Group((mesh.b,), (pivot, mesh), "geared")
        return None

    def _classify(self, links: tuple[int, ...], closing: list[Pin | Prism],
                  q_ref: NDArray[np.float64]) -> Group:
        """A dyad of a kind solved in closed form, with its branch; else a numeric group."""
        if len(links) != 2 or len(closing) != 3:
            return Group(links, tuple(closing), "numeric")
        a, b = links

        def between(c: Pin | Prism, x: int, y: int) -> bool:
            return set(c.members) == {x, y}

        middle = [c for c in closing if between(c, a, b)]
        ends_a = [c for c in closing if not between(c, a, b) and _touches(c, a)]
        ends_b = [c for c in closing if not between(c, a, b) and _touches(c, b)]
        if len(middle) != 1 or len(ends_a) != 1 or len(ends_b) != 1:
            return Group(links, tuple(closing), "numeric")
        j1, j2, j3 = ends_a[0], middle[0], ends_b[0]
        kind = "".join(c.letter for c in (j1, j2, j3))
        if kind == "PRR":  # the mirror of RRP: name the links the other way round
            a, b, j1, j3 = b, a, j3, j1
            kind = "RRP"
        if kind not in ("RRR", "RRP", "RPR"):
            return Group(links, tuple(closing), "numeric")
        if kind in ("RRR", "RRP") and _pin_offset(j1, a) == _pin_offset(j2, a):
            return Group(links, tuple(closing), "numeric")  # a degenerate arm: no circle
        group = Group((a, b), (j1, j2, j3), kind)
        # The branch is read off the reference pose.
        return Group((a, b), (j1, j2, j3), kind, dyad_branch(group, q_ref))

    # -- equations ----------------------------------------------------------------------------

    def reference_coordinates(self) -> NDArray[np.float64]:
        """``q`` at the reference pose: ``(x, y, θ)`` per moving link, shape ``(3n,)``."""
        q = np.empty(3 * self.size)
        for k in range(self.size):
            q[3 * k : 3 * k + 2] = self.ref_origin[k].x, self.ref_origin[k].y
            q[3 * k + 2] = self.ref_angle[k]
        return q

    def driver_rows(self) -> NDArray[np.float64]:
        """The drivers' Jacobian rows at the reference pose, shape ``(m, 3n)`` (``m`` inputs)."""
        rows = np.zeros((len(self.drivers), 3 * self.size))
        pose = pose_of(self.reference_coordinates())
        for i, d in enumerate(self.drivers):
            for link, coeffs in d.jacobian(pose):
                if link != GROUND_INDEX:
                    rows[i, 3 * link : 3 * link + 3] += [float(x) for x in coeffs[0]]
        return rows

    @property
    def input_references(self) -> tuple[float, ...]:
        """Each input's position at the reference pose, in the order of the linkage's inputs.

        An angle (rad), or a place along its slide (m).
        """
        pose = pose_of(self.reference_coordinates())
        return tuple(float(d.position(pose)) for d in self.drivers)

    def jacobian(self, q: NDArray[np.float64]) -> NDArray[np.float64]:
        """The constraints' Jacobian at one pose ``q``, shape ``(3n − 1, 3n)``."""
        rows = []
        pose = pose_of(q)
        for c in self.constraints:
            block = np.zeros((c.rows, 3 * self.size))
            for link, coeffs in c.jacobian(pose):
                if link != GROUND_INDEX:
                    block[:, 3 * link : 3 * link + 3] += np.array(
                        [[float(x) for x in row] for row in coeffs])
            rows.append(block)
        return np.vstack(rows) if rows else np.zeros((0, 3 * self.size))


def _driver(linkage: Linkage, k: int, i: int, pins: Sequence[Pin], prisms: Sequence[Prism]
            ) -> Driver | SlideDriver:
    """Input ``i``'s driver: about link ``k``'s ground pivot, or along its ground slide.

    A link pinned to the ground turns about its pivot; one that slides on a ground guide and
    is pinned to none is driven along it (a linkage with several inputs: its verbs run along
    motions, not a crank's revolution).

    Raises
    ------
    SpecError
        If a slide is the only input.
    """
    pinned = any(GROUND_INDEX in c.members and k in c.members for c in pins)
    slide = [p for p in prisms if p.s == k and p.g == GROUND_INDEX]
    if pinned or not slide:
        return Driver(k, i)
    if len(linkage.inputs) < 2:
        raise SpecError(
            "a linkage driven along a slide alone is not turned by a crank: name it with the "
            "other inputs of a linkage with several (inputs = [...]), whose verbs run along "
            "its motions", key="mechanism.input", value=linkage.inputs[0])
    return SlideDriver(k, i, slide[0])


def _touches(c: Pin | Prism, k: int) -> bool:
    return k in c.members


def _pin_offset(c: Pin | Prism, k: int) -> tuple[float, float] | None:
    """The local point by which pin ``c`` holds link ``k`` (``None`` for a prism)."""
    p = c.held_at(k)
    return None if p is None else (p.x, p.y)
