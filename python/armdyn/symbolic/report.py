"""Readable reports of derivations: plain text, LaTeX or Markdown (HTML: report_html.py).

Small expressions are shown tidied the way one writes them by hand: sin^2 + cos^2
reduced, terms collected by joint accelerations, then velocity products, then the
rest (gravity), each coefficient factored. Large ones (a 6-dof arm with symbolic
inertia) are shown as common subexpressions ``x0 = ...`` followed by the results,
which is what one would compile anyway (the rules every format shares: tidy.py).
Tidying is for display only: the derivations themselves never call ``simplify``.

Registers ``EquationsOfMotion._repr_latex_`` with :mod:`armdyn.dispatch`.
"""

from __future__ import annotations

import symengine as se
import sympy as sp

from ..dispatch import register
from . import dag
from .names import SUBSCRIPT_DIGITS, UnicodeTextPrinter, latex_symbol_names, unicode_name
from .newton_euler import VECTOR_STEP_TEXT
from .newton_euler_floating import BASE_ROWS, FLOATING_NOTE
from .newton_euler_spherical import note as spherical_note
from .notes import note_text
from .report_html import derivation_html
from .terms import EquationsOfMotion, Step
from .tidy import TIDY_NODE_LIMIT, tidy_terms, too_big_to_tidy

FORMATS = ("text", "latex", "markdown")

_TEXT_NAMES = {
    **VECTOR_STEP_TEXT,
    "vc": "v_C",
    "pc": "p_C",
    "T_trans": "T_trans",
    "T_rot": "T_rot",
    "V": "V",
}


# ------------------------------------------------------------ text: symbols as the field writes them
def _text_names(eom: EquationsOfMotion) -> dict:
    """Symbol -> Unicode name for the coordinates, their derivatives and parameters
    whose names have the letters+digits form."""
    names = eom.symbol_names("text")
    for q, qd, qdd in zip(eom.robot.q, eom.robot.qd, eom.robot.qdd):
        for sym, dots in ((q, ""), (qd, "_dot"), (qdd, "_ddot")):
            u = unicode_name(q.name, dots)
            if u:
                names[sym] = u
    for sym in list(eom.robot.parameters.values()):
        u = unicode_name(sym.name)
        if u:
            names[sym] = u
    return names


def unicode_supported(stream=None) -> bool:
    """Whether ``stream`` (default stdout) can print the Unicode report."""
    import sys

    encoding = getattr(stream or sys.stdout, "encoding", None) or "ascii"
    try:
        "θ̇₁ω̇τ₁²".encode(encoding)
    except (UnicodeEncodeError, LookupError):
        return False
    return True


def _join(terms, render, text: bool | None = None, times: str | None = None) -> str:
    """Render ``(coefficient, monomial)`` terms coefficient first, signs folded.
    ``text``: plain-text layout (default: ``render is str``); ``times``: what goes between
    coefficient and monomial in text (default ``*`` for SymPy's ``str``, else a space)."""
    if not terms:
        return "0"
    text = render is str if text is None else text
    star = ("*" if render is str else " ") if times is None else times
    out = []
    for coef, mono in terms:
        negative = coef.could_extract_minus_sign()
        if negative:
            coef = -coef
        if mono == 1:
            body = render(coef)
        elif coef == 1:  # a unit coefficient is not written: d2_ddot, not 1*d2_ddot
            body = render(mono)
        elif isinstance(coef, sp.Add):  # a factored sum stays in front, in parentheses
            body = f"({render(coef)}){star}{render(mono)}" if text else f"\\left({render(coef)}\\right) {render(mono)}"
        elif any((f.is_Rational and f.q != 1) or (f.is_Pow and f.exp.is_negative) for f in sp.Mul.make_args(coef)):
            body = render(coef * mono)  # a fraction reads best as SymPy writes it: l1*cos(q1)/2
        else:  # coefficient first, as by hand: l₁ m₂ d̈₂
            body = f"{render(coef)}{star}{render(mono)}" if text else f"{render(coef)} {render(mono)}"
        out.append(("-" if negative else "+", body))
    joined = ("-" if out[0][0] == "-" else "") + out[0][1]
    for sign, body in out[1:]:
        joined += f" {sign} {body}"
    return joined


class Renderer:
    """Renders expressions of one derivation in one format."""

    def __init__(self, eom: EquationsOfMotion, fmt: str = "text", ascii: bool = False):
        if fmt not in FORMATS:
            raise ValueError(f"unknown format {fmt!r}; choose one of {', '.join(FORMATS)}")
        self.eom, self.fmt, self.ascii = eom, fmt, ascii
        # text: θ̇₁, d̈₂, m₂ (Unicode), or SymPy's own names with ascii (theta1_dot)
        self._text = str if ascii else UnicodeTextPrinter(_text_names(eom)).doprint
        self._latex_names = {**latex_symbol_names(eom.robot), **eom.symbol_names("latex")}

    def atom(self, expr) -> str:
        if self.fmt == "text":
            return self._text(expr)
        return sp.latex(expr, symbol_names=self._latex_names)

    def scalar(self, expr) -> str:
        eom = self.eom
        if dag.larger_than(expr, TIDY_NODE_LIMIT):
            return self.atom(expr)
        render = self._text if self.fmt == "text" else self.atom
        times = "*" if self.ascii else " "
        return _join(tidy_terms(expr, eom.q, eom.qd, eom.qdd), render, text=self.fmt == "text", times=times)

    def value(self, value) -> str:
        if isinstance(value, sp.MatrixBase):
            parts = [self.scalar(v) for v in value]
            if self.fmt == "text":
                return "[" + ", ".join(parts) + "]"
            return r"\begin{pmatrix}" + r" \\ ".join(parts) + r"\end{pmatrix}"
        return self.scalar(value)

    def label(self, step: Step) -> str:
        if self.fmt != "text":
            return step.label
        robot = self.eom.robot
        i = str(robot.link_index(step.link)) if step.link in robot.links else ""
        if self.ascii:
            return self._ascii_label(step, i)
        if step.name in _TEXT_NAMES:
            return f"{_TEXT_NAMES[step.name]}{i.translate(SUBSCRIPT_DIGITS)}"
        if step.link in self.eom.robot.coordinate_names:  # Lagrange equation steps are per coordinate
            k = self.eom.robot.coordinate_names.index(step.link)
            q, qd = self.atom(self.eom.q[k]), self.atom(self.eom.qd[k])
            return {"tau": f"τ{str(k + 1).translate(SUBSCRIPT_DIGITS)}", "dL_dqd": f"∂L/∂{qd}", "dL_dq": f"∂L/∂{q}"}[
                step.name
            ]
        if step.name == "tau":
            return "τ" + self._tau_rows(step.link).translate(SUBSCRIPT_DIGITS)
        return step.name

    def _ascii_label(self, step: Step, i: str) -> str:
        """ASCII labels for --ascii: omega_dot1, vc_dot2, tau1, dL/dtheta1_dot."""
        robot = self.eom.robot
        if step.link in robot.coordinate_names and step.name in ("tau", "dL_dqd", "dL_dq"):
            k = robot.coordinate_names.index(step.link)
            return {"tau": f"tau{k + 1}", "dL_dqd": f"dL/d{self.eom.qd[k]}", "dL_dq": f"dL/d{self.eom.q[k]}"}[step.name]
        if step.name == "tau":
            return f"tau{self._tau_rows(step.link)}"
        return f"{step.name}{i}"

    def _joint_of(self, link: str):
        return self.eom.robot.parent_joint(link)

    def _tau_rows(self, link: str) -> str:
        """The rows of tau of the joint moving ``link``, from 1: ``2``, or ``1..3`` for a
        joint of three (a spherical joint's moment)."""
        joint = self._joint_of(link)
        k = self.eom.robot.coordinate_index(joint)
        assert k is not None  # a tau step's joint has a coordinate
        return f"{k + 1}..{k + joint.nv}" if joint.nv > 1 else str(k + 1)

    def equation(self, lhs: str, rhs: str) -> str:
        if self.fmt == "text":
            return f"  {lhs} = {rhs}"
        if self.fmt == "latex":
            return f"{lhs} &= {rhs} \\\\"
        return f"$${lhs} = {rhs}$$"


def tau_lines(eom: EquationsOfMotion, fmt: str = "text", ascii: bool = False) -> list[str]:
    """The joint torques/forces as equations, one per joint (CSE form for big ones).
    ascii: plain ASCII text (tau1, theta1_dot) instead of Unicode (τ₁, θ̇₁)."""
    r = Renderer(eom, fmt, ascii)
    lines = []
    if fmt != "text":
        tau_name = lambda k: rf"\tau_{{{k + 1}}}"  # noqa: E731
    elif ascii:
        tau_name = lambda k: f"tau{k + 1}"  # noqa: E731
    else:
        tau_name = lambda k: "τ" + str(k + 1).translate(SUBSCRIPT_DIGITS)  # noqa: E731
    if too_big_to_tidy(eom):
        # SymEngine's CSE: SymPy's walks the expanded tree and takes minutes on a 6-dof arm
        subexprs, reduced = se.cse(se.sympify(list(eom.tau)))
        subexprs = [(sp.sympify(a), sp.sympify(b)) for a, b in subexprs]
        reduced = [sp.sympify(e) for e in reduced]
        lines.append(
            f"  ({len(subexprs)} common subexpressions x0..x{len(subexprs) - 1}, then tau)"
            if fmt == "text"
            else "% common subexpressions, then tau"
        )
        for sym, sub in subexprs:
            lines.append(r.equation(r.atom(sym), r.atom(sub)))
        exprs = reduced
        render = r.atom
    else:
        exprs = list(eom.tau)
        render = r.scalar
    base = 6 if eom.robot.floating else 0  # a floating base's wrench rows first
    for k, t in enumerate(exprs):
        if k < base:
            tex, text, what = BASE_ROWS[k]
            name, coord = (text if fmt == "text" else tex), what
        else:
            name = tau_name(k - base)
            coord = r.atom(eom.robot.q[k - base]) if fmt == "text" else eom.robot.coordinate_names[k - base]
        eq = r.equation(name, render(t))
        lines.append(f"{eq}    ({coord})" if fmt == "text" else eq)
    return lines


def steps_lines(eom: EquationsOfMotion, fmt: str = "text", ascii: bool = False) -> list[str]:
    """Every intermediate step, grouped by stage, each in the frame its label names
    (ascii: see :func:`tau_lines`)."""
    r = Renderer(eom, fmt, ascii)
    lines, stage = [], None
    titles = {
        "outward": "outward pass (each vector in its own link's frame)",
        "inward": "inward pass (force/moment exerted on each link by its parent, in the link's frame)",
        "energy": "energies (velocities in each link's frame, positions in the base frame)",
        "equations": "Euler-Lagrange equations",
    }
    for s in eom.steps:
        if s.stage != stage:
            stage = s.stage
            head = titles.get(stage, stage)
            lines.append(
                f" {head}:" if fmt == "text" else (rf"\intertext{{{head}}}" if fmt == "latex" else f"**{head}**")
            )
        eq = r.equation(r.label(s), r.value(s.value))
        note = s.note if ascii else note_text(s.note)
        where = f"{s.link}: {note}" if s.link else note
        lines.append(f"{eq}    # {where}" if fmt == "text" else eq)
    return lines


@register("latex", EquationsOfMotion)
def eom_latex(eom: EquationsOfMotion) -> str:
    """``EquationsOfMotion._repr_latex_``: tau as an ``aligned`` block."""
    lines = [ln for ln in tau_lines(eom, "latex") if not ln.lstrip().startswith("%")]
    return "$$\\begin{aligned}\n" + "\n".join(lines) + "\n\\end{aligned}$$"


def derivation_report(
    eoms: list[EquationsOfMotion], fmt: str = "text", steps: bool = False, agreement=None, ascii: bool = False
) -> str:
    """A whole report: the robot, for each method its (steps and) tau, then agreement.
    ascii: text format in plain ASCII (theta1_dot, tau1) instead of Unicode (θ̇₁, τ₁).

    ``fmt="html"`` gives a self-contained page with MathML (see report_html.py)."""
    if fmt == "html":
        return derivation_html(eoms, steps=steps, agreement=agreement)
    robot = eoms[0].robot
    joints = ", ".join(f"{j.name} {j.type}" for j in robot.movable_joints)
    params = ", ".join(sorted(robot.parameters)) or "none"
    head = f"{robot.name}: {robot.dof} dof ({joints}); parameters: {params}"
    if robot.floating:
        head += f"; {FLOATING_NOTE}"
    if robot.multi_dof_joints:
        head += f"; {spherical_note(robot)}"
    out = [head if fmt == "text" else (f"% {head}" if fmt == "latex" else f"# {robot.name}\n\n{head}")]
    for eom in eoms:
        title = {"newton-euler": "Newton-Euler", "lagrange": "Lagrange"}[eom.method]
        out.append("")
        out.append(f"{title}:" if fmt == "text" else (f"% {title}" if fmt == "latex" else f"## {title}"))
        if steps and robot.meta.get("frames"):
            note = " ".join(str(robot.meta["frames"]).split())
            out.append(
                f" frames: {note}"
                if fmt == "text"
                else (f"% frames: {note}" if fmt == "latex" else f"*Frames:* {note}")
            )
        if fmt == "latex":
            out.append(r"\begin{align*}")
        if steps:
            out += steps_lines(eom, fmt, ascii)
            out.append({"text": " result:", "latex": r"\intertext{result}", "markdown": "**result**"}[fmt])
        out += tau_lines(eom, fmt, ascii)
        if fmt == "latex":
            out.append(r"\end{align*}")
    if agreement is not None:
        out.append("")
        out.append(agreement.text() if fmt != "latex" else "\n".join("% " + s for s in agreement.text().split("\n")))
    return "\n".join(out)
