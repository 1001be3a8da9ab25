"""Equations of motion by Lagrange's method, symbolically.

Energies (kinematics by a velocity recursion in link frames, no differentiation)::

    w_i  = R^T w_p [+ qd z  (revolute)]            angular velocity, frame i
    v_i  = R^T (v_p + w_p x p_i) + V               frame origin velocity, frame i
           (V: the origin's velocity relative to the parent, qd z for a prismatic joint,
           qd z x r for a frame at r off a revolute axis; Joint.origin_motion)
    v_Ci = v_i + w_i x c_i                          centre-of-mass velocity, frame i
    T_i  = 1/2 m_i v_Ci . v_Ci  +  1/2 w_i^T I_i w_i   (translational + rotational)
    V_i  = - m_i gravity . p_Ci                      p_Ci: centre of mass in the base frame
    L = sum_i T_i - V_i

A mimic joint (``q_m = c q_l + o``) moves with ``qd = c qd_l``: T and V are then
functions of the independent coordinates only, and the equations below are the
reduced ones (its torque carried to the leader's by the chain rule).

Euler-Lagrange equations, with the time derivative taken by the chain rule::

    tau_k = d/dt (dL/dqd_k) - dL/dq_k
          = sum_j (d2T/dqd_k dqd_j) qdd_j + (d2T/dqd_k dq_j) qd_j  -  dT/dq_k + dV/dq_k

T is a quadratic form in qd, so ``M[k, j] = d2T/dqd_k dqd_j`` exactly; it is kept and
reused by :class:`~armdyn.symbolic.terms.EquationsOfMotion`.

The differentiation is done by SymEngine (a C++ core that SymPy expressions convert to
and from exactly), which is about a thousand times faster than SymPy's ``diff`` on the
energy of a 6- or 7-dof arm; everything returned is SymPy.
"""

from __future__ import annotations

import symengine as se
import sympy as sp

from ..model import Robot
from .joint_terms import armature, friction_torques, offsets
from .newton_euler_spherical import refuse_quasi_velocities
from .terms import EquationsOfMotion, Step


def link_energies(robot: Robot):
    """Per-link (T_trans, T_rot, V) and the steps showing them."""
    zero = sp.zeros(3, 1)
    w, v = {robot.base: zero}, {robot.base: zero}
    R0, p0 = {robot.base: sp.eye(3)}, {robot.base: zero}
    T_trans, T_rot, V, steps = {}, {}, {}, []
    base = robot.links[robot.base]
    if base.mass != 0:  # a constant, kept so that V is the total potential energy (as numeric V)
        V[robot.base] = -base.mass * robot.gravity.dot(base.com)
        steps.append(Step("energy", robot.base, "V", "V_{0}", V[robot.base], "potential energy of the base (constant)"))
    for joint in robot.joints:
        name, link = joint.child, robot.links[joint.child]
        i = robot.link_index(name)
        follow = robot.follows(joint)  # (k, c, o): coordinate c q_k + o, rate c qd_k (mimic joints)
        qd_j = 0 if follow is None else follow[1] * robot.qd[follow[0]]
        R, p = joint.transform(robot.joint_coordinate(joint))
        Rt = R.T
        w_i = Rt * w[joint.parent]
        v_i = Rt * (v[joint.parent] + w[joint.parent].cross(p)) + joint.origin_motion(qd_j)[0]
        if joint.type == "revolute":
            w_i = w_i + qd_j * joint.child_axis
        w[name], v[name] = w_i, v_i
        R0[name] = R0[joint.parent] * R
        p0[name] = p0[joint.parent] + R0[joint.parent] * p

        vc = v_i + w_i.cross(link.com)
        pc = p0[name] + R0[name] * link.com
        T_trans[name] = sp.Rational(1, 2) * link.mass * vc.dot(vc)
        T_rot[name] = sp.Rational(1, 2) * (w_i.T * link.inertia * w_i)[0, 0]
        V[name] = -link.mass * robot.gravity.dot(pc)
        steps += [
            Step("energy", name, "omega", rf"{{}}^{{{i}}}\omega_{{{i}}}", w_i, "angular velocity"),
            Step("energy", name, "vc", rf"{{}}^{{{i}}}v_{{C_{i}}}", vc, "velocity of the centre of mass"),
            Step("energy", name, "pc", rf"{{}}^{{0}}p_{{C_{i}}}", pc, "centre of mass in the base frame"),
            Step(
                "energy",
                name,
                "T_trans",
                rf"T_{{{i},\mathrm{{trans}}}}",
                T_trans[name],
                "translational kinetic energy 1/2 m vc.vc",
            ),
            Step(
                "energy",
                name,
                "T_rot",
                rf"T_{{{i},\mathrm{{rot}}}}",
                T_rot[name],
                "rotational kinetic energy 1/2 w^T I w",
            ),
            Step("energy", name, "V", rf"V_{{{i}}}", V[name], "potential energy -m gravity.pc"),
        ]
    return T_trans, T_rot, V, steps


def lagrange(robot: Robot) -> EquationsOfMotion:
    """Derive ``tau`` by the Euler-Lagrange equations; steps show T (trans/rot), V and L."""
    refuse_quasi_velocities(robot, "Lagrange's method (armdyn.derive(robot, 'lagrange'))")
    q, qd, qdd, n = robot.q, robot.qd, robot.qdd, robot.dof
    T_trans, T_rot, V_links, steps = link_energies(robot)
    T = sum(T_trans.values(), sp.Integer(0)) + sum(T_rot.values(), sp.Integer(0))
    ia = armature(robot)
    if any(x != 0 for x in ia):
        # rotors spinning at qd_k (reflected through their gears): 1/2 Ia_k qd_k^2 each
        T_rotor = sum((sp.Rational(1, 2) * ia[k] * qd[k] ** 2 for k in range(n)), sp.Integer(0))
        steps.append(Step("energy", "", "T_rotor", r"T_{\mathrm{rotor}}", T_rotor, "rotor kinetic energy 1/2 Ia qd^2"))
        T = T + T_rotor
    V = sum(V_links.values(), sp.Integer(0))
    steps += [
        Step("energy", "", "T", "T", T, "total kinetic energy"),
        Step("energy", "", "V", "V", V, "total potential energy"),
        Step("energy", "", "L", "L", T - V, "Lagrangian T - V"),
    ]

    T_, V_ = se.sympify(T), se.sympify(V)
    q_, qd_, qdd_ = (list(se.sympify(list(v))) for v in (q, qd, qdd))
    dT_dqd = [T_.diff(qd_[k]) for k in range(n)]  # generalised momenta p_k = dL/dqd_k
    M_ = [[None] * n for _ in range(n)]
    for k in range(n):
        for j in range(k, n):
            M_[k][j] = M_[j][k] = dT_dqd[k].diff(qd_[j])
    # friction and offset are generalised forces that do no conservative work:
    # Rayleigh's dissipation 1/2 Fv qd^2 gives Fv qd; Coulomb Fc sign(qd); a constant offset
    nonconservative = friction_torques(robot, qd) + offsets(robot)
    tau = []
    for k in range(n):
        ddt_p = sum((M_[k][j] * qdd_[j] + dT_dqd[k].diff(q_[j]) * qd_[j] for j in range(n)), se.Integer(0))
        dL_dq = T_.diff(q_[k]) - V_.diff(q_[k])
        tau_k = sp.sympify(ddt_p - dL_dq) + nonconservative[k]
        tau.append(tau_k)
        steps += [
            Step(
                "equations",
                robot.coordinate_names[k],
                "dL_dqd",
                rf"\partial L/\partial \dot q_{{{k + 1}}}",
                sp.sympify(dT_dqd[k]),
                "generalised momentum",
            ),
            Step(
                "equations",
                robot.coordinate_names[k],
                "dL_dq",
                rf"\partial L/\partial q_{{{k + 1}}}",
                sp.sympify(dL_dq),
                "dL/dq",
            ),
            Step(
                "equations",
                robot.coordinate_names[k],
                "tau",
                rf"\tau_{{{k + 1}}}",
                tau_k,
                "d/dt dL/dqd - dL/dq" + (" + friction + offset" if nonconservative[k] != 0 else ""),
            ),
        ]

    def mass_matrix():
        M = sp.zeros(n, n)
        for k in range(n):
            for j in range(k, n):
                M[k, j] = M[j, k] = sp.sympify(M_[k][j])
        return M

    return EquationsOfMotion(robot, "lagrange", sp.Matrix(tau), steps, _M_builder=mass_matrix)
