"""Fuzz campaign of the ``balancer`` command line on general linkages (``type = "linkage"``).

Usage::

    .venv/bin/python -m tests.fuzz.linkage_campaign --cases N --seed S [--start I]
        [--timeout SEC] [--keep DIR] [--memory-gb G] [--quiet]
    .venv/bin/python -m tests.fuzz.linkage_campaign --report DIR [--repro /tmp/linkfuzz]

Case ``i`` is :func:`tests.fuzz.linkages.make_case` ``(S, i)``. Each case's spec is written
to a temporary folder of its own and run through::

    balancer analyze spec.toml --json
    balancer simulate spec.toml --json --duration 0.05
    balancer optimize spec.toml --json --no-verify      (when the spec has [balance])
    balancer verify spec.toml --json --duration 0.05

each in a forked child (the heavy libraries are imported once, in the parent) with a time
limit and an address-space limit; ``balancer.cli.main`` is called as the console script does.
A run is classified by its exit code against what the input implies (a valid spec must be
accepted, bad input must exit 2 with a one-line message naming the file and one of the keys
the generator expects), by its output (strict JSON with the fields DESIGN.md fixes, keyed as
it says for a general linkage; no NaN or Infinity) and by its side effects (the spec left as
it was, nothing left in the folder). Internal errors ("balancer: internal error: ...") get
their full traceback recorded from the child.

With ``--keep DIR`` every run is appended to ``DIR/results.jsonl`` and the spec of every case
with a defect is kept in ``DIR/specs/``; ``--report DIR`` prints the counts over all chunks
run into ``DIR`` and writes one reproducer per defect class to ``--repro``.
"""

from __future__ import annotations

import os

if __name__ == "__main__":  # before NumPy loads: the machine is shared
    for _name in ("OPENBLAS_NUM_THREADS", "OMP_NUM_THREADS", "MKL_NUM_THREADS"):
        os.environ.setdefault(_name, "1")

import argparse  # noqa: E402
import collections  # noqa: E402
import hashlib  # noqa: E402
import json  # noqa: E402
import math  # noqa: E402
import multiprocessing  # noqa: E402
import re  # noqa: E402
import shutil  # noqa: E402
import sys  # noqa: E402
import tempfile  # noqa: E402
import time  # noqa: E402
import traceback  # noqa: E402
from dataclasses import asdict, dataclass, field  # noqa: E402
from pathlib import Path  # noqa: E402
from typing import Any  # noqa: E402

from .campaign import isolate  # noqa: E402
from .checks import _is_number, _reject_constant, snapshot  # noqa: E402
from .checks import _missing_fields as _fixed_fields  # noqa: E402
from .linkages import SPEC, LinkageCase, directed_cases, make_case  # noqa: E402

FIGURES = ("shaking_force", "shaking_moment", "driving_torque")


def commands(case: LinkageCase) -> list[tuple[str, tuple[str, ...]]]:
    """The verb and argv of each command run on ``case``."""
    out = [("analyze", ("analyze", SPEC, "--json")),
           ("simulate", ("simulate", SPEC, "--json", "--duration", "0.05"))]
    if b"[balance" in case.spec:
        out.append(("optimize", ("optimize", SPEC, "--json", "--no-verify")))
    out.append(("verify", ("verify", SPEC, "--json", "--duration", "0.05")))
    return out


# ----------------------------------------------------------------------------------------------
# Running one command in a forked child


def _preload() -> None:
    import balancer.api  # noqa: F401
    import balancer.balance.optimizer  # noqa: F401
    import balancer.cli  # noqa: F401
    import balancer.cli.analyze  # noqa: F401
    import balancer.cli.optimize  # noqa: F401
    import balancer.cli.pareto  # noqa: F401
    import balancer.cli.plot  # noqa: F401
    import balancer.cli.simulate  # noqa: F401
    import balancer.cli.sweep  # noqa: F401
    import balancer.cli.verify  # noqa: F401
    import balancer.report  # noqa: F401
    import balancer.simulation  # noqa: F401
    import balancer.spec  # noqa: F401
    import balancer.verification  # noqa: F401

    for name in ("balancer.balance.convex", "balancer.balance.nlp", "balancer.linkage.numeric",
                 "balancer.formulations.multibody", "cvxpy", "casadi", "scipy.integrate"):
        try:
            __import__(name)
        except ImportError:  # pragma: no cover
            pass


def _child(argv: tuple[str, ...], folder: str, io_dir: str, memory: int) -> None:
    isolate(folder, io_dir, memory)
    import balancer.cli as cli

    original = cli._innermost

    def innermost(exc: BaseException) -> str:  # record the internal error's traceback
        with open(os.path.join(io_dir, "traceback.txt"), "w", encoding="utf-8") as fh:
            traceback.print_exception(exc, file=fh)
        return original(exc)

    cli._innermost = innermost
    exc_info = None
    try:
        rc = cli.main(list(argv))
    except SystemExit as exc:
        rc = exc.code if isinstance(exc.code, int) else (0 if exc.code is None else 1)
    except BaseException as exc:  # noqa: BLE001 - what the interpreter would print
        traceback.print_exc(file=sys.stderr)
        with open(os.path.join(io_dir, "traceback.txt"), "w", encoding="utf-8") as fh:
            traceback.print_exception(exc, file=fh)
        exc_info = f"{type(exc).__name__}: {exc}"[:500]
        rc = 1
    sys.stdout.flush()
    sys.stderr.flush()
    with open(os.path.join(io_dir, "result.json"), "w", encoding="utf-8") as fh:
        json.dump({"rc": rc, "uncaught": exc_info}, fh)
    os._exit(0)


@dataclass
class Run:
    verb: str
    argv: tuple[str, ...]
    rc: int | None = None
    status: str = "exit"  # exit, timeout, signal, no-result
    seconds: float = 0.0
    stdout: str = ""
    stderr: str = ""
    traceback: str = ""
    uncaught: str | None = None
    new_files: list[str] = field(default_factory=list)
    spec_changed: bool = False
    defects: list[str] = field(default_factory=list)
    details: dict[str, str] = field(default_factory=dict)


def run_command(ctx, verb: str, argv: tuple[str, ...], folder: Path, scratch: Path,
                timeout: float, memory: int) -> Run:
    io_dir = scratch / f"io-{verb}"
    io_dir.mkdir()
    before = snapshot(folder)
    sys.stdout.flush()
    sys.stderr.flush()
    proc = ctx.Process(target=_child, args=(argv, str(folder), str(io_dir), memory),
                       daemon=True)
    start = time.perf_counter()
    proc.start()
    proc.join(timeout)
    run = Run(verb=verb, argv=argv)
    run.seconds = time.perf_counter() - start
    if proc.is_alive():
        proc.kill()
        proc.join()
        run.status = "timeout"
    else:
        result = io_dir / "result.json"
        if result.exists():
            data = json.loads(result.read_text(encoding="utf-8"))
            run.rc, run.uncaught = data["rc"], data["uncaught"]
        elif proc.exitcode is not None and proc.exitcode < 0:
            run.status, run.rc = "signal", proc.exitcode
        else:
            run.status, run.rc = "no-result", proc.exitcode
    proc.close()
    for name in ("stdout", "stderr"):
        p = io_dir / name
        setattr(run, name, p.read_bytes().decode("utf-8", "replace") if p.exists() else "")
    tb = io_dir / "traceback.txt"
    if tb.exists():
        run.traceback = tb.read_text(encoding="utf-8", errors="replace")
    after = snapshot(folder)
    run.spec_changed = before.get(SPEC) != after.get(SPEC)
    run.new_files = sorted(set(after) - set(before))
    shutil.rmtree(io_dir, ignore_errors=True)
    for f in run.new_files:  # the next command must see the folder as it was
        p = folder / f
        if p.is_dir():
            shutil.rmtree(p, ignore_errors=True)
        elif p.exists():
            p.unlink()
    return run


# ----------------------------------------------------------------------------------------------
# Classification


def _missing_fields(verb: str, doc: Any, argv: tuple[str, ...]) -> list[str]:
    """The CLI campaign's fixed fields (:func:`.checks._missing_fields`), and a general
    linkage's simulate states keyed by link name (DESIGN.md)."""
    miss = _fixed_fields(verb, doc, argv)
    if verb == "simulate" and isinstance(doc, dict):
        for state in ("initial", "final"):
            part = doc.get(state)
            for k in ("theta", "omega", "alpha"):
                if isinstance(part, dict) and not isinstance(part.get(k), dict):
                    miss.append(f"{state}.{k} (not keyed by link)")
    return miss


def _design_keys(verb: str, doc: dict, case: LinkageCase) -> list[str]:
    """Where a general linkage's JSON is keyed otherwise than DESIGN.md says."""
    info = case.info
    if not info.get("links"):
        return []
    moving = set(info["links"])
    ground = set(info["ground"])
    out: list[str] = []
    if verb == "analyze":
        reactions = doc.get("reactions")
        if not isinstance(reactions, dict):
            return ["analyze: no reactions object"]
        joints = {p for n, pts in info["links"].items() for p in pts if p in ground}
        ground_sliders = {s["link"] for s in info["sliders"] if s["guide"] == "ground"}
        for p in sorted(joints):
            if p not in reactions:
                out.append(f"analyze: reactions lacks ground joint {p}")
        for n in sorted(ground_sliders):
            entry = reactions.get(n)
            if not isinstance(entry, dict) or not {"max", "couple_max"} <= set(entry):
                out.append(f"analyze: reactions lacks ground slider {n} (max, couple_max)")
        extra = set(reactions) - ground - ground_sliders
        if extra:
            out.append(f"analyze: reactions keyed by {sorted(extra)}")
    elif verb == "simulate":
        for state in ("initial", "final"):
            for k in ("theta", "omega", "alpha"):
                v = (doc.get(state) or {}).get(k)
                if isinstance(v, dict) and set(v) != moving:
                    out.append(f"simulate: {state}.{k} keyed by {sorted(v)} not the moving links")
    elif verb == "optimize":
        links = doc.get("links")
        if isinstance(links, dict) and not set(links) <= moving:
            out.append(f"optimize: links keyed by {sorted(set(links) - moving)}")
    return out


def _semantic(verb: str, doc: dict, case: LinkageCase) -> list[tuple[str, str]]:
    """Checks of the numbers against the spec (valid specs only): (class, detail)."""
    out: list[tuple[str, str]] = []
    info = case.info
    if verb == "simulate" and info.get("frames_angle") and info.get("theta1") is None:
        theta = (doc.get("initial") or {}).get("theta") or {}
        bad = []
        for name, ref in info["frames_angle"].items():
            got = theta.get(name)
            if _is_number(got) and abs(got - ref) > 1e-7 * (1 + abs(ref)):
                bad.append((name, got, ref))
        if bad:
            wrapped = all(abs(abs(got - ref) - 2 * math.pi) < 1e-6 for _, got, ref in bad)
            cls = ("simulate: initial angle off the principal value by 2π" if wrapped else
                   "simulate: initial angles are not the reference pose's")
            text = [f"{n}: {got:.9g} vs reference {ref:.9g}" for n, got, ref in bad]
            out.append((cls, "; ".join(text[:4])))
    if verb == "simulate" and info.get("theta1") is not None:
        theta = (doc.get("initial") or {}).get("theta") or {}
        got = theta.get(info["input"])
        if _is_number(got) and abs(got - info["theta1"]) > 1e-7 * (1 + abs(info["theta1"])):
            out.append(("simulate: initial input angle is not simulation.theta1",
                        f"{got} vs {info['theta1']}"))
    if (verb == "optimize" and info.get("force_balance") and doc.get("status") == "optimal"
            and not _constant_loads(case)):
        b = ((doc.get("before") or {}).get("shaking_force") or {}).get("max")
        a = ((doc.get("after") or {}).get("shaking_force") or {}).get("max")
        if _is_number(a) and _is_number(b) and b > 0 and a > 1e-6 * b:
            out.append(("optimize: 'optimal' with force balance but the shaking force remains",
                        f"max shaking force before {b:.6g}, after {a:.6g} (ratio {a / b:.3g})"))
    return out


def _constant_loads(case: LinkageCase) -> bool:
    """Whether the spec has forces that force balance leaves on the ground: applied forces,
    springs anchored to the ground."""
    import tomllib

    try:
        doc = tomllib.loads(case.spec.decode("utf-8"))
    except (ValueError, UnicodeDecodeError):
        return True
    if any(isinstance(link, dict) and "force" in link
           for name, link in doc.get("links", {}).items()):
        return True
    ground = set(doc.get("links", {}).get("ground", {}).get("points", []))
    return any(set(s.get("points", [])) & ground for s in doc.get("springs", []))


_INTERNAL = re.compile(r"internal error: (\w+): .*\((\S+?:\d+)\); please report")


def classify(case: LinkageCase, run: Run) -> None:
    """Fill ``run.defects`` (class names) and ``run.details`` (class -> a detail)."""
    d: list[tuple[str, str]] = []
    verb = run.verb
    tag = case.family.split("/")[0] + "/" + case.family.split("/")[1] if "/" in case.family \
        else case.family
    if run.status == "timeout":
        d.append(("timeout" + (" [absurd size on purpose]" if case.heavy else ""),
                  f"{verb} after {run.seconds:.0f} s ({case.family})"))
    elif run.status == "signal":
        d.append((f"killed by signal {run.rc}", verb))
    elif run.status == "no-result":
        d.append(("child ended without a result", f"exit {run.rc}"))
    m = _INTERNAL.search(run.stderr)
    if m:
        d.append((f"internal error {m.group(1)} @ {m.group(2)}", run.stderr.strip()[-300:]))
    if run.uncaught:
        d.append(("uncaught exception (traceback)", run.uncaught))
    elif "Traceback (most recent call last)" in run.stderr:
        d.append(("'Traceback' in stderr", run.stderr[-300:]))
    done = run.status == "exit"
    rc = run.rc
    # Besides its one error line: 'wrote PATH' and a note on a unit that looks wrong.
    lines = [line for line in run.stderr.splitlines() if line.strip()
             and not line.startswith(("wrote ", "balancer: note: "))]
    if done and rc not in (0, 1, 2):
        d.append((f"exit code {rc} (not 0/1/2)", ""))
    if done and rc != 0:
        if len(lines) != 1 or not lines[0].startswith("balancer: "):
            d.append(("stderr not one line on failure", run.stderr[-300:]))
        if run.stdout.strip():
            d.append(("output written on failure (stdout)", run.stdout[:200]))
        if run.new_files:
            d.append(("output files left after a failure", ", ".join(run.new_files)))
    if done and rc == 0:
        # (The same lines as on failure: a plausibility note on a unit that looks wrong is
        # what the command must say, exit code unchanged; anything else is not.)
        if lines:
            d.append(("stderr output on success", run.stderr[-200:]))
        if run.new_files:
            d.append(("files written by a --json command", ", ".join(run.new_files)))
        try:
            doc = json.loads(run.stdout, parse_constant=_reject_constant)
        except ValueError as exc:
            doc = None
            if "non-finite" in str(exc):
                nan_at = re.findall(r'"(\w+)": (?:NaN|-?Infinity)', run.stdout)[:5]
                d.append((f"exit 0 with NaN/Infinity in JSON ({verb})",
                          f"at {nan_at} [{case.family}]"))
            else:
                d.append((f"invalid or partial JSON on success ({verb})", run.stdout[-200:]))
        if isinstance(doc, dict):
            miss = _missing_fields(verb, doc, run.argv)
            if miss:
                d.append((f"JSON missing fixed fields ({verb})", ", ".join(miss[:6])))
            if case.expect in ("valid", "edge"):
                for what in _design_keys(verb, doc, case):
                    d.append((what.split(":")[0] + ": JSON keyed otherwise than DESIGN.md",
                              what))
            if case.expect == "valid":
                d += _semantic(verb, doc, case)
    if run.spec_changed:
        d.append(("input spec changed", ""))
    # exit codes against the input
    if done and rc in (0, 1, 2):
        allowed = case.expected_rc(verb)
        message = lines[0] if lines else ""
        if rc not in allowed:
            if case.expect == "error":
                if rc == 0:
                    d.append((f"bad input accepted (exit 0) [{tag}]", "; ".join(case.notes[2:])
                              or case.family))
                else:
                    d.append((f"bad input gives exit 1, not 2 [{tag}]",
                              f"{'; '.join(case.notes[2:])} -> {message[:240]}"))
            elif case.expect == "valid" and not (verb in ("analyze", "verify", "optimize")
                                                 and not case.info.get("has_operation", True)):
                d.append((f"valid spec refused: {verb} exit {rc}",
                          f"[{case.family}] {message[:300]}"))
            elif case.expect == "no-full-turn":
                d.append((f"crank that cannot turn fully: {verb} exit {rc}, expected "
                          f"{'/'.join(map(str, sorted(allowed)))}", f"[{case.family}] "
                          f"{message[:240]}"))
            else:
                d.append((f"{verb} exit {rc}, expected {'/'.join(map(str, sorted(allowed)))}"
                          f" [{case.expect}]", f"[{case.family}] {message[:240]}"))
        if rc == 1 and case.expect == "valid" and re.search(
                r"numerical trouble|could not be solved|solver failed", message):
            d.append((f"{verb}: solver failure on a valid spec (exit 1)", message[:240]))
        if rc == 2:
            keys = case.expected_keys(verb)
            # A key, or the inline table it sits in (a centre of mass "links.x.com" whose
            # e, f, s or at is absurd: the model knows its magnitude, not how it was written).
            named = [*keys, *(k.rsplit(".", 1)[0] + ":" for k in keys
                              if k.split(".")[-2:-1] == ["com"])]
            if keys and not any(k in message for k in named):
                d.append((f"exit 2 without the key named [{tag}]",
                          f"expected one of {list(keys)}; {'; '.join(case.notes[2:])} -> "
                          f"{message[:240]}"))
            if SPEC not in message and not message.startswith("balancer: error: --"):
                d.append(("exit 2 message does not name the spec file", message[:240]))
    run.defects = [c for c, _ in d]
    run.details = {}
    for c, detail in d:
        run.details.setdefault(c, detail)


# ----------------------------------------------------------------------------------------------
# The campaign


def run_case(ctx, case: LinkageCase, root: Path, timeout: float, memory: int) -> list[Run]:
    base = Path(tempfile.mkdtemp(prefix=f"{case.name}-", dir=root))
    folder = base / "work"
    folder.mkdir()
    (folder / SPEC).write_bytes(case.spec)
    scratch = base / "io"
    scratch.mkdir()
    runs = []
    try:
        for verb, argv in commands(case):
            run = run_command(ctx, verb, argv, folder, scratch, timeout, memory)
            classify(case, run)
            runs.append(run)
            if run.spec_changed:
                (folder / SPEC).write_bytes(case.spec)
    finally:
        shutil.rmtree(base, ignore_errors=True)
    return runs


def _code_version() -> str:
    """``HEAD`` of the repository and a hash of its uncommitted changes to balancer/."""
    import subprocess

    root = Path(__file__).resolve().parents[2]
    try:
        head = subprocess.run(["git", "rev-parse", "--short", "HEAD"], cwd=root,
                              capture_output=True, text=True, check=True).stdout.strip()
        diff = subprocess.run(["git", "diff", "HEAD", "--", "balancer"], cwd=root,
                              capture_output=True, check=True).stdout
    except (OSError, subprocess.CalledProcessError):
        return "unknown"
    return head + (f"+dirty:{hashlib.sha256(diff).hexdigest()[:8]}" if diff else "")


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(prog="python -m tests.fuzz.linkage_campaign",
                                     description=__doc__.split("\n\n")[0])
    parser.add_argument("--cases", type=int, default=50)
    parser.add_argument("--seed", type=int, default=2026)
    parser.add_argument("--start", type=int, default=0, help="index of the first case")
    parser.add_argument("--group", help="only cases of this group (see linkages.GROUPS)")
    parser.add_argument("--directed", action="store_true",
                        help="run the directed cases (suspects found by hand) instead")
    parser.add_argument("--indices-file", type=Path,
                        help="run the case indices listed in this file (one a line) instead")
    parser.add_argument("--timeout", type=float, default=60.0, help="seconds per command")
    parser.add_argument("--memory-gb", type=float, default=4.0,
                        help="address-space limit of each command, GB (0: none)")
    parser.add_argument("--keep", type=Path, help="folder for results.jsonl and specs/")
    parser.add_argument("--quiet", action="store_true")
    parser.add_argument("--report", type=Path, metavar="DIR",
                        help="only print the report of the runs kept in DIR")
    parser.add_argument("--recheck", type=Path, action="append", default=[],
                        help="with --report: a folder of later runs of some cases (they win)")
    parser.add_argument("--repro", type=Path, default=Path("/tmp/linkfuzz"),
                        help="where --report writes one reproducer per class")
    args = parser.parse_args(argv)
    if args.report is not None:
        return report(args.report, args.repro, args.recheck)
    _preload()
    ctx = multiprocessing.get_context("fork")
    keep = args.keep
    log = None
    if keep is not None:
        (keep / "specs").mkdir(parents=True, exist_ok=True)
        log = (keep / "results.jsonl").open("a", encoding="utf-8")
    t0 = time.perf_counter()
    totals: collections.Counter[str] = collections.Counter()
    if args.indices_file is not None:
        indices = [int(x) for x in args.indices_file.read_text().split()]
    else:
        indices = list(range(args.start, args.start + args.cases))
    directed = {c.index: c for c in directed_cases()} if args.directed else {}
    if directed:
        indices = sorted(directed)
    args.cases = len(indices)
    version = _code_version()
    with tempfile.TemporaryDirectory(prefix="linkfuzz-") as tmp:
        for n, i in enumerate(indices, 1):
            case = directed[i] if directed else make_case(args.seed, i, args.group)
            runs = run_case(ctx, case, Path(tmp), args.timeout, int(args.memory_gb * 2**30))
            defective = any(r.defects for r in runs)
            if keep is not None:
                if defective:
                    (keep / "specs" / f"{case.name}.toml").write_bytes(case.spec)
                for r in runs:
                    rec = {"case": case.name, "seed": case.seed, "index": case.index,
                           "family": case.family, "expect": case.expect,
                           "keys": list(case.keys), "notes": list(case.notes),
                           "heavy": case.heavy, "spec_bytes": len(case.spec),
                           "code": version, "time": time.time(),
                           **{k: v for k, v in asdict(r).items()
                              if k not in ("stdout", "stderr", "traceback")},
                           "stdout": r.stdout[:1500], "stderr": r.stderr[-3000:],
                           "traceback": r.traceback[-6000:]}
                    log.write(json.dumps(rec) + "\n")
                log.flush()
            for r in runs:
                totals[f"{r.verb} exit {r.rc if r.status == 'exit' else r.status}"] += 1
                for c in r.defects:
                    totals["defect: " + c] += 1
            if not args.quiet:
                flags = "; ".join(dict.fromkeys(c for r in runs for c in r.defects))[:150]
                rcs = " ".join(f"{r.verb[:3]}={r.rc if r.status == 'exit' else r.status}"
                               for r in runs)
                print(f"[{n}/{args.cases} {time.perf_counter() - t0:6.0f} s] {case.name} "
                      f"{case.family} ({case.expect}) {rcs} {flags or 'ok'}",
                      file=sys.stderr, flush=True)
    if log is not None:
        log.close()
    print(f"\n{args.cases} cases in {time.perf_counter() - t0:.0f} s")
    for k, v in sorted(totals.items()):
        print(f"{v:6d}  {k}")
    return 0


# ----------------------------------------------------------------------------------------------
# Report over the kept results


def _slug(text: str) -> str:
    s = re.sub(r"[^A-Za-z0-9]+", "-", text).strip("-").lower()
    return s[:80] or "defect"


def report(keep: Path, repro: Path, extra: list[Path] | None = None) -> int:
    """Counts over ``keep``'s runs; a case run again in an ``extra`` folder (a recheck at a
    later version of the code) counts by its latest runs."""
    latest: dict[str, list[dict]] = {}
    spec_dirs = {}
    for folder in [keep, *(extra or [])]:
        by_case: dict[str, list[dict]] = collections.defaultdict(list)
        for line in (folder / "results.jsonl").read_text().splitlines():
            if line.strip():
                r = json.loads(line)
                by_case[r["case"]].append(r)
        for case, runs in by_case.items():
            latest[case] = runs
            spec_dirs[case] = folder / "specs"
    records = [r for runs in latest.values() for r in runs]
    versions = collections.Counter(r.get("code", "?") for r in records)
    print("code versions (commands run at each): " + ", ".join(
        f"{k} {v}" for k, v in versions.most_common()))
    cases = {r["case"] for r in records}
    print(f"{len(cases)} cases, {len(records)} commands\n")
    exits = collections.Counter()
    for r in records:
        exits[(r["verb"], r["rc"] if r["status"] == "exit" else r["status"])] += 1
    print("exit codes by command:")
    for (verb, rc), n in sorted(exits.items(), key=lambda kv: (kv[0][0], str(kv[0][1]))):
        print(f"  {verb:9s} {str(rc):9s} {n:6d}")
    expects = collections.Counter()
    for c in {(r["case"], r["expect"]) for r in records}:
        expects[c[1]] += 1
    print("\ncases by expectation: " + ", ".join(f"{k} {v}" for k, v in sorted(expects.items())))
    by_class: dict[str, list[dict]] = collections.defaultdict(list)
    for r in records:
        for c in dict.fromkeys(r["defects"]):
            by_class[c].append(r)
    clean = sum(1 for r in records if not r["defects"])
    print(f"\ncommands without a defect: {clean} of {len(records)}\n")
    print(f"{'runs':>6} {'cases':>6}  defect class")
    order = sorted(by_class.items(), key=lambda kv: (-len({r['case'] for r in kv[1]}), kv[0]))
    for name, items in order:
        print(f"{len(items):6d} {len({r['case'] for r in items}):6d}  {name}")
    if repro is not None:
        repro.mkdir(parents=True, exist_ok=True)
    print("\nexamples (smallest spec first):")
    for name, items in order:
        items = sorted(items, key=lambda r: (r["heavy"], r["spec_bytes"]))
        first = items[0]
        print(f"\n== {name} ({len(items)} runs, {len({r['case'] for r in items})} cases)")
        details = collections.Counter(r["details"].get(name, "")[:160] for r in items)
        for detail, n in details.most_common(4):
            print(f"   {n:4d}x {detail}")
        spec = spec_dirs[first["case"]] / f"{first['case']}.toml"
        cmd = "balancer " + " ".join(first["argv"])
        print(f"   e.g. {first['case']} [{first['family']}] {'; '.join(first['notes'][2:])[:150]}")
        print(f"   $ {cmd}   -> exit {first['rc']} ({first['status']}, {first['seconds']:.1f} s)")
        tail = first["stderr"].strip().splitlines()[-1:] if first["stderr"].strip() else []
        for line in tail:
            print(f"   {line[:300]}")
        if first["traceback"]:
            tb = [x for x in first["traceback"].strip().splitlines() if x.strip()][-6:]
            for line in tb:
                print(f"   | {line[:200]}")
        if repro is not None and spec.exists():
            folder = repro / _slug(name)
            folder.mkdir(parents=True, exist_ok=True)
            target = folder / f"{first['case']}.toml"
            shutil.copyfile(spec, target)
            (folder / "README.txt").write_text(
                f"class: {name}\ncase: {first['case']} ({first['family']}, expect "
                f"{first['expect']}, keys {first['keys']})\nnotes: {'; '.join(first['notes'])}\n"
                f"command (from this folder; the campaign names the spec spec.toml):\n"
                f"  cp {target.name} spec.toml && /work/main/.venv/bin/{cmd}\n"
                f"exit: {first['rc']} ({first['status']}, {first['seconds']:.1f} s)\n"
                f"detail: {first['details'].get(name, '')}\n\n--- stderr ---\n"
                f"{first['stderr']}\n--- traceback ---\n{first['traceback']}\n"
                f"--- stdout (head) ---\n{first['stdout'][:1500]}\n", encoding="utf-8")
            print(f"   reproducer: {target}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
