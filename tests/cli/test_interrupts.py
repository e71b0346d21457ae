"""Ctrl-C: a SIGINT at any moment ends a command with exit code 130 and one line on stderr.

Each test runs the command in a child process and sends it a real SIGINT once it is at work
(it has used a second of CPU, or written a sweep's first part); nothing here measures time.
"""

from __future__ import annotations

import os
import re
import signal
import subprocess
import sys
from pathlib import Path

import pyarrow.parquet as pq
import pytest

ROOT = Path(__file__).resolve().parents[2]
EXAMPLES = ROOT / "examples"
PB1 = EXAMPLES / "pb1.toml"

#: Of the full suite, not of the fast lane (`pytest -m "not slow"`).
pytestmark = [pytest.mark.slow,
              pytest.mark.skipif(not Path("/proc/self/stat").exists(),
                                 reason="reads the child's CPU time from /proc")]


def _env() -> dict[str, str]:
    return {**os.environ, "PYTHONPATH": os.pathsep.join(
        p for p in (str(ROOT), os.environ.get("PYTHONPATH", "")) if p)}


def _stat(pid: int) -> list[str]:
    """The fields of /proc/PID/stat after the command's name (state, ppid, pgrp, …)."""
    return Path(f"/proc/{pid}/stat").read_text().rsplit(")", 1)[1].split()


def _cpu_seconds(pid: int) -> float:
    fields = _stat(pid)
    return (int(fields[11]) + int(fields[12])) / os.sysconf("SC_CLK_TCK")


def _start(args: list[str], *, ignore_sigint: bool = False,
           session: bool = False) -> subprocess.Popen:
    """``python -m balancer ARGS``; SIGINT ignored from its start if asked (as a command
    started in the background of a script has it), in a process group of its own if asked
    (as a terminal's foreground job: Ctrl-C reaches every process of the group)."""
    def ignore() -> None:
        signal.signal(signal.SIGINT, signal.SIG_IGN)

    return subprocess.Popen([sys.executable, "-m", "balancer", *map(str, args)],
                            stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True,
                            env=_env(), preexec_fn=ignore if ignore_sigint else None,
                            start_new_session=session)


def _interrupt(proc: subprocess.Popen, ready, *, group: bool = False) -> tuple[int, str, str]:
    """Wait until ``ready()``, send SIGINT (to the process group), and collect the result."""
    import time

    while proc.poll() is None and not ready():
        time.sleep(0.02)
    if proc.poll() is not None:
        out, err = proc.communicate()
        pytest.fail(f"the command ended (exit {proc.returncode}) before it was interrupted: "
                    f"{err[-500:]}")
    if group:
        os.killpg(proc.pid, signal.SIGINT)
    else:
        proc.send_signal(signal.SIGINT)
    try:
        out, err = proc.communicate(timeout=900)  # a safety net, not a measure
    except subprocess.TimeoutExpired:
        proc.kill()
        proc.communicate()
        pytest.fail("the command went on after SIGINT")
    return proc.returncode, out, err


def _busy(proc: subprocess.Popen, seconds: float = 1.0):
    """Ready once the child has used ``seconds`` of CPU: past its imports, at work."""
    def ready() -> bool:
        try:
            return _cpu_seconds(proc.pid) >= seconds
        except OSError:
            return False
    return ready


def _long_commands(tmp: Path) -> dict[str, list]:
    """A command of every verb that works long enough to be interrupted."""
    big = tmp / "big.toml"  # some 5 s of a cycle analysis (2.5 GB by its own estimate)
    big.write_text((EXAMPLES / "stephenson_sixbar.toml").read_text().replace(
        "samples = 360", "samples = 600000"))
    assert "samples = 600000" in big.read_text()
    return {
        "analyze": ["analyze", big],
        "simulate": ["simulate", EXAMPLES / "stephenson_sixbar.toml", "--drive", "free",
                     "--method", "multibody", "--duration", "150"],
        "verify": ["verify", PB1, "--duration", "2000"],
        "optimize": ["optimize", PB1, "--verify-duration", "2000"],
        "plot": ["plot", PB1, "--animate", tmp / "turning.gif", "--frames", "3000"],
        "pareto": ["pareto", EXAMPLES / "stephenson_sixbar.toml", "--against", "driving-torque",
                   "--points", "1000"],
        "sweep": ["sweep", PB1, "--vary", "mechanism.lengths.coupler=2:4:50", "--vary",
                  "mechanism.lengths.frame=2.5:3.5:50", "--out", tmp / "s.parquet",
                  "--workers", "0"],
    }


@pytest.mark.parametrize("verb", ["analyze", "simulate", "verify", "optimize", "plot", "pareto",
                                  "sweep"])
def test_a_sigint_ends_every_verb_with_130_even_if_sigint_was_ignored_at_its_start(
        tmp_path, verb):
    """A command started with SIGINT ignored (the background of a script: the hidden fuzz
    campaign's simulate answered a SIGINT with the step budget's refusal 2.5 s later, exit 2)
    still stops at once when sent one."""
    proc = _start(_long_commands(tmp_path)[verb], ignore_sigint=True)
    code, out, err = _interrupt(proc, _busy(proc))
    assert code == 130, err
    assert err.splitlines()[-1].startswith("balancer: interrupted"), err
    assert len(err.splitlines()) == 1, err
    assert not list(tmp_path.glob("*.gif")) and not (tmp_path / "s.parquet").exists()


def test_ipopt_does_not_swallow_a_sigint(tmp_path):
    """CasADi stops IPOPT at a SIGINT and returns as if it had failed (NonIpopt_Exception_
    Thrown), after a warning on stderr: the balancing would go on with the convex design.
    The NLP stage raises KeyboardInterrupt instead, without the warning. IPOPT is made to
    iterate without end (tolerances it cannot meet) and printing, so that the signal comes
    while it runs; for a minute of CPU at most (``max_cpu_time``), so that a signal CasADi
    loses in a race ends the run after all (``interrupts.checked`` then raises) instead of
    hanging the test."""
    script = tmp_path / "nlp.py"
    script.write_text(f"""
import sys
from balancer.balance.nlp import NlpSolver
from balancer.balance.optimizer import Optimizer
from balancer.spec import load_design

optimizer = Optimizer.of(load_design({str(EXAMPLES / 'pb2.toml')!r}))
x = optimizer.convex.solve().x
endless = {{"ipopt.print_level": 5, "ipopt.tol": 1e-300, "ipopt.max_iter": 10**8,
           "ipopt.dual_inf_tol": 1e-300, "ipopt.constr_viol_tol": 1e-300,
           "ipopt.compl_inf_tol": 1e-300, "ipopt.acceptable_iter": 10**8,
           "ipopt.acceptable_tol": 1e-300, "ipopt.acceptable_obj_change_tol": 0.0,
           "ipopt.max_cpu_time": 60.0}}
try:
    solution = NlpSolver(optimizer.data, options=endless).solve(x)
except KeyboardInterrupt:
    print("interrupted", file=sys.stderr)
    sys.exit(130)
print("returned", solution.stage.solver_status, file=sys.stderr)
""")
    proc = subprocess.Popen([sys.executable, str(script)], stdout=subprocess.PIPE,
                            stderr=subprocess.PIPE, text=True, env=_env())
    for line in proc.stdout:  # IPOPT's iterations: it is running
        if line.startswith("iter"):
            break
    proc.send_signal(signal.SIGINT)
    out, err = proc.communicate(timeout=300)
    assert proc.returncode == 130, err
    assert err.strip() == "interrupted"


def _group(pgid: int) -> list[tuple[str, str]]:
    """The live processes of a process group: ``(pid, command line)`` (a zombie is dead)."""
    members = []
    for entry in Path("/proc").iterdir():
        if not entry.name.isdigit():
            continue
        try:
            fields = _stat(int(entry.name))
            command = (entry / "cmdline").read_bytes().replace(b"\0", b" ").decode()
        except (OSError, ValueError):
            continue
        if int(fields[2]) == pgid and fields[0] != "Z":
            members.append((entry.name, command))
    return members


def _rows(parts: Path) -> int:
    return sum(pq.read_metadata(p).num_rows for p in parts.glob("batch-*.parquet"))


@pytest.mark.parametrize("workers", ["2", "0"])
def test_ctrl_c_on_a_sweep_says_what_it_kept_and_resume_finishes_it(tmp_path, workers):
    """Ctrl-C at a terminal reaches the whole process group, the local cluster's worker
    processes too. The sweep says in one line how many points it kept, where, and how to
    finish; no traceback, no Dask log; the workers are gone when it exits; exit 130. Then the
    same command with --resume finishes the table."""
    out = tmp_path / "a.parquet"
    parts = tmp_path / "a.parquet.parts"
    args = ["sweep", PB1, "--vary", "mechanism.lengths.coupler=2:4:20", "--vary",
            "mechanism.lengths.frame=2.5:3.5:20", "--out", out, "--workers", workers,
            "--batch", "10"]
    proc = _start(args, session=True)
    workers_seen: list[str] = []

    def ready() -> bool:  # the first part written; the worker processes, as they are then
        if not any(parts.glob("batch-*.parquet")):
            return False
        workers_seen[:] = [pid for pid, command in _group(proc.pid) if "spawn_main" in command]
        return True

    code, stdout, err = _interrupt(proc, ready, group=True)
    assert code == 130, err
    assert stdout == ""
    lines = err.splitlines()
    assert len(lines) == 1, err
    match = re.fullmatch(r"balancer: interrupted: (\d+) of 400 points kept in (.+); run the "
                         r"same command with --resume to finish", lines[0])
    assert match, lines[0]
    assert int(match[1]) == _rows(parts) >= 10 and Path(match[2]) == parts
    assert len(workers_seen) == int(workers)
    assert not [pid for pid, _ in _group(proc.pid) if pid in workers_seen]  # none left
    done = subprocess.run([sys.executable, "-m", "balancer", *map(str, args), "--resume"],
                          capture_output=True, text=True, env=_env(), check=False)
    assert done.returncode == 0, done.stderr
    assert pq.read_table(out).column("point").to_pylist() == list(range(400))
    assert done.stdout.splitlines()[1].startswith(
        f"400 points: {match[1]} from the interrupted run before ("), done.stdout
