"""armdyn.simulate against second opinions:

* physics: a compound pendulum's small-angle period (closed form); passive UR5 and Panda
  conserve total energy (RK4, dt = 1e-3, 10 s) to 1e-6 relative from rest; from random
  states the drift (up to ~6e-6 at dt = 1e-3) is RK4's truncation error: fourth order in
  dt, below 1e-6 at dt = 5e-4, and made step by step the same by an independent RK4 on
  Pinocchio's aba (benchmarks/energy_drift_study.py has the 50-state study); a gravity-free joint
  under constant torque crosses its limit at the step the closed form gives;
* an independent integration: SciPy's solve_ivp at tight tolerance on Pinocchio's aba;
* the integrators' orders (RK4: error / 16 when dt halves; Euler: / 2);
* control: PD with gravity compensation reaches its target; computed torque follows the
  closed-form error e(t) = e0 (1 + w t) exp(-w t) (critically damped);
* the Python-callable slow path (a NumPy loop) == the Rust loop for the same torques;
* batches == single states, threads 1 == 2, progress pieces == one call, bit for bit;
* stored memory is proportional to what is stored (stride);
* bad input raises ValueError naming it.
"""

from __future__ import annotations

import math
import pickle
import tracemalloc

import numpy as np
import pytest

import armdyn
from armdyn import numeric as num
from armdyn.simulate import PD, ComputedTorque, simulate, simulate_adaptive


def pendulum(m=1.3, l=0.7, izz=0.02, gravity=(0.0, 0.0, -9.81), n_extra=0):
    """A compound pendulum about y: link com at (0, 0, -l), inertia izz about the com
    around y."""
    eye = np.eye(3).tolist()
    inertia = np.diag([izz, izz, izz]).tolist()
    b = num.ModelBuilder("pendulum", list(gravity), "base")
    k = b.add_joint("theta", "base", "bob", "revolute", eye, [0.0, 0.0, 0.0], [0.0, 1.0, 0.0], ["theta"])
    b.append_body(k, m, [0.0, 0.0, -l], inertia)
    return b.build()


@pytest.fixture(scope="module")
def ur5():
    return armdyn.load("ur5")


@pytest.fixture(scope="module")
def panda():
    return armdyn.load("panda")


def test_small_angle_period_closed_form():
    m, l, izz, g = 1.3, 0.7, 0.02, 9.81
    model = pendulum(m, l, izz)
    dt = 1e-3
    run = simulate(model, [1e-3], dt=dt, duration=6.0)
    q = run.q[:, 0]
    assert np.all(np.isfinite(q))
    up = np.flatnonzero((q[:-1] > 0) & (q[1:] <= 0))  # downward zero crossings
    assert len(up) >= 3
    times = (up + q[up] / (q[up] - q[up + 1])) * dt  # linear interpolation
    period = np.diff(times).mean()
    expect = 2 * math.pi * math.sqrt((izz + m * l * l) / (m * g * l))
    # the small-angle error at 1e-3 rad is theta0^2 / 16 ~ 6e-8 relative
    assert abs(period - expect) < 1e-6 * expect


@pytest.mark.parametrize("name", ["ur5", "panda"])
def test_passive_energy_drift_rk4_10s(name, request):
    """From rest: drift < 1e-6 over 10 s at dt = 1e-3. From random states the falling arm
    spins its light wrist at 100-180 rad/s, where RK4's truncation error at dt = 1e-3
    reaches a few 1e-6 (measured): there the check is that the drift is truncation error,
    shrinking ~16x when dt halves (4th order) and below 1e-6 at dt = 5e-4."""
    robot = request.getfixturevalue(name)
    rng = np.random.default_rng(10)
    dof = robot.dof
    q0 = np.vstack([np.zeros(dof), rng.uniform(-1.5, 1.5, (3, dof))])
    qd0 = np.vstack([np.zeros(dof), rng.uniform(-1.0, 1.0, (3, dof))])
    drifts = {}
    for dt in (1e-3, 5e-4):
        run = simulate(robot, q0, qd0, dt=dt, duration=10.0, stride=round(0.01 / dt))
        assert run.q.shape == (4, 1001, dof)
        assert np.all(np.isfinite(run.q)) and np.all(np.isfinite(run.energy))
        assert np.all(run.nonfinite_step == -1)
        assert np.all(run.kinetic.max(axis=1) > 1.0)  # the arms really move
        drifts[dt] = run.energy_drift()
        assert drifts[dt].shape == (4,)
    assert drifts[1e-3][0] < 1e-6, drifts  # from rest
    assert np.all(drifts[5e-4] < 1e-6), drifts
    # 4th order (~16x when dt halves) where the drift is truncation error, not round-off
    # (below ~1e-8 the 10 s sum of round-off dominates and the ratio means nothing)
    truncation = drifts[5e-4] > 1e-8
    assert truncation.any(), drifts
    assert np.all(drifts[1e-3][truncation] / drifts[5e-4][truncation] > 8), drifts


@pytest.fixture(scope="module")
def pinocchio_ur5(ur5):
    pytest.importorskip("pinocchio")
    from pinocchio_bridge import PinocchioRobot

    return PinocchioRobot(ur5)


def test_rk4_matches_solve_ivp_on_pinocchio_aba(ur5, pinocchio_ur5):
    solve_ivp = pytest.importorskip("scipy.integrate").solve_ivp
    dof = ur5.dof
    rng = np.random.default_rng(3)
    q0, qd0 = rng.uniform(-1, 1, dof), rng.uniform(-1, 1, dof)
    duration = 1.0
    # dt = 5e-4: the falling UR5 spins its wrist (1.3e-4 kg m^2) to ~55 rad/s within 1 s and
    # RK4's error at dt = 1e-3 is 4.5e-6 there (measured; 3e-7 at 5e-4, 4th order)
    run = simulate(ur5, q0, qd0, dt=5e-4, duration=duration, stride=200)
    coarse = simulate(ur5, q0, qd0, dt=1e-3, duration=duration, stride=100)

    def f(t, x):
        return np.concatenate([x[dof:], pinocchio_ur5.aba(x[:dof], x[dof:], np.zeros(dof))])

    sol = solve_ivp(f, (0, duration), np.concatenate([q0, qd0]), method="DOP853", rtol=1e-12, atol=1e-12, t_eval=run.t)
    assert sol.success
    np.testing.assert_allclose(run.q, sol.y[:dof].T, rtol=0, atol=1e-6)
    np.testing.assert_allclose(run.qd, sol.y[dof:].T, rtol=0, atol=1e-5)
    np.testing.assert_allclose(coarse.q, sol.y[:dof].T, rtol=0, atol=1e-5)
    assert np.abs(run.q - run.q[0]).max() > 0.1  # a real motion, not a trivial agreement

    # simulate_adaptive (solve_ivp on armdyn's aba) agrees too
    ad = simulate_adaptive(ur5, q0, qd0, duration=duration, t_eval=run.t)
    np.testing.assert_allclose(ad.q, sol.y[:dof].T, rtol=0, atol=1e-8)
    assert ad.energy_drift() < 1e-8


def _rk4_on_pinocchio(pr, q0, qd0, dt, steps):
    """Classical RK4 written out here on Pinocchio's aba; energies from Pinocchio's
    computeKineticEnergy / computePotentialEnergy. Returns q (steps + 1, dof) in armdyn's
    order and the total energy (steps + 1,)."""
    import pinocchio as pin

    q, v = np.array(q0[pr.perm]), np.array(qd0[pr.perm])
    zero = np.zeros_like(q)
    acc = lambda q, v: np.array(pin.aba(pr.model, pr.data, q, v, zero))  # noqa: E731

    def energy(q, v):
        return (
            pin.computeKineticEnergy(pr.model, pr.data, q, v)  # noqa: E731
            + pin.computePotentialEnergy(pr.model, pr.data, q)
            + pr.welded
        )

    qs, es = [q], [energy(q, v)]
    for _ in range(steps):
        a1 = acc(q, v)
        a2 = acc(q + dt / 2 * v, v + dt / 2 * a1)
        v2 = v + dt / 2 * a1
        a3 = acc(q + dt / 2 * v2, v + dt / 2 * a2)
        v3 = v + dt / 2 * a2
        a4 = acc(q + dt * v3, v + dt * a3)
        v4 = v + dt * a3
        q, v = q + dt / 6 * (v + 2 * v2 + 2 * v3 + v4), v + dt / 6 * (a1 + 2 * a2 + 2 * a3 + a4)
        qs.append(q)
        es.append(energy(q, v))
    return np.array(qs)[:, pr.inv], np.array(es)


@pytest.mark.parametrize("name", ["ur5", "panda"])
def test_energy_drift_is_rk4_truncation_not_ours(name, request):
    """The drift above 1e-6 from random states at dt = 1e-3 (see the test above and
    benchmarks/energy_drift_study.py) is RK4's: an independent RK4 on Pinocchio's aba,
    with Pinocchio's energies, follows the same trajectory and makes the same energy error,
    step by step. (Compared over 1 s: the passive arms are chaotic, two correct
    integrations part ways after a few seconds from round-off alone.)"""
    pytest.importorskip("pinocchio")
    from pinocchio_bridge import PinocchioRobot

    robot = request.getfixturevalue(name)
    pr = PinocchioRobot(robot)
    rng = np.random.default_rng(10)
    dof = robot.dof
    q0, qd0 = rng.uniform(-1.5, 1.5, (3, dof)), rng.uniform(-1.0, 1.0, (3, dof))
    dt, steps = 1e-3, 1000
    run = simulate(robot, q0, qd0, dt=dt, steps=steps)
    largest = 0.0
    for i in range(3):
        q_pin, e_pin = _rk4_on_pinocchio(pr, q0[i], qd0[i], dt, steps)
        assert np.all(np.isfinite(q_pin)) and np.all(np.isfinite(e_pin))
        np.testing.assert_allclose(run.q[i], q_pin, rtol=0, atol=1e-9)
        err, err_pin = run.energy[i] - run.energy[i, 0], e_pin - e_pin[0]
        # the same energy error, to 1e-4 of its size (round-off differences are ~1e-13 J)
        np.testing.assert_allclose(err, err_pin, rtol=0, atol=1e-4 * np.abs(err_pin).max() + 1e-12)
        largest = max(largest, np.abs(err_pin).max())
    assert largest > 1e-6, largest  # an error far above round-off (J) was compared


def test_orders_of_rk4_and_euler(ur5):
    dof = ur5.dof
    q0 = np.linspace(-0.5, 0.8, dof)
    exact = simulate_adaptive(ur5, q0, duration=0.5, t_eval=[0.5], rtol=1e-13, atol=1e-13).q[-1]
    for method, order in (("rk4", 4), ("euler", 1)):
        errs = []
        for dt in (2e-3, 1e-3):
            errs.append(np.abs(simulate(ur5, q0, dt=dt, duration=0.5, method=method).q_final - exact).max())
        ratio = errs[0] / errs[1]
        assert 2**order * 0.8 < ratio < 2**order * 1.25, (method, errs)


def test_pd_with_gravity_compensation_reaches_target(ur5):
    dof = ur5.dof
    target = np.array([0.3, -1.0, 1.2, -0.5, 0.4, 0.2])[:dof]
    q0 = np.zeros((2, dof))
    q0[1] = np.linspace(-0.6, 0.6, dof)
    # gains scaled by the joint inertias (M_ii at the target spans 1.3e-4 .. 2.5 kg m^2),
    # ~10 rad/s closed-loop bandwidth, well inside RK4's stability at dt = 1e-3
    m = np.diag(num.crba(ur5, target))
    kp, kd = 100.0 * m, 20.0 * m
    run = simulate(ur5, q0, dt=1e-3, duration=4.0, stride=100, controller=PD(kp=kp, kd=kd, target=target))
    assert np.all(np.isfinite(run.q))
    np.testing.assert_allclose(run.q_final, np.broadcast_to(target, (2, dof)), atol=1e-4)
    np.testing.assert_allclose(run.qd_final, 0, atol=1e-3)
    assert np.abs(run.q[1, 0] - target).max() > 0.5  # it had somewhere to go
    # the stored torque is the controller's: g(q) + Kp e + Kd ed at each sample
    expect = num.gravity(ur5, run.q[1]) + kp * (target - run.q[1]) - kd * run.qd[1]
    np.testing.assert_allclose(run.tau[1], expect, rtol=1e-12, atol=1e-9)


def test_pd_without_gravity_reaches_target():
    model = pendulum(gravity=(0.0, 0.0, 0.0))
    run = simulate(model, [0.0], dt=1e-3, duration=5.0, controller=PD(5.0, 2.0, [1.0], gravity_compensation=False))
    assert abs(run.q_final[0] - 1.0) < 1e-4


def test_computed_torque_follows_closed_form(panda):
    dof = panda.dof
    w = 4.0
    target = np.full(dof, 0.3)
    q0 = np.linspace(-0.4, 0.5, dof)
    run = simulate(
        panda, q0, dt=1e-3, duration=2.0, stride=50, controller=ComputedTorque(kp=w * w, kd=2 * w, target=target)
    )
    e0 = target - q0
    t = run.t[:, None]
    expect = target - e0 * (1 + w * t) * np.exp(-w * t)
    np.testing.assert_allclose(run.q, expect, rtol=0, atol=1e-8)


def test_callable_slow_path_equals_rust_controller(ur5):
    """The NumPy loop with a Python PD (+ gravity) callable == the Rust loop with PD."""
    dof, steps, dt = ur5.dof, 60, 1e-3
    rng = np.random.default_rng(5)
    q0 = rng.uniform(-1, 1, (3, dof))
    target = rng.uniform(-1, 1, dof)
    kp, kd = np.linspace(5, 1, dof), np.linspace(0.5, 0.1, dof)

    def tau(t, q, qd):
        assert q.shape == (3, dof) and qd.shape == (3, dof)
        return num.gravity(ur5, q) + kp * (target - q) - kd * qd

    for method in ("rk4", "euler"):
        fast = simulate(ur5, q0, dt=dt, steps=steps, controller=PD(kp, kd, target), stride=4, method=method)
        slow = simulate(ur5, q0, dt=dt, steps=steps, torque=tau, stride=4, method=method)
        for name in ("q", "qd", "qdd", "tau", "q_final", "qd_final"):
            np.testing.assert_allclose(getattr(slow, name), getattr(fast, name), rtol=1e-11, atol=1e-11)
        assert np.abs(fast.q_final - q0).max() > 1e-3
    const = rng.uniform(-3, 3, dof)
    fast = simulate(ur5, q0, dt=dt, steps=steps, torque=const)
    slow = simulate(ur5, q0, dt=dt, steps=steps, torque=lambda t, q, qd: const)
    np.testing.assert_allclose(slow.q, fast.q, rtol=1e-12, atol=1e-12)
    # a series of identical rows is the constant torque
    series = simulate(ur5, q0, dt=dt, steps=steps, torque=np.tile(const, (steps, 1)))
    assert np.array_equal(series.q, fast.q)


def test_batch_threads_pieces_equal_single_bitwise(ur5):
    dof = ur5.dof
    rng = np.random.default_rng(8)
    q0, qd0 = rng.uniform(-1, 1, (21, dof)), rng.uniform(-1, 1, (21, dof))
    per_state = rng.uniform(-3, 3, (21, 30, dof))
    for kw in (dict(), dict(torque=per_state), dict(controller=ComputedTorque(9.0, 6.0, q0[::-1]))):
        for method in ("rk4", "euler"):
            ref = simulate(ur5, q0, qd0, dt=1e-3, steps=30, stride=3, method=method, threads=1, **kw)
            two = simulate(ur5, q0, qd0, dt=1e-3, steps=30, stride=3, method=method, threads=2, **kw)
            calls = []
            pieces = simulate(
                ur5,
                q0,
                qd0,
                dt=1e-3,
                steps=30,
                stride=3,
                method=method,
                threads=2,
                progress=lambda d, n: calls.append(d),
                **kw,
            )
            assert calls[0] == 0 and calls[-1] == 30 and len(calls) > 2
            for other in (two, pieces):
                for name in ("q", "qd", "qdd", "tau", "q_final", "qd_final"):
                    assert np.array_equal(getattr(other, name), getattr(ref, name)), name
            for i in (0, 7, 20):
                kw1 = dict(kw)
                if "torque" in kw:
                    kw1["torque"] = per_state[i : i + 1]
                if "controller" in kw:
                    kw1["controller"] = ComputedTorque(9.0, 6.0, q0[::-1][i])
                one = simulate(ur5, q0[i : i + 1], qd0[i : i + 1], dt=1e-3, steps=30, stride=3, method=method, **kw1)
                assert np.array_equal(one.q[0], ref.q[i]) and np.array_equal(one.tau[0], ref.tau[i])


def test_joint_limit_crossing_reported_not_clamped():
    # no gravity, constant torque: theta = 1/2 (tau / I) t^2 exactly in RK4 (a quadratic)
    m, l, izz, tau = 1.0, 0.5, 0.01, 0.7
    model = pendulum(m, l, izz, gravity=(0.0, 0.0, 0.0))
    inertia = izz + m * l * l
    upper, dt = 0.3, 1e-3
    run = simulate(model, np.zeros((2, 1)), dt=dt, duration=2.0, torque=[tau], limits=([-1.0], [upper]))
    t_cross = math.sqrt(2 * upper * inertia / tau)
    expect = math.floor(t_cross / dt) + 1  # first step with theta > upper
    assert list(run.limit_step) == [expect, expect]
    assert list(run.limit_joint) == [0, 0]
    assert run.q_final[0, 0] > 1.5 * upper  # not clamped
    np.testing.assert_allclose(run.q[0, :, 0], 0.5 * tau / inertia * run.t**2, rtol=1e-12, atol=1e-15)
    assert run.limit_crossings() == [(0, expect, expect * dt, "theta"), (1, expect, expect * dt, "theta")]


def test_robot_limits_used(ur5):
    # UR5's elbow is limited to [-pi, pi]; a constant torque drives it past pi
    lower, upper = armdyn.simulate.joint_limits(ur5)
    assert np.all(np.isfinite(lower)) and np.all(upper > lower)
    tau = np.zeros(ur5.dof)
    tau[2] = 60.0
    q0 = np.zeros(ur5.dof)
    q0[2] = upper[2] - 0.05
    run = simulate(ur5, q0, dt=1e-3, duration=0.5, torque=tau)
    assert run.limit_step > 0 and run.limit_joint == 2
    k = run.limit_step
    assert run.q[k - 1, 2] <= upper[2] < run.q[k, 2]


def test_memory_proportional_to_stored():
    model = pendulum()
    q0 = np.linspace(-0.5, 0.5, 400)[:, None]

    def peak(stride):
        tracemalloc.start()
        simulate(model, q0, dt=1e-3, steps=2000, stride=stride, energies=False)
        _, top = tracemalloc.get_traced_memory()
        tracemalloc.stop()
        return top

    full, sparse = peak(1), peak(100)
    stored_full = 4 * 400 * 2001 * 8
    assert full >= stored_full
    assert full < 1.5 * stored_full
    assert sparse < 0.05 * full


def test_pickled_model_gives_same_results(ur5):
    model = num.compile_model(ur5)
    clone = pickle.loads(pickle.dumps(model))
    assert clone is not model and clone.coordinate_names == model.coordinate_names
    rng = np.random.default_rng(2)
    q, qd, tau = rng.uniform(-1, 1, (3, 8, ur5.dof))
    assert np.array_equal(clone.aba(q, qd, tau, None), model.aba(q, qd, tau, None))
    assert np.array_equal(clone.potential_energy(q, None), model.potential_energy(q, None))


@pytest.mark.parametrize(
    "kwargs, match",
    [
        (dict(dt=0.0, duration=1.0), "dt must be a positive"),
        (dict(dt=-1e-3, duration=1.0), "dt must be a positive"),
        (dict(dt=float("nan"), duration=1.0), "dt must be a positive"),
        (dict(dt=1e-3, duration=float("inf")), "duration must be"),
        (dict(dt=1e-3, duration=1.0005e-3), "not a whole number of steps"),
        (dict(dt=1e-3), "exactly one of duration"),
        (dict(dt=1e-3, duration=1.0, method="rk45"), "method must be"),
        (dict(dt=1e-3, duration=1.0, stride=0), "stride"),
        (dict(dt=1e-3, duration=1e6), "GiB"),
        (dict(dt=1e-3, duration=1.0, max_bytes=1000), "needs .* GiB"),
        (dict(dt=1e-3, steps=10, torque=np.zeros((9, 6))), r"torque: shape \(9, 6\)"),
        (dict(dt=1e-3, steps=10, torque=[1, 2]), r"torque: shape \(2,\)"),
        (dict(dt=1e-3, steps=10, torque=[np.nan] * 6), "torque contains NaN"),
        (dict(dt=1e-3, steps=10, controller=PD(1, 1, [0, 0])), "controller.target"),
        (dict(dt=1e-3, steps=10, controller=PD([1, 2], 1, 0)), "controller.kp"),
        (dict(dt=1e-3, steps=10, controller="pd"), "controller must be"),
        (dict(dt=1e-3, steps=10, torque=lambda t, q, qd: 1 / 0), "torque callable failed at step 0 .*ZeroDivision"),
        (
            dict(dt=1e-3, steps=10, torque=lambda t, q, qd: np.zeros(6) if t < 3e-3 else np.zeros(5)),
            r"returned shape \(5,\) at step 2 \(t = 0.003 s\)",
        ),
    ],
)
def test_bad_input(ur5, kwargs, match):
    with pytest.raises(ValueError, match=match):
        simulate(ur5, np.zeros(6), **kwargs)


def test_bad_states(ur5):
    with pytest.raises(ValueError, match="q0: shape"):
        simulate(ur5, np.zeros(5), dt=1e-3, steps=1)
    with pytest.raises(ValueError, match="q0 contains NaN"):
        simulate(ur5, [0, 0, np.nan, 0, 0, 0], dt=1e-3, steps=1)
    with pytest.raises(ValueError, match="qd0: shape"):
        simulate(ur5, np.zeros((3, 6)), np.zeros((2, 6)), dt=1e-3, steps=1)
