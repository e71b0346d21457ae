"""The four-bar's data: its lengths, its three moving links and its assembly branch.

Conventions (DESIGN.md): ground pivots A0 at the origin and A3 at ``(l4, 0)``; links crank
A0→A1, coupler A1→A2, rocker A2→A3.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import ClassVar

from ...errors import AssemblyError
from ...model.links import Link
from ...model.mechanisms import Branch, ChainModel
from .assembly import assembly_range


@dataclass(frozen=True, kw_only=True)
class FourBar(ChainModel):
    """A planar 4R four-bar linkage A0 A1 A2 A3 (Meijaard & van der Wijk 2020, Fig. 1).

    Ground pivots A0 at the origin and A3 at ``(l4, 0)``. Link 1 (crank) A0→A1, link 2 (coupler)
    A1→A2, link 3 (rocker) A2→A3, link 4 the frame A3→A0 (θ4 = π).

    Attributes
    ----------
    lengths
        ``(l1, l2, l3, l4)``: crank, coupler, rocker and frame lengths, m.
    crank, coupler, rocker
        The three moving links.
    branch
        ``"+"``: A2 to the left of the directed line A1→A3 (the paper's Fig. 1); ``"-"``: the
        other assembly.
    """

    type: ClassVar[str] = "four-bar"
    length_names: ClassVar[tuple[str, ...]] = ("crank", "coupler", "rocker", "frame")
    chain_links: ClassVar[tuple[str, ...]] = ("crank", "coupler", "rocker")
    #: Links whose pivot is on the ground, where a counter-rotor can sit.
    ground_pivoted: ClassVar[tuple[str, ...]] = ("crank", "rocker")

    lengths: tuple[float, float, float, float]
    crank: Link
    coupler: Link
    rocker: Link
    branch: Branch = "+"

    def __post_init__(self) -> None:
        """Check lengths, links and branch; raise :class:`AssemblyError` if it never assembles.

        Keys are the spec's, from its root (``mechanism.lengths.crank``).
        """
        self.check_chain()
        lengths = self.lengths  # as check_chain stored them
        if assembly_range(lengths).empty:
            l1, l2, l3, l4 = lengths
            raise AssemblyError(
                "the linkage cannot be assembled at any crank angle: the coupler and rocker "
                f"(|l2 − l3| = {abs(l2 - l3):.6g} m to l2 + l3 = {l2 + l3:.6g} m) cannot "
                f"bridge A1 to A3 (|l4 − l1| = {abs(l4 - l1):.6g} m to l1 + l4 = "
                f"{l1 + l4:.6g} m)",
                key="mechanism.lengths",
                value=dict(zip(self.length_names, lengths, strict=True)),
            )

    @property
    def links(self) -> tuple[Link, Link, Link]:
        """The moving links in order (crank, coupler, rocker)."""
        return (self.crank, self.coupler, self.rocker)
