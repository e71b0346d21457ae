"""The inverse dynamics of one design as a straight-line program over arrays of crank angles.

The equations of :mod:`.kinematics` and :mod:`.dynamics` are written once against
:class:`~.vectors.Ops`; evaluated on numpy arrays they run operation by operation through
Python, each making a temporary array, and recompute what several steps share (a link's
rotations, the constraints' Jacobians of the velocity and the force solves). Evaluated once on
CasADi's symbols for a single crank state, they become an expression graph that CasADi reduces
to a short algorithm (common subexpressions shared, structural zeros and constants folded,
registers reused). :class:`Tape` turns that algorithm into a Python function of numpy calls that
write into a fixed set of work arrays: the same arithmetic with a fraction of the operations and
no temporaries. CasADi's own virtual machine evaluates it one crank state at a time, which is
slower than numpy's loops over many.

:class:`CrankForcesProgram` is the program of :func:`~.dynamics.inverse_dynamics` (the
groups' route) of a linkage at crank states ``(θ1, ω1, α1)``. A numeric group (a Stephenson
triad) takes one Newton step from its continuation table's cubic (as the numpy route does) and
reports its residual: a state where it did not converge is left to the numpy route.
"""

from __future__ import annotations

import threading
from collections.abc import Callable
from typing import TYPE_CHECKING, Any

import numpy as np
from numpy.typing import ArrayLike, NDArray

from . import numeric
from .dynamics import Forces, inverse_dynamics
from .inputs import InputState
from .kernel import Kernel, compile_kernel, op_names
from .kinematics import Motion, numeric_start, positions, rates
from .structure import Structure
from .symbols import CasadiOps
from .vectors import Factor, Num, _is_zero, _minus, _times

if TYPE_CHECKING:  # annotations only: CasADi is imported where symbols are built
    import casadi as ca


_UNARY = {"SIN": "sin", "COS": "cos", "TAN": "tan", "SQRT": "sqrt", "NEG": "negative",
          "SQ": "square", "FABS": "absolute", "EXP": "exp", "LOG": "log", "ATAN": "arctan",
          "ASIN": "arcsin", "ACOS": "arccos", "FLOOR": "floor", "CEIL": "ceil",
          "NOT": "logical_not", "INV": "reciprocal", "SIGN": "sign", "TANH": "tanh"}
_BINARY = {"ADD": "add", "SUB": "subtract", "MUL": "multiply", "DIV": "divide",
           "ATAN2": "arctan2", "POW": "power", "CONSTPOW": "power", "FMIN": "fmin",
           "FMAX": "fmax", "LT": "less", "LE": "less_equal", "EQ": "equal",
           "NE": "not_equal", "AND": "logical_and", "OR": "logical_or",
           "COPYSIGN": "copysign", "HYPOT": "hypot", "FMOD": "fmod"}


class Tape:
    """A CasADi SX function's algorithm as numpy calls over arrays of its scalar inputs.

    Every input and output is a dense column vector of scalars; :meth:`__call__` takes each
    input as an ``(nnz, N)`` array and returns each output likewise, evaluating the
    algorithm on ``N`` states at once in blocks of :attr:`block` (so that its work arrays
    stay in the processor's cache). Constants are folded when the program is generated.

    Raises
    ------
    NotImplementedError
        If the algorithm has an operation numpy has no elementwise counterpart for.
    """

    #: States per block of the evaluation: its work arrays then stay in the processor's
    #: cache, and Python's share (a call per operation and block) stays small.
    block = 8192

    def __init__(self, fn: ca.Function) -> None:
        self.sizes_in = [fn.nnz_in(i) for i in range(fn.n_in())]
        self.sizes_out = [fn.nnz_out(i) for i in range(fn.n_out())]
        self.registers = fn.sz_w()
        self.source = _generate(fn)
        scope: dict[str, Any] = {"np": np}
        exec(compile(self.source, f"<tape {fn.name()}>", "exec"), scope)  # noqa: S102
        self._run: Callable[[list[NDArray[np.float64]], list[NDArray[np.float64]],
                             list[NDArray[np.float64]]], None] = scope["run"]

    def __call__(self, inputs: list[NDArray[np.float64]], n: int,
                 outs: list[NDArray[np.float64]] | None = None) -> list[NDArray[np.float64]]:
        """The outputs at ``n`` states: ``inputs[i]`` is ``(nnz_i, n)`` (or broadcasts to it).

        ``outs``, if given, receives them (arrays ``(nnz_j, n)``).
        """
        if outs is None:
            outs = [np.empty((m, n)) for m in self.sizes_out]
        size = max(min(self.block, n), 1)  # (no states: no block, nothing to do)
        work = [np.empty(size) for _ in range(self.registers)]
        with np.errstate(all="ignore"):
            for start in range(0, n, size):
                stop = min(start + size, n)
                if stop - start != size:
                    work = [w[: stop - start] for w in work]
                part_in = [np.broadcast_to(a, (a.shape[0], n))[:, start:stop] for a in inputs]
                part_out = [o[:, start:stop] for o in outs]
                self._run(work, part_in, part_out)
        return outs


def _generate(fn: ca.Function) -> str:
    """Python source of ``run(w, inputs, outs)``: ``fn``'s algorithm as numpy calls.

    A register that holds a constant or an input is not filled: its uses name the constant
    or the input's row instead, until an operation writes the register.
    """
    lines = ["def run(w, inputs, outs):"]
    lines.append("    " + ", ".join(f"w{r}" for r in range(fn.sz_w())) + ", = w"
                 if fn.sz_w() else "    pass")
    regs = _Registers()
    for k in range(fn.n_instructions()):
        op = op_names()[fn.instruction_id(k)]
        ins, outs = fn.instruction_input(k), fn.instruction_output(k)
        if op == "INPUT":
            regs.alias(outs[0], f"inputs[{ins[0]}][{ins[1]}]")
        elif op == "OUTPUT":
            lines.append(f"    outs[{outs[0]}][{outs[1]}] = {regs.name(ins[0])}")
        elif op == "CONST":
            regs.fix(outs[0], float(fn.instruction_constant(k)))
        elif op == "TWICE":
            _emit(lines, regs, "multiply", [ins[0]], outs[0], extra=2.0)
        elif op in _UNARY:
            _emit(lines, regs, _UNARY[op], [ins[0]], outs[0])
        elif op in _BINARY:
            _emit(lines, regs, _BINARY[op], [ins[0], ins[1]], outs[0])
        elif op == "IF_ELSE_ZERO":
            c, x = ins[0], ins[1]
            if c in regs.constant:
                if regs.constant[c] != 0:
                    regs.copy(x, outs[0], lines)
                else:
                    regs.fix(outs[0], 0.0)
            else:
                condition, value = regs.name(c), regs.name(x)
                regs.write(outs[0])
                lines.append(f"    w{outs[0]}[:] = np.where({condition} != 0, {value}, 0.0)")
        elif op == "ASSIGN":
            regs.copy(ins[0], outs[0], lines)
        else:
            raise NotImplementedError(f"CasADi operation {op} in a tape")
    return "\n".join(lines) + "\n"


class _Registers:
    """What each work register holds while the program is generated, in its order."""

    def __init__(self) -> None:
        self.constant: dict[int, float] = {}
        self.aliases: dict[int, str] = {}

    def name(self, r: int) -> str:
        """How the program names register ``r``'s value now."""
        if r in self.constant:
            return _literal(self.constant[r])
        return self.aliases.get(r, f"w{r}")

    def fix(self, r: int, value: float) -> None:
        self.aliases.pop(r, None)
        self.constant[r] = value

    def alias(self, r: int, expression: str) -> None:
        self.constant.pop(r, None)
        self.aliases[r] = expression

    def write(self, r: int) -> None:
        """Register ``r`` is written: it holds its own array from now on."""
        self.constant.pop(r, None)
        self.aliases.pop(r, None)

    def copy(self, source: int, r: int, lines: list[str]) -> None:
        """Register ``r`` takes ``source``'s value.

        An array is copied: ``source`` may be written before ``r`` is read.
        """
        if source in self.constant:
            self.fix(r, self.constant[source])
        elif source in self.aliases:  # an input: never written
            self.alias(r, self.aliases[source])
        elif source != r:
            self.write(r)
            lines.append(f"    w{r}[:] = w{source}")


def _literal(value: float) -> str:
    """``value`` as Python source: ``repr`` of a finite float, numpy's name of ±inf or NaN.

    CasADi folds ``1/0`` to a constant inf; ``repr`` writes it ``inf``, a name the program
    does not know.
    """
    if np.isfinite(value):
        return repr(value)
    return "np.nan" if np.isnan(value) else ("np.inf" if value > 0 else "-np.inf")


def _emit(lines: list[str], regs: _Registers, ufunc: str, ins: list[int], out: int,
          extra: float | None = None) -> None:
    """One elementwise operation into register ``out`` (folded when its inputs are constants)."""
    args = [regs.constant.get(r) for r in ins] + ([] if extra is None else [extra])
    if all(a is not None for a in args):
        with np.errstate(all="ignore"):
            regs.fix(out, float(getattr(np, ufunc)(*args)))
        return
    names = [regs.name(r) for r in ins] + ([] if extra is None else [_literal(extra)])
    regs.write(out)
    lines.append(f"    np.{ufunc}({', '.join(names)}, out=w{out})")


#: A pivot of the fixed order is accepted where no entry below it in its column is larger
#: than this many times it (threshold partial pivoting, as sparse LU codes do): the growth of
#: the elimination stays bounded; elsewhere the state is left to the numpy route's LU.
PIVOT_GROWTH = 4.0


class _FixedPivotOps(CasadiOps):
    """CasADi's functions with a dense remainder solved by LU in a fixed pivot order.

    The numpy route pivots per crank state (:class:`~.vectors._BatchLU`); a program cannot
    branch, and CasADi's symbolic QR costs four times the operations. So the order is the
    one partial pivoting takes at the reference state, and :attr:`health` collects, per
    elimination step and row below, ``|a_ip| − PIVOT_GROWTH·|a_pp|``: where all are ≤ 0 the
    order is a valid threshold pivoting.
    """

    def __init__(self, reference: Callable[[list[Num]], list[float]]) -> None:
        #: ``reference(entries)``: the symbols' values at the reference state, as floats.
        self.reference = reference
        self.health: list[Num] = []

    # An instance's factor (it needs the reference), where the other Ops' are static: this
    # class is only ever used through its instances.
    def factor(self, a: list[list[Num]]) -> Factor:  # type: ignore[override]
        return Factor(a, dense=self._solve)

    def _solve(self, block: list[list[Num]], columns: list[list[Num]]) -> list[list[Num]]:
        import casadi as ca  # heavy: only where symbols are built
        k = len(block)
        a = [list(row) for row in block]
        b = [list(row) for row in columns]
        values = self.reference([v for row in a for v in row])
        num = [list(values[i * k:(i + 1) * k]) for i in range(k)]
        inverse: list[Num] = []
        for p in range(k):
            best = max(range(p, k), key=lambda i: abs(num[i][p]))
            for rows in (a, b, num):
                rows[p], rows[best] = rows[best], rows[p]
            inverse.append(1.0 / a[p][p])
            for i in range(p + 1, k):
                if _is_zero(a[i][p]):
                    continue
                self.health.append(ca.fabs(a[i][p]) - PIVOT_GROWTH * ca.fabs(a[p][p]))
                m = a[i][p] * inverse[p]
                for j in range(p + 1, k):
                    a[i][j] = _minus(a[i][j], _times(m, a[p][j]))
                    num[i][j] -= num[i][p] / num[p][p] * num[p][j]
                for j in range(len(b[i])):
                    b[i][j] = _minus(b[i][j], _times(m, b[p][j]))
        x: list[list[Num]] = [[0.0] * len(b[0]) for _ in range(k)]
        for p in reversed(range(k)):
            for j in range(len(b[p])):
                acc = b[p][j]
                for c in range(p + 1, k):
                    acc = _minus(acc, _times(a[p][c], x[c][j]))
                x[p][j] = _times(acc, inverse[p])
        return x


class CrankForcesProgram:
    """:func:`~.dynamics.inverse_dynamics` of a linkage's own design as a :class:`Tape`.

    Built once per linkage, loads and gravity (a fraction of a second); then
    :meth:`evaluate` gives the same :class:`~.dynamics.Forces` as the numpy route at any crank
    states, to rounding.
    """

    def __init__(self, structure: Structure, *, loads: bool, gravity: tuple[float, float]) -> None:
        import casadi as ca  # heavy: only where symbols are built
        self.structure = s = structure
        theta1, omega1, alpha1 = (ca.SX.sym(n) for n in ("theta1", "omega1", "alpha1"))
        self.numeric = [i for i, g in enumerate(s.groups) if g.kind == "numeric"]
        sizes = [3 * len(s.groups[i].links) for i in self.numeric]
        guess = ca.SX.sym("guess", sum(sizes))
        starts = np.cumsum([0, *sizes])
        guesses = {i: [guess[j] for j in range(a, b)]
                   for i, a, b in zip(self.numeric, starts[:-1], starts[1:], strict=True)}
        gas = ca.SX.sym("gas", len(s.prisms))
        inputs = [theta1, omega1, alpha1, guess, gas]
        q_ref = s.reference_coordinates()
        guess_ref: list[ArrayLike] = [[q_ref[3 * k + j] for k in s.groups[i].links
                                       for j in range(3)] for i in self.numeric]
        at_reference = [s.ref_angle[s.input], 1.0, 0.0,
                        np.concatenate(guess_ref or [np.zeros(0)]), np.zeros(len(s.prisms))]

        def reference(entries: list[Num]) -> list[float]:
            probe = ca.Function("probe", inputs, [ca.vertcat(*[ca.SX(e) for e in entries])])
            return [float(v) for v in np.asarray(probe(*at_reference)).ravel()]

        ops = _FixedPivotOps(reference)
        residuals: list[Num] = []
        steps: list[Num] = []
        gaps: list[Num] = []
        state = InputState.symbolic([theta1], [omega1], [alpha1])
        pose = positions(s, state, ops, gaps=gaps, guesses=guesses, residuals=residuals,
                         steps=steps)
        vel, rate, acc, accel = rates(s, pose, state, ops)
        mo = Motion(state=state, pose=pose, velocity=tuple(vel), rate=tuple(rate),
                    acceleration=tuple(acc), accel=tuple(accel))
        forces = inverse_dynamics(s, mo, gravity=gravity, loads=loads, ops=ops,
                                  gas=[gas[j] for j in range(len(s.prisms))])
        self.forces = forces  # the names, in :meth:`Forces.arrays`' order
        entries = forces.arrays()
        # Checks (CHECKS): the groups' residuals (≤ the numpy route's tolerance), their angle
        # steps (≤ TAYLOR_STEP), the pivots' health (≤ 0), the dyads' gaps (≥ TOGGLE_GAP).
        entries += [_largest([ca.fabs(r) for r in residuals]),
                    _largest([ca.fabs(d) for d in steps]), _largest(ops.health),
                    _largest([-g for g in gaps])]
        #: The program as CasADi's function (its algorithm: :class:`Tape`, a compiled kernel).
        self.function = ca.Function("crank_forces", inputs,
                                    [ca.cse(ca.vertcat(*[ca.SX(e) for e in entries]))])
        self.tape = Tape(self.function)
        self.loads = loads
        self._kernel: list[Kernel | None] = []  # compiled when a long evaluation first asks

    @property
    def kernel(self) -> Kernel | None:
        """The program compiled (:mod:`.kernel`), or ``None`` where it cannot be (built once).

        The kernel compares the :data:`CHECKS` with their limits itself.
        """
        with _KERNEL_LOCK:
            if not self._kernel:
                self._kernel.append(compile_kernel(self.function, checked=len(CHECKS)))
            return self._kernel[0]

    def evaluate(self, theta1: NDArray[np.float64], omega1: NDArray[np.float64],
                 alpha1: NDArray[np.float64], *, compiled: bool = False,
                 into: Forces | None = None) -> tuple[Forces, NDArray[np.bool_]]:
        """The forces at crank states (arrays ``(N,)``) and where they are the numpy route's.

        ``compiled``: by the compiled :attr:`kernel` where there is one (the same figures as
        the tape's, to rounding), else by the numpy :class:`Tape`. ``into``: forces whose
        arrays ``(N, 1)`` (writable views, any stride) receive the figures of the program's
        names (:meth:`Forces.matching`), and are returned; the kernel writes them there
        directly.

        A state is left out (``False``) where a numeric group's Newton step did not converge
        to the numpy route's tolerance or the group cannot be placed there, where a dyad is
        within :data:`TOGGLE_GAP` of a toggle, and where any figure is not finite: its forces
        are then to be computed by the numpy route. (CasADi folds ``0·x`` to 0, so a figure
        that is structurally zero, such as the couple of a piston whose centre of mass is on
        its guide, stays 0 where the numpy route's ``0·NaN`` is NaN: outside the assembly
        range, or at a non-finite input.)
        """
        s = self.structure
        n = theta1.size
        ok = np.ones(n, dtype=bool)
        target = None if into is None else into.matching(self.forces)
        limits = (numeric.NEWTON_TOLERANCE * s.length_scale(), numeric.TAYLOR_STEP, 0.0,
                  -TOGGLE_GAP)
        kernel = self.kernel if compiled else None
        block = n if kernel is not None else Tape.block  # (the tape: its work arrays cached)
        rows = (list(np.empty((self.tape.sizes_out[0] - len(CHECKS), n))) if target is None
                else [a[:, 0] for a in target.arrays()])
        for a in range(0, n, max(block, 1)):
            b = min(a + block, n)
            theta = theta1[a:b]
            guesses = []
            for i in self.numeric:
                guess, inside = numeric_start(s, s.groups[i], theta)
                ok[a:b] &= inside
                guesses.append(np.where(np.isfinite(guess), guess, 0.0).T)
            guess = np.concatenate(guesses) if guesses else np.zeros((0, 1))
            gas = [np.asarray(s.linkage.sliders[c.slider].force.at(theta), dtype=float)
                   * np.ones(b - a) if self.loads else np.zeros(b - a) for c in s.prisms]
            gas_in = np.array(gas) if gas else np.zeros((0, 1))
            inputs = [theta[None, :], omega1[None, a:b], alpha1[None, a:b], guess, gas_in]
            if kernel is not None:
                _, valid = kernel(inputs, b - a, [r[a:b] for r in rows], limits)
                ok[a:b] &= valid
                continue
            out = self.tape(inputs, b - a)[0]
            for r, figure in zip(rows, out, strict=False):
                r[a:b] = figure
            checks = out[-len(CHECKS):]
            # (Every figure finite: their sum is, the figures being far below overflow.)
            ok[a:b] &= (np.all(checks <= np.array(limits)[:, None], axis=0)
                        & np.isfinite(out.sum(axis=0)))
        forces = self.forces.with_arrays([r[:, None] for r in rows]) if into is None else into
        return forces, ok


#: The program's last outputs, checks each at most its limit: the groups' largest residual
#: (≤ the numpy route's Newton tolerance), their largest angle step (≤ ``TAYLOR_STEP``), the
#: pivots' health (≤ 0), the dyads' least gap, negated (≤ −:data:`TOGGLE_GAP`).
CHECKS = ("closure", "step", "health", "toggle")
#: Least assembly gap of the dyads (a squared sine of a transmission angle,
#: :meth:`~.dyads.Dyads.rrr`) at which the program's figures are taken: nearer a toggle the
#: general core's solves lose digits as about ε/gap^1.65 (measured on a four-bar at its change
#: point: 1e-12 of the closed forms' at a gap of 1e-2, 2e-9 at 1e-4, 2e-6 at 1e-6), so that a
#: state there is left to the numpy route — a four-bar's closed forms, which take the toggle's
#: limit exactly. (A transmission angle of 1.8°: never in a working mechanism.)
TOGGLE_GAP = 1e-3

#: One compilation of a program's kernel at a time (a cycle analysis runs chunks on threads).
_KERNEL_LOCK = threading.Lock()

__all__ = ["CrankForcesProgram", "Tape"]


def _largest(values: list[Num]) -> ca.SX:
    """The largest of ``values`` (symbols), or −1 for none."""
    import casadi as ca  # heavy: only where symbols are built
    out = ca.SX(-1.0)
    for v in values:
        out = ca.fmax(out, v)
    return out
