"""The crank-forces program (``balancer.linkage.program``) against the numpy route it compiles.

The program evaluates the same equations (the groups' route of the general core) on CasADi's
reduction of them, with a fixed pivot order and one Newton step per numeric group; the numpy
route pivots per state and iterates. Both solve each state's equations to rounding, so they
agree to the rounding of the group solves: relative to each figure's largest magnitude, a few
hundred ε times the groups' condition (below 1e3 on these linkages, whose assembly gaps stay
above 1e-3), hence 1e-10.
"""

from __future__ import annotations

import tomllib
from pathlib import Path

import casadi as ca
import numpy as np
import pytest
from fuzz.linkages import _random_transform, build_topology, spec_from_topology

from balancer.linkage import kinematics, numeric
from balancer.linkage import program as program_module
from balancer.linkage.inputs import InputState
from balancer.linkage.kinematics import numeric_table
from balancer.linkage.program import CrankForcesProgram, Tape
from balancer.mechanisms import base, mechanism_of
from balancer.spec import design_from_dict, load_design

EXAMPLES = Path(__file__).resolve().parents[2] / "balancer" / "examples"
RTOL = 1e-10


def _fields(forces):
    out = {"driving_torque": forces.driving_torque, "shaking_moment": forces.shaking_moment,
           "shaking_force.x": forces.shaking_force.x, "shaking_force.y": forces.shaking_force.y,
           "rocking_couple.x": forces.rocking_couple.x, "rocking_couple.y": forces.rocking_couple.y}
    for p, r in forces.reactions.items():
        out[f"{p}.x"], out[f"{p}.y"] = r.x, r.y
    for k in forces.slider_normal:
        out[f"{k}.normal"] = forces.slider_normal[k]
        out[f"{k}.couple"] = forces.slider_couple[k]
    return {k: np.broadcast_to(np.asarray(v, dtype=float), forces.driving_torque.shape)
            for k, v in out.items()}


def _states(n: int, seed: int):
    rng = np.random.default_rng(seed)
    theta = np.concatenate([np.linspace(0, 2 * np.pi, n // 2, endpoint=False),
                            rng.uniform(-10, 10, n - n // 2)])
    return theta, rng.uniform(-20, 20, n), rng.uniform(-50, 50, n)


def _assert_same(got, want, where: str, length: float, slack=1.0) -> None:
    """Each figure within RTOL of its largest magnitude, or of what cancels in it.

    A figure that is zero in exact arithmetic (a couple of a guide no moment loads) is the
    rounding of terms as large as the largest force (times ``length``, m, for a moment).
    ``slack`` (per state, ``(N, 1)``) widens RTOL where the groups are worse conditioned.
    """
    a, b = _fields(got), _fields(want)
    assert a.keys() == b.keys(), where
    size = {k: float(np.max(np.abs(v[np.isfinite(v)]), initial=0.0)) for k, v in b.items()}
    moments = ("driving_torque", "shaking_moment", ".couple", "rocking_couple.x",
               "rocking_couple.y")
    force = max(v for k, v in size.items() if not k.endswith(moments))
    moment = max(max(v for k, v in size.items() if k.endswith(moments)), force * length)
    for key in b:
        finite = np.isfinite(b[key])
        np.testing.assert_array_equal(np.isfinite(a[key]), finite, err_msg=f"{where} {key}")
        floor = moment if key.endswith(moments) else force
        scale = max(size[key], 1e-6 * floor, 1e-300)
        off = np.abs(a[key] - b[key]) / np.broadcast_to(slack, finite.shape)
        err = float(np.max(off[finite], initial=0.0)) / scale
        assert err <= RTOL, f"{where} {key}: {err:.2e} relative"


def _numpy_route(mech, theta, omega, alpha, loads=True, gravity=(0.0, 0.0)):
    return mech.inverse_dynamics(mech.motion(theta, omega, alpha), route="newton-euler",
                                 loads=loads, gravity=gravity)


@pytest.mark.parametrize("name", ["watt_sixbar", "stephenson_sixbar", "quick_return",
                                  "jansen_leg", "engine"])
def test_the_program_gives_the_numpy_routes_forces(name):
    mech = mechanism_of(load_design(EXAMPLES / f"{name}.toml").mechanism)
    theta, omega, alpha = _states(3000, seed=1)
    for loads, gravity in ((True, (0.0, 0.0)), (False, (0.3, -9.81))):
        prog = CrankForcesProgram(mech.structure, loads=loads, gravity=gravity)
        forces, ok = prog.evaluate(theta, omega, alpha)
        want = _numpy_route(mech, theta, omega, alpha, loads, gravity)
        assert ok.mean() > 0.9, "the program leaves most states to the numpy route"
        _assert_same(_take(forces, ok), _take(want, ok), f"{name} loads={loads}",
                     mech.structure.length_scale())


def _take(value, rows):
    """``value`` (Forces, a dict, a vector or an array) at the given states."""
    if hasattr(value, "input_torques"):
        return type(value)(**{f: _take(getattr(value, f), rows) for f in
                              ("reactions", "slider_normal", "slider_couple",
                               "input_torques", "shaking_force", "shaking_moment",
                               "rocking_couple")})
    if isinstance(value, tuple):
        return tuple(_take(v, rows) for v in value)
    if isinstance(value, dict):
        return {k: _take(v, rows) for k, v in value.items()}
    if hasattr(value, "x"):
        return type(value)(value.x[rows], value.y[rows])
    return value[rows]


@pytest.mark.parametrize("family", ["watt1", "watt2", "stephenson2", "stephenson3",
                                    "quick-return", "slider-crank", "fourbar"])
@pytest.mark.parametrize("seed", [3, 17])
def test_the_program_agrees_on_random_linkages(family, seed):
    rng = np.random.default_rng(seed)
    topo, cls, _, _ = build_topology(rng, want="valid", family=family)
    assert cls == "valid"
    doc, _ = spec_from_topology(rng, topo, _random_transform(rng))
    for name, link in doc["links"].items():  # in planes along the crank's axis: rocking
        if name != "ground":
            link["z"] = float(rng.uniform(-0.3, 0.3))
    mech = mechanism_of(design_from_dict(doc).mechanism)
    theta, omega, alpha = _states(2000, seed=seed)
    want = _numpy_route(mech, theta, omega, alpha)
    got = base.Mechanism.crank_forces(mech, np.tile(theta, 5), np.tile(omega, 5),
                                      np.tile(alpha, 5))  # ≥ PROGRAM_STATES: the program
    assert theta.size * 5 >= base.PROGRAM_STATES
    _assert_same(_take(got, slice(0, theta.size)), want, f"{family} seed {seed}",
                 mech.structure.length_scale())


def test_states_the_program_leaves_out_are_the_numpy_routes(monkeypatch):
    """A pivot threshold no state meets leaves every state out; a Newton step's Taylor bound
    that the starts' errors (~1e-11 rad) straddle leaves some: the result is the numpy route's."""
    mech = mechanism_of(load_design(EXAMPLES / "stephenson_sixbar.toml").mechanism)
    theta, omega, alpha = _states(base.PROGRAM_STATES, seed=5)
    want = _numpy_route(mech, theta, omega, alpha)
    for setting, value, expect in ((program_module, 0.0, "none"), (numeric, 1e-11, "some")):
        name = "PIVOT_GROWTH" if setting is program_module else "TAYLOR_STEP"
        with monkeypatch.context() as patch:
            patch.setattr(setting, name, value)
            mech.__dict__.pop("_programs", None)  # built anew with the setting
            _, ok = mech._program(True, (0.0, 0.0)).evaluate(theta, omega, alpha)
            assert (not ok.any()) if expect == "none" else (0 < ok.sum() < ok.size), name
            _assert_same(mech.crank_forces(theta, omega, alpha), want, name,
                         mech.structure.length_scale())
    mech.__dict__.pop("_programs", None)


def test_a_tape_evaluates_its_function():
    """Every operation a tape maps, against CasADi's own evaluation, constants folded."""
    x, y = ca.SX.sym("x"), ca.SX.sym("y")
    exprs = [ca.sin(x) * ca.cos(y) + 2.5, ca.atan2(y, x), ca.sqrt(x * x + 1) / (y + 3),
             ca.if_else(x > y, x, y), ca.fmax(x, y) - ca.fmin(x, y), ca.fabs(x) * 2,
             -x, x**2, ca.exp(0.1 * y), ca.tan(0.2 * x), ca.SX(7.0) * ca.SX(3.0)]
    fn = ca.Function("f", [x, y], [ca.vertcat(*exprs)])
    tape = Tape(fn)
    rng = np.random.default_rng(0)
    xs, ys = rng.uniform(-2, 2, 1000), rng.uniform(-2, 2, 1000)
    (got,) = tape([xs[None, :], ys[None, :]], xs.size)
    want = np.asarray(fn.map(xs.size)(xs[None, :], ys[None, :]))
    np.testing.assert_allclose(got, want, rtol=4e-16 * 8, atol=0)


def test_a_tape_refuses_an_operation_it_cannot_map():
    x = ca.SX.sym("x")
    fn = ca.Function("f", [x], [ca.erf(x)])
    with pytest.raises(NotImplementedError, match="ERF"):
        Tape(fn)


def test_a_tape_writes_constants_that_are_not_finite():
    """CasADi folds 1/0 to inf; ``repr`` of it (``inf``, ``nan``) is no name in the program."""
    x = ca.SX.sym("x")
    exprs = [x + np.inf, x * np.nan, x - ca.SX(1.0) / ca.SX(0.0), ca.fmax(x, -np.inf)]
    fn = ca.Function("f", [x], [ca.vertcat(*exprs)])
    xs = np.array([-1.0, 0.0, 2.5, np.inf, np.nan])
    (got,) = Tape(fn)([xs[None, :]], xs.size)
    np.testing.assert_array_equal(got, np.asarray(fn.map(xs.size)(xs[None, :])))


def test_a_figure_folded_to_zero_is_nan_where_the_numpy_routes_is():
    """The engine's piston has its centre of mass on its guide: the guide's couple is 0·(…),
    which CasADi folds to 0 and numpy leaves NaN where the crank does not reach (an offset
    beyond rod − crank) or a state is not finite. Those states are the numpy route's."""
    doc = tomllib.loads((EXAMPLES / "engine.toml").read_text(encoding="utf-8"))
    doc["mechanism"]["lengths"]["offset"] = 0.07  # crank + offset > rod
    mech = mechanism_of(design_from_dict(doc).mechanism)
    assert not mech.assembly_range().full
    theta, omega, alpha = _states(base.PROGRAM_STATES, seed=7)
    theta[:3], omega[3], alpha[4] = (np.nan, np.inf, -np.inf), np.nan, np.nan
    with np.errstate(all="ignore"):
        got = mech.crank_forces(theta, omega, alpha)
        want = _numpy_route(mech, theta, omega, alpha)
    assert 0 < np.isfinite(want.slider_couple["slider"]).mean() < 1
    _assert_same(got, want, "engine beyond its range", mech.structure.length_scale())


#: A Stephenson triad with a slider (a numeric group) whose crank swings from one toggle of
#: the triad to another, further than π below its reference angle (−2.61 rad).
TRIAD = {"mechanism": {"type": "linkage", "input": "crank",
                       "points": {"D0": [0.0, 0.0], "D": [-0.649, -0.382], "C": [-0.363, 0.729],
                                  "A": [2.028, -0.411], "B": [1.617, -1.069],
                                  "A0": [-1.355, -1.656]},
                       "sliders": [{"link": "block", "guide": "ground", "point": "B",
                                    "direction": [-0.974, 0.226]}]},
         "links": {"ground": {"points": ["D0", "A0"]},
                   **{name: {"points": points, "mass": 1.0, "inertia": 0.01,
                             "com": {"e": 0.1, "f": 0.05}}
                      for name, points in (("crank", ["D0", "D"]), ("rod", ["D", "C"]),
                                           ("head", ["A", "B", "C"]), ("rocker", ["A0", "A"]),
                                           ("block", ["B"]))}}}


@pytest.mark.slow
def test_a_numeric_group_follows_its_branch_to_both_ends_of_its_table():
    """Within the last step of the table at each end, the start is the cubic through the last
    four rows (it was NaN, and Newton's method from zeros found another assembly), and an
    angle beyond π from the reference is in the range (it was outside the window a turn
    around the reference): the links move on from the end rows by less than the last step's
    change, the assembly range spans the table, and the program agrees with the numpy route."""
    mech = mechanism_of(design_from_dict(TRIAD).mechanism)
    s = mech.structure
    group = s.groups[-1]
    assert group.kind == "numeric"
    angles, tab = numeric_table(s, group)
    rows = np.flatnonzero(np.all(np.isfinite(tab), axis=1))
    h = angles[1] - angles[0]
    bands = []
    for end, side in ((rows[-1], -1), (rows[0], 1)):
        theta = angles[end] + side * np.linspace(0.0, h, 17)
        mo = mech.motion(theta)
        q = np.column_stack([np.asarray(v) for k in group.links for v in
                             (mo.pose.origins[k].x, mo.pose.origins[k].y, mo.pose.angles[k])])
        moved = np.max(np.abs(q - tab[end]), axis=1)
        assert np.all(moved <= np.max(np.abs(tab[end + side] - tab[end])) * (1 + 1e-9)), end
        bands.append(theta)
    assert angles[rows[0]] < s.ref_angle[s.input] - np.pi
    (lo, hi), = mech.assembly_range().intervals
    turn = 2 * np.pi
    assert abs((lo - angles[rows[0]]) % turn) < 1e-6 or abs((angles[rows[0]] - lo) % turn) < 1e-6
    assert abs((hi - angles[rows[-1]]) % turn) < 1e-6 or abs((angles[rows[-1]] - hi) % turn) < 1e-6
    theta = np.tile(np.concatenate([*bands, bands[1] + turn, bands[0] - 2 * turn]),
                    base.PROGRAM_STATES // 64 + 1)
    omega, alpha = np.full(theta.size, 3.0), np.full(theta.size, -2.0)
    with np.errstate(all="ignore"):
        want = _numpy_route(mech, theta, omega, alpha)
    assert np.isfinite(want.driving_torque).all()
    # By a toggle the figures' rounding grows as 1/gap (the gap a squared ratio of the
    # Jacobian's singular values): RTOL holds down to gaps of 1e-3 (the module's docstring).
    gaps: list = []
    kinematics.positions(s, InputState.crank(theta), gaps=gaps)
    slack = np.maximum(1.0, 1e-3 / gaps[-1])[:, None]
    _assert_same(mech.crank_forces(theta, omega, alpha), want, "triad's ends", s.length_scale(),
                 slack)
