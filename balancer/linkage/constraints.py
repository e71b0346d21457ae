"""The constraints of a general linkage, the groups they close, and link frames at poses.

The equations are those of :mod:`balancer.linkage.structure` (its docstring): a revolute joint
(:class:`Pin`), a prismatic pair (:class:`Prism`), a gear pair's mesh (:class:`Mesh`) and the
driver (:class:`Driver`), each
with its own residual, Jacobian, velocity terms and share of the frame's loads at a
:class:`Pose` (the core dispatches through these methods, never by a joint's kind), and an
Assur group (:class:`Group`) of them.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass, field
from typing import ClassVar, TypeAlias, cast

import numpy as np
from numpy.typing import NDArray

from .inputs import InputState
from .vectors import Num, OpsLike, V, _plus

#: Index of the ground among the links.
GROUND_INDEX = -1
#: A constraint's Jacobian by link: ``(link, rows)``, each row three coefficients (for ``x``,
#: ``y``, ``θ``).
Blocks: TypeAlias = list[tuple[int, list[list[Num]]]]


def _rate(rate: list[Num], k: int) -> Num:
    return 0.0 if k == GROUND_INDEX else rate[k]


def _sin(x: Num) -> Num:
    """``sin x`` of a number, an array or a CasADi symbol (which has its own)."""
    return x.sin() if hasattr(x, "sin") else np.sin(x)


def _cos(x: Num) -> Num:
    """``cos x`` of a number, an array or a CasADi symbol (which has its own)."""
    return x.cos() if hasattr(x, "cos") else np.cos(x)


def _velocity(vel: list[V], k: int) -> V:
    return V(0.0, 0.0) if k == GROUND_INDEX else vel[k]


@dataclass(eq=False)
class FrameTally:
    """What the joints put on the frame, collected joint by joint (:meth:`Pin.tally`, …).

    ``reactions`` by ground point (N), the ground sliders' ``normal`` force (N) and ``couple``
    (N·m) by the slider's link index, each motor's torque on its input by the input's index
    (N·m); ``zero`` what no joint puts there (an array of zeros, or the float 0.0 on symbols).
    """

    zero: Num
    reactions: dict[str, V] = field(default_factory=dict)
    normal: dict[int, Num] = field(default_factory=dict)
    couple: dict[int, Num] = field(default_factory=dict)
    torques: dict[int, Num] = field(default_factory=dict)
    #: Each gear pair's tooth force on its driven gear at the pitch point (N), by the pair's name.
    teeth: dict[str, V] = field(default_factory=dict)


@dataclass(frozen=True)
class Pin:
    """A revolute constraint: point ``pa`` of link ``a`` on point ``pb`` of link ``b``.

    ``pa``, ``pb`` are in the links' frames (the ground's frame is the spec's).
    """

    point: str
    a: int
    pa: V
    b: int
    pb: V

    rows = 2
    #: What each row constrains (:meth:`Structure.row_kinds`), and the joint's letter in a
    #: dyad's kind (``"RRP"``).
    row_kinds: ClassVar[tuple[str, ...]] = ("length", "length")
    letter: ClassVar[str] = "R"

    @property
    def members(self) -> tuple[int, int]:
        """The two links it joins."""
        return (self.a, self.b)

    def held_at(self, k: int) -> V | None:
        """The local point by which it holds link ``k``."""
        return self.pa if self.a == k else self.pb

    def residual(self, pose: Pose, state: InputState | None = None) -> list[Num]:
        """The two points' separation, m."""
        d = pose.point(self.a, self.pa) - pose.point(self.b, self.pb)
        return [d.x, d.y]

    def jacobian(self, pose: Pose) -> Blocks:
        """:meth:`residual`'s derivative by the links' coordinates."""
        ra = pose.rotate(self.a, self.pa)
        rb = pose.rotate(self.b, self.pb)
        return [(self.a, [[1.0, 0.0, -ra.y], [0.0, 1.0, ra.x]]),
                (self.b, [[-1.0, 0.0, rb.y], [0.0, -1.0, -rb.x]])]

    def gamma(self, pose: Pose, vel: list[V], rate: list[Num],
              state: InputState | None = None) -> list[Num]:
        """``γ`` (``Φ_q·q̈ = γ``): the velocity terms of the residual's second derivative."""
        ra, rb = pose.rotate(self.a, self.pa), pose.rotate(self.b, self.pb)
        wa, wb = _rate(rate, self.a), _rate(rate, self.b)
        out = ra * (wa * wa) - rb * (wb * wb)
        return [out.x, out.y]

    def prescribed_rates(self, state: InputState) -> list[Num]:
        """``Φ_q·q̇`` of its rows: zero (it prescribes no motion)."""
        return [0.0, 0.0]

    def row_scales(self, length: float) -> list[float]:
        """What each row is multiplied by to be a length, given the linkage's ``length``."""
        return [1.0, 1.0]

    def tally(self, frame: FrameTally, force: list[Num] | None, multipliers: list[Num]) -> None:
        """Its force on the frame (``force``: x, y, moment) as the reaction at its point.

        ``None``: it joins two moving links, and puts nothing on the frame.
        """
        if force is None:
            return
        old = frame.reactions.get(self.point, V(frame.zero, frame.zero))
        frame.reactions[self.point] = V(_plus(old.x, force[0]), _plus(old.y, force[1]))


@dataclass(frozen=True)
class Prism:
    """A prismatic pair: link ``s`` slides on a line fixed in link ``g``.

    ``ps`` is the slider point in ``s``'s frame; ``pg`` a point of the line and ``dg`` its unit
    direction, in ``g``'s frame; ``delta`` the constant ``θ_s − θ_g``. ``slider`` is its index
    in the spec's list.
    """

    slider: int
    s: int
    ps: V
    g: int
    pg: V
    dg: V
    delta: float

    rows = 2
    row_kinds: ClassVar[tuple[str, ...]] = ("angle", "length")
    letter: ClassVar[str] = "P"

    @property
    def members(self) -> tuple[int, int]:
        """The slider's link and the guide's."""
        return (self.s, self.g)

    def held_at(self, k: int) -> V | None:
        """``None``: a prism holds a link by no point."""
        return None

    def residual(self, pose: Pose, state: InputState | None = None) -> list[Num]:
        """The relative angle's error (rad) and the slider point's distance from the line (m)."""
        ts = 0.0 if self.s == GROUND_INDEX else pose.angles[self.s]
        tg = 0.0 if self.g == GROUND_INDEX else pose.angles[self.g]
        d = pose.rotate(self.g, self.dg)
        return [ts - tg - self.delta,
                d.cross(pose.point(self.s, self.ps) - pose.point(self.g, self.pg))]

    def jacobian(self, pose: Pose) -> Blocks:
        """:meth:`residual`'s derivative by the links' coordinates."""
        d = pose.rotate(self.g, self.dg)
        ps = pose.rotate(self.s, self.ps)
        reach = pose.origin(self.s) + ps - pose.origin(self.g)  # r̄_s + R_s·s̄ − r̄_g
        return [(self.s, [[0.0, 0.0, 1.0], [-d.y, d.x, d.dot(ps)]]),
                (self.g, [[0.0, 0.0, -1.0], [d.y, -d.x, -d.dot(reach)]])]

    def gamma(self, pose: Pose, vel: list[V], rate: list[Num],
              state: InputState | None = None) -> list[Num]:
        """``γ`` (``Φ_q·q̈ = γ``): the velocity terms of the residual's second derivative."""
        d = pose.rotate(self.g, self.dg)
        ps, pg = pose.rotate(self.s, self.ps), pose.rotate(self.g, self.pg)
        delta = pose.origin(self.s) + ps - pose.origin(self.g) - pg
        ws, wg = _rate(rate, self.s), _rate(rate, self.g)
        ddot = (_velocity(vel, self.s) + ps.perp() * ws - _velocity(vel, self.g)
                - pg.perp() * wg)
        line = (wg * wg * (d.cross(delta) - d.cross(pg)) + 2 * wg * d.dot(ddot)
                + ws * ws * d.cross(ps))
        return [0.0 * line, line]

    def prescribed_rates(self, state: InputState) -> list[Num]:
        """``Φ_q·q̇`` of its rows: zero (it prescribes no motion)."""
        return [0.0, 0.0]

    def row_scales(self, length: float) -> list[float]:
        """What each row is multiplied by to be a length: the angle's row by ``length``."""
        return [length, 1.0]

    def tally(self, frame: FrameTally, force: list[Num] | None, multipliers: list[Num]) -> None:
        """On a ground guide: the slider's normal force (N) and couple (N·m) on it."""
        if self.g == GROUND_INDEX:
            frame.normal[self.s] = multipliers[1]
            frame.couple[self.s] = multipliers[0]


@dataclass(frozen=True)
class Mesh:
    """A gear pair's mesh: link ``b`` turns at ``ratio`` times link ``a``, each about its pivot.

    The pivots (``pa`` of ``a`` on the ground's ``oa``, ``pb`` of ``b`` on ``ob``) are held by
    pins of their own; along the unit ``u`` from ``oa`` to ``ob`` (distance ``d``) the pitch
    circles touch at ``P = oa + ρ_a·u = ob + ρ_b·u``, ``ρ_b = d/(k − 1)`` and ``ρ_a = k·ρ_b``
    (``k`` the ratio), where the two gears' points have one velocity along the tangent
    ``t = i·u``. The residual (a length)

    ``ρ_b·sin(k·(θ_a − θ_a⁰) − (θ_b − θ_b⁰)) + t·(r̄_a + R_a·p̄_a − ō_a) − t·(r̄_b + R_b·p̄_b − ō_b)``

    vanishes where the angles keep the ratio from the reference pose and the pivots hold; its
    Jacobian there is the rolling condition ``t·(v_a(P) − v_b(P)) = 0``, so that its
    multiplier ``λ`` is the tooth force along ``t`` at ``P``: ``λ·t`` on ``b``, ``−λ·t`` on
    ``a`` (internal: nothing on the frame but through the pivots).
    """

    name: str
    a: int
    pa: V
    oa: V
    b: int
    pb: V
    ob: V
    ratio: float
    a_ref: float
    b_ref: float

    rows = 1
    row_kinds: ClassVar[tuple[str, ...]] = ("length",)
    letter: ClassVar[str] = "G"

    @property
    def members(self) -> tuple[int, int]:
        """The driver's link and the driven one's."""
        return (self.a, self.b)

    def held_at(self, k: int) -> V | None:
        """``None``: the mesh holds a link by no point."""
        return None

    @property
    def tangent(self) -> V:
        """``t``, the unit tangent of the pitch circles at the pitch point."""
        d = self.ob - self.oa
        size = (d.x * d.x + d.y * d.y) ** 0.5
        return V(-d.y / size, d.x / size)

    @property
    def radii(self) -> tuple[float, float]:
        """The signed pitch radii ``(ρ_a, ρ_b)`` along ``u``, m."""
        d = self.ob - self.oa
        rho_b = float((d.x * d.x + d.y * d.y) ** 0.5) / (self.ratio - 1)
        return self.ratio * rho_b, rho_b

    @property
    def pitch_point(self) -> V:
        """``P``, where the pitch circles touch (in the ground's frame), m."""
        d = self.ob - self.oa
        return self.oa + d * (self.ratio / (self.ratio - 1))

    def driven_angle(self, theta_a: Num) -> Num:
        """Link ``b``'s angle with link ``a`` at ``theta_a`` (rad), the ratio kept."""
        return self.b_ref + self.ratio * (theta_a - self.a_ref)

    def _slip(self, pose: Pose) -> Num:
        ta = 0.0 if self.a == GROUND_INDEX else pose.angles[self.a]
        tb = 0.0 if self.b == GROUND_INDEX else pose.angles[self.b]
        return self.ratio * (ta - self.a_ref) - (tb - self.b_ref)

    def residual(self, pose: Pose, state: InputState | None = None) -> list[Num]:
        """The pitch circles' slip along ``t`` (m), and the pivots' gaps along it."""
        t = self.tangent
        gap = (pose.point(self.a, self.pa) - self.oa) - (pose.point(self.b, self.pb) - self.ob)
        slip = self._slip(pose)
        sine = _sin(slip)
        return [_plus(self.radii[1] * sine, t.dot(gap))]

    def jacobian(self, pose: Pose) -> Blocks:
        """:meth:`residual`'s derivative by the links' coordinates."""
        t = self.tangent
        slip = self._slip(pose)
        cosine = _cos(slip)
        rho_b = self.radii[1]
        ra, rb = pose.rotate(self.a, self.pa), pose.rotate(self.b, self.pb)
        return [(self.a, [[t.x, t.y, rho_b * self.ratio * cosine + ra.cross(t)]]),
                (self.b, [[-t.x, -t.y, -rho_b * cosine - rb.cross(t)]])]

    def gamma(self, pose: Pose, vel: list[V], rate: list[Num],
              state: InputState | None = None) -> list[Num]:
        """``γ`` (``Φ_q·q̈ = γ``): the velocity terms of the residual's second derivative."""
        t = self.tangent
        slip = self._slip(pose)
        sine = _sin(slip)
        ra, rb = pose.rotate(self.a, self.pa), pose.rotate(self.b, self.pb)
        wa, wb = _rate(rate, self.a), _rate(rate, self.b)
        turn = self.ratio * wa - wb
        return [self.radii[1] * sine * (turn * turn)
                + t.dot(ra * (wa * wa) - rb * (wb * wb))]

    def prescribed_rates(self, state: InputState) -> list[Num]:
        """``Φ_q·q̇`` of its row: zero (it prescribes no motion of its own)."""
        return [0.0]

    def row_scales(self, length: float) -> list[float]:
        """Its row, a length."""
        return [1.0]

    def tally(self, frame: FrameTally, force: list[Num] | None, multipliers: list[Num]) -> None:
        """The tooth force on the driven gear, ``λ·t`` (N), by the pair's name."""
        t = self.tangent
        frame.teeth[self.name] = V(multipliers[0] * t.x, multipliers[0] * t.y)


class _InputDriver:
    """What an input's drivers share: one row prescribing input ``index`` of link ``link``.

    Its rate is the input's, its row a length or an angle as it is, its multiplier minus the
    motor's or actuator's load on the input; it holds the link by no point.
    """

    link: int
    index: int
    rows = 1

    def position(self, pose: Pose) -> Num:
        """The input's position at ``pose``: an angle (rad), or a place along a slide (m)."""
        raise NotImplementedError

    def residual(self, pose: Pose, state: InputState | None = None) -> list[Num]:
        """The input's position less its prescribed one in ``state`` (none given: 0)."""
        return [self.position(pose) - (0.0 if state is None else state.positions[self.index])]

    @property
    def members(self) -> tuple[int, int]:
        """The input's link and the ground."""
        return (self.link, GROUND_INDEX)

    def held_at(self, k: int) -> V | None:
        """``None``: the driver holds a link by no point."""
        return None

    def prescribed_rates(self, state: InputState) -> list[Num]:
        """``Φ_q·q̇`` of its row: the input's prescribed rate (rad/s, or m/s along a slide)."""
        return [state.rates[self.index]]

    def row_scales(self, length: float) -> list[float]:
        """Its row, as it is."""
        return [1.0]

    def tally(self, frame: FrameTally, force: list[Num] | None, multipliers: list[Num]) -> None:
        """The motor's torque (an actuator's force) on its input: minus its multiplier."""
        frame.torques[self.index] = -multipliers[0]

    def own_group(self, pins: Sequence[Pin], pivot: str) -> Group | None:
        """The group that places its link from the ground (``None``: it cannot).

        A crank's: the link's pin to the ground at its first point ``pivot``, and itself; a
        slide's: its prism and itself.
        """
        raise NotImplementedError


@dataclass(frozen=True)
class Driver(_InputDriver):
    """An input's driver: ``θ_link − θ_ground − θ_i = 0`` for input ``index``.

    Its multiplier is minus the motor's torque.
    """

    link: int
    #: Which input drives it (its place in the linkage's inputs and in an :class:`InputState`).
    index: int = 0

    row_kinds: ClassVar[tuple[str, ...]] = ("angle",)
    letter: ClassVar[str] = "D"
    #: Units of the input's position and of its motor's load.
    position_unit: ClassVar[str] = "rad"
    load_unit: ClassVar[str] = "N·m"

    def position(self, pose: Pose) -> Num:
        """The input link's angle, rad."""
        return pose.angles[self.link]

    def jacobian(self, pose: Pose) -> Blocks:
        """:meth:`residual`'s derivative by the links' coordinates."""
        return [(self.link, [[0.0, 0.0, 1.0]]), (GROUND_INDEX, [[0.0, 0.0, -1.0]])]

    def gamma(self, pose: Pose, vel: list[V], rate: list[Num],
              state: InputState | None = None) -> list[Num]:
        """``γ``: the input's prescribed acceleration (rad/s²; none given: zero)."""
        return [0.0 if state is None else state.accelerations[self.index]]

    def own_group(self, pins: Sequence[Pin], pivot: str) -> Group | None:
        """The input link about its pin to the ground at ``pivot`` (``None``: no such pin)."""
        found = [c for c in pins if c.a == self.link and c.b == GROUND_INDEX and c.point == pivot]
        return Group((self.link,), (found[0], self), "input") if found else None


@dataclass(frozen=True)
class SlideDriver(_InputDriver):
    """An input along a ground slide: ``d̄·(r̄_s + R_s·s̄ − p̄_g) − s_i = 0`` for input ``index``.

    The slider of ``prism`` (a prismatic pair on a ground guide, direction ``d̄``, point
    ``p̄_g``) is at ``s_i`` m along the guide from ``p̄_g``; its multiplier is minus the
    actuator's force on it along the guide (N).
    """

    link: int
    index: int
    prism: Prism

    row_kinds: ClassVar[tuple[str, ...]] = ("length",)
    letter: ClassVar[str] = "S"
    #: Units of the input's position and of its actuator's load.
    position_unit: ClassVar[str] = "m"
    load_unit: ClassVar[str] = "N"

    def position(self, pose: Pose) -> Num:
        """The slider point's place along the guide from its point, m."""
        p = self.prism
        return p.dg.dot(pose.point(self.link, p.ps) - p.pg)

    def jacobian(self, pose: Pose) -> Blocks:
        """:meth:`residual`'s derivative by the links' coordinates (the ground's at rest)."""
        d = self.prism.dg
        ps = pose.rotate(self.link, self.prism.ps)
        reach = pose.origin(self.link) + ps  # r̄_s + R_s·s̄ − r̄_g, the ground's at its origin
        return [(self.link, [[d.x, d.y, d.dot(ps.perp())]]),
                (GROUND_INDEX, [[-d.x, -d.y, d.cross(reach)]])]

    def gamma(self, pose: Pose, vel: list[V], rate: list[Num],
              state: InputState | None = None) -> list[Num]:
        """``γ``: the prescribed acceleration along the guide and ``ω_s²·d̄·(R_s·s̄)``, m/s²."""
        ps = pose.rotate(self.link, self.prism.ps)
        w = _rate(rate, self.link)
        spin = self.prism.dg.dot(ps) * (w * w)
        return [spin if state is None else state.accelerations[self.index] + spin]

    def own_group(self, pins: Sequence[Pin], pivot: str) -> Group | None:
        """The slider along its ground guide: its prism and itself place it."""
        return Group((self.link,), (self.prism, self), "slide")


Constraint = Pin | Prism | Mesh | Driver | SlideDriver


@dataclass(frozen=True)
class Group:
    """Links found together from the links found before them, and the constraints that do it.

    Attributes
    ----------
    links
        Indices of the group's links (each one's coordinates are unknowns of the group).
    constraints
        The constraints that close the group: every row touches a link of the group, the other
        links they touch are found before.
    kind
        ``"input"`` (a driven link, from its pivot and its driver), ``"geared"`` (a link
        turned by a gear pair, from its pivot and the mesh), ``"RRR"``, ``"RRP"``, ``"PRR"``,
        ``"RPR"`` (dyads in closed form; the letters are the joints from the first link's
        known side to the second's) or ``"numeric"``.
    sign
        The branch of a closed-form dyad at the reference pose (+1 or -1).
    """

    links: tuple[int, ...]
    constraints: tuple[Constraint, ...]
    kind: str
    sign: float = 1.0

    @property
    def pivot(self) -> Pin:
        """An input group's pivot: the pin its first constraint is."""
        c = self.constraints[0]
        if not isinstance(c, Pin):
            raise ValueError(f"a {self.kind} group has no pivot")
        return c

    @property
    def mesh(self) -> Mesh:
        """A geared group's mesh: its last constraint."""
        c = self.constraints[-1]
        if not isinstance(c, Mesh):
            raise ValueError(f"a {self.kind} group has no mesh")
        return c

    @property
    def driver(self) -> Driver | SlideDriver:
        """An input group's driver: its last constraint."""
        c = self.constraints[-1]
        if not isinstance(c, Driver | SlideDriver):
            raise ValueError(f"a {self.kind} group has no driver")
        return c

    @property
    def slide(self) -> Prism:
        """A slide group's prism (its first constraint): the guide its input runs along."""
        c = self.constraints[0]
        if not isinstance(c, Prism):
            raise ValueError(f"a {self.kind} group has no slide")
        return c

    def rrr(self) -> tuple[Pin, Pin, Pin]:
        """An RRR dyad's pins: on the first link's known side, between them, on the second's."""
        return cast(tuple[Pin, Pin, Pin], self._dyad("RRR"))

    def rrp(self) -> tuple[Pin, Pin, Prism]:
        """An RRP (PRR) dyad's joints: pin, pin, and the prism of its second link."""
        return cast(tuple[Pin, Pin, Prism], self._dyad("RRP"))

    def rpr(self) -> tuple[Pin, Prism, Pin]:
        """An RPR dyad's joints: a pin, the prism between its links, a pin."""
        return cast(tuple[Pin, Prism, Pin], self._dyad("RPR"))

    def _dyad(self, letters: str) -> tuple[Constraint, ...]:
        """Its three joints, if their letters (each kind's own) are ``letters``."""
        if "".join(c.letter for c in self.constraints) != letters:
            raise ValueError(f"a {self.kind} group is no {letters} dyad")
        return self.constraints


def unit(x: float, y: float) -> complex:
    """The unit vector along ``(x, y)``, any length but zero.

    Subnormal or near overflow alike: scaled by its larger component first, so that neither
    its length overflows nor its components lose their digits.
    """
    m = max(abs(x), abs(y))
    d = complex(x / m, y / m)
    return d / abs(d)


class Pose:
    """Link frames at one or many poses.

    Origins, angles and the rotations' cosines and sines, per moving link; the ground's frame
    is the spec's.
    """

    def __init__(self, origins: list[V], angles: list[Num], cos: list[Num] | None = None,
                 sin: list[Num] | None = None, ops: OpsLike | None = None) -> None:
        self.origins = origins
        self.angles = angles
        functions = np if ops is None else ops
        self.cos: list[Num] = [functions.cos(t) for t in angles] if cos is None else cos
        self.sin: list[Num] = [functions.sin(t) for t in angles] if sin is None else sin

    def origin(self, k: int) -> V:
        return V(0.0, 0.0) if k == GROUND_INDEX else self.origins[k]

    def rotate(self, k: int, p: V) -> V:
        """``R(θ_k)·p̄``."""
        if k == GROUND_INDEX:
            return p
        return p.rotated(self.cos[k], self.sin[k])

    def point(self, k: int, p: V) -> V:
        """``r̄_k + R(θ_k)·p̄``: a point of link ``k`` in the spec's frame."""
        return self.origin(k) + self.rotate(k, p)


def pose_of(q: NDArray[np.float64]) -> Pose:
    """The frames of coordinates ``q``: ``(x, y, θ)`` per moving link."""
    n = q.size // 3
    return Pose([V(q[3 * k], q[3 * k + 1]) for k in range(n)], [q[3 * k + 2] for k in range(n)])


def group_jacobian(g: Group, pose: Pose
                   ) -> tuple[list[list[Num]], list[list[tuple[int, list[Num]]]]]:
    """The Jacobian of a group's constraints at a pose, split by links.

    Returns ``(rows, known)``: ``Φ_S``, the k×k block in the group's own links' coordinates
    (entries floats — a structural 0.0 where no link term enters — or arrays), and for each
    row the blocks ``(link, coefficients)`` of the moving links found before the group.
    """
    index = {link: i for i, link in enumerate(g.links)}
    k = 3 * len(g.links)
    rows: list[list[Num]] = []
    known: list[list[tuple[int, list[Num]]]] = []
    for c in g.constraints:
        blocks = c.jacobian(pose)
        for r in range(c.rows):
            row: list[Num] = [0.0] * k
            row_known = []
            for link, coeffs in blocks:
                if link in index:
                    for j in range(3):
                        row[3 * index[link] + j] = row[3 * index[link] + j] + coeffs[r][j]
                elif link != GROUND_INDEX:
                    row_known.append((link, coeffs[r]))
            rows.append(row)
            known.append(row_known)
    return rows, known
