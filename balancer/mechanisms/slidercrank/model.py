"""The slider-crank's data: its lengths, crank, rod and slider, branch and gas force.

Conventions (DESIGN.md): A0 at the origin; crank A0→A1, connecting rod A1→A2, the slider's pin
A2 on the guide line ``y = offset`` along +x.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Any, ClassVar

from ...errors import AssemblyError, SpecError
from ...model.links import GasForce, Link
from ...model.mechanisms import Branch, ChainModel


@dataclass(frozen=True, kw_only=True)
class SliderCrank(ChainModel):
    """A slider-crank A0 A1 A2 with the slider's pin A2 on a straight guide.

    Wunderlich (1964), Sect. 3.

    A0 at the origin; link 1 (crank) A0→A1, link 2 (connecting rod) A1→A2; the slider's pin A2
    moves on the guide line ``y = offset`` along x. θ1, θ2 are the angles of A0→A1 and A1→A2.

    Attributes
    ----------
    lengths
        ``(r, L, e)``: crank and rod lengths (m, positive) and the signed offset of the guide
        from A0 (m).
    crank, rod
        The rotating links (centre of mass in the link frame, as for the four-bar).
    slider
        The slider: its centre of mass relative to the pin is in global axes; its inertia does
        not matter (it does not turn).
    branch
        ``"+"``: the slider on the +x side of the crank pin; ``"-"``: the other assembly.
    gas_force
        Force on the slider along the guide, from the frame (see :class:`GasForce`).
    """

    type: ClassVar[str] = "slider-crank"
    length_names: ClassVar[tuple[str, ...]] = ("crank", "rod", "offset")
    chain_links: ClassVar[tuple[str, ...]] = ("crank", "rod", "slider")
    #: The crank's pivot is the only one on the ground: where a counter-rotor can sit.
    ground_pivoted: ClassVar[tuple[str, ...]] = ("crank",)

    lengths: tuple[float, float, float]
    crank: Link
    rod: Link
    slider: Link
    branch: Branch = "+"
    gas_force: GasForce = field(default_factory=GasForce)

    def __post_init__(self) -> None:
        """Check lengths, links and branch; raise :class:`AssemblyError` if it never assembles.

        Keys are the spec's, from its root (``mechanism.lengths.offset``).
        """
        if not isinstance(self.gas_force, GasForce):
            raise SpecError("must be a GasForce", key="links.slider.gas_force",
                            value=self.gas_force)
        r, big_l, e = self.check_chain()
        if abs(e) > r + big_l:
            raise AssemblyError(
                f"the slider-crank cannot be assembled at any crank angle: the guide is "
                f"{abs(e):.6g} m from A0, beyond the reach of crank and rod "
                f"({r + big_l:.6g} m)",
                key="mechanism.lengths.offset",
                value=e,
            )

    @property
    def links(self) -> tuple[Link, Link, Link]:
        """The moving links in order (crank, rod, slider)."""
        return (self.crank, self.rod, self.slider)

    @property
    def gas_forces(self) -> tuple[tuple[str, GasForce], ...]:
        """Forces on sliders along their guides, by spec key: the gas force."""
        return (("links.slider.gas_force", self.gas_force),)

    def unloaded_fields(self) -> dict[str, Any]:
        """Without loads, no gas force either."""
        return {"gas_force": GasForce()}
