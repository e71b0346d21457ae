"""A trade-off front of least shaking against a second objective, as a report shows it."""

from __future__ import annotations

from typing import TYPE_CHECKING

import numpy as np

from ..balance.front import FIGURES
from .style import mark_point, number

if TYPE_CHECKING:  # annotations only: matplotlib is imported by the functions that draw
    from matplotlib.figure import Figure

    from ..balance.front import Front  # (no cycle: loaded by the command that makes it)


#: How far beyond a front's own extent (a fraction of it) the axes reach to take the original
#: design in; one farther away is an arrow at the edge (the front is not squashed into a corner).
FRONT_REACH = 0.3


def front_figure(front: Front, title: str | None = None) -> Figure:
    """A trade-off front as a designer puts it in a report.

    The least RMS shaking moment (an engine's: :attr:`Front.minimised`) against the second
    objective, each point's certified lower bound beside it, the knee marked. The axes are the
    front's: the original design is drawn where it lies within :data:`FRONT_REACH` of the
    front's extent, else as an arrow at the edge pointing its way, with its coordinates.

    Parameters
    ----------
    front
        A :class:`~balancer.balance.front.Front`.
    title
        The figure's title (default: what is traded against what).

    Notes
    -----
    The legend says whether the front's designs are held to exact force balance
    (:attr:`Front.force_balance`) and, where the original design is not force-balanced and the
    front is, why it is not on the front.
    """
    from matplotlib.figure import Figure

    force_balance, original_force_balanced = front.force_balance, front.original_force_balanced
    fig = Figure(figsize=(7.5, 4.5), layout="constrained")
    ax = fig.add_subplot()
    xs = np.array([p.value for p in front.points])
    ys = np.array([p.least for p in front.points])
    bounds = np.array([p.lower_bound for p in front.points])
    what = front.name.replace("_", " ")
    words, least_unit = FIGURES[front.minimised]
    label = f"least {words}" + (", every design force-balanced" if force_balance else "")
    if len(front.points) == 1:
        label += f" (one point: nothing to trade against {what})"
    ax.plot(xs, ys, "o-", color="C0", label=label)
    ax.plot(xs, bounds, "_", color="k", markersize=12, label="certified lower bound")
    knee = [p for p in front.points if p.knee]
    if knee:
        ax.plot([knee[0].value], [knee[0].least], "*", color="C3", markersize=14,
                label="knee")
    unit = f"{'RMS, ' if front.unit not in ('kg', 'kg·m') else ''}{front.unit}"
    ax.set_xlabel(f"{what} ({unit})")
    ax.set_ylabel(f"{words} ({least_unit})")
    ox, oy = front.original
    if np.isfinite(ox) and np.isfinite(oy):
        (x0, x1), (y0, y1) = _front_limits(xs, np.maximum(ys, bounds), (ox, oy))
        ax.set_xlim(x0, x1)
        ax.set_ylim(y0, y1)
        name = "original design"
        if force_balance and original_force_balanced is False:
            name += ": not force-balanced, so not on the front"
        mark_point(ax, ox, oy, name, f"original design\n{number(ox)} {front.unit}, "
                    f"{number(oy)} {least_unit}", marker="s", color="0.5", mec="0.2", ms=7)
    else:
        ax.set_ylim(bottom=0)
    ax.grid(True, alpha=0.3)
    short = words.removeprefix("RMS ")
    ax.set_title(title or f"{short[0].upper()}{short[1:]} against {what}")
    fig.legend(loc="outside lower center", ncols=1, fontsize="small")
    return fig


def _front_limits(xs: np.ndarray, ys: np.ndarray, original: tuple[float, float]
                  ) -> tuple[tuple[float, float], tuple[float, float]]:
    """The axes' limits of a front (its points ``xs``, ``ys``), and the original's if near.

    The moment axis starts at zero (less a margin, for the points at zero). The original is
    taken in if that widens the front's extent by at most :data:`FRONT_REACH` of it each way,
    or the front is a single point; then a margin of 5 % each side.
    """
    ox, oy = original
    x0, x1 = float(xs.min()), float(xs.max())
    y0, y1 = 0.0, float(ys.max())
    reach_x = FRONT_REACH * (x1 - x0)
    reach_y = FRONT_REACH * y1
    single = x1 - x0 <= 1e-9 * max(abs(x0), abs(x1))
    if single or ((x0 - reach_x <= ox <= x1 + reach_x) and oy <= y1 + reach_y):
        x0, x1 = min(x0, ox), max(x1, ox)
        y1 = max(y1, oy)
    if x1 == x0:
        x0, x1 = x0 - 0.5 * max(abs(x0), 1.0), x1 + 0.5 * max(abs(x1), 1.0)
    if y1 <= 0.0:
        y1 = 1.0
    pad_x, pad_y = 0.05 * (x1 - x0), 0.05 * (y1 - y0)
    return (x0 - pad_x, x1 + pad_x), (y0 - pad_y, y1 + pad_y)
