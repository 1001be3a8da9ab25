"""One trajectory with SciPy's ``solve_ivp`` (adaptive step, error control) on armdyn's
``aba``: :func:`simulate_adaptive` (exported by :mod:`armdyn.simulate`).

A configuration that is not flat (a floating base; spherical, planar or free joints) is
integrated in its embedding: the state holds ``q`` as stored (quaternions ``x, y, z, w``,
planar ``x, y, cos, sin``) and moves it by the exact kinematics of each group,
``q' = Q(q) v`` (:func:`configuration_rate`), whose flow stays on the manifold. The
solver's own steps leave it by no more than its tolerance; every evaluation and every
returned sample is projected back (quaternions and ``(cos, sin)`` pairs normalised), so
the dynamics always see a valid configuration. No chart, no singularity, the solver's
error control unchanged (it measures the embedded coordinates).
"""

from __future__ import annotations

import math

import numpy as np

from .numeric import compiled_model, kinetic_energy, potential_energy
from .simulate_arrays import BASE_VELOCITY_NAMES, checked_state, contiguous, floating_energies, per_joint

__all__ = ["simulate_adaptive", "configuration_rate"]


def configuration_rate(layout, q: np.ndarray, v: np.ndarray) -> np.ndarray:
    """``dq/dt`` (nq,) of the configuration ``q`` (nq,) moving with the velocity ``v``
    (nv,), ``layout`` the robot's groups (:func:`armdyn.configuration.group_layout`): 1-dof
    joints ``v``; SE(3) (a floating base, free joints) ``p' = R v_lin``, the quaternion
    turning at ``v_ang``; SO(3) the quaternion turning at ``v``; SE(2) ``(x, y)' = R
    (vx, vy)``, ``(cos, sin)' = wz (-sin, cos)``. The velocities in the moving frame, as
    :func:`armdyn.configuration.integrate`'s, so ``integrate(q, h v) = q + h
    configuration_rate(q, v) + O(h^2)``."""
    from .configuration import quaternion_multiply, rotate_vector

    def turning(quat, w):  # 1/2 quat (x) (w, 0): R' = R [w]x
        return 0.5 * quaternion_multiply(quat, np.append(w, 0.0))

    out = np.zeros_like(q)
    out[layout.flat_q] = v[layout.flat_v]
    for iq, iv in zip(layout.se3_q, layout.se3_v):
        quat = q[iq[3:]]
        out[iq[:3]] = rotate_vector(quat, v[iv[:3]])
        out[iq[3:]] = turning(quat, v[iv[3:]])
    for iq, iv in zip(layout.so3_q, layout.so3_v):
        out[iq] = turning(q[iq], v[iv])
    for iq, iv in zip(layout.se2_q, layout.se2_v):
        c, s = q[iq[2]], q[iq[3]]
        vx, vy, wz = v[iv]
        out[iq] = [c * vx - s * vy, s * vx + c * vy, -s * wz, c * wz]
    return out


def _project(layout, q: np.ndarray) -> np.ndarray:
    """``q`` (..., nq) with every quaternion and ``(cos, sin)`` pair normalised."""
    q = np.array(q, dtype=float)
    blocks = [iq[3:] for iq in layout.se3_q] + list(layout.so3_q) + [iq[2:] for iq in layout.se2_q]
    for index in blocks:
        q[..., index] /= np.linalg.norm(q[..., index], axis=-1, keepdims=True)
    return q


def simulate_adaptive(
    robot, q0, qd0=None, *, duration, torque=None, rtol=1e-10, atol=1e-12, method="DOP853", t_eval=None
):
    """One trajectory with SciPy's ``solve_ivp`` (adaptive step, error control) on ``aba``.

    q0 (nq,), qd0 (nv,) (both dof for 1-dof joints on a fixed base). torque: None, (nv,)
    constant, or a callable ``torque(t, q, qd)`` with q (nq,), qd (nv,) returning (nv,).
    t_eval: the sample times (default: 101 evenly spaced over ``[0, duration]``). Returns
    a :class:`~armdyn.trajectory.Trajectory` of single-state shape (``dt`` is ``nan``: the
    steps are SciPy's). A floating base or joints of several coordinates: integrated in
    the embedding (the module docstring); limits checked on the 1-dof joints.
    """
    from scipy.integrate import solve_ivp

    from .trajectory import Trajectory, joint_limits

    model = compiled_model(robot)
    floating = bool(getattr(model, "floating", False))
    nq, nv = getattr(model, "nq", model.dof), getattr(model, "nv", model.dof)
    flat = nq == nv and not floating
    q0 = checked_state(q0, "q0", nq)
    qd0 = np.zeros(nv) if qd0 is None else checked_state(qd0, "qd0", nv)
    if q0.ndim != 1 or qd0.ndim != 1:
        raise ValueError(f"simulate_adaptive integrates one state: q0 ({nq},), qd0 ({nv},)")
    if not (math.isfinite(duration) and duration > 0):
        raise ValueError(f"duration must be a positive finite number of seconds, got {duration!r}")
    if flat:
        project = lambda q: q  # noqa: E731
        rate = lambda q, v: v  # noqa: E731
        flat_q = flat_v = np.arange(nq)
    else:
        from .configuration import check_configuration, group_layout

        if not hasattr(robot, "configuration_layout"):
            raise ValueError(
                f"simulate_adaptive on '{robot.name}' (a floating base or joints of several coordinates) needs the "
                "robot itself (armdyn.load's), not its compiled model: the kinematics follow its joints' groups"
            )
        layout = group_layout(robot)
        check_configuration(robot, q0, "q0")
        project = lambda q: _project(layout, q)  # noqa: E731
        rate = lambda q, v: configuration_rate(layout, q, v)  # noqa: E731
        flat_q, flat_v = layout.flat_q, layout.flat_v
    if torque is None:
        tau_of = lambda t, q, qd: np.zeros(nv)  # noqa: E731
    elif callable(torque):
        tau_of = torque
    else:
        const = per_joint(torque, "torque", nv)
        tau_of = lambda t, q, qd: const  # noqa: E731
    t_eval = np.linspace(0.0, duration, 101) if t_eval is None else np.asarray(t_eval, dtype=float)

    def f(t, x):  # x = (q, qd, W): the torque's work integrated with the state
        q, qd = project(x[:nq]), x[nq : nq + nv]
        tau = np.asarray(tau_of(t, q, qd), dtype=float)
        return np.concatenate(
            [rate(q, qd), model.aba(contiguous(q), contiguous(qd), contiguous(tau), None), [tau @ qd]]
        )

    sol = solve_ivp(
        f, (0.0, duration), np.concatenate([q0, qd0, [0.0]]), method=method, rtol=rtol, atol=atol, t_eval=t_eval
    )
    if not sol.success:
        raise ValueError(f"solve_ivp failed: {sol.message}")
    q, qd = contiguous(project(sol.y[:nq].T)), contiguous(sol.y[nq : nq + nv].T)
    tau = contiguous(np.array([tau_of(t, a, b) for t, a, b in zip(sol.t, q, qd)], dtype=float).reshape(len(sol.t), nv))
    qdd = model.aba(q, qd, tau, None)
    lower, upper = joint_limits(robot)
    base_v = nv - len(lower)  # a floating base's six: the limits are the joints'
    joints = q[:, flat_q]
    outside = (joints < lower[flat_v - base_v]) | (joints > upper[flat_v - base_v])
    first = int(np.flatnonzero(outside.any(axis=1))[0]) if outside.any() else -1
    names = [*(BASE_VELOCITY_NAMES if floating else ()), *model.coordinate_names]
    run = Trajectory(
        t=sol.t,
        q=q,
        qd=qd,
        qdd=qdd,
        tau=tau,
        q_final=q[-1],
        qd_final=qd[-1],
        limit_step=first,
        limit_joint=int(flat_v[outside[first].argmax()]) if first >= 0 else -1,
        nonfinite_step=-1,
        dt=float("nan"),
        stride=1,
        method=method,
        coordinate_names=names,
        work=sol.y[nq + nv].copy(),
    )
    if floating:
        run.kinetic, run.potential = floating_energies(model, q, qd)
    else:
        run.kinetic = kinetic_energy(model, q, qd)
        run.potential = potential_energy(model, q)
    return run
