"""Benchmark: whole commands against their anchors (issue 13), one table from one run.

Run on its own: ``python benchmarks/bench_commands.py [--repeats N] [--markdown]
[--no-memory]``. Whole-process rows run the venv's ``balancer`` entry point (and each anchor
script) as a subprocess: one warm-up, then the median wall time of ``--repeats`` runs (5).
In-process rows run in this process after a warm-up, median of the same number of runs.
``ratio`` is always ours ÷ the anchor's (lower is better). An anchor that cannot run (Exudyn not
installed, no C compiler) gives a row that says so. The subprocesses cache their bytecode in a
temporary ``PYTHONPYCACHEPREFIX`` (written by the warm-up), as an installed package has it,
even where ``PYTHONDONTWRITEBYTECODE`` is set (that would recompile balancer's modules on every
run: 0.1–0.2 s a command); ``--no-pyc`` keeps the environment as it is.

Every table is printed under the machine it ran on (:func:`tables.print_machine`: processor,
numpy's SIMD level, the BLAS core, …). Goals are ratios to an anchor measured in the same run,
so that they carry from machine to machine: whole commands without an anchor of their own are
measured against ``python -c "import numpy"`` (the least a Python tool with numpy costs to
start, :data:`STARTUP_ANCHOR`, run alternately with each command: the ratio is the median of
the pairs'), their issues' goals in seconds converted once into ratios on the machine they were
set for (:data:`STARTUP_REFERENCE`); a goal that has no anchor says so in its row.

Rows and their anchors:

``python -c "import numpy"``
    The start-up anchor of the whole-command rows below that have no other.
``optimize pb1``
    ``balancer optimize examples/pb1.toml``, verification included, against
    ``anchors/de_pb1.py`` (one-seed SciPy differential evolution of PB1 with exact force
    balance by elimination, also a whole process). Goal ≥ 3× faster than DE (ratio ≤ 0.33;
    the issue's 1.0 s is shown, not judged).
``optimize watt_sixbar``
    Against the start-up anchor: the issue's ≤ 1.5 s as a ratio.
``verify``
    ``balancer verify`` of PB2's balanced design, written first by ``balancer optimize
    examples/pb2.toml --out balanced.toml`` as in the README. Against the start-up anchor:
    the issue's ≤ 1.0 s as a ratio.
``simulate meijaard2020``
    The paper's example (free from rest at θ1 = 1 rad, 5 s) against
    ``anchors/exudyn_meijaard.py`` (Exudyn: rigid bodies and revolute joints, generalized-α at a
    fixed step). The final states of both are compared with balancer's at rtol 1e-13: the
    default command's row shows both errors; the "equal accuracy" row runs balancer at the
    loosest ``--rtol`` whose error is no larger than Exudyn's. Goal ratio ≤ 0.5.
``analyze <example>``
    Every shipped example, against the start-up anchor: the issue's ≤ 0.3 s each as a ratio;
    the paper's four-bar also within 1.6× the anchor (issue 41's goal, a ratio itself).
    ``--help``: ≤ 0.1 s as a ratio. Each shipped engine's ``search`` ≤ 0.3 s; the in-line
    four's counterweights for its main bearings (``optimize inline_four_mains.toml``, a cone
    per bearing and sample) ≤ 1.5 s (issue 44).
``re-solve PB1``
    In process: PB1's certified convex optimum re-solved after its bounds change, through the
    bounds-only API: ``Optimizer.of(design)`` is built once; each re-solve is
    ``optimizer.with_problem(problem).convex.solve()`` (the problem's bounds resolved, the
    conic programs assembled with the new data, the SOCP, tie-break, repairs and certified
    lower bound). The rows below it give ``ConvexSolver.solve()`` alone with unchanged bounds,
    the whole ``optimizer.with_problem(problem).run("convex")`` (its status, the balanced
    design's cycle analysis), and the public ``balancer.optimize(design, backend="convex")``,
    which builds everything. Goal ≤ 3 ms, absolute: it has no anchor (the row says so); and
    the solve's time independent of the number of samples (the same solve at 100 times PB1's
    samples, within 1.5× — the noise of one run: a ratio within the run).
``cycle 10^6``
    In process: ``cycle_analysis`` of the paper's four-bar at 10⁶ angles against
    ``anchors/floor_fourbar.c``, the same arithmetic (Eq. 2–10, Newton–Euler per link, reactions,
    shaking force and moment, driving torque) in a plain C loop on one thread, compiled with
    ``cc -O2`` into a temporary directory; its results are checked against balancer's at every
    angle. Goal ≤ 0.6× the floor (issue 32: two cores make 0.5 the limit; the issue's 0.1 s
    is shown, not judged); the
    Watt six-bar ≤ 1.2×, the Stephenson six-bar ≤ 2.5× and an in-line six engine (the in-line
    three's cylinders twice, mirrored) ≤ 3× that same four-bar floor. Memory: the peak of what
    a fresh process allocates during the call (tracemalloc, which sees NumPy's arrays) for 10⁶
    and 10⁷ angles, less the result arrays themselves; flat means that working memory does not
    grow with the number of angles (its growth per extra angle below 1 byte; the results take
    73). The note adds the peak resident set's growth where Linux reports it.
"""

from __future__ import annotations

import argparse
import dataclasses
import json
import math
import os
import shutil
import statistics
import subprocess
import sys
import tempfile
import time
from collections.abc import Callable
from pathlib import Path

import tables

ROOT = Path(__file__).resolve().parent.parent
EXAMPLES = ROOT / "balancer" / "examples"
ANCHORS = Path(__file__).resolve().parent / "anchors"
#: balancer's simulate tolerances tried for the equal-accuracy row, loosest first.
RTOLS = (1e-4, 1e-5, 1e-6, 1e-7, 1e-8, 1e-9, 1e-10)
TIMEOUT = 600
#: Environment of the subprocesses (set by :func:`main`): bytecode cached, as for a user.
ENV: dict[str, str] | None = None
#: The whole-command rows' anchor: a Python process that imports numpy, and nothing else.
STARTUP_ANCHOR = [sys.executable, "-c", "import numpy"]
#: ``python -c "import numpy"`` (median of 5 after a warm-up, bytecode cached) on the machine
#: where the absolute goals of the whole-command rows were turned into ratios: the 2-core
#: Intel Xeon (AVX-512, numpy X86_V4, OpenBLAS SkylakeX) of 2026-11-29, s.
STARTUP_REFERENCE = 0.10
#: Measured by :func:`main` before the rows: the start-up anchor in this run, s (``None``: it
#: could not run).
STARTUP: float | None = None


@dataclasses.dataclass
class Row:
    """One line of the table."""

    goal: str
    measured: str = "—"
    anchor: str = "—"
    ratio: str = "—"
    target: str = ""
    met: str = "—"
    note: str = ""


class Failed(RuntimeError):
    """A command or an anchor that did not run; the message goes into the row."""


def balancer_command() -> list[str]:
    """The venv's ``balancer`` entry point (beside this Python), else ``python -m balancer``."""
    exe = Path(sys.executable).with_name("balancer")
    if exe.exists():
        return [str(exe)]
    found = shutil.which("balancer")
    return [found] if found else [sys.executable, "-m", "balancer"]


def run(cmd: list[str], *, check: bool = True) -> subprocess.CompletedProcess:
    """Run a command quietly; :class:`Failed` with its last line of stderr if it fails."""
    try:
        out = subprocess.run(cmd, capture_output=True, text=True, timeout=TIMEOUT, cwd=ROOT,
                             env=ENV)
    except (OSError, subprocess.TimeoutExpired) as exc:
        raise Failed(str(exc)) from exc
    if check and out.returncode != 0:
        last = (out.stderr.strip().splitlines() or [f"exit code {out.returncode}"])[-1]
        raise Failed(f"exit {out.returncode}: {last[:120]}")
    return out


def wall(cmd: list[str], repeats: int) -> float:
    """Median wall time of a whole process, s (one warm-up run first)."""
    run(cmd)
    times = []
    for _ in range(repeats):
        start = time.perf_counter()
        run(cmd)
        times.append(time.perf_counter() - start)
    return statistics.median(times)


def in_process(fn: Callable[[int], object], repeats: int) -> float:
    """Median time of ``fn(i)`` in this process, s (``fn(0)`` once first as a warm-up)."""
    fn(0)
    times = []
    for i in range(repeats):
        start = time.perf_counter()
        fn(i + 1)
        times.append(time.perf_counter() - start)
    return statistics.median(times)


def sec(x: float) -> str:
    return f"{x:.3f} s"


def msec(x: float) -> str:
    return f"{x * 1e3:.2f} ms"


def yes(ok: bool) -> str:
    return "yes" if ok else "NO"


def against_startup(goal: str, cmd: list[str], repeats: int, limit: float,
                    ratio_goal: float | None = None) -> Row:
    """A whole command's row judged against the start-up anchor, run alternately with it.

    One warm-up of each, then ``repeats`` pairs (the anchor, then the command): the ratio is
    the median of the pairs' ratios, so that a machine whose load changes during the run
    (another process taking a core for a while) moves both alike. ``limit`` is the issue's goal
    in seconds; it becomes the ratio ``limit /`` :data:`STARTUP_REFERENCE`, unless the issue
    set a ratio itself (``ratio_goal``). Without the anchor the row is judged on ``limit`` and
    says so.
    """
    target = limit / STARTUP_REFERENCE if ratio_goal is None else ratio_goal
    if STARTUP is None:
        seconds = wall(cmd, repeats)
        return Row(goal, measured=sec(seconds), anchor="start-up anchor failed",
                   target=f"≤ {limit:g} s (absolute: no anchor)", met=yes(seconds <= limit))
    run(STARTUP_ANCHOR)
    run(cmd)
    ours, anchor = [], []
    for _ in range(repeats):
        for times, what in ((anchor, STARTUP_ANCHOR), (ours, cmd)):
            start = time.perf_counter()
            run(what)
            times.append(time.perf_counter() - start)
    ratio = statistics.median(a / b for a, b in zip(ours, anchor, strict=True))
    return Row(goal, measured=sec(statistics.median(ours)),
               anchor=f"{sec(statistics.median(anchor))} (import numpy, alternated)",
               ratio=f"{ratio:.2f}", target=(f"ratio ≤ {target:.2f} (≤ {limit:g} s)"
                                             if ratio_goal is None else f"ratio ≤ {target:.2f}"),
               met=yes(ratio <= target))


def guarded(goal: str, target: str, body: Callable[[], list[Row]]) -> list[Row]:
    """The rows of ``body``; a row saying what failed instead of a crash."""
    try:
        return body()
    except Exception as exc:  # a benchmark row reports a failure, never crashes
        return [Row(goal, measured=f"failed: {type(exc).__name__}: {exc}"[:100], target=target)]


# -- 1. optimize --------------------------------------------------------------------------------


def optimize_rows(repeats: int) -> list[Row]:
    bal = balancer_command()
    target = "ratio ≤ 0.33 (1.0 s: info)"

    def pb1() -> list[Row]:
        ours = wall([*bal, "optimize", "examples/pb1.toml"], repeats)
        row = Row("optimize pb1.toml (whole process, verification included)",
                  measured=sec(ours), target=target)
        try:
            de = wall([sys.executable, str(ANCHORS / "de_pb1.py")], repeats)
            found = json.loads(run([sys.executable, str(ANCHORS / "de_pb1.py"),
                                    "--json"]).stdout)
        except Failed as exc:
            row.anchor = f"DE unavailable: {exc}"[:60]
            row.target = "≤ 1.0 s (absolute: no anchor)"
            row.met = yes(ours <= 1.0)
            return [row]
        row.anchor = f"{sec(de)} (DE script)"
        row.ratio = f"{ours / de:.2f}"
        row.met = yes(ours / de <= 1 / 3)
        row.note = (f"DE finds RMS {found['rms_shaking_moment']:.6g} N·m, "
                    f"{found['generations']} generations")
        return [row]

    def watt() -> list[Row]:
        return [against_startup("optimize watt_sixbar.toml (whole process)",
                                [*bal, "optimize", "examples/watt_sixbar.toml"], repeats, 1.5)]

    return (guarded("optimize pb1.toml", target, pb1)
            + guarded("optimize watt_sixbar.toml", "≤ 1.5 s", watt))


# -- 2. verify ----------------------------------------------------------------------------------


def verify_rows(repeats: int, tmp: Path) -> list[Row]:
    bal = balancer_command()

    def body() -> list[Row]:
        balanced = tmp / "balanced.toml"
        run([*bal, "optimize", "examples/pb2.toml", "--out", str(balanced), "--force"])
        return [against_startup("verify balanced.toml (PB2 optimised, as in the README)",
                                [*bal, "verify", str(balanced)], repeats, 1.0)]

    return guarded("verify balanced.toml", "≤ 1.0 s", body)


# -- 3. simulate against Exudyn -----------------------------------------------------------------


def final_state(doc: dict) -> list[float]:
    f = doc["final"]
    return [*f["theta"], *f["omega"], *f["alpha"]]


def state_error(a: list[float], b: list[float]) -> float:
    return max(abs(x - y) for x, y in zip(a, b, strict=True))


def simulate_rows(repeats: int) -> list[Row]:
    bal = balancer_command()
    spec = "examples/meijaard2020.toml"
    target = "ratio ≤ 0.5"
    anchor = [sys.executable, str(ANCHORS / "exudyn_meijaard.py"), spec]

    def body() -> list[Row]:
        ref = final_state(json.loads(run([*bal, "simulate", spec, "--rtol", "1e-13", "--atol",
                                          "1e-15", "--json"]).stdout))
        default = json.loads(run([*bal, "simulate", spec, "--json"]).stdout)
        err_default = state_error(final_state(default), ref)
        ours = wall([*bal, "simulate", spec], repeats)
        row = Row(f"simulate meijaard2020.toml (default rtol {default['rtol']:g})",
                  measured=sec(ours), target=target)
        probe = run([sys.executable, "-c", "import exudyn"], check=False)
        if probe.returncode != 0:
            row.anchor = "anchor unavailable: pip install 'balancer[bench]' (exudyn)"
            row.note = f"final-state error {err_default:.1e}"
            return [row]
        try:
            ex = json.loads(run([*anchor, "--json"]).stdout)
            exudyn_time = wall(anchor, repeats)
        except (Failed, ValueError) as exc:
            row.anchor = f"anchor unavailable: {exc}"[:60]
            return [row]
        err_exudyn = state_error([*ex["theta"], *ex["omega"], *ex["alpha"]], ref)
        row.anchor = f"{sec(exudyn_time)} (Exudyn, {ex['steps']} steps)"
        row.ratio = f"{ours / exudyn_time:.2f}"
        row.met = yes(ours / exudyn_time <= 0.5)
        row.note = f"final-state error: ours {err_default:.1e}, Exudyn {err_exudyn:.1e}"
        rows = [row]
        # Equal accuracy: the loosest tolerance at least as accurate as Exudyn.
        for rtol in RTOLS:
            args = ["--rtol", f"{rtol:g}", "--atol", f"{rtol * 1e-2:g}"]
            doc = json.loads(run([*bal, "simulate", spec, *args, "--json"]).stdout)
            err = state_error(final_state(doc), ref)
            if err <= err_exudyn:
                t = wall([*bal, "simulate", spec, *args], repeats)
                rows.append(Row(f"simulate meijaard2020.toml, equal accuracy (--rtol {rtol:g})",
                                measured=sec(t), anchor=row.anchor,
                                ratio=f"{t / exudyn_time:.2f}", target=target,
                                met=yes(t / exudyn_time <= 0.5),
                                note=f"final-state error: ours {err:.1e}, Exudyn "
                                     f"{err_exudyn:.1e}"))
                break
        return rows

    return guarded("simulate meijaard2020.toml", target, body)


# -- 4. analyze, --help -------------------------------------------------------------------------


def analyze_rows(repeats: int) -> list[Row]:
    bal = balancer_command()
    rows = []
    for spec in sorted(EXAMPLES.glob("*.toml")):
        # A linkage with several inputs is analysed along its motions (inverse kinematics,
        # every motion's samples) and over its workspace's grid: its own budget.
        limit = 1.0 if "\ninputs = [" in spec.read_text() else 0.3

        def body(spec=spec, limit=limit) -> list[Row]:
            return [against_startup(f"analyze {spec.name}",
                                    [*bal, "analyze", f"examples/{spec.name}"], repeats, limit)]
        rows += guarded(f"analyze {spec.name}", f"≤ {limit:g} s", body)

    for spec in sorted(EXAMPLES.glob("*.toml")):
        if "\ninputs = [" not in spec.read_text():
            continue
        # A linkage with several inputs simulated along its first motion (two formulations'
        # check in verify, every motion and a free run): issue 42's verbs, their own budgets.
        for verb, limit in (("simulate", 1.0), ("verify", 1.5)):
            def along(spec=spec, verb=verb, limit=limit) -> list[Row]:
                return [against_startup(f"{verb} {spec.name}",
                                        [*bal, verb, f"examples/{spec.name}"], repeats, limit)]
            rows += guarded(f"{verb} {spec.name}", f"≤ {limit:g} s", along)

    for spec in sorted(EXAMPLES.glob("*.toml")):
        text = spec.read_text()
        if "\n[plan]" not in text:
            continue
        # A motion's time law planned (issue 43): the transcription on its mesh and on half
        # of it, IPOPT from one or two starts, the analyses before and after; with the masses,
        # the balancing and the plan in turn until neither improves.
        verbs = [("plan", [], 1.5)]
        if "\n[balance]" in text:
            verbs.append(("plan --with-masses", ["--with-masses"], 2.5))
        for verb, flags, limit in verbs:
            def planned(spec=spec, verb=verb, flags=flags, limit=limit) -> list[Row]:
                return [against_startup(f"{verb} {spec.name}",
                                        [*bal, "plan", f"examples/{spec.name}", *flags],
                                        repeats, limit)]
            rows += guarded(f"{verb} {spec.name}", f"≤ {limit:g} s", planned)

    for spec in sorted(EXAMPLES.glob("*.toml")):
        text = spec.read_text()
        if 'type = "engine"' not in text or "[[crankshafts]]" in text:
            continue  # (a search arranges one crankshaft's pins: geared ones are refused)
        # An engine's cranks and firing orders searched (issue 44): every even-firing crank
        # judged from its cylinders' phasors.
        def searched(spec=spec) -> list[Row]:
            return [against_startup(f"search {spec.name}",
                                    [*bal, "search", f"examples/{spec.name}"], repeats, 0.3)]
        rows += guarded(f"search {spec.name}", "≤ 0.3 s", searched)

    def mains() -> list[Row]:  # issue 44: a bound on the main bearings, a cone per sample
        return [against_startup("optimize inline_four_mains.toml (whole process, no verify)",
                                [*bal, "optimize", "examples/inline_four_mains.toml",
                                 "--no-verify"], repeats, 1.5)]
    rows += guarded("optimize inline_four_mains.toml", "≤ 1.5 s", mains)

    def paper() -> list[Row]:  # issue 41: the paper's four-bar within 1.6× of numpy's start-up
        return [against_startup("analyze meijaard2020.toml (issue 41)",
                                [*bal, "analyze", "examples/meijaard2020.toml"], repeats, 0.3,
                                ratio_goal=1.6)]

    def helps() -> list[Row]:
        return [against_startup("balancer --help", [*bal, "--help"], repeats, 0.1)]

    return (rows + guarded("analyze meijaard2020.toml (issue 41)", "ratio ≤ 1.6", paper)
            + guarded("balancer --help", "≤ 0.1 s", helps))


# -- 5. re-solve with new bounds (in process) ---------------------------------------------------


def resolve_rows(repeats: int) -> list[Row]:
    target = "≤ 3 ms (absolute: no anchor)"

    def body() -> list[Row]:
        import balancer
        from balancer.balance.optimizer import Optimizer
        from balancer.spec import load_design

        design = load_design(EXAMPLES / "pb1.toml")

        def with_bounds(k: int):
            """PB1's problem with the masses' upper bound and the counter-rotors' range changed."""
            top = (4.0, 3.0, 2.5, 3.5)[k % 4]
            rotor = (20.0, 5.0, 10.0, 15.0)[k % 4]
            problem = design.balance
            for name, f in design.balance.links:
                problem = problem.with_link(name, dataclasses.replace(
                    f, mass=(f.mass[0], top * f.mass[0]), counter_rotor=(0.0, rotor)))
            return problem

        problems = [with_bounds(k) for k in range(4)]
        optimizer = Optimizer.of(design)

        def resolve(i: int):
            return optimizer.with_problem(problems[i % 4]).convex.solve()

        # The re-solve must give what a build from the spec gives.
        for k in range(4):
            a = resolve(k).objective
            b = balancer.optimize(dataclasses.replace(design, balance=problems[k]),
                                  backend="convex").objective
            if not math.isclose(a, b, rel_tol=1e-9):
                raise Failed(f"re-solve {a} differs from a full build {b}")
        t_resolve = in_process(resolve, repeats * 4)
        solver = optimizer.convex
        t_solve = in_process(lambda i: solver.solve(), repeats * 4)
        t_run = in_process(lambda i: optimizer.with_problem(problems[i % 4]).run("convex"),
                           repeats * 4)
        # Independent of the number of samples beyond the one-time reduction.
        many = dataclasses.replace(design, operation=dataclasses.replace(
            design.operation, samples=100 * design.operation.samples))
        many_solver = Optimizer.of(many).convex
        t_many = in_process(lambda i: many_solver.solve(), repeats * 4)
        variants = [dataclasses.replace(design, balance=p) for p in problems]
        t_api = in_process(lambda i: balancer.optimize(variants[i % 4], backend="convex"),
                           repeats * 2)
        return [
            Row("PB1 re-solved with new bounds (in process)", measured=msec(t_resolve),
                target=target, met=yes(t_resolve <= 3e-3),
                note="optimizer.with_problem(problem).convex.solve(): certified optimum"),
            Row("  ConvexSolver.solve(), bounds unchanged", measured=msec(t_solve),
                target="(≤ 3 ms, absolute: info)", met=f"({yes(t_solve <= 3e-3)})",
                note="SOCP + tie-break + certificate on a built solver"),
            Row(f"  ConvexSolver.solve(), {100 * design.operation.samples} samples",
                measured=msec(t_many), target="ratio to the row above ≤ 1.5",
                met=yes(t_many <= 1.5 * t_solve),
                note=f"{t_many / t_solve:.2f}× the time at {design.operation.samples} samples"),
            Row('  optimizer.with_problem(problem).run("convex"), new bounds',
                measured=msec(t_run), target="(info)",
                note="the whole result: status, balanced design's cycle analysis"),
            Row('  balancer.optimize(design, backend="convex"), new bounds',
                measured=msec(t_api), target="(info)",
                note="public API: builds regressors, programs, before/after analyses"),
        ]

    return guarded("PB1 re-solved with new bounds", target, body)


# -- 6. cycle analysis against a compiled floor -------------------------------------------------


def compiler() -> str | None:
    for name in (os.environ.get("CC"), "cc", "gcc", "clang"):
        if name and shutil.which(name):
            return shutil.which(name)
    return None


def floor_arguments(design) -> list[str]:
    """The floor's 29 numbers: lengths, branch, speed, per link m I e f Fx Fy M, Jc1 Jc3."""
    mech = design.mechanism
    args = [*mech.lengths, 1.0 if mech.branch == "+" else -1.0, design.operation.speed]
    for link in (mech.crank, mech.coupler, mech.rocker):
        args += [link.mass, link.inertia, link.e, link.f, *link.force, link.moment]
    args += [mech.crank.counter_rotor, mech.rocker.counter_rotor]
    return [repr(float(a)) for a in args]


_MEMORY = """
import json, sys, tracemalloc
from pathlib import Path
from balancer.cycle import cycle_analysis
from balancer.spec import load_design

def status(key):  # kB from /proc/self/status (Linux), else None
    try:
        for line in Path("/proc/self/status").read_text().splitlines():
            if line.startswith(key + ":"):
                return int(line.split()[1]) * 1024
    except OSError:
        return None

design = load_design(sys.argv[1])
n = int(sys.argv[2])
try:  # reset the peak resident set size (Linux: VmHWM := VmRSS)
    Path("/proc/self/clear_refs").write_text("5")
    rss0 = status("VmRSS")
except OSError:
    rss0 = None
tracemalloc.start()
ca = cycle_analysis(design.mechanism, design.operation.speed, n)
current, peak = tracemalloc.get_traced_memory()
tracemalloc.stop()
hwm = status("VmHWM")
r = ca.reactions
arrays = [ca.theta1, r.shaking_force, r.shaking_moment, r.driving_torque, r.rocking_couple,
          *r.ground.values(),
          *r.slider_normal.values(), *r.slider_couple.values()]
if ca.singular is not None:
    arrays.append(ca.singular)
print(json.dumps({"peak": peak, "kept": current, "results": sum(a.nbytes for a in arrays),
                  "rss": None if rss0 is None or hwm is None else hwm - rss0}))
"""


def inline_six():
    """An in-line six: the in-line three's cylinders and crank, twice, mirrored (throws at
    0°, 240°, 120°, 120°, 240°, 0° along the crank)."""
    from dataclasses import replace

    from balancer.spec import load_design

    engine = load_design(EXAMPLES / "inline_three.toml").mechanism
    first = engine.cylinders[0]
    pitch = engine.cylinders[1].z - first.z
    phases = (0.0, 240.0, 120.0, 120.0, 240.0, 0.0)
    cylinders = tuple(replace(first, z=(k - 2.5) * pitch, phase_deg=phase)
                      for k, phase in enumerate(phases))
    return replace(engine, cylinders=cylinders, firing_order=None, gas=None)


#: The issue's goals for other mechanisms, as multiples of the four-bar's floor.
CYCLE_GOALS = (("Watt six-bar", "watt_sixbar", 1.2), ("Stephenson six-bar",
                                                      "stephenson_sixbar", 2.5),
               ("in-line six engine", None, 3.0))


def cycle_rows(repeats: int, tmp: Path, memory: bool) -> list[Row]:
    n = 10**6
    target = "ratio ≤ 0.6 (0.1 s: info)"
    spec = EXAMPLES / "meijaard2020.toml"

    def body() -> list[Row]:
        import numpy as np

        from balancer.cycle import cycle_analysis
        from balancer.spec import load_design

        design = load_design(spec)
        speed = design.operation.speed
        ours = in_process(lambda i: cycle_analysis(design.mechanism, speed, n), repeats)
        row = Row("cycle analysis, 10^6 angles, four-bar (in process)", measured=sec(ours),
                  target=target)
        cc = compiler()
        if cc is None:
            row.anchor = "no C compiler: floor skipped"
            row.target = "≤ 0.1 s (absolute: no anchor)"
            row.met = yes(ours <= 0.1)
            return [row]
        exe = tmp / "floor_fourbar"
        run([cc, "-O2", "-o", str(exe), str(ANCHORS / "floor_fourbar.c"), "-lm"])
        args = floor_arguments(design)
        out_file = tmp / "floor.bin"
        run([str(exe), str(n), str(out_file), *args])  # warm-up, and the results to check
        times = [float(run([str(exe), str(n), "-", *args]).stdout.split()[0])
                 for _ in range(repeats)]
        floor = statistics.median(times)
        got = np.fromfile(out_file).reshape(n, 8)
        r = cycle_analysis(design.mechanism, speed, n).reactions
        a0, a3 = r.ground["A0"], r.ground["A3"]
        ref = np.column_stack([a0.real, a0.imag, a3.real, a3.imag, r.shaking_force.real,
                               r.shaking_force.imag, r.shaking_moment, r.driving_torque])
        rel = max(float(np.max(np.abs(got[:, k] - ref[:, k])) / np.max(np.abs(ref[:, k])))
                  for k in range(8))
        row.anchor = f"{sec(floor)} (C floor, cc -O2)"
        row.ratio = f"{ours / floor:.2f}"
        row.met = yes(ours / floor <= 0.6)
        threads = getattr(sys.modules.get("balancer.cycle"), "WORKERS", "?")
        row.note = (f"floor agrees to {rel:.1e} (max rel.); floor 1 thread, "
                    f"balancer {threads}, compiled program")
        if rel > 1e-10:
            row.note = f"FLOOR DISAGREES: {rel:.1e}; " + row.note
        rows = [row]
        for words, name, goal in CYCLE_GOALS:
            mech = inline_six() if name is None else load_design(
                EXAMPLES / f"{name}.toml").mechanism
            theirs = in_process(lambda i, m=mech: cycle_analysis(m, speed, n), repeats)
            rows.append(Row(f"  {words}, 10^6 angles (in process)", measured=sec(theirs),
                            anchor=f"{sec(floor)} (the four-bar's C floor)",
                            ratio=f"{theirs / floor:.2f}", target=f"ratio ≤ {goal}",
                            met=yes(theirs / floor <= goal)))
        return rows

    rows = guarded("cycle analysis, 10^6 angles", target, body)
    if memory:
        def mem() -> list[Row]:
            doc = {k: json.loads(run([sys.executable, "-c", _MEMORY, str(spec),
                                      str(10**k)]).stdout) for k in (6, 7)}
            work = {k: d["peak"] - d["results"] for k, d in doc.items()}
            mb = 1 / 2**20
            per_angle = (work[7] - work[6]) / (10**7 - 10**6)  # bytes per extra angle
            flat = per_angle < 1.0  # the results alone take 73 bytes per angle
            note = (f"tracemalloc peak {doc[6]['peak'] * mb:.0f} → {doc[7]['peak'] * mb:.0f} MB"
                    f" of which results {doc[6]['results'] * mb:.0f} → "
                    f"{doc[7]['results'] * mb:.0f} MB")
            if doc[6]["rss"] is not None:
                note += (f"; peak RSS growth {doc[6]['rss'] * mb:.0f} → "
                         f"{doc[7]['rss'] * mb:.0f} MB")
            return [Row("  cycle working memory beyond its results, 10^6 → 10^7 angles",
                        measured=(f"{work[6] * mb:.0f} → {work[7] * mb:.0f} MB, "
                                  f"{per_angle:+.1f} B/angle"),
                        target="flat: < 1 B/angle",
                        met=yes(flat), note=note)]
        rows += guarded("cycle memory", "flat: < 1 B/angle", mem)
    return rows


# -- the table ----------------------------------------------------------------------------------


HEADER = ("goal", "measured", "anchor", "ratio", "target", "met", "note")


def cells(row: Row) -> tuple[str, ...]:
    return (row.goal, row.measured, row.anchor, row.ratio, row.target, row.met, row.note)


def print_table(rows: list[Row], markdown: bool) -> None:
    tables.print_table(HEADER, [cells(r) for r in rows], markdown=markdown)


def load() -> str:
    """The load average (1, 5, 15 minutes), or ``?`` where the system does not say."""
    average = " ".join(f"{x:.2f}" for x in os.getloadavg()) if hasattr(os, "getloadavg") else "?"
    return f"load average {average}"


def startup_row(repeats: int) -> list[Row]:
    """The start-up anchor, measured now (sets :data:`STARTUP`)."""
    global STARTUP

    def body() -> list[Row]:
        global STARTUP
        STARTUP = wall(STARTUP_ANCHOR, repeats)
        return [Row('python -c "import numpy" (anchor of the whole-command rows)',
                    measured=sec(STARTUP), target="(anchor)",
                    note=f"{sec(STARTUP_REFERENCE)} on the machine the goals were converted "
                         "on")]

    STARTUP = None
    return guarded('python -c "import numpy"', "(anchor)", body)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--repeats", type=int, default=5, help="timed runs per row (median)")
    parser.add_argument("--markdown", action="store_true", help="print the table as Markdown")
    parser.add_argument("--no-pyc", action="store_true",
                        help="run the subprocesses in this environment as it is (by default "
                             "their bytecode is cached in a temporary PYTHONPYCACHEPREFIX, "
                             "as an installed package's is, even under "
                             "PYTHONDONTWRITEBYTECODE)")
    parser.add_argument("--no-memory", action="store_true",
                        help="skip the 10^6 vs 10^7 memory row (a 10^7 cycle in a fresh "
                             "process)")
    args = parser.parse_args()
    tables.print_machine(markdown=args.markdown)
    print(load(), flush=True)
    print(f"balancer: {' '.join(balancer_command())}; whole processes: median of "
          f"{args.repeats} after 1 warm-up; ratio = ours / anchor", flush=True)
    start = time.perf_counter()
    with tempfile.TemporaryDirectory(prefix="bench_commands_") as tmp_name:
        tmp = Path(tmp_name)
        global ENV
        if not args.no_pyc:
            ENV = {k: v for k, v in os.environ.items() if k != "PYTHONDONTWRITEBYTECODE"}
            ENV["PYTHONPYCACHEPREFIX"] = str(tmp / "pycache")
            print("subprocesses: bytecode cached in a temporary PYTHONPYCACHEPREFIX (written by "
                  "the warm-up runs)", flush=True)
        else:
            print("subprocesses: environment as it is (PYTHONDONTWRITEBYTECODE="
                  f"{os.environ.get('PYTHONDONTWRITEBYTECODE', 'unset')})", flush=True)
        rows = startup_row(args.repeats)
        for make in (lambda: optimize_rows(args.repeats),
                     lambda: verify_rows(args.repeats, tmp),
                     lambda: simulate_rows(args.repeats),
                     lambda: analyze_rows(args.repeats),
                     lambda: resolve_rows(args.repeats),
                     lambda: cycle_rows(args.repeats, tmp, not args.no_memory)):
            new = make()
            rows += new
            for row in new:
                print(f"  {row.goal}: {row.measured}", file=sys.stderr, flush=True)
    print()
    print_table(rows, args.markdown)
    print()
    counted = [r for r in rows if r.met.startswith(("yes", "NO"))]
    print(f"{sum(r.met.startswith('yes') for r in counted)} of {len(counted)} goals met; "
          f"{time.perf_counter() - start:.0f} s; "
          f"{load()} at the end")


if __name__ == "__main__":
    main()
