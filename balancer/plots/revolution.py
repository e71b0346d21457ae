"""Figures of one revolution at the operating speed, before and after a redesign.

The shaking force's polar diagram (and the rocking couple's, for links in several planes), the
shaking moment, the driving torque and an engine's mount torque over the crank angle.
"""

from __future__ import annotations

from typing import TYPE_CHECKING

import numpy as np

from ..cycle import ROUNDING_SPAN, CycleAnalysis, drawn_panels, natural_scales, panel_keys
from ..cycle import Figure as Figures
from ..quantities import PANELS, QUANTITIES
from ..rounding import speed_text
from .style import AFTER_STYLE, BEFORE_STYLE, axes, legend_outside, number

if TYPE_CHECKING:  # annotations only: matplotlib is imported by the functions that draw
    from matplotlib.axes import Axes
    from matplotlib.figure import Figure


def _closed(values: np.ndarray) -> np.ndarray:
    """A revolution's samples with the first repeated at the end (the curve closes)."""
    return np.append(values, values[:1])


def _cycle_label(role: str, values: np.ndarray, unit: str) -> str:
    f = Figures.of(values)
    return f"{role}: RMS {number(f.rms)} {unit}, max {number(f.max)} {unit}"


def _roles(before: CycleAnalysis | None) -> tuple[str, str]:
    return ("balanced design", "original") if before is not None else ("design", "")


def plot_shaking_force_polar(analysis: CycleAnalysis, before: CycleAnalysis | None = None,
                             ax: Axes | None = None,
                             legend: bool = True) -> Axes:
    """Polar diagram of the shaking force: its vector's tip over one revolution, N.

    ``analysis`` and ``before`` (the original's, optional) are
    :class:`~balancer.cycle.CycleAnalysis`; a dot marks θ1 = 0 and an arrow the sense of
    travel. A force-balanced design's curve is a point at the origin.
    """
    return _polar(analysis, before, ax, legend, "shaking_force")


def plot_rocking_couple_polar(analysis: CycleAnalysis, before: CycleAnalysis | None = None,
                              ax: Axes | None = None,
                              legend: bool = True) -> Axes:
    """Polar diagram of the rocking couple ``(Mx, My)`` over one revolution, N·m.

    As :func:`plot_shaking_force_polar`: for links in several planes along the crank's axis.
    """
    return _polar(analysis, before, ax, legend, "rocking_couple")




#: The quantities drawn over the crank angle (the others are polar diagrams).
_OVER_ANGLE = ("shaking_moment", "driving_torque", "mount_torque")


def _values(analysis: CycleAnalysis, quantity: str) -> np.ndarray:
    """A drawn quantity's samples over the cycle (``quantity`` a key of :data:`QUANTITIES`)."""
    panel = QUANTITIES[quantity].panel
    return np.asarray(drawn_panels(analysis, [panel])[panel])


def _zero_below_rounding(analysis: CycleAnalysis, quantity: str) -> np.ndarray:
    """A quantity's samples, all zero where every one is below rounding of its natural scale.

    (A balanced design's shaking moment of 1e-12 N·m is drawn as the zero it is, not as noise
    blown up to fill its panel; the label still gives its RMS and maximum.)
    """
    values = _values(analysis, quantity)
    floor = ROUNDING_SPAN * natural_scales(analysis)[QUANTITIES[quantity].panel]
    if np.nanmax(np.abs(values), initial=0.0) <= floor:
        return np.zeros_like(values)
    return values


def _span(analysis: CycleAnalysis) -> str:
    """What the samples span, for a title: one revolution, or a four-stroke's 720°."""
    return "one revolution" if analysis.revolutions == 1 else "a cycle of 720°"


def _polar(analysis: CycleAnalysis, before: CycleAnalysis | None, ax: Axes | None,
           legend: bool, quantity: str) -> Axes:
    name, unit = QUANTITIES[quantity].words, QUANTITIES[quantity].unit
    title = f"{name} over {_span(analysis)} (polar diagram)"
    ax = axes(ax)
    after_role, before_role = _roles(before)
    ax.axhline(0.0, color="0.6", lw=0.8)
    ax.axvline(0.0, color="0.6", lw=0.8)
    for a, role, style in ((before, before_role, BEFORE_STYLE),
                           (analysis, after_role, AFTER_STYLE)):
        if a is None:
            continue
        colour, lw = style["color"], style["lw"]
        f = _closed(_zero_below_rounding(a, quantity))
        ax.plot(f.real, f.imag, **style, label=_cycle_label(role, _values(a, quantity), unit))
        ax.plot(f.real[:1], f.imag[:1], "o", color=colour, ms=6, mec="k", mew=0.6, zorder=4)
        k = max(1, f.size // 8)
        if abs(f[k + 1] - f[k]) > 0:
            ax.annotate("", xy=(f[k + 1].real, f[k + 1].imag), xytext=(f[k].real, f[k].imag),
                        arrowprops={"arrowstyle": "-|>", "color": colour, "lw": lw,
                                    "mutation_scale": 14})
    ax.plot([], [], "o", color="w", mec="k", mew=0.6, label="θ1 = 0, arrow: sense of travel")
    ax.set_aspect("equal", adjustable="datalim")
    ax.set_xlabel(f"{name}, x ({unit})")
    ax.set_ylabel(f"{name}, y ({unit})")
    ax.set_title(title)
    ax.grid(alpha=0.3)
    if legend:
        legend_outside(ax)
    return ax


def plot_over_crank_angle(analysis: CycleAnalysis, quantity: str,
                          before: CycleAnalysis | None = None, ax: Axes | None = None,
                          legend: bool = True) -> Axes:
    """``quantity`` over the crank angle, N·m, in degrees over the analysis' cycle.

    ``quantity`` ``"shaking_moment"``, ``"driving_torque"`` or (an engine's)
    ``"mount_torque"``; of ``analysis`` and, if given, ``before`` (the original's).

    Raises
    ------
    ValueError
        For another ``quantity``, or ``"mount_torque"`` of a mechanism that has none (naming
        what is drawn).
    """
    ax = axes(ax)
    names = _OVER_ANGLE
    drawable = [q for q in names if QUANTITIES[q].panel in panel_keys(analysis, before)]
    if quantity not in drawable:
        raise ValueError(f"no such quantity to draw over the crank angle: {quantity!r} "
                         f"(one of {', '.join(map(repr, drawable))})")
    after_role, before_role = _roles(before)
    for a, role, style in ((before, before_role, BEFORE_STYLE),
                           (analysis, after_role, AFTER_STYLE)):
        if a is None:
            continue
        ax.plot(np.degrees(np.append(a.theta1, 2 * np.pi * a.revolutions)),
                _closed(_zero_below_rounding(a, quantity)), **style,
                label=_cycle_label(role, _values(a, quantity), QUANTITIES[quantity].unit))
    span = 360.0 * analysis.revolutions
    ax.set_xlim(0.0, span)
    ax.set_xticks(np.arange(0, span + 1, 45 * analysis.revolutions))
    ax.set_xlabel("crank angle θ1 (°)")
    ax.set_ylabel(QUANTITIES[quantity].label)
    ax.set_title(f"{QUANTITIES[quantity].words} over {_span(analysis)}")
    ax.grid(alpha=0.3)
    if legend:
        legend_outside(ax)
    return ax


def cycle_figure(analysis: CycleAnalysis, before: CycleAnalysis | None = None,
                 title: str = "") -> Figure:
    """The picture a balancing report starts with: one revolution at the operating speed.

    The shaking force's polar diagram (beside it the rocking couple's, where the design or
    the original has links in several planes), and the shaking moment, the driving torque and
    (for an engine) the torque on its mounts over the crank angle; of the design, and of the
    original before it (``before``) if given. Each panel's title gives its RMS and maximum
    (original → design; N or N·m); one legend below the panels; the speed in rad/s and rpm.
    """
    from matplotlib.figure import Figure

    keys = panel_keys(analysis, before)
    left = [key for key in keys if key in ("force", "couple")]
    right = [key for key in keys if key not in left]
    fig = Figure(figsize=(7.0 + 5.0 * len(left), 3.5 * len(right)), layout="constrained")
    axes = fig.subplot_mosaic([[*left, key] for key in right],
                              width_ratios=[*([1.0] * len(left)), 1.3])
    plot_shaking_force_polar(analysis, before, ax=axes["force"], legend=False)
    if "couple" in axes:
        plot_rocking_couple_polar(analysis, before, ax=axes["couple"], legend=False)
    for key in right:
        plot_over_crank_angle(analysis, PANELS[key].key, before, ax=axes[key], legend=False)
    after_panels = drawn_panels(analysis, keys)
    before_panels = drawn_panels(before, keys) if before is not None else None
    drawn = [a for a in (analysis, before) if a is not None]
    for key in keys:
        unit = PANELS[key].unit
        ax = axes[key]
        # what is rounding of the panel's natural scale reads as the zero its curve is drawn as
        floor = ROUNDING_SPAN * max(natural_scales(a)[key] for a in drawn)
        figures = [_figure_pair(before_panels[key] if before_panels is not None else None,
                                after_panels[key], stat, floor) for stat in ("rms", "max")]
        ax.set_title(f"{ax.get_title()}\nRMS {figures[0]} {unit}, max {figures[1]} {unit}",
                     fontsize="medium")
    handles, labels = axes["force"].get_legend_handles_labels()
    fig.legend(handles, [label.split(": RMS")[0] for label in labels],
               loc="outside lower center",
               ncols=len(handles), fontsize="small")
    what = f"{_span(analysis)} at {speed_text(analysis.speed)}"
    if any(analysis.gravity):
        what += f", gravity ({analysis.gravity[0]:g}, {analysis.gravity[1]:g}) m/s²"
    if before is not None:
        what += ", before and after balancing"
    fig.suptitle(f"{title}: {what}" if title else what)
    return fig


def _figure_pair(before: np.ndarray | None, after: np.ndarray, stat: str,
                 floor: float = 0.0) -> str:
    """``"b → a"`` (or ``"a"``) of a figure of one revolution's values, to 3 digits.

    A figure at most ``floor`` (rounding of its panel's natural scale) reads ``0``.
    """
    def text(values: np.ndarray) -> str:
        value = getattr(Figures.of(values), stat)
        return "0" if abs(value) <= floor else number(value)

    return text(after) if before is None else f"{text(before)} → {text(after)}"
