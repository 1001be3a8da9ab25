"""Controllers and torque callables in armdyn.simulate on joints of several coordinates
(spherical, planar, free) and on a floating base, against second opinions:

* PD drives a ball pendulum (no gravity) to a target orientation, and its Lyapunov
  function ``T + 1/2 kp |e|^2`` (``T = 1/2 w^T I_O w`` written here, ``e`` the tangent
  error) never increases: ``dV/dt = -kd |w|^2`` exactly, since ``e . de/dt = -e . w``
  for ``e = log(R^T R*)``;
* computed torque on an arm of a ball joint and a hinge: an error along one axis of the
  ball stays on that axis, so each block obeys ``e'' + kd e' + kp e = 0`` exactly; the
  errors follow the critically damped closed form ``e0 (1 + w t) exp(-w t)``;
* a torque callable returning Pinocchio's ``computeGeneralizedGravity`` holds a ball
  pendulum still; a callable ``-c qd`` equals MuJoCo's RK4 with the joint damping ``c``,
  a constant one MuJoCo's ``qfrc_applied``;
* a floating robot with PD on its joints and no gravity keeps its linear momentum and
  its angular momentum about the centre of mass (Pinocchio's
  ``computeCentroidalMomentum``): the base rows of tau are zero; with gravity
  compensation the joints' torques at the target are Pinocchio's generalized gravity;
* computed torque on a floating robot (the base unactuated: collocated partial feedback
  linearization) gives its joints the closed form too, zero base rows, and keeps the
  momentum without gravity (Pinocchio);
* simulate_adaptive on the manifold (its embedding): the symmetric top's closed form,
  a pendulum's energy by hand, a floating robot's momentum (Pinocchio); its kinematics
  ``q' = Q(q) v`` against the central difference of armdyn.configuration.integrate;
* ``armdyn simulate --controller --target`` on a ball arm and a floating robot, with
  one-line errors naming the bad value.
"""

from __future__ import annotations

import warnings

import numpy as np
import pytest
from optional import mujoco, needs_mujoco, needs_pinocchio, pin
from test_simulate_joints import PENDULUM, ROD_COM, ROD_INERTIA, ROD_MASS, ball_pendulum, chain, gap

import armdyn
from armdyn import numeric as num
from armdyn.io.mjcf import MjcfIgnoredWarning
from armdyn.io.mjcf_state import from_mujoco_state, to_mujoco_state
from armdyn.model import Joint, Link, Robot
from armdyn.simulate import PD, ComputedTorque, simulate, simulate_adaptive

I_O = ROD_INERTIA + ROD_MASS * (ROD_COM @ ROD_COM * np.eye(3) - np.outer(ROD_COM, ROD_COM))


def quaternion(axis, angle) -> np.ndarray:
    """The unit quaternion (x, y, z, w) of a turn by ``angle`` about ``axis``."""
    axis = np.asarray(axis, dtype=float) / np.linalg.norm(axis)
    return np.array([*(np.sin(angle / 2) * axis), np.cos(angle / 2)])


def quat_mul(a, b) -> np.ndarray:
    """Hamilton product of quaternions (x, y, z, w), written out here."""
    (x1, y1, z1, w1), (x2, y2, z2, w2) = a, b
    return np.array(
        [
            w1 * x2 + x1 * w2 + y1 * z2 - z1 * y2,
            w1 * y2 - x1 * z2 + y1 * w2 + z1 * x2,
            w1 * z2 + x1 * y2 - y1 * x2 + z1 * w2,
            w1 * w2 - x1 * x2 - y1 * y2 - z1 * z2,
        ]
    )


@pytest.mark.parametrize("method", ["rk4", "euler"])
def test_pd_turns_a_ball_pendulum_to_its_target(method):
    robot = ball_pendulum(gravity=(0.0, 0.0, 0.0))
    target = quaternion([1.0, -2.0, 0.5], 2.0)
    q0 = quaternion([0.3, 1.0, -1.0], 0.7)
    kp, kd = 4.0, 3.0
    pd = PD(kp=kp, kd=kd, target=target, gravity_compensation=False)
    run = simulate(robot, q0, [0.5, -0.3, 0.8], dt=1e-3, duration=12.0, method=method, stride=10, controller=pd)
    # e = log(R^T R*): the turn from q to the target in q's frame, by hand (the shorter way)
    rel = np.array([quat_mul(q * [-1, -1, -1, 1], target) for q in run.q])
    rel *= np.sign(rel[:, 3:])
    half = np.arctan2(np.linalg.norm(rel[:, :3], axis=1), rel[:, 3])
    e = rel[:, :3] * (2 * half / np.maximum(np.sin(half), 1e-300))[:, None]
    np.testing.assert_allclose(e, num.difference(robot, run.q, target), rtol=0, atol=1e-12)
    assert np.linalg.norm(e[0]) > 1.0 and np.linalg.norm(e[-1]) < 1e-4
    np.testing.assert_allclose(run.tau, kp * e - kd * run.qd, rtol=0, atol=1e-12)
    lyapunov = 0.5 * np.einsum("si,ij,sj->s", run.qd, I_O, run.qd) + 0.5 * kp * (e * e).sum(axis=1)
    rises = np.diff(lyapunov)
    # monotone up to the integrator's error (RK4: rounding; semi-implicit Euler: O(h) per step)
    assert rises.max() < (1e-12 if method == "rk4" else 1e-4) * lyapunov[0], rises.max()
    assert lyapunov[-1] < 1e-6 * lyapunov[0]


def ball_arm() -> Robot:
    """A ball joint at the shoulder, a hinge at the elbow, gravity -z."""
    upper = Link("upper", 1.5, (0.05, 0.0, -0.3), [[0.02, 0.001, 0.0], [0.001, 0.03, 0.002], [0.0, 0.002, 0.04]])
    fore = Link("fore", 0.8, (0.0, 0.02, -0.2), [[0.01, 0.0, 0.0], [0.0, 0.012, 0.0], [0.0, 0.0, 0.004]])
    joints = [
        Joint("shoulder", "spherical", "base", "upper"),
        Joint("elbow", "revolute", "upper", "fore", axis=(0, 1, 0), xyz=(0, 0, -0.5)),
    ]
    return Robot("ball_arm", [Link("base"), upper, fore], joints)


@pytest.mark.parametrize("method, tol", [("rk4", 1e-9), ("euler", 3e-3)])
def test_computed_torque_error_decays_as_the_closed_form(method, tol):
    robot = ball_arm()
    target = np.array([*quaternion([0.2, 0.9, -0.4], 1.1), 0.6])
    axis, angle, elbow = np.array([1.0, -2.0, 2.0]) / 3.0, 0.8, -0.5
    # q0 = target turned back by the angle about the axis: e(0) = angle * axis (in q0's frame)
    q0 = np.array([*quat_mul(target[:4], quaternion(axis, -angle)), target[4] - elbow])
    kp = np.array([25.0, 25.0, 25.0, 16.0])  # critically damped at 5 and 4 rad/s
    kd = 2.0 * np.sqrt(kp)
    run = simulate(robot, q0, dt=1e-3, duration=3.0, method=method, controller=ComputedTorque(kp, kd, target))
    t = run.t[:, None]
    want = np.concatenate([angle * axis * (1 + 5 * t) * np.exp(-5 * t), elbow * (1 + 4 * t) * np.exp(-4 * t)], axis=1)
    np.testing.assert_allclose(num.difference(robot, run.q, target), want, rtol=0, atol=tol)
    # the velocity is -e' (e = log(R^T R*) along a fixed axis), here -d/dt of the closed form
    want_v = np.concatenate([angle * axis * 25 * t * np.exp(-5 * t), elbow * 16 * t * np.exp(-4 * t)], axis=1)
    np.testing.assert_allclose(run.qd, want_v, rtol=0, atol=10 * tol)


def test_computed_torque_at_a_small_error_in_any_direction():
    """An error and a velocity along different axes: the error dynamics are linear only to
    first order in e, so the closed form holds to O(|e|^2)."""
    robot = ball_arm()
    target = np.array([*quaternion([0.2, 0.9, -0.4], 1.1), 0.6])
    e0, v0 = np.array([1e-3, -2e-3, 0.5e-3, 1e-3]), np.array([0.0, 3e-3, 2e-3, 0.0])
    q0 = num.integrate(robot, target, -e0)
    controller = ComputedTorque(25.0, 10.0, target)
    run = simulate(robot, q0, v0, dt=1e-3, duration=2.0, controller=controller)
    t = run.t[:, None]
    # e' = -v: e(t) = (e0 + (e0' + 5 e0) t) exp(-5 t) with e0' = -v0
    want = (e0 + (-v0 + 5 * e0) * t) * np.exp(-5 * t)
    err = np.abs(num.difference(robot, run.q, target) - want).max()
    half = simulate(robot, num.integrate(robot, target, -e0 / 2), v0 / 2, dt=1e-3, duration=2.0, controller=controller)
    err_half = np.abs(num.difference(robot, half.q, target) - want / 2).max()
    assert err < 0.2 * (e0 @ e0), err  # second order in |e|
    assert 3.5 < err / err_half < 4.5, (err, err_half)


@needs_pinocchio
@pytest.mark.parametrize("method", ["rk4", "euler"])
def test_callable_of_pinocchio_gravity_holds_a_ball_pendulum(method):
    from pinocchio_bridge import configuration_permutation, to_pinocchio

    robot = ball_pendulum()
    model, _, perm = to_pinocchio(robot)
    assert np.array_equal(perm, np.arange(3)) and np.array_equal(configuration_permutation(robot), np.arange(4))
    data = model.createData()
    calls = []

    def gravity(t, q, qd):
        calls.append(q.shape)
        return np.array([pin.computeGeneralizedGravity(model, data, row) for row in q])

    q0 = quaternion([1.0, 0.4, 0.0], 0.9)  # well off the hanging pose: gravity pulls hard
    run = simulate(robot, q0, dt=1e-3, duration=1.0, method=method, torque=gravity)
    assert calls[0] == (1, 4) and len(calls) == (4 if method == "rk4" else 1) * 1000 + 1
    assert np.abs(run.tau[0]).max() > 5.0
    assert np.abs(num.difference(robot, run.q, q0)).max() < 1e-12 and np.abs(run.qd).max() < 1e-12
    # unheld, it falls: the hold is the callable's doing
    free = simulate(robot, q0, dt=1e-3, duration=1.0, method=method)
    assert np.abs(num.difference(robot, free.q_final, q0)).max() > 0.1


DAMPED = PENDULUM.replace('type="ball"/>', 'type="ball" damping="0.05"/>')


@needs_mujoco
@pytest.mark.parametrize("force", ["damping", "applied"])
def test_callable_against_mujoco_rk4(tmp_path, force):
    """A torque callable on a ball joint against MuJoCo's RK4: ``-c qd`` (evaluated at
    every stage) against the joint damping ``c`` (0.05, light: the rod turns easily about
    its axis; MuJoCo evaluates it at every stage too), or a constant torque against
    ``qfrc_applied`` (in the joint's frame, as qvel). The gap is small and shrinks at
    least 8-fold when dt halves."""
    plain, mjcf = tmp_path / "plain.xml", tmp_path / "mujoco.xml"
    plain.write_text(PENDULUM.format(inside=""))
    mjcf.write_text((DAMPED if force == "damping" else PENDULUM).format(inside=""))
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", MjcfIgnoredWarning)
        robot = armdyn.load(str(plain))
    q0, v0 = quaternion([0.3, 1.0, 0.2], 1.2), np.array([1.5, -2.0, 3.0])
    applied = np.array([0.8, -1.5, 0.05])
    torque = (lambda t, q, qd: -0.05 * qd) if force == "damping" else (lambda t, q, qd: applied)
    gaps = []
    for dt in (4e-3, 2e-3):
        model = mujoco.MjModel.from_xml_path(str(mjcf))
        model.opt.integrator = mujoco.mjtIntegrator.mjINT_RK4
        model.opt.timestep = dt
        data = mujoco.MjData(model)
        data.qpos[:], data.qvel[:] = to_mujoco_state(robot, q0, v0)
        if force == "applied":
            data.qfrc_applied[:] = applied
        steps = round(1.0 / dt)
        for _ in range(steps):
            mujoco.mj_step(model, data)
        run = simulate(robot, q0, v0, dt=dt, steps=steps, energies=False, torque=torque)
        q, v = from_mujoco_state(robot, data.qpos.copy(), data.qvel.copy())
        gaps.append(gap(robot, run.q_final, run.qd_final, q, v))
    passive = simulate(robot, q0, v0, dt=2e-3, steps=500, energies=False)
    assert gap(robot, passive.q_final, passive.qd_final, q, v) > 1e-2  # the torque matters
    assert gaps[0] < 1e-6, gaps
    assert gaps[1] < gaps[0] / 8, gaps


def world_jointed(robot: Robot) -> Robot:
    """``robot`` (a floating base) as a fixed-base robot whose base hangs on a ``floating``
    joint from a massless world link: the same q, v layout, for the Pinocchio bridge."""
    joints = [Joint("root", "floating", "world", robot.base), *robot.joints]
    return Robot(robot.name, [Link("world"), *robot.links.values()], joints, gravity=tuple(robot.gravity))


@needs_pinocchio
@pytest.mark.parametrize("method, order", [("rk4", 4), ("euler", 1)])
def test_pd_on_a_floating_robot_keeps_its_momentum(method, order):
    """Linear momentum and angular momentum about the centre of mass: no external force,
    no torque on the base. The integrators keep them to their truncation error: the drift
    shrinks by 2^order when dt halves."""
    from pinocchio_bridge import configuration_permutation, to_pinocchio

    robot = chain(True)
    robot = Robot(robot.name, list(robot.links.values()), robot.joints, gravity=(0, 0, 0), root_joint="free-flyer")
    rng = np.random.default_rng(5)
    q0, v0 = num.random_configuration(robot, rng), rng.uniform(-1, 1, robot.nv)
    target = num.random_configuration(robot, rng)[7:]
    pd = PD(kp=np.linspace(2.0, 4.0, robot.nv - 6), kd=0.5, target=target, gravity_compensation=False)
    model, _, perm = to_pinocchio(world_jointed(robot))
    assert np.array_equal(perm, np.arange(robot.nv))
    assert np.array_equal(configuration_permutation(world_jointed(robot)), np.arange(robot.nq))
    data = model.createData()
    drifts = []
    for dt in (2e-3, 1e-3):
        run = simulate(robot, q0, v0, dt=dt, duration=1.0, stride=round(0.02 / dt), method=method, controller=pd)
        assert np.array_equal(run.tau[:, :6], np.zeros((len(run.t), 6)))
        assert np.abs(run.tau[:, 6:]).max() > 1.0  # the joints are driven
        momenta = np.array([pin.computeCentroidalMomentum(model, data, q, v).vector for q, v in zip(run.q, run.qd)])
        assert np.abs(momenta[0]).max() > 0.1
        drifts.append(np.abs(momenta - momenta[0]).max())
    assert drifts[1] < (1e-7 if method == "rk4" else 0.1), drifts
    assert drifts[0] / drifts[1] > 0.8 * 2**order, drifts


@needs_pinocchio
def test_pd_gravity_on_a_floating_robot_is_pinocchio_generalized_gravity():
    from pinocchio_bridge import to_pinocchio

    robot = chain(True)
    rng = np.random.default_rng(6)
    q0 = num.random_configuration(robot, rng)
    run = simulate(robot, q0, dt=1e-3, steps=1, controller=PD(kp=3.0, kd=1.0, target=q0[7:]))
    model, _, _ = to_pinocchio(world_jointed(robot))
    g = pin.computeGeneralizedGravity(model, model.createData(), q0)
    assert np.abs(g[6:]).max() > 1.0
    np.testing.assert_allclose(run.tau[0], [0.0] * 6 + list(g[6:]), rtol=0, atol=1e-12)


@needs_pinocchio
def test_computed_torque_on_a_floating_robot():
    """The joints' errors (any, the robot at rest) decay as the critically damped closed
    form, as on a fixed base; the base takes no wrench: the base rows of tau are zero and,
    without gravity, the momentum stays (Pinocchio), while the base moves."""
    from pinocchio_bridge import to_pinocchio

    robot = chain(True)
    robot = Robot(robot.name, list(robot.links.values()), robot.joints, gravity=(0, 0, 0), root_joint="free-flyer")
    rng = np.random.default_rng(3)
    target = num.random_configuration(robot, rng)
    e0 = np.concatenate([np.zeros(6), rng.uniform(-0.5, 0.5, robot.nv - 6)])
    q0 = num.integrate(robot, target, -e0)  # difference(q0, target) = e0 on the joints
    run = simulate(robot, q0, dt=1e-3, duration=2.0, stride=10, controller=ComputedTorque(25.0, 10.0, target[7:]))
    t = run.t[:, None]
    want = e0[6:] * (1 + 5 * t) * np.exp(-5 * t)
    np.testing.assert_allclose(num.difference(robot, run.q, target)[:, 6:], want, rtol=0, atol=1e-9)
    assert np.array_equal(run.tau[:, :6], np.zeros((len(run.t), 6))) and np.abs(run.tau[:, 6:]).max() > 0.5
    model, _, _ = to_pinocchio(world_jointed(robot))
    data = model.createData()
    momenta = np.array([pin.computeCentroidalMomentum(model, data, q, v).vector for q, v in zip(run.q, run.qd)])
    np.testing.assert_allclose(momenta, 0.0, rtol=0, atol=1e-9)  # from rest: zero throughout
    assert np.abs(num.difference(robot, run.q[0], run.q[-1])[:6]).max() > 0.01  # the base moved


def test_pd_widths_and_refusals_on_a_floating_base():
    robot = chain(True)
    q0 = num.neutral(robot)
    with pytest.raises(ValueError, match=r"controller.kp \(a scalar or the joints' velocity coordinates, v\[6:\]"):
        simulate(robot, q0, dt=1e-3, steps=2, controller=PD(np.ones(robot.nv), 1.0, q0[7:]))
    with pytest.raises(ValueError, match=r"controller.target_qd \(the joints' velocity coordinates"):
        simulate(robot, q0, dt=1e-3, steps=2, controller=PD(1.0, 1.0, q0[7:], target_qd=np.zeros(robot.nv)))
    bad = q0[7:].copy()
    bad[0] = 2.0  # the ball's quaternion, q[7:11] of the whole configuration
    with pytest.raises(ValueError, match=r"controller.target\[7:11\] of joint 'ball'"):
        simulate(robot, q0, dt=1e-3, steps=2, controller=PD(1.0, 1.0, bad))


def test_batch_of_targets_equals_single_runs():
    """One target per state (N, nq) in SIMD lanes and leftovers: each state's run is its
    own single run."""
    robot = chain(False)
    rng = np.random.default_rng(7)
    q0 = np.stack([num.random_configuration(robot, rng) for _ in range(6)])
    targets = np.stack([num.random_configuration(robot, rng) for _ in range(6)])
    for controller in (PD(9.0, 3.0, targets), ComputedTorque(9.0, 6.0, targets)):
        batch = simulate(robot, q0, dt=2e-3, steps=50, stride=25, controller=controller)
        for r in range(6):
            one = type(controller)(controller.kp, controller.kd, targets[r])
            single = simulate(robot, q0[r], dt=2e-3, steps=50, stride=25, controller=one)
            np.testing.assert_array_equal(batch.q[r], single.q)
            np.testing.assert_array_equal(batch.tau[r], single.tau)


BALL_ARM_MJCF = """<mujoco model="ballarm"><worldbody>
  <body name="upper" pos="0 0 1"><joint name="shoulder" type="ball"/>
    <inertial pos="0.05 0 -0.3" mass="1.5" diaginertia="0.02 0.03 0.04"/>
    <body name="fore" pos="0 0 -0.5"><joint name="elbow" axis="0 1 0"/>
      <inertial pos="0 0.02 -0.2" mass="0.8" diaginertia="0.01 0.012 0.004"/></body></body>
</worldbody></mujoco>"""


def test_cli_controller_on_a_ball_arm(tmp_path, capsys):
    """``armdyn simulate --controller pd-gravity --target`` (the joints' blocks, as --q0)
    drives a ball-and-hinge arm to the target (PD with gravity compensation: no steady
    error); bad targets and gains end with one line naming them, status 2."""
    from armdyn.cli import main

    path = tmp_path / "arm.xml"
    path.write_text(BALL_ARM_MJCF)
    quat = quaternion([1.0, 1.0, 0.0], 0.6)
    target = ",".join(f"{x:.17g}" for x in [*quat, 0.4])
    common = ["simulate", str(path), "--duration", "4", "--dt", "0.001"]
    assert main([*common, "--controller", "pd-gravity", "--target", target]) == 0
    out = capsys.readouterr().out
    q_final = np.array(out.split("q_final  = [")[1].split("]")[0].split(","), dtype=float)
    q_final[:4] /= np.linalg.norm(q_final[:4])  # 6 printed digits
    robot = armdyn.load(path)
    assert np.abs(num.difference(robot, q_final, [*quat, 0.4])).max() < 1e-4
    for argv, message in (
        (["--controller", "pd", "--target", "0,0,0,2,0"], "--target[0:4] of joint 'shoulder'"),
        (["--controller", "pd", "--target", "0,0,1"], "--target needs 5 joint values, got 3"),
        (["--controller", "pd", "--target", target, "--kp", "1,2"], "--kp needs 1 or 4 values"),
        (["--controller", "pd", "--target", "0,0,0,1,nan"], "--target must be finite numbers"),
    ):
        assert main([*common, *argv]) == 2, argv
        err = capsys.readouterr().err.strip()
        assert err.count("\n") == 0 and message in err and "Traceback" not in err, err


def test_cli_pd_on_a_floating_robot(tmp_path, capsys):
    """A floating base: --target is the joints' configuration (the base unactuated, its
    pose refused); PD and computed torque run."""
    from armdyn.cli import main

    path = tmp_path / "free.xml"
    path.write_text(BALL_ARM_MJCF.replace('<joint name="shoulder" type="ball"/>', "<freejoint/>", 1))
    common = ["simulate", str(path), "--duration", "0.2", "--dt", "0.001", "--target"]
    assert main([*common, "0.3", "--controller", "pd"]) == 0
    assert "work of tau" in capsys.readouterr().out
    assert main([*common, "0,0,1,0,0,0,1,0.3", "--controller", "pd"]) == 2
    assert "--target needs 1 joint values (the floating base is not actuated" in capsys.readouterr().err
    assert main([*common, "0.3", "--controller", "computed-torque"]) == 0
    assert "work of tau" in capsys.readouterr().out


def test_adaptive_top_precesses_as_euler_equations():
    """simulate_adaptive on a ball joint (the quaternion integrated in its embedding): the
    symmetric top's closed form (as tests/test_simulate_joints.py), a unit quaternion, the
    world angular momentum kept."""
    from test_simulate_joints import rotation

    I1, I3 = 0.3, 0.5
    top = Link("top", 1.0, (0.0, 0.0, 0.0), [[I1, 0, 0], [0, I1, 0], [0, 0, I3]])
    robot = Robot("top", [Link("base"), top], [Joint("ball", "spherical", "base", "top")], gravity=(0, 0, 0))
    a, w3 = 1.2, 3.0
    quat = quaternion([0.2, -0.4, 0.1], 1.0)
    run = simulate_adaptive(robot, quat, [a, 0.0, w3], duration=3.0)
    W = (I3 - I1) / I1 * w3
    want = np.stack([a * np.cos(W * run.t), a * np.sin(W * run.t), np.full_like(run.t, w3)], axis=-1)
    np.testing.assert_allclose(run.qd, want, rtol=0, atol=1e-8)
    assert np.abs(np.linalg.norm(run.q, axis=1) - 1).max() < 1e-14
    L = np.einsum("sij,jk,sk->si", rotation(run.q), np.diag([I1, I1, I3]), run.qd)
    np.testing.assert_allclose(L, np.tile(L[0], (len(L), 1)), rtol=0, atol=1e-8)
    assert np.abs(L[0]).max() > 0.3 and np.ptp(run.q[:, 0]) > 0.1  # it turns


def test_adaptive_ball_pendulum_energy_and_a_held_pose():
    """A swinging ball pendulum keeps T + V written by hand; a callable of the gravity
    torques holds it still."""
    from test_simulate_joints import rotation

    robot = ball_pendulum()
    q0 = quaternion([1.0, 0.3, 0.0], 0.8)
    run = simulate_adaptive(robot, q0, [0.5, -1.0, 2.0], duration=2.0)
    energy = 0.5 * np.einsum("si,ij,sj->s", run.qd, I_O, run.qd) + ROD_MASS * 9.81 * (rotation(run.q) @ ROD_COM)[:, 2]
    assert np.ptp(energy) < 1e-8 * abs(energy[0]) and np.ptp(run.potential) > 1.0
    held = simulate_adaptive(robot, q0, duration=1.0, torque=lambda t, q, qd: num.gravity(robot, q))
    assert np.abs(held.tau[0]).max() > 5.0
    assert np.abs(num.difference(robot, held.q, q0)).max() < 1e-10 and np.abs(held.qd).max() < 1e-10


@needs_pinocchio
def test_adaptive_floating_robot_keeps_its_momentum():
    from pinocchio_bridge import to_pinocchio

    robot = chain(True)
    robot = Robot(robot.name, list(robot.links.values()), robot.joints, gravity=(0, 0, 0), root_joint="free-flyer")
    rng = np.random.default_rng(8)
    q0, v0 = num.random_configuration(robot, rng), rng.uniform(-1, 1, robot.nv)
    run = simulate_adaptive(robot, q0, v0, duration=1.0, t_eval=np.linspace(0, 1, 21))
    assert run.q.shape == (21, robot.nq) and run.coordinate_names[:2] == ["base_vx", "base_vy"]
    model, _, _ = to_pinocchio(world_jointed(robot))
    data = model.createData()
    momenta = np.array([pin.computeCentroidalMomentum(model, data, q, v).vector for q, v in zip(run.q, run.qd)])
    np.testing.assert_allclose(momenta, np.tile(momenta[0], (21, 1)), rtol=0, atol=1e-8)
    assert np.ptp(run.q[:, 0]) > 0.05  # the base moves


@pytest.mark.parametrize("seed", range(4))
def test_configuration_rate_is_the_derivative_of_integrate(seed):
    """simulate_adaptive's ``q' = Q(q) v`` against the central difference of
    armdyn.configuration.integrate (the groups' exponentials) on random trees of every
    joint kind, fixed and floating."""
    from random_models import random_robot

    from armdyn.configuration import group_layout
    from armdyn.io import with_root_joint
    from armdyn.simulate_adaptive import configuration_rate

    rng = np.random.default_rng(seed)
    while True:
        robot = random_robot(rng, n_joints=5, tree=True, kinds="RPFSLX")
        if robot.multi_dof_joints:
            break
    if seed % 2:
        robot = with_root_joint(robot, "free-flyer")
    q, v, h = num.random_configuration(robot, rng), rng.uniform(-2, 2, robot.nv), 1e-5
    central = (num.integrate(robot, q, h * v) - num.integrate(robot, q, -h * v)) / (2 * h)
    np.testing.assert_allclose(configuration_rate(group_layout(robot), q, v), central, rtol=0, atol=1e-8)


@pytest.mark.parametrize("method", ["rk4", "euler"])
def test_callable_pd_on_a_floating_robot_is_the_rust_pd(method):
    """A joint PD written here as a torque callable, its error from
    armdyn.configuration.difference (NumPy's logs of the groups), the base rows zero,
    against the Rust PD (the core's logs): one trajectory to rounding, on a floating
    robot under gravity with a ball, a hinge, a planar and a free joint."""
    robot = chain(True)
    rng = np.random.default_rng(11)
    q0, v0 = num.random_configuration(robot, rng), rng.uniform(-1, 1, robot.nv)
    target = num.random_configuration(robot, rng)[7:]
    kp, kd = np.linspace(2.0, 5.0, robot.nv - 6), 0.8

    def pd(t, q, qd):
        whole = np.concatenate([q[:, :7], np.broadcast_to(target, (len(q), len(target)))], axis=1)
        e = num.difference(robot, q, whole)[:, 6:]
        return np.concatenate([np.zeros((len(q), 6)), kp * e - kd * qd[:, 6:]], axis=1)

    kw = dict(dt=2e-3, duration=0.5, stride=25, method=method)
    by_hand = simulate(robot, q0, v0, torque=pd, **kw)
    rust = simulate(robot, q0, v0, controller=PD(kp, kd, target, gravity_compensation=False), **kw)
    assert np.abs(by_hand.tau[:, 6:]).max() > 1.0
    np.testing.assert_allclose(by_hand.tau, rust.tau, rtol=0, atol=1e-9)
    np.testing.assert_allclose(num.difference(robot, by_hand.q, rust.q), 0.0, rtol=0, atol=1e-10)
    np.testing.assert_allclose(by_hand.work, rust.work, rtol=0, atol=1e-9)
