"""MJCF reader (armdyn.io.mjcf) against MuJoCo itself, which compiles the same files with
its own parser and computes the dynamics with its own algorithms.

For each model: the joint-space inertia matrix (``mj_fullM`` after ``mj_forward``) against
``armdyn.numeric.crba``, and inverse dynamics (``mj_inverse`` with every constraint
disabled: contacts, limits, equalities and MuJoCo's frictionloss constraint) against
``armdyn.numeric.rnea``, at random states, to 1e-10. MuJoCo puts ``armature`` on M's
diagonal and its passive damping force ``-damping qd`` into ``qfrc_inverse``'s balance,
as armdyn does with the joint's ``armature`` and ``damping``; a ``frictionloss`` is
armdyn's ``friction sign(qd)``, added to MuJoCo's torque here by hand. Tests that need
MuJoCo skip alone; a closed form checks the planar arm without it.
"""

from __future__ import annotations

import random
import re
import time
import warnings
from pathlib import Path

import numpy as np
import pytest

import armdyn
import armdyn.numeric as numeric
from armdyn.errors import ModelError
from armdyn.io.mjcf import MjcfIgnoredWarning, load_mjcf

TOL = 1e-10


def mujoco_model(path, springs: bool = True):
    mujoco = pytest.importorskip("mujoco")
    model = mujoco.MjModel.from_xml_path(str(path))
    model.opt.disableflags |= mujoco.mjtDisableBit.mjDSBL_CONSTRAINT
    if not springs:  # what armdyn reports as ignored: joint springs and fluid forces
        model.opt.disableflags |= mujoco.mjtDisableBit.mjDSBL_SPRING
        model.opt.density = model.opt.viscosity = 0
        model.opt.wind[:] = 0
    return mujoco, model


def full_inertia(mujoco, model, data) -> np.ndarray:
    M = np.zeros((model.nv, model.nv))
    try:
        mujoco.mj_fullM(model, data, M)  # MuJoCo 4
    except TypeError:
        mujoco.mj_fullM(model, M, data.qM)  # MuJoCo 3
    return M


def compare_with_mujoco(path, robot=None, states: int = 6, seed: int = 0, springs: bool = True) -> float:
    """Largest difference of M and inverse dynamics between MuJoCo and armdyn (MuJoCo's
    joint order mapped to armdyn's by name); ``springs=False``: without MuJoCo's springs
    and fluid forces."""
    mujoco, model = mujoco_model(path, springs)
    data = mujoco.MjData(model)
    if robot is None:
        with warnings.catch_warnings():
            warnings.simplefilter("ignore", MjcfIgnoredWarning)
            robot = armdyn.load(path)
    assert robot.dof == model.nv == model.nq
    perm = [robot.coordinate_index(model.joint(i).name) for i in range(model.njnt)]
    assert perm == list(range(robot.dof))  # armdyn keeps MuJoCo's joint order
    friction = np.array([model.dof_frictionloss[i] for i in range(model.nv)])
    rng = np.random.default_rng(seed)
    worst = 0.0
    for _ in range(states):
        q, qd, qdd = rng.uniform(-1.5, 1.5, (3, model.nv))
        data.qpos[:], data.qvel[:] = q, qd
        mujoco.mj_forward(model, data)
        M = full_inertia(mujoco, model, data)
        data.qacc[:] = qdd
        mujoco.mj_inverse(model, data)
        tau = data.qfrc_inverse + friction * np.sign(qd)
        qa, qda, qdda = (np.zeros(robot.dof) for _ in range(3))
        qa[perm], qda[perm], qdda[perm] = q, qd, qdd
        Ma = numeric.crba(robot, qa)[np.ix_(perm, perm)]
        taua = numeric.rnea(robot, qa, qda, qdda)[perm]
        scale = max(1.0, np.abs(M).max(), np.abs(tau).max())
        diff = max(np.abs(M - Ma).max(), np.abs(tau - taua).max()) / scale
        assert np.isfinite(diff)
        worst = max(worst, diff)
    return worst


def write(tmp_path, text: str, name: str = "robot.xml"):
    path = tmp_path / name
    path.write_text(text)
    return path


# ------------------------------------------------------------ hand-written models

PLANAR_2R = """<mujoco model="planar2r">
  <option gravity="0 -9.81 0"/>
  <worldbody>
    <body name="link1">
      <joint name="j1" axis="0 0 1"/>
      <inertial pos="0.5 0 0" mass="2" diaginertia="0.15 0.2 0.3"/>
      <body name="link2" pos="1 0 0">
        <joint name="j2" axis="0 0 1"/>
        <inertial pos="0.4 0 0" mass="1.5" diaginertia="0.06 0.1 0.15"/>
      </body>
    </body>
  </worldbody>
</mujoco>"""


def test_planar_2r_closed_form(tmp_path):
    """M and gravity of a planar 2R arm from the textbook formulas (no MuJoCo needed)."""
    robot = load_mjcf(write(tmp_path, PLANAR_2R))
    m1, m2, l1, c1, c2, I1, I2, g = 2.0, 1.5, 1.0, 0.5, 0.4, 0.3, 0.15, 9.81
    for q1, q2 in np.random.default_rng(1).uniform(-3, 3, (5, 2)):
        q = np.array([q1, q2])
        m11 = I1 + I2 + m1 * c1**2 + m2 * (l1**2 + c2**2 + 2 * l1 * c2 * np.cos(q2))
        m12 = I2 + m2 * (c2**2 + l1 * c2 * np.cos(q2))
        M = np.array([[m11, m12], [m12, I2 + m2 * c2**2]])
        grav = g * np.array([(m1 * c1 + m2 * l1) * np.cos(q1) + m2 * c2 * np.cos(q1 + q2), m2 * c2 * np.cos(q1 + q2)])
        assert np.abs(numeric.crba(robot, q) - M).max() < 1e-12
        assert np.abs(numeric.rnea(robot, q, np.zeros(2), np.zeros(2)) - grav).max() < 1e-12


def test_planar_2r_against_mujoco(tmp_path):
    assert compare_with_mujoco(write(tmp_path, PLANAR_2R)) < TOL


RP_ARM = """<mujoco model="rp">
  <compiler angle="radian"/>
  <worldbody>
    <body name="base" pos="0 0 0.3" euler="0.1 0.2 0.3">
      <joint name="turn" type="hinge" axis="0 0 1" ref="0.4" damping="0.7" armature="0.05"/>
      <inertial pos="0.1 0 0.05" mass="3" diaginertia="0.05 0.06 0.07" quat="0.9 0.1 0.2 0.3"/>
      <body name="slider" pos="0.2 0.1 0" zaxis="1 0 0.2">
        <joint name="reach" type="slide" axis="0 0 1" ref="0.15" range="0 0.5" damping="2" frictionloss="0.3"/>
        <inertial pos="0 0 0.2" mass="1.2" fullinertia="0.02 0.03 0.015 0.001 -0.002 0.0005"/>
      </body>
    </body>
  </worldbody>
</mujoco>"""


def test_rp_arm_against_mujoco(tmp_path):
    path = write(tmp_path, RP_ARM)
    robot = load_mjcf(path)
    reach = robot.joints[1]
    assert (reach.type, float(reach.damping), float(reach.friction), float(reach.upper)) == ("prismatic", 2, 0.3, 0.5)
    assert float(robot.joints[0].armature) == 0.05
    assert compare_with_mujoco(path, robot) < TOL


SIX_JOINTS = """<mujoco model="six">
  <default>
    <joint axis="0 1 0" damping="0.5" armature="0.01"/>
    <geom type="capsule" density="800"/>
    <default class="wrist">
      <joint axis="1 0 0" damping="0.1"/>
      <geom type="box" size="0.03 0.03 0.03"/>
      <default class="tool">
        <geom type="sphere" size="0.04" mass="0.3"/>
      </default>
    </default>
  </default>
  <worldbody>
    <geom type="plane" size="1 1 0.1"/>
    <body name="b1" pos="0 0 0.1">
      <joint name="q1" axis="0 0 1"/>
      <geom fromto="0 0 0 0 0 0.3" size="0.05"/>
      <body name="b2" pos="0 0 0.3" axisangle="1 0 0 30">
        <joint name="q2"/>
        <geom fromto="0 0 0 0.4 0 0" size="0.04"/>
        <body name="b3" pos="0.4 0 0" xyaxes="0 1 0 -1 0 0">
          <joint name="q3" pos="0 0 0.02"/>
          <geom type="cylinder" fromto="0 0 0 0.35 0 0.05" size="0.035"/>
          <body name="b4" pos="0.35 0 0.05" childclass="wrist">
            <joint name="q4"/>
            <geom pos="0.05 0 0"/>
            <body name="b5" pos="0.1 0 0" euler="0 90 0">
              <joint name="q5" axis="0 0 1"/>
              <geom type="ellipsoid" size="0.03 0.04 0.05" euler="10 20 30"/>
              <body name="b6" pos="0 0 0.08">
                <joint name="q6" class="tool" axis="0 1 0"/>
                <geom class="tool" pos="0 0 0.05"/>
                <site name="tcp" pos="0 0 0.1"/>
              </body>
            </body>
          </body>
        </body>
      </body>
    </body>
  </worldbody>
  <actuator><motor joint="q1"/><motor joint="q2"/></actuator>
  <sensor><jointpos joint="q1"/></sensor>
</mujoco>"""


def test_six_joints_with_default_classes_against_mujoco(tmp_path):
    path = write(tmp_path, SIX_JOINTS)
    with pytest.warns(MjcfIgnoredWarning) as record:
        robot = load_mjcf(path)
    message = str(record[0].message)
    for word in ("<actuator>", "<sensor>", "<site>", "<geom> of the world body"):
        assert word in message
    assert float(robot.joints[3].damping) == 0.1 and float(robot.joints[0].damping) == 0.5
    assert compare_with_mujoco(path, robot) < TOL


ORIENTATIONS = [
    ("degree", "xyz", 'euler="30 -50 70"'),
    ("radian", "xyz", 'euler="0.5 -0.9 1.2"'),
    ("degree", "ZYX", 'euler="30 -50 70"'),
    ("radian", "zxZ", 'euler="0.5 -0.9 1.2"'),
    ("degree", "xyz", 'axisangle="1 2 3 75"'),
    ("radian", "xyz", 'axisangle="1 2 3 1.3"'),
    ("degree", "xyz", 'quat="0.3 -0.4 0.5 0.6"'),
    ("degree", "xyz", 'xyaxes="1 1 0 -1 2 0.5"'),
    ("degree", "xyz", 'zaxis="0.2 -0.3 -1"'),
    ("degree", "xyz", 'zaxis="0 0 -1"'),
]


@pytest.mark.parametrize("angle, seq, orientation", ORIENTATIONS)
def test_orientations_against_mujoco(tmp_path, angle, seq, orientation):
    """Each orientation on a body, an inertial frame, a geom and a joint's reference turn."""
    ref = "20" if angle == "degree" else "0.35"
    text = f"""<mujoco>
      <compiler angle="{angle}" eulerseq="{seq}"/>
      <worldbody>
        <body name="a" pos="0.1 0.2 0.3" {orientation}>
          <joint name="ja" axis="1 1 0" ref="{ref}" pos="0.05 0 0"/>
          <inertial pos="0.1 0.2 0" mass="2" diaginertia="0.1 0.2 0.25" {orientation}/>
          <body name="b" pos="0.3 0 0" {orientation}>
            <joint name="jb" axis="0 1 1"/>
            <geom type="box" size="0.1 0.05 0.02" pos="0.1 0 0" {orientation}/>
          </body>
        </body>
      </worldbody>
    </mujoco>"""
    assert compare_with_mujoco(write(tmp_path, text)) < TOL


MULTI_JOINT = """<mujoco>
  <worldbody>
    <body name="carriage" pos="0 0 0.5" euler="0 0 30">
      <joint name="x" type="slide" axis="1 0 0" ref="0.2"/>
      <joint name="yaw" axis="0 0 1" pos="0.1 0 0" ref="15"/>
      <joint name="pitch" axis="0 1 0" pos="0 0.05 0.1" damping="0.2"/>
      <inertial pos="0.2 0.1 0.05" mass="4" fullinertia="0.3 0.25 0.2 0.01 0.02 -0.015"/>
      <body name="arm" pos="0.4 0 0">
        <joint name="roll" axis="1 0 0" pos="0.02 0 0"/>
        <joint name="lift" type="slide" axis="0 0 1"/>
        <inertial pos="0.1 0 0" mass="1" diaginertia="0.01 0.02 0.02"/>
      </body>
    </body>
  </worldbody>
</mujoco>"""


def test_several_joints_in_one_body_against_mujoco(tmp_path):
    path = write(tmp_path, MULTI_JOINT)
    robot = load_mjcf(path)
    assert robot.dof == 5
    assert robot.meta["intermediate_links"] == ["carriage_x", "carriage_yaw", "arm_roll"]
    assert compare_with_mujoco(path, robot) < TOL


GEOMS_ONLY = """<mujoco>
  <compiler inertiagrouprange="0 2"/>
  <worldbody>
    <body name="a" pos="0 0 0.2">
      <joint name="j1" axis="0 0 1"/>
      <geom type="sphere" size="0.05" pos="0.1 0 0"/>
      <geom type="capsule" size="0.03 0.1" pos="0 0.1 0" euler="90 0 0" density="500"/>
      <geom type="capsule" fromto="0 0 0 0.3 0.1 0" size="0.02"/>
      <geom type="mesh" mesh="shell" group="3"/>
      <body name="b" pos="0.3 0.1 0">
        <joint name="j2" axis="0 1 0"/>
        <geom type="cylinder" size="0.04 0.12" quat="1 1 0 0" mass="0.8"/>
        <geom type="box" fromto="0 0 0 0.2 0 0.1" size="0.02 0.03"/>
        <frame pos="0.2 0 0.1" euler="0 45 0">
          <geom type="ellipsoid" size="0.05 0.03 0.02"/>
          <body name="c" pos="0.05 0 0">
            <frame pos="0.01 0.02 0" euler="30 0 0">
              <joint name="j3" type="slide" axis="1 0 0"/>
              <joint name="j4" axis="0 1 0" pos="0 0 0.03"/>
            </frame>
            <geom type="box" size="0.02 0.02 0.04" density="7800"/>
            <body name="d" pos="0 0 0.1">
              <joint name="j5" axis="1 0 0"/>
              <frame pos="0.02 0 0.01" quat="0.9 0.1 0.3 0">
                <inertial pos="0.01 0 0" mass="0.5" fullinertia="0.002 0.003 0.004 0.0001 0 0"/>
              </frame>
            </body>
          </body>
        </frame>
      </body>
    </body>
  </worldbody>
  <asset><mesh name="shell" vertex="0 0 0 1 0 0 0 1 0 0 0 1"/></asset>
</mujoco>"""


def test_inertia_from_geoms_against_mujoco(tmp_path):
    path = write(tmp_path, GEOMS_ONLY)
    with pytest.warns(MjcfIgnoredWarning, match="outside inertiagrouprange"):
        robot = load_mjcf(path)
    mujoco, model = mujoco_model(path)
    masses = {model.body(i).name: model.body_mass[i] for i in range(model.nbody)}
    for name in ("a", "b", "c", "d"):
        assert abs(float(robot.links[name].floats("mass")) - masses[name]) < 1e-12 * masses[name]
    assert compare_with_mujoco(path, robot) < TOL


@pytest.mark.parametrize("mode", ["auto", "true", "false"])
def test_inertiafromgeom_and_gravity_flag_against_mujoco(tmp_path, mode):
    """``inertiafromgeom``: an <inertial> wins unless 'true'; 'false' never uses geoms."""
    text = f"""<mujoco>
      <compiler inertiafromgeom="{mode}"/>
      <option gravity="1 2 -5"><flag gravity="disable" contact="disable"/></option>
      <worldbody><body name="a"><joint name="j1" axis="0 1 0"/>
        <inertial pos="0.1 0 0" mass="2" diaginertia="0.1 0.1 0.1"/>
        <geom type="box" size="0.1 0.2 0.3" pos="0.2 0 0"/>
        <body name="b" pos="0.5 0 0"><joint name="j2" axis="1 0 0"/>
          <inertial pos="0 0.1 0" mass="1" diaginertia="0.01 0.02 0.02"/>
          <geom type="sphere" size="0.1"/>
        </body></body></worldbody></mujoco>"""
    path = write(tmp_path, text)
    with pytest.warns(MjcfIgnoredWarning):
        robot = load_mjcf(path)
    assert list(robot.gravity) == [0, 0, 0]
    assert float(robot.links["a"].floats("mass")) == (2 if mode != "true" else pytest.approx(48))
    assert compare_with_mujoco(path, robot) < TOL


def test_include_files_against_mujoco(tmp_path):
    """Included files are relative to the main file's directory, also inside an included file."""
    (tmp_path / "parts").mkdir()
    write(
        tmp_path, '<mujoco><body name="b" pos="1 0 0"><joint name="j2"/><geom size="0.1"/></body></mujoco>', "arm.xml"
    )
    write(
        tmp_path,
        '<mujoco><compiler angle="radian"/><default><joint damping="0.3"/></default></mujoco>',
        "parts/settings.xml",
    )
    write(tmp_path, '<mujoco><include file="arm.xml"/></mujoco>', "parts/arm.xml")
    main = write(
        tmp_path,
        '<mujoco><include file="parts/settings.xml"/><worldbody>'
        '<body name="a" euler="0 1.2 0"><joint name="j1"/><geom size="0.2"/>'
        '<include file="parts/arm.xml"/></body></worldbody></mujoco>',
    )
    robot = load_mjcf(main)
    assert float(robot.joints[1].damping) == 0.3
    assert compare_with_mujoco(main, robot) < TOL


def test_mujoco_test_model_with_its_unsupported_parts_changed(tmp_path):
    """MuJoCo's own test model (shipped in its wheel): its ball joint made a hinge, its mesh
    a sphere, its free bodies welded (armdyn: floating='weld'; MuJoCo: the free joints
    removed); everything else as written: defaults, several joints per body, fromto
    geoms, tendons, actuators, sensors. MuJoCo's springs and fluid forces are switched off
    (armdyn lists them as ignored)."""
    mujoco = pytest.importorskip("mujoco")
    source = Path(mujoco.__file__).parent / "testdata" / "model.xml"
    if not source.is_file():
        pytest.skip(f"mujoco {mujoco.__version__} ships no testdata/model.xml")
    text = source.read_text().replace('type="ball"', 'type="hinge"')
    text = text.replace('type="mesh" mesh="icosahedron"', 'type="sphere"')
    text = text.replace('<joint type="hinge" axis="0 1 0"/>', '<joint name="tilt" type="hinge" axis="0 1 0"/>')
    path = write(tmp_path, text)
    with pytest.warns(MjcfIgnoredWarning) as record:
        robot = load_mjcf(path, floating="weld")
    for word in ("<tendon>", "joint stiffness", "<option viscosity>", "free joint read as a fixed base"):
        assert word in str(record[0].message)
    welded = re.sub(r"<keyframe>.*?</keyframe>", "", text.replace("<freejoint/>", ""), flags=re.S)
    assert robot.dof == 11
    assert compare_with_mujoco(write(tmp_path, welded, "welded.xml"), robot, springs=False) < TOL


# ------------------------------------------ MuJoCo's own MJCF from example-robot-data


@pytest.mark.parametrize("urdf", ["ur_description/urdf/ur5_robot.urdf", "panda_description/urdf/panda.urdf"])
def test_mjcf_written_by_mujoco_from_urdf(tmp_path, urdf):
    from optional import example_robot_data_dir

    mujoco = pytest.importorskip("mujoco")
    text = (example_robot_data_dir() / urdf).read_text()
    # the meshes are not installed where the URDF points; they only make contacts
    text = re.sub(r"<(visual|collision)>.*?</\1>", "", text, flags=re.S)
    model = mujoco.MjModel.from_xml_string(text)
    path = tmp_path / "robot.xml"
    mujoco.mj_saveLastXML(str(path), model)
    assert compare_with_mujoco(path) < TOL


# ------------------------------------------------------------------ bad input


def one_body(joint: str = "<joint/>", inertial: str = '<inertial pos="0 0 0" mass="1" diaginertia="1 1 1"/>'):
    return f"<mujoco><worldbody><body name='b'>{joint}{inertial}</body></worldbody></mujoco>"


@pytest.mark.parametrize(
    "text, words",
    [
        (
            one_body("<joint name='s' type='ball' damping='1 2'/>"),
            r"<joint name='s'>: damping \[1.0, 2.0\]: a nonlinear damping polynomial",
        ),
        (
            "<mujoco><worldbody><body><body name='b'><freejoint name='f'/></body></body></worldbody></mujoco>",
            "<freejoint name='f'>: free joint in a body that is not a child of the world body",
        ),
        (one_body("<freejoint name='f'/><joint/>"), "<freejoint name='f'>: a free joint must be its body's only"),
        (one_body("<joint type='screw'/>"), "unknown joint type 'screw'"),
        (one_body("<joint axis='0 0 0'/>"), "axis is zero"),
        (one_body("<joint axis='0 1'/>"), "'axis' is '0 1': expected 3 numbers"),
        (one_body("<joint damping='nan'/>"), "'nan' is not a finite number"),
        (one_body("<joint damping='-1'/>"), "damping -1.0 is negative"),
        (one_body("<joint class='nope'/>"), "unknown default class 'nope'"),
        (one_body("<joint dampng='1'/>"), "<joint>: unknown attribute 'dampng'"),
        (one_body("<joint damping='1 0.5'/>"), "nonlinear damping polynomial is not supported"),
        (one_body("<joint springdamper='0.1 1'/>"), "springdamper .* is not supported"),
        ("<mujoco><default><geom sise='1'/></default></mujoco>", "<geom>: unknown attribute 'sise'"),
        (one_body(inertial="<inertial pos='0 0 0' mass='1' diaginertia='1 1 1' qat='1 0 0 0'/>"), "attribute 'qat'"),
        (one_body(inertial="<inertial mass='1' diaginertia='1 1 1'/>"), "<inertial> has no 'pos'"),
        (one_body(inertial="<inertial pos='0 0 0' mass='1'/>"), "needs one of 'diaginertia' and 'fullinertia'"),
        (
            one_body(inertial="<inertial pos='0 0 0' mass='1' diaginertia='1 1 1' quat='1 0 0 0' euler='0 0 0'/>"),
            "more than one orientation",
        ),
        (one_body(inertial="<geom type='mesh' mesh='m'/>"), "body 'b' has no <inertial>.*mesh geom"),
        (one_body(inertial="<geom type='hfield'/>"), "hfield geom"),
        (one_body(inertial="<geom type='capsule' size='0.1'/>"), "capsule needs 2 positive size numbers"),
        (one_body(inertial="<composite/>"), "<composite> is not supported"),
        (one_body(inertial="<wing/>"), "unknown element <wing> in <body>"),
        ("<robot name='r'/>", "the root element is <robot>, expected <mujoco>"),
        (
            "<mujoco><worldbody><body name='a&#10;b'/></worldbody></mujoco>",
            r"<body name='a\\nb'>: name: expected a name",
        ),
        ("<mujoco><worldbody><joint/></worldbody></mujoco>", "cannot be in the world body"),
        ("<mujoco><default><inertial mass='1'/></default></mujoco>", "no inertial defaults"),
        ("<mujoco><compiler angle='grad'/></mujoco>", "angle is 'grad'"),
        ("<mujoco><compiler eulerseq='xyw'/></mujoco>", "eulerseq is 'xyw'"),
        ("<mujoco><compiler settotalmass='3'/></mujoco>", "settotalmass .* is not supported"),
        ("<mujoco><worldbody><body name='b'/><body name='b'/></worldbody></mujoco>", "the name 'b' is used twice"),
        ("<mujoco>\n<worldbody>\n<body>\n</worldbody></mujoco>", "<mjcf>:4: column 3: malformed XML: mismatched tag"),
    ],
)
def test_bad_input_is_one_clear_error(text, words):
    with pytest.raises(ModelError, match=words) as err:
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            load_mjcf(text)
    assert "\n" not in str(err.value)


def test_errors_name_file_and_line(tmp_path):
    path = write(
        tmp_path,
        "<mujoco>\n<worldbody>\n<body name='b'>\n<joint name='s' type='ball' damping='1 2'/>\n</body>\n</worldbody>\n</mujoco>",
    )
    with pytest.raises(ModelError) as err:
        armdyn.load(path)
    assert str(err.value).startswith(f"{path}:4: <joint name='s'>: damping [1.0, 2.0]: a nonlinear damping polynomial")


def test_free_joint_is_welded_on_request(tmp_path):
    text = """<mujoco><worldbody><body name="base" pos="0 0 1" euler="0 0 90"><freejoint name="float"/>
      <inertial pos="0 0 0" mass="5" diaginertia="1 1 1"/>
      <body name="arm" pos="0.5 0 0"><joint name="j" axis="0 1 0"/><inertial pos="0.2 0 0" mass="1" diaginertia="0.1 0.1 0.1"/>
      </body></body></worldbody></mujoco>"""
    path = write(tmp_path, text)
    assert armdyn.load(path).floating  # the free body floats unless welded
    with pytest.warns(MjcfIgnoredWarning, match="fixed base"):
        robot = armdyn.load(path, floating="weld")
    assert robot.dof == 1 and robot.joints[0].type == "fixed"
    with pytest.raises(ModelError, match="floating= applies to MJCF"):
        armdyn.load("rp-arm", floating="weld")
    # welded at its pose (turned 90 degrees about z): the joint axis is the world's -x, the
    # arm's centre of mass 0.2 along +y from it; holding 1 kg there takes -(0.2 * 9.81) about -x
    tau = numeric.rnea(robot, np.zeros(1), np.zeros(1), np.zeros(1))
    assert abs(tau[0] - (-0.2 * 9.81)) < 1e-12


@pytest.mark.parametrize("encoding", ["utf-8", "utf-16"])
def test_dtd_and_entities_are_refused(encoding):
    bomb = f'<?xml version="1.0" encoding="{encoding}"?>\n<!DOCTYPE m [<!ENTITY a "aaaa"><!ENTITY b "&a;&a;&a;">]>\n'
    with pytest.raises(ModelError, match="<!DOCTYPE> on line 2: a DTD is not allowed in MJCF"):
        load_mjcf((bomb + '<mujoco model="&b;"/>').encode(encoding))


def test_mutated_files_give_one_line_model_errors_only():
    """Random cuts and insertions into the models above: each loads or is one ModelError
    line (no other exception, no message over several lines)."""
    rng = random.Random(7)
    pieces = ['"', "<", ">", "/", " ", "-1", "1e400", "nan", "=", "class", "body", "joint", "frame", "euler"]
    pieces += ["quat", '"0 0 0"', "type", "ball", "&#10;", "x", "inertial", "geom", "fromto"]
    for _ in range(300):
        text = list(rng.choice([SIX_JOINTS, RP_ARM, MULTI_JOINT, GEOMS_ONLY, PLANAR_2R]))
        for _ in range(rng.randint(1, 4)):
            k = rng.randrange(len(text))
            if rng.random() < 0.5:
                del text[k : k + rng.randint(1, 5)]
            else:
                text.insert(k, rng.choice(pieces))
        try:
            with warnings.catch_warnings():
                warnings.simplefilter("ignore")
                load_mjcf("".join(text))
        except ModelError as err:
            assert "\n" not in str(err)


def test_includes_are_bounded(tmp_path):
    write(tmp_path, '<mujoco><include file="b.xml"/></mujoco>', "a.xml")
    write(tmp_path, '<mujoco><include file="a.xml"/></mujoco>', "b.xml")
    with pytest.raises(ModelError, match=r"b.xml:1: <include>: include loop: a.xml -> b.xml -> a.xml"):
        load_mjcf(tmp_path / "a.xml")
    for k in range(20):
        write(tmp_path, f'<mujoco><include file="d{k + 1}.xml"/></mujoco>', f"d{k}.xml")
    with pytest.raises(ModelError, match="includes nested deeper than 16"):
        load_mjcf(tmp_path / "d0.xml")
    write(tmp_path, '<mujoco><include file="x.xml"/><include file="x.xml"/></mujoco>', "twice.xml")
    write(tmp_path, "<mujoco/>", "x.xml")
    with pytest.raises(ModelError, match="included twice"):
        load_mjcf(tmp_path / "twice.xml")
    with pytest.raises(ModelError, match="cannot include 'missing.xml': no such file"):
        load_mjcf(write(tmp_path, '<mujoco><include file="missing.xml"/></mujoco>', "m.xml"))
    with pytest.raises(ModelError, match="needs the model read from its file"):
        load_mjcf('<mujoco><include file="x.xml"/></mujoco>')


def test_huge_counts_and_deep_nesting_end_in_bounded_time():
    start = time.perf_counter()
    deep = 3000
    text = (
        "<mujoco><worldbody>" + "<body><joint/><geom size='0.1'/>" * deep + "</body>" * deep + "</worldbody></mujoco>"
    )
    robot = load_mjcf(text)
    assert robot.dof == deep
    sites = "<site/>" * 200_000
    with pytest.warns(MjcfIgnoredWarning, match=r"<site> x200000"):
        load_mjcf(f"<mujoco><worldbody><body><joint/><geom size='1'/>{sites}</body></worldbody></mujoco>")
    classes = "".join(f"<default class='c{k}'>" for k in range(150)) + "</default>" * 150
    with pytest.raises(ModelError, match="nested deeper than 100"):
        load_mjcf(f"<mujoco><default>{classes}</default></mujoco>")
    assert time.perf_counter() - start < 60


def test_made_up_names_never_take_the_files_names():
    text = """<mujoco><worldbody>
      <body name="a"><inertial pos="0 0 0" mass="1" diaginertia="1 1 1"/>
        <body name="b"><joint name="j"/><joint name="k"/><inertial pos="0 0 0" mass="1" diaginertia="1 1 1"/></body>
        <body name="b_j"><joint name="a_fixed"/><inertial pos="0 0 0" mass="1" diaginertia="1 1 1"/></body>
      </body></worldbody></mujoco>"""
    robot = load_mjcf(text)
    assert sorted(j.name for j in robot.joints) == ["a_fixed", "a_fixed_", "j", "k"]
    assert robot.joints[0].name == "a_fixed_" and robot.joints[0].type == "fixed"
    assert robot.meta["intermediate_links"] == ["b_j_"]


def test_massless_body_is_reported():
    text = "<mujoco><worldbody><body name='hub'><joint/><body name='tip' pos='1 0 0'><joint/><geom size='0.1'/></body></body></worldbody></mujoco>"
    with pytest.warns(UserWarning, match=r"massless: \['hub'\]"):
        robot = load_mjcf(text)
    assert robot.meta["massless_links"] == ["hub"]
