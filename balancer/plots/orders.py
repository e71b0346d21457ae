"""The order table as bars: each load's amplitude by multiple of the crank speed.

Per order, the shaking force's (and, for links in several planes, the rocking couple's) forward
and backward whirl side by side, and the shaking moment's and driving torque's amplitudes; of
the design and, for a balanced spec, of the original before it (:mod:`balancer.orders`).
"""

from __future__ import annotations

from typing import TYPE_CHECKING

import numpy as np

from ..cycle import ROUNDING_SPAN, CycleAnalysis, natural_scales
from ..orders import Order, order_name
from .style import COLOURS

if TYPE_CHECKING:  # annotations only: matplotlib is imported by the functions that draw
    from matplotlib.axes import Axes
    from matplotlib.figure import Figure

#: The panels: title, unit, and the bars of one order (label, value).
_PANELS = {
    "force": ("shaking force", "N"),
    "couple": ("rocking couple", "N·m"),
    "moment": ("shaking moment", "N·m"),
    "torque": ("driving torque", "N·m"),
}


def _bars(order: Order, panel: str) -> list[tuple[str, float]]:
    if panel == "force":
        return [("forward", order.shaking_force.forward),
                ("backward", order.shaking_force.backward)]
    if panel == "couple":
        return [("forward", order.rocking_couple.forward),
                ("backward", order.rocking_couple.backward)]
    value = order.shaking_moment if panel == "moment" else order.driving_torque
    return [("amplitude", abs(value))]


def plot_orders(analysis: CycleAnalysis, panel: str, before: CycleAnalysis | None = None,
                ax: Axes | None = None) -> Axes:
    """One panel of :func:`orders_figure`: ``"force"``, ``"couple"``, ``"moment"``, ``"torque"``.

    Bars by order (order 0: the mean's magnitude); for force and couple the forward whirl (with
    the crank) solid and the backward (against it) hatched; the original's grey beside the
    design's.
    """
    from .style import axes

    ax = axes(ax)
    title, unit = _PANELS[panel]
    rows = [(None, before), ("design", analysis)] if before is not None else [
        ("design", analysis)]
    orders = analysis.orders
    kinds = [label for label, _ in _bars(orders[0], panel)]
    groups = [(role, kind) for role, a in rows if a is not None for kind in kinds]
    width = 0.8 / len(groups)
    x = np.arange(len(orders))
    for i, (role, kind) in enumerate(groups):
        a = before if role is None else analysis
        assert a is not None
        floor = ROUNDING_SPAN * natural_scales(a)[panel]  # rounding: drawn as the zero it is
        values = [v if v > floor else 0.0 for v in
                  (dict(_bars(o, panel))[kind] for o in a.orders)]
        colour = COLOURS["before"] if role is None else COLOURS["after"]
        who = "original" if role is None else ("balanced design" if before is not None
                                               else "design")
        ax.bar(x - 0.4 + width * (i + 0.5), values, width, color=colour,
               hatch="//" if kind == "backward" else None, edgecolor="k", linewidth=0.4,
               label=f"{who}, {kind}" if kind != "amplitude" else who)
    ax.set_xticks(x, [order_name(o.order) for o in orders])
    ax.set_xlabel("order (multiple of the crank speed)")
    ax.set_ylabel(f"{title} ({unit})")
    ax.set_title(f"{title} by order")
    ax.grid(axis="y", alpha=0.3)
    ax.legend(fontsize="small")
    return ax


def orders_figure(analysis: CycleAnalysis, before: CycleAnalysis | None = None,
                  title: str = "") -> Figure:
    """The order table of ``analyze`` as bars, of the design and of its original if given."""
    from matplotlib.figure import Figure

    panels = ["force", *([] if analysis.mechanism.in_one_plane() else ["couple"]),
              "moment", "torque"]
    fig = Figure(figsize=(12, 3.2 * len(panels)), layout="constrained")
    axes = fig.subplots(len(panels), 1)
    for panel, ax in zip(panels, axes, strict=True):
        plot_orders(analysis, panel, before, ax)
    what = f"orders at {analysis.speed:g} rad/s (peak amplitudes; order 0: the mean)"
    if before is not None:
        what += ", before and after balancing"
    fig.suptitle(f"{title}\n{what}" if title else what)
    return fig
