"""Figures along a motion of a linkage's inputs (DESIGN.md, "Mechanisms with several inputs").

The loads on the frame over time — the shaking force (its x and y components and magnitude),
the shaking moment about the origin, the rocking couple where the links are not in one plane,
each input's torque — and the mechanism drawn at a few poses along the motion, with its marker
point's path and its total centre of mass's track. Computing nothing: the caller gives the
analysis (:class:`~balancer.motion_analysis.MotionAnalysis`) and, for the mechanism's panels,
what to draw of it (:class:`MotionDrawing`, from :func:`balancer.api.motion_drawing`).
"""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass
from typing import TYPE_CHECKING, Any

import numpy as np
from numpy.typing import NDArray

from ..cycle import ROUNDING_SPAN
from ..mechanisms.base import in_one_plane
from ..motion_analysis import MotionAnalysis, load_words
from ..quantities import QUANTITIES
from ..report.along import law_words
from .style import COLOURS, SERIES, axes, legend_outside, number

if TYPE_CHECKING:  # annotations only: matplotlib is imported by the functions that draw
    from matplotlib.axes import Axes
    from matplotlib.figure import Figure


@dataclass(frozen=True, kw_only=True, eq=False)
class MotionDrawing:
    """What the figure of a motion draws of its mechanism: positions, complex ``x + i·y``, m.

    Made by :func:`balancer.api.motion_drawing` from a
    :class:`~balancer.motion_analysis.MotionAnalysis` (the mechanism's forward kinematics at
    its states); :func:`motion_figure` draws it.

    Attributes
    ----------
    t
        The times of the poses drawn, s.
    links
        Each moving link's points at those poses, ``(poses, k)``, in the order to join them
        (a link of three or more points closed into a polygon), by the link's name.
    ground
        The ground points' places, by name.
    centre_of_mass
        The total centre of mass at each of the analysis' times, ``(samples,)``.
    point
        The motion's marker point, whose path is drawn (``None``: a motion of the inputs'
        own angles).
    path
        That point's place at each of the analysis' times, ``(samples,)`` (``None`` without a
        point).
    """

    t: NDArray[np.float64]
    links: Mapping[str, NDArray[np.complex128]]
    ground: Mapping[str, complex]
    centre_of_mass: NDArray[np.complex128]
    point: str | None = None
    path: NDArray[np.complex128] | None = None

    def __repr__(self) -> str:
        marker = f", point {self.point}'s path" if self.point is not None else ""
        return (f"MotionDrawing({len(self.links)} links at {self.t.size} poses, "
                f"t = {', '.join(f'{t:.3g}' for t in self.t)} s{marker}, "
                f"{self.centre_of_mass.size} states)")


#: How a vector's parts are drawn over time: its x and y components, and its magnitude.
_PARTS: tuple[tuple[str, dict[str, Any]], ...] = (
    ("x component", {"color": SERIES[0], "lw": 1.2}),
    ("y component", {"color": SERIES[1], "lw": 1.2, "ls": "--"}),
    ("magnitude", {"color": COLOURS["sum"], "lw": 1.6}))
#: How a moment or a torque is drawn over time.
_VALUE: dict[str, Any] = {"color": COLOURS["after"], "lw": 1.6}


def loads_over_time(analysis: MotionAnalysis) -> dict[str, tuple[str, str]]:
    """The loads drawn over time, in the figure's order: key → ``(words, unit)``.

    The keys are :meth:`~balancer.motion_analysis.MotionAnalysis.loads`': ``shaking_force``,
    ``shaking_moment``, ``rocking_couple`` (where the links are not in one plane) and
    ``torque_<input>`` per input; the words and units are the quantity table's.
    """
    q = QUANTITIES
    out = {key: (q[key].axis or q[key].words, q[key].unit)
           for key in ("shaking_force", "shaking_moment")}
    if not in_one_plane(analysis.mechanism):
        out["rocking_couple"] = (q["rocking_couple"].words, q["rocking_couple"].unit)
    for name in analysis.inputs:  # (a slide's actuator: a force, N)
        out[f"torque_{name}"] = load_words(analysis.mechanism, f"torque_{name}")
    return out


def _values(analysis: MotionAnalysis, key: str) -> NDArray[np.number]:
    """A drawn load's samples (complex for a vector)."""
    r = analysis.reactions
    if key.startswith("torque_"):
        return r.torques[analysis.inputs.index(key.removeprefix("torque_"))]
    return {"shaking_force": r.shaking_force, "shaking_moment": r.shaking_moment,
            "rocking_couple": r.rocking_couple}[key]


def rounding_floors(analysis: MotionAnalysis) -> dict[str, float]:
    """What is rounding of a force (N) and of a moment (N·m) along the motion, by unit.

    :data:`~balancer.cycle.ROUNDING_SPAN` of each unit's natural scale
    (:meth:`~balancer.motion_analysis.MotionAnalysis.natural_scales`).
    """
    return {unit: ROUNDING_SPAN * scale for unit, scale in analysis.natural_scales().items()}


def _figure_text(value: float, floor: float) -> str:
    """A figure to 3 digits, ``0`` where it is at most ``floor`` (rounding of its scale)."""
    return "0" if abs(value) <= floor else number(value)


def plot_over_time(analysis: MotionAnalysis, key: str, ax: Axes | None = None) -> Axes:
    """A load on the frame over the motion's time, with its RMS and maximum in the title.

    ``key`` one of :func:`loads_over_time`': a vector (the shaking force, N; the rocking
    couple, N·m) as its x and y components and its magnitude, a moment or torque (N·m) as it
    is. Where every sample is rounding of its scale (:func:`rounding_floors`) the curves are
    drawn as the zero they are, and the title's figures read 0.

    Raises
    ------
    ValueError
        For another ``key`` (naming those drawn).
    """
    drawn = loads_over_time(analysis)
    if key not in drawn:
        raise ValueError(f"no such load to draw over the motion: {key!r} "
                         f"(one of {', '.join(map(repr, drawn))})")
    words, unit = drawn[key]
    ax = axes(ax)
    floor = rounding_floors(analysis)[unit]
    values = _values(analysis, key)
    shown = (np.zeros_like(values) if np.nanmax(np.abs(values), initial=0.0) <= floor
             else values)
    if np.iscomplexobj(shown):
        for (part, style), curve in zip(_PARTS, (shown.real, shown.imag, np.abs(shown)),
                                        strict=True):
            ax.plot(analysis.t, curve, **style, label=part)
    else:
        ax.plot(analysis.t, shown, **_VALUE, label=words)
    figure = analysis.loads()[key]
    ax.set_title(f"{words}\nRMS {_figure_text(figure.rms, floor)} {unit}, "
                 f"max {_figure_text(figure.max, floor)} {unit}", fontsize="medium")
    ax.set_ylabel(f"{words} ({unit})")
    ax.set_xlabel("time t (s)")
    ax.set_xlim(float(analysis.t[0]), float(analysis.t[-1]))
    ax.axhline(0.0, color="0.6", lw=0.8, zorder=0)
    ax.grid(alpha=0.3)
    return ax


def plot_poses(analysis: MotionAnalysis, drawing: MotionDrawing,
               ax: Axes | None = None) -> Axes:
    """The mechanism at the drawing's poses, its point's path, its centre of mass' track (m).

    The poses light to dark in time; the path (m) through the motion's waypoints (where the
    motion is a point's path); the total centre of mass's track, or a dot where it stands
    still (within :data:`~balancer.cycle.ROUNDING_SPAN` of the mechanism's size).
    """
    ax = axes(ax)
    ground = np.array(list(drawing.ground.values()), complex)
    ax.plot(ground.real, ground.imag, "k^", ms=9, label="frame (ground points)", zorder=5)
    poses = drawing.t.size
    times = ", ".join(number(float(t)) for t in drawing.t)
    for j in range(poses):
        alpha = 1.0 if poses == 1 else 0.3 + 0.7 * j / (poses - 1)
        for i, points in enumerate(drawing.links.values()):
            ax.plot(points[j].real, points[j].imag, "-o", color=COLOURS["link"], lw=2.2, ms=3.5,
                    alpha=alpha, zorder=3,
                    label=(f"links at t = {times} s" + (" (light to dark)" if poses > 1 else "")
                           if i == 0 and j == poses - 1 else None))
    if drawing.point is not None and drawing.path is not None:
        ax.plot(drawing.path.real, drawing.path.imag, color=COLOURS["com"], lw=1.4, zorder=4,
                label=f"path of {drawing.point}")
        waypoints = np.asarray(analysis.motion.path, float)
        ax.plot(waypoints[:, 0], waypoints[:, 1], "D", color="w", mec=COLOURS["com"], mew=1.2,
                ms=6, ls="none", zorder=4.5, label=f"waypoints of {drawing.point}")
    centre = drawing.centre_of_mass
    size = analysis.mechanism.structure.length_scale()
    if np.nanmax(np.abs(centre - np.nanmean(centre)), initial=0.0) <= ROUNDING_SPAN * size:
        ax.plot(centre.real[:1], centre.imag[:1], "o", color=COLOURS["after"], ms=7, zorder=6,
                label="total centre of mass: stationary")
    else:
        ax.plot(centre.real, centre.imag, color=COLOURS["after"], lw=2.0, zorder=6,
                label="track of the total centre of mass")
    ax.set_aspect("equal", adjustable="datalim")
    ax.set_xlabel("x (m)")
    ax.set_ylabel("y (m)")
    ax.set_title(f"the mechanism along motion {analysis.name}", fontsize="medium")
    ax.grid(alpha=0.3)
    return ax


def plot_centre_of_mass_track(analysis: MotionAnalysis, drawing: MotionDrawing,
                              ax: Axes | None = None) -> Axes:
    """The total centre of mass's track about its mean place, magnified (mm).

    A force-balanced mechanism's stands still: a dot at the origin, within
    :data:`~balancer.cycle.ROUNDING_SPAN` of the mechanism's size.
    """
    ax = axes(ax)
    centre = drawing.centre_of_mass
    offset = (centre - np.nanmean(centre)) * 1e3
    reach = float(np.nanmax(np.abs(offset), initial=0.0))
    size = analysis.mechanism.structure.length_scale()
    if reach <= ROUNDING_SPAN * size * 1e3:
        ax.plot([0.0], [0.0], "o", color=COLOURS["after"], ms=7)
        ax.set_title("total centre of mass: stands still", fontsize="medium")
    else:
        ax.plot(offset.real, offset.imag, color=COLOURS["after"], lw=1.6)
        ax.plot(offset.real[:1], offset.imag[:1], "o", color=COLOURS["after"], ms=5, mec="k",
                mew=0.6, zorder=4)
        ax.set_title(f"total centre of mass from its mean place (dot: t = "
                     f"{number(float(analysis.t[0]))} s)\nmoves up to {reach:.4g} mm",
                     fontsize="medium")
    ax.set_aspect("equal", adjustable="datalim")
    ax.set_xlabel("x (mm)")
    ax.set_ylabel("y (mm)")
    ax.grid(alpha=0.3)
    return ax


def _law_words(analysis: MotionAnalysis) -> str:
    m = analysis.motion
    return (f"motion {m.name} over {m.duration:g} s ({law_words(m)}, {analysis.t.size} "
            "states)")


def motion_figure(analysis: MotionAnalysis, drawing: MotionDrawing | None = None,
                  title: str = "") -> Figure:
    """The picture of a report on a motion: the loads on the frame over time, the mechanism.

    Left, over the motion's time (s): the shaking force's x and y components and magnitude
    (N), the shaking moment about the origin (N·m), the rocking couple (where the links are
    not in one plane; N·m) and each input's torque (``torque on <input>``, N·m), each panel's
    title with its RMS and maximum (the analysis' own figures:
    :meth:`~balancer.motion_analysis.MotionAnalysis.loads`; a figure that is rounding of its
    scale reads 0 and its curve is drawn as zero, :func:`plot_over_time`). Right, given
    ``drawing`` (:func:`balancer.api.motion_drawing` of the same analysis): the mechanism at a
    few poses with its marker point's path through the waypoints and its total centre of
    mass's track (:func:`plot_poses`), and that track magnified about its mean place
    (:func:`plot_centre_of_mass_track`). The suptitle names the motion, its time law and the
    gravity included.

    Nothing is computed here: ``analysis`` is :func:`balancer.analyze_motions`' (one of its
    ``motions``), sampled as the spec's motion says.

    Raises
    ------
    ValueError
        If ``drawing`` is not of ``analysis``' states (its centre of mass at another count of
        states).
    """
    from matplotlib.figure import Figure

    if drawing is not None and drawing.centre_of_mass.shape != analysis.t.shape:
        raise ValueError(f"the drawing is of {drawing.centre_of_mass.size} states, the analysis "
                         f"of {analysis.t.size}: draw motion_drawing(analysis) of this analysis")

    keys = list(loads_over_time(analysis))
    rows = len(keys)
    if drawing is None:
        fig = Figure(figsize=(8.0, 2.4 * rows + 1.0), layout="constrained")
        panels = fig.subplot_mosaic([[key] for key in keys])
    else:
        fig = Figure(figsize=(15.0, max(2.4 * rows + 1.0, 9.0)), layout="constrained")
        side = ["poses"] * (rows - 1) + ["centre"]
        panels = fig.subplot_mosaic([[key, s] for key, s in zip(keys, side, strict=True)],
                                    width_ratios=[1.0, 1.1])
        plot_poses(analysis, drawing, ax=panels["poses"])
        legend_outside(panels["poses"])
        plot_centre_of_mass_track(analysis, drawing, ax=panels["centre"])
    for key in keys:
        ax = panels[key]
        plot_over_time(analysis, key, ax=ax)
        if key != keys[-1]:
            ax.sharex(panels[keys[-1]])
            ax.set_xlabel("")
            ax.tick_params(labelbottom=False)
    handles, labels = panels["shaking_force"].get_legend_handles_labels()
    fig.legend(handles, labels, loc="outside lower left", ncols=len(handles), fontsize="small")
    what = _law_words(analysis)
    gravity = analysis.gravity
    if any(gravity):
        what += f", gravity ({gravity[0]:g}, {gravity[1]:g}) m/s²"
    fig.suptitle(f"{title}: {what}" if title else what)
    return fig
