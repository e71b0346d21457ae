"""The structured batched solver of the linkage core against LAPACK, system by system."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from balancer.linkage.constraints import group_jacobian
from balancer.linkage.inputs import InputState
from balancer.linkage.kinematics import positions
from balancer.linkage.structure import Structure
from balancer.linkage.vectors import Factor
from balancer.mechanisms import mechanism_of
from balancer.spec import load_design

EXAMPLES = Path(__file__).resolve().parents[2] / "examples"

EPS = np.finfo(float).eps


def _bound(k: int, cond: np.ndarray) -> np.ndarray:
    """Forward error of LU with partial pivoting: ``k·2^(k−1)·κ·ε`` (Wilkinson's growth bound,
    which the constant pivots also obey here: in these draws their multipliers are at most 1)."""
    return k * 2.0 ** (k - 1) * cond * EPS


def _random_structured(rng, k: int, n: int) -> list[list]:
    """A ``k×k`` pattern like a constraints' Jacobian: zeros, constants ±1, arrays in [−1, 1]."""
    rows = []
    for _ in range(k):
        row = []
        for _ in range(k):
            kind = rng.integers(3)
            row.append(0.0 if kind == 0 else float(rng.choice([-1.0, 1.0])) if kind == 1
                       else rng.uniform(-1, 1, n))
        rows.append(row)
    return rows


def _dense(rows: list[list], n: int) -> np.ndarray:
    return np.stack([np.stack([np.broadcast_to(v, (n,)) for v in row], axis=-1)
                     for row in rows], axis=1)


@pytest.mark.parametrize("k", [1, 2, 3, 4, 6, 8])
def test_factor_solves_random_structured_systems_like_lapack(k):
    rng = np.random.default_rng(1000 + k)
    n = 400
    for _ in range(20):
        a = _random_structured(rng, k, n)
        dense = _dense(a, n)
        cond = np.linalg.cond(dense)
        keep = cond < 1e8  # structurally singular patterns and near-singular draws aside
        if not keep.any():
            continue
        b = [[rng.uniform(-1, 1, n), rng.uniform(-1, 1, (n, 3))] for _ in range(k)]
        x = Factor(a).solve(b)
        ref_1 = np.linalg.solve(dense, np.stack([row[0] for row in b], 1)[:, :, None])[:, :, 0]
        ref_c = np.linalg.solve(dense, np.stack([row[1] for row in b], 1))
        got_1 = np.stack([np.broadcast_to(row[0], (n,)) for row in x], 1)
        got_c = np.stack([np.broadcast_to(row[1], (n, 3)) for row in x], 1)
        scale_1 = np.linalg.norm(ref_1, axis=1)
        err_1 = np.linalg.norm(got_1 - ref_1, axis=1)
        assert np.all(err_1[keep] <= _bound(k, cond[keep]) * scale_1[keep])
        err_c = np.linalg.norm(got_c - ref_c, axis=(1, 2))
        scale_c = np.linalg.norm(ref_c, axis=(1, 2))
        assert np.all(err_c[keep] <= _bound(k, cond[keep]) * scale_c[keep])


def test_a_singular_system_gives_non_finite_values_not_an_error():
    n = 3
    a = [[np.array([1.0, 0.0, 2.0]), 1.0], [np.array([2.0, 0.0, 1.0]), 1.0]]
    x = Factor(a).solve([[np.ones(n)], [np.ones(n)]])
    assert np.isfinite(x[0][0][[0, 2]]).all() and not np.isfinite(x[0][0][1])
    big = [[np.array([1.0, 1.0]), np.array([2.0, 2.0]), np.array([0.0, 1.0])],
           [np.array([2.0, 2.0]), np.array([4.0, 4.0]), np.array([0.0, 1.0])],
           [np.array([1.0, 0.0]), np.array([0.0, 1.0]), np.array([1.0, 1.0])]]
    y = Factor(big).solve([[np.ones(2)] for _ in range(3)])
    assert np.all(np.isfinite([row[0][1] for row in y]))  # the second system is regular
    assert not np.all(np.isfinite([row[0][0] for row in y]))  # the first: rank 2


@pytest.mark.parametrize("example", ["watt_sixbar.toml", "stephenson_sixbar.toml",
                                     "quick_return.toml", "jansen_leg.toml"])
def test_factor_solves_the_shipped_linkages_group_jacobians(example):
    mech = mechanism_of(load_design(EXAMPLES / example).mechanism)
    structure: Structure = mech.structure
    theta = np.linspace(0.0, 2 * np.pi, 181)
    pose = positions(structure, InputState.crank(theta))
    rng = np.random.default_rng(7)
    for g in structure.groups:
        rows, _ = group_jacobian(g, pose)
        k = len(rows)
        dense = _dense(rows, theta.size)
        cond = np.linalg.cond(dense)
        keep = np.isfinite(cond)
        b = [[rng.uniform(-1, 1, theta.size)] for _ in range(k)]
        for transpose in (False, True):
            m = [list(r) for r in zip(*rows, strict=True)] if transpose else rows
            d = np.swapaxes(dense, 1, 2) if transpose else dense
            x = np.stack([np.broadcast_to(r[0], theta.shape) for r in Factor(m).solve(b)], 1)
            ref = np.linalg.solve(d[keep], np.stack([r[0] for r in b], 1)[keep][:, :, None])
            err = np.linalg.norm(x[keep] - ref[:, :, 0], axis=1)
            assert np.all(err <= _bound(k, cond[keep]) * np.linalg.norm(ref[:, :, 0], axis=1))
