"""Generated code for a floating base and for joints of several coordinates (spherical,
planar, floating).

Both are parametrised by quasi-velocities (a twist, an angular velocity: no time
derivative of coordinates), so their code takes Pinocchio's three arrays, as
``armdyn.numeric`` does, and passes them unchanged::

    q (nq,)   configuration: a floating base's origin x, y, z (world frame) and
              orientation quaternion x, y, z, w; a spherical joint's quaternion
              x, y, z, w; a planar joint's x, y, cos, sin; a floating joint's x, y, z and
              quaternion; a revolute or prismatic joint's coordinate
    v (nv,)   velocity: the base's twist in its own frame (linear vb_x, vb_y, vb_z, then
              angular wb_x, wb_y, wb_z), a spherical joint's angular velocity relative to
              its parent (child frame axes), a planar joint's vx, vy, wz and a floating
              joint's twist (linear, angular) in the same way, a joint's rate
    a (nv,)   their time derivatives

and gives, in Pinocchio's order (``M(q) a + bias(q, v) = tau``):

* tau (nv,): a floating base's wrench (force, then moment about its origin, base frame),
  a spherical joint's moment about its centre, a joint's torque or force;
* M (nv, nv); g (nv,): tau at ``v = a = 0``; bias (nv,): ``C v + g``, tau at ``a = 0``.

C is refused: the Christoffel matrix of M does not apply to quasi-velocities; ask for
the bias. So are the regressor and ``base=True`` (armdyn.identification takes a fixed
base with joints of one coordinate) and mimic joints with either (armdyn.numeric does
not, to check the code against).

Each quaternion is normalised inside the code: the rotation is that of ``q / |q|``,
written with ``s = 2 / (x^2 + y^2 + z^2 + w^2)`` (``R = [[1 - s (y^2 + z^2), s (x y - w z),
...]]``, no square root), so a quaternion of any nonzero length gives the rotation of its
direction (armdyn.numeric and Pinocchio want unit ones); a zero quaternion has none and
gives NaN or inf (the compiled library refuses it). The base's position does not enter
the dynamics (the functions do not read it); a planar joint's (cos, sin) pair is
normalised too (a square root).

The programs run the symbolic Newton-Euler recursion (:mod:`armdyn.symbolic.newton_euler_floating`,
:mod:`armdyn.symbolic.newton_euler_spherical`) with every step's vector a named line (a
value met twice is one line; each sine and cosine computed once); M is its columns at
rest under unit accelerations (Walker and Orin), on and above the diagonal. Those derivations
keep gravity in the base frame (``gb_x, gb_y, gb_z``) and a joint's pose (a spherical or
floating joint's rotation ``ball.r11`` ... ``ball.r33``, a planar joint's ``cos``, ``sin``,
the position ``x, y (, z)``) as symbols, which the code computes first from q (the lines
each function starts with). Joint friction, rotor inertia and
offsets are added as ``armdyn.derive`` adds them.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import sympy as sp

from ..errors import FloatingBaseError, ModelError
from ..model import Robot
from ..programs.program import Builder, Program

#: what codegen generates for these robots when not told
DEFAULT_WHAT = ("tau", "M", "g", "bias")


@dataclass
class Layout:
    """The arrays' symbols (``q`` (nq), ``v``, ``a`` (nv)), the quaternions among ``q``
    (``[(first index, whose)]``), the lines computing the derivation's rotation and gravity
    symbols from them (``preamble``) and the header lines saying all this."""

    q: list
    v: list
    a: list
    quaternions: list = field(default_factory=list)
    preamble: list = field(default_factory=list)
    conventions: list = field(default_factory=list)


def _where(robot: Robot) -> tuple[str, str | None]:
    return f"robot '{robot.name}'", robot.meta.get("file")


def check_robot(robot: Robot) -> None:
    """Refuse, naming the joint, what the derivations do not take (module doc)."""
    where, source = _where(robot)
    if robot.mimic_joints:  # nothing to check such code against: armdyn.numeric refuses them too
        beside = "on a floating base" if robot.floating else "beside joints of several coordinates"
        raise (FloatingBaseError if robot.floating else ModelError)(
            f"armdyn.codegen does not take mimic joints {beside} yet (joint '{robot.mimic_joints[0].name}')",
            where,
            source,
        )


def check_what(robot: Robot, what, base: bool) -> None:
    """Refuse C, the regressor and ``base=True`` with the reason (module doc)."""
    where, source = _where(robot)
    if robot.floating:
        error, kind = FloatingBaseError, "a floating base parametrised by its twist"
    else:
        named = ", ".join(f"{j.type} joint '{j.name}'" for j in robot.multi_dof_joints)
        error, kind = ModelError, f"the velocity of {named}"
    has = "a floating base" if robot.floating else named
    if base or "regressor" in what:
        asked = "base=True (the base parameters)" if base else "the regressor"
        raise error(
            f"armdyn.codegen: {asked} comes from armdyn.identification, which takes a fixed base with revolute "
            f"and prismatic joints only; this robot has {has}",
            where,
            source,
        )
    if "C" in what:
        raise error(
            f"armdyn.codegen: C, the Christoffel matrix of M, does not apply to {kind} (a quasi-velocity, no "
            "time derivative of coordinates): generate the bias C v + g instead (what='tau,M,g,bias', "
            "--what tau,M,g,bias)",
            where,
            source,
        )


def _quaternion_symbols(whose: str) -> list:
    # Dummies: no clash with a model's own names is possible
    return [sp.Dummy(f"{whose}.q{c}") for c in "xyzw"]


def _rotation(builder: Builder, quaternion, hint: str) -> sp.Matrix:
    """R of the quaternion ``x, y, z, w`` normalised (module doc), its scale ``s`` a line
    of ``builder``."""
    x, y, z, w = quaternion
    n = builder.let(x**2 + y**2 + z**2 + w**2, f"{hint}_n")
    s = builder.let(2 / n, f"{hint}_s")
    return sp.Matrix(
        [
            [1 - s * (y**2 + z**2), s * (x * y - w * z), s * (x * z + w * y)],
            [s * (x * y + w * z), 1 - s * (x**2 + z**2), s * (y * z - w * x)],
            [s * (x * z - w * y), s * (y * z + w * x), 1 - s * (x**2 + y**2)],
        ]
    )


def layout(robot: Robot, v, a) -> Layout:
    """The arrays of ``robot``'s code (``v``, ``a``: the derivation's velocity and
    acceleration symbols) and the preamble's lines."""
    from ..symbolic.base_symbols import BASE_GRAVITY
    from ..symbolic.newton_euler_spherical import configuration_symbols, position_symbols, rotation_symbols

    q: list = []
    quaternions = []
    taken = {s.name for s in robot.free_symbols()} | {s.name for s in [*robot.q, *v, *a]}
    taken |= {s.name for j in robot.multi_dof_joints for s in configuration_symbols(j)} | {s.name for s in BASE_GRAVITY}
    builder = Builder(reserved=[sp.Symbol(n) for n in taken])
    preamble = []
    if robot.floating:
        quat = _quaternion_symbols("base")
        q += [sp.Dummy(f"base.{c}") for c in "xyz"] + quat
        quaternions.append((3, "the base"))
        R = _rotation(builder, quat, "base")
        preamble += list(zip(BASE_GRAVITY, R.T * sp.Matrix(robot.gravity)))
    joints = {j.name: j for j in robot.movable_joints}
    for name, kind, iq, iv in robot.configuration_layout:
        joint = joints[name]
        if kind in ("planar", "floating"):  # the position first, as it is
            position = [sp.Dummy(f"{name}.{c}") for c in "xyz"[: 2 if kind == "planar" else 3]]
            q += position
            preamble += list(zip(position_symbols(joint), position))
        if kind == "planar":  # (cos, sin), normalised
            c, s = sp.Dummy(f"{name}.c"), sp.Dummy(f"{name}.s")
            q += [c, s]
            inv = builder.let(1 / sp.sqrt(c**2 + s**2), f"{name}_inv")
            preamble += list(zip(configuration_symbols(joint)[2:], (c * inv, s * inv)))
        elif kind in ("spherical", "floating"):
            quat = _quaternion_symbols(name)
            quaternions.append((len(q), f"joint '{name}'"))
            q += quat
            preamble += list(zip(rotation_symbols(joint), _rotation(builder, quat, name)))
        else:
            q.append(robot.q[iv - (6 if robot.floating else 0)])
    assert len(q) == robot.nq
    # the scales first: the rotation entries and gravity read them
    lines = builder.assignments + preamble
    return Layout(q, list(v), list(a), quaternions, lines, _conventions(robot, q, v))


def _conventions(robot: Robot, q, v) -> list[str]:
    """What the header says of the arrays."""
    out = [
        "Equation of motion: M(q) a + bias(q, v) = tau, bias = C(q, v) v + g(q) (SI units, radians),",
        "arrays in Pinocchio's layout and order (armdyn.numeric's):",
        f"q (nq = {len(q)}): {', '.join(s.name for s in q)}",
        f"v (nv = {len(v)}): {', '.join(s.name for s in v)}; a: their time derivatives",
    ]
    if robot.floating:
        out += [
            "The base: its origin (world frame; not read) and orientation quaternion x, y, z, w;",
            "its twist in its own frame (linear, angular); tau's first 6 rows the wrench on it",
            "(force, moment about its origin, base frame). Gravity enters as gb = R^T g.",
        ]
    said = {j.type for j in robot.multi_dof_joints}
    if "spherical" in said:
        out += [
            "A spherical joint: quaternion x, y, z, w; angular velocity relative to its parent in",
            "its child frame; tau its moment about its centre, in that frame.",
        ]
    if "planar" in said:
        out += [
            "A planar joint: x, y, cos, sin in its placement frame's x-y plane ((cos, sin) normalised);",
            "vx, vy, wz relative to its parent in its child frame; tau the force and moment on it.",
        ]
    if "floating" in said:
        out += [
            "A floating joint: position, quaternion x, y, z, w in its placement frame; its twist",
            "relative to its parent in its child frame (linear, angular); tau the wrench on it.",
        ]
    out.append("Quaternions are normalised here (the rotation of q/|q|; a zero one gives NaN or inf).")
    return out


def _named_sines(program: Program, builder: Builder) -> Program:
    """The program with each sine and cosine a line of its own, read where it is used
    (``sin_q1 = sin(q1)``: computed once; the C batch code takes them from its kernel)."""
    exprs = [e for _, e in program.assignments] + [sp.sympify(e) for e in program.outputs]
    found = sorted(set().union(*(e.atoms(sp.sin, sp.cos) for e in exprs)), key=sp.default_sort_key)
    if not found:
        return program
    named = {f: builder.name(f"{type(f).__name__}_{f.args[0]}") for f in found}
    lines = [(named[f], f) for f in found]
    lines += [(t, e.xreplace(named)) for t, e in program.assignments]
    return Program(lines, [sp.sympify(e).xreplace(named) for e in program.outputs], program.shape)


def programs(robot: Robot, what) -> tuple[dict, dict, Layout]:
    """The programs of ``what`` (tau, M, g, bias): the symbolic Newton-Euler's recursion
    with every step's vector a named line (:class:`Builder`: a value met twice is one
    line), joint friction, rotor inertia and offsets added as ``armdyn.derive`` adds them;
    each program starts with the preamble's lines it needs. Also their sources and the
    layout."""
    from ..symbolic import newton_euler_spherical as spherical
    from ..symbolic.joint_terms import armature, has_joint_terms, joint_torques
    from ..symbolic.newton_euler import recursion
    from ..symbolic.newton_euler_floating import (
        BASE_ACCELERATION,
        BASE_GRAVITY,
        BASE_VELOCITY,
        check_floating_robot,
        floating_recursion,
    )

    nv, base = robot.nv, (6 if robot.floating else 0)
    v, a = spherical.rates(robot)
    if robot.floating:
        check_floating_robot(robot)
        v, a = [*BASE_VELOCITY, *v], [*BASE_ACCELERATION, *a]
    else:
        spherical.check_joints(robot, "armdyn.codegen")
    found = layout(robot, v, a)
    reserved = robot.free_symbols() | {*found.q, *found.v, *found.a} | {s for s, _ in found.preamble}
    builder = Builder(reserved=reserved | set(robot.q) | set(robot.qd) | set(robot.qdd))

    def let(x, hint):
        return sp.Matrix(builder.vector(x, hint)) if isinstance(x, sp.MatrixBase) and x.shape == (3, 1) else x

    def tau(v, a, gravity: bool) -> list:
        if robot.floating:
            out = floating_recursion(robot, v, a, BASE_GRAVITY if gravity else [0, 0, 0], let=let)
        else:
            out = recursion(robot, v, a, -robot.gravity if gravity else sp.zeros(3, 1), let=let)
        return list(out)

    def with_joint_terms(rows, v, a) -> list:
        if not has_joint_terms(robot):
            return rows
        extra = joint_torques(robot, v[base:], a[base:])
        return rows[:base] + [r + e for r, e in zip(rows[base:], extra)]

    zero = [0] * nv
    derivation = "floating-base Newton-Euler" if robot.floating else "Newton-Euler with joints of several coordinates"
    outputs, sources = {}, {}
    for w in what:
        if w == "M":  # Walker-Orin: column j is tau at rest, no gravity, a = e_j; symmetric
            columns = [tau(zero, [int(i == j) for i in range(nv)], False) for j in range(nv)]
            ia = armature(robot)
            for k in range(nv - base):
                columns[base + k][base + k] += ia[k]
            outputs[w] = [columns[max(i, j)][min(i, j)] for i in range(nv) for j in range(nv)]
            sources[w] = f"{derivation}, unit accelerations (Walker-Orin)"
        else:
            vw, aw = {"tau": (v, a), "g": (zero, zero), "bias": (v, zero)}[w]
            outputs[w] = with_joint_terms(tau(vw, aw, True), vw, aw)
            sources[w] = derivation + {"tau": "", "g": " at v = a = 0", "bias": " at a = 0"}[w]
        sources[w] += ", every step a named vector"
    programs = {}
    for w, out in outputs.items():
        shape = (nv, nv) if w == "M" else (nv,)
        prog = Program(list(builder.assignments), out, shape).pruned()
        prog = _named_sines(prog, builder)
        programs[w] = Program(found.preamble + prog.assignments, prog.outputs, shape).pruned()
    return programs, sources, found
