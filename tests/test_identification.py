"""Regressor and base parameters (armdyn.identification, armdyn.numeric.regressor).

Second opinions:
* ``Y * pi`` == the Newton-Euler and the Lagrange torques, exactly (sin/cos polynomial
  reduction) on the small arms, at random states on the 6- and 7-dof ones against the
  Rust rnea and the NumPy reference;
* the Rust regressor == the symbolic one evaluated (different algorithms: spatial
  algebra vs Craig's recursion written linear in the parameters), and == Pinocchio's
  computeJointTorqueRegressor on the inertial columns;
* the number of base parameters == the numeric rank (SVD, floats) of the Rust regressor
  stacked over random states, on every bundled arm, with and without joint terms;
  PUMA 560: 36 and 52; hand-derived grouping of the planar 2R arm;
* identification: torques simulated with noise from known parameters give back beta.
"""

from __future__ import annotations

import warnings

import numpy as np
import pytest
import sympy as sp
from test_joint_dynamics import BUNDLED, numeric_arm, states, with_terms

import armdyn
from armdyn import numeric as num
from armdyn import reference as ref
from armdyn.identification import (
    base_parameters,
    exact_rank,
    regressor,
    symbolic_inertias,
    with_symbolic_joint_terms,
)
from armdyn.symbolic import dag
from armdyn.symbolic.agreement import trig_reduce

SMALL = ["rp-arm", "planar-2r", "planar-3r"]
BIG = [n for n in BUNDLED if n not in SMALL]


def floats(matrix) -> np.ndarray:
    return np.array([[float(x) for x in row] for row in matrix.tolist()], dtype=float)


def evaluate(Y: sp.Matrix, robot, q, qd, qdd) -> np.ndarray:
    values = {
        s: np.array([v])
        for s, v in zip(list(robot.q) + list(robot.qd) + list(robot.qdd), list(q) + list(qd) + list(qdd))
    }
    return dag.evaluate(Y, values)[:, :, 0]


# ------------------------------------------------------------------ the regressor


@pytest.mark.parametrize("name", SMALL)
def test_regressor_exact_on_small_arms(name):
    robot = with_symbolic_joint_terms(armdyn.load(name), ("armature", "damping", "friction", "torque_offset"))
    reg = regressor(robot)
    n = robot.dof
    assert reg.Y.shape == (n, len(reg.names)) and reg.pi.shape == (len(reg.names), 1)
    assert reg.names[:10] == ["M1", "MX1", "MY1", "MZ1", "XX1", "XY1", "YY1", "XZ1", "YZ1", "ZZ1"]
    assert reg.names[-4:] == [f"IA{n}", f"FV{n}", f"FC{n}", f"OFF{n}"] or robot.joints[-1].type == "fixed"
    for method in ("newton-euler", "lagrange"):
        tau = armdyn.derive(robot, method).tau
        assert all(trig_reduce(e, robot.q) == 0 for e in reg.Y * reg.pi - tau), method


def test_regressor_values_are_standard_parameters():
    """pi of the planar 2R arm against its hand-written standard parameters."""
    robot = armdyn.load("planar-2r")
    reg = regressor(robot)
    pi = dict(zip(reg.names, reg.pi))
    link = robot.links["link1"]
    m, c = link.mass, link.com
    assert pi["M1"] == m and pi["MX1"] == m * c[0]
    # inertia about the origin: I_c + m (c.c - c c^T), its zz entry is Izz_c + m (cx^2 + cy^2)
    assert sp.expand(pi["ZZ1"] - (link.inertia[2, 2] + m * (c[0] ** 2 + c[1] ** 2))) == 0


@pytest.mark.parametrize("name", BIG)
def test_regressor_numeric_on_big_arms(name):
    robot = with_terms(numeric_arm(name))
    reg = regressor(robot)
    pi = floats(reg.pi).ravel()
    assert np.isfinite(pi).all()
    rng = np.random.default_rng(21)
    count = 0
    for q, qd, qdd in states(robot, rng):
        Y = evaluate(reg.Y, robot, q, qd, qdd)
        tau = num.rnea(robot, q, qd, qdd)
        scale = max(1.0, np.abs(tau).max())
        np.testing.assert_allclose(Y @ pi, tau, rtol=0, atol=1e-10 * scale)
        np.testing.assert_allclose(Y @ pi, ref.rnea(robot, q, qd, qdd), rtol=0, atol=1e-10 * scale)
        count += 1
    assert count == 4


@pytest.mark.parametrize("name", BUNDLED)
def test_numeric_regressor(name):
    robot = with_terms(numeric_arm(name))
    reg = regressor(robot)
    pi = floats(reg.pi).ravel()
    rng = np.random.default_rng(22)
    cases = states(robot, rng)
    for q, qd, qdd in cases:
        Y = num.regressor(robot, q, qd, qdd)
        assert Y.shape == (robot.dof, len(reg.names))
        tau = num.rnea(robot, q, qd, qdd)
        scale = max(1.0, np.abs(tau).max())
        np.testing.assert_allclose(Y @ pi, tau, rtol=0, atol=1e-11 * scale)
        sym = evaluate(reg.Y, robot, q, qd, qdd)
        np.testing.assert_allclose(Y, sym, rtol=0, atol=1e-11 * max(1.0, np.abs(sym).max()))
    Q, QD, QDD = (np.array([c[i] for c in cases]) for i in range(3))
    batch = num.regressor(robot, Q, QD, QDD, threads=2)
    np.testing.assert_array_equal(batch, np.array([num.regressor(robot, *c) for c in cases]))
    full = num.regressor(robot, Q[0], QD[0], QDD[0], columns="all")
    assert full.shape == (robot.dof, 10 * len(robot.joints) + 4 * robot.dof)


def test_numeric_regressor_bad_input():
    robot = numeric_arm("ur5")
    with pytest.raises(ValueError, match="qd"):
        num.regressor(robot, np.zeros(6), np.zeros(5), np.zeros(6))
    with pytest.raises(ValueError, match="NaN"):
        num.regressor(robot, np.zeros(6), np.zeros(6), np.full(6, np.nan))
    with pytest.raises(ValueError, match="columns"):
        num.regressor(robot, np.zeros(6), np.zeros(6), np.zeros(6), columns="some")


@pytest.mark.parametrize("name", ["puma560", "ur5", "panda", "iiwa14", "stanford", "scara"])
def test_numeric_regressor_matches_pinocchio(name):
    pin = pytest.importorskip("pinocchio")
    from pinocchio_bridge import PinocchioRobot

    robot = numeric_arm(name)
    P = PinocchioRobot(robot)
    rng = np.random.default_rng(23)
    # Pinocchio's joint j carries armdyn's link of the j-th movable joint (bridge) plus the
    # links welded to it: compare the blocks of the movable links
    blocks = {j.name: 10 * k for k, j in enumerate(robot.joints) if j.movable}
    checked = 0
    for q, qd, qdd in states(robot, rng, 2):
        ours = num.regressor(robot, q, qd, qdd)
        theirs = pin.computeJointTorqueRegressor(P.model, P.data, P._p(q), P._p(qd), P._p(qdd))
        theirs = np.asarray(theirs)[P.inv]  # rows in armdyn's order
        for jid in range(1, P.model.njoints):
            name_j = P.model.names[jid]
            a = ours[:, blocks[name_j] : blocks[name_j] + 10]
            b = theirs[:, 10 * (jid - 1) : 10 * jid]
            if not any(
                j.parent == robot.movable_joints[robot.coordinate_names.index(name_j)].child and not j.movable
                for j in robot.joints
            ):
                np.testing.assert_allclose(a, b, rtol=0, atol=1e-11 * max(1.0, np.abs(b).max()))
                checked += 1
        pin_pi = np.concatenate([P.model.inertias[j].toDynamicParameters() for j in range(1, P.model.njoints)])
        np.testing.assert_allclose(theirs @ pin_pi, num.rnea(robot, q, qd, qdd), rtol=1e-11, atol=1e-11)
    assert checked >= 2 * (robot.dof - 1)


# ------------------------------------------------------------------ base parameters


def numeric_rank(robot, states_count=40, seed=31) -> int:
    """Rank of the Rust regressor stacked over random states (SVD, floats)."""
    rng = np.random.default_rng(seed)
    n = robot.dof
    Q, QD, QDD = (rng.uniform(-np.pi, np.pi, (states_count, n)) for _ in range(3))
    W = num.regressor(robot, Q, QD, QDD).reshape(states_count * n, -1)
    norms = np.linalg.norm(W, axis=0)
    W = W[:, norms > 1e-9 * norms.max()]  # zero columns (round-off only) carry no rank
    W = W / np.linalg.norm(W, axis=0)  # column scaling: masses vs inertias
    s = np.linalg.svd(W, compute_uv=False)
    return int(np.sum(s > s[0] * 1e-9))


@pytest.mark.parametrize("terms", [False, True], ids=["rigid", "friction+rotor"])
@pytest.mark.parametrize("name", BUNDLED)
def test_base_parameter_count_equals_numeric_rank(name, terms):
    robot = numeric_arm(name)
    joint_terms = ("armature", "damping", "friction") if terms else ()
    symbolic = symbolic_inertias(robot)
    if terms:
        symbolic = with_symbolic_joint_terms(symbolic, joint_terms)
    base = base_parameters(symbolic)
    numeric = with_terms(robot, terms=joint_terms) if terms else robot
    B = len(base.names)
    assert (
        B
        == numeric_rank(numeric)
        == exact_rank(base.regressor.Y, state_symbols=list(robot.q) + list(robot.qd) + list(robot.qdd))
    )
    assert base.Y.shape == (robot.dof, B) and len(base.beta) == B
    # zero columns of the numeric regressor are the unidentifiable parameters
    rng = np.random.default_rng(32)
    W = np.concatenate([num.regressor(numeric, *s) for s in states(robot, rng)])
    zero = [nm for nm, col in zip(base.regressor.names, W.T) if np.all(np.abs(col) < 1e-12)]
    assert zero == base.unidentifiable


def test_puma560_36_and_52():
    robot = symbolic_inertias(numeric_arm("puma560"))
    base = base_parameters(robot)
    assert len(base.names) == 36
    full = base_parameters(with_symbolic_joint_terms(robot))
    assert len(full.names) == 52  # 36 + 6 Fv + 6 Fc + 4 Ia
    # IA1 joins ZZ1R (joint 1's axis is fixed in space) and IA2 joins ZZ2R (link 2's
    # rotation about its own axis is seen only by joint 2 once grouped): 4 Ia left
    by_name = dict(zip(full.names, full.beta))
    IA1, IA2, ZZ1, ZZ2 = sp.symbols("IA1 IA2 ZZ1 ZZ2")
    assert by_name["ZZ1R"].coeff(IA1) == 1 and by_name["ZZ1R"].coeff(ZZ1) == 1
    assert by_name["ZZ2R"].coeff(IA2) == 1 and by_name["ZZ2R"].coeff(ZZ2) == 1
    assert [n for n in full.names if n.startswith("IA")] == ["IA3", "IA4", "IA5", "IA6"]
    assert sum(n.startswith(("FV", "FC")) for n in full.names) == 12


def test_planar_2r_grouping_by_hand():
    """Khalil's rules by hand for the planar elbow: joint 2 at distance l1 along x1 with a
    parallel axis gives MX1R = MX1 + l1 M2, ZZ1R = ZZ1 + l1^2 M2; the rest of link 1 and
    MZ2 (and what only turns about z) have no effect; M2 acts only through the groups."""
    robot = armdyn.load("planar-2r")
    base = base_parameters(robot)
    s = {n: sp.Symbol(n) for n in ("MX1", "MY1", "ZZ1", "M2", "MX2", "MY2", "ZZ2")}
    l1 = robot.parameters["l1"]
    expected = {
        "MX1R": s["MX1"] + l1 * s["M2"],
        "MY1": s["MY1"],
        "ZZ1R": s["ZZ1"] + l1**2 * s["M2"],
        "MX2": s["MX2"],
        "MY2": s["MY2"],
        "ZZ2": s["ZZ2"],
    }
    assert dict(zip(base.names, base.beta)) == expected
    assert not any(isinstance(a, sp.Float) for b in base.beta for a in sp.preorder_traversal(b))
    assert {"M1", "XX1", "XX2"} <= set(base.unidentifiable) and "M2" not in base.unidentifiable


@pytest.mark.parametrize("name", SMALL + ["scara"])
def test_base_regressor_identity_exact(name):
    robot = with_symbolic_joint_terms(armdyn.load(name))
    base = base_parameters(robot)
    reg = base.regressor
    assert base.Y == reg.Y[:, base.columns]
    diff = base.Y * base.values - reg.Y * reg.pi
    assert all(trig_reduce(e, robot.q) == 0 for e in diff)


@pytest.mark.parametrize("name", ["puma560", "iiwa14", "stanford"])
def test_base_regressor_identity_numeric(name):
    robot = with_terms(numeric_arm(name), terms=("armature", "damping", "friction"))
    base = base_parameters(robot)
    beta = floats(base.values).ravel()
    rng = np.random.default_rng(33)
    for q, qd, qdd in states(robot, rng):
        Yb = num.regressor(robot, q, qd, qdd)[:, base.columns]
        tau = num.rnea(robot, q, qd, qdd)
        np.testing.assert_allclose(Yb @ beta, tau, rtol=0, atol=1e-10 * max(1.0, np.abs(tau).max()))


def test_identification_recovers_beta():
    """The README's example: PUMA 560 with friction and rotor inertia, torques simulated
    along random states with noise, base parameters by least squares."""
    robot = with_terms(numeric_arm("puma560"), terms=("armature", "damping", "friction"))
    base = base_parameters(robot)
    beta = floats(base.values).ravel()
    rng = np.random.default_rng(34)
    N = 400
    Q, QD, QDD = rng.uniform(-np.pi, np.pi, (N, 6)), rng.uniform(-2, 2, (N, 6)), rng.uniform(-4, 4, (N, 6))
    tau = num.rnea(robot, Q, QD, QDD) + rng.normal(0, 0.01, (N, 6))
    W = num.regressor(robot, Q, QD, QDD)[:, :, base.columns].reshape(N * 6, -1)
    estimate, *_ = np.linalg.lstsq(W, tau.ravel(), rcond=None)
    assert np.isfinite(estimate).all()
    # relative error small where the data excite the parameter enough
    np.testing.assert_allclose(estimate, beta, rtol=0, atol=5e-3 * max(1.0, np.abs(beta).max()))


def test_base_parameters_symbolic_geometry():
    """rp-arm keeps its symbolic length l1 and gravity g: beta is exact, count equals the
    rank at random rational geometry."""
    robot = armdyn.load("rp-arm")
    base = base_parameters(with_symbolic_joint_terms(robot))
    assert len(base.names) == exact_rank(
        base.regressor.Y, state_symbols=list(robot.q) + list(robot.qd) + list(robot.qdd)
    )
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        bound = robot.bind({"l1": 0.7, "g": 9.81, "m1": 1.0, "m2": 2.0})
    assert len(base.names) == numeric_rank(with_terms(bound, terms=("armature", "damping", "friction")))


def test_scara_geometry_dependent_grouping():
    """SCARA (standard DH, alpha2 = pi): link 3 only slides along the vertical relative to
    link 2, its frame origin at p = (a2, 0, z) in link 2's frame, axes x3 = x2, y3 = -y2.
    By hand, moving its first moment h3 and inertia onto link 2 (parallel axis in
    first-moment form, I' = I + 2 (p.h) 1 - p h^T - h p^T + ...): MX2R = MX2 + MX3,
    MY2R = MY2 - MY3 and ZZ2R = ZZ2 + ZZ3 + 2 (a2 MX3 + z MZ3) - 2 z MZ3 = ZZ2 + ZZ3 + 2 a2 MX3,
    exact in the symbol a2 (a grouping Khalil's general rules alone do not make)."""
    robot = armdyn.load("scara")
    base = base_parameters(robot)
    a2 = robot.parameters["a2"]
    MX2, MX3, ZZ2, ZZ3 = sp.symbols("MX2 MX3 ZZ2 ZZ3")
    by_name = dict(zip(base.names, base.beta))
    assert sp.expand(by_name["MX2R"] - (MX2 + MX3)) == 0
    assert sp.expand(by_name["ZZ2R"] - (ZZ2 + ZZ3 + 2 * a2 * MX3)) == 0
    assert sp.expand(by_name["MY2R"] - (sp.Symbol("MY2") - sp.Symbol("MY3"))) == 0
