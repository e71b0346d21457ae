"""What the designer reads is what is true (issue 40).

- ``N_<link>`` points as docs/outputs.md says: the force of a sliding link on its guide, along
  the guide's direction turned +90°, checked by summing the frame's forces.
"""

from __future__ import annotations

import math
from pathlib import Path

from balancer.api import analyze
from balancer.spec import load_design

ROOT = Path(__file__).resolve().parent.parent
EXAMPLES = ROOT / "examples"


def test_a_piston_s_normal_force_points_along_its_axis_turned_a_quarter_turn():
    """docs/outputs.md: N_<link> is the force on the frame across the guide, along the guide's
    direction turned +90°. Summed with the main bearings' reaction it is the shaking force."""
    design = load_design(EXAMPLES / "v8.toml")
    cycle = analyze(design)
    names, columns = cycle.columns()
    col = dict(zip(names, columns, strict=True))
    total = col["ROx"] + 1j * col["ROy"]
    for k, c in enumerate(design.mechanism.cylinders, start=1):
        total = total + col[f"N_piston{k}"] * 1j * complex(math.cos(c.bank), math.sin(c.bank))
    force = col["shaking_force_x"] + 1j * col["shaking_force_y"]
    assert max(abs(total - force)) < 1e-12 * max(abs(col["N_piston1"]))
    assert max(abs(col["N_piston1"])) > 1000  # (not a sum of zeros)
