"""Symbolic derivations: each result against an independent second opinion.

* the RP arm of the exercise: its final tau1, tau2 (verified there by Lagrange), and
  intermediate Newton-Euler steps against a hand derivation by differentiating positions;
* the planar 2R arm: Spong's textbook closed form of M, C, g;
* Newton-Euler == Lagrange on every bundled model and on random chains and trees;
* kinetic energy from link-frame recursion == from base-frame differentiation;
* M symmetric positive definite, Mdot - 2C skew-symmetric, tau == M qdd + C qd + g.
"""

from __future__ import annotations

import warnings

import numpy as np
import pytest
import sympy as sp
from random_models import random_robot

import armdyn
from armdyn.symbolic import check, derive
from armdyn.symbolic.agreement import trig_reduce


def zero(expr, q) -> bool:
    """Exact: expr reduces to 0 modulo sin^2 + cos^2 = 1."""
    return trig_reduce(expr, q) == 0


@pytest.fixture(scope="module")
def rp():
    robot = armdyn.load("rp-arm")
    return robot, derive(robot, "newton-euler"), derive(robot, "lagrange")


def exercise_tau(robot):
    """tau1, tau2 as printed at the end of 7-4 (and of its Lagrangian check)."""
    m1, m2, l1, g = (robot.parameters[n] for n in ("m1", "m2", "l1", "g"))
    th, d = robot.q
    thd, dd = robot.qd
    thdd, ddd = robot.qdd
    tau1 = (
        (m1 + m2) * l1**2 * thdd
        + m2 * l1 * ddd
        + 2 * m2 * d * thd * dd
        + m2 * thdd * d**2
        + (m1 + m2) * g * l1 * sp.cos(th)
        - m2 * g * d * sp.sin(th)
    )
    tau2 = m2 * l1 * thdd + m2 * ddd - m2 * thd**2 * d + m2 * g * sp.cos(th)
    return tau1, tau2


def test_rp_arm_names(rp):
    robot, _, _ = rp
    assert robot.coordinate_names == ["theta1", "d2"]
    assert set(robot.parameters) == {"m1", "m2", "l1", "g"}
    assert robot.parameters["m1"] == sp.Symbol("m1")  # plain symbols: users can compare with their own


@pytest.mark.parametrize("method", ["newton-euler", "lagrange"])
def test_rp_arm_matches_exercise_exactly(rp, method):
    robot, ne, la = rp
    eom = ne if method == "newton-euler" else la
    tau1, tau2 = exercise_tau(robot)
    assert sp.expand(eom.tau[0] - tau1) == 0
    assert sp.expand(eom.tau[1] - tau2) == 0


def _hand_accelerations(robot):
    """Acceleration of each mass minus gravity, by differentiating its position twice in
    time, then expressed in the link's frame: the hand derivation of the exercise,
    independent of the Newton-Euler recursion."""
    t = sp.Symbol("t")
    th, d = (sp.Function(n)(t) for n in robot.coordinate_names)
    l1, g = robot.parameters["l1"], robot.parameters["g"]
    R01 = sp.Matrix([[sp.cos(th), -sp.sin(th), 0], [sp.sin(th), sp.cos(th), 0], [0, 0, 1]])
    R12 = sp.Matrix([[1, 0, 0], [0, 0, -1], [0, 1, 0]]).T  # the exercise's R_1^2 maps 1 -> 2
    p1 = R01 * sp.Matrix([l1, 0, 0])  # mass 1
    p2 = p1 + R01 * sp.Matrix([0, d, 0])  # mass 2 on the slider along y1
    gravity = sp.Matrix([0, -g, 0])
    acc1 = R01.T * (p1.diff(t, 2) - gravity)
    acc2 = (R01 * R12).T * (p2.diff(t, 2) - gravity)
    names = {
        th.diff(t, 2): robot.qdd[0],
        d.diff(t, 2): robot.qdd[1],
        th.diff(t): robot.qd[0],
        d.diff(t): robot.qd[1],
        th: robot.q[0],
        d: robot.q[1],
    }
    return acc1.subs(names), acc2.subs(names)


def test_rp_arm_newton_euler_steps_against_hand_derivation(rp):
    """The exercise drops -l1*theta1_dot^2 (centripetal) from vd_1 and vd_2 and writes
    theta1_dot for theta1_ddot in F_2; armdyn must have every term."""
    robot, ne, _ = rp
    acc1, acc2 = _hand_accelerations(robot)
    q = robot.q
    assert all(zero(e, q) for e in ne.step("vc_dot", "link1") - acc1)
    assert all(zero(e, q) for e in ne.step("vc_dot", "link2") - acc2)
    # pinned by hand: x component of link 2's acceleration, with the dropped term
    l1, g, m2 = (robot.parameters[n] for n in ("l1", "g", "m2"))
    th, d = q
    thd, dd = robot.qd
    thdd, _ = robot.qdd
    vcd2_x = -thdd * d - 2 * thd * dd + g * sp.sin(th) - l1 * thd**2
    assert sp.expand(ne.step("vc_dot", "link2")[0] - vcd2_x) == 0
    assert sp.expand(ne.step("F", "link2")[0] - m2 * vcd2_x) == 0
    # angular velocity of link 2 in frame 2, as in the exercise
    assert list(ne.step("omega", "link2")) == [0, -thd, 0]
    # the inward pass ends at tau1 = z . n_1
    assert sp.expand(ne.step("n", "link1")[2] - ne.tau[0]) == 0


def test_rp_arm_lagrange_energies(rp):
    robot, _, la = rp
    m1, m2, l1, g = (robot.parameters[n] for n in ("m1", "m2", "l1", "g"))
    th, d = robot.q
    thd, dd = robot.qd
    T = sp.Rational(1, 2) * m1 * (l1 * thd) ** 2 + sp.Rational(1, 2) * m2 * ((thd * l1 + dd) ** 2 + (thd * d) ** 2)
    V = m1 * g * l1 * sp.sin(th) + m2 * g * (l1 * sp.sin(th) + d * sp.cos(th))
    assert zero(la.step("T", "") - T, robot.q)
    assert zero(la.step("V", "") - V, robot.q)


def test_rp_arm_agreement_is_exact(rp):
    _, ne, la = rp
    report = check(ne, la)
    assert report, report.text()
    assert all(r.how == "exact" for r in report.results)


def test_planar_2r_textbook_closed_form():
    """Spong, Hutchinson, Vidyasagar, Robot Modeling and Control, planar elbow manipulator."""
    robot = armdyn.load("planar-2r")
    eom = derive(robot, "newton-euler")
    m1, m2, l1, lc1, lc2, I1, I2, g = (robot.parameters[n] for n in ("m1", "m2", "l1", "lc1", "lc2", "I1", "I2", "g"))
    q1, q2 = robot.q
    qd1, qd2 = robot.qd
    c2 = sp.cos(q2)
    M = sp.Matrix(
        [
            [m1 * lc1**2 + m2 * (l1**2 + lc2**2 + 2 * l1 * lc2 * c2) + I1 + I2, m2 * (lc2**2 + l1 * lc2 * c2) + I2],
            [m2 * (lc2**2 + l1 * lc2 * c2) + I2, m2 * lc2**2 + I2],
        ]
    )
    h = -m2 * l1 * lc2 * sp.sin(q2)
    C = sp.Matrix([[h * qd2, h * qd2 + h * qd1], [-h * qd1, 0]])
    G = sp.Matrix(
        [(m1 * lc1 + m2 * l1) * g * sp.cos(q1) + m2 * lc2 * g * sp.cos(q1 + q2), m2 * lc2 * g * sp.cos(q1 + q2)]
    )
    for ours, book in ((eom.M, M), (eom.C, C), (eom.g, G)):
        assert all(zero(sp.expand_trig(e), robot.q) for e in ours - book)


def _numeric_agreement(robot, samples=8, seed=1):
    ne, la = derive(robot, "newton-euler"), derive(robot, "lagrange")
    report = check(ne, la, exact=False, samples=samples, seed=seed)
    assert report, report.text()


@pytest.mark.parametrize("name", [r["name"] for r in armdyn.io.bundled_robots()])
def test_newton_euler_equals_lagrange_on_bundled(name):
    robot = armdyn.load(name, strict=False)
    ne, la = derive(robot, "newton-euler"), derive(robot, "lagrange")
    report = check(ne, la, structure=robot.dof <= 3, samples=6)
    assert report, report.text()


@pytest.mark.parametrize("seed", range(6))
def test_newton_euler_equals_lagrange_on_random_robots(seed):
    rng = np.random.default_rng(seed)
    robot = random_robot(rng, n_joints=int(rng.integers(2, 5)), tree=bool(seed % 2))
    _numeric_agreement(robot, seed=seed)


def _kinetic_energy_in_base_frame(robot):
    """T = sum 1/2 m v.v + 1/2 w0^T (R I R^T) w0 with v, w0 from differentiating the
    base-frame pose in time (w0 from Rdot R^T), an independent second opinion on the
    link-frame velocity recursion."""
    t = sp.Symbol("t")
    funcs = [sp.Function(n)(t) for n in robot.coordinate_names]
    R0, p0 = {robot.base: sp.eye(3)}, {robot.base: sp.zeros(3, 1)}
    T = 0
    for joint in robot.joints:
        k = robot.coordinate_index(joint)
        R, p = joint.transform(0 if k is None else funcs[k])
        R0[joint.child] = R0[joint.parent] * R
        p0[joint.child] = p0[joint.parent] + R0[joint.parent] * p
        link = robot.links[joint.child]
        pc = p0[joint.child] + R0[joint.child] * link.com
        v = pc.diff(t)
        W = R0[joint.child].diff(t) * R0[joint.child].T  # skew(w0)
        w0 = sp.Matrix([W[2, 1], W[0, 2], W[1, 0]])
        I0 = R0[joint.child] * link.inertia * R0[joint.child].T
        T += sp.Rational(1, 2) * link.mass * v.dot(v) + sp.Rational(1, 2) * (w0.T * I0 * w0)[0, 0]
    names = {}
    for f, q, qd in zip(funcs, robot.q, robot.qd):
        names[f.diff(t)] = qd
    T = T.subs(names)
    return T.subs(dict(zip(funcs, robot.q)))


@pytest.mark.parametrize("seed", range(3))
def test_kinetic_energy_is_frame_independent(seed):
    rng = np.random.default_rng(100 + seed)
    robot = random_robot(rng, n_joints=3, tree=bool(seed % 2))
    la = derive(robot, "lagrange")
    T_links = la.step("T", "")
    T_base = _kinetic_energy_in_base_frame(robot)
    f = sp.lambdify(list(robot.q) + list(robot.qd), [T_links, T_base])
    for _ in range(5):
        x = rng.uniform(-np.pi, np.pi, 2 * robot.dof)
        a, b = f(*x)
        assert a == pytest.approx(b, rel=1e-10, abs=1e-12)


@pytest.mark.parametrize("name", ["planar-2r", "puma560"])
def test_mass_matrix_symmetric_positive_definite(name):
    # published values where the model has them (PUMA's break the triangle inequality:
    # strict=False, as a user must), positive ones otherwise
    rng = np.random.default_rng(3)
    with warnings.catch_warnings():
        warnings.filterwarnings("ignore", message=".*triangle inequality")
        robot = armdyn.load(name, strict=False)
        robot = robot.bind({p: rng.uniform(0.5, 2.0) for p in robot.parameters if p not in robot.defaults})
    eom = derive(robot, "lagrange")
    f = sp.lambdify(list(robot.q), eom.M)
    for _ in range(10):
        M = np.array(f(*rng.uniform(-np.pi, np.pi, robot.dof)), dtype=float)
        assert np.allclose(M, M.T, atol=1e-12)
        assert np.linalg.eigvalsh(M).min() > 0


def test_coriolis_split_on_random_tree():
    robot = random_robot(np.random.default_rng(7), n_joints=3, tree=True)
    report = check(derive(robot), exact=False, samples=6)
    names = [r.name for r in report.results]
    assert any("M qdd + C qd + g" in n for n in names) and not any("skew" in n for n in names)
    assert all(r.how == "numeric, 6 points" for r in report.results), report.text()
    assert report, report.text()


def test_structure_checks_notice_wrong_velocity_terms():
    """A Newton-Euler tau whose velocity terms are wrong (M untouched) must fail every
    check that involves C. The old "Mdot - 2C skew-symmetric" check passed on it: C was
    built from M alone, so it could not see the velocity terms at all."""
    robot = armdyn.load("rp-arm")
    ne, la = derive(robot), derive(robot, "lagrange")
    broken = derive(robot)
    m1, (_q1, q2), (qd1, qd2) = robot.parameters["m1"], robot.q, robot.qd
    broken.tau = ne.tau + sp.Matrix([m1 * sp.sin(q2) * qd1 * qd2, 0])  # M, g unchanged
    for exact in (True, False):
        report = check(broken, exact=exact, samples=5)
        passed = {r.name for r in report.results if r.passed}
        assert passed == {"M symmetric (newton-euler)"}, report.text()
        # the Lagrange derivation is right, and the Newton-Euler one is the reference
        report = check(la, broken, exact=exact, samples=5)
        assert [r.name for r in report.results if not r.passed] == [
            "tau: lagrange == newton-euler",
            "tau (newton-euler) == M qdd + C qd + g, C from the Christoffel symbols of M",
        ], report.text()
    assert check(la, ne), check(la, ne).text()


@pytest.mark.parametrize("samples", [0, -3, 2.5, True])
def test_zero_samples_is_an_error(samples):
    robot = armdyn.load("planar-2r")
    with pytest.raises(ValueError, match="samples must be a positive integer"):
        check(derive(robot), exact=False, samples=samples)


def test_agreement_check_can_fail():
    """The check must notice a wrong tau (so a green check means something)."""
    robot = armdyn.load("rp-arm")
    ne, la = derive(robot), derive(robot, "lagrange")
    broken = derive(robot)
    broken.tau = ne.tau + sp.Matrix([robot.parameters["m1"] * robot.qd[0] ** 2, 0])
    assert not check(broken, la, structure=False)
    assert not check(broken, la, exact=False, structure=False)


def test_rp_arm_and_planar_2r_against_sympy_mechanics():
    """sympy.physics.mechanics' LagrangesMethod (own frames, own time derivatives)."""
    from mechanics_bridge import mechanics_tau

    for name in ("rp-arm", "planar-2r"):
        robot = armdyn.load(name)
        theirs = mechanics_tau(robot)
        ours = derive(robot).tau
        assert all(zero(sp.expand_trig(e), robot.q) for e in ours - theirs), name


def test_random_tree_against_sympy_mechanics():
    from mechanics_bridge import mechanics_tau

    rng = np.random.default_rng(11)
    robot = random_robot(rng, n_joints=3, tree=True, kinds="RP")
    theirs, ours = mechanics_tau(robot), derive(robot).tau
    syms = list(robot.q) + list(robot.qd) + list(robot.qdd)
    f = sp.lambdify(syms, [theirs, ours])
    for _ in range(5):
        a, b = (np.array(v, dtype=float).ravel() for v in f(*rng.uniform(-2, 2, len(syms))))
        assert np.allclose(a, b, rtol=1e-10, atol=1e-10)
