"""Fuzz campaign for the ``balancer`` command line.

Usage::

    .venv/bin/python -m tests.fuzz.campaign --commands N --seed S [--timeout SEC] [--jobs J]
        [--keep DIR] [--start I] [--profile full|cheap] [--memory-gb G] [--directed]

Case ``i`` (``start <= i < start + N``) is :func:`tests.fuzz.generate.make_case` ``(S, i)``.
Each runs ``balancer.cli.main(argv)`` in a forked child (heavy libraries are imported once, in
the parent) inside its own prepared work folder, with its stdout and stderr captured at the file
descriptors, an address-space limit, and root's file-mode override dropped (so that a read-only
folder is read-only). Prints counts by exit code and by defect class, with up to three
reproducers per class; with ``--keep DIR`` the reproducers' work folders (spec, argv, stderr)
and ``results.jsonl`` (every run) are kept there. ``--directed`` runs the fixed list of known
suspects (:func:`tests.fuzz.generate.directed_cases`) instead of random cases.
"""

from __future__ import annotations

import os

if __name__ == "__main__":  # before NumPy loads: the machine is shared
    for _name in ("OPENBLAS_NUM_THREADS", "OMP_NUM_THREADS", "MKL_NUM_THREADS"):
        os.environ.setdefault(_name, "1")

import argparse  # noqa: E402
import collections  # noqa: E402
import io  # noqa: E402
import json  # noqa: E402
import multiprocessing  # noqa: E402
import resource  # noqa: E402
import shutil  # noqa: E402
import sys  # noqa: E402
import tempfile  # noqa: E402
import time  # noqa: E402
from pathlib import Path  # noqa: E402

from .checks import (  # noqa: E402
    Run,
    drop_dac_override,
    execute,
    finish_run,
    reload_written_spec,
    reproducer,
    snapshot,
)
from .generate import (  # noqa: E402
    Case,
    directed_cases,
    make_case,
    prepare_workdir,
    release_workdir,
)


def _preload() -> None:
    """Import what the commands import, once, so that each forked child starts fast."""
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
    import balancer.plots  # noqa: F401
    import balancer.report  # noqa: F401
    import balancer.simulation  # noqa: F401
    import balancer.verification  # noqa: F401

    for name in ("cvxpy", "casadi", "scipy.integrate", "matplotlib.figure", "PIL.Image",
                 "matplotlib.backends.backend_agg"):
        try:
            __import__(name)
        except ImportError:  # pragma: no cover
            pass


def isolate(folder: str, io_dir: str, memory: int) -> None:
    """In a forked child: stdout and stderr to files in ``io_dir``, no stdin, the working
    directory ``folder``, and at most ``memory`` bytes of address space (0: no limit)."""
    out = os.open(os.path.join(io_dir, "stdout"), os.O_WRONLY | os.O_CREAT | os.O_TRUNC)
    err = os.open(os.path.join(io_dir, "stderr"), os.O_WRONLY | os.O_CREAT | os.O_TRUNC)
    os.dup2(out, 1)
    os.dup2(err, 2)
    sys.stdout = io.TextIOWrapper(io.FileIO(1, "w", closefd=False), encoding="utf-8")
    sys.stderr = io.TextIOWrapper(io.FileIO(2, "w", closefd=False), encoding="utf-8",
                                  errors="backslashreplace", line_buffering=True)
    sys.stdin = open(os.devnull)  # noqa: SIM115
    os.chdir(folder)
    if memory:
        resource.setrlimit(resource.RLIMIT_AS, (memory, memory))


def _child(argv: tuple[str, ...], verb: str, folder: str, io_dir: str, memory: int) -> None:
    """Run one command (in the forked child); write ``result.json`` to ``io_dir``."""
    isolate(folder, io_dir, memory)
    drop_dac_override()
    rc, exc = execute(argv)
    reload_error = None
    if rc == 0 and verb == "optimize" and "--out" in argv:
        i = argv.index("--out")
        target = Path(folder) / argv[i + 1] if i + 1 < len(argv) else None
        if target is not None and argv[i + 1] and target.is_file():
            reload_error = reload_written_spec(target)
    sys.stdout.flush()
    sys.stderr.flush()
    with open(os.path.join(io_dir, "result.json"), "w", encoding="utf-8") as fh:
        json.dump({"rc": rc, "exception": exc, "reload_error": reload_error}, fh)
    os._exit(0)


class _Job:
    def __init__(self, case: Case, root: Path, ctx, memory: int) -> None:
        self.case = case
        self.base = root / case.name
        self.folder = prepare_workdir(case, self.base / "work")
        self.io = self.base / "io"
        self.io.mkdir()
        self.before = snapshot(self.folder)
        sys.stdout.flush()
        sys.stderr.flush()
        self.proc = ctx.Process(target=_child, args=(case.argv, case.verb, str(self.folder),
                                                     str(self.io), memory), daemon=True)
        self.start = time.perf_counter()
        self.proc.start()

    def finish(self, timed_out: bool) -> Run:
        run = Run(argv=self.case.argv, seconds=time.perf_counter() - self.start)
        if timed_out:
            self.proc.kill()
            self.proc.join()
            run.status = "timeout"
        result = self.io / "result.json"
        if not timed_out:
            if result.exists():
                data = json.loads(result.read_text(encoding="utf-8"))
                run.rc, run.exception = data["rc"], data["exception"]
                run.reload_error = data["reload_error"]
                run.status = "exception" if run.exception else "exit"
            elif self.proc.exitcode is not None and self.proc.exitcode < 0:
                run.status, run.rc = "signal", self.proc.exitcode
            else:
                run.status, run.rc = "no-result", self.proc.exitcode
        for name in ("stdout", "stderr"):
            p = self.io / name
            text = p.read_bytes().decode("utf-8", "replace") if p.exists() else ""
            setattr(run, name, text)
        self.proc.close()
        return finish_run(self.case, run, self.before, self.folder)

    def cleanup(self) -> None:
        release_workdir(self.folder)
        shutil.rmtree(self.base, ignore_errors=True)


def run_campaign(cases: list[Case], *, timeout: float, jobs: int, memory: int,
                 progress=None) -> list[tuple[Case, Run]]:
    """Run every case; return ``(case, run)`` pairs in case order."""
    _preload()
    ctx = multiprocessing.get_context("fork")
    results: dict[int, tuple[Case, Run]] = {}
    pending = list(cases)
    running: list[_Job] = []
    with tempfile.TemporaryDirectory(prefix="balancer-fuzz-") as tmp:
        root = Path(tmp)
        while pending or running:
            while pending and len(running) < jobs:
                running.append(_Job(pending.pop(0), root, ctx, memory))
            time.sleep(0.01)
            for job in list(running):
                elapsed = time.perf_counter() - job.start
                if job.proc.is_alive() and elapsed < timeout:
                    continue
                job.proc.join(timeout=0 if elapsed >= timeout else 5)
                run = job.finish(timed_out=job.proc.is_alive())
                job.cleanup()
                running.remove(job)
                results[job.case.index] = (job.case, run)
                if progress is not None:
                    progress(job.case, run, len(results))
    return [results[c.index] for c in cases]


# ----------------------------------------------------------------------------------------------
# Report


def _keep(case: Case, run: Run, keep: Path) -> Path:
    folder = keep / case.name
    if folder.exists():
        release_workdir(folder)
        shutil.rmtree(folder)
    prepare_workdir(case, folder)
    meta = keep / f"{case.name}.txt"
    meta.write_text(
        f"kind: {case.kind}\nnotes: {'; '.join(case.notes)}\nargv: {json.dumps(case.argv)}\n"
        f"exit: {run.rc} ({run.status}, {run.seconds:.1f} s)\n"
        f"defects: {json.dumps(run.defects)}\n"
        f"reproduce: {reproducer(case, folder.resolve())}\n\n--- stderr ---\n{run.stderr}\n"
        f"--- stdout (first 2000 characters) ---\n{run.stdout[:2000]}\n",
        encoding="utf-8",
    )
    return folder


def report(results: list[tuple[Case, Run]], keep: Path | None, out=sys.stdout) -> None:
    """Print the counts tables and reproducers."""
    codes = collections.Counter()
    for _, run in results:
        if run.status in ("exit", "exception"):
            codes[str(run.rc) if run.rc in (0, 1, 2) else "other"] += 1
        else:
            codes[run.status] += 1
    print(f"\n{len(results)} commands; exit codes:", file=out)
    for k in ("0", "1", "2", "other", "timeout", "signal", "no-result"):
        if codes[k]:
            print(f"  {k:>10}  {codes[k]:5d}", file=out)
    by_class: dict[str, list[tuple[Case, Run]]] = collections.defaultdict(list)
    for case, run in results:
        for d in dict.fromkeys(run.defects):
            by_class[d].append((case, run))
    clean = sum(1 for _, run in results if not run.defects)
    print(f"\nruns without a defect: {clean}\n", file=out)
    print(f"{'count':>6}  defect class", file=out)
    for name, items in sorted(by_class.items(), key=lambda kv: (-len(kv[1]), kv[0])):
        print(f"{len(items):6d}  {name}", file=out)
    print("\nreproducers (up to 3 per class):", file=out)
    for name, items in sorted(by_class.items(), key=lambda kv: (-len(kv[1]), kv[0])):
        print(f"\n== {name} ({len(items)})", file=out)
        # prefer the smallest specs: the simplest to read
        for case, run in sorted(items, key=lambda cr: (cr[0].heavy, len(cr[0].spec)))[:3]:
            where = _keep(case, run, keep) if keep is not None else None
            print(f"  [{case.kind}] {'; '.join(case.notes)}", file=out)
            print(f"    argv: {json.dumps(case.argv)}  exit {run.rc} ({run.status}, "
                  f"{run.seconds:.1f} s)", file=out)
            if where is not None:
                print(f"    spec: {where / 'spec.toml'}", file=out)
                print(f"    $ {reproducer(case, where.resolve())}", file=out)
            if run.exception:
                print(f"    {run.exception['type']}: {run.exception['message'][:200]}",
                      file=out)
                for frame in run.exception.get("innermost", run.exception["frames"][-4:]):
                    print(f"      {frame}", file=out)
            elif run.stderr.strip():
                lines = run.stderr.strip().splitlines()
                line = next((x for x in lines if "Warning" in x or "error" in x), lines[-1])
                print(f"    stderr: {line.strip()[:200]}", file=out)


def main(argv: list[str] | None = None) -> int:
    """Run the campaign from the command line."""
    parser = argparse.ArgumentParser(prog="python -m tests.fuzz.campaign",
                                     description=__doc__.split("\n\n")[0])
    parser.add_argument("--commands", type=int, default=100)
    parser.add_argument("--seed", type=int, default=0)
    parser.add_argument("--start", type=int, default=0, help="index of the first case")
    parser.add_argument("--timeout", type=float, default=60.0, help="seconds per command")
    parser.add_argument("--jobs", type=int, default=1, help="commands at a time (default 1)")
    parser.add_argument("--keep", type=Path, help="folder for reproducers and results.jsonl")
    parser.add_argument("--profile", choices=("full", "cheap"), default="full")
    parser.add_argument("--memory-gb", type=float, default=4.0,
                        help="address-space limit of each child, GB (0: none)")
    parser.add_argument("--quiet", action="store_true", help="no per-command progress line")
    parser.add_argument("--directed", action="store_true",
                        help="run the directed cases (known suspects) instead")
    args = parser.parse_args(argv)
    if args.directed:
        cases = directed_cases()
    else:
        cases = [make_case(args.seed, i, args.profile)
                 for i in range(args.start, args.start + args.commands)]
    keep = args.keep
    log = None
    if keep is not None:
        keep.mkdir(parents=True, exist_ok=True)
        log = (keep / "results.jsonl").open("w", encoding="utf-8")
    t0 = time.perf_counter()

    def progress(case: Case, run: Run, done: int) -> None:
        if log is not None:
            log.write(json.dumps({"case": case.name, "kind": case.kind, "notes": case.notes,
                                  "heavy": case.heavy, **run.as_dict()}) + "\n")
            log.flush()
        if not args.quiet:
            flag = ", ".join(run.defects)[:110] or "ok"
            print(f"[{done}/{len(cases)} {time.perf_counter() - t0:6.0f} s] {case.name} "
                  f"{case.kind} -> {run.rc} ({run.seconds:.1f} s) {flag}", file=sys.stderr,
                  flush=True)

    results = run_campaign(cases, timeout=args.timeout, jobs=max(1, args.jobs),
                           memory=int(args.memory_gb * 2**30), progress=progress)
    if log is not None:
        log.close()
    report(results, keep)
    print(f"\n{time.perf_counter() - t0:.0f} s", file=sys.stdout)
    return 0


if __name__ == "__main__":
    sys.exit(main())
