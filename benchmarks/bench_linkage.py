"""Benchmark: the general linkage core on the shipped six-bars, against issue 12's targets.

Run on its own: ``python benchmarks/bench_linkage.py``. Each figure is the median (and best) of
repeated in-process runs after one warm-up run (imports and the one-time compilation of the
CasADi functions are not counted: they are paid once per process and mechanism).

Targets (issue 12), per shipped six-bar:

- cycle analysis at 10⁶ crank angles ≤ 1 s;
- the certified balanced design (convex backend, global optimum and its lower bound) ≤ 0.1 s;
- a 5 s simulation to 1e-9 (free motion, the linkage's default formulation — crank-angle for a
  linkage of dyads, multibody otherwise — rtol 1e-10) ≤ 0.3 s.

These targets are absolute seconds with no anchor (``bench_commands.py`` measures the cycle
analyses against a C floor): the table says so, under the machine it ran on. ``--markdown``
prints it for the docs.
"""

from __future__ import annotations

import argparse
import statistics
import time
from dataclasses import replace
from pathlib import Path

from tables import print_machine, print_table

ROOT = Path(__file__).resolve().parent.parent
EXAMPLES = ("watt_sixbar.toml", "stephenson_sixbar.toml")
REPEATS = 3


def _timed(fn) -> list[float]:
    fn()  # warm-up: imports, compiled functions, caches of the mechanism's structure
    out = []
    for _ in range(REPEATS):
        t = time.perf_counter()
        fn()
        out.append(time.perf_counter() - t)
    return out


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--markdown", action="store_true", help="print the table as Markdown")
    args = parser.parse_args()
    print_machine(markdown=args.markdown)
    from balancer.balance.optimizer import optimize
    from balancer.cycle import cycle_analysis
    from balancer.formulations import default_method
    from balancer.simulation import simulate
    from balancer.spec import load_design

    rows = []
    for name in EXAMPLES:
        path = ROOT / "examples" / name
        if not path.exists():
            continue
        design = load_design(path)
        speed = design.operation.speed if design.operation else 10.0
        free = replace(design.simulation, duration=5.0, drive="free",
                       omega1=design.simulation.omega1 or speed)
        cases = [
            ("cycle analysis, 10^6 angles", 1.0,
             lambda d=design, s=speed: cycle_analysis(d.mechanism, s, 10**6).summary),
            ("certified balance (convex)", 0.1,
             lambda d=design: optimize(d, "convex")),
            (f"5 s free simulation, rtol 1e-10 ({default_method(design.mechanism)})", 0.3,
             lambda d=design, f=free: simulate(d.mechanism, f, rtol=1e-10, atol=1e-12)),
        ]
        for label, target, fn in cases:
            if "balance" in label and design.balance is None:
                continue
            secs = _timed(fn)
            med = statistics.median(secs)
            rows.append((name, label, med, min(secs), target, "yes" if med <= target else "NO"))
    header = ("example", "measurement", "median s", "best s", "target s (absolute: no anchor)",
              "met")
    cells = [[f"{c:.4f}" if isinstance(c, float) else str(c) for c in r] for r in rows]
    print(f"median of {REPEATS} in-process runs after a warm-up")
    print_table(header, cells, markdown=args.markdown)


if __name__ == "__main__":
    main()
