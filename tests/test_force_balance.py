"""Force-balance conditions of linkages with several inputs (:mod:`balancer.force_balance`).

The conditions are found by sampling the configuration space; here they are checked against a
closed form (the parallelogram five-bar: the first moments along each of its two independent
link directions must vanish, four real conditions), against the count of independent
directions less loop closures (a general five-bar: 4 link directions less 1 closure, three
complex conditions; a 3-RRR: 7 less 2, five), and by a design from their null space, whose
total centre of mass must stand still over states far from those sampled.
"""

from __future__ import annotations

import numpy as np
import pytest
from linkage.several_inputs_specs import A, B, fivebar, linkage_of, parallelogram, three_rrr

from balancer.force_balance import first_moment_map, force_balance_conditions
from balancer.linkage.inputs import InputState
from balancer.mechanisms import mechanism_of


def _rank(m: np.ndarray) -> int:
    sv = np.linalg.svd(m, compute_uv=False)
    return int(np.sum(sv > 1e-10 * sv[0]))


def test_the_parallelogram_five_bars_conditions_are_its_two_directions_first_moments():
    mech = mechanism_of(linkage_of(parallelogram()))
    found = force_balance_conditions(mech)
    assert found.count == 4
    layout = mech.layout
    closed = np.zeros((4, layout.size))
    # along p's direction: (m·e + i·m·f)_p + A·m_r + (m·e + i·m·f)_s = 0
    closed[0, [layout.index("p", "me"), layout.index("s", "me")]] = 1.0
    closed[0, layout.index("r", "m")] = A
    closed[1, [layout.index("p", "mf"), layout.index("s", "mf")]] = 1.0
    # along q's direction: (m·e + i·m·f)_q + B·m_s + (m·e + i·m·f)_r = 0
    closed[2, [layout.index("q", "me"), layout.index("r", "me")]] = 1.0
    closed[2, layout.index("s", "m")] = B
    closed[3, [layout.index("q", "mf"), layout.index("r", "mf")]] = 1.0
    assert _rank(np.vstack([found.matrix, closed])) == 4  # the same row space
    assert _rank(closed) == 4


@pytest.mark.parametrize(("spec", "count"), [
    (fivebar, 6), pytest.param(three_rrr, 10, marks=pytest.mark.slow)])
def test_the_count_of_conditions_is_the_directions_less_the_closures(spec, count):
    assert force_balance_conditions(mechanism_of(linkage_of(spec()))).count == count


@pytest.mark.parametrize("spec", [
    fivebar, parallelogram,
    pytest.param(three_rrr, marks=pytest.mark.slow)])  # (its platform by continuation: 1 s)
def test_a_design_of_the_null_space_keeps_its_centre_of_mass_still(spec):
    mech = mechanism_of(linkage_of(spec()))
    found = force_balance_conditions(mech)
    null = np.linalg.svd(found.matrix)[2][found.count:].T
    rng = np.random.default_rng(7)
    x = null @ rng.normal(size=null.shape[1])
    x *= np.max(np.abs(mech.layout.vector(mech.linkage))) / np.max(np.abs(x))
    # states over a box three times the one sampled, those that assemble
    reference = np.array([mech.structure.ref_angle[k] for k in mech.structure.inputs])
    q = reference[:, None] + rng.uniform(-0.8, 0.8, (reference.size, 400))
    state = InputState.of(list(q))
    g = first_moment_map(mech, state)
    kept = np.all(np.isfinite(g), axis=1)
    if spec is parallelogram:  # (past its folded pose the dyad's branch is the kite: another
        # mechanism, whose conditions are others; the parallelogram's states only)
        angles = mech.pose_at(state).angles
        kept &= np.abs(np.remainder(angles[3] - angles[0] + np.pi, 2 * np.pi) - np.pi) < 1e-9
    moment = g[kept] @ x
    assert moment.size > 40
    terms = np.max(np.abs(g[kept] * x))
    assert np.max(np.abs(moment - moment[0])) <= 1e-12 * terms * x.size
    # and the design as it is moves its centre of mass
    own = g[kept] @ mech.layout.vector(mech.linkage)
    assert np.max(np.abs(own - own[0])) > 1e-3 * np.max(np.abs(own))
