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

from . import mechanisms
from .errors import OutputError
from .mechanisms import drawing_frames
from .model import FourBar
from .outputs import write_with
from .simulate import Trajectory

#: Colours for A0, A3 and their sum (colour-blind safe).
COLOURS = {"A0": "#0072B2", "A3": "#D55E00", "sum": "#000000", "before": "#999999",
           "after": "#009E73"}


def _axes(ax: Axes | None) -> Axes:
    if ax is not None:
        return ax
    return Figure(figsize=(7, 4), layout="constrained").add_subplot()


def plot_reactions(traj: Trajectory, ax: Axes | None = None, title: str = "") -> Axes:
    """Components of R̄A0, R̄A3 and of their sum over time (as the paper's Fig. 8 and 9)."""
    ax = _axes(ax)
    t = traj.t
    ax.plot(t, traj.RA0.real, color=COLOURS["A0"], lw=1.2, label="$R_{A0x}$")
    ax.plot(t, traj.RA0.imag, color=COLOURS["A0"], lw=1.2, ls="--", label="$R_{A0y}$")
    ax.plot(t, traj.RA3.real, color=COLOURS["A3"], lw=1.2, label="$R_{A3x}$")
    ax.plot(t, traj.RA3.imag, color=COLOURS["A3"], lw=1.2, ls="--", label="$R_{A3y}$")
    total = traj.shaking_force
    ax.plot(t, total.real, color=COLOURS["sum"], lw=1.8, label="$R_{A0x}+R_{A3x}$")
    ax.plot(t, total.imag, color=COLOURS["sum"], lw=1.8, ls="--", label="$R_{A0y}+R_{A3y}$")
    ax.set_xlabel("time t (s)")
    ax.set_ylabel("force on the ground (N)")
    ax.set_title(title or f"reactions, {traj.drive} motion")
    ax.grid(alpha=0.3)
    ax.legend(fontsize="small", ncol=3, loc="upper right")
    return ax


def plot_shaking_moment(
    traj: Trajectory, original: Trajectory | None = None, ax: Axes | None = None,
    title: str = "",
) -> Axes:
    """Shaking moment about A0 over time, before (the original) and after."""
    ax = _axes(ax)
    if original is not None:
        ax.plot(original.t, original.shaking_moment, color=COLOURS["before"], lw=1.5,
                label="before (original)")
    ax.plot(traj.t, traj.shaking_moment, color=COLOURS["after"], lw=1.5,
            label="after" if original is not None else "shaking moment")
    ax.set_xlabel("time t (s)")
    ax.set_ylabel("shaking moment about A0 (N·m)")
    ax.set_title(title or f"shaking moment, {traj.drive} motion")
    ax.grid(alpha=0.3)
    ax.legend(fontsize="small")
    return ax


def centre_of_mass_path(linkage, traj: Trajectory) -> np.ndarray:
    """Total centre of mass along a simulated motion, complex, m."""
    return mechanisms.centre_of_mass_path(linkage, traj.theta, tuple(traj.omega),
                                          tuple(traj.alpha))


def plot_com_path(
    linkage: FourBar, traj: Trajectory, original: FourBar | None = None,
    original_traj: Trajectory | None = None, ax: Axes | None = None,
) -> Axes:
    """Path of the total centre of mass, with the ground pivots (a point when balanced)."""
    ax = _axes(ax)
    if original is not None and original_traj is not None:
        path = centre_of_mass_path(original, original_traj)
        ax.plot(path.real, path.imag, color=COLOURS["before"], lw=1.5, label="before (original)")
    path = centre_of_mass_path(linkage, traj)
    label = "after" if original is not None else "total centre of mass"
    if np.ptp(path.real) + np.ptp(path.imag) < 1e-9 * max(linkage.lengths):
        ax.plot(path.real[:1], path.imag[:1], "o", color=COLOURS["after"],
                label=f"{label}: stationary")
    else:
        ax.plot(path.real, path.imag, color=COLOURS["after"], lw=1.5, label=label)
    from .mechanisms import frame_points

    ground = np.array(frame_points(linkage))
    ax.plot(ground.real, ground.imag, "k^", ms=8, label="frame (pivots, guide)")
    ax.set_aspect("equal", adjustable="datalim")
    ax.set_xlabel("x (m)")
    ax.set_ylabel("y (m)")
    ax.set_title("path of the total centre of mass")
    ax.grid(alpha=0.3)
    ax.legend(fontsize="small")
    return ax


def verification_figure(design, verification) -> Figure:
    """The report figure of ``balancer verify``.

    Columns: the crank driven at the operating speed, free motion; rows: reactions at A0 and A3
    and their sum, shaking moment before and after, path of the total centre of mass.
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
        plot_reactions(run.trajectory, ax=axes[0, col], title=f"reactions, {label}")
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


def animate(linkage: FourBar, path: str | os.PathLike[str], *, frames: int = 72, fps: int = 24,
            title: str = "") -> Path:
    """Write a GIF of the linkage turning one revolution with its total centre of mass traced.

    Frames are equally spaced crank angles (the crank at constant speed). The still parts are
    drawn once and each frame only blits the moving artists onto them (matplotlib's animation
    machinery would redraw the whole figure three times a frame); Pillow writes the GIF.
    Written whole or not at all.
    """
    from matplotlib.backends.backend_agg import FigureCanvasAgg
    from PIL import Image

    joints, coms, total = drawing_frames(linkage, frames)
    fig = Figure(figsize=(6, 4.5), dpi=100, layout="constrained")
    canvas = FigureCanvasAgg(fig)
    ax = fig.add_subplot()
    everything = np.concatenate([joints.ravel(), coms.ravel(), total])
    pad = 0.08 * max(linkage.lengths)
    ax.set_xlim(everything.real.min() - pad, everything.real.max() + pad)
    ax.set_ylim(everything.imag.min() - pad, everything.imag.max() + pad)
    ax.set_aspect("equal")
    ax.set_xlabel("x (m)")
    ax.set_ylabel("y (m)")
    ax.set_title(title or "linkage over one crank revolution")
    ax.grid(alpha=0.3)
    ax.plot(total.real, total.imag, color=COLOURS["before"], lw=1, ls=":",
            label="path of the total centre of mass")
    from .mechanisms import frame_points

    ground = np.array(frame_points(linkage))
    ax.plot(ground.real[:2], ground.imag[:2], "k^", ms=10, zorder=5)
    if linkage.type == "slider-crank":
        ax.plot(ground.real[1:], ground.imag[1:], "k-", lw=6, alpha=0.25, zorder=1)
    (bars,) = ax.plot([], [], "-o", color=COLOURS["A0"], lw=3, ms=6, label="links",
                      animated=True)
    (link_coms,) = ax.plot([], [], "s", color=COLOURS["A3"], ms=5,
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
        bars.set_data(joints[k].real, joints[k].imag)
        link_coms.set_data(coms[k].real, coms[k].imag)
        trace.set_data(total[: k + 1].real, total[: k + 1].imag)
        com.set_data([total[k].real], [total[k].imag])
        for artist in (trace, bars, link_coms, com):
            ax.draw_artist(artist)
        rgba = np.asarray(canvas.buffer_rgba())
        images.append(Image.fromarray(rgba[..., :3].copy()).quantize(colors=64))
    return write_with(path, lambda tmp: images[0].save(
        tmp, format="GIF", save_all=True, append_images=images[1:],
        duration=round(1000 / fps), loop=0), suffix=".gif")
