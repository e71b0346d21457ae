"""Cycle analysis: one crank revolution at constant speed, for any mechanism.

Given a mechanism (:func:`balancer.mechanisms.mechanism_of`) and the operating speed, the
crank turns through ``θ1 = 2π·j/N`` (absolute angles, whatever the reference pose) and the
mechanism's inverse dynamics (:meth:`~balancer.mechanisms.base.Mechanism.inverse_dynamics`)
gives what it does to its frame: the force at every ground point, the normal force and couple
of every slider on a ground guide, the shaking force and moment and the driving torque. Samples
exactly at a singular pose that the smooth motion passes (a four-bar's change points) take the
limits of that motion for the shaking sums and the torque; their individual reactions, which
grow without bound, are NaN and flagged.

Long revolutions are evaluated in chunks that fit the CPU cache, on two threads (numpy runs its
loops without the GIL), writing into preallocated arrays.
"""

from __future__ import annotations

import math
import os
from collections.abc import Iterator, Sequence
from contextlib import contextmanager
from contextvars import ContextVar
from dataclasses import dataclass
from functools import cached_property
from typing import Any

import numpy as np
from numpy.typing import ArrayLike, NDArray

from .columns import Columns, analysis_columns
from .errors import SpecError
from .force_balance import RESIDUAL_FLOOR, force_balance_residual
from .linkage.dynamics import Forces
from .linkage.kinematics import Motion
from .linkage.loads import Reactions, SupportLoad
from .mechanisms import geometry, mechanism_of
from .mechanisms.base import (
    KERNEL_STATES,
    ROUTES,
    Mechanism,
    Route,
    frame_points,
    in_one_plane,
    require_full_revolution,
)
from .model import MechanismModel as Model
from .orders import Order, Whirl, order_bins, order_table, whirls
from .quantities import FRAME_LOADS
from .rounding import speed_text

#: Number of crank angles evaluated at once.
CHUNK = 32768
#: Threads evaluating the chunks of a long cycle.
WORKERS = min(2, os.cpu_count() or 1)
#: Whether the cycle analyses of this thread run their chunks on it alone
#: (:func:`one_thread`).
_ONE_THREAD: ContextVar[bool] = ContextVar("balancer_cycle_one_thread", default=False)


@contextmanager
def one_thread() -> Iterator[None]:
    """Within it, this thread's cycle analyses evaluate their chunks on it alone.

    A sweep's worker runs its points so: its cores are the other workers'.
    """
    token = _ONE_THREAD.set(True)
    try:
        yield
    finally:
        _ONE_THREAD.reset(token)


@dataclass(frozen=True)
class Figure:
    """RMS and maximum magnitude of a quantity over the samples of a cycle (same unit)."""

    rms: float
    max: float

    @classmethod
    def of(cls, values: ArrayLike) -> Figure:
        """Figures of an array of real or complex values (complex: vector magnitudes).

        Values that do not exist (NaN, at a change point) are left out; computed without
        overflow for any finite values.
        """
        values = np.asarray(values).ravel()
        if not values.size:
            return cls(rms=math.nan, max=math.nan)
        if np.iscomplexobj(values):  # by chunks: no copy of a long cycle's magnitudes
            top = max(float(np.max(np.abs(values[i : i + CHUNK])))
                      for i in range(0, values.size, CHUNK))
        else:
            top = float(max(np.max(values), -np.min(values)))
        if math.isnan(top):  # samples that do not exist (NaN, at a change point): left out
            mag = np.abs(values)
            mag = mag[~np.isnan(mag)]
            return cls.of(mag) if mag.size else cls(rms=math.nan, max=math.nan)
        if top == 0 or not math.isfinite(top):
            return cls(rms=top, max=top)
        if 1e-100 < top < 1e100:  # the sum of squares neither overflows nor underflows
            total = float(np.vdot(values, values).real)
            return cls(rms=math.sqrt(total / values.size), max=top)
        total = 0.0
        for i in range(0, values.size, CHUNK):
            scaled = np.abs(values[i : i + CHUNK]) / top
            total += float(np.dot(scaled, scaled))
        return cls(rms=top * math.sqrt(total / values.size), max=top)

    def as_dict(self) -> dict[str, float]:
        """``{"rms": …, "max": …}``."""
        return {"rms": self.rms, "max": self.max}


@dataclass(frozen=True)
class CycleSummary:
    """The figures of a cycle analysis."""

    shaking_force: Figure
    shaking_moment: Figure
    driving_torque: Figure
    rocking_couple: Figure
    ground: dict[str, Figure]
    slider_normal: dict[str, Figure]
    slider_couple: dict[str, Figure]
    mount_torque: Figure | None = None

    @property
    def max_ground_reaction(self) -> float:
        """The largest force on the frame at any one ground point or guide over the cycle, N.

        The magnitudes of the forces at the ground points and the normal forces of the sliders
        on ground guides (what the frame's bearings carry one by one, beside their sum, the
        shaking force); 0 for a mechanism with neither.
        """
        values = [f.max for f in (*self.ground.values(), *self.slider_normal.values())
                  if not math.isnan(f.max)]
        return max(values, default=0.0)

    def as_dict(self) -> dict[str, dict[str, float]]:
        """The frame loads' figures with their JSON names (the rocking couple's: its magnitude).

        Those of :data:`balancer.quantities.FRAME_LOADS` the summary has (an engine's
        ``mount_torque`` too), in its order.
        """
        figures = ((q.key, getattr(self, q.key)) for q in FRAME_LOADS)
        return {key: figure.as_dict() for key, figure in figures if figure is not None}


@dataclass(frozen=True, eq=False)
class CycleAnalysis:
    """One crank revolution at constant speed: what the mechanism does to its frame.

    Attributes
    ----------
    mechanism
        The analysed mechanism.
    speed
        Crank speed, rad/s.
    theta1
        The sampled crank angles, rad.
    reactions
        The results at those angles.
    route
        The inverse-dynamics route used.
    gravity
        ``(gx, gy)`` the figures include, m/s² (``(0, 0)``: none).
    loads
        Whether applied loads are included.
    singular
        Samples at a singular pose of the smooth motion (individual reactions NaN).
    revolutions
        Crank revolutions the samples span: 2 for loads that repeat every two (a four-stroke
        engine's gas force, period 4π), else 1.
    """

    mechanism: Mechanism
    speed: float
    theta1: NDArray[np.float64]
    reactions: Reactions
    route: Route
    gravity: tuple[float, float] = (0.0, 0.0)
    loads: bool = True
    singular: NDArray[np.bool_] | None = None
    revolutions: int = 1

    @cached_property
    def summary(self) -> CycleSummary:
        """Each column's RMS and largest magnitude (computed when first asked)."""
        r = self.reactions
        return CycleSummary(
            shaking_force=Figure.of(r.shaking_force),
            shaking_moment=Figure.of(r.shaking_moment),
            driving_torque=Figure.of(r.driving_torque),
            rocking_couple=Figure.of(r.rocking_couple),
            ground={p: Figure.of(v) for p, v in r.ground.items()},
            slider_normal={k: Figure.of(v) for k, v in r.slider_normal.items()},
            slider_couple={k: Figure.of(v) for k, v in r.slider_couple.items()},
            mount_torque=None if self.mount_torque is None else Figure.of(self.mount_torque),
        )

    def load(self, key: str) -> NDArray[Any]:
        """A frame load by its key (:data:`balancer.quantities.QUANTITIES`), at the samples.

        ``supports``: the supports' loads one after another (:attr:`supports`).
        """
        if key == "supports":
            return np.concatenate([s.force for s in self.supports])
        return np.asarray(getattr(self.reactions, key))

    def __repr__(self) -> str:
        s = self.summary
        cycle = (f" over a cycle of 720° ({self.samples} in all)" if self.revolutions == 2
                 else "")
        return (f"CycleAnalysis({self.mechanism.model.type}, {self.samples_per_revolution} "
                f"angles per revolution{cycle} at {speed_text(self.speed)}: RMS shaking force "
                f"{s.shaking_force.rms:.4g} N, "
                f"shaking moment {s.shaking_moment.rms:.4g} N·m, driving torque "
                f"{s.driving_torque.rms:.4g} N·m)")

    @property
    def linkage(self) -> Model:
        """The mechanism's model (a FourBar, SliderCrank, Linkage or Engine)."""
        return self.mechanism.model

    @cached_property
    def mount_torque(self) -> NDArray[np.float64] | None:
        """An engine's torque about z on its mounts, N·m: shaking moment + driving torque.

        With the load (what the engine drives) off the frame, the mounts carry ``−dH_z/dt``
        less the output torque (DESIGN.md); ``None`` for a mechanism that is not an engine.
        """
        if not self.mechanism.presentation.mount_torque:
            return None
        return self.reactions.shaking_moment + self.reactions.driving_torque

    @cached_property
    def supports(self) -> tuple[SupportLoad, ...]:
        """The loads at the supports that share a ground point's reaction, at the samples.

        An engine's main bearings where its spec places them
        (:attr:`~balancer.mechanisms.base.Mechanism.supports`); none in general.
        """
        supports = self.mechanism.supports
        if supports is None:
            return ()
        return supports.loads(self.motion, self.reactions, loads=self.loads,
                              gravity=self.gravity)

    def support_orders(self, support: SupportLoad) -> list[tuple[float, Whirl]]:
        """A support's load by order of the crank speed (as :attr:`orders`' shaking force)."""
        bins = order_bins(self.samples, self.revolutions)
        return [(float(q), w) for (q, _), w in zip(bins, whirls(support.force,
                                                                  [j for _, j in bins]),
                                                  strict=True)]

    @cached_property
    def motion(self) -> Motion:
        """Kinematics at the sampled angles (computed when first asked for)."""
        with np.errstate(all="ignore"):
            return self.mechanism.motion(self.theta1, self.speed, 0.0)

    @cached_property
    def centre_of_mass_excursion(self) -> float:
        """How far the moving links' total centre of mass strays from its mean place, m.

        The largest distance over the samples from the mean of the sampled positions: zero
        (to rounding) exactly when the design is force-balanced; what a designer can picture
        of an unbalance. Samples at a singular pose are left out.
        """
        with np.errstate(all="ignore"):
            centre = geometry.total_centre_of_mass(self.mechanism, self.motion)
        path = np.asarray(centre, dtype=complex) * np.ones(self.samples)
        path = path[np.isfinite(path)]
        if not path.size:
            return math.nan
        return float(np.max(np.abs(path - path.mean())))

    @cached_property
    def force_balance_residual(self) -> float:
        """How far the design is from shaking-force balance: its conditions' residual.

        Relative: the first moments of mass left over, over those that make them
        (:func:`balancer.force_balance.force_balance_residual`); 0 for a balanced design.
        """
        return force_balance_residual(self.mechanism)

    @property
    def force_balanced(self) -> bool:
        """Whether the design is force-balanced (its residual is rounding)."""
        return self.force_balance_residual <= RESIDUAL_FLOOR

    @cached_property
    def orders(self) -> tuple[Order, ...]:
        """The frame's loads by order of the crank speed (:mod:`balancer.orders`).

        From the equally spaced samples of the cycle; samples at a singular pose carry the
        limits of the smooth motion.
        """
        r = self.reactions
        return order_table(r.shaking_force, r.rocking_couple, r.shaking_moment,
                           r.driving_torque, revolutions=self.revolutions,
                           mount_torque=self.mount_torque)

    def columns(self) -> tuple[list[str], Columns]:
        """The columns of ``analyze --csv``: names and values over the samples.

        See :func:`balancer.columns.analysis_columns`.
        """
        return analysis_columns(self)

    @property
    def samples(self) -> int:
        """Number of sampled crank angles (over all the cycle's revolutions)."""
        return self.theta1.size

    @property
    def samples_per_revolution(self) -> int:
        """Sampled crank angles per revolution (the spec's ``samples``)."""
        return self.theta1.size // self.revolutions

    @property
    def time(self) -> NDArray[np.float64]:
        """Time at each sample from θ1 = 0, s."""
        return self.theta1 / self.speed


def sample_angles(samples: int, revolutions: int = 1) -> NDArray[np.float64]:
    """``θ1 = 2π·k/samples``, ``k = 0 … revolutions·samples − 1``: the cycle's angles, rad."""
    angles = np.arange(samples * revolutions, dtype=float)
    angles *= 2 * np.pi / samples  # in place: no second array of a long cycle's size
    return angles


def cycle_analysis(model: Model | Mechanism, speed: float, samples: int = 360, *,
                   route: Route | None = None, loads: bool = True,
                   gravity: tuple[float, float] = (0.0, 0.0),
                   theta1: NDArray[np.float64] | None = None) -> CycleAnalysis:
    """Analyse one cycle at constant ``speed`` (rad/s), ``samples`` angles per revolution.

    The cycle is one revolution, or two where the loads repeat every two
    (:attr:`~balancer.model.MechanismModel.cycle_revolutions`: a four-stroke engine's gas force).

    Parameters
    ----------
    model
        A mechanism's model (FourBar, SliderCrank, Linkage, Engine) or a :class:`Mechanism`.
    speed
        Crank speed, rad/s.
    samples
        Number of equally spaced angles per revolution from θ1 = 0.
    route
        Inverse-dynamics route (one of :data:`~balancer.mechanisms.base.ROUTES`; default the first).
    loads
        Include applied loads (forces, moments, a slider's gas force).
    gravity
        ``(gx, gy)``, m/s²: the frame then carries the weights too.
    theta1
        Angles to use instead of the equally spaced ones, rad.

    Raises
    ------
    AssemblyError
        If the crank cannot turn a full revolution.
    SpecError
        For an unknown route.
    """
    mech = model if isinstance(model, Mechanism) else mechanism_of(model)
    route = route or ROUTES[0]
    if route not in ROUTES:
        raise SpecError(f"the {mech.model.type} has no such route; choose from "
                        f"{', '.join(ROUTES)}", key="route", value=route)
    require_full_revolution(mech, "a cycle analysis")
    revolutions = mech.model.cycle_revolutions if theta1 is None else 1
    angles = (sample_angles(samples, revolutions) if theta1 is None
              else np.asarray(theta1, dtype=float))
    n = angles.size
    reactions = Reactions.empty(n, frame_points(mech), mech.linkage.ground_sliders,
                                teeth=tuple(g.name for g in mech.linkage.gears))

    compiled = n >= KERNEL_STATES  # a long cycle: its chunks by the compiled program

    def evaluate(theta: NDArray[np.float64], into: Forces | None = None, *,
                 fast: bool = True) -> Forces:
        with np.errstate(all="ignore"):
            return mech.crank_forces(theta, speed, 0.0, route=route, loads=loads,
                                     gravity=gravity, compiled=compiled and fast, into=into)

    def fill(start: int) -> None:
        sl = slice(start, start + CHUNK)
        evaluate(angles[sl], into=reactions.at(sl).forces())  # written into the cycle's

    starts = range(0, n, CHUNK)
    if len(starts) > 1 and WORKERS > 1 and not _ONE_THREAD.get():
        from concurrent.futures import ThreadPoolExecutor  # a long cycle only: 3 ms to import

        pool = ThreadPoolExecutor(WORKERS)
        try:
            list(pool.map(fill, starts))
        finally:  # interrupted (Ctrl-C): the chunks not begun are dropped, not waited for
            pool.shutdown(wait=True, cancel_futures=True)
    else:
        for start in starts:
            fill(start)
    singular = np.zeros(n, bool)
    for limit in mech.limits(angles):
        hit = limit.mask
        # (A few states beside a change point: by the mechanism's own route, which takes the
        # limit best — a four-bar's closed forms, not the compiled general core.)
        parts = [Reactions.of(evaluate(angles[hit] + d, fast=False)) for d in limit.offsets]
        for name in ("shaking_force", "shaking_moment", "driving_torque", "rocking_couple"):
            getattr(reactions, name)[hit] = sum(w * getattr(p, name) for w, p
                                                in zip(limit.weights, parts, strict=True))
        for values in (*reactions.ground.values(), *reactions.slider_normal.values(),
                       *reactions.slider_couple.values()):
            values[hit] = np.nan
        singular |= hit
    return CycleAnalysis(mechanism=mech, speed=speed, theta1=angles, reactions=reactions,
                         route=route, gravity=(gravity[0], gravity[1]), loads=loads,
                         singular=singular, revolutions=revolutions)


#: Largest distance, between two samples, of a drawn curve from the line through them,
#: relative to the span of its panel: about a pixel of a panel 500 pixels high.
DRAWING_TOLERANCE = 2e-3

#: Fewest and most crank angles of a drawn revolution (the spec's ``samples`` if more).
PLOT_SAMPLES = (720, 2**17)

#: A curve whose span is below this fraction of its natural scale (the largest force on the
#: ground, times the linkage's size for a moment) is drawn as rounding: not refined further.
ROUNDING_SPAN = 1e-9


def drawn_analyses(models: Sequence[Model | Mechanism], speed: float, *,
                   samples: int | None = None, least: int = 0,
                   gravity: tuple[float, float] = (0.0, 0.0),
                   tolerance: float = DRAWING_TOLERANCE) -> list[CycleAnalysis]:
    """Revolutions of mechanisms at the same crank angles, sampled finely enough to draw.

    At ``speed`` (rad/s) with ``gravity`` (m/s²), from at least ``least`` and
    :data:`PLOT_SAMPLES`' least crank angles, doubled until every drawn curve
    (:func:`drawn_panels`: the shaking force's tip, the rocking couple's, the shaking moment,
    the driving torque, an engine's mount torque) of every model lies within ``tolerance`` of
    its panel's span from the straight lines between its samples (checked at the midpoints),
    or the most; ``samples`` takes exactly that many.

    Raises
    ------
    AssemblyError
        If a crank cannot turn a full revolution.
    """
    def at(n: int) -> list[CycleAnalysis]:
        return [cycle_analysis(m, speed, n, gravity=gravity) for m in models]

    n = samples or max(least, PLOT_SAMPLES[0])
    coarse = at(n)
    while samples is None and 2 * n <= PLOT_SAMPLES[1]:
        fine = at(2 * n)
        if _drawn_within(fine, tolerance):
            return fine
        coarse, n = fine, 2 * n
    return coarse


def panel_keys(*analyses: CycleAnalysis | None) -> tuple[str, ...]:
    """The panels a figure of these analyses draws (``None`` left out), in the figure's order.

    ``"force"``; ``"couple"`` (the rocking couple) where any of them has links out of the
    crank's plane (a design balanced in several planes beside an original in one: the
    original's couple is the zero it is); ``"moment"``, ``"torque"``; ``"mount"`` (an engine's
    torque on its mounts) where every one of them reports it.
    """
    given = [a for a in analyses if a is not None]
    planes = any(not in_one_plane(a.mechanism) for a in given)
    mounts = bool(given) and all(a.mount_torque is not None for a in given)
    return ("force", *(("couple",) if planes else ()), "moment", "torque",
            *(("mount",) if mounts else ()))


def drawn_panels(analysis: CycleAnalysis, keys: Sequence[str] | None = None
                 ) -> dict[str, NDArray[np.number]]:
    """What the cycle figure draws of an analysis, by panel, over its samples.

    ``keys`` the panels (default :func:`panel_keys` of this analysis alone): the shaking force
    (complex, N), the rocking couple (complex, N·m), the shaking moment, the driving torque and
    an engine's mount torque (N·m).
    """
    r = analysis.reactions
    values: dict[str, NDArray[np.number]] = {
        "force": r.shaking_force, "couple": r.rocking_couple, "moment": r.shaking_moment,
        "torque": r.driving_torque}
    if analysis.mount_torque is not None:
        values["mount"] = analysis.mount_torque
    return {key: values[key] for key in (panel_keys(analysis) if keys is None else keys)}


def natural_scales(analysis: CycleAnalysis) -> dict[str, float]:
    """The scale of each drawn panel (:func:`drawn_panels`) from the loads that make it.

    The largest force on the frame at one ground point or guide (N) for the shaking force,
    times the mechanism's size (m) for a moment (N·m): a panel whose values are below
    :data:`ROUNDING_SPAN` of its scale is rounding, zero for a reader.
    """
    force = analysis.reactions.largest_force()
    moment = force * analysis.mechanism.structure.length_scale()
    return {"force": force, "couple": moment, "moment": moment, "torque": moment,
            "mount": moment}


def _drawn_within(analyses: Sequence[CycleAnalysis], tolerance: float) -> bool:
    """Whether every curve at the even samples is drawn within ``tolerance`` of its panel.

    The odd samples are the midpoints: their distance from the chords of the even ones,
    relative to the panel's span over all the analyses (floored at :data:`ROUNDING_SPAN` of
    its natural scale).
    """
    force_scale = max(a.reactions.largest_force() for a in analyses)
    length = analyses[0].mechanism.structure.length_scale()
    keys = panel_keys(*analyses)
    panels = [drawn_panels(a, keys) for a in analyses]
    for key in keys:
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
