"""The quantities the package reports, each named once: key, words, unit, panel.

One table (:data:`QUANTITIES`) names what a mechanism does to its frame and what balancing
weighs: the key under which JSON documents, objective terms, sweep columns and fronts carry it,
the words a report and a plot's title use, its SI unit, and the panel of a drawing that shows
it. Reports, plots, the balancing's objective, fronts and sweeps read their names and units
here; a new output quantity is a line here and the figure that computes it.
"""

from __future__ import annotations

from collections.abc import Callable, Mapping
from dataclasses import dataclass
from typing import Any


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
    squares
        As a mean-square term of a balancing's objective: the frame loads it squares and
        averages, each ``(key, part)`` with part ``""`` (a real load), ``"x"`` or ``"y"`` (a
        complex one's components); empty for a term that is no load's mean square (the added
        mass, the unbalance, a largest load).
    largest
        As a term of a balancing's objective that weighs the square of a load's largest
        magnitude (over the samples and, for the supports, every support): that load's key;
        ``""`` for every other quantity.
    """

    key: str
    words: str
    unit: str
    axis: str = ""
    panel: str = ""
    frame: bool = False
    out_of_plane: bool = False
    squares: tuple[tuple[str, str], ...] = ()
    largest: str = ""

    @property
    def label(self) -> str:
        """The axis' label: its words and unit (``shaking force (N)``)."""
        return f"{self.axis or self.words} ({self.unit})"


#: Every reported quantity by key: the frame's loads over a revolution (their RMS and maxima
#: in every report), then what balancing also weighs.
QUANTITIES: Mapping[str, Quantity] = {q.key: q for q in (
    Quantity("shaking_force", "shaking force", "N", panel="force", frame=True,
             squares=(("shaking_force", "x"), ("shaking_force", "y"))),
    Quantity("shaking_moment", "shaking moment", "N·m",
             axis="shaking moment about the origin", panel="moment", frame=True,
             squares=(("shaking_moment", ""),)),
    Quantity("driving_torque", "driving torque", "N·m", axis="driving torque on the crank",
             panel="torque", frame=True, squares=(("driving_torque", ""),)),
    Quantity("rocking_couple", "rocking couple", "N·m", panel="couple", frame=True,
             out_of_plane=True, squares=(("rocking_couple", "x"), ("rocking_couple", "y"))),
    Quantity("mount_torque", "mount torque", "N·m", axis="torque about z on the mounts",
             panel="mount", frame=True),
    Quantity("shaking_force_x", "shaking force along x", "N",
             squares=(("shaking_force", "x"),)),
    Quantity("shaking_force_y", "shaking force along y", "N",
             squares=(("shaking_force", "y"),)),
    Quantity("added_mass", "added mass", "kg"),
    Quantity("unbalance", "unbalance", "N"),
    Quantity("main_bearing_load", "main-bearing load", "N",
             squares=(("supports", "x"), ("supports", "y"))),
    Quantity("largest_bearing_load", "largest main-bearing load", "N", largest="supports"),
)}

#: The quantities a cycle drawing shows, by panel key.
PANELS: Mapping[str, Quantity] = {q.panel: q for q in QUANTITIES.values() if q.panel}
#: The loads on the frame every analysis reports, in the reports' order.
FRAME_LOADS: tuple[Quantity, ...] = tuple(q for q in QUANTITIES.values() if q.frame)


def squared_parts(key: str, load: Callable[[str], Any]) -> list[Any]:
    """The arrays the mean-square term ``key`` squares and averages (:attr:`Quantity.squares`).

    ``load`` gives a frame load by its key: samples, or a linear map of a design vector whose
    rows are samples (a complex load's ``x`` and ``y`` parts are its real and imaginary parts).
    """
    out = []
    for name, part in QUANTITIES[key].squares:
        value = load(name)
        out.append(value if not part else value.real if part == "x" else value.imag)
    return out


def unit_of(key: str) -> str:
    """The SI unit of quantity ``key``."""
    return QUANTITIES[key].unit


def words_of(key: str) -> str:
    """What a report calls quantity ``key``."""
    return QUANTITIES[key].words
