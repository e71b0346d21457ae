"""The explicit Runge–Kutta method of order 8 (DOP853) that every simulation integrates with.

Dormand and Prince's pair of orders 8(5,3) with its dense output of order 7, as in Hairer's
DOP853 (Hairer, Nørsett & Wanner, *Solving ODEs I*, Sect. II.10) and as
:class:`scipy.integrate.DOP853` implements it: the same tableau (below, as SciPy writes it,
``scipy/integrate/_ivp/dop853_coefficients.py``, BSD licence), the same initial step, error
norm, step size control and dense output, so that both integrate alike to rounding (a test
steps both side by side). It is written here, in numpy alone, because importing
``scipy.integrate`` costs more (0.3–0.6 s) than a whole verification's integration: the
command line pays for it on every ``simulate`` and ``verify``.

:class:`DOP853` is stepped by hand (:mod:`balancer.simulation` projects and looks for events
between steps); :meth:`DOP853.dense_output` interpolates within the last step, at one time or
at an array of times in one call. :class:`CompiledDOP853` evaluates the Runge–Kutta stages of a
formulation whose right-hand side is a CasADi function
(:meth:`~balancer.formulations.Formulation.symbolic_rhs`) in one compiled call per step: the
twelve stages of a step (and the three more of the dense output) are one function of
``(t, h, y, f)``, one call instead of twelve Python calls of the right-hand side, which
dominate the integration of a small system. :class:`TimeOnlyDOP853` skips the stages'
combinations for a right-hand side of the time alone (a driven crank's motor work).
Everything else is :class:`DOP853`'s.
"""

from __future__ import annotations

from collections.abc import Callable
from typing import TYPE_CHECKING, Any

import numpy as np
from numpy.typing import ArrayLike, NDArray

from ..errors import SolverError
from ..formulations.compiled import Compiled

if TYPE_CHECKING:
    import casadi as ca

#: Step size control (SciPy's, after Hairer): the asymptotic factor times this, ...
SAFETY = 0.9
#: ... at least this (a rejected step) ...
MIN_FACTOR = 0.2
#: ... and at most this.
MAX_FACTOR = 10.0

# -- the tableau ------------------------------------------------------------------------------
# Stages 0–11 the method, 12 the step's end (B), 13–15 the dense output's extra stages.

N_STAGES = 12
N_STAGES_EXTENDED = 16
INTERPOLATOR_POWER = 7

C = np.array([0.0,
              0.526001519587677318785587544488e-01,
              0.789002279381515978178381316732e-01,
              0.118350341907227396726757197510,
              0.281649658092772603273242802490,
              0.333333333333333333333333333333,
              0.25,
              0.307692307692307692307692307692,
              0.651282051282051282051282051282,
              0.6,
              0.857142857142857142857142857142,
              1.0,
              1.0,
              0.1,
              0.2,
              0.777777777777777777777777777778])

A = np.zeros((N_STAGES_EXTENDED, N_STAGES_EXTENDED))
A[1, 0] = 5.26001519587677318785587544488e-2

A[2, 0] = 1.97250569845378994544595329183e-2
A[2, 1] = 5.91751709536136983633785987549e-2

A[3, 0] = 2.95875854768068491816892993775e-2
A[3, 2] = 8.87627564304205475450678981324e-2

A[4, 0] = 2.41365134159266685502369798665e-1
A[4, 2] = -8.84549479328286085344864962717e-1
A[4, 3] = 9.24834003261792003115737966543e-1

A[5, 0] = 3.7037037037037037037037037037e-2
A[5, 3] = 1.70828608729473871279604482173e-1
A[5, 4] = 1.25467687566822425016691814123e-1

A[6, 0] = 3.7109375e-2
A[6, 3] = 1.70252211019544039314978060272e-1
A[6, 4] = 6.02165389804559606850219397283e-2
A[6, 5] = -1.7578125e-2

A[7, 0] = 3.70920001185047927108779319836e-2
A[7, 3] = 1.70383925712239993810214054705e-1
A[7, 4] = 1.07262030446373284651809199168e-1
A[7, 5] = -1.53194377486244017527936158236e-2
A[7, 6] = 8.27378916381402288758473766002e-3

A[8, 0] = 6.24110958716075717114429577812e-1
A[8, 3] = -3.36089262944694129406857109825
A[8, 4] = -8.68219346841726006818189891453e-1
A[8, 5] = 2.75920996994467083049415600797e1
A[8, 6] = 2.01540675504778934086186788979e1
A[8, 7] = -4.34898841810699588477366255144e1

A[9, 0] = 4.77662536438264365890433908527e-1
A[9, 3] = -2.48811461997166764192642586468
A[9, 4] = -5.90290826836842996371446475743e-1
A[9, 5] = 2.12300514481811942347288949897e1
A[9, 6] = 1.52792336328824235832596922938e1
A[9, 7] = -3.32882109689848629194453265587e1
A[9, 8] = -2.03312017085086261358222928593e-2

A[10, 0] = -9.3714243008598732571704021658e-1
A[10, 3] = 5.18637242884406370830023853209
A[10, 4] = 1.09143734899672957818500254654
A[10, 5] = -8.14978701074692612513997267357
A[10, 6] = -1.85200656599969598641566180701e1
A[10, 7] = 2.27394870993505042818970056734e1
A[10, 8] = 2.49360555267965238987089396762
A[10, 9] = -3.0467644718982195003823669022

A[11, 0] = 2.27331014751653820792359768449
A[11, 3] = -1.05344954667372501984066689879e1
A[11, 4] = -2.00087205822486249909675718444
A[11, 5] = -1.79589318631187989172765950534e1
A[11, 6] = 2.79488845294199600508499808837e1
A[11, 7] = -2.85899827713502369474065508674
A[11, 8] = -8.87285693353062954433549289258
A[11, 9] = 1.23605671757943030647266201528e1
A[11, 10] = 6.43392746015763530355970484046e-1

A[12, 0] = 5.42937341165687622380535766363e-2
A[12, 5] = 4.45031289275240888144113950566
A[12, 6] = 1.89151789931450038304281599044
A[12, 7] = -5.8012039600105847814672114227
A[12, 8] = 3.1116436695781989440891606237e-1
A[12, 9] = -1.52160949662516078556178806805e-1
A[12, 10] = 2.01365400804030348374776537501e-1
A[12, 11] = 4.47106157277725905176885569043e-2

A[13, 0] = 5.61675022830479523392909219681e-2
A[13, 6] = 2.53500210216624811088794765333e-1
A[13, 7] = -2.46239037470802489917441475441e-1
A[13, 8] = -1.24191423263816360469010140626e-1
A[13, 9] = 1.5329179827876569731206322685e-1
A[13, 10] = 8.20105229563468988491666602057e-3
A[13, 11] = 7.56789766054569976138603589584e-3
A[13, 12] = -8.298e-3

A[14, 0] = 3.18346481635021405060768473261e-2
A[14, 5] = 2.83009096723667755288322961402e-2
A[14, 6] = 5.35419883074385676223797384372e-2
A[14, 7] = -5.49237485713909884646569340306e-2
A[14, 10] = -1.08347328697249322858509316994e-4
A[14, 11] = 3.82571090835658412954920192323e-4
A[14, 12] = -3.40465008687404560802977114492e-4
A[14, 13] = 1.41312443674632500278074618366e-1

A[15, 0] = -4.28896301583791923408573538692e-1
A[15, 5] = -4.69762141536116384314449447206
A[15, 6] = 7.68342119606259904184240953878
A[15, 7] = 4.06898981839711007970213554331
A[15, 8] = 3.56727187455281109270669543021e-1
A[15, 12] = -1.39902416515901462129418009734e-3
A[15, 13] = 2.9475147891527723389556272149
A[15, 14] = -9.15095847217987001081870187138


B = A[N_STAGES, :N_STAGES]

E3 = np.zeros(N_STAGES + 1)
E3[:-1] = B.copy()
E3[0] -= 0.244094488188976377952755905512
E3[8] -= 0.733846688281611857341361741547
E3[11] -= 0.220588235294117647058823529412e-1

E5 = np.zeros(N_STAGES + 1)
E5[0] = 0.1312004499419488073250102996e-1
E5[5] = -0.1225156446376204440720569753e+1
E5[6] = -0.4957589496572501915214079952
E5[7] = 0.1664377182454986536961530415e+1
E5[8] = -0.3503288487499736816886487290
E5[9] = 0.3341791187130174790297318841
E5[10] = 0.8192320648511571246570742613e-1
E5[11] = -0.2235530786388629525884427845e-1

# First 3 coefficients are computed separately.
D = np.zeros((INTERPOLATOR_POWER - 3, N_STAGES_EXTENDED))
D[0, 0] = -0.84289382761090128651353491142e+1
D[0, 5] = 0.56671495351937776962531783590
D[0, 6] = -0.30689499459498916912797304727e+1
D[0, 7] = 0.23846676565120698287728149680e+1
D[0, 8] = 0.21170345824450282767155149946e+1
D[0, 9] = -0.87139158377797299206789907490
D[0, 10] = 0.22404374302607882758541771650e+1
D[0, 11] = 0.63157877876946881815570249290
D[0, 12] = -0.88990336451333310820698117400e-1
D[0, 13] = 0.18148505520854727256656404962e+2
D[0, 14] = -0.91946323924783554000451984436e+1
D[0, 15] = -0.44360363875948939664310572000e+1

D[1, 0] = 0.10427508642579134603413151009e+2
D[1, 5] = 0.24228349177525818288430175319e+3
D[1, 6] = 0.16520045171727028198505394887e+3
D[1, 7] = -0.37454675472269020279518312152e+3
D[1, 8] = -0.22113666853125306036270938578e+2
D[1, 9] = 0.77334326684722638389603898808e+1
D[1, 10] = -0.30674084731089398182061213626e+2
D[1, 11] = -0.93321305264302278729567221706e+1
D[1, 12] = 0.15697238121770843886131091075e+2
D[1, 13] = -0.31139403219565177677282850411e+2
D[1, 14] = -0.93529243588444783865713862664e+1
D[1, 15] = 0.35816841486394083752465898540e+2

D[2, 0] = 0.19985053242002433820987653617e+2
D[2, 5] = -0.38703730874935176555105901742e+3
D[2, 6] = -0.18917813819516756882830838328e+3
D[2, 7] = 0.52780815920542364900561016686e+3
D[2, 8] = -0.11573902539959630126141871134e+2
D[2, 9] = 0.68812326946963000169666922661e+1
D[2, 10] = -0.10006050966910838403183860980e+1
D[2, 11] = 0.77771377980534432092869265740
D[2, 12] = -0.27782057523535084065932004339e+1
D[2, 13] = -0.60196695231264120758267380846e+2
D[2, 14] = 0.84320405506677161018159903784e+2
D[2, 15] = 0.11992291136182789328035130030e+2

D[3, 0] = -0.25693933462703749003312586129e+2
D[3, 5] = -0.15418974869023643374053993627e+3
D[3, 6] = -0.23152937917604549567536039109e+3
D[3, 7] = 0.35763911791061412378285349910e+3
D[3, 8] = 0.93405324183624310003907691704e+2
D[3, 9] = -0.37458323136451633156875139351e+2
D[3, 10] = 0.10409964950896230045147246184e+3
D[3, 11] = 0.29840293426660503123344363579e+2
D[3, 12] = -0.43533456590011143754432175058e+2
D[3, 13] = 0.96324553959188282948394950600e+2
D[3, 14] = -0.39177261675615439165231486172e+2
D[3, 15] = -0.14972683625798562581422125276e+3


def _rms(x: NDArray[np.float64]) -> float:
    """Root-mean-square norm."""
    return float(np.linalg.norm(x)) / x.size ** 0.5


class DOP853:
    """Hairer's DOP853 with automatic step size control, stepped by hand.

    Parameters
    ----------
    fun
        The right-hand side ``fun(t, y) → ẏ`` (1-D float arrays).
    t0, y0
        Initial time (s) and state.
    t_bound
        Time at which the integration ends, s.
    rtol, atol
        Relative and absolute tolerances (``atol`` a number or one per component; it may be
        changed between steps). ``rtol`` is at least 100 ε.
    max_step
        Largest step, s.
    first_step
        The first step, s (default: chosen from the right-hand side, Hairer, Nørsett & Wanner,
        Sect. II.4).

    Attributes
    ----------
    status
        ``"running"``, ``"finished"`` or ``"failed"``.
    t, y, f
        Time, state and right-hand side after the last step; ``t_old`` and ``y_old`` before it.
    nfev
        Right-hand-side evaluations so far.
    """

    n_stages = N_STAGES
    order = 8
    error_estimator_order = 7
    A_EXTRA = A[N_STAGES + 1 :]  # (before A and C are cut to the method's stages)
    C_EXTRA = C[N_STAGES + 1 :]
    A = A[:N_STAGES, :N_STAGES]
    B = B
    C = C[:N_STAGES]
    E3 = E3
    E5 = E5
    D = D
    TOO_SMALL_STEP = "Required step size is less than spacing between numbers."

    def __init__(self, fun: Callable[[float, NDArray[np.float64]], ArrayLike], t0: float,
                 y0: ArrayLike, t_bound: float, *, rtol: float, atol: ArrayLike,
                 max_step: float = np.inf, first_step: float | None = None) -> None:
        y0 = np.asarray(y0, dtype=float)
        if y0.ndim != 1 or not np.isfinite(y0).all():
            raise ValueError("the initial state must be a 1-D array of finite numbers")
        self.nfev = 0

        def counted(t: float, y: NDArray[np.float64]) -> NDArray[np.float64]:
            self.nfev += 1
            return np.asarray(fun(t, y), dtype=float)

        self.fun = counted
        self.t_old: float | None = None
        self.t = t0
        self.y = y0
        self.y_old: NDArray[np.float64] | None = None
        self.t_bound = t_bound
        self.direction = np.sign(t_bound - t0) if t_bound != t0 else 1
        self.n = y0.size
        self.status = "running"
        self.max_step = max_step
        self.rtol = max(rtol, 100 * np.finfo(float).eps)
        self.atol: float | NDArray[np.float64] = np.asarray(atol)
        self.f = self.fun(self.t, self.y)
        if first_step is None:
            self.h_abs = self._initial_step()
        elif 0 < first_step <= abs(t_bound - t0):
            self.h_abs = first_step
        else:
            raise ValueError("the first step must be positive and within the interval")
        self.K_extended = np.empty((N_STAGES_EXTENDED, self.n))
        self.K = self.K_extended[: self.n_stages + 1]
        self.error_exponent = -1 / (self.error_estimator_order + 1)
        self.h_previous: float | None = None

    def _initial_step(self) -> float:
        """The first step (Hairer, Nørsett & Wanner, Sect. II.4)."""
        t0, y0, f0 = self.t, self.y, self.f
        if y0.size == 0:
            return np.inf
        length = abs(self.t_bound - t0)
        if length == 0.0:
            return 0.0
        scale = self.atol + np.abs(y0) * self.rtol
        d0, d1 = _rms(y0 / scale), _rms(f0 / scale)
        h0 = 1e-6 if d0 < 1e-5 or d1 < 1e-5 else 0.01 * d0 / d1
        h0 = min(h0, length)
        if not h0 > 0:  # a rate that is not finite, or beyond double precision's range

            raise SolverError(f"the integrator cannot start at t = {t0:.6g} s: the state's "
                              "rate of change is not finite (loads, springs or masses of "
                              "magnitudes double precision cannot follow)")
        f1 = self.fun(t0 + h0 * self.direction, y0 + h0 * self.direction * f0)
        d2 = _rms((f1 - f0) / scale) / h0
        if d1 <= 1e-15 and d2 <= 1e-15:
            h1 = max(1e-6, h0 * 1e-3)
        else:
            h1 = (0.01 / max(d1, d2)) ** (1 / (self.error_estimator_order + 1))
        return min(100 * h0, h1, length, self.max_step)

    def step(self) -> str | None:
        """Take one step; the message says why it failed (``status == "failed"``)."""
        if self.status != "running":
            raise RuntimeError("the integration has ended")
        if self.n == 0 or self.t == self.t_bound:
            self.t_old, self.t = self.t, self.t_bound
            self.status = "finished"
            return None
        t = self.t
        success, message = self._step_impl()
        if not success:
            self.status = "failed"
        else:
            self.t_old = t
            if self.direction * (self.t - self.t_bound) >= 0:
                self.status = "finished"
        return message

    def _stages(self, t: float, y: NDArray[np.float64], h: float) -> NDArray[np.float64]:
        """The stages into ``K`` (``K[0]`` is ``f``, ``K[12]`` f at the end); the end's ``y``."""
        K, A, C = self.K, self.A, self.C
        K[0] = self.f
        for s in range(1, self.n_stages):
            dy = np.dot(K[:s].T, A[s, :s]) * h
            K[s] = self.fun(t + C[s] * h, y + dy)
        y_new = y + h * np.dot(K[:-1].T, self.B)
        K[-1] = self.fun(t + h, y_new)
        return y_new

    def _error_norm(self, h: float, scale: NDArray[np.float64]) -> float:
        K = self.K
        err5 = np.dot(K.T, self.E5) / scale
        err3 = np.dot(K.T, self.E3) / scale
        err5_2 = np.linalg.norm(err5) ** 2
        err3_2 = np.linalg.norm(err3) ** 2
        if err5_2 == 0 and err3_2 == 0:
            return 0.0
        return np.abs(h) * err5_2 / np.sqrt((err5_2 + 0.01 * err3_2) * len(scale))

    def _step_impl(self) -> tuple[bool, str | None]:
        t, y = self.t, self.y
        min_step = 10 * np.abs(np.nextafter(t, self.direction * np.inf) - t)
        h_abs = min(max(self.h_abs, min_step), self.max_step)
        rejected = False
        while True:
            if h_abs < min_step:
                return False, self.TOO_SMALL_STEP
            h = h_abs * self.direction
            t_new = t + h
            if self.direction * (t_new - self.t_bound) > 0:
                t_new = self.t_bound
            h = t_new - t
            h_abs = np.abs(h)
            y_new = self._stages(t, y, h)
            scale = self.atol + np.maximum(np.abs(y), np.abs(y_new)) * self.rtol
            error_norm = self._error_norm(h, scale)
            if error_norm < 1:
                factor = MAX_FACTOR if error_norm == 0 else min(
                    MAX_FACTOR, SAFETY * error_norm ** self.error_exponent)
                if rejected:
                    factor = min(1, factor)
                h_abs *= factor
                break
            h_abs *= max(MIN_FACTOR, SAFETY * error_norm ** self.error_exponent)
            rejected = True
        self.h_previous = h
        self.y_old = y
        self.t = t_new
        self.y = y_new
        self.h_abs = h_abs
        self.f = self.K[-1].copy()
        return True, None

    def dense_output(self) -> DenseOutput:
        """The interpolant of the last step (three more right-hand sides)."""
        if self.t_old is None:
            raise RuntimeError("no step has been taken")
        if self.n == 0 or self.t == self.t_old:
            return DenseOutput(self.t_old, self.t, self.y, np.zeros((0, self.n)))
        return self._dense_output_impl()

    def _extra_stages(self, h: float) -> None:
        """The dense output's stages 13–15 into ``K_extended``."""
        assert self.t_old is not None and self.y_old is not None  # after a step
        K = self.K_extended
        for s, (a, c) in enumerate(zip(self.A_EXTRA, self.C_EXTRA, strict=True),
                                   start=self.n_stages + 1):
            dy = np.dot(K[:s].T, a[:s]) * h
            K[s] = self.fun(self.t_old + c * h, self.y_old + dy)

    def _dense_output_impl(self) -> DenseOutput:
        h = self.h_previous
        assert h is not None and self.t_old is not None and self.y_old is not None  # a step
        self._extra_stages(h)
        K = self.K_extended
        F = np.empty((INTERPOLATOR_POWER, self.n))
        f_old = K[0]
        delta_y = self.y - self.y_old
        F[0] = delta_y
        F[1] = h * f_old - delta_y
        F[2] = 2 * delta_y - h * (self.f + f_old)
        F[3:] = h * np.dot(self.D, K)
        return DenseOutput(self.t_old, self.t, self.y_old, F)


class DenseOutput:
    """The polynomial of DOP853's dense output over one step, from ``t_old`` to ``t``.

    Called with a time it gives the state there, shape ``(n,)``; with an array of times, the
    states at all of them in one evaluation, shape ``(n, count)``. (No polynomial, ``F`` with
    no rows: the constant ``y_old``.)
    """

    def __init__(self, t_old: float, t: float, y_old: NDArray[np.float64],
                 F: NDArray[np.float64]) -> None:
        self.t_old, self.t = t_old, t
        self.h = t - t_old
        self.y_old = y_old
        self.F = F

    def __call__(self, t: ArrayLike) -> NDArray[np.float64]:
        t = np.asarray(t, dtype=float)
        if not len(self.F):
            return self.y_old.copy() if t.ndim == 0 else np.repeat(
                self.y_old[:, None], t.size, axis=1)
        x = (t - self.t_old) / self.h
        if t.ndim == 0:
            y = np.zeros_like(self.y_old)
        else:
            x = x[:, None]
            y = np.zeros((len(x), len(self.y_old)))
        for i, f in enumerate(reversed(self.F)):
            y += f
            if i % 2 == 0:
                y *= x
            else:
                y *= 1 - x
        y += self.y_old
        return y.T


class TimeOnlyDOP853(DOP853):
    """:class:`DOP853` for a right-hand side that depends on the time alone, not on the state.

    A step's stages are then the right-hand side at known times, with no combination of the
    earlier stages to form (numpy calls that cost as much as a small formulation's right-hand
    side): a driven crank's motor work is such a quadrature
    (:attr:`~balancer.formulations.Formulation.time_only`). The same steps as
    :class:`DOP853`'s, bit for bit.
    """

    def _stages(self, t: float, y: NDArray[np.float64], h: float) -> NDArray[np.float64]:
        K, fun = self.K, self.fun
        K[0] = self.f
        for s, c in enumerate(self.C[1:], start=1):
            K[s] = fun(t + c * h, y)
        y_new = y + h * np.dot(K[:-1].T, self.B)
        K[-1] = fun(t + h, y_new)
        return y_new

    def _extra_stages(self, h: float) -> None:
        assert self.t_old is not None and self.y_old is not None  # after a step
        K = self.K_extended
        for s, c in enumerate(self.C_EXTRA, start=self.n_stages + 1):
            K[s] = self.fun(self.t_old + c * h, self.y_old)


# -- compiled stages --------------------------------------------------------------------------


def with_extra_work(rhs: ca.Function) -> ca.Function:
    """``rhs`` of a state with one more entry, the work of an extra power that is zero."""
    import casadi as ca

    t = ca.MX.sym("t")
    y = ca.MX.sym("y", rhs.size1_in(1) + 1)
    return ca.Function("rhs_with_work", [t, y], [ca.vertcat(rhs(t, y[:-1]), 0)])


def _stages(rhs: ca.Function, n: int, a: NDArray[np.float64], c: NDArray[np.float64],
            first: int, count: int) -> tuple[ca.MX, ca.MX, ca.MX, ca.MX, list[ca.MX]]:
    """Stages ``first … first+count−1`` of an explicit Runge–Kutta method.

    As MX of ``(t, y, h, K[:first])``.
    """
    import casadi as ca

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
        import casadi as ca


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
    """:class:`DOP853` stepping through compiled stages.

    Parameters
    ----------
    fun
        The right-hand side in Python (the first step and its initial step size use it).
    stages
        The same right-hand side's compiled stages (:class:`Stages`).
    """

    def __init__(self, fun: Callable[[float, NDArray[np.float64]], ArrayLike], t0: float,
                 y0: ArrayLike, t_bound: float, *, stages: Stages, **options: Any) -> None:
        super().__init__(fun, t0, y0, t_bound, **options)
        self._step, self._extra = stages.step, stages.extra

    def _stages(self, t: float, y: NDArray[np.float64], h: float) -> NDArray[np.float64]:
        n, stages = self.n, self.n_stages
        out = self._step(np.concatenate([[t, h], y, self.f]))
        self.nfev += stages
        self.K[0] = self.f
        self.K[1:] = out[: stages * n].reshape(stages, n)
        return out[stages * n :]

    def _extra_stages(self, h: float) -> None:
        assert self.t_old is not None and self.y_old is not None  # after a step
        k, stages = self.K_extended, self.n_stages
        extra = self._extra(np.concatenate([[self.t_old, h], self.y_old,
                                            k[: stages + 1].reshape(-1)]))
        self.nfev += len(self.C_EXTRA)
        k[stages + 1 :] = extra.reshape(len(self.C_EXTRA), self.n)
