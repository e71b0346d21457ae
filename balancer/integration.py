"""SciPy's DOP853 with its Runge–Kutta stages evaluated in one compiled call per step.

For a formulation whose right-hand side is a CasADi function
(:meth:`~balancer.formulations.Formulation.symbolic_rhs`), the twelve stages of a step (and
the three more of the dense output) are one compiled function of ``(t, y, f, h)``: the step
then costs one call instead of twelve Python calls of the right-hand side, which dominate the
integration of a small system. Everything else — the initial step, the error norm, the step
size control, the dense output's polynomial — is SciPy's own (:class:`scipy.integrate.DOP853`,
Hairer, Nørsett & Wanner, *Solving ODEs I*, Sect. II.10), so both integrate alike to rounding.
"""

from __future__ import annotations

import casadi as ca
import numpy as np
from scipy.integrate import DOP853
from scipy.integrate._ivp.rk import (  # the controller's constants, SciPy's own
    MAX_FACTOR,
    MIN_FACTOR,
    SAFETY,
    Dop853DenseOutput,
)

from .formulations.compiled import Compiled


def with_extra_work(rhs: ca.Function) -> ca.Function:
    """``rhs`` of a state with one more entry, the work of an extra power that is zero."""
    t = ca.MX.sym("t")
    y = ca.MX.sym("y", rhs.size1_in(1) + 1)
    return ca.Function("rhs_with_work", [t, y], [ca.vertcat(rhs(t, y[:-1]), 0)])


def _stages(rhs: ca.Function, n: int, a, c, first: int, count: int):
    """Stages ``first … first+count−1`` of an explicit Runge–Kutta method.

    As MX of ``(t, y, h, K[:first])``.
    """
    t, h = ca.MX.sym("t"), ca.MX.sym("h")
    y = ca.MX.sym("y", n)
    known = ca.MX.sym("k", n * first)  # K[0], K[1], … one after another
    ks = [known[j * n : (j + 1) * n] for j in range(first)]
    for s in range(first, first + count):
        dy = sum((float(a[s][j]) * ks[j] for j in range(s) if a[s][j] != 0), ca.MX.zeros(n))
        ks.append(rhs(t + float(c[s]) * h, y + h * dy))
    return t, y, h, known, ks


class Stages:
    """The compiled stages of DOP853 for a right-hand side ``(t, y) → ẏ`` (built once).

    ``step(t, h, y, f)`` gives stages 2–12 and the step's end ``y``; ``extra(t, h, y, K)``
    the dense output's three more.
    """

    def __init__(self, rhs: ca.Function) -> None:
        n = rhs.size1_in(1)
        stages = DOP853.n_stages
        t, y, h, known, ks = _stages(rhs, n, DOP853.A, DOP853.C, 1, stages - 1)
        y_new = y + h * sum((float(b) * k for b, k in zip(DOP853.B, ks, strict=True)),
                            ca.MX.zeros(n))
        f_new = rhs(t + h, y_new)
        self.step = Compiled(ca.Function("dop853_step", [ca.vertcat(t, h, y, known)],
                                         [ca.vertcat(*ks[1:], f_new, y_new)]))
        size = stages + 1 + len(DOP853.C_EXTRA)  # K[12] is f at the step's end
        a = np.zeros((size, size))
        a[:stages, :stages] = DOP853.A
        a[stages + 1 :, :] = DOP853.A_EXTRA
        c = np.concatenate([DOP853.C, [1.0], DOP853.C_EXTRA])
        t, y, h, known, ks = _stages(rhs, n, a, c, stages + 1, len(DOP853.C_EXTRA))
        self.extra = Compiled(ca.Function("dop853_extra", [ca.vertcat(t, h, y, known)],
                                          [ca.vertcat(*ks[stages + 1 :])]))


class CompiledDOP853(DOP853):
    """:class:`scipy.integrate.DOP853` stepping through compiled stages.

    Parameters
    ----------
    fun
        The right-hand side in Python (SciPy's first step and its initial step size use it).
    stages
        The same right-hand side's compiled stages (:class:`Stages`).
    """

    def __init__(self, fun, t0, y0, t_bound, *, stages: Stages, **options) -> None:
        super().__init__(fun, t0, y0, t_bound, **options)
        self._step, self._extra = stages.step, stages.extra

    def _step_impl(self):
        t, y = self.t, self.y
        rtol, atol = self.rtol, self.atol
        min_step = 10 * np.abs(np.nextafter(t, self.direction * np.inf) - t)
        h_abs = min(max(self.h_abs, min_step), self.max_step)
        step_accepted = False
        step_rejected = False
        n, stages = self.n, self.n_stages
        while not step_accepted:
            if h_abs < min_step:
                return False, self.TOO_SMALL_STEP
            h = h_abs * self.direction
            t_new = t + h
            if self.direction * (t_new - self.t_bound) > 0:
                t_new = self.t_bound
            h = t_new - t
            h_abs = np.abs(h)
            out = self._step(np.concatenate([[t, h], y, self.f]))
            self.nfev += stages
            self.K[0] = self.f
            self.K[1:] = out[: stages * n].reshape(stages, n)
            y_new = out[stages * n :]
            f_new = self.K[-1]
            scale = atol + np.maximum(np.abs(y), np.abs(y_new)) * rtol
            error_norm = self._estimate_error_norm(self.K, h, scale)
            if error_norm < 1:
                factor = MAX_FACTOR if error_norm == 0 else min(
                    MAX_FACTOR, SAFETY * error_norm ** self.error_exponent)
                if step_rejected:
                    factor = min(1, factor)
                h_abs *= factor
                step_accepted = True
            else:
                h_abs *= max(MIN_FACTOR, SAFETY * error_norm ** self.error_exponent)
                step_rejected = True
        self.h_previous = h
        self.y_old = y
        self.t = t_new
        self.y = y_new
        self.h_abs = h_abs
        self.f = f_new.copy()
        return True, None

    def _dense_output_impl(self):
        k = self.K_extended
        h = self.h_previous
        stages = self.n_stages
        extra = self._extra(np.concatenate([[self.t_old, h], self.y_old,
                                            k[: stages + 1].reshape(-1)]))
        self.nfev += len(self.C_EXTRA)
        k[stages + 1 :] = extra.reshape(len(self.C_EXTRA), self.n)
        f = np.empty((7, self.n))
        f_old = k[0]
        delta_y = self.y - self.y_old
        f[0] = delta_y
        f[1] = h * f_old - delta_y
        f[2] = 2 * delta_y - h * (self.f + f_old)
        f[3:] = h * np.dot(self.D, k)
        return Dop853DenseOutput(self.t_old, self.t, self.y_old, f)
