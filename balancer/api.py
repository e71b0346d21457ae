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


def analyze(design: Design, *, route: str | None = None,
            gravity: tuple[float, float] | None = None) -> CycleAnalysis:
    """One crank revolution at the design's operating speed (``[operation]``).

    Parameters
    ----------
    design
        The design.
    route
        Inverse-dynamics route (default the mechanism's first).
    gravity
        Gravitational acceleration ``(gx, gy)``, m/s², instead of the spec's
        ``[operation] gravity`` (whose default is none); the figures then include the weights.

    Raises
    ------
    SpecError
        If the spec has no operating speed, the crank cannot turn a full revolution, or
        ``gravity`` is not two finite numbers.
    """
    if design.operation is None:
        raise SpecError(
            "missing required key: a cycle analysis needs the operating speed",
            key="operation.speed",
        )
    op = design.operation
    if gravity is None:
        gravity = op.gravity
    else:
        from . import validate as v
        from .model import check_scales

        gravity = v.vector2(gravity, "gravity")
        check_scales(design.mechanism, {"operation.speed": op.speed}, {"gravity": gravity})
    return cycle_analysis(design.mechanism, op.speed, op.samples, route=route, gravity=gravity)
