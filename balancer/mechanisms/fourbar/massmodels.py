"""Mass models of the four-bar's links and of the linkage as a whole.

- Complex joint masses and the real/virtual equivalent masses ``mᵃ, mᵇ, mᶜ``
  (Meijaard & van der Wijk 2020, Eq. 29).
- Principal vectors of the opened loop (Eq. 12–13) and of the system about the frame
  (Eq. 30–31), and the total centre of mass from each (Eq. 16, 32).
- Wunderlich's (1964) result that the total centre of mass traces a curve similar to a coupler
  curve of the linkage (his Eq. 7–9): the fixed points B0, B3 and the coupler-point ratio β.
- The constant equivalent mass matrix of a link (Eq. 45), its equivalent joint forces (Eq. 46),
  and the assembled matrices and force vectors of the four-bar (Eq. 48–49, 53–54).

The inertial parameters of a link, in which everything dynamic is linear, are
``π = (m, m·e, m·f, J)`` with ``J = I + m·(e² + f²)`` the moment of inertia about the link's
first joint (kg, kg·m, kg·m, kg·m²). Functions that take them accept numpy arrays or CasADi
symbols alike.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass
from typing import Protocol

import numpy as np
from numpy.typing import NDArray

from ...linkage.massmodels import equivalent_joint_forces, equivalent_mass_matrix
from ...linkage.vectors import Num
from ...model import Link
from .kinematics import Position
from .model import FourBar


class LinkVectors(Protocol):
    """The moving links' vectors ``l̄1``, ``l̄2``, ``l̄3`` (complex, m).

    A :class:`Position`'s arrays, or one state's numbers.
    """

    @property
    def l1(self) -> Num: ...
    @property
    def l2(self) -> Num: ...
    @property
    def l3(self) -> Num: ...


# ----------------------------------------------------------------------------------------------
# Complex joint masses (Eq. 29)






# ----------------------------------------------------------------------------------------------
# Principal vectors


@dataclass(frozen=True, eq=False)
class OpenedLoopVectors:
    """Principal vectors of the opened loop (Eq. 12) and the derived vectors (Eq. 13), m.

    Each is a complex array over the positions; ``a14p`` and ``a34p`` are the primed
    ``ā'14``, ``ā'34``.
    """

    a12: NDArray[np.complex128]
    a21: NDArray[np.complex128]
    a23: NDArray[np.complex128]
    a32: NDArray[np.complex128]
    a14p: NDArray[np.complex128]
    a34p: NDArray[np.complex128]


def opened_loop_vectors(linkage: FourBar, pos: Position) -> OpenedLoopVectors:
    """Principal vectors of the opened loop at the given positions (Eq. 12–13)."""
    (l1, l2, l3, _), (c1, c2, c3) = linkage.lengths, linkage.links
    m1, m2, m3 = c1.mass, c2.mass, c3.mass
    mt = m1 + m2 + m3
    z1, z2, z3 = c1.com / l1, c2.com / l2, c3.com / l3
    v1, v2, v3 = pos.l1, pos.l2, pos.l3
    a12 = v1 * (1 - z1) * m1 / mt
    a21 = -v2 * (m3 + m2 * z2) / mt
    a23 = v2 * (m1 + m2 * (1 - z2)) / mt
    a32 = -v3 * z3 * m3 / mt
    a14p = -v1 * (m2 + m3 + m1 * z1) / mt
    a34p = v3 * (m1 + m2 + m3 * (1 - z3)) / mt
    return OpenedLoopVectors(a12=a12, a21=a21, a23=a23, a32=a32, a14p=a14p, a34p=a34p)


@dataclass(frozen=True, eq=False)
class FrameVectors:
    """Principal vectors of the system about the frame (Eq. 30) and derived vectors (Eq. 31), m.

    Complex arrays over the positions; ``a41`` and ``a43`` are constant, ``a12p``, ``a32p`` are
    ``ā'12``, ``ā'32``.
    """

    a14: NDArray[np.complex128]
    a41: complex
    a43: complex
    a34: NDArray[np.complex128]
    a12p: NDArray[np.complex128]
    a32p: NDArray[np.complex128]


def frame_coefficients(linkage: FourBar) -> tuple[complex, complex]:
    """The complex coefficients ``(k14, k34)`` with ``ā14 = k14·l̄1``, ``ā34 = k34·l̄3`` (Eq. 30).

    ``m_tot·k14 = −(m1·s̄1/l1 + m2·(1 − s̄2/l2))`` and
    ``m_tot·k34 = m2·s̄2/l2 + m3·(1 − s̄3/l3)``. Both vanish exactly when the linkage is
    force-balanced (Eq. 57).
    """
    (l1, l2, l3, _), (c1, c2, c3) = linkage.lengths, linkage.links
    mt = linkage.total_mass
    k14 = -(c1.mass * c1.com / l1 + c2.mass * (1 - c2.com / l2)) / mt
    k34 = (c2.mass * c2.com / l2 + c3.mass * (1 - c3.com / l3)) / mt
    return k14, k34


def frame_vectors(linkage: FourBar, pos: Position) -> FrameVectors:
    """Principal vectors about the frame at the given positions (Eq. 30–31)."""
    (_, l2, _, l4), (c1, c2, c3) = linkage.lengths, linkage.links
    mt = linkage.total_mass
    k14, k34 = frame_coefficients(linkage)
    v4 = -l4  # l̄4 = l4·exp(iπ)
    a14 = k14 * pos.l1
    a34 = k34 * pos.l3
    a41 = (c2.mass * c2.com / l2 + c3.mass) * v4 / mt
    a43 = -(c1.mass + c2.mass * (1 - c2.com / l2)) * v4 / mt
    a12p = a14 + pos.l1  # Eq. 31
    a32p = a34 - pos.l3
    return FrameVectors(a14=a14, a41=a41, a43=a43, a34=a34, a12p=a12p, a32p=a32p)


def link_centres_of_mass(
    linkage: FourBar, pos: Position
) -> tuple[NDArray[np.complex128], NDArray[np.complex128], NDArray[np.complex128]]:
    """Positions of the links' centres of mass ``r̄k = r̄p + s̄k·l̄k/lk``, m."""
    (l1, l2, l3, _), (c1, c2, c3) = linkage.lengths, linkage.links
    r1 = c1.com / l1 * pos.l1
    r2 = pos.l1 + c2.com / l2 * pos.l2
    r3 = pos.A2 + c3.com / l3 * pos.l3
    return r1, r2, r3


def total_com_direct(linkage: FourBar, pos: Position) -> NDArray[np.complex128]:
    """Total centre of mass as the mass-weighted sum of the link centres of mass, m."""
    r1, r2, r3 = link_centres_of_mass(linkage, pos)
    c1, c2, c3 = linkage.links
    return (c1.mass * r1 + c2.mass * r2 + c3.mass * r3) / linkage.total_mass


def total_com_opened(linkage: FourBar, pos: Position) -> NDArray[np.complex128]:
    """Total centre of mass from the opened-loop principal vectors (Eq. 16), m.

    ``r̄S = −(ā'14 + ā21 + ā32)`` with A0 at the origin.
    """
    pv = opened_loop_vectors(linkage, pos)
    return -(pv.a14p + pv.a21 + pv.a32)


def total_com_frame(linkage: FourBar, pos: Position) -> NDArray[np.complex128]:
    """Total centre of mass from the principal vectors about the frame (Eq. 32), m.

    ``r̄S = −ā14 − ā41 − ā34``.
    """
    pv = frame_vectors(linkage, pos)
    return -pv.a14 - pv.a41 - pv.a34


# ----------------------------------------------------------------------------------------------
# Wunderlich 1964


@dataclass(frozen=True)
class WunderlichLinkage:
    """The four-bar B0 B1 B2 B3 whose coupler point traces the total centre of mass.

    Wunderlich (1964), Eq. 4, 7–9, with the masses normalised by ``m_tot``: the centre of mass is
    ``Z = α1·l̄1 + α2·l̄2 + α3·l̄3 = c + γ·z`` where ``z = l̄1 + β·l̄2`` is the coupler point of
    the linkage itself with ``A1B = β·l̄2``.

    Attributes
    ----------
    alpha
        ``(α1, α2, α3)`` of his Eq. 7 (dimensionless, complex).
    B0, B3
        Fixed pivots ``Z0 = α3·a`` and ``Z3 = α1·a`` with ``a = l4`` (his Eq. 8), m.
    gamma
        Similarity factor ``γ = α1 − α3`` (rotation and scale; his Eq. 4).
    beta
        Coupler-point ratio ``β = (α2 − α3)/(α1 − α3)`` (his Eq. 9); infinite when
        ``α1 = α3``.
    """

    alpha: tuple[complex, complex, complex]
    B0: complex
    B3: complex
    gamma: complex
    beta: complex

    def trace(self, pos: Position) -> NDArray[np.complex128]:
        """The total centre of mass as ``B0 + γ·(l̄1 + β·l̄2)``, m."""
        return self.B0 + self.gamma * (pos.l1 + self.beta * pos.l2)

    def generating_joints(
        self, pos: Position
    ) -> tuple[NDArray[np.complex128], NDArray[np.complex128]]:
        """Moving joints B1, B2 of the generating linkage (``v_k = γ·l̄k``), m."""
        b1 = self.B0 + self.gamma * pos.l1
        return b1, b1 + self.gamma * pos.l2

    @property
    def is_circle(self) -> bool:
        """Whether the path degenerates to a circle (β = 0, 1 or ∞; Wunderlich Eq. 5a–c)."""
        a1, a2, a3 = self.alpha
        scale = max(abs(a1), abs(a2), abs(a3), 1.0)
        tol = 1e-12 * scale
        return abs(a2 - a3) < tol or abs(a1 - a2) < tol or abs(a1 - a3) < tol

    @property
    def is_stationary(self) -> bool:
        """Whether the path shrinks to a point (α1 = α2 = α3; Wunderlich Eq. 5d, Theorem 2)."""
        a1, a2, a3 = self.alpha
        scale = max(abs(a1), abs(a2), abs(a3), 1.0)
        return abs(a1 - a2) < 1e-12 * scale and abs(a2 - a3) < 1e-12 * scale


def wunderlich_linkage(linkage: FourBar) -> WunderlichLinkage:
    """Wunderlich's generating four-bar for the total centre-of-mass path (his Eq. 7–9).

    His ``σk`` are the centres of mass as fractions of the link vectors, ``σk = s̄k/lk``, and
    his masses sum to one.
    """
    (l1, l2, l3, l4), (c1, c2, c3) = linkage.lengths, linkage.links
    mt = linkage.total_mass
    mu1, mu2, mu3 = c1.mass / mt, c2.mass / mt, c3.mass / mt
    s1, s2, s3 = c1.com / l1, c2.com / l2, c3.com / l3
    a1 = mu1 * s1 + mu2 + mu3
    a2 = mu2 * s2 + mu3
    a3 = mu3 * s3
    gamma = a1 - a3
    beta = (a2 - a3) / gamma if gamma != 0 else complex("inf")
    a = complex(l4, 0.0)  # u1 + u2 + u3 = A0A3
    return WunderlichLinkage(
        alpha=(complex(a1), complex(a2), complex(a3)),
        B0=complex(a3 * a),
        B3=complex(a1 * a),
        gamma=complex(gamma),
        beta=complex(beta),
    )


# ----------------------------------------------------------------------------------------------
# Equivalent mass matrix (Eq. 45–46) and the assembled four-bar matrices (Eq. 48–49, 53–54)










#: Order of the nodes in the four-bar's global matrices.
NODES = ("A0", "A1", "A2", "A3")
#: Nodes (first, second) of each moving link in :data:`NODES`.
LINK_NODES = ((0, 1), (1, 2), (2, 3))


def global_mass_matrix(linkage: FourBar, inertias: Sequence[float] | None = None
                       ) -> NDArray[np.float64]:
    """Assembled 8×8 mass matrix over the joint coordinates of A0, A1, A2, A3 (Eq. 45), kg.

    Parameters
    ----------
    linkage
        The four-bar.
    inertias
        Moments of inertia about the centres of mass to use instead of the links' own (for
        example including counter-rotors), kg·m².
    """
    big = np.zeros((8, 8))
    for k, (link, (p, q)) in enumerate(zip(linkage.links, LINK_NODES, strict=True)):
        if inertias is not None:
            link = Link(mass=link.mass, inertia=inertias[k], e=link.e, f=link.f)
        me = equivalent_mass_matrix(link.inertial_parameters, linkage.lengths[k])
        idx = [2 * p, 2 * p + 1, 2 * q, 2 * q + 1]
        big[np.ix_(idx, idx)] += me
    return big


def fourbar_mass_matrix(linkage: FourBar, inertias: Sequence[float] | None = None
                        ) -> NDArray[np.float64]:
    """The 4×4 mass matrix ``M`` of Eq. 48 over ``(r_A1x, r_A1y, r_A2x, r_A2y)``, kg."""
    return global_mass_matrix(linkage, inertias)[2:6, 2:6]


def reaction_mass_matrix(linkage: FourBar, inertias: Sequence[float] | None = None
                         ) -> NDArray[np.float64]:
    """The 4×4 matrix ``M_r`` of Eq. 53: rows A0x, A0y, A3x, A3y; columns A1x, A1y, A2x, A2y."""
    g = global_mass_matrix(linkage, inertias)
    return g[np.ix_([0, 1, 6, 7], [2, 3, 4, 5])]


def fourbar_force_vector(linkage: FourBar, pos: LinkVectors,
                         moments: Sequence[Num] | None = None) -> tuple[Num, ...]:
    """Force vectors of Eq. 49 (at A1, A2) and Eq. 54 without the reactions (at A0, A3).

    Returns the equivalent applied forces at the four nodes as complex arrays
    ``(F_A0, F_A1, F_A2, F_A3)``, N. ``F_A1``, ``F_A2`` are ``F1 + i·F2`` and ``F3 + i·F4`` of
    Eq. 49; ``F_A0``, ``F_A3`` are Eq. 54's ``F_r`` plus the reactions.

    Parameters
    ----------
    moments
        Applied moments on the three links to use instead of the links' own, N·m.
    """
    vectors = (pos.l1, pos.l2, pos.l3)
    nodes: list[Num] = [0j, 0j, 0j, 0j]
    for k, (link, (p, q)) in enumerate(zip(linkage.links, LINK_NODES, strict=True)):
        mom = None if moments is None else moments[k]
        fp, fq = equivalent_joint_forces(link, linkage.lengths[k], vectors[k], mom)
        nodes[p] = nodes[p] + fp
        nodes[q] = nodes[q] + fq
    return tuple(nodes)
