"""Fuzzing the command line in-process: random valid and hostile specs and command lines.

The cases come from ``tests/fuzz/generate.py`` (cheap profile: no absurd sizes) and are
checked by ``tests/fuzz/checks.py``; the long campaign is ``python -m tests.fuzz.campaign``.
Every run must end with an exit code 0, 1 or 2, never a traceback or a hang; a failure prints one
line on stderr; ``--json`` output is strict JSON with the fixed fields; the input spec is left
as it was and nothing (not even a temporary file) is left behind by a failed command.
"""

from __future__ import annotations

import shutil
import tempfile
from pathlib import Path

import pytest
from fuzz.checks import run_inprocess
from fuzz.generate import make_case, prepare_workdir, release_workdir
from hypothesis import HealthCheck, Phase, given, settings
from hypothesis import strategies as st

#: The whole module is of the full suite, not of the fast lane (`pytest -m "not slow"`).
pytestmark = pytest.mark.slow

#: Defect classes these tests fail on (the campaign reports more, e.g. exit codes that differ
#: from what the input implies and DESIGN.md's planned checks of file extensions).
ASSERTED = (
    "traceback",
    "hang",
    "killed by a signal",
    "exit code",
    "'Traceback' in stderr",
    "stderr not exactly one line on failure",
    "NaN/Infinity in --json output",
    "invalid JSON on stdout",
    "JSON missing fixed fields",
    "input spec changed",
    "partial output after a failure",
    "leftover temporary files",
)

SETTINGS = settings(
    deadline=None,
    derandomize=True,
    database=None,
    phases=(Phase.explicit, Phase.generate),  # shrinking a seed means nothing
    suppress_health_check=(HealthCheck.too_slow,),
)


def _check(seed: int, group: str) -> None:
    case = make_case(seed, 0, profile="cheap", group=group)
    root = Path(tempfile.mkdtemp(prefix="balancer-fuzz-"))
    try:
        folder = prepare_workdir(case, root / "work")
        run = run_inprocess(case, folder, timeout=20.0)
    finally:
        release_workdir(root / "work")
        shutil.rmtree(root, ignore_errors=True)
    defects = [d for d in run.defects if d.startswith(ASSERTED)]
    if defects:
        spec = case.spec.decode("utf-8", "replace")
        detail = run.exception["frames"] if run.exception else run.stderr[-1500:]
        pytest.fail(
            f"{'; '.join(defects)}\n"
            f"case {case.kind} ({'; '.join(case.notes)}), seed {seed}: "
            f"balancer {' '.join(case.argv)} -> exit {run.rc} ({run.status})\n"
            f"--- spec.toml ---\n{spec}\n--- detail ---\n{detail}",
            pytrace=False,
        )


seeds = st.integers(min_value=0, max_value=2**32 - 1)


@pytest.mark.slow
@settings(SETTINGS, max_examples=60)
@given(seed=seeds)
def test_valid_specs_and_command_lines(seed):
    _check(seed, "valid")


@pytest.mark.slow
@settings(SETTINGS, max_examples=60)
@given(seed=seeds, group=st.sampled_from(["spec", "spec", "absurd", "text"]))
def test_hostile_specs(seed, group):
    _check(seed, group)


@pytest.mark.slow
@settings(SETTINGS, max_examples=50)
@given(seed=seeds, group=st.sampled_from(["cmd", "cmd", "odd"]))
def test_hostile_command_lines(seed, group):
    _check(seed, group)
