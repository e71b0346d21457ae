"""Shaking-force balance of any linkage: linear conditions found from the linkage itself.

The total first moment of mass of the moving links, ``Σ_k (m_k·r̄_Ok + R(θ_k)·(m·s̄)_k)``, is
linear in the design vector ``π`` (:class:`balancer.linkage.dynamics.Layout`) with coefficients
that are functions of the inputs' positions: ``G(q)·π`` (a one-input linkage's ``q`` is its
crank angle θ1). The shaking force vanishes for every motion exactly when the total centre of
mass is stationary, ``(G(q) − G(q0))·π = 0`` for all ``q`` (DESIGN.md; Meijaard & van der Wijk
2020, Eq. 57–58 for the four-bar; Wunderlich 1964, Eq. 10d and 20a–b). Those coefficient
functions span a space of finite dimension, so the conditions are the row space of their
variation sampled at enough states — angles over the crank's range, or for several inputs
states spread over a box of :data:`SPREAD` rad about the reference pose (the functions are
analytic: a neighbourhood shows their span): an SVD gives it, with a rank test in
units where every column is a mass (the first moments' columns, and a mass column times a
length) so that no link's size hides a condition, and a clear gap between the singular values
kept and those of rounding. The conditions are then checked at states not used to find them:
a condition missed by the sampling would show there.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

from .errors import SolverError
from .linkage.inputs import InputState
from .mechanisms import geometry
from .mechanisms.base import Mechanism

#: Singular values below this share of the largest are rounding (a condition that holds).
NULL_TOLERANCE = 1e-11
#: Singular values kept must be above this share of the largest: a clear gap, or the rank is
#: in doubt.
KEPT_TOLERANCE = 1e-7
#: A residual below this (relative to the size of its terms) is rounding: force-balanced.
RESIDUAL_FLOOR = 1e-9
#: Share of a condition's magnitude at the links' own scales (each link's mass, and its mass
#: times the linkage's size for its first moments) below which its terms count as vanishing:
#: a condition whose every term is rounding (the first moments across links whose centres of
#: mass lie on their lines, left by the sums that made them) is judged against that, not
#: against its rounding-sized terms.
SMALL_ROW = 1e-6
#: Samples per design-vector entry (and at least :data:`MIN_SAMPLES`) to find the conditions.
SAMPLES_PER_ENTRY = 6
MIN_SAMPLES = 64
#: Half the side, rad, of the box about the reference pose whose states find the conditions of
#: a linkage with several inputs.
SPREAD = 0.3


@dataclass(frozen=True, eq=False)
class ForceBalance:
    """The force-balance conditions ``A·π = 0`` of a mechanism.

    Attributes
    ----------
    matrix
        ``A``, one row per condition, columns in the layout's order (kg per unit of the
        entry: rows of unit norm in the scaled parameters).
    scales
        The column scales used (``L`` for a mass, 1 for a first moment), m or 1.
    singular_values
        All singular values of the sampled variation, largest first (for diagnosis).
    """

    matrix: NDArray[np.float64]
    scales: NDArray[np.float64]
    singular_values: NDArray[np.float64]
    links: tuple[slice, ...] = ()
    length: float = 1.0

    @property
    def count(self) -> int:
        """Number of independent conditions."""
        return self.matrix.shape[0]

    def rows(self, x: NDArray[np.float64]) -> NDArray[np.float64]:
        """Each condition's residual relative to the size of its terms.

        The size is the sum over links of each link's contribution (its entries combined
        first: a heavy link whose centre of mass sits on its pivot contributes nothing and
        must not hide a light link's unbalance), at least the raw terms' rounding,
        ``64·ε·Σ_j |A_ij·x_j|``, over :data:`RESIDUAL_FLOOR`, and :data:`SMALL_ROW` of the
        row's magnitude at the links' own scales (``m`` for a mass, ``m·`` :attr:`length` for
        a first moment).
        """
        x = np.asarray(x, dtype=float)
        terms = self.matrix * x
        combined = sum(np.abs(terms[:, s].sum(axis=1)) for s in self.links) if self.links \
            else np.abs(terms).sum(axis=1)
        raw = np.abs(terms).sum(axis=1)
        own = np.zeros(x.size)
        for s in self.links:  # (m, m·e, m·f, J): a mass, two first moments, an inertia
            mass = abs(float(x[s.start]))
            own[s.start : s.start + 4] = (mass, mass * self.length, mass * self.length,
                                          mass * self.length**2)
        eps = np.finfo(float).eps
        size = np.maximum.reduce([combined, 64 * eps / RESIDUAL_FLOOR * raw,
                                  SMALL_ROW * (np.abs(self.matrix) @ own),
                                  np.full(combined.shape, 1e-300)])
        return np.abs(terms.sum(axis=1)) / size

    def residual(self, x: NDArray[np.float64]) -> float:
        """The largest condition's residual relative to the size of its terms (0: balanced).

        Dimensionless: the shaking force's first moment of mass left over, over the first
        moments that make it.
        """
        return float(np.max(self.rows(x), initial=0.0))


def first_moment_map(mech: Mechanism, state: InputState) -> NDArray[np.complex128]:
    """``G(q)``: the moving links' total first moment of mass per unit design entry.

    At the inputs' positions of ``state``; shape ``(N, P)``, complex (x + i·y), kg·m per kg
    (mass entries) or per kg·m (first moments); inertias and counter-rotors do not enter.
    """
    layout, structure = mech.layout, mech.structure
    with np.errstate(all="ignore"):
        pose = mech.pose_at(state)  # (positions alone: no rates)
    g = np.zeros((state.count, layout.size), dtype=complex)
    for k, name in enumerate(structure.names):
        s = layout.link_slice(name)
        c, sn = pose.cos[k], pose.sin[k]
        g[:, s.start] = pose.origins[k].complex()
        g[:, s.start + 1] = c + 1j * sn
        g[:, s.start + 2] = -sn + 1j * c
    return g


def _states(mech: Mechanism, count: int, rng: np.random.Generator,
            within: InputState | None = None) -> InputState:
    """States where the mechanism assembles, spread over its range (seeded).

    One input: :func:`_angles` (``within`` given: shifted by half a step, within the range of
    ``within``'s angles where the crank does not turn fully). Several: uniform in the box of
    :data:`SPREAD` about the reference pose (``within``: in the box the states of ``within``
    span), those that do not assemble left out — drawn again until ``count`` are found.
    """
    inputs = mech.structure.inputs
    if len(inputs) == 1:
        angles = _angles(mech, count, rng)
        if within is not None:
            angles = angles + np.pi / count
            if not mech.assembly_range().full:
                first = np.asarray(within.positions[0])
                angles = np.clip(angles, first.min(), first.max())
        return InputState.crank(angles)
    if within is None:
        reference = np.array(mech.structure.input_references)
        # (SPREAD rad about a pivot; along a slide, SPREAD of the linkage's size)
        spread = np.array([SPREAD * (mech.structure.length_scale()
                                     if d.position_unit == "m" else 1.0)
                           for d in mech.structure.drivers])
        low, high = reference - spread, reference + spread
    else:
        spans = np.array([np.asarray(p) for p in within.positions])
        low, high = spans.min(axis=1), spans.max(axis=1)
    found: list[NDArray[np.float64]] = []
    total = 0
    for _ in range(8):
        q = low[:, None] + (high - low)[:, None] * rng.uniform(0, 1, (len(inputs), 2 * count))
        with np.errstate(all="ignore"):
            pose = mech.pose_at(InputState.of(list(q)))
        ok = np.all([np.isfinite(a) for a in pose.angles], axis=0)
        found.append(q[:, ok])
        total += int(ok.sum())
        if total >= count:
            break
    q = np.hstack(found)[:, :count]
    if q.shape[1] < count:
        raise SolverError("the linkage assembles at too few states about its reference pose "
                          "to find its force-balance conditions")
    return InputState.of(list(q))


def _angles(mech: Mechanism, count: int, rng: np.random.Generator) -> NDArray[np.float64]:
    """Crank angles where the mechanism assembles, spread over its range (seeded)."""
    r = mech.assembly_range()
    if r.full:
        lo, hi = 0.0, 2 * np.pi
    else:
        lo, hi = r.intervals[0]
        pad = 1e-3 * (hi - lo)
        lo, hi = lo + pad, hi - pad
    base = lo + (hi - lo) * (np.arange(count) + 0.5) / count
    return base + (hi - lo) / count * 0.4 * rng.uniform(-1, 1, count)


def force_balance_conditions(mech: Mechanism) -> ForceBalance:
    """The conditions of shaking-force balance of a mechanism (see the module docstring).

    Cached with the mechanism's geometry (:attr:`~balancer.linkage.structure.Structure.
    kinematic`: they depend on it and on the layout alone, which a redesign keeps).

    Raises
    ------
    SolverError
        If the sampled singular values show no clear gap, or the conditions do not hold at
        fresh angles (the rank cannot be trusted).
    """
    cache = mech.structure.kinematic
    if "force balance" in cache:
        return cache["force balance"]
    layout = mech.layout
    links = tuple(layout.link_slice(name) for name in mech.structure.names)
    length = mech.structure.length_scale()
    closed = mech.closed_form_force_balance()
    if closed is not None:  # the seeds' conditions, exact
        result = ForceBalance(matrix=closed, scales=np.ones(layout.size),
                              singular_values=np.zeros(0), links=links, length=length)
        cache["force balance"] = result
        return result
    scales = _mass_scales(mech)
    count = max(MIN_SAMPLES, SAMPLES_PER_ENTRY * layout.size)
    rng = np.random.default_rng(20260101)  # the same angles every run
    states = _states(mech, count, rng)
    d = _variation(mech, [states], scales)
    rows, sv, null = _row_space(d)
    if rows.shape[0] and null.size:  # at fresh states the null space is stationary too
        fresh = _states(mech, count, np.random.default_rng(20260102), within=states)
        df = _variation(mech, [fresh], scales)
        if np.max(np.abs(df @ null)) > 1e3 * NULL_TOLERANCE * sv[0]:
            raise SolverError("the force-balance conditions found at sampled angles do not "
                              "hold at others: the sampling missed a condition")
    result = ForceBalance(matrix=rows * scales, scales=scales, singular_values=sv, links=links,
                          length=length)
    cache["force balance"] = result
    return result


def force_balance_along(mech: Mechanism, motions: Sequence[InputState]) -> ForceBalance:
    """The conditions that hold the total centre of mass still along each of ``motions``.

    ``[balance] force = "motion"``: the states of each motion (its samples), the first
    moment's variation about its own mean along it — a motion need not end where another
    starts — stacked, and their row space as for :func:`force_balance_conditions`. A path
    through the inputs' space visits fewer of the coefficient functions' combinations than
    the whole space: fewer conditions. Kept with the geometry, per set of motions.

    Raises
    ------
    SolverError
        If the singular values show no clear gap (the rank cannot be trusted).
    """
    cache = mech.structure.kinematic.setdefault("force balance along", {})
    key = tuple(m.key() for m in motions)
    if key in cache:
        return cache[key]
    scales = _mass_scales(mech)
    try:
        rows, sv, _ = _row_space(_variation(mech, motions, scales))
    except SolverError as exc:
        raise SolverError(f"{exc} along the motions (a motion too small to tell a "
                          "condition from rounding: force-balance it for every motion)"
                          ) from None
    layout = mech.layout
    result = ForceBalance(matrix=rows * scales, scales=scales, singular_values=sv,
                          links=tuple(layout.link_slice(n) for n in mech.structure.names),
                          length=mech.structure.length_scale())
    cache[key] = result
    return result


def _mass_scales(mech: Mechanism) -> NDArray[np.float64]:
    """Each entry's scale: the linkage's size for a mass (its column then a first moment), 1."""
    layout = mech.layout
    scales = np.ones(layout.size)
    for name in mech.structure.names:
        scales[layout.index(name, "m")] = mech.structure.length_scale()
    return scales


def _variation(mech: Mechanism, parts: Sequence[InputState], scales: NDArray[np.float64]
               ) -> NDArray[np.float64]:
    """The first moment's variation about each part's mean, x and y rows stacked, scaled."""
    blocks = []
    for states in parts:
        g = first_moment_map(mech, states)
        d = g - g.mean(axis=0)
        blocks += [d.real, d.imag]
    return np.vstack(blocks) / scales  # columns in units of a first moment


def _row_space(d: NDArray[np.float64]
               ) -> tuple[NDArray[np.float64], NDArray[np.float64], NDArray[np.float64]]:
    """The rows of the sampled variation's row space, its singular values, its null space.

    Raises
    ------
    SolverError
        If singular values lie between rounding and a clear condition.
    """
    # (Rows ≥ columns: the reduced factorisation has every right singular vector, without
    # the square left factor of the samples' size.)
    _, sv, vt = np.linalg.svd(d, full_matrices=False)
    top = sv[0] if sv.size else 0.0
    if top == 0:
        return np.zeros((0, d.shape[1])), sv, np.eye(d.shape[1])
    rank = int(np.sum(sv > NULL_TOLERANCE * top))
    if np.any((sv > NULL_TOLERANCE * top) & (sv < KEPT_TOLERANCE * top)):
        raise SolverError(
            "the force-balance conditions cannot be told from rounding: singular values "
            f"{', '.join(f'{x / top:.1e}' for x in sv)} of the largest show no clear gap")
    rows = vt[:rank].copy()
    # A parameter that moves no centre of mass at any sampled angle (an inertia, a
    # counter-rotor, the mass of a link whose frame's origin is fixed) has a column of exact
    # zeros; its entries in the rows are the SVD's rounding (1e-16), which times an inertia
    # of 200 kg·m² left a residual of 2e-12 of a condition's terms that no change of the
    # first moments could restore (linkage campaign, seed 40, case 751: 'no feasible design
    # found'). They are zero.
    rows[:, ~np.any(d, axis=0)] = 0.0
    return rows, sv, vt[rank:].T


#: Crank angles over a revolution at which a mechanism with rotors is judged.
ROTOR_SAMPLES = 1024


def force_balance_residual(mech: Mechanism) -> float:
    """How far a mechanism's own design is from shaking-force balance (0: balanced).

    A mechanism with rotors besides its links (an engine's crankshaft masses and balance
    shafts, whose first moments are not in the design vector): the largest swing of the total
    first moment of mass over :data:`ROTOR_SAMPLES` crank angles of a revolution, over the sum
    of each body's own largest swing (:meth:`~balancer.mechanisms.base.Mechanism.first_moments`).
    """
    if not mech.rotors:
        return force_balance_conditions(mech).residual(mech.layout.vector(mech.linkage))
    theta = 2 * np.pi * np.arange(ROTOR_SAMPLES) / ROTOR_SAMPLES
    with np.errstate(all="ignore"):
        moments = geometry.first_moments(mech, mech.motion(theta))
    swings = [np.asarray(m, dtype=complex) * np.ones(theta.size) for m in moments]
    swings = [m - m.mean() for m in swings]
    total = float(np.max(np.abs(sum(swings))))
    size = sum(float(np.max(np.abs(m))) for m in swings)
    eps = np.finfo(float).eps
    return total / max(size, 1e-300) if total > 64 * eps * size else 0.0
