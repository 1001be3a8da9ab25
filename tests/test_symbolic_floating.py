"""The symbolic Newton-Euler of a floating base (armdyn.derive on a root_joint="free-flyer"
robot) against the numeric floating-base RNEA and CRBA of the Rust core (spatial
algebra, RBDA ch. 9: an independent algorithm, itself checked against Pinocchio in
test_floating.py), and against a free body's Newton-Euler equations written by hand.

The symbolic tau keeps gravity as symbols in the base frame (gb = R^T g); at a numeric
state they take R^T g with R the quaternion's rotation, written out here.
"""

from __future__ import annotations

import warnings

import numpy as np
import pytest
import sympy as sp
from optional import example_robot_data_dir

import armdyn
import armdyn.numeric as numeric
from armdyn.cli import main
from armdyn.errors import FloatingBaseError
from armdyn.symbolic import check, dag, derive, prove_agreement
from armdyn.symbolic.newton_euler_floating import BASE_GRAVITY, gravity_in_base

TOL = 1e-10

ONE_BODY = """<robot name="box">
  <link name="body">
    <inertial><origin xyz="0.1 -0.2 0.3"/><mass value="2.5"/>
      <inertia ixx="0.3" iyy="0.4" izz="0.5" ixy="0.01" ixz="0.02" iyz="0.03"/></inertial>
  </link>
</robot>
"""

# a one-joint arm on ONE_BODY
ARM = """  <link name="arm"><inertial><origin xyz="0.2 0 0"/><mass value="1"/>
    <inertia ixx="0.01" iyy="0.02" izz="0.02" ixy="0" ixz="0" iyz="0"/></inertial></link>
  <joint name="q1" type="revolute"><parent link="body"/><child link="arm"/><origin xyz="0.3 0 0"/>
    <axis xyz="0 0 1"/><limit lower="-3" upper="3" effort="1" velocity="1"/></joint>
</robot>
"""

# a base with a branch of three joints (revolute, prismatic, revolute; frames turned and
# offset, a massive link welded on) and a second, one-joint branch with joint friction
CHAIN = """<robot name="rpr">
  <link name="body"><inertial><origin xyz="0.05 0.02 -0.01"/><mass value="4"/>
    <inertia ixx="0.2" iyy="0.3" izz="0.4" ixy="0.01" ixz="0" iyz="0.02"/></inertial></link>
  <link name="upper"><inertial><origin xyz="0.15 0.01 0"/><mass value="1.2"/>
    <inertia ixx="0.01" iyy="0.03" izz="0.03" ixy="0.001" ixz="0" iyz="0"/></inertial></link>
  <link name="slider"><inertial><origin xyz="0 0.02 0.1"/><mass value="0.7"/>
    <inertia ixx="0.02" iyy="0.02" izz="0.005" ixy="0" ixz="0.001" iyz="0"/></inertial></link>
  <link name="hand"><inertial><origin xyz="0.05 0 0.02"/><mass value="0.4"/>
    <inertia ixx="0.002" iyy="0.003" izz="0.003" ixy="0" ixz="0" iyz="0.0005"/></inertial></link>
  <link name="tool"><inertial><origin xyz="0 0 0.03"/><mass value="0.2"/>
    <inertia ixx="0.001" iyy="0.001" izz="0.0005" ixy="0" ixz="0" iyz="0"/></inertial></link>
  <link name="tail"><inertial><origin xyz="-0.1 0 0"/><mass value="0.5"/>
    <inertia ixx="0.001" iyy="0.004" izz="0.004" ixy="0" ixz="0" iyz="0"/></inertial></link>
  <joint name="q1" type="revolute"><parent link="body"/><child link="upper"/>
    <origin xyz="0.2 0.1 0.05" rpy="0.3 -0.2 0.1"/><axis xyz="0 0 1"/>
    <limit lower="-3" upper="3" effort="1" velocity="1"/></joint>
  <joint name="d2" type="prismatic"><parent link="upper"/><child link="slider"/>
    <origin xyz="0.3 0 0" rpy="0 1.5707963267948966 0"/><axis xyz="0 0 1"/>
    <limit lower="-1" upper="1" effort="1" velocity="1"/></joint>
  <joint name="q3" type="revolute"><parent link="slider"/><child link="hand"/>
    <origin xyz="0 0.05 0.2" rpy="-0.4 0 0.7"/><axis xyz="0.6 0 0.8"/>
    <limit lower="-3" upper="3" effort="1" velocity="1"/></joint>
  <joint name="weld" type="fixed"><parent link="hand"/><child link="tool"/>
    <origin xyz="0.1 0 0" rpy="0 0 0.5"/></joint>
  <joint name="q4" type="revolute"><parent link="body"/><child link="tail"/>
    <origin xyz="-0.2 0 0" rpy="0 0 3.0"/><axis xyz="0 1 0"/>
    <limit lower="-3" upper="3" effort="1" velocity="1"/><dynamics damping="0.3" friction="0.2"/></joint>
</robot>
"""


def rotation(quat) -> np.ndarray:
    """R of the unit quaternion (x, y, z, w): base axes in world coordinates."""
    x, y, z, w = quat
    return np.array(
        [
            [1 - 2 * (y * y + z * z), 2 * (x * y - z * w), 2 * (x * z + y * w)],
            [2 * (x * y + z * w), 1 - 2 * (x * x + z * z), 2 * (y * z - x * w)],
            [2 * (x * z - y * w), 2 * (y * z + x * w), 1 - 2 * (x * x + y * y)],
        ]
    )


def close(a, b) -> float:
    """Relative difference; NaN or inf never passes."""
    a, b = np.asarray(a, dtype=float), np.asarray(b, dtype=float)
    assert a.shape == b.shape
    assert np.isfinite(a).all() and np.isfinite(b).all()
    return float(np.max(np.abs(a - b), initial=0.0) / max(1.0, float(np.max(np.abs(b), initial=0.0))))


def load(tmp_path, text: str):
    path = tmp_path / "robot.urdf"
    path.write_text(text)
    return armdyn.load(path, root_joint="free-flyer"), path


def states(robot, rng, count: int):
    """Random (q, v, a): any base pose, joints in [-pi, pi]."""
    for _ in range(count):
        quat = rng.standard_normal(4)
        quat /= np.linalg.norm(quat)
        q = np.concatenate([rng.uniform(-1, 1, 3), quat, rng.uniform(-np.pi, np.pi, robot.dof)])
        v, a = rng.uniform(-2, 2, (2, robot.nv))
        yield q, v, a


def evaluate(eom, matrix, q, v, a) -> np.ndarray:
    """``matrix`` of ``eom`` at the numeric state (gravity R^T g in the base frame)."""
    g_b = rotation(q[3:7]).T @ np.array([float(x) for x in eom.robot.gravity])
    symbols = [*eom.q, *eom.qd, *eom.qdd, *BASE_GRAVITY]
    values = [*q[7:], *v, *a, *g_b]
    return dag.evaluate(matrix, {s: np.array([x]) for s, x in zip(symbols, values)})[..., 0]


def agrees_with_the_core(robot, eom, rng, count: int = 4):
    for q, v, a in states(robot, rng, count):
        assert close(evaluate(eom, eom.tau, q, v, a).ravel(), numeric.rnea(robot, q, v, a)) < TOL
        zero = np.zeros(robot.nv)
        assert close(evaluate(eom, eom.g, q, zero, zero).ravel(), numeric.rnea(robot, q, zero, zero)) < TOL
        assert close(evaluate(eom, eom.bias, q, v, zero).ravel(), numeric.rnea(robot, q, v, zero)) < TOL
    M = evaluate(eom, eom.M, q, v, a)
    assert M.shape == (robot.nv, robot.nv)
    assert close(M, numeric.crba(robot, q)) < TOL and close(M, M.T) < TOL


# ------------------------------------------------------------------ one free body


def test_one_free_body_is_newton_euler_by_hand():
    """COM at the base origin: f = m (vbd + w x v - g_b), n = I wd + w x I w, exactly."""
    m, a, b, c, d, e, f = sp.symbols("m a b c d e f")
    inertia = sp.Matrix([[a, d, e], [d, b, f], [e, f, c]])
    body = armdyn.Link("body", m, [0, 0, 0], inertia)
    robot = armdyn.Robot("body", [body], [], parameters=[m, a, b, c, d, e, f], root_joint="free-flyer")
    eom = derive(robot)
    v, w = sp.Matrix(eom.qd[:3]), sp.Matrix(eom.qd[3:6])
    vd, wd = sp.Matrix(eom.qdd[:3]), sp.Matrix(eom.qdd[3:6])
    g_b = sp.Matrix(list(BASE_GRAVITY))
    force = m * (vd + w.cross(v) - g_b)
    moment = inertia * wd + w.cross(inertia * w)
    assert eom.tau.shape == (6, 1) and eom.qd.shape == eom.qdd.shape == (6, 1)
    assert all(sp.expand(x) == 0 for x in eom.tau - force.col_join(moment))
    # M: the body's spatial inertia; symmetric exactly
    assert eom.M == sp.diag(m, m, m, 0, 0, 0) + sp.zeros(3, 3).row_join(sp.zeros(3, 3)).col_join(
        sp.zeros(3, 3).row_join(inertia)
    )


def test_one_free_body_from_a_urdf_against_the_core(tmp_path):
    robot, _ = load(tmp_path, ONE_BODY)
    assert robot.floating and robot.dof == 0
    eom = derive(robot)
    agrees_with_the_core(robot, eom, np.random.default_rng(0))
    # free fall: no wrench when the base origin accelerates at g (base frame), not turning
    rng = np.random.default_rng(1)
    quat = rng.standard_normal(4)
    quat /= np.linalg.norm(quat)
    q = np.concatenate([[0.3, -0.1, 2.0], quat])
    g_b = rotation(quat).T @ np.array([0.0, 0.0, -9.81])
    acc = np.concatenate([g_b, np.zeros(3)])
    wrench = evaluate(eom, eom.tau, q, np.zeros(6), acc).ravel()
    assert np.isfinite(wrench).all() and np.max(np.abs(wrench)) < 1e-12


def test_gravity_in_base_is_r_transpose_g(tmp_path):
    robot, _ = load(tmp_path, ONE_BODY)
    rng = np.random.default_rng(2)
    for _ in range(3):
        quat = rng.standard_normal(4)
        quat /= np.linalg.norm(quat)
        assert close(gravity_in_base(robot, quat), rotation(quat).T @ np.array([0, 0, -9.81])) < 1e-14


# ------------------------------------------------------------------ chains and a quadruped


def test_a_floating_rpr_tree_against_the_core(tmp_path):
    robot, _ = load(tmp_path, CHAIN)
    assert [j.type for j in robot.movable_joints] == ["revolute", "prismatic", "revolute", "revolute"]
    eom = derive(robot)
    assert eom.tau.shape == (robot.nv, 1) and eom.M.shape == (robot.nv, robot.nv)
    agrees_with_the_core(robot, eom, np.random.default_rng(3))
    # every step is reported, the base's first and last: its outward rows, then the arm's
    names = [(s.stage, s.link, s.name) for s in eom.steps]
    assert names[:6] == [("outward", "body", k) for k in ("omega", "omega_dot", "v_dot", "vc_dot", "F", "N")]
    # then the joint friction of q4 (Fv qd + Fc sign(qd)) as for a fixed base
    assert names[-3:] == [("inward", "body", "f"), ("inward", "body", "n"), ("inward", "", "tau_joint")]
    # the base's last steps are its wrench: tau[0:6]
    assert all(sp.expand(x) == 0 for x in sp.Matrix(eom.tau[:3]) - eom.step("f", "body"))
    assert all(sp.expand(x) == 0 for x in sp.Matrix(eom.tau[3:6]) - eom.step("n", "body"))


def test_solo12_against_the_core():
    urdf = example_robot_data_dir() / "solo_description/robots/solo12.urdf"
    if not urdf.is_file():
        pytest.fail(f"{urdf} is missing (example-robot-data layout changed?)")
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        robot = armdyn.load(urdf, strict=False, root_joint="free-flyer").without_joint_dynamics()
    eom = derive(robot)  # about 1 s for tau, 3 s for M
    assert eom.tau.shape == (18, 1)
    agrees_with_the_core(robot, eom, np.random.default_rng(4), count=2)


# ------------------------------------------------------------------ what is not offered


def test_lagrange_check_and_christoffel_c_are_refused(tmp_path):
    robot, path = load(tmp_path, ONE_BODY)
    with pytest.raises(FloatingBaseError, match="newton-euler") as err:
        derive(robot, "lagrange")
    assert str(path) in str(err.value)
    with pytest.raises(FloatingBaseError, match="floating base"):
        prove_agreement(robot)
    eom = derive(robot)
    with pytest.raises(FloatingBaseError, match="floating base"):
        check(eom)
    with pytest.raises(FloatingBaseError, match="bias"):
        eom.C


def test_cli_derives_the_steps_with_root_joint(tmp_path, capsys):
    _, path = load(tmp_path, ONE_BODY.replace("</robot>", ARM))
    code = main(["derive", str(path), "--root-joint", "free-flyer", "--steps"])
    out = capsys.readouterr()
    assert code == 0
    assert "Newton-Euler only" in out.err and "Lagrange:" not in out.out
    for label in ("ω₀ = ", "v̇₀ = ", "ω₁ = ", "f₁ = ", "f₀ = ", "n₀ = ", "f_bx = ", "n_bz = ", "τ₁ = "):
        assert label in out.out, label
    assert "v̇_b + ω_b × v_b − g_b" in out.out and "ω_bx" in out.out and "g_bz" in out.out
    code = main(["derive", str(path), "--root-joint", "free-flyer", "--method", "lagrange"])
    err = capsys.readouterr().err
    assert code == 2 and "armdyn: error:" in err and "'newton-euler' derives it" in err


def test_reports_name_the_base_rows_and_symbols(tmp_path):
    from armdyn.symbolic.report import derivation_report

    robot, _ = load(tmp_path, ONE_BODY.replace("</robot>", ARM))
    eom = derive(robot)
    latex = derivation_report([eom], "latex")
    for row in (r"f_{b,x} &=", r"n_{b,z} &=", r"\tau_{1} &="):
        assert row in latex, row
    assert r"\dot{v}_{b,x}" in latex and r"\omega_{b,y}" in latex and r"g_{b,z}" in latex
    html = derivation_report([eom], "html")
    assert "wrench on the base" in html and "moment about the base origin on the base" in html
    # the base's symbols typeset with their LaTeX names: g_{b,z}, omega_{b,y}
    assert "<msub><mi>g</mi><mrow><mi>b</mi><mo>,</mo><mi>z</mi></mrow></msub>" in html
    assert "<msub><mi>&#969;</mi><mrow><mi>b</mi><mo>,</mo><mi>y</mi></mrow></msub>" in html
