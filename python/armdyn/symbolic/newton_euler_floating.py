"""Equations of motion of a floating-base robot by Newton-Euler, symbolically.

The base (link 0, frame 0) is a free rigid body (``root_joint="free-flyer"``). Its
generalised velocity is its twist in its own frame, as Pinocchio's free-flyer ``v``:
``v_b`` (the velocity of the base origin) and ``w_b`` (the angular velocity), both in
base axes, the symbols ``vb_x, vb_y, vb_z, wb_x, wb_y, wb_z``; its generalised
acceleration is their time derivative (``vb_x_dot`` ... ``wb_z_dot``: the spatial
acceleration in the base frame, Pinocchio's ``a``). The base's pose enters only through
gravity, kept as a vector of symbols in the base frame, ``g_b = R^T g``
(``gb_x, gb_y, gb_z``; ``R`` the base axes in world coordinates, the quaternion's
rotation; ``g`` the robot's gravity, world frame): the expressions stay short (no
quaternion products) and hold for every orientation. At a numeric state put
:func:`gravity_in_base` in for them.

The recursion is RBDA ch. 9's floating-base RNEA in Craig's form: the base's rows
(:data:`BASE_STEPS`) start the outward pass from the base's own motion instead of rest::

    w_0  = w_b,     wd_0 = wd_b
    vd_0 = vbd + wb x vb - gb      (the base origin's acceleration, gravity as a fictitious
                                    acceleration; wb x vb turns the spatial acceleration
                                    into the classical one)
    vcd_0, F_0, N_0                as for every link (NEWTON_EULER_STEPS' rows)

then every joint's rows of :data:`~armdyn.symbolic.newton_euler.NEWTON_EULER_STEPS`,
unchanged (a spherical, planar or floating joint by its velocity, its pose as symbols:
newton_euler_spherical.py, whose :func:`~.newton_euler_spherical.state_values` puts in a
floating robot's values too), and the inward pass as for every link, ending on the base::

    f_0 = F_0 + sum_c R_c f_c,    n_0 = N_0 + c_0 x F_0 + sum_c (R_c n_c + P_c x R_c f_c)

``(f_0, n_0)`` is the wrench that must act on the base (base frame, moment about its
origin; zero for a robot flying free at its physical acceleration). ``tau`` is
``(f_0, n_0, tau_1 .. tau_n)``: ``6 + n`` rows in Pinocchio's order.

Lagrange's method is not offered for a floating base: the twist is no time derivative of
coordinates (quasi-velocities), and a Lagrangian of the base's pose (quaternion or angles)
is a different exercise. For the same reason ``C`` is not the Christoffel matrix of ``M``:
the equations carry ``bias = C v + g`` (tau at zero acceleration) instead.
"""

from __future__ import annotations

from functools import cached_property

import sympy as sp

from ..errors import FloatingBaseError, ModelError
from ..model import Robot
from . import dag
from . import newton_euler_spherical as spherical
from .base_symbols import BASE_ACCELERATION, BASE_GRAVITY, BASE_VELOCITY, gravity_in_base  # noqa: F401
from .joint_terms import armature, friction_torques, has_joint_terms, joint_torques
from .newton_euler import (
    INWARD_STEPS,
    OUTWARD_STEPS,
    NewtonEulerStep,
    cross,
    recursion,
    step_latex,
)
from .terms import EquationsOfMotion, Step

#: the base rows of tau: (LaTeX, text, what they are)
BASE_ROWS = tuple(
    (rf"{k}_{{b,{a}}}", f"{k}_b{a}", f"{what} on the base, base frame")
    for k, what in (("f", "force"), ("n", "moment about the base origin"))
    for a in "xyz"
)

#: what a report says of a floating robot's derivation
FLOATING_NOTE = (
    "a floating base: velocity its twist (vb_x..wb_z, base frame), gravity gb = R^T g in the base frame; "
    "tau: the wrench on the base (f_b, n_b), then the joints"
)


def base_v_dot(vd_b, w_b, v_b, g_b):
    """Classical acceleration of the base origin in the base frame, gravity included as
    a fictitious acceleration: ``vd_b + w_b x v_b - g_b``."""
    return vd_b + cross(w_b, v_b) - g_b


#: the base's outward rows: its own velocity and accelerations, then the rows of
#: NEWTON_EULER_STEPS that take the link's own values only (vc_dot, F, N), shared. The
#: context ``c`` holds the base's ``v``, ``w``, ``vd``, ``wd`` (twist and its
#: derivative), ``g`` (gravity, base frame) and its ``m``, ``c``, ``I``.
BASE_STEPS = (
    NewtonEulerStep(
        "omega", "outward", "ω", r"{}^{#}\omega_{#}", "angular velocity of the base (its twist's)", (), lambda c: c["w"]
    ),
    NewtonEulerStep(
        "omega_dot",
        "outward",
        "ω̇",
        r"{}^{#}\dot\omega_{#}",
        "angular acceleration of the base",
        (),
        lambda c: c["wd"],
    ),
    NewtonEulerStep(
        "v_dot",
        "outward",
        "v̇",
        r"{}^{#}\dot v_{#}",
        "linear acceleration of the base origin, vbd + wb x vb - gb (gravity included as base acceleration)",
        (),
        lambda c: base_v_dot(c["vd"], c["w"], c["v"], c["g"]),
    ),
    *(s for s in OUTWARD_STEPS if all(where == "self" for _, where in s.inputs)),
)


def _vec(x) -> sp.Matrix:
    return sp.Matrix(list(x))


def floating_recursion(robot: Robot, v, a, g_b, steps: list[Step] | None = None, let=None) -> sp.Matrix:
    """tau (6 + n) for the velocity ``v`` and acceleration ``a`` (6 + n each: base twist,
    then joints) under gravity ``g_b`` (base frame). Appends the steps if given; ``let``
    as :func:`~.newton_euler.recursion`'s."""
    let = let or (lambda x, hint: x)
    base = robot.links[robot.base]
    ctx = {"v": _vec(v[:3]), "w": _vec(v[3:6]), "vd": _vec(a[:3]), "wd": _vec(a[3:6]), "g": _vec(g_b)}
    ctx.update(m=base.mass, c=base.com, I=base.inertia)
    own: dict = {}
    for step in BASE_STEPS:
        own[step.key] = let(step.formula(ctx, *(own[key] for key, _ in step.inputs)), f"{step.key}0_")
    values: dict = {}
    arm: list[Step] | None = [] if steps is not None else None
    joint_tau = recursion(
        robot, list(v[6:]), list(a[6:]), own["v_dot"], arm, (own["omega"], own["omega_dot"]), values, let
    )
    value, placement = values["value"], values["placement"]
    for key, x in own.items():
        value[key][robot.base] = x
    kids = [j.child for j in robot.children(robot.base)]
    for step in INWARD_STEPS:  # the base's inward rows: those of every link
        args = [value[key][robot.base] for key, _ in step.inputs]
        kid_values = [(*placement[k], *(value[key][k] for key in step.children)) for k in kids]
        value[step.key][robot.base] = let(step.formula(ctx, *args, kid_values), f"{step.key}0_")
    f_b, n_b = value["f"][robot.base], value["n"][robot.base]
    if steps is not None and arm is not None:
        name = robot.base
        # base first outward, last inward: the arm's steps in between
        steps += [Step("outward", name, s.key, step_latex(s, 0), own[s.key], s.meaning) for s in BASE_STEPS]
        steps += arm
        notes = {
            "f": "force that must act on the base (Pinocchio's tau[0:3])",
            "n": "moment about the base origin that must act on the base (Pinocchio's tau[3:6])",
        }
        steps += [Step("inward", name, s.key, step_latex(s, 0), value[s.key][name], notes[s.key]) for s in INWARD_STEPS]
    return sp.Matrix([*f_b, *n_b, *joint_tau])


def mass_matrix(robot: Robot) -> sp.Matrix:
    """M ((6 + n) x (6 + n)) column by column: tau at rest, without gravity, for each unit
    acceleration (base twist components, then joints), as for a fixed base; rotor
    inertias on the joints' diagonal."""
    size = robot.nv
    M = sp.zeros(size, size)
    rest = [0] * size
    for j in range(size):
        M[:, j] = floating_recursion(robot, rest, [int(i == j) for i in range(size)], [0, 0, 0])
    ia = armature(robot)
    for k in range(robot.dof):
        M[6 + k, 6 + k] += ia[k]
    return M


class FloatingEquationsOfMotion(EquationsOfMotion):
    """The equations of motion of a floating-base robot, ``M(q) a + bias(q, v, g_b) = tau``
    (see the module doc): ``q`` the joints (the base pose enters through ``gravity``; a
    joint of several coordinates by its pose symbols, newton_euler_spherical.py), ``qd``
    (6 + n) the base twist then the joint rates (a joint of several coordinates' velocity),
    ``qdd`` (6 + n) their time derivatives, ``tau`` (6 + n) the wrench on the base then
    the joint torques."""

    @property
    def q(self) -> sp.Matrix:
        return sp.Matrix(spherical.pose_symbols(self.robot))  # (0, 0) without joints

    @property
    def qd(self) -> sp.Matrix:
        return sp.Matrix([*BASE_VELOCITY, *spherical.rates(self.robot)[0]])

    @property
    def qdd(self) -> sp.Matrix:
        return sp.Matrix([*BASE_ACCELERATION, *spherical.rates(self.robot)[1]])

    @property
    def gravity(self) -> sp.Matrix:
        """Gravity in the base frame, ``R^T g`` (3 symbols; :func:`gravity_in_base`)."""
        return BASE_GRAVITY

    @cached_property
    def bias(self) -> sp.Matrix:
        """``C v + g`` (6 + n): tau at zero acceleration."""
        return dag.xreplace(self.tau, {s: 0 for s in self.qdd})

    @cached_property
    def friction(self) -> sp.Matrix:
        """Joint friction (6 + n; the base has none)."""
        return sp.Matrix([0] * 6 + list(friction_torques(self.robot, self.qd[6:])))

    @property
    def C(self) -> sp.Matrix:  # type: ignore[override]
        raise FloatingBaseError(
            "the Christoffel matrix C does not apply to a floating base parametrised by its twist "
            "(quasi-velocities); use eom.bias (C v + g) and eom.g",
            f"robot '{self.robot.name}'",
            self.robot.meta.get("file"),
        )

    def symbol_names(self, fmt: str) -> dict:
        """The base's symbols as the reports print them (``v_{b,x}``, ``\\dot{\\omega}_{b,z}``),
        and the joints of several coordinates' (newton_euler_spherical.py)."""
        names = spherical.joint_symbol_names(self.robot, fmt)
        for k, (v, a) in enumerate(zip(BASE_VELOCITY, BASE_ACCELERATION)):
            letter, axis = ("v", "ω")[k // 3], "xyz"[k % 3]
            if fmt == "latex":
                tex = (r"v", r"\omega")[k // 3]
                names[v], names[a] = rf"{tex}_{{b,{axis}}}", rf"\dot{{{tex}}}_{{b,{axis}}}"
            else:
                names[v], names[a] = f"{letter}_b{axis}", f"{letter}\u0307_b{axis}"
        for axis, g in zip("xyz", BASE_GRAVITY):
            names[g] = rf"g_{{b,{axis}}}" if fmt == "latex" else f"g_b{axis}"
        return names


def check_floating_robot(robot: Robot) -> None:
    where, source = f"robot '{robot.name}'", robot.meta.get("file")
    spherical.check_joints(robot, "the floating-base Newton-Euler derivation")
    if robot.mimic_joints:
        raise FloatingBaseError("mimic joints with a floating base are not supported yet", where, source)
    taken = {s.name for s in (*BASE_VELOCITY, *BASE_ACCELERATION, *BASE_GRAVITY)}
    clash = taken & ({s.name for s in robot.free_symbols()} | set(robot.coordinate_names))
    if clash:
        raise ModelError(f"names {sorted(clash)} are the floating base's own symbols: rename them", where, source)


def newton_euler_floating(robot: Robot) -> FloatingEquationsOfMotion:
    """Derive ``tau`` (6 + n) of a floating-base robot by Newton-Euler (module doc)."""
    check_floating_robot(robot)
    steps: list[Step] = []
    v, a = spherical.rates(robot)
    tau = floating_recursion(robot, [*BASE_VELOCITY, *v], [*BASE_ACCELERATION, *a], BASE_GRAVITY, steps)
    if has_joint_terms(robot):
        extra = joint_torques(robot, v, a)
        tau = tau + sp.Matrix([0] * 6 + list(extra))
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
    return FloatingEquationsOfMotion(robot, "newton-euler", tau, steps, _M_builder=lambda: mass_matrix(robot))
