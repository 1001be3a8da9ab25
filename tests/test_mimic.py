"""Mimic joints (URDF ``<mimic>``): a joint that follows its leader,
``q_m = multiplier * q_leader + offset``, with no degree of freedom of its own.

Second opinions:

* Pinocchio 4.1's own mimic model (``buildModelFromUrdf(path, mimic=True)``): rnea,
  crba, forward dynamics (from its M and h: it has no aba for mimic joints), frames,
  Jacobians, energies;
* the three armdyn engines against each other: numeric (the Rust core on the full tree,
  mapped by G, armdyn.mimic), reference (NumPy, the constraint inside the recursions),
  symbolic Newton-Euler and Lagrange (the constraint inside the derivations);
* the same arm written without ``<mimic>``, its joints driven by hand at
  ``c q_leader + o``, with the torques summed by virtual work, in plain NumPy here;
* identities: rnea = M qdd + h, aba(rnea) = qdd, T = 1/2 qd'M qd, C qd = h - g,
  Mdot - 2C skew (Mdot by finite differences), g = dV/dq and J qd = d(fk)/dt (finite
  differences), batches = loops.

The example-robot-data sweep (test_urdf.py) covers the published grippers.
"""

from __future__ import annotations

import warnings

import numpy as np
import pytest
import sympy as sp

import armdyn
import armdyn.numeric as numeric
import armdyn.reference as reference
from armdyn.errors import ModelError
from armdyn.io.urdf import MasslessWarning, load_urdf
from armdyn.mimic import MimicModel
from armdyn.model import Joint, Link, Mimic, Robot

ENGINES = [numeric, reference]

# A 3-dof arm with four mimic joints: a wrist that follows the elbow (multiplier 1.5,
# offset 0.2), a gripper whose right finger mirrors the left one, and a side link on
# another branch that follows the elbow (-0.7), so the constraint couples two branches.
# Leaders come before their mimics in every depth-first order (Pinocchio needs that).
ARM = """<?xml version="1.0"?>
<robot name="mimic_arm">
  <link name="base"/>
  <joint name="shoulder" type="revolute">
    <parent link="base"/><child link="upper"/><axis xyz="0 0 1"/><limit effort="1" velocity="1" lower="-3" upper="3"/>
    <origin xyz="0 0 0.3"/>
  </joint>
  <link name="upper">
    <inertial><origin xyz="0.2 0 0"/><mass value="2"/>
      <inertia ixx="0.01" iyy="0.05" izz="0.05" ixy="0.001" ixz="0" iyz="0.002"/></inertial>
  </link>
  <joint name="elbow" type="revolute">
    <parent link="upper"/><child link="fore"/><axis xyz="0 1 0"/><limit effort="1" velocity="1" lower="-3" upper="3"/>
    <origin xyz="0.4 0 0" rpy="0.1 0.2 0.3"/>
  </joint>
  <link name="fore">
    <inertial><origin xyz="0.15 0.01 0" rpy="0.3 0 0"/><mass value="1.5"/>
      <inertia ixx="0.008" iyy="0.03" izz="0.03" ixy="0" ixz="0.001" iyz="0"/></inertial>
  </link>
  <joint name="side" type="revolute">
    <parent link="upper"/><child link="side_link"/><axis xyz="0.6 0 0.8"/><limit effort="1" velocity="1" lower="-3" upper="3"/>
    <origin xyz="0.1 0.1 0"/>
    <mimic joint="elbow" multiplier="-0.7"/>
  </joint>
  <link name="side_link">
    <inertial><origin xyz="0 0.1 0"/><mass value="0.4"/>
      <inertia ixx="0.002" iyy="0.001" izz="0.002" ixy="0" ixz="0" iyz="0"/></inertial>
  </link>
  <joint name="wrist" type="revolute">
    <parent link="fore"/><child link="hand"/><axis xyz="1 0 0"/><limit effort="1" velocity="1" lower="-3" upper="3"/>
    <origin xyz="0.3 0 0"/>
    <mimic joint="elbow" multiplier="1.5" offset="0.2"/>
  </joint>
  <link name="hand">
    <inertial><origin xyz="0.05 0 0.01"/><mass value="0.6"/>
      <inertia ixx="0.001" iyy="0.002" izz="0.002" ixy="0" ixz="0" iyz="0"/></inertial>
  </link>
  <joint name="finger_left" type="prismatic">
    <parent link="hand"/><child link="left"/><axis xyz="0 1 0"/><limit effort="1" velocity="1" lower="-3" upper="3"/>
    <origin xyz="0.1 0.02 0"/>
  </joint>
  <link name="left">
    <inertial><origin xyz="0.02 0 0"/><mass value="0.1"/>
      <inertia ixx="0.0001" iyy="0.0001" izz="0.0001" ixy="0" ixz="0" iyz="0"/></inertial>
  </link>
  <joint name="finger_right" type="prismatic">
    <parent link="hand"/><child link="right"/><axis xyz="0 1 0"/><limit effort="1" velocity="1" lower="-3" upper="3"/>
    <origin xyz="0.1 -0.02 0"/>
    <mimic joint="finger_left" multiplier="-1" offset="0.01"/>
  </joint>
  <link name="right">
    <inertial><origin xyz="0.02 0 0"/><mass value="0.12"/>
      <inertia ixx="0.0001" iyy="0.0002" izz="0.0001" ixy="0" ixz="0" iyz="0"/></inertial>
  </link>
  <joint name="tool" type="fixed">
    <parent link="right"/><child link="tip"/><origin xyz="0.04 0 0"/>
    <mimic joint="shoulder"/>
  </joint>
  <link name="tip">
    <inertial><mass value="0.05"/><inertia ixx="1e-5" iyy="1e-5" izz="1e-5" ixy="0" ixz="0" iyz="0"/></inertial>
  </link>
</robot>
"""

#: (mimic joint, leader, multiplier, offset) as written in ARM
MIMICS = [("side", "elbow", -0.7, 0.0), ("wrist", "elbow", 1.5, 0.2), ("finger_right", "finger_left", -1.0, 0.01)]


def states(robot, rng, count):
    for _ in range(count):
        yield (rng.uniform(-1.5, 1.5, robot.dof), rng.uniform(-1, 1, robot.dof), rng.uniform(-1, 1, robot.dof))


@pytest.fixture(scope="module")
def arm():
    return load_urdf(ARM)


# ------------------------------------------------------------------ the model


def test_mimic_joints_are_read_and_add_no_coordinate(arm):
    assert arm.dof == 3 and arm.coordinate_names == ["shoulder", "elbow", "finger_left"]
    assert [j.name for j in arm.mimic_joints] == ["side", "wrist", "finger_right"]
    for name, leader, mult, off in MIMICS:
        k, m, o = arm.follows(name)
        assert (arm.coordinate_names[k], float(m), float(o)) == (leader, mult, off)
        assert arm.coordinate_index(name) is None
    assert arm.follows("tool") is None  # <mimic> on a fixed joint: ignored
    assert next(j for j in arm.joints if j.name == "tool").mimic is None
    wrist = next(j for j in arm.joints if j.name == "wrist")
    assert sp.simplify(arm.joint_coordinate(wrist) - (1.5 * sp.Symbol("elbow") + 0.2)) == 0


def _chain(*mimics):
    """Three revolute joints on one body: b mimics a, c mimics b (as given)."""
    r = sp.Rational
    links = [Link("base"), *(Link(n, 1, [r(1, 10), 0, 0], sp.diag(r(1, 100), r(2, 100), r(2, 100))) for n in "ABC")]
    joints = [
        Joint("a", "revolute", "base", "A"),
        Joint("b", "revolute", "A", "B", xyz=[r(1, 5), 0, 0], mimic=mimics[0]),
        Joint("c", "revolute", "B", "C", xyz=[r(1, 5), 0, 0], axis=[0, 1, 0], mimic=mimics[1]),
    ]
    return Robot("chain", links, joints)


def test_a_chain_of_mimics_is_composed():
    """c = 3 b - 1, b = 2 a + 0.5  =>  c = 6 a + 0.5 by hand; same dynamics as c
    mimicking a directly with those numbers."""
    chained = _chain(Mimic("a", 2, sp.Rational(1, 2)), Mimic("b", 3, -1))
    direct = _chain(Mimic("a", 2, sp.Rational(1, 2)), Mimic("a", 6, sp.Rational(1, 2)))
    assert chained.dof == 1 and chained.follows("c") == (0, 6, sp.Rational(1, 2))
    rng = np.random.default_rng(11)
    for q, qd, qdd in states(chained, rng, 3):
        for engine in ENGINES:
            np.testing.assert_allclose(engine.rnea(chained, q, qd, qdd), engine.rnea(direct, q, qd, qdd), rtol=1e-13)


@pytest.mark.parametrize(
    "mimics, joint, words",
    [
        ((Mimic("b"), Mimic("b")), "joint 'b'", "loop (b -> b)"),
        ((Mimic("c"), Mimic("b")), "joint 'b'", "loop (b -> c -> b)"),
        ((Mimic("a"), Mimic("z")), "joint 'c'", "mimics joint 'z', which does not exist"),
    ],
)
def test_bad_mimics_are_one_clear_error(mimics, joint, words):
    with pytest.raises(ModelError) as info:
        _chain(*mimics)
    assert info.value.element == joint and words in info.value.message


def test_bad_mimic_in_a_file_names_the_file_and_joint(tmp_path):
    path = tmp_path / "arm.urdf"
    path.write_text(ARM.replace('<mimic joint="elbow" multiplier="1.5"', '<mimic joint="elbo" multiplier="1.5"'))
    with pytest.raises(ModelError) as info:
        load_urdf(path)
    assert str(info.value) == f"{path}: joint 'wrist': mimics joint 'elbo', which does not exist"


def test_a_fixed_joint_cannot_be_given_a_mimic():
    with pytest.raises(ModelError, match="joint 'w': a fixed joint cannot mimic"):
        Joint("w", "fixed", "a", "b", mimic=Mimic("x"))


def test_a_leader_moving_nothing_is_not_idle_when_its_mimic_moves_mass():
    """The leader's own link is massless but its mimic moves a mass: M is regular, no
    warning; with the mimic's link massless too, the warning names the leader."""
    xml = ARM.replace('<mass value="0.1"/>', '<mass value="0"/>').replace(
        'ixx="0.0001" iyy="0.0001" izz="0.0001"', 'ixx="0" iyy="0" izz="0"'
    )
    with warnings.catch_warnings():
        warnings.simplefilter("error", MasslessWarning)
        load_urdf(xml)
    xml = (
        xml.replace('<mass value="0.12"/>', '<mass value="0"/>')
        .replace('ixx="0.0001" iyy="0.0002" izz="0.0001"', 'ixx="0" iyy="0" izz="0"')
        .replace(
            '<mass value="0.05"/><inertia ixx="1e-5" iyy="1e-5" izz="1e-5"',
            '<mass value="0"/><inertia ixx="0" iyy="0" izz="0"',
        )
    )
    with pytest.warns(MasslessWarning, match="finger_left"):
        load_urdf(xml)


def test_symbolic_multiplier_binds():
    a, b = sp.symbols("k o")
    robot = _chain(Mimic("a", a, b), Mimic("a", 1, 0))
    robot = Robot(robot.name, robot.links.values(), robot.joints, parameters=[a, b])
    with pytest.raises(armdyn.errors.UnboundParameterError):
        numeric.rnea(robot, [0.1], [0.2], [0.3])
    bound = robot.bind({"k": 2, "o": sp.Rational(1, 2)})
    direct = _chain(Mimic("a", 2, sp.Rational(1, 2)), Mimic("a", 1, 0))
    np.testing.assert_allclose(
        numeric.rnea(bound, [0.1], [0.2], [0.3]), numeric.rnea(direct, [0.1], [0.2], [0.3]), rtol=1e-14
    )


# ------------------------------------------------------------------ Pinocchio


def test_arm_agrees_with_pinocchio_mimic_model(arm):
    pin = pytest.importorskip("pinocchio")
    from pinocchio_bridge import welded_potential_energy
    from test_urdf import compare_with_pinocchio, has_mimic, pin_configuration

    model = pin.buildModelFromXML(ARM, mimic=True)
    assert has_mimic(model) and model.nv == 3
    assert compare_with_pinocchio(arm, model, np.random.default_rng(12), states=4)
    # energies, frames and Jacobians with Pinocchio's mimic model
    data = model.createData()
    rng = np.random.default_rng(13)
    for q, qd, _ in states(arm, rng, 3):
        qp, perm = pin_configuration(model, arm, q)
        pin.forwardKinematics(model, data, qp, qd[perm])
        pin.updateFramePlacements(model, data)
        # Pinocchio 4.1 has no energies with mimic joints: from its body velocities and
        # placements (bodies welded to the base add a constant, as pinocchio_bridge says)
        T = sum(0.5 * data.v[j].np @ (model.inertias[j] * data.v[j]).np for j in range(1, model.njoints))
        V = welded_potential_energy(arm) - sum(
            model.inertias[j].mass * model.gravity.linear @ (data.oMi[j] * model.inertias[j].lever)
            for j in range(1, model.njoints)
        )
        pin.computeJointJacobians(model, data, qp)
        for engine in ENGINES:
            np.testing.assert_allclose(engine.kinetic_energy(arm, q, qd), T, rtol=1e-12)
            np.testing.assert_allclose(engine.potential_energy(arm, q), V, rtol=1e-12, atol=1e-12)
            poses = engine.forward_kinematics(arm, q)
            for i, name in enumerate(arm.links):
                fid = model.getFrameId(name, pin.BODY)
                np.testing.assert_allclose(poses[i], data.oMf[fid].homogeneous, atol=1e-12, err_msg=name)
                J = pin.getFrameJacobian(model, data, fid, pin.LOCAL_WORLD_ALIGNED)
                ours = engine.jacobian(arm, q, name)[:, perm]
                np.testing.assert_allclose(ours, J, atol=1e-12, err_msg=f"{engine.__name__} jacobian {name}")


# ------------------------------------------------------------------ by hand


def test_against_the_unconstrained_arm_driven_by_hand(arm):
    """The arm without <mimic> (six free joints), its mimic joints driven at
    ``c q_leader + o``; the torque of the constrained arm is, by virtual work, each
    leader's torque plus c times its mimics'. M likewise (sums of blocks)."""
    free = load_urdf("\n".join(line for line in ARM.splitlines() if "<mimic" not in line))
    assert free.dof == 6
    rng = np.random.default_rng(14)
    for q, qd, qdd in states(arm, rng, 4):
        full = {name: (q[k], qd[k], qdd[k]) for k, name in enumerate(arm.coordinate_names)}
        for name, leader, c, o in MIMICS:
            ql, qdl, qddl = full[leader]
            full[name] = (c * ql + o, c * qdl, c * qddl)
        Q, QD, QDD = (np.array([full[n][i] for n in free.coordinate_names]) for i in range(3))
        tau_full = dict(zip(free.coordinate_names, reference.rnea(free, Q, QD, QDD)))
        M_full = reference.crba(free, Q)
        expected = {n: tau_full[n] for n in arm.coordinate_names}
        weights = np.zeros((6, 3))  # column k: d(full coordinates)/d q_k
        for k, name in enumerate(arm.coordinate_names):
            weights[free.coordinate_names.index(name), k] = 1
        for name, leader, c, _ in MIMICS:
            expected[leader] += c * tau_full[name]
            weights[free.coordinate_names.index(name), arm.coordinate_names.index(leader)] = c
        expected = np.array([expected[n] for n in arm.coordinate_names])
        M = np.einsum("ai,ab,bj->ij", weights, M_full, weights)
        for engine in ENGINES:
            np.testing.assert_allclose(engine.rnea(arm, q, qd, qdd), expected, rtol=1e-12, atol=1e-12)
            np.testing.assert_allclose(engine.crba(arm, q), M, rtol=1e-12, atol=1e-14)


# ------------------------------------------------------------------ identities


def test_identities(arm):
    rng = np.random.default_rng(15)
    eps = 1e-6
    for q, qd, qdd in states(arm, rng, 3):
        M = numeric.crba(arm, q)
        h, g = numeric.bias(arm, q, qd), numeric.gravity(arm, q)
        C = numeric.coriolis_matrix(arm, q, qd)
        assert np.all(np.isfinite(M)) and np.all(np.isfinite(C))
        np.testing.assert_allclose(numeric.rnea(arm, q, qd, qdd), M @ qdd + h, rtol=1e-12, atol=1e-12)
        np.testing.assert_allclose(numeric.aba(arm, q, qd, numeric.rnea(arm, q, qd, qdd)), qdd, rtol=1e-10, atol=1e-12)
        np.testing.assert_allclose(M, M.T, atol=1e-15)
        assert np.linalg.eigvalsh(M).min() > 0
        np.testing.assert_allclose(numeric.kinetic_energy(arm, q, qd), 0.5 * qd @ M @ qd, rtol=1e-12)
        np.testing.assert_allclose(C @ qd, h - g, rtol=1e-10, atol=1e-12)
        np.testing.assert_allclose(C, reference.coriolis_matrix(arm, q, qd), rtol=1e-10, atol=1e-12)
        # Mdot - 2C skew, Mdot by central differences along qd
        Mdot = (numeric.crba(arm, q + eps * qd) - numeric.crba(arm, q - eps * qd)) / (2 * eps)
        N = Mdot - 2 * C
        np.testing.assert_allclose(N, -N.T, atol=1e-8)
        # g = dV/dq and J qd = d/dt of every link's origin and orientation
        dV = [
            (numeric.potential_energy(arm, q + eps * e) - numeric.potential_energy(arm, q - eps * e)) / (2 * eps)
            for e in np.eye(arm.dof)
        ]
        np.testing.assert_allclose(dV, g, rtol=1e-7, atol=1e-8)
        X1, X0 = numeric.forward_kinematics(arm, q + eps * qd), numeric.forward_kinematics(arm, q - eps * qd)
        for i, name in enumerate(arm.links):
            v = numeric.jacobian(arm, q, name) @ qd
            np.testing.assert_allclose(v[:3], (X1[i][:3, 3] - X0[i][:3, 3]) / (2 * eps), atol=1e-8)
            Rdot = (X1[i][:3, :3] - X0[i][:3, :3]) / (2 * eps)
            W = Rdot @ numeric.forward_kinematics(arm, q)[i][:3, :3].T  # skew(w)
            np.testing.assert_allclose(v[3:], [W[2, 1], W[0, 2], W[1, 0]], atol=1e-8)


def test_batches_equal_loops(arm):
    rng = np.random.default_rng(16)
    Q, QD, QDD = (rng.uniform(-1, 1, (300, arm.dof)) for _ in range(3))
    tau = numeric.rnea(arm, Q, QD, QDD, threads=2)
    assert tau.shape == (300, 3)
    for r in (0, 137, 299):
        np.testing.assert_array_equal(tau[r], numeric.rnea(arm, Q[r], QD[r], QDD[r]))
        np.testing.assert_array_equal(numeric.crba(arm, Q)[r], numeric.crba(arm, Q[r]))
        np.testing.assert_array_equal(numeric.aba(arm, Q, QD, tau)[r], numeric.aba(arm, Q[r], QD[r], tau[r]))
        np.testing.assert_array_equal(numeric.coriolis_matrix(arm, Q, QD)[r], numeric.coriolis_matrix(arm, Q[r], QD[r]))
        np.testing.assert_array_equal(numeric.jacobian(arm, Q, "hand")[r], numeric.jacobian(arm, Q[r], "hand"))
        np.testing.assert_array_equal(numeric.kinetic_energy(arm, Q, QD)[r], numeric.kinetic_energy(arm, Q[r], QD[r]))
    np.testing.assert_allclose(numeric.aba(arm, Q, QD, tau), QDD, rtol=1e-9, atol=1e-11)


def test_compiled_model_and_bad_input(arm):
    model = numeric.compile_model(arm)
    assert isinstance(model, MimicModel) and numeric.compile_model(model) is model
    assert model.dof == 3 and model.full.dof == 6 and model.coordinate_names == arm.coordinate_names
    free = load_urdf("\n".join(line for line in ARM.splitlines() if "<mimic" not in line))
    assert isinstance(numeric.compile_model(free), numeric.NumericModel)  # no mimic: the Rust model itself
    q = np.zeros(3)
    with pytest.raises(ValueError, match=r"qd: expected shape \(3,\)"):
        numeric.rnea(arm, q, np.zeros(6), q)
    with pytest.raises(ValueError, match=r"qdd contains NaN or inf \(at qdd\[1\]\)"):
        numeric.rnea(arm, q, q, [0, np.nan, 0])
    with pytest.raises(ValueError, match="q: expected real numbers"):
        numeric.crba(arm, q + 1j)
    with pytest.raises(ValueError, match="does not match"):
        numeric.bias(arm, np.zeros((2, 3)), np.zeros((3, 3)))
    with pytest.raises(ValueError, match="link"):
        numeric.jacobian(arm, q, "nowhere")


# ------------------------------------------------------------------ symbolic


SMALL = """<robot name="small">
  <link name="base"/>
  <joint name="q1" type="revolute"><parent link="base"/><child link="a"/><axis xyz="0 0 1"/></joint>
  <link name="a"><inertial><origin xyz="0.5 0 0"/><mass value="2"/>
    <inertia ixx="0.1" iyy="0.2" izz="0.3" ixy="0" ixz="0" iyz="0"/></inertial></link>
  <joint name="m1" type="revolute"><parent link="a"/><child link="b"/><axis xyz="0 1 0"/>
    <origin xyz="1 0 0"/><mimic joint="q1" multiplier="2" offset="0.5"/></joint>
  <link name="b"><inertial><origin xyz="0.25 0 0"/><mass value="1"/>
    <inertia ixx="0.05" iyy="0.1" izz="0.1" ixy="0" ixz="0" iyz="0"/></inertial></link>
  <joint name="d2" type="prismatic"><parent link="a"/><child link="c"/><axis xyz="1 0 0"/></joint>
  <link name="c"><inertial><mass value="0.5"/>
    <inertia ixx="0.01" iyy="0.01" izz="0.01" ixy="0" ixz="0" iyz="0"/></inertial></link>
  <joint name="m2" type="prismatic"><parent link="c"/><child link="d"/><axis xyz="0 0 1"/>
    <mimic joint="d2" multiplier="-1"/></joint>
  <link name="d"><inertial><origin xyz="0 0.1 0"/><mass value="0.3"/>
    <inertia ixx="0.01" iyy="0.01" izz="0.01" ixy="0" ixz="0" iyz="0"/></inertial></link>
</robot>
"""


def test_symbolic_newton_euler_and_lagrange_agree_with_mimic_joints():
    robot = load_urdf(SMALL)
    assert robot.dof == 2
    ne, lg = armdyn.derive(robot, "newton-euler"), armdyn.derive(robot, "lagrange")
    report = armdyn.symbolic.agreement.check(ne, lg, exact=False, samples=10)
    assert report, report.text()
    # the mimic joints' coordinates and rates are the multiplier times the leader's
    q1, d2 = robot.q
    assert sp.Symbol("m1") not in ne.tau.free_symbols | lg.tau.free_symbols
    assert ne.tau.free_symbols >= {q1, d2, *robot.qd, *robot.qdd}
    steps = {(s.link, s.name) for s in ne.steps}
    assert ("b", "tau_mimic") in steps and ("d", "tau_mimic") in steps


def test_symbolic_equals_numeric_with_mimic_joints():
    robot = load_urdf(SMALL)
    eom = armdyn.derive(robot, "newton-euler")
    lg = armdyn.derive(robot, "lagrange")
    syms = list(robot.q) + list(robot.qd) + list(robot.qdd)
    tau_ne = sp.lambdify(syms, eom.tau, "numpy")
    tau_lg = sp.lambdify(syms, lg.tau, "numpy")
    M_ne = sp.lambdify(list(robot.q), eom.M, "numpy")
    rng = np.random.default_rng(17)
    for q, qd, qdd in states(robot, rng, 5):
        args = [*q, *qd, *qdd]
        for engine in ENGINES:
            ours = engine.rnea(robot, q, qd, qdd)
            assert np.all(np.isfinite(ours))
            np.testing.assert_allclose(np.ravel(tau_ne(*args)), ours, rtol=1e-12, atol=1e-12)
            np.testing.assert_allclose(np.ravel(tau_lg(*args)), ours, rtol=1e-12, atol=1e-12)
            np.testing.assert_allclose(np.array(M_ne(*q), dtype=float), engine.crba(robot, q), rtol=1e-12, atol=1e-12)


def test_newton_euler_steps_show_the_mimic_rates():
    """Link b turns about its y axis at 2 q1_dot on top of link a's turn: omega_b =
    R^T (0, 0, q1_dot) + (0, 2 q1_dot, 0) with R = Rot(y, 2 q1 + 1/2), by hand."""
    robot = load_urdf(SMALL)
    eom = armdyn.derive(robot, "newton-euler")
    step = next(s for s in eom.steps if s.link == "b" and s.name == "omega")
    th, w = robot.q[0], robot.qd[0]
    a = 2 * th + 0.5
    R = sp.Matrix([[sp.cos(a), 0, sp.sin(a)], [0, 1, 0], [-sp.sin(a), 0, sp.cos(a)]])
    expected = R.T * sp.Matrix([0, 0, w]) + sp.Matrix([0, 2 * w, 0])
    difference = sp.lambdify([th, w], step.value - expected, "numpy")
    for x, y in np.random.default_rng(18).uniform(-2, 2, (5, 2)):
        np.testing.assert_allclose(np.array(difference(x, y), dtype=float), 0, atol=1e-14)
    from armdyn.symbolic.report import derivation_report

    text = derivation_report([eom], steps=True)
    assert "tau_mimic" in text and "mimic joint 'm1'" in text


def test_prove_agreement_picks_numeric_checks_for_mimic_angles():
    """sin(2 q1 + 0.5) is no polynomial in sin q1, cos q1, so the default check compares
    at random points (and passes); mimics of +-q_leader stay exact."""
    report = armdyn.prove_agreement(load_urdf(SMALL))
    assert report, report.text()
    assert all(r.how.startswith("numeric") for r in report.results)
    report = armdyn.prove_agreement(_chain(Mimic("a", 2, sp.Rational(1, 2)), Mimic("a", 1, 0)))
    assert report, report.text()
    assert all(r.how.startswith("numeric") for r in report.results)
    mirror = _chain(Mimic("a", -1, 0), Mimic("b", 1, 0))  # exact numbers (URDF floats defeat exact checks)
    report = armdyn.prove_agreement(mirror)
    assert report, report.text()
    assert [r.how for r in report.results] == ["exact"] * len(report.results)


def test_show_table_says_whom_mimic_joints_follow(arm):
    from armdyn.show import table

    text = table(arm)
    assert "3 dof" in text
    assert "mimic: wrist = 1.5 * elbow + 0.2" in text and "mimic: finger_right = -1 * finger_left + 0.01" in text
    assert "mimic: side = -0.7 * elbow\n" in text + "\n"


@pytest.mark.filterwarnings("ignore:overflow encountered:RuntimeWarning")  # NumPy's, on the way to the error
def test_overflowing_mimic_coordinate_is_a_clear_error():
    robot = _chain(Mimic("a", sp.Float(1e308), 0), Mimic("a", 1, 0))
    with pytest.raises(ValueError, match="mimic joint's coordinate .* overflows"):
        numeric.rnea(robot, [10.0], [0.0], [0.0])
    assert np.all(np.isfinite(numeric.rnea(robot, [1e-300], [0.0], [0.0])))
