"""The state of a mechanism's inputs: positions, rates and accelerations of its driven joints.

A linkage with ``n`` inputs (driven links, each turned about its ground pivot) is placed by
``n`` positions; its motion needs their rates and accelerations too. An :class:`InputState`
holds the three at ``N`` states at once (arrays of shape ``(N,)`` per input, broadcast
together), or CasADi symbols in the programs built on symbols. A one-input mechanism's crank
state ``(θ1, ω1, α1)`` is the case ``n = 1`` (:meth:`InputState.crank`).

Units: an input turned about a pivot has its position in rad (the driven link's frame angle in
the spec's frame, as the crank's ``θ1``), its rate in rad/s and its acceleration in rad/s².
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np
from numpy.typing import ArrayLike, NDArray

from .vectors import Num


@dataclass(frozen=True, eq=False)
class InputState:
    """Positions, rates and accelerations of every input at ``N`` states.

    Attributes
    ----------
    positions, rates, accelerations
        One entry per input, in the order of the linkage's inputs: rad, rad/s, rad/s² (arrays
        of one shape, or CasADi symbols).
    """

    positions: tuple[Num, ...]
    rates: tuple[Num, ...]
    accelerations: tuple[Num, ...]

    @classmethod
    def of(cls, positions: Sequence[ArrayLike] | NDArray[np.float64],
           rates: Sequence[ArrayLike] | NDArray[np.float64] | None = None,
           accelerations: Sequence[ArrayLike] | NDArray[np.float64] | None = None
           ) -> InputState:
        """Numeric states: one row of positions per input (rad), rates and accelerations.

        Rates and accelerations likewise (default zero), all broadcast to one shape ``(N,)``
        (a scalar gives ``N = 1``).
        """
        count = len(positions)
        if count == 0:
            raise ValueError("an input state needs at least one input")
        zeros = [0.0] * count
        rows = [*positions, *(zeros if rates is None else rates),
                *(zeros if accelerations is None else accelerations)]
        if len(rows) != 3 * count:
            raise ValueError("positions, rates and accelerations must name the same inputs")
        arrays = [np.atleast_1d(np.asarray(x, dtype=float))
                  for x in np.broadcast_arrays(*(np.asarray(r, dtype=float) for r in rows))]
        return cls(tuple(arrays[:count]), tuple(arrays[count : 2 * count]),
                   tuple(arrays[2 * count :]))

    @classmethod
    def crank(cls, theta1: ArrayLike, omega1: ArrayLike = 0.0, alpha1: ArrayLike = 0.0
              ) -> InputState:
        """A one-input mechanism's crank states, broadcast together.

        Angle (rad), rate (rad/s), acceleration (rad/s²).
        """
        return cls.of([theta1], [omega1], [alpha1])

    @classmethod
    def symbolic(cls, positions: Sequence[Num], rates: Sequence[Num],
                 accelerations: Sequence[Num]) -> InputState:
        """States on symbols (CasADi's), taken as given."""
        return cls(tuple(positions), tuple(rates), tuple(accelerations))

    @classmethod
    def join(cls, parts: Sequence[InputState]) -> InputState:
        """Numeric states of ``parts`` one after another (the same inputs)."""
        def joined(get: str) -> list[NDArray[np.float64]]:
            return [np.concatenate([np.asarray(getattr(p, get)[i], dtype=float) for p in parts])
                    for i in range(parts[0].size)]

        return cls.of(joined("positions"), joined("rates"), joined("accelerations"))

    @property
    def size(self) -> int:
        """The number of inputs ``n``."""
        return len(self.positions)

    @property
    def count(self) -> int:
        """The number of states ``N`` (numeric states)."""
        return int(np.size(self.positions[0]))

    def key(self) -> tuple[object, ...]:
        """A hashable key of numeric states (their shape and every figure's bytes)."""
        first = np.asarray(self.positions[0])
        return (first.shape, *(np.asarray(x).tobytes() for x in
                               (*self.positions, *self.rates, *self.accelerations)))

    def at(self, rows: NDArray[np.bool_] | NDArray[np.intp]) -> InputState:
        """The numeric states at ``rows`` (a mask or indices)."""
        def take(xs: tuple[Num, ...]) -> tuple[Num, ...]:
            return tuple(np.asarray(x)[rows] for x in xs)
        return InputState(take(self.positions), take(self.rates), take(self.accelerations))

    def sole(self) -> tuple[Num, Num, Num]:
        """A one-input mechanism's ``(θ1, ω1, α1)``; ``ValueError`` for several inputs."""
        if self.size != 1:
            raise ValueError(f"the state has {self.size} inputs, not one")
        return self.positions[0], self.rates[0], self.accelerations[0]
