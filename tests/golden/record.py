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

#: Examples without a ``[balance]`` section (no optimize, pareto): engines are balanced by
#: counterweights and shafts of their own (issue 31).
UNBALANCED = ("meijaard2020", "single_cylinder", "inline_three", "inline_four", "v6", "v8")
#: Fields and phrases that measure wall-clock time or name a temporary folder.
_MASKS = (
    (re.compile(r'("(?:time|seconds)": )[-+0-9.eE]+'), r"\1<t>"),
    (re.compile(r"\b[0-9.]+(?:e[-+]?\d+)? ms\b"), "<t> ms"),
    (re.compile(r"(right-hand sides, )[0-9.eE+-]+ s"), r"\1<t> s"),
    (re.compile(r"(\d+ points in )[0-9.]+ s \([0-9.]+ points/s"), r"\1<t> s (<r> points/s"),
)


#: A number as the outputs print it (JSON, tables, CSV).
_NUMBER = re.compile(r"(?<![\w.])[-+]?(?:\d+\.?\d*|\.\d+)(?:[eE][-+]?\d+)?(?![\w.])")
#: Counters of a solver's or an integrator's path, which rounding on another machine's
#: arithmetic (another BLAS kernel) may lengthen or shorten by a step: not compared.
_COUNTERS = re.compile(r'("(?:iterations|steps|nfev|evaluations)": )\d+'
                       r"|\b\d+( solver iterations| steps| right-hand sides)")
#: Agreement of two figures: relative, and as a share of the largest figure of the same
#: output (a rounding-level figure, such as a balanced design's 4e-14 N, is noise on another
#: machine's arithmetic).
RELATIVE = 1e-9
OF_LARGEST = 1e-12


def _counters_masked(text: str) -> str:
    return _COUNTERS.sub(lambda m: (m.group(1) or "") + "<n>" + (m.group(2) or ""), text)


def difference(recorded: str, now: str, *, table: bool = False) -> str | None:
    """Where ``now`` differs from ``recorded`` beyond another machine's rounding, or ``None``.

    The text between the numbers must be the same; each number the same to :data:`RELATIVE`,
    or to :data:`OF_LARGEST` of the output's largest number; in a readable ``table`` (figures
    printed to a few significant digits), or to the last digit it is printed with. (JSON, CSV
    and TOML print the shortest text that reads back as the same double: every digit counts.)
    """
    a, b = _counters_masked(recorded), _counters_masked(now)
    if a == b:
        return None
    if _skeleton(a) != _skeleton(b):
        for line_a, line_b in zip(a.splitlines(), b.splitlines(), strict=False):
            if _skeleton(line_a) != _skeleton(line_b):
                return f"text differs:\n  recorded: {line_a}\n  now:      {line_b}"
        return "a different number of lines"
    xs, ys = _NUMBER.findall(a), _NUMBER.findall(b)
    largest = max((abs(float(x)) for x in xs), default=0.0)
    for x, y in zip(xs, ys, strict=True):
        fx, fy = float(x), float(y)
        printed = 1.000001 * max(_last_digit(x), _last_digit(y)) if table else 0.0
        if abs(fx - fy) > max(RELATIVE * max(abs(fx), abs(fy)), OF_LARGEST * largest, printed):
            return f"a figure differs: recorded {x}, now {y}"
    return None


def _skeleton(text: str) -> list[str]:
    """The text between the numbers, a table's padding and rules reduced to one character.

    (A figure printed one digit shorter narrows its column.)
    """
    return [re.sub(r"-{2,}", "-", re.sub(r"[ \t]+", " ", part)) for part in _NUMBER.split(text)]


def _last_digit(token: str) -> float:
    """The value of one unit in the last printed digit of a number of fewer than 15 digits."""
    mantissa, _, exponent = token.lower().lstrip("+-").partition("e")
    digits = mantissa.replace(".", "").lstrip("0")
    if len(digits) >= 15:  # a full repr: compared relatively
        return 0.0
    decimals = len(mantissa.partition(".")[2])
    return 10.0 ** (int(exponent or 0) - decimals)


def mask(text: str, folder: Path | None = None) -> str:
    """``text`` with wall-clock times, the temporary ``folder`` and the checkout replaced.

    (A clone elsewhere names the examples by another path.)
    """
    for pattern, replacement in _MASKS:
        text = pattern.sub(replacement, text)
    if folder is not None:
        text = text.replace(str(folder), "<tmp>")
    return text.replace(str(ROOT), "<root>")


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
        "verify.json": ["verify", spec, "--json"],
    }
    if name not in UNBALANCED:
        out.update({
            "optimize.txt": ["optimize", spec, "--no-verify"],
            "optimize.json": ["optimize", spec, "--json"],
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
