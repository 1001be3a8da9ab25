"""The worked solution of a variant, from armdyn's own derivation, in the Markdown that
``armdyn grade`` reads; and the slips a test (or a mock class) injects into it.

    steps = solution_steps(robot)                 # every Newton-Euler step, then Lagrange's
    slipped, slip = inject_slip(steps, rng, robot.q)   # one term dropped or its sign flipped
    text = solution_markdown(steps, front)        # the .md file

Newton-Euler: the base's values (``ω_0 = ω̇_0 = 0``, ``v̇_0 = -g``: gravity as an upward
acceleration of the base), then the outward pass (ω, ω̇, v̇, v̇_C, F = m v̇_C, N per link)
and the inward pass (f, n, τ per link), as :func:`armdyn.symbolic.derive` gives them, each
in its own link's frame. Lagrange: T, V, L, then per coordinate ∂L/∂q̇, its time
derivative, ∂L/∂q and τ. The LaTeX of each value is armdyn's report renderer's.
"""

from __future__ import annotations

import functools
import re
from dataclasses import dataclass, replace

import sympy as sp
from sympy.printing.latex import LatexPrinter

from ..model import Robot
from ..symbolic.agreement import trig_reduce

NE = "newton-euler"
LAGRANGE = "lagrange"
_NE_HEAD = {
    "outward": "Outward pass (each vector in its own link's frame)",
    "inward": "Inward pass (force and moment on each link by its parent, in the link's frame)",
}


@dataclass(frozen=True)
class SolutionStep:
    """One equation of the solution.

    part:   "newton-euler" | "lagrange"
    name:   the grader's step name (``v_dot_1``, ``tau_2``, ``T``, ``dL_dqd_1``)
    stage:  a heading the step sits under
    label:  LaTeX of the left-hand side
    value:  SymPy expression or (3, 1) Matrix
    """

    part: str
    name: str
    stage: str
    label: str
    value: object


@dataclass(frozen=True)
class Slip:
    """A slip injected at ``steps[index]``: ``how`` = "sign" (one term's sign flipped) or
    "drop" (one term dropped), in ``component`` (0-2, or None for a scalar)."""

    index: int
    part: str
    name: str
    how: str
    component: int | None
    term: str


def solution_steps(robot: Robot) -> list[SolutionStep]:
    """Every step of both methods for ``robot`` (in the grader's order)."""
    robot.require_one_dof_joints("armdyn's course (a worked solution)")
    from ..symbolic import derive

    ne = derive(robot, NE)
    la = derive(robot, LAGRANGE)
    out = []
    base_head = "The base (gravity as an upward acceleration of the base)"
    gravity = sp.Matrix(robot.gravity)
    out.append(SolutionStep(NE, "omega_0", base_head, r"{}^{0}\omega_{0}", sp.zeros(3, 1)))
    out.append(SolutionStep(NE, "omega_dot_0", base_head, r"{}^{0}\dot\omega_{0}", sp.zeros(3, 1)))
    out.append(SolutionStep(NE, "v_dot_0", base_head, r"{}^{0}\dot v_{0}", -gravity))
    for s in ne.steps:
        if s.name == "tau":
            index = robot.coordinate_index(robot.parent_joint(s.link)) + 1
        else:
            index = robot.link_index(s.link)
        out.append(SolutionStep(NE, f"{s.name}_{index}", _NE_HEAD.get(s.stage, s.stage), s.label, s.value))
    head = "Energies"
    values = {s.name: s.value for s in la.steps if not s.link}
    for key in ("T", "V", "L"):
        out.append(SolutionStep(LAGRANGE, key, head, key, values[key]))
    L = values["L"]
    q, qd, qdd = robot.q, robot.qd, robot.qdd
    for k in range(robot.dof):
        i = k + 1
        head = f"Euler-Lagrange equation of coordinate {i}"
        p = sp.diff(L, qd[k])
        ddt = sum((sp.diff(p, q[j]) * qd[j] + sp.diff(p, qd[j]) * qdd[j] for j in range(robot.dof)), sp.Integer(0))
        tau = next(s.value for s in la.steps if s.name == "tau" and s.link == robot.coordinate_names[k])
        out.append(
            SolutionStep(LAGRANGE, f"dL_dqd_{i}", head, rf"\frac{{\partial L}}{{\partial \dot{{q}}_{{{i}}}}}", p)
        )
        out.append(
            SolutionStep(
                LAGRANGE,
                f"ddt_dL_dqd_{i}",
                head,
                rf"\frac{{d}}{{dt}}\frac{{\partial L}}{{\partial \dot{{q}}_{{{i}}}}}",
                ddt,
            )
        )
        out.append(
            SolutionStep(LAGRANGE, f"dL_dq_{i}", head, rf"\frac{{\partial L}}{{\partial q_{{{i}}}}}", sp.diff(L, q[k]))
        )
        out.append(SolutionStep(LAGRANGE, f"tau_{i}", head, rf"\tau_{{{i}}}", tau))
    return out


def _terms(expr, q) -> list:
    """The terms of ``expr`` as the grader's explanations see them (sin^2 -> 1 - cos^2,
    expanded), so that a slip made on one of them is described as that term."""
    return list(_reduced_terms(sp.sympify(expr), tuple(q)))


@functools.lru_cache(maxsize=8192)
def _reduced_terms(expr, q: tuple) -> tuple:
    # memoised: a mock class injects many slips into the same solution
    return sp.Add.make_args(sp.expand(trig_reduce(expr, q, keep_trig=True)))


def _candidates(step: SolutionStep, q, how: str) -> list[tuple]:
    """``(component, term)`` pairs a slip of kind ``how`` may change in ``step``.

    Not every change is a slip: the grader rightly accepts a Newton-Euler value without
    its gravity terms (gravity as a force) and a vector with its sign flipped (the
    d'Alembert force, the reaction), so terms with ``g`` are left alone in Newton-Euler
    and a sign is flipped only in a component of two terms or more."""
    vals = list(step.value) if isinstance(step.value, sp.MatrixBase) else [step.value]
    out = []
    for c, v in enumerate(vals):
        terms = [t for t in _terms(v, q) if t != 0]
        if how == "sign" and len(terms) < 2:
            continue
        for t in terms:
            if step.part == NE and t.has(sp.Symbol("g")):
                continue
            out.append((c if isinstance(step.value, sp.MatrixBase) else None, t))
    return out


def slippable(steps: list[SolutionStep], q, how: str) -> list[int]:
    """Indices of the steps a slip of kind ``how`` ("sign" | "drop") can be injected into."""
    return [k for k, s in enumerate(steps) if _candidates(s, q, how)]


def inject_slip(steps: list[SolutionStep], rng, q, index: int | None = None, how: str | None = None):
    """A copy of ``steps`` with one slip at ``index`` (drawn from :func:`slippable` when
    None): one term of one component dropped or its sign flipped (``how``, drawn when
    None). ``q``: the robot's coordinates (for the terms' form). Returns ``(steps, Slip)``;
    later steps keep their right values."""
    how = how or ("sign", "drop")[int(rng.integers(2))]
    if index is None:
        choices = slippable(steps, q, how)
        index = choices[int(rng.integers(len(choices)))]
    s = steps[index]
    cands = _candidates(s, q, how)
    if not cands:
        raise ValueError(f"step {s.name}: no term a {how!r} slip can change")
    component, t = cands[int(rng.integers(len(cands)))]
    expr = s.value[component] if component is not None else s.value
    terms = _terms(expr, q)
    new = sp.Add(*[x for x in terms if x != t]) if how == "drop" else sp.Add(*terms) - 2 * t
    if component is not None:
        value = sp.Matrix(s.value)
        value[component] = new
    else:
        value = new
    out = list(steps)
    out[index] = replace(s, value=value)
    return out, Slip(index=index, part=s.part, name=s.name, how=how, component=component, term=sp.sstr(t))


def _teacher_names(robot: Robot) -> dict:
    """Symbol -> LaTeX as a teacher writes it: ``\\theta_1``, ``\\dot\\theta_1``, ``\\ddot d_2``,
    ``l_1``, ``m_2`` (one-character indices without braces)."""
    from ..symbolic.names import latex_symbol_names

    names = {}
    for sym, tex in latex_symbol_names(robot).items():
        tex = re.sub(r"\\(dot|ddot)\{(\\?[A-Za-z]+)\}", r"\\\1\2", tex)  # \dot{\theta} -> \dot\theta
        tex = re.sub(r"_\{(\w)\}", r"_\1", tex)  # _{1} -> _1
        names[sym] = re.sub(r"(\\d?dot)([A-Za-z])", r"\1 \2", tex)  # \dot d_2 stays two tokens
    return names


class TeacherPrinter(LatexPrinter):
    """SymPy's LaTeX with a teacher's notation: ``\\sin\\theta_1`` (no parentheses around
    one symbol), ``\\sin(\\theta_1 + \\theta_2)``, the model's symbols as :func:`_teacher_names`."""

    def __init__(self, names: dict):
        super().__init__({"symbol_names": names, "mul_symbol": None})

    def _print_Function(self, expr, exp=None):
        fn = expr.func.__name__
        if fn in ("sin", "cos", "tan") and len(expr.args) == 1:
            arg = expr.args[0]
            inner = self._print(arg)
            power = f"^{{{exp}}}" if exp is not None else ""
            return f"\\{fn}{power} {inner}" if arg.is_Symbol else f"\\{fn}{power}\\left({inner}\\right)"
        return super()._print_Function(expr, exp)


def teacher_latex(value, names: dict, q=(), qd=(), qdd=()) -> str:
    """LaTeX of a value as a teacher writes it: expanded with ``sin^2 + cos^2 = 1``, its
    terms collected on the joint accelerations, then the rates, then ``g``, and each
    coefficient on the masses; a vector as a ``pmatrix`` column."""
    printer = TeacherPrinter(names)
    order = [*qdd, *qd, sp.Symbol("g")]

    def one(x):
        if sp.count_ops(x) < 400:
            x = sp.expand(trig_reduce(x, q, keep_trig=True)) if len(q) else sp.expand(x)
            masses = sorted((s for s in x.free_symbols if re.fullmatch(r"m\d+", s.name)), key=str)
            x = sp.collect(x, [s for s in order if x.has(s)], func=lambda c: sp.collect(c, masses))
        return printer.doprint(x)

    if isinstance(value, sp.MatrixBase):
        return r"\begin{pmatrix}" + r" \\ ".join(one(v) for v in value) + r"\end{pmatrix}"
    return one(value)


def solution_markdown(robot: Robot, steps: list[SolutionStep], front: dict, title: str, intro: str = "") -> str:
    """The solution file: YAML front matter ``front`` (``robot:``, ``student:``...), a
    title, ``intro`` (Markdown), then one ``$$ label = value $$`` line per step under
    its part's and stage's headings."""
    import yaml

    names = _teacher_names(robot)
    lines = [
        "---",
        yaml.safe_dump(front, sort_keys=True, default_flow_style=False, allow_unicode=True).rstrip(),
        "---",
        f"# {title}",
        "",
    ]
    if intro:
        lines += [intro, ""]
    part = stage = None
    for s in steps:
        if s.part != part:
            part, stage = s.part, None
            lines += ["## Newton-Euler" if part == NE else "## Lagrange check", ""]
        if s.stage != stage:
            stage = s.stage
            lines += [f"**{stage}**", ""]
        value = teacher_latex(s.value, names, robot.q, robot.qd, robot.qdd)
        lines += [f"$${s.label} = {value}$$", ""]
    return "\n".join(lines).rstrip() + "\n"
