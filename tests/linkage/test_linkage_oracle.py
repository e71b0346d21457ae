"""The general linkage core's inverse dynamics against an oracle from sympy.physics.mechanics.

The oracle shares nothing with :mod:`balancer.linkage` but the spec it reads (a plain dict,
the one this file also writes to TOML for :func:`balancer.spec.load_design`). Each moving link
is a rigid body with its own coordinates: the position of its centre of mass and the angle of
its frame (``(x, y, θ)``; balancer uses the frame's origin instead). sympy's ``Lagrangian`` and
``LagrangesMethod`` give the unconstrained bodies' equations ``M·q̈ = Q`` from their kinetic
energy and the applied forces (weights, loads, springs, and the motors: an unknown torque
``τ_i`` on each input ``i``); counter-rotors are zero-mass discs on their link's ground pivot
turned at −1× its angle, so they enter through the kinetic energy only. The joints are
holonomic constraints ``Φ(q) = 0`` written here, added with multipliers:
``M·q̈ − Q + Φ_qᵀ·λ = 0``. Positions come from a continuation from the reference pose along
the straight line to the inputs' angles, with Newton's method on those constraints;
velocities and accelerations from ``[Φ_q; drivers]`` (one driver row per input: its link's
angle); then ``λ`` and the torques ``τ`` from ``Φ_qᵀ·λ − B·τ = Q₀ − M·q̈`` (``B``: a column
per motor).

In these coordinates a joint's generalized force on a body, ``−Φ_qᵀ·λ`` over its rows, *is*
the force on it (``x``, ``y``) and its moment about the centre of mass (``θ``), so the ground
gets minus that force (Newton's third law) at the joint. The shaking force and moment are
summed from those, and cross-checked inside the oracle by the momentum theorems (applied forces
less the rate of change of the linear and angular momentum, counter-rotors included), which
need no convention for where a counter-rotor's reaction goes.

Conventions checked (DESIGN.md, "General planar linkages"): reactions are forces of the
mechanism on the ground, per ground point, springs not included; shaking moment about the
origin of the spec's coordinates, with each motor's reaction (−τ_i) and ``+2·J·α`` per
counter-rotor; a slider on a ground guide exerts on it a normal force ``N`` along the guide's
direction turned by +90° (``d̂⊥``), acting at the slider's point, and a pure couple.

The one-input linkages (a Watt six-bar, a crank shaper, an offset slider-crank) are checked
through their mechanism (:func:`balancer.mechanisms.mechanism_of`) at random crank states; the
linkages with several inputs (a 5R five-bar, a 3-RRR parallel manipulator:
``several_inputs_specs``, with loads, springs and counter-rotors added here) through the core
itself (:meth:`Structure.of <balancer.linkage.structure.Structure.of>`,
:func:`balancer.linkage.kinematics.motion`, :func:`balancer.linkage.dynamics.inverse_dynamics`
and :func:`~balancer.linkage.dynamics.regressors`) along a smooth motion of the inputs near the
reference pose, which both sides reach along the straight line from it.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
import pytest
import sympy as sp
import sympy.physics.mechanics as me
from linkage.several_inputs_specs import fivebar, three_rrr

from balancer.linkage import dynamics, kinematics
from balancer.linkage.inputs import InputState
from balancer.linkage.structure import Structure
from balancer.mechanisms import mechanism_of
from balancer.mechanisms.base import ROUTES
from balancer.spec import load_design

#: The whole module is of the full suite, not of the fast lane (`pytest -m "not slow"`): each
#: case builds its oracle with sympy (a second or two), whichever of its tests runs.
pytestmark = pytest.mark.slow

EPS = float(np.finfo(float).eps)

#: Largest condition number (2-norm) allowed at the sampled states for the oracle's matrices
#: ``[Φ_q; drivers]`` (positions, rates, accelerations) and ``[Φ_qᵀ, −B]`` (multipliers and
#: torques), with angle columns divided and angle rows multiplied by the linkage's size so that
#: every entry is in common units. balancer solves with the same matrices group by group.
KAPPA_MAX = 1e4

#: Relative tolerance of every comparison. Each side evaluates its terms with a few dozen
#: roundings (≈ 64·ε of the largest term) and solves linear systems of size 3n ≤ 21 with
#: condition ≤ KAPPA_MAX by backward-stable LU: ≤ KAPPA_MAX·64·ε ≈ 1.4e-10 of the scale of
#: the unknowns per solve. Positions (Newton, converged to rounding), rates, accelerations and
#: forces are such solves in sequence, each feeding the next: a few times 1.4e-10, below 1e-9.
#: Scales: per quantity, the largest magnitude over what is compared — all links' rates (or
#: the inputs'), all accelerations (or the largest rate squared), all forces, and all moments
#: (the inputs' torques among them) together with force × the linkage's reach from the origin
#: (a moment about the origin of forces at points that far carries their rounding times that
#: arm).
TOL = 1e-9

SEED = 20261123
STATES = 6  # per linkage: five moving states and one at rest (statics)


# -- the linkages ---------------------------------------------------------------------------


def _rot(v, a):
    z = complex(*v) * complex(math.cos(a), math.sin(a))
    return (z.real, z.imag)


def _add(a, b):
    return (a[0] + b[0], a[1] + b[1])


def _circles(p1, r1, p3, r3, sign):
    """The intersection of two circles on the left (+1) or right (−1) of p1 → p3."""
    p1, p3 = complex(*p1), complex(*p3)
    d = p3 - p1
    u = (r1**2 - r3**2 + abs(d) ** 2) / (2 * abs(d))
    h = math.sqrt(r1**2 - u * u)
    p = p1 + d / abs(d) * (u + sign * 1j * h)
    return (p.real, p.imag)


def _link(points, mass, inertia, e, f, **more):
    return {"points": points, "mass": mass, "inertia": inertia, "com": {"e": e, "f": f}, **more}


def watt_six_bar() -> dict:
    """Watt I: four-bar A0-A1-A2-A3 with a ternary rocker A3-A2-B, then the dyad B-C-D.

    Crank at the origin; a spring from a ground anchor K (no joint there) to a coupler point E,
    another between the rocker's B and the crank pin A1; counter-rotors on all three links
    pivoted to the ground (one of them, dc, has its ground pivot as its second point).
    """
    a0, a3, d = (0.0, 0.0), (3.2, 0.0), (3.0, 3.6)
    a1 = _rot((1.0, 0.0), 1.0)
    a2 = _circles(a1, 3.0, a3, 2.0, +1)
    b = _add(a3, _rot((0.9, -1.1), math.atan2(a2[1] - a3[1], a2[0] - a3[0])))
    c = _circles(b, 2.1, d, 1.7, -1)
    e = _add(a1, _rot((1.2, 0.5), math.atan2(a2[1] - a1[1], a2[0] - a1[0])))
    points = {"A0": a0, "A1": a1, "A2": a2, "A3": a3, "B": b, "C": c, "D": d, "E": e,
              "K": (0.5, 2.5)}
    return {
        "mechanism": {"type": "linkage", "input": "crank", "points": points, "sliders": []},
        "links": {
            "ground": {"points": ["A0", "A3", "D", "K"]},
            "crank": _link(["A0", "A1"], 2.1, 0.11, 0.35, 0.12, counter_rotor=0.07),
            "coupler": _link(["A1", "A2", "E"], 3.0, 3.1, 1.45, 0.4, moment=3.7),
            "rocker": _link(["A3", "A2", "B"], 2.2, 2.1, 1.1, -0.5, counter_rotor=0.4,
                            force=[4.0, -6.0]),
            "bc": _link(["B", "C"], 1.3, 0.6, 0.9, 0.2, force=[-5.5, 2.5], moment=-1.9),
            "dc": _link(["C", "D"], 1.1, 0.35, 0.6, -0.15, counter_rotor=0.05),
        },
        "springs": [{"points": ["K", "E"], "stiffness": 120.0, "free_length": 0.8},
                    {"points": ["B", "A1"], "stiffness": 60.0, "free_length": 2.0}],
        "gravity": (0.7, -9.81),
        "speed": 6.0,
    }


def crank_shaper() -> dict:
    """Quick return: the crank's pin A1 carries a block that slides on a rocker pivoted at B0.

    The guide line on the rocker is offset 0.05 m from its pivot (an RPR dyad that is not
    through the pivot); the rocker's tip R drives a ram on an inclined ground guide through a
    link R-S (an RRP dyad). The origin is the rocker's pivot, not the crank's.
    """
    a0, b0 = (0.1, 0.6), (0.0, 0.0)
    a1 = _add(a0, _rot((0.25, 0.0), 0.4))
    psi = math.atan2(a1[1] - b0[1], a1[0] - b0[0])
    line = psi + math.asin(0.05 / math.dist(a1, b0))  # passes 0.05 from B0
    r = _add(b0, _rot((1.2, 0.0), line - 0.05))
    h = 1.3
    s = (r[0] + math.sqrt(0.6**2 - (h - r[1]) ** 2), h)
    points = {"A0": a0, "A1": a1, "B0": b0, "R": r, "S": s}
    return {
        "mechanism": {
            "type": "linkage", "input": "crank", "points": points,
            "sliders": [
                {"link": "block", "guide": "rocker", "point": "A1",
                 "direction": list(_rot((1.0, 0.0), line))},
                {"link": "ram", "guide": "ground", "point": "S", "direction": [1.0, 0.15]},
            ],
        },
        "links": {
            "ground": {"points": ["A0", "B0"]},
            "crank": _link(["A0", "A1"], 1.4, 0.012, 0.08, 0.03, counter_rotor=0.02),
            "block": _link(["A1"], 0.6, 0.004, 0.03, -0.02),
            "rocker": _link(["B0", "R"], 2.5, 0.35, 0.55, 0.06, counter_rotor=0.03,
                            moment=2.0),
            "link": _link(["R", "S"], 0.9, 0.03, 0.3, 0.05),
            "ram": _link(["S"], 4.0, 0.2, 0.1, -0.07, force=[-40.0, 5.0]),
        },
        "springs": [],
        "gravity": (0.0, -9.81),
        "speed": 8.0,
    }


def offset_slider_crank() -> dict:
    """A slider-crank whose piston runs on an inclined ground guide offset 0.03 m from A0.

    The guide's direction is given with length 2 (it must be normalised); a spring from a
    ground anchor H to the piston.
    """
    a1 = _rot((0.1, 0.0), 2.2)
    d = (math.cos(0.5), math.sin(0.5))
    n = (-d[1], d[0])
    off = 0.03
    across = a1[0] * n[0] + a1[1] * n[1] - off
    along = a1[0] * d[0] + a1[1] * d[1] + math.sqrt(0.35**2 - across**2)
    p = (off * n[0] + along * d[0], off * n[1] + along * d[1])
    points = {"A0": (0.0, 0.0), "A1": a1, "P": p, "H": (0.6, 0.5)}
    return {
        "mechanism": {
            "type": "linkage", "input": "crank", "points": points,
            "sliders": [{"link": "piston", "guide": "ground", "point": "P",
                         "direction": [2 * d[0], 2 * d[1]]}],
        },
        "links": {
            "ground": {"points": ["A0", "H"]},
            "crank": _link(["A0", "A1"], 1.2, 0.004, 0.02, 0.01, counter_rotor=0.003),
            "rod": _link(["A1", "P"], 0.5, 0.006, 0.12, 0.01, moment=0.8),
            "piston": _link(["P"], 0.7, 0.001, 0.01, 0.02, force=[-30.0, 10.0]),
        },
        "springs": [{"points": ["H", "P"], "stiffness": 150.0, "free_length": 0.1}],
        "gravity": (-1.5, -9.81),
        "speed": 30.0,
    }


def loaded_fivebar() -> dict:
    """The 5R five-bar of ``several_inputs_specs`` with loads, springs and counter-rotors.

    A spring from a ground anchor K (no joint there) to the coupler's point E, another between
    the cranks' pins C and D; counter-rotors on both cranks (the inputs). Each input swings
    about its reference angle (``motion``: amplitudes in rad, angular frequencies in rad/s,
    phases in rad).
    """
    spec = fivebar()
    spec["mechanism"]["points"]["K"] = [0.35, 0.45]
    spec["mechanism"]["sliders"] = []
    links = spec["links"]
    links["ground"]["points"].append("K")
    links["left"]["counter_rotor"] = 0.0008
    links["right"]["counter_rotor"] = 0.0005
    links["upper_left"]["force"] = [3.0, -2.0]
    links["upper_right"]["moment"] = 0.4
    spec["springs"] = [{"points": ["K", "E"], "stiffness": 80.0, "free_length": 0.1},
                       {"points": ["C", "D"], "stiffness": 40.0, "free_length": 0.2}]
    spec["gravity"] = (0.5, -9.81)
    spec["motion"] = {"amplitudes": (0.25, 0.2), "frequencies": (30.0, 50.0),
                      "phases": (0.3, -0.7)}
    return spec


def loaded_three_rrr() -> dict:
    """The 3-RRR of ``several_inputs_specs`` with loads, a spring and counter-rotors.

    A force and a moment on the platform, a spring from a ground anchor K to the platform's
    C2, counter-rotors on two of the three cranks; small swings of the inputs (about 0.08 rad:
    the motion must stay inside the workspace, on the reference pose's branch).
    """
    spec = three_rrr()
    spec["mechanism"]["points"]["K"] = [0.2, -0.25]
    spec["mechanism"]["sliders"] = []
    links = spec["links"]
    links["ground"]["points"].append("K")
    links["crank1"]["counter_rotor"] = 0.002
    links["crank3"]["counter_rotor"] = 0.0015
    links["platform"]["force"] = [-4.0, 2.5]
    links["platform"]["moment"] = 0.3
    links["distal2"]["force"] = [1.0, 1.5]
    spec["springs"] = [{"points": ["K", "C2"], "stiffness": 150.0, "free_length": 0.15}]
    spec["gravity"] = (-0.8, -9.81)
    spec["motion"] = {"amplitudes": (0.08, 0.06, 0.07), "frequencies": (30.0, 50.0, 40.0),
                      "phases": (0.3, -0.7, 1.1)}
    return spec


LINKAGES = {"watt": watt_six_bar, "shaper": crank_shaper, "slider_crank": offset_slider_crank,
            "fivebar": loaded_fivebar, "3-RRR": loaded_three_rrr}


def inputs_of(spec: dict) -> list[str]:
    """The spec's driven links: ``inputs`` (several) or ``input`` (one)."""
    mech = spec["mechanism"]
    return list(mech["inputs"]) if "inputs" in mech else [mech["input"]]


def to_toml(spec: dict) -> str:
    """The spec as TOML (floats by ``repr``: they read back exactly)."""
    def num(x):
        return repr(float(x))

    def vec(v):
        return f"[{num(v[0])}, {num(v[1])}]"

    def names(ps):
        return "[" + ", ".join(f'"{p}"' for p in ps) + "]"

    mech = spec["mechanism"]
    driven = (f'input = "{mech["input"]}"' if "input" in mech
              else f"inputs = {names(mech['inputs'])}")
    out = ["[mechanism]", 'type = "linkage"', driven, "", "[mechanism.points]"]
    out += [f"{p} = {vec(xy)}" for p, xy in mech["points"].items()]
    for s in mech.get("sliders", []):
        out += ["", "[[mechanism.sliders]]", f'link = "{s["link"]}"',
                f'guide = "{s["guide"]}"', f'point = "{s["point"]}"',
                f"direction = {vec(s['direction'])}"]
    for name, link in spec["links"].items():
        out += ["", f"[links.{name}]", f"points = {names(link['points'])}"]
        if name == "ground":
            continue
        out += [f"mass = {num(link['mass'])}", f"inertia = {num(link['inertia'])}",
                f"com = {{ e = {num(link['com']['e'])}, f = {num(link['com']['f'])} }}"]
        for key in ("moment", "counter_rotor"):
            if key in link:
                out.append(f"{key} = {num(link[key])}")
        if "force" in link:
            out.append(f"force = {vec(link['force'])}")
    for s in spec.get("springs", []):
        out += ["", "[[springs]]", f"points = {names(s['points'])}",
                f"stiffness = {num(s['stiffness'])}", f"free_length = {num(s['free_length'])}"]
    return "\n".join(out) + "\n"


# -- the oracle -----------------------------------------------------------------------------


class Oracle:
    """Inverse dynamics of a linkage spec from Lagrange's equations with multipliers.

    Parameters (the vector ``p``): per moving link ``m, e, f, I_G, Fx, Fy, M, J_c`` (mass,
    centre of mass in the link's frame, inertia about it, applied force at it and moment,
    counter-rotor), per spring ``k, L0``, then gravity ``gx, gy``. One unknown torque per
    input (the spec's ``inputs``, or its one ``input``), in their order.
    """

    PER_LINK = ("m", "e", "f", "I", "Fx", "Fy", "M", "Jc")

    def __init__(self, spec: dict) -> None:
        mech, links = spec["mechanism"], spec["links"]
        self.spec = spec
        pts = {p: (float(x), float(y)) for p, (x, y) in mech["points"].items()}
        self.points = pts
        self.names = [k for k in links if k != "ground"]
        self.ground_points = list(links["ground"]["points"])
        names, n = self.names, len(self.names)
        self.n = n
        sliders, springs = mech["sliders"], spec["springs"]
        self.size = max(math.dist(a, b) for a in pts.values() for b in pts.values())
        self.reach = max(math.hypot(*xy) for xy in pts.values())

        # Frames at the reference pose: origin at the first point, x towards the second (a
        # one-point link: along its slider's direction).
        phi, origin, local = {}, {}, {}
        for name in names:
            ps = links[name]["points"]
            o = pts[ps[0]]
            if len(ps) > 1:
                ax = (pts[ps[1]][0] - o[0], pts[ps[1]][1] - o[1])
            else:
                (ax,) = [tuple(s["direction"]) for s in sliders if s["link"] == name]
            phi[name] = math.atan2(ax[1], ax[0])
            origin[name] = o
            local[name] = {p: _rot((pts[p][0] - o[0], pts[p][1] - o[1]), -phi[name])
                           for p in ps}
        self.phi = phi
        carriers = {}
        for name in ["ground", *names]:
            for p in links[name]["points"]:
                carriers.setdefault(p, []).append(name)
        self.grounded = [k for k in names if set(links[k]["points"]) & set(self.ground_points)]

        # Symbols.
        t = me.dynamicsymbols._t
        q = []
        for k in range(n):
            q += list(me.dynamicsymbols(f"x{k} y{k} th{k}"))
        qd = [s.diff(t) for s in q]
        qdd = [s.diff(t, 2) for s in q]
        par = {}
        for k in range(n):
            for name in self.PER_LINK:
                par[(k, name)] = sp.Symbol(f"{name}_{k}", real=True)
        for i in range(len(springs)):
            par[("spring", i, "k")] = sp.Symbol(f"k_{i}", real=True)
            par[("spring", i, "L0")] = sp.Symbol(f"L0_{i}", real=True)
        gx, gy = sp.symbols("gx gy", real=True)
        self.par_keys = [*par.keys(), "gx", "gy"]
        psyms = [*par.values(), gx, gy]
        self.inputs = [names.index(name) for name in inputs_of(spec)]
        taus = list(sp.symbols(f"tau0:{len(self.inputs)}", real=True))

        # Bodies: the frame N is the ground's (the spec's coordinates), O its origin.
        frame = me.ReferenceFrame("N")
        o_pt = me.Point("O")
        o_pt.set_vel(frame, 0)
        bodies, frames, coms, rotors = [], [], [], []
        for k, name in enumerate(names):
            x, y, th = q[3 * k : 3 * k + 3]
            b = me.ReferenceFrame(f"B{k}")
            b.orient_axis(frame, frame.z, th)
            g = o_pt.locatenew(f"G{k}", x * frame.x + y * frame.y)
            g.set_vel(frame, qd[3 * k] * frame.x + qd[3 * k + 1] * frame.y)
            body = me.RigidBody(f"link{k}", g, b, par[(k, "m")],
                                (me.inertia(b, 0, 0, par[(k, "I")]), g))
            bodies.append(body)
            frames.append(b)
            coms.append(g)
            if name in self.grounded:  # a disc on the pivot, turned at −1× the link
                pivot = next(p for p in links[name]["points"] if p in self.ground_points)
                c = me.ReferenceFrame(f"C{k}")
                c.orient_axis(frame, frame.z, -th)
                at = o_pt.locatenew(f"Q{k}", pts[pivot][0] * frame.x + pts[pivot][1] * frame.y)
                at.set_vel(frame, 0)
                rotors.append(me.RigidBody(f"rotor{k}", at, c, sp.Integer(0),
                                           (me.inertia(c, 0, 0, par[(k, "Jc")]), at)))

        def point(name, p):
            """Point ``p`` of link ``name`` (the ground's: fixed), as a sympy Point."""
            if name == "ground":
                fixed = o_pt.locatenew(f"g_{p}", pts[p][0] * frame.x + pts[p][1] * frame.y)
                fixed.set_vel(frame, 0)
                return fixed
            k = names.index(name)
            u, v = local[name][p]
            e, f = par[(k, "e")], par[(k, "f")]
            out = coms[k].locatenew(f"{name}_{p}", (u - e) * frames[k].x
                                    + (v - f) * frames[k].y)
            out.v2pt_theory(coms[k], frame, frames[k])
            return out

        def xy(pt):
            r = pt.pos_from(o_pt)
            return sp.Matrix([r.dot(frame.x), r.dot(frame.y)])

        # Constraints, each with what it joins.
        phis, self.joints = [], []
        for p, on in carriers.items():
            if len(on) < 2:
                continue
            base = on[0]
            for other in on[1:]:
                self.joints.append(("pin", p, other, base, len(phis)))
                phis += list(xy(point(other, p)) - xy(point(base, p)))
        for s in sliders:
            ks = names.index(s["link"])
            gname = s["guide"]
            th_g = 0 if gname == "ground" else q[3 * names.index(gname) + 2]
            phi_g = 0.0 if gname == "ground" else phi[gname]
            dx, dy = s["direction"]
            norm = math.hypot(dx, dy)
            nrm = sp.Matrix([-dy / norm, dx / norm])  # d̂⊥ at the reference pose
            turn = sp.Matrix([[sp.cos(th_g - phi_g), -sp.sin(th_g - phi_g)],
                              [sp.sin(th_g - phi_g), sp.cos(th_g - phi_g)]])
            if gname == "ground":
                on_line = sp.Matrix(pts[s["point"]])
            else:  # the point of the guide link where the slider's point was at the reference
                kg = names.index(gname)
                u, v = _rot((pts[s["point"]][0] - origin[gname][0],
                             pts[s["point"]][1] - origin[gname][1]), -phi[gname])
                e, f = par[(kg, "e")], par[(kg, "f")]
                gpt = coms[kg].locatenew(f"line{ks}", (u - e) * frames[kg].x
                                         + (v - f) * frames[kg].y)
                on_line = xy(gpt)
            self.joints.append(("slider", s["point"], s["link"], gname, len(phis)))
            phis.append(q[3 * ks + 2] - th_g - (phi[s["link"]] - phi_g))
            phis.append(((turn * nrm).T * (xy(point(s["link"], s["point"])) - on_line))[0])
        assert len(phis) == 3 * n - len(self.inputs), "one degree of freedom per input"

        # Applied forces: weights and loads at the centres of mass, moments, springs, motors.
        forces = []
        for k in range(n):
            m = par[(k, "m")]
            forces.append((coms[k], (m * gx + par[(k, "Fx")]) * frame.x
                           + (m * gy + par[(k, "Fy")]) * frame.y))
            forces.append((frames[k], par[(k, "M")] * frame.z))
        for k, tau in zip(self.inputs, taus, strict=True):
            forces.append((frames[k], tau * frame.z))
        # A spring's force on its first end enters as symbols (its law is put in below, on
        # plain symbols: differentiating square roots of time functions is slow in sympy).
        spring_ends, spring_force = [], []
        for i, s in enumerate(springs):
            ends = [point(carriers[p][0], p) for p in s["points"]]
            spring_ends.append([xy(e) for e in ends])
            fx, fy = sp.symbols(f"spring{i}_x spring{i}_y", real=True)
            spring_force.append((fx, fy))
            for end, name_pt, sign in zip(ends, s["points"], (1, -1), strict=True):
                if carriers[name_pt][0] != "ground":  # the ground's share: in solve()
                    forces.append((end, sign * (fx * frame.x + fy * frame.y)))

        lagrangian = me.Lagrangian(frame, *bodies, *rotors)
        lm = me.LagrangesMethod(lagrangian, q, forcelist=forces, bodies=[*bodies, *rotors],
                                frame=frame)
        lm.form_lagranges_equations()  # M·q̈ − Q = 0 for the unconstrained bodies
        lm_mass, lm_forcing = lm.mass_matrix, lm.forcing  # M·q̈ = forcing

        # Plain symbols for lambdify.
        qs = sp.symbols(f"q0:{3 * n}", real=True)
        qds = sp.symbols(f"qd0:{3 * n}", real=True)
        qdds = sp.symbols(f"qdd0:{3 * n}", real=True)
        plain = {**dict(zip(qdd, qdds, strict=True)), **dict(zip(qd, qds, strict=True)),
                 **dict(zip(q, qs, strict=True))}

        def flat(expr):
            return sp.Matrix(expr).xreplace(plain)

        law = {}
        for i, (ends, (fx, fy)) in enumerate(zip(spring_ends, spring_force, strict=True)):
            delta = flat(ends[1]) - flat(ends[0])
            length = sp.sqrt(delta.dot(delta))
            pull = par[("spring", i, "k")] * (length - par[("spring", i, "L0")]) / length
            law[fx], law[fy] = pull * delta[0], pull * delta[1]
        forcing = flat(lm_forcing).xreplace(law)

        args = [list(qs), list(qds), list(qdds), psyms]

        def fn(*exprs):
            return sp.lambdify(args, [flat(e) for e in exprs], modules="numpy", cse=True)

        # The joints as holonomic constraints Φ(q) = 0 with multipliers λ: the equations are
        # M·q̈ − Q + Φ_qᵀ·λ = 0 (so −Φ_qᵀ·λ is what the joints do to the bodies) and
        # Φ̈ = Φ_q·q̈ + (Φ_q·q̇)_q·q̇ = 0.
        phi_m = flat(phis)
        jac = phi_m.jacobian(qs)
        qd_col = sp.Matrix(qds)
        self._kin = fn(phi_m, jac)
        # Frame origins (balancer's coordinates), their velocities and accelerations.
        frame_origins = []
        for k in range(n):
            e, f = par[(k, "e")], par[(k, "f")]
            origin_pt = coms[k].locatenew(f"O{k}", -e * frames[k].x - f * frames[k].y)
            origin_pt.v2pt_theory(coms[k], frame, frames[k])
            coms[k].set_acc(frame, qdd[3 * k] * frame.x + qdd[3 * k + 1] * frame.y)
            origin_pt.a2pt_theory(coms[k], frame, frames[k])
            frame_origins.append(origin_pt)

        def components(vectors):
            return [[v.dot(frame.x), v.dot(frame.y)] for v in vectors]

        # Momentum theorems: shaking force and moment about O with no joint forces at all.
        linear = me.linear_momentum(frame, *bodies)
        angular = me.angular_momentum(o_pt, frame, *bodies, *rotors)
        applied_f = sum(((par[(k, "m")] * gx + par[(k, "Fx")]) * frame.x
                         + (par[(k, "m")] * gy + par[(k, "Fy")]) * frame.y for k in range(n)),
                        sp.Integer(0) * frame.x)
        applied_m = sum(par[(k, "M")] + coms[k].pos_from(o_pt).cross(
            (par[(k, "m")] * gx + par[(k, "Fx")]) * frame.x
            + (par[(k, "m")] * gy + par[(k, "Fy")]) * frame.y).dot(frame.z) for k in range(n))
        shake_f = applied_f - linear.dt(frame)
        self._dyn = fn(
            lm_mass, forcing.jacobian(taus), forcing.xreplace(dict.fromkeys(taus, 0)),
            -(jac * qd_col).jacobian(qs) * qd_col,
            components(pt.pos_from(o_pt) for pt in frame_origins),
            components(pt.vel(frame) for pt in frame_origins),
            components(pt.acc(frame) for pt in frame_origins),
            [list(xy(point(s["link"], s["point"]))) for s in sliders] or [[0, 0]],
            [[*a, *b] for a, b in spring_ends] or [[0, 0, 0, 0]],
            [shake_f.dot(frame.x), shake_f.dot(frame.y),
             applied_m - angular.dt(frame).dot(frame.z)])
        self._positions = {}

    # -- parameters ---------------------------------------------------------------------------

    def parameters(self, *, loads=True, springs=True, gravity=(0.0, 0.0), design=None):
        """``p`` of the spec's design (or of ``design``: ``{link: (m, e, f, I_G, J_c)}``)."""
        links = self.spec["links"]
        values = []
        for key in self.par_keys:
            if key in ("gx", "gy"):
                values.append(gravity[0] if key == "gx" else gravity[1])
            elif key[0] == "spring":
                s = self.spec["springs"][key[1]]
                values.append((s["stiffness"] if springs else 0.0) if key[2] == "k"
                              else s["free_length"])
            else:
                k, what = key
                link = links[self.names[k]]
                mine = {"m": link["mass"], "e": link["com"]["e"], "f": link["com"]["f"],
                        "I": link["inertia"], "Jc": link.get("counter_rotor", 0.0),
                        "Fx": link.get("force", (0.0, 0.0))[0] if loads else 0.0,
                        "Fy": link.get("force", (0.0, 0.0))[1] if loads else 0.0,
                        "M": link.get("moment", 0.0) if loads else 0.0}
                if design is not None and what in ("m", "e", "f", "I", "Jc"):
                    m, e, f, inertia, jc = design[self.names[k]]
                    mine.update(m=m, e=e, f=f, I=inertia, Jc=jc)
                values.append(mine[what])
        return np.array(values, dtype=float)

    # -- kinematics ---------------------------------------------------------------------------

    def _kin_matrix(self, q, p):
        """``Φ(q)`` and ``[Φ_q; drivers]`` (a driver row per input: its angle)."""
        z = np.zeros(3 * self.n)
        phi, jac = self._kin(q, z, z, p)
        drive = np.zeros((len(self.inputs), 3 * self.n))
        for j, k in enumerate(self.inputs):
            drive[j, 3 * k + 2] = 1.0
        return np.ravel(phi), np.vstack([np.asarray(jac, dtype=float), drive])

    def _scaled(self, a):
        """``a`` (rows like ``[Φ_q; drivers]``) in common units: angles times the size."""
        a = np.array(a, dtype=float)
        a[:, 2::3] /= self.size
        kinds = ["length"] * (3 * self.n)
        for kind, _, _, _, row in self.joints:
            if kind == "slider":
                kinds[row] = "angle"
        kinds[3 * self.n - len(self.inputs):] = ["angle"] * len(self.inputs)  # the drivers
        a[[r for r, kind in enumerate(kinds) if kind == "angle"]] *= self.size
        return a

    def _q_ref(self, p):
        """The reference pose in the oracle's coordinates (centres of mass of design ``p``)."""
        q = []
        for k, name in enumerate(self.names):
            ps = self.spec["links"][name]["points"]
            com = (p[self.par_keys.index((k, "e"))], p[self.par_keys.index((k, "f"))])
            gpos = _add(self.points[ps[0]], _rot(com, self.phi[name]))
            q += [gpos[0], gpos[1], self.phi[name]]
        return np.array(q)

    def positions(self, theta, p):
        """``q`` at the inputs' angles ``theta`` (one per input), continued from the reference
        pose along the straight line to them in the inputs' angles (Newton)."""
        theta = np.atleast_1d(np.asarray(theta, dtype=float))
        key = (*theta, *(p[self.par_keys.index((k, w))] for k in range(self.n) for w in "ef"))
        if key in self._positions:
            return self._positions[key]
        m = len(self.inputs)
        ic = [3 * k + 2 for k in self.inputs]
        q = self._q_ref(p)
        assert np.max(np.abs(self._kin_matrix(q, p)[0])) <= 64 * EPS * self.size
        start = q[ic]
        steps = max(1, math.ceil(np.max(np.abs(theta - start)) / 0.05))
        for i in range(1, steps + 1):
            target = start + (theta - start) * i / steps
            rhs = np.zeros(3 * self.n)
            rhs[-m:] = target - q[ic]
            q = q + np.linalg.solve(self._kin_matrix(q, p)[1], rhs)  # the tangent predictor
            last = math.inf
            for _ in range(30):
                phi, a = self._kin_matrix(q, p)
                step = np.linalg.solve(a, -np.append(phi, q[ic] - target))
                q = q + step
                moved = np.max(np.abs(step))
                # Converged: the step at rounding, or no longer halving once below √ε (Newton
                # squares the step from there: what is left is Φ's rounding through the
                # matrix's inverse — a small platform's angle gets it times size/radius).
                if moved <= 4 * EPS * self.size or (
                        moved <= math.sqrt(EPS) * self.size and moved > last / 2):
                    break
                last = moved
            else:
                raise AssertionError("the oracle's Newton iteration did not converge")
        q[ic] = theta
        res = self._kin_matrix(q, p)[0]
        assert np.max(np.abs(res)) <= 64 * EPS * self.size, "the oracle's pose does not close"
        self._positions[key] = q
        return q

    # -- dynamics -----------------------------------------------------------------------------

    def solve(self, theta, omega, alpha, p):
        """Everything at one state of the inputs (their angles, rates and accelerations, one
        each per input), as a dict of numbers and arrays (``tau``: one torque per input)."""
        n3, m = 3 * self.n, len(self.inputs)
        q = self.positions(theta, p)
        kin = self._kin_matrix(q, p)[1]  # [Φ_q; drivers]
        jac = kin[:-m]
        rhs = np.zeros(n3)
        rhs[-m:] = omega
        qd = np.linalg.solve(kin, rhs)
        mass, motor, applied, gamma, *_ = self._dyn(q, qd, np.zeros(n3), p)
        mass, motor = np.asarray(mass, dtype=float), np.asarray(motor, dtype=float).reshape(n3, m)
        qdd = np.linalg.solve(kin, np.append(np.ravel(gamma), alpha))
        # M·q̈ − Q + Φ_qᵀ·λ = 0 with Q = Q₀ + B·τ (Q₀ everything but the motors, B's columns
        # the motors' generalized directions): Φ_qᵀ·λ − B·τ = Q₀ − M·q̈. M (sympy's, from the
        # kinetic energy) is positive on its diagonal: the inertia enters with +.
        assert np.all(np.diag(mass) > 0)
        multipliers = np.column_stack([jac.T, -motor])
        lam_tau = np.linalg.solve(multipliers, np.ravel(applied) - mass @ qdd)
        lam, tau = lam_tau[:-m], lam_tau[-m:]
        *_, origins, origin_vel, origin_acc, sliders, ends, momentum = self._dyn(q, qd, qdd, p)
        kappa = max(np.linalg.cond(self._scaled(kin)),
                    np.linalg.cond(self._scaled(multipliers.T)))

        # Each joint's generalized force on the bodies: −(Φ_q)ᵀ·λ over its rows; in centre-of-mass
        # coordinates its (x, y) entries on a body are the force on it, θ the moment about
        # its centre of mass.
        def on_body(row0, k):
            g = -jac[row0 : row0 + 2].T @ lam[row0 : row0 + 2]
            return g[3 * k : 3 * k + 3]

        pos = np.asarray(sliders, dtype=float).reshape(-1, 2)
        reactions = {pt: np.zeros(2) for pt in self.ground_points}
        normal, couple, tangential, pin_couple = {}, {}, [], []
        force = np.zeros(2)
        moment = -np.sum(tau)  # the motors' reactions
        slider_index = 0
        for kind, pt, link, base, row in self.joints:
            if kind == "slider":
                here = pos[slider_index]
                slider_index += 1
            if base != "ground":
                continue
            k = self.names.index(link)
            g = on_body(row, k)
            com = q[3 * k : 3 * k + 2]
            if kind == "pin":
                at = np.array(self.points[pt])
                on_ground = -g[:2]
                reactions[pt] = reactions[pt] + on_ground
                pin_couple.append(g[2] - _cross(at - com, g[:2]))  # a pin has none
                force = force + on_ground
                moment += _cross(at, on_ground)
            else:
                s = next(s for s in self.spec["mechanism"]["sliders"] if s["link"] == link)
                d = np.array(s["direction"], dtype=float) / np.hypot(*s["direction"])
                nrm = np.array([-d[1], d[0]])
                on_ground = -g[:2]
                c = -(g[2] - _cross(here - com, g[:2]))
                normal[link], couple[link] = on_ground @ nrm, c
                tangential.append(on_ground @ d)  # frictionless: none
                force = force + on_ground
                moment += _cross(here, on_ground) + c
        ends = np.asarray(ends, dtype=float).reshape(-1, 4)
        for i, s in enumerate(self.spec["springs"]):
            k_s = p[self.par_keys.index(("spring", i, "k"))]
            l0 = p[self.par_keys.index(("spring", i, "L0"))]
            ea, eb = ends[i, :2], ends[i, 2:]
            length = np.hypot(*(eb - ea))
            pull = k_s * (length - l0) * (eb - ea) / length  # on the first end
            for name_pt, at, f in ((s["points"][0], ea, pull), (s["points"][1], eb, -pull)):
                if name_pt in self.ground_points:
                    force = force + f
                    moment += _cross(at, f)
        for k, name in enumerate(self.names):
            if name in self.grounded:
                moment += 2 * p[self.par_keys.index((k, "Jc"))] * qdd[3 * k + 2]
        momentum = np.ravel(momentum)
        return {
            "q": q, "qd": qd, "qdd": qdd, "tau": tau, "reactions": reactions,
            "normal": normal, "couple": couple, "force": force, "moment": moment,
            "momentum_force": momentum[:2], "momentum_moment": momentum[2],
            "tangential": np.array(tangential), "pin_couple": np.array(pin_couple),
            "origins": np.asarray(origins, dtype=float).reshape(-1, 2),
            "origin_vel": np.asarray(origin_vel, dtype=float).reshape(-1, 2),
            "origin_acc": np.asarray(origin_acc, dtype=float).reshape(-1, 2),
            "kappa": kappa,
        }


def _cross(a, b):
    return a[0] * b[1] - a[1] * b[0]


# -- fixtures -------------------------------------------------------------------------------


#: The general core's routes (:func:`balancer.linkage.dynamics.inverse_dynamics`) by the
#: mechanism's names for them (what the tests are parametrized by).
CORE_ROUTES = {"newton-euler": "groups", "mass-matrix": "global"}


class Core:
    """A linkage with several inputs through the general core itself: :meth:`Structure.of
    <balancer.linkage.structure.Structure.of>` and the core's functions, answering what the
    tests ask a one-input linkage's mechanism (:func:`mechanism_of`)."""

    routes = tuple(CORE_ROUTES)

    def __init__(self, linkage) -> None:
        self.linkage = linkage
        self.structure = Structure.of(linkage)
        self.layout = dynamics.Layout.of(self.structure)
        self.link_names = self.structure.names
        self.grounded_links = linkage.grounded_links

    def motion(self, theta, omega, alpha):
        """The motion at the inputs' states (arrays ``(m, N)``: a row per input)."""
        return kinematics.motion(self.structure, InputState.of(theta, omega, alpha))

    def inverse_dynamics(self, mo, *, route=None, loads=True, gravity=(0.0, 0.0)):
        return dynamics.inverse_dynamics(self.structure, mo, self.linkage, gravity=gravity,
                                         loads=loads, route=CORE_ROUTES[route or "newton-euler"])

    def regressors(self, mo, gravity=(0.0, 0.0)):
        forces, _ = dynamics.regressors(self.structure, mo, gravity)
        return forces


@dataclass
class Case:
    """A linkage, its oracle and its states: ``theta``, ``omega``, ``alpha`` have a row per
    input (rad, rad/s, rad/s²) and a column per state."""

    name: str
    spec: dict
    mech: object
    oracle: Oracle
    theta: np.ndarray
    omega: np.ndarray
    alpha: np.ndarray
    gravity: tuple[float, float]

    @property
    def several(self) -> bool:
        return len(self.theta) > 1

    def motion(self):
        if self.several:
            return self.mech.motion(self.theta, self.omega, self.alpha)
        return self.mech.motion(self.theta[0], self.omega[0], self.alpha[0])

    def oracle_states(self, p):
        return [self.oracle.solve(t, w, a, p)
                for t, w, a in zip(self.theta.T, self.omega.T, self.alpha.T, strict=True)]


def _random_crank_states(spec, rng):
    """One input's states: random angles over a turn, rates and accelerations up to the
    spec's ``speed`` (and twice its square)."""
    speed = spec["speed"]
    theta1 = rng.uniform(0.0, 2 * math.pi, STATES)
    omega1 = rng.uniform(-speed, speed, STATES)
    alpha1 = rng.uniform(-2 * speed**2, 2 * speed**2, STATES)
    return theta1[None, :], omega1[None, :], alpha1[None, :]


def _swinging_states(spec, oracle, rng):
    """Several inputs' states along ``θ_i(t) = θ_i,ref + a_i·sin(w_i·t + φ_i)`` at random
    times (the spec's ``motion``; the reference angles the oracle's)."""
    motion = spec["motion"]
    ref = np.array([oracle.phi[name] for name in inputs_of(spec)])[:, None]
    a, w, phase = (np.array(motion[key], dtype=float)[:, None]
                   for key in ("amplitudes", "frequencies", "phases"))
    t = rng.uniform(0.0, 1.0, STATES)[None, :]
    arg = w * t + phase
    return ref + a * np.sin(arg), a * w * np.cos(arg), -a * w**2 * np.sin(arg)


@pytest.fixture(scope="module", params=list(LINKAGES))
def case(request, tmp_path_factory) -> Case:
    spec = LINKAGES[request.param]()
    path = tmp_path_factory.mktemp(request.param) / "spec.toml"
    path.write_text(to_toml(spec), encoding="utf-8")
    linkage = load_design(path).mechanism
    oracle = Oracle(spec)
    rng = np.random.default_rng([SEED, list(LINKAGES).index(request.param)])
    if len(inputs_of(spec)) == 1:
        mech = mechanism_of(linkage)
        theta, omega, alpha = _random_crank_states(spec, rng)
    else:  # (the mechanism's interface is a crank's)
        mech = Core(linkage)
        theta, omega, alpha = _swinging_states(spec, oracle, rng)
    omega[:, -1] = alpha[:, -1] = 0.0  # at rest: statics of gravity, loads and springs
    return Case(request.param, spec, mech, oracle, theta, omega, alpha, spec["gravity"])


@pytest.fixture(scope="module")
def solved(case):
    """The oracle at the case's states, with everything on (loads, springs, gravity)."""
    return case.oracle_states(case.oracle.parameters(gravity=case.gravity))


class Errors:
    """Worst error per quantity relative to its scale; one assertion names them all."""

    def __init__(self) -> None:
        self.rows: list[tuple[str, float, float]] = []

    def add(self, name, got, want, scale):
        err = float(np.max(np.abs(np.asarray(got, dtype=float) - np.asarray(want, dtype=float))))
        self.rows.append((name, err, scale))

    def check(self):
        bad = [f"{n}: |error| {e:.3e} > {TOL:g}·{s:.4g}" for n, e, s in self.rows
               if not e <= TOL * s]
        assert not bad, "\n".join(bad)


def _column(x):
    return np.asarray(x, dtype=float).reshape(-1)


# -- tests ----------------------------------------------------------------------------------


@pytest.mark.slow
def test_states_are_regular_and_the_crank_turns(case, solved):
    """A one-input linkage's crank turns fully; several inputs' motion (near the reference
    pose) places every link at every state; the oracle's matrices are well conditioned."""
    if case.several:
        mo = case.motion()
        for k in range(len(case.mech.linkage.link_names)):
            for x in (mo.pose.angles[k], mo.pose.origins[k].x, mo.pose.origins[k].y):
                assert np.all(np.isfinite(x))
    else:
        assert case.mech.assembly_range().full
    kappa = max(s["kappa"] for s in solved)
    assert kappa <= KAPPA_MAX, f"ill-conditioned state (κ = {kappa:.3g}): the tolerance fails"


@pytest.mark.slow
def test_oracle_is_consistent_with_the_momentum_theorems(case, solved):
    """Joint forces summed on the ground (with −τ_i per motor and +2·J·α per counter-rotor)
    equal applied forces less the momentum's rate; pins carry no couple, ground guides no
    tangential force."""
    o = case.oracle
    force_scale = max(max(np.max(np.abs(s["force"])), *(np.max(np.abs(r)) for r in
                                                         s["reactions"].values()))
                      for s in solved)
    moment_scale = max(force_scale * o.reach, max(abs(s["moment"]) for s in solved))
    errs = Errors()
    for s in solved:
        errs.add("shaking force", s["force"], s["momentum_force"], force_scale)
        errs.add("shaking moment", s["moment"], s["momentum_moment"], moment_scale)
        errs.add("pin couples", s["pin_couple"], 0.0, moment_scale)
        if s["tangential"].size:
            errs.add("tangential guide forces", s["tangential"], 0.0, force_scale)
    errs.check()


def test_spec_read_as_written(case):
    """The design vector is (m, m·e, m·f, I_G + m·(e² + f²)) per link, then counter-rotors."""
    mech, links = case.mech, case.spec["links"]
    assert tuple(mech.linkage.link_names) == tuple(case.oracle.names)
    assert set(mech.linkage.grounded_links) == set(case.oracle.grounded)
    x = mech.layout.vector(mech.linkage)
    want = _design_vector(mech.layout, {
        k: (links[k]["mass"], links[k]["com"]["e"], links[k]["com"]["f"], links[k]["inertia"],
            links[k].get("counter_rotor", 0.0)) for k in case.oracle.names})
    np.testing.assert_allclose(x, want, rtol=4 * EPS, atol=0)


def _design_vector(layout, design):
    x = np.zeros(layout.size)
    for i, (name, what) in enumerate(layout.entries):
        m, e, f, inertia, jc = design[name]
        x[i] = {"m": m, "me": m * e, "mf": m * f, "J": inertia + m * (e * e + f * f),
                "Jc": jc}[what]
    return x


def test_kinematics(case, solved):
    """Angles, frame origins, and their rates and accelerations, link by link."""
    mo = case.motion()
    o = case.oracle

    def at(x, i):  # a link that does not turn has a constant angle (a float)
        return float(np.broadcast_to(np.asarray(x, dtype=float), (STATES,))[i])

    errs = Errors()
    for k, name in enumerate(case.mech.linkage.link_names):
        j = o.names.index(name)
        for i, s in enumerate(solved):
            rates = np.abs(s["qd"][2::3])
            w_scale = max(np.max(rates), np.max(np.abs(case.omega[:, i])))
            a_scale = max(np.max(np.abs(s["qdd"][2::3])), np.max(rates) ** 2)
            turn = at(mo.pose.angles[k], i) - s["q"][3 * j + 2]
            errs.add(f"{name} angle", math.remainder(turn, 2 * math.pi), 0.0, 1.0)
            errs.add(f"{name} origin", [at(mo.pose.origins[k].x, i), at(mo.pose.origins[k].y, i)],
                     s["origins"][j], o.reach)
            if not np.any(case.omega[:, i]) and not np.any(case.alpha[:, i]):  # at rest
                errs.add(f"{name} rates at rest",
                         [at(mo.rate[k], i), at(mo.accel[k], i), at(mo.velocity[k].x, i),
                          at(mo.velocity[k].y, i), at(mo.acceleration[k].x, i),
                          at(mo.acceleration[k].y, i)], 0.0, 0.0)
                continue
            errs.add(f"{name} rate", at(mo.rate[k], i), s["qd"][3 * j + 2], w_scale)
            errs.add(f"{name} acceleration", at(mo.accel[k], i), s["qdd"][3 * j + 2], a_scale)
            errs.add(f"{name} origin velocity",
                     [at(mo.velocity[k].x, i), at(mo.velocity[k].y, i)], s["origin_vel"][j],
                     w_scale * o.size)
            errs.add(f"{name} origin acceleration",
                     [at(mo.acceleration[k].x, i), at(mo.acceleration[k].y, i)],
                     s["origin_acc"][j], a_scale * o.size)
    errs.check()


def _compare(case, forces, states, column=None):
    """Balancer's :class:`Forces` (one column, or ``column`` of a regressor) against the
    oracle's states."""
    o = case.oracle

    def at(x):
        x = np.asarray(x, dtype=float)
        return _column(x if column is None else x @ column)

    f_scale = max(max(np.max(np.abs(s["force"])) for s in states),
                  max(np.max(np.abs(r)) for s in states for r in s["reactions"].values()),
                  max((abs(v) for s in states for v in s["normal"].values()), default=0.0))
    m_scale = max(f_scale * o.reach, max(abs(s["moment"]) for s in states),
                  max(np.max(np.abs(s["tau"])) for s in states),
                  max((abs(v) for s in states for v in s["couple"].values()), default=0.0))
    errs = Errors()
    assert set(forces.reactions) == set(o.ground_points)
    for pt in o.ground_points:
        errs.add(f"reaction at {pt} (x)", at(forces.reactions[pt].x),
                 [s["reactions"][pt][0] for s in states], f_scale)
        errs.add(f"reaction at {pt} (y)", at(forces.reactions[pt].y),
                 [s["reactions"][pt][1] for s in states], f_scale)
    ground_sliders = [s["link"] for s in case.spec["mechanism"]["sliders"]
                      if s["guide"] == "ground"]
    assert set(forces.slider_normal) == set(ground_sliders)
    for link in ground_sliders:
        errs.add(f"normal force of {link}", at(forces.slider_normal[link]),
                 [s["normal"][link] for s in states], f_scale)
        errs.add(f"couple of {link}", at(forces.slider_couple[link]),
                 [s["couple"][link] for s in states], m_scale)
    errs.add("shaking force (x)", at(forces.shaking_force.x), [s["force"][0] for s in states],
             f_scale)
    errs.add("shaking force (y)", at(forces.shaking_force.y), [s["force"][1] for s in states],
             f_scale)
    errs.add("shaking moment", at(forces.shaking_moment), [s["moment"] for s in states],
             m_scale)
    assert len(forces.input_torques) == len(o.inputs)
    if len(o.inputs) == 1:
        errs.add("driving torque", at(forces.driving_torque), [s["tau"][0] for s in states],
                 m_scale)
    else:
        for j, name in enumerate(inputs_of(case.spec)):
            errs.add(f"torque on input {name}", at(forces.input_torques[j]),
                     [s["tau"][j] for s in states], m_scale)
    errs.check()


@pytest.mark.parametrize("route", ROUTES)
def test_inverse_dynamics(case, solved, route):
    """Loads, springs, gravity and counter-rotors on: every force on the ground, the torque."""
    forces = case.mech.inverse_dynamics(case.motion(), route=route, gravity=case.gravity)
    _compare(case, forces, solved)


def test_inverse_dynamics_without_loads(case):
    """``loads=False`` drops applied forces and moments but keeps springs (DESIGN.md)."""
    states = case.oracle_states(case.oracle.parameters(loads=False, gravity=case.gravity))
    forces = case.mech.inverse_dynamics(case.motion(), loads=False, gravity=case.gravity)
    _compare(case, forces, states)


@pytest.mark.parametrize("design", ["spec", "random"])
def test_regressors(case, design):
    """``regressors(mo) @ x`` is the inverse dynamics of design ``x`` without loads or springs,
    for the spec's design and for another one."""
    o, mech = case.oracle, case.mech
    links = case.spec["links"]
    if design == "spec":
        values = {k: (links[k]["mass"], links[k]["com"]["e"], links[k]["com"]["f"],
                      links[k]["inertia"], links[k].get("counter_rotor", 0.0))
                  for k in o.names}
    else:
        rng = np.random.default_rng([SEED, 99, list(LINKAGES).index(case.name)])
        values = {}
        for k in o.names:
            m = rng.uniform(0.3, 4.0)
            size = 0.5 * o.size
            values[k] = (m, rng.uniform(-size, size), rng.uniform(-size, size),
                         m * (rng.uniform(0.05, 0.4) * size) ** 2,
                         rng.uniform(0.0, 0.3) * m * size**2 if k in o.grounded else 0.0)
    x = _design_vector(mech.layout, values)
    p = o.parameters(loads=False, springs=False, gravity=case.gravity, design=values)
    states = case.oracle_states(p)
    mo = case.motion()
    _compare(case, mech.regressors(mo, gravity=case.gravity), states, column=x)
    if design == "spec" and not case.spec["springs"]:  # then the same as inverse_dynamics
        ref = mech.inverse_dynamics(mo, loads=False, gravity=case.gravity)
        reg = mech.regressors(mo, gravity=case.gravity)
        scale = max(np.max(np.abs(ref.shaking_force.x)), np.max(np.abs(ref.shaking_force.y)),
                    *(np.max(np.abs(tau)) / o.reach for tau in ref.input_torques))
        for a, b, s in ((reg.shaking_force.x @ x, ref.shaking_force.x, scale),
                        (reg.shaking_force.y @ x, ref.shaking_force.y, scale),
                        (reg.shaking_moment @ x, ref.shaking_moment, scale * o.reach),
                        *((r @ x, f, scale * o.reach) for r, f in
                          zip(reg.input_torques, ref.input_torques, strict=True))):
            assert np.max(np.abs(_column(a) - _column(b))) <= TOL * s
