"""``pareto``'s and ``sweep``'s reports: trade-off fronts and sweep tables as text, JSON and CSV."""

from __future__ import annotations

from collections.abc import Mapping
from typing import Any, Protocol

import numpy as np

from ..balance.front import FIGURES, Front
from ..rounding import Scales
from .text import csv_text, table

# ----------------------------------------------------------------------------------------------
# Trade-off fronts


def front_json(front: Front, spec: str | None = None) -> dict[str, Any]:
    """The ``pareto --json`` document: ``against`` and ``points`` are fixed names."""
    doc: dict[str, Any] = {} if spec is None else {"spec": spec}
    doc.update(front.as_dict())
    return doc


def front_text(front: Front, spec: str | None = None) -> str:
    """The readable front: one row per point, the knee marked."""
    head = f"balancer pareto — {spec}" if spec else "balancer pareto"
    name = front.name.replace("_", " ")
    others = front.figure_names
    # Each column's scale its largest figure (the bound the minimised figure's).
    sc = Scales([(front.name, p.value) for p in front.points]
                + [(front.minimised, x) for p in front.points for x in (p.least, p.lower_bound)]
                + [(n, p.figures[n]) for p in front.points for n in others])
    # A bound of 0 under a positive optimum is none made (the certificate could not bound the
    # program's box): shown as such, not as a certified 0.
    uncertified = [p.lower_bound <= 0 and not sc.rounding(p.least, front.minimised)
                   for p in front.points]
    rows = [[f"{i + 1}", sc.fmt(p.value, front.name), sc.fmt(p.least, front.minimised),
             *(sc.fmt(p.figures[n], n) for n in others),
             "—" if bare else sc.fmt(p.lower_bound, front.minimised),
             "knee" if p.knee else ""]
            for i, (p, bare) in enumerate(zip(front.points, uncertified, strict=True))]
    unit = FIGURES[front.minimised][1]
    held = ("each mass·radius within its bound; the unbalance term's place taken by the "
            "bound on the mass" if front.masses
            else "the balancing constraints of [balance] hold at every point")
    lines = [head,
             f"least {front.words} against {name} ({len(front.points)} "
             f"point{'s' if len(front.points) != 1 else ''}, each a "
             + ("global optimum with its certified lower bound" if not any(uncertified) else
                "solver's optimum, its lower bound certified where shown (— : the "
                "certificate could not bound it)")
             + f"; {held})", "",
             table(rows, ["point", f"{name} {front.unit}", f"{front.words} {unit}",
                          *(f"{FIGURES[n][0]} {FIGURES[n][1]}" for n in others),
                          f"certified bound {unit}", ""])]
    lines += [f"note: {note}" for note in front.notes]
    return "\n".join(lines)


def front_csv(front: Front) -> str:
    """The front as CSV: one row per point (knee: 1 at the knee, else 0)."""
    points = front.points
    others = front.figure_names
    return csv_text(
        [front.minimised, front.name, "epsilon", "lower_bound", "knee", *others],
        [np.array([p.least for p in points]), np.array([p.value for p in points]),
         np.array([p.epsilon for p in points]), np.array([p.lower_bound for p in points]),
         np.array([1.0 if p.knee else 0.0 for p in points]),
         *(np.array([p.figures[n] for p in points]) for n in others)])


class SweepSummary(Protocol):
    """What the summary reads of a sweep (:class:`balancer.sweeps.SweepResult`, a layer above)."""

    @property
    def statuses(self) -> Mapping[str, int]:
        """Points by status."""
    @property
    def points(self) -> int:
        """Points in all."""
    @property
    def computed(self) -> int:
        """Points this run computed."""
    @property
    def resumed(self) -> int:
        """Batches kept from an interrupted run."""
    @property
    def workers(self) -> int:
        """Dask workers (0: this process)."""
    @property
    def seconds(self) -> float:
        """Wall-clock time, s."""
    @property
    def rate(self) -> float | None:
        """Points per second of this run, or ``None``."""
    @property
    def residual_force(self) -> Mapping[str, float | str] | None:
        """The perturbed designs' residual RMS shaking force (``mean``, ``p95``, ``max``), N."""


def sweep_text(result: SweepSummary, spec: str | None = None) -> str:
    """The readable summary of a sweep."""
    head = f"balancer sweep — {spec}" if spec else "balancer sweep"
    rows = [[status, str(count)] for status, count in sorted(result.statuses.items())]
    where = (f"{result.workers} Dask workers" if result.workers else "this process")
    # The rate counts this run's own points, not those kept from an interrupted run.
    rate = f"{result.rate:.3g} points/s" if result.rate is not None else "no time to measure"
    timing = f"{result.seconds:.1f} s ({rate}, {where})"
    if not result.resumed:
        summary = f"{result.points} points in {timing}"
    else:
        now = (f"{result.computed} computed in {timing}" if result.computed
               else "none left to compute")
        summary = (f"{result.points} points: {result.points - result.computed} from the "
                   f"interrupted run before ({result.resumed} batches), {now}")
    lines = [head, summary, "", table(rows, ["status", "points"]), ""]
    if result.residual_force is not None:
        r = result.residual_force
        lines += [f"residual RMS shaking force of the perturbed designs: mean {r['mean']:.4g} "
                  f"N, 95th percentile {r['p95']:.4g} N, largest {r['max']:.4g} N", ""]
    return "\n".join(lines).rstrip("\n")
