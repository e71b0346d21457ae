"""Benchmark: the paper's example (Eq. 56; free from rest at θ1 = 1 rad, 5 s) in every formulation.

Run on its own: ``python benchmarks/bench_simulate.py``. For each formulation and tolerance it
prints the wall-clock time of ``simulate`` in-process (median of several runs; integration plus
the 501 outputs with their reactions), the right-hand-side evaluations, and the largest error of
the final angles, rates and accelerations against a reference run at rtol 1e-13.

Targets (issue 3): the fastest formulation reaches a final-state error of 1e-8 in at most 30 ms;
none takes more than 1 s. Both absolute, with no anchor (``bench_commands.py`` measures
``simulate`` against Exudyn): the lines say so, under the machine the table ran on.
``--markdown`` prints the table for the docs.
"""

from __future__ import annotations

import argparse
import statistics
import time
from pathlib import Path

import numpy as np
from tables import print_machine, print_table

from balancer.mechanisms.fourbar.mechanism import FourBarMechanism
from balancer.simulation import simulate_design
from balancer.spec import load_design

#: The paper's four formulations of the four-bar.
METHODS = tuple(FourBarMechanism.own_formulations)

ROOT = Path(__file__).resolve().parent.parent
REPEATS = 5
TOLERANCES = (1e-8, 1e-10)


def final_state(traj) -> np.ndarray:
    return np.concatenate([traj.theta[:, -1], traj.omega[:, -1], traj.alpha[:, -1]])


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--markdown", action="store_true", help="print the table as Markdown")
    args = parser.parse_args()
    print_machine(markdown=args.markdown)
    design = load_design(ROOT / "examples" / "meijaard2020.toml")
    reference = final_state(simulate_design(design, method="opened-loop", rtol=1e-13,
                                            atol=1e-15))
    rows = []
    for method in METHODS:
        for rtol in TOLERANCES:
            times = []
            for _ in range(REPEATS):
                start = time.perf_counter()
                traj = simulate_design(design, method=method, rtol=rtol, atol=rtol * 1e-2)
                times.append(time.perf_counter() - start)
            error = float(np.max(np.abs(final_state(traj) - reference)))
            rows.append((method, rtol, statistics.median(times), traj.nfev, traj.steps, error))
    fastest = min((r for r in rows if r[5] <= 1e-8), key=lambda r: r[2], default=None)
    print(f"paper's example, 5 s; {REPEATS} runs each")
    header = ("formulation", "rtol", "median ms", "rhs evals", "steps", "final-state error")
    print_table(header, [(method, f"{rtol:.0e}", f"{1e3 * secs:.1f}", str(nfev), str(steps),
                          f"{error:.2e}") for method, rtol, secs, nfev, steps, error in rows],
                markdown=args.markdown, right=range(1, len(header)))
    print()
    if fastest is not None:
        ok = fastest[2] <= 0.030
        print(f"fastest to a final-state error of 1e-8: {fastest[0]} at rtol {fastest[1]:.0e}, "
              f"{1e3 * fastest[2]:.1f} ms (target 30 ms, absolute: no anchor; "
              f"{'met' if ok else 'NOT met'})")
    slowest = max(rows, key=lambda r: r[2])
    print(f"slowest run: {slowest[0]} at rtol {slowest[1]:.0e}, {1e3 * slowest[2]:.0f} ms "
          f"(target 1 s, absolute: no anchor; {'met' if slowest[2] <= 1.0 else 'NOT met'})")


if __name__ == "__main__":
    main()
