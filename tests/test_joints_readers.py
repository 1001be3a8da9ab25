"""URDF planar and floating joints, MJCF ball joints and free bodies: read, then
compared with Pinocchio (URDF: its own parser on the same text) and MuJoCo (MJCF: its
own compiler on the same text) at random states."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest
from optional import mujoco, needs_mujoco, needs_pinocchio, pin

from armdyn import numeric
from armdyn.errors import ModelError
from armdyn.io import load
from armdyn.io.mjcf import MjcfIgnoredWarning, load_mjcf
from armdyn.io.mjcf_state import from_mujoco_force, from_mujoco_state, to_mujoco_force, to_mujoco_state
from armdyn.io.urdf import load_urdf

TOL = 1e-10


def _inertial(mass: float, com: str, ixx: float, iyy: float, izz: float, ixy: float = 0.0) -> str:
    return (
        f'<inertial><origin xyz="{com}" rpy="0.1 0.2 0.3"/><mass value="{mass}"/>'
        f'<inertia ixx="{ixx}" iyy="{iyy}" izz="{izz}" ixy="{ixy}" ixz="0.01" iyz="-0.02"/></inertial>'
    )


def _link(name: str, k: int) -> str:
    return f'<link name="{name}">{_inertial(1.0 + 0.3 * k, f"0.1 {0.02 * k} -0.05", 0.3, 0.4, 0.5, 0.03)}</link>'


def _joint(name, kind, parent, child, xyz, rpy, extra="") -> str:
    return (
        f'<joint name="{name}" type="{kind}"><parent link="{parent}"/><child link="{child}"/>'
        f'<origin xyz="{xyz}" rpy="{rpy}"/>{extra}</joint>'
    )


LIMIT = '<limit lower="-2" upper="2" effort="10" velocity="3"/>'


def tree(planar: str = '<axis xyz="0 0 1"/>', free: str = "") -> str:
    """A tree (depth first, siblings by joint name: Pinocchio's order, which armdyn keeps):
    a revolute shoulder, a planar joint (its elements ``planar``) in a tilted plane, an
    unaligned revolute elbow, a floating joint (its elements ``free``) in the middle of
    the tree, then prismatic and revolute joints, a fixed joint, and a revolute branch
    off the first link."""
    names = ["base", "l1", "l2", "l3", "l4", "l5", "l6", "l7", "l8"]
    return (
        '<robot name="mixed">'
        + "".join(_link(n, k) for k, n in enumerate(names))
        + _joint("a_shoulder", "revolute", "base", "l1", "0 0 0.3", "0 0 0", '<axis xyz="0 0 1"/>' + LIMIT)
        + _joint("b_table", "planar", "l1", "l2", "0.2 0 0.1", "0.4 -0.3 0.2", planar)
        + _joint("c_elbow", "revolute", "l2", "l3", "0.3 0.1 0", "0 0.5 0", '<axis xyz="0.6 0 0.8"/>' + LIMIT)
        + _joint("d_free", "floating", "l3", "l4", "0.1 -0.2 0.25", "0.3 0.1 -0.6", free)
        + _joint("e_slide", "prismatic", "l4", "l5", "0 0.1 0.2", "0 0 0", '<axis xyz="0 1 0"/>' + LIMIT)
        + _joint("f_wrist", "revolute", "l5", "l6", "0.1 0 0", "0.2 0 0", '<axis xyz="1 0 0"/>' + LIMIT)
        + _joint("g_weld", "fixed", "l6", "l7", "0 0 0.1", "0 0.3 0")
        + _joint("h_side", "revolute", "l1", "l8", "-0.2 0.1 0", "0 0 0.7", '<axis xyz="0 1 0"/>' + LIMIT)
        + "</robot>"
    )


TREE = tree()


# ------------------------------------------------------------------------ URDF


def test_urdf_planar_and_floating_joints_are_read():
    robot = load_urdf(TREE)
    kinds = [(name, kind) for name, kind, _, _ in robot.configuration_layout]
    assert kinds == [
        ("a_shoulder", "revolute"),
        ("b_table", "planar"),
        ("c_elbow", "revolute"),
        ("d_free", "floating"),
        ("e_slide", "prismatic"),
        ("f_wrist", "revolute"),
        ("h_side", "revolute"),
    ]
    assert (robot.nq, robot.nv) == (5 + 4 + 7, 5 + 3 + 6)
    assert robot.coordinate_names[1:4] == ["b_table.vx", "b_table.vy", "b_table.wz"]


@needs_pinocchio
def test_urdf_layout_is_pinocchios():
    """Pinocchio's parser gives the same joints, kinds and q/v offsets."""
    robot, model = load_urdf(TREE), pin.buildModelFromXML(TREE)
    assert (model.nq, model.nv) == (robot.nq, robot.nv)
    theirs = [(model.names[i], model.joints[i].idx_q, model.joints[i].idx_v) for i in range(1, model.njoints)]
    assert theirs == [(name, iq, iv) for name, _, iq, iv in robot.configuration_layout]
    assert [model.joints[i].shortname() for i in (2, 4)] == ["JointModelPlanar", "JointModelFreeFlyer"]


@needs_pinocchio
def test_urdf_kinematics_agree_with_pinocchio():
    """Each link's pose from the read model's joint transforms (not the numeric core) is
    Pinocchio's, at armdyn's random configurations (the layouts are one)."""
    robot, model = load_urdf(TREE), pin.buildModelFromXML(TREE)
    data, rng = model.createData(), np.random.default_rng(6)
    for _ in range(5):
        q = numeric.random_configuration(robot, rng)
        pin.framesForwardKinematics(model, data, q)
        for link, (R, p) in link_poses(robot, q).items():
            pose = data.oMf[model.getFrameId(link, pin.BODY)]
            assert np.abs(R - pose.rotation).max() <= 1e-12 and np.abs(p - pose.translation).max() <= 1e-12, link


def pinocchio_dynamics(model, q, v, a, tau):
    data = model.createData()
    M = pin.crba(model, data, q)
    M = np.triu(M) + np.triu(M, 1).T  # Pinocchio fills the upper triangle
    return pin.rnea(model, data, q, v, a).copy(), M, pin.aba(model, data, q, v, tau).copy()


def compare_dynamics(robot, model, seed: int, states: int = 6) -> None:
    """rnea, crba and aba of armdyn and Pinocchio at random states (q from armdyn's
    random_configuration: the layouts are one), relative to the largest entry."""
    rng = np.random.default_rng(seed)
    for _ in range(states):
        q = numeric.random_configuration(robot, rng)
        v, a, tau = rng.uniform(-1.5, 1.5, (3, robot.nv))
        tau_p, M_p, qdd_p = pinocchio_dynamics(model, q, v, a, tau)
        tau_a = numeric.rnea(robot, q, v, a)
        M_a = numeric.crba(robot, q)
        qdd_a = numeric.aba(robot, q, v, tau)
        for name, mine, theirs in (("rnea", tau_a, tau_p), ("crba", M_a, M_p), ("aba", qdd_a, qdd_p)):
            err = np.abs(mine - theirs).max() / max(1.0, np.abs(theirs).max())
            assert err <= TOL, (name, err)


@needs_pinocchio
def test_urdf_dynamics_agree_with_pinocchio():
    compare_dynamics(load_urdf(TREE), pin.buildModelFromXML(TREE), seed=1)


@needs_pinocchio
def test_urdf_continuous_joint_is_one_angle_where_pinocchio_keeps_cos_sin():
    """A ``continuous`` joint is read as revolute, q its angle (nq 1); Pinocchio's parser
    makes it an unbounded revolute joint, q = (cos, sin) (nq 2). v, a and tau are the same
    arrays; q converts by the angle's cos and sin (documented in io/urdf.py)."""
    text = (
        '<robot name="wheel">'
        + "".join(_link(n, k) for k, n in enumerate(["base", "l1", "l2"]))
        + _joint("a_hip", "revolute", "base", "l1", "0 0 0.3", "0 0 0", '<axis xyz="0 1 0"/>' + LIMIT)
        + _joint("b_wheel", "continuous", "l1", "l2", "0.2 0 0.1", "0.4 -0.3 0.2", '<axis xyz="0 0 1"/>')
        + "</robot>"
    )
    robot, model = load_urdf(text), pin.buildModelFromXML(text)
    assert (robot.nq, robot.nv, model.nq, model.nv) == (2, 2, 3, 2)
    data, rng = model.createData(), np.random.default_rng(8)
    for _ in range(5):
        (hip, wheel), (v, a) = rng.uniform(-3, 3, 2), rng.uniform(-1.5, 1.5, (2, 2))
        q_pin = np.array([hip, np.cos(wheel), np.sin(wheel)])
        tau = pin.rnea(model, data, q_pin, v, a)
        assert np.abs(numeric.rnea(robot, np.array([hip, wheel]), v, a) - tau).max() <= TOL


@needs_pinocchio
def test_urdf_free_flyer_root_with_floating_and_planar_joints(tmp_path):
    """``root_joint="free-flyer"`` as before: the root floats too (Pinocchio's root joint)."""
    path = tmp_path / "mixed.urdf"
    path.write_text(TREE)
    robot = load(path, root_joint="free-flyer")
    model = pin.buildModelFromXML(TREE, pin.JointModelFreeFlyer())
    assert (robot.nq, robot.nv) == (model.nq, model.nv) == (7 + 16, 6 + 14)
    compare_dynamics(robot, model, seed=2)


@pytest.mark.parametrize(
    "planar, words",
    [
        ("", 'give <axis xyz="0 0 1"/> and turn the plane with <origin rpy>; got no <axis>'),
        ('<axis xyz="1 0 0"/>', "got <axis> [1.0, 0.0, 0.0]"),
        ('<axis xyz="0 0 -1"/>', "got <axis> [0.0, 0.0, -1.0]"),
        ('<axis xyz="0 0 1"/><limit lower="-1" upper="1" effort="1" velocity="1"/>', "takes no lower, upper, velocity"),
        ('<axis xyz="0 0 1"/><mimic joint="a_shoulder"/>', "takes no mimic"),
    ],
)
def test_urdf_planar_joint_we_cannot_honour_is_refused(tmp_path, planar, words):
    path = tmp_path / "bad.urdf"
    path.write_text(tree(planar=planar))
    with pytest.raises(ModelError) as info:
        load_urdf(path)
    err = info.value
    assert err.source == str(path) and err.element == "joint 'b_table'" and words in err.message
    assert "\n" not in str(err)


def test_urdf_floating_joint_axis_is_unused():
    """The URDF spec: a floating joint's <axis> is not used (nor is it by Pinocchio)."""
    robot = load_urdf(tree(free='<axis xyz="0 1 0"/>'))
    assert robot.configuration_layout == load_urdf(TREE).configuration_layout


# ------------------------------------------------------------------------ MJCF

#: a ball-jointed pendulum: the ball's centre 0.4 above the body origin, the body turned
BALL_PENDULUM = """<mujoco model="ball_pendulum">
  <option gravity="0.3 -0.2 -9.81"><flag contact="disable"/></option>
  <worldbody>
    <body name="bob" pos="0.1 0.2 1.0" euler="10 20 30">
      <joint name="ball" type="ball" pos="0 0 0.4"/>
      <inertial pos="0.05 -0.02 -0.3" mass="2.5" fullinertia="0.04 0.05 0.03 0.004 -0.002 0.001"/>
    </body>
  </worldbody>
</mujoco>"""

#: hinge, slide and ball joints in a chain: a body with a slide then a ball (an
#: intermediate link), a ball inside a turned <frame>, a hinge with a ref
MIXED_CHAIN = """<mujoco model="mixed_chain">
  <option><flag contact="disable"/></option>
  <worldbody>
    <body name="b1" pos="0 0 0.5">
      <joint name="h1" axis="0 1 0" pos="0 0 0.1"/>
      <inertial pos="0.1 0 0" mass="1.2" diaginertia="0.01 0.02 0.03"/>
      <body name="b2" pos="0.3 0 0" quat="0.9 0.1 0.3 0.2">
        <joint name="s2" type="slide" axis="1 0 0.5"/>
        <joint name="ball2" type="ball" pos="0.05 0 0"/>
        <inertial pos="0.1 0.05 0" mass="0.8" diaginertia="0.02 0.01 0.015" euler="5 10 15"/>
        <body name="b3" pos="0.25 0 0">
          <frame pos="0 0.1 0" euler="0 0 45">
            <joint name="ball3" type="ball" pos="0.02 0 0"/>
          </frame>
          <inertial pos="0 0 -0.1" mass="0.6" fullinertia="0.01 0.012 0.008 0.001 0 -0.002"/>
          <body name="b4" pos="0 0 -0.2">
            <joint name="h4" axis="0 0 1" ref="20"/>
            <inertial pos="0.05 0 0" mass="0.3" diaginertia="0.002 0.003 0.004"/>
          </body>
        </body>
      </body>
    </body>
  </worldbody>
</mujoco>"""

#: two free bodies (one carrying a hinged lid) beside a fixed two-joint arm
FREE_BODIES = """<mujoco model="free_bodies">
  <option><flag contact="disable"/></option>
  <worldbody>
    <body name="arm" pos="0 0 0.2">
      <joint name="shoulder" axis="0 0 1"/>
      <inertial pos="0.1 0 0" mass="1" diaginertia="0.01 0.02 0.02"/>
      <body name="forearm" pos="0.3 0 0">
        <joint name="elbow" axis="0 1 0"/>
        <inertial pos="0.15 0 0" mass="0.5" diaginertia="0.005 0.01 0.01"/>
      </body>
    </body>
    <body name="box" pos="0.5 0.2 0.1" euler="10 0 30">
      <freejoint name="box_free"/>
      <inertial pos="0.01 0.02 -0.01" mass="0.7" fullinertia="0.003 0.004 0.005 0.0002 0.0001 -0.0003"/>
      <body name="lid" pos="0.05 0 0.05">
        <joint name="lid_hinge" axis="1 0 0"/>
        <inertial pos="0 0.03 0" mass="0.1" diaginertia="0.0005 0.0004 0.0006"/>
      </body>
    </body>
    <body name="pebble" pos="-0.3 0 0.5">
      <joint name="pebble_free" type="free"/>
      <inertial pos="0 0 0" mass="0.3" diaginertia="0.001 0.002 0.003"/>
    </body>
  </worldbody>
</mujoco>"""

# the mixed chain with damping and rotor inertia on every joint, its ball joint's too (MuJoCo
# applies them to each of the ball's three velocities, as armdyn to each coordinate)
DAMPED_CHAIN = MIXED_CHAIN.replace(
    "<worldbody>", '<default><joint damping="0.3" armature="0.05"/></default><worldbody>', 1
)
MODELS = {
    "ball_pendulum": BALL_PENDULUM,
    "mixed_chain": MIXED_CHAIN,
    "free_bodies": FREE_BODIES,
    "damped_chain": DAMPED_CHAIN,
}


def read(text: str):
    with pytest.warns(MjcfIgnoredWarning, match="flag contact"):
        return load_mjcf(text)


def test_mjcf_ball_and_free_joints_are_read():
    kinds = {name: [(n, k) for n, k, _, _ in read(text).configuration_layout] for name, text in MODELS.items()}
    assert kinds["ball_pendulum"] == [("ball", "spherical")]
    assert kinds["mixed_chain"] == [
        ("h1", "revolute"),
        ("s2", "prismatic"),
        ("ball2", "spherical"),
        ("ball3", "spherical"),
        ("h4", "revolute"),
    ]
    robot = read(FREE_BODIES)
    assert not robot.floating and robot.base == "world"
    assert kinds["free_bodies"] == [
        ("shoulder", "revolute"),
        ("elbow", "revolute"),
        ("box_free", "floating"),
        ("lid_hinge", "revolute"),
        ("pebble_free", "floating"),
    ]
    assert robot.meta["mujoco_joints"] == ["shoulder", "elbow", "box_free", "lid_hinge", "pebble_free"]
    pose = robot.meta["free_poses"]["pebble_free"]
    assert pose == ((-0.3, 0.0, 0.5), (1.0, 0.0, 0.0, 0.0))


def test_mjcf_one_free_body_beside_a_jointed_arm_hangs_from_the_world():
    """One free body and an arm with joints: not a floating base (that would drop the arm)."""
    text = FREE_BODIES.replace('<joint name="pebble_free" type="free"/>', "")
    robot = read(text)
    assert not robot.floating and [k for _, k, _, _ in robot.configuration_layout].count("floating") == 1
    # without the arm, the one free body is the floating base, as before
    alone = text[: text.index('<body name="arm"')] + text[text.index('<body name="box"') :]
    assert read(alone).floating


#: MuJoCo's joint type numbers (mjtJoint; compared with the ints of model.jnt_type)
FREE, BALL = (0, 1) if mujoco is None else (int(mujoco.mjtJoint.mjJNT_FREE), int(mujoco.mjtJoint.mjJNT_BALL))


def mujoco_model(text: str):
    model = mujoco.MjModel.from_xml_string(text)
    model.opt.disableflags |= mujoco.mjtDisableBit.mjDSBL_CONSTRAINT  # limits too
    return model


def random_qpos(model, rng) -> np.ndarray:
    """A random MuJoCo configuration, in MuJoCo's own layout (quaternions w x y z)."""
    qpos = np.zeros(model.nq)
    for j in range(model.njnt):
        a, kind = model.jnt_qposadr[j], model.jnt_type[j]
        if kind == FREE:
            qpos[a : a + 3] = rng.uniform(-1, 1, 3)
            a += 3
        if kind in (FREE, BALL):
            quat = rng.standard_normal(4)
            qpos[a : a + 4] = quat / np.linalg.norm(quat)
        else:
            qpos[a] = rng.uniform(-2, 2)
    return qpos


def rotation_wxyz(quat) -> np.ndarray:
    """R of the unit quaternion (w, x, y, z), written out here."""
    w, x, y, z = quat
    return np.array(
        [
            [1 - 2 * (y * y + z * z), 2 * (x * y - z * w), 2 * (x * z + y * w)],
            [2 * (x * y + z * w), 1 - 2 * (x * x + z * z), 2 * (y * z - x * w)],
            [2 * (x * z - y * w), 2 * (y * z + x * w), 1 - 2 * (x * x + y * y)],
        ]
    )


def velocity_map(robot, model, qpos) -> np.ndarray:
    """``T`` with armdyn's ``v = T qvel``, by hand: the rotation's transpose on a free
    joint's linear velocity (MuJoCo: world axes, armdyn: body axes), 1 elsewhere."""
    layout = {name: iv for name, _, _, iv in robot.configuration_layout}
    names = robot.meta["mujoco_joints"]  # MuJoCo's joints in order, unnamed ones named by armdyn
    T = np.zeros((robot.nv, model.nv))
    for j in range(model.njnt):
        mv, kind = model.jnt_dofadr[j], model.jnt_type[j]
        assert model.joint(j).name in ("", names[j])
        iv = layout[names[j]]
        if kind == FREE:
            a = model.jnt_qposadr[j]
            T[iv : iv + 3, mv : mv + 3] = rotation_wxyz(qpos[a + 3 : a + 7]).T
            T[iv + 3 : iv + 6, mv + 3 : mv + 6] = np.eye(3)
        else:
            width = 3 if kind == BALL else 1
            T[iv : iv + width, mv : mv + width] = np.eye(width)
    return T


def link_poses(robot, q) -> dict[str, tuple[np.ndarray, np.ndarray]]:
    """Every link's (R, p) in the world from the joints' own transforms (the model's
    SymPy description, not the numeric core)."""
    first = {name: (kind, iq) for name, kind, iq, _ in robot.configuration_layout}
    poses = {robot.base: (np.eye(3), np.zeros(3))}
    for joint in robot.joints:
        kind, iq = first.get(joint.name, ("fixed", 0))
        coordinate = 0 if kind == "fixed" else q[iq] if joint.nq == 1 else list(q[iq : iq + joint.nq])
        R, p = (np.array(m.evalf(), dtype=float) for m in joint.transform(coordinate))
        R0, p0 = poses[joint.parent]
        poses[joint.child] = (R0 @ R, p0 + R0 @ p.ravel())
    return poses


@needs_mujoco
@pytest.mark.parametrize("name", MODELS)
def test_mjcf_kinematics_agree_with_mujoco(name):
    """Each body's pose from the read model (through the state conversion) is MuJoCo's."""
    robot, model = read(MODELS[name]), mujoco_model(MODELS[name])
    data, rng = mujoco.MjData(model), np.random.default_rng(3)
    for _ in range(5):
        data.qpos[:] = random_qpos(model, rng)
        mujoco.mj_kinematics(model, data)
        q, _ = from_mujoco_state(robot, data.qpos, np.zeros(model.nv))
        poses = link_poses(robot, q)
        for b in range(1, model.nbody):
            R, p = poses[model.body(b).name]
            assert np.abs(R - data.xmat[b].reshape(3, 3)).max() <= 1e-12
            assert np.abs(p - data.xpos[b]).max() <= 1e-12


@needs_mujoco
@pytest.mark.parametrize("name", MODELS)
def test_mjcf_dynamics_agree_with_mujoco(name):
    """mj_fullM and mj_inverse's qfrc_inverse against armdyn's crba and rnea: ``M_mujoco
    = T^T M T`` and ``qfrc = T^T tau`` (T by hand), the state through from_mujoco_state."""
    robot, model = read(MODELS[name]), mujoco_model(MODELS[name])
    data, rng = mujoco.MjData(model), np.random.default_rng(4)
    for _ in range(6):
        data.qpos[:] = random_qpos(model, rng)
        data.qvel[:], data.qacc[:] = rng.uniform(-1.5, 1.5, (2, model.nv))
        mujoco.mj_forward(model, data)
        M = np.zeros((model.nv, model.nv))
        mujoco.mj_fullM(model, data, M)
        mujoco.mj_inverse(model, data)
        q, v, a = from_mujoco_state(robot, data.qpos, data.qvel, data.qacc)
        T = velocity_map(robot, model, data.qpos)
        assert np.abs(T @ data.qvel - v).max() <= 1e-14
        M_a = T.T @ numeric.crba(robot, q) @ T
        qfrc = T.T @ numeric.rnea(robot, q, v, a)
        scale = max(1.0, np.abs(M).max(), np.abs(data.qfrc_inverse).max())
        assert np.abs(M_a - M).max() / scale <= TOL
        assert np.abs(qfrc - data.qfrc_inverse).max() / scale <= TOL
        assert np.abs(to_mujoco_force(robot, q, numeric.rnea(robot, q, v, a)) - data.qfrc_inverse).max() <= TOL * scale


def test_mujoco_state_round_trip_and_layout():
    """to_mujoco_state inverts from_mujoco_state; a ball's quaternion is reordered (w x
    y z <-> x y z w) and its velocity kept; a free joint's linear velocity is turned
    into the world's axes (by hand: R v)."""
    robot = read(FREE_BODIES)
    rng = np.random.default_rng(8)
    Q = np.array([numeric.random_configuration(robot, rng) for _ in range(4)])
    V, A = rng.standard_normal((2, 4, robot.nv))
    qpos, qvel, qacc = to_mujoco_state(robot, Q, V, A)
    back = from_mujoco_state(robot, qpos, qvel, qacc)
    for mine, theirs in zip(back, (Q, V, A)):
        assert np.abs(mine - theirs).max() <= 1e-14
    # box_free: armdyn q[2:9], v[2:8]; MuJoCo qpos[2:9] (w x y z at 5:9), qvel[2:8]
    x, y, z, w = Q[0, 5:9]
    assert np.array_equal(qpos[0, 5:9], [w, x, y, z])
    assert np.abs(qvel[0, 2:5] - rotation_wxyz([w, x, y, z]) @ V[0, 2:5]).max() <= 1e-15
    ball = read(BALL_PENDULUM)
    q = numeric.random_configuration(ball, rng)
    qpos, qvel = to_mujoco_state(ball, q, [0.1, 0.2, 0.3])
    assert np.array_equal(qpos, q[[3, 0, 1, 2]]) and np.array_equal(qvel, [0.1, 0.2, 0.3])


@pytest.mark.parametrize("where", ["qpos", "q"])
def test_a_state_with_a_non_unit_quaternion_is_refused(where):
    robot = read(FREE_BODIES)
    if where == "qpos":
        qpos = np.zeros(robot.nq)
        qpos[5], qpos[13] = 1.0, 0.5  # box_free's w is 1, pebble_free's w is 0.5
        with pytest.raises(ValueError, match=r"quaternion \(w, x, y, z\) qpos\[13:17\] of joint 'pebble_free'"):
            from_mujoco_state(robot, qpos, np.zeros(robot.nv))
        with pytest.raises(ValueError, match="pebble_free"):
            from_mujoco_force(robot, qpos, np.zeros(robot.nv))
    else:
        q = numeric.neutral(robot)
        q[8] = 1.5  # box_free's w
        with pytest.raises(ValueError, match=r"quaternion \(x, y, z, w\) q\[5:9\] of joint 'box_free' \(floating\)"):
            to_mujoco_state(robot, q, np.zeros(robot.nv))


def test_mjcf_ball_joint_dynamics_are_read():
    """A ball joint's damping, armature and frictionloss become its joint dynamics on each
    of its three coordinates (the model's rows; MuJoCo's agreement in
    test_mjcf_dynamics_agree_with_mujoco["damped_chain"])."""
    text = BALL_PENDULUM.replace('type="ball"', 'type="ball" damping="0.1" armature="0.2" frictionloss="0.3"')
    ball = read(text).movable_joints[0]
    assert ball.type == "spherical"
    assert (float(ball.damping), float(ball.armature), float(ball.friction)) == (0.1, 0.2, 0.3)
    with pytest.raises(ModelError, match="damping .*nonlinear damping polynomial"):
        load_mjcf(BALL_PENDULUM.replace('type="ball"', 'type="ball" damping="0.1 0.2"'))


def test_mjcf_ball_range_and_stiffness_are_reported():
    text = BALL_PENDULUM.replace('type="ball"', 'type="ball" range="0 60" stiffness="2"')
    with pytest.warns(MjcfIgnoredWarning, match="ball joint range.*joint stiffness|joint stiffness.*ball joint range"):
        robot = load_mjcf(text)
    assert robot.movable_joints[0].type == "spherical"


@needs_mujoco
def test_mujoco_test_model_with_its_ball_joint_and_free_bodies(tmp_path):
    """MuJoCo's own test model (shipped in its wheel) with its ball joint and its five
    free bodies (one of them carrying legs), so each free body hangs on a floating joint;
    changed: its mesh made a sphere, the gravity compensation dropped; MuJoCo's springs and
    fluid forces switched off (armdyn lists them as ignored)."""
    source = Path(mujoco.__file__).parent / "testdata" / "model.xml"
    if not source.is_file():
        pytest.skip(f"mujoco {mujoco.__version__} ships no testdata/model.xml")
    text = source.read_text().replace('type="mesh" mesh="icosahedron"', 'type="sphere"')
    text = text.replace(' gravcomp="0.5"', "")
    path = tmp_path / "model.xml"
    path.write_text(text)
    with pytest.warns(MjcfIgnoredWarning, match="joint stiffness"):
        robot = load_mjcf(path)
    kinds = [k for _, k, _, _ in robot.configuration_layout]
    assert (kinds.count("floating"), kinds.count("spherical")) == (5, 1) and not robot.floating
    model = mujoco.MjModel.from_xml_path(str(path))
    model.opt.disableflags |= mujoco.mjtDisableBit.mjDSBL_CONSTRAINT | mujoco.mjtDisableBit.mjDSBL_SPRING
    model.opt.density = model.opt.viscosity = 0
    model.opt.wind[:] = 0
    data, rng = mujoco.MjData(model), np.random.default_rng(9)
    for _ in range(4):
        data.qpos[:] = random_qpos(model, rng)
        data.qvel[:], data.qacc[:] = rng.uniform(-1.5, 1.5, (2, model.nv))
        mujoco.mj_forward(model, data)
        M = np.zeros((model.nv, model.nv))
        mujoco.mj_fullM(model, data, M)
        mujoco.mj_inverse(model, data)
        q, v, a = from_mujoco_state(robot, data.qpos, data.qvel, data.qacc)
        T = velocity_map(robot, model, data.qpos)
        scale = max(1.0, np.abs(M).max(), np.abs(data.qfrc_inverse).max())
        assert np.abs(T.T @ numeric.crba(robot, q) @ T - M).max() / scale <= TOL
        assert np.abs(T.T @ numeric.rnea(robot, q, v, a) - data.qfrc_inverse).max() / scale <= TOL


@needs_mujoco
def test_readme_ball_joint_block_runs(tmp_path):
    """README's "Ball, planar and floating joints" Python block, run as written: armdyn's
    inverse dynamics of a ball-jointed pendulum equal MuJoCo's mj_inverse."""
    import os
    import subprocess
    import sys

    import armdyn

    readme = (Path(__file__).resolve().parent.parent / "README.md").read_text()
    section = readme.split("### Ball, planar and floating joints", 1)[1]
    code = section.split("```python\n", 1)[1].split("```", 1)[0]
    env = {**os.environ, "PYTHONPATH": str(Path(armdyn.__file__).parent.parent)}
    done = subprocess.run(
        [sys.executable, "-W", "ignore", "-c", code], cwd=tmp_path, env=env, capture_output=True, text=True, timeout=300
    )
    assert done.returncode == 0, done.stderr
    names, gap = done.stdout.strip().splitlines()
    assert names == "['ball.wx', 'ball.wy', 'ball.wz', 'hinge']"
    assert float(gap) < 1e-12


def test_show_and_view_a_ball_joint(tmp_path):
    """`armdyn show` draws a robot with a ball joint (2-D and 3-D) at its neutral
    configuration or at a typed --q, whose quaternion (few digits) is normalised; a
    quaternion far from unit length is refused, naming the joint."""
    import os
    import subprocess
    import sys

    import armdyn

    (tmp_path / "pendulum.xml").write_text(
        "<mujoco><worldbody><body name='rod' pos='0 0 1'><joint name='ball' type='ball'/>"
        "<geom type='capsule' fromto='0 0 0 0 0 -0.6' size='0.03' mass='2'/></body></worldbody></mujoco>"
    )
    env = {**os.environ, "PYTHONPATH": str(Path(armdyn.__file__).parent.parent)}

    def show(*args):
        cmd = [sys.executable, "-m", "armdyn", "show", "pendulum.xml", *args]
        return subprocess.run(cmd, cwd=tmp_path, env=env, capture_output=True, text=True, timeout=300)

    for args in (["-o", "a.png"], ["--3d", "-o", "a.html"], ["--q", "0,0.7071068,0,0.7071068", "-o", "b.png"]):
        done = show(*args)
        assert done.returncode == 0, done.stderr
    assert "joint 'ball''s quaternion normalised" in done.stderr
    done = show("--q", "0,0,0,2", "-o", "c.png")
    assert done.returncode == 2 and "joint 'ball''s quaternion [0.0, 0.0, 0.0, 2.0] has length 2" in done.stderr
    assert "Traceback" not in done.stderr
    # the 2-D picture's poses are the numeric core's at that configuration
    from armdyn.show import frame_poses

    robot = load(tmp_path / "pendulum.xml")
    q = np.array([0.0, np.sqrt(0.5), 0.0, np.sqrt(0.5)])
    got = frame_poses(robot, q)
    np.testing.assert_allclose(np.array(list(got.values())), numeric.forward_kinematics(robot, q), atol=1e-12)
