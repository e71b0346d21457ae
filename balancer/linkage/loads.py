"""What a mechanism does to its frame at a set of states: one record, :class:`Reactions`.

The cycle analysis, a simulation's trajectory and the seeds' closed forms all give their
frame loads as this record. The core's arithmetic forms stay beside it:
:class:`~balancer.linkage.dynamics.Forces` (columns of vectors, on numpy arrays or CasADi
symbols, for designs or parameters) and :class:`~balancer.linkage.dynamics.Shaking` (linear
maps of the design vector); :meth:`Reactions.of` is the one conversion from forces to the
record, :meth:`Reactions.forces` the record's arrays seen as forces.
"""

from __future__ import annotations

from collections.abc import Iterable, Sequence
from dataclasses import dataclass, field
from typing import Any

import numpy as np
from numpy.typing import NDArray

from .dynamics import Forces
from .vectors import V


@dataclass(frozen=True, eq=False)
class SupportLoad:
    """The load on the frame at one of the supports that share a ground point's reaction.

    An engine's main bearing, each carrying its share of the crankshaft's loads: the supports
    of one ground point sum to its reaction in :class:`Reactions`.

    Attributes
    ----------
    name
        The support's name (``B1``, ``B2``, …).
    z
        Its plane along the axis, m.
    force
        Its load on the frame at each sample, complex ``x + i·y``, N.
    """

    name: str
    z: float
    force: NDArray[np.complex128]


@dataclass(frozen=True, eq=False)
class Reactions:
    """What the mechanism exerts on its frame at each sample (arrays of shape ``(N,)``).

    The package's one numeric record of the frame's loads; the core computes them as
    :class:`~balancer.linkage.dynamics.Forces` (on numpy arrays or CasADi symbols) and
    :class:`~balancer.linkage.dynamics.Shaking` (maps of the design vector), and
    :meth:`of` makes this record of forces.

    Attributes
    ----------
    ground
        Force on the ground at each ground point, complex ``x + i·y``, N.
    slider_normal, slider_couple
        Normal force (N) and couple (N·m) of each slider on a ground guide, by link.
    shaking_force
        Sum of all forces on the frame, complex, N.
    shaking_moment
        Their moment about the origin, with the motors' reactions and counter-rotors, N·m.
    torques
        Torque of each motor on its input, N·m, in the order of the mechanism's inputs
        (:attr:`driving_torque`: a one-input mechanism's).
    rocking_couple
        The couple about ``x`` and ``y`` from links in planes along the crank's axis, complex
        ``Mx + i·My``, N·m (zero for a mechanism in one plane).
    teeth
        Each gear pair's tooth force on its driven gear at the pitch point, complex, N, by
        the pair's name (internal: it reaches the frame through the gears' pivots).
    """

    ground: dict[str, NDArray[np.complex128]]
    slider_normal: dict[str, NDArray[np.float64]]
    slider_couple: dict[str, NDArray[np.float64]]
    shaking_force: NDArray[np.complex128]
    shaking_moment: NDArray[np.float64]
    torques: tuple[NDArray[np.float64], ...]
    rocking_couple: NDArray[np.complex128]
    teeth: dict[str, NDArray[np.complex128]] = field(default_factory=dict)

    @property
    def driving_torque(self) -> NDArray[np.float64]:
        """A one-input mechanism's motor torque on its crank, N·m (``ValueError`` for several)."""
        if len(self.torques) != 1:
            raise ValueError(f"the loads have {len(self.torques)} input torques, not one")
        return self.torques[0]

    @classmethod
    def of(cls, forces: Forces, column: int = 0) -> Reactions:
        """The loads of one column of the core's ``forces`` (arrays ``(N, C)``), at its states."""
        def real(a: Any) -> NDArray[np.float64]:
            return np.asarray(a)[:, column]

        def vector(v: V) -> NDArray[np.complex128]:
            return np.asarray(v.complex())[:, column]

        return cls(ground={p: vector(v) for p, v in forces.reactions.items()},
                   slider_normal={k: real(v) for k, v in forces.slider_normal.items()},
                   slider_couple={k: real(v) for k, v in forces.slider_couple.items()},
                   shaking_force=vector(forces.shaking_force),
                   shaking_moment=real(forces.shaking_moment),
                   torques=tuple(real(t) for t in forces.input_torques),
                   rocking_couple=vector(forces.rocking_couple),
                   teeth={g: vector(v) for g, v in forces.teeth.items()})

    @classmethod
    def empty(cls, n: int, ground_points: Iterable[str], sliders: Iterable[str],
              inputs: int = 1, teeth: Iterable[str] = ()) -> Reactions:
        """Uninitialised arrays for ``n`` states.

        At these ground points and ground sliders, ``inputs`` motors' torques and these gear
        pairs' tooth forces.
        """
        sliders = tuple(sliders)
        return cls(ground={p: np.empty(n, complex) for p in ground_points},
                   slider_normal={k: np.empty(n) for k in sliders},
                   slider_couple={k: np.empty(n) for k in sliders},
                   shaking_force=np.empty(n, complex), shaking_moment=np.empty(n),
                   torques=tuple(np.empty(n) for _ in range(inputs)),
                   rocking_couple=np.empty(n, complex),
                   teeth={g: np.empty(n, complex) for g in teeth})

    @classmethod
    def join(cls, parts: Sequence[Reactions]) -> Reactions:
        """The loads of ``parts`` one after another (the same ground points, sliders, inputs)."""
        first = parts[0]

        def joined(arrays: list[NDArray[Any]]) -> NDArray[Any]:
            return np.concatenate(arrays)

        return cls(
            ground={p: joined([r.ground[p] for r in parts]) for p in first.ground},
            slider_normal={k: joined([r.slider_normal[k] for r in parts])
                           for k in first.slider_normal},
            slider_couple={k: joined([r.slider_couple[k] for r in parts])
                           for k in first.slider_couple},
            shaking_force=joined([r.shaking_force for r in parts]),
            shaking_moment=joined([r.shaking_moment for r in parts]),
            torques=tuple(joined([r.torques[i] for r in parts])
                          for i in range(len(first.torques))),
            rocking_couple=joined([r.rocking_couple for r in parts]),
            teeth={g: joined([r.teeth[g] for r in parts]) for g in first.teeth})

    def arrays(self) -> list[NDArray[Any]]:
        """Every array of the record (the ground points' and sliders' first)."""
        return [*self.ground.values(), *self.slider_normal.values(),
                *self.slider_couple.values(), self.shaking_force, self.shaking_moment,
                *self.torques, self.rocking_couple, *self.teeth.values()]

    @property
    def size(self) -> int:
        """Number of states."""
        return int(np.prod(np.broadcast_shapes(*(np.shape(a) for a in self.arrays()))))

    def at(self, where: Any) -> Reactions:
        """The loads at states ``where`` (an index array, a mask or a slice: views for a slice)."""
        def pick(a: Any) -> Any:
            return np.asarray(a)[where]

        return Reactions(ground={p: pick(v) for p, v in self.ground.items()},
                         slider_normal={k: pick(v) for k, v in self.slider_normal.items()},
                         slider_couple={k: pick(v) for k, v in self.slider_couple.items()},
                         shaking_force=pick(self.shaking_force),
                         shaking_moment=pick(self.shaking_moment),
                         torques=tuple(pick(t) for t in self.torques),
                         rocking_couple=pick(self.rocking_couple),
                         teeth={g: pick(v) for g, v in self.teeth.items()})

    def forces(self, rocking_couple: V | None = None) -> Forces:
        """The record as the core's forces of one column, ``(N, 1)``.

        Views of the record's arrays (what is written there is the record's) where they have
        all ``N`` states; an array given for fewer (a constant) is broadcast, read-only.
        ``rocking_couple``: forces' own couple instead of the record's.
        """
        n = self.size

        def real(a: Any) -> NDArray[np.float64]:
            a = np.asarray(a)
            return (a if a.shape == (n,) else np.broadcast_to(a, (n,)))[:, None]

        def vector(a: NDArray[np.complex128]) -> V:
            a = np.asarray(a)
            return V(real(a.real), real(a.imag))

        return Forces(reactions={p: vector(v) for p, v in self.ground.items()},
                      slider_normal={k: real(v) for k, v in self.slider_normal.items()},
                      slider_couple={k: real(v) for k, v in self.slider_couple.items()},
                      input_torques=tuple(real(t) for t in self.torques),
                      shaking_force=vector(self.shaking_force),
                      shaking_moment=real(self.shaking_moment),
                      rocking_couple=(vector(self.rocking_couple) if rocking_couple is None
                                      else rocking_couple),
                      teeth={g: vector(v) for g, v in self.teeth.items()})

    def largest_force(self) -> float:
        """The largest force on the frame at one ground point or guide, N (0 for neither).

        The magnitudes of the forces at the ground points and the sliders' normal forces on
        their guides, states that do not exist (NaN) left out.
        """
        return max((float(np.nanmax(np.abs(v), initial=0.0)) for v in
                    (*self.ground.values(), *self.slider_normal.values())), default=0.0)
