"""What a geometry computes once is shared by its designs, and is what they would compute.

``Structure.of`` keeps the structures of recent geometries: a design and its redesign (which
changes masses only) share the equations and ``Structure.kinematic`` — the assembly range, the
numeric groups' tables, motions at a few states, the force-balance conditions. Each is checked
here against the same computed afresh (the cache emptied), and a change of geometry against
sharing anything.
"""

from __future__ import annotations

from dataclasses import replace
from pathlib import Path

import numpy as np
import pytest

import balancer.linkage.structure as structure_module
from balancer.cycle import cycle_analysis
from balancer.force_balance import force_balance_conditions
from balancer.linkage.inputs import InputState
from balancer.linkage.kinematics import motion
from balancer.mechanisms import mechanism_of
from balancer.spec import load_design

EXAMPLES = Path(__file__).resolve().parents[2] / "examples"


def heavier(model, factor: float = 2.0):
    """The same geometry, every link's mass ``factor`` times (a redesign)."""
    return model.with_links({name: replace(model.link(name),
                                           mass=factor * model.link(name).mass)
                             for name in model.link_names})


@pytest.mark.parametrize("name", ["watt_sixbar", "stephenson_sixbar", "quick_return"])
def test_a_redesign_shares_its_geometrys_work_and_it_is_what_it_would_compute(name):
    model = load_design(EXAMPLES / f"{name}.toml").mechanism
    # (Models of their own: the example's mechanism, built by an earlier test, may hold a
    # structure whose geometry has left the cache since.)
    first = mechanism_of(heavier(model, 1.25))
    second = mechanism_of(heavier(model))
    assert second.structure.kinematic is first.structure.kinematic
    assert second.structure.linkage is not first.structure.linkage
    theta = np.linspace(0, 2 * np.pi, 360, endpoint=False)
    shared = motion(second.structure, InputState.crank(theta, 7.0, 0.5))
    assert motion(first.structure, InputState.crank(theta, 7.0, 0.5)) is shared
    conditions = force_balance_conditions(second)
    analysis = cycle_analysis(second, 7.0, 360)
    structure_module._SKELETONS.clear()  # afresh: nothing kept
    fresh = mechanism_of(heavier(model, 3.0))  # (a model of its own: a mechanism of its own)
    assert fresh.structure.kinematic is not first.structure.kinematic
    again = motion(fresh.structure, InputState.crank(theta, 7.0, 0.5))
    for a, b in zip([*shared.pose.cos, *shared.rate], [*again.pose.cos, *again.rate],
                    strict=True):
        np.testing.assert_array_equal(np.asarray(a), np.asarray(b))
    assert fresh.assembly_range() == second.assembly_range()
    np.testing.assert_array_equal(force_balance_conditions(fresh).matrix, conditions.matrix)
    # The same geometry's motion, fresh: masses 1.5 times the redesign's, forces 1.5 times.
    redo = cycle_analysis(fresh, 7.0, 360)
    np.testing.assert_allclose(redo.reactions.shaking_force,
                               1.5 * analysis.reactions.shaking_force, rtol=1e-12,
                               atol=1e-12 * np.max(np.abs(analysis.reactions.shaking_force)))


def test_another_geometry_shares_nothing():
    design = load_design(EXAMPLES / "pb1.toml")
    model = design.mechanism
    lengths = list(model.lengths)
    lengths[1] *= 1.01
    other = replace(model, lengths=tuple(lengths))
    a, b = mechanism_of(model), mechanism_of(other)
    assert a.structure.kinematic is not b.structure.kinematic
    assert a.structure.local != b.structure.local
