"""Mass·radius sites: an engine's counterweights and balance-shaft eccentrics as design entries.

DESIGN.md, "Balancing an engine". The designer names the planes where counterweights may go on
the crankshaft (``[balance.counterweights]``) and the shafts there may be (``[[balance.shafts]]``:
ratio, axis, planes); each is a *site* whose mass·radius vector ``x_i = mr_i·e^{iφ_i}`` is two
entries of the balancing problem's design vector, ``(Re x_i, Im x_i)`` in kg·m, after the
linkage's own (:class:`balancer.linkage.dynamics.Layout`). A mass·radius on a rotor turning at
``k·θ1`` about ``ā`` puts on the frame, at constant crank speed ω
(:meth:`balancer.linkage.rotors.Rotor.loads`):

- the force ``F = x·(kω)²·e^{ikθ1}`` (complex; its centrifugal force on its bearing),
- the rocking couple ``i·z·F`` (``Mx + i·My``, its plane ``z``),
- the shaking moment about z ``ā × F``,

and nothing on the driving torque: every load is linear in ``(Re x, Im x)``, as a link's loads
are in its first moments, so a site's two columns join the linkage's regressors
(:func:`site_columns`) and its bound ``|x_i| ≤ max_mr`` is a second-order cone of the one
balancing problem (:class:`balancer.balance.problem.NumericProblem`). The engine's eccentrics
that the balancing keeps are sites too, held at their values: the loads of the base engine (its
links and kept masses) are the design vector's fixed part, and ``J(x0)`` is the original's.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass
from typing import cast

import numpy as np
from numpy.typing import NDArray

from ..errors import SpecError
from ..linkage.rotors import Eccentric, Rotor
from ..mechanisms import mechanism_of
from ..model import Design
from ..model import MechanismModel as Model
from ..model.balance import PlacedMass, RotorBalanced, RotorBalanceProblem, ShaftDesign
from ..parts.sizing import most_mr
from ..rounding import direction_deg

#: A mass·radius below this share of its bound is none (an interior-point method reaches the
#: apex of a cone, a mass of nothing, only to its tolerance).
ABSENT = 1e-9


@dataclass(frozen=True)
class Site:
    """One mass·radius on a rotor: chosen by the balancing, or kept at its value.

    Attributes
    ----------
    shaft
        ``None`` on the crankshaft, else the new shaft's index (from 0); ``-1`` a kept mass on
        one of the engine's own rotors.
    ratio
        The rotor's speed over the crank's.
    at
        Its axis, complex ``x + i·y``, m.
    z
        Its plane, m.
    max_mr
        Its bound, kg·m (a kept mass: its own mass·radius).
    kept
        ``None`` for a site the balancing chooses; else the kept mass·radius vector, kg·m.
    bearing
        A kept mass's rotor's bearing, the frame's point its force acts at (the crankshaft's
        masses: the main bearings' ``O``; a balance shaft's: its own); ``None`` for a chosen
        site (on a crankshaft where :attr:`shaft` is ``None``, else on its new shaft).
    crankshaft
        A chosen counterweight's crankshaft (1 the first; an engine's geared ones 2 and on).
    """

    shaft: int | None
    ratio: float
    at: complex
    z: float
    max_mr: float
    kept: complex | None = None
    bearing: str | None = None
    crankshaft: int = 1

    @property
    def free(self) -> bool:
        """Whether the balancing chooses this mass·radius."""
        return self.kept is None

    def rotor(self, angle: float) -> Rotor:
        """A unit mass·radius here at ``angle`` (rad), as a rotor without inertia."""
        return Rotor(ratio=float(self.ratio), inertia=0.0, axis=self.at,
                     eccentrics=(Eccentric(mr=1.0, angle=angle, z=self.z),))

    def on_crank(self, frame_points: tuple[str, ...]) -> bool:
        """Whether it is on a crankshaft, its force on that crankshaft's main bearings.

        ``frame_points``: the linkage's ground points, where the crankshaft's masses bear (a
        balance shaft's bearing is a point of its own, even where it turns with the crank).
        """
        return self.shaft is None or (self.bearing is not None and self.bearing in frame_points)

    @property
    def where(self) -> str:
        """The site in words, as a violation names it."""
        where = (("crankshaft" if self.crankshaft == 1 else f"crankshaft {self.crankshaft}")
                 if self.shaft is None else f"shaft {(self.shaft or 0) + 1}")
        return f"{where} at z = {self.z:g} m"


@dataclass(frozen=True)
class Sites:
    """The mass·radius sites of an engine's balancing, and what they build.

    Attributes
    ----------
    sites
        The chosen sites (the crankshaft's planes, then each new shaft's), then the kept ones.
    start
        The design vector's entry of the first site's ``Re x`` (the linkage's entries before).
    problem
        The spec's side.
    replaced
        The places (crankshaft, plane z in m) whose labelled counterweights the chosen ones
        replace.
    speed
        The crank's speed, rad/s (the unbalance's ``ω``).
    """

    sites: tuple[Site, ...]
    start: int
    problem: RotorBalanceProblem
    replaced: tuple[tuple[int, float], ...]
    speed: float

    @property
    def size(self) -> int:
        """Entries of the design vector the sites hold (two each)."""
        return 2 * len(self.sites)

    def entries(self, i: int) -> slice:
        """The design vector's entries of site ``i``: ``Re x``, ``Im x``."""
        return slice(self.start + 2 * i, self.start + 2 * i + 2)

    @property
    def chosen(self) -> tuple[int, ...]:
        """Indices of the sites the balancing chooses."""
        return tuple(i for i, s in enumerate(self.sites) if s.free)

    def chosen_entries(self, size: int) -> NDArray[np.bool_]:
        """Mask of the chosen sites' entries in a design vector of ``size`` entries."""
        mask = np.zeros(size, dtype=bool)
        for i in self.chosen:
            mask[self.entries(i)] = True
        return mask

    def vector(self, x: NDArray[np.float64], i: int) -> complex:
        """Site ``i``'s mass·radius vector in ``x``, kg·m."""
        a, b = (float(v) for v in np.asarray(x)[self.entries(i)])
        return complex(a, b)

    def masses(self, x: NDArray[np.float64]) -> tuple[tuple[PlacedMass, ...],
                                                      tuple[ShaftDesign, ...]]:
        """The counterweights (per chosen plane) and new shafts of ``x``."""
        cws: list[PlacedMass] = []
        per_shaft: list[list[PlacedMass]] = [[] for _ in self.problem.shafts]
        for i in self.chosen:
            s = self.sites[i]
            placed = _placed(s.z, self.vector(x, i), s.max_mr, s.crankshaft)
            (cws if s.shaft is None else per_shaft[s.shaft]).append(placed)
        shafts = tuple(ShaftDesign(ratio=f.ratio, at=f.at, eccentrics=tuple(e))
                       for f, e in zip(self.problem.shafts, per_shaft, strict=True))
        return tuple(cws), shafts

    def as_placed(self, x: NDArray[np.float64]) -> NDArray[np.float64]:
        """``x`` with each chosen site as its placed mass says it (size and angle, as written)."""
        out = np.array(x, dtype=float)
        cws, shafts = self.masses(out)
        placed = list(cws) + [e for s in shafts for e in s.eccentrics]
        for i, c in zip(self.chosen, placed, strict=True):
            phase = math.radians(c.phase_deg)
            out[self.entries(i)] = c.mr * math.cos(phase), c.mr * math.sin(phase)
        return out

    def into_bounds(self, x: NDArray[np.float64]) -> NDArray[np.float64]:
        """``x`` with each chosen mass·radius beyond its bound scaled back onto it."""
        out = np.array(x, dtype=float)
        for i in self.chosen:
            size = abs(self.vector(out, i))
            bound = self.sites[i].max_mr
            if size > bound:
                out[self.entries(i)] *= bound / size
        return out

    def violations(self, x: NDArray[np.float64], tol: float) -> list[str]:
        """The bounds ``x`` breaks by more than ``tol`` of the bound, as text."""
        out = []
        for i in self.chosen:
            s, mr = self.sites[i], abs(self.vector(x, i))
            if mr > s.max_mr * (1 + tol):
                out.append(f"{s.where}: mr {mr:.9g} kg·m above {s.max_mr:.9g}")
        return out

    def model_of(self, model: Model, x: NDArray[np.float64]) -> Model:
        """``model`` with the chosen masses of ``x`` in place of the replaced ones."""
        counterweights, shafts = self.masses(x)
        return cast("RotorBalanced", model).with_rotor_masses(counterweights, shafts,
                                                              self.replaced)

    def unbalance(self, x: NDArray[np.float64]) -> float:
        """``√Σ (|x_i|·ω²)²`` over the chosen sites, N."""
        mask = self.chosen_entries(np.asarray(x).size)
        return float(np.linalg.norm(np.asarray(x)[mask])) * self.speed**2

    def bearing_loads(self, x: NDArray[np.float64], force: NDArray[np.complex128]
                      ) -> tuple[float, ...]:
        """Each new shaft's largest bearing force over the cycle, N.

        Its eccentrics' columns of the shaking force's regressors ``force`` (``(N, P)``) times
        their entries of ``x``.
        """
        out = []
        for j in range(len(self.problem.shafts)):
            cols = np.zeros(np.asarray(x).size, dtype=bool)
            for i in self.chosen:
                if self.sites[i].shaft == j:
                    cols[self.entries(i)] = True
            out.append(float(np.max(np.abs(force[:, cols] @ np.asarray(x)[cols]),
                                    initial=0.0)))
        return tuple(out)


def _placed(z: float, vector: complex, bound: float, crankshaft: int = 1) -> PlacedMass:
    """A mass·radius vector as its size and angle (none below :data:`ABSENT` of its bound)."""
    mr = abs(vector)
    if mr <= ABSENT * bound:
        return PlacedMass(z=z, mr=0.0, phase_deg=0.0, crankshaft=crankshaft)
    return PlacedMass(z=z, mr=min(mr, bound),
                      phase_deg=direction_deg(vector), crankshaft=crankshaft)


def sites_of(design: Design, start: int) -> tuple[Sites, NDArray[np.float64]]:
    """The sites of an engine's ``[balance]``, and their entries of the original design.

    The chosen sites' entries of the original are its replaced counterweights summed per
    plane (no new shaft); the kept ones' are their own.

    Raises
    ------
    SpecError
        If the spec names nothing to choose, or has no ``[operation]``.
    """
    problem = cast("RotorBalanceProblem", design.balance)
    if design.operation is None:
        raise SpecError("missing required key: the balancing objective is evaluated at the "
                        "operating speed", key="operation.speed")
    model = cast("RotorBalanced", design.mechanism)
    cws = problem.counterweights
    # A crank-web sector's room bounds each plane's mass·radius (balancer.parts.sizing).
    room = math.inf if cws is None or cws.part is None else most_mr(cws.part)
    sites: list[Site] = []
    if cws is not None:
        for k in cws.crankshafts or model.shafts:  # (none named: every crankshaft)
            if k not in model.shafts:
                raise SpecError(f"names no crankshaft: there are {len(model.shafts)}",
                                key="balance.counterweights.crankshafts",
                                value=list(cws.crankshafts or ()))
            sites += [Site(None, model.shaft_ratio(k), model.shaft_axis(k), z, min(mr, room),
                           crankshaft=k) for z, mr in zip(cws.planes, cws.max_mr, strict=True)]
    replaced = tuple((s.crankshaft, s.z) for s in sites)
    for j, shaft in enumerate(problem.shafts):
        sites += [Site(j, shaft.ratio, complex(*shaft.at), z, mr)
                  for z, mr in zip(shaft.planes, shaft.max_mr, strict=True)]
    if not sites:
        raise SpecError("nothing to choose: name counterweight planes "
                        "([balance.counterweights]) or a shaft ([[balance.shafts]])",
                        key="balance")
    original = np.zeros(2 * len(sites))
    for k, c in model.counterweights_in(replaced):
        i = next(i for i, s in enumerate(sites) if (s.crankshaft, s.z) == (k, c.z))
        original[2 * i: 2 * i + 2] += c.mr * np.array([math.cos(math.radians(c.phase_deg)),
                                                       math.sin(math.radians(c.phase_deg))])
    base = model.with_rotor_masses((), (), replaced)
    kept = [Site(-1, rotor.ratio, rotor.axis, e.z, e.mr, e.mr * complex(math.cos(e.angle),
                                                                         math.sin(e.angle)),
                 bearing=point)
            for point, rotor in mechanism_of(base).rotors for e in rotor.eccentrics if e.mr]
    values = [v for s in kept for v in (cast("complex", s.kept).real,
                                        cast("complex", s.kept).imag)]
    return (Sites(tuple(sites + kept), start, problem, replaced, design.operation.speed),
            np.concatenate([original, np.asarray(values, dtype=float)]))


def site_columns(sites: Sequence[Site], theta: NDArray[np.float64], omega: float,
                 alpha: float = 0.0) -> tuple[NDArray[np.complex128], NDArray[np.float64],
                                              NDArray[np.complex128]]:
    """The sites' regressor columns at crank angles ``theta``: force, moment, rocking couple.

    Each site's two columns are the loads of a unit mass·radius at angle 0 and ``π/2``
    (``Re x`` and ``Im x``), ``(N, 2·sites)``; the crank at rate ``omega`` and acceleration
    ``alpha``.
    """
    n = 2 * len(sites)
    force = np.zeros((theta.size, n), complex)
    couple = np.zeros((theta.size, n), complex)
    moment = np.zeros((theta.size, n))
    alphas = np.full(theta.size, alpha)
    for i, site in enumerate(sites):
        for col, angle in ((2 * i, 0.0), (2 * i + 1, math.pi / 2)):
            loads = site.rotor(angle).loads(theta, omega, alphas)
            force[:, col], couple[:, col], moment[:, col] = (loads.force, loads.couple,
                                                             loads.moment)
    return force, moment, couple


__all__ = ["Site", "Sites", "site_columns", "sites_of"]
