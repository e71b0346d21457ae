"""A second-order cone program in numbers, handed to Clarabel as it is.

The convex balancing problem (:mod:`.convex`) is small (tens of variables, a few dozen cone
rows) and its data are already numbers: the bounds as :class:`~.certificate.Constraint`
``M·u + m ∈ K``, force balance as ``E·u = r``, the objective a norm or a sum of squares of an
affine map. Clarabel solves it in about a millisecond; CVXPY's canonicalisation of the same
program took 30–40 ms per solve. So the program is assembled here once, in Clarabel's standard
form (its documented Python interface: ``DefaultSolver(P, q, A, b, cones, settings)``)

    minimise ½·yᵀ·H·y + hᵀ·y  subject to  A·y + s = b,  s ∈ K,

with ``y = u`` (or ``(u, t)`` in epigraph form), equalities first (the zero cone), then the
bounds (nonnegative rows), then the second-order cones, each constraint as ``A = −M``,
``b = m``: ``s = M·u + m``. Clarabel's dual ``z ∈ K*`` then satisfies
``H·y + h = Σ Mᵀ·z``: each constraint's multiplier in the convention of the Lagrangian
``f − Σ zᵀ·(M·u + m)``, which :mod:`.certificate` uses. CVXPY stays the tests' independent
route to the same optimum (``tests/balance/test_conic.py``) and builds the rarely solved
programs of the infeasibility diagnosis.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

import numpy as np
from numpy.typing import NDArray

from .certificate import Constraint

#: Clarabel's statuses in CVXPY's words (what the reports have always said).
STATUS: dict[str, str] = {
    "Solved": "optimal",
    "AlmostSolved": "optimal_inaccurate",
    "PrimalInfeasible": "infeasible",
    "AlmostPrimalInfeasible": "infeasible_inaccurate",
    "DualInfeasible": "unbounded",
    "AlmostDualInfeasible": "unbounded_inaccurate",
    "MaxIterations": "user_limit",
    "MaxTime": "user_limit",
}
#: The statuses whose point is a solution.
SOLVED = ("optimal", "optimal_inaccurate")
#: Largest entry of an objective's data (Hessian, linear term) that Clarabel is given as it
#: is; an objective with a larger one is divided by it (the point is the same, the
#: multipliers are multiplied back). Those of the balancing problems are of order one, in
#: scaled units, unless weights of different units meet scales far apart.
COST_SCALE_LIMIT = 1e6


#: Clarabel's settings objects by the settings they hold (made once: the same few are asked
#: for at every solve; Clarabel copies them into each solver).
_SETTINGS: dict[tuple[tuple[str, Any], ...], Any] = {}


def _settings(settings: dict[str, Any]) -> Any:
    """Clarabel's ``DefaultSettings`` with ``settings`` (names of its fields), quiet."""
    import clarabel

    key: tuple[tuple[str, Any], ...] | None = tuple(sorted(settings.items()))
    try:
        options = _SETTINGS.get(key)  # type: ignore[arg-type]  # (a tuple here)
    except TypeError:  # a value that cannot be a key: made for this solve alone
        key, options = None, None
    if options is None:
        options = clarabel.DefaultSettings()
        options.verbose = False
        for name, value in settings.items():
            setattr(options, name, value)
        if key is not None:
            _SETTINGS[key] = options
    return options


@dataclass(frozen=True, eq=False)
class CscMatrix:
    """A dense matrix's nonzeros in compressed sparse columns, as Clarabel reads a matrix.

    Clarabel takes any object with the attributes of SciPy's CSC arrays that it reads
    (``shape``, ``indptr``, ``indices``, ``data``, ``has_canonical_format``); built here with
    numpy, without importing ``scipy.sparse`` (0.1–0.2 s) for a few hundred numbers. The
    entries are those ``scipy.sparse.csc_array(dense)`` stores, in its order: column by
    column, rows ascending.
    """

    shape: tuple[int, int]
    indptr: NDArray[np.int64]
    indices: NDArray[np.int64]
    data: NDArray[np.float64]
    has_canonical_format = True  # sorted rows, no duplicates

    @classmethod
    def of(cls, dense: NDArray[np.float64]) -> CscMatrix:
        """The nonzeros of a dense 2-D array."""
        dense = np.asarray(dense, dtype=float)
        cols, rows = np.nonzero(dense.T)  # column-major: each column's rows ascending
        indptr = np.zeros(dense.shape[1] + 1, dtype=np.int64)
        np.cumsum(np.bincount(cols, minlength=dense.shape[1]), out=indptr[1:])
        return cls(shape=dense.shape, indptr=indptr, indices=rows.astype(np.int64),
                   data=dense[rows, cols])


@dataclass(frozen=True, eq=False)
class ConicSolution:
    """What one solve returned.

    ``u`` is ``None`` unless the status is one of :data:`SOLVED`; ``duals`` holds one
    multiplier per constraint (in the order given), ``epigraph_dual`` the norm's cone
    multiplier ``(μ, w)`` in epigraph form.
    """

    status: str
    u: NDArray[np.float64] | None
    duals: tuple[NDArray[np.float64], ...]
    epigraph_dual: NDArray[np.float64] | None
    iterations: int
    time: float


class ConicProgram:
    """``min f(u)`` subject to ``M_i·u + m_i ∈ K_i`` and ``E·u = r``, assembled once.

    The objective is one of

    - ``norm``: ``‖P·u + q‖`` (epigraph form: a variable ``t`` and the cone ``‖P·u + q‖ ≤ t``);
    - ``squares``: ``‖P·u + q‖² + g·u`` (a quadratic objective);
    - ``nearest``: ``‖u − target‖²``, the target given at each solve.

    Parameters
    ----------
    n
        Number of variables ``u``.
    constraints
        The cone constraints, in the order their multipliers are returned.
    equality
        ``(E, r)``, or ``None``; ``r`` may be replaced at each solve.
    objective
        ``"norm"``, ``"squares"`` or ``"nearest"``.
    P, q, g
        The objective's data (``norm`` and ``squares``).
    """

    def __init__(self, n: int, constraints: list[Constraint], *,
                 equality: tuple[NDArray[np.float64], NDArray[np.float64]] | None = None,
                 objective: str, P: NDArray[np.float64] | None = None,
                 q: NDArray[np.float64] | None = None,
                 g: NDArray[np.float64] | None = None) -> None:
        self.n = n
        self.objective = objective
        epigraph = objective == "norm"
        width = n + 1 if epigraph else n
        self.width = width
        if equality is not None:
            e, r = (np.atleast_2d(np.asarray(equality[0], float)),
                    np.asarray(equality[1], float).reshape(-1))
        else:
            e, r = np.zeros((0, n)), np.zeros(0)
        self._equality_rows = e.shape[0]
        # The nonnegative rows first, then the cones, each in the order given (as CVXPY
        # orders them: Clarabel's iterates, and so its last digits, depend on the order).
        order = ([i for i, c in enumerate(constraints) if c.kind == "nonneg"]
                 + [i for i, c in enumerate(constraints) if c.kind == "soc"])
        if epigraph and (P is None or q is None):
            raise ValueError("the norm objective needs P and q")
        total = e.shape[0] + sum(constraints[i].M.shape[0] for i in order) + (
            P.shape[0] + 1 if epigraph and P is not None else 0)
        a_matrix = np.zeros((total, width))
        b_vector = np.zeros(total)
        a_matrix[: e.shape[0], :n] = e
        b_vector[: e.shape[0]] = r
        cones: list[tuple[str, int]] = [("zero", e.shape[0])] if e.shape[0] else []
        self._slices: list[slice] = [slice(0, 0)] * len(constraints)
        start = e.shape[0]
        for i in order:
            con = constraints[i]
            k = con.M.shape[0]
            a_matrix[start : start + k, :n] = -con.M
            b_vector[start : start + k] = con.m
            self._slices[i] = slice(start, start + k)
            start += k
            if con.kind == "nonneg" and cones and cones[-1][0] == "nonneg":
                cones[-1] = ("nonneg", cones[-1][1] + k)
            else:
                cones.append((con.kind, k))
        self._epigraph: slice | None = None
        hessian = np.zeros((width, width))
        linear = np.zeros(width)
        if epigraph:
            assert P is not None and q is not None  # (checked above)
            k = P.shape[0]
            a_matrix[start, n] = -1.0  # t
            a_matrix[start + 1 : start + 1 + k, :n] = -P
            b_vector[start + 1 : start + 1 + k] = q
            self._epigraph = slice(start, start + k + 1)
            cones.append(("soc", k + 1))
            linear[n] = 1.0
        elif objective == "squares":
            assert P is not None and q is not None
            hessian[:n, :n] = 2.0 * P.T @ P
            linear[:n] = 2.0 * P.T @ q + (0.0 if g is None else g)
        elif objective == "nearest":
            hessian[:n, :n] = 2.0 * np.eye(n)
        else:
            raise ValueError(f"unknown objective {objective!r}")
        self._A = a_matrix
        self._b = b_vector
        # An objective whose data are far from unity (a penalty on added mass that dwarfs the
        # shaking of a linkage a millimetre across) is divided by their size: Clarabel's
        # equilibration leaves such a cost as it is, and it then declared a bounded problem
        # unbounded. The multipliers are multiplied back.
        size = max(float(np.max(np.abs(hessian), initial=0.0)),
                   float(np.max(np.abs(linear), initial=0.0)))
        self._cost_scale = size if size > COST_SCALE_LIMIT else 1.0
        self._H = np.triu(hessian) / self._cost_scale
        self._h = linear / self._cost_scale
        self._cones = cones
        # Clarabel's forms of what every solve shares
        self._csc = (CscMatrix.of(self._H), CscMatrix.of(self._A))
        self._clarabel_cones: list[Any] | None = None

    def solve(self, settings: dict[str, Any], *, target: NDArray[np.float64] | None = None,
              equality_rhs: NDArray[np.float64] | None = None) -> ConicSolution:
        """Solve with Clarabel (``settings``: names of its ``DefaultSettings``).

        ``target`` is the ``nearest`` objective's point; ``equality_rhs`` replaces ``r``.
        """
        import clarabel

        b = self._b
        if equality_rhs is not None:
            b = b.copy()
            b[: self._equality_rows] = equality_rhs
        h = self._h
        if self.objective == "nearest":
            assert target is not None
            h = np.zeros(self.width)
            h[: self.n] = -2.0 * np.asarray(target, float) / self._cost_scale
        if self._clarabel_cones is None:  # (the same cones at every solve)
            kinds = {"zero": clarabel.ZeroConeT, "nonneg": clarabel.NonnegativeConeT,
                     "soc": clarabel.SecondOrderConeT}
            self._clarabel_cones = [kinds[kind](k) for kind, k in self._cones]
        solver = clarabel.DefaultSolver(self._csc[0], h, self._csc[1], b, self._clarabel_cones,
                                        _settings(settings))
        with np.errstate(over="ignore", invalid="ignore"):
            result = solver.solve()
        status = STATUS.get(str(result.status), "solver_error")
        z = np.asarray(result.z, dtype=float) * self._cost_scale
        duals = tuple(z[s] for s in self._slices) if z.size == self._b.size else tuple(
            np.full(s.stop - s.start, np.nan) for s in self._slices)
        epigraph = None
        if self._epigraph is not None and z.size == self._b.size:
            epigraph = z[self._epigraph]
        u = np.asarray(result.x, dtype=float)[: self.n] if status in SOLVED else None
        if u is not None and not np.all(np.isfinite(u)):
            u, status = None, "solver_error"
        return ConicSolution(status=status, u=u, duals=duals, epigraph_dual=epigraph,
                             iterations=int(result.iterations), time=float(result.solve_time))


#: Clarabel's settings for every solve here (tight: the zero optimum of complete balancing
#: must be reached to ~1e-10 of the original shaking moment).
CLARABEL_SETTINGS: dict[str, float | int] = {
    "tol_gap_abs": 1e-10,
    "tol_gap_rel": 1e-10,
    "tol_feas": 1e-10,
    "tol_infeas_abs": 1e-10,
    "tol_infeas_rel": 1e-10,
    "tol_ktratio": 1e-8,
    "max_iter": 200,
}
#: Settings Clarabel is run with again, in turn, where it stops for numerical trouble (its
#: factorisation fails in a thin feasible set, as the redesign campaign found on problems at
#: the edge of force balance): a stronger static regularisation, then no equilibration.
NUMERICAL_FALLBACKS: tuple[dict[str, float | bool], ...] = (
    {"static_regularization_constant": 1e-7},
    {"equilibrate_enable": False},
)
#: Settings tried, in turn, where Clarabel stops "almost solved" (its reduced tolerances met,
#: not the full ones): shorter steps keep the iterates further inside the cones, where a thin
#: feasible set (a tie-break whose design has a mass, a centre and an inertia all at their
#: bounds) loses fewer digits. The first that solves fully is taken. (The Jansen leg's
#: tie-break: "almost solved" with the default 0.99, its j held 3e-8 to 5e-7 off its mass
#: bound depending on the machine's arithmetic; at 0.9 solved, the mass on its bound.) The same
#: settings serve a loose certificate (:data:`CERTIFY_AGAIN`): each lands on another point of
#: the central path, whose dual residual differs (the Jansen leg's gap of 2.7e-7, or 4e-6 on
#: another arithmetic, tightened below 1e-8).
ACCURACY_FALLBACKS: tuple[dict[str, float | bool], ...] = (
    {"max_step_fraction": 0.9},
    {"equilibrate_enable": False},
)


def solve_program(program: ConicProgram, settings: dict[str, Any],
                  **data: NDArray[np.float64]) -> ConicSolution:
    """``program`` by Clarabel with ``settings``, again where it did not solve fully.

    Numerical trouble (a thin feasible set): again with :data:`NUMERICAL_FALLBACKS`; "almost
    solved": again with :data:`ACCURACY_FALLBACKS`, the first that solves fully taken (else
    the almost-solved answer stands). Whether a stage solves fully must not hinge on the
    machine's rounding more than it must.
    """
    solution = program.solve(settings, **data)
    for fallback in NUMERICAL_FALLBACKS:  # numerical trouble (a thin feasible set): again
        if solution.status != "solver_error":
            break
        solution = program.solve({**settings, **fallback}, **data)
    if solution.status == "optimal_inaccurate":
        for fallback in ACCURACY_FALLBACKS:
            again = program.solve({**settings, **fallback}, **data)
            if again.status == "optimal":
                return again
    return solution
