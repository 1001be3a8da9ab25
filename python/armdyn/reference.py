"""Reference rigid-body dynamics in plain NumPy: the test oracle.

Small and readable on purpose, in the style of Featherstone's spatial_v2, for ONE state
(``q, qd, qdd`` of shape ``(n,)``). It is slow; the fast engine is :mod:`armdyn.numeric`.
Every function has the signature of its counterpart in ``armdyn.numeric``:

    rnea(robot, q, qd, qdd)       -> tau (n,)       M qdd + C qd + g (+ Fv qd + Fc sign(qd); Ia in M,
                                                    the torque offset in g, as docs/architecture.md)
    crba(robot, q)                -> M (n, n)
    aba(robot, q, qd, tau)        -> qdd (n,)
    gravity(robot, q)             -> g (n,)         = rnea(q, 0, 0)
    bias(robot, q, qd)            -> h (n,)         = rnea(q, qd, 0) = C qd + g
    coriolis_matrix(robot, q, qd) -> C (n, n)       Christoffel symbols of M (Mdot - 2C skew)
    kinetic_energy(robot, q, qd)  -> T              = 1/2 qd' M qd
    potential_energy(robot, q)    -> V              = -sum over all links (base included) of m gravity . p_com
    forward_kinematics(robot, q)  -> (nlinks, 4, 4) pose of every link frame in the base frame,
                                                    order list(robot.links) (base first)
    jacobian(robot, q, link)      -> J (6, n)       rows [v; w] of the link frame's origin, base axes
    rnea_ext / aba_ext(..., f_ext, frame)           rnea / aba with one wrench [f; n] per link
    rnea_derivatives(robot, q, qd, qdd[, f_ext, frame]) -> (dtau_dq, dtau_dqd, M)   forward mode
    aba_derivatives(robot, q, qd, tau[, f_ext, frame])  -> (dqdd_dq, dqdd_dqd, Minv) forward mode
    minverse(robot, q)            -> M^-1 (n, n)    (NumPy's inverse of crba)
    gravity_derivatives(robot, q) -> dg/dq (n, n)
    jacobian_dot(robot, q, qd, link) -> dJ/dt (6, n)  product rule on the pose chain

The spatial algebra and the robot as arrays are in :mod:`armdyn.reference_tree`, the
derivatives and external wrenches in :mod:`armdyn.reference_derivatives`; every function
above is exported from here.

Conventions
-----------
* Spatial vectors are ``[angular; linear]`` (Featherstone). Motion vectors ``v``, force
  vectors ``f``; ``X`` is a Plücker motion transform, forces transform with ``X^-T``.
* Bodies are indexed like ``robot.joints``: body ``k`` is the child link of joint ``k``;
  ``parent[k]`` is the body index of its parent link, -1 for the base. Fixed joints are
  kept as bodies whose motion subspace ``S`` is empty (6 x 0), so every algorithm below is
  Featherstone's table line by line, with no special case for them.
* ``Xup[k]`` transforms motion vectors from the parent body's coordinates to body ``k``'s.
  It is built from the child pose ``(R, p)`` given by :meth:`armdyn.model.Joint.transform`
  (the one definition of the frame convention): ``Xup = plux(R^T, p)``.
* Gravity enters as a fictitious base acceleration ``a_0 = -[0; g]`` (RBDA ch. 5).
* A mimic joint (``q_m = c q_l + o``, :meth:`armdyn.model.Robot.follows`) is a body whose
  ``S`` is ``c`` times its axis, acting on its leader's coordinate ``l``: its velocity
  and acceleration are ``S qd_l``, ``S qdd_l``, and everything it contributes to a
  coordinate (``S^T f`` to ``tau``, entries of ``M``, Jacobian columns) is *added* to
  ``l``'s. Forward dynamics of such a robot solves ``M qdd = tau - h`` (the constraint
  couples bodies that ABA treats separately).

References
----------
[RBDA] R. Featherstone, *Rigid Body Dynamics Algorithms*, Springer 2008:
       ch. 2 spatial algebra (spatial_v2's crm, crf, mcI, plux), Table 5.1 RNEA,
       Table 6.2 CRBA, Table 7.1 ABA.
[SHV]  M. W. Spong, S. Hutchinson, M. Vidyasagar, *Robot Modeling and Control*, Wiley 2006:
       ch. 4 geometric Jacobian, ch. 7 Euler-Lagrange equations and Christoffel symbols.
"""

from __future__ import annotations

import numpy as np

from .model import Robot
from .reference_derivatives import (
    aba_derivatives,
    aba_ext,
    gravity_derivatives,
    jacobian_dot,
    rnea_derivatives,
    rnea_ext,
)
from .reference_tree import (
    Tree,
    a_gravity,
    checked_state,
    crf,
    crm,
    inverse_motion_transform,
    mcI,
    plux,
    poses,
    skew3,
    tree_of,
    xup,
)

__all__ = [
    "aba",
    "aba_derivatives",
    "aba_ext",
    "bias",
    "coriolis_matrix",
    "crba",
    "crf",
    "crm",
    "forward_kinematics",
    "gravity",
    "gravity_derivatives",
    "inverse_motion_transform",
    "jacobian",
    "jacobian_dot",
    "kinetic_energy",
    "mcI",
    "minverse",
    "plux",
    "potential_energy",
    "rnea",
    "rnea_derivatives",
    "rnea_ext",
    "skew3",
]


# --------------------------------------------------------------------------- algorithms


def rnea(robot: Robot, q, qd, qdd) -> np.ndarray:
    """Inverse dynamics ``tau = M qdd + C qd + g`` (n,), recursive Newton-Euler, RBDA Table 5.1."""
    t = tree_of(robot)
    q, qd, qdd = checked_state(t, q, "q"), checked_state(t, qd, "qd"), checked_state(t, qdd, "qdd")
    Xup = xup(t, q)
    nb = len(t.parent)
    v, a, f = [None] * nb, [None] * nb, [None] * nb
    for i in range(nb):
        vJ = t.S[i] @ qd[t.dofs[i]]
        lam = t.parent[i]
        v_lam = np.zeros(6) if lam < 0 else v[lam]
        a_lam = -a_gravity(t) if lam < 0 else a[lam]
        v[i] = Xup[i] @ v_lam + vJ
        a[i] = Xup[i] @ a_lam + t.S[i] @ qdd[t.dofs[i]] + crm(v[i]) @ vJ
        f[i] = t.inertia[i] @ a[i] + crf(v[i]) @ t.inertia[i] @ v[i]
    tau = np.zeros(t.n)
    for i in reversed(range(nb)):
        tau[t.dofs[i]] += t.S[i].T @ f[i]  # += : a mimic joint adds to its leader's
        if t.parent[i] >= 0:
            f[t.parent[i]] = f[t.parent[i]] + Xup[i].T @ f[i]
    # joint terms (docs/architecture.md): Ia qdd + Fv qd + Fc sign(qd) + offset, np.sign(0) = 0
    return tau + t.armature * qdd + t.viscous * qd + t.coulomb * np.sign(qd) + t.offset


def crba(robot: Robot, q) -> np.ndarray:
    """Joint-space inertia matrix ``M`` (n, n), composite-rigid-body algorithm, RBDA Table 6.2."""
    t = tree_of(robot)
    q = checked_state(t, q, "q")
    Xup = xup(t, q)
    nb = len(t.parent)
    IC = [I.copy() for I in t.inertia]
    for i in reversed(range(nb)):
        if t.parent[i] >= 0:
            IC[t.parent[i]] = IC[t.parent[i]] + Xup[i].T @ IC[i] @ Xup[i]
    M = np.zeros((t.n, t.n))
    for i in range(nb):
        F = IC[i] @ t.S[i]
        M[np.ix_(t.dofs[i], t.dofs[i])] += t.S[i].T @ F  # += : mimic joints share a coordinate
        j = i
        while t.parent[j] >= 0:
            F = Xup[j].T @ F
            j = t.parent[j]
            M[np.ix_(t.dofs[i], t.dofs[j])] += F.T @ t.S[j]
            M[np.ix_(t.dofs[j], t.dofs[i])] += t.S[j].T @ F
    return M + np.diag(t.armature)  # rotor inertias on the diagonal


def aba(robot: Robot, q, qd, tau) -> np.ndarray:
    """Forward dynamics ``qdd`` (n,), articulated-body algorithm, RBDA Table 7.1."""
    t = tree_of(robot)
    q, qd, tau = checked_state(t, q, "q"), checked_state(t, qd, "qd"), checked_state(t, tau, "tau")
    if t.mimic:  # ABA's recursion cannot follow the constraint: solve M qdd = tau - h
        return np.linalg.solve(crba(robot, q), tau - bias(robot, q, qd))
    Xup = xup(t, q)
    nb = len(t.parent)
    v, c, IA, pA = [None] * nb, [None] * nb, [None] * nb, [None] * nb
    for i in range(nb):  # pass 1: velocities, velocity-product accelerations, bias forces
        vJ = t.S[i] @ qd[t.dofs[i]]
        v_lam = np.zeros(6) if t.parent[i] < 0 else v[t.parent[i]]
        v[i] = Xup[i] @ v_lam + vJ
        c[i] = crm(v[i]) @ vJ
        IA[i] = t.inertia[i].copy()
        pA[i] = crf(v[i]) @ t.inertia[i] @ v[i]
    U, Dinv, u = [None] * nb, [None] * nb, [None] * nb
    # the joint terms: Ia joins D_i = S^T I^A S + Ia; friction and offset are taken off tau
    tau = tau - t.viscous * qd - t.coulomb * np.sign(qd) - t.offset
    for i in reversed(range(nb)):  # pass 2: articulated-body inertias and bias forces
        U[i] = IA[i] @ t.S[i]
        Dinv[i] = np.linalg.inv(t.S[i].T @ U[i] + np.diag(t.armature[t.dofs[i]]))  # 1x1, or 0x0 for a fixed joint
        u[i] = tau[t.dofs[i]] - t.S[i].T @ pA[i]
        lam = t.parent[i]
        if lam >= 0:
            Ia = IA[i] - U[i] @ Dinv[i] @ U[i].T
            pa = pA[i] + Ia @ c[i] + U[i] @ Dinv[i] @ u[i]
            IA[lam] = IA[lam] + Xup[i].T @ Ia @ Xup[i]
            pA[lam] = pA[lam] + Xup[i].T @ pa
    qdd = np.zeros(t.n)
    a = [None] * nb
    for i in range(nb):  # pass 3: accelerations
        a_lam = -a_gravity(t) if t.parent[i] < 0 else a[t.parent[i]]
        a[i] = Xup[i] @ a_lam + c[i]
        qdd_i = Dinv[i] @ (u[i] - U[i].T @ a[i])
        qdd[t.dofs[i]] = qdd_i
        a[i] = a[i] + t.S[i] @ qdd_i
    return qdd


def gravity(robot: Robot, q) -> np.ndarray:
    """Gravity torques ``g(q) = rnea(q, 0, 0)`` (n,)."""
    n = robot.dof
    return rnea(robot, q, np.zeros(n), np.zeros(n))


def bias(robot: Robot, q, qd) -> np.ndarray:
    """Nonlinear effects ``h = C(q, qd) qd + g(q) = rnea(q, qd, 0)`` (n,)."""
    return rnea(robot, q, qd, np.zeros(robot.dof))


def minverse(robot: Robot, q) -> np.ndarray:
    """``M(q)^-1`` (n, n), by inverting the CRBA's M (NumPy's LU)."""
    return np.linalg.inv(crba(robot, q))


# ------------------------------------------------------------ world-frame view: Coriolis matrix


def _world(t: Tree, q: np.ndarray):
    """World-frame (base-frame) quantities at ``q``.

    Returns ``S0[k]`` (6, 0/1): joint k's motion subspace in base coordinates (at the base
    origin), ``I0[k]`` (6, 6): body k's spatial inertia in base coordinates, and
    ``path[k]``: the bodies from the root to k, k included.
    """
    Xup = xup(t, q)
    nb = len(t.parent)
    X0, S0, I0, path = [None] * nb, [None] * nb, [None] * nb, [None] * nb
    for k in range(nb):
        lam = t.parent[k]
        X0[k] = Xup[k] if lam < 0 else Xup[k] @ X0[lam]  # base -> body k
        S0[k] = inverse_motion_transform(X0[k]) @ t.S[k]
        I0[k] = X0[k].T @ t.inertia[k] @ X0[k]
        path[k] = ([] if lam < 0 else path[lam]) + [k]
    return S0, I0, path


def coriolis_matrix(robot: Robot, q, qd) -> np.ndarray:
    """Coriolis/centrifugal matrix ``C(q, qd)`` (n, n) built from the Christoffel symbols of M
    [SHV ch. 7]:

        C_ij = sum_k 1/2 (dM_ij/dq_k + dM_ik/dq_j - dM_jk/dq_i) qd_k,

    so ``C qd = bias - gravity`` and ``Mdot - 2C`` is skew-symmetric. ``dM/dq`` is exact
    (no finite differences): in base coordinates ``M = sum_b J_b^T I0_b J_b``, with ``J_b``
    the (6, n) matrix whose columns are the world axes ``S0_j`` of the joints j on b's path.
    Moving joint k by dq_k turns everything in k's subtree by the twist ``S0_k dq_k``, so a
    motion vector m and an inertia I0 attached to that subtree change as (RBDA ch. 2)

        dm/dq_k = crm(S0_k) m,     dI0/dq_k = crf(S0_k) I0 - I0 crm(S0_k),

    and everything outside k's subtree does not change.
    """
    t = tree_of(robot)
    q, qd = checked_state(t, q, "q"), checked_state(t, qd, "qd")
    S0, I0, path = _world(t, q)
    nb, n = len(t.parent), t.n

    def jacobian_world(b):
        J = np.zeros((6, n))
        for j in path[b]:
            J[:, t.dofs[j]] += S0[j]
        return J

    dM = np.zeros((n, n, n))  # dM[:, :, c] = dM/dq_c
    for k in range(nb):
        if not t.dofs[k].size:
            continue  # a fixed joint has no coordinate
        s = S0[k][:, 0]
        for b in range(nb):
            if k not in path[b]:
                continue  # body b is not in k's subtree: it and its Jacobian do not move
            J = jacobian_world(b)
            dJ = np.zeros((6, n))
            for j in path[b][path[b].index(k) :]:  # joints at or below k on b's path move
                dJ[:, t.dofs[j]] += crm(s) @ S0[j]
            dI = crf(s) @ I0[b] - I0[b] @ crm(s)
            dM[:, :, t.dofs[k][0]] += dJ.T @ I0[b] @ J + J.T @ dI @ J + J.T @ I0[b] @ dJ
    # Christoffel symbols gamma[i, j, k] = 1/2 (dM_ij/dq_k + dM_ik/dq_j - dM_jk/dq_i), contracted with qd
    gamma = 0.5 * (dM + dM.transpose(0, 2, 1) - dM.transpose(2, 0, 1))
    return gamma @ qd


# --------------------------------------------------------------------------- energies


def kinetic_energy(robot: Robot, q, qd) -> float:
    """Kinetic energy ``T = sum_b 1/2 v_b^T I_b v_b`` (body velocities from RBDA Table 5.1)."""
    t = tree_of(robot)
    q, qd = checked_state(t, q, "q"), checked_state(t, qd, "qd")
    Xup = xup(t, q)
    v, T = [None] * len(t.parent), 0.0
    for i in range(len(t.parent)):
        v_lam = np.zeros(6) if t.parent[i] < 0 else v[t.parent[i]]
        v[i] = Xup[i] @ v_lam + t.S[i] @ qd[t.dofs[i]]
        T += 0.5 * v[i] @ t.inertia[i] @ v[i]
    return float(T + 0.5 * t.armature @ qd**2)  # + the rotors' 1/2 Ia qd^2


def potential_energy(robot: Robot, q) -> float:
    """Gravitational potential ``V = -sum_links m g . p_com`` (zero at the base origin),
    summed over every link, the base and links welded to it included (a constant)."""
    t = tree_of(robot)
    q = checked_state(t, q, "q")
    X = forward_kinematics(robot, q)
    V = -t.base_mass * t.gravity @ t.base_com
    for k in range(len(t.parent)):
        R, p = X[k + 1][:3, :3], X[k + 1][:3, 3]
        V -= t.mass[k] * t.gravity @ (p + R @ t.com[k])
    return float(V)


# --------------------------------------------------------------------------- kinematics


def forward_kinematics(robot: Robot, q) -> np.ndarray:
    """Homogeneous pose (4x4) of every link frame in the base frame, shape (nlinks, 4, 4),
    in the order of ``list(robot.links)`` (base first: the identity). Composed directly
    from the joints' (R, p), independently of the spatial algebra above."""
    t = tree_of(robot)
    q = checked_state(t, q, "q")
    X = np.tile(np.eye(4), (len(t.parent) + 1, 1, 1))
    for k, (R, p) in enumerate(poses(t, q)):
        local = np.eye(4)
        local[:3, :3], local[:3, 3] = R, p
        X[k + 1] = (np.eye(4) if t.parent[k] < 0 else X[t.parent[k] + 1]) @ local
    return X


def jacobian(robot: Robot, q, link) -> np.ndarray:
    """Geometric Jacobian (6, n) of the origin of ``link``'s frame, rows ``[v; w]`` in base axes
    (Pinocchio's LOCAL_WORLD_ALIGNED) [SHV ch. 4]: for each joint j on the link's path, with
    world axis z_j and a point o_j on that axis,

        revolute:   J_v = z_j x (o_link - o_j),   J_w = z_j
        prismatic:  J_v = z_j,                    J_w = 0

    ``link`` is a link name or an index into ``list(robot.links)``.
    """
    t = tree_of(robot)
    q = checked_state(t, q, "q")
    if isinstance(link, str):
        if link not in t.link_names:
            raise ValueError(f"unknown link '{link}'; links are {t.link_names}")
        b = t.link_names.index(link) - 1
    else:
        if not -1 <= int(link) - 1 < len(t.parent):
            raise ValueError(f"link index {link} out of range 0..{len(t.parent)}")
        b = int(link) - 1
    X = forward_kinematics(robot, q)
    o_link = X[b + 1][:3, 3]
    J = np.zeros((6, t.n))
    while b >= 0:
        if t.dofs[b].size:
            R = X[b + 1][:3, :3]
            o, z = X[b + 1][:3, 3] + R @ t.point[b], R @ t.axis[b]
            col, c = t.dofs[b][0], t.follow[b][0]  # a mimic joint moves c times its leader's rate
            if t.kind[b] == "revolute":
                J[:3, col] += c * np.cross(z, o_link - o)
                J[3:, col] += c * z
            else:  # prismatic
                J[:3, col] += c * z
        b = t.parent[b]
    return J
