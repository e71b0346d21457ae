"""Anchor: the paper's four-bar (Meijaard & van der Wijk 2020, Eq. 56) simulated with Exudyn.

The same run as ``balancer simulate examples/meijaard2020.toml``: free motion under the applied
loads of Eq. 56 (a constant force at each link's centre of mass, a moment on each link), no
gravity, from rest at θ1 = 1 rad on the "+" branch, for 5 s. Exudyn (``pip install exudyn``,
or ``pip install 'balancer[bench]'``) models it its own way: three planar rigid bodies
(``ObjectRigidBody2D``, coordinates ``x, y, φ`` of the centre of mass) connected to each other
and to the ground by four ``RevoluteJoint2D`` — an index-3 DAE with 9 coordinates and 8
constraints — integrated by Exudyn's implicit generalized-α solver (second order) at a fixed step
``--step`` (1 ms) with its default spectral radius ``--rho`` 0.9 and full Newton iterations to
1e-10. The spec is read with ``tomllib``; the initial position comes from the paper's closed
form (Eq. 2–4); nothing of balancer runs in the timed path.

Run on its own: ``python benchmarks/anchors/exudyn_meijaard.py [SPEC] [--step H] [--rho R]
[--json]``. It prints the final state (``theta``, ``omega``, ``alpha`` of links 1–3, the
quantities ``balancer simulate --json`` gives). ``--check`` then also simulates the same run
with balancer at ``rtol = 1e-13`` (a reference far more accurate than either) and prints the
largest difference of Exudyn's final state from it, so that the accuracy is measured, not
assumed.

Accuracy on this run (largest final-state difference from the reference; θ and ω fall as h²,
α is the index-3 solver's and does not improve below about 1 ms):

==========  ===============  ===============  ================
step h      θ                ω                α
==========  ===============  ===============  ================
2 ms        7.0e-7           6.4e-7           3.9e-7
1 ms        1.8e-7           1.6e-7           1.4e-7
0.5 ms      4.4e-8           4.0e-8           6.2e-7
0.1 ms      1.8e-9           1.6e-9           9.1e-6
==========  ===============  ===============  ================

With ``--rho 1`` (no numerical damping) the accelerations oscillate (α off by 2e-3 at 1 ms).
balancer's default (rtol 1e-10) is at about 4e-12, which this solver cannot reach in θ and ω
short of some 10⁶ steps and not at all in α; ``benchmarks/bench_commands.py`` therefore times
balancer's default command and, for equal accuracy, balancer at the loosest tolerance whose
error is no larger than this script's at 1 ms.
"""

from __future__ import annotations

import argparse
import cmath
import json
import math
import sys
import time
import tomllib
from pathlib import Path

DEFAULT_SPEC = Path(__file__).resolve().parents[2] / "examples" / "meijaard2020.toml"
#: Fixed time step, s (final-state error about 2e-7, see the docstring).
DEFAULT_STEP = 1e-3
#: Spectral radius at infinity of generalized-α (Exudyn's default).
DEFAULT_RHO = 0.9
#: Newton tolerance (relative and absolute); tighter changes nothing in the final state.
NEWTON_TOL = 1e-10


def read_spec(path: Path) -> dict:
    """Lengths, link data and the initial state of a four-bar spec (DESIGN.md's keys)."""
    spec = tomllib.loads(path.read_text())
    mech = spec["mechanism"]
    if mech.get("type") != "four-bar":
        raise SystemExit(f"{path}: this anchor simulates four-bars only")
    lengths = mech["lengths"]
    ls = (lengths["crank"], lengths["coupler"], lengths["rocker"], lengths["frame"])
    links = []
    for name in ("crank", "coupler", "rocker"):
        link = spec["links"][name]
        com = link["com"]
        s = (complex(com["e"], com["f"]) if "e" in com
             else cmath.rect(com["s"], com.get("sigma", 0.0)))
        links.append({"mass": link["mass"], "inertia": link["inertia"], "com": s,
                      "force": tuple(link.get("force", (0.0, 0.0))),
                      "moment": link.get("moment", 0.0)})
    sim = spec.get("simulation", {})
    gravity = tuple(sim.get("gravity", (0.0, 0.0)))
    return {"lengths": ls, "branch": mech.get("branch", "+"), "links": links,
            "theta1": sim.get("theta1", 0.0), "omega1": sim.get("omega1", 0.0),
            "duration": sim.get("duration", 5.0), "gravity": gravity}


def closed_form_angles(lengths, theta1: float, branch: str) -> tuple[float, float, float]:
    """θ1, θ2, θ3 of the assembled four-bar (the paper's Eq. 2–4)."""
    l1, l2, l3, l4 = lengths
    v1 = cmath.rect(l1, theta1)
    v23 = l4 - v1  # l̄23 = −l̄1 − l̄4
    l23 = abs(v23)
    d23 = (l23 * l23 + l2 * l2 - l3 * l3) / (2 * l23)
    h23 = (1 if branch == "+" else -1) * math.sqrt(l2 * l2 - d23 * d23)
    v2 = (d23 + 1j * h23) * v23 / l23
    v3 = v23 - v2
    return theta1, cmath.phase(v2), cmath.phase(v3)


def simulate(data: dict, step: float = DEFAULT_STEP, rho: float = DEFAULT_RHO) -> dict:
    """Build the model in Exudyn, integrate, and return the final state."""
    import exudyn as exu
    from exudyn.itemInterface import (
        LoadForceVector,
        LoadTorqueVector,
        MarkerBodyPosition,
        MarkerBodyRigid,
        NodeRigidBody2D,
        ObjectGround,
        ObjectJointRevolute2D,
        ObjectRigidBody2D,
    )

    sc = exu.SystemContainer()
    mbs = sc.AddSystem()
    lengths = data["lengths"]
    l1, l2, l3, l4 = lengths
    thetas = closed_form_angles(lengths, data["theta1"], data["branch"])
    if data["omega1"] != 0.0:
        raise SystemExit("this anchor starts from rest (omega1 = 0), as the paper's example")
    # Joint positions at the start: A0, A1, A2 (A3 = (l4, 0)); each link's frame has its
    # origin at its first joint, x towards the second.
    first = [0j, cmath.rect(l1, thetas[0])]
    first.append(first[1] + cmath.rect(l2, thetas[1]))
    ground = mbs.AddObject(ObjectGround(referencePosition=[0, 0, 0]))
    bodies, nodes = [], []
    for k, link in enumerate(data["links"]):
        theta = thetas[k]
        centre = first[k] + link["com"] * cmath.exp(1j * theta)  # global centre of mass
        node = mbs.AddNode(NodeRigidBody2D(referenceCoordinates=[centre.real, centre.imag, theta],
                                           initialVelocities=[0.0, 0.0, 0.0]))
        body = mbs.AddObject(ObjectRigidBody2D(mass=link["mass"], inertia=link["inertia"],
                                               nodeNumber=node))
        nodes.append(node)
        bodies.append(body)
        # Loads: a constant force (global axes) at the centre of mass, a moment on the link.
        centre_marker = mbs.AddMarker(MarkerBodyRigid(bodyNumber=body, localPosition=[0, 0, 0]))
        gx, gy = data["gravity"]
        fx = link["force"][0] + link["mass"] * gx
        fy = link["force"][1] + link["mass"] * gy
        mbs.AddLoad(LoadForceVector(markerNumber=centre_marker, loadVector=[fx, fy, 0]))
        mbs.AddLoad(LoadTorqueVector(markerNumber=centre_marker,
                                     loadVector=[0, 0, link["moment"]]))

    def joint_marker(k: int, at_second: bool) -> int:
        """Marker at link k's first (or second) joint, in the body frame of its centre."""
        s = data["links"][k]["com"]
        local = (lengths[k] if at_second else 0.0) - s
        return mbs.AddMarker(MarkerBodyPosition(bodyNumber=bodies[k],
                                                localPosition=[local.real, local.imag, 0]))

    a0 = mbs.AddMarker(MarkerBodyPosition(bodyNumber=ground, localPosition=[0, 0, 0]))
    a3 = mbs.AddMarker(MarkerBodyPosition(bodyNumber=ground, localPosition=[l4, 0, 0]))
    pairs = [(a0, joint_marker(0, False)), (joint_marker(0, True), joint_marker(1, False)),
             (joint_marker(1, True), joint_marker(2, False)), (joint_marker(2, True), a3)]
    for m0, m1 in pairs:
        mbs.AddObject(ObjectJointRevolute2D(markerNumbers=[m0, m1]))
    mbs.Assemble()

    settings = exu.SimulationSettings()
    ti = settings.timeIntegration
    ti.endTime = data["duration"]
    ti.numberOfSteps = round(data["duration"] / step)
    ti.generalizedAlpha.spectralRadius = rho
    ti.generalizedAlpha.computeInitialAccelerations = True
    ti.newton.relativeTolerance = NEWTON_TOL
    ti.newton.absoluteTolerance = NEWTON_TOL
    ti.newton.useModifiedNewton = False  # full Newton: faster here
    ti.verboseMode = 0
    ti.adaptiveStep = False
    settings.solution.file.write = False
    settings.solution.sensors.writePeriod = data["duration"]
    settings.show.computationTime = False
    settings.show.statistics = False
    ok = exu.SolveDynamic(mbs, settings, solverType=exu.DynamicSolverType.GeneralizedAlpha)
    if not ok:
        raise SystemExit("Exudyn's solver failed")
    cfg = exu.ConfigurationType.Current
    q = mbs.systemData.GetODE2Coordinates(configuration=cfg)
    qd = mbs.systemData.GetODE2Coordinates_t(configuration=cfg)
    qdd = mbs.systemData.GetODE2Coordinates_tt(configuration=cfg)
    # Each rigid body's three coordinates are displacements from its reference (x, y, φ).
    index = [mbs.GetNodeODE2Index(n) + 2 for n in nodes]
    return {"theta": [thetas[k] + float(q[i]) for k, i in enumerate(index)],
            "omega": [float(qd[i]) for i in index],
            "alpha": [float(qdd[i]) for i in index],
            "steps": round(data["duration"] / step)}


def balancer_reference(spec: Path) -> dict:
    """balancer's final state of the same run at rtol 1e-13 (for ``--check`` only)."""
    from balancer.simulation import simulate_design
    from balancer.spec import load_design

    traj = simulate_design(load_design(spec), method="opened-loop", rtol=1e-13, atol=1e-15)
    return {"theta": traj.theta[:, -1].tolist(), "omega": traj.omega[:, -1].tolist(),
            "alpha": traj.alpha[:, -1].tolist()}


def state_error(a: dict, b: dict) -> float:
    """Largest difference of the final angles, rates and accelerations."""
    return max(abs(x - y) for key in ("theta", "omega", "alpha")
               for x, y in zip(a[key], b[key], strict=True))


def main(argv: list[str] | None = None) -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("spec", nargs="?", type=Path, default=DEFAULT_SPEC)
    parser.add_argument("--step", type=float, default=DEFAULT_STEP, help="time step, s")
    parser.add_argument("--rho", type=float, default=DEFAULT_RHO,
                        help="generalized-α spectral radius at infinity")
    parser.add_argument("--json", action="store_true", help="print the final state as JSON")
    parser.add_argument("--check", action="store_true",
                        help="compare with balancer's final state at rtol 1e-13")
    args = parser.parse_args(argv)
    start = time.perf_counter()
    final = simulate(read_spec(args.spec), args.step, args.rho)
    final["seconds"] = time.perf_counter() - start
    if args.check:
        ref = balancer_reference(args.spec)
        final["error_vs_reference"] = state_error(final, ref)
        final["reference"] = {k: ref[k] for k in ("theta", "omega", "alpha")}
    if args.json:
        json.dump(final, sys.stdout, indent=2)
        print()
        return
    print(f"Exudyn {args.spec.name}: {final['steps']} steps of {args.step:g} s, "
          f"{final['seconds']:.3f} s (model and integration)")
    for key in ("theta", "omega", "alpha"):
        print(f"  final {key:5s} " + "  ".join(f"{v:+.12f}" for v in final[key]))
    if args.check:
        print(f"  largest difference from balancer's final state at rtol 1e-13: "
              f"{final['error_vs_reference']:.2e}")


if __name__ == "__main__":
    main()
