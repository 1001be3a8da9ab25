"""armdyn.simulate vs MuJoCo's mujoco.rollout and Robotics Toolbox's fdyn, side by side in
one process, on the UR5; and a floating robot (solo12) against MuJoCo's rollout.

    PYTHONPATH=python python3 benchmarks/bench_simulate.py            # N = 1e4 states x 1000 steps
    PYTHONPATH=python python3 benchmarks/bench_simulate.py --quick    # N = 1e3
    PYTHONPATH=python python3 benchmarks/bench_simulate.py --case floating --quick

The model: example-robot-data's ``ur5_robot.urdf``, loaded by armdyn (``armdyn.load``) and
by MuJoCo (``mujoco.MjModel.from_xml_path``, which compiles URDF), no actuators, zero
damping/friction; MuJoCo with contacts and all constraints disabled
(``mjDSBL_CONSTRAINT``: no joint-limit forces either), ``mjINT_RK4``, ``timestep = dt``.
Both integrate the same N random initial states (q uniform in [-pi, pi], qd in [-1, 1]),
passive, for ``--steps`` steps of dt = 1e-3 on ``--threads`` threads; before timing, the
final states of the first states are compared (they must agree to 1e-6: same model, same
integrator).

* armdyn: ``simulate(ur5, Q0, QD0, dt, steps, stride, threads)``, the whole batch in one
  call; ``stride`` = steps (first and last states stored) and = 1 (every state, as MuJoCo).
* MuJoCo: ``rollout.rollout(model, [data] * threads, x0, nstep=steps, state=buf)`` into a
  preallocated state buffer (every state stored: rollout always does), in blocks of
  ``--block`` states to bound memory (a block of 1000 states x 1000 steps is ~100 MB).
* Robotics Toolbox: ``robot.fdyn(T, q0, qd0=qd0, solver="RK45", solver_args={"max_step":
  dt})`` on a DHRobot built from armdyn's bundled ``ur5.yaml`` (RTB's own ``models.DH.UR5``
  has a singular inertia matrix, so fdyn fails on it), checked against armdyn's aba first;
  timed per trajectory on a few trajectories (SciPy's RK45 with steps of at most dt: scipy
  offers no fixed-step RK4 in that interface; 6 evaluations per step against RK4's 4).

``--core-before PATH``: also time another build of the extension (``_core*.so``, e.g.
the one before a change to the integrator) in the same process, alternating with this
one, on the same compiled model description: "armdyn before (...)" rows and the ratio.

Reported: median seconds over ``--repeat`` runs (runs alternate between libraries),
simulated steps per second (states x steps / time), and ratios armdyn / other.
Also the peak memory (tracemalloc) of armdyn with stride = steps vs stride = 1.

The floating case (``--case floating``): example-robot-data's solo12 (12 joints and a
free base) given to MuJoCo's compiler as a floating URDF
(:func:`armdyn.io.mjcf_state.urdf_for_mujoco`), the MJCF it writes loaded by both;
``--floating-states`` random states (base anywhere, any orientation, joints in [-pi, pi],
velocities in [-1, 1]) passed to MuJoCo through :func:`armdyn.io.mjcf_state.to_mujoco_state`;
RK4, contacts off; the final states of the first 8 must agree to 1e-9 (both fourth order).
armdyn runs the floating integrator (one state per task, f64) with stride = steps.

Not a test: timings depend on the machine and its load.
"""

from __future__ import annotations

import argparse
import os
import platform
import statistics
import sys
import time
import tracemalloc

import numpy as np

import armdyn
from armdyn.simulate import simulate

URDF = "ur_description/urdf/ur5_robot.urdf"


def urdf_path() -> str:
    try:
        import example_robot_data

        return example_robot_data.getModelPath(URDF) + "/" + URDF
    except ImportError:
        pass
    import glob

    hits = glob.glob(
        os.path.join(
            sys.prefix, "lib", "python*", "site-packages", "cmeel.prefix", "share", "example-robot-data", "robots", URDF
        )
    )
    if not hits:
        sys.exit(f"cannot find example-robot-data's {URDF}: pip install example-robot-data")
    return hits[0]


def rtb_ur5():
    """Robotics Toolbox DHRobot of armdyn's bundled UR5 (standard DH, UR's masses and
    centres of mass, cylinder inertias; ``python/armdyn/robots/ur5.yaml``). RTB's own
    ``models.DH.UR5`` has a singular M (links without inertia) and fdyn fails on it."""
    import roboticstoolbox as rtb
    import yaml

    here = os.path.dirname(os.path.abspath(__file__))
    with open(os.path.join(here, "..", "python", "armdyn", "robots", "ur5.yaml")) as f:
        table = yaml.safe_load(f)["dh"]
    links = []
    for row in table:
        alpha = {"pi/2": np.pi / 2, "-pi/2": -np.pi / 2, "0": 0.0}[str(row["alpha"])]
        i = row["inertia"]
        inertia = [
            [i.get("ixx", 0), i.get("ixy", 0), i.get("ixz", 0)],
            [i.get("ixy", 0), i.get("iyy", 0), i.get("iyz", 0)],
            [i.get("ixz", 0), i.get("iyz", 0), i.get("izz", 0)],
        ]
        links.append(
            rtb.RevoluteDH(
                d=float(row["d"]),
                a=float(row["a"]),
                alpha=alpha,
                m=float(row["mass"]),
                r=[float(c) for c in row["com"]],
                I=np.array(inertia, dtype=float),
                G=0,
                Jm=0,
            )
        )
    robot = rtb.DHRobot(links, name="ur5-armdyn", gravity=[0, 0, -9.81])
    return robot


def load_core(path: str):
    """Another build of the extension module, imported under a name of its own (its
    init function is ``PyInit__core``, so the module's last name part must be ``_core``)."""
    import importlib.util

    spec = importlib.util.spec_from_file_location("armdyn_core_before._core", path)
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


def compiled_with(core, robot):
    """``robot`` compiled by the extension module ``core`` (armdyn.numeric's compile_model
    with that module's NumericModel)."""
    from armdyn.numeric import compiled

    saved = compiled.NumericModel
    compiled.NumericModel = core.NumericModel
    try:
        return compiled.compile_model(armdyn.load(robot.meta["file"]) if robot.meta.get("file") else robot)
    finally:
        compiled.NumericModel = saved


def median_time(f, repeat: int) -> float:
    times = []
    for _ in range(repeat):
        t0 = time.perf_counter()
        f()
        times.append(time.perf_counter() - t0)
    return statistics.median(times)


def main() -> None:
    p = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    p.add_argument("--states", type=int, default=10_000)
    p.add_argument("--steps", type=int, default=1000)
    p.add_argument("--dt", type=float, default=1e-3)
    p.add_argument("--threads", type=int, default=2)
    p.add_argument("--repeat", type=int, default=3)
    p.add_argument("--block", type=int, default=1000, help="MuJoCo states per rollout call")
    p.add_argument("--rtb-trajectories", type=int, default=3)
    p.add_argument("--quick", action="store_true")
    p.add_argument("--core-before", help="another build of armdyn's _core*.so to time alongside")
    p.add_argument("--case", choices=("ur5", "floating", "all"), default="all")
    p.add_argument("--floating-states", type=int, default=2000)
    args = p.parse_args()
    if args.quick:
        args.states, args.repeat, args.rtb_trajectories = 1000, 2, 1
        args.floating_states = min(args.floating_states, 200)
    if args.case in ("floating", "all"):
        floating_case(args)
    if args.case == "floating":
        return
    n, steps, dt, threads = args.states, args.steps, args.dt, args.threads

    import re
    import tempfile

    # without <visual>/<collision> (meshes MuJoCo would try to open; no contacts anyway)
    text = open(urdf_path()).read()
    text = re.sub(r"<(visual|collision)\b.*?</\1>", "", text, flags=re.S)
    folder = tempfile.mkdtemp()
    path = os.path.join(folder, "ur5_robot.urdf")
    with open(path, "w") as f:
        f.write(text)
    ur5 = armdyn.load(path)
    dof = ur5.dof
    rng = np.random.default_rng(0)
    q0 = rng.uniform(-np.pi, np.pi, (n, dof))
    qd0 = rng.uniform(-1, 1, (n, dof))
    print(f"# UR5 from {os.path.basename(path)}, {n} states x {steps} steps, dt = {dt}, {threads} threads")
    print(
        f"# {platform.processor() or platform.machine()}, {os.cpu_count()} cores, simd {armdyn.numeric._core.simd_kernels()}"
    )

    results = {}

    def run_armdyn(stride):
        return simulate(ur5, q0, qd0, dt=dt, steps=steps, stride=stride, threads=threads, energies=False)

    timers = {"armdyn (stride = steps)": lambda: run_armdyn(steps), "armdyn (stride = 1)": lambda: run_armdyn(1)}
    if args.core_before:
        import armdyn.simulate as sim_module

        before_core = load_core(args.core_before)
        now_core = sim_module._core
        before_model = compiled_with(before_core, ur5)
        now_model = armdyn.numeric.compile_model(ur5)
        lower, upper = armdyn.simulate.joint_limits(ur5)

        def run_with(core, model, stride):
            sim_module._core = core
            try:
                return simulate(
                    model,
                    q0,
                    qd0,
                    dt=dt,
                    steps=steps,
                    stride=stride,
                    threads=threads,
                    energies=False,
                    limits=(lower, upper),
                )
            finally:
                sim_module._core = now_core

        a, b = run_with(before_core, before_model, steps), run_with(now_core, now_model, steps)
        assert np.array_equal(a.q_final, b.q_final), "the two builds integrate differently"
        print(f"# check: {args.core_before} and this build: final states bit for bit equal")
        timers = {
            "armdyn (stride = steps)": lambda: run_with(now_core, now_model, steps),
            "armdyn before (stride = steps)": lambda: run_with(before_core, before_model, steps),
            "armdyn (stride = 1)": lambda: run_with(now_core, now_model, 1),
            "armdyn before (stride = 1)": lambda: run_with(before_core, before_model, 1),
        }

    try:
        import mujoco
        from mujoco import rollout
    except ImportError:
        mujoco = None
        print("# MuJoCo: not installed (pip install mujoco)")
    if mujoco is not None:
        mj = mujoco.MjModel.from_xml_path(path)
        assert mj.nv == dof and mj.nu == 0, (mj.nv, mj.nu)
        mj.opt.timestep = dt
        mj.opt.integrator = mujoco.mjtIntegrator.mjINT_RK4
        mj.opt.disableflags |= mujoco.mjtDisableBit.mjDSBL_CONSTRAINT | mujoco.mjtDisableBit.mjDSBL_CONTACT
        mj.dof_damping[:] = 0
        mj.dof_armature[:] = 0
        mj.dof_frictionloss[:] = 0
        datas = [mujoco.MjData(mj) for _ in range(threads)]
        spec = mujoco.mjtState.mjSTATE_FULLPHYSICS
        nstate = mujoco.mj_stateSize(mj, spec)
        x0 = np.zeros((n, nstate))
        d = datas[0]
        for i in range(n):
            d.qpos[:], d.qvel[:], d.time = q0[i], qd0[i], 0.0
            mujoco.mj_getState(mj, d, x0[i], spec)
        block = min(args.block, n)
        buf = np.empty((block, steps, nstate))
        qpos = slice(1, 1 + mj.nq)  # FULLPHYSICS: time, qpos, qvel, ...

        def run_mujoco():
            for b in range(0, n, block):
                k = min(block, n - b)
                rollout.rollout(mj, datas, x0[b : b + k], nstep=steps, state=buf[:k], persistent_pool=True)
            return buf

        # same model, same integrator: the final positions agree
        first_block = rollout.rollout(mj, datas, x0[:8], nstep=steps)[0]
        ours = run_armdyn(steps)
        err = np.abs(first_block[:, -1, qpos] - ours.q_final[:8]).max()
        print(f"# check: MuJoCo vs armdyn final q, 8 states after {steps} steps: max |diff| = {err:.2e}")
        assert err < 1e-6, err
        timers["MuJoCo rollout"] = run_mujoco

    names = list(timers)
    times = {k: [] for k in names}
    for _ in range(args.repeat):
        for k in names:
            times[k].append(median_time(timers[k], 1))
    for k in names:
        results[k] = statistics.median(times[k])

    rtb_per_traj = None
    try:
        import roboticstoolbox as rtb  # noqa: F401 - availability only
    except ImportError as err:
        print(f"# Robotics Toolbox: not importable ({err})")
    else:
        robot = rtb_ur5()
        arm = armdyn.load("ur5")
        x = rng.uniform(-1, 1, (3, dof))
        err = np.abs(robot.accel(x[0], x[1], x[2]) - armdyn.aba(arm, x[0], x[1], x[2])).max()
        print(f"# check: RTB accel vs armdyn aba on ur5.yaml: max |diff| = {err:.2e}")
        assert err < 1e-9, err
        T = steps * dt
        per = []
        for i in range(args.rtb_trajectories):
            t0 = time.perf_counter()
            robot.fdyn(T, q0[i], qd0=qd0[i], solver="RK45", solver_args={"max_step": dt})
            per.append(time.perf_counter() - t0)
        rtb_per_traj = statistics.median(per)

    print()
    print(f"{'':28s} {'time (s)':>10s} {'steps/s':>12s} {'per trajectory':>15s}")
    for k in names:
        t = results[k]
        print(f"{k:28s} {t:10.3f} {n * steps / t:12.3e} {t / n * 1e6:12.1f} us")
    if rtb_per_traj is not None:
        print(
            f"{'Robotics Toolbox fdyn':28s} {'':10s} {steps / rtb_per_traj:12.3e} {rtb_per_traj * 1e6:12.1f} us"
            f"   (median of {args.rtb_trajectories} trajectories, 1 thread)"
        )
    print()
    for k in [k for k in names if k.startswith("armdyn")]:
        if "MuJoCo rollout" in results:
            print(f"throughput {k} / MuJoCo rollout: {results['MuJoCo rollout'] / results[k]:.2f}x")
        if rtb_per_traj is not None:
            print(f"per trajectory, {k} vs RTB fdyn: {rtb_per_traj / (results[k] / n):.0f}x faster")
    for k in [k for k in names if k.startswith("armdyn before")]:
        now = k.replace("armdyn before", "armdyn")
        print(f"time {now} / {k}: {results[now] / results[k]:.3f}")

    # memory: what is stored decides the peak
    for stride in (steps, 10, 1):
        tracemalloc.start()
        simulate(ur5, q0[:1000], qd0[:1000], dt=dt, steps=steps, stride=stride, threads=threads, energies=False)
        _, peak = tracemalloc.get_traced_memory()
        tracemalloc.stop()
        stored = 4 * 1000 * (steps // stride + 1) * dof * 8
        print(
            f"memory, 1000 states, stride {stride:4d}: peak {peak / 2**20:8.1f} MiB, stored arrays {stored / 2**20:8.1f} MiB"
        )


def floating_case(args) -> None:
    """solo12 floating: armdyn's simulate vs MuJoCo's rollout (see the module doc)."""
    import tempfile
    import warnings

    import mujoco
    from mujoco import rollout

    from armdyn.io.mjcf_state import from_mujoco_state, to_mujoco_state, urdf_for_mujoco

    urdf = urdf_path().replace(URDF, "solo_description/robots/solo12.urdf")
    folder = tempfile.mkdtemp()
    compiled = mujoco.MjModel.from_xml_string(urdf_for_mujoco(open(urdf).read()))
    path = os.path.join(folder, "solo12.xml")
    mujoco.mj_saveLastXML(path, compiled)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        robot = armdyn.load(path, strict=False)
    n, steps, dt, threads = args.floating_states, args.steps, args.dt, args.threads
    rng = np.random.default_rng(1)
    q0 = np.array([armdyn.numeric.random_configuration(robot, rng) for _ in range(n)])
    v0 = rng.uniform(-1, 1, (n, robot.nv))
    mj = mujoco.MjModel.from_xml_path(path)
    mj.opt.timestep = dt
    mj.opt.integrator = mujoco.mjtIntegrator.mjINT_RK4
    mj.opt.disableflags |= mujoco.mjtDisableBit.mjDSBL_CONSTRAINT | mujoco.mjtDisableBit.mjDSBL_CONTACT
    datas = [mujoco.MjData(mj) for _ in range(threads)]
    spec = mujoco.mjtState.mjSTATE_FULLPHYSICS
    x0 = np.zeros((n, mujoco.mj_stateSize(mj, spec)))
    qpos, qvel = to_mujoco_state(robot, q0, v0)
    for i in range(n):
        datas[0].qpos[:], datas[0].qvel[:], datas[0].time = qpos[i], qvel[i], 0.0
        mujoco.mj_getState(mj, datas[0], x0[i], spec)
    block = min(args.block, n)
    buf = np.empty((block, steps, x0.shape[1]))

    def run_mujoco():
        for b in range(0, n, block):
            k = min(block, n - b)
            rollout.rollout(mj, datas, x0[b : b + k], nstep=steps, state=buf[:k], persistent_pool=True)

    def run_armdyn():
        return simulate(robot, q0, v0, dt=dt, steps=steps, stride=steps, threads=threads, energies=False)

    last = rollout.rollout(mj, datas, x0[:8], nstep=steps)[0][:, -1]
    q_mj, v_mj = from_mujoco_state(robot, last[:, 1 : 1 + mj.nq], last[:, 1 + mj.nq : 1 + mj.nq + mj.nv])
    ours = run_armdyn()
    gap = max(
        np.abs(armdyn.numeric.difference(robot, ours.q_final[:8], q_mj)).max(),
        np.abs(ours.qd_final[:8] - v_mj).max(),
    )
    print(f"# solo12 floating (MJCF written by MuJoCo), {n} states x {steps} steps, dt = {dt}, {threads} threads")
    print(f"# check: MuJoCo vs armdyn final q, v, 8 states: max |diff| = {gap:.2e}")
    assert gap < 1e-9, gap
    times = {"armdyn floating (stride = steps)": [], "MuJoCo rollout (floating)": []}
    for _ in range(args.repeat):
        times["armdyn floating (stride = steps)"].append(median_time(run_armdyn, 1))
        times["MuJoCo rollout (floating)"].append(median_time(run_mujoco, 1))
    print(f"{'':34s} {'time (s)':>10s} {'steps/s':>12s} {'per trajectory':>15s}")
    for k, ts in times.items():
        t = statistics.median(ts)
        print(f"{k:34s} {t:10.3f} {n * steps / t:12.3e} {t / n * 1e6:12.1f} us")
    ratio = statistics.median(times["MuJoCo rollout (floating)"]) / statistics.median(
        times["armdyn floating (stride = steps)"]
    )
    print(f"throughput armdyn floating / MuJoCo rollout: {ratio:.2f}x")
    print()


if __name__ == "__main__":
    main()
