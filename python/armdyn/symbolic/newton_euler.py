"""Equations of motion by the recursive (iterated) Newton-Euler method, symbolically.

The recursion is Craig's (Introduction to Robotics, eqs. 6.45-6.53), generalised to
joints placed anywhere (model.py's frames, non-DH included), to link frames off their
joint's axis (the exercise's frame 1 at the point mass), to fixed joints and to branched
trees. Every vector of link i is expressed in link i's own frame.

Outward, for link i with parent p, child frame in parent ``(R, P)`` (R: axes of frame i
in frame p; P(q): origin of frame i in frame p, moving relative to frame p with velocity
``V`` and acceleration ``Vd``, both in frame i), joint axis ``z`` (in frame i) and
coordinate ``q``::

    revolute:   w_i  = R^T w_p + qd z
                wd_i = R^T wd_p + (R^T w_p) x qd z + qdd z
    prismatic:  w_i  = R^T w_p,        wd_i = R^T wd_p
    spherical, planar, floating: as revolute with the vector s = Z_w v for qd z, and
                their V, Vd (by their velocity v: newton_euler_spherical.py)
    vd_i  = R^T (wd_p x P + w_p x (w_p x P) + vd_p) + 2 (R^T w_p) x V + Vd
    vcd_i = wd_i x c_i + w_i x (w_i x c_i) + vd_i
    F_i = m_i vcd_i,   N_i = I_i wd_i + w_i x I_i w_i

(``V = Vd = 0`` for a revolute joint whose child frame sits on its axis; for a prismatic
joint ``V = qd z``, ``Vd = qdd z``, which is Craig's ``2 w_i x qd z + qdd z``.)
A mimic joint (``q_m = c q_l + o``, :meth:`armdyn.model.Robot.follows`) moves with
``qd = c qd_l``, ``qdd = c qdd_l``, and its ``tau`` is added ``c`` times to ``tau_l``
(virtual work: ``delta q_m = c delta q_l``).

Gravity enters as the base's acceleration ``vd_0 = -gravity``. Inward, over the children
c of link i (``R_c``, ``P_c`` the child's placement in frame i)::

    f_i = F_i + sum_c R_c f_c
    n_i = N_i + c_i x F_i + sum_c (R_c n_c + P_c x R_c f_c)      (about frame i's origin)
    tau_i = z . (n_i - o_i x f_i) (revolute),  z . f_i (prismatic)

``f_i``/``n_i`` are the force and moment that the parent exerts on link i. ``o_i`` is a
point on joint i's axis in frame i (zero when frame i sits on the axis, as in Craig's
frames); the step ``n`` is reported about that point (the moment whose z component is
the joint torque), ``n_i - o_i x f_i``. ``F_i``/``N_i`` are the rates of change of
momentum (Craig's sign; the exercise writes the d'Alembert inertial force ``-m vcd``).

The per-step formulas are the functions ``omega`` ... ``joint_torque`` below, wired into
the recursion by one table, ``NEWTON_EULER_STEPS``, which the derivation and
:mod:`armdyn.grading.methods` (re-applying it to a student's own values) share.
"""

from __future__ import annotations

from dataclasses import dataclass, replace
from typing import Callable

import sympy as sp

from ..model import Robot
from . import newton_euler_spherical as spherical
from .joint_terms import armature, has_joint_terms, joint_torques
from .terms import EquationsOfMotion, Step

#: the joints that turn (their rate adds to the angular velocity)
TURNING = ("revolute", *spherical.DERIVED)


def _mul(A, v):
    """``A * v`` (A a matrix or a scalar, v a column) skipping zero factors: SymPy's
    ``0 * x`` asks whether ``x`` is finite, which walks the whole of a large ``x`` (most of
    the derivation's time before this). Other types (the grader's numbers) multiply as usual."""
    if not isinstance(v, sp.MatrixBase):
        return A * v
    if not isinstance(A, sp.MatrixBase):
        return sp.zeros(*v.shape) if A == 0 else A * v
    return sp.Matrix([sp.Add(*[a * x for a, x in zip(A.row(r), v) if a != 0 and x != 0]) for r in range(A.rows)])


def cross(a, b):
    """``a x b`` (3-vectors), skipping zero factors as :func:`_mul`."""
    if not (isinstance(a, sp.MatrixBase) and isinstance(b, sp.MatrixBase)):
        return a.cross(b)

    def m(x, y):
        return 0 if x == 0 or y == 0 else x * y

    return sp.Matrix([m(a[1], b[2]) - m(a[2], b[1]), m(a[2], b[0]) - m(a[0], b[2]), m(a[0], b[1]) - m(a[1], b[0])])


# ------------------------------------------------------------------ step formulas
# Vectors are (3, 1) SymPy matrices; each formula names its inputs as Craig does.


def joint_rate(z, qd, kind):
    """The joint's own angular rate in frame i: ``qd z`` (revolute: ``z`` its axis), or
    ``Z_w v`` (a joint of several coordinates: ``z`` its 6 x nv ``Z``, ``qd`` its
    velocity ``v``; newton_euler_spherical.py)."""
    return _mul(z[3:, :], sp.Matrix(list(qd))) if kind in spherical.DERIVED else _mul(qd, z)


def omega(R, w_p, z, qd, kind):
    """Angular velocity of link i in frame i."""
    return _mul(R.T, w_p) + (joint_rate(z, qd, kind) if kind in TURNING else sp.zeros(3, 1))


def omega_dot(R, w_p, wd_p, z, qd, qdd, kind):
    """Angular acceleration of link i in frame i."""
    if kind not in TURNING:
        return _mul(R.T, wd_p)
    return _mul(R.T, wd_p) + cross(_mul(R.T, w_p), joint_rate(z, qd, kind)) + joint_rate(z, qdd, kind)


def v_dot(R, w_p, wd_p, vd_p, P, V, Vd):
    """Linear acceleration of frame i's origin, in frame i (the exercise's formula):
    ``R^T (wd_p x P + w_p x (w_p x P) + vd_p) + 2 w x V + Vd`` with ``w = R^T w_p`` and the
    origin's velocity ``V`` and acceleration ``Vd`` relative to the parent frame, in
    frame i (:meth:`armdyn.model.Joint.origin_motion`)."""
    return _mul(R.T, cross(wd_p, P) + cross(w_p, cross(w_p, P)) + vd_p) + 2 * cross(_mul(R.T, w_p), V) + Vd


def vc_dot(w, wd, vd, c):
    """Linear acceleration of link i's centre of mass ``c`` (frame i)."""
    return cross(wd, c) + cross(w, cross(w, c)) + vd


def inertial_force(m, vcd):
    return _mul(m, vcd)


def inertial_moment(I, w, wd):
    return _mul(I, wd) + cross(w, _mul(I, w))


def joint_force(F, children):
    """f_i from F_i and the children's ``(R_c, f_c)``."""
    out = F
    for Rc, fc in children:
        out = out + _mul(Rc, fc)
    return out


def joint_moment(N, c, F, children):
    """n_i about frame i's origin from N_i, F_i (at ``c``) and the children's
    ``(R_c, P_c, n_c, f_c)``."""
    out = N + cross(c, F)
    for Rc, Pc, nc, fc in children:
        out = out + _mul(Rc, nc) + cross(Pc, _mul(Rc, fc))
    return out


def moment_about(n, f, point):
    """The moment ``n`` (about frame i's origin) taken about ``point`` (frame i)."""
    return n - cross(point, f)


def joint_torque(kind, z, n_axis, f):
    """tau_i: ``z . n`` (moment about a point on the axis) or ``z . f`` (prismatic); a
    joint of several coordinates' nv: ``Z_v^T f + Z_w^T n`` (``n`` about the moved
    frame's origin; newton_euler_spherical.py)."""
    if kind in spherical.DERIVED:
        return _mul(z[:3, :].T, f) + _mul(z[3:, :].T, n_axis)
    return (n_axis if kind == "revolute" else f).dot(z)


# ------------------------------------------------------------------ the steps, one table
# derive computes and reports them from this table; the grader (grading/methods.py)
# re-applies the same entries to a student's own values; the reports name them by `symbol`.


@dataclass(frozen=True)
class NewtonEulerStep:
    """One step of the recursion for link i.

    key:      armdyn's name of the step ("omega", "vc_dot", "f", ...)
    sweep:    "outward" (base to tips) or "inward" (tips to base)
    symbol:   the text symbol ("ω̇", "v̇_C")
    latex:    Craig's left-hand side, ``#`` standing for i (``{}^{#}\\dot\\omega_{#}``)
    meaning:  what the value is, as the derivation report says it
    inputs:   the steps it takes, each ``(key, "parent" | "self")``
    children: the steps it takes from each child c (inward sweep)
    formula:  ``formula(link, *inputs)`` for an outward step, ``formula(link, *inputs,
              kids)`` for an inward one, ``kids = [(R_c, P_c, *children values)]``; ``link``
              maps "R", "P", "V", "Vd" (placement of frame i in its parent's frame, and the
              origin's relative motion), "z", "qd", "qdd", "kind" (the joint) and "m", "c", "I"
              (the link) to their values.
    """

    key: str
    sweep: str
    symbol: str
    latex: str
    meaning: str
    inputs: tuple
    formula: Callable
    children: tuple = ()


NEWTON_EULER_STEPS = (
    NewtonEulerStep(
        "omega",
        "outward",
        "ω",
        r"{}^{#}\omega_{#}",
        "angular velocity",
        (("omega", "parent"),),
        lambda c, w: omega(c["R"], w, c["z"], c["qd"], c["kind"]),
    ),
    NewtonEulerStep(
        "omega_dot",
        "outward",
        "ω̇",
        r"{}^{#}\dot\omega_{#}",
        "angular acceleration",
        (("omega", "parent"), ("omega_dot", "parent")),
        lambda c, w, wd: omega_dot(c["R"], w, wd, c["z"], c["qd"], c["qdd"], c["kind"]),
    ),
    NewtonEulerStep(
        "v_dot",
        "outward",
        "v̇",
        r"{}^{#}\dot v_{#}",
        "linear acceleration of the frame origin (gravity included as base acceleration)",
        (("omega", "parent"), ("omega_dot", "parent"), ("v_dot", "parent")),
        lambda c, w, wd, vd: v_dot(c["R"], w, wd, vd, c["P"], c["V"], c["Vd"]),
    ),
    NewtonEulerStep(
        "vc_dot",
        "outward",
        "v̇_C",
        r"{}^{#}\dot v_{C_#}",
        "linear acceleration of the centre of mass",
        (("omega", "self"), ("omega_dot", "self"), ("v_dot", "self")),
        lambda c, w, wd, vd: vc_dot(w, wd, vd, c["c"]),
    ),
    NewtonEulerStep(
        "F",
        "outward",
        "F",
        r"{}^{#}F_{#}",
        "inertial force m vcd",
        (("vc_dot", "self"),),
        lambda c, a: inertial_force(c["m"], a),
    ),
    NewtonEulerStep(
        "N",
        "outward",
        "N",
        r"{}^{#}N_{#}",
        "inertial moment I wd + w x I w",
        (("omega", "self"), ("omega_dot", "self")),
        lambda c, w, wd: inertial_moment(c["I"], w, wd),
    ),
    NewtonEulerStep(
        "f",
        "inward",
        "f",
        r"{}^{#}f_{#}",
        "force exerted on the link by its parent",
        (("F", "self"),),
        lambda c, F, kids: joint_force(F, [(Rc, fc) for Rc, _, fc in kids]),
        children=("f",),
    ),
    NewtonEulerStep(
        "n",
        "inward",
        "n",
        r"{}^{#}n_{#}",
        "moment exerted on the link by its parent",
        (("N", "self"), ("F", "self")),
        lambda c, N, F, kids: joint_moment(N, c["c"], F, kids),
        children=("n", "f"),
    ),
)
OUTWARD_STEPS = tuple(s for s in NEWTON_EULER_STEPS if s.sweep == "outward")
INWARD_STEPS = tuple(s for s in NEWTON_EULER_STEPS if s.sweep == "inward")
#: the vector steps' text symbols, for every report
VECTOR_STEP_TEXT = {s.key: s.symbol for s in NEWTON_EULER_STEPS}


def step_latex(step: NewtonEulerStep, i: int) -> str:
    """Craig's left-hand side of ``step`` for link ``i``."""
    return step.latex.replace("#", str(i))


def recursion(
    robot: Robot,
    qd,
    qdd,
    base_acceleration,
    steps: list[Step] | None = None,
    base_rotation=None,
    values: dict | None = None,
    let=None,
) -> sp.Matrix:
    """tau (n x 1) for joint velocities ``qd`` and accelerations ``qdd`` (sequences of
    length n, symbols or numbers) with the base accelerating at ``base_acceleration``
    (3 x 1; ``-gravity`` for the equations of motion). Appends the steps if given.

    base_rotation: the base's ``(omega, omega_dot)`` (frame 0) when it turns (a floating
    base, newton_euler_floating.py); None: at rest. values: a dict that receives the
    steps' values (``"value"``: key -> link -> value), the children's placements
    (``"placement"``) and the links' formula quantities (``"context"``). let: ``(value,
    hint) -> value`` applied to each step's value as computed (generated code names them
    there: printing/generate_floating.py); None: kept as they are."""
    let = let or (lambda x, hint: x)
    zero = sp.zeros(3, 1)
    value = {s.key: {} for s in NEWTON_EULER_STEPS}  # key -> link name -> value
    value["omega"][robot.base], value["omega_dot"][robot.base] = base_rotation or (zero, zero)
    value["v_dot"][robot.base] = base_acceleration
    placement, context = {}, {}  # link name -> (R, P); link name -> the formulas' link quantities
    if values is not None:
        values.update(value=value, placement=placement, context=context)
    record = steps is not None
    outward: list[Step] = []

    for joint in robot.joints:
        link = robot.links[joint.child]
        name, parent, i = joint.child, joint.parent, robot.link_index(joint.child)
        follow = robot.follows(joint)  # (k, c, o): this joint's coordinate is c q_k + o
        if joint.type in spherical.DERIVED:  # nv rates: its velocity
            assert follow is not None  # a joint of several coordinates has coordinates of its own
            k = follow[0]
            qd_j, qdd_j = qd[k : k + joint.nv], qdd[k : k + joint.nv]
            ctx = spherical.motion(joint, qd_j, qdd_j)
        else:
            qd_j, qdd_j = (follow[1] * qd[follow[0]], follow[1] * qdd[follow[0]]) if follow is not None else (0, 0)
            R, P = joint.transform(robot.joint_coordinate(joint))
            V, Vd = joint.origin_motion(qd_j, qdd_j)
            ctx = {"R": R, "P": P, "V": V, "Vd": Vd, "z": joint.child_axis}
        placement[name] = (ctx["R"], ctx["P"])
        ctx.update(qd=qd_j, qdd=qdd_j, kind=joint.type)
        ctx.update(m=link.mass, c=link.com, I=link.inertia)
        context[name] = ctx
        for step in OUTWARD_STEPS:
            args = [value[key][parent if where == "parent" else name] for key, where in step.inputs]
            value[step.key][name] = let(step.formula(ctx, *args), f"{step.key}{i}_")
        if record:
            outward += [
                Step("outward", name, s.key, step_latex(s, i), value[s.key][name], s.meaning) for s in OUTWARD_STEPS
            ]

    tau = [sp.Integer(0)] * robot.dof
    inward: list[Step] = []
    tau_steps = []  # (position in inward, k): filled in with the final tau_k at the end
    for joint in reversed(robot.joints):
        name, i = joint.child, robot.link_index(joint.child)
        kids = [c.child for c in robot.children(name)]
        for step in INWARD_STEPS:
            args = [value[key][name] for key, _ in step.inputs]
            kid_values = [(*placement[c], *(value[key][c] for key in step.children)) for c in kids]
            value[step.key][name] = let(step.formula(context[name], *args, kid_values), f"{step.key}{i}_")
        f_i, n_i = value["f"][name], value["n"][name]
        follow = robot.follows(joint)
        several = joint.type in spherical.DERIVED
        if several:
            point = joint.joint_point()  # the moved frame's origin
        else:
            point = joint.joint_point(robot.joint_coordinate(joint)) if joint.type in TURNING else sp.zeros(3, 1)
        n_axis = moment_about(n_i, f_i, point)
        if follow is not None:
            k, mult, _ = follow
            tau_j = joint_torque(joint.type, context[name]["z"], n_axis, f_i)
            if several:
                tau[k : k + joint.nv] = list(tau_j)
            else:
                tau[k] = tau[k] + mult * tau_j  # a mimic joint's torque is carried to its leader
        if record:
            centre = ("centre" if joint.type == "spherical" else "origin") if several else "axis point"
            about = "" if point == sp.zeros(3, 1) else f", about joint {i}'s {centre} {list(point)} (frame {i})"
            reported = {"f": f_i, "n": n_axis}  # n about the axis point: its z component is the torque
            inward += [
                Step(
                    "inward",
                    name,
                    s.key,
                    step_latex(s, i),
                    reported[s.key],
                    s.meaning + (about if s.key == "n" else ""),
                )
                for s in INWARD_STEPS
            ]
            kind = "torque" if joint.type == "revolute" else "force"
            if joint.mimic is not None:
                tex = joint.name.replace("_", r"\_")
                inward.append(
                    Step(
                        "inward",
                        name,
                        "tau_mimic",
                        rf"\tau_{{\mathrm{{{tex}}}}}",
                        tau_j,
                        f"joint {kind} of mimic joint '{joint.name}', added {mult} times to tau{k + 1}",
                    )
                )
            elif several:  # its nv rows, complete now (no mimic follows one)
                label = rf"\tau_{{{k + 1}..{k + joint.nv}}}"
                note = f"{spherical.TAU_MEANING[joint.type]} of joint '{joint.name}', joint frame"
                inward.append(Step("inward", name, "tau", label, tau_j, note))
            elif follow is not None:
                tau_steps.append((len(inward), k))
                inward.append(
                    Step("inward", name, "tau", rf"\tau_{{{k + 1}}}", tau[k], f"joint {kind} of '{joint.name}'")
                )
    for pos, k in tau_steps:  # with mimic joints, tau_k is complete only now
        inward[pos] = replace(inward[pos], value=tau[k])
    if record:
        steps += outward + inward  # inward in the order computed: last link first, as in the exercise
    return sp.Matrix(tau)


def mass_matrix(robot: Robot) -> sp.Matrix:
    """M (n x n) column by column: tau with qd = 0, no gravity and qdd = e_j is M e_j
    (Walker and Orin, 1982, method 1). Zeros make these passes far cheaper than
    differentiating tau."""
    n = robot.dof
    M = sp.zeros(n, n)
    zeros = [0] * n
    for j in range(n):
        unit = [int(i == j) for i in range(n)]
        M[:, j] = recursion(robot, zeros, unit, sp.zeros(3, 1))
    return M + sp.diag(*armature(robot))  # rotor inertias on the diagonal


def newton_euler(robot: Robot) -> EquationsOfMotion:
    """Derive ``tau`` by iterated Newton-Euler; steps as in Craig's outward/inward passes.
    Spherical, planar and floating joints by their velocity (newton_euler_spherical.py:
    a :class:`~.newton_euler_spherical.SphericalEquationsOfMotion`)."""
    spherical.check_joints(robot)
    steps: list[Step] = []
    velocity, acceleration = spherical.rates(robot)
    tau = recursion(robot, velocity, acceleration, -robot.gravity, steps)
    if has_joint_terms(robot):
        # docs/architecture.md: tau += Ia qdd + Fv qd + Fc sign(qd) + offset, joint by joint
        extra = joint_torques(robot, velocity, acceleration)
        tau = tau + extra
        steps.append(
            Step(
                "inward",
                "",
                "tau_joint",
                r"\tau_{\mathrm{joint}}",
                extra,
                "rotor inertia, viscous and Coulomb friction, offset: Ia qdd + Fv qd + Fc sign(qd) + offset",
            )
        )
    kind = spherical.SphericalEquationsOfMotion if robot.multi_dof_joints else EquationsOfMotion
    return kind(robot, "newton-euler", tau, steps, _M_builder=lambda: mass_matrix(robot))
