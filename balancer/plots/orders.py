"""The order table as bars: each load's amplitude by multiple of the crank speed.

Per order, the shaking force's (and, for links in several planes, the rocking couple's) forward
and backward whirl side by side, and the shaking moment's, driving torque's and an engine's
mount torque's amplitudes (order 0: the signed mean); of the design and, for a balanced spec, of
the original before it (:mod:`balancer.orders`). On a linear or a logarithmic axis.
"""

from __future__ import annotations

from typing import TYPE_CHECKING

import numpy as np

from ..cycle import ROUNDING_SPAN, CycleAnalysis, natural_scales, panel_keys
from ..orders import Order, order_name
from ..quantities import PANELS
from ..rounding import speed_text
from .style import COLOURS, axes, number

if TYPE_CHECKING:  # annotations only: matplotlib is imported by the functions that draw
    from matplotlib.axes import Axes
    from matplotlib.figure import Figure

#: On a logarithmic axis, a bar at most this fraction of its panel's largest is rounding of
#: it: left out (as the zero it is), so that it does not stretch the axis over decades of noise.
LOG_FLOOR = 1e-12


def _bars(order: Order, panel: str) -> list[tuple[str, float]]:
    """The bars of one order in a panel: ``(kind, value)``; a scalar's order 0 signed."""
    if panel == "force":
        return [("forward", order.shaking_force.forward),
                ("backward", order.shaking_force.backward)]
    if panel == "couple":
        return [("forward", order.rocking_couple.forward),
                ("backward", order.rocking_couple.backward)]
    value = {"moment": order.shaking_moment, "torque": order.driving_torque,
             "mount": order.mount_torque}[panel]
    return [("amplitude", np.nan if value is None else value)]


def plot_orders(analysis: CycleAnalysis, panel: str, before: CycleAnalysis | None = None,
                ax: Axes | None = None, *, log: bool = False) -> Axes:
    """One panel of :func:`orders_figure`: a load's bars by order, N or N·m.

    ``panel`` ``"force"``, ``"couple"``, ``"moment"``, ``"torque"`` or (an engine's)
    ``"mount"``. Bars by order: peak amplitudes, and at order 0 the mean — a moment's or
    torque's with its sign (a firing engine's driving torque is negative), a force's or
    couple's magnitude. For force and couple the forward whirl (with the crank) solid and the
    backward (against it) hatched; the original's grey beside the design's. A bar below
    rounding of its load's natural scale is drawn as the zero it is.

    ``log``: a logarithmic axis of magnitudes (84 N beside 43 kN) in whole decades, from
    below the smallest bar above :data:`LOG_FLOOR` of the largest; a negative mean is drawn by
    its magnitude and labelled with its signed value. A panel with no bar above zero stays
    linear.
    """
    ax = axes(ax)
    title, unit = PANELS[panel].words, PANELS[panel].unit
    rows = [(None, before), ("design", analysis)] if before is not None else [
        ("design", analysis)]
    orders = analysis.orders
    kinds = [label for label, _ in _bars(orders[0], panel)]
    groups = [(role, kind) for role, a in rows if a is not None for kind in kinds]
    width = 0.8 / len(groups)
    x = np.arange(len(orders))
    drawn: list[tuple[str | None, str, list[float]]] = []
    for role, kind in groups:
        a = before if role is None else analysis
        assert a is not None
        floor = ROUNDING_SPAN * natural_scales(a)[panel]  # rounding: drawn as the zero it is
        drawn.append((role, kind, [v if abs(v) > floor else 0.0 for v in
                                   (dict(_bars(o, panel))[kind] for o in a.orders)]))
    largest = max((abs(v) for _, _, values in drawn for v in values if np.isfinite(v)),
                  default=0.0)
    log = log and largest > 0.0
    for i, (role, kind, values) in enumerate(drawn):
        heights = values
        if log:
            heights = [abs(v) if abs(v) > LOG_FLOOR * largest else 0.0 for v in values]
        colour = COLOURS["before"] if role is None else COLOURS["after"]
        who = "original" if role is None else ("balanced design" if before is not None
                                               else "design")
        where = x - 0.4 + width * (i + 0.5)
        ax.bar(where, heights, width, color=colour,
               hatch="//" if kind == "backward" else None, edgecolor="k", linewidth=0.4,
               label=f"{who}, {kind}" if kind != "amplitude" else who)
        if log:
            for at, value, height in zip(where, values, heights, strict=True):
                if value < 0 and height > 0:
                    ax.annotate(number(value).replace("-", "−"), (at, height),
                                xytext=(0, 2), textcoords="offset points", ha="center",
                                va="bottom", rotation=90, fontsize="x-small")
    if log:
        shown = [abs(v) for _, _, values in drawn for v in values
                 if abs(v) > LOG_FLOOR * largest]
        ax.set_yscale("log")
        # Whole decades, the smallest bar at least twice the axis' foot and the largest at
        # most half its top.
        ax.set_ylim(10.0 ** np.floor(np.log10(min(shown)) - np.log10(2.0)),
                    10.0 ** np.ceil(np.log10(largest) + np.log10(2.0)))
    else:
        ax.axhline(0.0, color="k", lw=0.6)
    ax.set_xticks(x, [order_name(o.order) for o in orders])
    ax.set_xlabel("order (multiple of the crank speed)")
    ax.set_ylabel(f"{title} ({unit}){', log scale' if log else ''}")
    ax.set_title(f"{title} by order")
    ax.grid(axis="y", alpha=0.3)
    ax.legend(fontsize="small")
    return ax


def orders_figure(analysis: CycleAnalysis, before: CycleAnalysis | None = None,
                  title: str = "", *, log: bool = False) -> Figure:
    """The order table of ``analyze`` as bars, of the design and of its original if given.

    A panel per load (:func:`plot_orders`): the shaking force, the rocking couple (where the
    design or the original has links in several planes), the shaking moment, the driving
    torque and an engine's mount torque; ``log`` draws each on a logarithmic axis. The title
    gives the speed in rad/s and rpm.
    """
    from matplotlib.figure import Figure

    panels = list(panel_keys(analysis, before))
    fig = Figure(figsize=(12, 3.2 * len(panels)), layout="constrained")
    axes = fig.subplots(len(panels), 1)
    for panel, ax in zip(panels, axes, strict=True):
        plot_orders(analysis, panel, before, ax, log=log)
    what = (f"orders at {speed_text(analysis.speed)} (peak amplitudes; order 0: the mean, "
            "a moment's or torque's with its sign)")
    if before is not None:
        what += ", before and after balancing"
    fig.suptitle(f"{title}\n{what}" if title else what)
    return fig
