"""Grouped inertial parameters: what of each link's inertia can ride on its parent.

Khalil's grouping rules (W. Khalil, E. Dombre, *Modeling, Identification and Control of
Robots*, 2002, sec. 9.3, the base inertial parameters; M. Gautier, W. Khalil, "Direct
calculation of minimum set of inertial parameters of serial robots", IEEE Trans. Robotics
and Automation 6(3), 1990), stated here as one rigid-body fact and applied in closed form,
tip to base:

* **revolute joint j about z_j**: the part of link j's inertia that is unchanged by a
  rotation about z_j and has no inertia about z_j itself -- mass ``M_j``, first moment
  ``(0, 0, MZ_j)`` and inertia ``diag(YY_j, YY_j, 0)`` about the origin -- has a spatial
  inertia ``I_s`` with ``I_s S_j = 0`` (S_j the joint's motion subspace) and
  ``X(q)^* I_s X(q) = I_s``. Its kinetic and potential energies do not depend on q_j or
  qd_j, so it moves as if fixed to the parent: it is taken off link j (``XX_j -= YY_j``,
  ``YY_j = MZ_j = M_j = 0``) and added to the parent through the joint's fixed placement;
* **prismatic joint j along z_j**: the rotational part alone (``m = 0``, ``MS = 0``,
  ``J_j``) is unchanged by a translation, so all of ``J_j`` moves to the parent.

Adding a body of mass ``m``, first moment ``h`` and inertia ``J`` (about its origin) to
the parent through the placement ``(R, p)`` of the frame it is expressed in (parallel
axis theorem with the first moment, the same expression as the composite links of
:mod:`armdyn.programs.composite_mass_matrix`)::

    M'  = M + m
    MS' = MS + R h + m p
    J'  = J + R J R^T + m (p.p 1 - p p^T) + 2 (p.R h) 1 - p (R h)^T - (R h) p^T

What reaches the fixed base is dropped (it never moves). The equations of motion are
unchanged (the Lagrangian is the same function of q, qd), so the customized algorithms
evaluated at the grouped parameters give the same tau, g, M and C, with the zeros
propagated: fewer operations per state. The grouped parameters are computed once per
parameter set (``XX2R = XX2 - YY2 + ...`` in the generated header), like the barycentric
ones. Joints whose axis is not the child frame's +-z are left ungrouped (still exact).
"""

from __future__ import annotations

import sympy as sp

from ..model import Robot
from .program import names
from .vectors import UPPER, ZERO, dot, expanded, minus, mv, plus, rows, times


def moved_to_parent(m, h, J, R, p):
    """(m, MS (3,), J (3x3 rows)) of a body (mass m, first moment h (3,), inertia J
    (3x3 rows) about its origin, in its own frame) given in a frame placed at
    (R (3x3 rows), p (3,)) in its parent, expressed about the parent's origin in the
    parent's axes (the module docstring's formula, entry by entry). Also Khalil's general
    grouping in :mod:`armdyn.identification`."""
    Rh, pp = mv(R, h), dot(p, p)
    pRh = dot(p, Rh)
    RJ = [[plus(*[times(R[i][k], J[k][l]) for k in range(3)]) for l in range(3)] for i in range(3)]
    Jp = [[None] * 3 for _ in range(3)]
    for a, b in UPPER:
        # the sums in the order of the formula: with float coefficients a different
        # grouping of the same terms could round differently
        e = plus(*[times(RJ[a][l], R[b][l]) for l in range(3)])
        e = minus(minus(minus(e, times(times(m, p[a]), p[b])), times(p[a], Rh[b])), times(Rh[a], p[b]))
        if a == b:
            e = plus(e, plus(times(m, pp), times(2, pRh)))
        Jp[a][b] = Jp[b][a] = e
    return m, [plus(Rh[i], times(m, p[i])) for i in range(3)], Jp


def grouped_parameters(robot: Robot, parameters: dict, definitions: list):
    """The grouped parameters ``{link: (M, MS (3x1), J (3x3))}`` and the definitions of
    the new symbols ``[(Symbol, expression of the model's parameters)]``.

    parameters, definitions: as returned by
    :func:`armdyn.programs.customized_ne.standard_parameters` (barycentric, link frames).
    A grouped entry that is a number or a symbol stays as it is; any other is named after
    Khalil (``XX2R``, ``MX3R``, ...). Links are keyed and framed as ``robot.canonical()``.
    """
    robot = robot.canonical()
    table = dict(definitions)
    taken = names(robot.free_symbols()) | names((*robot.q, *robot.qd, *robot.qdd)) | names(s for s, _ in definitions)
    # (M, MS (3,), J (3x3 rows)) of each link, as lists: SymPy's Matrix arithmetic is slow
    work = {link: [sp.sympify(M), list(MS), rows(J)] for link, (M, MS, J) in parameters.items()}
    z_axes = (sp.Matrix([0, 0, 1]), sp.Matrix([0, 0, -1]))
    for joint in reversed(robot.joints):  # tip to base: a link has received its children's parts
        link = joint.child
        if joint.type not in ("revolute", "prismatic") or link not in work:
            continue
        if joint.axis not in z_axes:
            continue
        M, MS, J = work[link]
        if joint.type == "revolute":
            D = [[J[1][1], ZERO, ZERO], [ZERO, J[1][1], ZERO], [ZERO, ZERO, ZERO]]  # diag(YY, YY, 0)
            moved = (M, [ZERO, ZERO, MS[2]], D)
            work[link] = [ZERO, [MS[0], MS[1], ZERO], [[minus(J[a][b], D[a][b]) for b in range(3)] for a in range(3)]]
            R, p = joint.transform(0)
        else:
            moved = (ZERO, [ZERO] * 3, J)
            work[link] = [M, MS, [[ZERO] * 3 for _ in range(3)]]
            R, p = joint.rotation, joint.xyz  # J alone: where the frame sits does not matter
        if joint.parent == robot.base or joint.parent not in work:
            continue  # the fixed base never moves
        m, h, Jp = moved_to_parent(*moved, rows(R), list(p))
        M_p, MS_p, J_p = work[joint.parent]
        work[joint.parent] = [
            plus(M_p, m),
            [plus(MS_p[i], h[i]) for i in range(3)],
            [[plus(J_p[a][b], Jp[a][b]) for b in range(3)] for a in range(3)],
        ]

    new_definitions = []

    def named(value, original, label):
        value = expanded(value)
        if value.is_Atom or value == original:
            return value
        name = label + "R"
        while name in taken:
            name += "_"
        taken.add(name)
        s = sp.Symbol(name)
        new_definitions.append((s, expanded(value.xreplace(table))))
        return s

    out = {}
    for link, (M, MS, J) in work.items():
        i = str(robot.link_index(link))
        M0, MS0, J0 = parameters[link]
        Mn = named(M, M0, f"M{i}")
        MSn = [named(MS[k], MS0[k], f"M{'XYZ'[k]}{i}") for k in range(3)]
        Jn = [[None] * 3 for _ in range(3)]
        for a, b in UPPER:
            Jn[a][b] = Jn[b][a] = named(J[a][b], J0[a, b], f"{'XYZ'[a]}{'XYZ'[b]}{i}")
        out[link] = (Mn, sp.Matrix(MSn), sp.Matrix(Jn))
    return out, new_definitions
