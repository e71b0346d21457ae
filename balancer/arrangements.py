"""Crank arrangements and firing orders searched: every crank, ranked by what it leaves free.

For an engine's cylinders as its spec places them (planes, banks, which share a crank pin:
:meth:`~.model.Engine.throws`), every assignment of pin phases to the throws whose cylinders can
fire evenly — the firings ``Θ/n`` apart over the working cycle ``Θ`` (720° for a four-stroke,
360° for a two-stroke), each cylinder at its top dead centre ``bank − phase`` (or, in a
four-stroke, 360° later) — and every firing order each allows, cylinder 1 first. Throw 1 keeps
its phase (the crank's angle is a convention); the others take the phases that put their first
cylinder's top dead centre on a firing, ``bank − s − j·Θ/n`` (``s`` cylinder 1's). With a
``step`` the firing may be uneven: every throw's phase a multiple of ``step`` from throw 1's,
and every firing that fits in the working cycle by the engine's own rule
(:meth:`~.mechanisms.engine.model.Engine.firing_angles`: the order's first cylinder at its first
top dead centre at or after θ1 = 0, each next one at its own next top dead centre after the
previous firing), each by one order that fires it — cylinder 1 first where one does — the even
ones among them.

Each candidate is judged by what it leaves free, from its cylinders' inertial loads alone (rods
and pistons, not the crankshaft's own masses, which the designer sizes after): a cylinder with
its pin at phase ``φ`` has its phase-0 phasors turned, order ``n``'s forward by ``e^{i·n·φ}``
and backward by ``e^{−i·n·φ}`` (:mod:`balancer.phasors`: its load is the phase-0 one at
``θ1 + φ``), and its couple is ``i·z`` times its force. Counterweights on the crank turn with it:
they can take the primary's forward whirl (force and couple) and nothing else, so the ranking is
by, in turn, the primary force's and couple's backward whirls, the secondary force and couple
(both whirls), each to the rounding of the engine's scale; then by the driving torque's
fluctuation (below); then by the firings that follow one another in the same half of the crank
(fewer spreads the load along it: the in-line six's 1-5-3-6-2-4 alternates); then by the firing
order. The classic answers come out on top by themselves (the tests hold them): the flat-plane
four, the in-line six, the cross-plane V8.

The driving torque comes from the firing: each cylinder's torque at the operating speed,
inertial and from its gas (where the spec gives ``[gas]``), is its own at phase 0 firing at its
own top dead centre, shifted along the working cycle by where its firing falls, ``s = f0 − f``
(its harmonic ``h`` turned by ``e^{i·h·2π·s/Θ}``: exact, the samples raised to a multiple
that every bank and pin phase falls on, so that ``s`` is a whole number of them). Each
candidate reports the torque's orders up to :data:`TORQUE_ORDERS` (a four-stroke's half orders
from ½) and ranks by its energy swing ``ΔE`` (the largest less the
least of ``∫ (T − T̄) dθ`` over the working cycle, the turning-moment diagram's: what a flywheel
must hold for a given speed fluctuation, :mod:`balancer.speed_fluctuation`), the integral of
the torque's trigonometric interpolant evaluated :data:`SWING_REFINE` times finer than the
samples. It is the same for every even firing of cylinders of one size; it ranks uneven ones.
"""

from __future__ import annotations

import functools
import itertools
import math
from collections.abc import Iterator
from dataclasses import dataclass, replace
from fractions import Fraction
from typing import TYPE_CHECKING

import numpy as np
from numpy.typing import NDArray

from .cycle import cycle_analysis
from .errors import SpecError
from .mechanisms import mechanism_of
from .mechanisms.engine.model import Crankshaft, Engine
from .phasors import phasors

if TYPE_CHECKING:  # (a balancing's result, where search --balance asks for one)
    from .balance.result import BalanceResult

#: Figures below this share of the engine's scale are rounding (zero) in the ranking.
ROUNDING = 1e-9
#: Most cylinders a search takes (the firing orders grow as the factorial).
MOST_CYLINDERS = 12
#: Most candidates a search judges.
MOST_CANDIDATES = 200_000
#: Cranks judged before the candidates they make project the whole search's count.
PROJECT_AFTER = 16
#: The driving torque's orders a search reports, up to this one.
TORQUE_ORDERS = 12
#: The energy swing's grid: this many times finer than the samples.
SWING_REFINE = 4


@dataclass(frozen=True)
class Arrangement:
    """One crank and firing order, and what it leaves free.

    Attributes
    ----------
    phases
        Each cylinder's crank pin phase, degrees in [0, 360), cylinder 1 first.
    firing_order
        The cylinders in the order they fire, as the spec's ``firing_order`` takes it:
        cylinder 1 first, but for an uneven firing that only an order from another cylinder
        fires (:func:`search` with a ``step``).
    free
        What crank counterweights cannot take, N and N·m: ``force_1_backward``,
        ``couple_1_backward``, ``force_2``, ``couple_2`` (both whirls' magnitudes summed).
    counterweights
        What they can: ``force_1_forward``, ``couple_1_forward``, N and N·m.
    same_half
        Firings that follow one another in the same half of the crank (cyclically).
    intervals
        The crank angles from each firing to the next, in the firing order, degrees (the
        last to the first's next firing; all ``Θ/n`` where the firing is even).
    torque
        The driving torque's orders at the operating speed, inertial and from the gas: each
        ``(order, amplitude)`` up to :data:`TORQUE_ORDERS`, N·m.
    energy_swing
        ``ΔE``, J: the largest less the least of the torque's integral about its mean over
        the working cycle (module docstring).
    rank
        Its place, from 1; equal for arrangements the ranking cannot tell apart (the same
        figures to rounding and the same ``same_half``).
    balanced
        The engine with it balanced as the spec's ``[balance]`` asks (``search --balance``),
        or ``None``.
    """

    phases: tuple[float, ...]
    firing_order: tuple[int, ...]
    free: dict[str, float]
    counterweights: dict[str, float]
    same_half: int
    intervals: tuple[float, ...] = ()
    torque: tuple[tuple[float, float], ...] = ()
    energy_swing: float = 0.0
    rank: int = 0
    balanced: BalanceResult | None = None

    def lowest_torque_order(self, rounding: float) -> float | None:
        """The lowest order of the driving torque above ``rounding`` (N·m), or ``None``."""
        return next((order for order, amplitude in self.torque if amplitude > rounding), None)

    def as_dict(self) -> dict[str, object]:
        """An entry of ``search --json``'s ``arrangements``."""
        out: dict[str, object] = {
            "rank": self.rank, "phases_deg": list(self.phases),
            "firing_order": list(self.firing_order), **self.free, **self.counterweights,
            "same_half": self.same_half, "firing_intervals_deg": list(self.intervals),
            "energy_swing": self.energy_swing,
            "torque_orders": [{"order": order, "amplitude": amplitude}
                              for order, amplitude in self.torque]}
        if self.balanced is not None:
            b = self.balanced
            out["balanced"] = {"status": str(b.status), "objective": b.objective,
                               "lower_bound": b.lower_bound,
                               "terms": b.term_rms(b.after)}
        return out


@dataclass(frozen=True)
class Search:
    """Every even-firing crank of an engine, ranked (best first).

    Attributes
    ----------
    arrangements
        Ranked, best first.
    speed
        The speed the loads are at, rad/s.
    scale
        The engine's scale of force, N (a cylinder's reciprocating ``m·r·ω²``), by which
        figures are rounding.
    torque_scale
        Its scale of torque, N·m: the largest order of one cylinder's driving torque (and of
        energy, J: per radian).
    step
        The phases' step of an uneven search, degrees, or ``None`` (even firing only).
    """

    arrangements: tuple[Arrangement, ...]
    speed: float
    scale: float
    torque_scale: float = 1.0
    step: float | None = None


def _step(cycle: int, n: int) -> Fraction:
    """The firing interval ``cycle/n``, degrees."""
    return Fraction(cycle, n)


def _firing_orders(tdc: list[Fraction], start: Fraction, interval: Fraction, cycle: int
                   ) -> Iterator[tuple[int, ...]]:
    """Each order in which the cylinders (TDCs ``tdc``, degrees) fire evenly from ``start``.

    Cylinder 1 in the first slot; each other cylinder in a slot ``start + j·interval`` its top
    dead centre meets (mod ``cycle``; a four-stroke's cylinder at its TDC or 360° later).
    """
    n = len(tdc)
    options: list[list[int]] = []
    for t in tdc:
        slots = []
        for extra in (0, 360) if cycle == 720 else (0,):
            position = (t + extra - start) % cycle
            if position % interval == 0:
                slots.append(int(position / interval))
        options.append(sorted(set(slots)))
    if 0 not in options[0]:
        return
    taken = [0] * n
    order = [0] * n

    def place(c: int) -> Iterator[tuple[int, ...]]:
        if c == n:
            yield tuple(order)
            return
        for slot in options[c]:
            if not taken[slot]:
                taken[slot] = 1
                order[slot] = c + 1
                yield from place(c + 1)
                taken[slot] = 0

    taken[0] = 1
    order[0] = 1
    yield from place(1)


def search(engine: Engine, speed: float, top: int | None = None, *,
           step: float | None = None, samples: int = 360) -> Search:
    """Every crank of ``engine``'s cylinders and its firing orders, ranked.

    See the module docstring: the even-firing cranks, or with ``step`` (degrees, dividing
    360) every crank whose throws' phases are multiples of it from throw 1's and every firing
    order that fits in the working cycle. ``top``: keep the best ``top`` only. ``samples``:
    angles per revolution of each cylinder's driving torque.

    Raises
    ------
    SpecError
        For more than :data:`MOST_CYLINDERS` cylinders, a step that does not divide 360°, too
        many candidates, no crank at all, or an engine of several crankshafts.
    """
    if engine.crankshafts:
        raise SpecError("a search arranges the pins of one crankshaft: an engine with geared "
                        "crankshafts is not searched (their pins' phases are the spec's)",
                        key="crankshafts")
    cylinders = engine.cylinders
    n = len(cylinders)
    if n > MOST_CYLINDERS:
        raise SpecError(f"a search takes at most {MOST_CYLINDERS} cylinders (got {n})",
                        key="mechanism.cylinders")
    cycle = 720 if engine.strokes == 4 else 360
    interval = _step(cycle, n)
    throws = _pins(engine)
    banks = [Fraction(c.bank_deg).limit_denominator(10**6) for c in cylinders]
    first_phase = Fraction(cylinders[throws[0][0]].phase_deg).limit_denominator(10**6)
    start = (banks[0] - first_phase) % 360  # cylinder 1's TDC (throw 1's phase kept)
    if step is None:
        candidates = [[first_phase]] + [
            sorted({(banks[t[0]] - start - j * interval) % 360 for j in range(n)})
            for t in throws[1:]]
    else:
        grid = _grid(step)
        candidates = [[first_phase]] + [
            sorted({(first_phase + j * grid) % 360 for j in range(int(360 / grid))})
            for _ in throws[1:]]
    cranks = math.prod(len(c) for c in candidates)
    if cranks > MOST_CANDIDATES:
        raise SpecError("too many cranks to judge: fewer throws, cylinders sharing pins"
                        + ("" if step is None else ", or a coarser step"),
                        key="mechanism.cylinders" if step is None else "--step")
    # The torque's samples: every shift of a cylinder's torque (its bank, its pin's phase, its
    # firing) a whole number of them, so that shifting its harmonics is exact and candidates
    # alike come out alike (the spec's samples raised to the next multiple of 360°/g, g the
    # angles' greatest common divisor; as they are where that would take eight times more).
    g = functools.reduce(_gcd, [Fraction(360), *banks, first_phase,
                                interval if step is None else _grid(step)])
    whole = int(360 / g)
    if whole <= 8 * samples:
        samples = -(-samples // whole) * whole
    # each cylinder's phasors at phase 0: its rod and piston alone
    bare = Crankshaft(inertia=engine.crankshaft.inertia)
    unit = []
    for c in cylinders:
        one = replace(engine, cylinders=(replace(c, phase_deg=0.0),), crankshaft=bare,
                      balance_shafts=(), firing_order=None, gas=None, main_bearings=())
        p = phasors(mechanism_of(one), speed, (1, 2))
        unit.append({order: p.total_force(order) for order in (1, 2)})
    torques = _unit_torques(engine, bare, speed, samples, cycle)
    torque_scale = float(np.max(2 * np.abs(torques.spectra[:, 1:]), initial=0.0)) or 1.0
    first = cylinders[0]
    rod = engine.rod
    scale = (engine.piston + rod.mass) * first.crank * speed**2 or 1.0
    zs = [c.z for c in cylinders]
    middle = (min(zs) + max(zs)) / 2
    half = [0 if z < middle else 1 for z in zs]
    out: list[Arrangement] = []
    for done, choice in enumerate(itertools.product(*candidates), start=1):
        phases = [Fraction(0)] * n
        for t, phase in zip(throws, choice, strict=True):
            for k in t:
                phases[k] = phase
        tdc = [(banks[k] - phases[k]) % 360 for k in range(n)]
        fired = ([(order, _firings(tdc, order))
                  for order in _firing_orders(tdc, start, interval, cycle)] if step is None
                 else list(_uneven_orders(tdc, cycle)))
        if not fired:
            continue
        free, taken = _judge(unit, [float(p) for p in phases], zs)
        orders = [order for order, _ in fired]
        firings = [firing for _, firing in fired]
        spectra = torques.of(firings)
        swings = torques.swings(spectra)
        for order, firing, spectrum, swing in zip(orders, firings, spectra, swings,
                                                  strict=True):
            same = sum(half[order[i] - 1] == half[order[(i + 1) % n] - 1] for i in range(n))
            angles = [firing[k - 1] for k in order] + [firing[order[0] - 1] + cycle]
            out.append(Arrangement(
                phases=tuple(float(p) for p in phases), firing_order=order,
                free=free, counterweights=taken, same_half=same,
                intervals=tuple(float(b - a) for a, b in itertools.pairwise(angles)),
                torque=tuple((torques.order(h), float(2 * abs(spectrum[h])))
                             for h in range(1, torques.highest + 1)),
                energy_swing=float(swing)))
        # (refused as soon as the cranks judged so far say the whole would be too many)
        projected = len(out) * cranks / done if done >= PROJECT_AFTER else len(out)
        if projected > MOST_CANDIDATES:
            raise SpecError(f"too many cranks and firing orders to judge (about {projected:.3g}"
                            f" from the first {done} of {cranks} cranks): a coarser step",
                            key="--step")
    if not out:
        raise SpecError("no crank of these cylinders fires evenly (their banks and the working "
                        "cycle leave none)" if step is None else
                        "no crank on this step fires every cylinder within the working cycle",
                        key="mechanism.cylinders" if step is None else "--step")
    length = max(zs) - min(zs) or first.crank

    def key(a: Arrangement) -> tuple[object, ...]:
        figures = [a.free["force_1_backward"] / scale, a.free["couple_1_backward"] / (
            scale * length), a.free["force_2"] / scale, a.free["couple_2"] / (scale * length),
            a.energy_swing / torque_scale]
        return (*(0 if f <= ROUNDING else round(f, 9) for f in figures), a.same_half,
                a.firing_order, a.phases)

    ranked = sorted(out, key=key)
    places: list[Arrangement] = []
    for i, a in enumerate(ranked):
        tied = i and key(a)[:6] == key(ranked[i - 1])[:6]
        places.append(replace(a, rank=places[-1].rank if tied else i + 1))
    return Search(arrangements=tuple(places[:top] if top else places), speed=speed,
                  scale=scale, torque_scale=torque_scale,
                  step=None if step is None else float(step))


def _gcd(a: Fraction, b: Fraction) -> Fraction:
    """The greatest common divisor of two rational angles (0 with 0: the other)."""
    d = a.denominator * b.denominator // math.gcd(a.denominator, b.denominator)
    return Fraction(math.gcd(int(a * d), int(b * d)), d)


def _grid(step: float) -> Fraction:
    """An uneven search's step of the pins' phases, degrees: a whole fraction of 360°."""
    if not math.isfinite(step):
        raise SpecError("the pins' phases' step must be a number of degrees that divides 360°",
                        key="--step", value=step)
    grid = Fraction(step).limit_denominator(10**6)
    if not (0 < grid <= 360 and (360 / grid).denominator == 1):
        raise SpecError("the pins' phases' step must divide 360° a whole number of times "
                        "(e.g. 90, 60, 45, 30)", key="--step", value=step)
    return grid


def _firings(tdc: list[Fraction], order: tuple[int, ...]) -> list[Fraction]:
    """Each cylinder's firing angle, degrees, by cylinder, for the firing ``order``.

    The engine's rule (:meth:`~.mechanisms.engine.model.Engine.firing_angles`): the first at
    its first top dead centre at or after 0, each next one at its own next top dead centre
    (``tdc`` mod 360) after the previous firing.
    """
    out = [Fraction(0)] * len(tdc)
    previous: Fraction | None = None
    for k in order:
        angle = tdc[k - 1] if previous is None else _next_after(tdc[k - 1], previous)
        out[k - 1] = angle
        previous = angle
    return out


def _next_after(tdc: Fraction, previous: Fraction) -> Fraction:
    """The first angle after ``previous`` at which a top dead centre ``tdc`` (mod 360) falls."""
    angle = tdc + 360 * math.floor((previous - tdc) / 360)
    while angle <= previous:
        angle += 360
    return angle


def _uneven_orders(tdc: list[Fraction], cycle: int
                   ) -> Iterator[tuple[tuple[int, ...], list[Fraction]]]:
    """Each firing that fits in the working cycle ``cycle``: an order, and its angles.

    The firing angles by cylinder as :func:`_firings` gives them. By its rule (the first at its
    first top dead centre, each next one at its next top dead centre after the previous
    firing, all within ``cycle`` of the first), from every cylinder first: an order from
    another cylinder can fire a pattern no order from cylinder 1 fires (a cylinder at the later
    of its two top dead centres while the earlier one follows the previous firing too). Orders
    that fire the cylinders the same angles apart (the same pattern, shifted) are one engine:
    the first found is kept, cylinder 1 first where one order from it fires the pattern.
    """
    seen: set[tuple[Fraction, ...]] = set()
    for first in range(1, len(tdc) + 1):
        for order in _orders_from(tdc, cycle, first):
            firing = _firings(tdc, order)
            pattern = tuple((f - firing[0]) % cycle for f in firing)
            if pattern not in seen:
                seen.add(pattern)
                yield order, firing


def _orders_from(tdc: list[Fraction], cycle: int, first: int) -> Iterator[tuple[int, ...]]:
    """Each firing order, cylinder ``first`` first, whose firings fit in the working cycle."""
    n = len(tdc)
    start = tdc[first - 1]
    order = [first]
    used = [k == first - 1 for k in range(n)]

    def place(previous: Fraction) -> Iterator[tuple[int, ...]]:
        if len(order) == n:
            yield tuple(order)
            return
        for k in range(n):
            if used[k]:
                continue
            angle = _next_after(tdc[k], previous)
            if angle - start >= cycle:
                continue
            used[k] = True
            order.append(k + 1)
            yield from place(angle)
            order.pop()
            used[k] = False

    yield from place(start)


@dataclass(frozen=True, eq=False)
class _Torques:
    """Each cylinder's driving torque at phase 0, as harmonics of the working cycle.

    ``spectra[k, h]``: cylinder ``k``'s harmonic ``h`` of its ``N`` samples over the working
    cycle (``τ(θ) = Σ c_h·e^{i·h·2π·θ/Θ}``, the real signal's one-sided coefficients: order
    ``h·360/Θ``, amplitude ``2·|c_h|``); ``fires[k]`` its firing angle at phase 0, degrees;
    ``cycle`` Θ, degrees.
    """

    spectra: NDArray[np.complex128]
    fires: tuple[float, ...]
    cycle: int
    samples: int

    @property
    def highest(self) -> int:
        """The harmonic of order :data:`TORQUE_ORDERS`."""
        return min(TORQUE_ORDERS * self.cycle // 360, self.spectra.shape[1] - 1)

    def swings(self, spectra: NDArray[np.complex128]) -> NDArray[np.float64]:
        """``ΔE`` of each of ``spectra`` (rows of harmonics), J.

        ``E(θ) = Σ_{h≥1} 2·Re(c_h·Θ/(i·2π·h)·e^{i·h·2π·θ/Θ})`` (Θ in radians; the Nyquist
        term of an even count of samples integrates to a sine that vanishes on them: none, as
        :meth:`balancer.speed_fluctuation.CrankEnergy.work` has it) on a grid
        :data:`SWING_REFINE` times finer than the samples; its largest less its least.
        """
        h = np.arange(1, spectra.shape[1])
        theta = math.radians(self.cycle)
        fine = self.samples * SWING_REFINE
        padded = np.zeros((spectra.shape[0], fine // 2 + 1), complex)
        padded[:, 1 : h.size + 1] = spectra[:, 1:] * theta / (2j * math.pi * h) * fine
        if self.samples % 2 == 0:
            padded[:, self.samples // 2] = 0.0
        energy = np.fft.irfft(padded, fine, axis=1)
        return np.asarray(energy.max(axis=1) - energy.min(axis=1))

    def order(self, h: int) -> float:
        """The order of harmonic ``h``."""
        return h * 360 / self.cycle

    def of(self, firings: list[list[Fraction]]) -> NDArray[np.complex128]:
        """The engine's torque harmonics for each candidate's firing angles, ``(C, H + 1)``.

        Each cylinder's own shifted by ``s = f0 − f`` (its harmonic ``h`` turned by
        ``e^{i·h·2π·s/Θ}``) and summed.
        """
        shifts = np.array([[(f0 - float(f)) % self.cycle for f0, f in zip(
            self.fires, firing, strict=True)] for firing in firings])
        h = np.arange(self.spectra.shape[1])
        turns = np.exp(2j * np.pi * shifts[:, :, None] * h / self.cycle)
        return np.einsum("ckh,kh->ch", turns, self.spectra)


def _unit_torques(engine: Engine, bare: Crankshaft, speed: float, samples: int,
                  cycle: int) -> _Torques:
    """Each cylinder's driving torque at phase 0 (its rod and piston, and its gas), analysed.

    The cycle analysis at constant ``speed`` of the cylinder alone on the bare crankshaft, in
    its plane at bank 0, firing at its first top dead centre (where the spec gives ``[gas]``),
    over the working cycle (a revolution's torque repeated where it has no gas); once for each
    cylinder of another size. The torque about the crank's axis does not see the plane, and a
    bank ``b`` turns the cylinder about the axis: its torque is bank 0's at ``θ − b``, firing at
    ``b`` (mod 360°), its harmonic ``h`` turned by ``e^{−i·h·2π·b/Θ}``.
    """
    spectra, fires = [], []
    analysed: dict[object, NDArray[np.complex128]] = {}
    for c in engine.cylinders:
        upright = replace(c, phase_deg=0.0, bank_deg=0.0, z=0.0)
        if upright not in analysed:
            one = replace(engine, cylinders=(upright,), crankshaft=bare, balance_shafts=(),
                          main_bearings=(), firing_order=None if engine.gas is None else (1,))
            analysis = cycle_analysis(one, speed, samples)
            torque = np.asarray(analysis.reactions.driving_torque, float)
            torque = np.tile(torque, cycle // (360 * analysis.revolutions))
            analysed[upright] = np.fft.rfft(torque) / torque.size
        bank = float(Fraction(c.bank_deg).limit_denominator(10**6) % 360)
        h = np.arange(analysed[upright].size)
        spectra.append(analysed[upright] * np.exp(-2j * np.pi * h * bank / cycle))
        fires.append(bank)
    return _Torques(spectra=np.array(spectra), fires=tuple(fires), cycle=cycle,
                    samples=samples * cycle // 360)


def _pins(engine: Engine) -> list[tuple[int, ...]]:
    """The crank pins: each a tuple of cylinder indices, in the order of their first.

    Cylinders side by side along the crank in other banks with the same phase in the spec
    share one (a V's pair); a cylinder of an in-line bank has its own.
    """
    cylinders = engine.cylinders
    order = sorted(range(len(cylinders)), key=lambda i: (cylinders[i].z, i))
    pins: list[list[int]] = []
    for i in order:
        c = cylinders[i]
        if pins:
            last = cylinders[pins[-1][-1]]
            same = abs((c.phase_deg - last.phase_deg + 180.0) % 360.0 - 180.0) <= 1e-9
            banks = {cylinders[k].bank_deg % 360.0 for k in pins[-1]}
            if same and c.bank_deg % 360.0 not in banks:
                pins[-1].append(i)
                continue
        pins.append([i])
    return sorted((tuple(p) for p in pins), key=min)


def _judge(unit: list[dict[int, tuple[complex, complex]]], phases: list[float],
           zs: list[float]) -> tuple[dict[str, float], dict[str, float]]:
    """What the cylinders at ``phases`` (degrees) leave free and what counterweights take."""
    sums: dict[tuple[int, str], complex] = {}
    for u, phase, z in zip(unit, phases, zs, strict=True):
        for order in (1, 2):
            forward, backward = u[order]
            turn = complex(math.cos(math.radians(order * phase)),
                           math.sin(math.radians(order * phase)))
            f, b = forward * turn, backward * turn.conjugate()
            for what, value in (("ff", f), ("fb", b), ("cf", 1j * z * f), ("cb", 1j * z * b)):
                sums[(order, what)] = sums.get((order, what), 0j) + value
    free = {"force_1_backward": abs(sums[(1, "fb")]), "couple_1_backward": abs(sums[(1, "cb")]),
            "force_2": abs(sums[(2, "ff")]) + abs(sums[(2, "fb")]),
            "couple_2": abs(sums[(2, "cf")]) + abs(sums[(2, "cb")])}
    taken = {"force_1_forward": abs(sums[(1, "ff")]), "couple_1_forward": abs(sums[(1, "cf")])}
    return free, taken


__all__ = ["Arrangement", "Search", "search"]
