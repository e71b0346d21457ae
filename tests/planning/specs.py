"""Specs of the planning tests: a carriage on a straight guide (the issue's exact cases)."""

from __future__ import annotations

#: The carriage's mass, kg, its stroke, m, and the stroke's duration, s.
MASS, STROKE, DURATION = 2.0, 0.3, 1.0


def carriage(law: str = "cubic") -> dict:
    """A carriage of mass ``MASS`` driven along a horizontal ground guide through the origin,
    its stroke ``STROKE`` in ``DURATION`` from rest to rest, and a spindle turning about its
    own centre of mass (a second input, held still by the motion): the shaking force is
    ``MASS·a`` along x, the moment about the origin zero."""
    return {
        "mechanism": {"type": "linkage", "inputs": ["carriage", "spindle"],
                      "points": {"A": [0.0, 0.0], "S": [0.5, 0.2], "T": [0.6, 0.2]},
                      "sliders": [{"link": "carriage", "guide": "ground", "point": "A",
                                   "direction": [1.0, 0.0]}]},
        "links": {"ground": {"points": ["S"]},
                  "carriage": {"points": ["A"], "mass": MASS, "inertia": 0.01,
                               "com": {"e": 0.0, "f": 0.0}},
                  "spindle": {"points": ["S", "T"], "mass": 0.5, "inertia": 0.002,
                              "com": {"e": 0.0, "f": 0.0}}},
        "motion": [{"name": "stroke", "times": [0.0, DURATION],
                    "path": [[0.0, 0.0], [STROKE, 0.0]], "law": law, "samples": 101}],
    }
