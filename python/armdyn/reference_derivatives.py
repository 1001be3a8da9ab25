"""The NumPy oracle's derivatives: forward-mode RNEA and ABA, with external wrenches.

The oracle for the Rust core's analytical derivatives (``rnea_derivatives``,
``aba_derivatives``, ``gravity_derivatives``, ``jacobian_dot``) and for ``rnea``/``aba``
with one external wrench per link (``rnea_ext``, ``aba_ext``); signatures and conventions
as in :mod:`armdyn.reference`, which exports them all.
"""

from __future__ import annotations

import numpy as np

from .model import Robot
from .reference_tree import Tree, a_gravity, checked_state, crf, crm, poses, skew3, tree_of, xup

# --------------------------------------------------------------------------- derivatives
#
# The oracle for the analytical derivatives of the Rust core (Carpentier & Mansard's
# recursions): here, plain forward-mode differentiation. Each function below carries a
# tangent ``d`` beside every quantity of Featherstone's tables (product rule, line by
# line) for one direction ``(dq, dqd, dqdd or dtau)``; a derivative matrix is the stack
# of the n directions e_c. The joint transform's derivative is ``dXup_k/dq_k =
# -crm(S_k) Xup_k`` (Xup = XJ(q) XT with XJ the rotation about / translation along S).
#
# External wrenches ``f_ext``: shape (nlinks, 6), one ``[f; n]`` (force, then moment)
# per link of ``list(robot.links)`` (base first; its row acts on the base only). With
# ``frame="local"`` the moment is about the link frame's origin and both are in link
# axes; with ``frame="world"`` about the base frame's origin, in base axes (a wrench
# fixed in space). They enter RBDA's tables as ``f_i = I a + v x* I v - f^x_i``.


def _f_ext_bodies(t: Tree, Xup, dXup, f_ext, frame: str):
    """Body-frame external forces ``[n; f]`` (nb, 6) and their tangents, from (nlinks, 6)."""
    nb = len(t.parent)
    fb, dfb = np.zeros((nb, 6)), np.zeros((nb, 6))
    if f_ext is None:
        return fb, dfb
    W = np.asarray(f_ext, dtype=float)
    if W.shape != (nb + 1, 6) or not np.all(np.isfinite(W)):
        raise ValueError(f"f_ext must be a finite ({nb + 1}, 6) array, got shape {W.shape}")
    if frame not in ("local", "world"):
        raise ValueError(f"frame must be 'local' or 'world', got {frame!r}")
    X0, dX0 = [None] * nb, [None] * nb
    for k in range(nb):
        w = np.concatenate([W[k + 1, 3:], W[k + 1, :3]])  # [n; f]
        lam = t.parent[k]
        X0[k] = Xup[k] if lam < 0 else Xup[k] @ X0[lam]
        dX0[k] = dXup[k] if lam < 0 else dXup[k] @ X0[lam] + Xup[k] @ dX0[lam]
        if frame == "local":  # body k's frame is link k + 1's frame
            fb[k] = w
        else:  # forces transform with X^-T; d(X^-T) = -X^-T dX^T X^-T
            XinvT = np.linalg.inv(X0[k]).T
            fb[k] = XinvT @ w
            dfb[k] = -XinvT @ dX0[k].T @ XinvT @ w
    return fb, dfb


def _dxup(t: Tree, Xup, dq):
    return [-crm(t.S[k] @ dq[t.dofs[k]]) @ Xup[k] for k in range(len(t.parent))]


def _rnea_tangent(t: Tree, q, qd, qdd, dq, dqd, dqdd, f_ext=None, frame="local"):
    """``(tau, d tau)`` along ``(dq, dqd, dqdd)``: RBDA Table 5.1 with a tangent per line."""
    Xup = xup(t, q)
    dXup = _dxup(t, Xup, dq)
    fb, dfb = _f_ext_bodies(t, Xup, dXup, f_ext, frame)
    nb = len(t.parent)
    v, dv, a, da, f, df = [None] * nb, [None] * nb, [None] * nb, [None] * nb, [None] * nb, [None] * nb
    for i in range(nb):
        S, I, lam = t.S[i], t.inertia[i], t.parent[i]
        vJ, dvJ = S @ qd[t.dofs[i]], S @ dqd[t.dofs[i]]
        v_lam, dv_lam = (np.zeros(6), np.zeros(6)) if lam < 0 else (v[lam], dv[lam])
        a_lam, da_lam = (-a_gravity(t), np.zeros(6)) if lam < 0 else (a[lam], da[lam])
        v[i] = Xup[i] @ v_lam + vJ
        dv[i] = dXup[i] @ v_lam + Xup[i] @ dv_lam + dvJ
        a[i] = Xup[i] @ a_lam + S @ qdd[t.dofs[i]] + crm(v[i]) @ vJ
        da[i] = dXup[i] @ a_lam + Xup[i] @ da_lam + S @ dqdd[t.dofs[i]] + crm(dv[i]) @ vJ + crm(v[i]) @ dvJ
        f[i] = I @ a[i] + crf(v[i]) @ I @ v[i] - fb[i]
        df[i] = I @ da[i] + crf(dv[i]) @ I @ v[i] + crf(v[i]) @ I @ dv[i] - dfb[i]
    tau, dtau = np.zeros(t.n), np.zeros(t.n)
    for i in reversed(range(nb)):
        tau[t.dofs[i]] = t.S[i].T @ f[i]
        dtau[t.dofs[i]] = t.S[i].T @ df[i]
        lam = t.parent[i]
        if lam >= 0:
            f[lam] = f[lam] + Xup[i].T @ f[i]
            df[lam] = df[lam] + dXup[i].T @ f[i] + Xup[i].T @ df[i]
    # joint friction, rotor inertia and offset (docs/architecture.md) with their tangent (Coulomb's is 0:
    # sign(qd) is piecewise constant)
    tau = tau + t.armature * qdd + t.viscous * qd + t.coulomb * np.sign(qd) + t.offset
    dtau = dtau + t.armature * dqdd + t.viscous * dqd
    return tau, dtau


def _aba_tangent(t: Tree, q, qd, tau, dq, dqd, dtau, f_ext=None, frame="local"):
    """``(qdd, d qdd)`` along ``(dq, dqd, dtau)``: RBDA Table 7.1 with a tangent per line."""
    Xup = xup(t, q)
    dXup = _dxup(t, Xup, dq)
    fb, dfb = _f_ext_bodies(t, Xup, dXup, f_ext, frame)
    nb = len(t.parent)
    v, dv, c, dc = [None] * nb, [None] * nb, [None] * nb, [None] * nb
    IA, dIA, pA, dpA = [None] * nb, [None] * nb, [None] * nb, [None] * nb
    for i in range(nb):
        S, I, lam = t.S[i], t.inertia[i], t.parent[i]
        vJ, dvJ = S @ qd[t.dofs[i]], S @ dqd[t.dofs[i]]
        v_lam, dv_lam = (np.zeros(6), np.zeros(6)) if lam < 0 else (v[lam], dv[lam])
        v[i] = Xup[i] @ v_lam + vJ
        dv[i] = dXup[i] @ v_lam + Xup[i] @ dv_lam + dvJ
        c[i] = crm(v[i]) @ vJ
        dc[i] = crm(dv[i]) @ vJ + crm(v[i]) @ dvJ
        IA[i], dIA[i] = I.copy(), np.zeros((6, 6))
        pA[i] = crf(v[i]) @ I @ v[i] - fb[i]
        dpA[i] = crf(dv[i]) @ I @ v[i] + crf(v[i]) @ I @ dv[i] - dfb[i]
    U, dU, Dinv, dDinv, u, du = [None] * nb, [None] * nb, [None] * nb, [None] * nb, [None] * nb, [None] * nb
    for i in reversed(range(nb)):
        S, lam = t.S[i], t.parent[i]
        U[i], dU[i] = IA[i] @ S, dIA[i] @ S
        # joint terms: D = S^T I^A S + Ia; friction and offset are torques not delivered
        k = t.dofs[i]
        Dinv[i] = np.linalg.inv(S.T @ U[i] + np.diag(t.armature[k]))
        dDinv[i] = -Dinv[i] @ (S.T @ dU[i]) @ Dinv[i]
        u[i] = tau[k] - S.T @ pA[i] - (t.viscous[k] * qd[k] + t.coulomb[k] * np.sign(qd[k]) + t.offset[k])
        du[i] = dtau[k] - S.T @ dpA[i] - t.viscous[k] * dqd[k]
        if lam >= 0:
            Ia = IA[i] - U[i] @ Dinv[i] @ U[i].T
            dIa = dIA[i] - dU[i] @ Dinv[i] @ U[i].T - U[i] @ dDinv[i] @ U[i].T - U[i] @ Dinv[i] @ dU[i].T
            pa = pA[i] + Ia @ c[i] + U[i] @ Dinv[i] @ u[i]
            dpa = (
                dpA[i]
                + dIa @ c[i]
                + Ia @ dc[i]
                + dU[i] @ Dinv[i] @ u[i]
                + U[i] @ dDinv[i] @ u[i]
                + U[i] @ Dinv[i] @ du[i]
            )
            X, dX = Xup[i], dXup[i]
            IA[lam] = IA[lam] + X.T @ Ia @ X
            dIA[lam] = dIA[lam] + dX.T @ Ia @ X + X.T @ dIa @ X + X.T @ Ia @ dX
            pA[lam] = pA[lam] + X.T @ pa
            dpA[lam] = dpA[lam] + dX.T @ pa + X.T @ dpa
    qdd, dqdd = np.zeros(t.n), np.zeros(t.n)
    a, da = [None] * nb, [None] * nb
    for i in range(nb):
        S, lam = t.S[i], t.parent[i]
        a_lam, da_lam = (-a_gravity(t), np.zeros(6)) if lam < 0 else (a[lam], da[lam])
        ap = Xup[i] @ a_lam + c[i]
        dap = dXup[i] @ a_lam + Xup[i] @ da_lam + dc[i]
        qdd_i = Dinv[i] @ (u[i] - U[i].T @ ap)
        dqdd_i = dDinv[i] @ (u[i] - U[i].T @ ap) + Dinv[i] @ (du[i] - dU[i].T @ ap - U[i].T @ dap)
        qdd[t.dofs[i]], dqdd[t.dofs[i]] = qdd_i, dqdd_i
        a[i], da[i] = ap + S @ qdd_i, dap + S @ dqdd_i
    return qdd, dqdd


def rnea_ext(robot: Robot, q, qd, qdd, f_ext, frame: str = "local") -> np.ndarray:
    """Inverse dynamics with external wrenches ``tau = M qdd + C qd + g - sum J^T w`` (n,):
    RBDA Table 5.1 with ``f_i = I a + v x* I v - f^x_i`` (see the section comment)."""
    t = tree_of(robot)
    q, qd, qdd = checked_state(t, q, "q"), checked_state(t, qd, "qd"), checked_state(t, qdd, "qdd")
    Z = np.zeros(t.n)
    return _rnea_tangent(t, q, qd, qdd, Z, Z, Z, f_ext, frame)[0]


def aba_ext(robot: Robot, q, qd, tau, f_ext, frame: str = "local") -> np.ndarray:
    """Forward dynamics with external wrenches (n,): RBDA Table 7.1 with
    ``p^A_i = v x* I v - f^x_i`` (see the section comment)."""
    t = tree_of(robot)
    q, qd, tau = checked_state(t, q, "q"), checked_state(t, qd, "qd"), checked_state(t, tau, "tau")
    Z = np.zeros(t.n)
    return _aba_tangent(t, q, qd, tau, Z, Z, Z, f_ext, frame)[0]


def rnea_derivatives(robot: Robot, q, qd, qdd, f_ext=None, frame: str = "local"):
    """``(dtau_dq, dtau_dqd, M)``, each (n, n), ``[i, j] = d tau_i / d x_j``, by forward-mode
    differentiation of RBDA Table 5.1 (one tangent pass per coordinate)."""
    t = tree_of(robot)
    q, qd, qdd = checked_state(t, q, "q"), checked_state(t, qd, "qd"), checked_state(t, qdd, "qdd")
    return _forward_mode(t, _rnea_tangent, q, qd, qdd, f_ext, frame)


def aba_derivatives(robot: Robot, q, qd, tau, f_ext=None, frame: str = "local"):
    """``(dqdd_dq, dqdd_dqd, Minv)``, each (n, n), ``[i, j] = d qdd_i / d x_j``, by
    forward-mode differentiation of RBDA Table 7.1 (one tangent pass per coordinate)."""
    t = tree_of(robot)
    q, qd, tau = checked_state(t, q, "q"), checked_state(t, qd, "qd"), checked_state(t, tau, "tau")
    return _forward_mode(t, _aba_tangent, q, qd, tau, f_ext, frame)


def _forward_mode(t, tangent, q, qd, x, f_ext, frame):
    """The three (n, n) Jacobians of ``tangent``'s output with respect to q, qd and x
    (qdd or tau), ``[i, j] = d out_i / d arg_j``: one tangent pass per coordinate, seeded
    with a unit vector in one argument and zeros in the other two."""
    E, Z = np.eye(t.n), np.zeros(t.n)
    cols = [
        [tangent(t, q, qd, x, *(E[c] if k == w else Z for k in range(3)), f_ext, frame)[1] for c in range(t.n)]
        for w in range(3)
    ]
    return tuple(np.array(c).reshape(t.n, t.n).T for c in cols)


def gravity_derivatives(robot: Robot, q) -> np.ndarray:
    """``dg/dq`` (n, n) = ``dtau_dq`` at ``qd = qdd = 0``."""
    n = robot.dof
    return rnea_derivatives(robot, q, np.zeros(n), np.zeros(n))[0]


def jacobian_dot(robot: Robot, q, qd, link) -> np.ndarray:
    """``dJ/dt`` (6, n) of :func:`jacobian` (rows ``[v; w]``, base axes), by the product rule
    on the pose chain: with ``X_k = X_parent L_k(q_k)``, ``Xdot_k = Xdot_parent L_k + X_parent
    dL_k/dq_k qd_k``, where ``dL/dq`` is ``[R skew(axis), 0]`` (revolute: ``R = R_place
    Rot(axis, q)``) or ``[0, R axis]`` (prismatic); then each column ``[z x (p - o); z]`` or
    ``[z; 0]`` is differentiated: ``zdot = Rdot axis``, ``odot``, ``pdot`` from ``Xdot``."""
    t = tree_of(robot)
    q, qd = checked_state(t, q, "q"), checked_state(t, qd, "qd")
    if isinstance(link, str):
        if link not in t.link_names:
            raise ValueError(f"unknown link '{link}'; links are {t.link_names}")
        b = t.link_names.index(link) - 1
    else:
        b = int(link) - 1
    nb = len(t.parent)
    X, Xd = [None] * nb, [None] * nb
    for k, (R, p) in enumerate(poses(t, q)):
        L, dL = np.eye(4), np.zeros((4, 4))
        L[:3, :3], L[:3, 3] = R, p
        if t.dofs[k].size:
            rate = qd[t.dofs[k]][0]
            if t.kind[k] == "revolute":  # about the axis through the joint point (child frame)
                dL[:3, :3] = R @ skew3(t.axis[k]) * rate
                dL[:3, 3] = R @ np.cross(t.point[k], t.axis[k]) * rate
            else:
                dL[:3, 3] = R @ t.axis[k] * rate
        lam = t.parent[k]
        Xp, Xpd = (np.eye(4), np.zeros((4, 4))) if lam < 0 else (X[lam], Xd[lam])
        X[k], Xd[k] = Xp @ L, Xpd @ L + Xp @ dL
    Jd = np.zeros((6, t.n))
    if b < 0:
        return Jd
    p, pd = X[b][:3, 3], Xd[b][:3, 3]
    j = b
    while j >= 0:
        if t.dofs[j].size:
            z, zd = X[j][:3, :3] @ t.axis[j], Xd[j][:3, :3] @ t.axis[j]
            # a point on the axis (the frame origin unless the link frame sits off it)
            o, od = X[j][:3, 3] + X[j][:3, :3] @ t.point[j], Xd[j][:3, 3] + Xd[j][:3, :3] @ t.point[j]
            col = t.dofs[j][0]
            if t.kind[j] == "revolute":
                Jd[:3, col] = np.cross(zd, p - o) + np.cross(z, pd - od)
                Jd[3:, col] = zd
            else:
                Jd[:3, col] = zd
        j = t.parent[j]
    return Jd
