"""A linkage with several inputs simulated: driven along a motion in two formulations, and free.

Second routes: the multibody formulation's saddle-point system (absolute coordinates and
multipliers, compiled CasADi) against the linkage core's kinematics and inverse dynamics
(group by group, numpy); each run's energy balance (the motors' work by quadrature against the
kinetic energy and the configuration's work); a driven bar's torque in closed form; a free run
integrated in both formulations.
"""

from __future__ import annotations

import csv
import io
import json
import math

import numpy as np
import pytest
from linkage.several_inputs_specs import (
    crank_slider,
    fivebar,
    linkage_of,
    parallelogram,
    three_rrr,
)

from balancer.cli import main
from balancer.formulations.multibody import Multibody
from balancer.linkage import trajectory
from balancer.linkage.inputs import InputState
from balancer.mechanisms import mechanism_of
from balancer.model.motions import MotionSpec
from balancer.motion_verification import _agreement, fastest_state
from balancer.simulation.motions import simulate_along, simulate_free

GRAVITY = (0.0, -9.81)
#: The runs' quadrature tolerance (relative): the energy balance holds to the panels' count
#: times it (a few hundred at most).
RTOL = 1e-10


def _inputs_motion(count: int, size: float = 0.3) -> MotionSpec:
    """The inputs' own path: each swings out and back (rad from the reference), quintic law."""
    path = ((0.0,) * count, tuple(size * (-1) ** i for i in range(count)),
            tuple(-size * 2 / 3 * (i + 1) / count for i in range(count)), (0.0,) * count)
    return MotionSpec(name="sway", times=(0.0, 0.3, 0.7, 1.0), path=path, law="quintic",
                      samples=81)


def _point_motion() -> MotionSpec:
    """The five-bar's apex E along a small loop about its reference place (m)."""
    e = (0.1, 0.35)
    path = tuple((e[0] + 0.02 * math.sin(a), e[1] + 0.015 * (1 - math.cos(a)))
                 for a in np.linspace(0.0, 2 * math.pi, 5))
    return MotionSpec(name="loop", times=(0.0, 0.25, 0.5, 0.75, 1.0), path=path, point="E",
                      law="spline", samples=101)


CASES = {
    "fivebar, inputs' path": (fivebar, lambda: _inputs_motion(2)),
    "fivebar, point's path": (fivebar, _point_motion),
    "parallelogram": (parallelogram, lambda: _inputs_motion(2)),
    "3-RRR": (three_rrr, lambda: _inputs_motion(3, 0.08)),
    "crank and slide": (crank_slider, lambda: _inputs_motion(2, 0.1)),
}


@pytest.mark.parametrize("case", [pytest.param(c, marks=pytest.mark.slow) if c == "3-RRR"
                                  else c for c in CASES])
def test_the_two_formulations_agree_along_a_motion(case):
    make_spec, make_motion = CASES[case]
    mech = mechanism_of(linkage_of(make_spec()))
    motion = make_motion()
    a = simulate_along(mech, motion, method="multibody", gravity=GRAVITY, rtol=RTOL)
    b = simulate_along(mech, motion, method="input-coordinates", gravity=GRAVITY, rtol=RTOL)
    # The saddle-point solve against the group-by-group route: rounding of the loads' scales
    # times the system's conditioning (1e-14 seen).
    assert _agreement(a, b) <= 1e-10
    np.testing.assert_allclose(a.kinetic_energy, b.kinetic_energy,
                               rtol=1e-12, atol=1e-12 * float(np.max(a.kinetic_energy)))
    for run in (a, b):  # each formulation's torques against its own kinetic energy
        assert run.energy_error <= 100 * RTOL
        assert run.drive == "motion" and run.motion == motion.name
        assert np.max(run.kinetic_energy) > 0  # (it moves: the balance weighs something)


@pytest.mark.parametrize("case", ["fivebar, point's path", "3-RRR"])
def test_the_multibody_accelerations_are_the_kinematics(case):
    make_spec, make_motion = CASES[case]
    mech = mechanism_of(linkage_of(make_spec()))
    state = trajectory.input_state(mech.structure, make_motion())
    f = Multibody(mech, gravity=GRAVITY, prescribed=True)
    pd = f.prescribed_dynamics(state)
    mo = mech.motion_at(state)
    acc = np.column_stack([x for k in range(mech.structure.size)
                           for x in (np.broadcast_to(mo.acceleration[k].x, (state.count,)),
                                     np.broadcast_to(mo.acceleration[k].y, (state.count,)),
                                     np.broadcast_to(mo.accel[k], (state.count,)))])
    scale = float(np.max(np.abs(acc)))
    np.testing.assert_allclose(pd.qdd, acc, rtol=0, atol=1e-11 * scale)
    for i, k in enumerate(mech.structure.inputs):  # each driver holds its input's acceleration
        np.testing.assert_allclose(pd.qdd[:, 3 * k + 2], state.accelerations[i],
                                   rtol=0, atol=1e-12 * scale)


def test_a_driven_bar_needs_the_closed_form_torque():
    # One bar about a ground pivot, driven along a quintic swing under gravity:
    # τ = J_O·α + m·g·(e·cos θ − f·sin θ), J_O = J + m·(e² + f²).
    m, j, e, f = 0.7, 0.004, 0.12, 0.01
    spec = {"mechanism": {"type": "linkage", "input": "bar",
                          "points": {"O": [0.0, 0.0], "P": [0.3, 0.0]}},
            "links": {"ground": {"points": ["O"]},
                      "bar": {"points": ["O", "P"], "mass": m, "inertia": j,
                              "com": {"e": e, "f": f}}}}
    mech = mechanism_of(linkage_of(spec))
    motion = MotionSpec(name="swing", times=(0.0, 0.5), path=((0.0,), (1.2,)), law="quintic",
                        samples=41)
    for method in ("multibody", "input-coordinates"):
        run = simulate_along(mech, motion, method=method, gravity=GRAVITY, rtol=RTOL)
        theta, alpha = run.state.positions[0], run.state.accelerations[0]
        torque = ((j + m * (e * e + f * f)) * alpha
                  + m * 9.81 * (e * np.cos(theta) - f * np.sin(theta)))
        np.testing.assert_allclose(run.reactions.torques[0], torque, rtol=1e-12,
                                   atol=1e-13 * float(np.max(np.abs(torque))))
        # The pivot carries the weight less the centre of mass's m·a_c: on the frame,
        # m·ḡ − m·a_c with a_c = α·(R·c̄)⊥ − ω²·R·c̄.
        omega = run.state.rates[0]
        centre = (e + 1j * f) * np.exp(1j * theta)
        a_c = alpha * 1j * centre - omega**2 * centre
        pivot = m * (GRAVITY[0] + 1j * GRAVITY[1]) - m * a_c
        np.testing.assert_allclose(run.reactions.ground["O"], pivot, rtol=0,
                                   atol=1e-12 * float(np.max(np.abs(pivot))))
        assert run.energy_error <= 100 * RTOL


@pytest.mark.parametrize("make_spec", [fivebar, parallelogram, crank_slider],
                         ids=["fivebar", "parallelogram", "crank and slide"])
def test_free_motion_agrees_in_both_formulations(make_spec):
    mech = mechanism_of(linkage_of(make_spec()))
    start = fastest_state(mech, _inputs_motion(2))
    runs = [simulate_free(mech, start, 0.05, method=method, gravity=GRAVITY, outputs=11,
                          rtol=RTOL, atol=1e-12) for method in ("multibody", "input-coordinates")]
    a, b = runs
    for run in runs:
        assert run.energy_error <= 100 * RTOL  # a first integral of the integrated system
    size = mech.structure.length_scale()
    for t in b.reactions.torques:  # the core's torques at the free accelerations: rounding
        assert float(np.max(np.abs(t))) <= 1e-9 * a.largest_reaction * size
    assert all(np.all(t == 0.0) for t in a.reactions.torques)  # no driver: none
    # Two integrations to rtol 1e-10 (their global errors: a few hundred steps' worth at most).
    for pa, pb in zip(a.state.positions, b.state.positions, strict=True):
        np.testing.assert_allclose(pa, pb, rtol=0, atol=1e-7)
    force = max(a.largest_reaction, 1e-300)
    assert float(np.max(np.abs(a.reactions.shaking_force - b.reactions.shaking_force))) \
        <= 1e-6 * force
    assert a.drift[0] <= 1e-9 * mech.structure.length_scale()


def test_a_free_start_that_does_not_assemble_is_refused():
    from balancer.errors import AssemblyError

    mech = mechanism_of(linkage_of(fivebar()))
    # Left crank pointing left, right one right: C and D farther apart than E's two links reach.
    far = InputState.of([np.array([math.pi]), np.array([0.0])], [np.zeros(1), np.zeros(1)])
    with pytest.raises(AssemblyError):
        simulate_free(mech, far, 0.1)


def _example(tmp_path, name):
    from importlib.resources import files

    path = tmp_path / f"{name}.toml"
    path.write_text((files("balancer") / "examples" / f"{name}.toml").read_text())
    return path


def _cli(capsys, *argv):
    code = main([str(a) for a in argv])
    out = capsys.readouterr()
    return code, out.out, out.err


def test_simulate_writes_the_analysis_columns_and_agrees_with_it(tmp_path, capsys):
    spec = _example(tmp_path, "fivebar_5r")
    code, _, err = _cli(capsys, "simulate", spec, "--motion", "loop", "--out",
                        tmp_path / "run.csv")
    assert code == 0, err
    code, _, err = _cli(capsys, "analyze", spec, "--motion", "loop", "--csv",
                        tmp_path / "an.csv")
    assert code == 0, err
    run = list(csv.reader(io.StringIO((tmp_path / "run.csv").read_text())))
    analysis = list(csv.reader(io.StringIO((tmp_path / "an.csv").read_text())))
    assert run[0] == analysis[0]  # the same columns, in the same order
    x, y = (np.array(rows[1:], dtype=float) for rows in (run, analysis))
    scale = np.max(np.abs(y), axis=0)
    assert np.all(np.abs(x - y) <= 1e-10 * np.maximum(scale, 1e-300))


@pytest.mark.slow
def test_simulate_free_and_verify_on_a_robot(tmp_path, capsys):
    spec = _example(tmp_path, "forbal2")
    code, out, err = _cli(capsys, "simulate", spec, "--drive", "free", "--json")
    assert code == 0, err
    doc = json.loads(out)
    assert doc["drive"] == "free" and doc["inputs"] == ["link11", "link21"]
    assert doc["energy_error"] <= 1e-6 and set(doc["initial"]) == {"link11", "link21"}
    code, out, err = _cli(capsys, "verify", spec, "--json")
    assert code == 0, err
    doc = json.loads(out)
    assert set(doc["motions"]) == {"diamond", "circle", "figure-eight"}
    for run in doc["motions"].values():  # the published design is nearly force-balanced
        assert run["force_level"] <= 0.02 and run["formulations_agree_to"] <= 1e-10
        assert set(run["max_torques"]) == {"link11", "link21"}


def test_simulate_refuses_what_a_motion_does_not_have(tmp_path, capsys):
    spec = _example(tmp_path, "three_rrr")
    for argv, key in ((["--drive", "constant-speed"], "--drive"),
                      (["--method", "opened-loop"], "--method"),
                      (["--motion", "nope"], "--motion")):
        code, _, err = _cli(capsys, "simulate", spec, *argv)
        assert code == 2 and f"{key}: " in err and "Traceback" not in err, err


@pytest.mark.slow
def test_verify_draws_its_figure_along_the_motions(tmp_path, capsys):
    spec = _example(tmp_path, "pick_fivebar")
    code, out, err = _cli(capsys, "verify", spec, "--plot", tmp_path / "v.png")
    assert code == 0, err
    assert (tmp_path / "v.png").stat().st_size > 10_000
    assert "along pick" in out and "free for" in out


def _momentum_rate(mech, state):
    """``Σ m_k·a_ck`` from the core's kinematics: each centre of mass's acceleration, N."""
    mo = mech.motion_at(state)
    total = 0.0
    for k, link in enumerate(mech.linkage.links):
        c, s_ = np.asarray(mo.pose.cos[k]), np.asarray(mo.pose.sin[k])
        rx, ry = link.e * c - link.f * s_, link.e * s_ + link.f * c
        w, al = np.asarray(mo.rate[k]), np.asarray(mo.accel[k])
        ax = np.asarray(mo.acceleration[k].x) - al * ry - w * w * rx
        ay = np.asarray(mo.acceleration[k].y) + al * rx - w * w * ry
        total = total + link.mass * (ax + 1j * ay)
    return np.ravel(total)


def test_the_shaking_force_is_the_momentum_rate_driven_and_free():
    # Newton's law for the moving links together (no gravity): the frame feels −Σ m·a_c.
    mech = mechanism_of(linkage_of(fivebar()))
    motion = _inputs_motion(2)
    driven = simulate_along(mech, motion)
    free = simulate_free(mech, fastest_state(mech, motion), 0.05, outputs=6)
    for run in (driven, free):
        expected = -_momentum_rate(mech, run.state)
        scale = float(np.max(np.abs(expected)))
        assert scale > 1e-3  # (the five-bar is not balanced: a test that can fail)
        assert float(np.max(np.abs(run.reactions.shaking_force - expected))) <= 1e-9 * scale


def _loaded_fivebar() -> dict:
    """The five-bar with a spring from the ground to E, a force and a moment on its links and
    counter-rotors on its cranks: every kind of load the two formulations must carry."""
    spec = fivebar()
    spec["mechanism"]["points"]["G"] = [0.3, 0.45]
    spec["links"]["ground"]["points"] = ["A", "B", "G"]
    spec["springs"] = [{"points": ["G", "E"], "stiffness": 40.0, "free_length": 0.15}]
    spec["links"]["upper_left"] |= {"force": [0.3, -0.2], "moment": 0.05}
    spec["links"]["left"]["counter_rotor"] = 0.0008
    spec["links"]["right"]["counter_rotor"] = 0.0005
    return spec


def test_springs_loads_and_counter_rotors_driven_and_free():
    mech = mechanism_of(linkage_of(_loaded_fivebar()))
    motion = _inputs_motion(2)
    a = simulate_along(mech, motion, method="multibody", gravity=GRAVITY, rtol=RTOL)
    b = simulate_along(mech, motion, method="input-coordinates", gravity=GRAVITY, rtol=RTOL)
    assert _agreement(a, b) <= 1e-10
    assert max(a.energy_error, b.energy_error) <= 100 * RTOL
    start = fastest_state(mech, motion)
    free = [simulate_free(mech, start, 0.05, method=method, gravity=GRAVITY, outputs=11,
                          rtol=RTOL, atol=1e-12) for method in ("multibody", "input-coordinates")]
    for run in free:  # (the spring's configuration torque left out of M would show here)
        assert run.energy_error <= 100 * RTOL
    for pa, pb in zip(free[0].state.positions, free[1].state.positions, strict=True):
        np.testing.assert_allclose(pa, pb, rtol=0, atol=1e-7)


def test_a_link_turning_far_between_samples_keeps_its_turns():
    # A crank-rocker's crank turned three times in eight samples, a moment on it: its work
    # counts the turns the angles make between samples (from the rates), not their nearest
    # values modulo 2π.
    from linkage.several_inputs_specs import crank_rocker

    spec = crank_rocker()
    spec["links"]["crank"]["moment"] = 2.0
    mech = mechanism_of(linkage_of(spec))
    motion = MotionSpec(name="turns", times=(0.0, 1.0), path=((0.0,), (6 * math.pi,)),
                        law="quintic", samples=8)
    for method in ("multibody", "input-coordinates"):
        run = simulate_along(mech, motion, method=method, rtol=RTOL)
        assert run.energy_error <= 100 * RTOL


@pytest.mark.slow  # (0.8 s: the full suite's)
def test_what_a_fuzz_campaign_found_along_motions(tmp_path, capsys):
    # A [simulation] table on a robot is read (its method among the robot's formulations);
    # a driven run's --duration is refused (it lasts its motion); a motion that moves a
    # picometre is simulated (its power is rounding: the work's tolerance floors there); a
    # bad waypoint is named with its motion's index.
    spec = _example(tmp_path, "pick_fivebar")
    text = spec.read_text()
    spec.write_text(text + '\n[simulation]\nduration = 0.05\nmethod = "input-coordinates"\n')
    code, out, err = _cli(capsys, "simulate", spec, "--drive", "free", "--json")
    assert code == 0, err
    doc = json.loads(out)
    assert doc["method"] == "input-coordinates" and doc["duration"] == 0.05
    code, _, err = _cli(capsys, "simulate", spec, "--duration", "0.3")
    assert code == 2 and "--duration: is a free run's" in err, err
    start = "[0.16867194669263857, 0.2944945065744622]"
    tiny = text.replace("[0.22, 0.25]", "[0.16867194669363858, 0.2944945065744622]")
    assert tiny != text and start in tiny
    spec.write_text(tiny)
    code, out, err = _cli(capsys, "simulate", spec, "--json")
    assert code == 0, err
    spec.write_text(text.replace("[0.22, 0.25]", "[2.2, 2.5]"))
    for verb in ("simulate", "verify"):
        code, _, err = _cli(capsys, verb, spec)
        assert code == 2 and ": motion[1].path: " in err, err


def test_a_csv_field_too_long_is_bad_input(tmp_path, capsys):
    spec = _example(tmp_path, "pick_fivebar")
    (tmp_path / "pick.csv").write_text("t,p,q\n0,0,0\n0.5,0.1,0.05\n1,0,0\n2," + "1" * 140_000
                                       + ",0\n")
    text = spec.read_text()
    start = text.index("[[motion]]")
    end = text.index("\n[", start + 10) if "\n[" in text[start + 10:] else len(text)
    spec.write_text(text[:start] + '[[motion]]\nname = "pick"\nfile = "pick.csv"\n'
                    + text[end:])
    code, _, err = _cli(capsys, "analyze", spec)
    assert code == 2 and "motion[1].file: is not a CSV table" in err, err
