"""The README and the documentation site: short, built without a warning, every code block run.

- The README stays a five-minute read (under 12 KB) whose two set-up commands are fixed.
- The site in ``docs/`` builds with Sphinx, warnings as errors, into a temporary folder.
- Every code block of the README and of ``docs/`` runs: ``console`` and ``bash`` command lines
  with the ``balancer`` command line (in a temporary folder holding the examples; a ``console``
  block's ``$ `` lines are commands and the lines after each are what it prints, checked line by
  line against what it prints now, figures to another machine's rounding and ``…`` standing for
  lines left out); ``python`` blocks executed in order in one namespace per page
  (``docs/tutorial.md``'s by ``tests/test_tutorial.py``); ``toml`` blocks read, a complete spec
  loaded (a spec file: written to the file its first line names, ``# NAME.toml``, or appended
  to it, ``# NAME.toml, continued``) and every key of a fragment found in the spec schema. ``text``
  blocks are pictures, and a block in braces a Sphinx directive.
- The API page documents every public name; the outputs page every JSON key the verbs print
  and every CSV column.
"""

from __future__ import annotations

import contextlib
import html
import io
import json
import re
import shlex
import shutil
import subprocess
import sys
import tomllib
from dataclasses import dataclass
from pathlib import Path

import pytest
from golden import compare
from golden.record import STORE, mask

import balancer
from balancer.spec import loads_design, schema

#: The whole module is of the full suite, not of the fast lane (`pytest -m "not slow"`).
pytestmark = pytest.mark.slow

ROOT = Path(__file__).resolve().parent.parent
DOCS = ROOT / "docs"
README = ROOT / "README.md"
PAGES = sorted(DOCS.glob("*.md"))
#: The README's set-up commands, fixed: the one command line that installs and analyses the
#: shipped example, and the one that runs the tests.
SETUP = ('python3 -m venv .venv && .venv/bin/pip install -e ".[dev]" && '
         ".venv/bin/balancer analyze examples/meijaard2020.toml",
         ".venv/bin/python -m pytest")
MAX_README_BYTES = 12_000
ELISION = ("…", "...")
FILE_LINE = re.compile(r"#\s*(\S+\.toml)(, continued)?\s*$")
EXIT_CODE = re.compile(r"#\s*exit code (\d+)\s*$")


@dataclass
class Block:
    """A fenced code block: its language, text and first line in its file."""

    language: str
    text: str
    line: int


def blocks(path: Path) -> list[Block]:
    """The fenced code blocks of a Markdown file, in order."""
    out, current = [], None
    for number, line in enumerate(path.read_text(encoding="utf-8").splitlines(), 1):
        if current is None:
            match = re.match(r"^(`{3,})\s*(\S*)", line)
            if match:
                current = (match.group(1), match.group(2), number + 1, [])
        elif line.strip() == current[0]:
            out.append(Block(current[1], "\n".join(current[3]) + "\n", current[2]))
            current = None
        else:
            current[3].append(line)
    assert current is None, f"{path.name}: a code block is not closed"
    return out


# --- the README ------------------------------------------------------------------------------


def test_the_readme_is_short_and_its_set_up_commands_are_fixed():
    text = README.read_text(encoding="utf-8")
    assert len(text.encode("utf-8")) < MAX_README_BYTES
    bash = [b.text.strip() for b in blocks(README) if b.language == "bash"]
    assert bash[:2] == list(SETUP)
    assert "](docs/gallery/pb1_cycle.png)" in text
    for page in re.findall(r"\]\((docs/[\w./-]+\.md)\)", text):
        assert (ROOT / page).is_file(), page


# --- the site --------------------------------------------------------------------------------


def test_the_site_builds_without_a_warning(tmp_path):
    out = tmp_path / "html"
    run = subprocess.run(
        [sys.executable, "-m", "sphinx", "-W", "--keep-going", "-q", "-b", "html",
         "-d", str(tmp_path / "doctrees"), str(DOCS), str(out)],
        capture_output=True, text=True, cwd=tmp_path, timeout=600)
    assert run.returncode == 0, run.stdout + run.stderr
    for page in PAGES:
        assert (out / page.with_suffix(".html").name).is_file(), page.name
    # The spec reference is generated from the schema: every table and key is on the page.
    spec = text_of(out / "spec.html")
    for section in schema.SECTIONS:
        assert "".join(section.header.split()) in spec, section.header
        for key in (*section.keys, *([section.names] if section.names else [])):
            mechanisms = "all" if key.mechanisms == schema.MECHANISMS else ", ".join(
                key.mechanisms)
            row = " ".join((key.name, key.unit, key.default, mechanisms, key.meaning))
            assert "".join(row.replace("`", "").split()) in spec, (section.header, key.name)
    cli = text_of(out / "cli.html")
    for verb in ("analyze", "simulate", "optimize", "verify", "plot", "pareto", "sweep",
                 "plan", "example"):
        assert f"balancer{verb}[-h]" in cli, verb
    assert "--verify-duration" in cli and "--all-columns" in cli


def text_of(page: Path) -> str:
    """A built page's text without its tags and spaces (which markup moves)."""
    text = html.unescape(re.sub(r"<[^>]+>", "", page.read_text(encoding="utf-8")))
    return "".join(text.split())


def test_every_page_is_in_the_site():
    index = (DOCS / "index.md").read_text(encoding="utf-8")
    listed = {line.strip() for line in index.splitlines()}
    for page in PAGES:
        assert page.stem == "index" or page.stem in listed, page.name
    assert not list(DOCS.rglob("*.rst")), "the pages are Markdown (MyST)"


# --- the code blocks -------------------------------------------------------------------------


def _commands(text: str, with_output: bool) -> list[tuple[str, list[str]]]:
    """The command lines of a block and, for a console block, what each prints."""
    out: list[tuple[str, list[str]]] = []
    pending = ""
    for line in text.splitlines():
        if with_output and not pending and not line.startswith("$ "):
            assert out, f"output before any command: {line!r}"
            out[-1][1].append(line)
            continue
        line = line[2:] if with_output and not pending else line
        if line.rstrip().endswith("\\"):
            pending += line.rstrip()[:-1].strip() + " "
            continue
        command = (pending + line.strip()).strip()
        pending = ""
        if command and not command.startswith("#"):
            out.append((command, []))
    assert not pending, "a command line continues past the block"
    return out


def run_balancer(command: str) -> tuple[int, str]:
    """Run a ``balancer`` command line in this process: its exit code, stdout then stderr."""
    from balancer.cli import main

    words = shlex.split(command, comments=True)
    assert words[0] == "balancer", f"a block may run balancer only: {command}"
    out, err = io.StringIO(), io.StringIO()
    with contextlib.redirect_stdout(out), contextlib.redirect_stderr(err):
        code = main(words[1:])
    return code, out.getvalue() + err.getvalue()


def check_output(expected: list[str], printed: str, verb: str = "analyze") -> None:
    """Each line shown is printed, in order; ``…`` stands for lines left out.

    A line's figures agree by ``verb``'s rule for text (:func:`golden.compare.text_rule`: an
    analysis to rounding, a simulation to its integrator, an optimum to its certificate).
    """
    actual = [compare.masked(mask(line)).rstrip() for line in printed.splitlines()]
    largest = compare.largest_figure(printed)
    tolerance = compare.text_rule(verb, printed)
    at = 0
    for line in expected:
        if not line.strip() or line.strip() in ELISION:
            continue
        shown = compare.masked(mask(line)).rstrip()
        for i in range(at, len(actual)):
            if (compare.skeleton(actual[i]) == compare.skeleton(shown)
                    and compare.line_difference(shown, actual[i], tolerance, largest) is None):
                at = i + 1
                break
        else:
            near = [a for a in actual if compare.skeleton(a) == compare.skeleton(shown)]
            raise AssertionError(f"not printed (or not in this order): {line!r}"
                                 + (f"\n  printed: {near[0]!r}" if near else "")
                                 + "\n--- printed:\n" + printed)


def run_command(command: str, expected: list[str]) -> None:
    if command in SETUP:
        return  # the set-up itself: a virtual environment, and the test suite
    wanted = EXIT_CODE.search(command)
    code, printed = run_balancer(command)
    assert code == (int(wanted.group(1)) if wanted else 0), f"{command}: exit {code}\n{printed}"
    if expected:
        check_output(expected, printed, shlex.split(command, comments=True)[1])


def check_toml(block: Block, folder: Path) -> None:
    first = block.text.splitlines()[0]
    data = tomllib.loads(block.text)  # every block is TOML on its own
    match = FILE_LINE.fullmatch(first.strip())
    text = block.text
    if match:
        path = folder / match.group(1)
        if match.group(2):
            assert path.is_file(), f"{path.name} is continued before it is written"
            text = path.read_text(encoding="utf-8") + "\n" + text
        path.write_text(text, encoding="utf-8")
        data = tomllib.loads(text)
    if match:  # a spec file: complete
        loads_design(text, source=match.group(1))
    else:
        for path, key in toml_keys(data):
            section = schema.section(path)
            assert section is not None, f"[{path}] is no table of the spec"
            assert section.names or key in schema.known(path), f"{path}.{key} is no spec key"


def toml_keys(data: dict, path: str = "") -> list[tuple[str, str]]:
    """Every (table, key) of a TOML document, into the tables the spec schema has."""
    out = []
    for key, value in data.items():
        out.append((path, key))
        inner = f"{path}.{key}" if path else key
        if isinstance(value, dict) and schema.section(inner) is not None:
            out += toml_keys(value, inner)
        elif isinstance(value, list) and value and all(isinstance(v, dict) for v in value):
            for i, item in enumerate(value):
                out += toml_keys(item, f"{inner}[{i}]")
    return out


@pytest.mark.parametrize("path", [README, *PAGES], ids=lambda p: p.relative_to(ROOT).as_posix())
def test_every_code_block_runs(path, tmp_path, monkeypatch, capsys):
    shutil.copytree(ROOT / "balancer" / "examples", tmp_path / "examples",
                    ignore=shutil.ignore_patterns("*.py", "__pycache__"))
    monkeypatch.chdir(tmp_path)
    namespace: dict = {}
    for block in blocks(path):
        where = f"{path.name}:{block.line}"
        try:
            if block.language in ("console", "bash"):
                for command, expected in _commands(block.text, block.language == "console"):
                    run_command(command, expected)
            elif block.language == "python":
                if path.name != "tutorial.md":  # tests/test_tutorial.py runs the tutorial
                    exec(compile(block.text, where, "exec"), namespace)  # noqa: S102 - our docs
            elif block.language == "toml":
                check_toml(block, tmp_path)
            else:
                assert block.language == "text" or block.language.startswith("{"), (
                    f"a block of language {block.language!r}: say what it is (console, bash, "
                    "python, toml; text for a picture)")
        except Exception as exc:
            raise AssertionError(f"{where}: {exc}") from exc
    capsys.readouterr()


def test_the_block_runner_checks_what_is_shown():
    printed = "RMS 101.59 N·m in 12.5 ms\ngap 4.7e-08 N·m\nforce 430.272 N"
    check_output(["RMS 101.59 N·m in 3 ms", "…", "force 430.272 N"], printed)
    check_output(["gap 5.1e-08 N·m"], printed)  # rounding-level: another machine's
    for wrong in (["RMS 102.59 N·m in 3 ms"], ["force 430.272 N", "RMS 101.59 N·m in 1 ms"],
                  ["force 430.272 kN"]):
        with pytest.raises(AssertionError):
            check_output(wrong, printed)
    assert _commands("$ balancer a \\\n  --b\nout\n$ balancer c  # note\n", True) == [
        ("balancer a --b", ["out"]), ("balancer c  # note", [])]


# --- the API and outputs pages ---------------------------------------------------------------


def test_the_api_page_documents_every_public_name():
    text = (DOCS / "api.md").read_text(encoding="utf-8")
    documented = re.findall(r"^\.\. auto(?:function|class|data):: balancer\.(\w+)$", text, re.M)
    assert sorted(documented) == sorted(balancer.__all__)


def _documented_keys(heading: str) -> set[str]:
    """The first column's keys of the table under a heading of docs/outputs.md."""
    text = (DOCS / "outputs.md").read_text(encoding="utf-8")
    part = text.split(f"## {heading}\n", 1)[1].split("\n## ", 1)[0]
    keys: set[str] = set()
    for row in re.findall(r"^\| (`[^|]+) \|", part, re.M):
        keys |= set(re.findall(r"`([^`]+)`", row))
    return keys


def _recorded_json(verb: str) -> set[str]:
    keys: set[str] = set()
    for path in [*STORE.glob(f"*/{verb}.json"), *STORE.glob(f"*/{verb}-*.json")]:
        text = path.read_text(encoding="utf-8")
        document = text.split("--- stdout\n", 1)[1].split("--- stderr", 1)[0]
        keys |= set(json.loads(re.sub(r"<t>", "0", document)))
    assert keys
    return keys


@pytest.mark.parametrize("verb", ["analyze", "simulate", "optimize", "verify", "plan"])
def test_the_outputs_page_names_every_json_key(verb):
    documented = _documented_keys(f"`{verb} --json`")
    if verb == "analyze":  # (a linkage with several inputs: along its motions)
        documented |= _documented_keys("`analyze --json` along motions")
    assert documented == _recorded_json(verb)


def test_the_outputs_page_names_the_fronts_and_sweeps_keys(tmp_path, monkeypatch):
    monkeypatch.chdir(tmp_path)
    spec = str(ROOT / "examples" / "pb1.toml")
    _, front = run_balancer(f"balancer pareto {spec} --against driving-torque --points 3 --json")
    _, sweep = run_balancer(f"balancer sweep {spec} --vary mechanism.lengths.coupler=2.9:3.1:2 "
                            "--workers 0 --out s.parquet --json")
    engine = str(ROOT / "examples" / "v8_to_balance.toml")
    _, engine_front = run_balancer(f"balancer pareto {engine} --against added-mass --points 2 "
                                   "--json")
    shaper = str(ROOT / "examples" / "quick_return.toml")  # (its flywheel bound: notes)
    _, noted = run_balancer(f"balancer pareto {shaper} --against driving-torque --points 2 "
                            "--json")
    front_doc, sweep_doc = json.loads(front), json.loads(sweep.split("wrote")[0])
    documented = _documented_keys("`pareto --json` and `sweep --json`")
    assert documented == (set(front_doc) | set(sweep_doc) | set(json.loads(engine_front))
                          | set(json.loads(noted)))
    assert {"shaking_moment", "driving_torque", "epsilon", "lower_bound",
            "knee"} == set(front_doc["points"][0])


def test_the_outputs_page_names_every_csv_column():
    documented = _documented_keys("CSV columns")
    patterns = [re.compile("^" + re.sub(r"<\w+>", r"\\w+", re.escape(name).replace(
        r"\<", "<").replace(r"\>", ">")) + "$") for name in documented]
    columns: set[str] = set()
    for path in STORE.glob("*/*.csv"):
        header = [line for line in path.read_text().splitlines() if line.startswith("t,")]
        columns |= set(header[0].split(","))
    for column in columns:
        assert any(p.match(column) for p in patterns), column
    for pattern in patterns:
        assert any(pattern.match(c) for c in columns), pattern.pattern
