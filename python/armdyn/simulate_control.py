"""The torques of :func:`armdyn.simulate.simulate` that depend on the state: its
controllers' arrays (checked and laid out for the Rust core) and the Python-callable path
(a NumPy loop), for every robot: 1-dof joints, joints of several coordinates, a floating
base.

Controllers on a configuration that is not flat (spherical, planar, free joints; a
floating base): the error is on the tangent space, ``e = difference(q, q*)``
(:func:`armdyn.configuration.difference`, Pinocchio's ``difference(q, q*)``): the
velocity that moves ``q`` to the target ``q*`` in unit time, in ``q``'s frame (a ball
joint's ``log(R^T R*)`` in its child frame, the sign such that ``Kp e`` turns toward the
target). Gains ``kp``, ``kd`` and ``target_qd`` are per velocity coordinate, ``target``
a configuration (q's layout). On 1-dof joints ``e = q* - q``, as before.

A floating base is not actuated: the controllers' arrays cover the joints only
(``target`` the joints' configuration, ``q[7:]``'s width; ``kp``, ``kd``,
``target_qd`` ``v[6:]``'s), and the base's six rows of ``tau`` are zero.
:class:`~armdyn.trajectory.PD` acts on the joints; with ``gravity_compensation`` it adds
the joints' rows of the generalized gravity ``g(q)`` (Pinocchio's
``computeGeneralizedGravity``: what holds the joints still while the base is held; a
robot in free fall needs none). :class:`~armdyn.trajectory.ComputedTorque` gives the
joints the acceleration ``qdd* = Kp e + Kd (qd* - qd)`` and lets the base take the one
that follows (collocated partial feedback linearization, Spong 1994): with ``M_bb`` the
whole robot's composite inertia, ``a_b = -M_bb^-1 (M_bj qdd* + h_b)`` and ``tau_j = M_jb
a_b + M_jj qdd* + h_j``, so the joints' errors obey ``e'' + Kd e' + Kp e = 0`` as on a
fixed base while the base moves as the joints' motion drives it (no wrench on it: the
momentum changes by gravity alone).
"""

from __future__ import annotations

import numpy as np

from . import _core
from .simulate_arrays import contiguous
from .trajectory import PD, ComputedTorque

__all__ = ["controller_arrays", "simulate_callable"]

BASE_Q, BASE_V = 7, 6


def _rows_of(x, name: str, what: str, rows: int, width: int, scalar: bool = False) -> np.ndarray:
    """``x`` (width,) or (rows, width) (or a scalar, if ``scalar``), finite, as (rows,
    width); None is zeros. ``what`` it should be, said when its shape is wrong."""
    if x is None:
        return np.zeros((rows, width))
    try:
        a = np.asarray(x, dtype=float)
    except (TypeError, ValueError):
        raise ValueError(f"{name}: cannot be read as an array of numbers") from None
    if scalar and a.ndim == 0:
        a = np.full(width, float(a))
    if a.shape not in ((width,), (rows, width)):
        raise ValueError(f"{name} ({what}): expected ({width},) or ({rows}, {width}) values, got shape {a.shape}")
    if not np.all(np.isfinite(a)):
        raise ValueError(f"{name} contains NaN or inf")
    return np.broadcast_to(a, (rows, width))


def controller_arrays(robot, model, controller, q0: np.ndarray) -> tuple[str, dict]:
    """The Rust core's torque kind and arrays for ``controller`` on ``robot`` (compiled
    ``model``) from the states ``q0`` (N, nq): ``kp``, ``kd`` (nv,), ``target`` (N, nq),
    ``target_qd`` (N, nv), at the whole widths (a floating base's rows padded: zero gains
    and velocity, the start's pose, none of which acts). ValueError naming a bad value."""
    floating = bool(getattr(model, "floating", False))
    nq, nv = getattr(model, "nq", model.dof), getattr(model, "nv", model.dof)
    bq, bv = (BASE_Q, BASE_V) if floating else (0, 0)
    rows = q0.shape[0]
    if isinstance(controller, PD):
        kind = "pd-gravity" if controller.gravity_compensation else "pd"
    elif isinstance(controller, ComputedTorque):
        kind = "computed-torque"
    else:
        raise ValueError(f"controller must be an armdyn.simulate.PD or ComputedTorque, got {type(controller).__name__}")
    # what each array covers: the whole widths, or the joints' (a floating base's rows are not actuated)
    covers = {
        "q": "the joints' configuration, q[7:]: the base is not actuated" if floating else "a configuration",
        "v": "the joints' velocity coordinates, v[6:]: the base is not actuated"
        if floating
        else "one per velocity coordinate",
    }
    gains = {}
    for name in ("kp", "kd"):
        a = _rows_of(getattr(controller, name), f"controller.{name}", f"a scalar or {covers['v']}", 1, nv - bv, True)
        gains[name] = contiguous(np.concatenate([np.zeros(bv), a[0]]))
    target = np.array(q0, dtype=float)
    target[:, bq:] = _rows_of(controller.target, "controller.target", covers["q"], rows, nq - bq)
    if nq != nv and hasattr(robot, "configuration_layout"):  # a quaternion or (cos, sin) pair off unit length,
        # named (a compiled model's: by the core)
        from .configuration import check_configuration

        check_configuration(robot, target, "controller.target")
    target_qd = np.zeros((rows, nv))
    target_qd[:, bv:] = _rows_of(controller.target_qd, "controller.target_qd", covers["v"], rows, nv - bv)
    return kind, dict(kp=gains["kp"], kd=gains["kd"], target=contiguous(target), target_qd=contiguous(target_qd))


def _v_of_q(robot, nq: int) -> np.ndarray:
    """Per coordinate of q, the first velocity coordinate that moves it (a quaternion's:
    its block's first angular one), as the Rust core names a non-finite state."""
    from .configuration import group_layout

    layout = group_layout(robot)
    out = np.zeros(nq, dtype=np.int64)
    out[layout.flat_q] = layout.flat_v
    for iq, iv in zip(layout.se3_q, layout.se3_v):
        out[iq[:3]], out[iq[3:]] = iv[:3], iv[3]
    for iq, iv in zip(layout.so3_q, layout.so3_v):
        out[iq] = iv[0]
    for iq, iv in zip(layout.se2_q, layout.se2_v):
        out[iq[:2]], out[iq[2:]] = iv[:2], iv[2]
    return out


def simulate_callable(robot, model, q0, qd0, torque, dt, steps, stride, method, lower, upper):
    """The slow path: a NumPy loop calling ``torque(t, q, qd)`` (q (N, nq), qd (N, nv)) at
    every stage, ``aba`` batched over the states in Rust. On a configuration that is not
    flat the steps are the Rust integrators' (semi-implicit Euler ``q' = q (+) h v'``, RK4
    as Runge-Kutta-Munthe-Kaas with the core's ``q (+) xi`` and local rate); on 1-dof
    joints they reduce to ``q + h v`` and the classical RK4."""
    rows, nq = q0.shape
    nv = qd0.shape[1]
    flat = nq == nv and not getattr(model, "floating", False)
    if flat:
        flat_q = flat_v = v_of_q = np.arange(nq)
        plus, rate = (lambda q, xi: q + xi), (lambda theta, v: v)
    else:
        from .configuration import group_layout

        if not hasattr(robot, "configuration_layout"):
            raise ValueError(
                f"a torque callable on '{robot.name}' (a floating base or joints of several coordinates) needs the "
                "robot itself (armdyn.load's), not its compiled model: the Python loop steps along its joints' groups"
            )
        layout = group_layout(robot)
        flat_q, flat_v, v_of_q = layout.flat_q, layout.flat_v, _v_of_q(robot, nq)
        plus = lambda q, xi: _core._manifold_integrate(model, contiguous(q), contiguous(xi))  # noqa: E731
        rate = lambda theta, v: _core._manifold_local_rate(model, contiguous(theta), contiguous(v))  # noqa: E731
    base_v = nv - len(lower)  # a floating base's six: the limits are the joints'
    samples = steps // stride + 1
    out = {name: np.empty((rows, samples, nq if name == "q" else nv)) for name in ("q", "qd", "qdd", "tau")}
    out["work"] = np.empty((rows, samples))
    work = np.zeros(rows)  # of the torque, integrated by the same method as the state
    limit_step = np.full(rows, -1, dtype=np.int64)
    limit_joint = np.full(rows, -1, dtype=np.int64)
    nonfinite = np.full(rows, -1, dtype=np.int64)
    nonfinite_joint = np.full(rows, -1, dtype=np.int64)

    def tau_at(k, t, q, qd):
        try:
            tau = torque(t, q.copy(), qd.copy())
        except Exception as err:  # noqa: BLE001 - the user's error, shown with the step
            raise ValueError(
                f"torque callable failed at step {k} (t = {t:.6g} s): {type(err).__name__}: {err}"
            ) from err
        if np.iscomplexobj(tau):  # float() would drop the imaginary part with only a warning
            raise ValueError(f"torque callable returned complex values at step {k} (t = {t:.6g} s); torques are real")
        try:
            tau = np.asarray(tau, dtype=float)
        except (TypeError, ValueError):
            raise ValueError(f"torque callable returned a non-numeric value at step {k} (t = {t:.6g} s)") from None
        if tau.shape not in ((nv,), (rows, nv)):
            raise ValueError(
                f"torque callable returned shape {tau.shape} at step {k} (t = {t:.6g} s); "
                f"expected ({nv},) or ({rows}, {nv}) (one per velocity coordinate)"
            )
        return contiguous(np.broadcast_to(tau, (rows, nv)))

    def acc(k, t, q, qd):
        live = nonfinite < 0
        if not live.all():  # diverged states stopped: finite stand-ins (their start), their samples are dropped
            q, qd = np.where(live[:, None], q, q0), np.where(live[:, None], qd, 0.0)
        tau = tau_at(k, t, q, qd)
        try:
            return model.aba(contiguous(q), contiguous(qd), tau, None), tau
        except ValueError:
            pass
        # no finite acceleration for some state (velocities so large that the dynamics
        # overflow: a diverging run): that state stops here, the others go on
        a = np.full_like(qd, np.nan)
        for i in np.flatnonzero(live):
            try:
                a[i] = model.aba(contiguous(q[i]), contiguous(qd[i]), tau[i], None)
            except ValueError:
                nonfinite[i], nonfinite_joint[i] = k, int(np.argmax(np.abs(qd[i])))
        return a, tau

    def check(k, q, qd):
        if len(flat_q):  # limits on the 1-dof joints only
            joints = q[:, flat_q]
            outside = (joints < lower[flat_v - base_v]) | (joints > upper[flat_v - base_v])
            new = (limit_step < 0) & outside.any(axis=1)
            limit_step[new], limit_joint[new] = k, flat_v[outside[new].argmax(axis=1)]
        bad_v, bad_q = ~np.isfinite(qd), ~np.isfinite(q)
        bad = (nonfinite < 0) & (bad_v.any(axis=1) | bad_q.any(axis=1))
        for i in np.flatnonzero(bad):
            nonfinite[i] = k
            nonfinite_joint[i] = min([*np.flatnonzero(bad_v[i]), *v_of_q[bad_q[i]]])

    q, qd = q0.copy(), qd0.copy()
    check(0, q, qd)
    h = dt
    with np.errstate(over="ignore", invalid="ignore"):  # a diverging state is reported, not warned about
        for k in range(steps + 1):
            t = k * dt
            if k < steps or k % stride == 0:
                a1, tau1 = acc(k, t, q, qd)
            if k % stride == 0:
                s = k // stride
                out["q"][:, s], out["qd"][:, s], out["qdd"][:, s], out["tau"][:, s] = q, qd, a1, tau1
                out["work"][:, s] = work
            if k == steps:
                break
            if method == "euler":
                work = work + h * (tau1 * qd).sum(axis=1)
                qd = qd + h * a1
                q = plus(q, h * qd)
            else:  # the stages at q (+) theta_i, theta' = dexp^-1_{-theta}(v) (the classical RK4 when flat)
                k1 = qd
                q2, qd2 = plus(q, h / 2 * k1), qd + h / 2 * a1
                a2, tau2 = acc(k, t + h / 2, q2, qd2)
                k2 = rate(h / 2 * k1, qd2)
                q3, qd3 = plus(q, h / 2 * k2), qd + h / 2 * a2
                a3, tau3 = acc(k, t + h / 2, q3, qd3)
                k3 = rate(h / 2 * k2, qd3)
                q4, qd4 = plus(q, h * k3), qd + h * a3
                a4, tau4 = acc(k, t + h, q4, qd4)
                k4 = rate(h * k3, qd4)
                work = work + h / 6 * (
                    (tau1 * qd).sum(axis=1)
                    + 2 * (tau2 * qd2).sum(axis=1)
                    + 2 * (tau3 * qd3).sum(axis=1)
                    + (tau4 * qd4).sum(axis=1)
                )
                q = plus(q, h / 6 * (k1 + 2 * k2 + 2 * k3 + k4))
                qd = qd + h / 6 * (a1 + 2 * a2 + 2 * a3 + a4)
            check(k + 1, q, qd)
            if (nonfinite >= 0).all():
                break
    out.update(
        q_final=q,
        qd_final=qd,
        limit_step=limit_step,
        limit_joint=limit_joint,
        nonfinite_step=nonfinite,
        nonfinite_joint=nonfinite_joint,
    )
    return out
