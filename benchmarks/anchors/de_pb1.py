"""Anchor: benchmark PB1 solved by SciPy's differential evolution, one seed, as a whole process.

What it solves — PB1 of ``examples/pb1.toml`` (DESIGN.md): the paper's four-bar (Meijaard &
van der Wijk 2020, Eq. 56) with its coupler unchanged; crank and rocker free (mass 1×–4× the
paper's, centre of mass within a circle of radius equal to the link's length around its ground
pivot, inertia about the centre of mass at least ``m·(0.1·l)²``), a counter-rotor on each
(0–20 kg·m²); exact shaking-force balance; minimise the mean-square shaking moment over one
revolution at 10 rad/s, 360 crank angles.

How: balancer reads the spec and builds the regressors (``numeric_problem``: the shaking
moment at every sampled angle as a linear map ``K`` of the design vector ``x`` — per link
``m, m·e, m·f`` and the second moment about its first joint, then the counter-rotors — so that
``J(x) = ‖K·x‖²``); everything else is NumPy and :func:`scipy.optimize.differential_evolution`
on the physical parameters: the masses ``m1, m3``, the inertias above their least values
``I − m·ρ² ≥ 0`` and the counter-rotors (six variables; the crank's inertia and counter-rotor
change nothing at constant speed, as the search finds out for itself). Force balance is exact
by elimination: the crank's and rocker's centres of mass are not variables but solved from the
paper's Eq. 57,

    s̄1 = −(m2/m1)·(1 − s̄2/l2)·l1,    s̄3 = l3·(1 + (m2/m3)·s̄2/l2),

and a centre of mass that then leaves its disc is penalised (``J_original·(1 + 10·excess/l)``,
worse than any feasible design). Settings as ``benchmarks/bench_optimize.py``'s DE: the default
population (15 per variable), ``tol = 1e-12``, at most 3000 generations, the whole population
evaluated at once (``vectorized=True``), L-BFGS-B polish, seed 0.

Run on its own: ``python benchmarks/anchors/de_pb1.py [SPEC] [--json]``; it prints the RMS
shaking moment found, the design, and its checks (force-balance residual, discs, bounds).
"""

from __future__ import annotations

import argparse
import json
import math
import time
from pathlib import Path

import numpy as np
from scipy.optimize import differential_evolution

from balancer.balance.problem import numeric_problem
from balancer.spec import load_design

DEFAULT_SPEC = Path(__file__).resolve().parents[2] / "examples" / "pb1.toml"


def de_problem(data):
    """Bounds, a vectorised objective and the design map for differential evolution."""
    if data.mechanism.model.type != "four-bar":
        raise SystemExit("this anchor eliminates force balance with Eq. 57: four-bars only")
    l1, l2, l3, _ = data.linkage.lengths
    crank, coupler, rocker = data.links
    if crank.com_fixed is not None or rocker.com_fixed is not None:
        raise SystemExit("Eq. 57 is solved for the crank's and rocker's centres of mass: "
                         "both must be free")
    names, bounds = [], []

    def add(name, lo, hi):
        names.append(name)
        bounds.append((float(lo), float(hi)))

    for b in data.links:
        if b.mass[0] < b.mass[1]:
            add(f"m_{b.name}", *b.mass)
        if b.name == "coupler" and b.com_fixed is None:  # PB2: the coupler's centre is free
            c, r = b.com_centre, b.com_radius
            add("e2", c.real - r, c.real + r)
            add("f2", c.imag - r, c.imag + r)
        if b.inertia[0] < b.inertia[1]:
            add(f"dI_{b.name}", 0.0, b.mass[1] * b.length**2)  # I − max(I_low, m·ρ²)
    for b in (crank, rocker):
        if b.counter_rotor is not None and b.counter_rotor[0] < b.counter_rotor[1]:
            add(f"Jc_{b.name}", *b.counter_rotor)
    index = {n: i for i, n in enumerate(names)}
    j0 = data.original_objective

    def designs(z):
        """Design vectors (columns) and penalties of a population ``z`` (variables × members)."""
        z = z[:, None] if z.ndim == 1 else z
        pop = z.shape[1]

        def value(name, fixed):
            return z[index[name]] if name in index else np.full(pop, float(fixed))

        m = [value(f"m_{b.name}", b.mass[0]) for b in data.links]
        s2 = (z[index["e2"]] + 1j * z[index["f2"]] if "e2" in index
              else np.full(pop, coupler.com_fixed))
        s1 = -(m[1] / m[0]) * (1 - s2 / l2) * l1  # Eq. 57
        s3 = l3 * (1 + (m[1] / m[2]) * s2 / l2)
        x = np.zeros((data.size, pop))
        penalty = np.zeros(pop)
        for b, s, mi in zip(data.links, (s1, s2, s3), m, strict=True):
            if b.com_radius is not None:
                excess = np.maximum(np.abs(s - b.com_centre) - b.com_radius, 0.0)
                penalty = np.maximum(penalty, np.where(excess > 0,
                                                       j0 * (1 + 10 * excess / b.length), 0.0))
            low = np.maximum(b.inertia[0], mi * b.gyration**2)
            inertia = np.minimum(low + value(f"dI_{b.name}", 0.0), b.inertia[1])
            k = b.start
            x[k], x[k + 1], x[k + 2] = mi, mi * s.real, mi * s.imag
            x[k + 3] = inertia + mi * np.abs(s) ** 2  # second moment about the first joint
            if b.rotor is not None:
                x[b.rotor] = value(f"Jc_{b.name}", b.counter_rotor[0] if b.counter_rotor
                                   else 0.0)
        return x, penalty

    def objective(z):
        x, penalty = designs(z)
        quad = np.sum((data.rows @ x) ** 2, axis=0)
        mass = data.weights.added_mass * (x[data.mass_entries].sum(axis=0) - data.original_mass)
        return np.where(penalty > 0, penalty, quad + mass)

    return names, bounds, objective, designs


def solve(spec: Path) -> dict:
    """Build PB1's regressors, run the differential evolution, check the design."""
    data = numeric_problem(load_design(spec))
    names, bounds, objective, designs = de_problem(data)
    result = differential_evolution(objective, bounds, vectorized=True, updating="deferred",
                                    tol=1e-12, maxiter=3000, seed=0, polish=True)
    x, penalty = designs(result.x)
    x = x[:, 0]
    a, b = data.force_balance
    return {
        "objective": float(result.fun),
        "rms_shaking_moment": math.sqrt(max(float(result.fun), 0.0)),
        "original_rms_shaking_moment": math.sqrt(data.original_objective),
        "variables": dict(zip(names, map(float, result.x), strict=True)),
        "generations": int(result.nit),
        "nfev": int(result.nfev),
        "force_balance_residual": float(np.max(np.abs(a @ x - b))),
        "penalty": float(penalty[0]),
        "violations": data.violations(x),
    }


def main(argv: list[str] | None = None) -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("spec", nargs="?", type=Path, default=DEFAULT_SPEC)
    parser.add_argument("--json", action="store_true", help="print the result as JSON")
    args = parser.parse_args(argv)
    start = time.perf_counter()
    out = solve(args.spec)
    out["seconds"] = time.perf_counter() - start
    if args.json:
        print(json.dumps(out, indent=2))
        return
    print(f"differential evolution on {args.spec.name}: RMS shaking moment "
          f"{out['rms_shaking_moment']:.6g} N·m (original {out['original_rms_shaking_moment']:.6g}"
          f"), {out['generations']} generations, nfev {out['nfev']}, "
          f"{out['seconds']:.2f} s after imports")
    print("  " + ", ".join(f"{k} = {v:.6g}" for k, v in out["variables"].items()))
    ok = out["penalty"] == 0 and not out["violations"]
    print(f"  force-balance residual {out['force_balance_residual']:.1e}; "
          f"{'within every bound' if ok else 'VIOLATES: ' + '; '.join(out['violations'])}")


if __name__ == "__main__":
    main()
