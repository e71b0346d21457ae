"""Cumulative adaptive quadrature of a vectorised integrand, at a grid of times.

A driven crank's motion is prescribed: the only quantity a simulation has to integrate is the
work of the motor (and of a force that depends on the crank angle), ``W(t) = ∫₀ᵗ P dt``, whose
integrand is a function of the time alone. :func:`cumulative` finds it at every output time
with the 7-point Gauss and 15-point Kronrod pair (Piessens et al., *QUADPACK*, 1983, ``qk15``;
the constants below are QUADPACK's) on panels that tile the span: all the panels' nodes in one
call of the integrand, every panel whose error estimate ``|K15 − G7|`` exceeds
``atol + rtol·|W|`` (the value at its ends, as an integrator's step is judged against its
state) halved, and the halves evaluated together, until none does. An output time inside a
panel takes the integral of the interpolant through the panel's nodes up to it, its error
measured by the interpolant's last Legendre terms: the panels are as many as the integrand
needs, not one per output interval (a formulation's power costs a compiled solve per node).

``scipy.integrate.quad_vec`` is adaptive and vector-valued, but it calls the integrand once per
node (a Python call of a formulation's equations, about as costly as a whole panel of nodes
evaluated together here), and importing ``scipy.integrate`` costs more than the whole
quadrature of a verification run (0.3–0.6 s): the dozen lines are written here.
"""

from __future__ import annotations

import math
from collections.abc import Callable, Sequence
from dataclasses import dataclass
from typing import TypeAlias

import numpy as np
from numpy.typing import NDArray

from ..errors import SolverError

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
#: Panels halved, at most, beyond this many per first panel (and this many more): an integrand
#: whose estimates do not fall with halving (not smooth at the tolerance: a driven motion that
#: starts at a dead point, where the torque is singular) would double its panels each round.
MAX_REFINED = 20
EXTRA_REFINED = 10_000


@dataclass(frozen=True, eq=False)
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


def _partial_basis() -> tuple[NDArray[np.float64], NDArray[np.float64]]:
    """The partial integrals of the 15 nodes' Lagrange basis, and of its last two terms.

    ``A``, ``B`` with ``legvander(u, 15)·A`` the integrals ``∫₋₁ᵘ L_j`` of the Lagrange basis
    of the 15 nodes, and ``legvander(u, 15)·B`` those of its last two Legendre terms. The
    interpolant through the nodes as a Legendre series (whose Vandermonde matrix at these
    nodes is well conditioned, unlike the monomials'), integrated term by term from −1
    (``numpy.polynomial.legendre``).
    """
    lagrange = np.linalg.inv(np.polynomial.legendre.legvander(NODES, 14))  # row n: c_n's weights
    tail = lagrange.copy()
    tail[:13] = 0.0  # the terms of degree 13 and 14 only
    return (np.asarray(np.polynomial.legendre.legint(lagrange, lbnd=-1.0), dtype=float),
            np.asarray(np.polynomial.legendre.legint(tail, lbnd=-1.0), dtype=float))


_PARTIAL, _TAIL = _partial_basis()

#: Accepted panels: their left and right ends and their Kronrod sums ``(panels, components)``.
Panels: TypeAlias = tuple[NDArray[np.float64], NDArray[np.float64], NDArray[np.float64]]
#: Times inside accepted panels: their indices, their panels' left ends and the integrals
#: from those to them.
Inside: TypeAlias = tuple[NDArray[np.intp], NDArray[np.float64], NDArray[np.float64]]


def partial_weights(u: NDArray[np.float64]) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
    """Weights on the 15 nodes of ``∫₋₁ᵘ`` of the integrand's interpolant, and of its tail.

    The interpolant through the 15 nodes (degree 14) and the part of it that its Legendre
    terms of degree 13 and 14 make, each shape ``(len(u), 15)``. At ``u = 1`` the first are
    the Kronrod weights (the rule is interpolatory) and the second vanish; inside a panel the
    tail's integral measures the error of the interpolant's, as ``|K15 − G7|`` (G7 exact to
    degree 13) does at its end: a series whose last terms are below the tolerance has
    converged (the Clenshaw–Curtis and Chebfun criterion).
    """
    basis = np.polynomial.legendre.legvander(np.asarray(u, dtype=float), 15)
    return basis @ _PARTIAL, basis @ _TAIL


def cumulative(integrand: Callable[[NDArray[np.float64]], NDArray[np.float64]],
               times: NDArray[np.float64], *, rtol: float, atol: float,
               max_width: float = math.inf, breaks: Sequence[float] = ()) -> Cumulative:
    """``∫ integrand`` from ``times[0]`` to each of ``times`` (increasing), adaptively.

    The span is split into panels (of at most ``max_width``), which need not end at the
    times: a time inside a panel gets the integral of the integrand's interpolant through the
    panel's 15 nodes from the panel's start, its error measured by the interpolant's last
    Legendre terms (:func:`partial_weights`). A panel is accepted when every
    such error (its end's and its times') is within its tolerance, else halved; the panels are
    as many as the integrand needs, however many times are asked for.

    Parameters
    ----------
    integrand
        ``integrand(t)`` for a 1-D array of times: an array of shape ``(len(t), components)``.
    times
        Increasing times; the integral is wanted at each.
    rtol, atol
        A panel is accepted when ``|K15 − G7| ≤ atol + rtol·max(|W(a)|, |W(b)|)`` for each
        component, ``W`` the integral at its ends (the global error is then at most the panels'
        count times that), and so at each time inside it.
    max_width
        Widest first panel: the span is split evenly into panels no wider (a periodic
        integrand needs several per period, or both rules can agree on a wrong value).
    breaks
        Times inside the span where the integrand is not smooth (a motion's waypoints, where
        its acceleration may jump): the first panels end there, so that no panel straddles
        a jump and the halvings do not chase it.

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
    start, end = float(times[0]), float(times[-1])
    knots = np.unique([start, *(b for b in breaks if start < b < end), end])
    parts = []
    for a, b in zip(knots[:-1], knots[1:], strict=True):
        count = max(1, math.ceil((b - a) / max_width))
        parts.append(a + (b - a) * np.arange(count) / count)
    edges = np.append(np.concatenate(parts), end)
    pieces = edges.size - 1
    left, right = edges[:-1], edges[1:]
    refined = 0  # panels made by halving
    accepted: list[Panels] = []  # (left, right, kronrod sum) of the accepted panels
    # (time index, its panel's left end, integral from it) of the times inside
    interior: list[Inside] = []
    evaluations = 0
    for _ in range(MAX_ROUNDS + 1):
        values, kronrod, gauss = _rules(integrand, left, right)
        evaluations += left.size * NODES.size
        # The integral at each panel's ends, from all the panels so far in time order.
        lefts = np.concatenate([left, *(a[0] for a in accepted)])
        sums = np.concatenate([kronrod, *(a[2] for a in accepted)])
        order = np.argsort(lefts, kind="stable")
        at_end = np.empty_like(sums)
        at_end[order] = np.cumsum(sums[order], axis=0)
        at_end = at_end[: left.size]
        size = np.maximum(np.abs(at_end - kronrod), np.abs(at_end))
        good = np.all(np.abs(kronrod - gauss) <= atol + rtol * size, axis=1)
        inside, owner = _times_inside(times, left, right)
        if inside.size:
            u = (2 * times[inside] - left[owner] - right[owner]) / (right[owner] - left[owner])
            w_k, w_tail = partial_weights(u)
            half = (0.5 * (right - left))[owner, None]
            part = half * np.einsum("tn,tnc->tc", w_k, values[owner])
            error = half * np.einsum("tn,tnc->tc", w_tail, values[owner])
            before = (at_end - kronrod)[owner]
            scale = np.maximum(np.abs(before), np.abs(before + part))
            ok = np.all(np.abs(error) <= atol + rtol * scale, axis=1)
            np.logical_and.at(good, owner, ok)
            kept = good[owner]
            interior.append((inside[kept], left[owner[kept]], part[kept]))
        accepted.append((left[good], right[good], kronrod[good]))
        if good.all():
            return _assemble(times, accepted, interior, evaluations)
        bad = ~good
        finite = np.isfinite(values).all(axis=2)
        if not finite.all():  # halving cannot help: where the power first is not finite
            nodes = (0.5 * (left + right))[:, None] + (0.5 * (right - left))[:, None] * NODES
            raise SolverError(f"the driven motion's power is not finite at t = "
                              f"{float(np.min(nodes[~finite])):.6g} s")
        mid = 0.5 * (left[bad] + right[bad])
        left, right = np.concatenate([left[bad], mid]), np.concatenate([mid, right[bad]])
        refined += left.size
        if refined > MAX_REFINED * pieces + EXTRA_REFINED:
            break
    where = float(np.min(left))
    raise SolverError(f"the quadrature of the driven motion's power did not converge near "
                      f"t = {where:.6g} s (rtol = {rtol:g}, atol = {atol:g}): the power is not "
                      "finite or not smooth enough there")


def _times_inside(times: NDArray[np.float64], left: NDArray[np.float64],
                  right: NDArray[np.float64]) -> tuple[NDArray[np.intp], NDArray[np.intp]]:
    """The times strictly inside the panels, and the panel each is in."""
    order = np.argsort(left)
    first = np.searchsorted(times, left[order], side="right")
    last = np.searchsorted(times, right[order], side="left")
    counts = last - first
    owner = np.repeat(order, counts)
    inside = np.repeat(first - np.cumsum(counts) + counts, counts) + np.arange(counts.sum())
    return inside, owner


def _assemble(times: NDArray[np.float64], accepted: list[Panels], interior: list[Inside],
              evaluations: int) -> Cumulative:
    """The integral at every time from the accepted panels (they tile the span).

    A time at a panel's end takes the sum of the panels up to it; a time inside one, the sum
    up to the panel's start and the partial integral found when the panel was accepted.
    """
    left = np.concatenate([a[0] for a in accepted])
    right = np.concatenate([a[1] for a in accepted])
    kronrod = np.concatenate([a[2] for a in accepted])
    order = np.argsort(left)
    left, right, kronrod = left[order], right[order], kronrod[order]
    at_start = np.concatenate([np.zeros((1, kronrod.shape[1])), np.cumsum(kronrod, axis=0)])
    out = np.empty((times.size, kronrod.shape[1]))
    out[0] = 0.0
    ends = np.searchsorted(times, right, side="left")  # a time at a panel's end: its sum
    at = ends < times.size
    hit = at.copy()
    hit[at] = times[ends[at]] == right[at]
    out[ends[hit]] = at_start[1:][hit]
    for inside, panel_left, part in interior:
        out[inside] = at_start[np.searchsorted(left, panel_left)] + part
    return Cumulative(values=out, panels=left.size, evaluations=evaluations)


def _rules(integrand: Callable[[NDArray[np.float64]], NDArray[np.float64]],
           left: NDArray[np.float64], right: NDArray[np.float64]
           ) -> tuple[NDArray[np.float64], NDArray[np.float64], NDArray[np.float64]]:
    """The integrand at the panels' nodes, and the Kronrod and Gauss sums on each panel.

    Shapes ``(panels, 15, components)`` and ``(panels, components)``.
    """
    half = 0.5 * (right - left)
    nodes = (0.5 * (left + right))[:, None] + half[:, None] * NODES[None, :]
    values = np.asarray(integrand(nodes.ravel()), dtype=float)
    values = values.reshape(left.size, NODES.size, -1)
    kronrod = half[:, None] * np.einsum("n,pnc->pc", KRONROD, values)
    gauss = half[:, None] * np.einsum("n,pnc->pc", GAUSS, values)
    return values, kronrod, gauss
