"""The crank-forces program (``balancer.linkage.program``) against the numpy route it compiles.

The program evaluates the same equations (the groups' route of the general core) on CasADi's
reduction of them, with a fixed pivot order and one Newton step per numeric group; the numpy
route pivots per state and iterates. Both solve each state's equations to rounding, so they
agree to the rounding of the group solves: relative to each figure's largest magnitude, a few
hundred ε times the groups' condition (below 1e3 on these linkages, whose assembly gaps stay
above 1e-3), hence 1e-10.
"""

from __future__ import annotations

from pathlib import Path

import casadi as ca
import numpy as np
import pytest
from fuzz.linkages import _random_transform, build_topology, spec_from_topology

from balancer.linkage import program as program_module
from balancer.linkage.program import CrankForcesProgram, Tape
from balancer.mechanisms import base, mechanism_of
from balancer.spec import design_from_dict, load_design

EXAMPLES = Path(__file__).resolve().parent.parent / "balancer" / "examples"
RTOL = 1e-10


def _fields(forces):
    out = {"driving_torque": forces.driving_torque, "shaking_moment": forces.shaking_moment,
           "shaking_force.x": forces.shaking_force.x, "shaking_force.y": forces.shaking_force.y}
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


def _assert_same(got, want, where: str, length: float) -> None:
    """Each figure within RTOL of its largest magnitude, or of what cancels in it.

    A figure that is zero in exact arithmetic (a couple of a guide no moment loads) is the
    rounding of terms as large as the largest force (times ``length``, m, for a moment).
    """
    a, b = _fields(got), _fields(want)
    assert a.keys() == b.keys(), where
    size = {k: float(np.max(np.abs(v[np.isfinite(v)]), initial=0.0)) for k, v in b.items()}
    moments = ("driving_torque", "shaking_moment", ".couple")
    force = max(v for k, v in size.items() if not k.endswith(moments))
    moment = max(max(v for k, v in size.items() if k.endswith(moments)), force * length)
    for key in b:
        finite = np.isfinite(b[key])
        np.testing.assert_array_equal(np.isfinite(a[key]), finite, err_msg=f"{where} {key}")
        floor = moment if key.endswith(moments) else force
        scale = max(size[key], 1e-6 * floor, 1e-300)
        err = float(np.max(np.abs(a[key][finite] - b[key][finite]), initial=0.0)) / scale
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
    if hasattr(value, "driving_torque"):
        return type(value)(**{f: _take(getattr(value, f), rows) for f in
                              ("reactions", "slider_normal", "slider_couple",
                               "driving_torque", "shaking_force", "shaking_moment")})
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
    from balancer.linkage import numeric

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
