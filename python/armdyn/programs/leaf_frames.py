"""Turning a leaf link's frame about its joint axis so that its first moment lies on y.

A link with no children (the last link of a chain, each tip of a tree) is free to have
its frame turned about its joint axis by any constant angle ``th``: the joint axis, the
joint torque ``tau = z . n`` and every other link are unchanged, the joint coordinate
enters as ``q + th`` (Khalil and Dombre, *Modeling, Identification and Control of
Robots*, 2002, sec. 3.2: the x axis of the terminal frame is arbitrary). Choosing

    th = atan2(-MX, MY)     (0 when MX = MY = 0)

puts the link's first moment on y: ``MS' = (0, sqrt(MX^2 + MY^2), MZ)``, so every
product with ``MX`` disappears from the link's force ``U MS`` and moment ``MS x vd``
(and the ``y`` component of the acceleration with it). On y rather than x: the force
then takes U's second column, whose diagonal entry ``U22`` the Euler moment's
coefficients need anyway (:func:`armdyn.programs.link_terms.squares`), where ``U11``
would be formed for the force alone (one sum more). The inertia about the origin
turns with the frame (``J' = Rz(th)^T J Rz(th)``); its ``YY'``, zero after Khalil's
grouping before the turn, is not zero any more, so ``diag(YY', YY', 0)`` is grouped onto
the parent again (:func:`_yy_moved`). The angle, the turned first moment and inertia are
computed once per parameter set, like the grouped parameters; per state the joint angle
costs one addition, ``q + th``, whose sine and cosine replace those of ``q``.

Only revolute joints about the child frame's +z (armdyn's canonical frames) are turned.
"""

from __future__ import annotations

import sympy as sp

from ..model import Robot
from .program import is_value, names
from .vectors import UPPER


def _turned(M, MS, J, c, s):
    """(M, MS', J') of a body seen from its frame turned by the angle with cosine ``c``
    and sine ``s`` about z: ``MS' = Rz^T MS``, ``J' = Rz^T J Rz``."""
    XX, XY, XZ, YY, YZ, ZZ = J[0, 0], J[0, 1], J[0, 2], J[1, 1], J[1, 2], J[2, 2]
    Jp = sp.Matrix(
        [
            [c * c * XX + 2 * c * s * XY + s * s * YY, c * s * (YY - XX) + (c * c - s * s) * XY, c * XZ + s * YZ],
            [0, s * s * XX - 2 * c * s * XY + c * c * YY, -s * XZ + c * YZ],
            [0, 0, ZZ],
        ]
    )
    for a, b in ((1, 0), (2, 0), (2, 1)):
        Jp[a, b] = Jp[b, a]
    return M, sp.Matrix([c * MS[0] + s * MS[1], -s * MS[0] + c * MS[1], MS[2]]), Jp


def turn_leaf_frames(robot: Robot, parameters: dict, definitions: list, taken=()):
    """``(parameters, new_definitions, turns)``: ``parameters`` ``{link: (M, MS, J)}`` with
    every leaf link's turned (first moment on y), the definitions
    ``[(Symbol, expression)]`` of the new per-parameter-set symbols (``th6``, ``MY6L``,
    ``XX6L``, ... ; in the symbols of ``parameters`` and ``definitions``' right-hand
    sides), and ``turns`` ``{link: th}`` for :func:`customized_newton_euler`.

    A leaf whose ``MX`` or ``MY`` is zero, or whose joint is not revolute about +z, is
    left as it is. Otherwise the turn pays: it removes the 5 products of ``MX`` with their
    5 sums (3 in ``U MS``, 2 in ``MS x vd``), ``vd_y`` (2 products, 1 sum) and ``U11``
    (1 sum), and adds at
    most ``q + th`` (1 addition), the ``YY'`` term (1 product, 1 sum) where it cannot be
    grouped onto the parent and, where ``XY`` was zero, the ``XY'`` terms (3 products,
    3 sums). The parent's inertia entries that take ``YY'`` become per-parameter-set
    symbols too (``XX5L = XX5R + YY6'``).
    """
    robot = robot.canonical()
    used = names(robot.free_symbols()) | names((*robot.q, *robot.qd, *robot.qdd))
    used |= names(s for s, _ in definitions) | names(taken)
    parents = {j.parent for j in robot.joints}
    out, new, turns = dict(parameters), [], {}

    def symbol(name):
        while name in used:
            name += "_"
        used.add(name)
        return sp.Symbol(name)

    z = sp.Matrix([0, 0, 1])
    for joint in robot.joints:
        link = joint.child
        if joint.type != "revolute" or joint.axis != z or link in parents or link not in parameters:
            continue
        M, MS, J = parameters[link]
        if sp.sympify(MS[0]) == 0 or sp.sympify(MS[1]) == 0:
            continue  # already on an axis: turning would only swap x and y
        tag = str(robot.link_index(link))
        MX, MY = MS[0], MS[1]
        norm2 = MX**2 + MY**2
        nonzero = sp.Ne(norm2, 0)
        r = sp.sqrt(norm2)
        # MX = MY = 0: nothing to turn (th = 0, J' = J)
        th = sp.Piecewise((sp.atan2(-MX, MY), nonzero), (0, True))
        if not th.free_symbols:  # a model bound to numbers: a number (atan2 may leave pi in it)
            th = sp.Float(sp.N(th, 20), 20)
        else:
            sym = symbol(f"th{tag}")
            new.append((sym, th))
            th = sym
        _, MSt, Jt = _turned(M, MS, J, MY / r, -MX / r)

        def named(value, label, unturned=None):
            if value.is_Atom:
                return value
            sym = symbol(label)
            new.append(
                (sym, value if unturned is None else sp.Piecewise((sp.factor(value), nonzero), (unturned, True)))
            )
            return sym

        MSn = sp.Matrix([0, named(r, f"MY{tag}L"), MS[2]])  # c MX + s MY = 0; -s MX + c MY = |(MX, MY)|
        moved = _yy_moved(robot, joint, out, Jt[1, 1], J[1, 1])
        if moved is not None:  # Khalil's grouping again: YY' rides on the parent
            Jt, J = Jt - Jt[1, 1] * sp.diag(1, 1, 0), J - J[1, 1] * sp.diag(1, 1, 0)
            if joint.parent != robot.base:
                Mp, MSp, Jp = out[joint.parent]
                Jp = sp.Matrix(Jp)
                ptag = str(robot.link_index(joint.parent))
                for a, b in UPPER:
                    if not is_value(moved[0][a, b], 0):
                        Jp[a, b] = Jp[b, a] = named(
                            Jp[a, b] + moved[0][a, b], f"{'XYZ'[a]}{'XYZ'[b]}{ptag}L", Jp[a, b] + moved[1][a, b]
                        )
                out[joint.parent] = (Mp, MSp, Jp)
        Jn = sp.zeros(3, 3)
        for a, b in UPPER:
            Jn[a, b] = Jn[b, a] = (
                named(Jt[a, b], f"{'XYZ'[a]}{'XYZ'[b]}{tag}L", J[a, b]) if Jt[a, b] != J[a, b] else J[a, b]
            )
        out[link] = (M, MSn, Jn)
        turns[link] = th
    return out, new, turns


def _yy_moved(robot: Robot, joint, parameters: dict, YYt, YY):
    """``(D YYt, D YY)`` with ``D = R diag(1, 1, 0) R^T`` (3x3, the parent's axes; ``R``
    the joint's fixed rotation): the turned leaf's ``diag(YY', YY', 0)``, which a rotation
    about the joint axis leaves unchanged and which has no inertia about it, moved onto
    the parent (Khalil's grouping, as :mod:`armdyn.programs.grouping` did before the turn:
    the turn made ``YY' != 0`` again); ``YY`` is its value when the turn angle is 0. None
    when ``YY'`` is zero or when moving it would make a zero entry of the parent's
    inertia nonzero (more products than it saves). Onto the fixed base it simply goes: it
    never moves."""
    if is_value(YYt, 0):
        return None
    R, _ = joint.transform(sp.Integer(0))
    D = R * sp.diag(1, 1, 0) * R.T
    if not all(sp.sympify(e).is_Number for e in D):
        return None
    if joint.parent != robot.base:
        Jp = parameters[joint.parent][2]
        if any(not is_value(D[a, b], 0) and is_value(Jp[a, b], 0) for a in range(3) for b in range(3)):
            return None
    return D * YYt, D * YY
