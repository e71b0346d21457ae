"""Outputs of every verb on every shipped example, recorded to guard a restructuring.

A change that moves code without meaning to change what it computes (the layering of issue 26,
the one mechanism model of issue 27) must leave every output as it was. This module runs each
verb on each example in-process and returns its outputs as text, with what changes from run to
run (wall-clock times, the temporary paths) masked; ``tests/test_golden.py`` compares them with
the copies recorded here before the change. It is a guard against unintended change, not a
check of correctness: every figure here is checked by an independent route elsewhere.

Record (after a change that is meant to alter outputs, and only then)::

    .venv/bin/python -m tests.golden.record
"""

from __future__ import annotations

import contextlib
import hashlib
import io
import re
import shutil
import sys
import tempfile
from pathlib import Path

ROOT = Path(__file__).resolve().parents[2]
EXAMPLES = ROOT / "examples"
STORE = Path(__file__).resolve().parent / "outputs"

#: Examples without a ``[balance]`` section (no optimize, pareto).
UNBALANCED = ("meijaard2020",)
#: Fields and phrases that measure wall-clock time or name a temporary folder.
_MASKS = (
    (re.compile(r'("(?:time|seconds)": )[-+0-9.eE]+'), r"\1<t>"),
    (re.compile(r"\b[0-9.]+(?:e[-+]?\d+)? ms\b"), "<t> ms"),
    (re.compile(r"(right-hand sides, )[0-9.eE+-]+ s"), r"\1<t> s"),
    (re.compile(r"(\d+ points in )[0-9.]+ s \([0-9.]+ points/s"), r"\1<t> s (<r> points/s"),
)


def mask(text: str, folder: Path | None = None) -> str:
    """``text`` with wall-clock times and the temporary ``folder`` replaced by markers."""
    for pattern, replacement in _MASKS:
        text = pattern.sub(replacement, text)
    if folder is not None:
        text = text.replace(str(folder), "<tmp>")
    return text


def examples() -> list[str]:
    """The shipped examples' names."""
    return sorted(p.stem for p in EXAMPLES.glob("*.toml"))


def commands(name: str) -> dict[str, list[str]]:
    """The command lines recorded for example ``name`` (``{tmp}`` is the output folder)."""
    spec = str(EXAMPLES / f"{name}.toml")
    out = {
        "analyze.txt": ["analyze", spec],
        "analyze.json": ["analyze", spec, "--json"],
        "analyze-mass-matrix.json": ["analyze", spec, "--json", "--route", "mass-matrix"],
        "analyze.csv": ["analyze", spec, "--csv", "{tmp}/out.csv"],
        "simulate.txt": ["simulate", spec, "--outputs", "41"],
        "simulate.json": ["simulate", spec, "--json", "--outputs", "41"],
        "simulate.csv": ["simulate", spec, "--outputs", "41", "--all-columns", "--out",
                         "{tmp}/out.csv"],
        "verify.json": ["verify", spec, "--json", "--duration", "0.5"],
    }
    if name not in UNBALANCED:
        out.update({
            "optimize.txt": ["optimize", spec, "--no-verify"],
            "optimize.json": ["optimize", spec, "--json", "--verify-duration", "0.5"],
            "optimize-convex.json": ["optimize", spec, "--json", "--no-verify", "--backend",
                                     "convex"],
            "optimize.toml": ["optimize", spec, "--no-verify", "--out", "{tmp}/out.toml"],
        })
    return out


def run(argv: list[str]) -> tuple[int, str, str, dict[str, str]]:
    """Run the command line in-process: exit code, stdout, stderr, files written (by name)."""
    from balancer.cli import main

    folder = Path(tempfile.mkdtemp(prefix="balancer-golden-"))
    try:
        args = [a.replace("{tmp}", str(folder)) for a in argv]
        out, err = io.StringIO(), io.StringIO()
        with contextlib.redirect_stdout(out), contextlib.redirect_stderr(err):
            code = main(args)
        files = {p.name: p.read_text() for p in sorted(folder.iterdir())}
        return (code, mask(out.getvalue(), folder), mask(err.getvalue(), folder),
                {k: mask(v, folder) for k, v in files.items()})
    finally:
        shutil.rmtree(folder, ignore_errors=True)


def output(name: str, key: str) -> str:
    """What the recorded command ``key`` of example ``name`` gives now, as one text."""
    code, out, err, files = run(commands(name)[key])
    parts = [f"exit {code}", "--- stdout", out, "--- stderr", err]
    suffix = key.rsplit(".", 1)[1]
    for file, text in files.items():
        if file.endswith(suffix):
            parts += [f"--- {file}", _abridged(text) if suffix == "csv" else text]
    return "\n".join(parts)


def _abridged(csv: str) -> str:
    """A long CSV as its digest, its header and every 30th row (the digest holds the rest)."""
    lines = csv.splitlines()
    digest = hashlib.sha256(csv.encode()).hexdigest()
    return "\n".join([f"sha256 {digest}", *lines[:1], *lines[1::30]])


def record(names: list[str] | None = None) -> None:
    """Write the current outputs of every example (or of ``names``) to :data:`STORE`."""
    for name in names or examples():
        folder = STORE / name
        folder.mkdir(parents=True, exist_ok=True)
        for key in commands(name):
            (folder / key).write_text(output(name, key))
        print(f"recorded {name}", file=sys.stderr)


if __name__ == "__main__":
    record(sys.argv[1:] or None)
