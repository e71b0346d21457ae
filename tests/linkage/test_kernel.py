"""The straight-line program compiled with numba (``balancer/linkage/kernel.py``).

The kernel is the numpy tape's algorithm written as scalar code: every check compares the two
(the tape is the second route, itself checked against the general core and the closed forms in
``tests/linkage/test_linkage.py``), and a long cycle's figures with the kernel against the numpy
route's. Its cache: a second process loads what the first compiled; a folder that cannot be
written, or two processes compiling at once, are not errors; ``BALANCER_KERNELS=0`` turns it off;
a short analysis never imports numba.
"""

from __future__ import annotations

import json
import math
import os
import subprocess
import sys
from pathlib import Path

import casadi as ca
import numpy as np
import pytest

from balancer.cycle import cycle_analysis
from balancer.linkage.kernel import CACHE_ENV, SWITCH_ENV, Kernel, compile_kernel
from balancer.linkage.program import Tape
from balancer.mechanisms import mechanism_of
from balancer.mechanisms.base import frame_points
from balancer.spec import load_design

#: The whole module is of the full suite, not of the fast lane (`pytest -m "not slow"`).
pytestmark = pytest.mark.slow

ROOT = Path(__file__).resolve().parents[2]
EXAMPLES = ROOT / "examples"
#: Mechanisms of every kind of group: a four-bar's dyads, a slider-crank's, the Watt six-bar's
#: two loops, the Stephenson six-bar's numeric triad, an engine's cylinders and rotors.
NAMES = ("pb1", "quick_return", "watt_sixbar", "stephenson_sixbar", "single_cylinder", "v8")
#: The kernel and the tape make the same IEEE operations in the same order, on scalars where
#: the tape makes them on arrays; the C library's ``sin``, ``atan2``, … are the same ones.
#: They then agree bit for bit; a few units of the last place are allowed (a libm that rounds
#: its vector loop apart from its scalar one), relative to each row's scale.
ULPS = 8 * np.finfo(float).eps


@pytest.fixture(autouse=True)
def cache(tmp_path_factory, monkeypatch):
    """A cache folder of the test session (not the user's)."""
    folder = tmp_path_factory.getbasetemp() / "kernel-cache"
    monkeypatch.setenv(CACHE_ENV, str(folder))
    monkeypatch.delenv(SWITCH_ENV, raising=False)
    return folder


def states(n: int, seed: int = 7):
    rng = np.random.default_rng(seed)
    return (rng.uniform(0, 2 * math.pi, n), rng.uniform(-30, 30, n), rng.uniform(-500, 500, n))


def close(a: np.ndarray, b: np.ndarray) -> None:
    scale = np.nanmax(np.abs(b), axis=-1, keepdims=True) + 1e-300
    np.testing.assert_array_equal(np.isnan(a), np.isnan(b))
    assert np.nanmax(np.abs(a - b) / scale) <= ULPS


@pytest.mark.parametrize("name", NAMES)
def test_a_mechanisms_kernel_is_its_tape(name):
    """The program's forces at random crank states (ω, α any), both routes, loads on."""
    mech = mechanism_of(load_design(EXAMPLES / f"{name}.toml").mechanism)
    program = mech._program(True, (0.0, -9.81))
    assert program is not None and program.kernel is not None
    theta, omega, alpha = states(3000)
    by_tape, ok_tape = program.evaluate(theta, omega, alpha)
    by_kernel, ok_kernel = program.evaluate(theta, omega, alpha, compiled=True)
    np.testing.assert_array_equal(ok_tape, ok_kernel)
    assert ok_kernel.mean() > 0.5  # (most states are the program's)
    for a, b in zip(by_kernel.arrays(), by_tape.arrays(), strict=True):
        close(np.asarray(a)[ok_kernel, 0], np.asarray(b)[ok_tape, 0])


@pytest.mark.parametrize("name", ("pb1", "watt_sixbar", "v8"))
def test_a_long_cycle_by_the_kernel_is_the_numpy_routes(name):
    """``crank_forces`` compiled (a long cycle's chunks) against the numpy route — for the
    four-bar its closed forms (Eq. 12–28) — within rounding of the figures' scale."""
    mech = mechanism_of(load_design(EXAMPLES / f"{name}.toml").mechanism)
    theta = np.linspace(0, 2 * math.pi, 4001)
    compiled = mech.crank_forces(theta, 40.0, 0.0, compiled=True)
    numpy_route = mech.crank_forces(theta, 40.0, 0.0, compiled=False)
    # (A figure that cancels — a balanced engine's moment — is rounding of the largest terms:
    # the scale is the largest figure of all.)
    scale = max(float(np.max(np.abs(np.asarray(b, float)))) for b in numpy_route.arrays())
    for a, b in zip(compiled.arrays(), numpy_route.arrays(), strict=True):
        assert np.max(np.abs(np.asarray(a, float) - np.asarray(b, float))) <= 1e-12 * scale


def test_a_cycle_analysis_long_enough_runs_compiled_and_gives_the_same_summary(monkeypatch):
    """The threshold lowered: the whole analysis through the kernel = through numpy."""
    import balancer.cycle as cycle_module

    design = load_design(EXAMPLES / "watt_sixbar.toml")
    speed = design.operation.speed
    slow = cycle_analysis(design.mechanism, speed, 6000)
    monkeypatch.setattr(cycle_module, "KERNEL_STATES", 1000)
    fast = cycle_analysis(design.mechanism, speed, 6000)
    a, b = fast.summary.as_dict(), slow.summary.as_dict()
    for key in a:
        for stat in ("rms", "max"):
            assert a[key][stat] == pytest.approx(b[key][stat], rel=1e-12, abs=1e-9)


def test_the_kernel_source_covers_every_operation_of_the_tape():
    """Elementwise operations with NaN, ±0 and infinities: kernel = tape, NaN for NaN."""
    x, y = ca.SX.sym("x"), ca.SX.sym("y")
    exprs = [ca.sin(x), ca.cos(y), ca.tan(x / 10), ca.sqrt(ca.fabs(x)), ca.exp(-x * x),
             ca.log(1 + ca.fabs(y)), ca.atan(x), ca.asin(ca.tanh(x)), ca.acos(ca.tanh(y)),
             ca.atan2(y, x), ca.fmin(x, y), ca.fmax(x, y), ca.sign(y), ca.floor(x), ca.ceil(y),
             x < y, x <= y, x == y, x != y, ca.logic_and(x > 0, y > 0),
             ca.logic_or(x > 0, y > 0), ca.if_else(x > 0, y, 0), x**2, x**3.5, ca.fabs(x) ** y,
             1 / x, -x, 2 * x, ca.hypot(x, y), ca.fmod(x, 3), ca.logic_not(x > 0)]
    fn = ca.Function("f", [x, y], [ca.vertcat(*exprs)])
    values = np.array([0.0, -0.0, 1.5, -2.25, np.nan, np.inf, -np.inf, 1e-300, 7.0])
    xs, ys = (a.ravel() for a in np.meshgrid(values, values))
    with np.errstate(all="ignore"):
        tape = Tape(fn)([xs[None, :], ys[None, :]], xs.size)[0]
    kernel = np.array(Kernel(fn)([xs[None, :], ys[None, :]], xs.size)[0])
    np.testing.assert_array_equal(np.isnan(kernel), np.isnan(tape))
    finite = np.isfinite(tape)
    np.testing.assert_array_equal(kernel[~finite & ~np.isnan(tape)],
                                  tape[~finite & ~np.isnan(tape)])
    assert np.max(np.abs(kernel[finite] - tape[finite]) / (1 + np.abs(tape[finite]))) <= ULPS


def _child(code: str, env: dict[str, str]) -> dict:
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True,
                         env={**os.environ, **env}, check=True, timeout=600).stdout
    return json.loads(out.strip().splitlines()[-1])


_BUILD = """
import json, sys, time
import numpy as np
from balancer.mechanisms import mechanism_of
from balancer.spec import load_design

mech = mechanism_of(load_design(sys.argv[1] if len(sys.argv) > 1 else {spec!r}).mechanism)
program = mech._program(True, (0.0, 0.0))
t = time.perf_counter()
kernel = program.kernel
seconds = time.perf_counter() - t
theta = np.linspace(0, 6, 500)
forces, ok = program.evaluate(theta, 30.0 + 0 * theta, 0 * theta, compiled=True)
print(json.dumps({{"cached": kernel.cached, "seconds": seconds,
                  "sum": float(np.sum(np.asarray(forces.driving_torque)))}}))
"""


def test_a_second_process_loads_the_compiled_kernel_from_the_cache(tmp_path):
    code = _BUILD.format(spec=str(EXAMPLES / "stephenson_sixbar.toml"))
    env = {CACHE_ENV: str(tmp_path / "cache")}
    first = _child(code, env)
    files = list((tmp_path / "cache" / "kernels").glob("kernel_*.py"))
    assert first["cached"] and len(files) == 1
    second = _child(code, env)
    assert second["cached"] and second["sum"] == first["sum"]
    assert second["seconds"] < first["seconds"]  # (loaded, not compiled again)


def test_two_processes_compiling_at_once_and_a_cache_that_cannot_be_written(tmp_path):
    code = _BUILD.format(spec=str(EXAMPLES / "watt_sixbar.toml"))
    env = {CACHE_ENV: str(tmp_path / "shared")}
    runs = [subprocess.Popen([sys.executable, "-c", code], stdout=subprocess.PIPE, text=True,
                             env={**os.environ, **env}) for _ in range(2)]
    results = [json.loads(p.communicate(timeout=600)[0].strip().splitlines()[-1])
               for p in runs]
    assert all(p.returncode == 0 for p in runs)
    assert results[0]["sum"] == results[1]["sum"]
    blocked = tmp_path / "a-file"
    blocked.write_text("not a folder")
    alone = _child(code, {CACHE_ENV: str(blocked)})
    assert not alone["cached"] and alone["sum"] == results[0]["sum"]


def test_kernels_switched_off_leave_the_tape(monkeypatch):
    monkeypatch.setenv(SWITCH_ENV, "0")
    mech = mechanism_of(load_design(EXAMPLES / "pb1.toml").mechanism)
    fn = mech._program(False, (0.0, 0.0)).function
    assert compile_kernel(fn) is None


def test_a_short_analysis_and_help_never_import_numba():
    code = ("import sys, json\n"
            "from balancer.cli import main\n"
            f"main(['analyze', {str(EXAMPLES / 'pb1.toml')!r}, '--json'])\n"
            "print(json.dumps({'numba': 'numba' in sys.modules}))")
    assert _child(code, {}) == {"numba": False}


def test_the_cache_keeps_the_most_recently_used_kernels(cache, monkeypatch):
    """Beyond KEPT kernels the least recently used goes, its numba code with it."""
    import balancer.linkage.kernel as kernel_module

    monkeypatch.setattr(kernel_module, "KEPT", 2)
    x = ca.SX.sym("x")
    names = []
    for k in range(4):  # (each of its own form: a kernel takes its constants as inputs)
        names.append(Kernel(ca.Function(f"f{k}", [x], [ca.sin(x) ** (k + 2.5)])).name)
    folder = cache / "kernels"
    kept = {p.stem for p in folder.glob("kernel_*.py")}
    assert names[-1] in kept and names[0] not in kept and len(kept) <= 3
    assert not list((folder / "__pycache__").glob(f"{names[0]}.*"))
    again = Kernel(ca.Function("f3", [x], [ca.sin(x) ** 5.5]))  # the newest: still there
    assert again.cached and again([np.array([[2.0]])], 1)[0][0][0] == math.sin(2.0) ** 5.5


def test_designs_of_one_topology_share_one_kernel():
    """A kernel takes its design's numbers as inputs: PB1 and PB1 with another coupler and
    frame (a sweep's point) compile one kernel; each still gives its own tape's figures."""
    import tomllib

    from balancer.spec import design_from_dict
    from balancer.sweeps import with_values

    data = tomllib.loads((EXAMPLES / "pb1.toml").read_text())
    other = with_values(data, {"mechanism.lengths.coupler": 3.37,
                               "mechanism.lengths.frame": 2.81})
    programs = [mechanism_of(design_from_dict(d).mechanism)._program(True, (0.0, 0.0))
                for d in (data, other)]
    assert programs[0].kernel.name == programs[1].kernel.name
    assert not np.array_equal(programs[0].kernel.constants, programs[1].kernel.constants)
    theta, omega, alpha = states(2000, seed=11)
    for program in programs:
        by_tape, _ = program.evaluate(theta, omega, alpha)
        by_kernel, _ = program.evaluate(theta, omega, alpha, compiled=True)
        for a, b in zip(by_kernel.arrays(), by_tape.arrays(), strict=True):
            close(np.asarray(a)[:, 0], np.asarray(b)[:, 0])


@pytest.mark.parametrize("name", ("inline_four", "stephenson_sixbar", "quick_return"))
@pytest.mark.parametrize("compiled", (True, False))
def test_forces_written_into_a_cycles_columns_are_the_forces_returned(name, compiled):
    """``crank_forces(into=…)`` into strided views of complex columns (a cycle's), rotors'
    bearings of their own and sliders included: the same figures as returned, bit for bit."""
    from balancer.linkage.dynamics import Forces
    from balancer.linkage.vectors import V

    mech = mechanism_of(load_design(EXAMPLES / f"{name}.toml").mechanism)
    theta, omega, alpha = states(1500, seed=3)
    returned = mech.crank_forces(theta, omega, alpha, compiled=compiled)
    n = theta.size
    columns = {key: np.full(n, np.nan, complex) for key in
               ("force", "couple", *(f"R{p}" for p in frame_points(mech)))}
    reals = {key: np.full(n, np.nan) for key in
             ("torque", "moment", *(f"N{k}" for k in mech.linkage.ground_sliders),
              *(f"C{k}" for k in mech.linkage.ground_sliders))}

    def vector(a):
        return V(a.real[:, None], a.imag[:, None])

    into = Forces(reactions={p: vector(columns[f"R{p}"]) for p in frame_points(mech)},
                  slider_normal={k: reals[f"N{k}"][:, None] for k in mech.linkage.ground_sliders},
                  slider_couple={k: reals[f"C{k}"][:, None] for k in mech.linkage.ground_sliders},
                  input_torques=(reals["torque"][:, None],), shaking_force=vector(columns["force"]),
                  shaking_moment=reals["moment"][:, None], rocking_couple=vector(columns["couple"]))
    written = mech.crank_forces(theta, omega, alpha, compiled=compiled, into=into)
    assert written is into
    for a, b in zip(into.arrays(), returned.matching(into).arrays(), strict=True):
        np.testing.assert_array_equal(np.asarray(a)[:, 0], np.broadcast_to(b, (n, 1))[:, 0])


def test_no_states_and_wrong_sizes():
    """No states: empty outputs from both routes; arrays of the wrong size: refused (the
    compiled loop does not check its indices)."""
    x, y = ca.SX.sym("x"), ca.SX.sym("y")
    fn = ca.Function("g", [x, y], [ca.vertcat(ca.sin(x) * y, x + 2.0)])
    tape = Tape(fn)([np.zeros((1, 0)), np.zeros((1, 0))], 0)[0]
    rows, ok = Kernel(fn)([np.zeros((1, 0)), np.zeros((1, 0))], 0)
    assert tape.shape == (2, 0) and [r.shape for r in rows] == [(0,), (0,)] and ok.size == 0
    kernel = Kernel(fn)
    with pytest.raises(ValueError, match="outputs"):
        kernel([np.ones((1, 5)), np.ones((1, 5))], 5, [np.empty(5), np.empty(4)])
    with pytest.raises(ValueError, match="inputs"):
        kernel([np.ones((1, 5)), np.ones((2, 5))], 5)
    with pytest.raises(ValueError, match="inputs"):
        kernel([np.ones((1, 5)), np.ones((1, 3))], 5)


def test_a_change_point_four_bar_compiled_is_its_closed_forms(monkeypatch):
    """PB1 with a 2 m frame (a change point at θ1 = 0, sampled): the compiled cycle — the
    states near the toggle and the change point's limit by the closed forms, the rest by the
    kernel — equals the numpy route's to 1e-10 of each column's largest value. (The general
    core loses digits as a toggle nears: 2e-6 of the closed forms' at a gap of 1e-6.)"""
    import tomllib

    import balancer.cycle as cycle_module
    from balancer.spec import design_from_dict
    from balancer.sweeps import with_values

    data = tomllib.loads((EXAMPLES / "pb1.toml").read_text())
    mech = mechanism_of(design_from_dict(
        with_values(data, {"mechanism.lengths.frame": 2.0})).mechanism)
    assert mech.change_points()
    numpy_route = cycle_analysis(mech, 10.0, 600)
    monkeypatch.setattr(cycle_module, "KERNEL_STATES", 512)
    monkeypatch.setattr(cycle_module, "CHUNK", 300)
    compiled = cycle_analysis(mech, 10.0, 600)
    assert numpy_route.singular.any()
    a, b = compiled.reactions, numpy_route.reactions
    for got, want in ((a.shaking_force, b.shaking_force), (a.shaking_moment, b.shaking_moment),
                      (a.driving_torque, b.driving_torque), (a.ground["A0"], b.ground["A0"])):
        np.testing.assert_array_equal(np.isnan(got), np.isnan(want))
        assert np.nanmax(np.abs(got - want)) <= 1e-10 * np.nanmax(np.abs(want))
