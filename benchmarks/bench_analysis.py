"""Benchmark: cycle analysis of 10⁶ crank angles, and ``balancer analyze`` as a whole command.

Run on its own: ``python benchmarks/bench_analysis.py``. Each measurement runs in a fresh
process (so that first-touch memory and imports count, as they do for a user) and is repeated;
the table shows the median and the best, and the peak resident memory of the process.

Targets (issue 2): 10⁶ angles in at most 0.3 s and 500 MB; ``balancer analyze
examples/meijaard2020.toml`` in at most 0.5 s wall clock. Both are absolute: this script has
no anchor (``bench_commands.py`` measures the same against a C floor and against Python's
start-up); the table says so, under the machine it ran on. ``--markdown`` prints it for the
docs.
"""

from __future__ import annotations

import argparse
import json
import shutil
import statistics
import subprocess
import sys
import time
from pathlib import Path

from tables import print_machine, print_table

ROOT = Path(__file__).resolve().parent.parent
EXAMPLE = ROOT / "examples" / "meijaard2020.toml"
REPEATS = 5

_CYCLE = """
import json, resource, time
from balancer.spec import load_design
from balancer.cycle import cycle_analysis
design = load_design({example!r})
t = time.perf_counter()
ca = cycle_analysis(design.mechanism, 10.0, {n}, route={route!r})
s = ca.summary
elapsed = time.perf_counter() - t
print(json.dumps({{"seconds": elapsed,
                  "peak_mb": resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024}}))
"""


def _cycle(route: str, n: int) -> list[dict[str, float]]:
    runs = []
    for _ in range(REPEATS):
        code = _CYCLE.format(example=str(EXAMPLE), n=n, route=route)
        out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True,
                             check=True)
        runs.append(json.loads(out.stdout))
    return runs


def _command() -> list[float]:
    exe = shutil.which("balancer")
    cmd = [exe] if exe else [sys.executable, "-m", "balancer"]
    times = []
    for _ in range(REPEATS):
        t = time.perf_counter()
        subprocess.run([*cmd, "analyze", str(EXAMPLE)], capture_output=True, check=True)
        times.append(time.perf_counter() - t)
    return times


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--markdown", action="store_true", help="print the table as Markdown")
    args = parser.parse_args()
    print_machine(markdown=args.markdown)
    rows = []
    for route in ("newton-euler", "mass-matrix"):
        runs = _cycle(route, 10**6)
        secs = [r["seconds"] for r in runs]
        peak = max(r["peak_mb"] for r in runs)
        ok = statistics.median(secs) <= 0.3 and peak <= 500
        rows.append((f"cycle analysis, 10^6 angles ({route})", statistics.median(secs),
                     min(secs), f"{peak:.0f} MB", "0.3 s, 500 MB (absolute: no anchor)",
                     "yes" if ok else "NO"))
    times = _command()
    rows.append(("balancer analyze examples/meijaard2020.toml", statistics.median(times),
                 min(times), "-", "0.5 s (absolute: no anchor)",
                 "yes" if statistics.median(times) <= 0.5 else "NO"))
    header = ("measurement", "median s", "best s", "peak memory", "target", "met")
    print(f"{REPEATS} fresh-process runs each")
    print_table(header, [[f"{c:.3f}" if isinstance(c, float) else str(c) for c in r]
                         for r in rows], markdown=args.markdown)


if __name__ == "__main__":
    main()
