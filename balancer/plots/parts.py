"""A dimensioned drawing of a link with its counterweight as a part, in the link's frame (mm).

The link's points and the lines between them, the part's profile filled, its dimensions (radii,
angle, length and width, thickness, bore), and three centres: the original link's, the part's
and the balanced link's. Computes nothing: the part is given
(:class:`balancer.parts.made.LinkPart`). An engine's crank-web sector
(:class:`balancer.parts.planes.PlanePart`) is drawn on the crankshaft at θ1 = 0: its axis, the
nearest throws' pins, the sector and the direction the optimiser chose (:func:`web_figure`).
"""

from __future__ import annotations

import cmath
import math
from pathlib import Path

import numpy as np
from matplotlib.figure import Figure

from ..parts.made import LinkPart
from ..parts.planes import PlanePart
from ..parts.shapes import AnnularSector, Annulus, Line, Loop, Rectangle
from ..report.parts import dimensions_text
from .style import write_figure

#: The drawing's files, by extension.
DRAWING_TYPES = (".svg", ".png")


def _outline(loop: Loop) -> np.ndarray:
    """A loop's points, mm (arcs at one point a degree)."""
    out: list[complex] = []
    for edge in loop:
        if isinstance(edge, Line):
            out.append(edge.start)
        else:
            n = max(int(abs(math.degrees(edge.end - edge.start))), 8)
            out += [edge.point(a) for a in np.linspace(edge.start, edge.end, n + 1)[:-1]]
    out.append(out[0])
    return 1e3 * np.asarray(out)


def _dimension(ax: object, a: complex, b: complex, text: str) -> None:
    """A dimension line with arrows from ``a`` to ``b`` (mm) and its text at its middle."""
    ax.annotate("", xy=(b.real, b.imag), xytext=(a.real, a.imag),  # type: ignore[attr-defined]
                arrowprops={"arrowstyle": "<->", "lw": 0.8, "color": "0.2",
                            "shrinkA": 0, "shrinkB": 0})
    m = (a + b) / 2
    ax.annotate(text, xy=(m.real, m.imag), fontsize="small",  # type: ignore[attr-defined]
                ha="center", va="bottom", color="0.1",
                bbox={"boxstyle": "round,pad=0.15", "fc": "white", "ec": "none", "alpha": 0.8})


def part_figure(part: LinkPart) -> Figure:
    """The drawing of one link and its part (:mod:`module docstring <balancer.plots.parts>`)."""
    fig = Figure(figsize=(7.5, 6.0))
    ax = fig.add_subplot()
    pts = 1e3 * np.array([p for _, p in part.points])
    if len(pts) > 1:
        ax.plot(np.append(pts.real, pts[0].real) if len(pts) > 2 else pts.real,
                np.append(pts.imag, pts[0].imag) if len(pts) > 2 else pts.imag,
                color="0.45", lw=3, solid_capstyle="round", label=f"{part.link}", zorder=1)
    for name, p in part.points:
        ax.plot(1e3 * p.real, 1e3 * p.imag, "o", ms=8, mfc="white", mec="0.2", zorder=3)
        ax.annotate(name, (1e3 * p.real, 1e3 * p.imag), xytext=(6, 6),
                    textcoords="offset points", fontsize="small")
    profile = part.sized.profile
    if profile is not None:
        loops = [_outline(loop) for loop in profile.loops()]
        path = np.concatenate([np.append(x, np.nan) for x in loops])
        ax.fill(loops[0].real, loops[0].imag, color="tab:orange", alpha=0.55, zorder=2,
                label=f"{part.sized.room.shape}: {dimensions_text(part)}")
        for hole in loops[1:]:
            ax.fill(hole.real, hole.imag, color="white", zorder=2)
        ax.plot(path.real, path.imag, color="tab:orange", lw=1.2, zorder=2)
        _dimensions(ax, profile)
    for props, marker, label in (
            (part.original, "x", "original centre of mass"),
            (part.sized.made, "+", "part's centre"),
            (part.balanced, "*", "balanced centre of mass")):
        if props is not None:
            c = 1e3 * props.centre
            ax.plot(c.real, c.imag, marker, ms=10, mew=1.5, zorder=4, label=label)
    made = part.sized.made
    state = ("exact" if part.sized.exact else "nearest in its room") if made else "not made"
    mass = f", {made.mass:.4g} kg" if made else ""
    ax.set_title(f"{part.link}: {part.sized.room.shape} of "
                 f"{part.sized.room.material.name}{mass} ({state})", fontsize="medium")
    ax.set_xlabel("x along the link (mm)")
    ax.set_ylabel("y across the link (mm)")
    ax.set_aspect("equal", adjustable="datalim")
    ax.grid(True, lw=0.3, alpha=0.5)
    ax.legend(fontsize="small", loc="best")
    return fig


def _dimensions(ax: object, profile: Annulus | AnnularSector | Rectangle) -> None:
    """The profile's dimension lines."""
    t = f"t {1e3 * profile.thickness:.4g}"
    if isinstance(profile, Annulus):
        c = 1e3 * profile.centre
        r = 1e3 * profile.outer
        _dimension(ax, c - r, c + r, f"Ø {2 * r:.4g}, {t}")
        if profile.inner:
            ri = 1e3 * profile.inner
            _dimension(ax, c - 1j * ri, c + 1j * ri, f"Ø {2 * ri:.4g}")
    elif isinstance(profile, AnnularSector):
        p = 1e3 * profile.pivot
        u = cmath.rect(1.0, profile.direction)
        ro, ri = 1e3 * profile.outer, 1e3 * profile.inner
        _dimension(ax, p, p + ro * u, f"R {ro:.4g}")
        if ri:
            v = cmath.rect(1.0, profile.direction + profile.angle / 4)
            _dimension(ax, p, p + ri * v, f"R {ri:.4g}")
        a = np.linspace(profile.direction - profile.angle / 2,
                        profile.direction + profile.angle / 2, 60)
        arc = p + 1.08 * ro * np.exp(1j * a)
        ax.plot(arc.real, arc.imag, color="0.2", lw=0.8)  # type: ignore[attr-defined]
        mid = p + 1.12 * ro * u
        ax.annotate(f"{math.degrees(profile.angle):.4g}°, {t}",  # type: ignore[attr-defined]
                    (mid.real, mid.imag), fontsize="small", ha="center")
    else:
        q = [1e3 * c for c in profile.corners()]
        _dimension(ax, q[0] - 0.15 * (q[3] - q[0]), q[1] - 0.15 * (q[2] - q[1]),
                   f"{1e3 * profile.length:.4g}")
        _dimension(ax, q[1] + 0.1 * (q[1] - q[0]), q[2] + 0.1 * (q[1] - q[0]),
                   f"{1e3 * profile.width:.4g}, {t}")


def web_figure(part: PlanePart) -> Figure:
    """The drawing of one plane's crank-web sector on the crankshaft at θ1 = 0 (mm).

    The crank's axis O and the nearest throws' pins, the sector filled and dimensioned, its
    centre, and the direction the optimiser chose.
    """
    fig = Figure(figsize=(7.5, 6.0))
    ax = fig.add_subplot()
    for name, p in part.points:
        ax.plot(1e3 * p.real, 1e3 * p.imag, "o", ms=8, mfc="white", mec="0.2", zorder=3)
        ax.annotate(name, (1e3 * p.real, 1e3 * p.imag), xytext=(6, 6),
                    textcoords="offset points", fontsize="small")
        if abs(p) > 0:
            ax.plot([0.0, 1e3 * p.real], [0.0, 1e3 * p.imag], color="0.45", lw=3,
                    solid_capstyle="round", zorder=1)
    profile = part.sized.profile
    if profile is not None:
        loops = [_outline(loop) for loop in profile.loops()]
        path = np.concatenate([np.append(x, np.nan) for x in loops])
        ax.fill(loops[0].real, loops[0].imag, color="tab:orange", alpha=0.55, zorder=2,
                label=f"sector: {dimensions_text(part)}")
        for hole in loops[1:]:
            ax.fill(hole.real, hole.imag, color="white", zorder=2)
        ax.plot(path.real, path.imag, color="tab:orange", lw=1.2, zorder=2)
        _dimensions(ax, profile)
    made = part.sized.made
    if made is not None:
        c = 1e3 * made.centre
        ax.plot(c.real, c.imag, "+", ms=10, mew=1.5, zorder=4, label="part's centre")
    reach = 1e3 * (profile.outer if isinstance(profile, AnnularSector | Annulus)
                   else abs(part.points[-1][1]))
    u = cmath.rect(reach, math.radians(part.placed.phase_deg))
    ax.plot([0.0, u.real], [0.0, u.imag], ls="--", color="0.3", lw=0.8, zorder=1,
            label=f"asked: {part.placed.mr:.4g} kg·m at {part.placed.phase_deg:.4g}°")
    state = ("exact" if part.sized.exact else "nearest in its room") if made else "not made"
    mass = f", {made.mass:.4g} kg" if made else ""
    ax.set_title(f"{part.name}: sector of {part.sized.room.material.name}{mass} ({state})",
                 fontsize="medium")
    ax.set_xlabel("x at θ1 = 0 (mm)")
    ax.set_ylabel("y at θ1 = 0 (mm)")
    ax.set_aspect("equal", adjustable="datalim")
    ax.grid(True, lw=0.3, alpha=0.5)
    ax.legend(fontsize="small", loc="best")
    return fig


def write_part_drawing(part: LinkPart | PlanePart, stem: Path) -> list[Path]:
    """Write the drawing at ``stem`` as SVG and PNG (:data:`DRAWING_TYPES`); the paths."""
    fig = web_figure(part) if isinstance(part, PlanePart) else part_figure(part)
    out = []
    for suffix in DRAWING_TYPES:
        path = stem.with_name(stem.name + suffix)  # (a name with a dot keeps it)
        write_figure(fig, path, 150 if suffix == ".png" else None, suffix[1:])
        out.append(path)
    return out
