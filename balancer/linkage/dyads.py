"""The dyads in closed form: the two links of an RRR, RRP (PRR) or RPR group placed at once.

RRR: two circles meet; RRP: a circle meets a line; RPR: the angle of a line through a point
(see :mod:`balancer.linkage.structure`). The branch, the sign that picks one of the two
solutions, is read off the reference pose (:func:`dyad_branch`) and followed from there.
"""

from __future__ import annotations

import math
from typing import TypeAlias, overload

import numpy as np
from numpy.typing import NDArray

from .constraints import GROUND_INDEX, Group, Pin, Pose
from .vectors import NUMPY, Num, OpsLike, V

#: A link's frame: its angle (rad), and its cosine and sine (``None``: from the angle).
Frame: TypeAlias = tuple[Num, Num | None, Num | None]
#: How a dyad places one of its links: its frame, a point to place it by (global), and that
#: point's local position in the link (``None``: the point is the link's origin).
Placement: TypeAlias = tuple[Frame, V, V | None]
#: A dyad's two links placed, and its gap (≥ 0 where it assembles).
Solution: TypeAlias = tuple[Placement, Placement, Num]


def known_point(pose: Pose, c: Pin, k: int) -> tuple[V, V]:
    """For pin ``c`` holding group link ``k``: the partner's point (known) and ``k``'s local."""
    if c.a == k:
        return pose.point(c.b, c.pb), c.pa
    return pose.point(c.a, c.pa), c.pb


def _local(c: Pin, k: int) -> V:
    return c.pa if c.a == k else c.pb


def _angle_of(ops: OpsLike, w: V, local: V) -> Num:
    """The angle of a link whose local vector ``local`` lies along global ``w``."""
    return ops.atan2(w.y, w.x) - math.atan2(local.y, local.x)


def _frame_of(ops: OpsLike, w: V, local: V) -> Frame:
    """Angle, cosine and sine of a link that turns ``local`` into global ``w`` (``|w| = |local|``).

    ``w = R(θ)·local`` gives ``cos θ = w·local/|local|²`` and ``sin θ = (local × w)/|local|²``:
    a few products instead of two transcendental functions (the dyads' ``w`` has the link's
    length to rounding).
    """
    inverse = 1.0 / local.norm2()
    return _angle_of(ops, w, local), w.dot(local) * inverse, local.cross(w) * inverse


class Dyads:
    """Closed-form positions of the dyads.

    Each returns, per link, its frame — angle, cosine and sine (``None`` for those to compute
    from the angle) — and a point to place it by (with its local position, or ``None`` for
    its origin), and a gap: ≥ 0 where the dyad assembles. Without a ``sign``,
    the branch at the given (reference) pose instead.
    """

    @overload
    @staticmethod
    def rrr(ops: OpsLike, pose: Pose, g: Group, sign: None = None) -> float: ...
    @overload
    @staticmethod
    def rrr(ops: OpsLike, pose: Pose, g: Group, sign: Num) -> Solution: ...

    @staticmethod
    def rrr(ops: OpsLike, pose: Pose, g: Group, sign: Num | None = None) -> float | Solution:
        (a, b), (j1, j2, j3) = g.links, g.rrr()
        p1, pa1 = known_point(pose, j1, a)
        p3, pb3 = known_point(pose, j3, b)
        pa2, pb2 = _local(j2, a), _local(j2, b)
        ra2 = (pa2 - pa1).norm2()
        rb2 = (pb2 - pb3).norm2()
        dvec = p3 - p1
        d2 = dvec.norm2()
        d = ops.sqrt(d2)
        along = (ra2 - rb2 + d2) / (2 * d)
        gap = ra2 - along * along  # ≥ 0 where the circles meet
        if sign is None:  # the reference pose: read the branch off it
            p2 = pose.point(a, pa2)
            return float(np.sign(dvec.cross(p2 - p1)))
        h = ops.sqrt(ops.where(gap >= 0, gap, np.nan)) if ops is NUMPY else ops.sqrt(gap)
        p2 = p1 + dvec * (along / d) + dvec.perp() * (sign * h / d)
        frame_a = _frame_of(ops, p2 - p1, pa2 - pa1)
        frame_b = _frame_of(ops, p2 - p3, pb2 - pb3)
        return (frame_a, p1, pa1), (frame_b, p3, pb3), gap / ra2

    @staticmethod
    def _rrp_line(ops: OpsLike, pose: Pose, g: Group) -> tuple[V, V, Num, Num, Num]:
        """The line ``Q + t·d̄`` that ``P2`` runs on, and ``b``'s angle, cosine and sine."""
        b, (_, j2, j3) = g.links[1], g.rrp()
        other = j3.g if j3.s == b else j3.s
        theta_k = 0.0 if other == GROUND_INDEX else pose.angles[other]
        theta_b = theta_k + j3.delta if j3.s == b else theta_k - j3.delta
        cb, sb = ops.cos(theta_b), ops.sin(theta_b)
        pb2 = _local(j2, b)
        if j3.s == b:  # b's point runs on a line of the known link
            d = pose.rotate(other, j3.dg)
            q = pose.point(other, j3.pg) - (j3.ps - pb2).rotated(cb, sb)
        else:  # the known link's point runs on a line of b
            d = j3.dg.rotated(cb, sb)
            q = pose.point(other, j3.ps) + (pb2 - j3.pg).rotated(cb, sb)
        return q, d, theta_b, cb, sb

    @overload
    @classmethod
    def rrp(cls, ops: OpsLike, pose: Pose, g: Group, sign: None = None) -> float: ...
    @overload
    @classmethod
    def rrp(cls, ops: OpsLike, pose: Pose, g: Group, sign: Num) -> Solution: ...

    @classmethod
    def rrp(cls, ops: OpsLike, pose: Pose, g: Group, sign: Num | None = None
            ) -> float | Solution:
        (a, b), (j1, j2, _) = g.links, g.rrp()
        p1, pa1 = known_point(pose, j1, a)
        pa2, pb2 = _local(j2, a), _local(j2, b)
        ra2 = (pa2 - pa1).norm2()
        q, d, theta_b, cb, sb = cls._rrp_line(ops, pose, g)
        w = p1 - q
        t0 = w.dot(d)
        dist = d.cross(w)
        gap = ra2 - dist * dist
        if sign is None:
            p2 = pose.point(a, pa2)
            return float(np.sign((p2 - p1).dot(d)))
        root = ops.sqrt(ops.where(gap >= 0, gap, np.nan)) if ops is NUMPY else ops.sqrt(gap)
        p2 = q + d * (t0 + sign * root)
        frame_a = _frame_of(ops, p2 - p1, pa2 - pa1)
        origin_b = p2 - pb2.rotated(cb, sb)
        return (frame_a, p1, pa1), ((theta_b, cb, sb), origin_b, None), gap / ra2

    @overload
    @staticmethod
    def rpr(ops: OpsLike, pose: Pose, g: Group, sign: None = None) -> float: ...
    @overload
    @staticmethod
    def rpr(ops: OpsLike, pose: Pose, g: Group, sign: Num) -> Solution: ...

    @staticmethod
    def rpr(ops: OpsLike, pose: Pose, g: Group, sign: Num | None = None) -> float | Solution:
        (a, b), (j1, j2, j3) = g.links, g.rpr()
        pivots = {a: known_point(pose, j1, a), b: known_point(pose, j3, b)}
        s_link, g_link = j2.s, j2.g
        p_s, ps_piv = pivots[s_link]
        p_g, pg_piv = pivots[g_link]
        cd, sd = math.cos(j2.delta), math.sin(j2.delta)
        w = (j2.ps - ps_piv).rotated(cd, sd) - (j2.pg - pg_piv)
        c0 = j2.dg.cross(w)
        dp = p_s - p_g
        r2 = dp.norm2()
        gap = 1.0 - c0 * c0 / r2
        if sign is None:
            return float(np.sign(pose.rotate(g_link, j2.dg).dot(dp)))
        sin_b = -c0 / ops.sqrt(r2)
        cos_b = sign * (ops.sqrt(ops.where(gap >= 0, gap, np.nan)) if ops is NUMPY
                        else ops.sqrt(gap))
        phi = ops.atan2(dp.y, dp.x) - ops.atan2(sin_b, cos_b)
        theta_g = phi - math.atan2(j2.dg.y, j2.dg.x)
        theta_s = theta_g + j2.delta
        frames: dict[int, Frame] = {g_link: (theta_g, None, None),
                                    s_link: (theta_s, None, None)}
        return ((frames[a], pivots[a][0], pivots[a][1]), (frames[b], pivots[b][0],
                                                          pivots[b][1]), gap)


def dyad_branch(group: Group, q_ref: NDArray[np.float64]) -> float:
    """The branch ``σ`` of a closed-form dyad at the reference pose (+1 or -1).

    ``q_ref``: the reference pose's coordinates, ``(x, y, θ)`` per moving link.
    """
    n = q_ref.size // 3
    pose = Pose([V(q_ref[3 * k], q_ref[3 * k + 1]) for k in range(n)],
                [q_ref[3 * k + 2] for k in range(n)])
    solver = {"RRR": Dyads.rrr, "RRP": Dyads.rrp, "RPR": Dyads.rpr}[group.kind]
    sign = solver(NUMPY, pose, group)
    return sign if sign != 0 else 1.0
