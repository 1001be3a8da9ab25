"""Derivatives of the dynamics, M^-1, dg/dq and dJ/dt for robots with mimic joints
(armdyn.mimic: ``q_full = G q + o``; derivatives ``G^T D_full G`` by the chain rule,
forward dynamics through ``-M^-1 dID/dx`` with ``M = G^T M_full G``).

Second opinions:
* central differences of armdyn's rnea/aba/gravity/jacobian for mimic robots (which map
  the full tree's values, not its derivatives, and solve the reduced equations by
  Cholesky: a different route from the analytic derivatives);
* Pinocchio 4.1's own mimic model (``buildModelFromXML(urdf, mimic=True)``): its
  computeRNEADerivatives/computeABADerivatives/computeMinverse refuse mimic joints, so
  central differences of its rnea, its crba, and forward dynamics built from them
  (``M^-1 (tau - rnea(q, qd, 0))``);
* identities: ``Minv M = I``; ``dqdd/dq = -Minv dtau/dq`` at ``qdd = aba``;
* batches equal single calls; external wrenches are refused with a clear error.
"""

from __future__ import annotations

from dataclasses import replace

import numpy as np
import pytest
from test_mimic import ARM

from armdyn import numeric as num
from armdyn.io.urdf import load_urdf
from armdyn.model import Robot

H = 1e-6


def _central(f, x, h=H):
    cols = [(np.asarray(f(x + h * e)) - np.asarray(f(x - h * e))) / (2 * h) for e in np.eye(len(x))]
    return np.stack(cols, axis=-1)


def assert_close(actual, expected, rtol, what):
    actual, expected = np.asarray(actual, float), np.asarray(expected, float)
    assert actual.shape == expected.shape, (what, actual.shape, expected.shape)
    assert np.isfinite(actual).all() and np.isfinite(expected).all(), f"{what}: not finite"
    err = np.abs(actual - expected).max() / max(np.abs(expected).max(), 1.0)
    assert err <= rtol, f"{what}: relative error {err:.2e} > {rtol:.0e}"


def _with_terms(robot: Robot) -> Robot:
    """Friction, rotor inertia and offset on the independent joints."""
    rng = np.random.default_rng(3)
    joints = [
        replace(
            j,
            armature=rng.uniform(0.01, 0.1),
            damping=rng.uniform(0.1, 0.5),
            friction=rng.uniform(0.1, 0.3),
            torque_offset=rng.uniform(-0.2, 0.2),
        )
        if j.movable and j.mimic is None
        else j
        for j in robot.joints
    ]
    return Robot(
        robot.name,
        robot.links.values(),
        joints,
        robot.gravity,
        robot.parameters,
        robot.meta,
        robot.base,
        robot.defaults,
        strict=False,
    )


ROBOTS = {"plain": lambda: load_urdf(ARM), "terms": lambda: _with_terms(load_urdf(ARM))}


@pytest.fixture(scope="module", params=list(ROBOTS))
def arm(request):
    robot = ROBOTS[request.param]()
    assert robot.mimic_joints and robot.dof == 3
    return request.param, robot


def _state(robot, seed):
    rng = np.random.default_rng(seed)
    n = robot.dof
    qd = rng.uniform(0.3, 1.5, n) * rng.choice([-1.0, 1.0], n)  # off qd = 0 (Coulomb)
    return rng.uniform(-1.5, 1.5, n), qd, rng.uniform(-2, 2, n)


def test_against_central_differences(arm):
    name, robot = arm
    for seed in (1, 2):
        q, qd, x = _state(robot, seed)
        mine = num.rnea_derivatives(robot, q, qd, x)
        fd = (
            _central(lambda y: num.rnea(robot, y, qd, x), q),
            _central(lambda y: num.rnea(robot, q, y, x), qd),
            _central(lambda y: num.rnea(robot, q, qd, y), x),
        )
        for a, b, what in zip(mine, fd, ("dtau_dq", "dtau_dqd", "M")):
            assert_close(a, b, 1e-7, f"{name} {what}")
        mine = num.aba_derivatives(robot, q, qd, x)
        fd = (
            _central(lambda y: num.aba(robot, y, qd, x), q),
            _central(lambda y: num.aba(robot, q, y, x), qd),
            _central(lambda y: num.aba(robot, q, qd, y), x),
        )
        for a, b, what in zip(mine, fd, ("dqdd_dq", "dqdd_dqd", "Minv"), strict=True):
            assert_close(a, b, 1e-7, f"{name} {what}")
        assert_close(num.minverse(robot, q), fd[2], 1e-7, f"{name} minverse")
        assert_close(
            num.gravity_derivatives(robot, q), _central(lambda y: num.gravity(robot, y), q), 1e-7, f"{name} dg/dq"
        )
        for link in robot.links:
            fdj = _central(lambda t: num.jacobian(robot, q + t[0] * qd, link), np.zeros(1))[..., 0]
            assert_close(num.jacobian_dot(robot, q, qd, link), fdj, 1e-7, f"{name} jacobian_dot {link}")


def test_identities(arm):
    name, robot = arm
    q, qd, tau = _state(robot, 3)
    dq, dqd, Minv = num.aba_derivatives(robot, q, qd, tau)
    r_dq, r_dqd, M = num.rnea_derivatives(robot, q, qd, num.aba(robot, q, qd, tau))
    assert_close(Minv @ M, np.eye(robot.dof), 1e-12, f"{name} Minv M")
    assert_close(M, num.crba(robot, q), 1e-13, f"{name} M == crba")
    assert_close(dq, -Minv @ r_dq, 1e-12, f"{name} dqdd_dq")
    assert_close(dqd, -Minv @ r_dqd, 1e-12, f"{name} dqdd_dqd")


def test_against_pinocchio_mimic_model():
    """Pinocchio's mimic model (no terms: its rnea lacks friction; armature not set)."""
    pin = pytest.importorskip("pinocchio")
    from test_urdf import pin_configuration

    robot = load_urdf(ARM)
    model = pin.buildModelFromXML(ARM, mimic=True)
    data = model.createData()
    assert model.nv == robot.dof == 3
    # every joint of ARM is revolute or prismatic (nq = 1), so pin q = q[perm] + pin's offsets
    _, perm = pin_configuration(model, robot, np.zeros(robot.dof))
    inv = np.argsort(perm)

    def rnea(q, qd, qdd):  # armdyn order in and out
        qp, _ = pin_configuration(model, robot, q)
        return np.asarray(pin.rnea(model, data, qp, qd[perm], qdd[perm]))[inv]

    def crba(q):
        # a fresh Data each time: Pinocchio 4.1's crba on a mimic model gives another
        # (wrong) M when called again on the same Data, even with data.M zeroed
        qp, _ = pin_configuration(model, robot, q)
        M = np.array(pin.crba(model, model.createData(), qp))
        M = np.triu(M) + np.triu(M, 1).T
        return M[np.ix_(inv, inv)]

    def fd_pin(q, qd, tau):  # forward dynamics from Pinocchio's M and bias
        return np.linalg.solve(crba(q), tau - rnea(q, qd, np.zeros_like(q)))

    for seed in (4, 5):
        q, qd, x = _state(robot, seed)
        np.testing.assert_allclose(num.rnea(robot, q, qd, x), rnea(q, qd, x), rtol=1e-12, atol=1e-12)
        dq, dqd, M = num.rnea_derivatives(robot, q, qd, x)
        assert_close(dq, _central(lambda y: rnea(y, qd, x), q), 1e-7, "dtau_dq vs Pinocchio")
        assert_close(dqd, _central(lambda y: rnea(q, y, x), qd), 1e-7, "dtau_dqd vs Pinocchio")
        assert_close(M, crba(q), 1e-12, "M vs Pinocchio crba")
        adq, adqd, Minv = num.aba_derivatives(robot, q, qd, x)
        assert_close(Minv, np.linalg.inv(crba(q)), 1e-11, "Minv vs inverse of Pinocchio's crba")
        assert_close(num.minverse(robot, q), np.linalg.inv(crba(q)), 1e-11, "minverse vs Pinocchio")
        assert_close(adq, _central(lambda y: fd_pin(y, qd, x), q), 1e-7, "dqdd_dq vs Pinocchio")
        assert_close(adqd, _central(lambda y: fd_pin(q, y, x), qd), 1e-7, "dqdd_dqd vs Pinocchio")


def test_batches_equal_single_calls(arm):
    name, robot = arm
    rng = np.random.default_rng(6)
    Q, QD, X = (rng.uniform(-1.5, 1.5, (7, robot.dof)) for _ in range(3))
    for threads in (1, 2):
        for fn in (num.rnea_derivatives, num.aba_derivatives):
            batch = fn(robot, Q, QD, X, threads=threads)
            for b in batch:
                assert b.shape == (7, robot.dof, robot.dof)
            for i in range(len(Q)):
                for b, s in zip(batch, fn(robot, Q[i], QD[i], X[i]), strict=True):
                    np.testing.assert_allclose(b[i], s, rtol=1e-14, atol=1e-14 * max(1.0, np.abs(s).max()))
        for fn, args in (
            (num.minverse, (Q,)),
            (num.gravity_derivatives, (Q,)),
            (lambda r, q, qd, **k: num.jacobian_dot(r, q, qd, "hand", **k), (Q, QD)),
        ):
            batch = fn(robot, *args, threads=threads)
            for i in range(len(Q)):
                s = fn(robot, *(a[i] for a in args))
                np.testing.assert_allclose(batch[i], s, rtol=1e-14, atol=1e-14 * max(1.0, np.abs(s).max()))


def test_bad_input(arm):
    _, robot = arm
    q = np.zeros(robot.dof)
    W = np.zeros((len(robot.links), 6))
    with pytest.raises(ValueError, match="f_ext is not available yet for robots with mimic joints"):
        num.rnea_derivatives(robot, q, q, q, f_ext=W)
    with pytest.raises(ValueError, match="f_ext is not available yet for robots with mimic joints"):
        num.aba_derivatives(robot, q, q, q, f_ext=W)
    with pytest.raises(ValueError, match=r"qd: expected shape \(3,\)"):
        num.rnea_derivatives(robot, q, np.zeros(4), q)
    with pytest.raises(ValueError, match=r"q contains NaN or inf \(at q\[1\]\)"):
        num.minverse(robot, np.array([0.0, np.nan, 0.0]))
    with pytest.raises(ValueError, match="tau contains NaN"):
        num.aba_derivatives(robot, q, q, np.array([0.0, np.inf, 0.0]))
    with pytest.raises(ValueError, match="frame"):
        num.rnea_derivatives(robot, q, q, q, frame="moon")
