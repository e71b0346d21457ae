"""The constraints of a general linkage, the groups they close, and link frames at poses.

The equations are those of :mod:`balancer.linkage.structure` (its docstring): a revolute joint
(:class:`Pin`), a prismatic pair (:class:`Prism`) and the driver (:class:`Driver`), their
residuals and Jacobians at a :class:`Pose`, and an Assur group (:class:`Group`) of them.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import TypeAlias

import numpy as np
from numpy.typing import NDArray

from .vectors import Num, OpsLike, V

#: Index of the ground among the links.
GROUND_INDEX = -1
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


@dataclass(frozen=True)
class Driver:
    """The driver: ``θ_input − θ_ground − θ1 = 0`` (its multiplier is minus the motor torque)."""

    link: int

    rows = 1


Constraint = Pin | Prism | Driver


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
        ``"crank"`` (the input, from its pivot and the driver), ``"RRR"``, ``"RRP"``, ``"PRR"``,
        ``"RPR"`` (dyads in closed form; the letters are the joints from the first link's
        known side to the second's) or ``"numeric"``.
    sign
        The branch of a closed-form dyad at the reference pose (+1 or -1).
    """

    links: tuple[int, ...]
    constraints: tuple[Constraint, ...]
    kind: str
    sign: float = 1.0


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


def constraint_residual(c: Constraint, pose: Pose, angle: Num = 0.0) -> list[Num]:
    """The residual of one constraint at a pose: ``c.rows`` values (m or rad).

    ``angle`` is the crank angle a driver prescribes.
    """
    if isinstance(c, Pin):
        d = pose.point(c.a, c.pa) - pose.point(c.b, c.pb)
        return [d.x, d.y]
    if isinstance(c, Prism):
        ts = 0.0 if c.s == GROUND_INDEX else pose.angles[c.s]
        tg = 0.0 if c.g == GROUND_INDEX else pose.angles[c.g]
        d = pose.rotate(c.g, c.dg)
        return [ts - tg - c.delta, d.cross(pose.point(c.s, c.ps) - pose.point(c.g, c.pg))]
    return [pose.angles[c.link] - angle]


#: A constraint's Jacobian by link: ``(link, rows)``, each row three coefficients (for ``x``,
#: ``y``, ``θ``).
Blocks: TypeAlias = list[tuple[int, list[list[Num]]]]


def constraint_jacobian(c: Constraint, pose: Pose) -> Blocks:
    """The Jacobian of one constraint at a pose.

    ``(link, rows)`` pairs: per link, ``c.rows`` rows of three coefficients (for ``x``, ``y``,
    ``θ``), each a value or an array.
    """
    if isinstance(c, Pin):
        ra = pose.rotate(c.a, c.pa)
        rb = pose.rotate(c.b, c.pb)
        return [(c.a, [[1.0, 0.0, -ra.y], [0.0, 1.0, ra.x]]),
                (c.b, [[-1.0, 0.0, rb.y], [0.0, -1.0, -rb.x]])]
    if isinstance(c, Prism):
        d = pose.rotate(c.g, c.dg)
        ps = pose.rotate(c.s, c.ps)
        reach = pose.origin(c.s) + ps - pose.origin(c.g)  # r̄_s + R_s·s̄ − r̄_g
        return [(c.s, [[0.0, 0.0, 1.0], [-d.y, d.x, d.dot(ps)]]),
                (c.g, [[0.0, 0.0, -1.0], [d.y, -d.x, -d.dot(reach)]])]
    return [(c.link, [[0.0, 0.0, 1.0]]), (GROUND_INDEX, [[0.0, 0.0, -1.0]])]


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
        blocks = constraint_jacobian(c, pose)
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
