"""Proof by simulation that a design shakes its frame as little as claimed.

A balanced design is simulated with a formulation other than the one the optimiser used (the
optimiser's objective comes from the linear maps of inverse dynamics; the default check of a
four-bar uses the opened loop with principal vectors, Eq. 22–28, of a slider-crank its complex
masses, of a general linkage the multibody formulation's multipliers): once with the crank
driven at the operating speed, once in free motion from the spec's initial state. The largest
shaking force (the sum of the forces on the frame) and shaking moment of each run are compared
with those of the unbalanced original when the spec names one (``[original]``, written by
``balancer optimize``).
"""

from __future__ import annotations

from dataclasses import dataclass, replace

import numpy as np

from .errors import LockupError, SpecError
from .mechanisms import mechanism_of
from .model import Design
from .simulate import Trajectory, simulate


@dataclass(frozen=True)
class RunCheck:
    """One simulated motion of the design (and of the original) and its shaking figures.

    Attributes
    ----------
    trajectory, original
        The simulated motion of the design and of the unbalanced original (or ``None``).
    max_shaking_force, max_shaking_moment
        Largest shaking force (N) and |shaking moment| (N·m) over the run (over the part
        before it stopped, if it stopped; ``None`` if it could not start).
    original_max_shaking_force, original_max_shaking_moment
        The same for the original, or ``None``.
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

    def as_dict(self) -> dict:
        """Plain dictionary for JSON."""
        return {
            "max_shaking_force": self.max_shaking_force,
            "max_shaking_moment": self.max_shaking_moment,
            "original_max_shaking_force": self.original_max_shaking_force,
            "original_max_shaking_moment": self.original_max_shaking_moment,
            "force_ratio": self.force_ratio,
            "force_level": self.force_level,
            "moment_ratio": self.moment_ratio,
            "energy_error": None if self.trajectory is None else self.trajectory.energy_error,
            "note": self.note,
        }


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

    def as_dict(self) -> dict:
        """Plain dictionary for JSON (``max_shaking_force``, ``max_shaking_moment`` fixed)."""
        return {
            "method": self.method,
            "max_shaking_force": self.max_shaking_force,
            "max_shaking_moment": self.max_shaking_moment,
            "driven": self.driven.as_dict(),
            "free": self.free.as_dict(),
        }


def _figures(traj: Trajectory | None) -> tuple[float | None, float | None]:
    if traj is None or traj.t.size == 0:
        return None, None
    return float(np.max(np.abs(traj.shaking_force))), float(np.max(np.abs(traj.shaking_moment)))


def _simulate_span(linkage, settings, method: str, **kw) -> tuple[Trajectory | None, str]:
    """The run, or the part of it before the motion stopped, and why it stopped ("" if not)."""
    try:
        return simulate(linkage, settings, method=method, **kw), ""
    except LockupError as exc:
        return getattr(exc, "partial", None), str(exc)


def _run(linkage, original, settings, method: str, **kw) -> RunCheck:
    """Simulate the design and the original over the same span.

    A run that stops early (a lock-up, a dead point its formulation cannot pass) is judged over
    the part before it stopped, the note says where; the original is then run over that span.
    """
    traj, note = _simulate_span(linkage, settings, method, **kw)
    force, moment = _figures(traj)
    orig = None
    o_force = o_moment = None
    if original is not None and force is not None:
        span = settings if not note else replace(settings, duration=float(traj.t[-1]))
        orig, o_note = _simulate_span(original, span, method, **kw) if span.duration > 0 \
            else (None, "")
        o_force, o_moment = _figures(orig)
        if o_note:
            note = "; ".join(x for x in (note, f"original: {o_note}") if x)
            o_force = o_moment = None  # over a shorter span: not comparable
    if note and traj is not None and traj.t.size:
        note += f" (figures over 0 ≤ t ≤ {float(traj.t[-1]):.6g} s)"
    return RunCheck(trajectory=traj, original=orig, max_shaking_force=force,
                    max_shaking_moment=moment, original_max_shaking_force=o_force,
                    original_max_shaking_moment=o_moment, note=note)


def verify(
    design: Design,
    *,
    method: str | None = None,
    duration: float | None = None,
    rtol: float = 1e-11,
    atol: float = 1e-13,
    outputs: int | None = None,
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
        Simulated time of each run, s (default: the spec's ``[simulation] duration``).
    rtol, atol
        Integrator tolerances (tight: the balanced figures are at integration-error level).
    outputs
        Output times per run (default: the spec's).

    Raises
    ------
    SpecError
        If the spec has no operating speed, or the crank cannot turn fully when driven.
    """
    if design.operation is None:
        raise SpecError("missing required key: the driven check runs at the operating speed",
                        key="operation.speed")
    linkage = design.mechanism
    mech = mechanism_of(linkage)
    method = method or mech.verify_method
    settings = design.simulation
    if duration is not None:
        settings = replace(settings, duration=duration)
    if outputs is not None:
        settings = replace(settings, outputs=outputs)
    start = settings.theta1
    mech.require_full_revolution("a driven check")
    driven_settings = replace(settings, drive="constant-speed", omega1=design.operation.speed,
                              theta1=start)
    free_settings = replace(settings, drive="free")
    kw = {"rtol": rtol, "atol": atol}
    return Verification(
        method=method,
        driven=_run(linkage, design.original, driven_settings, method, **kw),
        free=_run(linkage, design.original, free_settings, method, **kw),
    )
