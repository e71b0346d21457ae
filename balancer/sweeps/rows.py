"""A sweep's rows: the design at a point, analysed and balanced (or analysed alone).

:func:`evaluate_point` is one row of a design sweep (the certified optimum of
:func:`balancer.balance.optimizer.optimize`, convex backend, and the design's own figures);
:func:`analyse_point` one row of a perturbation sweep (the design's own figures alone);
:func:`run_batch` a batch of them, one Dask task. :data:`COLUMNS` are the table's columns after
the varied keys.
"""

from __future__ import annotations

from typing import Any

from ..balance.optimizer import optimize
from ..balance.result import InfeasibleError
from ..cycle import cycle_analysis, one_thread
from ..errors import AssemblyError, LockupError, SolverError, SpecError
from ..model import Design
from ..motion_analysis import along_motions
from ..spec import design_from_dict
from .keys import with_values

#: The table's fixed columns after the varied keys, in order.
COLUMNS = ("point", "status", "shaking_moment_before", "shaking_moment_after",
           "shaking_force_before", "shaking_force_after", "rocking_couple_before",
           "rocking_couple_after", "lower_bound", "added_mass", "message")


def _empty_row(values: dict[str, float], index: int) -> dict[str, Any]:
    """A row with the point's values and every figure still empty."""
    return {**values, "point": index, "status": "", "message": "",
            **{name: None for name in COLUMNS[2:-1]}}


def _own_figures(design: Design) -> dict[str, float]:
    """The design's own inertial figures (the ``before`` columns).

    At the operating speed, or along its motions (a linkage with several inputs).
    """
    if design.operation is None:  # (the sweep has checked: several inputs, with motions)
        summary = along_motions(design.mechanism, design.motions, loads=False).summary
    else:
        summary = cycle_analysis(design.mechanism, design.operation.speed,
                                 design.operation.samples, loads=False).summary
    return {"shaking_moment_before": summary.shaking_moment.rms,
            "shaking_force_before": summary.shaking_force.rms,
            "rocking_couple_before": summary.rocking_couple.rms}


def evaluate_point(data: dict[str, Any], values: dict[str, float], index: int
                   ) -> dict[str, Any]:
    """One row of the table: the design at ``values``, analysed and balanced."""
    row = _empty_row(values, index)
    try:
        design = design_from_dict(with_values(data, values))
        result = optimize(design, "convex")
    except (AssemblyError, LockupError, SpecError) as exc:
        # It does not assemble, its crank does not turn fully, or a value makes the spec
        # invalid (a negative length, …).
        row.update(status="bad-geometry", message=str(exc))
        return row
    except SolverError as exc:  # InfeasibleError among them: the design's own figures
        row.update(status="infeasible" if isinstance(exc, InfeasibleError) else "failed",
                   message=str(exc))
        try:
            row.update(_own_figures(design))
        except Exception:  # noqa: BLE001 - the row keeps its status; figures stay empty
            pass
        return row
    before, after = result.before.summary, result.after.summary
    row.update(status=str(result.status), message=result.message,
               shaking_moment_before=before.shaking_moment.rms,
               shaking_moment_after=after.shaking_moment.rms,
               shaking_force_before=before.shaking_force.rms,
               shaking_force_after=after.shaking_force.rms,
               rocking_couple_before=before.rocking_couple.rms,
               rocking_couple_after=after.rocking_couple.rms,
               lower_bound=result.rms_lower_bound if result.rms_form else None,
               added_mass=result.added_mass)
    return row



def analyse_point(data: dict[str, Any], values: dict[str, float], index: int
                  ) -> dict[str, Any]:
    """One row of a perturbation sweep: the perturbed design's own figures (no redesign)."""
    row = _empty_row(values, index)
    try:
        design = design_from_dict(with_values(data, values))
        if design.operation is None and not design.motions:
            raise SpecError("missing required key", key="operation.speed")
        row.update(_own_figures(design), status="analysed")
    except (AssemblyError, LockupError, SpecError) as exc:
        row.update(status="bad-geometry", message=str(exc))
    return row



def run_batch(data: dict[str, Any], batch: list[tuple[int, dict[str, float]]],
              analyse_only: bool = False) -> list[dict[str, Any]]:
    """Evaluate a batch of points (a Dask task): their rows, in order.

    ``analyse_only``: the designs' own figures (a perturbation sweep), no redesign. A long
    cycle's chunks run on the task's own thread (:func:`~balancer.cycle.one_thread`): the
    machine's other cores are the other workers'.
    """
    evaluate = analyse_point if analyse_only else evaluate_point
    with one_thread():  # (a long cycle's chunks: on this worker's thread alone)
        return [evaluate(data, values, index) for index, values in batch]
