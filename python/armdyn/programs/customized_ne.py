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
  (the architecture's standard parameters), so that no parallel-axis term is computed per state;
* ``U_j = skew(wd_j) + skew(w_j)^2`` is formed once per link and used both for the link's
  own force and its children's accelerations (Khalil eq. 9.79);
* a rotation about the joint axis keeps ``wx^2 + wy^2``: when the axis is a parent axis
  ``e_k`` (every DH frame), ``U_j[2, 2] = -(wx^2 + wy^2)`` is the parent's ``U[k, k]``
  and ``wy^2`` is never formed (:func:`~armdyn.programs.link_terms.squares`);
* the last column of a child's U above the diagonal is its parent's U column turned by
  the joint (the joint's own motion adds nothing there,
  :func:`~armdyn.programs.link_terms.column_from_parent`); the child's
  ``wd_x = w_y w_z - U23`` and ``wd_y = U13 - w_x w_z`` follow with one sum each;
* runs of parallel joints (``q2 + q3``) take their angular quantities from the link before
  the run, and a base-fixed link's torque their moments, by the compound angle
  (:mod:`armdyn.programs.parallel_joints`);
* the second link of an arm on a base-fixed first joint (perpendicular axes) gives only
  two projections of its Euler moment, in closed form, and a child continuing a run its
  acceleration without the link's U; the links further along that run give the same two
  projections, where that makes the program shorter (:mod:`armdyn.programs.two_rate_link`);
* optionally (``turns``, :mod:`armdyn.programs.leaf_frames`) a leaf link's frame turned
  about its joint axis by a per-parameter-set angle.

The recursion runs per link over one state object (:class:`LinkState`); each special form
is asked where it applies, and :class:`Forms` switches them off one by one.

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

from dataclasses import dataclass, field

import sympy as sp

from ..model import Robot
from .link_terms import children_need_wd, column_from_parent, euler_moment, parent_invariant, skew2, squares
from .parallel_joints import Run, about_z, compound_angular, own_revolute_about_z, parallel_runs, root_torque
from .program import Builder, Program, names
from .two_rate_link import (
    TwoRateLink,
    euler_projections,
    in_frame,
    lower_column,
    point_acceleration,
    root_axes,
    run_link,
    second_link,
    second_link_moment,
)
from .vectors import (
    UPPER,
    ZERO,
    cross,
    dot,
    expanded,
    expanded_times,
    minus,
    mtv,
    mv,
    plus,
    rows,
    times,
    turned_about_z,
    vadd,
    vscale,
)

#: per link, in the architecture's (Pinocchio's) order of the standard parameters
STANDARD_NAMES = ("M", "MX", "MY", "MZ", "XX", "XY", "YY", "XZ", "YZ", "ZZ")


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
        tag = str(robot.link_index(joint.child))
        R = [[b.let(R[r][s], f"R{tag}_{r + 1}{s + 1}") for s in range(3)] for r in range(3)]
        p = [b.let(p[r], f"p{tag}_{'xyz'[r]}") for r in range(3)]
        frames[joint.child] = (R, p)
    return frames


@dataclass(frozen=True)
class Forms:
    """The special forms :func:`customized_newton_euler` may use, each where it applies
    (all of them by default). Switching one off leaves the plain recursion there: to
    measure what a form saves, or to test it against the program without it.

    parallel_runs: a link continuing a run of parallel joints takes its angular velocity
        and U column from the run's anchor by the compound angle where that is cheaper,
        and a base-fixed link's torque the run's moments by the compound rotation
        (:mod:`~armdyn.programs.parallel_joints`);
    two_rate_links: the second link of an arm on a base-fixed first joint gives only two
        projections of its Euler moment, in closed form, and a child continuing a run
        from the root its acceleration without the link's U
        (:mod:`~armdyn.programs.two_rate_link`);
    run_links: the links further along such a run give the same two projections:
        ``"shorter"`` (the program is built with and without them and the shorter kept:
        they save one operation on the PUMA 560 and cost two on the bundled UR5, whose
        inertia tensors are numeric and diagonal; with a caller's builder, never),
        ``"always"`` or ``"never"``.
    """

    parallel_runs: bool = True
    two_rate_links: bool = True
    run_links: str = "shorter"

    def __post_init__(self):
        if self.run_links not in ("shorter", "always", "never"):
            raise ValueError(f"Forms: run_links must be 'shorter', 'always' or 'never', not {self.run_links!r}")


@dataclass
class LinkState:
    """One link's quantities in the recursion, filled in pass by pass, all in the link's
    own frame (3-vectors as lists, 3x3 matrices as lists of rows).

    joint, tag (the link's index as the temporaries' names show it), k (its coordinate's
    index, None for a fixed joint), R, p: its frame in the parent's.
    Outward: w, wd (angular velocity and acceleration), sq (the named products of w,
    :func:`~armdyn.programs.link_terms.squares`), column ((U13, U23) when read off the
    parent, else None), vd (the origin's acceleration, gravity included), U, F (force),
    N (moment about the origin); euler_and_ms: ``(J wd + w x J w, MS x vd)`` when N is
    their plain sum (a root link's, until a second link takes its J33 part), else None.
    Forms: run (the run of parallel joints it continues, or None), Ra (its compound
    rotation from the run's anchor), compound (its angular quantities came by Ra);
    two_rate (its moment's closed form, or None), root (that form's base-fixed joint),
    second (the form is the second link's, not a run link's).
    Inward: f, n (total force and moment), Rf (its force in the parent's axes)."""

    joint: object = None
    tag: str = ""
    k: int | None = None
    R: list | None = None
    p: list | None = None
    w: list | None = None
    wd: list | None = None
    sq: dict | None = None
    column: tuple | None = None
    vd: list | None = None
    U: list | None = None
    F: list | None = None
    N: list | None = None
    euler_and_ms: tuple | None = None
    run: Run | None = None
    Ra: list | None = None
    compound: bool = False
    two_rate: TwoRateLink | None = None
    root: object = None
    second: bool = False
    f: list | None = None
    n: list | None = None
    Rf: list | None = None


@dataclass
class RootSum:
    """The projections on a base-fixed root's axis of the Euler moments of the two-rate
    links on it: ``a' (A_1 + A_2 + ...) + rest_1 + rest_2 + ...`` (one product with
    ``a'``), named ``A<first>`` after the first such link."""

    ad: sp.Expr
    first: str
    A: list = field(default_factory=list)
    rests: list = field(default_factory=list)


def customized_newton_euler(
    robot: Robot,
    qd=None,
    qdd=None,
    gravity=True,
    parameters=None,
    builder: Builder | None = None,
    turns: dict | None = None,
    forms: Forms | None = None,
) -> tuple[Program, list]:
    """tau (n,) of ``robot`` as a :class:`Program` of the joint coordinates, velocities
    ``qd`` and accelerations ``qdd`` (default: the robot's symbols; pass zeros for the
    gravity torques) and the barycentric parameters.

    parameters: ``{link: (M, MS, J)}`` to use (default :func:`standard_parameters`).
    Returns ``(program, definitions)``: the definitions of the new parameter symbols, as
    :func:`standard_parameters` (those only when ``parameters`` is None) and
    :func:`moment_differences` (always).
    turns: ``{link: th}`` leaf links whose frame (and ``parameters``) are turned about
    their joint axis (:func:`armdyn.programs.leaf_frames.turn_leaf_frames`).
    forms: the special forms to use (:class:`Forms`; default all).
    """
    forms = forms or Forms()
    run_links = forms.run_links == "always" or (forms.run_links == "shorter" and builder is None)
    args = (robot, qd, qdd, gravity, parameters, builder, turns, forms)
    program, definitions, joined = _program(*args, run_links=run_links)
    if joined and forms.run_links == "shorter":
        # the run links' closed forms' saving depends on the inertias: keep the shorter
        generic, generic_definitions, _ = _program(*args, run_links=False)
        if generic.operation_counts()["total"] <= program.operation_counts()["total"]:
            return generic, generic_definitions
    return program, definitions


def _program(
    robot: Robot,
    qd,
    qdd,
    gravity,
    parameters,
    builder: Builder | None,
    turns: dict | None,
    forms: Forms,
    run_links: bool,
) -> tuple[Program, list, bool]:
    """The program, its definitions, and whether a run link's projections joined another
    link's on a root (then the program without run links may be the shorter)."""
    robot = robot.canonical()  # link frames on their joints (frames off the axis: same dynamics)
    qd = list(robot.qd) if qd is None else [sp.sympify(x) for x in qd]
    qdd = list(robot.qdd) if qdd is None else [sp.sympify(x) for x in qdd]
    definitions = []
    if parameters is None:
        parameters, definitions = standard_parameters(robot)
    free = robot.free_symbols()
    differences, extra = moment_differences(robot, parameters, definitions, free)
    definitions = definitions + extra
    b = builder or Builder(reserved=free | set(robot.q) | set(robot.qd) | set(robot.qdd) | {s for s, _ in definitions})
    recursion = _Recursion(robot, b, qd, qdd, gravity, parameters, differences, definitions, turns, forms, run_links)
    for joint in robot.joints:
        recursion.outward(joint)
    tau = recursion.inward()
    joined = any(len(total.A) > 1 for total in recursion.along_root.values())
    return b.program(tau, (robot.dof,)), definitions, joined


class _Recursion:
    """The customized recursion over one robot (canonical frames): per link, outward
    (:meth:`outward`: angular velocity and acceleration, origin acceleration, the form of
    the moment, force and moment), then inward (:meth:`inward`: forces, moments,
    torques). Each form is asked where it applies; the plain recursion does the rest."""

    def __init__(
        self, robot: Robot, b: Builder, qd, qdd, gravity, parameters, differences, definitions, turns, forms, run_links
    ):
        self.robot, self.b, self.qd, self.qdd = robot, b, qd, qdd
        self.parameters, self.differences, self.definitions = parameters, differences, definitions
        self.forms, self.run_links = forms, run_links
        self.frames = joint_frames(robot, b, turns)
        # each joint's angle as joint_frames named it (a turned leaf's q + th is one temporary)
        angles = {j.child: b.let(robot.joint_coordinate(j) + (turns or {}).get(j.child, 0)) for j in robot.joints}
        self.runs = parallel_runs(robot, angles) if forms.parallel_runs else {}
        zero = [ZERO] * 3
        base_acc = list(-robot.gravity) if gravity else zero
        self.links = {robot.base: LinkState(w=zero, wd=zero, vd=b.vector(base_acc, "g"), U=[zero] * 3)}
        self.joint_of = {j.child: j for j in robot.joints}
        self.along_root: dict = {}  # root coordinate index -> RootSum

    def outward(self, joint) -> None:
        robot = self.robot
        name = joint.child
        s = LinkState(joint, str(robot.link_index(name)), robot.coordinate_index(joint), *self.frames[name])
        s.run = self.runs.get(name)
        self._angular(s)
        self._origin_acceleration(s)
        self._two_rate_form(s)
        self._wrench(s)
        self.links[name] = s

    def _angular(self, s: LinkState) -> None:
        """w, wd, the products of w and U's column read off the parent, of a link; for
        one continuing a run, by the compound angle where that is cheaper."""
        b, joint, R, tag = self.b, s.joint, s.R, s.tag
        parent = self.links[joint.parent]
        w_in = mtv(R, parent.w)
        column = column_from_parent(joint, R, parent.U)
        if s.run is not None:
            anchor = self.links[s.run.anchor]
            s.Ra = s.run.rotation(b)
            column_run = column_from_parent(joint, s.Ra, anchor.U)
            w_in, column, s.compound = compound_angular(s.Ra, anchor.w, column_run, w_in, column)
        w_in = b.vector(w_in, f"wi{tag}")
        wd = mtv(R, parent.wd)
        z, k = list(joint.axis), s.k
        if joint.type == "revolute":
            s.w = b.vector(vadd(w_in, vscale(self.qd[k], z)), f"w{tag}")
            s.sq = squares(b, s.w, tag, parent_invariant(joint, R, parent.U))
            if column is not None:
                column = b.let(column[0], f"U{tag}_13"), b.let(column[1], f"U{tag}_23")
                wd = [minus(s.sq["yz"], column[1]), minus(column[0], s.sq["xz"]), plus(wd[2], self.qdd[k])]
            else:
                wd = vadd(wd, vscale(self.qdd[k], z), cross(w_in, vscale(self.qd[k], z)))
        else:
            s.w = b.vector(w_in, f"w{tag}")
            s.sq = squares(b, s.w, tag, parent_invariant(joint, R, parent.U))
        s.column = column
        s.wd = b.vector(wd, f"wd{tag}")

    def _origin_acceleration(self, s: LinkState) -> None:
        """vd of a link: through its parent's U, or, for a link continuing a run from the
        root through a second link, in that link's basis (u, v, e3) turned by the
        compound angle (:func:`~armdyn.programs.two_rate_link.point_acceleration`)."""
        b, joint, tag = self.b, s.joint, s.tag
        parent = self.links[joint.parent]
        through = parent.two_rate
        if s.run is not None and through is not None and through.gz is not None and s.run.anchor == through.root:
            vd = in_frame(point_acceleration(b, through, s.p, parent.tag), *root_axes(s.Ra))
        else:
            Up_p = b.vector(mv(parent.U, s.p), f"Up{tag}")
            vd = mtv(s.R, b.vector(vadd(Up_p, parent.vd), f"a{tag}"))  # named: both rows of R^T use it
        if joint.type == "prismatic":
            z, k = list(joint.axis), s.k
            vd = vadd(vd, vscale(2, cross(s.w, vscale(self.qd[k], z))), vscale(self.qdd[k], z))
        s.vd = b.vector(vd, f"vd{tag}")

    def _two_rate_form(self, s: LinkState) -> None:
        """The closed form of the link's moment, where it applies: a second link
        (:func:`~armdyn.programs.two_rate_link.second_link`), or a link further along a run
        from a base-fixed root, by its compound rotation (its moment's x, y components
        only ever reach the root's torque, :func:`~armdyn.programs.parallel_joints.root_torque`)."""
        robot, joint = self.robot, s.joint
        parent = self.links[joint.parent]
        root = self.joint_of.get(joint.parent)
        if (
            root is not None
            and root.parent == robot.base
            and own_revolute_about_z(robot, root)
            and own_revolute_about_z(robot, joint)
        ):
            if self.forms.two_rate_links:
                origin = vadd(mv(parent.U, s.p), parent.vd)  # L's origin's acceleration, root axes
                s.two_rate = second_link(
                    self.b, joint, s.R, root, parent.w, parent.wd, origin, self.qd[s.k], self.qdd[s.k], s.tag
                )
                s.root, s.second = root, True
        elif self.run_links and s.compound and s.column is not None and own_revolute_about_z(robot, joint):
            root = self.joint_of[s.run.anchor]
            if root.parent == robot.base and own_revolute_about_z(robot, root):
                anchor = self.links[s.run.anchor]
                s.two_rate = run_link(self.b, root, anchor.w, anchor.wd, s.Ra, s.w, s.wd, s.tag)
                s.root = root

    def _wrench(self, s: LinkState) -> None:
        """U, the force F and the moment N of a link (Khalil eqs. 9.79-9.82), the moment
        by its closed form where :meth:`_two_rate_form` found one."""
        b, name, tag = self.b, s.joint.child, s.tag
        M, MS, J = self.parameters[name]
        MS, J = list(MS), rows(J)
        lower = None
        if s.two_rate is not None and not s.second:  # U31, U32 of a run link without w_x w_z, w_y w_z
            needed, closed_lower = children_need_wd(self.robot, name, self.frames), lower_column(s.two_rate, s.column)
            # U31 needs wd_y generically, U32 wd_x: the closed form where no child reads them
            lower = (None if 1 in needed else closed_lower[0], None if 0 in needed else closed_lower[1])
        s.U = skew2(b, s.w, s.wd, tag, s.sq, s.column, lower)
        s.F = b.vector(vadd(vscale(M, s.vd), mv(s.U, MS)), f"F{tag}")
        if s.two_rate is None:
            s.euler_and_ms = (euler_moment(J, self.differences[name], s.wd, s.U, s.sq), cross(MS, s.vd))
            s.N = b.vector(vadd(*s.euler_and_ms), f"N{tag}")
            return
        t = s.two_rate
        ms, gMS, root_J33, shared = cross(MS, s.vd), None, ZERO, False
        if s.second:
            root = self.links[t.root]
            ms, gMS, root_J33, new = second_link_moment(b, t, MS, s.vd, tag, root, self.parameters[t.root][2])
            self.definitions += new
            # a child continuing a run from the root shares W (two_rate_link.point_acceleration)
            shared = gMS is not None and any(
                self.runs.get(c.child) is not None and self.runs[c.child].anchor == t.root
                for c in self.robot.children(name)
            )
        A, rest, along_z = euler_projections(b, J, t, tag, root_J33, gMS[:2] if shared else None)
        # with gravity folded in, along_z holds the first moment's z part too
        s.N = b.vector([ms[0], ms[1], along_z if shared else plus(ms[2], along_z)], f"N{tag}")
        total = self.along_root.setdefault(self.robot.coordinate_index(s.root), RootSum(t.ad, tag))
        total.A.append(A)
        total.rests.append(rest)

    def inward(self) -> list:
        """tau (n,): forces and moments tip to base (Khalil eqs. 9.83-9.85), a base-fixed
        link's torque through the runs behind it, the two-rate links' projections added
        to their roots' torques."""
        robot, b, links = self.robot, self.b, self.links
        tau = [sp.Integer(0)] * robot.dof
        for joint in reversed(robot.joints):
            s = links[joint.child]
            f, n = s.F, s.N
            for child in robot.children(joint.child):
                c = links[child.child]
                c.Rf = b.vector(mv(c.R, c.f), f"Rf{c.tag}")
                f = vadd(f, c.Rf)
                n = vadd(n, mv(c.R, c.n), cross(c.p, c.Rf))
            s.f, s.n = b.vector(f, f"f{s.tag}"), b.vector(n, f"n{s.tag}")
            if s.k is not None:
                tau[s.k] = dot(s.n if joint.type == "revolute" else s.f, list(joint.axis))
        for joint in robot.joints:  # base-fixed links behind runs: their torque only
            k = robot.coordinate_index(joint)
            if (
                joint.parent == robot.base
                and joint.type == "revolute"
                and k is not None
                and any(s.compound and s.run.anchor == joint.child for s in links.values())
            ):
                tau[k] = root_torque(robot, joint, links, b)
        for k, total in self.along_root.items():  # the two-rate links' Euler moments on the root axis
            tau[k] = plus(tau[k], times(total.ad, b.let(plus(*total.A), f"A{total.first}")), *total.rests)
        return tau
