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
import io
import json
import re
import shutil
import sys
import tempfile
from pathlib import Path

from . import compare

ROOT = Path(__file__).resolve().parents[2]
EXAMPLES = ROOT / "examples"
STORE = Path(__file__).resolve().parent / "outputs"

#: Examples without a ``[balance]`` section (no optimize, pareto): engines are balanced by
#: counterweights and shafts of their own (issue 31).
UNBALANCED = ("meijaard2020", "single_cylinder", "inline_three", "inline_four", "v6", "v8")
#: Fields and phrases that measure wall-clock time or name a temporary folder.
_MASKS = (
    (re.compile(r'("(?:time|seconds)": )[-+0-9.eE]+'), r'\1"<t>"'),
    (re.compile(r"\b[0-9.]+(?:e[-+]?\d+)? ms\b"), "<t> ms"),
    (re.compile(r"(right-hand sides, )[0-9.eE+-]+ s"), r"\1<t> s"),
    (re.compile(r"(\d+ points in )[0-9.]+ s \([0-9.]+ points/s"), r"\1<t> s (<r> points/s"),
)
#: A recorded output's parts: ``exit N``, then ``--- stdout``, ``--- stderr`` and each file
#: written (``--- out.csv``).
_PART = re.compile(r"^--- (stdout|stderr|\S+\.\w+)$", re.MULTILINE)
#: A CSV longer than this many rows is kept as its header and every :data:`CSV_EVERY`-th row
#: (each figure of those compared; a cycle's 360 or 720 angles, every 5th).
CSV_ROWS = 100
CSV_EVERY = 5


#: Examples whose balancing optimum is not unique: the objective leaves a valley of optimal
#: designs (another preferred design or other solver settings give another optimal one:
#: ``tests/test_golden.py`` shows it for each), and the tie-break's choice in it (the one
#: nearest the original) is only as well determined as its solve — where the tie-break does
#: not solve (the Stephenson six-bar's), the design is the interior point's in the valley. The
#: Jansen leg's upper link: 4.79 kg or 2.71 kg, with the same first moment and rotor inertia,
#: on two machines' arithmetic. Their outputs compare what the optimum fixes
#: (:func:`golden.compare._optimize_rule`), their text its wording.
NOT_UNIQUE = frozenset({"jansen_leg", "pb1", "pb2", "pb2_counterweights", "quick_return",
                        "stephenson_sixbar", "two_plane_drive", "watt_sixbar"})


def difference(recorded: str, now: str, key: str, sibling: str | None = None,
               unique: bool = True) -> str | None:
    """Where the output ``now`` of command ``key`` differs from ``recorded``, or ``None``.

    Part by part (:data:`_PART`): a JSON document and a CSV table figure by figure, each by
    what it is (:mod:`golden.compare`), a text (a table, a written spec) by its verb's
    tolerance with its wording exact. ``sibling``: the recorded JSON output of the same verb
    (an integrator's steps, ``rtol`` and travel, for its text and CSV); ``unique``: whether the
    example's optimum is (:data:`NOT_UNIQUE`).
    """
    verb, kind = key.split(".")[0].split("-")[0], key.rsplit(".", 1)[1]
    parts_a, parts_b = _parts(recorded), _parts(now)
    if list(parts_a) != list(parts_b):
        return f"other parts: recorded {list(parts_a)}, now {list(parts_b)}"
    document = _parts(sibling).get("stdout") if sibling else None
    if kind == "json":
        document = parts_a["stdout"]
    parsed = json.loads(document) if document else None
    text = compare.text_rule(verb, recorded, parsed, unique)
    for part, a in parts_a.items():
        b = parts_b[part]
        if part == "stdout" and kind == "json":
            problem = compare.compare_document(a, b, "json", compare.json_rules(verb, unique),
                                               text)
        elif part.endswith(".csv"):
            problem = compare.compare_csv(a, b, text)
        elif not unique and verb in ("optimize", "pareto") and part != "exit":
            # the lines about what the optimum fixes, by the design's tolerance
            fixed = compare.fixed_lines(parsed)
            problem = compare.compare_text(fixed(a), fixed(b), compare.DESIGN)
        else:
            problem = compare.compare_text(a, b, text)
        if problem is not None:
            return f"{part}: {problem}"
    return None


def _parts(text: str) -> dict[str, str]:
    pieces = _PART.split(text)
    parts = {"exit": pieces[0].strip()}
    for name, body in zip(pieces[1::2], pieces[2::2], strict=True):
        parts[name] = body.strip("\n")
    return parts


def mask(text: str, folder: Path | None = None) -> str:
    """``text`` with wall-clock times, the temporary ``folder`` and the checkout replaced.

    (A clone elsewhere names the examples by another path.)
    """
    for pattern, replacement in _MASKS:
        text = pattern.sub(replacement, text)
    if folder is not None:
        text = text.replace(str(folder), "<tmp>")
    return text.replace(str(ROOT), "<root>")


#: Shipped examples the verbs do not run yet, each with the reason: neither recorded nor
#: compared (``tests/test_golden.py`` lists them as skipped), nor analysed by the tests that run
#: a verb on every example (``tests/test_plausibility.py``).
NOT_RUN: dict[str, str] = {}
#: Shipped examples with several inputs, analysed along their motions (the motion whose CSV is
#: recorded): ``analyze``, and ``optimize`` where the spec has ``[balance]`` (simulate and
#: verify take a one-input mechanism so far).
ALONG_MOTIONS = {"forbal2": "diamond", "pick_fivebar": "pick", "fivebar_5r": "stroke",
                 "three_rrr": "shake"}


def examples() -> list[str]:
    """The shipped examples' names that the verbs run (all but :data:`NOT_RUN`)."""
    return sorted(p.stem for p in EXAMPLES.glob("*.toml") if p.stem not in NOT_RUN)


def commands(name: str) -> dict[str, list[str]]:
    """The command lines recorded for example ``name`` (``{tmp}`` is the output folder)."""
    spec = str(EXAMPLES / f"{name}.toml")
    if name in ALONG_MOTIONS:
        along = {"analyze.txt": ["analyze", spec],
                 "analyze.json": ["analyze", spec, "--json"],
                 "analyze.csv": ["analyze", spec, "--motion", ALONG_MOTIONS[name], "--csv",
                                 "{tmp}/out.csv"],
                 "simulate.txt": ["simulate", spec],
                 "simulate.json": ["simulate", spec, "--json"],
                 "simulate-free.json": ["simulate", spec, "--drive", "free", "--outputs", "41",
                                        "--json"],
                 "simulate.csv": ["simulate", spec, "--motion", ALONG_MOTIONS[name], "--out",
                                  "{tmp}/out.csv"],
                 "verify.json": ["verify", spec, "--json"]}
        if "[balance]" in (EXAMPLES / f"{name}.toml").read_text():
            along.update({
                "optimize.txt": ["optimize", spec, "--no-verify"],
                "optimize.json": ["optimize", spec, "--json", "--no-verify"],
                "optimize-convex.json": ["optimize", spec, "--json", "--no-verify",
                                         "--backend", "convex"],
                "optimize.toml": ["optimize", spec, "--no-verify", "--out", "{tmp}/out.toml"],
            })
        return along | _plans(name, spec)
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
    return out | _plans(name, spec)


def _plans(name: str, spec: str) -> dict[str, list[str]]:
    """``plan``'s command lines where the example has ``[plan]``."""
    text = (EXAMPLES / f"{name}.toml").read_text()
    if "[plan]" not in text:
        return {}
    out = {"plan.txt": ["plan", spec], "plan.json": ["plan", spec, "--json"]}
    if "[balance]" in text:  # (the masses chosen with the time law)
        out["plan-masses.json"] = ["plan", spec, "--with-masses", "--json"]
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
    """A long CSV as its header and every :data:`CSV_EVERY`-th row (:data:`CSV_ROWS`)."""
    lines = csv.splitlines()
    if len(lines) <= CSV_ROWS + 1:
        return "\n".join(lines)
    return "\n".join([*lines[:1], *lines[1::CSV_EVERY]])


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
