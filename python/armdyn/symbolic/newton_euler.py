"""Equations of motion by the recursive (iterated) Newton-Euler method, symbolically.

The recursion is Craig's (Introduction to Robotics, eqs. 6.45-6.53), generalised to
joints placed anywhere (model.py's frames, non-DH included), to fixed joints and to
branched trees. Every vector of link i is expressed in link i's own frame.

Outward, for link i with parent p, child frame in parent ``(R, p_i)`` (R: axes of frame i
in frame p), joint axis ``z`` (in frame i) and coordinate ``q``::

    revolute:   w_i  = R^T w_p + qd z
                wd_i = R^T wd_p + (R^T w_p) x qd z + qdd z
    prismatic:  w_i  = R^T w_p,        wd_i = R^T wd_p
    vd_i  = R^T (wd_p x p_i + w_p x (w_p x p_i) + vd_p)
            [+ 2 w_i x qd z + qdd z   (prismatic)]
    vcd_i = wd_i x c_i + w_i x (w_i x c_i) + vd_i
    F_i = m_i vcd_i,   N_i = I_i wd_i + w_i x I_i w_i

Gravity enters as the base's acceleration ``vd_0 = -gravity``. Inward, over the children
c of link i (``R_c``, ``p_c`` the child's placement in frame i)::

    f_i = F_i + sum_c R_c f_c
    n_i = N_i + c_i x F_i + sum_c (R_c n_c + p_c x R_c f_c)
    tau_i = z . n_i (revolute),  z . f_i (prismatic)

``f_i``/``n_i`` are the force and moment that the parent exerts on link i at frame i's
origin. ``F_i``/``N_i`` are the rates of change of momentum (Craig's sign; the exercise
writes the d'Alembert inertial force ``-m vcd``).
"""

from __future__ import annotations

import sympy as sp

from ..model import Robot
from .joint_terms import armature, has_joint_terms, joint_torques
from .terms import EquationsOfMotion, Step



def _recursion(robot: Robot, qd, qdd, base_acceleration, steps: list[Step] | None = None) -> sp.Matrix:
    """tau (n x 1) for joint velocities ``qd`` and accelerations ``qdd`` (sequences of
    length n, symbols or numbers) with the base accelerating at ``base_acceleration``
    (3 x 1; ``-gravity`` for the equations of motion). Appends the steps if given."""
    zero = sp.zeros(3, 1)
    w = {robot.base: zero}
    wd = {robot.base: zero}
    vd = {robot.base: base_acceleration}
    F, N, placement = {}, {}, {}
    record = steps is not None
    outward: list[Step] = []

    for joint in robot.joints:
        link = robot.links[joint.child]
        parent, i = joint.parent, robot.link_index(joint.child)
        k = robot.coordinate_index(joint)
        R, p = joint.transform(robot.joint_coordinate(joint))
        placement[joint.child] = (R, p)
        Rt = R.T
        z = joint.axis

        w_in = Rt * w[parent]
        wd_in = Rt * wd[parent]
        vd_c = Rt * (wd[parent].cross(p) + w[parent].cross(w[parent].cross(p)) + vd[parent])
        if joint.type == "revolute":
            w_i = w_in + qd[k] * z
            wd_i = wd_in + w_in.cross(qd[k] * z) + qdd[k] * z
        else:
            w_i, wd_i = w_in, wd_in
        if joint.type == "prismatic":
            vd_c = vd_c + 2 * w_i.cross(qd[k] * z) + qdd[k] * z
        c = link.com
        vcd = wd_i.cross(c) + w_i.cross(w_i.cross(c)) + vd_c
        w[joint.child], wd[joint.child], vd[joint.child] = w_i, wd_i, vd_c
        F[joint.child] = link.mass * vcd
        N[joint.child] = link.inertia * wd_i + w_i.cross(link.inertia * w_i)

        if record:
            name = joint.child
            outward += [
                Step("outward", name, "omega", rf"{{}}^{{{i}}}\omega_{{{i}}}", w_i, "angular velocity"),
                Step("outward", name, "omega_dot", rf"{{}}^{{{i}}}\dot\omega_{{{i}}}", wd_i, "angular acceleration"),
                Step("outward", name, "v_dot", rf"{{}}^{{{i}}}\dot v_{{{i}}}", vd_c,
                     "linear acceleration of the frame origin (gravity included as base acceleration)"),
                Step("outward", name, "vc_dot", rf"{{}}^{{{i}}}\dot v_{{C_{i}}}", vcd,
                     "linear acceleration of the centre of mass"),
                Step("outward", name, "F", rf"{{}}^{{{i}}}F_{{{i}}}", F[name], "inertial force m vcd"),
                Step("outward", name, "N", rf"{{}}^{{{i}}}N_{{{i}}}", N[name], "inertial moment I wd + w x I w"),
            ]

    f, n = {}, {}
    tau = [sp.Integer(0)] * robot.dof
    inward: list[Step] = []
    for joint in reversed(robot.joints):
        name, i = joint.child, robot.link_index(joint.child)
        link = robot.links[name]
        f_i = F[name]
        n_i = N[name] + link.com.cross(F[name])
        for child in robot.children(name):
            Rc, pc = placement[child.child]
            f_c = Rc * f[child.child]
            f_i = f_i + f_c
            n_i = n_i + Rc * n[child.child] + pc.cross(f_c)
        f[name], n[name] = f_i, n_i
        k = robot.coordinate_index(joint)
        if k is not None:
            tau[k] = (n_i if joint.type == "revolute" else f_i).dot(joint.axis)
        if record:
            inward += [
                Step("inward", name, "f", rf"{{}}^{{{i}}}f_{{{i}}}", f_i, "force exerted on the link by its parent"),
                Step("inward", name, "n", rf"{{}}^{{{i}}}n_{{{i}}}", n_i, "moment exerted on the link by its parent"),
            ]
            if k is not None:
                kind = "torque" if joint.type == "revolute" else "force"
                inward.append(Step("inward", name, "tau", rf"\tau_{{{k + 1}}}", tau[k], f"joint {kind} of '{joint.name}'"))
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
        M[:, j] = _recursion(robot, zeros, unit, sp.zeros(3, 1))
    return M + sp.diag(*armature(robot))  # rotor inertias on the diagonal


def newton_euler(robot: Robot) -> EquationsOfMotion:
    """Derive ``tau`` by iterated Newton-Euler; steps as in Craig's outward/inward passes."""
    steps: list[Step] = []
    tau = _recursion(robot, list(robot.qd), list(robot.qdd), -robot.gravity, steps)
    if has_joint_terms(robot):
        # DESIGN.md: tau += Ia qdd + Fv qd + Fc sign(qd) + offset, joint by joint
        extra = joint_torques(robot, robot.qd, robot.qdd)
        tau = tau + extra
        steps.append(Step("inward", "", "tau_joint", r"\tau_{\mathrm{joint}}", extra,
                          "rotor inertia, viscous and Coulomb friction, offset: Ia qdd + Fv qd + Fc sign(qd) + offset"))
    return EquationsOfMotion(robot, "newton-euler", tau, steps, _M_builder=lambda: mass_matrix(robot))
