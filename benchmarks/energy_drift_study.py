"""Where does RK4's energy drift on the passive UR5 and Panda come from?

Not a benchmark of speed: a study whose numbers go into benchmarks/README.md. It answers,
for the target "total energy drift over 10 s with RK4 at dt = 1e-3 below 1e-6
relative (friction off), from rest and from random states":

(a) the same initial states integrated by an independent RK4 (a plain Python loop written
    here, on Pinocchio's ``aba``, energies from Pinocchio's ``computeKineticEnergy`` /
    ``computePotentialEnergy``): same drift => RK4's truncation error for this model;
(b) armdyn's energy along the trajectory against three other evaluations: ``1/2 qd^T M qd``
    with M from armdyn's CRBA, and Pinocchio's kinetic / potential energy;
(c) the drift normalisation of ``Trajectory.energy_drift`` against two alternatives
    (max kinetic energy; the range of the total mechanical energy exchanged);
(d) round-off vs truncation: the drift at dt, dt/2, dt/4 (fourth order => /16 per halving),
    and armdyn's Rust loop (SIMD lanes) against its NumPy slow path (scalar f64 RK4);
(e) the drift of 50 random states per arm at dt = 1e-3 (q ~ U(-1.5, 1.5), qd ~ U(-1, 1),
    seed 10), its distribution, the dt at which all 50 meet 1e-6, and the joint speeds
    reached (against the robots' published velocity limits).

    PYTHONPATH=python python3 benchmarks/energy_drift_study.py [--states 50] [--pin-states 0 (all)]

Needs pinocchio for (a) and (b) (skipped with a note without it). Runs on one thread
(a few minutes on this machine).
"""

from __future__ import annotations

import argparse
import sys
import time
from pathlib import Path

import numpy as np

import armdyn
from armdyn import numeric as num
from armdyn.simulate import simulate

DURATION = 10.0
SEED = 10


def drift(e, kinetic):
    """``Trajectory.energy_drift``'s measure, recomputed here: max |E - E0| / max(|E0|, max T)."""
    scale = np.maximum(np.abs(e[..., :1]), kinetic.max(axis=-1, keepdims=True))
    return (np.abs(e - e[..., :1]) / scale).max(axis=-1)


def states(dof, count, seed=SEED):
    rng = np.random.default_rng(seed)
    return rng.uniform(-1.5, 1.5, (count, dof)), rng.uniform(-1.0, 1.0, (count, dof))


def quantiles(x):
    q = np.quantile(x, [0.0, 0.5, 0.9, 1.0])
    return f"min {q[0]:.2e}  median {q[1]:.2e}  p90 {q[2]:.2e}  max {q[3]:.2e}"


def pinocchio_rk4(pr, q0, qd0, dt, steps):
    """Classical RK4 (Hairer, Norsett, Wanner, Table 1.2) on Pinocchio's aba, written here
    independently of armdyn's loop; energies from Pinocchio at every step."""
    import pinocchio as pin

    model, data = pr.model, pr.data
    perm, inv = pr.perm, pr.inv
    q, v = np.array(q0[perm]), np.array(qd0[perm])
    tau = np.zeros_like(q)

    def acc(q, v):
        return np.array(pin.aba(model, data, q, v, tau))

    def energy(q, v):
        return pin.computeKineticEnergy(model, data, q, v), pin.computePotentialEnergy(model, data, q) + pr.welded

    ks, vs = np.empty(steps + 1), np.empty(steps + 1)
    qs = np.empty((steps + 1, len(q)))
    ks[0], vs[0] = energy(q, v)
    qs[0] = q
    h = dt
    for k in range(steps):
        a1 = acc(q, v)
        q2, v2 = q + 0.5 * h * v, v + 0.5 * h * a1
        a2 = acc(q2, v2)
        q3, v3 = q + 0.5 * h * v2, v + 0.5 * h * a2
        a3 = acc(q3, v3)
        q4, v4 = q + h * v3, v + h * a3
        a4 = acc(q4, v4)
        q = q + h / 6 * (v + 2 * v2 + 2 * v3 + v4)
        v = v + h / 6 * (a1 + 2 * a2 + 2 * a3 + a4)
        ks[k + 1], vs[k + 1] = energy(q, v)
        qs[k + 1] = q
    return qs[:, inv], ks, vs


def study(name, count, pin_states, out):
    robot = armdyn.load(name)
    dof = robot.dof
    q0, qd0 = states(dof, count)
    q0 = np.vstack([np.zeros(dof), q0])  # row 0: from rest
    qd0 = np.vstack([np.zeros(dof), qd0])
    say = lambda s="": print(s, file=out, flush=True)  # noqa: E731
    say(f"## {name} ({dof} dof): from rest + {count} random states, {DURATION:g} s, passive, friction off")

    # (e) + (d): armdyn's RK4 at dt, dt/2, dt/4; every step stored (the max over all steps)
    runs = {}
    for dt in (1e-3, 5e-4, 2.5e-4):
        t0 = time.perf_counter()
        runs[dt] = simulate(robot, q0, qd0, dt=dt, duration=DURATION, stride=round(1e-3 / dt), threads=1)
        d = runs[dt].energy_drift()
        assert np.all(np.isfinite(d)) and d.shape == (count + 1,)
        say(
            f"dt = {dt:g}: from rest {d[0]:.2e}; random states: {quantiles(d[1:])}; "
            f"{np.sum(d[1:] < 1e-6)}/{count} below 1e-6  ({time.perf_counter() - t0:.1f} s)"
        )
    d1, d2, d4 = (runs[dt].energy_drift() for dt in (1e-3, 5e-4, 2.5e-4))
    big = d2 > 1e-8  # where truncation, not round-off, dominates
    say(
        f"order check (states with drift > 1e-8 at dt/2: {big.sum()}): drift(dt)/drift(dt/2) "
        f"median {np.median(d1[big] / d2[big]):.1f} (min {np.min(d1[big] / d2[big]):.1f}); "
        f"drift(dt/2)/drift(dt/4) median {np.median(d2[big] / d4[big]):.1f} (4th order: 16)"
    )

    run = runs[1e-3]
    speed = np.abs(run.qd).max(axis=1)  # (N, dof) max |qd_j| over the run
    limits = np.array([float(j.velocity) if j.velocity is not None else np.nan for j in robot.joints if j.movable])
    names = robot.coordinate_names
    fastest = speed[1:].argmax(axis=1)
    say(
        f"max |qd| over the run (random states): median {np.median(speed[1:].max(axis=1)):.0f} rad/s, "
        f"max {speed[1:].max():.0f} rad/s; fastest joint: "
        + ", ".join(f"{names[j]} x{np.sum(fastest == j)}" for j in np.unique(fastest))
    )
    if np.all(np.isfinite(limits)):
        say(
            f"published velocity limits: {np.array2string(limits, precision=2)} rad/s; "
            f"random states exceeding a limit during the run: {np.sum((speed[1:] > limits).any(axis=1))}/{count}; "
            f"from rest: max |qd| {speed[0].max():.1f} rad/s"
        )
    r = np.corrcoef(np.log(speed[1:].max(axis=1)), np.log(d1[1:]))[0, 1]
    say(f"log drift vs log max |qd|: correlation {r:.2f}")
    top, ok = speed.max(axis=1), d1 < 1e-6
    if np.any(~ok):
        say(
            f"dt = 1e-3: every state whose joints stayed below {top[~ok].min():.0f} rad/s met 1e-6 "
            f"({np.sum(top < top[~ok].min())} states); the fastest state that met it reached {top[ok].max():.0f} rad/s"
        )
    for dt in (5e-4, 2.5e-4):
        d = runs[dt].energy_drift()
        if np.all(d < 1e-6):
            say(f"all {count + 1} states below 1e-6 at dt = {dt:g} (max {d.max():.2e})")
            break

    # (c) normalisations
    e, kin = run.energy, run.kinetic
    by_kinetic = (np.abs(e - e[:, :1]) / kin.max(axis=1, keepdims=True)).max(axis=1)
    exchanged = np.maximum(np.ptp(run.potential, axis=1), np.ptp(kin, axis=1))
    by_exchange = (np.abs(e - e[:, :1]) / exchanged[:, None]).max(axis=1)
    say(f"normalisation (random states, dt = 1e-3): energy_drift {quantiles(d1[1:])}")
    say(f"  / max T instead: {quantiles(by_kinetic[1:])}")
    say(f"  / energy exchanged (max of ptp V, ptp T): {quantiles(by_exchange[1:])}")
    say(
        f"  energy_drift <= /max T everywhere: {bool(np.all(d1 <= by_kinetic * (1 + 1e-12)))}; "
        f"denominator = |E0| for {np.sum(np.abs(e[:, 0]) > kin.max(axis=1))}/{count + 1} states"
    )

    # (d) Rust loop (SIMD lanes, threads) vs the NumPy slow path (scalar RK4 in Python)
    few = slice(0, 4)
    slow = simulate(robot, q0[few], qd0[few], dt=1e-3, duration=1.0, torque=lambda t, q, qd: np.zeros(dof))
    fast = simulate(robot, q0[few], qd0[few], dt=1e-3, duration=1.0, threads=2)
    say(
        f"Rust loop vs NumPy slow path, 4 states x 1 s: max |dq| {np.abs(slow.q - fast.q).max():.1e}, "
        f"max |dqd| {np.abs(slow.qd - fast.qd).max():.1e}"
    )

    # (b) energies along armdyn's trajectory, three other ways
    flat_q, flat_qd = run.q.reshape(-1, dof), run.qd.reshape(-1, dof)
    sample = np.random.default_rng(1).choice(len(flat_q), 5000, replace=False)
    qs, qds = flat_q[sample], flat_qd[sample]
    T = run.kinetic.reshape(-1)[sample]
    V = run.potential.reshape(-1)[sample]
    M = num.crba(robot, qs)
    T_crba = 0.5 * np.einsum("ni,nij,nj->n", qds, M, qds)
    scale = np.maximum(np.abs(T), 1.0)
    say(
        f"energy check on 5000 trajectory samples: |T - 1/2 qd^T M qd| / max(T, 1 J) max "
        f"{np.max(np.abs(T - T_crba) / scale):.1e}"
    )
    try:
        from pinocchio_bridge import PinocchioRobot
    except ImportError as err:
        say(f"(a), (b) with Pinocchio skipped: {err}")
        return
    pr = PinocchioRobot(robot)
    T_pin = np.array([pr.kinetic_energy(a, b) for a, b in zip(qs, qds)])
    V_pin = np.array([pr.potential_energy(a) for a in qs])
    say(
        f"  vs Pinocchio: kinetic max |dT| / max(T, 1 J) {np.max(np.abs(T - T_pin) / scale):.1e}; "
        f"potential max |dV| {np.max(np.abs(V - V_pin)):.1e} J (|V| up to {np.abs(V).max():.1f} J)"
    )

    # (a) independent RK4 on Pinocchio's aba, the same initial states. The passive arms are
    # chaotic: two correct integrations whose aba differ by round-off (1e-16) part ways
    # exponentially, so per state the two are compared while they still follow the same
    # trajectory, and over 10 s as distributions.
    steps = round(DURATION / 1e-3)
    picks = range(count + 1) if pin_states <= 0 else [0] + list(np.argsort(d1[1:])[::-1][: pin_states - 1] + 1)
    t0 = time.perf_counter()
    d_pin, horizon, early = [], [], []
    for i in picks:
        qp, kp, vp = pinocchio_rk4(pr, q0[i], qd0[i], 1e-3, steps)
        ep = kp + vp
        d_pin.append(drift(ep[None], kp[None])[0])
        apart = np.abs(run.q[i] - qp).max(axis=1)  # (steps + 1,)
        k = int(np.argmax(apart > 1e-6)) if np.any(apart > 1e-6) else steps + 1
        horizon.append(k * 1e-3)
        # drift over the common stretch (while the two agree to 1e-6 rad), both ways
        if k > 100:
            ours = drift(run.energy[i, None, :k], run.kinetic[i, None, :k])[0]
            theirs = drift(ep[None, :k], kp[None, :k])[0]
            if theirs > 1e-12:
                early.append(ours / theirs)
    d_pin = np.array(d_pin)
    picks = np.array(list(picks))
    say(f"independent RK4 on Pinocchio's aba, {len(picks)} states x {DURATION:g} s ({time.perf_counter() - t0:.0f} s):")
    say(f"  drift armdyn  {quantiles(d1[picks])}; {np.sum(d1[picks] < 1e-6)}/{len(picks)} below 1e-6")
    say(f"  drift Pinocchio {quantiles(d_pin)}; {np.sum(d_pin < 1e-6)}/{len(picks)} below 1e-6")
    say(
        f"  the two trajectories agree to 1e-6 rad for {quantiles(np.array(horizon))} s; over that common "
        f"stretch max |drift(armdyn)/drift(Pinocchio) - 1| = "
        f"{np.abs(np.array(early) - 1).max() if early else float('nan'):.1e} ({len(early)} states)"
    )
    # the same sensitivity within armdyn alone: q0 moved by 1e-14 rad
    nudged = simulate(robot, q0[picks] + 1e-14, qd0[picks], dt=1e-3, duration=DURATION, threads=1, energies=False)
    self_apart = np.abs(nudged.q - run.q[picks]).max(axis=(1, 2))
    pin_apart = np.array([np.abs(run.q[i] - pinocchio_rk4(pr, q0[i], qd0[i], 1e-3, steps)[0]).max() for i in picks[:3]])
    say(
        f"  chaos: armdyn vs armdyn with q0 + 1e-14 rad, max |dq| over 10 s {quantiles(self_apart)}; "
        f"armdyn vs Pinocchio (first 3) {np.array2string(pin_apart, precision=1)}"
    )
    say()


def main(argv=None):
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("--states", type=int, default=50)
    p.add_argument(
        "--pin-states", type=int, default=0, help="states integrated on Pinocchio (rest + the worst); 0: all"
    )
    p.add_argument("--robots", default="ur5,panda")
    args = p.parse_args(argv)
    if args.states < 1:
        p.error("--states must be at least 1")
    sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "tests"))  # the Pinocchio bridge
    for name in args.robots.split(","):
        study(name, args.states, args.pin_states, sys.stdout)


if __name__ == "__main__":
    main()
