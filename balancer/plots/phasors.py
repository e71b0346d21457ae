"""Phasor pictures: each plane's force and couple at an order, as arrows at θ1 = 0, and their sums.

One panel per order and load (the shaking force; the rocking couple where masses move in
several planes): the planes' forward phasors (turning with the crank) head to tail from the
origin, then their sum, the free load's forward whirl, as a thick arrow; the backward phasors
(turning against it) the same beside them. Where a chain closes on itself the engine is
balanced in that order and load. The phasors are :mod:`balancer.phasors`'; this module
computes nothing.
"""

from __future__ import annotations

from typing import TYPE_CHECKING

from ..orders import order_name
from ..phasors import Phasors
from ..rounding import Scales, speed_text
from .style import COLOURS, number

if TYPE_CHECKING:  # annotations only: matplotlib is imported by the functions that draw
    from matplotlib.axes import Axes
    from matplotlib.figure import Figure

#: The forward chain's colour, the backward's (colour-blind safe, Okabe & Ito).
FORWARD, BACKWARD = "#0072B2", "#D55E00"


def plot_phasors(phasors: Phasors, order: int, load: str, ax: Axes) -> Axes:
    """One panel: the planes' ``load`` (``"force"`` or ``"couple"``) phasors at ``order``.

    Forward and backward chains head to tail, each closed by its sum (thick), N or N·m.
    """
    unit = "N" if load == "force" else "N·m"
    reach = 0.0
    for k, (colour, which) in enumerate(((FORWARD, "forward"), (BACKWARD, "backward"))):
        tip = 0j
        for plane in phasors.planes:
            arrow = (plane.force[order] if load == "force" else plane.couple(order))[k]
            if abs(arrow) > 0:
                head = tip + arrow
                ax.annotate("", xy=(head.real, head.imag), xytext=(tip.real, tip.imag),
                            arrowprops={"arrowstyle": "->", "color": colour, "lw": 1.2})
            tip += arrow
            reach = max(reach, abs(tip))
        total = (phasors.total_force(order) if load == "force"
                 else phasors.total_couple(order))[k]
        # a sum at rounding of its chain's reach: the chain closes (none drawn, 0 printed)
        size = 0.0 if Scales([(unit, reach)]).rounding(abs(total), unit) else abs(total)
        if size:
            ax.annotate("", xy=(total.real, total.imag), xytext=(0.0, 0.0),
                        arrowprops={"arrowstyle": "-|>", "color": COLOURS["sum"], "lw": 2.4})
        ax.plot([], [], color=colour, lw=1.2,
                label=f"{which}: each plane; sum {number(size) if size else '0'} {unit}")
        reach = max(reach, size)
    ax.plot([], [], color=COLOURS["sum"], lw=2.4, label="sum: the free load's whirl")
    reach = reach or 1.0
    ax.set_xlim(-1.1 * reach, 1.1 * reach)
    ax.set_ylim(-1.1 * reach, 1.1 * reach)
    ax.set_aspect("equal")
    ax.axhline(0.0, color="0.8", lw=0.6, zorder=0)
    ax.axvline(0.0, color="0.8", lw=0.6, zorder=0)
    words = "force" if load == "force" else "couple (Mx + i·My)"
    ax.set_title(f"order {order_name(order)}: {words}, {unit}")
    ax.set_xlabel(f"x ({unit})" if load == "force" else f"Mx ({unit})")
    ax.set_ylabel(f"y ({unit})" if load == "force" else f"My ({unit})")
    ax.legend(loc="upper center", bbox_to_anchor=(0.5, -0.16), fontsize="small")
    return ax


def phasors_figure(phasors: Phasors, title: str = "") -> Figure:
    """Every order's force panel (and couple panel, for masses in several planes)."""
    from matplotlib.figure import Figure

    loads = ["force"] if phasors.in_one_plane else ["force", "couple"]
    rows = len(phasors.orders)
    fig = Figure(figsize=(5.2 * len(loads), 5.6 * rows), layout="constrained")
    grid = fig.subplots(rows, len(loads), squeeze=False)
    for i, order in enumerate(phasors.orders):
        for j, load in enumerate(loads):
            plot_phasors(phasors, order, load, grid[i][j])
    what = (f"phasors at θ1 = 0, {speed_text(phasors.speed)}:\neach plane's inertial load by "
            f"order ({len(phasors.planes)} planes), forward and backward whirls head to tail")
    fig.suptitle(f"{title}\n{what}" if title else what)
    return fig


__all__ = ["phasors_figure", "plot_phasors"]
