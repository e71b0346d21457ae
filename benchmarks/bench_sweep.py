"""Benchmark: design-space sweeps (issue 15) — points per second, against a plain loop.

Run on its own: ``python benchmarks/bench_sweep.py [--full]``. The PB1 family: the coupler and
the frame of examples/pb1.toml varied on a grid (a quarter of the points do not assemble as a
crank-rocker and cost little). Rows:

- a plain Python loop over the points (``evaluate_point``, no Dask, no files);
- the sweep in this process (``--workers 0``: batches and Parquet parts, no Dask);
- the sweep on a LocalCluster of 1 and of 2 worker processes (cluster start-up included);

each at two sizes, to show the cost linear in the points. ``--full`` adds issue 32's two
10,000-point sweeps on two workers: PB1's family (goal ≤ 60 s) and the Watt six-bar's with
``mechanism.points.B0.0`` and ``mechanism.points.D0.1`` each ±10 % (goal ≤ 120 s).
"""

from __future__ import annotations

import sys
import tempfile
import time
import tomllib
from pathlib import Path

from tables import print_table

ROOT = Path(__file__).resolve().parent.parent
SPEC = ROOT / "examples" / "pb1.toml"


def _grid(n: int):
    from balancer.sweeps import Vary

    side = round(n**0.5)
    return [Vary.parse(f"mechanism.lengths.coupler=2.0:4.0:{side}"),
            Vary.parse(f"mechanism.lengths.frame=2.5:3.5:{side}")]


def _loop(n: int) -> float:
    from balancer.sweeps import design_points, evaluate_point

    data = tomllib.loads(SPEC.read_text())
    points = design_points(_grid(n))
    start = time.perf_counter()
    for i, values in enumerate(points):
        evaluate_point(data, values, i)
    return time.perf_counter() - start


def _watt_grid(n: int):
    """The Watt six-bar's family of issue 32: B0's x and D0's y each ±10 %."""
    from balancer.sweeps import Vary

    side = round(n**0.5)
    return [Vary.parse(f"mechanism.points.B0.0=0.144:0.176:{side}"),
            Vary.parse(f"mechanism.points.D0.1=0.27:0.33:{side}")]


def _sweep(n: int, workers: int, spec: Path = SPEC, grid=_grid) -> float:
    from balancer.sweeps import sweep

    with tempfile.TemporaryDirectory() as tmp:
        start = time.perf_counter()
        sweep(spec, grid(n), Path(tmp) / "sweep.parquet", workers=workers)
        return time.perf_counter() - start


def main() -> None:
    from balancer.sweeps import design_points, evaluate_point

    # Warm-up: imports and first-call costs of this process.
    data = tomllib.loads(SPEC.read_text())
    for i, values in enumerate(design_points(_grid(16))):
        evaluate_point(data, values, i)
    sizes = (400, 1600)
    rows = []
    for n in sizes:
        rows.append(("plain loop", n, _loop(n)))
    for workers, label in ((0, "sweep, in process"), (1, "sweep, 1 Dask worker"),
                           (2, "sweep, 2 Dask workers")):
        for n in sizes:
            rows.append((label, n, _sweep(n, workers)))
    if "--full" in sys.argv:  # issue 32's goals, cluster start included
        rows.append(("sweep, 2 Dask workers (goal ≤ 60 s)", 10_000, _sweep(10_000, 2)))
        rows.append(("Watt six-bar ±10 %, 2 Dask workers (goal ≤ 120 s)", 10_000,
                     _sweep(10_000, 2, ROOT / "examples" / "watt_sixbar.toml", _watt_grid)))
    header = ("run", "points", "seconds", "points/s")
    cells = [(r, str(n), f"{s:.2f}", f"{n / s:.1f}") for r, n, s in rows]
    print(f"PB1 family (coupler × frame grid); Python {sys.version.split()[0]}")
    print_table(header, cells)


if __name__ == "__main__":
    main()
