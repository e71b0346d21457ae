"""Proof by simulation that a design shakes its frame as little as claimed.

A balanced design is simulated with a formulation other than the one the optimiser used (the
optimiser's objective comes from the linear maps of inverse dynamics; the default check of a
four-bar uses the opened loop with principal vectors, Eq. 22–28, of a slider-crank its complex
masses, of a general linkage the multibody formulation's multipliers): once with the crank
driven at the operating speed, once in free motion from the spec's initial state. The largest
shaking force (the sum of the forces on the frame) and shaking moment of each run are compared
with those of the unbalanced original when the spec names one (``[original]``, written by
``balancer optimize``).

The runs are sampled finely enough for their largest values and their plots: output times at
which the crank turns at most one part in :data:`PER_REVOLUTION` of a revolution. A driven
run's number follows from its speed; a free one's from its initial speed with
:data:`FREE_MARGIN` to spare, and a free run whose crank turned faster still has its outputs
resampled from the integration's steps.
"""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import dataclass, replace
from typing import Any

import numpy as np

from .errors import LockupError, SpecError
from .mechanisms import mechanism_of
from .mechanisms.base import require_full_revolution
from .model import Design, SimulationSettings
from .model import MechanismModel as Model
from .simulation import MAX_OUTPUTS, Trajectory, check, simulate

#: Output times per crank revolution at least: 2°, some fifteen across the engine example's
#: sharpest peak (its gas force's).
PER_REVOLUTION = 180
#: A free run's outputs allow for its crank turning this much faster than at the start (more
#: are resampled from the integration where it turns faster still).
FREE_MARGIN = 1.5
#: Integrator tolerances of the runs: what the check needs. A balanced design's shaking force
#: (and, balanced completely, its moment) vanishes at every state the formulation evaluates,
#: however accurately the motion reached it, and a driven run's motion is prescribed; what the
#: integration decides are the free run's figures, reported to four digits, and the energy
#: balance, which measures the integration itself. 1e-9 keeps the simulated motion as accurate
#: as the formulations agree with each other (1e-9 relative, DESIGN.md) at 0.6 times the steps
#: of 1e-11.
RTOL = 1e-9
#: Revolutions of the crank at the operating speed that each run of a check lasts where the
#: spec gives no ``[simulation] duration`` (an engine at 9000 rpm would otherwise run its
#: default 5 s: 750 revolutions; the peaks of a steady cycle repeat every revolution, or every
#: second one for a four-stroke engine).
CHECK_REVOLUTIONS = 4
#: Most wall-clock time each simulation of a check may take, s: a run that would take longer
#: at the rate of its first steps is refused up front (its motion much faster than its
#: duration: gravity of 1e10 m/s², say) rather than left to run for minutes.
CHECK_SECONDS = 20.0
ATOL = 1e-11


@dataclass(frozen=True)
class RunCheck:
    """One simulated motion of the design (and of the original) and its shaking figures.

    Attributes
    ----------
    trajectory, original
        The simulated motion of the design and of the unbalanced original (or ``None``).
    max_shaking_force, max_shaking_moment
        Largest shaking force (N) and absolute shaking moment (N·m) over the run (over the part
        before it stopped, if it stopped; ``None`` if it could not start).
    original_max_shaking_force, original_max_shaking_moment
        The same for the original, or ``None``.
    max_rocking_couple, original_max_rocking_couple
        Largest rocking couple's magnitude (N·m) of the design and of the original (0 for a
        mechanism in one plane; ``None`` as above).
    note
        Why a run stopped early or could not be made (for example a lock-up), and the span
        its figures cover.
    """

    trajectory: Trajectory | None
    original: Trajectory | None
    max_shaking_force: float | None
    max_shaking_moment: float | None
    original_max_shaking_force: float | None = None
    original_max_shaking_moment: float | None = None
    max_rocking_couple: float | None = None
    original_max_rocking_couple: float | None = None
    note: str = ""

    @property
    def force_level(self) -> float | None:
        """Largest shaking force relative to the largest individual reaction (dimensionless).

        At integration-error level for a force-balanced design.
        """
        if self.trajectory is None or self.max_shaking_force is None:
            return None
        scale = self.trajectory.largest_reaction
        return self.max_shaking_force / scale if scale > 0 else None

    @property
    def force_ratio(self) -> float | None:
        """Largest shaking force relative to the original's."""
        return _ratio(self.max_shaking_force, self.original_max_shaking_force)

    @property
    def moment_ratio(self) -> float | None:
        """Largest shaking moment relative to the original's."""
        return _ratio(self.max_shaking_moment, self.original_max_shaking_moment)

    @property
    def couple_ratio(self) -> float | None:
        """Largest rocking couple relative to the original's."""
        return _ratio(self.max_rocking_couple, self.original_max_rocking_couple)

    def as_dict(self) -> dict[str, Any]:
        """Plain dictionary for JSON."""
        return {
            "max_shaking_force": self.max_shaking_force,
            "max_shaking_moment": self.max_shaking_moment,
            "original_max_shaking_force": self.original_max_shaking_force,
            "original_max_shaking_moment": self.original_max_shaking_moment,
            "max_rocking_couple": self.max_rocking_couple,
            "original_max_rocking_couple": self.original_max_rocking_couple,
            "force_ratio": self.force_ratio,
            "force_level": self.force_level,
            "moment_ratio": self.moment_ratio,
            "energy_error": None if self.trajectory is None else self.trajectory.energy_error,
            "note": self.note,
            "steps": None if self.trajectory is None else self.trajectory.steps,
            "rtol": None if self.trajectory is None else self.trajectory.rtol,
            "duration": None if self.trajectory is None else self.duration,
            "revolutions": self.revolutions,
        }

    @property
    def duration(self) -> float:
        """Simulated time of the run, s (0 if it could not start)."""
        t = self.trajectory.t if self.trajectory is not None else None
        return 0.0 if t is None or t.size == 0 else float(t[-1] - t[0])

    @property
    def revolutions(self) -> float | None:
        """Revolutions of the input link (link 1) over the run, ``|Δθ1|/2π`` (``None``: none)."""
        if self.trajectory is None or self.trajectory.theta.size == 0:
            return None
        theta = self.trajectory.theta[0]
        return float(abs(theta[-1] - theta[0]) / (2 * np.pi))


def _ratio(a: float | None, b: float | None) -> float | None:
    if a is None or b is None or b == 0:
        return None
    return a / b


@dataclass(frozen=True)
class Verification:
    """The result of :func:`verify`.

    Attributes
    ----------
    method
        Formulation used for the simulations.
    driven
        The crank held at the operating speed.
    free
        Free motion from the spec's initial state.
    """

    method: str
    driven: RunCheck
    free: RunCheck

    def __repr__(self) -> str:
        def fmt(x: float | None) -> str:
            return "none" if x is None else f"{x:.4g}"

        return (f"Verification({self.method}: largest shaking force "
                f"{fmt(self.max_shaking_force)} N, moment {fmt(self.max_shaking_moment)} N·m)")

    @property
    def max_shaking_force(self) -> float | None:
        """Largest shaking force over the runs, N (``None``: neither could start)."""
        return max((x for x in (self.driven.max_shaking_force, self.free.max_shaking_force)
                    if x is not None), default=None)

    @property
    def max_shaking_moment(self) -> float | None:
        """Largest shaking moment over the runs, N·m (``None``: neither could start)."""
        return max((x for x in (self.driven.max_shaking_moment, self.free.max_shaking_moment)
                    if x is not None), default=None)

    @property
    def max_rocking_couple(self) -> float | None:
        """Largest rocking couple over the runs, N·m (``None``: neither could start)."""
        return max((x for x in (self.driven.max_rocking_couple, self.free.max_rocking_couple)
                    if x is not None), default=None)

    def as_dict(self) -> dict[str, Any]:
        """Plain dictionary for JSON (``max_shaking_force``, ``max_shaking_moment`` fixed)."""
        return {
            "method": self.method,
            "max_shaking_force": self.max_shaking_force,
            "max_shaking_moment": self.max_shaking_moment,
            "max_rocking_couple": self.max_rocking_couple,
            "driven": self.driven.as_dict(),
            "free": self.free.as_dict(),
        }


def _figures(traj: Trajectory | None) -> tuple[float | None, float | None, float | None]:
    """Largest shaking force, shaking moment and rocking couple of a run (``None``: no run)."""
    if traj is None or traj.t.size == 0:
        return None, None, None
    return (float(np.max(np.abs(traj.shaking_force))),
            float(np.max(np.abs(traj.shaking_moment))),
            float(np.max(np.abs(traj.rocking_couple))))


class _Tally:
    """Progress over all the simulations of a verification, in simulated seconds."""

    def __init__(self, progress: Callable[[float, float], None] | None, total: float) -> None:
        self.progress = progress
        self.total = total
        self.done = 0.0

    def simulate(self, linkage: Model, settings: SimulationSettings, method: str,
                 **kw: Any) -> Trajectory:
        """:func:`~balancer.simulation.simulate`, reporting its progress within the whole."""
        report: Callable[[float, float], None] | None = None
        if self.progress is not None:
            progress, done, total = self.progress, self.done, self.total

            def report_total(t: float, duration: float) -> None:
                progress(done + t, total)

            report = report_total

        try:
            return simulate(linkage, settings, method=method, progress=report,
                            max_seconds=CHECK_SECONDS, **kw)
        finally:
            self.done += settings.duration


def _simulate_span(tally: _Tally, linkage: Model, settings: SimulationSettings, method: str,
                   resolution: float | None, **kw: Any
                   ) -> tuple[Trajectory | None, str, SimulationSettings]:
    """The run (or its part before the motion stopped), why it stopped, its settings.

    The reason is "" for a run that did not stop. With a ``resolution`` (rad), the crank
    turns at most that far between two output times (:func:`~balancer.simulation.simulate`
    resamples the outputs of a crank that turned faster).
    """
    traj: Trajectory | None
    try:
        traj, note = tally.simulate(linkage, settings, method, resolution=resolution, **kw), ""
    except LockupError as exc:
        traj, note = getattr(exc, "partial", None), str(exc)
    if traj is not None and not note:  # as many outputs as it took (the original's too)
        settings = replace(settings, outputs=int(traj.t.size))
    return traj, note, settings


def _resolved(settings: SimulationSettings, speed: float, resolution: float | None
              ) -> SimulationSettings:
    """``settings`` with output times enough for a crank at ``speed`` (rad/s)."""
    if resolution is None:
        return settings
    need = math.ceil(abs(speed) * settings.duration / resolution) + 1
    return replace(settings, outputs=min(MAX_OUTPUTS, max(settings.outputs, need)))


def _run(tally: _Tally, linkage: Model, original: Model | None, settings: SimulationSettings,
         method: str, resolution: float | None = None, **kw: Any) -> RunCheck:
    """Simulate the design and the original over the same span.

    A run that stops early (a lock-up, a dead point its formulation cannot pass) is judged over
    the part before it stopped, the note says where; the original is then run over that span.
    """
    traj, note, settings = _simulate_span(tally, linkage, settings, method, resolution, **kw)
    force, moment, couple = _figures(traj)
    orig = None
    o_force = o_moment = o_couple = None
    if original is not None and force is not None:
        assert traj is not None  # (it has figures)
        span = settings if not note else replace(settings, duration=float(traj.t[-1]))
        orig, o_note, _ = _simulate_span(tally, original, span, method, resolution, **kw) \
            if span.duration > 0 else (None, "", span)
        o_force, o_moment, o_couple = _figures(orig)
        if o_note:
            note = "; ".join(x for x in (note, f"original: {o_note}") if x)
            o_force = o_moment = o_couple = None  # over a shorter span: not comparable
    if note and traj is not None and traj.t.size:
        note += f" (figures over 0 ≤ t ≤ {float(traj.t[-1]):.6g} s)"
    return RunCheck(trajectory=traj, original=orig, max_shaking_force=force,
                    max_shaking_moment=moment, original_max_shaking_force=o_force,
                    original_max_shaking_moment=o_moment, max_rocking_couple=couple,
                    original_max_rocking_couple=o_couple, note=note)


def verify(
    design: Design,
    *,
    method: str | None = None,
    duration: float | None = None,
    rtol: float = RTOL,
    atol: float = ATOL,
    outputs: int | None = None,
    progress: Callable[[float, float], None] | None = None,
) -> Verification:
    """Simulate the design driven at its operating speed and in free motion.

    Parameters
    ----------
    design
        The design; its ``[operation]`` speed is needed for the driven run, its ``[original]``
        (if any) is simulated alongside.
    method
        Formulation for the simulations (by default one the optimiser did not use: the
        mechanism's :attr:`~balancer.mechanisms.base.Mechanism.verify_method`).
    duration
        Simulated time of each run, s (default: the spec's ``[simulation] duration``, or
        where it gives none, :data:`CHECK_REVOLUTIONS` revolutions at the operating speed; the
        free run then starts at the operating speed unless the spec gives ``omega1``).
    rtol, atol
        Integrator tolerances (see :data:`RTOL`).
    outputs
        Output times per run (default: the spec's, or more: enough that the crank turns at
        most a :data:`PER_REVOLUTION`'th of a revolution between two).
    progress
        Called as ``progress(done, total)`` in simulated seconds over all the runs (the
        original's included) as they go (see :class:`balancer.progress.Progress`).

    Raises
    ------
    SpecError
        If the spec has no operating speed, or the crank cannot turn fully when driven; for
        whatever :func:`~balancer.simulation.simulate` refuses of any of the runs, before
        the first starts (:func:`~balancer.simulation.check`).
    """
    method, runs = _plan(design, method, duration, rtol, atol, outputs)
    total = sum(r.settings.duration for r in runs) * (1 + (design.original is not None))
    tally = _Tally(progress, total)
    # The free run first: a duration too long for the step budget is refused from the rate
    # of its first steps, before the driven run's work.
    free, driven = [_run(tally, design.mechanism, design.original, run.settings, method,
                         **run.kw) for run in runs]
    return Verification(method=method, driven=driven, free=free)


@dataclass(frozen=True)
class _Planned:
    """One run of a verification: its settings and :func:`simulate`'s keywords."""

    settings: SimulationSettings
    kw: dict[str, Any]


def _plan(design: Design, method: str | None, duration: float | None, rtol: float, atol: float,
          outputs: int | None) -> tuple[str, list[_Planned]]:
    """The method and the runs (free, then driven) of :func:`verify`, checked.

    Everything :func:`~balancer.simulation.simulate` refuses before it integrates is refused
    here, for every run of the design and of its original, before any is made
    (:func:`~balancer.simulation.check`).
    """
    if design.operation is None:
        raise SpecError("missing required key: the driven check runs at the operating speed",
                        key="operation.speed")
    linkage = design.mechanism
    mech = mechanism_of(linkage)
    method = method or mech.verify_method
    settings = design.simulation
    speed = design.operation.speed
    if duration is not None:
        settings = replace(settings, duration=duration)
    elif "duration" not in settings.given:  # sized to the machine's speed
        settings = replace(settings, duration=CHECK_REVOLUTIONS * 2 * math.pi / abs(speed))
    if "omega1" not in settings.given:
        # No initial state: the free run coasts from the operating speed (from rest, a machine
        # with no gravity and no loads would not move: its check would say nothing).
        settings = replace(settings, omega1=speed)
    resolution = None
    if outputs is not None:
        settings = replace(settings, outputs=outputs)
    else:
        resolution = 2 * math.pi / PER_REVOLUTION
    start = settings.theta1
    require_full_revolution(mech, "a driven check")
    driven_settings = _resolved(replace(settings, drive="constant-speed", omega1=speed,
                                        theta1=start), speed, resolution)
    free_settings = _resolved(replace(settings, drive="free"), FREE_MARGIN * settings.omega1,
                              resolution)
    kw = {"rtol": rtol, "atol": atol, "resolution": resolution}
    runs = [_Planned(settings=free_settings, kw=kw), _Planned(settings=driven_settings, kw=kw)]
    for model in (linkage, design.original):
        for run in runs:
            if model is not None:
                check(model, run.settings, method=method, **run.kw)
    return method, runs


def check_verification(design: Design, *, method: str | None = None,
                       duration: float | None = None, rtol: float = RTOL, atol: float = ATOL,
                       outputs: int | None = None) -> None:
    """Raise what :func:`verify` with these arguments would refuse before it simulates.

    For a command that verifies at its end (``optimize``): its bad input is found before its
    work. The arguments are :func:`verify`'s.
    """
    _plan(design, method, duration, rtol, atol, outputs)
