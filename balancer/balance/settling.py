"""The inert entries' values: what nothing the objective or a constraint measures decides.

An inertia about a centre of mass or a counter-rotor that the objective does not see (its
regressor column vanishes: a crank's at constant speed) is left out by the optimisers;
:meth:`Settling.settle` then gives it its value — the original's where allowed, a counter-rotor
the one that best balances a change of crank speed (:attr:`Settling.acceleration_factor`).
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from functools import cached_property
from typing import cast

import numpy as np
from numpy.typing import ArrayLike, NDArray

from .lsq import bounded_lstsq
from .problem_data import ProblemData
from .regressors import cycle_regressors
from .sites import site_columns


def _bounded_least_squares(a: NDArray[np.float64], x: NDArray[np.float64],
                           entries: Sequence[int], lower: ArrayLike, upper: ArrayLike,
                           original: ArrayLike) -> NDArray[np.float64]:
    """Values of ``x[entries]`` within bounds minimising ``‖a·x‖²``, nearest ``original``.

    A light pull towards the original (1e-6 of the problem's scale) picks one among equally
    good choices.
    """
    lows, highs = np.asarray(lower, float), np.asarray(upper, float)
    values = np.asarray(original, float)
    free = lows < highs
    out = values.copy()
    if not free.any():
        return out
    x = np.array(x, dtype=float)
    x[list(entries)] = values  # the fixed ones at their value, the free ones solved for
    solved = [e for e, f in zip(entries, free, strict=True) if f]
    lows, highs, values = lows[free], highs[free], values[free]
    cols = a[:, solved]
    rest = a @ x - cols @ x[solved]
    scale = np.maximum(np.abs(values), 1.0)
    weight = 1e-6 * max(float(np.linalg.norm(cols)), 1e-300)
    lhs = np.vstack([cols * scale, weight * np.eye(len(solved))])
    rhs = np.concatenate([-rest, weight * values / scale])
    sol = bounded_lstsq(lhs, rhs, lows / scale, highs / scale, tol=1e-14)
    out[free] = np.clip(sol.x * scale, lows, highs)
    return out


class Settling(ProblemData):
    """The values of a :class:`~.problem.NumericProblem`'s :attr:`~ProblemData.inert` entries."""

    @cached_property
    def acceleration_factor(self) -> NDArray[np.float64]:
        """Shaking moment per unit crank acceleration at rest, reduced: ``(P, P)``, N·m/(rad/s²).

        The regressors at ``(θ1, θ̇1 = 0, θ̈1 = 1)`` on the sampled angles, divided by ``√N``
        (``A``), as their triangular factor ``R`` (``‖R·x‖ = ‖A·x‖``, the root mean square of
        that shaking moment), so that settling costs the same at any number of samples. The
        objective, at constant speed, does not see what the crank's rotary inertia does when
        the speed changes; this does.
        """
        angles = np.asarray(self.states.positions[0], dtype=float)
        reg = self.unit_acceleration or cycle_regressors(self.mechanism, angles, 0.0, 1.0)
        moment = reg.shaking_moment
        if moment.shape[1] < self.size and self.sites is not None:  # the sites' columns
            moment = np.hstack([moment, site_columns(self.sites.sites, angles, 0.0, 1.0)[1]])
        rows = moment / math.sqrt(moment.shape[0])
        # (R alone: numpy's stubs say qr gives a QRResult whatever its mode.)
        return cast("NDArray[np.float64]", np.linalg.qr(rows, mode="r"))

    def settle(self, x: NDArray[np.float64], *, for_motion: bool = True) -> NDArray[np.float64]:
        """Give the :attr:`inert` entries their values.

        With ``for_motion`` false they just take the allowed value nearest the original's (all
        that a check of the objective or the constraints needs); otherwise:

        Nothing the objective or a constraint measures depends on them. An inertia about a
        centre of mass keeps the allowed value nearest the original's (a designer's crankshaft
        or flywheel is not shrunk behind their back). A counter-rotor is chosen, within its
        bounds, to minimise the mean square of the shaking moment per unit crank acceleration
        (:attr:`acceleration_factor`): what a change of crank speed (start-up, fluctuation, free
        motion) makes the frame feel; among equally good choices the one nearest the original.
        With Berkof's conditions met this gives the crank the counter-rotor that completes the
        balance for every motion.
        """
        x = np.array(x, dtype=float)
        own = self.own(x).tolist()
        offset = self._offset_values or [0.0] * self.size
        entries, lower, upper, original = [], [], [], []
        for b in self.links:
            k = b.start
            if not self.inert[k + 3]:
                continue
            m, me, mf = own[k], own[k + 1], own[k + 2]
            if self.absent(b, own):  # no counterweight: none of its inertia either
                x[k + 3] = self.offset[k + 3]
                continue
            if not m > 0:  # nothing to settle
                continue
            q = (me * me + mf * mf) / m
            lo = max(b.inertia[0], m * b.gyration**2)
            shift = offset[k + 3]
            # A counterweight's inertia nearest its least (it has no original).
            kept = lo if b.offset is not None else min(max(b.original.inertia, lo), b.inertia[1])
            entries.append(k + 3)
            lower.append(lo + q + shift)
            upper.append(b.inertia[1] + q + shift)
            original.append(kept + q + shift)
        for b in self.rotor_links:
            if self.inert[b.rotor_entry] and b.counter_rotor is not None:
                lo, hi = b.counter_rotor
                entries.append(b.rotor_entry)
                lower.append(lo)
                upper.append(hi)
                original.append(min(max(b.original.counter_rotor, lo), hi))
        if not entries:
            return x
        x[entries] = original
        if not for_motion:
            return x
        lower_a, upper_a, original_a = (np.array(v, dtype=float) for v in (lower, upper,
                                                                             original))
        rotor_entries = {b.rotor for b in self.rotor_links}
        rotors = np.array([i in rotor_entries for i in entries])
        if rotors.any():
            idx = [e for e, r in zip(entries, rotors, strict=True) if r]
            x[idx] = _bounded_least_squares(self.acceleration_factor, x, idx, lower_a[rotors],
                                            upper_a[rotors], original_a[rotors])
        return x
