"""Simulation: integrate the forward dynamics of a robot from one or many initial states.

    import armdyn
    from armdyn.simulate import simulate, PD
    ur5 = armdyn.load("ur5")
    run = simulate(ur5, q0, duration=2.0, dt=1e-3)                  # passive, RK4
    run = simulate(ur5, q0s, duration=2.0, dt=1e-3, stride=10)      # (N, dof) states, every 10th step kept
    run = simulate(ur5, q0, duration=2.0, dt=1e-3, controller=PD(kp=100, kd=20, target=q_star))
    run.q, run.qd, run.qdd, run.tau     # (S, dof), or (N, S, dof) for a batch
    run.t, run.energy, run.energy_drift()

Conventions: SI units, radians; the equation of motion is ``M(q) qdd + C(q, qd) qd + g(q)
= tau`` with gravity the robot's vector in the base frame (docs/architecture.md); forward dynamics is
the Rust core's articulated-body algorithm (``armdyn.aba``), so whatever the model's
``aba`` includes (joint friction, damping, rotor inertia where the model has them) is
integrated. Joint order: ``robot.coordinate_names``.

Three ways to integrate:

* :func:`simulate`, fixed step, ``method="rk4"`` (classical Runge-Kutta, 4 ``aba`` per
  step) or ``"euler"`` (semi-implicit / symplectic Euler, 1 ``aba`` per step). The loop
  runs in Rust over all states in parallel (SIMD lanes and threads), with no Python in
  it -- unless ``torque`` is a Python callable, the documented slow path (a NumPy loop
  calling the callable once per stage with every state at once).
* :func:`simulate_adaptive`: one trajectory with SciPy's ``solve_ivp`` (error control,
  ``DOP853`` by default) over the same ``aba``.

Torque: ``None`` (passive); a constant ``(dof,)``; a series ``(steps, dof)`` for every
state or ``(N, steps, dof)`` one per state (row ``k`` acts over ``[t_k, t_k + dt)``);
a controller run in Rust at every integrator stage (:class:`PD`,
:class:`ComputedTorque`); or a callable ``torque(t, q, qd) -> tau`` with ``q``, ``qd``
``(N, dof)`` and ``tau`` ``(dof,)`` or ``(N, dof)`` (widths nq and nv where they differ,
below).

A floating base (``robot.floating``, Pinocchio's layout: ``q0`` (7 + dof,) base position,
quaternion x y z w, joints; ``qd0`` and torques (6 + dof,) base linear and angular
velocity (wrench) in the base frame, joints): the same two methods with the base moved
on SE(3) as :func:`armdyn.configuration.integrate` moves it (semi-implicit Euler
``q' = q (+) h v'``; RK4 as Runge-Kutta-Munthe-Kaas, fourth order on the manifold; see
``crates/armdyn-core/src/algo/integrate_floating.rs``). Stored ``q`` rows are (7 + dof,),
the others (6 + dof,); ``limit_joint`` and ``nonfinite_joint`` index
``Trajectory.coordinate_names``, the velocity's (``base_vx`` ... ``base_wz``, then the
joints). Energies include the base: ``T = 1/2 v^T M v``, ``V = -g . (m c)`` with ``c``
the world centre of mass. The base is not actuated by a controller (below).

Joints of several coordinates (spherical, planar, free; ``robot.nq`` > ``robot.nv``),
fixed or floating base: the same two methods with each joint's block moved on its group
as :func:`armdyn.configuration.integrate` moves it (spherical on SO(3), free on SE(3),
planar on SE(2); the quaternions and planar ``(cos, sin)`` kept unit). ``q0`` and the
stored ``q`` rows are (nq,), the others (nv,) (``Trajectory.coordinate_names``);
limits are checked on the 1-dof joints only; energies as for a floating base.

Controllers there (:mod:`armdyn.simulate_control`): the error is on the tangent space,
``e = difference(q, target)`` (:func:`armdyn.configuration.difference`, Pinocchio's
``difference``: the velocity, in ``q``'s frame, that moves ``q`` to the target in unit
time, so ``Kp e`` turns a ball joint toward its target), ``target`` a configuration
(nq,), ``kp``, ``kd``, ``target_qd`` per velocity coordinate (nv,). :class:`PD`: ``tau =
[g(q)] + Kp e + Kd (qd* - qd)``; :class:`ComputedTorque`: ``tau = rnea(q, qd, Kp e + Kd
(qd* - qd))``, so that ``qdd = Kp e + Kd (qd* - qd)`` (an error along one axis of a
ball, or a small one, decays as ``e'' + Kd e' + Kp e = 0``). With a floating base the
controllers' arrays are the joints' (target ``q[7:]``, gains ``v[6:]``), the base's six
rows of ``tau`` are zero, PD's gravity compensation is the joints' rows of the
generalized gravity (what holds the joints while the base is held); computed torque
gives the joints ``qdd = Kp e + Kd (qd* - qd)`` and the base the acceleration that
follows (collocated partial feedback linearization: no wrench on the base, which the
joints' motion moves). A torque callable
gets ``q`` (N, nq) and ``qd`` (N, nv) and returns (nv,) or (N, nv), the steps those of
the Rust integrators. :func:`simulate_adaptive` integrates ``q`` in its embedding
(:mod:`armdyn.simulate_adaptive`).

Joint limits (from the robot's joints, or ``limits=(lower, upper)``) are reported, never
enforced: :attr:`Trajectory.limit_step` / :attr:`Trajectory.limit_joint` give, per state,
the first step at which a joint is outside its range and which joint.

Divergence: a state whose ``q`` or ``qd`` becomes NaN or inf stops there;
:attr:`Trajectory.nonfinite_step` / :attr:`Trajectory.nonfinite_joint` say when and in
which joint. A single state's arrays then end with the last finite sample before that
step (nothing after it was computed); in a batch the samples from that step on are NaN.
Energies are computed for the finite samples only.

Interrupting: Ctrl-C (SIGINT) during a run in Rust raises ``KeyboardInterrupt`` within
about 0.1 s; nothing is returned.

Memory: only every ``stride``-th step is stored, so memory is proportional to what is
kept (``N * (steps // stride + 1) * dof`` values per array); a run whose stored samples
would not fit in the available memory (or ``max_bytes``) is refused before it starts.
"""

from __future__ import annotations

import math
import os
from typing import Callable

import numpy as np

from . import _core
from .numeric import check_threads, compiled_model, kinetic_energy, potential_energy
from .simulate_adaptive import simulate_adaptive
from .simulate_arrays import BASE_VELOCITY_NAMES, checked_state, contiguous, floating_energies, per_joint
from .simulate_control import controller_arrays, simulate_callable
from .trajectory import PD, ComputedTorque, Trajectory, joint_limits

__all__ = ["simulate", "simulate_adaptive", "Trajectory", "PD", "ComputedTorque", "joint_limits"]


def _available_bytes() -> int:
    try:
        return os.sysconf("SC_AVPHYS_PAGES") * os.sysconf("SC_PAGE_SIZE")
    except (ValueError, OSError, AttributeError):
        return 8 << 30


def step_count(duration, steps, dt) -> int:
    """The number of integration steps of ``dt`` seconds: ``steps`` itself, or ``duration``
    (seconds, a whole number of steps); exactly one of them. ValueError naming the bad one."""
    # bool is an int to Python: dt=True would be a step of 1 s
    if isinstance(dt, (bool, np.bool_)) or not (
        isinstance(dt, (int, float, np.integer, np.floating)) and math.isfinite(dt) and dt > 0
    ):
        raise ValueError(f"dt must be a positive finite number of seconds, got {dt!r}")
    if (duration is None) == (steps is None):
        raise ValueError("give exactly one of duration (seconds) and steps")
    if steps is None:
        if isinstance(duration, (bool, np.bool_)) or not (
            isinstance(duration, (int, float, np.integer, np.floating)) and math.isfinite(duration) and duration > 0
        ):
            raise ValueError(f"duration must be a positive finite number of seconds, got {duration!r}")
        steps = round(duration / dt)
        if abs(steps * dt - duration) > 1e-9 * max(duration, 1.0):
            raise ValueError(f"duration {duration} is not a whole number of steps of dt = {dt}")
    if (
        isinstance(steps, (bool, np.bool_))
        or not isinstance(steps, (int, float, np.integer, np.floating))
        or int(steps) != steps
        or steps < 1
    ):
        raise ValueError(f"steps must be a positive integer, got {steps!r}")
    if steps > 1 << 40:
        raise ValueError(f"{steps} steps is more than armdyn integrates in one call")
    return int(steps)


def simulate(
    robot,
    q0,
    qd0=None,
    *,
    dt,
    duration=None,
    steps=None,
    method="rk4",
    torque=None,
    controller=None,
    stride=1,
    energies=True,
    limits=None,
    threads=None,
    max_bytes=None,
    progress: Callable[[int, int], None] | None = None,
) -> Trajectory:
    """Integrate from ``q0``, ``qd0`` ((dof,) or (N, dof); ``qd0`` default zero) with a fixed
    step ``dt`` (s) for ``duration`` seconds (a whole number of steps) or ``steps`` steps.

    method: ``"rk4"`` or ``"euler"`` (semi-implicit). torque / controller: see the module
    docstring (at most one of them). stride: store every ``stride``-th step (the first
    and, when ``steps`` is a multiple of ``stride``, the last state included; the last
    state is always in ``q_final``, ``qd_final``). energies: also compute kinetic and
    potential energy of every stored sample. limits: ``(lower, upper)`` (dof,) or None
    for the robot's own. threads: None = all cores. max_bytes: refuse runs whose stored
    samples need more (default: the available memory). progress: called as
    ``progress(steps_done, steps)`` during the run (the run is then cut into ~100
    pieces; the result is the same bit for bit).

    Bad input (shapes, NaN, a non-positive dt, a duration that is not a whole number of
    steps, a run that would not fit in memory) raises ``ValueError`` naming it.
    """
    model = compiled_model(robot)
    floating = bool(getattr(model, "floating", False))
    # the widths of q and of qd (qdd, tau): dof each, 7 + dof and 6 + dof with a floating base, nq and nv
    # with joints of several coordinates (whose q blocks are longer than their v blocks)
    dof, nv = getattr(model, "nq", model.dof), getattr(model, "nv", model.dof)
    steps = step_count(duration, steps, dt)
    dt = float(dt)
    if method not in ("rk4", "euler"):
        raise ValueError(f"method must be 'rk4' or 'euler', got {method!r}")
    if int(stride) != stride or stride < 1:
        raise ValueError(f"stride must be a positive integer, got {stride!r}")
    stride = int(stride)
    q0a = checked_state(q0, "q0", dof)
    single = q0a.ndim == 1
    q0a = contiguous(np.atleast_2d(q0a))
    rows = q0a.shape[0]
    threads = check_threads(threads)  # Rust reads True as 1
    qd0a = np.zeros((rows, nv)) if qd0 is None else checked_state(qd0, "qd0", nv)
    if qd0a.shape not in ((nv,), (rows, nv)):
        raise ValueError(f"qd0: shape {qd0a.shape} does not match q0's {q0a.shape}")
    qd0a = contiguous(np.broadcast_to(qd0a, (rows, nv)))
    lower, upper = (
        joint_limits(robot)
        if limits is None
        else (
            per_joint(limits[0], "limits[0] (lower)", model.dof),
            per_joint(limits[1], "limits[1] (upper)", model.dof),
        )
    )

    samples = steps // stride + 1
    need = ((dof + 3 * nv) * samples + (3 * samples if energies else 0)) * rows * 8
    budget = _available_bytes() if max_bytes is None else max_bytes
    if need > budget:
        raise ValueError(
            f"storing {rows} x {samples} samples of {dof} joints needs {need / 2**30:.2f} GiB, more than "
            f"the {budget / 2**30:.2f} GiB available: store fewer samples (stride), states or steps"
        )

    if torque is not None and controller is not None:
        raise ValueError("give torque or controller, not both")
    empty = np.zeros(0)
    args = dict(torque=empty, kp=empty, kd=empty, target=empty, target_qd=empty)
    if callable(torque):
        out = simulate_callable(robot, model, q0a, qd0a, torque, dt, steps, stride, method, lower, upper)
    else:
        if controller is not None:
            kind, gains = controller_arrays(robot, model, controller, q0a)
            args.update(gains)
        elif torque is None:
            kind = "zero"
        else:
            tau = np.asarray(torque, dtype=float)
            if not np.all(np.isfinite(tau)):
                raise ValueError("torque contains NaN or inf")
            if tau.shape == (nv,):
                kind, tau = "constant", np.broadcast_to(tau, (rows, nv))
            elif tau.shape == (steps, nv):
                kind = "series"
            elif tau.shape == (rows, steps, nv):
                kind = "series-per-state"
            else:
                raise ValueError(
                    f"torque: shape {tau.shape}; expected ({nv},) constant, ({steps}, {nv}) one row per step, "
                    f"or ({rows}, {steps}, {nv}) one series per state"
                )
            args["torque"] = contiguous(tau)
        out = _simulate_rust(model, q0a, qd0a, kind, args, dt, steps, stride, method, lower, upper, threads, progress)

    t = np.arange(samples) * (stride * dt)
    names = list(model.coordinate_names)
    if floating:  # limit_joint and nonfinite_joint index the velocity's coordinates (the joints' are already)
        names = [*BASE_VELOCITY_NAMES, *names]
    run = Trajectory(t=t, dt=dt, stride=stride, method=method, coordinate_names=names, **out)
    # a diverged state stopped at its nonfinite_step: its later samples were never written
    diverged = run.nonfinite_step >= 0
    kept = np.ones((rows, samples), dtype=bool)
    if diverged.any():
        kept[diverged] = run.t[None, :] < (run.nonfinite_step[diverged, None] * dt - 0.5 * dt)
        for name in ("q", "qd", "qdd", "tau"):
            getattr(run, name)[~kept] = np.nan
        run.work[~kept] = np.nan
    if energies:
        run.kinetic, run.potential = np.full((rows, samples), np.nan), np.full((rows, samples), np.nan)
        flat_q, flat_qd = run.q[kept], run.qd[kept]
        if len(flat_q) and floating:
            run.kinetic[kept], run.potential[kept] = floating_energies(model, flat_q, flat_qd, threads)
        elif len(flat_q):
            run.kinetic[kept] = kinetic_energy(model, contiguous(flat_q), contiguous(flat_qd), threads=threads)
            run.potential[kept] = potential_energy(model, contiguous(flat_q), threads=threads)
    if single:
        last = int(kept[0].sum())  # a single diverged state: only what was computed
        run.t = run.t[:last]
        for name in ("q", "qd", "qdd", "tau", "work", "kinetic", "potential"):
            if getattr(run, name) is not None:
                setattr(run, name, getattr(run, name)[0][:last])
        for name in ("q_final", "qd_final"):
            setattr(run, name, getattr(run, name)[0])
        for name in ("limit_step", "limit_joint", "nonfinite_step", "nonfinite_joint"):
            setattr(run, name, int(getattr(run, name)[0]))
    return run


def _simulate_rust(model, q0, qd0, kind, args, dt, steps, stride, method, lower, upper, threads, progress):
    call = lambda q, qd, k, tau: _core._simulate(  # noqa: E731
        model,
        q,
        qd,
        dt,
        k,
        stride,
        method,
        kind,
        tau,
        args["kp"],
        args["kd"],
        args["target"],
        args["target_qd"],
        lower,
        upper,
        threads,
    )
    if progress is None:
        return call(q0, qd0, steps, args["torque"])
    # In pieces of whole strides: each piece continues from the last one's final state,
    # its first sample replaces the last one's final sample (same state, and the torque
    # of the next step, as in one call).
    rows = q0.shape[0]
    samples = steps // stride + 1
    piece = max(1, steps // stride // 100) * stride
    out = None
    q, qd, done = q0, qd0, 0
    progress(0, steps)
    while done < steps:
        k = min(piece, steps - done)
        tau = args["torque"]
        if kind == "series":
            tau = tau[done : done + k]
        elif kind == "series-per-state":
            tau = contiguous(tau[:, done : done + k])
        part = call(q, qd, k, tau)
        if out is None:  # q's width may differ from the others' (a floating base: 7 + dof, 6 + dof)
            out = {name: np.empty((rows, samples, part[name].shape[2])) for name in ("q", "qd", "qdd", "tau")}
            out["work"] = np.empty((rows, samples))
            for name in ("limit_step", "limit_joint", "nonfinite_step", "nonfinite_joint"):
                out[name] = np.full(rows, -1, dtype=np.int64)
            work_before = np.zeros(rows)
        first = done // stride
        n = part["q"].shape[1]
        for name in ("q", "qd", "qdd", "tau"):
            out[name][:, first : first + n] = part[name]
        # each piece's work starts at 0 from its first state, the previous piece's last sample
        out["work"][:, first : first + n] = part["work"] + work_before[:, None]
        work_before = out["work"][:, first + n - 1]
        for name in ("limit_step", "nonfinite_step"):
            new = (out[name] < 0) & (part[name] >= 0)
            joint = "limit_joint" if name == "limit_step" else "nonfinite_joint"
            out[joint][new] = part[joint][new]
            out[name][new] = part[name][new] + done
        q, qd, done = part["q_final"], part["qd_final"], done + k
        progress(done, steps)
        if (out["nonfinite_step"] >= 0).all():  # every state diverged: nothing left to integrate
            break
    out["q_final"], out["qd_final"] = q, qd
    if done < steps:
        progress(steps, steps)
    return out
