"""Figures of a simulated motion: forces on the ground, shaking moment, the centre of mass' path.

The report figure of ``balancer verify`` (:func:`verification_figure`) assembles them, driven and
free, before and after.
"""

from __future__ import annotations

from typing import TYPE_CHECKING

import numpy as np

from ..mechanisms import mechanism_of
from ..mechanisms.base import Mechanism
from ..model import Design
from ..model import MechanismModel as Model
from ..rounding import speed_text
from ..simulation import Trajectory
from ..verification import Verification
from .drawing import centre_of_mass_path
from .style import (
    AFTER_STYLE,
    BEFORE_STYLE,
    COLOURS,
    SERIES,
    axes,
    draw_frame,
    legend_outside,
    number,
)

if TYPE_CHECKING:  # annotations only: matplotlib is imported by the functions that draw
    from matplotlib.axes import Axes
    from matplotlib.figure import Figure
    from matplotlib.lines import Line2D


#: Quantiles of a time panel's samples (all its curves together) that bound its bulk.
SPIKE_QUANTILES = (0.02, 0.98)

#: A time panel whose samples span more than this many times its bulk is clipped: a few
#: spikes (a free motion through a near-toggle) would squash every other curve to a line.
SPIKE_RATIO = 3.0

#: Room left beyond the bulk of a clipped panel, a fraction of the bulk's span.
SPIKE_ROOM = 0.25

#: Two curves closer than this fraction of their panel's height at every sample coincide.
COINCIDENT = 2e-3


def _curves(ax: Axes) -> list[Line2D]:
    """The axes' data curves (lines with more than two samples)."""
    return [line for line in ax.get_lines() if np.size(line.get_xdata()) > 2]


def _clip_spikes(ax: Axes, unit: str) -> None:
    """Keep a time panel's y-limits on the bulk of its samples, the spikes clipped and marked.

    The bulk of the samples (all the curves') lies between their :data:`SPIKE_QUANTILES`. A
    side is clipped where its extreme would make the panel more than :data:`SPIKE_RATIO`
    times the bulk's height: its limit is the bulk's, widened by :data:`SPIKE_ROOM` of it
    (the other side keeps its extreme). Each stretch of a curve beyond a limit
    is marked at the edge, at its peak, by a triangle of the curve's colour; the legend
    gives the largest value clipped, in ``unit``. What a designer reads: the motion's
    ordinary forces at a readable scale, and how large its brief peaks are.
    """
    curves = _curves(ax)
    if not curves:
        return
    values = np.concatenate([np.asarray(line.get_ydata(), float) for line in curves])
    values = values[np.isfinite(values)]
    low, high = float(values.min()), float(values.max())
    q_low, q_high = (float(q) for q in np.quantile(values, SPIKE_QUANTILES))
    bulk = q_high - q_low
    clip_top = bulk > 0 and high - q_low > SPIKE_RATIO * bulk
    clip_bottom = bulk > 0 and q_high - low > SPIKE_RATIO * bulk
    if not (clip_top or clip_bottom):
        return
    top = q_high + SPIKE_ROOM * bulk if clip_top else high
    bottom = q_low - SPIKE_ROOM * bulk if clip_bottom else low
    margin = 0.05 * (top - bottom)  # matplotlib's, on a side that is not clipped
    top, bottom = top + (0.0 if clip_top else margin), bottom - (0.0 if clip_bottom else margin)
    ax.set_ylim(bottom, top)
    edge = ax.get_xaxis_transform()  # x in data, y in axes fractions
    clipped: list[float] = []
    for line in curves:
        t, y = np.asarray(line.get_xdata(), float), np.asarray(line.get_ydata(), float)
        for beyond, at, marker, sign in ((y > top, 1.0, "^", 1.0),
                                         (y < bottom, 0.0, "v", -1.0)):
            starts = np.flatnonzero(np.diff(np.r_[0, beyond.astype(int)]) == 1)
            ends = np.flatnonzero(np.diff(np.r_[beyond.astype(int), 0]) == -1) + 1
            for a, b in zip(starts, ends, strict=True):
                peak = a + int(np.argmax(sign * y[a:b]))
                ax.plot([t[peak]], [at], marker, color=line.get_color(), ms=8, mec="k",
                        mew=0.5, transform=edge, clip_on=False, zorder=6)
                clipped.append(abs(y[peak]))
    ax.plot([], [], "^", color="w", mec="k", mew=0.5, ms=8,
            label=f"clipped peaks (▲▼ at the edge): up to {number(max(clipped))} {unit}")


def _reveal_coincident(ax: Axes) -> None:
    """Keep both of two curves visible where one lies on the other.

    Where a curve coincides (within :data:`COINCIDENT` of the panel's height at every
    sample, at the same times) with one drawn before it, it is drawn on top of it dashed and
    thinner, and its legend entry says which one it coincides with.
    """
    low, high = ax.get_ylim()
    tolerance = COINCIDENT * (high - low)
    curves = _curves(ax)
    for j, later in enumerate(curves):
        for earlier in curves[:j]:
            t, y = later.get_xdata(), np.asarray(later.get_ydata(), float)
            if not (np.array_equal(t, earlier.get_xdata()) and
                    np.nanmax(np.abs(y - np.asarray(earlier.get_ydata(), float)),
                              initial=0.0) <= tolerance):
                continue
            later.set_linestyle((0, (4, 3)))
            later.set_linewidth(0.6 * min(later.get_linewidth(), earlier.get_linewidth()))
            later.set_zorder(max(later.get_zorder(), earlier.get_zorder()) + 0.1)
            later.set_label(f"{later.get_label()} (coincides with {earlier.get_label()})")
            break


def plot_reactions(traj: Trajectory, ax: Axes | None = None, title: str = "",
                   original: Trajectory | None = None, clip_spikes: bool = False) -> Axes:
    """Every force on the ground over time and their sum (as the paper's Fig. 8 and 9), N.

    The x (solid) and y (dashed) components at each ground point, the normal force (dotted) of
    each slider on a ground guide, and the shaking force's components (black). With the
    ``original``'s motion, before and after instead: the magnitude of each force on the ground
    and of their sum, the original's thin and faint, the design's solid. A curve that lies on
    an earlier one is drawn dashed on top of it (:func:`_reveal_coincident`); with
    ``clip_spikes``, brief spikes are clipped and marked (:func:`_clip_spikes`).
    """
    ax = axes(ax)
    if original is not None:
        _plot_reaction_magnitudes(ax, traj, original)
    else:
        t = traj.t
        colours = iter(SERIES * (1 + (len(traj.ground) + len(traj.slider_normal))
                                 // len(SERIES)))
        for point, values in traj.ground.items():
            colour = next(colours)
            ax.plot(t, values.real, color=colour, lw=1.2, label=f"$R_{{{point}x}}$")
            ax.plot(t, values.imag, color=colour, lw=1.2, ls="--", label=f"$R_{{{point}y}}$")
        for link, normal in traj.slider_normal.items():
            ax.plot(t, normal, color=next(colours), lw=1.2, ls=":", label=f"normal force, {link}")
        total = traj.shaking_force
        ax.plot(t, total.real, color=COLOURS["sum"], lw=1.8, label="sum, x")
        ax.plot(t, total.imag, color=COLOURS["sum"], lw=1.8, ls="--", label="sum, y")
        ax.set_ylabel("force on the ground (N)")
    ax.set_xlabel("time t (s)")
    ax.set_title(title or f"forces on the ground, {traj.drive} motion")
    ax.grid(alpha=0.3)
    if clip_spikes:
        _clip_spikes(ax, "N")
    _reveal_coincident(ax)
    legend_outside(ax)
    return ax


def _plot_reaction_magnitudes(ax: Axes, traj: Trajectory, original: Trajectory) -> None:
    """Magnitudes of the forces on the ground and of their sum, before and after."""
    names = [*traj.ground, *traj.slider_normal]
    colours = dict(zip(names, SERIES * (1 + len(names) // len(SERIES)), strict=False))
    for run, role, lw, alpha in ((original, "before", 1.0, 0.55), (traj, "after", 1.6, 1.0)):
        for point, values in run.ground.items():
            ax.plot(run.t, np.abs(values), color=colours[point], lw=lw, alpha=alpha,
                    label=f"$|R_{{{point}}}|$, {role}")
        for link, normal in run.slider_normal.items():
            ax.plot(run.t, np.abs(normal), color=colours[link], lw=lw, alpha=alpha, ls=":",
                    label=f"normal force, {link}, {role}")
        ax.plot(run.t, np.abs(run.shaking_force), color=COLOURS["sum"], lw=lw + 0.4,
                alpha=alpha, ls="--" if role == "before" else "-",
                label=f"|sum| (shaking force), {role}")
    ax.set_ylabel("magnitude of the force on the ground (N)")


def plot_shaking_moment(
    traj: Trajectory, original: Trajectory | None = None, ax: Axes | None = None,
    title: str = "", clip_spikes: bool = False,
) -> Axes:
    """Shaking moment about the origin over time, before (the original) and after, N·m.

    As :func:`plot_reactions`: coinciding curves both visible, spikes clipped if asked.
    """
    ax = axes(ax)
    if original is not None:
        ax.plot(original.t, original.shaking_moment, **BEFORE_STYLE, label="before (original)")
    ax.plot(traj.t, traj.shaking_moment, **(AFTER_STYLE if original is not None else
                                            {"color": COLOURS["after"], "lw": 1.5}),
            label="after" if original is not None else "shaking moment")
    ax.set_xlabel("time t (s)")
    ax.set_ylabel("shaking moment about the origin (N·m)")
    ax.set_title(title or f"shaking moment, {traj.drive} motion")
    ax.grid(alpha=0.3)
    if clip_spikes:
        _clip_spikes(ax, "N·m")
    _reveal_coincident(ax)
    legend_outside(ax)
    return ax


def plot_com_path(
    linkage: Model | Mechanism, traj: Trajectory, original: Model | Mechanism | None = None,
    original_traj: Trajectory | None = None, ax: Axes | None = None,
) -> Axes:
    """Path of the total centre of mass, with the frame (a point when balanced)."""
    ax = axes(ax)
    if original is not None and original_traj is not None:
        path = centre_of_mass_path(original, original_traj)
        ax.plot(path.real, path.imag, color=COLOURS["before"], lw=1.5, label="before (original)")
    path = centre_of_mass_path(linkage, traj)
    label = "after" if original is not None else "total centre of mass"
    size = mechanism_of(linkage).structure.length_scale()
    if np.ptp(path.real) + np.ptp(path.imag) < 1e-9 * size:
        ax.plot(path.real[:1], path.imag[:1], "o", color=COLOURS["after"],
                label=f"{label}: stationary")
    else:
        ax.plot(path.real, path.imag, color=COLOURS["after"], lw=1.5, label=label)
    draw_frame(ax, linkage)
    ax.set_aspect("equal", adjustable="datalim")
    ax.set_xlabel("x (m)")
    ax.set_ylabel("y (m)")
    ax.set_title("path of the total centre of mass")
    ax.grid(alpha=0.3)
    legend_outside(ax)
    return ax


def verification_figure(design: Design, verification: Verification) -> Figure:
    """The report figure of ``balancer verify``.

    Columns: the crank driven at the operating speed, free motion; rows: the forces on the
    ground and their sum, shaking moment, path of the total centre of mass; each before and
    after where the design names its original. Legends beside the panels. The free motion's
    panels are set on the bulk of their samples, brief spikes (a pass near a toggle) clipped
    and marked with their size; the driven run's show every sample, its peaks being the
    loads at the operating speed.
    """
    from matplotlib.figure import Figure

    fig = Figure(figsize=(17, 14), layout="constrained")
    axes = fig.subplots(3, 2)
    title = design.title or "design"
    fig.suptitle(f"{title}: verification by simulation ({verification.method} formulation)")
    speed = design.operation.speed if design.operation else 0.0
    runs = ((verification.driven, f"crank driven at {speed_text(speed)}", 0),
            (verification.free, "free motion", 1))
    for run, label, col in runs:
        free = run is verification.free
        if run.trajectory is None:
            axes[0, col].text(0.5, 0.5, f"{label}: no simulation\n{run.note}", ha="center",
                              va="center", wrap=True, transform=axes[0, col].transAxes)
            continue
        plot_reactions(run.trajectory, ax=axes[0, col], title=f"forces on the ground, {label}",
                       original=run.original, clip_spikes=free)
        plot_shaking_moment(run.trajectory, run.original, ax=axes[1, col],
                            title=f"shaking moment, {label}", clip_spikes=free)
        plot_com_path(design.mechanism, run.trajectory, design.original, run.original,
                      ax=axes[2, col])
        axes[2, col].set_title(f"path of the total centre of mass, {label}")
    return fig
