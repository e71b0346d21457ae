"""A straight-line program compiled to machine code with numba: one kernel per topology.

:class:`~.program.Tape` evaluates CasADi's algorithm of a program as numpy calls over arrays of
states, one array operation after another. :class:`Kernel` writes the same algorithm as scalar
Python over the states of a block and compiles it with numba (LLVM; no system compiler
needed): the arithmetic between two calls of the C library (sines, cosines, arc tangents) runs
as one loop over the block that the compiler turns into vector instructions, the calls as a
scalar loop of their own, and what one loop hands the next waits in a work array of the block
(:func:`kernel_source`). The design's numbers are the kernel's inputs, not constants of its
source: the designs of one topology — a sweep over dimensions — share one compiled kernel. The
operations are those of :class:`~.program.Tape`, each IEEE-rounded as numpy rounds it
(``fastmath`` off, no contraction into fused multiply-adds), so the two agree to rounding: bit
for bit where numpy calls the C library too, within an ulp where numpy has vector functions of
its own (``exp``, ``log``, ``pow``, ``atan2``, ``tan``, ``asin`` on some machines).

Compiled code is cached on disk (numba's cache, beside the generated source), keyed by the
source's hash: a design analysed again, in this process or the next, loads its kernel in
milliseconds instead of compiling it again (a few seconds). The folder is
:func:`cache_dir` (``BALANCER_CACHE_DIR`` overrides it); two processes compiling the same
kernel at once, or a folder that cannot be written, are not errors — the kernel is then
compiled in memory for this process alone. numba is imported only here, only when a kernel is
asked for (a long cycle analysis): ``balancer --help`` and an ``analyze`` of 360 angles never
import it. Where numba is missing or cannot compile a program, :func:`compile_kernel` returns
``None`` and the numpy tape runs instead. ``BALANCER_KERNELS=0`` turns kernels off.
"""

from __future__ import annotations

import contextlib
import hashlib
import importlib.util
import math
import os
import sys
import tempfile
import threading
from collections.abc import Callable
from functools import cache
from pathlib import Path
from typing import TYPE_CHECKING, Any

import numpy as np
from numpy.typing import ArrayLike, NDArray

if TYPE_CHECKING:  # annotations only: CasADi is imported where symbols are built
    import casadi as ca

#: The generated source's format: part of the cache key (a change here makes new kernels).
KERNEL_FORMAT = 5
#: Kernels kept in the cache folder (the least recently used go first): a design analysed at
#: length keeps its kernel (about 150 KB) until this many others are.
KEPT = 256
#: Environment variables: the cache folder, and ``0`` to turn kernels off.
CACHE_ENV = "BALANCER_CACHE_DIR"
SWITCH_ENV = "BALANCER_KERNELS"

_UNARY = {"SIN": "math.sin({a})", "COS": "math.cos({a})", "TAN": "math.tan({a})",
          "SQRT": "math.sqrt({a})", "EXP": "math.exp({a})", "LOG": "math.log({a})",
          "ATAN": "math.atan({a})", "ASIN": "math.asin({a})", "ACOS": "math.acos({a})",
          "TANH": "math.tanh({a})", "FABS": "abs({a})", "NEG": "(-{a})", "SQ": "({a} * {a})",
          "TWICE": "(2.0 * {a})", "INV": "(1.0 / {a})", "FLOOR": "np.floor({a})",
          "CEIL": "np.ceil({a})", "SIGN": "_sign({a})", "NOT": "(1.0 if {a} == 0.0 else 0.0)"}
_BINARY = {"ADD": "({a} + {b})", "SUB": "({a} - {b})", "MUL": "({a} * {b})",
           "DIV": "({a} / {b})", "ATAN2": "math.atan2({a}, {b})", "POW": "({a} ** {b})",
           "CONSTPOW": "({a} ** {b})", "FMIN": "_fmin({a}, {b})", "FMAX": "_fmax({a}, {b})",
           "LT": "(1.0 if {a} < {b} else 0.0)", "LE": "(1.0 if {a} <= {b} else 0.0)",
           "EQ": "(1.0 if {a} == {b} else 0.0)", "NE": "(1.0 if {a} != {b} else 0.0)",
           "AND": "(1.0 if {a} != 0.0 and {b} != 0.0 else 0.0)",
           "OR": "(1.0 if {a} != 0.0 or {b} != 0.0 else 0.0)", "HYPOT": "math.hypot({a}, {b})",
           "COPYSIGN": "math.copysign({a}, {b})", "FMOD": "np.fmod({a}, {b})",
           "IF_ELSE_ZERO": "({b} if {a} != 0.0 else 0.0)"}

#: numpy's ``fmin``/``fmax`` (a NaN loses) and ``sign``, in the generated module's scalars.
_HELPERS = '''
@numba.njit(inline="always")
def _fmin(a, b):
    return b if a != a else (a if b != b else (a if a < b else b))


@numba.njit(inline="always")
def _fmax(a, b):
    return b if a != a else (a if b != b else (a if a > b else b))


@numba.njit(inline="always")
def _sign(a):
    return a if a != a else (1.0 if a > 0.0 else (-1.0 if a < 0.0 else 0.0))
'''


@cache
def op_names() -> dict[int, str]:
    """CasADi's operation codes by name without the ``OP_`` prefix (``OP_SIN`` → ``SIN``)."""
    import casadi

    return {getattr(casadi, name): name[3:] for name in dir(casadi) if name.startswith("OP_")}


def _literal(value: float) -> str:
    """``value`` as Python source (``math``'s names for ±inf and NaN)."""
    if math.isfinite(value):
        return repr(value)
    return "math.nan" if math.isnan(value) else ("math.inf" if value > 0 else "-math.inf")


#: Operations that are calls of the C library (no vector form without fast, inexact maths):
#: each runs in a scalar loop of its own, between the loops of arithmetic.
_CALLS = frozenset({"SIN", "COS", "TAN", "EXP", "LOG", "ATAN", "ASIN", "ACOS", "TANH", "ATAN2",
                    "POW", "CONSTPOW", "HYPOT", "FMOD"})

#: States per block: the values one loop hands the next stay in the processor's cache.
BLOCK = 1024


def kernel_source(fn: ca.Function, checked: int = 0) -> tuple[str, NDArray[np.float64]]:
    """The source of a module whose ``run`` is ``fn``'s algorithm, and the constants it takes.

    ``run(constants, in_0, …, outs, limits, ok, n)``: each input ``in_k`` is ``(nnz_k, n)``;
    ``outs`` holds one array ``(n,)`` (any stride) per scalar output, in order, but the last
    ``checked``; ``ok[i]`` says that every output is finite at state ``i`` and each checked one
    is at most its entry of ``limits``.

    The algorithm's constants are the entries of ``constants``, in their order (a design's
    numbers: designs of one topology share the source, hence one compiled kernel), but a
    constant power's exponent, written where it is used. The states run in blocks of
    :data:`BLOCK`; within a block, the algorithm's operations run in loops over the block's
    states, one loop per stage: arithmetic, ``sqrt``, ``abs``, comparisons — operations the
    compiler turns into vector instructions — up to the next call of the C library
    (:data:`_CALLS`), then a scalar loop of the calls whose arguments are ready, and so on. A
    value that one loop hands another waits in a work array of the block; the rest stay in
    registers.
    """
    ops = op_names()
    n_in = fn.n_in()
    flat_out = [sum(fn.nnz_out(j) for j in range(o)) for o in range(fn.n_out())]
    n_flat = sum(fn.nnz_out(j) for j in range(fn.n_out()))
    if checked > n_flat or n_flat - checked < 1:
        raise NotImplementedError("a kernel writes at least one output")
    register: dict[int, tuple[str, Any]] = {}  # what a work register holds now
    stage: dict[int, int] = {}  # each operation's loop (even: arithmetic, odd: calls)
    operations: list[tuple[int, str, list[tuple[str, Any]]]] = []
    outputs: dict[int, tuple[str, Any]] = {}
    values: list[float] = []  # the constants, in their order
    for k in range(fn.n_instructions()):
        op = ops[fn.instruction_id(k)]
        ins, outs = fn.instruction_input(k), fn.instruction_output(k)
        if op == "INPUT":
            register[outs[0]] = ("input", f"in_{ins[0]}[{ins[1]}, i]")
        elif op == "CONST":
            values.append(float(fn.instruction_constant(k)))
            register[outs[0]] = ("constant", (len(values) - 1, values[-1]))
        elif op == "OUTPUT":
            outputs[flat_out[outs[0]] + outs[1]] = register[ins[0]]
        elif op == "ASSIGN":
            register[outs[0]] = register[ins[0]]
        elif op in _UNARY or op in _BINARY:
            args = [register[ins[0]]] + ([register[ins[1]]] if op in _BINARY else [])
            after = max([stage[a[1]] for a in args if a[0] == "value"], default=0)
            call = op in _CALLS
            stage[k] = after + (after % 2 == 0 if call else after % 2)
            operations.append((k, op, args))
            register[outs[0]] = ("value", k)
        else:
            raise NotImplementedError(f"CasADi operation {op} in a kernel")
    # The values a later loop (or the outputs) reads: a row of the work array each.
    handed = {a[1] for k, _, args in operations for a in args
              if a[0] == "value" and stage[a[1]] != stage[k]}
    handed |= {a[1] for a in outputs.values() if a[0] == "value"}
    row = {k: r for r, k in enumerate(sorted(handed))}

    def name(arg: tuple[str, Any], where: int | None) -> str:
        kind, what = arg
        if kind == "input":
            return str(what)
        if kind == "constant":
            return f"c{what[0]}"
        return f"v{what}" if stage[what] == where else f"w[{row[what] * BLOCK} + j]"

    lines = ["import math", "", "import numba", "import numpy as np", "", _HELPERS, "",
             "@numba.njit(cache=CACHE, nogil=True, error_model='numpy')",
             "def run(constants, " + "".join(f"in_{k}, " for k in range(n_in))
             + "outs, limits, ok, n):"]
    lines += [f"    c{c} = constants[{c}]" for c in range(len(values))]
    lines += [f"    w = np.empty({max(len(row), 1) * BLOCK})",
              f"    for start in range(0, n, {BLOCK}):",
              f"        size = min({BLOCK}, n - start)"]
    for loop in range(max(stage.values(), default=0) + 1):
        body = [(k, op, args) for k, op, args in operations if stage[k] == loop]
        if not body:
            continue
        lines += ["        for j in range(size):", "            i = start + j"]
        for k, op, args in body:
            a = name(args[0], loop)
            if op == "CONSTPOW" and args[1][0] == "constant":  # (an exponent of the form)
                b = _literal(args[1][1][1])
            else:
                b = name(args[1], loop) if len(args) > 1 else ""
            expression = (_UNARY[op].format(a=a) if op in _UNARY
                          else _BINARY[op].format(a=a, b=b))
            lines.append(f"            v{k} = {expression}")
            if k in row:
                lines.append(f"            w[{row[k] * BLOCK} + j] = v{k}")
    lines += ["        for j in range(size):", "            i = start + j"]
    for o in range(n_flat):
        lines.append(f"            o{o} = {name(outputs[o], None)}")
    for o in range(n_flat - checked):
        lines.append(f"            outs[{o}][i] = o{o}")
    total = " + ".join(f"o{o}" for o in range(n_flat))
    within = "".join(f" and o{n_flat - checked + q} <= limits[{q}]" for q in range(checked))
    lines += [f"            total = {total}",
              f"            ok[i] = total - total == 0.0{within}"]
    return "\n".join(lines) + "\n", np.array(values, dtype=float)


def cache_dir() -> Path:
    """Where compiled kernels are kept: ``$BALANCER_CACHE_DIR``, else the user's cache folder.

    (``$XDG_CACHE_HOME/balancer``, or ``~/.cache/balancer``; a ``kernels`` folder within.)
    """
    given = os.environ.get(CACHE_ENV)
    if given:
        return Path(given) / "kernels"
    base = os.environ.get("XDG_CACHE_HOME") or os.path.join(os.path.expanduser("~"), ".cache")
    return Path(base) / "balancer" / "kernels"


def prune(folder: Path, keep: str, most: int | None = None) -> None:
    """Remove the least recently used kernels beyond :data:`KEPT` (``most``) from ``folder``.

    Each kernel's source and numba's cached code of it go together; ``keep`` (a kernel's
    name) stays. Another process pruning, loading or writing at the same time is not an
    error: what cannot be removed stays.
    """
    most = KEPT if most is None else most
    try:
        sources = sorted(folder.glob("kernel_*.py"), key=lambda p: p.stat().st_mtime)
    except OSError:
        return
    for path in sources[: max(len(sources) - most, 0)]:
        if path.stem == keep:
            continue
        for old in (path, *(folder / "__pycache__").glob(f"{path.stem}.*")):
            with contextlib.suppress(OSError):
                old.unlink()


def enabled() -> bool:
    """Whether kernels may be used (``BALANCER_KERNELS`` is not ``0``) and numba is there."""
    if os.environ.get(SWITCH_ENV, "1").strip() == "0":
        return False
    return importlib.util.find_spec("numba") is not None


class Kernel:
    """``fn``'s algorithm compiled (see the module and :func:`kernel_source`).

    ``checked``: its last outputs that are checks, each to be at most a limit (see
    :meth:`__call__`).

    Raises
    ------
    NotImplementedError
        If the algorithm has an operation the kernel has no scalar counterpart for.
    ImportError
        If numba is not installed.
    """

    def __init__(self, fn: ca.Function, checked: int = 0) -> None:
        self.sizes_in = [fn.nnz_in(i) for i in range(fn.n_in())]
        self.size_out = sum(fn.nnz_out(j) for j in range(fn.n_out())) - checked
        self.checked = checked
        #: The source, and the design's numbers: the kernel's first argument.
        self.source, self.constants = kernel_source(fn, checked)
        digest = hashlib.sha256(f"{KERNEL_FORMAT}\n{self.source}".encode()).hexdigest()[:24]
        self.name = f"kernel_{digest}"
        self.cached = False
        try:
            with _COMPILE_LOCK:  # (a module half loaded by another thread is not used)
                self._run = self._load()
                self._compile()
        except Exception:  # noqa: BLE001 - a cache that cannot be read or written: in memory
            self.cached = False
            self._run = self._in_memory()
            self._compile()
    def _in_memory(self) -> Callable[..., None]:
        """The module's ``run`` compiled for this process alone (no disk cache)."""
        scope: dict[str, Any] = {}
        exec(compile(self._text(False), f"<{self.name}>", "exec"), scope)  # noqa: S102
        return scope["run"]

    def _load(self) -> Callable[..., None]:
        """The module's ``run`` from the cache folder (its compiled code cached by numba).

        The module is registered under its name (numba finds it again so when it loads the
        cached code).
        """
        if self.name in sys.modules:  # (loaded in this process already)
            self.cached = True
            return sys.modules[self.name].run
        folder = cache_dir()
        folder.mkdir(parents=True, exist_ok=True)
        path = folder / f"{self.name}.py"
        if not path.exists() or path.read_text(encoding="utf-8") != self._text(True):
            # Whole or not at all: another process may be reading or writing it now.
            fd, tmp = tempfile.mkstemp(dir=folder, prefix=f".{self.name}.", suffix=".tmp")
            with os.fdopen(fd, "w", encoding="utf-8") as f:
                f.write(self._text(True))
            os.replace(tmp, path)
            prune(folder, keep=self.name)
        else:
            with contextlib.suppress(OSError):
                os.utime(path)  # (used: the last to go when the folder is pruned)
        spec = importlib.util.spec_from_file_location(self.name, path)
        assert spec is not None and spec.loader is not None
        module = importlib.util.module_from_spec(spec)
        sys.modules[self.name] = module
        try:
            spec.loader.exec_module(module)
        except BaseException:
            del sys.modules[self.name]
            raise
        self.cached = True
        return module.run

    def _text(self, cache: bool) -> str:
        return f"CACHE = {cache}\n" + self.source

    def _compile(self) -> None:
        """Compile for its arguments' types now (or load the cached code)."""
        import numba

        floats = numba.types.Array(numba.float64, 1, "C")
        table = numba.types.Array(numba.float64, 2, "C")
        outs = numba.types.UniTuple(numba.types.Array(numba.float64, 1, "A"), self.size_out)
        signature = numba.void(floats, *([table] * len(self.sizes_in)), outs, floats,
                               numba.types.Array(numba.boolean, 1, "C"), numba.intp)
        with _COMPILE_LOCK:
            self._run.compile(signature)  # type: ignore[attr-defined]

    def __call__(self, inputs: list[NDArray[np.float64]], n: int,
                 into: list[NDArray[np.float64]] | None = None,
                 limits: ArrayLike = ()) -> tuple[list[NDArray[np.float64]], NDArray[np.bool_]]:
        """The outputs at ``n`` states, and where they are valid.

        ``inputs[i]`` is ``(nnz_i, n)`` (or broadcasts to it). Returns one array ``(n,)`` per
        scalar output but the checked ones — ``into``'s, if given (writable, any stride) —
        and ``ok``: where every output is finite and each checked one at most its entry of
        ``limits``.
        """
        if into is None:
            into = list(np.empty((self.size_out, n)))
        # (Its compiled loop does not check its indices: the sizes are checked here.)
        if len(into) != self.size_out or any(np.shape(o) != (n,) for o in into):
            raise ValueError(f"the kernel writes {self.size_out} outputs of {n} states")
        if len(inputs) != len(self.sizes_in) or any(
                np.shape(a)[0] != rows or np.shape(a)[1] not in (1, n)
                for a, rows in zip(inputs, self.sizes_in, strict=False)):
            raise ValueError(f"the kernel takes inputs of {self.sizes_in} rows by {n} states")
        # Its compiled signature takes C-ordered inputs: a broadcast one (a constant row) is
        # made whole.
        arrays = [np.require(_whole(np.asarray(a, dtype=float), n), requirements=("C", "W"))
                  for a in inputs]
        ok = np.empty(n, dtype=bool)
        bounds = np.ascontiguousarray(limits, dtype=float).reshape(-1)
        if bounds.size != self.checked:
            raise ValueError(f"the kernel checks {self.checked} outputs, not {bounds.size}")
        self._run(self.constants, *arrays, tuple(into), bounds, ok, n)
        return into, ok


def _whole(a: NDArray[np.float64], n: int) -> NDArray[np.float64]:
    """``a`` ``(rows, n)``: broadcast where it is not (a view: made whole by the caller)."""
    return a if a.shape[1:] == (n,) else np.broadcast_to(a, (a.shape[0], n))


#: One compilation at a time in this process (numba's compiler is not reentrant).
_COMPILE_LOCK = threading.RLock()


def compile_kernel(fn: ca.Function, checked: int = 0) -> Kernel | None:
    """``fn`` as a :class:`Kernel`, or ``None`` where it cannot be one.

    Where kernels are off, numba is missing, or it cannot compile the algorithm (an operation
    without a scalar counterpart, or numba's own failure): the numpy tape then runs, which
    gives the same figures.
    """
    if not enabled():
        return None
    try:
        return Kernel(fn, checked)
    except Exception:  # noqa: BLE001 - any failure to compile leaves the numpy route
        return None


__all__ = ["BLOCK", "CACHE_ENV", "KEPT", "SWITCH_ENV", "Kernel", "cache_dir", "compile_kernel",
           "enabled", "kernel_source", "op_names", "prune"]
