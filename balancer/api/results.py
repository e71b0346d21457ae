"""Results as the command line prints them: a JSON-like dictionary, a table of the samples."""

from __future__ import annotations

from typing import Any

import numpy as np

from .. import report
from ..balance.front import Front
from ..balance.result import BalanceResult
from ..cycle import CycleAnalysis
from ..simulation import Trajectory
from ..verification import Verification


def to_dict(result: CycleAnalysis | BalanceResult | Trajectory | Verification | Front
            ) -> dict[str, Any]:
    """Any result as the plain dictionary the command line prints with ``--json``.

    A cycle analysis (``analyze``), a balancing result (``optimize``: ``before`` and ``after``
    with loads and gravity, ``inertial`` without, as the command prints them), a trajectory
    (``simulate``), a verification (``verify``) or a front (``pareto``).
    """
    if isinstance(result, CycleAnalysis):
        return report.analysis_json(result)
    if isinstance(result, BalanceResult):
        return report.optimization_json(result, *result.operating)
    if isinstance(result, Trajectory):
        return report.simulation_json(result)
    if isinstance(result, Verification | Front):
        return result.as_dict()
    raise TypeError(f"no dictionary form for {type(result).__name__}")


def to_table(result: CycleAnalysis | Trajectory | Front) -> Any:
    """A cycle analysis or a trajectory as a tidy table (``pyarrow.Table``, one row per sample).

    The columns of ``analyze --csv`` or ``simulate --out --all-columns`` (SI units); a front's
    points, one row each. ``.to_pandas()`` gives a DataFrame where pandas is installed.
    """
    import pyarrow as pa

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
