"""What a drawing shows of a mechanism besides its links: sliding blocks and shafts' masses.

A mechanism's links are drawn from its kinematics alone (:mod:`balancer.plots.drawing`); a
mechanism adds one :class:`Drawing` (:meth:`~balancer.mechanisms.base.Mechanism.drawing`): the
rectangle of each sliding link that is one point (a piston, by its bore), and the counterweights
and eccentrics on shafts geared to the crank (an engine's). Like
:mod:`~balancer.mechanisms.presentation`, the plots read it; the kinematics, dynamics and
balancing never do.
"""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass, field

from ..model import Linkage

#: A sliding block's size in a drawing where the mechanism gives none: its length along its
#: slider and its width across, as fractions of the crank's reach (:func:`of_linkage`).
BLOCK_SIZE = (0.6, 0.35)
#: A piston's length along its cylinder over its bore, in a drawing.
PISTON_LENGTH = 0.7


def piston_block(crank: float, bore: float | None) -> tuple[float, float]:
    """A piston's ``(length, width)`` in a drawing, m.

    Its bore across (without one, the stroke ``2·crank``: a square engine), and
    :data:`PISTON_LENGTH` of it along its axis; ``crank`` and ``bore`` in m.
    """
    width = bore if bore is not None else 2.0 * crank
    return PISTON_LENGTH * width, width


@dataclass(frozen=True)
class DrawnMass:
    """A mass·radius on a shaft geared to the crank, as a drawing shows it.

    Attributes
    ----------
    axis
        The shaft's axis in the x–y plane, complex, m.
    ratio
        The shaft's speed over the crank's (its angle is ``ratio·θ1 + angle``).
    angle
        The mass' direction from the axis at θ1 = 0, rad.
    mr
        Its mass·radius, kg·m.
    what
        ``"counterweight"`` or ``"eccentric"``.
    """

    axis: complex
    ratio: float
    angle: float
    mr: float
    what: str


@dataclass(frozen=True)
class Drawing:
    """What a drawing shows of a mechanism besides its links' lines.

    Attributes
    ----------
    reach
        The input link's reach: its farthest point from its first (its pivot), m; with
        several inputs, the largest of theirs. It scales the blocks and the masses' sectors.
    blocks
        Per sliding link that is one point, the ``(length, width)`` of a rectangle centred on
        its point, its length along its frame's x-axis (its slider's direction), m.
    masses
        The counterweights and eccentrics on shafts geared to the crank (none in general: a
        link's counterweight is part of the link, a counter-rotor a disc on its axis).
    """

    reach: float
    blocks: Mapping[str, tuple[float, float]] = field(default_factory=dict)
    masses: tuple[DrawnMass, ...] = ()


def crank_reach(linkage: Linkage) -> float:
    """The input links' largest reach: a point's farthest distance from its link's first, m."""
    places = dict(linkage.points)
    reach = 0.0
    for name in linkage.inputs:
        first, *others = next(b.points for b in linkage.bodies if b.name == name)
        pivot = complex(*places[first])
        reach = max([reach, *(abs(complex(*places[p]) - pivot) for p in others)])
    return reach


def of_linkage(linkage: Linkage) -> Drawing:
    """A general linkage's drawing: its one-point sliding links as blocks, no shafts' masses.

    Each block :data:`BLOCK_SIZE` of the crank's reach.
    """
    reach = crank_reach(linkage)
    one_point = {b.name for b in linkage.bodies if len(b.points) == 1}
    return Drawing(reach=reach, blocks={s.link: (BLOCK_SIZE[0] * reach, BLOCK_SIZE[1] * reach)
                                        for s in linkage.sliders if s.link in one_point})
