"""The least flywheel for a required speed fluctuation, from the machine's exact energy balance.

A one-input mechanism with a flywheel of inertia ``I_f`` on its crank, running under a constant
torque ``T_c`` that takes (an engine's load) or gives (a machine's motor) the mean work of its
applied loads, moves by

    (I_f + J(θ))·θ̈ + ½·J'(θ)·θ̇² = Q(θ) + T_c,        T_c = −Q̄,

with ``J(θ)`` the mechanism's inertia seen by the crank (every link, counter-rotor and geared
rotor), ``Q(θ)`` the generalised force of its applied loads (gas, springs, weights) and ``Q̄`` its
mean over the cycle. The three are the inverse dynamics' driving torque at three crank states
(the motor's torque is ``T = J·α + ½·J'·ω² − Q``):

    T(θ, 0, 0) = −Q,    T(θ, 0, 1) − T(θ, 0, 0) = J,    T(θ, 1, 0) − T(θ, 0, 0) = ½·J',

and a fourth, ``T(θ, 2, 0)``, checks that no load depends on the speed. Multiplied by ``θ̇`` the
equation is exact energy: ``½·(I_f + J(θ))·ω(θ)² = E0 + W(θ)``, ``W(θ) = ∫₀^θ (Q − Q̄) dθ``
(periodic), so that over the cycle

    ω(θ) = √(2·(E0 + W(θ)) / (I_f + J(θ))),

``E0`` chosen so that the mean speed (the cycle's angle over its time, ``Θ / ∫ dθ/ω``) is the
operating speed. The speed fluctuation ``δ = (ω_max − ω_min)/ω_mean`` falls as ``I_f`` grows;
:func:`flywheel` finds the least ``I_f`` with ``δ`` at most the required one by root finding on
this exact ``δ(I_f)``, beside the classical estimate ``ΔE/(δ·ω²) − J̄`` of the turning-moment
diagram (``ΔE`` the energy swing of the crank's torque at the constant operating speed,
``Q − ½·J'·ω²``, about its mean: ``max − min`` of ``W(θ) − ½·ω²·(J(θ) − J(0))``; ``J̄`` the mean
of ``J``), which treats the inertia as constant and ``ω_mean`` as ``(ω_max + ω_min)/2``.

``W`` is the integral of the trigonometric interpolant of the sampled ``Q − Q̄`` (exact for a
band-limited load, spectrally accurate for a smooth one), and ``W``, ``J`` are evaluated on a
grid :data:`REFINE` times finer by the same interpolation, so that the extremes of ``ω`` are not
limited by the samples' spacing.
"""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import dataclass
from functools import cached_property

import numpy as np
from numpy.typing import NDArray

from .errors import SolverError, SpecError
from .mechanisms.base import Mechanism

#: The grid ``W`` and ``J`` are evaluated on for the extremes of ``ω``: this many times finer
#: than the samples (by trigonometric interpolation).
REFINE = 16
#: A load that depends on the speed: its share of the torque's scale at which the energy balance
#: above no longer holds (the driving torque at twice the speed is not ``4·½J' − Q``).
SPEED_DEPENDENT = 1e-9
#: The root finders' relative tolerance (on ``E0`` and on ``I_f``).
ROOT_TOLERANCE = 1e-13


@dataclass(frozen=True)
class Flywheel:
    """The least flywheel for a speed fluctuation, and the energy figures it comes from.

    Attributes
    ----------
    fluctuation
        The required ``δ = (ω_max − ω_min)/ω_mean``.
    speed
        The mean speed, rad/s.
    inertia
        The least inertia to add on the crank, kg·m² (0: the mechanism alone meets ``δ``).
    energy_swing
        ``ΔE``, J: the turning-moment diagram's energy swing at the operating speed (its
        torque ``Q − ½·J'·ω²`` about its mean, integrated: largest less least).
    mean_torque
        ``Q̄``, N·m: the applied loads' mean torque on the crank (an engine's mean indicated
        torque; what ``T_c`` takes away).
    mechanism_inertia
        ``J`` over the cycle, kg·m²: its least, mean and largest.
    classical
        The classical estimate ``ΔE/(δ·ω²) − J̄``, kg·m² (it may be negative).
    fluctuation_without
        ``δ`` of the mechanism alone (no flywheel); ``inf`` where it cannot run at that mean
        speed (it stops within its cycle).
    speeds
        ``ω_min`` and ``ω_max`` with the flywheel, rad/s.
    """

    fluctuation: float
    speed: float
    inertia: float
    energy_swing: float
    mean_torque: float
    mechanism_inertia: tuple[float, float, float]
    classical: float
    fluctuation_without: float
    speeds: tuple[float, float]

    def as_dict(self) -> dict[str, object]:
        """The ``flywheel`` object of ``analyze --json``."""
        return {"fluctuation": self.fluctuation, "inertia": self.inertia,
                "energy_swing": self.energy_swing, "mean_torque": self.mean_torque,
                "mechanism_inertia": dict(zip(("min", "mean", "max"), self.mechanism_inertia,
                                              strict=True)),
                "classical_inertia": self.classical,
                "fluctuation_without": (None if math.isinf(self.fluctuation_without)
                                        else self.fluctuation_without),
                "speed_min": self.speeds[0], "speed_max": self.speeds[1]}


@dataclass(frozen=True, eq=False)
class CrankEnergy:
    """``J``, ``½·J'`` and ``Q`` over a cycle's crank angles (see the module docstring).

    Attributes
    ----------
    theta
        The crank angles, rad: equally spaced over the cycle from 0.
    inertia
        ``J(θ)``, kg·m².
    half_slope
        ``½·dJ/dθ``, kg·m².
    load
        ``Q(θ)``, N·m.
    cycle
        The cycle's angle, rad (``2π`` times its revolutions).
    """

    theta: NDArray[np.float64]
    inertia: NDArray[np.float64]
    half_slope: NDArray[np.float64]
    load: NDArray[np.float64]
    cycle: float

    @classmethod
    def of(cls, mech: Mechanism, theta: NDArray[np.float64], cycle: float,
           gravity: tuple[float, float] = (0.0, 0.0)) -> CrankEnergy:
        """From the inverse dynamics at four crank states per angle (loads included).

        Raises
        ------
        SpecError
            If a load depends on the crank's speed (the energy balance needs it not to).
        """
        def torque(omega: float, alpha: float) -> NDArray[np.float64]:
            with np.errstate(all="ignore"):
                f = mech.crank_forces(theta, omega, alpha, loads=True, gravity=gravity)
            return np.asarray(f.driving_torque, dtype=float)[:, 0]

        rest, pushed, moving, faster = (torque(0.0, 0.0), torque(0.0, 1.0), torque(1.0, 0.0),
                                        torque(2.0, 0.0))
        inertia, half_slope = pushed - rest, moving - rest
        scale = float(np.max(np.abs(np.concatenate([rest, inertia, half_slope])), initial=0.0))
        if np.max(np.abs(faster - rest - 4 * half_slope), initial=0.0) > SPEED_DEPENDENT * max(
                scale, 1e-300) * 4:
            raise SpecError("a load depends on the crank's speed: the flywheel's energy balance "
                            "needs loads of the crank's angle alone", key="operation."
                            "speed_fluctuation")
        return cls(theta=theta, inertia=inertia, half_slope=half_slope, load=-rest,
                   cycle=cycle)

    @classmethod
    def over_cycle(cls, mech: Mechanism, samples: int, gravity: tuple[float, float] = (0.0, 0.0)
                   ) -> CrankEnergy:
        """:meth:`of` over the mechanism's cycle.

        Its model's :attr:`~balancer.model.MechanismModel.cycle_revolutions`, at ``samples``
        equally spaced angles per revolution from 0.
        """
        revolutions = mech.model.cycle_revolutions
        theta = np.arange(samples * revolutions, dtype=float) * (2 * math.pi / samples)
        return cls.of(mech, theta, 2 * math.pi * revolutions, gravity)

    @property
    def mean_load(self) -> float:
        """``Q̄``, N·m."""
        return float(np.mean(self.load))

    @cached_property
    def _fine(self) -> dict[tuple[str, int], NDArray[np.float64]]:
        """:meth:`work` and :meth:`inertia_on` by grid, each computed once.

        The root finders ask for them at every step.
        """
        return {}

    def work(self, refine: int = 1) -> NDArray[np.float64]:
        """``W(θ) = ∫₀^θ (Q − Q̄) dθ`` on the grid ``refine`` times finer, J (read only).

        The integral of ``Q``'s trigonometric interpolant (its mean term left out).
        """
        if ("work", refine) in self._fine:
            return self._fine[("work", refine)]
        n = self.load.size
        coefficients = np.fft.rfft(self.load - self.mean_load)
        k = np.arange(coefficients.size) * (2 * math.pi / self.cycle)
        integral = np.zeros_like(coefficients)
        integral[1:] = coefficients[1:] / (1j * k[1:])
        if n % 2 == 0:  # the Nyquist term of a real sequence integrates to a sine: none
            integral[-1] = 0.0
        values = _interpolated(integral, n, refine)
        out = self._fine[("work", refine)] = values - values[0]
        return out

    def inertia_on(self, refine: int = 1) -> NDArray[np.float64]:
        """``J(θ)`` on the grid ``refine`` times finer, kg·m² (read only)."""
        if ("inertia", refine) not in self._fine:
            self._fine[("inertia", refine)] = _interpolated(np.fft.rfft(self.inertia),
                                                            self.inertia.size, refine)
        return self._fine[("inertia", refine)]


def _interpolated(coefficients: NDArray[np.complex128], n: int, refine: int
                  ) -> NDArray[np.float64]:
    """The trigonometric interpolant of ``n`` samples (their ``rfft``) on ``refine·n`` points."""
    m = n * refine
    padded = np.zeros(m // 2 + 1, complex)
    padded[: coefficients.size] = coefficients
    if n % 2 == 0 and refine > 1:  # the Nyquist term splits between ±n/2
        padded[n // 2] *= 0.5
    return np.fft.irfft(padded, m) * refine


def speeds(energy: CrankEnergy, added: float, speed: float, refine: int = REFINE
           ) -> NDArray[np.float64]:
    """``ω(θ)`` over the cycle with ``added`` inertia on the crank, mean ``speed``, rad/s.

    On the grid ``refine`` times finer than the samples; ``E0`` by root finding on the mean
    speed (the cycle's angle over its time). The sign of ``speed`` is the turning's.
    """
    work = energy.work(refine)
    total = energy.inertia_on(refine) + added
    if np.min(total) <= 0:
        raise SolverError("the mechanism's inertia seen by the crank is not positive over the "
                          "cycle: no speed fluctuation can be computed")
    target = abs(speed)

    def mean(e0: float) -> float:
        omega = np.sqrt(2 * (e0 + work) / total)
        return 1.0 / float(np.mean(1.0 / omega))

    low = -float(np.min(work))  # ω reaches 0 there
    low = low + abs(low) * 1e-15 + 1e-300
    if mean(low) >= target:
        raise TooSlow("at this mean speed the crank stops within the cycle: the loads' work "
                      "swing is more than its kinetic energy")
    high = max(low, 0.0) + 0.5 * float(np.max(total)) * target**2 + float(np.ptp(work)) + 1e-300
    while mean(high) < target:
        high *= 2
    e0 = bracketed_root(lambda e: mean(e) - target, low, high)
    return float(np.sign(speed)) * np.sqrt(2 * (e0 + work) / total)


class TooSlow(SolverError):
    """The mechanism cannot run at the mean speed asked: it stops within its cycle."""


def bracketed_root(f: Callable[[float], float], low: float, high: float,
                   rtol: float = ROOT_TOLERANCE) -> float:
    """A root of ``f`` between ``low`` and ``high``, where ``f`` changes sign (Illinois method).

    Regula falsi with the Illinois modification: superlinear, and the bracket holds the root
    throughout; to ``rtol`` of the root (or of the bracket's size where the root is 0). By
    hand rather than :func:`scipy.optimize.brentq`, whose import costs ``analyze`` more than
    its whole budget.
    """
    f_low, f_high = f(low), f(high)
    if f_low == 0:
        return low
    if f_high == 0:
        return high
    if (f_low > 0) == (f_high > 0):
        raise SolverError("the speed fluctuation's root is not bracketed")
    side = 0
    for _ in range(400):
        x = high - f_high * (high - low) / (f_high - f_low)
        fx = f(x)
        if fx == 0 or abs(high - low) <= rtol * max(abs(x), 1e-300):
            return x
        if (fx > 0) == (f_high > 0):
            high, f_high = x, fx
            if side == 1:
                f_low /= 2
            side = 1
        else:
            low, f_low = x, fx
            if side == -1:
                f_high /= 2
            side = -1
    return x


def _excess_or_too_slow(excess: Callable[[float], float], added: float) -> float:
    """``excess(added)``, or ``inf`` where the mechanism stops within its cycle."""
    try:
        return excess(added)
    except TooSlow:
        return math.inf


def fluctuation_of(omega: NDArray[np.float64]) -> float:
    """``δ = (ω_max − ω_min)/ω_mean`` of speeds over a cycle on an even grid of angle."""
    w = np.abs(omega)
    return float((np.max(w) - np.min(w)) * np.mean(1.0 / w))


def fluctuation_alone(energy: CrankEnergy, speed: float) -> float:
    """``δ`` of the mechanism with no flywheel at mean ``speed``.

    ``inf`` where it cannot run at that mean speed (it stops within its cycle).
    """
    try:
        return fluctuation_of(speeds(energy, 0.0, speed))
    except TooSlow:
        return math.inf


def flywheel(energy: CrankEnergy, speed: float, fluctuation: float) -> Flywheel:
    """The least flywheel inertia for speed fluctuation ``fluctuation`` at mean ``speed``.

    Raises
    ------
    SpecError
        If ``fluctuation`` is not in ``(0, 2)``.
    """
    if not 0 < fluctuation < 2:
        raise SpecError("must be in (0, 2): (ω_max − ω_min)/ω_mean",
                        key="operation.speed_fluctuation", value=fluctuation)
    j = energy.inertia_on(REFINE)
    swing = float(np.ptp(energy.work(REFINE) - 0.5 * speed**2 * (j - j[0])))
    j_range = (float(np.min(j)), float(np.mean(j)), float(np.max(j)))
    def excess(i_f: float) -> float:
        return fluctuation_of(speeds(energy, i_f, speed)) - fluctuation

    alone = fluctuation_alone(energy, speed)
    if alone <= fluctuation:
        added = 0.0
    else:
        high = max(swing / (fluctuation * speed**2), j_range[2], 1e-300)
        while _excess_or_too_slow(excess, high) > 0:
            high *= 2
        low = 0.0
        if math.isinf(alone):  # the least inertia with which it runs at all, bracketed
            runs = high
            for _ in range(200):
                trial = (low + runs) / 2
                if math.isinf(_excess_or_too_slow(excess, trial)):
                    low = trial
                else:
                    runs = trial
                if runs - low <= ROOT_TOLERANCE * runs:
                    break
            low = runs
        added = low if excess(low) <= 0 else bracketed_root(excess, low, high)
    omega = np.abs(speeds(energy, added, speed))
    return Flywheel(fluctuation=fluctuation, speed=abs(speed), inertia=added,
                    energy_swing=swing, mean_torque=energy.mean_load, mechanism_inertia=j_range,
                    classical=swing / (fluctuation * speed**2) - j_range[1],
                    fluctuation_without=alone,
                    speeds=(float(np.min(omega)), float(np.max(omega))))


__all__ = ["CrankEnergy", "Flywheel", "flywheel", "fluctuation_of", "speeds"]
