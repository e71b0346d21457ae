"""Specs of linkages driven at several inputs, shared by their tests (not a test module).

A 5R five-bar (two inputs, a closed-form dyad) and a 3-RRR planar parallel manipulator (three
inputs, a numeric group of four links), as the plain dicts a spec file reads into
(:func:`balancer.spec.reader.design_from_dict`). Used by ``test_several_inputs.py`` (finite
differences, energy balance, momentum theorems) and ``test_linkage_oracle.py`` (the
sympy.physics.mechanics oracle); imported as ``linkage.several_inputs_specs`` (``tests`` is on
pytest's ``pythonpath``).
"""

from __future__ import annotations

import math

import numpy as np

from balancer.model import Linkage
from balancer.spec.reader import design_from_dict


def linkage_of(spec: dict) -> Linkage:
    """The linkage a spec dict describes."""
    mechanism = design_from_dict(spec).mechanism
    assert isinstance(mechanism, Linkage)
    return mechanism


def _link(points, mass, inertia, e, f):
    return {"points": points, "mass": mass, "inertia": inertia, "com": {"e": e, "f": f}}


def crank_rocker() -> dict:
    """A one-input crank-rocker (the crank at A0, the rocker at A3), to set beside them."""
    return {
        "mechanism": {"type": "linkage", "input": "crank",
                      "points": {"A0": [0.0, 0.0], "A1": [0.1, 0.0], "A2": [0.35, 0.2],
                                 "A3": [0.3, 0.0]}},
        "links": {"ground": {"points": ["A0", "A3"]},
                  "crank": _link(["A0", "A1"], 1.0, 0.01, 0.05, 0.0),
                  "coupler": _link(["A1", "A2"], 1.0, 0.02, 0.1, 0.0),
                  "rocker": _link(["A3", "A2"], 1.0, 0.01, 0.1, 0.0)},
    }


def fivebar() -> dict:
    """A general (not parallelogram) 5R five-bar: two cranks on ground pivots A and B."""
    return {
        "mechanism": {"type": "linkage", "inputs": ["left", "right"],
                      "points": {"A": [0.0, 0.0], "B": [0.15, 0.0], "C": [-0.05, 0.2],
                                 "D": [0.22, 0.18], "E": [0.1, 0.35]}},
        "links": {"ground": {"points": ["A", "B"]},
                  "left": _link(["A", "C"], 0.3, 0.002, 0.08, 0.01),
                  "right": _link(["B", "D"], 0.25, 0.0015, 0.09, -0.005),
                  "upper_left": _link(["C", "E"], 0.2, 0.001, 0.07, 0.0),
                  "upper_right": _link(["D", "E"], 0.22, 0.0012, 0.06, 0.004)},
    }


def three_rrr() -> dict:
    """A symmetric 3-RRR planar parallel manipulator: three cranks (0.15 m) on a base circle
    of 0.3 m, three distal links (0.15 m), a platform of radius 0.06 m turned 0.2 rad; each
    elbow placed on the circles' intersection that bends it the same way."""
    points, links = {}, {"ground": {"points": ["A1", "A2", "A3"]}}
    platform = []
    for i in range(1, 4):
        at = math.pi / 2 + 2 * math.pi * (i - 1) / 3
        a = 0.3 * complex(math.cos(at), math.sin(at))
        c = 0.06 * complex(math.cos(at + 0.2), math.sin(at + 0.2))
        d = c - a
        half = abs(d) / 2
        b = a + d / 2 + 1j * d / abs(d) * math.sqrt(0.15 ** 2 - half ** 2)
        points |= {f"A{i}": [a.real, a.imag], f"B{i}": [b.real, b.imag],
                   f"C{i}": [c.real, c.imag]}
        links[f"crank{i}"] = _link([f"A{i}", f"B{i}"], 0.4 + 0.05 * i, 0.003, 0.05, 0.002 * i)
        links[f"distal{i}"] = _link([f"B{i}", f"C{i}"], 0.25, 0.0018, 0.06, -0.003)
        platform.append(f"C{i}")
    links["platform"] = _link(platform, 0.5, 0.0012, 0.01, 0.01)
    return {"mechanism": {"type": "linkage", "inputs": ["crank1", "crank2", "crank3"],
                          "points": points}, "links": links}


A, B = 0.2, 0.15  # the parallelogram's sides: p (A→P1) and q (A→P2)


def parallelogram() -> dict:
    """Both motors at A: p = A→P1, q = A→P2; r = P1→Q ∥ q, s = P2→Q→E ∥ p (E beyond Q)."""
    u1, u2 = np.exp(1j * 0.6), np.exp(1j * 2.0)
    p1, p2 = A * u1, B * u2
    q = p1 + B * u2
    e = p2 + 1.4 * A * u1
    pts = {"A": 0j, "P1": p1, "P2": p2, "Q": q, "E": e}
    return {
        "mechanism": {"type": "linkage", "inputs": ["p", "q"],
                      "points": {k: [v.real, v.imag] for k, v in pts.items()}},
        "links": {"ground": {"points": ["A"]},
                  "p": _link(["A", "P1"], 0.29, 0.005, -0.005, 0.002),
                  "q": _link(["A", "P2"], 0.29, 0.005, -0.012, 0.002),
                  "r": _link(["P1", "Q"], 0.1, 0.0004, 0.12, 0.002),
                  "s": _link(["P2", "Q", "E"], 0.15, 0.0026, -0.02, 0.002)},
    }


def crank_slider() -> dict:
    """A crank on a ground pivot A and a block driven along a horizontal ground guide through
    B, joined by two links at E: two inputs, one about a pivot and one along a slide."""
    return {
        "mechanism": {"type": "linkage", "inputs": ["crank", "block"],
                      "points": {"A": [0.0, 0.0], "C": [0.04, 0.15], "E": [0.2, 0.3],
                                 "B": [0.32, 0.0]},
                      "sliders": [{"link": "block", "guide": "ground", "point": "B",
                                   "direction": [1.0, 0.0]}]},
        "links": {"ground": {"points": ["A"]},
                  "crank": _link(["A", "C"], 0.3, 0.002, 0.07, 0.01),
                  "upper": _link(["C", "E"], 0.2, 0.001, 0.1, 0.0),
                  "lower": _link(["B", "E"], 0.25, 0.0015, 0.12, -0.004),
                  "block": _link(["B"], 0.8, 0.0004, 0.01, -0.005)},
    }
