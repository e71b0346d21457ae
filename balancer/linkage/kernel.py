"""A straight-line program compiled to machine code: one loop over crank states, with numba.

:class:`~.program.Tape` evaluates CasADi's algorithm of a program as numpy calls over arrays of
states, one array operation after another. :class:`Kernel` writes the same algorithm as scalar
Python — each of CasADi's operations one assignment, in its order, inside one loop over the
states — and compiles it with numba (LLVM; no system compiler needed): every intermediate stays
in a register, each state costs its arithmetic alone. The operations are those of
:class:`~.program.Tape`, each IEEE-rounded as numpy rounds it (``fastmath`` off; ``math``'s
functions are the C library's, as numpy's are), so the two agree to rounding — in practice bit
for bit.

Compiled code is cached on disk (numba's cache, beside the generated source), keyed by the
source's hash: a design analysed again, in this process or the next, loads its kernel in
milliseconds instead of compiling it again (about a second). The folder is
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
from numpy.typing import NDArray

if TYPE_CHECKING:  # annotations only: CasADi is imported where symbols are built
    import casadi as ca

#: The generated source's format: part of the cache key (a change here makes new kernels).
KERNEL_FORMAT = 4
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


def kernel_source(fn: ca.Function) -> str:
    """Python source of a module whose ``run(in_0, …, out_0, …)`` is ``fn``'s algorithm.

    Each input ``in_k`` is ``(nnz_k, N)`` (it may broadcast: stride 0), each output ``out_j``
    ``(nnz_j, N)``; ``run`` loops over the ``N`` states. Constants are written where they are
    used (numba folds what they make constant).
    """
    n_in, n_out = fn.n_in(), fn.n_out()
    arguments = ", ".join([f"in_{k}" for k in range(n_in)] + [f"out_{j}" for j in range(n_out)])
    body: list[str] = []
    names: dict[int, str] = {}
    ops = op_names()
    for k in range(fn.n_instructions()):
        op = ops[fn.instruction_id(k)]
        ins, outs = fn.instruction_input(k), fn.instruction_output(k)
        if op == "INPUT":
            names[outs[0]] = f"in_{ins[0]}[{ins[1]}, i]"
            continue
        if op == "OUTPUT":
            body.append(f"out_{outs[0]}[{outs[1]}, i] = {names.get(ins[0], f'w{ins[0]}')}")
            continue
        if op == "CONST":
            names[outs[0]] = _literal(float(fn.instruction_constant(k)))
            continue
        a = names.get(ins[0], f"w{ins[0]}")
        if op == "ASSIGN":
            expression = a
        elif op in _UNARY:
            expression = _UNARY[op].format(a=a)
        elif op in _BINARY:
            expression = _BINARY[op].format(a=a, b=names.get(ins[1], f"w{ins[1]}"))
        else:
            raise NotImplementedError(f"CasADi operation {op} in a kernel")
        names.pop(outs[0], None)  # the register holds its own value from here on
        body.append(f"w{outs[0]} = {expression}")
    lines = ["import math", "", "import numba", "import numpy as np", "", _HELPERS, "",
             "@numba.njit(cache=CACHE, nogil=True, error_model='numpy')",
             f"def run({arguments}):",
             "    for i in range(out_0.shape[1]):" if n_out else "    pass"]
    lines += [f"        {line}" for line in body] if n_out else []
    return "\n".join(lines) + "\n"


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
    """``fn``'s algorithm compiled: called like :class:`~.program.Tape` (see the module).

    Raises
    ------
    NotImplementedError
        If the algorithm has an operation the kernel has no scalar counterpart for.
    ImportError
        If numba is not installed.
    """

    def __init__(self, fn: ca.Function) -> None:
        self.sizes_in = [fn.nnz_in(i) for i in range(fn.n_in())]
        self.sizes_out = [fn.nnz_out(i) for i in range(fn.n_out())]
        self.source = kernel_source(fn)
        digest = hashlib.sha256(f"{KERNEL_FORMAT}\n{self.source}".encode()).hexdigest()[:24]
        self.name = f"kernel_{digest}"
        self.cached = False
        try:
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
        """Compile for 2-D float arrays of any layout now (or load the cached code)."""
        import numba

        array = numba.types.Array(numba.float64, 2, "C")
        signature = numba.void(*([array] * (len(self.sizes_in) + len(self.sizes_out))))
        with _COMPILE_LOCK:
            self._run.compile(signature)  # type: ignore[attr-defined]

    def __call__(self, inputs: list[NDArray[np.float64]], n: int,
                 outs: list[NDArray[np.float64]] | None = None) -> list[NDArray[np.float64]]:
        """The outputs at ``n`` states: ``inputs[i]`` is ``(nnz_i, n)`` (or broadcasts to it).

        ``outs``, if given, receives them (arrays ``(nnz_j, n)``).
        """
        if outs is None:
            outs = [np.empty((m, n)) for m in self.sizes_out]
        # Its compiled signature takes C-ordered, writable arrays: a broadcast input (a constant
        # row) is made whole, an output that is a strided view is written through a copy.
        arrays = [np.require(np.broadcast_to(np.asarray(a, dtype=float), (a.shape[0], n)),
                             requirements=("C", "W")) for a in inputs]
        written = [np.require(o, requirements=("C", "W")) for o in outs]
        self._run(*arrays, *written)
        for o, w in zip(outs, written, strict=True):
            if w is not o:
                o[...] = w
        return outs


#: One compilation at a time in this process (numba's compiler is not reentrant).
_COMPILE_LOCK = threading.RLock()


def compile_kernel(fn: ca.Function) -> Kernel | None:
    """``fn`` as a :class:`Kernel`, or ``None`` where it cannot be one.

    Where kernels are off, numba is missing, or it cannot compile the algorithm (an operation
    without a scalar counterpart, or numba's own failure): the numpy tape then runs, which
    gives the same figures.
    """
    if not enabled():
        return None
    try:
        return Kernel(fn)
    except Exception:  # noqa: BLE001 - any failure to compile leaves the numpy route
        return None


__all__ = ["CACHE_ENV", "KEPT", "SWITCH_ENV", "Kernel", "cache_dir", "compile_kernel",
           "enabled", "kernel_source", "op_names", "prune"]
