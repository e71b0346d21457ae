"""Kinematics (Eq. 1–11) against independent routes: loop closure, finite differences, Eq. 11."""

from __future__ import annotations

import math

import numpy as np
import pytest
from conftest import CLASS_EXAMPLES, PAPER_LENGTHS, random_angles, random_linkage
from helpers import ROUNDING, derivative_with_error, rel_err

from balancer.errors import AssemblyError
from balancer.mechanisms.fourbar import assembly
from balancer.mechanisms.fourbar import kinematics as kin


def test_class_examples_are_what_they_claim():
    for name, lengths in CLASS_EXAMPLES.items():
        assert str(assembly.classify(lengths)) == name


@pytest.mark.parametrize("name", list(CLASS_EXAMPLES))
@pytest.mark.parametrize("branch", ["+", "-"])
def test_loop_closure_and_lengths(name, branch):
    lengths = CLASS_EXAMPLES[name]
    rng = assembly.assembly_range(lengths)
    assert not rng.empty
    t = np.concatenate([np.linspace(a, b, 2001) for a, b in rng.intervals])
    pos = kin.position(lengths, t, branch)
    l1, l2, l3, l4 = lengths
    scale = max(lengths)
    closure = pos.l1 + pos.l2 + pos.l3 - l4  # Eq. 1 with l̄4 = −l4
    # Rounding of a few operations on lengths ≤ scale (a residual, not amplified near the
    # ends of the range): ~ROUNDING·scale ≈ 1.4e-14·scale, within 1e-12·scale.
    assert np.max(np.abs(closure)) <= 1e-12 * scale
    for v, length in ((pos.l1, l1), (pos.l2, l2), (pos.l3, l3)):
        assert np.max(np.abs(np.abs(v) - length)) <= 1e-12 * scale


@pytest.mark.parametrize("branch", ["+", "-"])
def test_branch_side(branch):
    t = np.linspace(-3, 3, 101)
    pos = kin.position(PAPER_LENGTHS, t, branch)
    side = kin.cross(pos.l2 + pos.l3, pos.l2)  # A1→A3 × A1→A2: positive when A2 is on the left
    assert np.all(np.sign(side) == (1 if branch == "+" else -1))


def test_branches_are_mirror_images_about_A1A3():
    t = np.linspace(-3, 3, 51)
    plus = kin.position(PAPER_LENGTHS, t, "+")
    minus = kin.position(PAPER_LENGTHS, t, "-")
    # Reflect A2 of one branch in the line A1→A3: it must land on the other.
    a1, a3 = plus.A1, plus.A3
    w = (a3 - a1) / np.abs(a3 - a1)
    reflected = a1 + w * np.conj((plus.A2 - a1) / w)
    # Rounding of the two position analyses and the reflection (~ROUNDING = 1.4e-14 of the
    # frame length): within 1e-13.
    assert rel_err(reflected, minus.A2, scale=3.2) < 1e-13


#: Least |sin(θ3 − θ2)| of the random states: the condition of the analyses is ≤ 1/MARGIN.
MARGIN = 0.2


def _states(seed, count=20):
    """Random (linkage, θ1, ω1, α1) away from singular positions."""
    rng = np.random.default_rng(seed)
    out = []
    while len(out) < count:
        linkage = random_linkage(rng)
        t = random_angles(rng, linkage, 1)[0]
        pos = kin.position_of(linkage, t)
        if abs(pos.sin_transmission[0]) < MARGIN:
            continue
        out.append((linkage, t, rng.uniform(-3, 3), rng.uniform(-5, 5)))
    return out


@pytest.mark.parametrize("case", _states(1))
def test_rates_and_accelerations_against_finite_differences(case):
    linkage, t0, w1, a1 = case

    def at(t):
        th = t0 + w1 * t + 0.5 * a1 * t * t
        return kin.motion_of(linkage, th, w1 + a1 * t, a1)

    mo = at(0.0)

    def tol(error, value):
        # The difference's own error bound, plus the analytic value's rounding: ROUNDING
        # times the condition (≤ 1/MARGIN) times its magnitude.
        return error + ROUNDING / MARGIN * float(np.max(np.abs(value)))

    # The rates and the joints' velocities are made of terms of magnitude max|ω| and
    # max|ω|·max(l) (the rates of coupler and rocker may cancel to small values).
    rates = float(max(np.max(np.abs(w)) for w in mo.omega))
    arm = max(linkage.lengths)
    # Angular velocity of link k from the rotating unit vector: ω = Im(conj(u)·du/dt).
    for k in range(3):
        u = mo.vectors[k] / abs(mo.vectors[k])
        du, error = derivative_with_error(lambda t, k=k: at(t).vectors[k] / abs(at(t).vectors[k]))
        omega_fd = np.imag(np.conj(u) * du)
        assert np.max(np.abs(mo.omega[k] - omega_fd)) < tol(error, mo.omega[k])
        alpha_fd, error = derivative_with_error(lambda t, k=k: at(t).omega[k], scale=rates)
        assert np.max(np.abs(mo.alpha[k] - alpha_fd)) < tol(error, mo.alpha[k])
    # Joint velocities and accelerations against positions.
    for j in range(2):
        v_fd, v_error = derivative_with_error(lambda t, j=j: at(t).joint_positions()[j],
                                              scale=arm)
        a_fd, a_error = derivative_with_error(lambda t, j=j: at(t).joint_velocities[j],
                                              scale=rates * arm)
        v = mo.joint_velocities[j]
        a = mo.joint_accelerations[j]
        assert np.max(np.abs(v - v_fd)) < tol(v_error, v)
        assert np.max(np.abs(a - a_fd)) < tol(a_error, a)


@pytest.mark.parametrize("case", _states(2, count=30))
def test_eq11_theta2_free_form_agrees(case):
    linkage, t, w1, a1 = case
    mo = kin.motion_of(linkage, t, w1, a1)
    w2, a2 = kin.coupler_rates_eq11(
        linkage.lengths, mo.theta[0], mo.theta[2], w1, mo.omega[2], a1, mo.alpha[2]
    )
    # Two closed forms at one state: rounding, ≲ ROUNDING/MARGIN ≈ 7e-14 of the rates
    # (and of the accelerations' terms ω², α): within 1e-12 and 1e-11.
    assert rel_err(w2, mo.omega[1], scale=max(1.0, abs(w1))) < 1e-12
    assert rel_err(a2, mo.alpha[1], scale=max(1.0, abs(mo.alpha[1][0]), w1 * w1)) < 1e-11


def test_transfer_functions_are_derivatives_of_the_angles():
    t = np.linspace(-3, 3, 25)
    pos = kin.position(PAPER_LENGTHS, t)
    big2, big3 = kin.transfer_functions(pos)
    h = 1e-4

    def central(k, step):
        plus = kin.position(PAPER_LENGTHS, t + step)
        minus = kin.position(PAPER_LENGTHS, t - step)
        vp = (plus.l2, plus.l3)[k - 1]
        vm = (minus.l2, minus.l3)[k - 1]
        return np.angle(vp / vm) / (2 * step)  # unwrapped difference of the angle

    # Central difference: truncation h²·f⁽³⁾/6, four times that at 2h, so |D(2h) − D(h)|/3
    # estimates it (taken twice); rounding: angles within ROUNDING times the position
    # analysis's condition (rad), over 2h.
    rounding = ROUNDING / np.min(np.abs(pos.sin_transmission)) / (2 * h)
    for k, big in ((1, big2), (2, big3)):
        fd = central(k, h)
        truncation = np.max(np.abs(central(k, 2 * h) - fd)) / 3
        assert rel_err(big, fd, scale=1.0) < 2 * truncation + rounding


@pytest.mark.parametrize("name", list(CLASS_EXAMPLES))
def test_assembly_range_ends_are_triangle_bounds(name):
    lengths = CLASS_EXAMPLES[name]
    l1, l2, l3, l4 = lengths
    rng = assembly.assembly_range(lengths)
    if rng.full:
        assert assembly.crank_turns_fully(lengths)
        return
    for a, b in rng.intervals:
        for end in (a, b):
            l23 = math.sqrt(l1 * l1 + l4 * l4 - 2 * l1 * l4 * math.cos(end))
            # Rounding of the end (an arc cosine) and of the law of cosines: the residual is
            # ~ROUNDING·l1·l4/l23 ≲ 1e-13 (a forward evaluation: no ill-conditioning); 1e-9 ≥ it.
            assert min(abs(l23 - (l2 + l3)), abs(l23 - abs(l2 - l3))) < 1e-9
            pos = kin.position(lengths, end)  # on the bound: assembles, flagged singular
            assert pos.singular[0]
        outside = [a - 1e-3, b + 1e-3]
        for t in outside:
            if not rng.contains(t):
                with pytest.raises(AssemblyError, match="cannot be assembled at crank angle"):
                    kin.position(lengths, t)
        mid = 0.5 * (a + b)
        assert rng.contains(mid)
        assert not kin.position(lengths, mid).singular[0]


def test_classification_rules():
    assert assembly.classify((1, 3, 2, 3.2)) == assembly.LinkageClass.CRANK_ROCKER
    assert assembly.classify((2, 2, 2, 2)) == assembly.LinkageClass.CHANGE_POINT
    assert assembly.classify((1, 1, 1, 5)) == assembly.LinkageClass.TRIPLE_ROCKER
    assert assembly.assembly_range((1, 1, 1, 5)).empty


def test_positions_near_a_dead_point_are_flagged_not_nan():
    lengths = CLASS_EXAMPLES["rocker-crank"]
    rng = assembly.assembly_range(lengths)
    a, _ = rng.intervals[0]
    pos = kin.position(lengths, [a, a + 1e-14, a + 1e-3])
    assert np.all(np.isfinite(pos.l2))
    assert list(pos.singular) == [True, True, False]


def test_unassemblable_angle_names_the_angle_and_range():
    lengths = CLASS_EXAMPLES["double-rocker"]
    with pytest.raises(AssemblyError) as info:
        kin.position(lengths, 0.0)
    assert "θ1 = 0 rad" in str(info.value) and "assembles for θ1 in" in str(info.value)


def test_change_point_linkage_flags_the_flat_positions():
    lengths = CLASS_EXAMPLES["change-point"]
    pos = kin.position(lengths, [0.0, math.pi, 1.0])
    assert list(pos.singular) == [True, True, False]
