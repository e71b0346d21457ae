"""Benchmark: the balancing backends on PB1 and PB2 against SciPy's differential evolution.

Run on its own: ``python benchmarks/bench_optimize.py [--repeats N]``. Everything runs in one
process with the problem already built (regressors, the CVXPY problem compiled by a first solve,
the IPOPT solver created); each time is the median (and the best) of ``N`` solves, the
differential evolution's of ``--de-repeats`` runs.

Rows:

``convex``
    :meth:`ConvexSolver.solve`: the SOCP and the tie-break (what ``backend="convex"`` solves).
``nlp``
    The convex solve, then :meth:`NlpSolver.solve` from its design (what ``backend="nlp"``
    solves); ``nlp alone`` is IPOPT's share.
``run(...)``
    :meth:`Optimizer.run`, which adds the before/after cycle analyses (Newton–Euler route).
``DE``
    :func:`scipy.optimize.differential_evolution` (the problem of ``anchors/de_pb1.py``, the
    whole-command benchmark's anchor) on the physical parameters of the free
    links, ``m``, ``e``, ``f``, ``I − m·ρ²`` (≥ 0) and the counter-rotors, with the same
    objective (the same regressor matrices, evaluated for the whole population at once:
    ``vectorized=True``). Force balance is enforced exactly by elimination: the crank's and
    the rocker's centres of mass are not variables but solved from Eq. 57,
    ``s̄1 = −(m2/m1)·(1 − s̄2/l2)·l1`` and ``s̄3 = l3·(1 + (m2/m3)·s̄2/l2)``; a centre of mass
    that then leaves its disc is penalised (``J_original·(1 + 10·excess/l)``, worse than any
    feasible design). The coupler's centre of mass (PB2) is drawn in the box around its disc
    and penalised likewise outside it. Default population (15 per variable), ``tol=1e-12``,
    at most 3000 generations, L-BFGS-B polish, seed 0.

Targets (the balancing issue): convex ≤ 50 ms and NLP ≤ 100 ms on PB1, both ≥ 10× faster than
DE and never worse in objective. The ratios to DE are measured in the same run (the anchor);
the milliseconds are absolute. Printed under the machine it ran on; ``--markdown`` for the docs.
"""

from __future__ import annotations

import argparse
import math
import statistics
import time
from pathlib import Path

from anchors.de_pb1 import de_problem
from scipy.optimize import differential_evolution
from tables import print_machine, print_table

from balancer.balance.optimizer import Optimizer
from balancer.balance.problem import NumericProblem, numeric_problem
from balancer.spec import load_design

ROOT = Path(__file__).resolve().parent.parent


def _timed(fn, repeats: int):
    times = []
    out = None
    for _ in range(repeats):
        t = time.perf_counter()
        out = fn()
        times.append(time.perf_counter() - t)
    return statistics.median(times), min(times), out


def _run_de(data: NumericProblem):
    _, bounds, objective, designs = de_problem(data)
    result = differential_evolution(
        objective,
        bounds,
        vectorized=True,
        updating="deferred",
        tol=1e-12,
        maxiter=3000,
        seed=0,
        polish=True,
    )
    x, penalty = designs(result.x)
    assert penalty[0] == 0 and not data.violations(x[:, 0]), "DE's design is not feasible"
    return float(result.fun), int(result.nit), int(result.nfev)


def _bench(name: str, repeats: int, de_repeats: int) -> list[tuple]:
    """Rows ``(problem, method, median s, best s, iterations, J, J_original)`` for one problem."""
    design = load_design(ROOT / "examples" / f"{name}.toml")
    t = time.perf_counter()
    data = numeric_problem(design)
    t_data = time.perf_counter() - t
    t = time.perf_counter()
    opt = Optimizer(data)
    first = opt.convex.solve()  # compiles the CVXPY problems
    t_convex_build = time.perf_counter() - t
    t = time.perf_counter()
    nlp_solver = opt.nlp
    t_nlp_build = time.perf_counter() - t
    j0 = data.original_objective
    print(
        f"{name}: regressors {t_data * 1e3:.1f} ms, CVXPY build + first solve "
        f"{t_convex_build * 1e3:.1f} ms, IPOPT build {t_nlp_build * 1e3:.1f} ms; "
        f"original J = {j0:.6g} (N·m)²"
    )
    rows = []
    med, best, sol = _timed(opt.convex.solve, repeats)
    iters = sum(s.iterations for s in sol.stages)
    rows.append((name, "convex", med, best, iters, sol.objective, j0))

    def nlp():
        c = opt.convex.solve()
        return c, nlp_solver.solve(c.x)

    med, best, (c, n) = _timed(nlp, repeats)
    # What backend "nlp" returns: the better design (a tie goes to the convex one).
    rows.append((name, "nlp (convex + IPOPT)", med, best,
                 sum(s.iterations for s in c.stages) + n.stage.iterations,
                 min(n.objective, c.objective), j0))  # fmt: skip
    med, best, alone = _timed(lambda: nlp_solver.solve(first.x), repeats)
    rows.append((name, "nlp alone (IPOPT)", med, best, alone.stage.iterations, alone.objective,
                 j0))  # fmt: skip
    for backend in ("convex", "nlp"):
        med, best, res = _timed(lambda b=backend: opt.run(b), max(3, repeats // 3))
        rows.append((name, f"run({backend!r}) + analyses", med, best, res.iterations,
                     res.objective, j0))  # fmt: skip
    med, best, (fun, nit, nfev) = _timed(lambda: _run_de(data), de_repeats)
    rows.append((name, f"DE ({nfev} evaluations)", med, best, nit, fun, j0))
    return rows


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--repeats", type=int, default=15, help="solves per timing (median)")
    parser.add_argument("--de-repeats", type=int, default=3,
                        help="differential-evolution runs per timing (median; seeded, so each "
                        "run is the same search)")
    parser.add_argument("--markdown", action="store_true", help="print the table as Markdown")
    args = parser.parse_args()
    print_machine(markdown=args.markdown)
    rows = _bench("pb1", args.repeats, args.de_repeats) + _bench("pb2", args.repeats,
                                                                 args.de_repeats)
    header = ("problem", "method", "median ms", "best ms", "iterations", "J (N·m)²",
              "√(J/J_orig)")  # fmt: skip
    table = []
    for name, method, med, best, iters, obj, j0 in rows:
        ratio = math.sqrt(obj / j0) if obj >= 0 else float("nan")
        table.append((name, method, f"{med * 1e3:.2f}", f"{best * 1e3:.2f}", str(iters),
                      f"{obj:.12g}", f"{ratio:.3g}"))  # fmt: skip
    print()
    print_table(header, table, markdown=args.markdown, right=range(2, len(header)))
    print()
    for name in ("pb1", "pb2"):
        sel = {m: (med, obj, j0) for n, m, med, _, _, obj, j0 in rows if n == name}
        de_time, de_obj, j0 = next(v for m, v in sel.items() if m.startswith("DE"))
        for method in ("convex", "nlp (convex + IPOPT)"):
            t, obj, _ = sel[method]
            verdict = "not worse" if obj <= de_obj + 1e-9 * abs(de_obj) + 1e-12 * j0 else "WORSE"
            print(
                f"{name} {method}: {de_time / t:.0f}× faster than DE; objective {verdict} than "
                f"DE's ({obj:.12g} vs {de_obj:.12g} (N·m)²)"
            )


if __name__ == "__main__":
    main()
