"""Feasibility: the bounds and force balance that a solver's design must meet, as text.

:meth:`Feasibility.violations` lists the constraints a design vector breaks (each link's
bounds, its counter-rotor's, and shaking-force balance); force balance is judged condition by
condition against the size of its terms (:meth:`Feasibility.force_balance_rows`), so that
rounding, which no design can beat, is never taken for an unbalance.
"""

from __future__ import annotations

from functools import cached_property

import numpy as np
from numpy.typing import NDArray

from ..force_balance import SMALL_ROW, force_balance_conditions
from ..mechanisms.base import Mechanism
from .objective_scale import ROUNDING_FACTOR
from .problem_data import ProblemData

#: Relative tolerance of :meth:`Feasibility.violations` for a solver's design (bounds and
#: force balance): ten times Clarabel's tolerance.
FEASIBILITY_TOLERANCE = 1e-9


#: Relative residual of a force-balance condition (against the size of its terms) that a
#: balanced design must meet: rounding, with room for the conditioning of the rows.
FORCE_BALANCE_TOLERANCE = 1e-12


#: The share of a row's raw terms that its size is at least: their rounding over the tolerance.
_RAW_SHARE = ROUNDING_FACTOR * float(np.finfo(float).eps) / FORCE_BALANCE_TOLERANCE


#: A bound met to this (relative, :meth:`Feasibility.violations`) is met to rounding: the
#: physical values (:meth:`~.physical.PhysicalValues.physical`) then meet it exactly.
ROUNDING_TOLERANCE = 1e-12


def force_balance_system(mech: Mechanism) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
    """``(A, b)`` of shaking-force balance.

    From :func:`~balancer.force_balance.force_balance_conditions`.
    """
    conditions = force_balance_conditions(mech)
    return conditions.matrix, np.zeros(conditions.count)


class Feasibility(ProblemData):
    """Whether a design vector meets a :class:`~.problem.NumericProblem`'s constraints."""

    def violations(self, x: NDArray[np.float64], tol: float = FEASIBILITY_TOLERANCE) -> list[str]:
        """The constraints that ``x`` breaks by more than ``tol`` (relative), as text.

        Bounds are compared on the scale of the link (``m``, ``l``, ``m·l²``); force balance
        per condition against the size of its terms (:meth:`force_balance_rows`), at
        ``max(tol, FORCE_BALANCE_TOLERANCE)``. An empty list means ``x`` is a feasible design.
        """
        out = []
        own = self.own(x).tolist()  # Python floats: the same arithmetic, a scalar at a time
        for b in self.links:
            k = b.start
            m, me, mf, j = own[k : k + 4]
            whose = b.name if b.offset is None else f"{b.name}'s counterweight"
            if self.absent(b, own):
                continue  # none added: the link as it is
            if not m > 0:
                if b.listed:  # (a held link may have none: an engine's crankshaft on its axis)
                    out.append(f"{whose}: mass {m:.6g} kg is not positive")
                continue
            l, mref, iref = b.length, b.mass_ref, b.inertia_ref
            if m < b.mass[0] - tol * mref or m > b.mass[1] + tol * mref:
                out.append(f"{b.bound_key('mass')}: {m:.9g} kg outside [{b.mass[0]:.9g}, "
                           f"{b.mass[1]:.9g}]")
            com = complex(me, mf) / m
            if b.on_line and abs(com.imag) > tol * l:
                out.append(f"{b.key}.com_on_line: centre of mass {com.imag:.3g} m off the line")
            if b.com_fixed is not None:
                if abs(com - b.com_fixed) > tol * l:
                    out.append(f"{b.name}: centre of mass moved by {abs(com - b.com_fixed):.3g} m")
            elif abs(com - b.com_centre) > b.radius + tol * l:
                out.append(
                    f"{b.bound_key('com_radius')}: centre of {whose} "
                    f"{abs(com - b.com_centre):.9g} m from {b.about} (at most "
                    f"{b.com_radius:.9g})"
                )
            inertia = j - (me * me + mf * mf) / m
            lo = max(b.inertia[0], m * b.gyration**2)
            if inertia < lo - tol * iref or inertia > b.inertia[1] + tol * iref:
                out.append(
                    f"{whose}: inertia {inertia:.9g} kg·m² outside [{lo:.9g}, {b.inertia[1]:.9g}]"
                )
            if b.offset is not None:  # its spread (LinkBounds.counterweight_reach)
                p = b.com_centre
                about_p = j - 2 * (p.real * me + p.imag * mf) + m * abs(p) ** 2
                if about_p > m * b.counterweight_reach**2 + tol * iref:
                    out.append(f"{whose}: second moment {about_p:.9g} kg·m² about {b.about} "
                               f"beyond m·(2R² + ρ²) = {m * b.counterweight_reach**2:.9g}")
        for b in self.rotor_links:
            value = float(x[b.rotor_entry])
            if b.counter_rotor is None:
                if abs(value) > tol * b.inertia_ref:
                    out.append(f"{b.name}: has no counter-rotor, got {value:.6g} kg·m²")
                continue
            lo, hi = b.counter_rotor
            scale = max(b.inertia_ref, hi)
            if value < lo - tol * scale or value > hi + tol * scale:
                out.append(
                    f"{b.key}.counter_rotor: {value:.9g} kg·m² outside [{lo:.9g}, {hi:.9g}]"
                )
        if self.sites is not None:
            out += self.sites.violations(x, tol)
        bound, rows = self.support_bound, self.regressors.supports
        if bound is not None and rows is not None:
            largest = float(np.max(np.abs(rows @ np.asarray(x, float)), initial=0.0))
            if largest > bound * (1 + tol):
                words = self.mechanism.presentation.support_words
                out.append(f"balance.max_bearing_load: a {words} carries {largest:.9g} N, above "
                           f"{bound:.9g}")
        residual = self.force_balance_residual(x)
        if residual > max(tol, FORCE_BALANCE_TOLERANCE):
            out.append(f"force balance: residual {residual:.3g} of its terms")
        return out

    def force_balance_residual(self, x: NDArray[np.float64]) -> float:
        """Largest residual of the force-balance conditions relative to their terms' size.

        See :meth:`force_balance_rows`. 0 when force balance is not imposed.
        """
        return float(np.max(self.force_balance_rows(x), initial=0.0))

    @cached_property
    def _force_balance_sizes(self) -> tuple[NDArray[np.float64], ...]:
        """What :meth:`force_balance_rows` needs of ``(A, b)`` alone.

        ``|A|``, the indicator ``(P, links)`` of each link's entries (a link's terms are
        combined before their magnitude is taken), each row's :data:`SMALL_ROW` floor, and
        ``|b|``.
        """
        assert self.force_balance is not None, "where force balance is imposed"
        a, rhs = self.force_balance
        by_link = np.zeros((self.size, len(self.links)))
        for j, b in enumerate(self.links):
            by_link[b.entries, j] = 1.0
        return np.abs(a), by_link, SMALL_ROW * (np.abs(a) @ self.scales), np.abs(rhs)

    def force_balance_rows(self, x: NDArray[np.float64]) -> NDArray[np.float64]:
        """Each condition's residual relative to the size of its terms.

        ``|A_i·x − b_i| / s_i``. The size ``s_i`` is the sum over links of the magnitude of
        each link's contribution (a link's terms combined first: a heavy link whose centre of
        mass sits on its pivot contributes nothing, exactly, and must not hide a light link's
        unbalance); it is at least :data:`ROUNDING_FACTOR`·ε/:data:`FORCE_BALANCE_TOLERANCE`
        times the raw terms ``Σ_j |A_ij·x_j|`` (their rounding, which no design can beat) and
        :data:`SMALL_ROW` of the row at the parameters' scales. Under a counterweight an entry
        is the sum of the kept link's and the counterweight's (:attr:`offset`), whose rounding
        is that of both: its raw term is ``|A_ij|·(|x_j − offset_j| + |offset_j|)`` (a
        counterweight that cancels the kept link's first moment, as a slider-crank's rod
        must have ``m·f = 0``, leaves a sum of rounding).
        """
        if self.force_balance is None:
            return np.zeros(0)
        a, rhs = self.force_balance
        x = np.asarray(x, dtype=float)
        abs_a, by_link, floor, abs_rhs = self._force_balance_sizes
        if self._offset_values is None:  # no counterweight: |x − 0| + |0| is |x|, exactly
            raw = abs_a @ np.abs(x) + abs_rhs
        else:
            offset = self.offset
            raw = abs_a @ (np.abs(x - offset) + np.abs(offset)) + abs_rhs
        combined = np.abs((a * x) @ by_link).sum(axis=1) + abs_rhs
        size = np.maximum(np.maximum(combined, _RAW_SHARE * raw), floor)
        residual = np.abs(a @ x - rhs)
        if floor.all():  # every row has a positive size
            return residual / size
        with np.errstate(divide="ignore", invalid="ignore"):
            return np.where(size > 0, residual / size, residual)
