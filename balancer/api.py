"""The Python API in a few calls, for scripts and notebooks.

>>> from balancer import load_design, analyze
>>> design = load_design("examples/meijaard2020.toml")
>>> analysis = analyze(design)
>>> analysis.summary.shaking_moment.rms  # doctest: +SKIP

Each call takes a :class:`~balancer.model.Design` (from :func:`~balancer.spec.load_design`) and
returns a result object; nothing here prints or writes files.
"""

from __future__ import annotations

from .cycle import DRAWING_TOLERANCE, CycleAnalysis, cycle_analysis, drawn_analyses
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


def cycle_analyses(design: Design, *, samples: int | None = None,
                   tolerance: float = DRAWING_TOLERANCE) -> tuple[CycleAnalysis,
                                                                   CycleAnalysis | None]:
    """One revolution of the design and of its original, sampled finely enough to draw.

    At the operating speed with the spec's gravity, from at least the spec's ``samples``
    (:func:`balancer.cycle.drawn_analyses`, to ``tolerance`` of each panel's span); with
    ``samples``, exactly that many crank angles.

    Returns
    -------
    tuple
        ``(design's, original's or None)`` :class:`~balancer.cycle.CycleAnalysis`, both at
        the same crank angles.

    Raises
    ------
    SpecError
        If the design has no operating speed; :class:`~balancer.errors.AssemblyError` if a
        crank cannot turn a full revolution.
    """
    if design.operation is None:
        raise SpecError("missing required key: a cycle analysis needs the operating speed",
                        key="operation.speed")
    op = design.operation
    models = [design.mechanism, *([design.original] if design.original is not None else [])]
    analyses = drawn_analyses(models, op.speed, samples=samples, least=op.samples,
                              gravity=op.gravity, tolerance=tolerance)
    return analyses[0], (analyses[1] if len(analyses) > 1 else None)


def optimize(design: Design, *, backend: str = "nlp"):
    """The balanced design of the spec's ``[balance]`` problem (:class:`BalanceResult`).

    ``backend`` ``"nlp"`` (the certified convex optimum, then IPOPT on the designer's own
    parameters) or ``"convex"``. See :func:`balancer.balance.optimizer.optimize`.
    """
    from .balance.optimizer import optimize as run

    return run(design, backend)


def simulate(design: Design, *, method: str | None = None, drive: str | None = None,
             duration: float | None = None, rtol: float | None = None,
             atol: float | None = None, outputs: int | None = None):
    """Forward dynamics from the spec's ``[simulation]``, each keyword overriding it.

    Returns a :class:`~balancer.simulation.Trajectory`. See
    :func:`balancer.simulation.simulate_design`.
    """
    from .simulation import simulate_design

    return simulate_design(design, method=method, drive=drive, duration=duration, rtol=rtol,
                           atol=atol, outputs=outputs)


def verify(design: Design, *, method: str | None = None, duration: float | None = None):
    """Proof by simulation (driven and free) that a design is balanced (:class:`Verification`).

    See :func:`balancer.verification.verify`.
    """
    from .verification import verify as run

    return run(design, method=method, duration=duration)


def pareto(design: Design, *, against: str, points: int = 11):
    """The exact front of least RMS shaking moment against ``against`` (:class:`Front`).

    ``against``: ``"driving-torque"``, ``"added-mass"`` or ``"shaking-force"``. See
    :func:`balancer.balance.pareto.pareto_front`.
    """
    from .balance.pareto import pareto_front

    return pareto_front(design, against, points)


def example(name: str) -> Design:
    """A design spec shipped with the package, by name (``balancer example`` lists them)."""
    from . import examples

    return examples.load(name)


def to_dict(result) -> dict:
    """Any result as the plain dictionary the command line prints with ``--json``.

    A cycle analysis (``analyze``), a balancing result (``optimize``: ``before`` and ``after``
    with loads and gravity, ``inertial`` without, as the command prints them), a trajectory
    (``simulate``), a verification (``verify``) or a front (``pareto``).
    """
    from . import report
    from .balance.pareto import Front
    from .balance.result import BalanceResult
    from .simulation import Trajectory
    from .verification import Verification

    if isinstance(result, CycleAnalysis):
        return report.analysis_json(result)
    if isinstance(result, BalanceResult):
        return report.optimization_json(result, *result.operating)
    if isinstance(result, Trajectory):
        return report.simulation_json(result)
    if isinstance(result, Verification | Front):
        return result.as_dict()
    raise TypeError(f"no dictionary form for {type(result).__name__}")


def to_table(result):
    """A cycle analysis or a trajectory as a tidy table (``pyarrow.Table``, one row per sample).

    The columns of ``analyze --csv`` or ``simulate --out --all-columns`` (SI units); a front's
    points, one row each. ``.to_pandas()`` gives a DataFrame where pandas is installed.
    """
    import numpy as np
    import pyarrow as pa

    from .balance.pareto import Front
    from .simulation import Trajectory

    if isinstance(result, CycleAnalysis):
        names, values = result.columns()
    elif isinstance(result, Trajectory):
        names, values = result.columns(all_columns=True)
    elif isinstance(result, Front):
        rows = result.as_dict()["points"]
        return pa.Table.from_pylist(rows)
    else:
        raise TypeError(f"no table form for {type(result).__name__}")
    n = np.shape(values[0])
    return pa.table({name: np.broadcast_to(np.asarray(v, dtype=float), n)
                     for name, v in zip(names, values, strict=True)})
