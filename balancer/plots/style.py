"""What every figure shares: colours, line styles, axes, legends, numbers, and writing files."""

from __future__ import annotations

import os
from pathlib import Path
from typing import TYPE_CHECKING, Any

import numpy as np

from ..linkage.inputs import InputState
from ..mechanisms.base import Mechanism
from ..model import MechanismModel as Model
from ..outputs import figure_type, write_with
from .drawing import frame, pitch_circles

if TYPE_CHECKING:  # annotations only: matplotlib is imported by the functions that draw
    from matplotlib.axes import Axes
    from matplotlib.figure import Figure
    from matplotlib.lines import Line2D


#: Colours for the sum, before and after, links, centres of mass and balance shafts'
#: eccentrics (colour-blind safe, Okabe & Ito).
COLOURS = {"sum": "#000000", "before": "#999999", "after": "#009E73", "link": "#0072B2",
           "com": "#D55E00", "eccentric": "#E69F00"}


#: How a curve of the original (before) and of the design (after) is drawn where both are: the
#: original dashed on top, so that it shows where the two coincide.
BEFORE_STYLE: dict[str, Any] = {"color": COLOURS["before"], "lw": 1.4, "ls": (0, (5, 2)),
                                 "zorder": 3}

AFTER_STYLE: dict[str, Any] = {"color": COLOURS["after"], "lw": 2.2, "zorder": 2}

#: Colours for the forces at the ground points and guides, in order (A0, A3, … ).
SERIES = ("#0072B2", "#D55E00", "#CC79A7", "#E69F00", "#56B4E9", "#F0E442", "#009E73")


def axes(ax: Axes | None) -> Axes:
    """``ax``, or the axes of a new figure (7 × 4 in) where it is ``None``."""
    from matplotlib.figure import Figure

    if ax is not None:
        return ax
    return Figure(figsize=(7, 4), layout="constrained").add_subplot()


def legend_outside(ax: Axes, **kw: Any) -> None:
    """The axes' legend to the right of its frame, clear of the data."""
    ax.legend(loc="upper left", bbox_to_anchor=(1.02, 1.0), borderaxespad=0.0,
              fontsize="small", **kw)


def number(x: float) -> str:
    """Three significant digits, whole numbers below a million written out (1800, not 1.8e+03)."""
    if 1.0 <= abs(x) < 1e6:
        return f"{x:.{max(3, int(np.log10(abs(x))) + 1)}g}"
    return f"{x:.3g}"


def draw_frame(ax: Axes, linkage: Model | Mechanism,
               label: str | None = "frame (pivots, guides)", states: InputState | None = None
               ) -> None:
    """The frame: the ground pivots as triangles, the ground guides' travel as thick lines.

    The travel over a revolution, or over the input ``states`` given (a motion's); each gear
    pair's pitch circles dashed about their pivots.
    """
    pivots, guides = frame(linkage, states=states)
    ax.plot(pivots.real, pivots.imag, "k^", ms=8, label=label, zorder=5)
    for ends in guides:
        ax.plot(ends.real, ends.imag, "k-", lw=6, alpha=0.25, zorder=1)
    turn = np.exp(1j * np.linspace(0.0, 2 * np.pi, 121))
    for centre, radius in pitch_circles(linkage):
        ring = centre + radius * turn
        ax.plot(ring.real, ring.imag, "k--", lw=0.8, alpha=0.5, zorder=1)


#: How far inside the frame (a fraction of the axes) a point beyond the limits is marked.
EDGE_INSET = 0.08


def mark_point(ax: Axes, x: float, y: float, label: str, where: str, **style: Any) -> Line2D:
    """Mark the point ``(x, y)`` (data) on ``ax`` labelled ``label``, keeping its limits.

    Inside the limits: a marker of ``style`` there. Outside: the marker where the point would
    be with each coordinate beyond the limits brought :data:`EDGE_INSET` inside the frame (a
    coordinate within its limits stays exact), an arrow from it to the frame pointing the
    point's way, and ``where`` (the point's coordinates, with units) beside it. Returns the
    marker (a ``Line2D``, for a legend).
    """
    xlim, ylim = ax.get_xlim(), ax.get_ylim()
    u = (x - xlim[0]) / (xlim[1] - xlim[0])
    v = (y - ylim[0]) / (ylim[1] - ylim[0])
    if 0.0 <= u <= 1.0 and 0.0 <= v <= 1.0:
        (marker,) = ax.plot([x], [y], linestyle="none", label=label, zorder=6, **style)
    else:
        inside = np.clip([u, v], EDGE_INSET, 1.0 - EDGE_INSET)
        d = np.array([u, v]) - inside
        d /= np.linalg.norm(d)
        reach = min((1.0 - inside[i]) / d[i] if d[i] > 0 else -inside[i] / d[i]
                    for i in (0, 1) if d[i] != 0)
        (marker,) = ax.plot([inside[0]], [inside[1]], linestyle="none", transform=ax.transAxes,
                            label=f"{label} (off the axes: arrow)", zorder=6, clip_on=False,
                            **style)
        tip = inside + reach * d
        ax.annotate("", xy=(tip[0], tip[1]), xytext=(inside[0], inside[1]),
                    xycoords="axes fraction",
                    arrowprops={"arrowstyle": "-|>", "color": style.get("mec", "k"),
                                "lw": 1.2, "shrinkA": 7, "shrinkB": 0})
        ax.annotate(where, xy=(inside[0], inside[1]), xycoords="axes fraction",
                    xytext=(-12 * d[0], -12 * d[1]),
                    textcoords="offset points", fontsize="small",
                    bbox={"boxstyle": "round,pad=0.2", "fc": "white", "ec": "none",
                          "alpha": 0.8},
                    ha="right" if d[0] > 0.3 else "left" if d[0] < -0.3 else "center",
                    va="top" if d[1] > 0.3 else "bottom" if d[1] < -0.3 else "center")
    ax.set_xlim(xlim)
    ax.set_ylim(ylim)
    return marker


def write_figure(fig: Figure, out: Path, dpi: float | None, kind: str = "png") -> Path:
    """Write ``fig`` to ``out`` as ``kind`` (``png``, ``svg``, ``pdf``), whole or not at all."""
    from matplotlib.backends.backend_agg import FigureCanvasAgg

    FigureCanvasAgg(fig)
    return write_with(out, lambda tmp: fig.savefig(tmp, dpi=dpi, format=kind),
                      suffix=out.suffix)


def save_figure(fig: Figure, path: str | os.PathLike[str], dpi: float = 150) -> Path:
    """Write the figure to ``path`` in the format its extension names, atomically.

    PNG at ``dpi``; SVG and PDF are vector formats. Returns the path written.

    Raises
    ------
    OutputError
        For an extension other than :data:`FIGURE_TYPES`', or a file that cannot be written.
    """
    out = Path(path)
    return write_figure(fig, out, dpi, figure_type(out))


def save_png(fig: Figure, path: str | os.PathLike[str], dpi: float = 100) -> Path:
    """Write the figure as one PNG at ``dpi``, atomically; returns the path written."""
    return write_figure(fig, Path(path).with_suffix(".png"), dpi)


#: How the spec's own design is marked on an atlas.
ORIGINAL_STYLE: dict[str, Any] = {"marker": "*", "ms": 16, "mfc": "white", "mec": "k",
                                   "mew": 1.2}
