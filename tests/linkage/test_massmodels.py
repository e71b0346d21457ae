"""Mass models (Eq. 12–16, 29–32, 45–49, 53–54; Wunderlich Eq. 7–10) against direct routes."""

from __future__ import annotations

from dataclasses import replace

import numpy as np
import pytest
from conftest import paper_linkage, random_angles, random_linkage
from helpers import ROUNDING, rel_err

from balancer.linkage import massmodels as link_mm
from balancer.mechanisms.fourbar import kinematics as kin
from balancer.mechanisms.fourbar import massmodels as mm
from balancer.mechanisms.fourbar.conditions import force_balanced_by_crank_and_rocker
from balancer.model import Link


def _cases(seed, n=25):
    rng = np.random.default_rng(seed)
    out = []
    for _ in range(n):
        linkage = random_linkage(rng)
        out.append((linkage, random_angles(rng, linkage, 50)))
    return out


@pytest.mark.parametrize(("linkage", "angles"), _cases(10))
def test_principal_vector_centre_of_mass_equals_direct_sum(linkage, angles):
    pos = kin.position_of(linkage, angles)
    direct = mm.total_com_direct(linkage, pos)
    scale = max(linkage.lengths)
    # Mass-weighted sums of a few vectors ≤ scale, each way: rounding ~ROUNDING·scale ≈
    # 1.4e-14·scale (the mass ratios are ≤ 25), within 1e-12·scale.
    assert rel_err(mm.total_com_opened(linkage, pos), direct, scale=scale) < 1e-12  # Eq. 16
    assert rel_err(mm.total_com_frame(linkage, pos), direct, scale=scale) < 1e-12  # Eq. 32


@pytest.mark.parametrize(("linkage", "angles"), _cases(11, n=10))
def test_principal_vector_identities(linkage, angles):
    pos = kin.position_of(linkage, angles)
    pv = mm.opened_loop_vectors(linkage, pos)
    fv = mm.frame_vectors(linkage, pos)
    scale = max(linkage.lengths)
    # Eq. 12: ā23 = ā21 + l̄2; Eq. 13 derived vectors; Eq. 30: l̄4 = ā41 − ā43. Each side a
    # handful of operations on vectors ≤ scale: ≲ 10ε·scale ≈ 2e-15·scale, within 1e-14.
    assert rel_err(pv.a23, pv.a21 + pos.l2, scale=scale) < 1e-14
    assert rel_err(pv.a14p, pv.a12 - pos.l1, scale=scale) < 1e-14
    assert rel_err(pv.a34p, pv.a32 + pos.l3, scale=scale) < 1e-14
    assert abs(fv.a41 - fv.a43 - (-linkage.lengths[3])) < 1e-14 * scale
    # Eq. 14–15: link centres of mass from the principal vectors (rounding, as above, of
    # terms up to (m1 + m2 + m3)·scale: within 1e-12 of m_k·scale).
    r1, r2, r3 = mm.link_centres_of_mass(linkage, pos)
    m1, m2, m3 = (c.mass for c in linkage.links)
    rs = mm.total_com_direct(linkage, pos)
    assert rel_err(m1 * r1, m1 * rs - (m2 + m3) * pv.a12 + m1 * pv.a21 + m1 * pv.a32,
                   scale=scale * m1) < 1e-12
    assert rel_err(m2 * r2, m2 * rs + m2 * pv.a12 - m1 * pv.a21 - m3 * pv.a23 + m2 * pv.a32,
                   scale=scale * m2) < 1e-12
    assert rel_err(m3 * r3, m3 * rs + m3 * pv.a12 + m3 * pv.a23 - (m1 + m2) * pv.a32,
                   scale=scale * m3) < 1e-12


@pytest.mark.parametrize(("linkage", "angles"), _cases(12, n=10))
def test_complex_joint_masses_reproduce_the_centre_of_mass(linkage, angles):
    pos = kin.position_of(linkage, angles)
    joints = ((0.0, pos.A1), (pos.A1, pos.A2), (pos.A2, pos.A3))
    for k, link in enumerate(linkage.links):
        # Joint masses of magnitude ≤ m·(1 + |s̄|/l) ≤ 2.6·m, from a few operations each:
        # rounding ≲ 8ε·m ≈ 2e-15·m, within 1e-14·m; the two forms to ROUNDING·m (a mass, not
        # an absolute number).
        mp, mq = link_mm.complex_joint_masses(link, linkage.lengths[k])
        assert abs(mp + mq - link.mass) < 1e-14 * link.mass
        ma, mb, mc = link_mm.equivalent_masses(link, linkage.lengths[k])
        tol = ROUNDING * link.mass
        assert abs(mp - (ma - 1j * mc)) < tol and abs(mq - (mb + 1j * mc)) < tol
        rp, rq = joints[k]
        r = mm.link_centres_of_mass(linkage, pos)[k]
        # Rounding of m·|r| ≤ m·3 (these linkages reach ≤ 3 m): ~ROUNDING, within 1e-13.
        assert rel_err(mp * rp + mq * rq, link.mass * r, scale=link.mass * 3) < 1e-13  # Eq. 29


@pytest.mark.parametrize(("linkage", "angles"), _cases(13))
def test_wunderlich_similarity(linkage, angles):
    pos = kin.position_of(linkage, angles)
    w = mm.wunderlich_linkage(linkage)
    rs = mm.total_com_direct(linkage, pos)
    scale = max(linkage.lengths)
    # Wunderlich's similarity holds to rounding (DESIGN.md): two sums of a few vectors ≤ scale
    # with mass-ratio coefficients, ~ROUNDING·scale; within 1e-12·scale.
    assert rel_err(w.trace(pos), rs, scale=scale) < 1e-12
    # The generating linkage B0B1B2B3 is the original scaled and rotated by γ (Eq. 4).
    b1, b2 = w.generating_joints(pos)
    assert rel_err(np.abs(b1 - w.B0), abs(w.gamma) * linkage.lengths[0], scale=scale) < 1e-12
    assert rel_err(np.abs(b2 - b1), abs(w.gamma) * linkage.lengths[1], scale=scale) < 1e-12
    assert rel_err(np.abs(w.B3 - b2), abs(w.gamma) * linkage.lengths[2], scale=scale) < 1e-12
    assert abs(w.B3 - w.B0 - w.gamma * linkage.lengths[3]) < 1e-12 * scale


def test_wunderlich_theorem_2_stationary_centre_of_mass():
    linkage = force_balanced_by_crank_and_rocker(paper_linkage(loads=False))
    w = mm.wunderlich_linkage(linkage)
    assert w.is_stationary
    pos = kin.position_of(linkage, np.linspace(0, 2 * np.pi, 73))
    rs = mm.total_com_direct(linkage, pos)
    # Rounding of mass-weighted positions ≤ 3.2 m: ~ROUNDING·3.2 m ≈ 5e-14 m; the conditions
    # (Eq. 57, Eq. 10d below) are ratios of numbers of order one: ≲ 10ε. Within 1e-13.
    assert np.max(np.abs(rs - rs[0])) < 1e-13
    # Wunderlich: its position is m3·σ3·a (masses normalised).
    c3 = linkage.rocker
    expected = c3.mass / linkage.total_mass * (c3.com / linkage.lengths[2]) * linkage.lengths[3]
    assert abs(rs[0] - expected) < 1e-13
    # Eq. 10d in Wunderlich's own form.
    mt = linkage.total_mass
    m1, m2, m3 = (c.mass / mt for c in linkage.links)
    s1, s2, s3 = (c.com / length for c, length in zip(linkage.links, linkage.lengths, strict=False))
    assert abs(s2 - (1 + m1 / m2 * s1)) < 1e-13
    assert abs(s3 - (1 + m2 / m3 + m1 / m3 * s1)) < 1e-13


def test_wunderlich_circle_case_beta_zero():
    # Eq. 10a: σ2/(σ3 − 1) = m3/m2 makes β = 0: the centre of mass moves on a circle about B0.
    linkage = paper_linkage(loads=False)
    l1, l2, l3, _ = linkage.lengths
    c2, c3 = linkage.coupler, linkage.rocker
    s3 = 1 + (c2.mass / c3.mass) * (c2.com / l2)
    linkage = linkage.with_link("rocker", replace(c3, e=(s3 * l3).real, f=(s3 * l3).imag))
    w = mm.wunderlich_linkage(linkage)
    # β cancels terms of order one in a handful of operations: ≲ 10ε ≈ 2e-15, within 1e-14;
    # the radius, rounding of positions ≤ 3.2 m as above.
    assert abs(w.beta) < 1e-14 and w.is_circle
    pos = kin.position_of(linkage, np.linspace(0, 2 * np.pi, 61))
    radius = np.abs(mm.total_com_direct(linkage, pos) - w.B0)
    assert np.ptp(radius) < 1e-13


def _rigid_motion(rng, length):
    p = complex(*rng.normal(size=2))
    th = rng.uniform(-3, 3)
    vp = complex(*rng.normal(size=2))
    w = rng.normal()
    q = p + length * np.exp(1j * th)
    vq = vp + 1j * w * (q - p)
    return p, q, vp, vq, w


@pytest.mark.parametrize("seed", range(10))
def test_equivalent_mass_matrix_gives_the_rigid_kinetic_energy(seed):
    rng = np.random.default_rng(seed)
    length = rng.uniform(0.5, 3)
    link = Link(mass=rng.uniform(0.5, 5), inertia=rng.uniform(0.1, 3),
                e=rng.uniform(-1, 2), f=rng.uniform(-1, 1))
    me = link_mm.equivalent_mass_matrix(link.inertial_parameters, length)
    assert np.allclose(me, me.T, rtol=0, atol=1e-15)  # symmetric by construction: exactly
    # Positive semidefinite: eigenvalues to rounding, ~ROUNDING·|Me| ≲ 1e-12 here.
    assert np.min(np.linalg.eigvalsh(me)) > -ROUNDING * np.max(np.abs(me))
    p, q, vp, vq, w = _rigid_motion(rng, length)
    x = np.array([vp.real, vp.imag, vq.real, vq.imag])
    v_com = vp + 1j * w * link.com / length * (q - p)
    t_rigid = 0.5 * link.mass * abs(v_com) ** 2 + 0.5 * link.inertia * w * w
    # Rounding of the quadratic form, whose terms are ≤ |Me|·|x|²: ROUNDING times those.
    terms = np.max(np.abs(me)) * float(x @ x)
    assert abs(0.5 * x @ me @ x - t_rigid) < ROUNDING * max(terms, t_rigid)
    # The complex application is the same matrix.
    ap, aq = complex(*rng.normal(size=2)), complex(*rng.normal(size=2))
    fp, fq = link_mm.equivalent_inertia_forces(link.inertial_parameters, length, ap, aq)
    acc = np.array([ap.real, ap.imag, aq.real, aq.imag])
    y = me @ acc
    # The same products in another order: ROUNDING times the terms, |Me|·|ẍ|.
    tol = ROUNDING * np.max(np.abs(me)) * np.sum(np.abs(acc))
    assert np.allclose([fp.real, fp.imag, fq.real, fq.imag], y, rtol=0, atol=tol)


@pytest.mark.parametrize("seed", range(10))
def test_equivalent_joint_forces_do_the_same_virtual_work(seed):
    rng = np.random.default_rng(seed)
    length = rng.uniform(0.5, 3)
    link = Link(mass=1.0, inertia=1.0, e=rng.uniform(-1, 2), f=rng.uniform(-1, 1),
                force=tuple(rng.normal(size=2)), moment=rng.normal())
    p, q, dp, dq, dth = _rigid_motion(rng, length)  # a rigid virtual displacement
    fp, fq = link_mm.equivalent_joint_forces(link, length, q - p)
    work_nodes = kin.inner(dp, fp) + kin.inner(dq, fq)
    d_com = dp + 1j * dth * link.com / length * (q - p)
    work = kin.inner(d_com, link.force_complex) + link.moment * dth
    # Rounding of products of numbers of order one and lengths ≤ 3 (terms ≲ 10):
    # ~ROUNDING·10 ≈ 1.4e-13 at worst, well above the handful of operations here (≲ 2e-14).
    assert abs(work_nodes - work) < 1e-13


def test_assembled_matrices_match_eq48_and_eq53_written_out():
    linkage = paper_linkage()
    (l1, l2, l3, _), (c1, c2, c3) = linkage.lengths, linkage.links
    m = mm.fourbar_mass_matrix(linkage)
    i1, i2, i3 = c1.inertia, c2.inertia, c3.inertia
    m1, m2, m3 = c1.mass, c2.mass, c3.mass
    e2, f2, e3, f3, e1, f1 = c2.e, c2.f, c3.e, c3.f, c1.e, c1.f
    s1sq, s2sq = e1**2 + f1**2, e2**2 + f2**2
    m11 = (i1 + m1 * s1sq) / l1**2 + (i2 + m2 * ((l2 - e2) ** 2 + f2**2)) / l2**2
    m13 = (m2 * e2 * (l2 - e2) - m2 * f2**2 - i2) / l2**2
    m14 = -m2 * f2 / l2
    m33 = (i2 + m2 * s2sq) / l2**2 + (i3 + m3 * ((l3 - e3) ** 2 + f3**2)) / l3**2
    expected = np.array([
        [m11, 0, m13, m14],
        [0, m11, -m14, m13],
        [m13, -m14, m33, 0],
        [m14, m13, 0, m33],
    ])
    # The same formulas in another order: rounding of the terms, which a mass matrix bounds by
    # its diagonal (|m13| cancels terms of that size): ROUNDING·max|diag|.
    tol = ROUNDING * np.max(np.abs(np.diag(expected)))
    assert np.allclose(m, expected, rtol=0, atol=tol)
    mr = mm.reaction_mass_matrix(linkage)
    r11 = (m1 * e1 * (l1 - e1) - m1 * f1**2 - i1) / l1**2
    r33 = (m3 * e3 * (l3 - e3) - m3 * f3**2 - i3) / l3**2
    expected_r = np.array([
        [r11, -m1 * f1 / l1, 0, 0],
        [m1 * f1 / l1, r11, 0, 0],
        [0, 0, r33, m3 * f3 / l3],
        [0, 0, -m3 * f3 / l3, r33],
    ])
    # Its terms: m·e·(l − e), m·f², I over l², and m·f/l.
    tol = ROUNDING * max(abs(m1 * e1 * (l1 - e1)) / l1**2, m1 * f1**2 / l1**2, i1 / l1**2,
                         abs(m3 * e3 * (l3 - e3)) / l3**2, m3 * f3**2 / l3**2, i3 / l3**2,
                         m1 * abs(f1) / l1, m3 * abs(f3) / l3)
    assert np.allclose(mr, expected_r, rtol=0, atol=tol)


def test_force_vector_matches_eq49_and_eq54_written_out():
    linkage = paper_linkage()
    (l1, l2, l3, l4), (c1, c2, c3) = linkage.lengths, linkage.links
    pos = kin.position_of(linkage, 0.7)
    f0, fa1, fa2, f3 = (np.asarray(x).reshape(-1)[0] for x in mm.fourbar_force_vector(linkage, pos))
    a1, a2 = pos.A1[0], pos.A2[0]
    (f1x, f1y), (f2x, f2y), (f3x, f3y) = c1.force, c2.force, c3.force
    M1, M2, M3 = c1.moment, c2.moment, c3.moment
    e1, f1, e2, f2, e3, f3_ = c1.e, c1.f, c2.e, c2.f, c3.e, c3.f
    F1 = (e1 / l1 * f1x + f1 / l1 * f1y - a1.imag / l1**2 * M1 + (1 - e2 / l2) * f2x
          - f2 / l2 * f2y + (a2.imag - a1.imag) / l2**2 * M2)
    F2 = (e1 / l1 * f1y - f1 / l1 * f1x + a1.real / l1**2 * M1 + (1 - e2 / l2) * f2y
          + f2 / l2 * f2x - (a2.real - a1.real) / l2**2 * M2)
    F3 = (e2 / l2 * f2x + f2 / l2 * f2y - (a2.imag - a1.imag) / l2**2 * M2
          + (1 - e3 / l3) * f3x - f3_ / l3 * f3y + (0 - a2.imag) / l3**2 * M3)
    F4 = (e2 / l2 * f2y - f2 / l2 * f2x + (a2.real - a1.real) / l2**2 * M2
          + (1 - e3 / l3) * f3y + f3_ / l3 * f3x - (l4 - a2.real) / l3**2 * M3)
    # Rounding of sums of a dozen terms ≲ 2 N: ≲ 12ε·2 N ≈ 5e-15 N, within 1e-14 N.
    assert np.allclose([fa1.real, fa1.imag, fa2.real, fa2.imag], [F1, F2, F3, F4], atol=1e-14)
    # Eq. 54 without the reactions.
    Fr1 = (1 - e1 / l1) * f1x - f1 / l1 * f1y + a1.imag / l1**2 * M1
    Fr2 = (1 - e1 / l1) * f1y + f1 / l1 * f1x - a1.real / l1**2 * M1
    Fr3 = e3 / l3 * f3x + f3_ / l3 * f3y - (0 - a2.imag) / l3**2 * M3
    Fr4 = e3 / l3 * f3y - f3_ / l3 * f3x + (l4 - a2.real) / l3**2 * M3
    assert np.allclose([f0.real, f0.imag, f3.real, f3.imag], [Fr1, Fr2, Fr3, Fr4], atol=1e-14)
