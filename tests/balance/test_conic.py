"""The conic program handed to Clarabel directly (balance/conic.py) against CVXPY's.

CVXPY canonicalises the same program by its own route (its cone ordering, variables and
duals); both end in Clarabel, so the optimum must agree to Clarabel's tolerance (1e-9 on the
gap and feasibility, here on problems of unit scale: a value to ~1e-8). The multipliers are
checked by what defines them: stationarity of the Lagrangian f − Σ zᵀ·(M·u + m) − νᵀ·(E·u − r)
in the convention the certificate uses, and membership of the (self-dual) cones.
"""

from __future__ import annotations

import math
import subprocess
import sys

import cvxpy as cp
import numpy as np
import pytest

from balancer.balance.certificate import Constraint
from balancer.balance.conic import CLARABEL_SETTINGS as PRODUCT_SETTINGS
from balancer.balance.conic import ConicProgram, CscMatrix

#: The product's Clarabel settings at tolerances of 1e-9 (gap, feasibility): at the product's
#: 1e-10, a random program of this file stalls "almost solved" on some machines' arithmetic
#: (seed 2 without AVX2), in CVXPY's canonical form and in ours alike. (The product meets that
#: status by repair and certificate; here the two routes are compared.)
TOLERANCE = 1e-9
CLARABEL_SETTINGS = {**PRODUCT_SETTINGS, "tol_gap_abs": TOLERANCE, "tol_gap_rel": TOLERANCE,
                     "tol_feas": TOLERANCE, "tol_infeas_abs": TOLERANCE,
                     "tol_infeas_rel": TOLERANCE}
#: Agreement of two solves to Clarabel's tolerances (1e-9) on problems of unit scale, with
#: room for the conditioning of a random problem (tenfold).
AGREE = 1e-8


def _random_program(seed: int, n: int = 6):
    """Bounds |u_j| ≤ 2, two cones ‖B·u + c‖ ≤ d + a·u strictly met at a point u0, E·u = E·u0."""
    rng = np.random.default_rng(seed)
    u0 = rng.uniform(-0.5, 0.5, n)
    constraints = []
    for j in range(n):
        row = np.zeros((1, n))
        row[0, j] = 1.0
        constraints.append(Constraint("nonneg", row, np.array([2.0])))  # u_j + 2 ≥ 0
        constraints.append(Constraint("nonneg", -row, np.array([2.0])))  # 2 − u_j ≥ 0
    for _ in range(2):
        b, c, a = rng.normal(size=(3, n)), rng.normal(size=3), 0.1 * rng.normal(size=n)
        d = np.linalg.norm(b @ u0 + c) - a @ u0 + 0.5
        constraints.append(Constraint("soc", np.vstack([a, b]), np.concatenate([[d], c])))
    e = rng.normal(size=(2, n))
    p, q = rng.normal(size=(4, n)), rng.normal(size=4)
    return constraints, (e, e @ u0), p, q


def _cvxpy(constraints, equality, objective):
    u = cp.Variable(constraints[0].M.shape[1])
    cons = [c.M[0] @ u + c.m[0] >= 0 if c.kind == "nonneg"
            else cp.SOC(c.M[0] @ u + c.m[0], c.M[1:] @ u + c.m[1:]) for c in constraints]
    cons.append(equality[0] @ u == equality[1])
    problem = cp.Problem(cp.Minimize(objective(u)), cons)
    problem.solve(solver=cp.CLARABEL, **CLARABEL_SETTINGS)
    assert problem.status == "optimal"
    return np.array(u.value), float(problem.value)


def _stationarity(constraints, equality, solution, gradient):
    """‖∇f − Σ Mᵀz − Eᵀν‖ with ν fitted by least squares (Clarabel's ν is internal)."""
    g = gradient - sum(c.M.T @ z for c, z in zip(constraints, solution.duals, strict=True))
    e = equality[0]
    nu = np.linalg.lstsq(e.T, g, rcond=None)[0]
    return float(np.linalg.norm(g - e.T @ nu))


@pytest.mark.parametrize("seed", range(4))
def test_norm_objective_agrees_with_cvxpy(seed):
    constraints, equality, p, q = _random_program(seed)
    program = ConicProgram(p.shape[1], constraints, equality=equality, objective="norm",
                           P=p, q=q)
    solution = program.solve(CLARABEL_SETTINGS)
    assert solution.status == "optimal"
    u_ref, value_ref = _cvxpy(constraints, equality, lambda u: cp.norm(p @ u + q))
    value = float(np.linalg.norm(p @ solution.u + q))
    assert value == pytest.approx(value_ref, rel=AGREE, abs=AGREE)
    # a unique optimum, to √tolerance (the objective is flat to first order at its minimum)
    assert np.max(np.abs(solution.u - u_ref)) < math.sqrt(TOLERANCE)
    # The epigraph's multiplier (μ, w): μ = 1 at the optimum and ∇‖P·u + q‖ = −Pᵀ·w... in
    # the Lagrangian t − μ·t − wᵀ(P·u + q), so stationarity in u reads Σ Mᵀz + Eᵀν = −Pᵀw.
    mu, w = solution.epigraph_dual[0], solution.epigraph_dual[1:]
    assert mu == pytest.approx(1.0, abs=AGREE)
    assert _stationarity(constraints, equality, solution, -p.T @ w) < AGREE
    for c, z in zip(constraints, solution.duals, strict=True):
        assert np.linalg.norm(z - c.project(z)) < AGREE  # in the cone


@pytest.mark.parametrize("seed", range(4))
def test_squares_objective_agrees_with_cvxpy(seed):
    constraints, equality, p, q = _random_program(seed)
    g = np.random.default_rng(100 + seed).normal(size=p.shape[1])
    program = ConicProgram(p.shape[1], constraints, equality=equality, objective="squares",
                           P=p, q=q, g=g)
    solution = program.solve(CLARABEL_SETTINGS)
    assert solution.status == "optimal"
    u_ref, value_ref = _cvxpy(constraints, equality,
                              lambda u: cp.sum_squares(p @ u + q) + g @ u)
    value = float(np.sum((p @ solution.u + q) ** 2) + g @ solution.u)
    assert value == pytest.approx(value_ref, rel=AGREE, abs=AGREE)
    gradient = 2 * p.T @ (p @ solution.u + q) + g
    assert _stationarity(constraints, equality, solution, gradient) < AGREE


@pytest.mark.parametrize("seed", range(3))
def test_an_objective_far_from_unity_is_solved_as_it_would_be_divided(seed):
    # Linkage fuzz campaign, seed 2611, case 142: an added-mass weight that dwarfed the
    # shaking of a linkage a third of a millimetre across gave a linear term of 3.5e13 beside
    # a Hessian of order one, and Clarabel called the bounded program unbounded. The program
    # divides such an objective by its size: the point is the one of the objective divided by
    # hand (the other route, the same program at unit scale), and the multipliers, multiplied
    # back, make the original objective's Lagrangian stationary, relative to its gradient.
    constraints, equality, p, q = _random_program(seed)
    g = np.random.default_rng(200 + seed).normal(size=p.shape[1])
    big = ConicProgram(p.shape[1], constraints, equality=equality, objective="squares",
                       P=p, q=q, g=3.5e13 * g)
    unit = ConicProgram(p.shape[1], constraints, equality=equality, objective="squares",
                        P=p / math.sqrt(3.5e13), q=q / math.sqrt(3.5e13), g=g)
    solution, reference = big.solve(CLARABEL_SETTINGS), unit.solve(CLARABEL_SETTINGS)
    assert solution.status == reference.status == "optimal"
    assert np.max(np.abs(solution.u - reference.u)) < AGREE
    gradient = 2 * p.T @ (p @ solution.u + q) + 3.5e13 * g
    assert _stationarity(constraints, equality, solution, gradient) < AGREE * np.linalg.norm(
        gradient)


def test_nearest_point_and_new_right_hand_side():
    constraints, (e, r), _, _ = _random_program(7)
    program = ConicProgram(e.shape[1], constraints, equality=(e, r), objective="nearest")
    target = np.full(e.shape[1], 3.0)  # outside the box: the projection meets bounds
    r2 = r + 0.1
    solution = program.solve(CLARABEL_SETTINGS, target=target, equality_rhs=r2)
    u_ref, _ = _cvxpy(constraints, (e, r2), lambda u: cp.sum_squares(u - target))
    assert np.max(np.abs(solution.u - u_ref)) < AGREE ** 0.5
    assert np.max(np.abs(e @ solution.u - r2)) < AGREE
    # ... and the program is unchanged for the next solve.
    again = program.solve(CLARABEL_SETTINGS, target=target)
    assert np.max(np.abs(e @ again.u - r)) < AGREE


def test_infeasible_program_has_no_point():
    row = np.ones((1, 2))
    constraints = [Constraint("nonneg", row, np.array([-1.0])),  # u1 + u2 ≥ 1
                   Constraint("nonneg", -row, np.array([0.0]))]  # u1 + u2 ≤ 0
    solution = ConicProgram(2, constraints, objective="nearest").solve(
        CLARABEL_SETTINGS, target=np.zeros(2))
    assert solution.status == "infeasible" and solution.u is None


def test_convex_balancing_does_not_import_cvxpy():
    """The certified optimum needs Clarabel only (CVXPY's import alone takes ~1 s)."""
    code = ("import sys; from balancer.spec import load_design; "
            "from balancer.balance.optimizer import optimize; "
            "optimize(load_design('examples/pb1.toml'), 'convex'); "
            "print('cvxpy' in sys.modules)")
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True,
                         check=True, cwd=__file__.rsplit("/tests/", 1)[0])
    assert out.stdout.strip() == "False"


def test_the_matrices_clarabel_reads_are_scipys_csc_arrays():
    # Clarabel reads shape, indptr, indices, data: the same as scipy.sparse would give it.
    from scipy.sparse import csc_array

    rng = np.random.default_rng(3)
    for shape in ((5, 3), (1, 7), (9, 9), (4, 0), (0, 2)):
        dense = rng.standard_normal(shape) * (rng.uniform(size=shape) < 0.4)
        mine, ref = CscMatrix.of(dense), csc_array(dense)
        assert mine.shape == ref.shape
        assert np.array_equal(mine.indptr, ref.indptr)
        assert np.array_equal(mine.indices, ref.indices)
        assert np.array_equal(mine.data, ref.data)


def test_an_almost_solved_program_is_solved_again_with_shorter_steps():
    """Clarabel "almost solved" (its reduced tolerances only): solve_program tries the
    ACCURACY_FALLBACKS in turn and takes the first that solves fully, else keeps the first
    answer; numerical trouble first tries NUMERICAL_FALLBACKS. (The Jansen leg's tie-break left
    its j 5e-7 off its mass bound "almost solved" on one machine's arithmetic.)"""
    from balancer.balance.conic import ACCURACY_FALLBACKS, NUMERICAL_FALLBACKS, solve_program

    class Program:
        def __init__(self, answers):
            self.answers, self.asked = answers, []

        def solve(self, settings, **data):
            self.asked.append(settings)
            status = self.answers(settings)
            return type("Solution", (), {"status": status, "u": None})()

    def shorter_steps_solve(settings):
        return "optimal" if settings.get("max_step_fraction") == 0.9 else "optimal_inaccurate"

    program = Program(shorter_steps_solve)
    assert solve_program(program, {"max_iter": 200}).status == "optimal"
    assert program.asked == [{"max_iter": 200}, {"max_iter": 200, **ACCURACY_FALLBACKS[0]}]
    never = Program(lambda settings: "optimal_inaccurate")
    assert solve_program(never, {}).status == "optimal_inaccurate"
    assert len(never.asked) == 1 + len(ACCURACY_FALLBACKS)
    trouble = Program(lambda settings: "solver_error" if not settings else "optimal")
    assert solve_program(trouble, {}).status == "optimal"
    assert trouble.asked == [{}, NUMERICAL_FALLBACKS[0]]
