"""``armdyn simulate``: run a simulation from the command line, report it, plot and animate it.

What it prints (stdout): the run's size, the final state, an energy line and the first
joint-limit crossing. The energy line of a passive run gives the relative drift of the
total energy ``E = T + V`` (integration error alone); with torques applied it gives the
work-energy balance ``max |E(t) - E(0) - W(t)| / scale`` with ``W`` the work of the
torques (:meth:`armdyn.simulate.Trajectory.energy_balance`), since ``E`` itself then
changes by the work done.

Exit status: 0 done; 2 bad input; 4 the state became NaN/inf (the run stopped at that
step: what was computed is reported and written); 130 interrupted (Ctrl-C: nothing is
written).

Progress bars (tqdm, on stderr) only when stderr is a terminal and the run is long.
The GIF plays in real time: each frame lasts the simulated time between the frames it
shows (GIF delays are whole centiseconds, at least 20 ms), at most :data:`MAX_FRAMES`
frames (longer runs show fewer, longer frames); its speed is printed.
"""

from __future__ import annotations

import math
import sys
from pathlib import Path

import numpy as np

__all__ = ["run", "gif_frames", "progress_bar", "energy_line", "EXIT_DIVERGED", "MAX_FRAMES"]

#: exit status of a run whose state became NaN/inf
EXIT_DIVERGED = 4
#: most frames in a GIF
MAX_FRAMES = 300


def progress_bar(total: int, desc: str, unit: str, enabled: bool = True):
    """A ``callback(done, total)`` drawing a tqdm bar on stderr, or None when disabled or
    stderr is not a terminal (a redirected log gets no ``\\r`` frames). Call
    ``callback.close()`` when done."""
    if not enabled or not sys.stderr.isatty():
        return None
    from tqdm import tqdm

    bar = tqdm(total=total, desc=desc, unit=unit, unit_scale=True, leave=False, file=sys.stderr, dynamic_ncols=True)

    def update(done, _total=None):
        bar.update(done - bar.n)

    update.close = bar.close
    return update


def gif_frames(t: np.ndarray, fps: float, max_frames: int = MAX_FRAMES) -> tuple[np.ndarray, int, float]:
    """Which samples of the times ``t`` (S,) (evenly spaced, s) become GIF frames, the frame
    duration (ms) and the playback slowdown (1.0: real time; 2.0: half speed).

    Frames are every ``k``-th sample, ``k`` the smallest step near ``1 / fps`` seconds
    that keeps at most ``max_frames`` frames and, where possible, makes ``k`` sample
    intervals a whole number of centiseconds (the GIF's delay unit), so that each frame
    lasts exactly the simulated time it covers.
    """
    if len(t) < 2:
        return np.arange(len(t)), 100, 1.0
    h = float(t[1] - t[0])
    k = max(1, round(1.0 / (fps * h)), math.ceil(len(t) / max_frames))
    for cand in range(k, 4 * k + 1):  # the first step whose span is a whole number of centiseconds
        span = cand * h * 100
        if abs(span - round(span)) < 1e-6 * max(span, 1) and round(span) >= 2:
            k = cand
            break
    span_ms = k * h * 1000
    duration = max(20, int(round(span_ms / 10)) * 10)
    return np.arange(0, len(t), k), duration, duration / span_ms


def speed_text(slowdown: float) -> str:
    """'real time', 'x2 slower' or 'x1.5 faster'."""
    if abs(slowdown - 1) < 0.01:
        return "real time"
    return f"x{slowdown:.3g} slower" if slowdown > 1 else f"x{1 / slowdown:.3g} faster"


def energy_line(run) -> str:
    """The energy report: drift for a passive run, the work-energy balance otherwise."""
    e = run.energy
    head = f"energy: E(0) = {e[0]:.6g} J, E(end) = {e[-1]:.6g} J"
    if run.passive:
        return f"{head}, relative drift {run.energy_drift():.3e}"
    return (
        f"{head}, work of tau W = {run.work[-1]:.6g} J, balance max |E - E(0) - W| / scale {run.energy_balance():.3e}"
    )


def run(args, robot) -> int:
    """The ``simulate`` subcommand on the loaded ``robot`` (see the module docstring)."""
    from ._io_atomic import atomic_writes
    from .show import numeric_robot
    from .simulate import simulate
    from .trajectory import PD, ComputedTorque

    robot = numeric_robot(robot)
    dof = robot.dof
    if robot.floating or robot.multi_dof_joints:
        q0, qd0 = manifold_start(robot, args)
    else:
        q0 = np.broadcast_to(_numbers(args.q0, "--q0", dof) or [0.0], (dof,))
        qd0 = np.broadcast_to(_numbers(args.qd0, "--qd0", dof) or [0.0], (dof,))
    if robot.floating and (args.animate or getattr(args, "three_d", None)):
        raise ValueError(
            f"'{robot.name}' has a floating base: --animate and --3d are for fixed-base robots "
            "(a run, --controller on the joints, --plot and the energy report work)"
        )
    controller = None
    if args.controller is not None:
        if args.target is None:
            raise ValueError(f"--controller {args.controller} needs --target (joint values)")
        base_q, base_v = (7, 6) if robot.floating else (0, 0)
        if robot.floating or robot.multi_dof_joints:
            target = manifold_target(robot, args.target)
        else:
            target = np.broadcast_to(_numbers(args.target, "--target", dof), (dof,))
        if args.controller == "computed-torque":  # gains of the unit-inertia error dynamics
            default = (25.0, 10.0)
        else:  # 10 rad/s, critically damped, scaled by each coordinate's inertia M_ii at the target
            from .numeric import crba

            at = np.array(q0, dtype=float)
            at[base_q:] = target
            m_ii = np.diag(crba(robot, at))[base_v:]
            default = (100.0 * m_ii, 20.0 * m_ii)
        # one gain per velocity coordinate of the joints (a ball joint's three)
        kp = np.broadcast_to(_numbers(args.kp, "--kp", dof, "velocity coordinate") or default[0], (dof,))
        kd = np.broadcast_to(_numbers(args.kd, "--kd", dof, "velocity coordinate") or default[1], (dof,))
        if args.controller == "computed-torque":
            controller = ComputedTorque(kp, kd, target)
        else:
            controller = PD(kp, kd, target, gravity_compensation=args.controller == "pd-gravity")
    elif args.target is not None:
        raise ValueError("--target needs --controller")
    if not (np.isfinite(args.dt) and args.dt > 0):
        raise ValueError(f"--dt must be a positive number of seconds, got {args.dt}")
    steps = round(args.duration / args.dt) if np.isfinite(args.duration) and args.duration > 0 else 0
    if steps < 1:
        raise ValueError(f"--duration must be at least one step of --dt, got {args.duration}")
    if abs(steps * args.dt - args.duration) > 1e-9 * max(args.duration, 1.0):  # as simulate() checks it
        raise ValueError(
            f"--duration {args.duration:g} is not a whole number of steps of --dt {args.dt:g} "
            f"({args.duration / args.dt:.6g} steps)"
        )
    stride = args.stride if args.stride is not None else max(1, steps // 2000)  # keep ~2000 samples

    bar = progress_bar(steps, "simulating", "step", not args.quiet and steps * dof >= 600_000)
    try:
        result = simulate(
            robot,
            q0,
            qd0,
            dt=args.dt,
            steps=steps,
            method=args.method,
            controller=controller,
            stride=stride,
            progress=bar,
        )
    finally:
        if bar is not None:
            bar.close()

    outputs, notes = [], []
    if args.plot:
        from .plots import plot_trajectory

        outputs.append(
            (
                args.plot,
                lambda tmp: plot_trajectory(result, tmp, title=f"{robot.name}: {args.method}, dt = {args.dt:g} s"),
            )
        )
    if args.animate:
        from .show import animate

        frames, duration, slowdown = gif_frames(result.t, args.fps)
        notes.append(f"GIF: {len(frames)} frames of {duration} ms, {speed_text(slowdown)}")

        def write_gif(tmp):
            gif_bar = progress_bar(len(frames), "drawing GIF", "frame", not args.quiet and len(frames) > 20)
            try:
                animate(robot, result.q[frames], tmp, t=result.t[frames], frame_ms=duration, progress=gif_bar)
            finally:
                if gif_bar is not None:
                    gif_bar.close()

        outputs.append((args.animate, write_gif))
    if getattr(args, "three_d", None):
        from .viewer import animate as animate_3d

        page = animate_3d(robot, result.t, result.q)
        notes.append(f"3-D: {page.frames} frames, real time")
        outputs.append((args.three_d, lambda tmp: Path(tmp).write_text(page.html(), encoding="utf-8")))
    atomic_writes(outputs)

    names = result.coordinate_names  # a floating base's first: base_vx ... base_wz
    print(f"{robot.name}: {steps} steps of {args.dt:g} s ({args.method}), {len(result.t)} samples stored")
    print("q_final  = [" + ", ".join(f"{v:.6g}" for v in result.q_final) + "]")
    print("qd_final = [" + ", ".join(f"{v:.6g}" for v in result.qd_final) + "]")
    if len(result.t):
        print(energy_line(result))
    if result.limit_step >= 0:
        print(
            f"joint limit: '{names[result.limit_joint]}' left its range at step {result.limit_step} "
            f"(t = {result.limit_step * args.dt:.4g} s); not clamped"
        )
    for note in notes:
        print(note)
    for path in (args.plot, args.animate, getattr(args, "three_d", None)):
        if path:
            print(f"wrote {path}")
    if result.nonfinite_step >= 0:
        k = result.nonfinite_step
        print(
            f"armdyn: the state became NaN/inf at step {k} (t = {k * args.dt:.6g} s) in joint "
            f"'{names[result.nonfinite_joint]}': the run stopped there (unstable: try a smaller --dt or "
            f"gentler gains); {len(result.t)} samples kept",
            file=sys.stderr,
        )
        return EXIT_DIVERGED
    return 0


def manifold_start(robot, args) -> tuple[np.ndarray, np.ndarray]:
    """``(q0, qd0)`` of a robot whose configuration is not flat (a floating base, ball,
    planar or floating joints), from its neutral configuration (a floating base at the
    pose an MJCF file wrote, else at the origin). ``--q0`` gives the joints' configuration
    (quaternions x y z w, planar x y cos sin; one value when every joint has one
    coordinate) or, with a floating base, the whole q (position, quaternion x y z w,
    joints); ``--qd0`` the joints' velocities (the base at rest) or the whole v. A
    quaternion off unit length is refused, naming it."""
    from .configuration import difference, neutral

    q0, qd0 = neutral(robot), np.zeros(robot.nv)
    if robot.floating and robot.meta.get("base_pose"):  # MuJoCo's qpos0: position, quaternion w x y z
        position, (w, x, y, z) = robot.meta["base_pose"]
        q0[:7] = [*position, x, y, z, w]
    qb, vb = (7, 6) if robot.floating else (0, 0)
    for values, out, option, base in ((args.q0, q0, "--q0", qb), (args.qd0, qd0, "--qd0", vb)):
        given = _numbers(values, option)
        if given is None:
            continue
        joints = len(out) - base
        if base and len(given) == len(out):
            out[:] = given
        elif len(given) == joints or (len(given) == 1 and (option == "--qd0" or robot.nq == robot.nv + qb - vb)):
            out[base:] = given
        else:
            whole = f", or {len(out)} for the floating base and the joints" if base else ""
            raise ValueError(f"{option} needs {joints} joint values{whole}, got {len(given)}")
    difference(robot, q0, q0)  # refuses a quaternion off unit length, naming it
    return q0, qd0


def manifold_target(robot, text: str) -> np.ndarray:
    """``--target`` of a robot whose configuration is not flat: the joints' configuration,
    read per joint block as ``--q0`` (quaternions x y z w, planar x y cos sin; one value
    when every joint has one coordinate). A floating base is not actuated: the joints'
    values only, never its pose. A quaternion off unit length is refused, naming it."""
    from .configuration import check_unit_blocks, grouped_layout

    given = _numbers(text, "--target")
    base_q, base_v = (7, 6) if robot.floating else (0, 0)
    joints = robot.nq - base_q
    if len(given) == 1 and joints == robot.nv - base_v:
        given = given * joints
    if len(given) != joints:
        base = " (the floating base is not actuated: no pose for it)" if robot.floating else ""
        raise ValueError(f"--target needs {joints} joint values{base}, got {len(given)}")
    # the joints' blocks at their places in the values given (a floating base's 7 off)
    layout = grouped_layout(
        tuple((n, k, iq - base_q, iv - base_v) for n, k, iq, iv in robot.configuration_layout), False
    )
    target = np.array(given)
    check_unit_blocks(layout, target, "--target")
    return target


def _numbers(text: str | None, option: str, dof: int | None = None, each: str = "joint"):
    if text is None:
        return None
    try:
        values = [float(x) for x in text.split(",")]
    except ValueError:
        raise ValueError(f"{option} must be comma-separated numbers, got {text!r}") from None
    if not all(np.isfinite(values)):
        raise ValueError(f"{option} must be finite numbers, got {text!r}")
    if dof is not None and len(values) not in (1, dof):
        raise ValueError(f"{option} needs 1 or {dof} values (one per {each}), got {len(values)}")
    return values
