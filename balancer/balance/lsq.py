"""Least squares with bounds on the unknowns: Stark and Parker's active-set method (BVLS).

``minimise ‖A·x − b‖ subject to lower ≤ x ≤ upper`` (a bound may be infinite), for the small
dense problems of the balancing: the refit of the certificate's multipliers
(:mod:`.certificate`) and the settling of parameters that do not matter at constant speed
(:mod:`.problem`). The unconstrained least-squares solution is taken where it lies within the
bounds; otherwise BVLS moves variables between the free set, solved by least squares, and the
bounds, until the Karush–Kuhn–Tucker conditions hold (Stark & Parker, *Computational
Statistics* 10, 1995). It follows :func:`scipy.optimize.lsq_linear` with ``method="bvls"``
step for step — its initialisation, its loops and its stopping tests — so that both give the
same ``x`` (a test compares them and checks the conditions), without importing
``scipy.optimize`` (0.3–0.6 s, more than a whole balancing) for it.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from numpy.typing import ArrayLike, NDArray


@dataclass(frozen=True, eq=False)
class BoundedFit:
    """The solution of :func:`bounded_lstsq`.

    Attributes
    ----------
    x
        The minimiser, within the bounds (a variable that met its bound on a step, an ulp
        beyond it, is set to it).
    optimality
        The largest violation of the Karush–Kuhn–Tucker conditions at ``x``, in units of the
        gradient ``Aᵀ·(A·x − b)``: its magnitude on a free variable, its component pointing
        into the bounds on a bound one (≤ 0 there at a minimum).
    active
        −1 where ``x`` is at its lower bound, +1 at its upper, 0 free.
    status
        ``"unconstrained"`` (the least-squares solution is within the bounds), ``"optimal"``
        (the conditions hold to ``tol``), ``"stalled"`` (the cost no longer decreased by more
        than ``tol`` of itself) or ``"iterations"`` (``max_iter`` reached).
    """

    x: NDArray[np.float64]
    optimality: float
    active: NDArray[np.float64]
    status: str


def _kkt_violation(g: NDArray[np.float64], on_bound: NDArray[np.float64]) -> float:
    """The largest violation of the optimality conditions (see :attr:`BoundedFit.optimality`)."""
    g_kkt = g * on_bound
    free = on_bound == 0
    g_kkt[free] = np.abs(g[free])
    return float(np.max(g_kkt))


def bounded_lstsq(A: ArrayLike, b: ArrayLike, lower: ArrayLike, upper: ArrayLike, *,
                  tol: float = 1e-10,
                  max_iter: int | None = None) -> BoundedFit:
    """``x`` minimising ``‖A·x − b‖`` with ``lower ≤ x ≤ upper`` (see the module docstring).

    Parameters
    ----------
    A, b
        The matrix ``(m, n)`` and the right-hand side ``(m,)``.
    lower, upper
        Bounds, arrays ``(n,)`` or numbers (``±inf`` for none); each lower below its upper.
    tol
        The main loop stops when the conditions' violation falls below it, or the cost's
        decrease in an iteration below ``tol`` times the cost.
    max_iter
        Most iterations of the main loop (default ``n``), after the initialisation's.
    """
    A = np.atleast_2d(np.asarray(A, dtype=float))
    b = np.atleast_1d(np.asarray(b, dtype=float))
    n = A.shape[1]
    lb = np.broadcast_to(np.asarray(lower, dtype=float), (n,)).copy()
    ub = np.broadcast_to(np.asarray(upper, dtype=float), (n,)).copy()
    if np.any(lb >= ub):
        raise ValueError("each lower bound must be below its upper bound")
    x_lsq = np.linalg.lstsq(A, b, rcond=-1)[0]
    if np.all((x_lsq >= lb) & (x_lsq <= ub)):
        g = A.T @ (A @ x_lsq - b)
        return BoundedFit(x=x_lsq, optimality=float(np.max(np.abs(g), initial=0.0)),
                          active=np.zeros(n), status="unconstrained")
    return _bvls(A, b, x_lsq, lb, ub, tol, max_iter)


def _bvls(A: NDArray[np.float64], b: NDArray[np.float64], x_lsq: NDArray[np.float64],
          lb: NDArray[np.float64], ub: NDArray[np.float64], tol: float,
          max_iter: int | None) -> BoundedFit:
    """BVLS from the unconstrained solution ``x_lsq`` (SciPy's ``_lsq/bvls.py``, as it is)."""
    n = A.shape[1]
    x = x_lsq.copy()
    on_bound = np.zeros(n)
    mask = x <= lb
    x[mask] = lb[mask]
    on_bound[mask] = -1
    mask = x >= ub
    x[mask] = ub[mask]
    on_bound[mask] = 1
    free_set = on_bound == 0
    active_set = ~free_set
    (free_set,) = np.nonzero(free_set)
    r = A @ x - b
    cost = 0.5 * np.dot(r, r)
    g = A.T @ r
    iteration = 0
    # Initialisation: the least-squares solution on the free variables, those beyond a bound
    # set to it, until the free ones' solution is within the bounds.
    while free_set.size > 0:
        iteration += 1
        z = np.linalg.lstsq(A[:, free_set], b - A @ (x * active_set), rcond=None)[0]
        lbv = z < lb[free_set]
        ubv = z > ub[free_set]
        v = lbv | ubv
        if np.any(lbv):
            ind = free_set[lbv]
            x[ind] = lb[ind]
            active_set[ind] = True
            on_bound[ind] = -1
        if np.any(ubv):
            ind = free_set[ubv]
            x[ind] = ub[ind]
            active_set[ind] = True
            on_bound[ind] = 1
        ind = free_set[~v]
        x[ind] = z[~v]
        r = A @ x - b
        cost = 0.5 * np.dot(r, r)
        g = A.T @ r
        if np.any(v):
            free_set = free_set[~v]
        else:
            break
    status = "iterations"
    optimality = _kkt_violation(g, on_bound)
    for _ in range(n if max_iter is None else max_iter):
        if optimality < tol:
            status = "optimal"
            break
        on_bound[np.argmax(g * on_bound)] = 0  # free the variable that most wants to move
        while True:
            free_set = on_bound == 0
            active_set = ~free_set
            (free_set,) = np.nonzero(free_set)
            x_free = x[free_set]
            lb_free, ub_free = lb[free_set], ub[free_set]
            z = np.linalg.lstsq(A[:, free_set], b - A @ (x * active_set), rcond=None)[0]
            (lbv,) = np.nonzero(z < lb_free)
            (ubv,) = np.nonzero(z > ub_free)
            v = np.hstack((lbv, ubv))
            if v.size == 0:
                x[free_set] = z
                break
            # Move towards z until the first variable meets its bound; it joins the bounds.
            alphas = np.hstack((lb_free[lbv] - x_free[lbv],
                                ub_free[ubv] - x_free[ubv])) / (z[v] - x_free[v])
            i = np.argmin(alphas)
            alpha = alphas[i]
            x_free *= 1 - alpha
            x_free += alpha * z
            x[free_set] = x_free
            on_bound[free_set[v[i]]] = -1 if i < lbv.size else 1
        r = A @ x - b
        cost_new = 0.5 * np.dot(r, r)
        stalled = cost - cost_new < tol * cost
        cost = cost_new
        g = A.T @ r
        optimality = _kkt_violation(g, on_bound)
        if stalled:
            status = "optimal" if optimality < tol else "stalled"
            break
    return BoundedFit(x=np.clip(x, lb, ub), optimality=optimality, active=on_bound,
                      status=status)


def pinv(a: NDArray[np.float64], rcond: float = 1e-15) -> NDArray[np.float64]:
    """The pseudo-inverse of a real matrix, as ``numpy.linalg.pinv(a, rcond)`` computes it.

    The same SVD and the same arithmetic (singular values at most ``rcond`` times the largest
    dropped), bit for bit, without its generic dispatch: the repairs take one per set of
    pinned entries, a dozen per design.
    """
    a = np.asarray(a, dtype=float)
    if a.ndim != 2 or not a.size:
        return np.asarray(np.linalg.pinv(a, rcond=rcond), dtype=float)
    u, s, vt = np.linalg.svd(a, full_matrices=False)
    large = s > rcond * s.max()
    s = np.divide(1, s, where=large, out=s)
    s[~large] = 0
    return np.asarray(vt.T @ (s[:, None] * u.T), dtype=float)
