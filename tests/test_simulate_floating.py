"""armdyn.simulate for a floating base (the base moved on SE(3), Rust's
``algo::integrate_floating``), against second opinions:

* free fall: the centre of mass follows ``c0 + v0 t + g t^2 / 2`` (a parabola: exact
  for RK4 without rotation, fourth order with a tumbling body);
* no gravity: the total linear momentum and the angular momentum about the world
  origin are conserved (read from the floating CRBA's base rows, ``M[:6] v``, and, for
  one rigid body, ``R I_c w`` by hand); the energy drifts little, by RK4's fourth order
  (error / 16 when dt halves), by Euler's first;
* a semi-implicit Euler step is ``v' = v + h aba(q, v)``, ``q' = integrate(q, h v')``
  with :func:`armdyn.configuration.integrate` (a separate implementation of the SE(3)
  exponential, in NumPy);
* batches == single states, threads 1 == 2; the fixed-base controllers and callables
  are refused; limits and divergence report the velocity coordinates (base first).

The comparison with MuJoCo's rollout of the same MJCF is in tests/test_mjcf_free.py.
"""

from __future__ import annotations

import numpy as np
import pytest
from random_models import random_robot

import armdyn
from armdyn import numeric as num
from armdyn.io import with_root_joint
from armdyn.simulate import simulate

G = np.array([0.0, 0.0, -9.81])


def free_body(gravity=tuple(G)):
    """One rigid body (a welded massless tip), its centre of mass off the base origin."""
    inertia = [[0.3, 0.01, 0.02], [0.01, 0.4, 0.03], [0.02, 0.03, 0.5]]
    return armdyn.Robot(
        "body",
        [armdyn.Link("base", 2.0, [0.1, -0.2, 0.3], inertia), armdyn.Link("tip", 0.0, [0, 0, 0], np.zeros((3, 3)))],
        [armdyn.Joint("weld", "fixed", "base", "tip")],
        gravity=gravity,
        root_joint="free-flyer",
    )


def floating_tree(seed: int, gravity=tuple(G)):
    rng = np.random.default_rng(seed)
    fixed = random_robot(rng, n_joints=4, tree=True)
    fixed = armdyn.Robot(fixed.name, fixed.links.values(), fixed.joints, gravity, base=fixed.base)
    return with_root_joint(fixed, "free-flyer"), rng


def rotation(quat) -> np.ndarray:
    """R of unit quaternions (x, y, z, w), last axis, written out here."""
    x, y, z, w = np.moveaxis(np.asarray(quat), -1, 0)
    return np.moveaxis(
        np.array(
            [
                [1 - 2 * (y * y + z * z), 2 * (x * y - z * w), 2 * (x * z + y * w)],
                [2 * (x * y + z * w), 1 - 2 * (x * x + z * z), 2 * (y * z - x * w)],
                [2 * (x * z - y * w), 2 * (y * z + x * w), 1 - 2 * (x * x + y * y)],
            ]
        ),
        (0, 1),
        (-2, -1),
    )


def momenta(robot, q, v):
    """World linear momentum and angular momentum about the world origin of the states
    (S, nq), (S, nv): ``M[:6] v`` is the whole robot's momentum in the base frame about
    the base origin (linear, angular)."""
    M = num.crba(robot, q)
    hb = np.einsum("sij,sj->si", M[:, :6], v)
    R = rotation(q[:, 3:7])
    p = np.einsum("sij,sj->si", R, hb[:, :3])
    return p, np.einsum("sij,sj->si", R, hb[:, 3:]) + np.cross(q[:, :3], p)


def com(robot, q):
    """World centre of mass of the states (S, nq), from the CRBA's base block."""
    M = num.crba(robot, q)
    h = np.stack([M[:, 5, 1], M[:, 3, 2], M[:, 4, 0]], axis=-1) / M[:, :1, 0]
    return q[:, :3] + np.einsum("sij,sj->si", rotation(q[:, 3:7]), h)


def start(robot, rng, spin=1.0):
    q = num.random_configuration(robot, rng)
    v = rng.uniform(-1, 1, robot.nv)
    v[3:6] *= spin
    return q, v


def close(a, b) -> float:
    a, b = np.asarray(a, dtype=float), np.asarray(b, dtype=float)
    assert np.isfinite(a).all() and np.isfinite(b).all()
    return float(np.max(np.abs(a - b)) / max(1.0, float(np.max(np.abs(b)))))


def test_free_fall_without_rotation_is_a_parabola():
    robot = free_body()
    rng = np.random.default_rng(0)
    q0, v0 = start(robot, rng, spin=0.0)
    run = simulate(robot, q0, v0, dt=0.01, duration=1.0)
    c = com(robot, run.q)
    vc0 = rotation(q0[3:7]) @ v0[:3]
    t = run.t[:, None]
    assert close(c, c[0] + vc0 * t + 0.5 * G * t * t) < 1e-12
    assert close(run.q[:, 3:7], np.broadcast_to(q0[3:7], (len(t), 4))) < 1e-14  # no rotation


@pytest.mark.parametrize("seed", range(3))
def test_tumbling_free_fall_centre_of_mass(seed):
    """A tumbling tree of bodies with moving joints: its centre of mass still falls on
    the parabola; RK4's error is fourth order."""
    robot, rng = floating_tree(seed)
    q0, v0 = start(robot, rng, spin=3.0)
    errors = []
    for dt in (4e-3, 2e-3):
        run = simulate(robot, q0, v0, dt=dt, duration=0.4)
        c = com(robot, run.q)
        p, _ = momenta(robot, run.q[:1], run.qd[:1])
        mass = num.crba(robot, q0)[0, 0]
        t = run.t[:, None]
        errors.append(np.max(np.abs(c - (c[0] + p[0] / mass * t + 0.5 * G * t * t))))
    assert errors[1] < 1e-7
    assert errors[0] / errors[1] > 10  # 16 for fourth order


@pytest.mark.parametrize("method", ["rk4", "euler"])
def test_one_body_angular_momentum_by_hand(method):
    """No gravity, one rigid body tumbling: R (I_c w) + c x m v_c is constant; for RK4 to
    the integrator's error, for semi-implicit Euler to first order."""
    robot = free_body(gravity=(0.0, 0.0, 0.0))
    rng = np.random.default_rng(1)
    q0, v0 = start(robot, rng, spin=4.0)
    run = simulate(robot, q0, v0, dt=1e-3, duration=1.0, method=method)
    m, cb = 2.0, np.array([0.1, -0.2, 0.3])
    Ic = np.array([[0.3, 0.01, 0.02], [0.01, 0.4, 0.03], [0.02, 0.03, 0.5]])
    R = rotation(run.q[:, 3:7])
    w = run.qd[:, 3:6]
    vc = np.einsum("sij,sj->si", R, run.qd[:, :3] + np.cross(w, cb))  # the com's world velocity
    c = run.q[:, :3] + np.einsum("sij,j->si", R, cb)
    L = np.einsum("sij,jk,sk->si", R, Ic, w) + np.cross(c, m * vc)
    assert close(L, np.broadcast_to(L[0], L.shape)) < (1e-9 if method == "rk4" else 1e-2)
    assert close(vc, np.broadcast_to(vc[0], vc.shape)) < (1e-12 if method == "rk4" else 1e-2)


@pytest.mark.parametrize("seed", range(3))
def test_momentum_and_energy_without_gravity(seed):
    robot, rng = floating_tree(10 + seed, gravity=(0.0, 0.0, 0.0))
    q0, v0 = start(robot, rng, spin=2.0)
    drifts = []
    for dt in (4e-3, 2e-3, 1e-3):
        run = simulate(robot, q0, v0, dt=dt, duration=1.0)
        p, L = momenta(robot, run.q, run.qd)
        assert close(p, np.broadcast_to(p[0], p.shape)) < 1e-8
        assert close(L, np.broadcast_to(L[0], L.shape)) < 1e-6
        drifts.append(run.energy_drift())
    assert drifts[-1] < 1e-8
    assert drifts[0] / drifts[1] > 8 and drifts[1] / drifts[2] > 8  # 16 for fourth order


def test_energy_with_gravity_by_hand_and_its_drift():
    """The stored energies are T + V with V = -m g . c (by hand for one body), and a
    passive run under gravity keeps E to RK4's error."""
    robot = free_body()
    rng = np.random.default_rng(2)
    q0, v0 = start(robot, rng, spin=3.0)
    run = simulate(robot, q0, v0, dt=1e-3, duration=1.0)
    c = com(robot, run.q)
    assert close(run.potential, -2.0 * c @ G) < 1e-12
    assert run.energy_drift() < 1e-9
    euler = simulate(robot, q0, v0, dt=1e-3, duration=1.0, method="euler")
    assert 1e-9 < euler.energy_drift() < 1e-2


def test_euler_step_is_the_configuration_space_integrate():
    robot, rng = floating_tree(20)
    q0, v0 = start(robot, rng, spin=2.0)
    h = 0.01
    run = simulate(robot, q0, v0, dt=h, steps=1, method="euler")
    v1 = v0 + h * num.aba(robot, q0, v0, np.zeros(robot.nv))
    assert close(run.qd[1], v1) < 1e-14
    assert close(run.q[1], num.integrate(robot, q0, h * v1)) < 1e-14


def test_rk4_converges_at_fourth_order():
    robot, rng = floating_tree(21)
    q0, v0 = start(robot, rng, spin=3.0)
    reference = simulate(robot, q0, v0, dt=2.5e-4, duration=0.4).q_final
    errors = []
    for dt in (8e-3, 4e-3, 2e-3):
        end = simulate(robot, q0, v0, dt=dt, duration=0.4).q_final
        errors.append(np.max(np.abs(num.difference(robot, reference, end))))
    assert errors[0] / errors[1] > 12 and errors[1] / errors[2] > 12


def test_torques_batches_and_threads():
    """A constant base wrench and joint torques; a batch (SIMD lane groups of 4 or 8,
    the leftover rows alone) equals its single runs, and the threads do not change a
    bit; the work is the wrench's and torques'."""
    robot, rng = floating_tree(22)
    states = [start(robot, rng) for _ in range(11)]
    Q, V = np.array([s[0] for s in states]), np.array([s[1] for s in states])
    tau = rng.uniform(-1, 1, robot.nv)
    one = simulate(robot, Q, V, dt=2e-3, steps=50, torque=tau, threads=1, stride=3)
    two = simulate(robot, Q, V, dt=2e-3, steps=50, torque=tau, threads=2, stride=3)
    assert np.array_equal(one.q, two.q) and np.array_equal(one.qd, two.qd) and np.array_equal(one.work, two.work)
    for k, (q, v) in enumerate(states):
        single = simulate(robot, q, v, dt=2e-3, steps=50, torque=tau, stride=3)
        assert np.array_equal(single.q, one.q[k]) and np.array_equal(single.qdd, one.qdd[k])
    assert one.q.shape == (11, 17, robot.nq) and one.qd.shape == (11, 17, robot.nv)
    assert one.energy_balance().max() < 1e-8
    series = np.broadcast_to(tau, (50, robot.nv))
    assert np.array_equal(simulate(robot, Q, V, dt=2e-3, steps=50, torque=series, stride=3).q, one.q)
    # one series per state, Euler: each lane its own torques
    per_state = rng.uniform(-1, 1, (11, 20, robot.nv))
    batch = simulate(robot, Q, V, dt=2e-3, steps=20, torque=per_state, method="euler")
    for k in (0, 7, 8, 10):
        single = simulate(robot, Q[k], V[k], dt=2e-3, steps=20, torque=per_state[k], method="euler")
        assert np.array_equal(single.q, batch.q[k]) and np.array_equal(single.work, batch.work[k])


def test_limits_and_refusals():
    robot, rng = floating_tree(23)
    q0, v0 = start(robot, rng)
    lower = np.full(robot.dof, -10.0)
    lower[1] = q0[8] + 1e-9
    run = simulate(robot, q0, v0 * 0, dt=1e-3, steps=3, limits=(lower, np.full(robot.dof, 10.0)))
    assert run.limit_step == 0 and run.coordinate_names[run.limit_joint] == robot.coordinate_names[1]
    assert run.coordinate_names[:6] == ["base_vx", "base_vy", "base_vz", "base_wx", "base_wy", "base_wz"]
    with pytest.raises(ValueError, match=r"controller.target \(the joints' configuration, q\[7:\]: the base is not"):
        simulate(robot, q0, v0, dt=1e-3, steps=3, controller=armdyn.simulate.PD(1.0, 1.0, q0))
    with pytest.raises(ValueError, match=rf"\({robot.nq},\)"):
        simulate(robot, q0[7:], v0, dt=1e-3, steps=3)
    with pytest.raises(ValueError, match="torque"):
        simulate(robot, q0, v0, dt=1e-3, steps=3, torque=np.zeros(robot.dof))


FREE_MJCF = """<mujoco model="bug"><worldbody><body name="torso" pos="0 0 1" euler="0 0 90"><freejoint/>
<inertial pos="0 0 0" mass="4" diaginertia="0.1 0.2 0.25"/>
<body name="leg" pos="0.3 0 0"><joint name="hip" axis="0 1 0"/>
<inertial pos="0.1 0 0" mass="0.5" diaginertia="0.01 0.01 0.01"/></body></body></worldbody></mujoco>"""


def test_cli_simulates_a_floating_mjcf(capsys, tmp_path):
    """``armdyn simulate`` on an MJCF with a free body: it starts at the pose the file
    writes (turned 90 degrees about z, 1 m up), --qd0 gives the whole velocity, the
    energy line reports the drift; a controller is refused with exit status 2."""
    from armdyn.cli import main

    path = tmp_path / "bug.xml"
    path.write_text(FREE_MJCF)
    plot = tmp_path / "run.png"
    common = ["simulate", str(path), "--duration", "0.2", "--dt", "0.001"]
    assert main([*common, "--qd0", "0,0,0,1,2,0.5,3", "--plot", str(plot)]) == 0
    out = capsys.readouterr().out
    q_final = np.array(out.split("q_final  = [")[1].split("]")[0].split(","), dtype=float)
    assert len(q_final) == 8 and plot.stat().st_size > 0
    assert "relative drift" in out and float(out.split("relative drift ")[1].split()[0]) < 1e-10
    # from the written pose (1 m up, turned 90 degrees about z): the centre of mass on
    # its parabola (6 printed digits)
    robot = armdyn.load(path)
    q0 = np.array([0, 0, 1, 0, 0, np.sqrt(0.5), np.sqrt(0.5), 0])
    v0 = np.array([0, 0, 0, 1, 2, 0.5, 3.0])
    p0, _ = momenta(robot, q0[None], v0[None])
    mass = num.crba(robot, q0)[0, 0]
    q_final[3:7] /= np.linalg.norm(q_final[3:7])
    expected = com(robot, q0[None])[0] + 0.2 * p0[0] / mass + 0.5 * G * 0.04
    assert robot.floating and np.abs(com(robot, q_final[None])[0] - expected).max() < 1e-5
    assert main([*common, "--controller", "pd", "--target", "0,0,1,0,0,0,1,0"]) == 2
    assert "the floating base is not actuated" in capsys.readouterr().err


def test_a_diverging_state_stops_alone():
    """A huge torque on one state of a lane group: that state is reported not finite at
    the step it overflows and its later samples are NaN; its lane neighbours go on; alone
    it stops at the same step."""
    robot, rng = floating_tree(24)
    Q = np.array([start(robot, rng)[0] for _ in range(9)])
    V = np.zeros((9, robot.nv))
    tau = np.zeros((9, 30, robot.nv))
    tau[2, 5:, -1] = 1e306  # on the last joint
    run = simulate(robot, Q, V, dt=1e-2, steps=30, torque=tau)
    assert run.nonfinite_step[2] > 5 and (np.delete(run.nonfinite_step, 2) == -1).all()
    assert np.isnan(run.q[2, run.nonfinite_step[2] :]).all() and np.isfinite(run.q[3]).all()
    alone = simulate(robot, Q[2], V[2], dt=1e-2, steps=30, torque=tau[2])
    assert alone.nonfinite_step == run.nonfinite_step[2] and len(alone.t) == alone.nonfinite_step
    assert alone.coordinate_names[alone.nonfinite_joint] in alone.coordinate_names


def test_progress_pieces_are_one_call():
    """With a progress callback the run is cut into pieces, each continuing from the
    last one's end: the same states, bit for bit, as one call (q of 7 + dof, the others
    of 6 + dof); the work, summed piece by piece, to rounding."""
    robot, rng = floating_tree(25)
    Q = np.array([start(robot, rng)[0] for _ in range(3)])
    V = rng.uniform(-1, 1, (3, robot.nv))
    tau = rng.uniform(-1, 1, (3, 300, robot.nv))
    seen = []
    pieces = simulate(robot, Q, V, dt=1e-3, steps=300, stride=2, torque=tau, progress=lambda k, n: seen.append(k))
    whole = simulate(robot, Q, V, dt=1e-3, steps=300, stride=2, torque=tau)
    assert len(seen) > 2 and seen[-1] == 300
    for name in ("q", "qd", "qdd", "tau", "q_final", "qd_final"):
        assert np.array_equal(getattr(pieces, name), getattr(whole, name)), name
    assert np.abs(pieces.work - whole.work).max() < 1e-15 * max(1.0, np.abs(whole.work).max()) * 300
