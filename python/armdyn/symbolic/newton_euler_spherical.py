"""Spherical (ball) joints in the symbolic Newton-Euler derivation, by their angular velocity.

A spherical joint is Pinocchio's JointModelSpherical: its configuration a unit quaternion,
its velocity ``w`` the angular velocity of the child relative to the parent, in the moved
joint frame's axes (the child frame's unless the model gives the joint a ``frame``
offset), its acceleration ``wd`` the time derivative of those three components. Here:

* the joint's rotation is kept as a rotation matrix of symbols, ``R = [r_jk]`` (``ball.r11``
  ... ``ball.r33`` for a joint named ``ball``; printed ``r⁽ⁱ⁾₁₁``, ``r^{(i)}_{11}``, i the
  child link's frame number), not written out from the quaternion: each entry then enters
  the recursion linearly and the steps stay as short as a revolute joint's (the
  quaternion's entries are quadratic in x, y, z, w). :func:`state_values` puts in the
  values at a quaternion;
* its three velocity coordinates (``robot.coordinate_names``: ``ball.wx``, ``ball.wy``,
  ``ball.wz``) are the symbols ``ball.wx`` ... (printed ``ω⁽ⁱ⁾x``), their derivatives
  ``ball.wx_dot`` ... (``ω̇⁽ⁱ⁾x``): in ``eom.qd`` and ``eom.qdd``, at the joint's rows;
* its three rows of ``tau`` are the moment the parent exerts on the child about the
  joint's centre, in the moved joint frame's axes (Pinocchio's tau of the joint).

In the recursion (:mod:`.newton_euler`) the joint turns as a revolute joint does, with the
vector ``S w`` in place of ``qd z`` (``S = Rf^T`` the frame offset's rotation taken back,
the identity without an offset)::

    w_i  = R^T w_p + S w
    wd_i = R^T wd_p + (R^T w_p) x S w + S wd
    tau  = S^T n_o            (n_o: the moment about the joint's centre o, frame i)

and a child frame off the centre, at ``r`` from it, moves relative to the parent with
``V = S w x r``, ``Vd = S wd x r + S w x (S w x r)``.

``w`` is no time derivative of coordinates (a quasi-velocity), so Lagrange's method is not
offered and ``C`` is no Christoffel matrix of ``M``: the equations carry ``bias = C v + g``
(tau at zero acceleration), as a floating base's do (:mod:`.newton_euler_floating`).
"""

from __future__ import annotations

from functools import cached_property

import numpy as np
import sympy as sp

from ..errors import ModelError
from ..model import Joint, Robot
from .names import SUBSCRIPT_DIGITS
from .terms import EquationsOfMotion

#: the joints of several coordinates the Newton-Euler derivation takes
DERIVED = ("spherical",)
_SUPERSCRIPT = str.maketrans("0123456789", "⁰¹²³⁴⁵⁶⁷⁸⁹")


def check_joints(robot: Robot, what: str = "the Newton-Euler derivation (armdyn.derive)") -> None:
    """A ModelError naming ``what`` and the joint for a joint of several coordinates other
    than spherical (planar, floating), or a name of the spherical joints' symbols that the
    model already uses."""
    if not robot.multi_dof_joints:
        return
    where, source = f"robot '{robot.name}'", robot.meta.get("file")
    other = [j for j in robot.multi_dof_joints if j.type not in DERIVED]
    if other:
        j = other[0]
        raise ModelError(
            f"{what} takes revolute, prismatic and spherical joints; joint '{j.name}' is {j.type}. "
            "armdyn.numeric's rnea, crba, aba ... take it",
            where,
            source,
        )
    taken = {s.name for j in robot.multi_dof_joints for s in rotation_symbols(j)}
    clash = taken & ({s.name for s in robot.free_symbols()} | set(robot.coordinate_names))
    if clash:
        raise ModelError(f"names {sorted(clash)} are a spherical joint's own symbols: rename them", where, source)


def rotation_symbols(joint: Joint) -> sp.Matrix:
    """(3, 3) the symbols of the spherical ``joint``'s rotation, ``<joint>.r11`` ...
    ``<joint>.r33``: the moved joint frame's axes (columns) in the placement frame."""
    return sp.Matrix(3, 3, lambda a, b: sp.Symbol(f"{joint.name}.r{a + 1}{b + 1}"))


def rates(robot: Robot) -> tuple[list, list]:
    """The generalised velocities and accelerations, ``(v, a)`` (dof each): a joint of one
    coordinate's ``qd`` and ``qdd``; a spherical joint's angular velocity (the symbols named
    after its coordinates, ``robot.q``'s at its rows) and their derivatives (``robot.qd``'s)."""
    v, a = list(robot.qd), list(robot.qdd)
    for j in robot.multi_dof_joints:
        k = robot.coordinate_index(j)
        v[k : k + j.nv], a[k : k + j.nv] = robot.q[k : k + j.nv], robot.qd[k : k + j.nv]
    return v, a


def pose_symbols(robot: Robot) -> list:
    """The symbols the equations' pose dependence is written in: the joints of one
    coordinate's ``q``, then each spherical joint's rotation entries (row by row)."""
    own = [robot.q[robot.coordinate_index(j)] for j in robot.movable_joints if j.type not in DERIVED]
    return own + [s for j in robot.multi_dof_joints for s in rotation_symbols(j)]


def motion(joint: Joint, w, wd) -> dict:
    """The recursion's quantities of the spherical ``joint`` at angular velocity ``w`` and
    acceleration ``wd`` (3 each, moved joint frame): the child frame's placement ``R``,
    ``P`` in the parent frame, its origin's motion ``V``, ``Vd`` relative to the parent
    (frame i), and ``z``: ``S``, the 3x3 map of ``w`` to frame i (module doc)."""
    Rm, zero = rotation_symbols(joint), sp.zeros(3, 1)
    w, wd = sp.Matrix(list(w)), sp.Matrix(list(wd))
    if joint.has_frame_offset:
        Rf, pf = joint.frame_rotation, joint.frame_xyz
        Rc, Pc, S = Rm * Rf, Rm * pf, Rf.T
        r = -joint.joint_point()  # the child frame's origin from the centre, frame i
        s, sd = S * w, S * wd
        V, Vd = s.cross(r), sd.cross(r) + s.cross(s.cross(r))
    else:
        Rc, Pc, S, V, Vd = Rm, zero, sp.eye(3), zero, zero
    return {"R": joint.rotation * Rc, "P": joint.xyz + joint.rotation * Pc, "V": V, "Vd": Vd, "z": S}


def state_values(robot: Robot, q, v=None, a=None) -> dict:
    """Symbol -> value of the equations' symbols at the numeric state ``q`` (nq,),
    ``v``, ``a`` (nv,) in armdyn.numeric's layout (:attr:`Robot.configuration_layout`;
    a fixed base): a spherical joint's rotation entries from its quaternion (x, y, z, w,
    of unit length: :func:`armdyn.configuration.check_configuration`), its angular
    velocity and acceleration; the other joints' q, qd, qdd."""
    from ..configuration import check_configuration
    from ..model.joints import multi_dof_motion

    robot.require_fixed_base("armdyn.symbolic.newton_euler_spherical.state_values")
    q = check_configuration(robot, np.asarray(q, dtype=float).reshape(-1))
    vel, acc = rates(robot)
    joints = {j.name: j for j in robot.movable_joints}
    out: dict = {}
    for name, kind, iq, iv in robot.configuration_layout:
        if kind == "spherical":
            R, _ = multi_dof_motion(kind, [float(x) for x in q[iq : iq + 4]])
            out.update(zip(rotation_symbols(joints[name]), (float(x) for x in R)))
        else:
            out[robot.q[iv]] = float(q[iq])
    for given, symbols in ((v, vel), (a, acc)):
        if given is not None:
            out.update(zip(symbols, (float(x) for x in np.asarray(given, dtype=float).reshape(-1))))
    return out


class SphericalEquationsOfMotion(EquationsOfMotion):
    """The equations of motion of a robot with spherical joints, ``M(q) a + bias(q, v) =
    tau`` (module doc): ``q`` the joints' coordinates and the spherical joints' rotation
    entries, ``qd`` and ``qdd`` (dof each) the velocities (a spherical joint's angular
    velocity) and their time derivatives, ``tau`` (dof) at the same rows."""

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
            "the Christoffel matrix C does not apply to a spherical joint's angular velocity "
            "(a quasi-velocity); use eom.bias (C v + g) and eom.g",
            f"robot '{self.robot.name}'",
            self.robot.meta.get("file"),
        )

    def symbol_names(self, fmt: str) -> dict:
        """The spherical joints' symbols as the reports print them: ``ω⁽¹⁾x``,
        ``\\dot{\\omega}^{(1)}_{x}``, ``r⁽¹⁾₁₂`` (1: the child link's frame number)."""
        robot, names = self.robot, {}
        for j in robot.multi_dof_joints:
            i, k = robot.link_index(j.child), robot.coordinate_index(j)
            tag = f"⁽{str(i).translate(_SUPERSCRIPT)}⁾"
            for axis, w, wd in zip("xyz", robot.q[k : k + 3], robot.qd[k : k + 3]):
                if fmt == "latex":
                    names[w], names[wd] = rf"\omega^{{({i})}}_{{{axis}}}", rf"\dot{{\omega}}^{{({i})}}_{{{axis}}}"
                else:
                    names[w], names[wd] = f"ω{tag}{axis}", f"ω\u0307{tag}{axis}"
            for n, r in enumerate(rotation_symbols(j)):
                jk = f"{n // 3 + 1}{n % 3 + 1}"
                names[r] = rf"r^{{({i})}}_{{{jk}}}" if fmt == "latex" else f"r{tag}{jk.translate(SUBSCRIPT_DIGITS)}"
        return names


def note(robot: Robot) -> str:
    """What a report says of the spherical joints' symbols (ASCII: the reports' --ascii too)."""
    parts = []
    for j in robot.multi_dof_joints:
        i = robot.link_index(j.child)
        parts.append(
            f"spherical joint '{j.name}': velocity its angular velocity relative to its parent in frame {i} "
            f"axes ({j.name}.wx ..., printed w^({i})x ...), its rotation the matrix [{j.name}.r11 ... "
            f"{j.name}.r33] (r^({i})jk: frame {i}'s axes in its placement frame), tau its moment about its centre"
        )
    return "; ".join(parts)
