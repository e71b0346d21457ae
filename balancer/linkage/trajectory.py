"""A motion's input states: waypoints, a time law, and inverse kinematics for a point's path.

A motion (:class:`balancer.model.motions.MotionSpec`) gives waypoints at times. Its path is a
cubic Hermite spline of the time argument ``τ`` through them (zero slopes at the ends, the
three-point differences ``(h₋·δ₊ + h₊·δ₋)/(h₋ + h₊)`` inside), or for ``law = "spline"`` the
periodic cubic spline (:func:`path_values`). The time law gives
``τ(t)`` and its two derivatives (:func:`time_argument`); by the chain rule a path value ``p``
has ``ṗ = p'(τ)·τ̇`` and ``p̈ = p''(τ)·τ̇² + p'(τ)·τ̈``.

Inputs' waypoints are each input's change from the reference pose (rad). A marker point's
waypoints (m) are reached by inverse kinematics on two inputs: the inputs ``θ`` with
``P(θ) = p`` by Newton's method (``J_P = ∂P/∂θ`` from the forward kinematics at unit input
rates), continued from the reference pose along the line to the first waypoint, then from
sample to sample along the path; the rates ``θ̇ = J_P⁻¹·ṗ`` and accelerations ``θ̈ = J_P⁻¹·(p̈ −
P̈|θ̈=0)``. The forward kinematics then places every link, on the reference pose's branch.
"""

from __future__ import annotations

import threading
from collections import OrderedDict
from typing import Literal

import numpy as np
from numpy.typing import NDArray

from ..errors import AssemblyError, SpecError
from ..model.motions import REVOLUTION, MotionSpec
from . import kinematics
from .constraints import GROUND_INDEX
from .inputs import InputState
from .structure import Structure
from .vectors import V

#: Which piece of the path a waypoint belongs to: the one after it, or the one before.
Side = Literal["left", "right"]

#: Steps from the reference pose to a point path's first waypoint, when it is the linkage's
#: length scale away (fewer when nearer).
APPROACH_STEPS = 32
#: Newton iterations at most per inverse-kinematics solve.
MAX_ITERATIONS = 30
#: Newton's method has converged where the point is within this share of the linkage's
#: length scale of its target.
TOLERANCE = 1e-13


def time_argument(spec: MotionSpec, t: NDArray[np.float64]
                  ) -> tuple[NDArray[np.float64], NDArray[np.float64], NDArray[np.float64]]:
    """The path's time argument ``τ`` (s) at times ``t`` (s), with ``dτ/dt`` and ``d²τ/dt²``.

    With ``u = (t − t₀)/T`` over the duration ``T``, ``τ = t₀ + T·g(u)``: the trapezoid's
    ``g`` has rate ``1/(1 − a)`` after a constant acceleration over ``a = acc_time/T``; the
    cubic's ``3u² − 2u³``; the quintic's ``10u³ − 15u⁴ + 6u⁵``; the spline's ``u``. A planned
    motion's pace (rows ``(τₖ, τ̇ₖ)`` at times ``tₖ``) has ``τ̈ = (τ̇ₖ₊₁² − τ̇ₖ²)/(2·Δτₖ)`` on
    each interval: ``τ = τₖ + τ̇ₖ·(t − tₖ) + τ̈·(t − tₖ)²/2``.
    """
    if spec.pace is not None:
        return _paced(spec, np.asarray(t, dtype=float))
    t0, duration = spec.times[0], spec.duration
    u = np.clip((np.asarray(t, dtype=float) - t0) / duration, 0.0, 1.0)
    if spec.law == "cubic":
        g, g1, g2 = 3 * u**2 - 2 * u**3, 6 * u - 6 * u**2, 6 - 12 * u
    elif spec.law == "quintic":
        g = 10 * u**3 - 15 * u**4 + 6 * u**5
        g1 = 30 * u**2 - 60 * u**3 + 30 * u**4
        g2 = 60 * u - 180 * u**2 + 120 * u**3
    elif spec.law == "trapezoid":
        assert spec.acc_time is not None
        a = spec.acc_time / duration
        rate = 1.0 / (1.0 - a)
        acc = rate / a
        rising, falling = u <= a, u >= 1.0 - a
        g = np.where(rising, 0.5 * acc * u**2,
                     np.where(falling, 1.0 - 0.5 * acc * (1.0 - u) ** 2,
                              0.5 * acc * a**2 + rate * (u - a)))
        g1 = np.where(rising, acc * u, np.where(falling, acc * (1.0 - u), rate))
        g2 = np.where(rising, acc, np.where(falling, -acc, 0.0))
    else:  # spline: the waypoints' own pace
        g, g1, g2 = u, np.ones_like(u), np.zeros_like(u)
    return t0 + duration * g, g1, g2 / duration


def _paced(spec: MotionSpec, t: NDArray[np.float64]
           ) -> tuple[NDArray[np.float64], NDArray[np.float64], NDArray[np.float64]]:
    """:func:`time_argument` of a planned motion's pace (constant ``τ̈`` between its rows)."""
    assert spec.pace is not None
    rows = np.asarray(spec.pace, dtype=float)
    knots = spec.pace_times
    tau, rate = rows[:, 0], rows[:, 1]
    acc = (rate[1:] ** 2 - rate[:-1] ** 2) / (2.0 * np.diff(tau))
    t = np.clip(t, knots[0], knots[-1])
    k = np.clip(np.searchsorted(knots, t, side="right") - 1, 0, len(knots) - 2)
    dt = t - knots[k]
    return (np.minimum(tau[k] + rate[k] * dt + 0.5 * acc[k] * dt**2, tau[k + 1]),
            rate[k] + acc[k] * dt, acc[k])


def _slopes(spec: MotionSpec) -> NDArray[np.float64]:
    """The path's slopes ``dp/dτ`` at the waypoints, ``(K, width)``.

    Hermite: zero at the ends, the three-point difference ``(h₋·δ₊ + h₊·δ₋)/(h₋ + h₊)`` inside.
    Spline: the slopes that make the second derivative continuous everywhere — periodic for a
    closed path (the last waypoint the first), clamped for an open one (zero slopes at its
    ends: from rest to rest). A tridiagonal system (cyclic where periodic), solved densely for a
    few waypoints; a table of many (a motion read from a file) by SciPy's ``CubicSpline`` with
    the same end conditions (its import costs half a second: only then).
    """
    knots = np.asarray(spec.times, dtype=float)
    values = np.asarray(spec.path, dtype=float)
    h = np.diff(knots)
    delta = np.diff(values, axis=0) / h[:, None]
    slopes = np.zeros_like(values)
    if spec.law != "spline":
        slopes[1:-1] = ((h[:-1, None] * delta[1:] + h[1:, None] * delta[:-1])
                        / (h[:-1] + h[1:])[:, None])
        return slopes
    periodic = spec.closed
    if periodic:  # (its ends equal to 1e-12: made one, as SciPy's periodic spline asks)
        values = values.copy()
        values[-1] = values[0]
    if len(knots) > DENSE_KNOTS:
        from scipy.interpolate import CubicSpline  # (a long table: a banded solve)

        fitted = CubicSpline(knots, values, bc_type="periodic" if periodic else "clamped")
        return np.asarray(fitted(knots, 1), dtype=float)
    # At waypoint i, continuity of p'' between the segments before (h₋, δ₋) and after
    # (h₊, δ₊): h₊·m₋ + 2(h₋ + h₊)·m + h₋·m₊ = 3(h₊·δ₋ + h₋·δ₊); cyclic over the K − 1
    # waypoints where periodic, else the inner ones with m = 0 at both ends.
    count = len(h)
    if periodic:
        system = np.zeros((count, count))
        rhs = np.zeros((count, values.shape[1]))
        for i in range(count):
            before, after = (i - 1) % count, i
            system[i, before] += h[after]
            system[i, i] += 2 * (h[before] + h[after])
            system[i, (i + 1) % count] += h[before]
            rhs[i] = 3 * (h[after] * delta[before] + h[before] * delta[after])
        slopes[:-1] = np.linalg.solve(system, rhs)
        slopes[-1] = slopes[0]
        return slopes
    inner = count - 1
    if inner > 0:
        system = np.zeros((inner, inner))
        rhs = np.zeros((inner, values.shape[1]))
        for j in range(inner):  # waypoint j + 1, between segments j and j + 1
            before, after = j, j + 1
            system[j, j] = 2 * (h[before] + h[after])
            if j > 0:
                system[j, j - 1] = h[after]
            if j < inner - 1:
                system[j, j + 1] = h[before]
            rhs[j] = 3 * (h[after] * delta[before] + h[before] * delta[after])
        slopes[1:-1] = np.linalg.solve(system, rhs)
    return slopes


#: Waypoints up to which a spline's slopes are solved densely here (more: SciPy's banded solve).
DENSE_KNOTS = 200


def path_at(spec: MotionSpec, tau: NDArray[np.float64], side: Side = "right"
            ) -> tuple[NDArray[np.float64], NDArray[np.float64], NDArray[np.float64]]:
    """The path's values at arguments ``tau`` (s) and their first two derivatives by ``τ``.

    At a waypoint, the piece after it (``side="right"``) or before it (``"left"``): the
    Hermite pieces' second derivatives differ there.

    Arrays ``(N, width)``: a point's ``(x, y)`` (m) or each input's change from the reference
    pose (rad). The cubic on each segment in Hermite form (``s`` its share of the segment
    ``h``): ``p = (2s³ − 3s² + 1)·p₀ + (s³ − 2s² + s)·h·m₀ + (−2s³ + 3s²)·p₁ + (s³ − s²)·h·m₁``.
    A revolution's path (:data:`~balancer.model.motions.REVOLUTION`) is straight: its input
    turns at one rate. (Written here rather than taken from scipy.interpolate, whose import
    alone costs a command half a second; the tests compare it with scipy's splines.)
    """
    knots = np.asarray(spec.times, dtype=float)
    values = np.asarray(spec.path, dtype=float)
    tau = np.asarray(tau, dtype=float)
    if spec.along == REVOLUTION:
        slope = (values[-1] - values[0]) / (knots[-1] - knots[0])
        return (values[0] + np.multiply.outer(tau - knots[0], slope),
                np.broadcast_to(slope, (tau.size, slope.size)).copy(),
                np.zeros((tau.size, slope.size)))
    if spec.law == "spline" and spec.closed:
        values = values.copy()
        values[-1] = values[0]
    slopes = _slopes(spec)
    seg = np.clip(np.searchsorted(knots, tau, side=side) - 1, 0, len(knots) - 2)
    h = (knots[seg + 1] - knots[seg])[:, None]
    s = ((tau - knots[seg])[:, None]) / h
    p0, p1, m0, m1 = values[seg], values[seg + 1], slopes[seg] * h, slopes[seg + 1] * h
    s2, s3 = s * s, s * s * s
    p = (2 * s3 - 3 * s2 + 1) * p0 + (s3 - 2 * s2 + s) * m0 + (-2 * s3 + 3 * s2) * p1 \
        + (s3 - s2) * m1
    d1 = ((6 * s2 - 6 * s) * p0 + (3 * s2 - 4 * s + 1) * m0 + (-6 * s2 + 6 * s) * p1
          + (3 * s2 - 2 * s) * m1) / h
    d2 = ((12 * s - 6) * p0 + (6 * s - 4) * m0 + (-12 * s + 6) * p1 + (6 * s - 2) * m1) / h**2
    return p, d1, d2


def path_values(spec: MotionSpec, t: NDArray[np.float64]
                ) -> tuple[NDArray[np.float64], NDArray[np.float64], NDArray[np.float64]]:
    """The path's values at times ``t`` and their first and second time derivatives.

    :func:`path_at` at the time law's argument, by the chain rule: ``ṗ = p'·τ̇``,
    ``p̈ = p''·τ̇² + p'·τ̈``.
    """
    tau, rate, acc = time_argument(spec, t)
    p, d1, d2 = path_at(spec, tau)
    return p, d1 * rate[:, None], d2 * rate[:, None] ** 2 + d1 * acc[:, None]


def break_times(spec: MotionSpec) -> NDArray[np.float64]:
    """The times (s) inside the motion where its accelerations may jump or kink.

    Where the path's argument ``τ`` passes an inner waypoint (the cubic pieces join there),
    the trapezoid's ends of acceleration and deceleration, and a pace's rows. ``τ(t)``
    increases: each waypoint's time is found by bisection to rounding.
    """
    t0, t1 = spec.start, spec.end
    inner = np.asarray(spec.times[1:-1], dtype=float)
    low, high = np.full(inner.shape, t0), np.full(inner.shape, t1)
    for _ in range(64):
        mid = 0.5 * (low + high)
        below = time_argument(spec, mid)[0] < inner
        low, high = np.where(below, mid, low), np.where(below, high, mid)
    out = [*(0.5 * (low + high))]
    if spec.pace is not None:
        out += [*spec.pace_times]
    elif spec.law == "trapezoid":
        assert spec.acc_time is not None
        out += [t0 + spec.acc_time, t1 - spec.acc_time]
    return np.unique(np.array([t for t in out if t0 < t < t1], dtype=float))


def sample_times(spec: MotionSpec) -> NDArray[np.float64]:
    """The motion's sampled times: ``samples`` equally spaced, both ends included, s."""
    return np.linspace(spec.start, spec.end, spec.samples)


def input_state(structure: Structure, spec: MotionSpec,
                t: NDArray[np.float64] | None = None) -> InputState:
    """The inputs' states along a motion at times ``t`` (default: :func:`sample_times`).

    At the motion's samples they depend on the geometry and the motion alone: kept with the
    geometry and given again (their arrays shared: not to be written into).

    Raises
    ------
    SpecError
        If the waypoints do not match the linkage's inputs, or the point is unknown.
    AssemblyError
        If a point's path leaves the workspace (no pose puts the point there, or the path
        passes a singular pose).
    """
    if t is None:  # the motion's samples: what it is analysed and balanced at, again and again
        with _STATES_LOCK:
            kept = structure.kinematic.setdefault("motion states", OrderedDict())
            known = kept.get(spec)
        if known is None:
            known = _input_state(structure, spec, sample_times(spec))
            with _STATES_LOCK:
                kept[spec] = known
                while len(kept) > STATES_KEPT:
                    kept.popitem(last=False)
        return known
    t = np.asarray(t, dtype=float)
    if spec.point is None:
        return _input_state(structure, spec, t)
    return _point_state_at(structure, spec, t)


#: A motion's input states at its samples are kept with the geometry
#: (:attr:`~balancer.linkage.structure.Structure.kinematic`): a design, its redesign and their
#: analyses ask for the same ones (the last :data:`STATES_KEPT` motions).
STATES_KEPT = 16
_STATES_LOCK = threading.Lock()


def _input_state(structure: Structure, spec: MotionSpec, times: NDArray[np.float64]
                 ) -> InputState:
    """:func:`input_state` at ``times``, computed."""
    p, v, a = path_values(spec, times)
    inputs = structure.inputs
    reference = np.array(structure.input_references)
    if spec.point is None:
        if p.shape[1] != len(inputs):
            raise SpecError(f"each waypoint must give one angle per input "
                            f"({', '.join(structure.linkage.inputs)})", key="path",
                            value=list(spec.path[0]))
        state = InputState.of(list((p + reference).T), list(v.T), list(a.T))
        _check_assembles(structure, spec, state, times, p)
        return state
    return _inverse_kinematics(structure, spec, p, v, a)


def _check_assembles(structure: Structure, spec: MotionSpec, state: InputState,
                     times: NDArray[np.float64], p: NDArray[np.float64]) -> None:
    """Raise where the inputs' own path puts the linkage where it does not assemble."""
    with np.errstate(all="ignore"):
        pose = kinematics.positions(structure, state)
    count = times.size
    kept = np.ones(count, dtype=bool)
    for angle in pose.angles:
        kept &= np.isfinite(np.broadcast_to(np.asarray(angle, dtype=float), (count,)))
    if not kept.all():
        i = int(np.argmin(kept))
        raise AssemblyError(
            f"the inputs' path leaves the workspace at t = {float(times[i]):g} s (the linkage "
            "does not assemble there)", key="path", value=[float(x) for x in p[i]])


def marker(structure: Structure, point: str) -> tuple[int, V]:
    """The link that carries ``point`` (a moving one) and the point in its frame."""
    links = [k for k in structure.point_links.get(point, ()) if k != GROUND_INDEX]
    if not links:
        known = ", ".join(p for p, ks in structure.point_links.items()
                          if any(k != GROUND_INDEX for k in ks))
        raise SpecError(f"must name a point of a moving link ({known})", key="point",
                        value=point)
    return links[0], structure.local[(links[0], point)]


def _point_and_jacobian(structure: Structure, k: int, local: V, theta: NDArray[np.float64]
                        ) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
    """The point at inputs ``theta`` ``(m, N)`` and ``∂P/∂θ``, ``(N, 2)`` and ``(N, 2, m)``."""
    m = theta.shape[0]
    zeros = [np.zeros(theta.shape[1])] * m
    pose = kinematics.positions(structure, InputState.of(list(theta)))
    at = pose.point(k, local)
    jac = np.empty((theta.shape[1], 2, m))
    for i in range(m):
        unit = [np.ones(theta.shape[1]) if j == i else zeros[j] for j in range(m)]
        vel, rate, _, _ = kinematics.rates(structure, pose, InputState.of(list(theta), unit),
                                           accelerations=False)
        r = pose.rotate(k, local)
        jac[:, 0, i] = vel[k].x - r.y * rate[k]
        jac[:, 1, i] = vel[k].y + r.x * rate[k]
    return np.column_stack([at.x, at.y]), jac


def _newton(structure: Structure, k: int, local: V, theta: NDArray[np.float64],
            target: NDArray[np.float64]) -> tuple[NDArray[np.float64], NDArray[np.bool_]]:
    """Newton's method for ``P(θ) = target`` at every column at once; where it converged."""
    scale = structure.length_scale()
    done = np.zeros(theta.shape[1], dtype=bool)
    for _ in range(MAX_ITERATIONS):
        with np.errstate(all="ignore"):
            at, jac = _point_and_jacobian(structure, k, local, theta)
            residual = at - target
            done = np.all(np.abs(residual) <= TOLERANCE * scale, axis=1)
            if done.all():
                break
            ok = np.isfinite(jac).all(axis=(1, 2)) & (np.abs(np.linalg.det(jac)) > 0)
            step = np.zeros_like(residual)
            if ok.any():
                step[ok] = np.linalg.solve(jac[ok], residual[ok][:, :, None])[:, :, 0]
            step[~ok] = np.nan
        theta = theta - step.T
    return theta, done


#: Samples of a point's path solved one after another (the rest at once, from those).
PATH_STEPS = 24


def _along_path(structure: Structure, spec: MotionSpec, k: int, local: V,
                first: NDArray[np.float64], p: NDArray[np.float64]) -> NDArray[np.float64]:
    """The inputs at every sample of the path ``p`` ``(N, 2)``, from ``first`` at its first.

    Up to :data:`PATH_STEPS` samples are solved in order, each from the extrapolation of the
    two before; every sample is then solved at once from the interpolation of those. Where
    that does not converge, or it leaves the branch (a step between samples more than twice
    the largest of the ordered pass), every sample is solved in order.
    """
    count = p.shape[0]
    stride = max(1, (count - 1) // PATH_STEPS)
    coarse = np.unique(np.append(np.arange(0, count, stride), count - 1))
    known = _in_order(structure, spec, k, local, first, p, coarse)
    if coarse.size == count:
        return known
    guess = np.array([np.interp(np.arange(count), coarse, row) for row in known])
    theta, done = _newton(structure, k, local, guess, p)
    step = np.max(np.abs(np.diff(theta, axis=1))) if done.all() else np.inf
    if done.all() and step <= 2 * np.max(np.abs(np.diff(known, axis=1))) / stride + 1e-12:
        return theta
    return _in_order(structure, spec, k, local, first, p, np.arange(count))


def _in_order(structure: Structure, spec: MotionSpec, k: int, local: V,
              first: NDArray[np.float64], p: NDArray[np.float64], rows: NDArray[np.intp]
              ) -> NDArray[np.float64]:
    """The inputs at the path's samples ``rows``, each from the ones before (continuation)."""
    out = np.empty((2, rows.size))
    out[:, 0] = first
    for i in range(1, rows.size):
        guess = out[:, i - 1 : i] if i == 1 else 2 * out[:, i - 1 : i] - out[:, i - 2 : i - 1]
        target = p[rows[i] : rows[i] + 1]
        theta, done = _newton(structure, k, local, guess, target)
        if not done.all():
            theta, done = _newton(structure, k, local, out[:, i - 1 : i], target)
        if not done.all():
            when = spec.start + rows[i] * spec.duration / (p.shape[0] - 1)
            raise AssemblyError(
                f"the point's path leaves the workspace at t = {when:g} s (no pose puts the "
                "point there, or the path passes a singular pose)",
                key="path", value=[float(target[0, 0]), float(target[0, 1])])
        out[:, i] = theta[:, 0]
    return out


def _inverse_kinematics(structure: Structure, spec: MotionSpec, p: NDArray[np.float64],
                        v: NDArray[np.float64], a: NDArray[np.float64]) -> InputState:
    """The inputs that put ``spec.point`` on its path (see the module docstring)."""
    if len(structure.inputs) != 2:
        raise SpecError(f"a point's path places two inputs; this linkage has "
                        f"{len(structure.inputs)}: give the inputs' own waypoints instead",
                        key="point", value=spec.point)
    assert spec.point is not None
    k, local = marker(structure, spec.point)
    reference = np.array(structure.input_references)[:, None]
    start = structure.point_position(spec.point)
    theta = reference.copy()
    way = float(np.hypot(p[0, 0] - start.x, p[0, 1] - start.y)) / structure.length_scale()
    steps = max(1, int(np.ceil(APPROACH_STEPS * min(way, 1.0))))
    for step in range(1, steps + 1):  # from the reference pose to the first waypoint
        goal = (start.x + (p[0, 0] - start.x) * step / steps,
                start.y + (p[0, 1] - start.y) * step / steps)
        theta, done = _newton(structure, k, local, theta, np.array([goal]))
        if not done.all():
            raise AssemblyError(
                "the point's first waypoint cannot be reached from the reference pose (no pose "
                "puts it there, or the way passes a singular pose)", key="path",
                value=list(spec.path[0]))
    out = _along_path(structure, spec, k, local, theta[:, 0], p)
    return _point_state(structure, k, local, out, v, a)


def _point_state_at(structure: Structure, spec: MotionSpec, t: NDArray[np.float64]
                    ) -> InputState:
    """A point's path at any times ``t`` of the motion (in any order).

    From the motion's samples (:func:`input_state`, found by continuation): their inputs
    interpolated in time start Newton's steps at every time at once; a time whose solution
    does not converge, or lands farther from its start than the samples are apart (another
    branch), is refused.
    """
    assert spec.point is not None
    k, local = marker(structure, spec.point)
    known = input_state(structure, spec)
    samples = sample_times(spec)
    guess = np.array([np.interp(t, samples, np.asarray(x, dtype=float))
                      for x in known.positions])
    p, v, a = path_values(spec, t)
    theta, done = _newton(structure, k, local, guess, p)
    apart = max(float(np.max(np.abs(np.diff(np.asarray(x, dtype=float)))))
                for x in known.positions) if samples.size > 1 else 0.0
    off = np.max(np.abs(theta - guess), axis=0) > max(apart, 1e-12)
    if not done.all() or off.any():
        bad = int(np.argmax(~done | off))
        raise AssemblyError(
            f"the point's path cannot be followed at t = {float(t[bad]):g} s from the "
            "motion's samples (a singular pose near it: take more samples)", key="path",
            value=[float(p[bad, 0]), float(p[bad, 1])])
    return _point_state(structure, k, local, theta, v, a)


def path_derivatives(structure: Structure, spec: MotionSpec, tau: NDArray[np.float64],
                     side: Side = "right") -> InputState:
    """The inputs along the path at arguments ``tau`` (s): ``q``, ``dq/dτ``, ``d²q/dτ²``.

    As an :class:`InputState` of positions (rad, absolute), first and second derivatives by
    the path's argument — the inputs' state where ``τ̇ = 1``, ``τ̈ = 0``: at any time law,
    ``q̇ = q'·τ̇`` and ``q̈ = q''·τ̇² + q'·τ̈``. A point's path by inverse kinematics, each
    argument's Newton steps started from the motion's samples (on their branch). At a
    waypoint, the path's piece after it or before it (``side``, as :func:`path_at`).

    Raises
    ------
    AssemblyError
        If the path leaves the workspace at one of the arguments.
    """
    tau = np.asarray(tau, dtype=float)
    p, d1, d2 = path_at(spec, tau, side)
    if spec.point is None:
        reference = np.array(structure.input_references)
        state = InputState.of(list((p + reference).T), list(d1.T), list(d2.T))
        _check_assembles(structure, spec, state, tau, p)
        return state
    k, local = marker(structure, spec.point)
    known = input_state(structure, spec)
    argument = time_argument(spec, sample_times(spec))[0]
    guess = np.array([np.interp(tau, argument, np.asarray(x, dtype=float))
                      for x in known.positions])
    theta, done = _newton(structure, k, local, guess, p)
    if not done.all():
        bad = int(np.argmin(done))
        raise AssemblyError(
            f"the point's path cannot be followed at its argument {float(tau[bad]):g} s from "
            "the motion's samples (a singular pose near it: take more samples)", key="path",
            value=[float(p[bad, 0]), float(p[bad, 1])])
    return _point_state(structure, k, local, theta, d1, d2)


def _point_state(structure: Structure, k: int, local: V, out: NDArray[np.float64],
                 v: NDArray[np.float64], a: NDArray[np.float64]) -> InputState:
    """The inputs' rates and accelerations where point ``local`` of link ``k`` has ``(v, a)``.

    ``out`` the inputs' positions ``(2, N)``; ``v``, ``a`` the point's velocity and
    acceleration ``(N, 2)``: the point's Jacobian by the inputs solves for the rates, and
    for the accelerations less the point's acceleration at zero input accelerations.
    """
    _, jac = _point_and_jacobian(structure, k, local, out)
    rates = np.linalg.solve(jac, v[:, :, None])[:, :, 0]
    mo = kinematics.motion(structure, InputState.of(list(out), list(rates.T)))
    drift = mo.point_acceleration(k, local)
    accelerations = np.linalg.solve(
        jac, (a - np.column_stack([drift.x, drift.y]))[:, :, None])[:, :, 0]
    return InputState.of(list(out), list(rates.T), list(accelerations.T))
