"""The Python API in a few calls, for scripts and notebooks.

>>> from balancer import load_design, analyze
>>> design = load_design("examples/meijaard2020.toml")
>>> analysis = analyze(design)
>>> analysis.summary.shaking_moment.rms  # doctest: +SKIP

Each call takes a :class:`~balancer.model.Design` (from :func:`~balancer.spec.load_design`) and
returns a result object; nothing here prints or writes files.
"""

from __future__ import annotations

from .cycle import CycleAnalysis, cycle_analysis
from .errors import SpecError
from .model import Design


def analyze(design: Design, *, route: str | None = None) -> CycleAnalysis:
    """One crank revolution at the design's operating speed (``[operation]``).

    Raises
    ------
    SpecError
        If the spec has no operating speed, or the crank cannot turn a full revolution.
    """
    if design.operation is None:
        raise SpecError(
            "missing required key: a cycle analysis needs the operating speed",
            key="operation.speed",
        )
    return cycle_analysis(design.mechanism, design.operation.speed, design.operation.samples,
                          route=route)
