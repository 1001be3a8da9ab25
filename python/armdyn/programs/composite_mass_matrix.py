"""The joint-space inertia matrix M(q) by composite links, as a straight-line program.

The composite rigid-body method (Walker and Orin 1982, method 3; Featherstone's CRBA,
*Rigid Body Dynamics Algorithms* sec. 6.2) in the barycentric parameters of
:func:`armdyn.programs.customized_ne.standard_parameters` (Khalil and Dombre 2002,
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
and dead code is removed as in :mod:`armdyn.programs.customized_ne`.
"""

from __future__ import annotations

import sympy as sp

from ..model import Robot
from .customized_ne import joint_frames, standard_parameters
from .program import Builder, Program
from .vectors import UPPER, ZERO, cross, dot, minus, mv, plus, rows, times, vadd, vscale


def _rotate_symmetric(b: Builder, R, J, hint) -> list:
    """R J R^T (3x3 rows) for a symmetric J (rows), computing the upper triangle only."""
    A = [
        [b.let(plus(*[times(R[r][k], J[k][s]) for k in range(3)]), f"{hint}A{r + 1}{s + 1}") for s in range(3)]
        for r in range(3)
    ]
    out = [[None] * 3 for _ in range(3)]
    for r, s in UPPER:
        out[r][s] = out[s][r] = dot(A[r], R[s])
    return out


def composite_mass_matrix(robot: Robot, parameters=None, builder: Builder | None = None) -> tuple[Program, list]:
    """M (n x n, row-major outputs) as a :class:`Program` of q and the barycentric
    parameters. Returns ``(program, definitions)`` as
    :func:`~armdyn.programs.customized_ne.customized_newton_euler`."""
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
        tag = str(robot.link_index(name))
        m, ms, J = parameters[name]
        ms, J = list(ms), rows(J)
        for child in robot.children(name):
            c = child.child
            R, p = frames[c]
            MSr = b.vector(mv(R, MSc[c]), f"MSr{str(robot.link_index(c))}")
            pMS, pp = dot(p, MSr), dot(p, p)
            Jr = _rotate_symmetric(b, R, Jc[c], f"Jr{str(robot.link_index(c))}")
            # J + Jr + Mc (pp 1 - p p^T) + 2 pMS 1 - p MSr^T - MSr p^T, summed in this order
            # (floats may round differently in another)
            Jnew = [[None] * 3 for _ in range(3)]
            for r, s in UPPER:
                diagonal = r == s
                e = plus(plus(J[r][s], Jr[r][s]), times(Mc[c], minus(pp if diagonal else ZERO, times(p[r], p[s]))))
                e = plus(e, times(2, pMS) if diagonal else ZERO)
                Jnew[r][s] = Jnew[s][r] = minus(minus(e, times(p[r], MSr[s])), times(MSr[r], p[s]))
            J = Jnew
            ms = [plus(plus(ms[i], MSr[i]), times(Mc[c], p[i])) for i in range(3)]
            m = plus(m, Mc[c])
        Mc[name] = b.let(m, f"Mc{tag}")
        MSc[name] = b.vector(ms, f"MSc{tag}")
        Jn = [[None] * 3 for _ in range(3)]
        for r, s in UPPER:
            Jn[r][s] = Jn[s][r] = b.let(J[r][s], f"Jc{tag}_{'xyz'[r]}{'xyz'[s]}")
        Jc[name] = Jn

    M = [[sp.Integer(0)] * n for _ in range(n)]
    for joint in robot.joints:
        j = robot.coordinate_index(joint)
        if j is None:
            continue
        name, z = joint.child, list(joint.axis)
        if joint.type == "revolute":
            nv, fv = mv(Jc[name], z), cross(z, MSc[name])
        else:
            nv, fv = cross(MSc[name], z), vscale(Mc[name], z)
        M[j][j] = b.let(dot(nv if joint.type == "revolute" else fv, z), f"M{j + 1}{j + 1}")
        link = name
        while True:
            up = robot.parent_joint(link)
            parent = up.parent
            if parent == robot.base:
                break
            R, p = frames[link]
            hint = f"{j + 1}_{str(robot.link_index(parent))}"
            fv = b.vector(mv(R, fv), f"f{hint}")
            nv = b.vector(vadd(mv(R, nv), cross(p, fv)), f"n{hint}")
            pj = robot.parent_joint(parent)
            i = robot.coordinate_index(pj)
            if i is not None:
                M[i][j] = M[j][i] = b.let(dot(nv if pj.type == "revolute" else fv, list(pj.axis)), f"M{i + 1}{j + 1}")
            link = parent
    return b.program([M[r][c] for r in range(n) for c in range(n)], (n, n)), definitions
