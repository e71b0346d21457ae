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
from .simulate import Trajectory

#: Colours for the sum, before and after (colour-blind safe, Okabe & Ito).
COLOURS = {"sum": "#000000", "before": "#999999", "after": "#009E73", "link": "#0072B2",
           "com": "#D55E00"}
#: Colours for the forces at the ground points and guides, in order (A0, A3, … ).
SERIES = ("#0072B2", "#D55E00", "#CC79A7", "#E69F00", "#56B4E9", "#F0E442", "#009E73")


def _axes(ax: Axes | None) -> Axes:
    if ax is not None:
        return ax
    return Figure(figsize=(7, 4), layout="constrained").add_subplot()


def plot_reactions(traj: Trajectory, ax: Axes | None = None, title: str = "") -> Axes:
    """Every force on the ground over time and their sum (as the paper's Fig. 8 and 9).

    The x (solid) and y (dashed) components at each ground point, the normal force (dotted) of
    each slider on a ground guide, and the shaking force's components (black).
    """
    ax = _axes(ax)
    t = traj.t
    colours = iter(SERIES * (1 + (len(traj.ground) + len(traj.slider_normal)) // len(SERIES)))
    for point, values in traj.ground.items():
        colour = next(colours)
        ax.plot(t, values.real, color=colour, lw=1.2, label=f"$R_{{{point}x}}$")
        ax.plot(t, values.imag, color=colour, lw=1.2, ls="--", label=f"$R_{{{point}y}}$")
    for link, values in traj.slider_normal.items():
        ax.plot(t, values, color=next(colours), lw=1.2, ls=":", label=f"normal force, {link}")
    total = traj.shaking_force
    ax.plot(t, total.real, color=COLOURS["sum"], lw=1.8, label="sum, x")
    ax.plot(t, total.imag, color=COLOURS["sum"], lw=1.8, ls="--", label="sum, y")
    ax.set_xlabel("time t (s)")
    ax.set_ylabel("force on the ground (N)")
    ax.set_title(title or f"forces on the ground, {traj.drive} motion")
    ax.grid(alpha=0.3)
    ax.legend(fontsize="small", ncol=3, loc="upper right")
    return ax


def plot_shaking_moment(
    traj: Trajectory, original: Trajectory | None = None, ax: Axes | None = None,
    title: str = "",
) -> Axes:
    """Shaking moment about the origin over time, before (the original) and after."""
    ax = _axes(ax)
    if original is not None:
        ax.plot(original.t, original.shaking_moment, color=COLOURS["before"], lw=1.5,
                label="before (original)")
    ax.plot(traj.t, traj.shaking_moment, color=COLOURS["after"], lw=1.5,
            label="after" if original is not None else "shaking moment")
    ax.set_xlabel("time t (s)")
    ax.set_ylabel("shaking moment about the origin (N·m)")
    ax.set_title(title or f"shaking moment, {traj.drive} motion")
    ax.grid(alpha=0.3)
    ax.legend(fontsize="small")
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
    ax.legend(fontsize="small")
    return ax


def verification_figure(design, verification) -> Figure:
    """The report figure of ``balancer verify``.

    Columns: the crank driven at the operating speed, free motion; rows: the forces on the
    ground and their sum, shaking moment before and after, path of the total centre of mass.
    """
    fig = Figure(figsize=(13, 14), layout="constrained")
    axes = fig.subplots(3, 2)
    title = design.title or "design"
    fig.suptitle(f"{title}: verification by simulation ({verification.method} formulation)")
    speed = design.operation.speed if design.operation else 0.0
    runs = ((verification.driven, f"crank driven at {speed:g} rad/s", 0),
            (verification.free, "free motion", 1))
    for run, label, col in runs:
        if run.trajectory is None:
            axes[0, col].text(0.5, 0.5, f"{label}: no simulation\n{run.note}", ha="center",
                              va="center", wrap=True, transform=axes[0, col].transAxes)
            continue
        plot_reactions(run.trajectory, ax=axes[0, col], title=f"forces on the ground, {label}")
        plot_shaking_moment(run.trajectory, run.original, ax=axes[1, col],
                            title=f"shaking moment, {label}")
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
#: Animation formats by file extension.
ANIMATION_TYPES: dict[str, str] = {".gif": "gif"}


def figure_type(path: str | os.PathLike[str], option: str | None = None,
                types: dict[str, str] = FIGURE_TYPES) -> str:
    """The file type that ``path``'s extension names, or :class:`OutputError` (exit 2)."""
    suffix = Path(path).suffix.lower()
    if suffix not in types:
        known = ", ".join(types)
        raise OutputError(f"the file type comes from the extension: use one of {known}",
                          key=option, value=str(path))
    return types[suffix]


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
    ``(frames, n)`` the moving links' centres of mass and ``(frames,)`` the total, m.
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
    coms = np.column_stack([c.complex() + 0 * mo.theta1 for c in mech.centres_of_mass(mo)])
    return links, coms, np.asarray(mech.total_centre_of_mass(mo), complex)


def animate(linkage, path: str | os.PathLike[str], *, frames: int = 72, fps: int = 24,
            title: str = "") -> Path:
    """Write a GIF of the linkage turning one revolution with its total centre of mass traced.

    Frames are equally spaced crank angles (the crank at constant speed). The still parts are
    drawn once and each frame only blits the moving artists onto them (matplotlib's animation
    machinery would redraw the whole figure three times a frame); Pillow writes the GIF.
    Written whole or not at all.
    """
    from matplotlib.backends.backend_agg import FigureCanvasAgg
    from PIL import Image

    links, coms, total = drawing_frames(linkage, frames)
    pivots, guides = frame(linkage)
    fig = Figure(figsize=(6, 4.5), dpi=100, layout="constrained")
    canvas = FigureCanvasAgg(fig)
    ax = fig.add_subplot()
    everything = np.concatenate([*(v.ravel() for v in links.values()), coms.ravel(), total,
                                 pivots, *guides])
    everything = everything[np.isfinite(everything)]
    extent = max(np.ptp(everything.real), np.ptp(everything.imag), 1e-300)
    pad = 0.08 * extent
    ax.set_xlim(everything.real.min() - pad, everything.real.max() + pad)
    ax.set_ylim(everything.imag.min() - pad, everything.imag.max() + pad)
    ax.set_aspect("equal")
    ax.set_xlabel("x (m)")
    ax.set_ylabel("y (m)")
    ax.set_title(title or "linkage over one crank revolution")
    ax.grid(alpha=0.3)
    ax.plot(total.real, total.imag, color=COLOURS["before"], lw=1, ls=":",
            label="path of the total centre of mass")
    _draw_frame(ax, linkage, label=None)
    bars = []
    for i, name in enumerate(links):
        (bar,) = ax.plot([], [], "-o", color=COLOURS["link"], lw=3, ms=5, animated=True,
                         label="links" if i == 0 else None)
        bars.append((bar, links[name]))
    (link_coms,) = ax.plot([], [], "s", color=COLOURS["com"], ms=5,
                           label="link centres of mass", animated=True)
    (trace,) = ax.plot([], [], color=COLOURS["after"], lw=2, animated=True)
    (com,) = ax.plot([], [], "o", color=COLOURS["after"], ms=9, label="total centre of mass",
                     animated=True)
    ax.legend(fontsize="small", loc="upper right")
    canvas.draw()
    fig.set_layout_engine("none")
    background = canvas.copy_from_bbox(fig.bbox)
    images = []
    for k in range(frames):
        canvas.restore_region(background)
        for bar, values in bars:
            bar.set_data(values[k].real, values[k].imag)
        link_coms.set_data(coms[k].real, coms[k].imag)
        trace.set_data(total[: k + 1].real, total[: k + 1].imag)
        com.set_data([total[k].real], [total[k].imag])
        for artist in (trace, *(bar for bar, _ in bars), link_coms, com):
            ax.draw_artist(artist)
        rgba = np.asarray(canvas.buffer_rgba())
        images.append(Image.fromarray(rgba[..., :3].copy()).quantize(colors=64))
    return write_with(path, lambda tmp: images[0].save(
        tmp, format="GIF", save_all=True, append_images=images[1:],
        duration=round(1000 / fps), loop=0), suffix=".gif")
