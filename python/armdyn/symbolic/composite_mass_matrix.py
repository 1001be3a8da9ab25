"""The joint-space inertia matrix M(q) by composite links, as a straight-line program.

The composite rigid-body method (Walker and Orin 1982, method 3; Featherstone's CRBA,
*Rigid Body Dynamics Algorithms* sec. 6.2) in the barycentric parameters of
:func:`armdyn.symbolic.customized_ne.standard_parameters` (Khalil and Dombre 2002,
sec. 9.4.2): composite link j (link j and everything beyond it) has mass ``Mc_j``,
first moment ``MSc_j`` and inertia ``Jc_j`` about link j's origin, in link j's frame.
Inward, for each child c of j with frame ``(R, p)`` in j::

    MSr  = R MSc_c
    Mc_j  += Mc_c
    MSc_j += MSr + Mc_c p
    Jc_j  += R Jc_c R^T + Mc_c (p.p 1 - p p^T) + 2 (p.MSr) 1 - p MSr^T - MSr p^T

(the last three terms: the parallel axis theorem for a body whose centre of mass is not
at its origin). A unit acceleration of joint j (axis z, everything else at rest) needs
the wrench at link j's origin, in link j's frame::

    revolute:  n = Jc_j z,        f = z x MSc_j
    prismatic: n = MSc_j x z,     f = Mc_j z

and ``M[i, j]`` is that wrench carried to each ancestor i (``f <- R f``,
``n <- R n + p x R f``) projected on joint i's axis: ``z_i . n`` (revolute) or
``z_i . f`` (prismatic). Only the upper triangle is computed; zeros and ones propagate
and dead code is removed as in :mod:`armdyn.symbolic.customized_ne`.
"""

from __future__ import annotations

import sympy as sp

from ..codegen.program import Builder, Program
from ..model import Robot
from .customized_ne import _safe, joint_frames, standard_parameters

_UPPER = ((0, 0), (0, 1), (1, 1), (0, 2), (1, 2), (2, 2))


def _rotate_symmetric(b: Builder, R, J, hint) -> sp.Matrix:
    """R J R^T for a symmetric J, computing the upper triangle only."""
    A = sp.Matrix(3, 3, lambda r, s: b.let((R[r, :] * J[:, s])[0], f"{hint}A{r + 1}{s + 1}"))
    out = sp.zeros(3, 3)
    for r, s in _UPPER:
        out[r, s] = out[s, r] = (A[r, :] * R[s, :].T)[0]
    return out


def composite_mass_matrix(robot: Robot, parameters=None, builder: Builder | None = None) -> tuple[Program, list]:
    """M (n x n, row-major outputs) as a :class:`Program` of q and the barycentric
    parameters. Returns ``(program, definitions)`` as
    :func:`~armdyn.symbolic.customized_ne.customized_newton_euler`."""
    robot = robot.canonical()  # link frames on their joints (frames off the axis: same dynamics)
    n = robot.dof
    definitions = []
    if parameters is None:
        parameters, definitions = standard_parameters(robot)
    b = builder or Builder(reserved=robot.free_symbols() | set(robot.q) | {s for s, _ in definitions})
    frames = joint_frames(robot, b)
    Mc, MSc, Jc = {}, {}, {}
    for joint in reversed(robot.joints):
        name = joint.child
        tag = _safe(str(robot.link_index(name)))
        m, ms, J = parameters[name]
        for child in robot.children(name):
            c = child.child
            R, p = frames[c]
            MSr = b.vector(R * MSc[c], f"MSr{_safe(str(robot.link_index(c)))}")
            pMS = (p.T * MSr)[0]
            pp = (p.T * p)[0]
            Jr = _rotate_symmetric(b, R, Jc[c], f"Jr{_safe(str(robot.link_index(c)))}")
            J = J + Jr + Mc[c] * (pp * sp.eye(3) - p * p.T) + 2 * pMS * sp.eye(3) - p * MSr.T - MSr * p.T
            ms = ms + MSr + Mc[c] * p
            m = m + Mc[c]
        Mc[name] = b.let(m, f"Mc{tag}")
        MSc[name] = b.vector(ms, f"MSc{tag}")
        Jn = sp.zeros(3, 3)
        for r, s in _UPPER:
            Jn[r, s] = Jn[s, r] = b.let(J[r, s], f"Jc{tag}_{'xyz'[r]}{'xyz'[s]}")
        Jc[name] = Jn

    M = [[sp.Integer(0)] * n for _ in range(n)]
    for joint in robot.joints:
        j = robot.coordinate_index(joint)
        if j is None:
            continue
        name, z = joint.child, joint.axis
        if joint.type == "revolute":
            nv, fv = Jc[name] * z, z.cross(MSc[name])
        else:
            nv, fv = MSc[name].cross(z), Mc[name] * z
        M[j][j] = b.let((nv if joint.type == "revolute" else fv).dot(z), f"M{j + 1}{j + 1}")
        link = name
        while True:
            up = robot.parent_joint(link)
            parent = up.parent
            if parent == robot.base:
                break
            R, p = frames[link]
            hint = f"{j + 1}_{_safe(str(robot.link_index(parent)))}"
            fv = b.vector(R * fv, f"f{hint}")
            nv = b.vector(R * nv + p.cross(fv), f"n{hint}")
            pj = robot.parent_joint(parent)
            i = robot.coordinate_index(pj)
            if i is not None:
                M[i][j] = M[j][i] = b.let((nv if pj.type == "revolute" else fv).dot(pj.axis), f"M{i + 1}{j + 1}")
            link = parent
    return b.program([M[r][c] for r in range(n) for c in range(n)], (n, n)), definitions
