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

import weakref
from dataclasses import dataclass
from typing import Callable

import numpy as np
import sympy as sp

from .errors import UnboundParameterError
from .model import Robot

# --------------------------------------------------------------------------- spatial algebra


def skew3(w: np.ndarray) -> np.ndarray:
    """3x3 cross-product matrix of a 3-vector: ``skew3(a) @ b == cross(a, b)``."""
    return np.array([[0.0, -w[2], w[1]], [w[2], 0.0, -w[0]], [-w[1], w[0], 0.0]])


def crm(v: np.ndarray) -> np.ndarray:
    """Spatial cross product for motion vectors, ``crm(v) @ m = v x m`` (RBDA ch. 2)."""
    w, u = skew3(v[:3]), skew3(v[3:])
    return np.block([[w, np.zeros((3, 3))], [u, w]])


def crf(v: np.ndarray) -> np.ndarray:
    """Spatial cross product for force vectors, ``crf(v) @ f = v x* f = -crm(v)^T f`` (RBDA ch. 2)."""
    return -crm(v).T


def plux(E: np.ndarray, r: np.ndarray) -> np.ndarray:
    """Plücker motion transform (6x6) to a frame rotated by ``E`` (new coordinates = E old)
    and displaced by ``r`` (origin of the new frame, old coordinates): ``rot(E) xlt(r)``."""
    return np.block([[E, np.zeros((3, 3))], [-E @ skew3(r), E]])


def inverse_motion_transform(X: np.ndarray) -> np.ndarray:
    """Inverse of ``plux(E, r)``: ``[[E^T, 0], [skew(r) E^T, E^T]]``, computed from the blocks."""
    Et = X[:3, :3].T
    r_cross = -Et @ X[3:, :3]  # X[3:, :3] = -E skew(r)
    return np.block([[Et, np.zeros((3, 3))], [r_cross @ Et, Et]])


def mcI(m: float, c: np.ndarray, Ic: np.ndarray) -> np.ndarray:
    """Spatial inertia (6x6) at the body frame's origin from mass ``m``, centre of mass ``c``
    and rotational inertia ``Ic`` about the centre of mass (RBDA ch. 2, spatial_v2's mcI)."""
    C = skew3(c)
    return np.block([[Ic + m * C @ C.T, m * C], [m * C.T, m * np.eye(3)]])


# --------------------------------------------------------------------------- the model as arrays


@dataclass
class _Tree:
    """A numeric Robot as Featherstone's arrays (see the module docstring)."""

    n: int  # number of coordinates
    parent: list[int]  # parent body index, -1 = base
    kind: list[str]  # joint type: revolute, prismatic, fixed
    axis: list[np.ndarray]  # (3,) unit axis in the child frame's axes
    point: list[np.ndarray]  # (3,) a point on the joint's axis, child-frame coordinates
    pose: list[Callable[[float], tuple]]  # q_k -> (R (3,3), p (3,)) child in parent
    S: list[np.ndarray]  # motion subspace (6, 0 or 1) in body coordinates
    dofs: list[np.ndarray]  # coordinate indices of joint k (empty for a fixed joint)
    inertia: list[np.ndarray]  # spatial inertia (6, 6) at the body frame origin
    mass: list[float]
    com: list[np.ndarray]  # (3,) in body frame
    gravity: np.ndarray  # (3,) base frame
    base_mass: float
    base_com: np.ndarray
    link_names: list[str]  # base first, then body k's name at k + 1
    follow: list[tuple[float, float]]  # (c, o): joint k's own coordinate is c q[dofs[k]] + o
    mimic: bool  # whether some joint is a mimic joint
    # per coordinate: rotor inertia Ia, viscous Fv, Coulomb Fc, offset (docs/architecture.md), (n,) each
    armature: np.ndarray = None
    viscous: np.ndarray = None
    coulomb: np.ndarray = None
    offset: np.ndarray = None


_trees: "weakref.WeakKeyDictionary[Robot, _Tree]" = weakref.WeakKeyDictionary()
_q = sp.Symbol("q")


def _floats(matrix) -> np.ndarray:
    return np.array([[float(x) for x in row] for row in matrix.tolist()])


def _tree(robot: Robot) -> _Tree:
    """Convert (once per robot) to arrays; refuse a robot with free symbols."""
    if robot in _trees:
        return _trees[robot]
    free = robot.free_symbols()
    if free:
        names = ", ".join(sorted(str(s) for s in free))
        raise UnboundParameterError(
            f"robot '{robot.name}' has unbound parameters: {names}; bind them with robot.bind({{...}})"
        )
    index = {robot.base: -1}
    kind, axes, points = [j.type for j in robot.joints], [], []
    parent, pose, S, dofs, inertia, mass, com, follow = [], [], [], [], [], [], [], []
    for k, joint in enumerate(robot.joints):
        parent.append(index[joint.parent])
        index[joint.child] = k
        R, p = joint.transform(_q)  # model.py's convention, lambdified to NumPy
        pose.append(sp.lambdify(_q, (R, p), "numpy"))
        axis = _floats(joint.child_axis).ravel()  # in the child frame's axes
        axes.append(axis)
        f = robot.follows(joint)  # (coordinate, multiplier, offset), None when fixed
        c = 1.0 if f is None else float(f[1])
        follow.append((c, 0.0 if f is None else float(f[2])))
        if joint.type == "revolute":
            # the axis is invariant under Rot(axis, q); a child frame off the axis (joint
            # point jp in child coordinates, constant) moves with linear velocity jp x axis
            jp = _floats(joint.joint_point(0)).ravel()
            points.append(jp)
            S.append(c * np.concatenate([axis, np.cross(jp, axis)])[:, None])
        elif joint.type == "prismatic":
            S.append(c * np.concatenate([np.zeros(3), axis])[:, None])
            points.append(np.zeros(3))
        else:
            S.append(np.zeros((6, 0)))
            points.append(np.zeros(3))
        dofs.append(np.array([] if f is None else [f[0]], dtype=int))
        link = robot.links[joint.child]
        m, c, Ic = float(link.mass), _floats(link.com).ravel(), _floats(link.inertia)
        mass.append(m)
        com.append(c)
        inertia.append(mcI(m, c, Ic))
    base = robot.links[robot.base]
    tree = _Tree(
        n=robot.dof,
        parent=parent,
        kind=kind,
        axis=axes,
        point=points,
        pose=pose,
        S=S,
        dofs=dofs,
        inertia=inertia,
        mass=mass,
        com=com,
        gravity=_floats(robot.gravity).ravel(),
        base_mass=float(base.mass),
        base_com=_floats(base.com).ravel(),
        link_names=list(robot.links),
        follow=follow,
        mimic=bool(robot.mimic_joints),
    )
    terms = [
        [float(getattr(j, k)) if getattr(j, k) is not None else 0.0 for j in robot.movable_joints]
        for k in ("armature", "damping", "friction", "torque_offset")
    ]
    tree.armature, tree.viscous, tree.coulomb, tree.offset = (np.array(x, dtype=float) for x in terms)
    _trees[robot] = tree
    return tree


def _state(tree: _Tree, x, name: str) -> np.ndarray:
    x = np.asarray(x, dtype=float)
    if x.shape != (tree.n,):
        raise ValueError(f"{name} must have shape ({tree.n},), got {x.shape}")
    if not np.all(np.isfinite(x)):
        raise ValueError(f"{name} contains NaN or inf")
    return x


def _joint_value(tree: _Tree, k: int, q: np.ndarray) -> float:
    c, o = tree.follow[k]
    return c * float(q[tree.dofs[k]][0]) + o if tree.dofs[k].size else 0.0


def _poses(tree: _Tree, q: np.ndarray) -> list[tuple[np.ndarray, np.ndarray]]:
    """(R, p) of each body in its parent, at ``q``."""
    out = []
    for k in range(len(tree.parent)):
        R, p = tree.pose[k](_joint_value(tree, k, q))
        out.append((np.array(R, dtype=float).reshape(3, 3), np.array(p, dtype=float).ravel()))
    return out


def _xup(tree: _Tree, q: np.ndarray) -> list[np.ndarray]:
    """Plücker transforms parent -> body k: jcalc and Xtree in one, ``Xup = plux(R^T, p)``."""
    return [plux(R.T, p) for R, p in _poses(tree, q)]


def _a_gravity(tree: _Tree) -> np.ndarray:
    return np.concatenate([np.zeros(3), tree.gravity])


# --------------------------------------------------------------------------- algorithms


def rnea(robot: Robot, q, qd, qdd) -> np.ndarray:
    """Inverse dynamics ``tau = M qdd + C qd + g`` (n,), recursive Newton-Euler, RBDA Table 5.1."""
    t = _tree(robot)
    q, qd, qdd = _state(t, q, "q"), _state(t, qd, "qd"), _state(t, qdd, "qdd")
    Xup = _xup(t, q)
    nb = len(t.parent)
    v, a, f = [None] * nb, [None] * nb, [None] * nb
    for i in range(nb):
        vJ = t.S[i] @ qd[t.dofs[i]]
        lam = t.parent[i]
        v_lam = np.zeros(6) if lam < 0 else v[lam]
        a_lam = -_a_gravity(t) if lam < 0 else a[lam]
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
    t = _tree(robot)
    q = _state(t, q, "q")
    Xup = _xup(t, q)
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
    t = _tree(robot)
    q, qd, tau = _state(t, q, "q"), _state(t, qd, "qd"), _state(t, tau, "tau")
    if t.mimic:  # ABA's recursion cannot follow the constraint: solve M qdd = tau - h
        return np.linalg.solve(crba(robot, q), tau - bias(robot, q, qd))
    Xup = _xup(t, q)
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
        a_lam = -_a_gravity(t) if t.parent[i] < 0 else a[t.parent[i]]
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


# ------------------------------------------------------------ world-frame view: Coriolis matrix


def _world(t: _Tree, q: np.ndarray):
    """World-frame (base-frame) quantities at ``q``.

    Returns ``S0[k]`` (6, 0/1): joint k's motion subspace in base coordinates (at the base
    origin), ``I0[k]`` (6, 6): body k's spatial inertia in base coordinates, and
    ``path[k]``: the bodies from the root to k, k included.
    """
    Xup = _xup(t, q)
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
    t = _tree(robot)
    q, qd = _state(t, q, "q"), _state(t, qd, "qd")
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
    t = _tree(robot)
    q, qd = _state(t, q, "q"), _state(t, qd, "qd")
    Xup = _xup(t, q)
    v, T = [None] * len(t.parent), 0.0
    for i in range(len(t.parent)):
        v_lam = np.zeros(6) if t.parent[i] < 0 else v[t.parent[i]]
        v[i] = Xup[i] @ v_lam + t.S[i] @ qd[t.dofs[i]]
        T += 0.5 * v[i] @ t.inertia[i] @ v[i]
    return float(T + 0.5 * t.armature @ qd**2)  # + the rotors' 1/2 Ia qd^2


def potential_energy(robot: Robot, q) -> float:
    """Gravitational potential ``V = -sum_links m g . p_com`` (zero at the base origin),
    summed over every link, the base and links welded to it included (a constant)."""
    t = _tree(robot)
    q = _state(t, q, "q")
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
    t = _tree(robot)
    q = _state(t, q, "q")
    X = np.tile(np.eye(4), (len(t.parent) + 1, 1, 1))
    for k, (R, p) in enumerate(_poses(t, q)):
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
    t = _tree(robot)
    q = _state(t, q, "q")
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


def _f_ext_bodies(t: _Tree, Xup, dXup, f_ext, frame: str):
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


def _dxup(t: _Tree, Xup, dq):
    return [-crm(t.S[k] @ dq[t.dofs[k]]) @ Xup[k] for k in range(len(t.parent))]


def _rnea_tangent(t: _Tree, q, qd, qdd, dq, dqd, dqdd, f_ext=None, frame="local"):
    """``(tau, d tau)`` along ``(dq, dqd, dqdd)``: RBDA Table 5.1 with a tangent per line."""
    Xup = _xup(t, q)
    dXup = _dxup(t, Xup, dq)
    fb, dfb = _f_ext_bodies(t, Xup, dXup, f_ext, frame)
    nb = len(t.parent)
    v, dv, a, da, f, df = [None] * nb, [None] * nb, [None] * nb, [None] * nb, [None] * nb, [None] * nb
    for i in range(nb):
        S, I, lam = t.S[i], t.inertia[i], t.parent[i]
        vJ, dvJ = S @ qd[t.dofs[i]], S @ dqd[t.dofs[i]]
        v_lam, dv_lam = (np.zeros(6), np.zeros(6)) if lam < 0 else (v[lam], dv[lam])
        a_lam, da_lam = (-_a_gravity(t), np.zeros(6)) if lam < 0 else (a[lam], da[lam])
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


def _aba_tangent(t: _Tree, q, qd, tau, dq, dqd, dtau, f_ext=None, frame="local"):
    """``(qdd, d qdd)`` along ``(dq, dqd, dtau)``: RBDA Table 7.1 with a tangent per line."""
    Xup = _xup(t, q)
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
        a_lam, da_lam = (-_a_gravity(t), np.zeros(6)) if lam < 0 else (a[lam], da[lam])
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
    t = _tree(robot)
    q, qd, qdd = _state(t, q, "q"), _state(t, qd, "qd"), _state(t, qdd, "qdd")
    Z = np.zeros(t.n)
    return _rnea_tangent(t, q, qd, qdd, Z, Z, Z, f_ext, frame)[0]


def aba_ext(robot: Robot, q, qd, tau, f_ext, frame: str = "local") -> np.ndarray:
    """Forward dynamics with external wrenches (n,): RBDA Table 7.1 with
    ``p^A_i = v x* I v - f^x_i`` (see the section comment)."""
    t = _tree(robot)
    q, qd, tau = _state(t, q, "q"), _state(t, qd, "qd"), _state(t, tau, "tau")
    Z = np.zeros(t.n)
    return _aba_tangent(t, q, qd, tau, Z, Z, Z, f_ext, frame)[0]


def rnea_derivatives(robot: Robot, q, qd, qdd, f_ext=None, frame: str = "local"):
    """``(dtau_dq, dtau_dqd, M)``, each (n, n), ``[i, j] = d tau_i / d x_j``, by forward-mode
    differentiation of RBDA Table 5.1 (one tangent pass per coordinate)."""
    t = _tree(robot)
    q, qd, qdd = _state(t, q, "q"), _state(t, qd, "qd"), _state(t, qdd, "qdd")
    return _forward_mode(t, _rnea_tangent, q, qd, qdd, f_ext, frame)


def aba_derivatives(robot: Robot, q, qd, tau, f_ext=None, frame: str = "local"):
    """``(dqdd_dq, dqdd_dqd, Minv)``, each (n, n), ``[i, j] = d qdd_i / d x_j``, by
    forward-mode differentiation of RBDA Table 7.1 (one tangent pass per coordinate)."""
    t = _tree(robot)
    q, qd, tau = _state(t, q, "q"), _state(t, qd, "qd"), _state(t, tau, "tau")
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


def minverse(robot: Robot, q) -> np.ndarray:
    """``M(q)^-1`` (n, n), by inverting the CRBA's M (NumPy's LU)."""
    return np.linalg.inv(crba(robot, q))


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
    t = _tree(robot)
    q, qd = _state(t, q, "q"), _state(t, qd, "qd")
    if isinstance(link, str):
        if link not in t.link_names:
            raise ValueError(f"unknown link '{link}'; links are {t.link_names}")
        b = t.link_names.index(link) - 1
    else:
        b = int(link) - 1
    nb = len(t.parent)
    X, Xd = [None] * nb, [None] * nb
    for k, (R, p) in enumerate(_poses(t, q)):
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
