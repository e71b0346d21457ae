"""An animation of the mechanism turning one revolution, or along a motion (GIF, or MP4).

An MP4 needs ffmpeg; a motion is of the inputs of a linkage with several.
"""

from __future__ import annotations

import os
from collections.abc import Callable, Mapping
from pathlib import Path
from typing import TYPE_CHECKING

import numpy as np
from numpy.typing import NDArray

from .. import outputs
from ..balance.counterweights import counterweights as link_counterweights
from ..cycle import sample_angles
from ..errors import OutputError, SpecError
from ..linkage import trajectory
from ..linkage.inputs import InputState
from ..mechanisms import mechanism_of
from ..mechanisms.base import Mechanism
from ..model import Design
from ..model import MechanismModel as Model
from ..model.motions import MotionSpec
from ..outputs import animation_type, write_with
from .drawing import (
    CounterweightLike,
    counterweight_paths,
    drawing_frames,
    drawn_mass_sectors,
    frame,
    pitch_circles,
    revolution,
    slider_block_outlines,
)
from .style import COLOURS, draw_frame

if TYPE_CHECKING:  # annotations only: matplotlib is imported by the functions that draw
    from matplotlib.artist import Artist
    from matplotlib.figure import Figure
    from matplotlib.lines import Line2D
    from matplotlib.patches import Circle, Polygon, Wedge

#: What :func:`animate` and :func:`animation_figure` take, as their refusal names it.
ACCEPTED = ("a Design (balancer.load_design, balancer.example), a mechanism model (a FourBar, "
            "SliderCrank, Linkage or Engine: a Design's .mechanism) or a Mechanism")

#: Half the angle of a sector that shows a shaft's counterweight or eccentric, degrees.
SECTOR_HALF_ANGLE = 60.0


def _arm(points: np.ndarray, target: np.ndarray) -> np.ndarray:
    """``(frames, 2)``: from the link's point nearest ``target`` (at the first frame) to it.

    ``points`` ``(frames, k)`` a link's points, ``target`` ``(frames,)`` a point it carries:
    the pair moves rigidly with the link.
    """
    near = int(np.argmin(np.abs(points[0] - target[0])))
    return np.column_stack([points[:, near], target])


def _drawn(design: Design | Model | Mechanism, title: str,
           counterweights: Mapping[str, CounterweightLike] | None
           ) -> tuple[Model | Mechanism, str, Mapping[str, CounterweightLike]]:
    """What an animation draws of what it is given: the mechanism, its title, the bodies added.

    A :class:`~balancer.model.Design` gives its mechanism, its title (where ``title`` is
    empty) and, where it names its original, the counterweights added to the original's links
    (where ``counterweights`` is ``None``; an engine's are masses on its shafts, which its
    mechanism draws).

    Raises
    ------
    SpecError
        For anything else than :data:`ACCEPTED`, naming what is accepted.
    """
    if isinstance(design, Design):
        weights = counterweights
        if (weights is None and design.original is not None
                and not mechanism_of(design.mechanism).presentation.balanced_on_shafts):
            weights = link_counterweights(design.original, design.mechanism)
        return design.mechanism, title or design.title, weights or {}
    if not isinstance(design, Model | Mechanism):
        raise SpecError(f"must be {ACCEPTED}", key="design", value=type(design).__name__)
    return design, title, counterweights or {}


def _frames_of(linkage: Model | Mechanism, frames: int, motion: MotionSpec | None
               ) -> tuple[InputState, list[str]]:
    """The frames' input states and their readouts.

    A revolution's crank angles, or a motion's equally spaced times (its inputs' states there).
    """
    if motion is None:
        return revolution(frames), [f"crank angle θ1 = {d:5.1f}°"
                                    for d in np.degrees(sample_angles(frames))]
    times = np.linspace(motion.start, motion.end, frames)
    states = trajectory.input_state(mechanism_of(linkage).structure, motion, times)
    return states, [f"{motion.name}: t = {t:.3g} s" for t in times]


def animation_figure(design: Design | Model | Mechanism, *, frames: int = 72,
                     title: str = "",
                     counterweights: Mapping[str, CounterweightLike] | None = None,
                     motion: MotionSpec | str | None = None
                     ) -> tuple[Figure, Callable[[int], list[Artist]]]:
    """The figure of an animation of one revolution, and what changes from frame to frame.

    Along a ``motion`` instead (a :class:`~balancer.model.motions.MotionSpec`, or a name of
    the design's ``[[motion]]``; a linkage with several inputs runs along its first without
    it): the frames at equally spaced times, the readout the time.

    ``design`` a :class:`~balancer.model.Design` (its mechanism, its title where ``title`` is
    empty, and for a balanced spec that names its original the counterweights added to its
    links), a mechanism's model or a :class:`~balancer.mechanisms.base.Mechanism`.

    Drawn once: the frame (pivots, guides), the path of the total centre of mass, the title
    (wrapped to the figure's width, above the axes), the legend. Per frame, at the crank angle
    θ1 = 360°·k/``frames``: the links; each sliding block as a rectangle along its slider (an
    engine's pistons as wide as their bore, or their stroke where the spec gives no bore, and
    0.7 of it long; a slider-crank's slider as a piston as wide as the stroke; other blocks
    0.6 × 0.35 of the crank's reach); each link's centre of mass on a thin arm from the
    link's nearest point (it turns with its link, wherever the balancing put it); the
    counterweights added to the original links (``counterweights``, per link as
    :func:`balancer.balance.counterweights.counterweights` gives them; ``kind`` ``"add"``) as
    their steel discs (a diamond for a point mass) on arms from their links; an engine's
    crankshaft counterweights (its masses labelled ``counterweight``) and balance shafts'
    eccentrics as sectors on their axes, turning with their shafts (sectors of one thickness:
    radius as the cube root of their mass·radius, the largest the crank's reach); the total
    centre of mass with its path so far; and the crank angle's readout. Links that no single
    added body makes (``rebuild``, ``remove``) are named in the legend.

    Returns
    -------
    tuple
        ``(fig, update)``: the :class:`~matplotlib.figure.Figure` (its moving artists marked
        animated, so a plain draw leaves them out) and ``update(k)``, which sets frame ``k``'s
        moving artists and returns them, to be drawn over the still picture.

    Raises
    ------
    SpecError
        If ``design`` is none of those (the message names what is accepted).
    """
    import textwrap

    from matplotlib.figure import Figure
    from matplotlib.lines import Line2D
    from matplotlib.patches import Circle, Polygon, Wedge

    spec = _motion_of(design, motion)
    linkage, title, weights = _drawn(design, title, counterweights)
    states, readouts = _frames_of(linkage, frames, spec)
    links, coms, total = drawing_frames(linkage, states)
    pivots, guides = frame(linkage, states=None if spec is None else states)
    discs = counterweight_paths(linkage, weights, states)
    blocks = slider_block_outlines(linkage, states)
    sectors = drawn_mass_sectors(linkage, states)
    fig = Figure(figsize=(6, 4.5), dpi=100, layout="constrained")
    ax = fig.add_subplot()
    rims = [c + r * s for c, r in discs.values() for s in (1, -1, 1j, -1j)]
    rims += [np.array([c + r * s for s in (1, -1, 1j, -1j)]) for c, r in pitch_circles(linkage)]
    rims += [m.axis + r * np.exp(1j * (angles + a))
             for m, angles, r in sectors for a in np.radians((-SECTOR_HALF_ANGLE, 0.0,
                                                               SECTOR_HALF_ANGLE))]
    everything = np.concatenate([*(v.ravel() for v in links.values()), *coms.values(), total,
                                 pivots, *guides, *rims, *(v.ravel() for v in blocks.values())])
    everything = everything[np.isfinite(everything)]
    extent = max(np.ptp(everything.real), np.ptp(everything.imag), 1e-300)
    pad = 0.08 * extent
    ax.set_xlim(everything.real.min() - pad, everything.real.max() + pad)
    ax.set_ylim(everything.imag.min() - pad, everything.imag.max() + pad)
    ax.set_aspect("equal")
    ax.set_xlabel("x (m)")
    ax.set_ylabel("y (m)")
    # The title above the whole figure (wrapped to its width): an axes' title wider than the
    # axes pushes the constrained layout's axes off the figure's edge, the y label clipped.
    fig.suptitle(title or ("linkage over one crank revolution" if spec is None
                           else f"linkage along its motion {spec.name}"), wrap=True)
    ax.grid(alpha=0.3)
    ax.plot(total.real, total.imag, color=COLOURS["before"], lw=1, ls=":",
            label="path of the total centre of mass")
    draw_frame(ax, linkage, label=None, states=None if spec is None else states)
    lines: list[tuple[Line2D, NDArray[np.complex128]]] = []  # (artist, (frames, n) joined)
    for name, points in links.items():
        (arm,) = ax.plot([], [], "-", color=COLOURS["com"], lw=1.0, animated=True, zorder=1.5)
        lines.append((arm, _arm(points, coms[name])))
    for i, points in enumerate(v for name, v in links.items() if name not in blocks):
        (bar,) = ax.plot([], [], "-o", color=COLOURS["link"], lw=3, ms=5, animated=True,
                         label="links" if i == 0 else None)
        lines.append((bar, points))
    outlines: list[tuple[Polygon, NDArray[np.complex128]]] = []
    block_name = mechanism_of(linkage).presentation.block_name
    for i, outline in enumerate(blocks.values()):
        block = Polygon(np.column_stack([outline[0].real, outline[0].imag]), closed=True,
                        fc=COLOURS["link"], ec="k", lw=0.8, alpha=0.55, animated=True,
                        zorder=1.8, label=block_name if i == 0 else None)
        ax.add_patch(block)
        outlines.append((block, outline))
    wedges: list[tuple[Wedge, NDArray[np.float64]]] = []
    for i, (mass, angles, radius) in enumerate(sectors):
        first = not any(m.what == mass.what for m, _, _ in sectors[:i])
        wedge = Wedge((mass.axis.real, mass.axis.imag), radius, 0.0, 1.0,
                      fc="0.35" if mass.what == "counterweight" else COLOURS["eccentric"],
                      ec="k", lw=0.5, alpha=0.5, animated=True, zorder=1.6,
                      label={"counterweight": "crankshaft counterweights",
                             "eccentric": "balance shafts' eccentrics"}[mass.what]
                      if first else None)
        ax.add_patch(wedge)
        wedges.append((wedge, np.degrees(angles)))
    for name, (centres, _) in discs.items():
        (arm,) = ax.plot([], [], "-", color="0.35", lw=2, animated=True)
        lines.append((arm, _arm(links[name], centres)))
    bodies: list[tuple[Circle | Line2D, NDArray[np.complex128], float]] = []
    for i, (centres, radius) in enumerate(discs.values()):
        body: Circle | Line2D
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
    link_com_values = np.column_stack(list(coms.values()))

    def update(k: int) -> list[Artist]:
        for line, values in lines:
            line.set_data(values[k].real, values[k].imag)
        for block, outline in outlines:
            block.set_xy(np.column_stack([outline[k].real, outline[k].imag]))
        for wedge, degrees_of in wedges:
            wedge.set_theta1(degrees_of[k] - SECTOR_HALF_ANGLE)
            wedge.set_theta2(degrees_of[k] + SECTOR_HALF_ANGLE)
        for body, centres, _ in bodies:
            if isinstance(body, Circle):  # (a disc: its radius is positive)
                body.set_center((centres[k].real, centres[k].imag))
            else:
                body.set_data([centres[k].real], [centres[k].imag])
        link_coms.set_data(link_com_values[k].real, link_com_values[k].imag)
        trace.set_data(total[: k + 1].real, total[: k + 1].imag)
        com.set_data([total[k].real], [total[k].imag])
        angle.set_text(readouts[k])
        return [trace, *(w for w, _ in wedges), *(b for b, _ in outlines),
                *(line for line, _ in lines), *(b for b, _, _ in bodies), link_coms, com, angle]

    return fig, update


def _motion_of(design: Design | Model | Mechanism, motion: MotionSpec | str | None
               ) -> MotionSpec | None:
    """The motion an animation runs along, or ``None`` (a revolution).

    ``motion`` itself, the design's motion of that name, or a several-input design's first.

    Raises
    ------
    SpecError
        For a name without a design, or a design without such a motion.
    """
    if isinstance(motion, MotionSpec):
        return motion
    if isinstance(design, Design):
        several = len(mechanism_of(design.mechanism).linkage.inputs) > 1
        return design.motion(motion) if motion is not None or several else None
    if motion is not None:
        raise SpecError("names a motion of a design: give the Design, or the MotionSpec",
                        key="motion", value=motion)
    return None


def animate(design: Design | Model | Mechanism, path: str | os.PathLike[str], *,
            frames: int = 72, fps: int = 24, title: str = "",
            counterweights: Mapping[str, CounterweightLike] | None = None,
            motion: MotionSpec | str | None = None) -> Path:
    """Write an animation of the mechanism turning one revolution, its centre of mass traced.

    Along a ``motion`` of its inputs instead (:func:`animation_figure`): a linkage with
    several inputs runs along its first without one.

    ``design`` a :class:`~balancer.model.Design` (as every other call takes: its title where
    ``title`` is empty, and for a balanced spec the bodies added to its original's links), a
    mechanism's model (a FourBar, SliderCrank, Linkage or Engine) or a
    :class:`~balancer.mechanisms.base.Mechanism`. What it draws: :func:`animation_figure`
    (``counterweights`` per link, as :attr:`BalanceResult.counterweights` gives them: the
    bodies added to the original links are drawn as their steel discs, turning with their
    links; an engine's counterweights and eccentrics as sectors on their shafts).

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
    SpecError
        If ``design`` is none of those (the message names what is accepted).
    """
    from matplotlib.backends.backend_agg import FigureCanvasAgg

    kind = animation_type(path)
    fig, update = animation_figure(design, frames=frames, title=title,
                                   counterweights=counterweights, motion=motion)
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

    exe = outputs.ffmpeg()
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
