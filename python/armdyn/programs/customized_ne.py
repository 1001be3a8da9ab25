"""Customized Newton-Euler: inverse dynamics as a short straight-line program.

Khalil and Kleinfinger's customized Newton-Euler (W. Khalil, E. Dombre, *Modeling,
Identification and Control of Robots*, 2002, sec. 9.5 and 9.3.3): the same recursion
as :mod:`armdyn.symbolic.newton_euler`, but

* every intermediate quantity that is not a number, a symbol or its negative becomes a
  named temporary, so nothing is computed twice and nothing is expanded;
* zeros and ones propagate (SymPy drops ``0*x`` and ``1*x`` on construction): the
  sparse DH frames and the zero velocity of the base cost nothing;
* the inertial parameters are the barycentric (standard) ones of each link ``j``:
  mass ``M``, first moment ``MS = M c`` and inertia ``J`` about the link frame's origin
  (DESIGN.md's standard parameters), so that no parallel-axis term is computed per state;
* ``U_j = skew(wd_j) + skew(w_j)^2`` is formed once per link and used both for the link's
  own force and its children's accelerations (Khalil eq. 9.79);
* a rotation about the joint axis keeps ``wx^2 + wy^2``: when the axis is a parent axis
  ``e_k`` (every DH frame), ``U_j[2, 2] = -(wx^2 + wy^2)`` is the parent's ``U[k, k]``
  and ``wy^2`` is never formed (:func:`_squares`);
* the last column of a child's U above the diagonal is its parent's U column turned by
  the joint (the joint's own motion adds nothing there, :func:`_column_from_parent`); the
  child's ``wd_x = w_y w_z - U23`` and ``wd_y = U13 - w_x w_z`` follow with one sum each;
* runs of parallel joints (``q2 + q3``) take their angular quantities from the link before
  the run, and a base-fixed link's torque their moments, by the compound angle
  (:mod:`armdyn.programs.parallel_joints`);
* the second link of an arm on a base-fixed first joint (perpendicular axes) gives only
  two projections of its Euler moment, in closed form, and a child continuing a run its
  acceleration without the link's U; the links further along that run give the same two
  projections, where that makes the program shorter (:mod:`armdyn.programs.two_rate_link`);
* optionally (``turns``, :mod:`armdyn.programs.leaf_frames`) a leaf link's frame turned
  about its joint axis by a per-parameter-set angle.

All vectors of link j are in link j's frame. Outward, with ``(R, p)`` link j's frame in
its parent's and ``z`` the joint axis (Khalil eqs. 9.77-9.82)::

    w_j  = R^T w_p + qd z                               (revolute; R^T w_p if prismatic)
    wd_j = R^T wd_p + qdd z + (R^T w_p) x qd z          (revolute; R^T wd_p if prismatic)
    vd_j = R^T (U_p p + vd_p)     [+ 2 w_j x qd z + qdd z  if prismatic],  vd_0 = -gravity
    F_j  = M_j vd_j + U_j MS_j
    N_j  = J_j wd_j + w_j x (J_j w_j) + MS_j x vd_j

Inward, over the children c of link j (``R_c``, ``p_c`` their frames)::

    f_j = F_j + sum_c R_c f_c
    n_j = N_j + sum_c (R_c n_c + p_c x R_c f_c)
    tau = z . n_j (revolute), z . f_j (prismatic)

Dead code (quantities no torque needs, e.g. the first link's force) is removed at the end.
"""

from __future__ import annotations

import re

import sympy as sp

from ..model import Robot
from .parallel_joints import about_z, cheaper, own_revolute_about_z, parallel_runs, root_torque
from .program import Builder, Program, is_value, names
from .two_rate_link import (euler_projections, gravity_moment, in_frame, lower_column, point_acceleration, root_axes,
                            run_link, second_link)
from .vectors import (UPPER, ZERO, cross, dot, expanded, expanded_times, minus, mtv, mv, plus, rows, times,
                      turned_about_z, vadd, vscale)

#: per link, in DESIGN.md's (Pinocchio's) order of the standard parameters
STANDARD_NAMES = ("M", "MX", "MY", "MZ", "XX", "XY", "YY", "XZ", "YZ", "ZZ")


def _safe(name: str) -> str:
    return re.sub(r"\W", "_", name)


def standard_parameters(robot: Robot):
    """Barycentric parameters of every link: ``{link: (M, MS (3x1), J (3x3))}`` and the
    definitions ``[(Symbol, expression of the model's parameters)]`` of the symbols that
    stand for them.

    ``MS = m c``, ``J = I_c + m (c.c 1 - c c^T)`` (inertia about the link origin, link
    axes; parallel axis theorem). A value that is zero or a number stays as it is, a
    plain symbol (e.g. the mass ``m2``) too; any other expression is named
    ``MX2, XX2, ...`` (Khalil's names, the number is the link's frame index).
    """
    robot = robot.canonical()  # link frames on their joints (frames off the axis: same dynamics)
    taken = names(robot.free_symbols()) | names((*robot.q, *robot.qd, *robot.qdd))
    definitions = []
    out = {}

    def named(value, kind, index):
        value = expanded(value) if value.free_symbols else value
        if value.is_Atom:
            return value
        name = f"{kind}{index}"
        while name in taken:
            name += "_"
        taken.add(name)
        s = sp.Symbol(name)
        definitions.append((s, value))
        return s

    for link_name, link in robot.links.items():
        if link_name == robot.base:
            continue
        i = robot.link_index(link_name)
        m, c, Ic = sp.sympify(link.mass), list(link.com), rows(link.inertia)
        cc = dot(c, c)
        M = named(m, "M", i)
        MS = [named(times(m, c[k]), "M" + "XYZ"[k], i) for k in range(3)]
        J = [[None] * 3 for _ in range(3)]
        for a, b in UPPER:
            J_ab = plus(Ic[a][b], expanded_times(m, minus(cc if a == b else ZERO, times(c[a], c[b]))))
            J[a][b] = J[b][a] = named(J_ab, "XYZ"[a] + "XYZ"[b], i)
        out[link_name] = (M, sp.Matrix(MS), sp.Matrix(J))
    return out, definitions


def moment_differences(robot: Robot, parameters: dict, definitions: list, free=None) -> tuple[dict, list]:
    """``{link: (ZZ - YY, XX - ZZ, YY - XX)}`` of the inertias about the link origins,
    each a number, a symbol, or a new parameter ``ZZmYY2, XXmZZ2, YYmXX2`` whose
    definition (in the model's parameters) is returned: like the barycentric parameters,
    they are computed once per parameter set, not per state (Khalil's grouped
    parameters have the same form, e.g. ``XXR = XX - YY``)."""
    free = robot.free_symbols() if free is None else free
    taken = names(free) | names(s for s, _ in definitions) | names(robot.q)
    table = dict(definitions)
    out, new = {}, []
    for link, (_, _, J) in parameters.items():
        i = robot.link_index(link)
        XX, YY, ZZ = J[0, 0], J[1, 1], J[2, 2]
        diffs = []
        for (a, b_), label in (((ZZ, YY), "ZZmYY"), ((XX, ZZ), "XXmZZ"), ((YY, XX), "YYmXX")):
            value = a - b_
            if value.is_Atom:
                diffs.append(value)
                continue
            name = f"{label}{i}"
            while name in taken:
                name += "_"
            taken.add(name)
            sym = sp.Symbol(name)
            new.append((sym, expanded(value.xreplace(table))))
            diffs.append(sym)
        out[link] = tuple(diffs)
    return out, new


def joint_frames(robot: Robot, b: Builder, turns: dict | None = None) -> dict:
    """``{child link: (R (3x3 rows), p (3,))}`` of every joint (the child frame in its
    parent's), with ``cos q``, ``sin q`` named once (``c1, s1``; 1-based like the joints)
    and non-trivial entries of ``R`` and ``p`` named.

    turns: ``{link: th}`` links whose frame is turned by the constant ``th`` about their
    (revolute, +z) joint axis (:mod:`armdyn.programs.leaf_frames`): their joint angle is
    ``q + th`` (named ``q6t``, one addition), and ``c6, s6`` are its cosine and sine."""
    frames = {}
    turns = turns or {}
    for joint in robot.joints:
        k = robot.coordinate_index(joint)
        coordinate = robot.joint_coordinate(joint)
        if joint.child in turns:
            coordinate = b.let(coordinate + turns[joint.child], f"q{k + 1}t")
        if joint.type == "revolute" and about_z(joint) and not joint.has_frame_offset:
            # the placement rotation times Rz(q), entry by hand (SymPy's Matrix product is slow)
            c, s = b.let(sp.cos(coordinate), f"c{k + 1}"), b.let(sp.sin(coordinate), f"s{k + 1}")
            R, p = turned_about_z(rows(joint.rotation), c, s), joint.xyz
        else:
            R, p = joint.transform(coordinate)
            if joint.type == "revolute":
                q = coordinate
                trig = {sp.cos(q): b.let(sp.cos(q), f"c{k + 1}"), sp.sin(q): b.let(sp.sin(q), f"s{k + 1}")}
                R = R.xreplace(trig)
            R = R.tolist()
        tag = _safe(str(robot.link_index(joint.child)))
        R = [[b.let(R[r][s], f"R{tag}_{r + 1}{s + 1}") for s in range(3)] for r in range(3)]
        p = [b.let(p[r], f"p{tag}_{'xyz'[r]}") for r in range(3)]
        frames[joint.child] = (R, p)
    return frames


def _squares(b: Builder, w, tag, S=None) -> dict:
    """The products of w's components that U and the Euler moment use (named once):
    ``xy, xz, yz``, the diagonal of ``skew(w)^2`` (``U11 = -wy^2 - wz^2``, ``U22``,
    ``U33``) and the differences ``d0 = wy^2 - wz^2, d1 = wz^2 - wx^2, d2 = wx^2 - wy^2``.

    S: ``-(wx^2 + wy^2)`` when it is already known from the parent (see
    :func:`_parent_invariant`): a rotation about the joint axis z leaves ``wx^2 + wy^2``
    unchanged, so ``wy^2`` is not needed (one multiplication less per link)::

        U22 = -wx^2 - wz^2,  d1 = wz^2 - wx^2,  U33 = S,  U11 = S - d1,  d0 = U22 - S,
        d2 = -d0 - d1

    (``d2`` from the other two differences, not from ``U11``: a link that needs no
    ``U11`` does not pay for it; never more operations than without ``S``, given ``S``.)
    """
    w1, w2, w3 = w
    xx, zz = b.let(w1 * w1, f"w{tag}xx"), b.let(w3 * w3, f"w{tag}zz")
    out = {"xy": b.let(w1 * w2, f"w{tag}xy"), "xz": b.let(w1 * w3, f"w{tag}xz"), "yz": b.let(w2 * w3, f"w{tag}yz")}
    if S is None:
        yy = b.let(w2 * w2, f"w{tag}yy")
        out.update(U11=b.let(-yy - zz, f"U{tag}_11"), U22=b.let(-xx - zz, f"U{tag}_22"),
                   U33=b.let(-xx - yy, f"U{tag}_33"), d0=b.let(yy - zz, f"w{tag}_yy_zz"),
                   d1=b.let(zz - xx, f"w{tag}_zz_xx"), d2=b.let(xx - yy, f"w{tag}_xx_yy"))
    else:
        U22, d1 = b.let(-xx - zz, f"U{tag}_22"), b.let(zz - xx, f"w{tag}_zz_xx")
        U11 = b.let(S - d1, f"U{tag}_11")
        out_d0 = b.let(U22 - S, f"w{tag}_yy_zz")
        out.update(U11=U11, U22=U22, U33=S, d0=out_d0, d1=d1,
                   d2=b.let(-out_d0 - d1, f"w{tag}_xx_yy"))
    return out


def _axis_in_parent(joint, R):
    """``(k, sign)`` when the joint moves about or along its child's z axis and that axis
    is the parent's ``sign e_k`` (``R e_z = sign e_k``, as in every DH frame), else None."""
    axis = joint.axis
    if joint.type not in ("revolute", "prismatic") or not (
            is_value(axis[0], 0) and is_value(axis[1], 0) and is_value(abs(axis[2]), 1)):
        return None
    col = [R[i][2] for i in range(3)]
    hits = [i for i, e in enumerate(col) if not is_value(e, 0)]
    if len(hits) != 1 or not is_value(abs(col[hits[0]]), 1):
        return None
    return hits[0], 1 if float(col[hits[0]]) > 0 else -1


def _parent_invariant(joint, R, U_parent):
    """``-(wx^2 + wy^2)`` of the child's angular velocity, read off the parent's U, or
    None. When the joint moves about (or along) the child's z axis and that axis is a
    parent axis ``+-e_k`` (:func:`_axis_in_parent`), the child's x and y components are
    the parent's other two components rotated about it, so
    ``wx^2 + wy^2 = sum_{i != k} wp_i^2 = -U_parent[k, k]`` (the norm is unchanged by a
    rotation; the parent's U diagonal holds these sums)."""
    found = _axis_in_parent(joint, R)
    return None if found is None else U_parent[found[0]][found[0]]


def _skew2(b: Builder, w, wd, tag, sq: dict, column=None, lower=None) -> list:
    """U = skew(wd) + skew(w) skew(w) (3x3 rows), Khalil eq. 9.79, from the named
    products ``sq`` of :func:`_squares`; ``column``: ``(U13, U23)`` when already known
    (:func:`_column_from_parent`); ``lower``: ``(U31, U32)`` where known otherwise
    (:func:`armdyn.programs.two_rate_link.lower_column`; None entries: the generic ones)."""
    xy, xz, yz = sq["xy"], sq["xz"], sq["yz"]
    U13, U23 = column if column is not None else (plus(xz, wd[1]), minus(yz, wd[0]))
    U31, U32 = lower if lower is not None else (None, None)
    U = [
        [sq["U11"], minus(xy, wd[2]), U13],
        [plus(xy, wd[2]), sq["U22"], U23],
        [minus(xz, wd[1]) if U31 is None else U31, plus(yz, wd[0]) if U32 is None else U32, sq["U33"]],
    ]
    return [[b.let(U[r][s], f"U{tag}_{r + 1}{s + 1}") for s in range(3)] for r in range(3)]


def _column_from_parent(joint, R, U_parent):
    """``(U13, U23)`` of a revolute child, from its parent's U, or None.

    With ``wi = R^T w_p`` and the joint rate ``qd`` about z, the child's
    ``U = skew(wd) + skew(w)^2`` is the parent's seen in the child frame plus terms of
    the joint's own motion::

        U = R^T U_p R + qdd skew(z) + 2 qd z wi^T - (2 qd wi_z + qd^2) (1 - z z^T)

    (expand ``skew(wi + qd z)^2`` and ``skew(R^T wd_p + qdd z + qd wi x z)``; the
    ``qd wi z^T`` parts of the two cancel). Its last column above the diagonal has no
    such term: ``(U13, U23)`` are the first two entries of ``R^T U_p R z = +-R^T U_p[:, k]``
    when ``R z = +-e_k``, a rotation of two entries of the parent's column k (4 products,
    2 sums) instead of ``R^T wd_p`` and ``qd (wi_y, -wi_x)`` (6 products, 4 sums); the
    child's ``wd_x = w_y w_z - U23`` and ``wd_y = U13 - w_x w_z`` then follow with one
    sum each."""
    found = _axis_in_parent(joint, R)
    if found is None or joint.type != "revolute" or not about_z(joint):
        return None
    k, sign = found
    return tuple(plus(*[times(R[m][i] if sign > 0 else -R[m][i], U_parent[m][k]) for m in range(3)])
                 for i in range(2))


def _euler_moment(J, differences, wd, U, sq) -> list:
    """J wd + w x (J w) (3,) for a symmetric J (3x3 rows), as linear in J's six entries,
    with the coefficients taken from U (whose off-diagonal entries are wd_k +- w_i w_j)
    and the squares of w::

        x: XX wdx + XY (wdy - wx wz) + XZ (wdz + wx wy) + YZ (wy^2 - wz^2) + (ZZ - YY) wy wz
        y: XY (wdx + wy wz) + YY wdy + YZ (wdz - wx wy) + XZ (wz^2 - wx^2) + (XX - ZZ) wx wz
        z: XZ (wdx - wy wz) + YZ (wdy + wx wz) + ZZ wdz + XY (wx^2 - wy^2) + (YY - XX) wx wy

    (15 products instead of the 24 of J wd, J w and the cross product). ``differences``
    are (ZZ - YY, XX - ZZ, YY - XX), parameters of their own (:func:`moment_differences`)."""
    (XX, XY, XZ), (_, YY, YZ), (_, _, ZZ) = J
    ZZ_YY, XX_ZZ, YY_XX = differences
    wxy, wxz, wyz = sq["xy"], sq["xz"], sq["yz"]
    d = [sq["d0"], sq["d1"], sq["d2"]]
    return [
        plus(times(XX, wd[0]), -times(XY, U[2][0]), times(XZ, U[1][0]), times(YZ, d[0]), times(ZZ_YY, wyz)),
        plus(times(XY, U[2][1]), times(YY, wd[1]), -times(YZ, U[0][1]), times(XZ, d[1]), times(XX_ZZ, wxz)),
        plus(-times(XZ, U[1][2]), times(YZ, U[0][2]), times(ZZ, wd[2]), times(XY, d[2]), times(YY_XX, wxy)),
    ]


def customized_newton_euler(robot: Robot, qd=None, qdd=None, gravity=True, parameters=None,
                            builder: Builder | None = None, turns: dict | None = None) -> tuple[Program, list]:
    """tau (n,) of ``robot`` as a :class:`Program` of the joint coordinates, velocities
    ``qd`` and accelerations ``qdd`` (default: the robot's symbols; pass zeros for the
    gravity torques) and the barycentric parameters.

    parameters: ``{link: (M, MS, J)}`` to use (default :func:`standard_parameters`).
    Returns ``(program, definitions)``: the definitions of the new parameter symbols, as
    :func:`standard_parameters` (those only when ``parameters`` is None) and
    :func:`moment_differences` (always).
    turns: ``{link: th}`` leaf links whose frame (and ``parameters``) are turned about
    their joint axis (:func:`armdyn.programs.leaf_frames.turn_leaf_frames`).

    The closed forms of the links further along a run from the second link
    (:func:`armdyn.programs.two_rate_link.run_link`) take one operation less on the PUMA 560
    and two more on the bundled UR5 (its inertia tensors numeric and diagonal): with a
    fresh builder the program is built with and without them and the shorter kept.
    """
    args = (robot, qd, qdd, gravity, parameters, builder, turns)
    program, definitions, closed = _customized_newton_euler(*args, close_runs=builder is None)
    if closed:
        generic, generic_definitions, _ = _customized_newton_euler(*args, close_runs=False)
        if generic.operation_counts()["total"] <= program.operation_counts()["total"]:
            return generic, generic_definitions
    return program, definitions


def _customized_newton_euler(robot: Robot, qd, qdd, gravity, parameters, builder: Builder | None, turns: dict | None,
                             close_runs: bool) -> tuple[Program, list, bool]:
    """:func:`customized_newton_euler`, with or without the closed forms of run links
    (``close_runs``); also whether it used any."""
    robot = robot.canonical()  # link frames on their joints (frames off the axis: same dynamics)
    n = robot.dof
    qd = list(robot.qd) if qd is None else [sp.sympify(x) for x in qd]
    qdd = list(robot.qdd) if qdd is None else [sp.sympify(x) for x in qdd]
    definitions = []
    if parameters is None:
        parameters, definitions = standard_parameters(robot)
    free = robot.free_symbols()
    differences, extra = moment_differences(robot, parameters, definitions, free)
    definitions = definitions + extra
    b = builder or Builder(reserved=free | set(robot.q) | set(robot.qd) | set(robot.qdd) | {s for s, _ in definitions})
    frames = joint_frames(robot, b, turns)
    # each joint's angle as joint_frames named it (a turned leaf's q + th is one temporary)
    angles = {j.child: b.let(robot.joint_coordinate(j) + (turns or {}).get(j.child, 0)) for j in robot.joints}
    runs, rotations = parallel_runs(robot, angles), {}
    zero = [ZERO] * 3
    base_acc = list(-robot.gravity) if gravity else zero
    w, wd = {robot.base: zero}, {robot.base: zero}
    vd = {robot.base: b.vector(base_acc, "g")}
    U = {robot.base: [zero] * 3}
    F, N = {}, {}
    joint_of = {j.child: j for j in robot.joints}
    # second links; each link's (Euler, MS x vd); per root: the A and the rest of its links' u . E
    seconds, raw, along_root = {}, {}, {}
    for joint in robot.joints:
        name, parent = joint.child, joint.parent
        tag = _safe(str(robot.link_index(name)))
        k = robot.coordinate_index(joint)
        R, p = frames[name]
        z = list(joint.axis)
        w_in = mtv(R, w[parent])
        column = _column_from_parent(joint, R, U[parent])
        run = runs.get(name)
        if run is not None:  # a run of parallel joints: from its anchor, by the compound angle
            Ra = run.rotation(b)
            w_run, column_run = mtv(Ra, w[run.anchor])[:2], _column_from_parent(joint, Ra, U[run.anchor])
            if cheaper([*w_run, *(column_run or ())], [*w_in[:2], *(column or ())]):
                w_in, column = [*w_run, w_in[2]], column_run
                rotations[name] = Ra
        w_in = b.vector(w_in, f"wi{tag}")
        wd_j = mtv(R, wd[parent])
        if joint.type == "revolute":
            w_j = b.vector(vadd(w_in, vscale(qd[k], z)), f"w{tag}")
            sq = _squares(b, w_j, tag, _parent_invariant(joint, R, U[parent]))
            if column is not None:
                column = b.let(column[0], f"U{tag}_13"), b.let(column[1], f"U{tag}_23")
                wd_j = [minus(sq["yz"], column[1]), minus(column[0], sq["xz"]), plus(wd_j[2], qdd[k])]
            else:
                wd_j = vadd(wd_j, vscale(qdd[k], z), cross(w_in, vscale(qd[k], z)))
        else:
            w_j = b.vector(w_in, f"w{tag}")
            sq = _squares(b, w_j, tag, _parent_invariant(joint, R, U[parent]))
        wd_j = b.vector(wd_j, f"wd{tag}")
        through = seconds.get(parent)
        if run is not None and through is not None and through.gz is not None and run.anchor == through.root:
            # a run from the root through the second link: the origin's acceleration in the
            # basis (u, v, e3) of the parent, turned here by the compound angle
            vd_j = in_frame(point_acceleration(b, through, p, _safe(str(robot.link_index(parent)))), *root_axes(Ra))
        else:
            Up_p = b.vector(mv(U[parent], p), f"Up{tag}")
            vd_j = mtv(R, b.vector(vadd(Up_p, vd[parent]), f"a{tag}"))  # named: both rows of R^T use it
        if joint.type == "prismatic":
            vd_j = vadd(vd_j, vscale(2, cross(w_j, vscale(qd[k], z))), vscale(qdd[k], z))
        vd_j = b.vector(vd_j, f"vd{tag}")
        M, MS, J = parameters[name]
        MS, J = list(MS), rows(J)
        root = joint_of.get(parent)
        second = closed = None
        if (root is not None and root.parent == robot.base and own_revolute_about_z(robot, root)
                and own_revolute_about_z(robot, joint)):
            origin = vadd(mv(U[parent], p), vd[parent])  # L's origin's acceleration, root axes
            second = second_link(b, joint, R, root, w[parent], wd[parent], origin, qd[k], qdd[k], tag)
        elif close_runs and name in rotations and column is not None and own_revolute_about_z(robot, joint):
            # further along a run from a base-fixed root, by its compound rotation: its
            # moment's x, y components only ever reach the root's torque (root_torque)
            root = joint_of[run.anchor]
            if root.parent == robot.base and own_revolute_about_z(robot, root):
                closed = run_link(b, root, w[run.anchor], wd[run.anchor], Ra, w_j, wd_j, tag)
        lower = None
        if closed is not None:  # U31 without w_x w_z and wd_y, U32 without w_y w_z and wd_x
            needed, closed_lower = _children_need_wd(robot, name, frames), lower_column(closed, column)
            # U31 needs wd_y generically, U32 wd_x: the closed form where no child reads them
            lower = (None if 1 in needed else closed_lower[0], None if 0 in needed else closed_lower[1])
        U_j = _skew2(b, w_j, wd_j, tag, sq, column, lower)
        F[name] = b.vector(vadd(vscale(M, vd_j), mv(U_j, MS)), f"F{tag}")
        if second is None and closed is None:
            raw[name] = (_euler_moment(J, differences[name], wd_j, U_j, sq), cross(MS, vd_j))
            N[name] = b.vector(vadd(*raw[name]), f"N{tag}")
        else:
            ms, gMS, root_J33, shared = cross(MS, vd_j), None, ZERO, False
            if second is not None:
                seconds[name] = second
                root_tag = _safe(str(robot.link_index(parent)))
                ms, gMS, root_J33 = _second_link_moment(b, second, MS, vd_j, tag, root_tag, raw, N, parameters,
                                                       definitions)
                # a child continuing a run from the root shares W (second_link.point_acceleration)
                shared = gMS is not None and any(
                    runs.get(c.child) is not None and runs[c.child].anchor == root.child for c in robot.children(name))
            A, rest, along_z = euler_projections(b, J, second or closed, tag, root_J33, gMS[:2] if shared else None)
            # with gravity folded in, along_z holds the first moment's z part too
            N[name] = b.vector([ms[0], ms[1], along_z if shared else plus(ms[2], along_z)], f"N{tag}")
            kr = robot.coordinate_index(root)
            As, rests, ad, first = along_root.get(kr, ([], [], (second or closed).ad, tag))
            along_root[kr] = (As + [A], rests + [rest], ad, first)
        w[name], wd[name], vd[name], U[name] = w_j, wd_j, vd_j, U_j

    f, nm, Rf = {}, {}, {}
    tau = [sp.Integer(0)] * n
    for joint in reversed(robot.joints):
        name = joint.child
        tag = _safe(str(robot.link_index(name)))
        f_j, n_j = F[name], N[name]
        for child in robot.children(name):
            Rc, pc = frames[child.child]
            f_c = Rf[child.child] = b.vector(mv(Rc, f[child.child]), f"Rf{_safe(str(robot.link_index(child.child)))}")
            f_j = vadd(f_j, f_c)
            n_j = vadd(n_j, mv(Rc, nm[child.child]), cross(pc, f_c))
        f[name], nm[name] = b.vector(f_j, f"f{tag}"), b.vector(n_j, f"n{tag}")
        k = robot.coordinate_index(joint)
        if k is not None:
            tau[k] = dot(nm[name] if joint.type == "revolute" else f[name], list(joint.axis))
    for joint in robot.joints:  # base-fixed links behind runs: their torque only
        k = robot.coordinate_index(joint)
        if (joint.parent == robot.base and joint.type == "revolute" and k is not None
                and any(runs[link].anchor == joint.child for link in rotations)):
            tau[k] = root_torque(robot, joint, frames, rotations, N, f, nm, Rf, b)
    for k, (As, rests, ad, first) in along_root.items():  # the run's Euler moments on the root axis
        tau[k] = plus(tau[k], times(ad, b.let(plus(*As), f"A{first}")), *rests)
    return b.program(tau, (n,)), definitions, any(len(As) > 1 for As, _, _, _ in along_root.values())


def _children_need_wd(robot: Robot, name, frames) -> set:
    """The components of link ``name``'s angular acceleration its children read: ``k``
    for a revolute child about the link's ``+-e_k`` (only its ``wd_z`` takes it), all
    three for any other child."""
    out = set()
    for child in robot.children(name):
        found = _axis_in_parent(child, frames[child.child][0])
        out |= {found[0]} if found is not None and child.type == "revolute" else {0, 1, 2}
    return out


def _second_link_moment(b: Builder, s, MS, vd_j, tag, root_tag, raw: dict, N: dict, parameters: dict,
                        definitions: list):
    """A second link's moment without its Euler part (only its projections are used,
    :func:`armdyn.programs.two_rate_link.euler_projections`): ``(MS x vd (3,), gMS, J33_R)``.

    ``MS x vd`` is ``(g MS) x u`` when gravity is all of the root's acceleration; ``gMS``
    (3,) is then ``g MS`` (new parameters appended to ``definitions``), else None. J33_R:
    the root's inertia about its axis, taken out of the root's moment ``N`` (its Euler
    moment on its axis is ``J33_R a'``, added inside the second link's ``A`` instead), or
    0 when another second link took it already or the root's moment is not that."""
    gMS = None
    if s.gz is not None:
        gMS, new = gravity_moment(b, MS, s, tag)
        definitions += new
        ms = cross(gMS, s.u)
    else:
        ms = cross(MS, vd_j)
    root_J33 = ZERO
    if s.root in raw:
        euler, root_ms = raw.pop(s.root)
        J33 = rows(parameters[s.root][2])[2][2]
        if euler[2] == times(J33, s.ad):
            root_J33 = J33
            N[s.root] = b.vector(vadd([euler[0], euler[1], ZERO], root_ms), f"N{root_tag}")
    return ms, gMS, root_J33
