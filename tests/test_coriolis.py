"""The Coriolis matrix C(q, qd) against independently computed quantities.

"Mdot - 2C is skew-symmetric" proves nothing when C is built from M (the Christoffel
symbols of a symmetric M give it by construction). Here every side comes from a
different algorithm:

* C: the Rust core's ``coriolis_matrix`` (Echeandia & Wensing 2021: body Jacobians and
  their derivatives, never M or its derivatives), Pinocchio's ``computeCoriolisMatrix``
  (a third implementation), and the symbolic engine's Christoffel C (SymPy, from the
  Lagrangian);
* Mdot: central differences of ``crba`` along qd, and the analytical derivatives of
  inverse dynamics (Carpentier & Mansard 2018): ``d(M(q) e_k)/dq`` is
  ``rnea_derivatives(q, 0, e_k).dtau_dq - rnea_derivatives(q, 0, 0).dtau_dq`` (gravity
  and constant terms cancel), so ``Mdot e_k = (that) qd``;
* C qd: ``rnea(q, qd, 0) - rnea(q, 0, 0)`` (the recursive Newton-Euler algorithm).

NaN never passes (``close`` asserts finiteness, then ``np.testing.assert_allclose``);
seeds are fixed.
"""

from __future__ import annotations

import warnings

import numpy as np
import pytest
import sympy as sp
from random_models import random_robot, random_state

import armdyn
from armdyn.symbolic import dag, derive


def close(actual, expected, rtol: float, scale: float, what: str) -> None:
    """``actual`` equals ``expected`` within ``rtol * scale``; both must be finite (a NaN
    or inf anywhere fails, whatever the other side holds)."""
    actual, expected = np.asarray(actual, dtype=float), np.asarray(expected, dtype=float)
    assert actual.size > 0 and actual.shape == expected.shape, f"{what}: shapes {actual.shape} {expected.shape}"
    assert np.all(np.isfinite(actual)), f"{what}: not finite: {actual}"
    assert np.all(np.isfinite(expected)), f"{what}: reference not finite: {expected}"
    assert np.isfinite(scale) and scale > 0, f"{what}: bad scale {scale}"
    np.testing.assert_allclose(actual, expected, rtol=0, atol=rtol * scale, err_msg=what)


def skew_part_check(N: np.ndarray, rtol: float, scale: float, what: str) -> None:
    """``N + N^T == 0``: N is skew-symmetric."""
    close(N + N.T, np.zeros_like(N), rtol, scale, what)


def mdot_analytic(robot, q, qd) -> np.ndarray:
    """Mdot (n, n) from the analytical derivatives of inverse dynamics:
    column k is ``d(M e_k)/dq qd`` (rnea_derivatives at qd = 0, qdd = e_k, minus qdd = 0)."""
    n = robot.dof
    Q = np.tile(q, (n + 1, 1))
    A = np.vstack([np.eye(n), np.zeros(n)])
    dtau_dq, _, _ = armdyn.rnea_derivatives(robot, Q, np.zeros((n + 1, n)), A)
    dM = dtau_dq[:n] - dtau_dq[n]  # dM[k] = d(M e_k)/dq, (n, n)
    return np.stack([dM[k] @ qd for k in range(n)], axis=1)


def mdot_differences(robot, q, qd, h: float = 1e-6) -> np.ndarray:
    """Mdot by central differences of M along qd: (M(q + h qd) - M(q - h qd)) / 2h."""
    return (armdyn.crba(robot, q + h * qd) - armdyn.crba(robot, q - h * qd)) / (2 * h)


def _bound(name: str, seed: int):
    """A bundled model bound to its published values, physical random values for
    parameters that have none (fixed seed)."""
    rng = np.random.default_rng(seed)
    with warnings.catch_warnings():
        warnings.filterwarnings("ignore", message=".*(triangle inequality|positive semi-definite)")
        robot = armdyn.load(name, strict=False)
        free = {}
        for p in robot.parameters:
            if p in robot.defaults:
                continue
            if p.startswith(("Ixy", "Ixz", "Iyz")):
                free[p] = float(rng.uniform(-0.05, 0.05))
            elif p.startswith(("Ixx", "Iyy", "Izz")):
                free[p] = float(rng.uniform(1.0, 1.5))
            else:
                free[p] = float(rng.uniform(0.5, 2.0))
        return robot.bind(free)


ARMS = ["rp-arm", "planar-2r", "planar-3r", "scara", "stanford", "puma560", "ur5", "panda", "iiwa14"]


def _robots():
    out = [(name, _bound(name, 11)) for name in ARMS]
    for seed in (1, 2, 3):
        rng = np.random.default_rng(seed)
        out.append((f"random tree {seed}", random_robot(rng, n_joints=7, tree=True)))
    out.append(("random chain, frame offsets", random_robot(np.random.default_rng(4), n_joints=6, frame_offsets=True)))
    return out


ROBOTS = _robots()


@pytest.mark.parametrize("name,robot", ROBOTS, ids=[n for n, _ in ROBOTS])
def test_mdot_minus_2c_skew_with_independent_c(name, robot):
    """Rust C (no M inside) with Mdot from two other algorithms: Mdot - 2C skew."""
    rng = np.random.default_rng(20)
    n = robot.dof
    samples = 4
    for _ in range(samples):
        q, qd = random_state(rng, n), random_state(rng, n)
        C = armdyn.coriolis_matrix(robot, q, qd)
        M = armdyn.crba(robot, q)
        scale = np.abs(M).max() * np.abs(qd).max()
        Md_a, Md_d = mdot_analytic(robot, q, qd), mdot_differences(robot, q, qd)
        close(Md_a, Md_d, 1e-6, scale, f"{name}: Mdot analytic == finite differences")
        close(Md_a, Md_a.T, 1e-12, scale, f"{name}: Mdot symmetric")
        skew_part_check(Md_a - 2 * C, 1e-10, scale, f"{name}: Mdot (rnea derivatives) - 2C skew")
        skew_part_check(Md_d - 2 * C, 1e-6, scale, f"{name}: Mdot (differences) - 2C skew")
        # C qd is the velocity part of inverse dynamics: rnea(q, qd, 0) - rnea(q, 0, 0)
        zero = np.zeros(n)
        h = armdyn.rnea(robot, q, qd, zero) - armdyn.rnea(robot, q, zero, zero)
        close(C @ qd, h, 1e-10, scale * np.abs(qd).max(), f"{name}: C qd == rnea(q, qd, 0) - g")
        # and Mdot = C + C^T (the Christoffel C's defining property, RBDA/Spong)
        close(C + C.T, Md_a, 1e-10, scale, f"{name}: C + C^T == Mdot")


def test_checks_can_fail():
    """A C with a symmetric error breaks "Mdot - 2C skew"; a C with a skew error K that
    leaves C qd unchanged (K qd = 0) passes both identities (so they alone do not pin C
    down) but not the comparison with the symbolic Christoffel C. A NaN fails ``close``."""
    robot = _bound("planar-3r", 11)
    rng = np.random.default_rng(21)
    q, qd = random_state(rng, 3), random_state(rng, 3)
    C = armdyn.coriolis_matrix(robot, q, qd)
    Md = mdot_analytic(robot, q, qd)
    scale = np.abs(armdyn.crba(robot, q)).max() * np.abs(qd).max()
    E = 1e-3 * scale * np.diag([1.0, -2.0, 0.5])  # symmetric error
    with pytest.raises(AssertionError):
        skew_part_check(Md - 2 * (C + E), 1e-10, scale, "symmetric error")
    a, b = np.cross(qd, [1.0, 0.3, -0.2]), np.cross(qd, [-0.4, 1.0, 0.7])
    K = 1e-3 * scale * (np.outer(a, b) - np.outer(b, a))  # skew, K qd = 0
    close((C + K) @ qd, C @ qd, 1e-12, scale * np.abs(qd).max(), "K qd = 0")
    skew_part_check(Md - 2 * (C + K), 1e-10, scale, "a skew error passes the skew check")
    eom = derive(robot, "lagrange")
    values = {s: v for s, v in zip(list(eom.q) + list(eom.qd), np.concatenate([q, qd]))}
    C_sym = np.array(sp.Matrix(eom.C).xreplace({s: sp.Float(v) for s, v in values.items()}).evalf(), dtype=float)
    close(C_sym, C, 1e-10, scale, "symbolic C == Rust C")
    with pytest.raises(AssertionError):
        close(C_sym, C + K, 1e-10, scale, "symbolic C == Rust C + K")
    with pytest.raises(AssertionError):
        close(C + np.nan, C, 1e-10, scale, "NaN")
    with pytest.raises(AssertionError):
        close(C, C + np.nan, 1e-10, scale, "NaN reference")
    with pytest.raises(AssertionError):
        close(C, C, 1e-10, float("nan"), "NaN scale")
    with pytest.raises(AssertionError):
        close(np.zeros(0), np.zeros(0), 1e-10, 1.0, "no samples")


@pytest.mark.parametrize("name", ["ur5", "iiwa14", "random tree 1", "random chain, frame offsets"])
def test_rust_coriolis_equals_pinocchio(name):
    """The Rust C against Pinocchio's computeCoriolisMatrix (a third implementation)."""
    pytest.importorskip("pinocchio")
    from pinocchio_bridge import PinocchioRobot

    robot = dict(ROBOTS)[name]
    P = PinocchioRobot(robot)
    rng = np.random.default_rng(22)
    for _ in range(4):
        q, qd = random_state(rng, robot.dof), random_state(rng, robot.dof)
        C = armdyn.coriolis_matrix(robot, q, qd)
        scale = np.abs(armdyn.crba(robot, q)).max() * np.abs(qd).max()
        close(C, P.coriolis_matrix(q, qd), 1e-10, scale, f"{name}: C == Pinocchio's")


@pytest.mark.parametrize("name", ["rp-arm", "planar-2r", "planar-3r", "scara", "stanford"])
@pytest.mark.parametrize("method", ["lagrange", "newton-euler"])
def test_symbolic_christoffel_c_equals_rust_c(name, method):
    """The symbolic C (Christoffel symbols of the symbolic M) equals the Rust core's C at
    random points, and the symbolic C qd equals the numeric rnea(q, qd, 0) - g."""
    robot = _bound(name, 11)
    eom = derive(robot, method)
    rng = np.random.default_rng(23)
    samples, n = 5, robot.dof
    q, qd = rng.uniform(-np.pi, np.pi, (2, samples, n))
    values = {s: col for s, col in zip(list(eom.q) + list(eom.qd), np.hstack([q, qd]).T)}
    C_sym = np.moveaxis(dag.evaluate(sp.Matrix(eom.C), values), -1, 0)  # (samples, n, n)
    C_num = armdyn.coriolis_matrix(robot, q, qd)
    assert C_sym.shape == C_num.shape == (samples, n, n)
    zero = np.zeros((samples, n))
    h = armdyn.rnea(robot, q, qd, zero) - armdyn.gravity(robot, q)
    for k in range(samples):
        scale = np.abs(armdyn.crba(robot, q[k])).max() * np.abs(qd[k]).max()
        close(C_sym[k], C_num[k], 1e-10, scale, f"{name} ({method}): symbolic C == Rust C")
        close(
            C_sym[k] @ qd[k],
            h[k],
            1e-10,
            scale * np.abs(qd[k]).max(),
            f"{name} ({method}): symbolic C qd == rnea(q, qd, 0) - g",
        )
