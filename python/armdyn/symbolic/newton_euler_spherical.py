"""Joints of several coordinates in the symbolic Newton-Euler derivation, by their velocity.

Spherical (ball), planar and floating (free) joints are Pinocchio's JointModelSpherical,
JointModelPlanar and JointModelFreeFlyer (:data:`armdyn.model.joints.MULTI_DOF`). Each
moves its joint frame relative to the placement frame by a motion ``(Rm, pm)``, and its
velocity ``v`` is the moved frame's twist relative to the parent, in the moved frame's
own axes (linear velocity of its origin, then angular velocity), ``S v`` with a
constant motion subspace ``S`` (6 x nv, :func:`subspace`)::

    spherical:  v = (wx, wy, wz)                  S = [0; I3]
    planar:     v = (vx, vy, wz)  in the x-y plane S = [e_x e_y 0; 0 0 e_z]
    floating:   v = (vx, vy, vz, wx, wy, wz)      S = I6

Its acceleration ``a`` is the time derivative of those components (Pinocchio's). Here:

* the joint's rotation ``Rm`` is kept as symbols, not written out from the quaternion:
  a spherical or floating joint's the matrix ``[r_jk]`` (``ball.r11`` ... ``ball.r33``
  for a joint named ``ball``; printed ``r⁽ⁱ⁾₁₁``, ``r^{(i)}_{11}``, i the child link's
  frame number; :func:`rotation_symbols`), a planar joint's its cos and sin
  (``plane.cos``, ``plane.sin``, printed ``c⁽ⁱ⁾``, ``s⁽ⁱ⁾``), so each entry enters the
  recursion linearly and the steps stay as short as a revolute joint's (a quaternion's
  entries are quadratic in x, y, z, w);
* a planar or floating joint's translation ``pm`` is its coordinates ``plane.x``,
  ``plane.y`` (and ``free.z``), printed ``p⁽ⁱ⁾x`` ...: the child's origin in the
  placement frame. It enters the equations through the child frame's placement ``P`` in
  its parent: the transport terms ``wd_p x P + w_p x (w_p x P)`` of the child's
  acceleration and the moment ``P x f`` of its force on the parent. A free joint on a
  body at rest (the fixed base) has equations independent of it, as a free body's
  dynamics do not depend on where it is; under a turning parent they do;
* the velocity coordinates (``robot.coordinate_names``: ``ball.wx`` ..., ``plane.vx``,
  ``plane.vy``, ``plane.wz``, ``free.vx`` ... ``free.wz``) are the symbols of those names
  (printed ``ω⁽ⁱ⁾x``, ``v⁽ⁱ⁾x``), their derivatives ``ball.wx_dot`` ... (``ω̇⁽ⁱ⁾x``): in
  ``eom.qd`` and ``eom.qdd``, at the joint's rows. :func:`state_values` puts in the
  values of all these symbols at a numeric state;
* its rows of ``tau`` are ``S^T`` times the wrench the parent exerts on the child, about
  the moved frame's origin, in its axes (Pinocchio's tau of the joint): a ball joint's
  moment about its centre, a planar joint's force along x, y and moment about z.

In the recursion (:mod:`.newton_euler`) the joint turns as a revolute joint does, with the
vector ``s = Z_w v`` for ``qd z`` (``Z = diag(Rf^T, Rf^T) S``: ``S`` in the child frame's
axes, ``Rf`` the frame offset's rotation, the identity without one; ``Z_v``, ``Z_w`` its
linear and angular rows)::

    w_i  = R^T w_p + s
    wd_i = R^T wd_p + (R^T w_p) x s + sd                    (sd = Z_w a)
    tau  = Z_v^T f + Z_w^T n_o      (f, n_o: the force and the moment about the moved
                                     frame's origin o, frame i)

and the child frame's origin, at ``r = Rf^T pf`` from ``o``, moves relative to the parent
with ``V = u + s x r``, ``Vd = ud + sd x r + s x (u + s x r)`` (``u = Z_v v``,
``ud = Z_v a``: a prismatic joint's ``V``, a revolute joint's, together).

``v`` is no time derivative of coordinates (quasi-velocities), so Lagrange's method is not
offered and ``C`` is no Christoffel matrix of ``M``: the equations carry ``bias = C v + g``
(tau at zero acceleration), as a floating base's do (:mod:`.newton_euler_floating`, which
takes these joints too).
"""

from __future__ import annotations

from functools import cached_property

import numpy as np
import sympy as sp

from ..errors import ModelError
from ..model import Joint, Robot
from .base_symbols import BASE_ACCELERATION, BASE_GRAVITY, BASE_VELOCITY, gravity_in_base
from .names import SUBSCRIPT_DIGITS
from .terms import EquationsOfMotion

#: the joints of several coordinates the Newton-Euler derivation takes
DERIVED = ("spherical", "planar", "floating")
_SUPERSCRIPT = str.maketrans("0123456789", "⁰¹²³⁴⁵⁶⁷⁸⁹")
#: what a joint's rows of tau are, by kind (reports)
TAU_MEANING = {
    "spherical": "moment about the centre",
    "planar": "force along x, y and moment about z at the origin",
    "floating": "force and moment about the origin",
}


def check_joints(robot: Robot, what: str = "the Newton-Euler derivation (armdyn.derive)") -> None:
    """A ModelError naming ``what`` for a name of the joints of several coordinates' own
    symbols (:func:`configuration_symbols`) that the model already uses (a parameter, a
    coordinate), which the derivation would confuse with them."""
    own = {s.name: j for j in robot.multi_dof_joints for s in configuration_symbols(j)}
    clash = set(own) & ({s.name for s in robot.free_symbols()} | set(robot.coordinate_names))
    if clash:
        named = ", ".join(sorted({f"'{own[n].name}'" for n in clash}))
        raise ModelError(
            f"{what}: names {sorted(clash)} are the own symbols of joint {named} (its configuration): rename them",
            f"robot '{robot.name}'",
            robot.meta.get("file"),
        )


def refuse_quasi_velocities(robot: Robot, what: str) -> None:
    """A ModelError naming ``what`` and the first joint of several coordinates: for what
    takes the time derivatives of coordinates (Lagrange's method, the agreement check)."""
    if not robot.multi_dof_joints:
        return
    j = robot.multi_dof_joints[0]
    names = ", ".join(j.coordinate_names)
    raise ModelError(
        f"{what} takes revolute and prismatic joints only: joint '{j.name}' ({j.type}) moves by its velocity "
        f"({names}, in its own frame), quasi-velocities that are no time derivatives of coordinates; "
        "armdyn.derive(robot, 'newton-euler') derives it",
        f"robot '{robot.name}'",
        robot.meta.get("file"),
    )


# ------------------------------------------------------------------ the joints' symbols


def rotation_symbols(joint: Joint) -> sp.Matrix:
    """(3, 3) the symbols of a spherical or floating ``joint``'s rotation, ``<joint>.r11``
    ... ``<joint>.r33``: the moved joint frame's axes (columns) in the placement frame."""
    return sp.Matrix(3, 3, lambda a, b: sp.Symbol(f"{joint.name}.r{a + 1}{b + 1}"))


def position_symbols(joint: Joint) -> list:
    """A planar joint's ``<joint>.x``, ``<joint>.y``, a floating one's and ``<joint>.z``:
    the moved frame's origin in the placement frame (none for a spherical joint)."""
    axes = {"planar": "xy", "floating": "xyz"}.get(joint.type, "")
    return [sp.Symbol(f"{joint.name}.{a}") for a in axes]


def turn_symbols(joint: Joint) -> list:
    """A planar joint's ``<joint>.cos``, ``<joint>.sin``: its turn about z."""
    return [sp.Symbol(f"{joint.name}.cos"), sp.Symbol(f"{joint.name}.sin")]


def configuration_symbols(joint: Joint) -> list:
    """The symbols the joint's pose is written in, in Pinocchio's order of its
    configuration: a spherical joint's rotation entries (row by row), a planar joint's
    x, y, cos, sin, a floating joint's x, y, z then rotation entries."""
    if joint.type == "planar":
        return position_symbols(joint) + turn_symbols(joint)
    return position_symbols(joint) + list(rotation_symbols(joint))


def joint_pose(joint: Joint) -> tuple[sp.Matrix, sp.Matrix]:
    """``(Rm, pm)``: the moved joint frame in the placement frame, in the joint's symbols."""
    if joint.type == "planar":
        c, s = turn_symbols(joint)
        x, y = position_symbols(joint)
        return sp.Matrix([[c, -s, 0], [s, c, 0], [0, 0, 1]]), sp.Matrix([x, y, 0])
    p = position_symbols(joint)
    return rotation_symbols(joint), sp.Matrix(p) if p else sp.zeros(3, 1)


def subspace(joint: Joint) -> sp.Matrix:
    """``S`` (6 x nv): the joint's velocity as the moved frame's twist (linear rows, then
    angular), in its own axes (module doc)."""
    if joint.type == "spherical":
        return sp.zeros(3, 3).col_join(sp.eye(3))
    if joint.type == "planar":
        S = sp.zeros(6, 3)
        S[0, 0] = S[1, 1] = S[5, 2] = 1
        return S
    return sp.eye(6)


def rates(robot: Robot) -> tuple[list, list]:
    """The generalised velocities and accelerations, ``(v, a)`` (dof each): a joint of one
    coordinate's ``qd`` and ``qdd``; a joint of several coordinates' velocity (the symbols
    named after its coordinates, ``robot.q``'s at its rows) and their derivatives
    (``robot.qd``'s)."""
    v, a = list(robot.qd), list(robot.qdd)
    for j in robot.multi_dof_joints:
        k = robot.coordinate_index(j)
        v[k : k + j.nv], a[k : k + j.nv] = robot.q[k : k + j.nv], robot.qd[k : k + j.nv]
    return v, a


def pose_symbols(robot: Robot) -> list:
    """The symbols the equations' pose dependence is written in: the joints of one
    coordinate's ``q``, then each joint of several coordinates' (:func:`configuration_symbols`)."""
    own = [robot.q[robot.coordinate_index(j)] for j in robot.movable_joints if j.type not in DERIVED]
    return own + [s for j in robot.multi_dof_joints for s in configuration_symbols(j)]


def motion(joint: Joint, v, a) -> dict:
    """The recursion's quantities of the ``joint`` of several coordinates at velocity ``v``
    and acceleration ``a`` (nv each, moved joint frame): the child frame's placement
    ``R``, ``P`` in the parent frame, its origin's motion ``V``, ``Vd`` relative to the
    parent (frame i), and ``z``: ``Z`` (6 x nv), ``S`` in frame i's axes (module doc)."""
    Rm, pm = joint_pose(joint)
    v, a, Z = sp.Matrix(list(v)), sp.Matrix(list(a)), subspace(joint)
    if joint.has_frame_offset:
        Rf, pf = joint.frame_rotation, joint.frame_xyz
        Rc, Pc = Rm * Rf, pm + Rm * pf
        Z = sp.diag(Rf.T, Rf.T) * Z
        r = -joint.joint_point()  # the child frame's origin from the moved frame's, frame i
    else:
        Rc, Pc, r = Rm, pm, sp.zeros(3, 1)
    u, s, ud, sd = Z[:3, :] * v, Z[3:, :] * v, Z[:3, :] * a, Z[3:, :] * a
    V, Vd = u + s.cross(r), ud + sd.cross(r) + s.cross(u + s.cross(r))
    return {"R": joint.rotation * Rc, "P": joint.xyz + joint.rotation * Pc, "V": V, "Vd": Vd, "z": Z}


def state_values(robot: Robot, q, v=None, a=None) -> dict:
    """Symbol -> value of the equations' symbols at the numeric state ``q`` (nq,),
    ``v``, ``a`` (nv,) in armdyn.numeric's layout (:attr:`Robot.configuration_layout`):
    a joint of several coordinates' rotation entries from its quaternion (x, y, z, w, of
    unit length: :func:`armdyn.configuration.check_configuration`) or (cos, sin), its
    position, velocity and acceleration; the other joints' q, qd, qdd. A floating base's
    gravity in its frame (:data:`~.base_symbols.BASE_GRAVITY`) from its
    quaternion, its twist and its derivative (the first six of ``v`` and ``a``)."""
    from ..configuration import check_configuration
    from ..model.joints import multi_dof_motion

    q = check_configuration(robot, np.asarray(q, dtype=float).reshape(-1))
    vel, acc = rates(robot)
    out: dict = {}
    if robot.floating:
        vel, acc = [*BASE_VELOCITY, *vel], [*BASE_ACCELERATION, *acc]
        out.update(zip(BASE_GRAVITY, (float(x) for x in gravity_in_base(robot, q[3:7]))))
    joints = {j.name: j for j in robot.movable_joints}
    for name, kind, iq, iv in robot.configuration_layout:
        joint = joints[name]
        if kind == "planar":
            out.update(zip(configuration_symbols(joint), (float(x) for x in q[iq : iq + 4])))
        elif kind in DERIVED:
            R, _ = multi_dof_motion(kind, [float(x) for x in q[iq : iq + joint.nq]])
            out.update(zip(position_symbols(joint), (float(x) for x in q[iq : iq + joint.nq - 4])))
            out.update(zip(rotation_symbols(joint), (float(x) for x in R)))
        else:
            out[robot.q[robot.coordinate_index(joint)]] = float(q[iq])
    for given, symbols in ((v, vel), (a, acc)):
        if given is not None:
            out.update(zip(symbols, (float(x) for x in np.asarray(given, dtype=float).reshape(-1))))
    return out


class SphericalEquationsOfMotion(EquationsOfMotion):
    """The equations of motion of a robot with joints of several coordinates (spherical,
    planar, floating), ``M(q) a + bias(q, v) = tau`` (module doc): ``q`` the joints'
    coordinates and the others' pose symbols (:func:`pose_symbols`), ``qd`` and ``qdd``
    (dof each) the velocities (a ball joint's angular velocity, ...) and their time
    derivatives, ``tau`` (dof) at the same rows."""

    @property
    def q(self) -> sp.Matrix:
        return sp.Matrix(pose_symbols(self.robot))

    @property
    def qd(self) -> sp.Matrix:
        return sp.Matrix(rates(self.robot)[0])

    @property
    def qdd(self) -> sp.Matrix:
        return sp.Matrix(rates(self.robot)[1])

    @cached_property
    def bias(self) -> sp.Matrix:
        """``C v + g`` (dof): tau at zero acceleration."""
        from . import dag

        return dag.xreplace(self.tau, {s: 0 for s in self.qdd})

    @property
    def C(self) -> sp.Matrix:  # type: ignore[override]
        raise ModelError(
            f"the Christoffel matrix C does not apply to a {self.robot.multi_dof_joints[0].type} joint's "
            "velocity (a quasi-velocity); use eom.bias (C v + g) and eom.g",
            f"robot '{self.robot.name}'",
            self.robot.meta.get("file"),
        )

    def symbol_names(self, fmt: str) -> dict:
        """The joints' symbols as the reports print them (:func:`joint_symbol_names`)."""
        return joint_symbol_names(self.robot, fmt)


def joint_symbol_names(robot: Robot, fmt: str) -> dict:
    """The symbols of the joints of several coordinates as the reports print them
    (``fmt`` "text" or "latex"): ``ω⁽¹⁾x``, ``\\dot{\\omega}^{(1)}_{x}``, ``v⁽²⁾y``,
    ``r⁽¹⁾₁₂``, ``c⁽²⁾``, ``p^{(2)}_{x}`` (1, 2: the child link's frame number)."""
    names: dict = {}
    for j in robot.multi_dof_joints:
        i, k = robot.link_index(j.child), robot.coordinate_index(j)
        for coordinate, w, wd in zip(j.coordinate_names, robot.q[k : k + j.nv], robot.qd[k : k + j.nv]):
            letter, axis = coordinate.rsplit(".", 1)[1]  # "vx" -> v, x
            names[w] = _printed(fmt, i, letter, axis)
            names[wd] = _printed(fmt, i, letter, axis, dot=True)
        for p, axis in zip(position_symbols(j), "xyz"):
            names[p] = _printed(fmt, i, "p", axis)
        if j.type == "planar":
            names.update((t, _printed(fmt, i, letter)) for t, letter in zip(turn_symbols(j), "cs"))
        else:
            for n, r in enumerate(rotation_symbols(j)):
                jk = f"{n // 3 + 1}{n % 3 + 1}"
                names[r] = _printed(fmt, i, "r", jk.translate(SUBSCRIPT_DIGITS) if fmt == "text" else jk)
    return names


def _printed(fmt: str, i: int, letter: str, axis: str = "", dot: bool = False) -> str:
    """``letter`` (``w``: omega) of frame ``i`` with its ``axis`` (or entry) as a subscript,
    dotted for a derivative: ``ω̇⁽¹⁾x``, ``\\dot{\\omega}^{(1)}_{x}``."""
    if fmt == "latex":
        tex = r"\omega" if letter == "w" else letter
        return (rf"\dot{{{tex}}}" if dot else tex) + f"^{{({i})}}" + (f"_{{{axis}}}" if axis else "")
    tag = f"⁽{str(i).translate(_SUPERSCRIPT)}⁾"
    return ("ω" if letter == "w" else letter) + ("\u0307" if dot else "") + tag + axis


def note(robot: Robot) -> str:
    """What a report says of the joints' symbols (ASCII: the reports' --ascii too)."""
    parts = []
    for j in robot.multi_dof_joints:
        i, first, last, name = robot.link_index(j.child), j.coordinate_names[0], j.coordinate_names[-1], j.name
        velocity = {
            "spherical": "its angular velocity",
            "planar": "its linear velocity in its x-y plane and turn rate",
            "floating": "its linear, then angular velocity",
        }[j.type]
        rotation = f"rotation [{name}.r11 ... {name}.r33] (printed r^({i})jk: frame {i}'s axes in its placement frame)"
        pose = {
            "spherical": rotation,
            "planar": f"position {name}.x, {name}.y (printed p^({i})x ...), turn {name}.cos, {name}.sin "
            f"(printed c^({i}), s^({i}))",
            "floating": f"position {name}.x ... {name}.z (printed p^({i})x ...), {rotation}",
        }[j.type]
        printed = f"{'w' if j.type == 'spherical' else 'v'}^({i})x"
        parts.append(
            f"{j.type} joint '{name}': velocity {first} ... {last} (printed {printed} ...), {velocity} relative "
            f"to its parent in frame {i} axes; {pose}; tau its {TAU_MEANING[j.type]}"
        )
    return "; ".join(parts)
