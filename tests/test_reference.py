"""armdyn.reference, the NumPy oracle, against second opinions:

* Pinocchio (an independent implementation, via tests/pinocchio_bridge.py) on random chains
  and branched trees with mixed revolute/prismatic/fixed joints and arbitrary frames;
* the identities of docs/architecture.md;
* Spong's hand-derived closed form of the planar 2R arm.
"""

from __future__ import annotations

import numpy as np
import pytest
import sympy as sp
from random_models import random_case, random_robot, random_state

from armdyn import reference as ref
from armdyn.errors import UnboundParameterError
from armdyn.model import Joint, Link, Robot

RTOL = 1e-12


def assert_rel(actual, expected, rtol=RTOL, what="", scale=None):
    """max |actual - expected| <= rtol * max |expected| (relative to the array's scale).

    ``scale`` replaces max |expected| where the expected value may vanish (e.g. C = 0 for a
    single joint): pass the natural size of the quantity, such as |M| |qd| for C.
    """
    actual, expected = np.asarray(actual, dtype=float), np.asarray(expected, dtype=float)
    assert actual.shape == expected.shape, (what, actual.shape, expected.shape)
    scale = max(np.max(np.abs(expected)) if scale is None else scale, 1e-300)
    err = np.max(np.abs(actual - expected)) / scale
    assert err <= rtol, f"{what}: relative error {err:.2e} > {rtol:.0e}"


# ------------------------------------------------------------------ random models

CASES = [(seed, False) for seed in range(4)] + [(seed, True) for seed in range(4, 10)]


@pytest.fixture(scope="module", params=CASES, ids=[f"{'tree' if t else 'chain'}{s}" for s, t in CASES])
def case(request):
    seed, tree = request.param
    return random_case(seed, tree, max_joints=10)


def test_random_models_cover_the_cases():
    """The random models exercise what they claim: all joint kinds, unaligned axes, branches."""
    kinds, unaligned, branched = set(), False, False
    for seed, tree in CASES:
        rng = np.random.default_rng(seed)
        robot = random_robot(rng, n_joints=int(rng.integers(3, 10)), tree=tree)
        kinds |= {j.type for j in robot.joints}
        unaligned |= any(sum(float(abs(c)) == 1.0 for c in j.axis) == 0 for j in robot.joints)
        branched |= any(len(robot.children(link)) > 1 for link in robot.links)
    assert kinds == {"revolute", "prismatic", "fixed"} and unaligned and branched


def test_dynamics_match_pinocchio(case):
    robot, P, states = case
    for q, qd, qdd in states:
        assert_rel(ref.rnea(robot, q, qd, qdd), P.rnea(q, qd, qdd), what="rnea")
        assert_rel(ref.crba(robot, q), P.crba(q), what="crba")
        assert_rel(ref.aba(robot, q, qd, qdd), P.aba(q, qd, qdd), what="aba")
        assert_rel(ref.gravity(robot, q), P.gravity(q), what="gravity")
        assert_rel(ref.bias(robot, q, qd), P.bias(q, qd), what="bias")
        C_scale = np.max(np.abs(P.crba(q))) * np.max(np.abs(qd))
        assert_rel(ref.coriolis_matrix(robot, q, qd), P.coriolis_matrix(q, qd), what="C", scale=C_scale)


def test_energies_match_pinocchio(case):
    robot, P, states = case
    for q, qd, _ in states:
        assert_rel(ref.kinetic_energy(robot, q, qd), P.kinetic_energy(q, qd), what="T")
        assert_rel(ref.potential_energy(robot, q), P.potential_energy(q), what="V")


def test_kinematics_match_pinocchio(case):
    robot, P, states = case
    for q, _, _ in states:
        X = ref.forward_kinematics(robot, q)
        assert X.shape == (len(robot.links), 4, 4)
        assert_rel(X, P.forward_kinematics(q), what="forward_kinematics")
        for i, link in enumerate(robot.links):
            J = ref.jacobian(robot, q, link)
            assert_rel(J, P.jacobian(q, link), what=f"jacobian {link}")
            assert np.array_equal(J, ref.jacobian(robot, q, i))  # by index, same link


# ------------------------------------------------------------------ identities (docs/architecture.md)


def test_rnea_is_crba_times_qdd_plus_bias(case):
    robot, _, states = case
    for q, qd, qdd in states:
        assert_rel(ref.rnea(robot, q, qd, qdd), ref.crba(robot, q) @ qdd + ref.rnea(robot, q, qd, 0 * qdd), 1e-12)


def test_aba_inverts_rnea(case):
    robot, _, states = case
    for q, qd, qdd in states:
        assert_rel(ref.aba(robot, q, qd, ref.rnea(robot, q, qd, qdd)), qdd, 1e-10)


def test_mass_matrix_symmetric_positive_definite(case):
    robot, _, states = case
    for q, _, _ in states:
        M = ref.crba(robot, q)
        assert_rel(M, M.T, 1e-14)
        assert np.all(np.linalg.eigvalsh(M) > 0)


def test_kinetic_energy_is_half_qd_M_qd(case):
    robot, _, states = case
    for q, qd, _ in states:
        assert_rel(ref.kinetic_energy(robot, q, qd), 0.5 * qd @ ref.crba(robot, q) @ qd)


def test_gravity_is_gradient_of_potential(case):
    robot, _, states = case
    h = 1e-6
    for q, _, _ in states:
        grad = np.array(
            [
                (ref.potential_energy(robot, q + h * e) - ref.potential_energy(robot, q - h * e)) / (2 * h)
                for e in np.eye(robot.dof)
            ]
        )
        # central differences: truncation O(h^2) ~ 1e-12, cancellation ~ |V| eps / h ~ 1e-9
        assert_rel(ref.gravity(robot, q), grad, 1e-7)


def test_coriolis_matrix(case):
    """C qd = bias - gravity exactly, and Mdot - 2C is skew (Mdot by central differences)."""
    robot, _, states = case
    h = 1e-6
    for q, qd, _ in states:
        C = ref.coriolis_matrix(robot, q, qd)
        C_scale = np.max(np.abs(ref.crba(robot, q))) * np.max(np.abs(qd))  # C may vanish
        assert_rel(C @ qd, ref.bias(robot, q, qd) - ref.gravity(robot, q), 1e-12, scale=C_scale * np.max(np.abs(qd)))
        Mdot = (ref.crba(robot, q + h * qd) - ref.crba(robot, q - h * qd)) / (2 * h)
        N = Mdot - 2 * C
        assert np.max(np.abs(N + N.T)) <= 1e-6 * C_scale


# ------------------------------------------------------------------ closed form: planar 2R


def planar_2r(m1, m2, l1, lc1, lc2, I1, I2, g):
    """Spong's two-link planar arm (Spong, Hutchinson, Vidyasagar, Robot Modeling and Control,
    ch. 7): joints about z, links along x, gravity -y."""
    links = [
        Link("base"),
        Link("link1", m1, [lc1, 0, 0], np.diag([0.3 * I1, 0.8 * I1, I1]).tolist()),
        Link("link2", m2, [lc2, 0, 0], np.diag([0.2 * I2, 0.9 * I2, I2]).tolist()),
        Link("tool"),
    ]
    joints = [
        Joint("q1", "revolute", "base", "link1"),
        Joint("q2", "revolute", "link1", "link2", xyz=[l1, 0, 0]),
        Joint("tool", "fixed", "link2", "tool", xyz=[0.7, 0, 0]),  # the tip, l2 = 0.7
    ]
    return Robot("planar_2r", links, joints, gravity=(0, -g, 0))


def test_planar_2r_closed_form():
    """M, C, g, T, V and the tip Jacobian from the textbook formulas, at random states:

    M = [[m1 lc1^2 + m2 (l1^2 + lc2^2 + 2 l1 lc2 c2) + I1 + I2,  m2 (lc2^2 + l1 lc2 c2) + I2],
         [m2 (lc2^2 + l1 lc2 c2) + I2,                             m2 lc2^2 + I2]]
    C = [[h qd2, h (qd1 + qd2)], [-h qd1, 0]],  h = -m2 l1 lc2 s2
    g = [(m1 lc1 + m2 l1) g c1 + m2 lc2 g c12,  m2 lc2 g c12]
    """
    m1, m2, l1, lc1, lc2, I1, I2, g, l2 = 2.3, 1.7, 0.9, 0.41, 0.33, 0.12, 0.07, 9.81, 0.7
    robot = planar_2r(m1, m2, l1, lc1, lc2, I1, I2, g)
    rng = np.random.default_rng(7)
    for _ in range(5):
        q, qd, qdd = (random_state(rng, 2) for _ in range(3))
        c1, s1, c2, s2 = np.cos(q[0]), np.sin(q[0]), np.cos(q[1]), np.sin(q[1])
        c12, s12 = np.cos(q.sum()), np.sin(q.sum())
        d12 = m2 * (lc2**2 + l1 * lc2 * c2) + I2
        M = np.array(
            [[m1 * lc1**2 + m2 * (l1**2 + lc2**2 + 2 * l1 * lc2 * c2) + I1 + I2, d12], [d12, m2 * lc2**2 + I2]]
        )
        h = -m2 * l1 * lc2 * s2
        C = np.array([[h * qd[1], h * (qd[0] + qd[1])], [-h * qd[0], 0.0]])
        G = np.array([(m1 * lc1 + m2 * l1) * g * c1 + m2 * lc2 * g * c12, m2 * lc2 * g * c12])
        V = m1 * g * lc1 * s1 + m2 * g * (l1 * s1 + lc2 * s12)
        J_tip = np.array(
            [
                [-l1 * s1 - l2 * s12, -l2 * s12],
                [l1 * c1 + l2 * c12, l2 * c12],
                [0, 0],
                [0, 0],
                [0, 0],
                [1, 1],
            ]
        )
        assert_rel(ref.crba(robot, q), M, what="M")
        assert_rel(ref.coriolis_matrix(robot, q, qd), C, what="C")
        assert_rel(ref.gravity(robot, q), G, what="g")
        assert_rel(ref.rnea(robot, q, qd, qdd), M @ qdd + C @ qd + G, what="tau")
        assert_rel(ref.aba(robot, q, qd, M @ qdd + C @ qd + G), qdd, 1e-11, what="qdd")
        assert_rel(ref.kinetic_energy(robot, q, qd), 0.5 * qd @ M @ qd, what="T")
        assert_rel(ref.potential_energy(robot, q), V, what="V")
        assert_rel(ref.jacobian(robot, q, "tool"), J_tip, what="J")
        tip = ref.forward_kinematics(robot, q)[3]
        assert_rel(tip[:3, 3], [l1 * c1 + l2 * c12, l1 * s1 + l2 * s12, 0], what="tip")


# ------------------------------------------------------------------ bad input


def test_unbound_robot_is_refused():
    m = sp.Symbol("m")
    robot = Robot(
        "r", [Link("base"), Link("a", m, [0, 0, 0], np.eye(3).tolist())], [Joint("j", "revolute", "base", "a")]
    )
    with pytest.raises(UnboundParameterError, match="m"):
        ref.rnea(robot, [0.0], [0.0], [0.0])
    assert ref.rnea(robot.subs({m: 1.0}), [0.0], [0.0], [0.0]).shape == (1,)


@pytest.mark.parametrize("q", [[0.0], [0.0, 1.0, 2.0], [[0.0, 1.0]], [np.nan, 0.0], [0.0, np.inf]])
def test_bad_state_is_refused(q):
    robot = planar_2r(1, 1, 1, 0.5, 0.5, 0.1, 0.1, 9.81)
    with pytest.raises(ValueError, match="q"):
        ref.crba(robot, q)
