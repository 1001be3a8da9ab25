"""A valid URDF with 10^4 joints loads and its dynamics are right.

Correctness only, no timing (the load time is in benchmarks/bench_load.py). The model
comes from tests/big_urdf.py, which also returns it as plain arrays; the checks compute
what the model must do from those arrays in NumPy, without armdyn's reader or engines:

* statics: ``rnea(q, 0, 0)`` is the gravity torque ``dV/dq``; for a revolute joint
  ``z . sum_j (c_j - o) x (-m_j g)`` over the bodies it carries, for a prismatic one
  ``z . sum_j (-m_j g)`` (subtree sums, one pass from the leaves);
* power: ``qd . rnea(q, qd, qdd) = d(T + V)/dt`` along ``q(t) = q + t qd + t^2/2 qdd``,
  with T and V from forward kinematics in NumPy and the time derivative by central
  differences (no friction in these files, so all the power goes into energy);
* Pinocchio, reading the same file with its own URDF parser, gives the same rnea
  (skips alone without Pinocchio) on 200-joint models: Pinocchio's ``createData``
  is killed for lack of memory at 10^3 joints here (24 GB; it allocates tensors that
  grow faster than nv^2), and at 10^4 its URDF parser overflows the main thread's stack
  on the chain (it recurses along the tree).
"""

from __future__ import annotations

import warnings

import numpy as np
import pytest
from big_urdf import big_urdf

import armdyn

N_JOINTS = 10_000
GRAVITY = np.array([0.0, 0.0, -9.81])


def _axis_rotation(axis: np.ndarray, angle: float) -> np.ndarray:
    """Rodrigues' formula (3, 3)."""
    K = np.array([[0, -axis[2], axis[1]], [axis[2], 0, -axis[0]], [-axis[1], axis[0], 0]])
    return np.eye(3) + np.sin(angle) * K + (1 - np.cos(angle)) * K @ K


def _kinematics(spec, qj: np.ndarray, qdj: np.ndarray):
    """World poses and velocities of every body, per joint values ``qj``/``qdj`` (n,)
    (zero for fixed joints). Returns z (n, 3) world joint axes, o (n, 3) joint frame
    origins after the motion, R0 (n, 3, 3), c (n, 3) world centres of mass, w (n, 3)
    angular velocities, vc (n, 3) velocities of the centres of mass."""
    n = len(spec.kind)
    R0, p0 = np.empty((n, 3, 3)), np.empty((n, 3))
    z, w, v = np.empty((n, 3)), np.empty((n, 3)), np.empty((n, 3))  # v: of the frame origin
    for k in range(n):  # parents come first (parent[k] < k)
        a = spec.parent[k]
        Rp, pp = (np.eye(3), np.zeros(3)) if a < 0 else (R0[a], p0[a])
        wp, vp = (np.zeros(3), np.zeros(3)) if a < 0 else (w[a], v[a])
        Rj = Rp @ spec.R[k]  # the placement frame in the world
        z[k] = Rj @ spec.axis[k]
        o_fixed = pp + Rp @ spec.xyz[k]
        if spec.kind[k] == "R":
            R0[k], p0[k] = Rj @ _axis_rotation(spec.axis[k], qj[k]), o_fixed
            w[k] = wp + z[k] * qdj[k]
            v[k] = vp + np.cross(wp, o_fixed - pp)
        elif spec.kind[k] == "P":
            R0[k], p0[k] = Rj, o_fixed + z[k] * qj[k]
            w[k] = wp
            v[k] = vp + np.cross(wp, p0[k] - pp) + z[k] * qdj[k]
        else:
            R0[k], p0[k] = Rj, o_fixed
            w[k], v[k] = wp, vp + np.cross(wp, o_fixed - pp)
    c = p0 + np.einsum("kij,kj->ki", R0, spec.com)
    vc = v + np.cross(w, c - p0)
    return z, p0, R0, c, w, vc


def _energy(spec, qj, qdj) -> float:
    """T + V in NumPy: 1/2 m |vc|^2 + 1/2 w' (R I R') w, V = -m g . c."""
    _, _, R0, c, w, vc = _kinematics(spec, qj, qdj)
    Iw = np.einsum("kij,kjl,kml,km->ki", R0, spec.inertia, R0, w)  # (R I R^T) w
    T = 0.5 * np.sum(spec.mass * np.sum(vc * vc, axis=1)) + 0.5 * np.sum(w * Iw)
    V = -np.sum(spec.mass * (c @ GRAVITY))
    return float(T + V)


def _gravity_torques(spec, qj) -> np.ndarray:
    """dV/dq per joint (n,), from subtree sums of m and m c (fixed joints: 0)."""
    n = len(spec.kind)
    z, o, _, c, _, _ = _kinematics(spec, qj, np.zeros(n))
    m_sub, mc_sub = spec.mass.copy(), spec.mass[:, None] * c
    for k in range(n - 1, -1, -1):  # children (k > parent) before parents
        a = spec.parent[k]
        if a >= 0:
            m_sub[a] += m_sub[k]
            mc_sub[a] += mc_sub[k]
    tau = np.zeros(n)
    for k in range(n):
        if spec.kind[k] == "R":  # -z . sum (c - o) x m g
            tau[k] = -z[k] @ np.cross(mc_sub[k] - m_sub[k] * o[k], GRAVITY)
        elif spec.kind[k] == "P":
            tau[k] = -z[k] @ (m_sub[k] * GRAVITY)
    return tau


def close(actual, expected, rtol: float, what: str) -> None:
    actual, expected = np.asarray(actual, dtype=float), np.asarray(expected, dtype=float)
    assert actual.size > 0 and actual.shape == expected.shape, what
    assert np.all(np.isfinite(actual)) and np.all(np.isfinite(expected)), f"{what}: not finite"
    scale = np.abs(expected).max()
    assert scale > 0, what
    np.testing.assert_allclose(actual, expected, rtol=0, atol=rtol * scale, err_msg=what)


@pytest.fixture(scope="module", params=[False, True], ids=["chain", "tree"])
def big(request, tmp_path_factory):
    tree = request.param
    text, spec = big_urdf(N_JOINTS, tree=tree, seed=5)
    path = tmp_path_factory.mktemp("big") / f"big_{'tree' if tree else 'chain'}.urdf"
    path.write_text(text)
    with warnings.catch_warnings():
        warnings.simplefilter("error")  # every link has mass: nothing to warn about
        robot = armdyn.load(str(path))
    return path, spec, robot


def _joint_values(robot, spec, x: np.ndarray) -> np.ndarray:
    """armdyn coordinates (dof,) -> per-joint values (n,) in the file's joint numbering."""
    out = np.zeros(len(spec.kind))
    for value, name in zip(x, robot.coordinate_names):
        out[int(name[1:])] = value
    return out


def test_loads_with_every_joint_in_tree_order(big):
    _, spec, robot = big
    assert len(robot.joints) == N_JOINTS
    assert robot.dof == sum(k != "F" for k in spec.kind) > 0
    seen = {robot.base}
    for j in robot.joints:  # the reader reordered the shuffled joints into a tree order
        assert j.parent in seen
        seen.add(j.child)


def test_rnea_statics_equal_subtree_moments(big):
    _, spec, robot = big
    rng = np.random.default_rng(6)
    for _ in range(2):
        q = rng.uniform(-np.pi, np.pi, robot.dof)
        zero = np.zeros(robot.dof)
        tau = armdyn.rnea(robot, q, zero, zero)
        expected = _gravity_torques(spec, _joint_values(robot, spec, q))
        movable = np.array([int(name[1:]) for name in robot.coordinate_names])
        close(tau, expected[movable], 1e-9, "rnea(q, 0, 0) == dV/dq from subtree moments")


def test_rnea_power_equals_energy_rate(big):
    _, spec, robot = big
    rng = np.random.default_rng(7)
    n = robot.dof
    q, qd, qdd = rng.uniform(-np.pi, np.pi, n), rng.uniform(-0.1, 0.1, n), rng.uniform(-0.1, 0.1, n)
    power = qd @ armdyn.rnea(robot, q, qd, qdd)
    h = 1e-4

    def energy(t):
        return _energy(
            spec, _joint_values(robot, spec, q + t * qd + 0.5 * t * t * qdd), _joint_values(robot, spec, qd + t * qdd)
        )

    rate = (energy(h) - energy(-h)) / (2 * h)
    scale = np.abs(qd) @ np.abs(armdyn.rnea(robot, q, qd, qdd))  # sum of |power| terms
    assert np.isfinite(power) and np.isfinite(rate) and scale > 0
    assert abs(power - rate) <= 1e-6 * scale, (power, rate, scale)


@pytest.mark.parametrize("tree", [False, True], ids=["chain", "tree"])
def test_rnea_equals_pinocchio_reading_the_same_file(tree, tmp_path):
    pin = pytest.importorskip("pinocchio")
    text, _ = big_urdf(200, tree=tree, seed=9)
    path = tmp_path / "big.urdf"
    path.write_text(text)
    robot = armdyn.load(str(path))
    model = pin.buildModelFromUrdf(str(path))
    data = model.createData()
    model.gravity.linear[:] = GRAVITY
    index = {name: i for i, name in enumerate(robot.coordinate_names)}
    assert len(index) == robot.dof == model.nv == model.njoints - 1
    rng = np.random.default_rng(8)
    n = robot.dof
    q, qd, qdd = rng.uniform(-np.pi, np.pi, n), rng.uniform(-1, 1, n), rng.uniform(-1, 1, n)
    pq, pv, pa = np.zeros(model.nq), np.zeros(model.nv), np.zeros(model.nv)
    for jid in range(1, model.njoints):  # continuous joints are (cos, sin) in Pinocchio's q
        k = index[model.names[jid]]
        iq, iv = model.joints[jid].idx_q, model.joints[jid].idx_v
        if model.joints[jid].nq == 2:
            pq[iq : iq + 2] = np.cos(q[k]), np.sin(q[k])
        else:
            pq[iq] = q[k]
        pv[iv], pa[iv] = qd[k], qdd[k]
    tau_pin = np.asarray(pin.rnea(model, data, pq, pv, pa))
    ours = np.empty(n)
    for jid in range(1, model.njoints):
        ours[index[model.names[jid]]] = tau_pin[model.joints[jid].idx_v]
    close(armdyn.rnea(robot, q, qd, qdd), ours, 1e-9, "rnea == Pinocchio's")
