"""Result objects of the balancing optimisers and the error for an infeasible problem.

A result says whether it succeeded in its own terms (:attr:`BalanceResult.success`,
:class:`Status`), never by a raw solver string; the solvers' own words are kept per stage in
:class:`StageReport` for diagnosis.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, replace
from enum import StrEnum
from functools import cached_property

import numpy as np
from numpy.typing import NDArray

from ..cycle import CycleAnalysis, cycle_analysis
from ..errors import SolverError
from ..model import Design
from ..model import MechanismModel as Model
from ..model.balance import Objective, ObjectiveTerm, PlacedMass, ShaftDesign
from ..motion_analysis import AlongMotions, along_motions
from ..quantities import QUANTITIES, squared_parts
from ..rounding import Scales
from .counterweights import Counterweight, added_mass, counterweights

#: Gap to the certified lower bound, relative to the problem's scale (the original design's
#: RMS; :meth:`balancer.balance.problem.NumericProblem.gap`), within which a design is called
#: globally optimal. The bound holds by weak duality (:mod:`balancer.balance.certificate`) and
#: lies ~1e-9 of that scale below the optimum; the tie-break accepts 1e-8.
GAP_TOLERANCE = 1e-6


class Status(StrEnum):
    """Outcome of a balancing."""

    OPTIMAL = "optimal"
    """A feasible design within :data:`GAP_TOLERANCE` (of the problem's scale) of the certified
    lower bound: globally optimal."""
    FEASIBLE = "feasible"
    """A feasible design (all bounds, exact force balance) that is not proven optimal: a local
    optimum, or the convex design made feasible when its relaxation was not tight."""
    FAILED = "failed"
    """No feasible design: the solver failed."""


@dataclass(frozen=True, kw_only=True)
class StageReport:
    """One solver run inside a balancing.

    Attributes
    ----------
    name
        ``"convex"`` (the SOCP), ``"tie-break"`` (nearest-to-original among the optimal
        designs), ``"nlp"`` (IPOPT on the physical parameters).
    converged
        Whether the solver reported convergence.
    solver_status
        The solver's own status word (for diagnosis only).
    iterations
        Solver iterations.
    time
        Wall-clock time of the stage, s.
    objective
        The objective ``J`` at the stage's design, (N·m)² (``nan`` if it has none).
    gap
        That objective's gap to the certified lower bound, relative to the problem's scale
        (:meth:`balancer.balance.problem.NumericProblem.gap`; ``nan`` until the bound is known).
    """

    name: str
    converged: bool
    solver_status: str
    iterations: int
    time: float
    objective: float
    gap: float = float("nan")


@dataclass(frozen=True)
class RotorMasses:
    """What a balancing builds: counterweights on the crankshaft and new shafts.

    Attributes
    ----------
    counterweights
        Per chosen plane, its counterweight (``mr`` 0: none there).
    shafts
        Each new shaft with an eccentric per plane (``mr`` 0: none there).
    radius
        The counterweights' radius, m (``None``: not given), for their masses.
    replaced
        The places (crankshaft, plane z in m) whose labelled counterweights the new ones
        replace.
    unbalance_before, unbalance_after
        ``√Σ (mr·ω²)²`` over the chosen planes' counterweights and the new shafts' eccentrics
        of the original (its replaced counterweights) and of the balanced design, N.
    bearing_loads
        Each new shaft's largest bearing force, N (its eccentrics' centrifugal forces summed).
    """

    counterweights: tuple[PlacedMass, ...]
    shafts: tuple[ShaftDesign, ...]
    radius: float | None
    replaced: tuple[tuple[int, float], ...]
    unbalance_before: float
    unbalance_after: float
    bearing_loads: tuple[float, ...]

    def mass(self, c: PlacedMass) -> float | None:
        """A counterweight's mass at :attr:`radius`, kg (``None`` without a radius)."""
        return None if self.radius is None else c.mr / self.radius

    @property
    def mr_sum(self) -> float:
        """``Σ |mr|`` of the chosen counterweights and the new shafts' eccentrics, kg·m."""
        return math.fsum([c.mr for c in self.counterweights]
                         + [e.mr for s in self.shafts for e in s.eccentrics])

    @property
    def added_mass(self) -> float | None:
        """:attr:`mr_sum` as masses at :attr:`radius` (the eccentrics' too), kg; else ``None``.

        What ``pareto --against added-mass`` bounds and a sweep's ``added_mass`` column holds
        for an engine (DESIGN.md, "Balancing an engine").
        """
        return None if self.radius is None else self.mr_sum / self.radius

    def as_dict(self) -> dict[str, object]:
        """``crankshaft_counterweights`` and ``balance_shafts`` as ``optimize --json`` gives."""
        cws = []
        several = any(c.crankshaft != 1 for c in self.counterweights)
        for c in self.counterweights:
            item: dict[str, object] = {"z": c.z, "mr": c.mr, "phase_deg": c.phase_deg}
            if several:  # (an engine of geared crankshafts: which one carries it)
                item["crankshaft"] = c.crankshaft
            mass = self.mass(c)
            if mass is not None:
                item["mass"] = mass
            cws.append(item)
        shafts = [{"ratio": s.ratio, "at": list(s.at),
                   "eccentrics": [{"z": e.z, "mr": e.mr, "phase_deg": e.phase_deg}
                                  for e in s.eccentrics],
                   "max_bearing_load": load}
                  for s, load in zip(self.shafts, self.bearing_loads, strict=True)]
        return {"crankshaft_counterweights": cws, "balance_shafts": shafts}



@dataclass(frozen=True, kw_only=True)
class FlywheelSizing:
    """What ``[balance] max_speed_fluctuation`` did (:mod:`.flywheel`): the flywheel it added.

    Attributes
    ----------
    bound
        ``δ``, the largest speed fluctuation allowed.
    before, balanced, after
        The speed fluctuation of the original, of the balanced design before its flywheel,
        and of the balanced design with it (``inf``: it cannot run at the operating speed).
    added
        The flywheel put on the crank, kg·m² (0: none needed).
    crank
        The crank's name.
    inertia, counter_rotor
        Their share of it, kg·m².
    """

    bound: float
    before: float
    balanced: float
    after: float
    added: float
    crank: str
    inertia: float
    counter_rotor: float

    def as_dict(self) -> dict[str, object]:
        """``optimize --json``'s ``speed_fluctuation``."""
        return {"bound": self.bound, "before": _finite(self.before),
                "balanced": _finite(self.balanced), "after": _finite(self.after),
                "flywheel": self.added, "crank": self.crank,
                "inertia_added": self.inertia, "counter_rotor_added": self.counter_rotor}


def _finite(value: float) -> float | None:
    return value if math.isfinite(value) else None


@dataclass(frozen=True, kw_only=True, eq=False)
class BalanceResult:
    """A balanced design and how it was found (shaped like SciPy's ``OptimizeResult``).

    The objective is the **inertial** one: applied loads are left out (they are not linear in
    the design); the balanced links keep the original loads.

    Attributes
    ----------
    success
        A feasible design was found (status ``optimal`` or ``feasible``).
    status
        See :class:`Status`.
    message
        One line for a report.
    backend
        ``"convex"`` or ``"nlp"``.
    linkage
        The balanced mechanism's model.
    original
        The design it came from.
    x
        Its design vector (the mechanism's layout,
        :class:`balancer.linkage.dynamics.Layout`): kg, kg·m, kg·m, kg·m² per link, then
        counter-rotor inertias, kg·m².
    objective
        ``J`` of the balanced design, (N·m)² (mean-square form, see
        :mod:`balancer.balance.problem`).
    original_objective
        ``J`` of the original design, (N·m)².
    lower_bound
        Certified by weak duality at the convex program's multipliers (whatever the solver's
        tolerances): no feasible design has a smaller ``J``, (N·m)².
    gap
        The design's gap to the lower bound relative to :attr:`scale`: ``(√J − √J_low)/scale``
        for a mean-square objective, else ``(J − J_low)/scale²``; dimensionless.
    scale
        The problem's own scale of ``√J``: the original design's weighted RMS (or, for an
        original that is balanced already, a share of what its inertias can produce), N·m.
    rms_form
        Whether ``J`` is a mean square (no mass term), so that :attr:`rms` and the bounds in
        N·m are meaningful.
    relaxation_tight
        Whether the convex relaxation was exact at its optimum (always, unless a link has a
        bounded inertia about a centre of mass that may move).
    iterations
        Solver iterations over all stages.
    time
        Wall-clock time of the solves, s (building the problem and the analyses excluded).
    stages
        Each solver run.
    before, after
        Cycle analyses of the original and the balanced design without loads (Newton–Euler
        route: an independent check of the objective, which the optimisers compute from the
        mass-matrix regressors); :attr:`operating` gives them with loads and gravity.
    gravity
        The spec's ``[operation] gravity`` (m/s²), for :attr:`operating`.
    weights
        The objective's weights (``[balance.objective]``).
    rotor_masses
        An engine's balancing: the counterweights and shafts it builds (``None`` for a
        linkage's, whose links change).
    flywheel
        Under ``[balance] max_speed_fluctuation``: the flywheel put on the crank and the speed
        fluctuations before and after (:class:`~.flywheel.FlywheelSizing`), else ``None``.
    """

    success: bool
    status: Status
    message: str
    backend: str
    linkage: Model
    original: Model
    x: NDArray[np.float64]
    objective: float
    original_objective: float
    lower_bound: float
    gap: float
    scale: float
    rms_form: bool
    relaxation_tight: bool
    iterations: int
    time: float
    stages: tuple[StageReport, ...]
    before: CycleAnalysis | AlongMotions
    after: CycleAnalysis | AlongMotions
    gravity: tuple[float, float] = (0.0, 0.0)
    weights: Objective = Objective()
    rotor_masses: RotorMasses | None = None
    flywheel: FlywheelSizing | None = None

    def __repr__(self) -> str:
        mass = self.added_mass
        added = "" if mass is None else f"; added mass {mass:.4g} kg"
        return f"BalanceResult({self.status}, {self.backend}: {self.message}{added})"

    @cached_property
    def operating(self) -> tuple[CycleAnalysis | AlongMotions, CycleAnalysis | AlongMotions]:
        """The original's and the balanced design's figures as ``analyze`` gives them.

        At the operating speed with the links' loads (a gas force, applied forces) and the
        spec's ``[operation] gravity``: what the machine's frame feels. :attr:`before` and
        :attr:`after` are the inertial part alone, which the optimiser balances; without loads
        and gravity the two agree.
        """
        if isinstance(self.before, AlongMotions):
            motions = [a.motion for a in self.before.motions]
            workspace = self.before.workspace_spec
            weights = self.before.weights
            return (along_motions(self.original, motions, gravity=self.gravity,
                                  workspace=workspace, weights=weights),
                    along_motions(self.linkage, motions, gravity=self.gravity,
                                  workspace=workspace, weights=weights))
        speed, samples = self.before.speed, self.before.samples
        original, balanced = (cycle_analysis(model, speed, samples, gravity=self.gravity)
                              for model in (self.original, self.linkage))
        return original, balanced

    @property
    def counterweights(self) -> dict[str, Counterweight]:
        """Per link, the body to add to the original link to build the balanced one.

        (None for an engine's balancing: its links stay; :attr:`rotor_masses` says what it
        adds.)
        """
        if self.rotor_masses is not None:
            return {}
        return counterweights(self.original, self.linkage)

    @property
    def added_mass(self) -> float | None:
        """Total mass of the counterweights, kg (material removed counts negative).

        An engine's: its chosen masses at the counterweights' radius
        (:attr:`RotorMasses.added_mass`; ``None`` where no radius is given).
        """
        if self.rotor_masses is not None:
            return self.rotor_masses.added_mass
        return added_mass(self.counterweights)

    @property
    def rms(self) -> float:
        """``√J``: the design's weighted RMS shaking (its RMS shaking moment by default), N·m."""
        return float(np.sqrt(max(self.objective, 0.0)))

    @property
    def rms_lower_bound(self) -> float:
        """``√J_low``: no feasible design has a smaller weighted RMS, N·m."""
        return float(np.sqrt(max(self.lower_bound, 0.0)))

    @property
    def rms_gap(self) -> float:
        """``√J − √J_low``, N·m."""
        return self.rms - self.rms_lower_bound

    @property
    def single_term(self) -> ObjectiveTerm | None:
        """The one quantity the objective weighs, or ``None`` (:attr:`Objective.single`).

        Then ``√(J/w)`` is that quantity's RMS in its own unit: :meth:`in_unit`.
        """
        return self.weights.single

    def in_unit(self, rms: float) -> float:
        """A figure of ``√J`` (N·m) as the RMS of :attr:`single_term` in its unit (N, N·m).

        ``√J = √w·RMS(q)``; without a single term, ``rms`` unchanged.
        """
        term = self.single_term
        return rms if term is None else rms / float(np.sqrt(term.weight))

    def term_rms(self, analysis: CycleAnalysis | AlongMotions) -> dict[str, float]:
        """Each mean-square term's RMS in ``analysis`` (inertial: :attr:`before`, :attr:`after`).

        Keyed by the term's name (:attr:`Objective.terms`), in its unit; ``added_mass`` gives
        the mass added to the original, kg; a largest load's term (``largest_bearing_load``)
        its largest magnitude, N.
        """
        values = {t.name: float(np.sqrt(np.mean(sum(
            part**2 for part in squared_parts(t.name, analysis.load)))))
            for t in self.weights.terms if QUANTITIES[t.name].squares}
        values.update({t.name: float(np.max(np.abs(analysis.load(QUANTITIES[t.name].largest)),
                                            initial=0.0))
                       for t in self.weights.terms if QUANTITIES[t.name].largest})
        values["added_mass"] = analysis.linkage.total_mass - self.original.total_mass
        if self.rotor_masses is not None:  # (of the chosen masses, not of the analysis)
            rm = self.rotor_masses
            values["unbalance"] = (rm.unbalance_after if analysis is self.after
                                   else rm.unbalance_before)
        return {t.name: values[t.name] for t in self.weights.terms}

    def summary(self, notes: list[str] | None = None) -> str:
        """One line: the status, the figure, the certified bound and the gap (and ``notes``).

        With one quantity in the objective, as its RMS in its own unit (N for a force, N·m for a
        moment or torque); otherwise the weighted sum ``J`` in (N·m)².
        """
        text = {
            Status.OPTIMAL: "globally optimal",
            Status.FEASIBLE: "feasible, not proven optimal",
            Status.FAILED: "no feasible design found",
        }[self.status]
        term = self.single_term
        if self.rms_form and term is not None:
            unit, name = term.unit, term.name.replace("_", " ")
            tolerance = (f"tolerance {GAP_TOLERANCE:g} of the problem's scale "
                         f"{self.in_unit(self.scale):.4g} {unit}")
            # (A figure within rounding of the problem's scale is 0: :class:`Scales`.)
            sc = Scales([(unit, self.in_unit(self.scale))])
            what = name if QUANTITIES[term.name].largest else f"RMS {name}"
            value = f"{what} {sc.number(self.in_unit(self.rms), unit)} {unit}"
            if self.original_objective > 0:
                ratio = sc.ratio(self.in_unit(self.rms),
                                 self.in_unit(math.sqrt(self.original_objective)), unit)
                value += f" ({ratio} of the original's)"
            parts = [text, value,
                     f"certified lower bound {self.in_unit(self.rms_lower_bound):.6g} {unit}",
                     f"gap {self.in_unit(self.rms_gap):.2g} {unit} ({tolerance})"]
        else:
            tolerance = f"tolerance {GAP_TOLERANCE:g} of the problem's scale {self.scale:.4g} N·m"
            parts = [text, f"J = {self.objective:.6g} (N·m)²",
                     f"certified lower bound {self.lower_bound:.6g} (N·m)²",
                     f"gap {self.gap * self.scale**2:.2g} (N·m)² ({tolerance}, squared)"]
        if not self.relaxation_tight:
            parts.append("convex relaxation not tight")
        return "; ".join(parts + (notes or []))

    @property
    def optimal(self) -> bool:
        """Whether the design is proven globally optimal."""
        return self.status is Status.OPTIMAL

    def balanced_design(self, design: Design) -> Design:
        """The spec ``design`` with the balanced mechanism, and the original kept as ``original``.

        (An engine's too: its crankshaft with the counterweights it had, its shafts.)
        """
        return replace(
            design,
            mechanism=self.linkage,
            original=design.original if design.original is not None else self.original,
        )


class InfeasibleError(SolverError):
    """The redesign problem has no feasible design (exit code 1).

    Attributes
    ----------
    needed
        Bounds that would make it feasible: ``(key, needed value, current value or None,
        unit)`` each, e.g. ``("balance.crank.com_radius", 0.5859, 0.3, "m")``.
    jointly
        ``False``: each of :attr:`needed` suffices alone (the others kept); ``True``: they
        suffice together.
    """

    def __init__(
        self,
        message: str,
        *,
        needed: tuple[tuple[str, float, float | None, str], ...] = (),
        jointly: bool = False,
    ) -> None:
        self.needed = needed
        self.jointly = jointly
        super().__init__(message)
