"""The symbolic Newton-Euler derivation of planar and free joints, and of ball joints under
a floating base (newton_euler_spherical.py, newton_euler_floating.py), against second
opinions at random states:

* a body on a planar joint, its equations written here by hand (Newton's and Euler's laws
  in the body frame for the velocity in the body's own axes);
* armdyn.numeric's rnea and crba (the Rust core's spatial algebra);
* Pinocchio's JointModelPlanar, JointModelFreeFlyer and JointModelSpherical, the models
  built by hand here (no armdyn code).

The pose symbols (rotation entries, cos/sin, positions) and the floating base's gravity
in its frame take their values from the numeric configuration (``state_values``).
"""

from __future__ import annotations

import numpy as np
import pytest
import sympy as sp
from optional import needs_pinocchio, pin
from test_symbolic_spherical import KNEE_AXIS, OFFSET_P, OFFSET_R, rot_x, rot_z

import armdyn
import armdyn.numeric as numeric
from armdyn.model import Joint, Link, Robot
from armdyn.symbolic import dag
from armdyn.symbolic.newton_euler_spherical import (
    SphericalEquationsOfMotion,
    configuration_symbols,
    note,
    position_symbols,
    state_values,
)
from armdyn.symbolic.report import derivation_report

TOL = 1e-9
G = 9.81

#: chains: (joint name, type, xyz, placement rotation, axis, (mass, com, inertia about it)),
#: the first joint's parent the root link ``base`` (massive under a floating base)
BODY = (2.0, np.array([0.1, -0.05, 0.2]), np.array([[0.15, 0.01, 0.0], [0.01, 0.2, 0.02], [0.0, 0.02, 0.25]]))
ARM = (1.2, np.array([0.15, 0.02, 0.0]), np.array([[0.01, 0.0, 0.001], [0.0, 0.03, 0.0], [0.001, 0.0, 0.03]]))
HAND = (0.5, np.array([0.0, 0.02, -0.05]), np.diag([0.002, 0.003, 0.002]))
BASE = (4.0, np.array([0.05, 0.02, -0.01]), np.diag([0.2, 0.3, 0.4]))
CHAINS = {
    "planar-base arm": [  # a mobile base in the floor's plane, then an arm
        ("cart", "planar", [0.1, -0.2, 0.3], rot_z(0.4), None, BODY),
        ("shoulder", "revolute", [0.2, 0.0, 0.1], np.eye(3), KNEE_AXIS, ARM),
    ],
    "free body mid-tree": [  # a free body hung under a turning link, a hand under it
        ("shoulder", "revolute", [0, 0, 0.4], rot_x(0.2), np.array([0.0, 0.0, 1.0]), ARM),
        ("free", "floating", [0.3, 0.05, 0.1], rot_x(0.3) @ rot_z(-0.4), None, BODY),
        ("wrist", "revolute", [0, 0, -0.25], np.eye(3), KNEE_AXIS, HAND),
    ],
    "ball under a floating base": [  # a floating trunk, a ball hip, a knee
        ("hip", "spherical", [0.1, 0.0, -0.2], rot_x(0.3), None, BODY),
        ("knee", "revolute", [0, 0, -0.5], np.eye(3), KNEE_AXIS, HAND),
    ],
}
FLOATING = {"ball under a floating base"}


def link(name: str, body) -> Link:
    m, c, inertia = body
    return Link(name, m, c.tolist(), inertia.tolist())


def chain(name: str, offset: bool) -> Robot:
    """The chain ``name`` in armdyn; ``offset``: each joint of several coordinates' child
    frame placed at (OFFSET_R, OFFSET_P) in its moved joint frame."""
    floating = name in FLOATING
    links, joints, parent = [link("base", BASE)], [], "base"
    for k, (joint, kind, xyz, R, axis, (m, c, inertia)) in enumerate(CHAINS[name]):
        child = f"link{k + 1}"
        links.append(link(child, (m, c, inertia)))
        extra = {"axis": axis.tolist()} if axis is not None else {}
        if offset and kind != "revolute":
            extra.update(frame_xyz=OFFSET_P.tolist(), frame_rotation=OFFSET_R.tolist())
        joints.append(Joint(joint, kind, parent, child, xyz, R.tolist(), **extra))
        parent = child
    return Robot(name, links, joints, root_joint="free-flyer" if floating else None)


def pinocchio_chain(name: str, offset: bool):
    """The chain ``name`` built in Pinocchio by hand: a frame offset ``Xf`` moves the body's
    inertia and the next joint's placement into the moved joint frame."""
    kinds = {"spherical": pin.JointModelSpherical, "planar": pin.JointModelPlanar, "floating": pin.JointModelFreeFlyer}
    model, parent, Xf = pin.Model(), 0, pin.SE3.Identity()
    if name in FLOATING:
        parent = model.addJoint(0, pin.JointModelFreeFlyer(), pin.SE3.Identity(), "root")
        model.appendBodyToJoint(parent, pin.Inertia(*BASE), pin.SE3.Identity())
    for joint, kind, xyz, R, axis, (m, c, inertia) in CHAINS[name]:
        jmodel = kinds[kind]() if kind in kinds else pin.JointModelRevoluteUnaligned(axis)
        parent = model.addJoint(parent, jmodel, Xf * pin.SE3(R, np.array(xyz, dtype=float)), joint)
        Xf = pin.SE3(OFFSET_R, OFFSET_P) if offset and kind != "revolute" else pin.SE3.Identity()
        model.appendBodyToJoint(parent, Xf.act(pin.Inertia(m, c, inertia)), pin.SE3.Identity())
    return model


def states(robot: Robot, count: int, seed: int):
    """Random (q, v, a) in armdyn.numeric's layout: unit quaternions and (cos, sin) pairs
    drawn here, positions in [-1, 1], angles in [-pi, pi]."""
    rng = np.random.default_rng(seed)

    def quaternion():
        x = rng.normal(size=4)
        return list(x / np.linalg.norm(x))

    for _ in range(count):
        q = list(rng.uniform(-1, 1, 3)) + quaternion() if robot.floating else []
        for _, kind, _, _ in robot.configuration_layout:
            th = rng.uniform(-np.pi, np.pi)
            if kind == "spherical":
                q += quaternion()
            elif kind == "planar":
                q += [*rng.uniform(-1, 1, 2), np.cos(th), np.sin(th)]
            elif kind == "floating":
                q += [*rng.uniform(-1, 1, 3), *quaternion()]
            else:
                q.append(th)
        yield np.array(q), rng.normal(size=robot.nv), rng.normal(size=robot.nv)


def evaluate(matrix, values: dict) -> np.ndarray:
    """``matrix`` at the symbol values; every symbol must have one (NaN never passes)."""
    assert dag.free_symbols(matrix) <= set(values), dag.free_symbols(matrix) - set(values)
    out = dag.evaluate(matrix, {s: np.array([x]) for s, x in values.items()})[..., 0]
    assert np.all(np.isfinite(out))
    return out


def close(got, expected) -> float:
    expected = np.asarray(expected, dtype=float)
    assert got.shape == expected.shape
    return float(np.max(np.abs(got - expected)) / max(1.0, float(np.max(np.abs(expected)))))


CASES = [(name, offset) for name in CHAINS for offset in (False, True)]
IDS = [f"{name}{', frame offset' if offset else ''}" for name, offset in CASES]


@pytest.fixture(scope="module")
def derived():
    """armdyn.derive of each case, once: (robot, eom)."""
    cache: dict = {}

    def get(name, offset):
        if (name, offset) not in cache:
            robot = chain(name, offset)
            cache[name, offset] = robot, armdyn.derive(robot)
        return cache[name, offset]

    return get


@pytest.mark.parametrize("name, offset", CASES, ids=IDS)
def test_tau_m_and_bias_equal_the_core(derived, name, offset):
    robot, eom = derived(name, offset)
    assert eom.tau.shape == (robot.nv, 1)
    zero = np.zeros(robot.nv)
    for q, v, a in states(robot, 3, 1):
        values = state_values(robot, q, v, a)
        assert close(evaluate(eom.tau, values).ravel(), numeric.rnea(robot, q, v, a)) <= TOL
        assert close(evaluate(eom.bias, values).ravel(), numeric.rnea(robot, q, v, zero)) <= TOL
        M = evaluate(eom.M, values)
        assert close(M, numeric.crba(robot, q)) <= TOL and close(M, M.T) <= TOL


@needs_pinocchio
@pytest.mark.parametrize("name, offset", CASES, ids=IDS)
def test_tau_m_and_bias_equal_pinocchio(derived, name, offset):
    robot, eom = derived(name, offset)
    model = pinocchio_chain(name, offset)
    data = model.createData()
    assert (model.nq, model.nv) == (robot.nq, robot.nv)
    for q, v, a in states(robot, 3, 2):
        values = state_values(robot, q, v, a)
        assert close(evaluate(eom.tau, values).ravel(), pin.rnea(model, data, q, v, a)) <= TOL
        assert close(evaluate(eom.bias, values).ravel(), pin.nonLinearEffects(model, data, q, v)) <= TOL
        assert close(evaluate(eom.M, values), pin.crba(model, data, q)) <= TOL


def test_a_body_on_a_planar_joint_by_hand():
    """One body (mass m, centre of mass c, inertia I about it) on a planar joint in a
    vertical plane (gravity g along -y). With its velocity (vx, vy, wz) in its own axes,
    the centre of mass moves at ``v_c = (vx - wz cy, vy + wz cx)`` (body axes), so
    ``T = 1/2 m |v_c|^2 + 1/2 Izz wz^2`` and M is T's Hessian; Newton's law in the turning
    body frame, ``f = m (dv_c/dt + wz e_z x v_c) - m R^T g``, and Euler's about the
    origin, ``n_z = Izz wzd + (c x f)_z``, give tau."""
    m, cx, cy, cz, g = sp.symbols("m c_x c_y c_z g", positive=True)
    Ixx, Iyy, Izz, Ixy, Ixz, Iyz = sp.symbols("I_xx I_yy I_zz I_xy I_xz I_yz")
    inertia = sp.Matrix([[Ixx, Ixy, Ixz], [Ixy, Iyy, Iyz], [Ixz, Iyz, Izz]])
    links = [Link("floor"), Link("body", m, [cx, cy, cz], inertia)]
    robot = Robot(
        "slider",
        links,
        [Joint("cart", "planar", "floor", "body")],
        gravity=(0, -g, 0),
        parameters=[m, cx, cy, cz, g, Ixx, Iyy, Izz, Ixy, Ixz, Iyz],
    )
    eom = armdyn.derive(robot)
    assert isinstance(eom, SphericalEquationsOfMotion)
    vx, vy, wz = eom.qd
    vxd, vyd, wzd = eom.qdd
    cos, sin = configuration_symbols(robot.joints[0])[2:]
    M = sp.Matrix([[m, 0, -m * cy], [0, m, m * cx], [-m * cy, m * cx, Izz + m * (cx**2 + cy**2)]])
    vc = sp.Matrix([vx - wz * cy, vy + wz * cx])
    T = m / 2 * (vc.T * vc)[0] + Izz / 2 * wz**2
    assert sp.expand(sp.hessian(T, eom.qd) - M) == sp.zeros(3, 3)
    assert sp.expand(eom.M - M) == sp.zeros(3, 3)
    # Newton: the derivative of v_c's components plus wz e_z x v_c, gravity R^T (0, -g) = (-s g, -c g)
    ac = sp.Matrix([vxd - wzd * cy - wz * (vy + wz * cx), vyd + wzd * cx + wz * (vx - wz * cy)])
    f = m * ac - m * sp.Matrix([-sin * g, -cos * g])
    tau = sp.Matrix([f[0], f[1], Izz * wzd + cx * f[1] - cy * f[0]])
    assert sp.expand(eom.tau - tau) == sp.zeros(3, 1)


def test_a_free_joint_on_the_fixed_base_does_not_depend_on_where_it_is(derived):
    """A free body's dynamics do not depend on its position; hung under a turning link
    they do (the transport terms and the moment of its force about the parent)."""
    links = [Link("ground"), link("body", BODY)]
    robot = Robot("box", links, [Joint("free", "floating", "ground", "body", [0.3, 0, 1], rot_x(0.3).tolist())])
    eom = armdyn.derive(robot)
    position = set(position_symbols(robot.joints[0]))
    assert not dag.free_symbols(eom.tau) & position
    robot, eom = derived("free body mid-tree", False)
    assert dag.free_symbols(eom.tau) & set(position_symbols(robot.joints[1])) == set(position_symbols(robot.joints[1]))


def test_steps_and_reports_name_the_symbols(derived):
    robot, eom = derived("planar-base arm", False)
    names = [(s.stage, s.link, s.name) for s in eom.steps]
    assert names[:6] == [("outward", "link1", k) for k in ("omega", "omega_dot", "v_dot", "vc_dot", "F", "N")]
    assert ("inward", "link1", "tau") in names and eom.step("tau", "link1").shape == (3, 1)
    text = derivation_report([eom], "text", steps=True)
    assert "planar joint 'cart'" in text and "τ₁..₃ = [" in text and "τ₄ = " in text
    assert "v̇⁽¹⁾x" in text and "ω⁽¹⁾z" in text and "τ₄ = " in text
    latex = derivation_report([eom], "latex", steps=True)
    assert r"\dot{v}^{(1)}_{x}" in latex and r"\omega^{(1)}_{z}" in latex
    ascii_text = derivation_report([eom], "text", steps=True, ascii=True)
    assert ascii_text.isascii() and "tau1..3" in ascii_text and "cart.vx_dot" in ascii_text
    # on a base at rest, with gravity along z, the cart's pose does not enter: its names, printed
    x, y, cos, sin = configuration_symbols(robot.joints[0])
    printed = [eom.symbol_names("text")[s] for s in (x, y, cos, sin)]
    assert printed == ["p⁽¹⁾x", "p⁽¹⁾y", "c⁽¹⁾", "s⁽¹⁾"]
    assert [eom.symbol_names("latex")[s] for s in (x, cos)] == ["p^{(1)}_{x}", "c^{(1)}"]
    robot, eom = derived("free body mid-tree", False)
    free = robot.joints[1]
    names = eom.symbol_names("text")
    assert [names[s] for s in configuration_symbols(free)[2:5]] == ["p⁽²⁾z", "r⁽²⁾₁₁", "r⁽²⁾₁₂"]
    assert [names[s] for s in eom.qdd[1:7]] == ["v̇⁽²⁾x", "v̇⁽²⁾y", "v̇⁽²⁾z", "ω̇⁽²⁾x", "ω̇⁽²⁾y", "ω̇⁽²⁾z"]
    assert "floating joint 'free': velocity free.vx ... free.wz" in note(robot)
    robot, eom = derived("ball under a floating base", False)
    text = derivation_report([eom], "text")
    assert "a floating base" in text and "spherical joint 'hip'" in text
    assert "f_bx = " in text and "τ₁ = " in text and "(ω⁽¹⁾x)" in text  # the base's rows, then the hip's
    html = derivation_report([eom], "html")
    assert "a floating base" in html and "spherical joint" in html


@pytest.mark.parametrize("kind", ["planar", "floating"])
def test_lagrange_and_c_are_refused_as_quasi_velocities(kind):
    robot = Robot("one", [Link("base"), link("body", BODY)], [Joint("j", kind, "base", "body")])
    with pytest.raises(armdyn.ModelError, match=r"quasi-velocities.*'newton-euler'\) derives it"):
        armdyn.derive(robot, "lagrange")
    with pytest.raises(armdyn.ModelError, match="quasi-velocity"):
        armdyn.derive(robot).C


PLANAR_URDF = """<robot name="cart">
  <link name="floor"/>
  <link name="cart"><inertial><origin xyz="0.1 0 0.2"/><mass value="3"/>
    <inertia ixx="0.1" iyy="0.2" izz="0.3" ixy="0" ixz="0" iyz="0"/></inertial></link>
  <link name="pole"><inertial><origin xyz="0 0 0.5"/><mass value="1"/>
    <inertia ixx="0.02" iyy="0.02" izz="0.001" ixy="0" ixz="0" iyz="0"/></inertial></link>
  <joint name="drive" type="planar"><parent link="floor"/><child link="cart"/><origin xyz="0 0 0.1"/>
    <axis xyz="0 0 1"/></joint>
  <joint name="hinge" type="revolute"><parent link="cart"/><child link="pole"/><origin xyz="0 0 0.3"/>
    <axis xyz="0 1 0"/><limit lower="-3" upper="3" effort="1" velocity="1"/></joint>
</robot>
"""


def test_cli_derives_a_planar_joint(tmp_path, capsys):
    from armdyn.cli import main

    path = tmp_path / "cart.urdf"
    path.write_text(PLANAR_URDF, encoding="utf-8")
    assert main(["derive", str(path), "--steps", "--method", "both"]) == 0
    out, err = capsys.readouterr()
    assert "planar joint is derived by Newton-Euler only" in err
    assert "outward pass" in out and "τ₁..₃ = [" in out and "τ₄ = " in out and "Lagrange:" not in out
    assert main(["derive", str(path), "--method", "lagrange"]) == 2
    err = capsys.readouterr().err
    assert str(path) in err and "'drive'" in err and "quasi-velocities" in err


def test_tidy_groups_the_terms_as_collect_does(derived):
    """The reports' grouping by joint accelerations and rate products (term by term) is
    SymPy's ``collect``'s, and the tidied terms add up to the expression (to the float
    coefficients' rounding)."""
    from armdyn.symbolic.agreement import trig_reduce
    from armdyn.symbolic.tidy import _by_motion, tidy_terms

    robot, eom = derived("planar-base arm", True)
    q, qd, qdd = eom.q, eom.qd, eom.qdd
    motion = list(qdd) + [qd[i] * qd[j] for i in range(len(qd)) for j in range(i, len(qd))]
    checked = 0
    for step in eom.steps:
        for x in step.value if isinstance(step.value, sp.MatrixBase) else [step.value]:
            e = trig_reduce(x, q, keep_trig=True)
            if e == 0:
                continue
            ours, collected = _by_motion(e, set(qd) | set(qdd), set(motion)), sp.collect(e, motion, evaluate=False)
            assert set(ours) == set(collected)
            assert all(sp.expand(ours[m] - collected[m]) == 0 for m in ours)
            rest = sp.expand(sum(c * m for c, m in tidy_terms(x, q, qd, qdd)) - e)  # factoring rounds floats
            assert all(abs(float(t.as_coeff_Mul()[0])) < 1e-12 for t in sp.Add.make_args(rest) if t != 0)
            checked += 1
    assert checked > 40


@pytest.mark.parametrize("floating", [False, True], ids=["fixed base", "floating base"])
@pytest.mark.parametrize("seed", [1, 10, 11, 14])  # a ball and a free joint; planar joints on a ball, ...
def test_random_trees_of_every_joint_kind_equal_the_core(seed, floating):
    """Branched random trees of revolute, prismatic, fixed, ball, planar and free joints,
    child frames off their joints, gravity in any direction, on a fixed or a floating
    base: tau and M equal the core's rnea and crba."""
    from random_models import random_robot

    rng = np.random.default_rng(300 + seed)
    robot = random_robot(rng, n_joints=4, tree=True, kinds="RPFSLX", frame_offsets=True)
    kinds = {j.type for j in robot.multi_dof_joints}
    assert kinds, "this seed draws no joint of several coordinates: the test would check nothing new"
    if floating:
        robot = Robot(robot.name, robot.links.values(), robot.joints, gravity=robot.gravity, root_joint="free-flyer")
    eom = armdyn.derive(robot)
    for q, v, a in states(robot, 2, seed):
        values = state_values(robot, q, v, a)
        assert close(evaluate(eom.tau, values).ravel(), numeric.rnea(robot, q, v, a)) <= TOL
    assert close(evaluate(eom.M, values), numeric.crba(robot, q)) <= TOL
