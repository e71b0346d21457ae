"""Inverse dynamics of a general linkage: joint forces, forces on the ground, driving torque.

With the motion prescribed, each moving link ``k`` obeys ``Σ_c Φ_{c,k}ᵀ·λ_c = E_k`` over the
constraints ``c`` that touch it, with ``λ_c`` their multipliers and ``E_k = Q_k − I_k`` the
applied generalized forces less the inertial ones, in the link's coordinates ``(x, y, θ)``:

``I_k = [m·r̈ + (α·J − ω²)·R·(m·s̄),  J_O·α + (R·m·s̄) × r̈]``  (``J_O`` about the frame's origin)

``Q_k = [m·ḡ + F̄,  (R·m·s̄) × ḡ + (R·s̄) × F̄ + M]`` plus springs, slider forces and, for a link
with a counter-rotor ``J_c``, ``−J_c·α`` on ``θ``.

Both are linear in the inertial parameters ``π_k = (m, m·e, m·f, J_O)`` but for the applied
force's moment (a force at a centre of mass that moves with the design): that part and springs
and slider forces are a constant column.

The groups of :mod:`.structure` are solved in reverse order: a group's ``λ`` from its own
links' equations (``Φ_SSᵀ·λ_S = E_S −`` what later groups put on them), then its constraints'
forces are put on the links found before it. A constraint's generalized force on the ground
(``−Φ_{c,ground}ᵀ·λ_c``, with the ground as a link at rest at the spec's origin) is the force
and the moment about the origin that the mechanism exerts on the frame there; the driver's is
the motor's reaction, ``−τ``.

Every result is computed for several columns of ``E`` at once: one for a given design, or one
per inertial parameter (and one for the constant part) for the regressors.
"""

from __future__ import annotations

from collections.abc import Iterable, Sequence
from dataclasses import dataclass, field
from typing import Literal, TypeAlias

import numpy as np
from numpy.typing import NDArray

from ..model import GROUND, Linkage
from . import rotors
from .constraints import (
    GROUND_INDEX,
    Blocks,
    Constraint,
    FrameTally,
    Pose,
)
from .inputs import InputState
from .kinematics import Motion, rates
from .structure import Structure
from .vectors import NUMPY, Num, OpsLike, V, _plus, _times

#: Parameters of a link in the design vector, in order: kg, kg·m, kg·m, kg·m² (about the frame's
#: origin).
LINK_PARAMETERS = ("m", "me", "mf", "J")


@dataclass(frozen=True)
class Layout:
    """The design vector of a general linkage, by name.

    Entries ``(link, "m")``, ``(link, "me")``, ``(link, "mf")``, ``(link, "J")`` per moving link
    (mass, first moments in the link's frame, inertia about its frame's origin), then
    ``(link, "Jc")`` per link pivoted to the ground (its counter-rotor's inertia).
    """

    entries: tuple[tuple[str, str], ...]

    @classmethod
    def of(cls, structure: Structure) -> Layout:
        """The layout of a linkage: its links in the spec's order, then the counter-rotors."""
        links = [(name, p) for name in structure.names for p in LINK_PARAMETERS]
        rotors = [(name, "Jc") for name in structure.linkage.grounded_links]
        return cls(entries=tuple(links + rotors))

    @property
    def size(self) -> int:
        """Number of entries."""
        return len(self.entries)

    def index(self, link: str, quantity: str) -> int:
        """Position of an entry."""
        return self.entries.index((link, quantity))

    def link_slice(self, link: str) -> slice:
        """The four entries of a link."""
        start = self.index(link, "m")
        return slice(start, start + 4)

    def rotor(self, link: str) -> int | None:
        """Position of a link's counter-rotor entry, or ``None``."""
        try:
            return self.index(link, "Jc")
        except ValueError:
            return None

    def vector(self, linkage: Linkage) -> NDArray[np.float64]:
        """The design vector of a model's links (its mass properties)."""
        x = np.zeros(self.size)
        for name, link in zip(linkage.link_names, linkage.links, strict=True):
            s = self.link_slice(name)
            x[s] = link.inertial_parameters
            r = self.rotor(name)
            if r is not None:
                x[r] = link.counter_rotor
        return x


@dataclass(frozen=True, eq=False)
class Forces:
    """Inverse dynamics at arrays of crank states, for ``C`` columns (designs or parameters).

    Every array has shape ``(N, C)`` (a scalar CasADi symbol each in the program of
    :mod:`.program`).

    Attributes
    ----------
    reactions
        Force of the mechanism on the ground at each ground point (the sum over the moving
        links pinned there), N.
    slider_normal, slider_couple
        For each slider whose guide is the ground: the normal force (N) and the couple (N·m)
        its link exerts on the guide; keyed by the sliding link's name.
    input_torques
        Torque of each motor on its input, N·m, in the order of the linkage's inputs
        (:attr:`driving_torque`: a one-input linkage's).
    shaking_force
        Sum of all forces of the mechanism on the ground (springs and slider forces anchored
        on it included), N.
    shaking_moment
        Their moment about the spec's origin with the motor's reaction and the counter-rotors,
        N·m.
    rocking_couple
        The couple about ``x`` and ``y`` on the frame from links in planes along the crank's
        axis (:func:`rocking_couple`), N·m; zero for a mechanism in one plane.
    teeth
        Each gear pair's tooth force on its driven gear at the pitch point, N, by the pair's
        name (internal to the machine: it reaches the frame through the gears' pivots).
    """

    reactions: dict[str, V]
    slider_normal: dict[str, Num]
    slider_couple: dict[str, Num]
    input_torques: tuple[Num, ...]
    shaking_force: V
    shaking_moment: Num
    rocking_couple: V
    teeth: dict[str, V] = field(default_factory=dict)

    @property
    def driving_torque(self) -> Num:
        """A one-input linkage's motor torque on its crank, N·m (``ValueError`` for several)."""
        if len(self.input_torques) != 1:
            raise ValueError(f"the forces have {len(self.input_torques)} input torques, not one")
        return self.input_torques[0]

    def arrays(self) -> list[Num]:
        """Every figure in one fixed order (what :meth:`with_arrays` reads back).

        Each input's torque, shaking force ``x`` and ``y``, shaking moment, rocking couple
        ``x`` and ``y``; each ground point's reaction ``x`` and ``y``, by name; each ground
        slider's normal force and couple, by name.
        """
        out = [*self.input_torques, self.shaking_force.x, self.shaking_force.y,
               self.shaking_moment, self.rocking_couple.x, self.rocking_couple.y]
        for p in sorted(self.reactions):
            out += [self.reactions[p].x, self.reactions[p].y]
        for k in sorted(self.slider_normal):
            out += [self.slider_normal[k], self.slider_couple[k]]
        for g in sorted(self.teeth):
            out += [self.teeth[g].x, self.teeth[g].y]
        return out

    def matching(self, names: Forces) -> Forces:
        """These forces' figures at ``names``' ground points and sliders (the same arrays).

        Raises
        ------
        KeyError
            If ``names`` has a ground point or slider these forces have not.
        """
        return Forces(reactions={p: self.reactions[p] for p in names.reactions},
                      slider_normal={k: self.slider_normal[k] for k in names.slider_normal},
                      slider_couple={k: self.slider_couple[k] for k in names.slider_couple},
                      input_torques=self.input_torques, shaking_force=self.shaking_force,
                      shaking_moment=self.shaking_moment, rocking_couple=self.rocking_couple,
                      teeth={g: self.teeth[g] for g in names.teeth})

    def with_arrays(self, values: Sequence[Num]) -> Forces:
        """Forces with the same names holding ``values`` in :meth:`arrays`' order."""
        points, sliders = sorted(self.reactions), sorted(self.slider_normal)
        m = len(self.input_torques)
        base = m + 5
        at = base + 2 * len(points)
        teeth = at + 2 * len(sliders)
        return Forces(
            reactions={p: V(values[base + 2 * i], values[base + 1 + 2 * i])
                       for i, p in enumerate(points)},
            slider_normal={k: values[at + 2 * i] for i, k in enumerate(sliders)},
            slider_couple={k: values[at + 2 * i + 1] for i, k in enumerate(sliders)},
            input_torques=tuple(values[:m]), shaking_force=V(values[m], values[m + 1]),
            shaking_moment=values[m + 2], rocking_couple=V(values[m + 3], values[m + 4]),
            teeth={g: V(values[teeth + 2 * i], values[teeth + 1 + 2 * i])
                   for i, g in enumerate(sorted(self.teeth))})


def _col(x: Num, n: int, c: int) -> NDArray[np.float64]:
    """``x`` (a scalar, ``(N,)`` or ``(N, C)``) as an ``(N, C)`` array."""
    a = np.asarray(x, dtype=float)
    if a.ndim == 1:
        a = a[:, None]
    return np.broadcast_to(a, (n, c))


#: A link's generalized force: force ``x``, ``y`` and moment about its frame's origin.
Generalized: TypeAlias = tuple[Num, Num, Num]


def inertial_columns(structure: Structure, mo: Motion, gravity: V
                     ) -> dict[str, list[tuple[str, Generalized]]]:
    """``−(I_k − gravity_k)`` per unit inertial parameter: the regressors' ``E_k`` columns.

    Returns ``{link: [(param, (Ex, Ey, Eθ))]}`` with each component an ``(N,)`` array; params
    ``m``, ``me``, ``mf``, ``J`` and, for a grounded link, ``Jc``.
    """
    out: dict[str, list[tuple[str, Generalized]]] = {}
    grounded = set(structure.linkage.grounded_links)
    for k, name in enumerate(structure.names):
        c, s = mo.pose.cos[k], mo.pose.sin[k]
        w, a = mo.rate[k], mo.accel[k]
        acc = mo.acceleration[k] - gravity  # r̈ − ḡ
        ex, ey = V(c, s), V(-s, c)  # the frame's axes
        cols: list[tuple[str, Generalized]] = [("m", (-acc.x, -acc.y, 0.0 * w))]
        for p, axis in (("me", ex), ("mf", ey)):
            lin = axis.perp() * a - axis * (w * w)  # (α·J − ω²)·R·ê
            cols.append((p, (-lin.x, -lin.y, -axis.cross(acc))))
        cols.append(("J", (0.0 * w, 0.0 * w, -a)))
        if name in grounded:
            cols.append(("Jc", (0.0 * w, 0.0 * w, -a)))  # the rotor's reaction on its link
        out[name] = cols
    return out


def applied_column(structure: Structure, mo: Motion, gravity: V, loads: bool = True,
                   ops: OpsLike = NUMPY, gas: list[Num] | None = None
                   ) -> tuple[list[tuple[Num, ...]], tuple[Num, ...]]:
    """The part of ``E`` that is not linear in the inertial parameters, and its share on the ground.

    Applied forces at the centres of mass and moments, springs, slider forces.

    Returns ``(per_link, ground)``: ``per_link[k] = (Ex, Ey, Eθ)``, ``ground = (Fx, Fy, Mz)``
    (arrays ``(N,)``; ``Mz`` about the origin). On symbols (``ops`` CasADi's), ``gas`` gives
    each prismatic pair's slider force along its guide (N), instead of its table.
    """
    zero: Num
    per: list[list[Num]]
    ground: list[Num]
    if ops is NUMPY:
        zero = np.zeros(mo.count)
        per = [[zero.copy(), zero.copy(), zero.copy()] for _ in structure.names]
        ground = [zero.copy(), zero.copy(), zero.copy()]
    else:
        zero = 0.0
        per = [[0.0, 0.0, 0.0] for _ in structure.names]
        ground = [0.0, 0.0, 0.0]

    def put(k: int, at: V, f: V) -> None:
        if k == GROUND_INDEX:
            ground[0] += f.x
            ground[1] += f.y
            ground[2] += at.cross(f)
            return
        arm = at - mo.pose.origin(k)
        per[k][0] += f.x
        per[k][1] += f.y
        per[k][2] += arm.cross(f)

    linkage = structure.linkage
    if loads:
        for k, link in enumerate(linkage.links):
            if link.has_loads:
                com = mo.point(k, V(link.e, link.f))
                put(k, com, V(*link.force) + V(zero, zero))
                per[k][2] += link.moment
    for spring in linkage.springs:
        (pa, ka), (pb, kb) = (_carrier(structure, p) for p in spring.points)
        a, b = mo.point(ka, pa), mo.point(kb, pb)
        d = b - a
        length = ops.sqrt(d.norm2())
        tension = spring.stiffness * (length - spring.free_length)
        with np.errstate(divide="ignore", invalid="ignore"):
            unit = d / length
        put(ka, a, unit * tension)
        put(kb, b, unit * (-tension))
    if loads:
        for j, c in enumerate(structure.prisms):
            table = linkage.sliders[c.slider].force
            if table.is_zero:
                continue
            value = (np.asarray(table.at(mo.theta1), dtype=float) if gas is None
                     else gas[j])
            d = mo.pose.rotate(c.g, c.dg)
            at = mo.point(c.s, c.ps)
            put(c.s, at, d * value)
            put(c.g, at, d * (-value))
    return [tuple(x) for x in per], tuple(ground)


def _carrier(structure: Structure, point: str) -> tuple[V, int]:
    """A point's local coordinates in a link that carries it (the ground first)."""
    links = structure.point_links[point]
    k = GROUND_INDEX if GROUND_INDEX in links else links[0]
    return structure.local[(k, point)], k


def kinetostatics(structure: Structure, mo: Motion, effective: list[list[Num]],
                  rotor_moment: Num | None = None,
                  ground_extra: tuple[Num, ...] | None = None, ops: OpsLike = NUMPY,
                  rocking: V | None = None) -> Forces:
    """Solve the groups in reverse order for given ``E`` columns (see the module docstring).

    Parameters
    ----------
    structure, mo
        The linkage and its motion (``N`` crank states).
    effective
        ``E_k`` per link: three arrays ``(N, C)`` (force x, force y, moment about the origin
        of the link's frame).
    rotor_moment
        The counter-rotors' moment on the ground, ``(N, C)`` (``+2·J_c·α`` summed).
    ground_extra
        Forces and moment on the ground not through joints (springs, slider forces): three
        ``(N, C)`` arrays.
    ops
        Elementary functions: numpy (the default), or CasADi's for one design on symbols
        (every entry then a scalar symbol, :mod:`balancer.linkage.program`).
    rocking
        The rocking couple (:func:`rocking_couple`), as the columns of ``effective``; none:
        zero.
    """
    numeric = ops is NUMPY
    if numeric:
        n, c_count = effective[0][0].shape if effective else (mo.count, 1)
        applied = [[np.array(e, dtype=float, copy=True) for e in row] for row in effective]
        zero: Num = np.zeros((n, c_count))
    else:
        applied = [list(row) for row in effective]
        zero = 0.0
    lam: dict[int, list[Num]] = {}
    ground_of: dict[int, list[Num]] = {}
    for g in reversed(structure.groups):
        index = {link: i for i, link in enumerate(g.links)}
        k = 3 * len(g.links)
        mat: list[list[Num]] = [[0.0] * k for _ in range(k)]  # Φ_SSᵀ, entries floats or (N,)
        rhs = [[applied[link][j]] for link in g.links for j in range(3)]
        blocks_of: list[tuple[Constraint, int, Blocks]] = []
        row = 0
        for c in g.constraints:
            blocks = c.jacobian(mo.pose)
            blocks_of.append((c, row, blocks))
            for link, coeffs in blocks:
                if link in index:
                    for r in range(c.rows):
                        for j in range(3):
                            mat[3 * index[link] + j][row + r] = _plus(
                                mat[3 * index[link] + j][row + r], coeffs[r][j])
            row += c.rows
        with np.errstate(divide="ignore", invalid="ignore"):
            solved = ops.factor(mat).solve(rhs)
        for c, row, blocks in blocks_of:
            values = [solved[row + r][0] for r in range(c.rows)]  # (N, C) each, or symbols
            lam[id(c)] = values
            for link, coeffs in blocks:
                if link in index:
                    continue
                force = [_sum(_times(coeffs[r][j], values[r]) for r in range(c.rows))
                         for j in range(3)]  # Φᵀ·λ on the known link's coordinates
                if link == GROUND_INDEX:
                    ground_of[id(c)] = [-f for f in force]
                else:
                    for j in range(3):
                        applied[link][j] = applied[link][j] - force[j]
    constraints = [c for g in structure.groups for c in g.constraints]
    return _collect(structure, constraints, lam, ground_of, zero, rotor_moment, ground_extra,
                    rocking)


def _sum(terms: Iterable[Num]) -> Num:
    """The sum of ``terms``, structural zeros (the float 0.0) skipped."""
    total: Num = 0.0
    for t in terms:
        total = _plus(total, t)
    return total


def global_kinetostatics(structure: Structure, mo: Motion, effective: list[list[Num]],
                         rotor_moment: Num | None = None,
                         ground_extra: tuple[Num, ...] | None = None,
                         rocking: V | None = None) -> Forces:
    """The same forces from all the links' equations at once: ``Φ_qᵀ·λ = E``.

    One ``3n × 3n`` solve per crank state over every constraint and the driver (the pairs of
    :attr:`Structure.pins`, not the groups'), instead of the groups one after another: an
    independent route to the same forces on the ground.
    """
    n, c_count = effective[0][0].shape
    size = 3 * structure.size
    constraints: list[Constraint] = [*structure.constraints, *structure.drivers]
    mat = np.zeros((n, size, size))
    rhs = np.zeros((n, size, c_count))
    for k in range(structure.size):
        for j in range(3):
            rhs[:, 3 * k + j, :] = effective[k][j]
    row = 0
    blocks_of: list[tuple[Constraint, int, Blocks]] = []
    for c in constraints:
        blocks = c.jacobian(mo.pose)
        blocks_of.append((c, row, blocks))
        for link, coeffs in blocks:
            if link == GROUND_INDEX:
                continue
            for r in range(c.rows):
                for j in range(3):
                    mat[:, 3 * link + j, row + r] += coeffs[r][j]
        row += c.rows
    with np.errstate(divide="ignore", invalid="ignore"):
        try:
            sol = np.linalg.solve(mat, rhs)
        except np.linalg.LinAlgError:
            sol = np.full((n, size, c_count), np.nan)
            ok = np.abs(np.linalg.det(mat)) > 0
            if ok.any():
                sol[ok] = np.linalg.solve(mat[ok], rhs[ok])
    lam: dict[int, list[Num]] = {}
    ground_of: dict[int, list[Num]] = {}
    for c, row, blocks in blocks_of:
        values = [sol[:, row + r, :] for r in range(c.rows)]
        lam[id(c)] = values
        for link, coeffs in blocks:
            if link == GROUND_INDEX:
                ground_of[id(c)] = [-_sum(_times(coeffs[r][j], values[r])
                                          for r in range(c.rows)) for j in range(3)]
    return _collect(structure, constraints, lam, ground_of, np.zeros((n, c_count)),
                    rotor_moment, ground_extra, rocking)


def _collect(structure: Structure, constraints: Sequence[Constraint],
             lam: dict[int, list[Num]], ground_of: dict[int, list[Num]], zero: Num,
             rotor_moment: Num | None, ground_extra: tuple[Num, ...] | None,
             rocking: V | None = None) -> Forces:
    """The forces on the ground from the constraints' multipliers.

    ``zero`` fills what no constraint puts there: an ``(N, C)`` array, or the float 0.0 on
    symbols.
    """
    frame = FrameTally(zero)
    fx: Num = zero
    fy: Num = zero
    mz: Num = zero
    for c in constraints:
        force = ground_of.get(id(c))  # (None: between moving links; a driver's always there)
        if force is not None:
            fx, fy, mz = _plus(fx, force[0]), _plus(fy, force[1]), _plus(mz, force[2])
        c.tally(frame, force, lam[id(c)])
    if rotor_moment is not None:
        mz = _plus(mz, rotor_moment)
    if ground_extra is not None:
        fx, fy, mz = (_plus(fx, ground_extra[0]), _plus(fy, ground_extra[1]),
                      _plus(mz, ground_extra[2]))
    reactions = frame.reactions
    for p in structure.linkage.ground.points:
        reactions.setdefault(p, V(zero, zero))
    names = structure.names
    return Forces(reactions=reactions,
                  slider_normal={names[k]: f for k, f in frame.normal.items()},
                  slider_couple={names[k]: m for k, m in frame.couple.items()},
                  input_torques=tuple(frame.torques.get(i, zero)
                                      for i in range(len(structure.drivers))),
                  shaking_force=V(fx, fy), shaking_moment=mz,
                  rocking_couple=V(zero, zero) if rocking is None else rocking,
                  teeth=frame.teeth)


def regressors(structure: Structure, mo: Motion, gravity: tuple[float, float] = (0.0, 0.0)
               ) -> tuple[Forces, Layout]:
    """Every result of :func:`inverse_dynamics` as a linear map of the design vector.

    Columns follow :class:`Layout`; applied loads, springs and slider forces are left out (the
    design vector's linear part only; :func:`inverse_dynamics` has the rest).
    """
    layout = Layout.of(structure)
    n = mo.count
    p = layout.size
    g = V(*gravity)
    effective = [[np.zeros((n, p)) for _ in range(3)] for _ in structure.names]
    rotor = np.zeros((n, p))
    for name, cols in inertial_columns(structure, mo, g).items():
        k = structure.index(name)
        for param, values in cols:
            j = layout.index(name, param)
            for r in range(3):
                effective[k][r][:, j] = values[r]
            if param == "Jc":
                rotor[:, j] = 2 * mo.accel[k]
    rocking = rocking_couple(structure.linkage,
                             [V(e[0], e[1]) for e in effective], np.zeros((n, p)))
    return kinetostatics(structure, mo, effective, rotor_moment=rotor, rocking=rocking), layout


#: A crank rate (rad/s) below which :func:`shaking_regressors` takes the links' rates of a
#: unit crank rate instead of dividing the motion's own by it (which, at a subnormal rate,
#: would have lost their digits).
TURNING = 1e-100


@dataclass(frozen=True, eq=False)
class Shaking:
    """What the frame feels from a linkage as linear maps of the design vector.

    Arrays ``(N, P)`` over :class:`Layout`'s entries: the shaking force (N), the shaking moment
    about the spec's origin with the motor's reaction and the counter-rotors (N·m), the
    driving torque (N·m) and the rocking couple (N·m) — per unit entry.
    """

    shaking_force: V
    shaking_moment: NDArray[np.float64]
    driving_torque: NDArray[np.float64]
    rocking_couple: V


def _pose_at(pose: Pose, mask: NDArray[np.bool_]) -> Pose:
    """The frames of ``pose`` at the states ``mask`` picks (arrays ``(N,)``; scalars kept)."""
    def take(a: Num) -> Num:
        return np.asarray(a)[mask] if np.ndim(a) else a

    return Pose([V(take(o.x), take(o.y)) for o in pose.origins], [take(t) for t in pose.angles],
                [take(c) for c in pose.cos], [take(s) for s in pose.sin])


def _put_at(values: Num, mask: NDArray[np.bool_], part: Num, n: int) -> NDArray[np.float64]:
    """``values`` (``(N,)``) with the states ``mask`` picks taken from ``part``."""
    out = np.array(np.broadcast_to(values, (n,)), dtype=float)
    out[mask] = part
    return out


def shaking_regressors(structure: Structure, mo: Motion,
                       gravity: tuple[float, float] = (0.0, 0.0), *,
                       torque_at_rest: bool = True) -> Shaking:
    """:func:`regressors`' shaking, moment, torque and couple without the joint forces.

    The whole linkage in equilibrium with the frame (the pins and the motor): what the frame
    receives is the sum of the links' ``E_k`` (the columns of :func:`inertial_columns`),

    ``F̄sh = Σ_k Ē_k``,  ``Msh = Σ_k (r̄_k × Ē_k + E_k,θ) + 2·J_c·α`` (the counter-rotors),

    and the constraints do no work, so the motor's power balances theirs (virtual power):
    ``τ·θ̇1 = −Σ_k (Ē_k·ṙ_k + E_k,θ·θ̇_k)`` with the links' rates per unit crank rate
    (the motion's own rates over ``θ̇1`` where it turns, else those of a unit crank rate). The
    rocking couple is :func:`rocking_couple` of the same columns. Equal to :func:`regressors`'
    figures (the groups' joint forces, solved state by state) to rounding, at a fraction of the
    work: the regressors of a design's balancing are these. With ``torque_at_rest`` false the
    driving torque at the states at rest is not computed (NaN there: the links' rates of a
    unit crank rate are not solved for them), for a caller that asks only what the frame
    feels there; every other figure is the same.
    """
    layout = Layout.of(structure)
    n, p = mo.count, layout.size
    g = V(*gravity)
    omega = np.asarray(mo.omega1, dtype=float) * np.ones(n)
    turning = np.abs(omega) > TURNING
    with np.errstate(divide="ignore", invalid="ignore"):
        unit = [(mo.velocity[k] / omega, mo.rate[k] / omega) for k in range(structure.size)]
    if not turning.all() and torque_at_rest:  # (at rest there: the links' rates at a unit
        # crank rate; each state's figures its own, whatever else is computed with it: at
        # those states alone)
        idle = ~turning
        m = int(idle.sum())
        vel, rate, _, _ = rates(structure, _pose_at(mo.pose, idle),
                                InputState.crank(mo.theta1[idle], np.ones(m), np.zeros(m)),
                                accelerations=False)
        unit = [(V(_put_at(v.x, idle, u.x, n), _put_at(v.y, idle, u.y, n)),
                 _put_at(w, idle, r, n))
                for (v, w), u, r in zip(unit, vel, rate, strict=True)]
    moment, power = np.zeros((n, p)), np.zeros((n, p))
    # Each link's share of the shaking force is its own columns (an entry is one link's):
    # their sum, the force, is each share in its columns. Kept per link only where a link
    # lies out of the plane (the rocking couple weighs each by its plane).
    force_x, force_y = np.zeros((n, p)), np.zeros((n, p))
    planar = not any(link.z for link in structure.linkage.links)
    shares = [] if planar else [V(np.zeros((n, p)), np.zeros((n, p))) for _ in structure.names]
    for name, cols in inertial_columns(structure, mo, g).items():
        k = structure.index(name)
        origin = mo.pose.origins[k]
        velocity, rate = unit[k]
        # A link's columns side by side: each entry's arithmetic as one column at a time
        # would do it (the same figures), in a few operations on the block.
        js = [layout.index(name, param) for param, _ in cols]
        ex, ey, et = (np.empty((n, len(cols))) for _ in range(3))
        for i, (_, column) in enumerate(cols):
            ex[:, i], ey[:, i], et[:, i] = column
        force_x[:, js] = ex
        force_y[:, js] = ey
        if shares:
            shares[k].x[:, js] = ex
            shares[k].y[:, js] = ey
        ox, oy, vx, vy, w = (np.reshape(np.broadcast_to(a, (n,)), (n, 1))
                             for a in (origin.x, origin.y, velocity.x, velocity.y, rate))
        moment[:, js] = ox * ey - oy * ex + et
        power[:, js] = ex * vx + ey * vy + et * w
        for j, (param, _) in zip(js, cols, strict=True):
            if param == "Jc":
                moment[:, j] += 2 * mo.accel[k]
    # (as the sum of the shares: the other links' zeros make a −0 entry +0, and nothing else)
    force_x += 0.0
    force_y += 0.0
    rocking = (V(np.zeros((n, p)), np.zeros((n, p))) if planar
               else rocking_couple(structure.linkage, shares, np.zeros((n, p))))
    # A state where a link is not placed (the linkage does not assemble there): NaN in every
    # column, as the joint forces give it (a link that is placed there keeps finite columns).
    measured = turning | torque_at_rest  # (the states whose driving torque is computed)
    lost = ~(np.isfinite(force_x) & np.isfinite(force_y) & np.isfinite(moment)
             & (np.isfinite(power) | ~measured[:, None])).all(axis=1)
    if not measured.all():
        power[~measured] = np.nan
    if lost.any():
        for figure in (force_x, force_y, moment, power, rocking.x, rocking.y):
            np.asarray(figure)[lost] = np.nan
    return Shaking(shaking_force=V(force_x, force_y), shaking_moment=moment,
                   driving_torque=-power, rocking_couple=rocking)


def inverse_dynamics(structure: Structure, mo: Motion, linkage: Linkage | None = None,
                     gravity: tuple[float, float] = (0.0, 0.0), loads: bool = True,
                     route: Literal["groups", "global"] = "groups", ops: OpsLike = NUMPY,
                     gas: list[Num] | None = None) -> Forces:
    """Joint forces on the ground, driving torque and shaking sums of a design (one column).

    Parameters
    ----------
    structure, mo
        The linkage and its motion.
    linkage
        The design whose mass properties to use (default: the structure's own).
    gravity
        ``(gx, gy)``, m/s².
    loads
        Include applied forces and moments and slider forces (springs always act).
    route
        ``"groups"`` (:func:`kinetostatics`) or ``"global"`` (:func:`global_kinetostatics`).
    ops, gas
        CasADi's elementary functions to build the forces on symbols (one crank state, the
        ``"groups"`` route; ``gas`` the slider forces, :func:`applied_column`); every result
        is then a scalar symbol instead of an ``(N, 1)`` array.
    """
    linkage = structure.linkage if linkage is None else linkage
    layout = Layout.of(structure)
    x = layout.vector(linkage)
    n = mo.count if ops is NUMPY else 1
    g = V(*gravity)
    structure_now = structure if linkage is structure.linkage else _with(structure, linkage)
    per, ground = applied_column(structure_now, mo, g, loads, ops, gas)
    numeric = ops is NUMPY

    def column(v: Num) -> Num:
        return v[:, None] if numeric else v

    # E_k = applied − (I_k − gravity_k) of the design: inertial_columns summed with the
    # design's parameters, in closed form (S̄ = R·(m·s̄), the first moment about the origin).
    effective: list[list[Num]] = []
    rotor: Num = np.zeros(n) if numeric else 0.0
    inertial = _inertial_forces(structure, mo, layout, x, g)
    for k, (name, (force, first, acc)) in enumerate(zip(structure.names, inertial,
                                                         strict=True)):
        j_origin = x[layout.link_slice(name)][3]
        r = layout.rotor(name)
        rotor_j = 0.0 if r is None else x[r]
        a = mo.accel[k]
        effective.append([column(per[k][0] - force.x),
                          column(per[k][1] - force.y),
                          column(per[k][2] - first.cross(acc)
                                 - (j_origin + rotors.link_inertia(rotor_j)) * a)])
        if rotor_j:
            rotor = rotor + rotors.ground_couple(rotor_j, a)
    shares = [V(column(s.x), column(s.y)) for s in _shares(structure, linkage, inertial, loads)]
    rocking = rocking_couple(linkage, shares, np.zeros((n, 1)) if numeric else 0.0)
    if not numeric:
        return kinetostatics(structure, mo, effective, rotor_moment=rotor,
                             ground_extra=tuple(ground), ops=ops, rocking=rocking)
    rotor = np.broadcast_to(rotor, (n,))[:, None]
    extra = tuple(np.asarray(v)[:, None] * np.ones((n, 1)) for v in ground)
    solver = kinetostatics if route == "groups" else global_kinetostatics
    return solver(structure, mo, effective, rotor_moment=rotor, ground_extra=extra,
                  rocking=rocking)


def _inertial_forces(structure: Structure, mo: Motion, layout: Layout, x: NDArray[np.float64],
                     gravity: V) -> list[tuple[V, V, V]]:
    """Per link of design ``x``: ``m·(r̈ − ḡ) + (α·J − ω²)·S̄``, ``S̄`` and ``r̈ − ḡ``.

    The link's inertia force less its weight (``m·(a_G − ḡ)``, N), its first moment about its
    frame's origin in global axes (``S̄ = R·(m·s̄)``, kg·m) and its origin's acceleration less
    gravity (m/s²).
    """
    out = []
    for k, name in enumerate(structure.names):
        m, me, mf, _ = x[layout.link_slice(name)]
        c, sn = mo.pose.cos[k], mo.pose.sin[k]
        w, a = mo.rate[k], mo.accel[k]
        acc = mo.acceleration[k] - gravity
        first = V(c * me - sn * mf, sn * me + c * mf)
        lin = first.perp() * a - first * (w * w)
        out.append((acc * m + lin, first, acc))
    return out


def _shares(structure: Structure, linkage: Linkage, inertial: list[tuple[V, V, V]],
            loads: bool) -> list[V]:
    """Each link's share of the shaking force, ``m·(ḡ − a_G) + F̄`` (its ``force``), N."""
    out = []
    for name, (force, _, _) in zip(structure.names, inertial, strict=True):
        link = linkage.link(name)
        applied = V(*link.force) if loads and link.has_loads else V(0.0, 0.0)
        out.append(applied - force)
    return out


def rocking_couple_of(structure: Structure, mo: Motion, linkage: Linkage | None = None,
                      gravity: tuple[float, float] = (0.0, 0.0), loads: bool = True) -> V:
    """The rocking couple of a design (:func:`rocking_couple`) without its joint forces.

    Arrays ``(N, 1)``, N·m; ``linkage`` the design (default: the structure's own).
    """
    linkage = structure.linkage if linkage is None else linkage
    layout = Layout.of(structure)
    inertial = _inertial_forces(structure, mo, layout, layout.vector(linkage), V(*gravity))
    n = mo.count
    shares = [V(np.asarray(s.x * np.ones(n))[:, None], np.asarray(s.y * np.ones(n))[:, None])
              for s in _shares(structure, linkage, inertial, loads)]
    return rocking_couple(linkage, shares, np.zeros((n, 1)))


def rocking_couple(linkage: Linkage, shares: Sequence[V], zero: Num) -> V:
    """The rocking couple on the frame from each link's share of the shaking force, N·m.

    ``shares[k] = m_k·(ḡ − a_k) + F̄_k``, link ``k``'s centre-of-mass acceleration ``a_k``
    and the force from outside the machine on it ``F̄_k`` (its ``force``; springs, slider and
    gas forces are the machine's own). From momentum (DESIGN.md, "Planes and the rocking
    couple"), the link a lamina in its plane ``z_k``:

    ``Mx = Σ_k z_k·(m_k·a_k,y − F_k,y) = −Σ_k z_k·share_k,y``,
    ``My = Σ_k z_k·(F_k,x − m_k·a_k,x) = Σ_k z_k·share_k,x``

    — the moment about the origin of each share applied in its plane. ``zero`` (an array of the
    shares' shape, or 0.0 on symbols) for a mechanism in one plane.
    """
    mx: Num = zero
    my: Num = zero
    for link, share in zip(linkage.links, shares, strict=True):
        if link.z:
            mx = mx - link.z * share.y
            my = my + link.z * share.x
    return V(mx, my)


def _with(structure: Structure, linkage: Linkage) -> Structure:
    from dataclasses import replace

    return replace(structure, linkage=linkage)


__all__ = ["GROUND", "Forces", "Layout", "inverse_dynamics", "kinetostatics", "regressors"]
