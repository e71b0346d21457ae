"""A sweep's atlas (the balanced shaking over the varied keys) and a tolerance histogram."""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from typing import TYPE_CHECKING, Any, Protocol

import numpy as np

from ..rounding import RPM
from .style import ORIGINAL_STYLE, legend_outside, mark_point, number

if TYPE_CHECKING:  # annotations only: matplotlib is imported by the functions that draw
    from matplotlib.artist import Artist
    from matplotlib.axes import Axes
    from matplotlib.collections import PathCollection, QuadMesh
    from matplotlib.figure import Figure


class PerturbLike(Protocol):
    """A perturbed key of a sweep (:class:`balancer.sweeps.Perturb`, a layer above)."""

    @property
    def key(self) -> str:
        """The spec key drawn."""
    @property
    def sigma(self) -> float:
        """The standard deviation of its normal draws, in its unit."""




def _key_label(key: str, units: dict[str, str]) -> str:
    """A spec key as an axis label, with its unit (``units``, by key; none if not given)."""
    unit = units.get(key, "")
    return f"{key} ({unit})" if unit else key


def _key_value(key: str, value: float, units: dict[str, str]) -> str:
    """``key = value unit``, the value to 4 significant digits (a speed's in rpm beside it)."""
    text = f"{key} = {value:.4g} {units.get(key, '')}".rstrip()
    return f"{text} ({value * RPM:.4g} rpm)" if units.get(key) == "rad/s" else text


def _rpm_axis(ax: Axes, key: str, units: dict[str, str], which: str) -> None:
    """Beside an axis of a speed (a key in rad/s), a second scale in rpm (top or right)."""
    if units.get(key) != "rad/s":
        return
    functions = (lambda w: w * RPM, lambda n: n / RPM)
    if which == "x":
        ax.secondary_xaxis("top", functions=functions).set_xlabel(f"{key} (rpm)")
    else:
        ax.secondary_yaxis("right", functions=functions).set_ylabel(f"{key} (rpm)")


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


#: The figure an atlas shows, by its column's stem in the sweep's table: its words.
HEADLINES = {"shaking_moment": "RMS shaking moment", "rocking_couple": "RMS rocking couple"}


def _no_design(status: str) -> dict[str, str]:
    """:data:`NO_DESIGN`'s entry for ``status`` (a generic one for any other status)."""
    return NO_DESIGN.get(status, {"label": f"no design ({status})", "facecolor": "white",
                                  "hatch": "--", "edgecolor": "0.5", "marker": "o"})


def sweep_figure(table: Mapping[str, Sequence[Any]], keys: Sequence[str] | None, *,
                 original: dict[str, float] | None = None,
                 perturbs: Sequence[PerturbLike] = (),
                 units: dict[str, str] | None = None,
                 headline: str = "shaking_moment") -> Figure:
    """The atlas of a sweep's table: the balanced RMS shaking moment over the varied keys.

    Parameters
    ----------
    table
        The sweep's table by column (:meth:`balancer.sweeps.SweepResult.table`).
    keys
        The varied keys, in the table's order; ``None`` for a perturbation sweep.
    original
        The spec's own value of each key (its unit's): the original design, marked.
    perturbs
        A perturbation sweep's :class:`~balancer.sweeps.Perturb` (``key``, ``sigma``): named
        in its histogram's title.
    units
        Each key's unit (:func:`balancer.sweeps.key_unit`), for the axes and titles.
    headline
        The figure shown (a key of :data:`HEADLINES`): the RMS shaking moment, or an engine's
        RMS rocking couple; its ``_before`` and ``_after`` columns.

    Returns
    -------
    Figure
        ``keys`` ``None``: the histogram of the perturbed designs' RMS shaking force (N). Two
        keys on a grid: a heat map; the cells without a balanced design hatched, their legend
        telling infeasible from bad geometry (and a failed solver). One key: the RMS shaking
        moment before and after against it, the points without a design marked along the
        bottom. Otherwise a scatter over the first two keys coloured by the balanced RMS
        shaking moment, the points without a design as markers. Axes in the keys' units; the
        original design a white star (a line for one key), or an arrow at the edge where it
        lies outside the swept ranges.
    """
    from matplotlib.figure import Figure

    units = units or {}
    if keys is None:
        return _perturbation_figure(table, perturbs, original or {}, units)
    words = HEADLINES[headline]
    after = np.array([np.nan if v is None else v for v in table[f"{headline}_after"]])
    status = np.array(table["status"], dtype=object)
    fig = Figure(figsize=(7.5, 5.0), layout="constrained")
    ax = fig.add_subplot()
    if len(keys) == 1:
        before = np.array([np.nan if v is None else v for v in table[f"{headline}_before"]])
        _atlas_line(ax, np.array(table[keys[0]], float), keys[0], before, after, status,
                    original, units, words)
    else:
        _atlas_map(fig, ax, [np.array(table[k], float) for k in keys[:2]], keys[:2], after,
                   status, original, units, words)
    return fig


def _no_design_masks(after: np.ndarray, status: np.ndarray) -> dict[str, np.ndarray]:
    """The points without a balanced design, by status (in :data:`NO_DESIGN`'s order)."""
    missing = ~np.isfinite(after)
    order = [*NO_DESIGN, *sorted(set(status[missing]) - set(NO_DESIGN))]
    return {s: missing & (status == s) for s in order if np.any(missing & (status == s))}


def _atlas_line(ax: Axes, x: np.ndarray, key: str, before: np.ndarray, after: np.ndarray,
                status: np.ndarray, original: dict[str, float] | None,
                units: dict[str, str], words: str) -> None:
    """One varied key: the RMS shaking moment (``words``) before and after balancing."""
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
                       label=f"original design: {_key_value(key, value, units)}")
            ax.set_xlim(xlim)
        else:
            ylim = ax.get_ylim()
            mark_point(ax, value, 0.5 * (ylim[0] + ylim[1]), "original design",
                        _key_value(key, value, units), **ORIGINAL_STYLE)
    ax.set_xlabel(_key_label(key, units))
    _rpm_axis(ax, key, units, "x")
    ax.set_ylabel(f"{words} (N·m)")
    ax.set_title(f"{words} before and after balancing")
    ax.grid(True, alpha=0.3)
    ax.figure.legend(loc="outside lower center", ncols=2, fontsize="small")


def _atlas_map(fig: Figure, ax: Axes, values: list[np.ndarray], keys: Sequence[str],
               after: np.ndarray, status: np.ndarray,
               original: dict[str, float] | None, units: dict[str, str], words: str) -> None:
    """Two varied keys: a heat map (a grid) or a scatter of the balanced figure (``words``)."""
    from matplotlib.colors import ListedColormap
    from matplotlib.patches import Patch

    x, y = values
    xs, ys = np.unique(x), np.unique(y)
    solved = np.isfinite(after)
    masks = _no_design_masks(after, status)
    handles: list[Artist] = []
    mesh: QuadMesh | PathCollection | None = None
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
        fig.colorbar(mesh, ax=ax, label=f"balanced {words} (N·m)")
    if original is not None and all(k in original for k in keys):
        ox, oy = (original[k] for k in keys)
        handles.append(mark_point(ax, ox, oy, "original design: the spec",
                                   f"{_key_value(keys[0], ox, units)}\n"
                                   f"{_key_value(keys[1], oy, units)}",
                                   **ORIGINAL_STYLE))
    ax.set_xlabel(_key_label(keys[0], units))
    ax.set_ylabel(_key_label(keys[1], units))
    _rpm_axis(ax, keys[0], units, "x")
    _rpm_axis(ax, keys[1], units, "y")
    ax.set_title(f"{words} of the balanced design at each point"
                 if mesh is not None else "No point has a balanced design")
    if handles:
        fig.legend(handles=handles, loc="outside lower center", ncols=1, fontsize="small")


def _perturbation_figure(table: Mapping[str, Sequence[Any]], perturbs: Sequence[PerturbLike],
                         original: dict[str, float],
                         units: dict[str, str]) -> Figure:
    """A perturbation sweep's histogram of the perturbed designs' RMS shaking force, N.

    Its title names each perturbed key, the spec's value (where ``original`` gives it) and the
    standard deviation σ of its normal draws, and how many designs were drawn and analysed.
    """
    from matplotlib.figure import Figure

    draws = len(table["status"])
    force = np.array([v for v in table["shaking_force_before"] if v is not None])
    fig = Figure(figsize=(7.5, 4.5), layout="constrained")
    ax = fig.add_subplot()
    if force.size:
        ax.hist(force, bins=max(10, min(60, force.size // 10)), color="C0",
                label="perturbed designs")
        p95 = float(np.percentile(force, 95))
        ax.axvline(p95, color="C3", ls="--", label=f"95th percentile: {number(p95)} N")
    analysed = (f"{draws} designs drawn" if force.size == draws else
                f"{draws} designs drawn, {force.size} analysed (the others: bad geometry)")
    spread = []
    for p in perturbs:
        unit = f" {units.get(p.key, '')}".rstrip()
        about = (_key_value(p.key, original[p.key], units).removeprefix(p.key)
                 if p.key in original else "")
        spread.append(f"{p.key}{about}, σ = {p.sigma:.3g}{unit}")
    title = f"Residual shaking force: {analysed}"
    if spread:
        title += ", each key normal about the spec's value\n" + "; ".join(spread)
    ax.set_title(title, fontsize="medium")
    ax.set_xlabel("RMS shaking force of the perturbed design (N)")
    ax.set_ylabel("designs")
    ax.grid(True, alpha=0.3)
    legend_outside(ax)
    return fig
