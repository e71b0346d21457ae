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
    :func:`scipy.optimize.differential_evolution` on the physical parameters of the free
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
DE and never worse in objective.
"""

from __future__ import annotations

import argparse
import math
import statistics
import time
from pathlib import Path

import numpy as np
from scipy.optimize import differential_evolution

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


def _de_problem(data: NumericProblem):
    """Bounds and a vectorised objective for differential evolution (see the module docstring)."""
    l1, l2, l3, _ = data.linkage.lengths
    crank, coupler, rocker = data.links
    bounds = []
    names = []

    def add(name, lo, hi):
        names.append(name)
        bounds.append((lo, hi))

    for b in data.links:
        if b.mass[0] < b.mass[1]:
            add(f"m{b.index}", *b.mass)
        if b.name == "coupler" and b.com_fixed is None:
            add("e2", b.com_centre - b.com_radius, b.com_centre + b.com_radius)
            add("f2", -b.com_radius, b.com_radius)
        if not b.inertia_fixed:
            add(f"dI{b.index}", 0.0, b.mass[1] * b.length**2)  # I − max(I_low, m·ρ²)
    for entry, b in ((12, crank), (13, rocker)):
        if b.counter_rotor[0] < b.counter_rotor[1]:
            add(f"Jc{entry}", *b.counter_rotor)
    index = {n: i for i, n in enumerate(names)}
    j0 = data.original_objective

    def designs(z):
        """Design vectors (columns) and penalties of a population ``z`` (variables × members)."""
        z = z[:, None] if z.ndim == 1 else z
        pop = z.shape[1]

        def value(name, fixed):
            return z[index[name]] if name in index else np.full(pop, fixed)

        m = [value(f"m{b.index}", b.mass[0]) for b in data.links]
        if "e2" in index:
            s2 = z[index["e2"]] + 1j * z[index["f2"]]
        else:
            s2 = np.full(pop, coupler.com_fixed)
        s1 = -(m[1] / m[0]) * (1 - s2 / l2) * l1  # Eq. 57
        s3 = l3 * (1 + (m[1] / m[2]) * s2 / l2)
        coms = (s1, s2, s3)
        x = np.zeros((14, pop))
        penalty = np.zeros(pop)
        for b, s in zip(data.links, coms, strict=True):
            k = 4 * b.index
            mi = m[b.index]
            if b.com_fixed is None:
                excess = np.maximum(np.abs(s - b.com_centre) - b.com_radius, 0.0)
                bad = np.where(excess > 0, j0 * (1 + 10 * excess / b.length), 0.0)
                penalty = np.maximum(penalty, bad)
            low = np.maximum(b.inertia[0], mi * b.gyration**2)
            inertia = np.minimum(low + value(f"dI{b.index}", 0.0), b.inertia[1])
            x[k], x[k + 1], x[k + 2] = mi, mi * s.real, mi * s.imag
            x[k + 3] = inertia + mi * np.abs(s) ** 2
        x[12] = value("Jc12", crank.counter_rotor[0])
        x[13] = value("Jc13", rocker.counter_rotor[0])
        return x, penalty

    def objective(z):
        x, penalty = designs(z)
        quad = np.sum((data.rows @ x) ** 2, axis=0)
        mass = data.weights.added_mass * (x[0] + x[4] + x[8] - data.original_mass)
        return np.where(penalty > 0, penalty, quad + mass)

    return bounds, objective, designs


def _run_de(data: NumericProblem):
    bounds, objective, designs = _de_problem(data)
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
    args = parser.parse_args()
    rows = _bench("pb1", args.repeats, args.de_repeats) + _bench("pb2", args.repeats,
                                                                 args.de_repeats)
    header = ("problem", "method", "median ms", "best ms", "iterations", "J (N·m)²",
              "√(J/J_orig)")  # fmt: skip
    table = [header]
    for name, method, med, best, iters, obj, j0 in rows:
        ratio = math.sqrt(obj / j0) if obj >= 0 else float("nan")
        table.append((name, method, f"{med * 1e3:.2f}", f"{best * 1e3:.2f}", str(iters),
                      f"{obj:.12g}", f"{ratio:.3g}"))  # fmt: skip
    widths = [max(len(r[i]) for r in table) for i in range(len(header))]
    print()
    for i, r in enumerate(table):
        print("  ".join(c.ljust(w) if j < 2 else c.rjust(w)
                        for j, (c, w) in enumerate(zip(r, widths, strict=True))))  # fmt: skip
        if i == 0:
            print("  ".join("-" * w for w in widths))
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
