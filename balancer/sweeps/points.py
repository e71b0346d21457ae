"""A sweep's points: the varied keys on a grid or sampled, or perturbed around the spec.

:class:`Vary` (``--vary KEY=LOW:HIGH:N``) and :func:`design_points` give the points of a design
sweep, on a grid or at ``samples`` points of a Latin hypercube or a Sobol' sequence (SciPy's
``qmc``); :class:`Perturb` (``--perturb KEY=SIGMA``) and :func:`perturbed_points` the seeded
draws of a tolerance study around the spec's own values.
"""

from __future__ import annotations

import itertools
import math
from collections.abc import Sequence
from dataclasses import dataclass
from typing import Any

from ..errors import SpecError
from .keys import key_value

#: Sampling methods of the varied keys.
METHODS = ("grid", "lhs", "sobol")
#: Most points one sweep takes (a million certified optima: hours on a laptop, and the table's
#: points are held in memory while it runs); a larger design space is several sweeps.
MAX_POINTS = 1_000_000


@dataclass(frozen=True)
class Perturb:
    """One perturbed key: the spec's value plus a normal deviate of deviation ``sigma``."""

    key: str
    sigma: float

    @classmethod
    def parse(cls, text: str) -> Perturb:
        """From ``KEY=SIGMA`` (SIGMA in the key's own unit)."""
        key, sep, rest = text.partition("=")
        try:
            sigma = float(rest)
        except ValueError:
            sigma = math.nan
        if not sep or not key or not (math.isfinite(sigma) and sigma > 0):
            raise SpecError("must be KEY=SIGMA with SIGMA > 0, e.g. links.crank.mass=0.01",
                            key="--perturb", value=text)
        return cls(key=key.strip(), sigma=sigma)


def perturbed_points(data: dict[str, Any], perturbs: Sequence[Perturb], samples: int | None,
                     seed: int = 0) -> list[dict[str, float]]:
    """``samples`` draws of the perturbed keys around the spec's values (seeded)."""
    import numpy as np

    _check_samples(samples, "--perturb")
    assert samples is not None  # (checked)
    keys = [p.key for p in perturbs]
    if len(set(keys)) != len(keys):
        raise SpecError("a key is perturbed twice", key="--perturb", value=", ".join(keys))
    base = [key_value(data, p.key) for p in perturbs]
    rng = np.random.default_rng(seed)
    draws = rng.standard_normal((samples, len(perturbs)))
    return [{p.key: b + p.sigma * float(d) for p, b, d in zip(perturbs, base, row, strict=True)}
            for row in draws]


def _check_samples(samples: int | None, what: str) -> None:
    """``--samples`` given, and within :data:`MAX_POINTS`."""
    if not samples or samples < 1:
        raise SpecError(f"{what} needs --samples N", key="--samples", value=samples)
    if samples > MAX_POINTS:
        raise SpecError(f"must be at most {MAX_POINTS:,} (several sweeps for more)",
                        key="--samples", value=samples)



@dataclass(frozen=True)
class Vary:
    """One varied key: ``key`` from ``low`` to ``high`` (``count`` values on a grid)."""

    key: str
    low: float
    high: float
    count: int

    @classmethod
    def parse(cls, text: str) -> Vary:
        """From ``KEY=LOW:HIGH:N`` (``N`` may be left out when sampling: ``KEY=LOW:HIGH``)."""
        key, sep, rest = text.partition("=")
        parts = rest.split(":")
        if not sep or not key or len(parts) not in (2, 3):
            raise SpecError("must be KEY=LOW:HIGH:N, e.g. mechanism.lengths.coupler=2.5:3.5:11",
                            key="--vary", value=text)
        try:
            low, high = float(parts[0]), float(parts[1])
            count = int(parts[2]) if len(parts) == 3 else 0
        except ValueError:
            raise SpecError("LOW and HIGH must be numbers, N a whole number", key="--vary",
                            value=text) from None
        if not (math.isfinite(low) and math.isfinite(high)) or low > high:
            raise SpecError("needs finite LOW ≤ HIGH", key="--vary", value=text)
        if len(parts) == 3 and count < 1:
            raise SpecError("N must be at least 1", key="--vary", value=text)
        return cls(key=key.strip(), low=low, high=high, count=count)


def design_points(varies: Sequence[Vary], method: str = "grid", samples: int | None = None,
                  seed: int = 0) -> list[dict[str, float]]:
    """The sweep's points: each a ``{key: value}``, in the table's order.

    ``grid``: every combination of each key's ``count`` evenly spaced values (the last key
    varying fastest). ``lhs``, ``sobol``: ``samples`` points of a Latin hypercube or a scrambled
    Sobol' sequence (seeded) scaled to the ranges.
    """
    if method not in METHODS:
        raise SpecError(f"must be one of {', '.join(METHODS)}", key="--method", value=method)
    if not varies:
        raise SpecError("nothing to vary: give --vary KEY=LOW:HIGH:N", key="--vary")
    keys = [v.key for v in varies]
    if len(set(keys)) != len(keys):
        raise SpecError("a key is varied twice", key="--vary", value=", ".join(keys))
    if method == "grid":
        for v in varies:
            if v.count < 1:
                raise SpecError("a grid needs N for every key (KEY=LOW:HIGH:N)", key="--vary",
                                value=v.key)
        total = math.prod(v.count for v in varies)
        if total > MAX_POINTS:
            raise SpecError(f"makes {total:.3g} points, more than the {MAX_POINTS:,} one sweep "
                            "takes: use fewer values per key, or several sweeps",
                            key="--vary", value=", ".join(f"{v.key}:{v.count}" for v in varies))
        axes = [[v.low] if v.count == 1 else
                [v.low + (v.high - v.low) * i / (v.count - 1) for i in range(v.count)]
                for v in varies]
        return [dict(zip(keys, combo, strict=True)) for combo in itertools.product(*axes)]
    _check_samples(samples, f"--method {method}")
    from scipy.stats import qmc

    sampler = (qmc.LatinHypercube(d=len(varies), seed=seed) if method == "lhs"
               else qmc.Sobol(d=len(varies), scramble=True, seed=seed))
    unit = sampler.random(samples)
    return [{v.key: v.low + (v.high - v.low) * float(u[i]) for i, v in enumerate(varies)}
            for u in unit]
