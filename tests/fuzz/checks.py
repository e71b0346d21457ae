"""Run one fuzz case through ``balancer.cli.main`` and classify what happened.

Shared by the campaign (:mod:`tests.fuzz.campaign`, one child process per case) and the
hypothesis tests (in-process). A run is classified by its exit code and by a list of defects,
each a short class name (the campaign groups runs by it).
"""

from __future__ import annotations

import contextlib
import ctypes
import hashlib
import io
import json
import math
import os
import re
import shlex
import signal
import sys
import tempfile
import traceback
import warnings
from dataclasses import asdict, dataclass, field
from pathlib import Path
from typing import Any

from .generate import SPEC, Case

#: Fields DESIGN.md fixes in each verb's ``--json`` document.
FIGURES = ("shaking_force", "shaking_moment", "driving_torque")


def _missing_fields(verb: str, doc: Any, argv: tuple[str, ...]) -> list[str]:
    """The fixed fields absent from (or malformed in) a ``--json`` document."""
    missing: list[str] = []
    if not isinstance(doc, dict):
        return ["<not an object>"]

    def figures(d: Any, where: str) -> None:
        for name in FIGURES:
            item = d.get(name) if isinstance(d, dict) else None
            for k in ("rms", "max"):
                if not isinstance(item, dict) or not _is_number(item.get(k)):
                    missing.append(f"{where}{name}.{k}")

    if verb == "analyze":
        figures(doc, "")
    elif verb == "simulate":
        for state in ("initial", "final"):
            for k in ("theta", "omega", "alpha"):
                v = doc.get(state, {}).get(k) if isinstance(doc.get(state), dict) else None
                ok = isinstance(v, list) and len(v) == 3 and all(map(_is_number, v))
                ok = ok or (isinstance(v, dict) and v and all(map(_is_number, v.values())))
                if not ok:
                    missing.append(f"{state}.{k}")
    elif verb == "optimize":
        for part in ("before", "after"):
            figures(doc.get(part), f"{part}.")
        links = doc.get("links")
        if not isinstance(links, dict) or not links:
            missing.append("links")
        else:
            for name, link in links.items():
                if not isinstance(link, dict) or "counter_rotor" not in link:
                    missing.append(f"links.{name}.counter_rotor")
        if "status" not in doc:
            missing.append("status")
        ver = doc.get("verification", "<absent>")
        if ver == "<absent>":
            missing.append("verification")
        elif ver is None:
            if "--no-verify" not in argv:
                missing.append("verification (null without --no-verify)")
        else:
            for k in ("max_shaking_force", "max_shaking_moment"):
                if not isinstance(ver, dict) or not _is_number(ver.get(k)):
                    missing.append(f"verification.{k}")
    elif verb == "verify":
        for k in ("max_shaking_force", "max_shaking_moment"):
            if not _is_number(doc.get(k)):
                missing.append(k)
    return missing


def _is_number(v: Any) -> bool:
    return isinstance(v, int | float) and not isinstance(v, bool) and math.isfinite(v)


def _reject_constant(name: str) -> Any:
    raise ValueError(f"non-finite JSON constant {name}")


def strict_json(text: str) -> tuple[Any, str | None]:
    """Parse ``text``; the error class (``json-nan``, ``json-invalid``) or ``None``."""
    try:
        return json.loads(text, parse_constant=_reject_constant), None
    except ValueError as exc:
        if "non-finite" in str(exc):
            return None, "NaN/Infinity in --json output"
        return None, "invalid JSON on stdout"


# ----------------------------------------------------------------------------------------------
# Files


def snapshot(folder: str | os.PathLike[str]) -> dict[str, str]:
    """Every entry under ``folder``: relative path -> content hash (``<dir>`` for folders)."""
    root = Path(folder)
    out: dict[str, str] = {}
    for dirpath, dirnames, filenames in os.walk(root):
        for d in dirnames:
            out[str((Path(dirpath) / d).relative_to(root))] = "<dir>"
        for f in filenames:
            p = Path(dirpath) / f
            try:
                out[str(p.relative_to(root))] = hashlib.sha256(p.read_bytes()).hexdigest()
            except OSError:
                out[str(p.relative_to(root))] = "<unreadable>"
    return out


# ----------------------------------------------------------------------------------------------
# Privileges: a read-only folder must be read-only for root too


class _CapHeader(ctypes.Structure):
    _fields_ = [("version", ctypes.c_uint32), ("pid", ctypes.c_int)]


class _CapData(ctypes.Structure):
    _fields_ = [("effective", ctypes.c_uint32), ("permitted", ctypes.c_uint32),
                ("inheritable", ctypes.c_uint32)]


#: CAP_DAC_OVERRIDE, CAP_DAC_READ_SEARCH, CAP_FOWNER.
_DAC_BITS = (1 << 1) | (1 << 2) | (1 << 3)


def _capabilities() -> tuple[Any, Any, Any] | None:
    try:
        libc = ctypes.CDLL(None, use_errno=True)
        header = _CapHeader(0x20080522, 0)
        data = (_CapData * 2)()
        if libc.capget(ctypes.byref(header), data) != 0:
            return None
        return libc, header, data
    except (OSError, AttributeError):
        return None


def drop_dac_override() -> None:
    """Drop root's power to ignore file modes for good (in a child process)."""
    caps = _capabilities() if os.geteuid() == 0 else None
    if caps is not None:
        libc, header, data = caps
        data[0].effective &= ~_DAC_BITS
        libc.capset(ctypes.byref(header), data)


@contextlib.contextmanager
def without_dac_override():
    """Drop root's power to ignore file modes for the calling thread (restored after).

    As root a folder of mode 555 is still writable; dropping CAP_DAC_OVERRIDE from the
    effective set makes the read-only folder and the unreadable spec behave as for a user.
    """
    caps = _capabilities() if os.geteuid() == 0 else None
    if caps is None:
        yield
        return
    libc, header, data = caps
    saved = data[0].effective
    data[0].effective &= ~_DAC_BITS
    changed = libc.capset(ctypes.byref(header), data) == 0
    try:
        yield
    finally:
        if changed:
            data[0].effective = saved
            libc.capset(ctypes.byref(header), data)


# ----------------------------------------------------------------------------------------------
# One run


@dataclass
class Run:
    """What one command did."""

    argv: tuple[str, ...]
    rc: int | None = None
    status: str = "exit"  # exit, exception, timeout, signal, no-result
    stdout: str = ""
    stderr: str = ""
    seconds: float = 0.0
    exception: dict[str, Any] | None = None
    reload_error: str | None = None
    spec_changed: bool = False
    new_entries: list[str] = field(default_factory=list)
    changed_entries: list[str] = field(default_factory=list)
    defects: list[str] = field(default_factory=list)

    def as_dict(self) -> dict[str, Any]:
        d = asdict(self)
        d["stdout"] = self.stdout[:2000]
        d["stderr"] = self.stderr[-4000:]
        return d


def _frames(tb) -> list[tuple[str, int, str]]:
    return [(f.filename, f.lineno or 0, f.name) for f in traceback.extract_tb(tb)]


def _short(filename: str) -> str:
    parts = Path(filename).parts
    for i in range(len(parts) - 1, -1, -1):
        if parts[i] == "balancer" and i + 1 < len(parts) and not any(
                p in ("site-packages", "tests") for p in parts[i + 1:]):
            return "/".join(parts[i:])
    return "/".join(parts[-2:])


def _is_balancer(filename: str) -> bool:
    parts = Path(filename).parts
    return "balancer" in parts and "tests" not in parts and "site-packages" not in parts


def exception_info(exc: BaseException) -> dict[str, Any]:
    """Type, message and frames of an uncaught exception; the class key of the defect."""
    frames = _frames(exc.__traceback__)
    ours = [f for f in frames if _is_balancer(f[0])]
    where = ours[-1] if ours else (frames[-1] if frames else ("?", 0, "?"))
    kind = type(exc).__name__
    for base in type(exc).__mro__[1:]:
        if base.__module__ == "builtins" and base.__name__ in ("MemoryError", "ValueError",
                                                              "OverflowError", "IndexError"):
            if base.__name__ not in kind:
                kind = f"{kind}({base.__name__})"
            break
    inner = ours[-3:] + ([frames[-1]] if frames and frames[-1] not in ours[-3:] else [])
    return {
        "type": kind,
        "message": str(exc)[:500],
        "where": f"{_short(where[0])}:{where[1]}",
        "frames": [f"{_short(f)}:{line} {name}" for f, line, name in frames[-8:]],
        "innermost": [f"{_short(f)}:{line} {name}" for f, line, name in inner],
    }


def execute(argv: tuple[str, ...], *, passthrough: tuple[type[BaseException], ...] = ()
            ) -> tuple[int, dict[str, Any] | None]:
    """``main(argv)`` as the interpreter would run it: exit code and any uncaught exception."""
    from balancer.cli import main

    try:
        rc = main(list(argv))
    except passthrough:
        raise
    except SystemExit as exc:  # --help
        code = exc.code
        if code is None:
            return 0, None
        if isinstance(code, int):
            return code, None
        print(code, file=sys.stderr)
        return 1, None
    except BaseException as exc:  # noqa: BLE001 - what the interpreter would print
        traceback.print_exc(file=sys.stderr)
        return 1, exception_info(exc)
    if not isinstance(rc, int) or isinstance(rc, bool):
        return 1, {"type": "bad-return", "message": repr(rc), "where": "balancer/cli.py",
                   "frames": []}
    return rc, None


def reload_written_spec(path: Path) -> str | None:
    """Whether a spec written by ``optimize --out`` reads back; the error, if not."""
    from balancer.errors import BalancerError
    from balancer.spec import load_design

    try:
        load_design(path)
    except BalancerError as exc:
        return f"{type(exc).__name__}: {exc}"
    except Exception as exc:  # noqa: BLE001
        return f"{type(exc).__name__}: {exc}"
    return None


def _output_of(argv: tuple[str, ...], option: str) -> str | None:
    if option in argv:
        i = argv.index(option)
        if i + 1 < len(argv):
            return argv[i + 1]
    return None


_NAN_WORD = re.compile(r"(?<![\w.])[-+]?(nan|inf|infinity)(?![\w])", re.IGNORECASE)
_FIGURE_EXT = (".png", ".svg", ".pdf")
_ANIMATION_EXT = (".gif", ".mp4")


def classify(case: Case, run: Run, before: dict[str, str], after: dict[str, str],
             folder: Path) -> list[str]:
    """The defect classes of a finished run (also stored in ``run.defects``)."""
    d: list[str] = []
    argv = case.argv
    if run.status == "timeout":
        d.append("hang (timeout)" + (" [absurd size on purpose]" if case.heavy else ""))
    elif run.status == "signal":
        d.append(f"killed by a signal ({run.rc})")
    elif run.status == "no-result":
        d.append("child ended without a result")
    if run.exception is not None:
        d.append(f"traceback {run.exception['type']} @ {run.exception['where']}")
    rc = run.rc
    done = run.status in ("exit", "exception")
    if done and rc not in (0, 1, 2):
        d.append(f"exit code {rc} (not 0/1/2)")
    if "Traceback" in run.stderr and run.exception is None:
        d.append("'Traceback' in stderr")
    # Besides its one error line, a command may say what it wrote ('wrote PATH') and note a
    # unit that looks wrong ('balancer: note: …'), on failure as on success.
    lines = [line for line in run.stderr.splitlines() if line.strip()
             and not line.startswith(("wrote ", "balancer: note: "))]
    if done and rc != 0:
        if run.exception is None and (len(lines) != 1 or not lines[0].startswith("balancer")):
            d.append("stderr not exactly one line on failure")  # (every traceback is too)
        if run.stdout.strip():
            d.append("stdout written on failure")
        if (rc == 2 and case.kind.startswith(("spec/", "text/")) and SPEC not in run.stderr
                and len(lines) == 1 and "--" not in lines[0]):
            d.append("exit-2 message does not name the spec file")
    if done and rc == 0 and lines:
        d.append("stderr output on success")
    if done and case.expect is not None and rc not in case.expect and rc in (0, 1, 2):
        family = case.kind.split("/")[0]
        if family == "cmd" or family == "odd":
            what = "; ".join(case.notes) or case.kind
        else:
            what = case.kind
        d.append(f"exit {rc}, expected {'/'.join(map(str, sorted(case.expect)))}: {what}")
    # stdout
    is_help = "--help" in argv or "-h" in argv
    if done and rc == 0 and not is_help and case.verb in ("analyze", "simulate", "optimize",
                                                          "verify"):
        if "--json" in argv:
            doc, error = strict_json(run.stdout)
            if error:
                d.append(error)
            elif doc is not None:
                missing = _missing_fields(case.verb, doc, argv)
                if missing:
                    d.append(f"JSON missing fixed fields ({case.verb})")
        elif _NAN_WORD.search(run.stdout):
            d.append("nan/inf in the text report")
    # files
    if run.spec_changed:
        d.append("input spec changed")
    new = list(run.new_entries)
    temps = [e for e in new if Path(e).name.startswith(".")]
    if temps:
        d.append("leftover temporary files")
    if done and rc != 0 and [e for e in new if e not in temps]:
        d.append("partial output after a failure")
    if done and rc == 0 and not is_help:
        d += _success_outputs(case, run, new, folder)
    run.defects = d
    return d


def _success_outputs(case: Case, run: Run, new: list[str], folder: Path) -> list[str]:
    d: list[str] = []
    argv = case.argv
    for option in ("--csv", "--out", "--plot", "--animate"):
        value = _output_of(argv, option)
        if value is None:
            continue
        if value == "":
            d.append(f"{option} '' silently ignored")
            continue
        path = folder / value
        ext = Path(value).suffix.lower()
        if option == "--plot":
            stem = path.with_suffix("") if ext in (".png", ".svg") else path
            written = [p for p in (stem.with_suffix(".png"), stem.with_suffix(".svg"),
                                   path) if p.exists()]
            if not written:
                d.append("--plot: nothing written on success")
            if ext not in _FIGURE_EXT:
                d.append(f"--plot {ext or 'no extension'} accepted (DESIGN: exit 2)")
            elif not path.exists():
                d.append(f"--plot {ext}: the named file was not written")
            continue
        if option == "--animate" and ext not in _ANIMATION_EXT:
            d.append(f"--animate {ext or 'no extension'} accepted (DESIGN: exit 2)")
        if not path.is_file():
            d.append(f"{option}: output missing after success")
            continue
        if option in ("--csv", "--out"):
            try:
                text = path.read_text(encoding="utf-8")
            except (OSError, UnicodeDecodeError):
                continue
            if _NAN_WORD.search(text):
                d.append(f"nan/inf in the {option} file")
    if run.reload_error is not None:
        d.append("optimize --out wrote a spec that does not load")
    return d


def finish_run(case: Case, run: Run, before: dict[str, str], folder: Path) -> Run:
    """Compare the work folder with its snapshot and classify."""
    after = snapshot(folder)
    run.spec_changed = before.get(SPEC) != after.get(SPEC)
    run.new_entries = sorted(set(after) - set(before))
    run.changed_entries = sorted(k for k in before if k in after and before[k] != after[k])
    classify(case, run, before, after, folder)
    return run


# ----------------------------------------------------------------------------------------------
# In-process runs (the hypothesis tests)


class Hang(BaseException):
    """Raised by the in-process watchdog."""


@contextlib.contextmanager
def _watchdog(seconds: float):
    def fire(signum, frame):
        raise Hang(f"no answer within {seconds} s")

    old = signal.signal(signal.SIGALRM, fire)
    signal.setitimer(signal.ITIMER_REAL, seconds)
    try:
        yield
    finally:
        signal.setitimer(signal.ITIMER_REAL, 0)
        signal.signal(signal.SIGALRM, old)


@contextlib.contextmanager
def _captured_fds():
    """Capture fd 1 and 2 (C libraries such as IPOPT write there) into temporary files."""
    files = [tempfile.TemporaryFile(), tempfile.TemporaryFile()]
    saved = [os.dup(1), os.dup(2)]
    result = {"out": "", "err": ""}
    try:
        for fd, f in zip((1, 2), files, strict=True):
            os.dup2(f.fileno(), fd)
        yield result
    finally:
        for fd, s in zip((1, 2), saved, strict=True):
            os.dup2(s, fd)
            os.close(s)
        for key, f in zip(("out", "err"), files, strict=True):
            f.seek(0)
            result[key] = f.read().decode("utf-8", "replace")
            f.close()


def run_inprocess(case: Case, folder: Path, timeout: float = 30.0) -> Run:
    """Run ``case`` in this process from its prepared ``folder`` and classify it."""
    before = snapshot(folder)
    run = Run(argv=case.argv)
    out, err = io.StringIO(), io.StringIO()
    cwd = os.getcwd()
    import time

    start = time.perf_counter()
    try:
        os.chdir(folder)
        with contextlib.ExitStack() as stack:
            fds = stack.enter_context(_captured_fds())
            stack.enter_context(contextlib.redirect_stdout(out))
            stack.enter_context(contextlib.redirect_stderr(err))
            stack.enter_context(warnings.catch_warnings())
            warnings.simplefilter("default")  # as the interpreter shows them: on stderr

            def show(message, category, filename, lineno, file=None, line=None):
                err.write(warnings.formatwarning(message, category, filename, lineno, line))

            warnings.showwarning = show
            stack.enter_context(without_dac_override())
            stack.enter_context(_watchdog(timeout))
            try:
                run.rc, run.exception = execute(case.argv, passthrough=(Hang,))
                run.status = "exception" if run.exception else "exit"
            except Hang:
                run.status = "timeout"
        run.stdout = out.getvalue() + fds["out"]
        run.stderr = err.getvalue() + fds["err"]
        if run.rc == 0 and case.verb == "optimize":
            target = _output_of(case.argv, "--out")
            if target and (folder / target).is_file():
                run.reload_error = reload_written_spec(folder / target)
    finally:
        os.chdir(cwd)
    run.seconds = time.perf_counter() - start
    return finish_run(case, run, before, folder)


def reproducer(case: Case, folder: str | os.PathLike[str]) -> str:
    """A shell line that reruns ``case`` from a prepared ``folder``."""
    return f"cd {shlex.quote(str(folder))} && balancer {shlex.join(case.argv)}"
