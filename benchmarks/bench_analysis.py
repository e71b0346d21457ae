"""Benchmark: cycle analysis of 10⁶ crank angles, and ``balancer analyze`` as a whole command.

Run on its own: ``python benchmarks/bench_analysis.py``. Each measurement runs in a fresh
process (so that first-touch memory and imports count, as they do for a user) and is repeated;
the table shows the median and the best, and the peak resident memory of the process.

Targets (issue 2): 10⁶ angles in at most 0.3 s and 500 MB; ``balancer analyze
examples/meijaard2020.toml`` in at most 0.5 s wall clock.
"""

from __future__ import annotations

import json
import shutil
import statistics
import subprocess
import sys
import time
from pathlib import Path

from tables import print_table

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
    rows = []
    for route in ("newton-euler", "mass-matrix"):
        runs = _cycle(route, 10**6)
        secs = [r["seconds"] for r in runs]
        peak = max(r["peak_mb"] for r in runs)
        ok = statistics.median(secs) <= 0.3 and peak <= 500
        rows.append((f"cycle analysis, 10^6 angles ({route})", statistics.median(secs),
                     min(secs), f"{peak:.0f} MB", "0.3 s, 500 MB", "yes" if ok else "NO"))
    times = _command()
    rows.append(("balancer analyze examples/meijaard2020.toml", statistics.median(times),
                 min(times), "-", "0.5 s", "yes" if statistics.median(times) <= 0.5 else "NO"))
    header = ("measurement", "median s", "best s", "peak memory", "target", "met")
    print(f"{REPEATS} fresh-process runs each; Python {sys.version.split()[0]}")
    print_table(header, [[f"{c:.3f}" if isinstance(c, float) else str(c) for c in r]
                         for r in rows])


if __name__ == "__main__":
    main()
