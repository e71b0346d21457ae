"""Benchmark: design-space sweeps (issue 15) — points per second, against a plain loop.

Run on its own: ``python benchmarks/bench_sweep.py [--full] [--markdown]``. The PB1 family: the
coupler and the frame of examples/pb1.toml varied on a grid (a quarter of the points do not
assemble as a crank-rocker and cost little). Rows:

- a plain Python loop over the points (``evaluate_point``, no Dask, no files): what one core
  balances, the anchor of the rows below;
- the sweep in this process (``--workers 0``: batches and Parquet parts, no Dask);
- the sweep on a LocalCluster of 1 and of 2 worker processes (cluster start-up included);

each at two sizes, to show the cost linear in the points, and issue 40's 2,000-point sweep on
two local workers, start included. Its goal (15 s on a 2-core AMD EPYC whose plain loop is to
reach 115 points/s) is stated as a ratio to the plain loop measured in the same run: the sweep
of 2,000 points in at most 15 s ÷ (2,000 / 115 points/s) = 0.86 of the time the plain loop
takes for 2,000 points (one core's work, on two). ``--full`` adds issue 32's two 10,000-point
sweeps on two workers: PB1's family (goal ≤ 60 s on the machine of issue 32, 0.86 of the plain
loop's time here likewise) and the Watt six-bar's with ``mechanism.points.B0.0`` and
``mechanism.points.D0.1`` each ±10 % (goal ≤ 120 s, absolute: no anchor of its own family).
Printed under the machine it ran on (:func:`tables.print_machine`).
"""

from __future__ import annotations

import argparse
import tempfile
import time
import tomllib
from pathlib import Path

from tables import print_machine, print_table

from balancer.sweeps import Vary, design_points, evaluate_point, sweep

ROOT = Path(__file__).resolve().parent.parent
SPEC = ROOT / "examples" / "pb1.toml"
#: Issue 40's sweep, as a share of the plain loop's time for the same points (see above).
SWEEP_RATIO = 15.0 / (2000 / 115)


def _grid(n: int) -> list[Vary]:
    side = round(n**0.5)
    return [Vary.parse(f"mechanism.lengths.coupler=2.0:4.0:{side}"),
            Vary.parse(f"mechanism.lengths.frame=2.5:3.5:{side}")]


def _loop(n: int) -> float:
    """Seconds of a plain loop over ``n`` points of PB1's family, in this process."""
    data = tomllib.loads(SPEC.read_text())
    points = design_points(_grid(n))
    start = time.perf_counter()
    for i, values in enumerate(points):
        evaluate_point(data, values, i)
    return time.perf_counter() - start


def _watt_grid(n: int) -> list[Vary]:
    """The Watt six-bar's family of issue 32: B0's x and D0's y each ±10 %."""
    side = round(n**0.5)
    return [Vary.parse(f"mechanism.points.B0.0=0.144:0.176:{side}"),
            Vary.parse(f"mechanism.points.D0.1=0.27:0.33:{side}")]


def _sweep(n: int, workers: int, spec: Path = SPEC, grid=_grid) -> float:
    """Seconds of a whole sweep of ``n`` points (a local cluster's start included)."""
    with tempfile.TemporaryDirectory() as tmp:
        start = time.perf_counter()
        sweep(spec, grid(n), Path(tmp) / "sweep.parquet", workers=workers)
        return time.perf_counter() - start


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--full", action="store_true",
                        help="add issue 32's two 10,000-point sweeps on two workers")
    parser.add_argument("--loop-only", action="store_true",
                        help="only the plain loop and issue 40's 2,000-point sweep")
    parser.add_argument("--markdown", action="store_true", help="print the table as Markdown")
    args = parser.parse_args()
    print_machine(markdown=args.markdown)
    # Warm-up: imports and first-call costs of this process.
    data = tomllib.loads(SPEC.read_text())
    for i, values in enumerate(design_points(_grid(16))):
        evaluate_point(data, values, i)
    sizes = (400, 1600)
    rows = []
    for n in sizes:
        rows.append(("plain loop (the anchor)", n, _loop(n), ""))
    rate = sizes[-1] / rows[-1][2]  # the plain loop's points per second: the anchor
    if not args.loop_only:
        for workers, label in ((0, "sweep, in process"), (1, "sweep, 1 Dask worker"),
                               (2, "sweep, 2 Dask workers")):
            for n in sizes:
                rows.append((label, n, _sweep(n, workers), ""))

    def goal(label: str, n: int, seconds: float) -> tuple[str, int, float, str]:
        ratio = seconds / (n / rate)
        return (label, n, seconds, f"{ratio:.2f} of the plain loop's time (goal ≤ "
                f"{SWEEP_RATIO:.2f}: {'met' if ratio <= SWEEP_RATIO else 'NOT met'})")

    rows.append(goal("issue 40: sweep, 2 Dask workers, start included", 2000, _sweep(2000, 2)))
    if args.full:  # issue 32's goals, cluster start included
        rows.append(goal("issue 32: sweep, 2 Dask workers", 10_000, _sweep(10_000, 2)))
        seconds = _sweep(10_000, 2, ROOT / "examples" / "watt_sixbar.toml", _watt_grid)
        verdict = "met" if seconds <= 120 else "NOT met"
        rows.append(("Watt six-bar ±10 %, 2 Dask workers", 10_000, seconds,
                     f"goal ≤ 120 s, absolute (no anchor): {verdict}"))
    header = ("run", "points", "seconds", "points/s", "goal")
    cells = [(r, str(n), f"{s:.2f}", f"{n / s:.1f}", g) for r, n, s, g in rows]
    print("PB1 family (coupler × frame grid)")
    print_table(header, cells, markdown=args.markdown, right=(1, 2, 3))


if __name__ == "__main__":
    main()
