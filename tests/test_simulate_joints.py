"""armdyn.simulate for joints of several coordinates (spherical on SO(3), planar on
SE(2), free on SE(3); Rust's ``algo::integrate_floating`` with ``algo::manifold``),
fixed or floating base, against second opinions:

* a ball pendulum conserves its energy, written here by hand (``T = 1/2 w^T I_O w``,
  ``V = m g z_c``), and keeps a unit quaternion; spun about the vertical through its
  centre of mass it turns at a constant rate (``q = (0, 0, sin wt/2, cos wt/2)``);
  a symmetric top without gravity precesses as Euler's equations' closed form and
  keeps its world angular momentum;
* RK4 is fourth order on the manifold (the error / 16 when dt halves), semi-implicit
  Euler first order, against a fine-step reference;
* a semi-implicit Euler step is ``v' = v + h aba(q, v)``, ``q' = integrate(q, h v')``
  with :func:`armdyn.configuration.integrate` (NumPy, a separate implementation of the
  groups' exponentials), on random trees of every joint kind;
* MuJoCo's RK4 rollout of the same MJCF (a ball pendulum, a chain of hinges and balls)
  ends where armdyn's does;
* a puck on a planar joint (gravity along the plane's normal) slides at a constant
  world velocity of its centre of mass and turns at a constant rate;
* batches equal single runs bit for bit; targets and torques of the wrong widths and
  non-unit quaternions are refused.
"""

from __future__ import annotations

import warnings

import numpy as np
import pytest
from optional import mujoco, needs_mujoco
from random_models import random_robot

import armdyn
from armdyn import numeric as num
from armdyn.io import with_root_joint
from armdyn.io.mjcf import MjcfIgnoredWarning
from armdyn.io.mjcf_state import from_mujoco_state, to_mujoco_state
from armdyn.model import Joint, Link, Robot
from armdyn.simulate import PD, simulate

ROD_MASS, ROD_COM = 2.0, np.array([0.0, 0.0, -0.6])
ROD_INERTIA = np.diag([0.1, 0.12, 0.02])  # about the centre of mass


def ball_pendulum(gravity=(0.0, 0.0, -9.81)) -> Robot:
    rod = Link("rod", ROD_MASS, tuple(ROD_COM), ROD_INERTIA.tolist())
    return Robot("ball", [Link("base"), rod], [Joint("ball", "spherical", "base", "rod")], gravity=gravity)


def rotation(quat) -> np.ndarray:
    """R of unit quaternions (x, y, z, w) on the last axis, written out here."""
    x, y, z, w = np.moveaxis(np.asarray(quat), -1, 0)
    R = np.array(
        [
            [1 - 2 * (y * y + z * z), 2 * (x * y - z * w), 2 * (x * z + y * w)],
            [2 * (x * y + z * w), 1 - 2 * (x * x + z * z), 2 * (y * z - x * w)],
            [2 * (x * z - y * w), 2 * (y * z + x * w), 1 - 2 * (x * x + y * y)],
        ]
    )
    return np.moveaxis(R, (0, 1), (-2, -1))


def test_ball_pendulum_conserves_energy_and_a_unit_quaternion():
    robot = ball_pendulum()
    I_O = ROD_INERTIA + ROD_MASS * (ROD_COM @ ROD_COM * np.eye(3) - np.outer(ROD_COM, ROD_COM))
    q0 = np.array([np.sin(0.4), 0.0, np.sin(0.2), 0.0])
    q0[3] = np.sqrt(1 - q0 @ q0)
    run = simulate(robot, q0, [0.5, -1.0, 2.0], dt=1e-3, duration=1.0)
    assert run.q.shape == (1001, 4) and run.qd.shape == (1001, 3)
    kinetic = 0.5 * np.einsum("si,ij,sj->s", run.qd, I_O, run.qd)
    potential = ROD_MASS * 9.81 * (rotation(run.q) @ ROD_COM)[:, 2]
    energy = kinetic + potential
    assert np.ptp(energy) < 1e-10 * abs(energy[0])
    assert np.ptp(kinetic) > 1.0  # it swings: the energy moves between its forms
    np.testing.assert_allclose(run.kinetic, kinetic, rtol=1e-12, atol=1e-12)
    np.testing.assert_allclose(run.potential - run.potential[0], potential - potential[0], rtol=0, atol=1e-11)
    assert np.abs(np.linalg.norm(run.q, axis=1) - 1).max() < 1e-14
    euler = simulate(robot, q0, [0.5, -1.0, 2.0], dt=1e-3, duration=1.0, method="euler")
    assert np.abs(np.linalg.norm(euler.q, axis=1) - 1).max() < 1e-14


def test_ball_pendulum_spins_about_the_vertical():
    """Hanging straight down, turning at w about the vertical (a principal axis of the
    inertia about the pivot, through the centre of mass): no torque, a steady turn."""
    w = 5.0
    run = simulate(ball_pendulum(), [0.0, 0.0, 0.0, 1.0], [0.0, 0.0, w], dt=1e-3, duration=2.0, stride=10)
    half = 0.5 * w * run.t
    want = np.stack([0 * half, 0 * half, np.sin(half), np.cos(half)], axis=-1)
    np.testing.assert_allclose(run.q, want, rtol=0, atol=1e-12)
    np.testing.assert_allclose(run.qd, np.tile([0.0, 0.0, w], (len(run.t), 1)), rtol=0, atol=1e-12)


@pytest.mark.parametrize("method, tol", [("rk4", 1e-9), ("euler", 2e-2)])
def test_symmetric_top_precesses_as_euler_equations(method, tol):
    """No gravity, the centre of mass on the pivot, I = diag(I1, I1, I3): w3 constant,
    (w1, w2) turning at W = (I3 - I1) / I1 w3 (w1 = a cos Wt, w2 = a sin Wt), and the
    world angular momentum R I w constant."""
    I1, I3 = 0.3, 0.5
    top = Link("top", 1.0, (0.0, 0.0, 0.0), [[I1, 0, 0], [0, I1, 0], [0, 0, I3]])
    robot = Robot("top", [Link("base"), top], [Joint("ball", "spherical", "base", "top")], gravity=(0, 0, 0))
    a, w3 = 1.2, 3.0
    quat = np.array([0.2, -0.4, 0.1, 0.0])
    quat[3] = np.sqrt(1 - quat @ quat)
    run = simulate(robot, quat, [a, 0.0, w3], dt=1e-3, duration=2.0, stride=100, method=method)
    W = (I3 - I1) / I1 * w3
    want = np.stack([a * np.cos(W * run.t), a * np.sin(W * run.t), np.full_like(run.t, w3)], axis=-1)
    np.testing.assert_allclose(run.qd, want, rtol=0, atol=tol)
    L = np.einsum("sij,jk,sk->si", rotation(run.q), np.diag([I1, I1, I3]), run.qd)
    np.testing.assert_allclose(L, np.tile(L[0], (len(L), 1)), rtol=0, atol=tol)


def chain(floating: bool) -> Robot:
    """A ball joint, a hinge, then a planar joint and a ball below (or, with a floating
    base, a free joint at the end), gravity -z."""

    def body(name, m, com):
        return Link(name, m, com, [[0.02, 0.001, 0.0], [0.001, 0.03, 0.002], [0.0, 0.002, 0.04]])

    links = [
        body("base", 3.0, (0.0, 0.0, 0.1)),
        body("a", 1.5, (0.05, 0.0, -0.3)),
        body("b", 1.0, (0.0, 0.02, -0.25)),
        body("c", 0.7, (0.1, 0.0, 0.0)),
        body("d", 0.5, (0.0, 0.0, -0.2)),
    ]
    last = "floating" if floating else "spherical"
    joints = [
        Joint("ball", "spherical", "base", "a"),
        Joint("hinge", "revolute", "a", "b", axis=(0, 1, 0), xyz=(0, 0, -0.5)),
        Joint("slide", "planar", "b", "c", xyz=(0, 0, -0.4)),
        Joint("end", last, "c", "d", xyz=(0.2, 0, 0)),
    ]
    return Robot("chain", links, joints, root_joint="free-flyer" if floating else None)


def start(robot: Robot, seed: int):
    rng = np.random.default_rng(seed)
    return num.random_configuration(robot, rng), rng.uniform(-1.5, 1.5, robot.nv)


def gap(robot, q, v, q_ref, v_ref) -> float:
    return max(np.abs(num.difference(robot, q_ref, q)).max(), np.abs(v - v_ref).max())


@pytest.mark.parametrize("floating", [False, True], ids=["fixed", "floating"])
def test_orders_against_a_fine_reference(floating):
    robot = chain(floating)
    q0, v0 = start(robot, 3)
    duration = 0.4
    ref = simulate(robot, q0, v0, dt=duration / 1280, duration=duration, energies=False)
    errors = {}
    for method, dts in (("rk4", (0.02, 0.01)), ("euler", (0.002, 0.001))):
        errors[method] = [
            gap(robot, run.q_final, run.qd_final, ref.q_final, ref.qd_final)
            for run in (simulate(robot, q0, v0, dt=dt, duration=duration, method=method, energies=False) for dt in dts)
        ]
    rk4, euler = errors["rk4"], errors["euler"]
    assert 12 < rk4[0] / rk4[1] < 20, rk4
    assert 1.7 < euler[0] / euler[1] < 2.3, euler
    # the reference's own error (RK4 at dt / 64) is far below both
    assert rk4[1] > 1e-9


@pytest.mark.parametrize("floating", [False, True], ids=["fixed", "floating"])
def test_energy_of_a_chain_is_conserved(floating):
    robot = chain(floating)
    q0, v0 = start(robot, 4)
    run = simulate(robot, q0, v0, dt=1e-3, duration=1.0, stride=50)
    energy = run.kinetic + run.potential
    assert np.ptp(energy) < 1e-8 * max(1.0, np.abs(energy).max()), np.ptp(energy)
    assert np.ptp(run.potential) > 0.1  # gravity does work inside the run


@pytest.mark.parametrize("seed", range(6))
def test_euler_step_is_configuration_integrate(seed):
    """One semi-implicit Euler step by hand, with the NumPy exponentials of
    armdyn.configuration, on a random tree of every joint kind (fixed base for even
    seeds, floating for odd ones)."""
    rng = np.random.default_rng(seed)
    while True:
        robot = random_robot(rng, n_joints=5, tree=True, kinds="RPFSLX")
        if robot.multi_dof_joints:
            break
    if seed % 2:
        robot = with_root_joint(robot, "free-flyer")
    q0 = num.random_configuration(robot, rng)
    v0 = rng.uniform(-1, 1, robot.nv)
    h = 1e-2
    v1 = v0 + h * num.aba(robot, q0, v0, np.zeros(robot.nv))
    q1 = num.integrate(robot, q0, h * v1)
    run = simulate(robot, q0, v0, dt=h, steps=1, method="euler", energies=False)
    np.testing.assert_allclose(run.qd_final, v1, rtol=0, atol=1e-13)
    np.testing.assert_allclose(run.q_final, q1, rtol=0, atol=1e-13)


PENDULUM = """<mujoco><option><flag contact="disable"/></option><worldbody>
  <body name="rod" pos="0 0 1"><joint name="ball" type="ball"/>
    <geom type="capsule" fromto="0 0 0 0.1 0 -0.6" size="0.03" mass="2"/>
    {inside}</body>
</worldbody></mujoco>"""

CHAIN = """<body name="arm" pos="0.1 0 -0.6"><joint name="hinge" axis="0 1 0"/>
      <geom type="capsule" fromto="0 0 0 0 0.1 -0.4" size="0.03" mass="1"/>
      <body name="tip" pos="0 0.1 -0.4"><joint name="wrist" type="ball"/>
        <geom type="box" pos="0.05 0 -0.1" size="0.05 0.03 0.1" mass="0.5"/>
        <body name="end" pos="0 0 -0.2"><joint name="pin" axis="1 0 0"/>
          <geom type="sphere" pos="0 0 -0.1" size="0.04" mass="0.3"/></body></body></body>"""


@needs_mujoco
@pytest.mark.parametrize("inside", ["", CHAIN], ids=["ball", "chain"])
def test_rollout_against_mujoco_rk4(tmp_path, inside):
    """MuJoCo's RK4 (contacts off) and armdyn's from the same state: the methods differ
    (MuJoCo's stages move the quaternion by each stage's own velocity, armdyn's by the
    Munthe-Kaas rate), so they agree to their truncation errors: the gap is small and
    shrinks at least 8-fold when dt halves (both fourth order, one solution)."""
    path = tmp_path / "pendulum.xml"
    path.write_text(PENDULUM.format(inside=inside))
    with warnings.catch_warnings():  # the contact flag is not rigid-body dynamics: ignored, said so
        warnings.simplefilter("ignore", MjcfIgnoredWarning)
        robot = armdyn.load(str(path))
    q0, v0 = start(robot, 8)
    gaps = []
    for dt in (4e-3, 2e-3):
        model = mujoco.MjModel.from_xml_path(str(path))
        model.opt.integrator = mujoco.mjtIntegrator.mjINT_RK4
        model.opt.timestep = dt
        data = mujoco.MjData(model)
        data.qpos[:], data.qvel[:] = to_mujoco_state(robot, q0, v0)
        steps = round(0.5 / dt)
        for _ in range(steps):
            mujoco.mj_step(model, data)
        run = simulate(robot, q0, v0, dt=dt, steps=steps, energies=False)
        q, v = from_mujoco_state(robot, data.qpos.copy(), data.qvel.copy())
        gaps.append(gap(robot, run.q_final, run.qd_final, q, v) / max(1.0, np.abs(v).max()))
    assert gaps[0] < 1e-7, gaps
    assert gaps[1] < max(gaps[0] / 8, 1e-12), gaps  # (a lone ball: both at rounding already)


def test_puck_slides_and_turns_as_the_closed_form():
    """A puck on a planar joint in the x-y plane, gravity along -z (the plane's normal:
    no force in the plane), its centre of mass off the joint's origin: the centre of mass
    moves at a constant world velocity, the puck turns at a constant rate."""
    c = np.array([0.1, -0.05, 0.0])
    puck = Link("puck", 1.3, tuple(c), [[0.01, 0, 0], [0, 0.02, 0], [0, 0, 0.03]])
    robot = Robot("puck", [Link("table"), puck], [Joint("slide", "planar", "table", "puck")])
    th0, wz = 0.3, 2.5
    q0 = [0.2, -0.1, np.cos(th0), np.sin(th0)]
    u = np.array([0.4, 0.7])  # the centre of mass's world velocity
    R0 = np.array([[np.cos(th0), -np.sin(th0)], [np.sin(th0), np.cos(th0)]])
    # the joint origin's velocity in the moving axes: R^T (u - wz k x R c)
    v0 = [*(R0.T @ (u - wz * np.array([-(R0 @ c[:2])[1], (R0 @ c[:2])[0]]))), wz]
    # the origin's velocity in the moving axes turns with them (the twist is not
    # constant): the centre of mass to RK4's truncation error, first order for Euler
    for method, tol in (("rk4", 1e-11), ("euler", 2e-2)):
        run = simulate(robot, q0, v0, dt=1e-3, duration=3.0, stride=100, method=method)
        th = th0 + wz * run.t
        np.testing.assert_allclose(run.q[:, 2:], np.stack([np.cos(th), np.sin(th)], axis=-1), rtol=0, atol=1e-12)
        R = np.moveaxis(np.array([[np.cos(th), -np.sin(th)], [np.sin(th), np.cos(th)]]), -1, 0)
        com = run.q[:, :2] + R @ c[:2]
        want = (np.array(q0[:2]) + R0 @ c[:2]) + run.t[:, None] * u
        np.testing.assert_allclose(com, want, rtol=0, atol=tol)
        np.testing.assert_allclose(run.qd[:, 2], wz, rtol=0, atol=1e-12)


@pytest.mark.parametrize("floating", [False, True], ids=["fixed", "floating"])
def test_batches_equal_single_runs(floating):
    robot = chain(floating)
    rng = np.random.default_rng(9)
    q0 = np.stack([num.random_configuration(robot, rng) for _ in range(11)])  # lane groups and leftovers
    v0 = rng.uniform(-1, 1, (11, robot.nv))
    for method in ("rk4", "euler"):
        batch = simulate(robot, q0, v0, dt=2e-3, steps=60, stride=20, method=method, threads=2)
        assert batch.q.shape == (11, 4, robot.nq) and batch.qd.shape == (11, 4, robot.nv)
        for r in range(11):
            one = simulate(robot, q0[r], v0[r], dt=2e-3, steps=60, stride=20, method=method, threads=1)
            for name in ("q", "qd", "qdd", "tau", "work", "kinetic", "potential", "q_final", "qd_final"):
                np.testing.assert_array_equal(getattr(batch, name)[r], getattr(one, name), err_msg=name)


def test_bad_targets_torques_and_quaternions_refused():
    """A controller's target is a configuration (nq), a callable's torque nv wide; a
    quaternion off unit length is named. (Controllers and callables: test_simulate_control_joints.py.)"""
    robot = ball_pendulum()
    q0 = [0.0, 0.0, 0.0, 1.0]
    with pytest.raises(ValueError, match=r"controller.target \(a configuration\): expected \(4,\)"):
        simulate(robot, q0, dt=1e-3, steps=2, controller=PD(kp=1.0, kd=1.0, target=np.zeros(3)))
    with pytest.raises(ValueError, match=r"controller.target\[0:4\] of joint 'ball'"):
        simulate(robot, q0, dt=1e-3, steps=2, controller=PD(kp=1.0, kd=1.0, target=[0.0, 0.0, 0.0, 2.0]))
    with pytest.raises(ValueError, match=r"returned shape \(4,\) at step 0.*expected \(3,\)"):
        simulate(robot, q0, dt=1e-3, steps=2, torque=lambda t, q, qd: np.zeros(4))
    with pytest.raises(ValueError, match=r"quaternion of joint 'ball' q\[0:4\]"):
        simulate(robot, [0.0, 0.0, 0.0, 1.1], dt=1e-3, steps=2)
    with pytest.raises(ValueError, match=r"shape \(3,\), expected \(4,\)"):
        simulate(robot, [0.0, 0.0, 1.0], dt=1e-3, steps=2)


def test_limits_report_the_hinge_in_velocity_coordinates():
    """A mixed chain whose hinge leaves its range: limit_joint indexes v (the ball's three
    coordinates first), named by coordinate_names."""
    robot = chain(False)
    q0 = num.neutral(robot)
    v0 = np.zeros(robot.nv)
    v0[3] = 2.0  # the hinge
    run = simulate(robot, q0, v0, dt=1e-3, steps=200, limits=(np.full(robot.dof, -0.1), np.full(robot.dof, 0.1)))
    assert run.coordinate_names[run.limit_joint] == "hinge"
    assert 40 < run.limit_step < 60  # about 0.1 rad / 2 rad/s


def test_progress_pieces_equal_one_run():
    """A run cut into pieces (``progress``) continues each from the last one's q_final
    (nq wide): the same bits as one call."""
    robot = chain(True)
    q0, v0 = start(robot, 12)
    seen = []
    one = simulate(robot, q0, v0, dt=2e-3, steps=300, stride=3)
    cut = simulate(robot, q0, v0, dt=2e-3, steps=300, stride=3, progress=lambda k, n: seen.append(k))
    assert len(seen) > 10 and seen[-1] == 300
    for name in ("q", "qd", "qdd", "tau", "work", "q_final", "qd_final"):
        np.testing.assert_array_equal(getattr(cut, name), getattr(one, name), err_msg=name)
