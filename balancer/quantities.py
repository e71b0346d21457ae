"""The quantities the package reports, each named once: key, words, unit, panel.

One table (:data:`QUANTITIES`) names what a mechanism does to its frame and what balancing
weighs: the key under which JSON documents, objective terms, sweep columns and fronts carry it,
the words a report and a plot's title use, its SI unit, and the panel of a drawing that shows
it. Reports, plots, the balancing's objective, fronts and sweeps read their names and units
here; a new output quantity is a line here and the figure that computes it.
"""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass


@dataclass(frozen=True)
class Quantity:
    """One reported quantity.

    Attributes
    ----------
    key
        Its name in JSON documents, objective terms and table columns (``shaking_force``).
    words
        What a report calls it (``shaking force``).
    unit
        Its SI unit (``N``, ``N·m``, ``kg``).
    axis
        What an axis over the crank angle calls it (the words, unless more is to be said).
    panel
        The key of the panel of a cycle drawing that shows it (``force``), or ``""`` where no
        panel does.
    frame
        Whether it is a load on the frame over the cycle, whose RMS and maximum every analysis
        reports (its summary's figure of that key, where the mechanism has one).
    out_of_plane
        Whether it is zero for a mechanism in one plane: a table then leaves it out.
    """

    key: str
    words: str
    unit: str
    axis: str = ""
    panel: str = ""
    frame: bool = False
    out_of_plane: bool = False

    @property
    def label(self) -> str:
        """The axis' label: its words and unit (``shaking force (N)``)."""
        return f"{self.axis or self.words} ({self.unit})"


#: Every reported quantity by key: the frame's loads over a revolution (their RMS and maxima
#: in every report), then what balancing also weighs.
QUANTITIES: Mapping[str, Quantity] = {q.key: q for q in (
    Quantity("shaking_force", "shaking force", "N", panel="force", frame=True),
    Quantity("shaking_moment", "shaking moment", "N·m",
             axis="shaking moment about the origin", panel="moment", frame=True),
    Quantity("driving_torque", "driving torque", "N·m", axis="driving torque on the crank",
             panel="torque", frame=True),
    Quantity("rocking_couple", "rocking couple", "N·m", panel="couple", frame=True,
             out_of_plane=True),
    Quantity("mount_torque", "mount torque", "N·m", axis="torque about z on the mounts",
             panel="mount", frame=True),
    Quantity("shaking_force_x", "shaking force along x", "N"),
    Quantity("shaking_force_y", "shaking force along y", "N"),
    Quantity("added_mass", "added mass", "kg"),
    Quantity("unbalance", "unbalance", "N"),
)}

#: The quantities a cycle drawing shows, by panel key.
PANELS: Mapping[str, Quantity] = {q.panel: q for q in QUANTITIES.values() if q.panel}
#: The loads on the frame every analysis reports, in the reports' order.
FRAME_LOADS: tuple[Quantity, ...] = tuple(q for q in QUANTITIES.values() if q.frame)


def unit_of(key: str) -> str:
    """The SI unit of quantity ``key``."""
    return QUANTITIES[key].unit


def words_of(key: str) -> str:
    """What a report calls quantity ``key``."""
    return QUANTITIES[key].words
