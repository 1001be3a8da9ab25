"""Derivatives of the dynamics and M^-1 with joint friction, rotor inertia and offset
(docs/architecture.md: ``tau = M qdd + C qd + g + Ia qdd + Fv qd + Fc sign(qd) + offset``).

The derivative functions must agree with rnea/aba, which include those terms:
``M`` and ``Minv`` get ``diag(Ia)``, ``dtau/dqd`` gets ``diag(Fv)``; the Coulomb term is
piecewise constant, so it adds nothing away from ``qd = 0``, and at ``qd_k = 0`` (where
rnea's ``Fc sign(qd_k)`` jumps, ``sign(0) = 0``) the derivative reported is that of both
branches, the jump left out.

Second opinions:
* central differences of the Rust core's rnea/aba/gravity (which have the terms) on
  bundled arms with random terms on every joint;
* one-sided differences at ``qd_k = 0`` that stay on one side of the jump;
* Pinocchio with ``model.armature`` (its rnea, crba, aba, computeRNEADerivatives,
  computeABADerivatives and computeMinverse include the armature, not ``damping`` or
  friction): its derivatives plus the closed form of the terms it lacks;
* identities: ``minverse @ crba = I``; ``dqdd/dq = -Minv dtau/dq`` at ``qdd = aba``.
"""

from __future__ import annotations

import numpy as np
import pytest
from test_joint_dynamics import numeric_arm, with_terms

from armdyn import numeric as num

ARMS = ["puma560", "ur5", "panda", "iiwa14", "stanford"]
H = 1e-6


def _central(f, x, h=H):
    """Central differences of f along each coordinate of x, coordinate as the last axis."""
    cols = [(np.asarray(f(x + h * e)) - np.asarray(f(x - h * e))) / (2 * h) for e in np.eye(len(x))]
    return np.stack(cols, axis=-1)


def assert_close(actual, expected, rtol, what, scale=None):
    """max |actual - expected| <= rtol * max(scale, max |expected|, 1); both finite."""
    actual, expected = np.asarray(actual, float), np.asarray(expected, float)
    assert actual.shape == expected.shape, (what, actual.shape, expected.shape)
    assert np.isfinite(actual).all() and np.isfinite(expected).all(), f"{what}: not finite"
    s = max(np.abs(expected).max(), 1.0 if scale is None else scale)
    err = np.abs(actual - expected).max() / s
    assert err <= rtol, f"{what}: relative error {err:.2e} > {rtol:.0e}"


def _state(robot, seed):
    """q, qd, qdd with every |qd_k| >= 0.2, so that a step of H never crosses qd_k = 0."""
    rng = np.random.default_rng(seed)
    n = robot.dof
    qd = rng.uniform(0.2, 1.5, n) * rng.choice([-1.0, 1.0], n)
    return rng.uniform(-2, 2, n), qd, rng.uniform(-2, 2, n)


def _terms(robot):
    """(Ia, Fv, Fc, offset), each (dof,)."""
    get = lambda t: np.array([float(getattr(j, t) or 0) for j in robot.movable_joints])  # noqa: E731
    return tuple(get(t) for t in ("armature", "damping", "friction", "torque_offset"))


@pytest.fixture(scope="module", params=ARMS)
def arm(request):
    return request.param, with_terms(numeric_arm(request.param))


def test_terms_are_present(arm):
    """The arms under test really have every term (else the checks below prove little)."""
    name, robot = arm
    for values in _terms(robot):
        assert values.size == robot.dof > 0 and np.all(values != 0), name


def test_rnea_derivatives_against_central_differences(arm):
    name, robot = arm
    q, qd, qdd = _state(robot, 11)
    mine = num.rnea_derivatives(robot, q, qd, qdd)
    fd = (
        _central(lambda y: num.rnea(robot, y, qd, qdd), q),
        _central(lambda y: num.rnea(robot, q, y, qdd), qd),
        _central(lambda y: num.rnea(robot, q, qd, y), qdd),
    )
    for a, b, what in zip(mine, fd, ("dtau_dq", "dtau_dqd", "M")):
        assert_close(a, b, 1e-6, f"{name} {what}")
    # the terms are really in there: without diag(Ia), diag(Fv) the check above would fail
    Ia, Fv, _, _ = _terms(robot)
    assert np.abs(mine[1] - np.diag(Fv) - fd[1]).max() > 1e3 * 1e-6 * max(np.abs(fd[1]).max(), 1)
    assert np.abs(mine[2] - np.diag(Ia) - fd[2]).max() > 1e3 * 1e-6 * max(np.abs(fd[2]).max(), 1)
    np.testing.assert_allclose(mine[2], num.crba(robot, q), rtol=0, atol=1e-12 * np.abs(mine[2]).max())


def test_aba_derivatives_and_minverse_against_central_differences(arm):
    name, robot = arm
    q, qd, qdd = _state(robot, 12)
    tau = num.rnea(robot, q, qd, qdd)
    dq, dqd, Minv = num.aba_derivatives(robot, q, qd, tau)
    fd = (
        _central(lambda y: num.aba(robot, y, qd, tau), q),
        _central(lambda y: num.aba(robot, q, y, tau), qd),
        _central(lambda y: num.aba(robot, q, qd, y), tau),
    )
    for a, b, what in zip((dq, dqd, Minv), fd, ("dqdd_dq", "dqdd_dqd", "Minv")):
        assert_close(a, b, 1e-6, f"{name} {what}")
    M = num.crba(robot, q)  # M + diag(Ia)
    for what, Mi in (("aba_derivatives Minv", Minv), ("minverse", num.minverse(robot, q))):
        assert_close(Mi @ M, np.eye(robot.dof), 1e-11, f"{name} {what} @ crba")
    np.testing.assert_allclose(num.minverse(robot, q), Minv, rtol=0, atol=1e-12 * np.abs(Minv).max())
    # identity (Carpentier & Mansard IV.C), from rnea_derivatives and minverse
    r_dq, r_dqd, _ = num.rnea_derivatives(robot, q, qd, num.aba(robot, q, qd, tau))
    assert_close(dq, -num.minverse(robot, q) @ r_dq, 1e-10, f"{name} dqdd_dq identity")
    assert_close(dqd, -num.minverse(robot, q) @ r_dqd, 1e-10, f"{name} dqdd_dqd identity")


def test_gravity_derivatives_unchanged_by_the_terms(arm):
    """g = rnea(q, 0, 0) has the offset (a constant) and Fc sign(0) = 0: dg/dq has no term."""
    name, robot = arm
    q, _, _ = _state(robot, 13)
    assert_close(num.gravity_derivatives(robot, q), _central(lambda y: num.gravity(robot, y), q), 1e-6, f"{name} dg/dq")


def test_coulomb_at_rest_is_the_derivative_of_both_branches(arm):
    """At qd_k = 0 rnea's Coulomb term jumps by Fc_k; the column k of dtau/dqd reported
    there equals the one-sided differences on either side (steps that stay off 0),
    i.e. the derivative of each smooth branch; likewise for aba."""
    name, robot = arm
    q, qd, qdd = _state(robot, 14)
    k = robot.dof // 2
    qd[k] = 0.0
    h = 1e-4
    e = np.eye(robot.dof)[k]
    dtau_dqd = num.rnea_derivatives(robot, q, qd, qdd)[1][:, k]
    tau = num.rnea(robot, q, qd, qdd)
    dqdd_dqd = num.aba_derivatives(robot, q, qd, tau)[1][:, k]

    def branch_slope(f, side):
        """d f(qd + t e)/dt at t = 0 on one side, from the quadratic through t = side*h,
        side*2h, side*3h (all off the jump): (-5/2 f1 + 4 f2 - 3/2 f3) / (side h)."""
        f1, f2, f3 = (f(qd + side * s * h * e) for s in (1, 2, 3))
        return (-2.5 * f1 + 4 * f2 - 1.5 * f3) / (side * h)

    for side in (1.0, -1.0):
        assert_close(
            dtau_dqd,
            branch_slope(lambda v: num.rnea(robot, q, v, qdd), side),
            1e-6,
            f"{name} dtau/dqd_{k} side {side:+}",
        )
        assert_close(
            dqdd_dqd,
            branch_slope(lambda v: num.aba(robot, q, v, tau), side),
            1e-6,
            f"{name} dqdd/dqd_{k} side {side:+}",
        )
    # and the jump is really there (so the sides above were needed)
    jump = num.rnea(robot, q, qd + 1e-9 * e, qdd) - tau
    assert abs(jump[k] - _terms(robot)[2][k]) < 1e-6


def test_against_pinocchio_with_armature(arm):
    """Pinocchio models the rotor inertia (``model.armature``) in rnea, crba, aba and their
    derivatives, but neither viscous nor Coulomb friction nor an offset. So: our dtau/dq
    and M equal its; our dtau/dqd is its plus diag(Fv); for forward dynamics at the
    torque reaching the joints, tau - (Fv qd + Fc sign(qd) + offset), dqdd/dq and Minv
    equal its and dqdd/dqd is its minus Minv diag(Fv)."""
    pytest.importorskip("pinocchio")
    from pinocchio_derivatives import PinocchioDerivatives

    name, robot = arm
    P = PinocchioDerivatives(robot)
    Ia, Fv, Fc, off = _terms(robot)
    P.model.armature = Ia[P.perm]
    P.data = P.model.createData()
    for seed in (21, 22):
        q, qd, qdd = _state(robot, seed)
        dq, dqd, M = num.rnea_derivatives(robot, q, qd, qdd)
        p_dq, p_dqd, p_M = P.rnea_derivatives(q, qd, qdd)
        assert_close(dq, p_dq, 1e-10, f"{name} dtau_dq")
        assert_close(dqd, p_dqd + np.diag(Fv), 1e-10, f"{name} dtau_dqd")
        assert_close(M, p_M, 1e-10, f"{name} M")
        tau = num.rnea(robot, q, qd, qdd)
        a_dq, a_dqd, Minv = num.aba_derivatives(robot, q, qd, tau)
        rigid_tau = tau - (Fv * qd + Fc * np.sign(qd) + off)
        p_dq, p_dqd, p_Minv = P.aba_derivatives(q, qd, rigid_tau)
        assert_close(Minv, p_Minv, 1e-10, f"{name} Minv")
        assert_close(num.minverse(robot, q), P.minverse(q), 1e-10, f"{name} minverse")
        assert_close(a_dq, p_dq, 1e-10, f"{name} dqdd_dq")
        assert_close(a_dqd, p_dqd - p_Minv @ np.diag(Fv), 1e-10, f"{name} dqdd_dqd")


def test_batches_with_terms_equal_single_calls(arm):
    name, robot = arm
    rng = np.random.default_rng(31)
    Q, QD, X = (rng.uniform(-2, 2, (9, robot.dof)) for _ in range(3))
    QD[0, 0] = 0.0  # Coulomb at rest in the batch too
    for threads in (1, 2):
        for fn in (num.rnea_derivatives, num.aba_derivatives):
            batch = fn(robot, Q, QD, X, threads=threads)
            for i in range(len(Q)):
                for b, s in zip(batch, fn(robot, Q[i], QD[i], X[i])):
                    np.testing.assert_array_equal(b[i], s)
        batch = num.minverse(robot, Q, threads=threads)
        for i in range(len(Q)):
            np.testing.assert_array_equal(batch[i], num.minverse(robot, Q[i]))


def test_against_the_reference(arm):
    """armdyn.reference: forward-mode differentiation of RBDA's tables, the terms added to
    the RNEA's tau and the ABA's D and u (a different algorithm), to 1e-10."""
    from armdyn import reference as ref

    name, robot = arm
    q, qd, qdd = _state(robot, 41)
    qd[0] = 0.0  # Coulomb at rest: both give the derivative of either side
    for mine, theirs, what in (
        (num.rnea_derivatives(robot, q, qd, qdd), ref.rnea_derivatives(robot, q, qd, qdd), "rnea"),
        (num.aba_derivatives(robot, q, qd, qdd), ref.aba_derivatives(robot, q, qd, qdd), "aba"),
    ):
        for a, b, k in zip(mine, theirs, range(3), strict=True):
            assert_close(a, b, 1e-10, f"{name} {what} output {k}")
    assert_close(num.minverse(robot, q), ref.minverse(robot, q), 1e-10, f"{name} minverse")
    np.testing.assert_allclose(
        ref.rnea_ext(robot, q, qd, qdd, np.zeros((len(robot.links), 6))),
        num.rnea(robot, q, qd, qdd),
        rtol=0,
        atol=1e-10 * max(1, np.abs(qdd).max()),
    )
