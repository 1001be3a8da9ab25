"""The steps of each method as formulas the grader can re-apply to a student's values.

A method is a set of steps ``(key, index)``; each has

* an expected value (canonical form: Craig's signs, gravity as base acceleration, the
  moment about frame i's origin, vectors in the link's own frame);
* formulas: how the method computes it from other steps (a list of alternatives, each
  ``(inputs, function)``); a step with no formula is a leaf (given data);
* conventions: how a student may legitimately present it (``forward``: canonical ->
  shown; ``inverse``: shown -> canonical), each named, the first one the usual one.

Functions take the input values and a ``ctx``: the model's quantities (rotations,
positions, axes, masses...) either symbolic or evaluated at a sample point, so the same
formula gives the symbolic value for a report and the numbers the grader compares. The
Newton-Euler formulas are those of :mod:`armdyn.symbolic.newton_euler`.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Callable

import sympy as sp

from ..model import Robot
from ..symbolic.lagrange import link_energies
from ..symbolic.newton_euler import INWARD_STEPS, OUTWARD_STEPS, joint_torque, moment_about
from ..symbolic.terms import time_derivative

Ref = tuple  # (key, index)


@dataclass
class Convention:
    """A way of presenting a step. ``extra``: refs whose values forward/inverse need."""

    name: str  # "" for the usual presentation
    forward: Callable
    inverse: Callable
    extra: tuple = ()


def _identity(value, ctx, *extra):
    return value


USUAL = Convention("", _identity, _identity)


@dataclass
class Formula:
    inputs: tuple
    fn: Callable  # fn(ctx, *input_values) -> canonical value


@dataclass
class Method:
    name: str
    robot: Robot
    refs: list  # every step, in the method's order
    formulas: dict = field(default_factory=dict)  # ref -> [Formula]
    conventions: dict = field(default_factory=dict)  # ref -> [Convention]
    leaves: dict = field(default_factory=dict)  # ref -> fn(ctx) for given data (no formula)
    labels: dict = field(default_factory=dict)  # ref -> (LaTeX label, frame text, note)

    def expected(self, ctx, cache: dict | None = None) -> dict:
        """Every step's canonical value in ``ctx`` (symbolic or at a point)."""
        out = {} if cache is None else cache
        for ref in self.refs:
            if ref in self.leaves:
                out[ref] = self.leaves[ref](ctx)
            else:
                formula = self.formulas[ref][0]
                out[ref] = formula.fn(ctx, *(out[r] for r in formula.inputs))
        return out

    def conventions_of(self, ref) -> list[Convention]:
        return self.conventions.get(ref, [USUAL])


# ------------------------------------------------------------------ Newton-Euler


def _link_context(robot: Robot):
    """Symbolic model quantities per link index (1..n), base = 0."""
    ctx = {"gravity": robot.gravity, "R0": {0: sp.eye(3)}, "zero": sp.zeros(3, 1)}
    for joint in robot.joints:
        i = robot.link_index(joint.child)
        p = robot.link_index(joint.parent)
        follow = robot.follows(joint)  # (k, multiplier, offset); None for a fixed joint
        q = robot.joint_coordinate(joint)
        qd, qdd = (
            (follow[1] * robot.qd[follow[0]], follow[1] * robot.qdd[follow[0]])
            if follow is not None
            else (sp.Integer(0), sp.Integer(0))
        )
        R, P = joint.transform(q)
        V, Vd = joint.origin_motion(qd, qdd)
        link = robot.links[joint.child]
        ctx[i] = {
            "parent": p,
            "kind": joint.type,
            "R": R,
            "P": P,
            "V": V,
            "Vd": Vd,
            "z": joint.child_axis,
            "qd": qd,
            "qdd": qdd,
            "m": link.mass,
            "c": link.com,
            "I": link.inertia,
            "o": joint.joint_point(q),
            "children": [robot.link_index(c.child) for c in robot.children(joint.child)],
        }
        ctx["R0"][i] = ctx["R0"][p] * R
    return ctx


def evaluate_context(ctx, point: dict):
    """``ctx`` with every symbol replaced by the numbers in ``point`` (symbol -> float)."""
    point = {k: sp.Float(v) for k, v in point.items()}

    def ev(x):
        if isinstance(x, sp.MatrixBase):
            return x.xreplace(point).evalf()
        if isinstance(x, sp.Basic):
            return x.xreplace(point).evalf()
        return x

    out = {}
    for key, value in ctx.items():
        if isinstance(value, dict):
            out[key] = {k: ev(v) if not isinstance(v, (list, str, int)) else v for k, v in value.items()}
        else:
            out[key] = ev(value)
    return out


def _inward(step, i: int, own: int) -> Callable:
    """An inward step's formula on flat inputs: its own, then each child's ``step.children``."""
    width = len(step.children)

    def fn(c, *values):
        rest = values[own:]
        kids = [(c[k]["R"], c[k]["P"], *rest[j * width : (j + 1) * width]) for j, k in enumerate(c[i]["children"])]
        return step.formula(c[i], *values[:own], kids)

    return fn


def newton_euler_method(robot: Robot) -> tuple[Method, dict]:
    """The Newton-Euler steps of ``robot`` and its symbolic context."""
    ctx = _link_context(robot)
    n = len(robot.links) - 1
    zero = sp.zeros(3, 1)
    m = Method("newton-euler", robot, [])
    m.leaves[("omega", 0)] = lambda c: c["zero"]
    m.leaves[("omega_dot", 0)] = lambda c: c["zero"]
    m.leaves[("v_dot", 0)] = lambda c: -c["gravity"]
    m.refs += [("omega", 0), ("omega_dot", 0), ("v_dot", 0)]

    def gravity_part(c, i):  # the base acceleration -gravity in frame i
        return c["R0"][i].T * (-c["gravity"])

    for i in range(1, n + 1):
        p = ctx[i]["parent"]
        for step in OUTWARD_STEPS:  # derive's own formulas, on the student's values
            inputs = tuple((key, p if where == "parent" else i) for key, where in step.inputs)
            m.formulas[(step.key, i)] = [Formula(inputs, lambda c, *v, i=i, step=step: step.formula(c[i], *v))]
            m.refs.append((step.key, i))

        gravity_free = Convention(
            "gravity as a force (no base acceleration in the accelerations)",
            lambda v, c, i=i: v - gravity_part(c, i),
            lambda v, c, i=i: v + gravity_part(c, i),
        )
        m.conventions[("v_dot", i)] = [USUAL, gravity_free]
        m.conventions[("vc_dot", i)] = [USUAL, gravity_free]
        dalembert = Convention("d'Alembert inertial force F = -m v̇_C", lambda v, c: -v, lambda v, c: -v)
        m.conventions[("F", i)] = [
            USUAL,
            dalembert,
            Convention(
                "gravity as a force (F = m v̇_C without the base acceleration)",
                lambda v, c, i=i: v - c[i]["m"] * gravity_part(c, i),
                lambda v, c, i=i: v + c[i]["m"] * gravity_part(c, i),
            ),
            Convention(
                "d'Alembert inertial force, gravity as a force",
                lambda v, c, i=i: -(v - c[i]["m"] * gravity_part(c, i)),
                lambda v, c, i=i: -v + c[i]["m"] * gravity_part(c, i),
            ),
        ]
        m.conventions[("N", i)] = [
            USUAL,
            Convention("d'Alembert inertial moment N = -(I ω̇ + ω × I ω)", lambda v, c: -v, lambda v, c: -v),
        ]

    # inward: children first
    for i in range(n, 0, -1):
        kids = ctx[i]["children"]
        for step in INWARD_STEPS:
            own = tuple((key, i) for key, _ in step.inputs)
            m.formulas[(step.key, i)] = [
                Formula(own + tuple((key, k) for k in kids for key in step.children), _inward(step, i, len(own)))
            ]
            m.refs.append((step.key, i))
        m.conventions[("f", i)] = [
            USUAL,
            Convention(f"the reaction: force exerted by link {i} on link {i - 1}", lambda v, c: -v, lambda v, c: -v),
        ]
        about_axis = Convention(
            f"moment about joint {i}'s axis",
            lambda v, c, f, i=i: moment_about(v, f, c[i]["o"]),
            lambda v, c, f, i=i: v + c[i]["o"].cross(f),
            (("f", i),),
        )
        about_origin = Convention(f"moment about frame {i}'s origin (off joint {i}'s axis)", _identity, _identity)
        on_axis = ctx[i]["o"] == zero
        if ctx[i]["kind"] == "revolute" and not on_axis:
            m.conventions[("n", i)] = [
                Convention("", about_axis.forward, about_axis.inverse, about_axis.extra),
                about_origin,
            ]
        elif ctx[i]["kind"] == "prismatic":
            m.conventions[("n", i)] = [
                USUAL,
                Convention(
                    f"moment about joint {i}'s placement origin (where the slide starts), not frame {i}'s origin",
                    about_axis.forward,
                    about_axis.inverse,
                    about_axis.extra,
                ),
            ]
        # the reaction, as for f: the moment exerted by link i on link i-1, in each of the above
        m.conventions[("n", i)] = [
            *m.conventions_of(("n", i)),
            *(
                _reaction(c, f"the reaction: moment exerted by link {i} on link {i - 1}")
                for c in m.conventions_of(("n", i))
            ),
        ]
        k = robot.coordinate_index(robot.parent_joint(list(robot.links)[i]))
        if k is not None:

            def tau_fn(c, nv, fv, i=i):
                point = c[i]["o"] if c[i]["kind"] == "revolute" else c["zero"]
                return joint_torque(c[i]["kind"], c[i]["z"], moment_about(nv, fv, point), fv)

            m.formulas[("tau", k + 1)] = [Formula((("n", i), ("f", i)), tau_fn)]
            m.refs.append(("tau", k + 1))
    return m, ctx


def _reaction(conv: Convention, name: str) -> Convention:
    """``conv`` with the sign of the reaction (action = -reaction), named."""
    full = f"{name} ({conv.name})" if conv.name else name
    return Convention(
        full, lambda v, c, *x: -conv.forward(v, c, *x), lambda v, c, *x: conv.inverse(-v, c, *x), conv.extra
    )


def rotation_between(ctx, frm: int, to: int):
    """The matrix mapping frame-``frm`` coordinates to frame-``to`` coordinates."""
    return ctx["R0"][to].T * ctx["R0"][frm]


def origin_in_base(ctx, k: int):
    """Frame ``k``'s origin in base-frame coordinates."""
    point = sp.zeros(3, 1)
    while k != 0:
        point, k = ctx["R0"][ctx[k]["parent"]] * ctx[k]["P"] + point, ctx[k]["parent"]
    return point


def position(ctx, key: str, index: int, frame: int | None, origin: int | None = None):
    """A kinematics position and what it is: ``key`` "P", frame ``index``'s origin, or
    "Pc", link ``index``'s mass centre, seen from frame ``origin``'s origin (default: the
    previous frame's for P, frame ``index``'s for Pc, the textbooks' ``{}^{i-1}P_i``,
    ``{}^{i}P_{C_i}``), written in ``frame`` (default: that origin's frame).
    Returns (vector, description, frame)."""
    home = ctx[index]["parent"] if key == "P" else index
    if origin is None or origin == home:
        vector = ctx[index]["P" if key == "P" else "c"]
        start = home
    else:  # Craig's {}^{j}P_{C_i}: from frame j's origin, in frame j
        point = origin_in_base(ctx, index) + (ctx["R0"][index] * ctx[index]["c"] if key == "Pc" else sp.zeros(3, 1))
        vector = ctx["R0"][origin].T * (point - origin_in_base(ctx, origin))
        start = home = origin
    frame = home if frame is None else frame
    what = f"frame {index}'s origin" if key == "P" else f"link {index}'s mass centre"
    return rotation_between(ctx, home, frame) * vector, f"{what} from frame {start}'s origin", frame


# ------------------------------------------------------------------ Lagrange


def lagrange_method(robot: Robot) -> tuple[Method, dict]:
    """The Lagrange steps of ``robot``: T, V, L, the partial derivatives (of L, and of T and V
    by q), tau."""
    T_trans, T_rot, V_links, _ = link_energies(robot)
    T = sum(T_trans.values(), sp.Integer(0)) + sum(T_rot.values(), sp.Integer(0))
    V = sum(V_links.values(), sp.Integer(0))
    q, qd, qdd = robot.q, robot.qd, robot.qdd
    ctx = {"T": T, "V": V, "q": q, "qd": qd, "qdd": qdd}
    m = Method("lagrange", robot, [("T", None), ("V", None), ("L", None)])
    m.leaves[("T", None)] = lambda c: c["T"]
    m.leaves[("V", None)] = lambda c: c["V"]
    m.formulas[("L", None)] = [Formula((("T", None), ("V", None)), lambda c, t, v: t - v)]
    for k in range(1, robot.dof + 1):
        j = k - 1
        m.formulas[("dL_dqd", k)] = [Formula((("L", None),), lambda c, L, j=j: _diff(L, c, "qd", j))]
        # the energies' partials by q_k, written separately (∂T/∂q_k, ∂V/∂q_k), give ∂L/∂q_k too
        m.formulas[("dT_dq", k)] = [Formula((("T", None),), lambda c, t, j=j: _diff(t, c, "q", j))]
        m.formulas[("dV_dq", k)] = [Formula((("V", None),), lambda c, v, j=j: _diff(v, c, "q", j))]
        m.formulas[("dL_dq", k)] = [
            Formula((("L", None),), lambda c, L, j=j: _diff(L, c, "q", j)),
            Formula((("dT_dq", k), ("dV_dq", k)), lambda c, t, v: t - v),
        ]
        m.formulas[("ddt_dL_dqd", k)] = [Formula((("dL_dqd", k),), lambda c, p: _ddt(p, c))]
        m.formulas[("tau", k)] = [Formula((("ddt_dL_dqd", k), ("dL_dq", k)), lambda c, a, b: a - b)]
        m.refs += [("dL_dqd", k), ("dT_dq", k), ("dV_dq", k), ("dL_dq", k), ("ddt_dL_dqd", k), ("tau", k)]
    return m, ctx


# Lagrange formulas differentiate, so they run symbolically; at a sample point the
# grader evaluates the symbolic result (see engine.Sampler).
def _diff(expr, c, which, j):
    return sp.diff(expr, c[which][j])


def _ddt(expr, c):
    return time_derivative(expr, c["q"], c["qd"], c["qdd"])
