"""The same robot in sympy.physics.mechanics, for tests and benchmarks.

An independent derivation: sympy.physics.mechanics builds reference frames from
direction-cosine matrices, differentiates positions and orientations with respect to
time itself, and forms Lagrange's equations with its ``LagrangesMethod``.
"""

from __future__ import annotations

import sympy as sp
from sympy.physics import mechanics as me

from armdyn.model import Robot


def mechanics_tau(robot: Robot) -> sp.Matrix:
    """tau (n x 1) of ``robot`` by sympy.physics.mechanics' LagrangesMethod, in armdyn's
    plain symbols (q, qd, qdd)."""
    eqs, names = mechanics_equations(robot)
    return plain_symbols(eqs, names)


def plain_symbols(eqs: sp.Matrix, names: dict) -> sp.Matrix:
    """Mechanics' equations with q(t), q'(t), q''(t) replaced by armdyn's plain symbols
    (one ``xreplace``: whole derivatives are matched before their q(t) inside)."""
    return eqs.xreplace(names)


def mechanics_equations(robot: Robot) -> tuple[sp.Matrix, dict]:
    """(LagrangesMethod's equations in dynamic symbols, map dynamic -> plain symbols)."""
    n = robot.dof
    qs = me.dynamicsymbols(f"armdyn_q0:{n}")
    qds = [qi.diff(me.dynamicsymbols._t) for qi in qs]
    world = me.ReferenceFrame("N")
    origin = me.Point("O")
    origin.set_vel(world, 0)
    frames, points = {robot.base: world}, {robot.base: origin}
    bodies = []
    gravity = robot.gravity[0] * world.x + robot.gravity[1] * world.y + robot.gravity[2] * world.z
    for joint in robot.joints:
        k = robot.coordinate_index(joint)
        R, p = joint.transform(0 if k is None else qs[k])
        parent = frames[joint.parent]
        frame = me.ReferenceFrame(f"F_{joint.child}")
        # R has the child's axes as columns in parent coordinates; orient_explicit(parent, R)
        # makes frame.x == R[0, 0] parent.x + R[1, 0] parent.y + R[2, 0] parent.z
        frame.orient_explicit(parent, R)
        point = points[joint.parent].locatenew(f"P_{joint.child}", p[0] * parent.x + p[1] * parent.y + p[2] * parent.z)
        point.set_vel(world, point.pos_from(origin).dt(world))
        frames[joint.child], points[joint.child] = frame, point
        link = robot.links[joint.child]
        c = link.com
        com = point.locatenew(f"C_{joint.child}", c[0] * frame.x + c[1] * frame.y + c[2] * frame.z)
        com.set_vel(world, com.pos_from(origin).dt(world))
        I = link.inertia
        dyadic = me.inertia(frame, I[0, 0], I[1, 1], I[2, 2], I[0, 1], I[1, 2], I[0, 2])
        body = me.RigidBody(f"B_{joint.child}", com, frame, link.mass, (dyadic, com))
        body.potential_energy = -link.mass * gravity.dot(com.pos_from(origin))
        bodies.append(body)
    lagrangian = me.Lagrangian(world, *bodies)
    lm = me.LagrangesMethod(lagrangian, qs)
    eqs = lm.form_lagranges_equations()
    names = {}
    for qi, qdi, a, b, c in zip(qs, qds, robot.q, robot.qd, robot.qdd):
        names[qdi.diff(me.dynamicsymbols._t)] = c
        names[qdi] = b
        names[qi] = a
    return eqs, names
