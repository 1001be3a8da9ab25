"""Generated code (armdyn.codegen) for a floating base and for spherical (ball) joints,
against two independent second opinions: armdyn's numeric Rust core (Featherstone's
spatial algorithms on Pinocchio's layout) and Pinocchio itself, at random states, to 1e-9.

The code takes Pinocchio's q (quaternions x, y, z, w, normalised inside the code), v and
a; it gives tau, M, g and bias (C v + g). Robots: a free body with an arm, a small
quadruped (URDF, four legs of two joints), a ball pendulum with joint friction, a ball
joint mid-chain; the compiled C (batch and single-state paths), the Python and the NumPy
code. Also: a non-unit quaternion (the rotation of its direction), the fixed-base bias, the
CLI, and what stays refused (C, base parameters). Also a planar-base arm, a free body
mid-tree and a ball hip under a floating base.
"""

from __future__ import annotations

import os
import shutil
import subprocess
import sys

import numpy as np
import pytest
from optional import needs_pinocchio, pin

import armdyn
import armdyn.numeric as an
import armdyn.printing as printing
from armdyn.errors import FloatingBaseError, ModelError
from armdyn.model import Joint, Link, Robot

HAVE_CC = shutil.which(os.environ.get("CC", "cc")) or shutil.which("gcc")
needs_cc = pytest.mark.skipif(not HAVE_CC, reason="no C compiler")

QUADRUPED = """<robot name="quad">
  <link name="body"><inertial><origin xyz="0.02 -0.01 0.03"/><mass value="6"/>
    <inertia ixx="0.08" iyy="0.2" izz="0.25" ixy="0.002" ixz="-0.003" iyz="0.001"/></inertial></link>
{legs}</robot>
"""
LEG = """  <link name="thigh_{k}"><inertial><origin xyz="0 {cy} -0.1"/><mass value="0.9"/>
    <inertia ixx="0.01" iyy="0.012" izz="0.003" ixy="0" ixz="0.0005" iyz="0"/></inertial></link>
  <link name="shin_{k}"><inertial><origin xyz="0.01 0 -0.12"/><mass value="0.3"/>
    <inertia ixx="0.004" iyy="0.004" izz="0.0008" ixy="0" ixz="0" iyz="0.0002"/></inertial></link>
  <joint name="hip_{k}" type="revolute"><parent link="body"/><child link="thigh_{k}"/>
    <origin xyz="{x} {y} -0.05" rpy="0 0 {yaw}"/><axis xyz="1 0 0"/>
    <limit lower="-3" upper="3" effort="1" velocity="1"/></joint>
  <joint name="knee_{k}" type="revolute"><parent link="thigh_{k}"/><child link="shin_{k}"/>
    <origin xyz="0 0 -0.22" rpy="0.1 0 0"/><axis xyz="0 1 0"/>
    <limit lower="-3" upper="3" effort="1" velocity="1"/></joint>
"""


def quadruped_urdf() -> str:
    legs = "".join(
        LEG.format(k=k, x=0.25 * sx, y=0.12 * sy, cy=0.02 * sy, yaw=0.05 * k)
        for k, (sx, sy) in enumerate([(1, 1), (1, -1), (-1, 1), (-1, -1)])
    )
    return QUADRUPED.format(legs=legs)


def inertia(a, b, c, d=0.0):
    return [[a, d, 0.0], [d, b, 0.0], [0.0, 0.0, c]]


def free_body() -> Robot:
    """A free body with one revolute arm (the arm's axis tilted)."""
    body = Link("body", 2.5, [0.1, -0.2, 0.3], [[0.3, 0.01, 0.02], [0.01, 0.4, 0.03], [0.02, 0.03, 0.5]])
    arm = Link("arm", 1.0, [0.2, 0.0, 0.05], inertia(0.01, 0.02, 0.02, 0.001))
    joint = Joint("q1", "revolute", "body", "arm", [0.3, 0.0, 0.1], axis=[0.0, 0.6, 0.8])
    return Robot("free-body", [body, arm], [joint], root_joint="free-flyer")


def one_body() -> Robot:
    body = Link("body", 2.5, [0.1, -0.2, 0.3], [[0.3, 0.01, 0.02], [0.01, 0.4, 0.03], [0.02, 0.03, 0.5]])
    return Robot("one-body", [body], [], root_joint="free-flyer")


def ball_pendulum() -> Robot:
    """A rod on a ball joint, with viscous and Coulomb friction and rotor inertia on it."""
    rod = Link("rod", 2.0, (0.02, 0.01, -0.6), inertia(0.1, 0.12, 0.04, 0.003))
    ball = Joint("ball", "spherical", "base", "rod", [0.0, 0.0, 1.0], damping=0.3, friction=0.2, armature=0.05)
    return Robot("ball-pendulum", [Link("base"), rod], [ball])


def ball_mid_chain() -> Robot:
    """revolute, ball (placed turned and off the parent's origin), revolute, prismatic."""
    rot = [[0.0, -1.0, 0.0], [1.0, 0.0, 0.0], [0.0, 0.0, 1.0]]
    links = [Link("base")]
    links += [Link("upper", 1.2, [0.0, 0.1, -0.1], inertia(0.02, 0.01, 0.015))]
    links += [Link("rod", 2.0, [0.05, 0.0, -0.3], inertia(0.1, 0.12, 0.04, 0.004))]
    links += [Link("hand", 0.5, [0.1, 0.02, -0.05], inertia(0.012, 0.02, 0.01))]
    links += [Link("tool", 0.2, [0.0, 0.0, 0.03], inertia(0.001, 0.001, 0.0005))]
    joints = [
        Joint("q0", "revolute", "base", "upper", [0.0, 0.0, 1.0], axis=[0.0, 1.0, 0.0]),
        Joint("ball", "spherical", "upper", "rod", [0.0, 0.2, -0.3], rotation=rot),
        Joint("q2", "revolute", "rod", "hand", [0.0, 0.0, -0.6], axis=[1.0, 0.0, 0.0]),
        Joint("d3", "prismatic", "hand", "tool", [0.1, 0.0, 0.0], axis=[0.0, 0.0, 1.0]),
    ]
    return Robot("ball-chain", links, joints)


def planar_base_arm(damping: float = 0.1) -> Robot:
    """A body sliding and turning on a tilted plane (planar joint, damped), an arm on it."""
    rot = [[1.0, 0.0, 0.0], [0.0, 0.0, -1.0], [0.0, 1.0, 0.0]]
    links = [Link("ground"), Link("cart", 3.0, [0.05, -0.02, 0.1], inertia(0.05, 0.06, 0.08, 0.002))]
    links += [Link("arm", 0.8, [0.2, 0.0, 0.02], inertia(0.004, 0.02, 0.02))]
    joints = [
        Joint("plane", "planar", "ground", "cart", [0.1, 0.0, 0.2], rotation=rot, damping=damping or None),
        Joint("q1", "revolute", "cart", "arm", [0.1, 0.05, 0.1], axis=[0.0, 0.0, 1.0]),
    ]
    return Robot("planar-arm", links, joints)


def free_mid_tree() -> Robot:
    """A free body hung under a revolute joint, a prismatic joint on it."""
    links = [Link("base"), Link("upper", 1.2, [0.0, 0.1, -0.1], inertia(0.02, 0.01, 0.015))]
    links += [Link("drone", 1.5, [0.02, 0.0, -0.05], inertia(0.03, 0.04, 0.05, 0.001))]
    links += [Link("probe", 0.2, [0.0, 0.0, 0.05], inertia(0.001, 0.001, 0.0005))]
    joints = [
        Joint("q0", "revolute", "base", "upper", [0.0, 0.0, 1.0], axis=[0.0, 1.0, 0.0]),
        Joint("fly", "floating", "upper", "drone", [0.0, 0.2, -0.3]),
        Joint("d2", "prismatic", "drone", "probe", [0.1, 0.0, 0.0], axis=[0.0, 0.0, 1.0]),
    ]
    return Robot("free-mid", links, joints)


def floating_ball_hip() -> Robot:
    """A floating body with a leg on a ball hip and a knee."""
    body = Link("body", 4.0, [0.02, 0.0, 0.05], inertia(0.1, 0.15, 0.2, 0.003))
    thigh = Link("thigh", 0.9, [0.0, 0.02, -0.12], inertia(0.01, 0.012, 0.003))
    shin = Link("shin", 0.3, [0.01, 0.0, -0.1], inertia(0.004, 0.004, 0.0008))
    joints = [
        Joint("hip", "spherical", "body", "thigh", [0.2, 0.1, -0.05], armature=0.01),
        Joint("knee", "revolute", "thigh", "shin", [0.0, 0.0, -0.25], axis=[0.0, 1.0, 0.0]),
    ]
    return Robot("ball-hip", [body, thigh, shin], joints, root_joint="free-flyer")


def quadruped(tmp_path_factory) -> Robot:
    path = tmp_path_factory.mktemp("quad") / "quad.urdf"
    path.write_text(quadruped_urdf())
    return armdyn.load(str(path), root_joint="free-flyer")


def states(robot: Robot, rng, count: int = 11, scale=None):
    """``count`` random (q, v, a) rows (11: one block of 8 lanes through the C batch code
    and 3 through its single-state function); quaternions unit, or of length ``scale``."""
    q = np.empty((count, robot.nq))
    blocks = [(0, 3, 4)] if robot.floating else []  # (first, position width, quaternion) of each group
    blocks += [(iq, 0, 4) for _, kind, iq, _ in robot.configuration_layout if kind == "spherical"]
    blocks += [(iq, 3, 4) for _, kind, iq, _ in robot.configuration_layout if kind == "floating"]
    flat = [iq for _, kind, iq, _ in robot.configuration_layout if kind in ("revolute", "prismatic")]
    q[:, flat] = rng.uniform(-np.pi, np.pi, (count, len(flat)))
    for iq in [iq for _, kind, iq, _ in robot.configuration_layout if kind == "planar"]:
        th = rng.uniform(-np.pi, np.pi, count)
        r = 1.0 if scale is None else scale
        q[:, iq : iq + 4] = np.column_stack([*rng.uniform(-1, 1, (2, count)), r * np.cos(th), r * np.sin(th)])
    for first, width, nquat in blocks:
        q[:, first : first + width] = rng.uniform(-1, 1, (count, width))
        quat = rng.normal(size=(count, nquat))
        quat /= np.linalg.norm(quat, axis=1, keepdims=True)
        q[:, first + width : first + width + 4] = quat * (1.0 if scale is None else scale)
    v, a = rng.uniform(-2, 2, (2, count, robot.nv))
    return q, v, a


def close(got, want, tol=1e-9):
    """Relative to the largest entry; NaN or inf never passes."""
    got, want = np.asarray(got, dtype=float), np.asarray(want, dtype=float)
    assert got.shape == want.shape, (got.shape, want.shape)
    assert np.all(np.isfinite(got)) and np.all(np.isfinite(want))
    np.testing.assert_allclose(got, want, rtol=tol, atol=tol * max(1.0, float(np.abs(want).max())))


def core(robot, q, v, a) -> dict:
    """The numeric core's answers, per quantity."""
    return {
        "tau": an.rnea(robot, q, v, a),
        "M": an.crba(robot, q),
        "g": an.gravity(robot, q),
        "bias": an.bias(robot, q, v),
    }


ARGS = {"tau": (0, 1, 2), "M": (0,), "g": (0,), "bias": (0, 1)}
ROBOTS = {
    "one-body": one_body,
    "free-body": free_body,
    "ball-pendulum": ball_pendulum,
    "ball-chain": ball_mid_chain,
    "planar-arm": planar_base_arm,
    "free-mid": free_mid_tree,
    "ball-hip": floating_ball_hip,
}


def _exec(source) -> dict:
    namespace: dict = {}
    exec(compile(source, "<generated>", "exec"), namespace)
    return namespace


# ------------------------------------------------------------ against the core
@needs_cc
@pytest.mark.parametrize("name", list(ROBOTS))
def test_compiled_c_equals_the_core(name, tmp_path):
    robot = ROBOTS[name]()
    lib = printing.compile(robot, directory=tmp_path)
    assert set(lib.functions) == {"tau", "M", "g", "bias"}  # the default: C does not apply
    assert lib.code.input_names == ("q", "v", "a") and lib.code.parameters == []
    rng = np.random.default_rng(3)
    arrays = states(robot, rng)
    want = core(robot, *arrays)
    for what, f in lib.functions.items():
        close(f(*(arrays[k] for k in ARGS[what])), want[what])
        close(f(*(arrays[k][9] for k in ARGS[what])), want[what][9])  # one state
    assert want["M"].shape == (11, robot.nv, robot.nv)


@needs_cc
def test_compiled_quadruped_equals_the_core_and_pinocchio(tmp_path, tmp_path_factory):
    robot = quadruped(tmp_path_factory)
    assert (robot.nq, robot.nv) == (15, 14)
    # baseline SIMD only: the AVX2 clones (tested on the fixed-base code) double the build time
    lib = printing.compile(robot, what="tau,M,g,bias", directory=tmp_path, flags=["-DARMDYN_NO_CLONES"])
    rng = np.random.default_rng(8)
    arrays = states(robot, rng)
    want = core(robot, *arrays)
    got = {w: f(*(arrays[k] for k in ARGS[w])) for w, f in lib.functions.items()}
    for what in want:
        close(got[what], want[what])
    if pin is None:
        pytest.skip("pinocchio is not installed (the core's comparison ran)")
    model = pin.buildModelFromXML(quadruped_urdf(), pin.JointModelFreeFlyer())
    data = model.createData()
    for k, (q, v, a) in enumerate(zip(*arrays)):
        close(got["tau"][k], pin.rnea(model, data, q, v, a))
        M = pin.crba(model, data, q)
        close(got["M"][k], np.triu(M) + np.triu(M, 1).T)
        close(got["g"][k], pin.computeGeneralizedGravity(model, data, q))
        close(got["bias"][k], pin.nonLinearEffects(model, data, q, v))


def test_one_free_body_is_newton_euler_by_hand():
    """A rigid body alone, written here by hand (base frame, moment about its origin O,
    COM at c, inertia I about the COM, gravity R^T g with R the quaternion's rotation):
    f = m (vd + w x v - R^T g + wd x c + w x (w x c)), n = I wd + w x I w + c x f."""
    robot = one_body()
    code = printing.codegen(robot, what="tau,M", lang="numpy")
    ns = _exec(code.source)
    m, c = 2.5, np.array([0.1, -0.2, 0.3])
    I = np.array([[0.3, 0.01, 0.02], [0.01, 0.4, 0.03], [0.02, 0.03, 0.5]])
    rng = np.random.default_rng(12)
    for q, v, a in zip(*states(robot, rng, count=5)):
        x, y, z, w = q[3:7]
        R = np.array(
            [
                [1 - 2 * (y * y + z * z), 2 * (x * y - w * z), 2 * (x * z + w * y)],
                [2 * (x * y + w * z), 1 - 2 * (x * x + z * z), 2 * (y * z - w * x)],
                [2 * (x * z - w * y), 2 * (y * z + w * x), 1 - 2 * (x * x + y * y)],
            ]
        )
        lin, om, lin_d, om_d = v[:3], v[3:], a[:3], a[3:]
        f = m * (lin_d + np.cross(om, lin) - R.T @ np.array([0, 0, -9.81]) + np.cross(om_d, c))
        f += m * np.cross(om, np.cross(om, c))
        n = I @ om_d + np.cross(om, I @ om) + np.cross(c, f)
        close(ns["one_body_tau"](q, v, a), np.concatenate([f, n]))
        # M: the spatial inertia about O in the base frame
        C = np.array([[0, -c[2], c[1]], [c[2], 0, -c[0]], [-c[1], c[0], 0]])
        M = np.block([[m * np.eye(3), -m * C], [m * C, I - m * C @ C]])
        close(ns["one_body_M"](q), M)


@pytest.mark.parametrize("name", ["free-body", "ball-chain", "planar-arm", "free-mid", "ball-hip"])
def test_python_and_numpy_code_equal_the_core(name):
    robot = ROBOTS[name]()
    rng = np.random.default_rng(5)
    arrays = states(robot, rng, count=3)
    want = core(robot, *arrays)
    py = printing.codegen(robot, lang="python")
    ns = _exec(py.source)
    for what, fn in py.functions.items():
        for k in range(3):
            got = np.array(ns[fn](*(arrays[i][k] for i in ARGS[what])), dtype=float)
            close(got.reshape(want[what][k].shape), want[what][k])
    npy = printing.codegen(robot, lang="numpy")
    ns = _exec(npy.source)
    for what, fn in npy.functions.items():
        close(ns[fn](*(arrays[i] for i in ARGS[what])), want[what])  # a batch
        close(ns[fn](*(arrays[i][1] for i in ARGS[what])), want[what][1])  # one state


@needs_pinocchio
@pytest.mark.parametrize("name", ["ball-pendulum", "ball-chain", "planar-arm", "free-mid"])
def test_joints_of_several_coordinates_equal_pinocchio(name):
    from pinocchio_bridge import PinocchioRobot

    robot = ROBOTS[name]()
    if name == "ball-pendulum":  # Pinocchio's rnea has no joint friction or rotor inertia
        robot = Robot(robot.name, list(robot.links.values()), [Joint("ball", "spherical", "base", "rod", [0, 0, 1.0])])
    if name == "planar-arm":
        robot = planar_base_arm(damping=0.0)
    ref = PinocchioRobot(robot)
    code = printing.codegen(robot, lang="numpy")
    ns = _exec(code.source)
    tau, M, bias = (ns[code.functions[w]] for w in ("tau", "M", "bias"))
    rng = np.random.default_rng(9)
    for q, v, a in zip(*states(robot, rng, count=4)):
        close(tau(q, v, a), ref.rnea(q, v, a))
        close(M(q), ref.crba(q))
        close(bias(q, v), ref.bias(q, v))


def test_symbolic_parameters_and_gravity_go_in_p():
    """rp-arm on a floating base, every parameter symbolic (g included): p in the
    code's order, against the core with the same numbers bound."""
    robot = armdyn.load("rp-arm", root_joint="free-flyer")
    code = printing.codegen(robot, what="tau,g", lang="numpy")
    names = [s.name for s in code.parameters]
    assert "g" in names
    rng = np.random.default_rng(2)
    values = {n: float(rng.uniform(0.5, 2.0)) for n in robot.parameters}
    p = code.parameter_values(values)
    bound = robot.bind(values)
    q, v, a = states(robot, rng, count=5)
    ns = _exec(code.source)
    close(ns["rp_arm_tau"](q, v, a, p), an.rnea(bound, q, v, a))
    close(ns["rp_arm_g"](q, p), an.gravity(bound, q))


# --------------------------------------------------------- the quaternions' length
@needs_cc
@pytest.mark.parametrize("name", ["free-body", "ball-chain", "free-mid"])
def test_a_non_unit_quaternion_is_normalised(name, tmp_path):
    """The documented behaviour: the rotation of q/|q|. The core (which wants unit
    quaternions) at the normalised q is the reference."""
    robot = ROBOTS[name]()
    lib = printing.compile(robot, what="tau,M,g", directory=tmp_path)
    rng = np.random.default_rng(4)
    for scale in (0.3, 2.5):
        q, v, a = states(robot, np.random.default_rng(4), scale=scale)
        unit, _, _ = states(robot, np.random.default_rng(4))
        assert not np.allclose(q, unit)
        close(lib.tau(q, v, a), an.rnea(robot, unit, v, a))
        close(lib.M(q), an.crba(robot, unit))
        close(lib.g(q), an.gravity(robot, unit))
    first, whose = lib.code.quaternions[0]
    q = states(robot, rng, count=1)[0][0]
    q[first : first + 4] = 0.0
    with pytest.raises(ValueError, match=rf"q\[{first}:{first + 4}\], the quaternion of {whose}, is zero"):
        lib.g(q)
    assert "Quaternions are normalised here" in lib.code.source


def test_a_planar_pair_off_unit_length_is_normalised():
    """A planar joint's (cos, sin) of length 0.3 or 2.5 gives the turn of its direction."""
    robot = planar_base_arm()
    code = printing.codegen(robot, what="tau", lang="numpy")
    tau = _exec(code.source)[code.functions["tau"]]
    for scale in (0.3, 2.5):
        q, v, a = states(robot, np.random.default_rng(6), scale=scale)
        unit, _, _ = states(robot, np.random.default_rng(6))
        assert not np.allclose(q, unit)
        close(tau(q, v, a), an.rnea(robot, unit, v, a))


# -------------------------------------------------------------- fixed-base bias
@needs_cc
@pytest.mark.parametrize("name", ["planar-2r", "puma560"])
def test_fixed_base_bias_equals_the_core(name, tmp_path):
    robot = armdyn.load(name, strict=False)
    rng = np.random.default_rng(6)
    robot = robot.bind({p: float(rng.uniform(0.5, 2.0)) for p in robot.parameters if p not in robot.defaults})
    lib = printing.compile(robot, what="bias", directory=tmp_path)
    q, qd = rng.uniform(-np.pi, np.pi, (2, 11, robot.dof))
    close(lib.bias(q, qd), an.bias(robot, q, qd))
    assert lib.code.input_names == ("q", "qd", "qdd")


@needs_cc
def test_base_parameter_bias_equals_the_core(tmp_path):
    """The bias in the base parameters (the customized Newton-Euler at qdd = 0 there), on
    a planar 2R with every parameter symbolic."""
    import sympy as sp
    from test_codegen import _numeric, _random_value, _symbolic_planar_2r

    from armdyn import identification

    robot = _symbolic_planar_2r()
    code = printing.codegen(robot, what="bias,g", base=True)
    assert code.sources["bias"].endswith("at the base parameters")
    rng = np.random.default_rng(7)
    values = {name: _random_value(name, rng) for name in robot.parameters}
    reg = identification.regressor(robot)
    std = {
        str(s): float(sp.sympify(e).xreplace({sp.Symbol(k): v for k, v in values.items()}))
        for s, e in zip(reg.symbols, reg.pi)
    }
    std.update(values)
    lib = printing.compile(code, directory=tmp_path)
    bound = _numeric(robot, values)
    q, qd = rng.uniform(-np.pi, np.pi, (2, 11, 2))
    close(lib.bias(q, qd, p=code.parameter_values(std)), an.bias(bound, q, qd))


# ----------------------------------------------------------------------- refusals
def test_mimic_joints_beside_a_ball_joint_or_a_floating_base_are_refused():
    from armdyn.model.joints import Mimic

    robot = ball_mid_chain()
    links = [*robot.links.values(), Link("extra", 0.3, [0.05, 0, 0], inertia(0.001, 0.002, 0.002))]
    joints = [*robot.joints, Joint("m", "revolute", "tool", "extra", [0.1, 0, 0], mimic=Mimic("q2", 2.0, 0.1))]
    with pytest.raises(ModelError, match="mimic joints beside joints of several coordinates yet \\(joint 'm'\\)"):
        printing.codegen(Robot("mimic", links, joints), what="tau")
    floating = free_body()
    links = [*floating.links.values(), Link("extra", 0.3, [0.05, 0, 0], inertia(0.001, 0.002, 0.002))]
    joints = [*floating.joints, Joint("m", "revolute", "arm", "extra", [0.1, 0, 0], mimic=Mimic("q1", 2.0, 0.1))]
    with pytest.raises(FloatingBaseError, match="mimic joints on a floating base yet \\(joint 'm'\\)"):
        printing.codegen(Robot("mimic", links, joints, root_joint="free-flyer"), what="tau")


def test_c_regressor_and_base_parameters_are_refused():
    floating, ball = free_body(), ball_pendulum()
    with pytest.raises(FloatingBaseError, match="C, the Christoffel matrix.*floating base.*bias"):
        printing.codegen(floating, what="tau,C")
    with pytest.raises(ModelError, match="C, the Christoffel matrix.*spherical joint 'ball'.*bias"):
        printing.codegen(ball, what="C")
    for robot in (floating, ball):
        with pytest.raises(ModelError, match="base=True .*armdyn.identification"):
            printing.codegen(robot, what="tau", base=True)
        with pytest.raises(ModelError, match="the regressor .*armdyn.identification"):
            printing.codegen(robot, what="regressor")


# ---------------------------------------------------------------------------- CLI
def _cli(*args):
    env = dict(os.environ, PYTHONPATH=os.path.join(os.path.dirname(__file__), "..", "python"))
    return subprocess.run([sys.executable, "-m", "armdyn", *args], capture_output=True, text=True, env=env, timeout=600)


@needs_cc
def test_cli_floating_urdf(tmp_path):
    from armdyn.printing.compile import build_shared_library

    model = tmp_path / "body.urdf"
    model.write_text(
        '<robot name="box"><link name="body"><inertial><origin xyz="0.1 0 0"/><mass value="2"/>'
        '<inertia ixx="0.1" iyy="0.2" izz="0.3" ixy="0" ixz="0" iyz="0"/></inertial></link></robot>'
    )
    out = tmp_path / "gen"
    res = _cli("codegen", str(model), "--root-joint", "free-flyer", "--out", str(out))
    assert res.returncode == 0, res.stderr
    assert "box_bias" in res.stdout and "box_C" not in res.stdout
    build_shared_library((out / "box_dynamics.c").read_text(), tmp_path / "build")
    res = _cli("codegen", str(model), "--root-joint", "free-flyer", "--what", "tau,C")
    assert res.returncode == 2 and res.stderr.startswith("armdyn: error:") and "Traceback" not in res.stderr
    assert len(res.stderr.strip().splitlines()) == 1 and str(model) in res.stderr and "bias" in res.stderr
