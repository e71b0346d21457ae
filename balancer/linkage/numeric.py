"""Positions of a group without a closed form, by Newton's method with continuation.

A group that is not a dyad of :mod:`.kinematics` (the four links of a Stephenson chain driven
from its binary link, a dyad with two prismatic pairs) is solved from its constraint equations
(:mod:`.structure`). A table of its coordinates over one revolution is built once by
continuation from the reference pose (:data:`TABLE_STEPS` steps, each Newton's method started
from a quadratic extrapolation of the steps before); at any crank angle the table, interpolated,
starts Newton's method, run on all the angles at once to rounding. Angles beyond where the
continuation stopped (the group locks or cannot be assembled) are NaN.

A linkage with several inputs has no one-dimensional table: each state is reached from the
reference pose along the straight line in the inputs' space (:data:`PATH_STEPS` steps per
radian of the largest input's change, each Newton's method from the linear extrapolation of
the two before, all states at once); a state whose path meets a pose where the group cannot
be assembled or locks is NaN.
"""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import replace

import numpy as np
from numpy.typing import NDArray

from .constraints import Group, Pose, group_jacobian
from .inputs import InputState
from .structure import Structure
from .vectors import NUMPY, Factor, Num, OpsLike, V

#: How the links found before a group are placed at input states: the general kinematics'
#: positions (:func:`balancer.linkage.kinematics.positions`), which solves the groups in order
#: and calls this module for a numeric one; passed in, so that the two modules do not import
#: each other.
Positions = Callable[[Structure, InputState], Pose]

#: Steps per radian from the reference pose to each state along the line in the inputs'
#: space, for a linkage with several inputs (by the largest input's change; at least
#: :data:`LEAST_PATH_STEPS`): a step of 1.2° at most.
PATH_STEPS = 48
LEAST_PATH_STEPS = 4

#: Steps of the continuation table over one revolution.
TABLE_STEPS = 720
#: Newton iterations at most, per solve.
MAX_ITERATIONS = 30
#: Newton's method has converged where every residual is at most this fraction of the
#: linkage's length scale.
NEWTON_TOLERANCE = 1e-13
#: Up to this many angles at once (the continuation's single steps), Newton's steps are
#: LAPACK's solves; beyond, the structured solve of :class:`~.vectors.Factor`.
FEW_ANGLES = 128


def _residual(g: Group, pose: Pose) -> list[Num]:
    return [r for c in g.constraints for r in c.residual(pose)]


def _set(pose: Pose, g: Group, q: NDArray[np.float64]) -> None:
    """Place the group's links from their coordinates ``q``, ``(N, 3·|g|)``."""
    _place(pose, g, list(q.T), NUMPY)


def _place(pose: Pose, g: Group, q: list[Num], ops: OpsLike) -> None:
    """Place the group's links from their coordinates, ``3·|g|`` arrays or symbols."""
    for i, k in enumerate(g.links):
        pose.origins[k] = V(q[3 * i], q[3 * i + 1])
        pose.angles[k] = q[3 * i + 2]
        pose.cos[k] = ops.cos(q[3 * i + 2])
        pose.sin[k] = ops.sin(q[3 * i + 2])


#: Largest angle step (rad) after which the cosine and sine are updated by the step's
#: Taylor polynomial instead of computed anew: its remainder ``δ³/6`` is then below 2e-19.
TAYLOR_STEP = 1e-6


def _moved(pose: Pose, g: Group, q: list[Num], step: list[Num], ops: OpsLike = NUMPY
           ) -> list[Num]:
    """Place the group's links at ``q − step`` (lists of ``3·|g|`` arrays); return those.

    A link whose angle moves by at most :data:`TAYLOR_STEP` everywhere has its cosine and
    sine rotated by ``−δ`` through ``cos δ ≈ 1 − δ²/2``, ``sin δ ≈ δ`` (remainders below
    rounding) instead of two transcendental evaluations: Newton's last step from a good start.
    On symbols (``ops`` not numpy) always so: the caller checks the steps.
    """
    out = [x - d for x, d in zip(q, step, strict=True)]
    for i, k in enumerate(g.links):
        pose.origins[k] = V(out[3 * i], out[3 * i + 1])
        pose.angles[k] = theta = out[3 * i + 2]
        delta = step[3 * i + 2]
        if ops is not NUMPY or np.all(np.abs(delta) <= TAYLOR_STEP):  # NaN: computed anew
            c, s = pose.cos[k], pose.sin[k]
            half = 1.0 - 0.5 * delta * delta
            pose.cos[k], pose.sin[k] = c * half + s * delta, s * half - c * delta
        else:
            pose.cos[k], pose.sin[k] = np.cos(theta), np.sin(theta)
    return out


def _jacobian(g: Group, pose: Pose, n: int) -> NDArray[np.float64]:
    rows = group_jacobian(g, pose)[0]
    jac = np.zeros((n, len(rows), len(rows)))
    for i, row in enumerate(rows):
        for j, v in enumerate(row):
            jac[:, i, j] = v
    return jac


def _dense_step(jac: NDArray[np.float64], res: NDArray[np.float64]) -> NDArray[np.float64]:
    """Newton's step ``J⁻¹·r`` per system by LAPACK (NaN where ``J`` is singular)."""
    try:
        return np.asarray(np.linalg.solve(jac, res[:, :, None])[:, :, 0], dtype=float)
    except np.linalg.LinAlgError:
        step = np.full(res.shape, np.nan)
        ok = np.abs(np.linalg.det(jac)) > 0
        if ok.any():
            step[ok] = np.linalg.solve(jac[ok], res[ok][:, :, None])[:, :, 0]
        return step


def newton(g: Group, pose: Pose, q: NDArray[np.float64], scale: float,
           tol: float = NEWTON_TOLERANCE) -> tuple[NDArray[np.float64], NDArray[np.bool_]]:
    """Newton's method on the group's equations at every angle at once.

    ``q`` is ``(N, 3·|g|)`` (each link's ``x``, ``y``, ``θ``); the links found before are in
    ``pose``. Returns the solution and where it converged (residual below ``tol`` of
    ``scale``, a length); on return ``pose`` holds the group's links at the solution.
    """
    n = q.shape[0]
    columns = list(np.array(np.asarray(q, dtype=float).T, order="C"))  # contiguous columns
    _place(pose, g, columns, NUMPY)
    done = np.zeros(n, dtype=bool)
    for _ in range(MAX_ITERATIONS):
        res = [np.broadcast_to(np.asarray(r, dtype=float), (n,)) for r in _residual(g, pose)]
        size = np.abs(res[0])
        for r in res[1:]:
            size = np.maximum(size, np.abs(r))
        done = size <= tol * scale
        if done.all():
            break
        with np.errstate(all="ignore"):
            if n <= FEW_ANGLES:  # LAPACK per system: less Python than the structured solve
                dense = _dense_step(_jacobian(g, pose, n), np.column_stack(res))
                step = list(dense.T)
            else:
                solved = Factor(group_jacobian(g, pose)[0]).solve([[r] for r in res])
                step = [np.broadcast_to(x[0], (n,)) for x in solved]
            step = [np.where(done, 0.0, d) for d in step]
            columns = _moved(pose, g, columns, step)
    return np.column_stack(columns), done


def _coordinates(structure: Structure, g: Group) -> NDArray[np.float64]:
    q = structure.reference_coordinates()
    return np.concatenate([q[3 * k : 3 * k + 3] for k in g.links])


def table(structure: Structure, g: Group, place: Positions
          ) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
    """The group's coordinates over one revolution from the reference pose (cached).

    ``place`` places the links found before the group (:data:`Positions`).

    Returns ``(theta1, q)``: ``2·TABLE_STEPS + 1`` angles a turn either way of the reference's
    input angle, and their coordinates (angles continuous), NaN beyond where the continuation
    stopped (the group locks or cannot be assembled).

    The continuation solves up to :data:`STRIDE` table rows at a time by one Newton solve
    over all of them (:func:`_continue`). Where the turn upwards comes back to the reference
    pose, the turn downwards is the same poses, each link's angle less what it turns in a
    revolution; otherwise it is continued too.
    """
    cache = structure.kinematic.setdefault("numeric tables", {})
    key = structure.groups.index(g)
    if key in cache:
        return cache[key]
    start = structure.ref_angle[structure.input]
    step = 2 * math.pi / TABLE_STEPS
    before = structure.groups[: structure.groups.index(g)]
    partial = replace(structure, groups=tuple(before), cache={},
                      kinematic={})  # places the known links
    q_ref = _coordinates(structure, g)
    out = np.full((2 * TABLE_STEPS + 1, q_ref.size), np.nan)
    angles = start + step * np.arange(-TABLE_STEPS, TABLE_STEPS + 1, dtype=float)
    out[TABLE_STEPS] = q_ref
    _continue(structure, partial, g, angles, out, 1, place)
    turn = _turn(structure, out[-1] - q_ref)
    if turn is not None:
        out[:TABLE_STEPS] = out[TABLE_STEPS:-1] - turn
    else:
        _continue(structure, partial, g, angles, out, -1, place)
    result = (angles, out)
    cache[key] = result
    return result


#: The largest stride of the continuation, in table steps.
STRIDE = 32


def _continue(structure: Structure, partial: Structure, g: Group, angles: NDArray[np.float64],
              out: NDArray[np.float64], direction: int, place: Positions) -> None:
    """Fill ``out``'s rows from the reference's (the middle row) towards ``direction``.

    The continuation steps by a stride of table rows that adapts: each step solves the next
    ``stride`` rows by one Newton solve over all of them at once, started from the quadratic
    through the rows found a stride and two strides back. The step is taken where every row
    converges to within a tenth of the last stride's change of its start: a branch the
    continuation did not leave (a jump to another branch is a whole link length away). After
    two steps taken the stride doubles (up to :data:`STRIDE`); a step refused halves it. At a
    stride of one row (the start, near a toggle or the end) the row is taken where Newton's
    method converges, and the table stops at the first that does not.
    """
    scale = structure.length_scale()
    middle = TABLE_STEPS
    done = [middle]  # rows found, in order away from the middle

    def solve_at(rows: NDArray[np.intp], guess: NDArray[np.float64]
                 ) -> tuple[NDArray[np.float64], NDArray[np.bool_]]:
        pose = place(partial, InputState.crank(angles[rows]))
        with np.errstate(all="ignore"):
            return newton(g, pose, guess, scale)

    i, stride, taken = 0, 1, 0
    while i < TABLE_STEPS:
        if taken >= 2 and 2 * stride <= STRIDE and len(done) > 4 * stride:
            stride, taken = 2 * stride, 0
        while stride > 1 and i + stride > TABLE_STEPS:
            stride //= 2
        rows = middle + direction * np.arange(i + 1, i + stride + 1)
        back = [out[j] for j in done[-1 - 2 * stride :: stride]]  # two strides back, one, now
        if len(back) < 3:  # the first rows: from the reference pose, then a line
            guess = np.broadcast_to(2 * back[-1] - back[0], (1, back[0].size))
        else:  # Newton's form at t = u/stride strides on: y0 + t·Δ + t(t+1)/2·Δ²
            t = (np.arange(1, stride + 1) / stride)[:, None]
            d1, d2 = back[2] - back[1], back[2] - 2 * back[1] + back[0]
            guess = back[2] + t * d1 + 0.5 * t * (t + 1) * d2
        q, ok = solve_at(rows, guess)
        if not (ok.all() and np.all(np.isfinite(q))):
            if stride == 1:
                return
            stride, taken = stride // 2, 0
            continue
        if stride > 1:
            moved = float(np.max(np.abs(back[2] - back[1])))
            if np.max(np.abs(q - guess)) > 0.1 * moved + 1e-12 * scale:
                stride, taken = stride // 2, 0
                continue
        out[rows] = q
        done.extend(rows)
        i += stride
        taken += 1


def _turn(structure: Structure, change: NDArray[np.float64]) -> NDArray[np.float64] | None:
    """What one revolution adds to the group's coordinates, if it ends at the reference pose.

    ``change`` is the coordinates after a turn less the reference's: the pose is the same if
    the origins are back (to 1e-9 of the length scale) and each angle has turned by a whole
    number of revolutions (to 1e-9 rad); then the exact change (zero or ``2πk``), else None.
    """
    if not np.all(np.isfinite(change)):
        return None
    turns = np.round(change[2::3] / (2 * math.pi))
    exact = np.zeros_like(change)
    exact[2::3] = 2 * math.pi * turns
    tol = np.tile([1e-9 * structure.length_scale(), 1e-9 * structure.length_scale(), 1e-9],
                  change.size // 3)
    return exact if np.all(np.abs(change - exact) <= tol) else None


def start(structure: Structure, g: Group, theta1: NDArray[np.float64],
          place: Positions) -> tuple[NDArray[np.float64], NDArray[np.bool_]]:
    """Where Newton's method starts for numeric group ``g`` at crank angles ``theta1``.

    Returns the group's coordinates from its continuation table (:func:`table`, by
    :func:`_cubic`), ``(N, 3·|g|)``, NaN where the table has none, and where it has
    (``inside``). A table that stops both ways spans less than a turn in general: an angle
    is then taken where it falls in that span, whichever side of the reference.
    """
    theta1 = np.atleast_1d(np.asarray(theta1, dtype=float))
    angles, tab = table(structure, g, place)
    begin = angles[TABLE_STEPS]
    lo, hi = angles[0], angles[-1]
    # The angle of each request in the table's window (a turn either way of the reference).
    ok_rows = np.all(np.isfinite(tab), axis=1)
    full = ok_rows[TABLE_STEPS:].all()
    valid = angles[ok_rows]
    if full:
        t = begin + np.mod(theta1 - begin, 2 * math.pi)
    elif valid.max() - valid.min() < 2 * math.pi:  # the range found is less than a turn:
        # its one angle there (an angle in it as it is)
        t = theta1 - 2 * math.pi * np.floor((theta1 - valid.min()) / (2 * math.pi))
    else:  # within the range found, in the window nearest the reference
        t = begin + np.remainder(theta1 - begin + math.pi, 2 * math.pi) - math.pi
    cubics = structure.kinematic.setdefault("numeric cubics", {})
    key = structure.groups.index(g)
    if key not in cubics:
        cubics[key] = _cubic_coefficients(tab)
    finite_rows = np.flatnonzero(ok_rows)  # one run: the continuation stops at its ends
    guess = _cubic(angles, cubics[key], t, (int(finite_rows[0]), int(finite_rows[-1])))
    inside = (t >= lo) & (t <= hi)
    if not full:
        inside &= (t >= valid.min()) & (t <= valid.max())
    guess[~inside] = np.nan
    return guess, inside


def path_start(structure: Structure, g: Group, state: InputState, place: Positions
               ) -> tuple[NDArray[np.float64], NDArray[np.bool_]]:
    """Where Newton's method starts for numeric group ``g`` of a linkage with several inputs.

    Each state is reached from the reference pose along the straight line in the inputs'
    space, :data:`PATH_STEPS` steps per radian of the largest change (see the module
    docstring). Returns the group's
    coordinates there, ``(N, 3·|g|)``, NaN where the path was lost, and where it was not.
    """
    count = state.count
    reference = np.array(structure.input_references)
    target = np.array([np.broadcast_to(np.asarray(x, dtype=float), (count,))
                       for x in state.positions])
    before = structure.groups[: structure.groups.index(g)]
    partial = replace(structure, groups=tuple(before), cache={}, kinematic={})
    scale = structure.length_scale()
    q = np.tile(_coordinates(structure, g), (count, 1))
    previous = q.copy()
    kept = np.all(np.isfinite(target), axis=0)
    reach = float(np.max(np.abs(target - reference[:, None])[:, kept], initial=0.0))
    steps = max(LEAST_PATH_STEPS, math.ceil(PATH_STEPS * reach))
    for j in range(1, steps + 1):
        at = reference[:, None] + (j / steps) * (target - reference[:, None])
        pose = place(partial, InputState.of(list(at)))
        guess = q if j == 1 else 2 * q - previous
        with np.errstate(all="ignore"):
            found, done = newton(g, pose, guess, scale)
        kept &= done & np.all(np.isfinite(found), axis=1)
        previous, q = q, np.where(kept[:, None], found, q)
    return np.where(kept[:, None], q, np.nan), kept


def solve_group(structure: Structure, g: Group, pose: Pose, state: InputState,
                place: Positions, gaps: list[Num] | None = None) -> None:
    """Place the links of numeric group ``g`` in ``pose`` at the input states ``state``.

    ``place`` places links found before it (:data:`Positions`); ``gaps``, if a list,
    receives the group's assembly gap (:func:`assembly_gap`).
    """
    if state.size == 1:
        guess, inside = start(structure, g, np.asarray(state.positions[0], dtype=float), place)
    else:
        guess, inside = path_start(structure, g, state, place)
    q, done = newton(g, pose, np.where(np.isfinite(guess), guess, 0.0), structure.length_scale())
    lost = ~(done & inside)
    if lost.any():
        q[lost] = np.nan
        _set(pose, g, q)
    if gaps is not None:
        gaps.append(assembly_gap(structure, g, pose, q.shape[0]))


def solve_group_symbolic(g: Group, pose: Pose, guess: list[Num], ops: OpsLike,
                         iterations: int = 2, steps: list[Num] | None = None) -> list[Num]:
    """Place numeric group ``g``'s links in ``pose`` by Newton's method on symbols.

    ``iterations`` steps from ``guess`` (the group's coordinates, ``3·|g|`` symbols: a good
    start, within the quadratic convergence of Newton's method); returns the residual of the
    group's equations at the result, for the caller to check that it converged.

    With a list ``steps``, the last step's cosines and sines come from the previous ones by
    the step's Taylor polynomial (as :func:`_moved`; valid where every angle moves by at
    most :data:`TAYLOR_STEP`) and ``steps`` receives the angles' changes for the caller to
    check that.
    """
    q = list(guess)
    _place(pose, g, q, ops)
    for i in range(iterations):
        residual = _residual(g, pose)
        step = [d[0] for d in
                ops.factor(group_jacobian(g, pose)[0]).solve([[r] for r in residual])]
        if steps is not None and i == iterations - 1:
            q = _moved(pose, g, q, step, ops)
            steps.extend(step[3 * j + 2] for j in range(len(g.links)))
        else:
            q = [x - d for x, d in zip(q, step, strict=True)]
            _place(pose, g, q, ops)
    return _residual(g, pose)


def _cubic(angles: NDArray[np.float64], coefficients: NDArray[np.float64],
           t: NDArray[np.float64], rows: tuple[int, int] | None = None
           ) -> NDArray[np.float64]:
    """The table at angles ``t`` by cubic interpolation on its uniform grid, ``(N, 3·|g|)``.

    Through the four rows around each angle (Lagrange's cubic; at the ends of the table or of
    its finite rows ``rows`` (first, last), the nearest four of those, or NaN if it has fewer):
    its error is ``O(h⁴)`` of the table's step ``h``, ~1e-8 of the coordinates at 720 steps a
    turn, so that one Newton step takes it to rounding. ``coefficients`` are the cubics' per
    four rows (:func:`_cubic_coefficients`): an angle costs one gather and Horner's rule.
    """
    step = angles[1] - angles[0]
    x = (t - angles[0]) / step
    finite = np.isfinite(x)
    first, last = (0, angles.size - 1) if rows is None else rows
    i = np.clip(np.floor(np.where(finite, x, 0.0)).astype(np.int64) - 1, first,
                max(first, last - 3))
    u = x - i  # in [1, 2] inside the table (the nodes are at 0, 1, 2, 3), [0, 3] at its ends
    width = coefficients.shape[1]
    picked = np.take(coefficients.reshape(4 * width, -1), i, axis=1).reshape(4, width, -1)
    out = ((picked[3] * u + picked[2]) * u + picked[1]) * u + picked[0]
    out[:, ~finite] = np.nan
    return out.T


def _cubic_coefficients(tab: NDArray[np.float64]) -> NDArray[np.float64]:
    """Power-basis coefficients of Lagrange's cubic through rows ``i … i+3`` at ``u = 0 … 3``.

    ``(4, 3·|g|, rows − 3)``: ``p(u) = a0 + a1·u + a2·u² + a3·u³`` for every start row ``i``.
    """
    y0, y1, y2, y3 = (tab[j : tab.shape[0] - 3 + j].T for j in range(4))
    return np.ascontiguousarray(np.stack([
        y0,
        (-11 * y0 + 18 * y1 - 9 * y2 + 2 * y3) / 6,
        y0 - 2.5 * y1 + 2 * y2 - 0.5 * y3,
        (-y0 + 3 * y1 - 3 * y2 + y3) / 6,
    ]))


def assembly_gap(structure: Structure, g: Group, pose: Pose, n: int) -> NDArray[np.float64]:
    """How far the group is from a singular pose: ``(σ_min/σ_max)²`` of its Jacobian.

    The Jacobian of the group's constraints in its links' coordinates, made dimensionless
    (angles times the linkage's length scale, angle rows likewise), so that it is 1 for a
    well-conditioned group and 0 where two of its links align (a toggle, where the crank's
    motion no longer fixes theirs) — the counterpart of the dyads' gap, a squared sine of a
    transmission angle. NaN where the group is not placed.
    """
    scale = structure.length_scale()
    jac = _jacobian(g, pose, n)
    columns = np.tile([1.0, 1.0, 1.0 / scale], len(g.links))
    rows = np.concatenate([c.row_scales(scale) for c in g.constraints])
    scaled = rows[None, :, None] * jac * columns[None, None, :]
    finite = np.all(np.isfinite(scaled), axis=(1, 2))
    out = np.full(n, np.nan)
    if finite.any():
        sv = np.linalg.svd(scaled[finite], compute_uv=False)
        out[finite] = (sv[:, -1] / sv[:, 0]) ** 2
    return out
