"""Cumulative adaptive quadrature of a vectorised integrand, at a grid of times.

A driven crank's motion is prescribed: the only quantity a simulation has to integrate is the
work of the motor (and of a force that depends on the crank angle), ``W(t) = ∫₀ᵗ P dt``, whose
integrand is a function of the time alone. :func:`cumulative` finds it at every output time
with the 7-point Gauss and 15-point Kronrod pair (Piessens et al., *QUADPACK*, 1983, ``qk15``;
the constants below are QUADPACK's) on panels that subdivide the intervals between the output
times: all the panels' nodes in one call of the integrand, every panel whose error estimate
``|K15 − G7|`` exceeds ``atol + rtol·|W|`` (the value at its ends, as an integrator's step is
judged against its state) halved, and the halves evaluated together, until none does.

``scipy.integrate.quad_vec`` is adaptive and vector-valued, but it calls the integrand once per
node (a Python call of a formulation's equations, about as costly as a whole panel of nodes
evaluated together here), and importing ``scipy.integrate`` costs more than the whole
quadrature of a verification run (0.3–0.6 s): the dozen lines are written here.
"""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

from .errors import SolverError

#: The Kronrod nodes on [−1, 1] from the end inwards (the negatives mirror them), then 0.
_XK = np.array([
    0.991455371120812639206854697526329,
    0.949107912342758524526189684047851,
    0.864864423359769072789712788640926,
    0.741531185599394439863864773280788,
    0.586087235467691130294144845693013,
    0.405845151377397166906606412076961,
    0.207784955007898467600689403773245,
    0.0,
])
#: Their Kronrod weights.
_WK = np.array([
    0.022935322010529224963732008058970,
    0.063092092629978553290700663189204,
    0.104790010322250183839876322541518,
    0.140653259715525918745189590510238,
    0.169004726639267902826583426598550,
    0.190350578064785409913256402421014,
    0.204432940075298892414161999234649,
    0.209482141084727828012999174891714,
])
#: The 7-point Gauss weights of the odd-numbered Kronrod nodes (±_XK[1], ±_XK[3], ±_XK[5], 0).
_WG = np.array([
    0.129484966168869693270611432679082,
    0.279705391489276667901467771423780,
    0.381830050505118944950369775488975,
    0.417959183673469387755102040816327,
])

#: The 15 nodes on [−1, 1] in increasing order, and the weights of both rules on them.
NODES = np.concatenate([-_XK[:-1], _XK[::-1]])
KRONROD = np.concatenate([_WK[:-1], _WK[::-1]])
GAUSS = np.zeros(15)
GAUSS[1:7:2] = _WG[:-1]
GAUSS[7] = _WG[-1]
GAUSS[9:15:2] = _WG[-2::-1]

#: Rounds of halving after which a panel that still fails its tolerance is an error (a panel
#: 2⁻⁶⁰ of its interval is below the rounding of the time).
MAX_ROUNDS = 60


@dataclass(frozen=True)
class Cumulative:
    """The result of :func:`cumulative`.

    Attributes
    ----------
    values
        The integral from the first time to each time, shape ``(times, components)``.
    panels
        Panels of the final subdivision.
    evaluations
        Points at which the integrand was evaluated.
    """

    values: NDArray[np.float64]
    panels: int
    evaluations: int


def cumulative(integrand: Callable[[NDArray[np.float64]], NDArray[np.float64]],
               times: NDArray[np.float64], *, rtol: float, atol: float,
               max_width: float = math.inf) -> Cumulative:
    """``∫ integrand`` from ``times[0]`` to each of ``times`` (increasing), adaptively.

    Parameters
    ----------
    integrand
        ``integrand(t)`` for a 1-D array of times: an array of shape ``(len(t), components)``.
    times
        Increasing times; the integral is wanted at each.
    rtol, atol
        A panel is accepted when ``|K15 − G7| ≤ atol + rtol·max(|W(a)|, |W(b)|)`` for each
        component, ``W`` the integral at its ends (the global error is then at most the panels'
        count times that).
    max_width
        Widest first panel: each interval between two times is split evenly into panels no
        wider (a periodic integrand needs several per period, or both rules can agree on a
        wrong value).

    Raises
    ------
    SolverError
        If a panel still fails its tolerance after :data:`MAX_ROUNDS` halvings (an integrand
        that is not finite, or not integrable to the tolerance).
    """
    times = np.asarray(times, dtype=float)
    if times.size < 2:  # nothing to integrate over: the components' count from one value
        shape = np.asarray(integrand(times[:1]), dtype=float).shape[1:]
        return Cumulative(values=np.zeros((times.size, *shape)), panels=0, evaluations=0)
    widths = np.diff(times)
    pieces = np.maximum(1, np.ceil(widths / max_width)).astype(int)
    owner = np.repeat(np.arange(widths.size), pieces)  # the interval each panel belongs to
    first = np.cumsum(pieces) - pieces
    within = np.arange(owner.size) - first[owner]
    step = widths[owner] / pieces[owner]
    left = times[owner] + step * within
    right = np.where(within + 1 == pieces[owner], times[owner + 1], left + step)
    done_value = []  # (owner, value) of the accepted panels
    done_owner = []
    evaluations = panels = 0
    for _ in range(MAX_ROUNDS + 1):
        kronrod, gauss = _rules(integrand, left, right)
        evaluations += left.size * NODES.size
        # Each panel's tolerance from the integral at its ends (all the panels so far).
        per_interval = np.zeros((widths.size, kronrod.shape[1]))
        for own, val in zip(done_owner, done_value, strict=True):
            np.add.at(per_interval, own, val)
        np.add.at(per_interval, owner, kronrod)
        at_times = np.concatenate([np.zeros((1, kronrod.shape[1])),
                                   np.cumsum(per_interval, axis=0)])
        size = np.maximum(np.abs(at_times[owner]), np.abs(at_times[owner + 1]))
        good = np.all(np.abs(kronrod - gauss) <= atol + rtol * size, axis=1)
        done_owner.append(owner[good])
        done_value.append(kronrod[good])
        panels += int(np.count_nonzero(good))
        if good.all():
            return Cumulative(values=at_times, panels=panels, evaluations=evaluations)
        bad = ~good
        mid = 0.5 * (left[bad] + right[bad])
        left = np.concatenate([left[bad], mid])
        right = np.concatenate([mid, right[bad]])
        owner = np.concatenate([owner[bad], owner[bad]])
        if not np.all(np.isfinite(kronrod[bad])):
            break
    where = float(left[0])
    raise SolverError(f"the quadrature of the driven motion's power did not converge near "
                      f"t = {where:.6g} s (rtol = {rtol:g}, atol = {atol:g}): the power is not "
                      "finite or not smooth enough there")


def _rules(integrand, left: NDArray[np.float64], right: NDArray[np.float64]):
    """The Kronrod and Gauss sums on each panel, shape ``(panels, components)``."""
    half = 0.5 * (right - left)
    nodes = (0.5 * (left + right))[:, None] + half[:, None] * NODES[None, :]
    values = np.asarray(integrand(nodes.ravel()), dtype=float)
    values = values.reshape(left.size, NODES.size, -1)
    kronrod = half[:, None] * np.einsum("n,pnc->pc", KRONROD, values)
    gauss = half[:, None] * np.einsum("n,pnc->pc", GAUSS, values)
    return kronrod, gauss
