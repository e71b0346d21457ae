"""Figures for a designer's report (matplotlib, Agg; never ``show()``).

Each ``plot_*`` function draws on the axes it is given (or a new figure's) and returns them;
:func:`verification_figure` assembles the report figure of ``balancer verify`` and
:func:`save_figure` writes it as PNG, SVG or PDF (from the extension), whole or not at all.
"""

from __future__ import annotations

import os
from pathlib import Path

import numpy as np
from matplotlib.axes import Axes
from matplotlib.figure import Figure

from .errors import OutputError
from .mechanisms import mechanism_of
from .model import GROUND
from .outputs import write_with
from .simulation import Trajectory

#: Colours for the sum, before and after (colour-blind safe, Okabe & Ito).
COLOURS = {"sum": "#000000", "before": "#999999", "after": "#009E73", "link": "#0072B2",
           "com": "#D55E00"}
#: How a curve of the original (before) and of the design (after) is drawn where both are: the
#: original dashed on top, so that it shows where the two coincide.
BEFORE_STYLE = {"color": COLOURS["before"], "lw": 1.4, "ls": (0, (5, 2)), "zorder": 3}
AFTER_STYLE = {"color": COLOURS["after"], "lw": 2.2, "zorder": 2}
#: Colours for the forces at the ground points and guides, in order (A0, A3, … ).
SERIES = ("#0072B2", "#D55E00", "#CC79A7", "#E69F00", "#56B4E9", "#F0E442", "#009E73")


def _axes(ax: Axes | None) -> Axes:
    if ax is not None:
        return ax
    return Figure(figsize=(7, 4), layout="constrained").add_subplot()


def _legend_outside(ax: Axes, **kw) -> None:
    """The axes' legend to the right of its frame, clear of the data."""
    ax.legend(loc="upper left", bbox_to_anchor=(1.02, 1.0), borderaxespad=0.0,
              fontsize="small", **kw)


#: Quantiles of a time panel's samples (all its curves together) that bound its bulk.
SPIKE_QUANTILES = (0.02, 0.98)
#: A time panel whose samples span more than this many times its bulk is clipped: a few
#: spikes (a free motion through a near-toggle) would squash every other curve to a line.
SPIKE_RATIO = 3.0
#: Room left beyond the bulk of a clipped panel, a fraction of the bulk's span.
SPIKE_ROOM = 0.25
#: Two curves closer than this fraction of their panel's height at every sample coincide.
COINCIDENT = 2e-3


def _curves(ax: Axes) -> list:
    """The axes' data curves (lines with more than two samples)."""
    return [line for line in ax.get_lines() if len(line.get_xdata()) > 2]


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
    clipped = []
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
            label=f"clipped peaks (▲▼ at the edge): up to {_number(max(clipped))} {unit}")


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
    ax = _axes(ax)
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
        for link, values in traj.slider_normal.items():
            ax.plot(t, values, color=next(colours), lw=1.2, ls=":", label=f"normal force, {link}")
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
    _legend_outside(ax)
    return ax


def _plot_reaction_magnitudes(ax: Axes, traj: Trajectory, original: Trajectory) -> None:
    """Magnitudes of the forces on the ground and of their sum, before and after."""
    names = [*traj.ground, *traj.slider_normal]
    colours = dict(zip(names, SERIES * (1 + len(names) // len(SERIES)), strict=False))
    for run, role, lw, alpha in ((original, "before", 1.0, 0.55), (traj, "after", 1.6, 1.0)):
        for point, values in run.ground.items():
            ax.plot(run.t, np.abs(values), color=colours[point], lw=lw, alpha=alpha,
                    label=f"$|R_{{{point}}}|$, {role}")
        for link, values in run.slider_normal.items():
            ax.plot(run.t, np.abs(values), color=colours[link], lw=lw, alpha=alpha, ls=":",
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
    ax = _axes(ax)
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
    _legend_outside(ax)
    return ax


def centre_of_mass_path(linkage, traj: Trajectory) -> np.ndarray:
    """Total centre of mass along a simulated motion, complex, m.

    From the crank's angle (the pose of the smooth motion there).
    """
    mech = mechanism_of(linkage)
    crank = traj.links.index(mech.input)
    mo = mech.motion(traj.theta[crank], traj.omega[crank], traj.alpha[crank])
    return np.asarray(mech.total_centre_of_mass(mo), complex)


def frame(linkage, samples: int = 72) -> tuple[np.ndarray, list[np.ndarray]]:
    """What to draw of the frame: the ground points, and each ground guide's travel, m.

    Returns the ground points (complex) and, per slider on a ground guide, the two ends of
    the stretch of its line that its point covers over a revolution (or near the reference
    pose, for a crank that does not turn fully).
    """
    from .cycle import sample_angles

    mech = mechanism_of(linkage)
    pivots = np.array(list(mech.ground_positions.values()), complex)
    rng = mech.assembly_range()
    angles = sample_angles(samples) if rng.full else np.linspace(*rng.intervals[0], samples)
    with np.errstate(all="ignore"):
        mo = mech.motion(angles)
    points = mech.points(mo)
    guides = []
    for slider in mech.linkage.sliders:
        if slider.guide == GROUND:
            path = points[slider.point][np.isfinite(points[slider.point])]
            if path.size:
                d = complex(*slider.direction) / abs(complex(*slider.direction))
                along = (path * np.conj(d)).real
                base = path[0] - (path[0] * np.conj(d)).real * d
                guides.append(base + d * np.array([along.min(), along.max()]))
    return pivots, guides


def _draw_frame(ax: Axes, linkage, label: str | None = "frame (pivots, guides)") -> None:
    pivots, guides = frame(linkage)
    ax.plot(pivots.real, pivots.imag, "k^", ms=8, label=label, zorder=5)
    for ends in guides:
        ax.plot(ends.real, ends.imag, "k-", lw=6, alpha=0.25, zorder=1)


def plot_com_path(
    linkage, traj: Trajectory, original=None,
    original_traj: Trajectory | None = None, ax: Axes | None = None,
) -> Axes:
    """Path of the total centre of mass, with the frame (a point when balanced)."""
    ax = _axes(ax)
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
    _draw_frame(ax, linkage)
    ax.set_aspect("equal", adjustable="datalim")
    ax.set_xlabel("x (m)")
    ax.set_ylabel("y (m)")
    ax.set_title("path of the total centre of mass")
    ax.grid(alpha=0.3)
    _legend_outside(ax)
    return ax


#: Largest distance, between two samples, of a drawn curve from the line through them,
#: relative to the span of its panel: about a pixel of a panel 500 pixels high.
DRAWING_TOLERANCE = 2e-3
#: Fewest and most crank angles of a drawn revolution (the spec's ``samples`` if more).
PLOT_SAMPLES = (720, 2**17)
#: A curve whose span is below this fraction of its natural scale (the largest force on the
#: ground, times the linkage's size for a moment) is drawn as rounding: not refined further.
ROUNDING_SPAN = 1e-9


def cycle_analyses(design, *, samples: int | None = None,
                   tolerance: float = DRAWING_TOLERANCE):
    """One revolution of the design and of its original, sampled finely enough to draw.

    At the operating speed (and the spec's gravity), from at least the spec's ``samples`` and
    :data:`PLOT_SAMPLES`' least, doubled until every drawn curve (the shaking force's tip, the
    shaking moment, the driving torque) lies within ``tolerance`` of its panel's span from
    the straight lines between its samples (checked at the midpoints), or the most.

    Parameters
    ----------
    design
        A design with an operating speed; its ``original`` (``[original]``) is analysed too.
    samples
        Take exactly this many crank angles instead.
    tolerance
        Largest midpoint deviation relative to the panel's span (dimensionless).

    Returns
    -------
    tuple
        ``(design's, original's or None)`` :class:`~balancer.cycle.CycleAnalysis`, both at
        the same crank angles.

    Raises
    ------
    SpecError
        If the design has no operating speed; :class:`~balancer.errors.AssemblyError` if the
        crank cannot turn a full revolution.
    """
    from dataclasses import replace

    from .api import analyze
    from .errors import SpecError

    if design.operation is None:
        raise SpecError("missing required key: a cycle analysis needs the operating speed",
                        key="operation.speed")
    designs = [design]
    if design.original is not None:
        designs.append(replace(design, mechanism=design.original, original=None))

    def at(n: int) -> list:
        return [analyze(replace(d, operation=replace(d.operation, samples=n))) for d in designs]

    n = samples or max(design.operation.samples, PLOT_SAMPLES[0])
    coarse = at(n)
    while samples is None and 2 * n <= PLOT_SAMPLES[1]:
        fine = at(2 * n)
        if _drawn_within(fine, tolerance):
            coarse = fine
            break
        coarse, n = fine, 2 * n
    return coarse[0], (coarse[1] if len(coarse) > 1 else None)


def _cycle_panels(analysis) -> dict[str, np.ndarray]:
    """What the cycle figure draws of an analysis, by panel."""
    r = analysis.reactions
    return {"force": r.shaking_force, "moment": r.shaking_moment, "torque": r.driving_torque}


def _drawn_within(analyses, tolerance: float) -> bool:
    """Whether every curve at the even samples is drawn within ``tolerance`` of its panel.

    The odd samples are the midpoints: their distance from the chords of the even ones,
    relative to the panel's span over all the analyses (floored at :data:`ROUNDING_SPAN` of
    its natural scale).
    """
    force_scale = max(max((float(np.nanmax(np.abs(v), initial=0.0)) for v in
                           (*a.reactions.ground.values(), *a.reactions.slider_normal.values())),
                          default=0.0) for a in analyses)
    length = analyses[0].mechanism.structure.length_scale()
    panels = [_cycle_panels(a) for a in analyses]
    for key in panels[0]:
        curves = [p[key] for p in panels]
        span = max(max(np.ptp(c.real), np.ptp(c.imag)) if np.iscomplexobj(c) else np.ptp(c)
                   for c in curves)
        natural = force_scale * (1.0 if key == "force" else length)
        span = max(span, ROUNDING_SPAN * natural, 1e-300)
        for c in curves:
            even, odd = c[0::2], c[1::2]
            chord = 0.5 * (even + np.roll(even, -1))
            if not np.nanmax(np.abs(odd - chord), initial=0.0) <= tolerance * span:
                return False
    return True


def _closed(values: np.ndarray) -> np.ndarray:
    """A revolution's samples with the first repeated at the end (the curve closes)."""
    return np.append(values, values[:1])


def _cycle_label(role: str, values: np.ndarray, unit: str) -> str:
    from .cycle import Figure as Figures

    f = Figures.of(values)
    return f"{role}: RMS {_number(f.rms)} {unit}, max {_number(f.max)} {unit}"


def _roles(before) -> tuple[str, str]:
    return ("balanced design", "original") if before is not None else ("design", "")


def plot_shaking_force_polar(analysis, before=None, ax: Axes | None = None,
                             legend: bool = True) -> Axes:
    """Polar diagram of the shaking force: its vector's tip over one revolution, N.

    ``analysis`` and ``before`` (the original's, optional) are
    :class:`~balancer.cycle.CycleAnalysis`; a dot marks θ1 = 0 and an arrow the sense of
    travel. A force-balanced design's curve is a point at the origin.
    """
    ax = _axes(ax)
    after_role, before_role = _roles(before)
    ax.axhline(0.0, color="0.6", lw=0.8)
    ax.axvline(0.0, color="0.6", lw=0.8)
    for a, role, style in ((before, before_role, BEFORE_STYLE),
                           (analysis, after_role, AFTER_STYLE)):
        if a is None:
            continue
        colour, lw = style["color"], style["lw"]
        f = _closed(a.reactions.shaking_force)
        ax.plot(f.real, f.imag, **style, label=_cycle_label(role, a.reactions.shaking_force, "N"))
        ax.plot(f.real[:1], f.imag[:1], "o", color=colour, ms=6, mec="k", mew=0.6, zorder=4)
        k = max(1, f.size // 8)
        if abs(f[k + 1] - f[k]) > 0:
            ax.annotate("", xy=(f[k + 1].real, f[k + 1].imag), xytext=(f[k].real, f[k].imag),
                        arrowprops={"arrowstyle": "-|>", "color": colour, "lw": lw,
                                    "mutation_scale": 14})
    ax.plot([], [], "o", color="w", mec="k", mew=0.6, label="θ1 = 0, arrow: sense of travel")
    ax.set_aspect("equal", adjustable="datalim")
    ax.set_xlabel("shaking force, x (N)")
    ax.set_ylabel("shaking force, y (N)")
    ax.set_title("shaking force over one revolution (polar diagram)")
    ax.grid(alpha=0.3)
    if legend:
        _legend_outside(ax)
    return ax


def plot_over_crank_angle(analysis, quantity: str, before=None, ax: Axes | None = None,
                          legend: bool = True) -> Axes:
    """``quantity`` (``"shaking_moment"`` or ``"driving_torque"``, N·m) over the crank angle.

    Of ``analysis`` and, if given, ``before`` (the original's), over one revolution in degrees.
    """
    ax = _axes(ax)
    names = {"shaking_moment": ("shaking moment about the origin", "shaking moment"),
             "driving_torque": ("driving torque on the crank", "driving torque")}
    if quantity not in names:
        raise ValueError(f"no such quantity: {quantity!r}")
    after_role, before_role = _roles(before)
    for a, role, style in ((before, before_role, BEFORE_STYLE),
                           (analysis, after_role, AFTER_STYLE)):
        if a is None:
            continue
        values = getattr(a.reactions, quantity)
        ax.plot(np.degrees(np.append(a.theta1, 2 * np.pi)), _closed(values), **style,
                label=_cycle_label(role, values, "N·m"))
    ax.set_xlim(0.0, 360.0)
    ax.set_xticks(np.arange(0, 361, 45))
    ax.set_xlabel("crank angle θ1 (°)")
    ax.set_ylabel(f"{names[quantity][0]} (N·m)")
    ax.set_title(f"{names[quantity][1]} over one revolution")
    ax.grid(alpha=0.3)
    if legend:
        _legend_outside(ax)
    return ax


def cycle_figure(analysis, before=None, title: str = "") -> Figure:
    """The picture a balancing report starts with: one revolution at the operating speed.

    The shaking force's polar diagram, and the shaking moment and driving torque over the
    crank angle; of the design, and of the original before it (``before``) if given. Each
    panel's title gives its RMS and maximum (original → design); one legend below the panels.
    """
    fig = Figure(figsize=(12, 7), layout="constrained")
    axes = fig.subplot_mosaic([["force", "moment"], ["force", "torque"]],
                              width_ratios=[1.0, 1.3])
    plot_shaking_force_polar(analysis, before, ax=axes["force"], legend=False)
    plot_over_crank_angle(analysis, "shaking_moment", before, ax=axes["moment"], legend=False)
    plot_over_crank_angle(analysis, "driving_torque", before, ax=axes["torque"], legend=False)
    for key, unit in (("force", "N"), ("moment", "N·m"), ("torque", "N·m")):
        ax = axes[key]
        after = _cycle_panels(analysis)[key]
        figures = [_figure_pair(_cycle_panels(before)[key] if before is not None else None,
                                after, stat) for stat in ("rms", "max")]
        ax.set_title(f"{ax.get_title()}\nRMS {figures[0]} {unit}, max {figures[1]} {unit}",
                     fontsize="medium")
    handles, labels = axes["force"].get_legend_handles_labels()
    fig.legend(handles, [label.split(": RMS")[0] for label in labels],
               loc="outside lower center",
               ncols=len(handles), fontsize="small")
    what = f"one revolution at {analysis.speed:g} rad/s"
    if any(analysis.gravity):
        what += f", gravity ({analysis.gravity[0]:g}, {analysis.gravity[1]:g}) m/s²"
    if before is not None:
        what += ", before and after balancing"
    fig.suptitle(f"{title}: {what}" if title else what)
    return fig


def _figure_pair(before: np.ndarray | None, after: np.ndarray, stat: str) -> str:
    """``"b → a"`` (or ``"a"``) of a figure of one revolution's values, to 3 digits."""
    from .cycle import Figure as Figures

    text = _number(getattr(Figures.of(after), stat))
    if before is None:
        return text
    return f"{_number(getattr(Figures.of(before), stat))} → {text}"


def _number(x: float) -> str:
    """Three significant digits, whole numbers below a million written out (1800, not 1.8e+03)."""
    if 1.0 <= abs(x) < 1e6:
        return f"{x:.{max(3, int(np.log10(abs(x))) + 1)}g}"
    return f"{x:.3g}"


def verification_figure(design, verification) -> Figure:
    """The report figure of ``balancer verify``.

    Columns: the crank driven at the operating speed, free motion; rows: the forces on the
    ground and their sum, shaking moment, path of the total centre of mass; each before and
    after where the design names its original. Legends beside the panels. The free motion's
    panels are set on the bulk of their samples, brief spikes (a pass near a toggle) clipped
    and marked with their size; the driven run's show every sample, its peaks being the
    loads at the operating speed.
    """
    fig = Figure(figsize=(17, 14), layout="constrained")
    axes = fig.subplots(3, 2)
    title = design.title or "design"
    fig.suptitle(f"{title}: verification by simulation ({verification.method} formulation)")
    speed = design.operation.speed if design.operation else 0.0
    runs = ((verification.driven, f"crank driven at {speed:g} rad/s", 0),
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


def _write_atomic(fig: Figure, out: Path, dpi: float | None, kind: str = "png") -> Path:
    """Write ``fig`` to ``out`` as ``kind`` (``png``, ``svg``, ``pdf``), whole or not at all."""
    from matplotlib.backends.backend_agg import FigureCanvasAgg

    FigureCanvasAgg(fig)
    return write_with(out, lambda tmp: fig.savefig(tmp, dpi=dpi, format=kind),
                      suffix=out.suffix)


#: Figure formats by file extension (matplotlib's Agg, SVG and PDF backends).
FIGURE_TYPES: dict[str, str] = {".png": "png", ".svg": "svg", ".pdf": "pdf"}
#: Animation formats by file extension (GIF by Pillow, MP4 by ffmpeg: :func:`ffmpeg`).
ANIMATION_TYPES: dict[str, str] = {".gif": "gif", ".mp4": "mp4"}


def figure_type(path: str | os.PathLike[str], option: str | None = None,
                types: dict[str, str] = FIGURE_TYPES) -> str:
    """The file type that ``path``'s extension names, or :class:`OutputError` (exit 2)."""
    suffix = Path(path).suffix.lower()
    if suffix not in types:
        known = ", ".join(types)
        raise OutputError(f"the file type comes from the extension: use one of {known}",
                          key=option, value=str(path))
    return types[suffix]


def ffmpeg() -> str | None:
    """The ffmpeg program that writes MP4 animations, or ``None`` if there is none.

    matplotlib's ``animation.ffmpeg_path`` setting (``ffmpeg`` on ``PATH`` by default), else
    the one the ``imageio-ffmpeg`` package ships (``pip install 'balancer[video]'``).
    """
    import shutil

    import matplotlib

    found = shutil.which(matplotlib.rcParams["animation.ffmpeg_path"])
    if found:
        return found
    try:
        import imageio_ffmpeg
    except ImportError:
        return None
    try:
        return imageio_ffmpeg.get_ffmpeg_exe()
    except RuntimeError:  # the package without its binary for this platform
        return None


def animation_type(path: str | os.PathLike[str], option: str | None = None) -> str:
    """The animation type that ``path``'s extension names, if it can be written here.

    Raises
    ------
    OutputError
        (exit 2) For an extension other than :data:`ANIMATION_TYPES`', or ``.mp4`` where there
        is no ffmpeg (:func:`ffmpeg`).
    """
    kind = figure_type(path, option, ANIMATION_TYPES)
    if kind == "mp4" and ffmpeg() is None:
        raise OutputError("an MP4 animation needs ffmpeg, which is not installed: install it "
                          "(or pip install 'balancer[video]'), or write a .gif", key=option,
                          value=str(path))
    return kind


def save_figure(fig: Figure, path: str | os.PathLike[str], dpi: float = 150) -> Path:
    """Write the figure to ``path`` in the format its extension names, atomically.

    PNG at ``dpi``; SVG and PDF are vector formats. Returns the path written.

    Raises
    ------
    OutputError
        For an extension other than :data:`FIGURE_TYPES`', or a file that cannot be written.
    """
    out = Path(path)
    return _write_atomic(fig, out, dpi, figure_type(out))


def save_png(fig: Figure, path: str | os.PathLike[str], dpi: float = 100) -> Path:
    """Write the figure as one PNG at ``dpi``, atomically; returns the path written."""
    return _write_atomic(fig, Path(path).with_suffix(".png"), dpi)


def drawing_frames(linkage, frames: int):
    """What an animation draws over a revolution at equally spaced crank angles.

    Returns ``(links, coms, total)``: per link (the ground's left out) a ``(frames, k)``
    complex array of its points in drawing order (a ternary link closed into a triangle),
    per link its centre of mass ``(frames,)``, and ``(frames,)`` the total, m.
    """
    from .cycle import sample_angles

    mech = mechanism_of(linkage)
    mo = mech.motion(sample_angles(frames), 1.0)
    points = mech.points(mo)
    links = {}
    for name, names in mech.drawing().items():
        if name == GROUND:
            continue
        ring = [*names, names[0]] if len(names) > 2 else list(names)
        links[name] = np.column_stack([points[p] for p in ring])
    coms = {name: np.asarray(c.complex() + 0 * mo.theta1, complex)
            for name, c in zip(mech.link_names, mech.centres_of_mass(mo), strict=True)}
    return links, coms, np.asarray(mech.total_centre_of_mass(mo), complex)


def counterweight_paths(linkage, counterweights, frames: int) -> dict[str, tuple]:
    """Where each counterweight to add is over a revolution: ``(centres, radius)`` per link.

    ``centres`` a ``(frames,)`` complex array (m): the counterweight's centre ``(e, f)`` in its
    link's frame, carried by the link; ``radius`` its steel disc's (m; 0 for a point).
    """
    from .cycle import sample_angles
    from .linkage.vectors import V

    mech = mechanism_of(linkage)
    mo = mech.motion(sample_angles(frames), 1.0)
    out = {}
    for k, name in enumerate(mech.link_names):
        w = counterweights.get(name)
        if w is None or w.kind != "add":
            continue
        centre = mo.point(k, V(w.e, w.f)).complex() + 0 * mo.theta1
        out[name] = (np.asarray(centre, complex), w.disc_radius or 0.0)
    return out


def _arm(points: np.ndarray, target: np.ndarray) -> np.ndarray:
    """``(frames, 2)``: from the link's point nearest ``target`` (at the first frame) to it.

    ``points`` ``(frames, k)`` a link's points, ``target`` ``(frames,)`` a point it carries:
    the pair moves rigidly with the link.
    """
    near = int(np.argmin(np.abs(points[0] - target[0])))
    return np.column_stack([points[:, near], target])


def animation_figure(linkage, *, frames: int = 72, title: str = "", counterweights=None):
    """The figure of an animation of one revolution, and what changes from frame to frame.

    Drawn once: the frame (pivots, guides), the path of the total centre of mass, the title
    (wrapped to the figure's width), the legend. Per frame, at the crank angle
    θ1 = 360°·k/``frames``: the links; each link's centre of mass on a thin arm from the
    link's nearest point (it turns with its link, wherever the balancing put it); the
    counterweights added to the original links (``counterweights``, per link as
    :func:`balancer.balance.counterweights.counterweights` gives them; ``kind`` ``"add"``) as
    their steel discs (a diamond for a point mass) on arms from their links; the total centre
    of mass with its path so far; and the crank angle's readout. Links that no single added
    body makes (``rebuild``, ``remove``) are named in the legend.

    Returns
    -------
    tuple
        ``(fig, update)``: the :class:`~matplotlib.figure.Figure` (its moving artists marked
        animated, so a plain draw leaves them out) and ``update(k)``, which sets frame ``k``'s
        moving artists and returns them, to be drawn over the still picture.
    """
    import textwrap

    from matplotlib.lines import Line2D
    from matplotlib.patches import Circle

    from .cycle import sample_angles

    weights = counterweights or {}
    links, coms, total = drawing_frames(linkage, frames)
    pivots, guides = frame(linkage)
    discs = counterweight_paths(linkage, weights, frames)
    fig = Figure(figsize=(6, 4.5), dpi=100, layout="constrained")
    ax = fig.add_subplot()
    rims = [c + r * s for c, r in discs.values() for s in (1, -1, 1j, -1j)]
    everything = np.concatenate([*(v.ravel() for v in links.values()), *coms.values(), total,
                                 pivots, *guides, *rims])
    everything = everything[np.isfinite(everything)]
    extent = max(np.ptp(everything.real), np.ptp(everything.imag), 1e-300)
    pad = 0.08 * extent
    ax.set_xlim(everything.real.min() - pad, everything.real.max() + pad)
    ax.set_ylim(everything.imag.min() - pad, everything.imag.max() + pad)
    ax.set_aspect("equal")
    ax.set_xlabel("x (m)")
    ax.set_ylabel("y (m)")
    ax.set_title(title or "linkage over one crank revolution", wrap=True)
    ax.grid(alpha=0.3)
    ax.plot(total.real, total.imag, color=COLOURS["before"], lw=1, ls=":",
            label="path of the total centre of mass")
    _draw_frame(ax, linkage, label=None)
    lines = []  # (artist, (frames, n) points joined)
    for name, points in links.items():
        (arm,) = ax.plot([], [], "-", color=COLOURS["com"], lw=1.0, animated=True, zorder=1.5)
        lines.append((arm, _arm(points, coms[name])))
    for i, points in enumerate(links.values()):
        (bar,) = ax.plot([], [], "-o", color=COLOURS["link"], lw=3, ms=5, animated=True,
                         label="links" if i == 0 else None)
        lines.append((bar, points))
    for name, (centres, _) in discs.items():
        (arm,) = ax.plot([], [], "-", color="0.35", lw=2, animated=True)
        lines.append((arm, _arm(links[name], centres)))
    bodies = []
    for i, (centres, radius) in enumerate(discs.values()):
        if radius > 0:
            body = Circle((centres[0].real, centres[0].imag), radius, color="0.35", alpha=0.8,
                          animated=True, label="counterweights added" if i == 0 else None)
            ax.add_patch(body)
        else:
            (body,) = ax.plot([], [], "D", color="0.35", ms=7, animated=True,
                              label="counterweights added" if i == 0 else None)
        bodies.append((body, centres, radius))
    (link_coms,) = ax.plot([], [], "s", color=COLOURS["com"], ms=5, animated=True,
                           label="link centres of mass (line: to its link)")
    (trace,) = ax.plot([], [], color=COLOURS["after"], lw=2, animated=True)
    (com,) = ax.plot([], [], "o", color=COLOURS["after"], ms=9, label="total centre of mass",
                     animated=True)
    angle = ax.text(0.02, 0.97, "", transform=ax.transAxes, ha="left", va="top",
                    fontsize="medium", animated=True,
                    bbox={"boxstyle": "round,pad=0.3", "fc": "white", "ec": "0.6", "alpha": 0.9})
    handles, _ = ax.get_legend_handles_labels()
    for kind, what in (("rebuild", "rebuilt, no single counterweight"),
                       ("remove", "lightened, material removed")):
        names = [name for name, w in weights.items() if w.kind == kind]
        if names:
            handles.append(Line2D([], [], ls="none",
                                  label=textwrap.fill(f"{what}: {', '.join(names)}", 36)))
    fig.legend(handles=handles, loc="outside lower center", ncols=2, fontsize="small")
    fig.draw_without_rendering()  # the constrained layout's first pass leaves the title out
    degrees = np.degrees(sample_angles(frames))
    link_com_values = np.column_stack(list(coms.values()))

    def update(k: int) -> list:
        for line, values in lines:
            line.set_data(values[k].real, values[k].imag)
        for body, centres, radius in bodies:
            if radius > 0:
                body.set_center((centres[k].real, centres[k].imag))
            else:
                body.set_data([centres[k].real], [centres[k].imag])
        link_coms.set_data(link_com_values[k].real, link_com_values[k].imag)
        trace.set_data(total[: k + 1].real, total[: k + 1].imag)
        com.set_data([total[k].real], [total[k].imag])
        angle.set_text(f"crank angle θ1 = {degrees[k]:5.1f}°")
        return [trace, *(line for line, _ in lines), *(b for b, _, _ in bodies), link_coms,
                com, angle]

    return fig, update


def animate(linkage, path: str | os.PathLike[str], *, frames: int = 72, fps: int = 24,
            title: str = "", counterweights=None) -> Path:
    """Write an animation of the linkage turning one revolution, its centre of mass traced.

    What it draws: :func:`animation_figure` (``counterweights`` per link, as
    :attr:`BalanceResult.counterweights` gives them: the bodies added to the original links
    are drawn as their steel discs, turning with their links).

    The type comes from the extension (:func:`animation_type`): a GIF (Pillow) or an MP4
    (H.264 by ffmpeg). Frames are equally spaced crank angles (the crank at constant speed).
    The still parts are drawn once and each frame only blits the moving artists onto them
    (matplotlib's animation writers would redraw the whole figure for every frame, and draw no
    artist marked animated). Written whole or not at all.

    Raises
    ------
    OutputError
        For an extension other than :data:`ANIMATION_TYPES`', an MP4 without ffmpeg (both
        before any work), or a file that cannot be written.
    """
    from matplotlib.backends.backend_agg import FigureCanvasAgg

    kind = animation_type(path)
    fig, update = animation_figure(linkage, frames=frames, title=title,
                                   counterweights=counterweights)
    canvas = FigureCanvasAgg(fig)
    canvas.draw()
    fig.set_layout_engine("none")
    background = canvas.copy_from_bbox(fig.bbox)
    ax = fig.axes[0]
    images = []
    for k in range(frames):
        canvas.restore_region(background)
        for artist in update(k):
            ax.draw_artist(artist)
        images.append(np.asarray(canvas.buffer_rgba())[..., :3].copy())
    writer = _write_mp4 if kind == "mp4" else _write_gif
    return write_with(path, lambda tmp: writer(tmp, images, fps), suffix=f".{kind}")


def _write_gif(path: str, images: list[np.ndarray], fps: int) -> None:
    """Write RGB frames as a looping GIF (64 colours a frame)."""
    from PIL import Image

    frames = [Image.fromarray(rgb).quantize(colors=64) for rgb in images]
    frames[0].save(path, format="GIF", save_all=True, append_images=frames[1:],
                   duration=round(1000 / fps), loop=0)


def _write_mp4(path: str, images: list[np.ndarray], fps: int) -> None:
    """Write RGB frames as an H.264 MP4 by piping them to ffmpeg.

    Raises
    ------
    OutputError
        If there is no ffmpeg, or it fails (its last line of error).
    """
    import subprocess

    exe = ffmpeg()
    if exe is None:
        raise OutputError("an MP4 animation needs ffmpeg, which is not installed",
                          source=path)
    height, width = images[0].shape[:2]
    command = [exe, "-y", "-loglevel", "error", "-f", "rawvideo", "-pix_fmt", "rgb24",
               "-s", f"{width}x{height}", "-r", str(fps), "-i", "-", "-an",
               "-vf", "pad=ceil(iw/2)*2:ceil(ih/2)*2", "-c:v", "libx264",
               "-pix_fmt", "yuv420p", "-movflags", "+faststart", "-f", "mp4", path]
    done = subprocess.run(command, input=b"".join(rgb.tobytes() for rgb in images),
                          capture_output=True, check=False)
    if done.returncode != 0:
        lines = done.stderr.decode(errors="replace").strip().splitlines() or ["no message"]
        raise OutputError(f"ffmpeg could not write the MP4 (exit {done.returncode}: "
                          f"{lines[-1]})", source=path)


#: How far beyond a front's own extent (a fraction of it) the axes reach to take the original
#: design in; one farther away is an arrow at the edge (the front is not squashed into a corner).
FRONT_REACH = 0.3


def front_figure(front, title: str | None = None, *, force_balance: bool = False,
                 original_force_balanced: bool | None = None) -> Figure:
    """A trade-off front as a designer puts it in a report.

    The least RMS shaking moment against the second objective, each point's certified lower
    bound beside it, the knee marked. The axes are the front's: the original design is drawn
    where it lies within :data:`FRONT_REACH` of the front's extent, else as an arrow at the edge
    pointing its way, with its coordinates.

    Parameters
    ----------
    front
        A :class:`~balancer.balance.pareto.Front`.
    title
        The figure's title (default: what is traded against what).
    force_balance
        Whether the front's designs are held to exact force balance (the spec's
        ``[balance] force_balance``): said in its legend.
    original_force_balanced
        Whether the original design is force-balanced; where it is not and the front is, the
        legend says why it is not on the front.
    """
    fig = Figure(figsize=(7.5, 4.5), layout="constrained")
    ax = fig.add_subplot()
    xs = np.array([p.value for p in front.points])
    ys = np.array([p.shaking_moment for p in front.points])
    bounds = np.array([p.lower_bound for p in front.points])
    what = front.name.replace("_", " ")
    label = "least RMS shaking moment" + (", every design force-balanced" if force_balance
                                          else "")
    if len(front.points) == 1:
        label += f" (one point: nothing to trade against {what})"
    ax.plot(xs, ys, "o-", color="C0", label=label)
    ax.plot(xs, bounds, "_", color="k", markersize=12, label="certified lower bound")
    knee = [p for p in front.points if p.knee]
    if knee:
        ax.plot([knee[0].value], [knee[0].shaking_moment], "*", color="C3", markersize=14,
                label="knee")
    unit = f"{'RMS, ' if front.unit != 'kg' else ''}{front.unit}"
    ax.set_xlabel(f"{what} ({unit})")
    ax.set_ylabel("RMS shaking moment (N·m)")
    ox, oy = front.original
    if np.isfinite(ox) and np.isfinite(oy):
        (x0, x1), (y0, y1) = _front_limits(xs, np.maximum(ys, bounds), (ox, oy))
        ax.set_xlim(x0, x1)
        ax.set_ylim(y0, y1)
        name = "original design"
        if force_balance and original_force_balanced is False:
            name += ": not force-balanced, so not on the front"
        _mark_point(ax, ox, oy, name, f"original design\n{_number(ox)} {front.unit}, "
                    f"{_number(oy)} N·m", marker="s", color="0.5", mec="0.2", ms=7)
    else:
        ax.set_ylim(bottom=0)
    ax.grid(True, alpha=0.3)
    ax.set_title(title or f"Shaking moment against {what}")
    fig.legend(loc="outside lower center", ncols=1, fontsize="small")
    return fig


def _front_limits(xs: np.ndarray, ys: np.ndarray, original: tuple[float, float]):
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


def _key_label(key: str) -> str:
    """A spec key as an axis label, with its unit (:func:`balancer.sweeps.key_unit`)."""
    from .sweeps import key_unit

    unit = key_unit(key)
    return f"{key} ({unit})" if unit else key


def _key_value(key: str, value: float) -> str:
    """``key = value unit``, the value to 4 significant digits."""
    from .sweeps import key_unit

    return f"{key} = {value:.4g} {key_unit(key)}".rstrip()


#: How far inside the frame (a fraction of the axes) a point beyond the limits is marked.
EDGE_INSET = 0.08


def _mark_point(ax: Axes, x: float, y: float, label: str, where: str, **style):
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
        ax.annotate("", xy=inside + reach * d, xytext=inside, xycoords="axes fraction",
                    arrowprops={"arrowstyle": "-|>", "color": style.get("mec", "k"),
                                "lw": 1.2, "shrinkA": 7, "shrinkB": 0})
        ax.annotate(where, xy=inside, xycoords="axes fraction", xytext=-12 * d,
                    textcoords="offset points", fontsize="small",
                    bbox={"boxstyle": "round,pad=0.2", "fc": "white", "ec": "none",
                          "alpha": 0.8},
                    ha="right" if d[0] > 0.3 else "left" if d[0] < -0.3 else "center",
                    va="top" if d[1] > 0.3 else "bottom" if d[1] < -0.3 else "center")
    ax.set_xlim(xlim)
    ax.set_ylim(ylim)
    return marker


#: How an atlas shows a point without a balanced design, by its row's ``status``
#: (:mod:`balancer.sweeps`): the legend's words, a heat map cell's fill, hatch and hatch colour
#: (``edgecolor``), a scattered point's marker.
NO_DESIGN: dict[str, dict[str, str]] = {
    "infeasible": {"label": "infeasible: no design within the [balance] bounds",
                   "facecolor": "0.85", "hatch": "//", "edgecolor": "0.3", "marker": "x"},
    "bad-geometry": {"label": "bad geometry: does not assemble, or the crank cannot turn fully",
                     "facecolor": "white", "hatch": "xx", "edgecolor": "#D55E00",
                     "marker": "+"},
    "failed": {"label": "the solver failed", "facecolor": "white", "hatch": "..",
               "edgecolor": "#CC79A7", "marker": "1"},
}
#: How the spec's own design is marked on an atlas.
ORIGINAL_STYLE = {"marker": "*", "ms": 16, "mfc": "white", "mec": "k", "mew": 1.2}


def _no_design(status: str) -> dict[str, str]:
    """:data:`NO_DESIGN`'s entry for ``status`` (a generic one for any other status)."""
    return NO_DESIGN.get(status, {"label": f"no design ({status})", "facecolor": "white",
                                  "hatch": "--", "edgecolor": "0.5", "marker": "o"})


def sweep_figure(path, keys, *, original: dict[str, float] | None = None,
                 perturbs=()) -> Figure:
    """The atlas of a sweep's table: the balanced RMS shaking moment over the varied keys.

    Parameters
    ----------
    path
        The sweep's Parquet table (:func:`balancer.sweeps.sweep`).
    keys
        The varied keys, in the table's order; ``None`` for a perturbation sweep.
    original
        The spec's own value of each key (its unit's): the original design, marked.
    perturbs
        A perturbation sweep's :class:`~balancer.sweeps.Perturb` (``key``, ``sigma``): named
        in its histogram's title.

    Returns
    -------
    Figure
        ``keys`` ``None``: the histogram of the perturbed designs' RMS shaking force (N). Two
        keys on a grid: a heat map; the cells without a balanced design hatched, their legend
        telling infeasible from bad geometry (and a failed solver). One key: the RMS shaking
        moment before and after against it, the points without a design marked along the
        bottom. Otherwise a scatter over the first two keys coloured by the balanced RMS
        shaking moment, the points without a design as markers. Axes in the keys' units
        (:func:`balancer.sweeps.key_unit`); the original design a white star (a line for one
        key), or an arrow at the edge where it lies outside the swept ranges.
    """
    import pyarrow.parquet as pq

    table = pq.read_table(path).to_pydict()
    if keys is None:
        return _perturbation_figure(table, perturbs, original or {})
    after = np.array([np.nan if v is None else v for v in table["shaking_moment_after"]])
    status = np.array(table["status"], dtype=object)
    fig = Figure(figsize=(7.5, 5.0), layout="constrained")
    ax = fig.add_subplot()
    if len(keys) == 1:
        before = np.array([np.nan if v is None else v for v in table["shaking_moment_before"]])
        _atlas_line(ax, np.array(table[keys[0]], float), keys[0], before, after, status,
                    original)
    else:
        _atlas_map(fig, ax, [np.array(table[k], float) for k in keys[:2]], keys[:2], after,
                   status, original)
    return fig


def _no_design_masks(after: np.ndarray, status: np.ndarray) -> dict[str, np.ndarray]:
    """The points without a balanced design, by status (in :data:`NO_DESIGN`'s order)."""
    missing = ~np.isfinite(after)
    order = [*NO_DESIGN, *sorted(set(status[missing]) - set(NO_DESIGN))]
    return {s: missing & (status == s) for s in order if np.any(missing & (status == s))}


def _atlas_line(ax: Axes, x: np.ndarray, key: str, before: np.ndarray, after: np.ndarray,
                status: np.ndarray, original: dict[str, float] | None) -> None:
    """One varied key: the RMS shaking moment before and after balancing against it."""
    ax.plot(x, before, "o-", color="0.5", label="before balancing (each point's own design)")
    ax.plot(x, after, "o-", color="C0", label="balanced (certified optimum)")
    ax.set_ylim(bottom=0)
    for s, mask in _no_design_masks(after, status).items():
        style = _no_design(s)
        ax.plot(x[mask], np.full(mask.sum(), 0.03), linestyle="none", marker=style["marker"],
                color=style["edgecolor"], ms=8, mew=1.5, transform=ax.get_xaxis_transform(),
                label=style["label"])
    if original is not None and key in original:
        value = original[key]
        xlim = ax.get_xlim()
        if xlim[0] <= value <= xlim[1]:
            ax.axvline(value, color="k", ls=":", lw=1.2,
                       label=f"original design: {_key_value(key, value)}")
            ax.set_xlim(xlim)
        else:
            ylim = ax.get_ylim()
            _mark_point(ax, value, 0.5 * (ylim[0] + ylim[1]), "original design",
                        _key_value(key, value), **ORIGINAL_STYLE)
    ax.set_xlabel(_key_label(key))
    ax.set_ylabel("RMS shaking moment (N·m)")
    ax.set_title("RMS shaking moment before and after balancing")
    ax.grid(True, alpha=0.3)
    ax.figure.legend(loc="outside lower center", ncols=2, fontsize="small")


def _atlas_map(fig: Figure, ax: Axes, values: list[np.ndarray], keys: list[str],
               after: np.ndarray, status: np.ndarray,
               original: dict[str, float] | None) -> None:
    """Two varied keys: a heat map (a grid) or a scatter of the balanced RMS shaking moment."""
    from matplotlib.colors import ListedColormap
    from matplotlib.patches import Patch

    x, y = values
    xs, ys = np.unique(x), np.unique(y)
    solved = np.isfinite(after)
    masks = _no_design_masks(after, status)
    handles = []
    mesh = None
    if xs.size * ys.size == x.size:  # a grid: a cell per point
        cell = np.searchsorted(ys, y), np.searchsorted(xs, x)

        def on_grid(v: np.ndarray) -> np.ndarray:
            grid = np.full((ys.size, xs.size), np.nan)
            grid[cell] = v
            return np.ma.masked_invalid(grid)

        if solved.any():
            mesh = ax.pcolormesh(xs, ys, on_grid(after), shading="nearest", cmap="viridis")
        for s, mask in masks.items():
            style = _no_design(s)
            ax.pcolor(xs, ys, on_grid(np.where(mask, 0.0, np.nan)), shading="nearest",
                      cmap=ListedColormap([style["facecolor"]]), hatch=style["hatch"],
                      edgecolor=style["edgecolor"], linewidth=0.0)
            handles.append(Patch(facecolor=style["facecolor"], hatch=style["hatch"],
                                 edgecolor=style["edgecolor"], label=style["label"]))
    else:
        if solved.any():
            mesh = ax.scatter(x[solved], y[solved], c=after[solved], cmap="viridis", s=14)
        for s, mask in masks.items():
            style = _no_design(s)
            handles.append(ax.scatter(x[mask], y[mask], marker=style["marker"], s=24,
                                      color=style["edgecolor"], label=style["label"]))
    if mesh is not None:
        fig.colorbar(mesh, ax=ax, label="balanced RMS shaking moment (N·m)")
    if original is not None and all(k in original for k in keys):
        ox, oy = (original[k] for k in keys)
        handles.append(_mark_point(ax, ox, oy, "original design: the spec",
                                   f"{_key_value(keys[0], ox)}\n{_key_value(keys[1], oy)}",
                                   **ORIGINAL_STYLE))
    ax.set_xlabel(_key_label(keys[0]))
    ax.set_ylabel(_key_label(keys[1]))
    ax.set_title("RMS shaking moment of the balanced design at each point"
                 if mesh is not None else "No point has a balanced design")
    if handles:
        fig.legend(handles=handles, loc="outside lower center", ncols=1, fontsize="small")


def _perturbation_figure(table: dict, perturbs, original: dict[str, float]) -> Figure:
    """A perturbation sweep's histogram of the perturbed designs' RMS shaking force, N.

    Its title names each perturbed key, the spec's value (where ``original`` gives it) and the
    standard deviation σ of its normal draws, and how many designs were drawn and analysed.
    """
    from .sweeps import key_unit

    draws = len(table["status"])
    force = np.array([v for v in table["shaking_force_before"] if v is not None])
    fig = Figure(figsize=(7.5, 4.5), layout="constrained")
    ax = fig.add_subplot()
    if force.size:
        ax.hist(force, bins=max(10, min(60, force.size // 10)), color="C0",
                label="perturbed designs")
        p95 = float(np.percentile(force, 95))
        ax.axvline(p95, color="C3", ls="--", label=f"95th percentile: {_number(p95)} N")
    analysed = (f"{draws} designs drawn" if force.size == draws else
                f"{draws} designs drawn, {force.size} analysed (the others: bad geometry)")
    spread = []
    for p in perturbs:
        unit = f" {key_unit(p.key)}".rstrip()
        about = f" = {original[p.key]:.4g}{unit}" if p.key in original else ""
        spread.append(f"{p.key}{about}, σ = {p.sigma:.3g}{unit}")
    title = f"Residual shaking force: {analysed}"
    if spread:
        title += ", each key normal about the spec's value\n" + "; ".join(spread)
    ax.set_title(title, fontsize="medium")
    ax.set_xlabel("RMS shaking force of the perturbed design (N)")
    ax.set_ylabel("designs")
    ax.grid(True, alpha=0.3)
    _legend_outside(ax)
    return fig
