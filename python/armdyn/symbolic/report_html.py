"""Derivations as HTML with MathML: ``armdyn derive ... --format html`` and Jupyter.

* :func:`derivation_html`: a self-contained page (inline CSS, MathML, no script, no
  network): the robot's joints and links, for each method its steps grouped by stage
  and link (with ``steps=True``) and the joint torques/forces tau, the terms M, g and C
  when they are cheap (small arms), and the agreement checks.
* :func:`eom_html`, :func:`robot_html`, :func:`agreement_html`: fragments for the
  ``_repr_html_`` of :class:`~armdyn.symbolic.terms.EquationsOfMotion`,
  :class:`~armdyn.model.Robot` and :class:`~armdyn.symbolic.agreement.AgreementReport`,
  registered with :mod:`armdyn.dispatch`.

Expressions are tidied as in the text report (:func:`armdyn.symbolic.tidy.tidy_terms`:
joint accelerations, then velocity products, then gravity, coefficients factored);
big ones (a 6-dof arm with symbolic inertia) are shown as common subexpressions, as
the other formats do. Step labels are the derivation's LaTeX, converted to MathML.
"""

from __future__ import annotations

import sympy as sp

from ..dispatch import register
from ..htmlpage import fragment, page
from ..mathml import MathWriter, escape, latex_to_mathml, math_element, typeset_width
from ..model import Robot
from . import dag
from .agreement import AgreementReport
from .names import latex_symbol_names
from .newton_euler_floating import BASE_ROWS, FLOATING_NOTE
from .newton_euler_spherical import note as spherical_note
from .notes import NOTE_FORMULAS, note_parts
from .terms import EquationsOfMotion
from .tidy import TIDY_NODE_LIMIT, tidy_terms, too_big_to_tidy

#: show M, C and g on the page for arms with at most this many joints (C costs O(n^3)
#: derivatives of M)
TERMS_MAX_DOF = 3
#: break sums wider than this (units of mathml.typeset_width, ~ one letter with its index)
LINE_WIDTH = 46
_STAGE_TITLES = {
    "outward": "Outward pass",
    "inward": "Inward pass",
    "energy": "Energies",
    "equations": "Euler\u2013Lagrange equations",
}
_STAGE_NOTES = {
    "outward": "each vector in its own link's frame",
    "inward": "force and moment exerted on each link by its parent, in the link's frame",
    "energy": "velocities in each link's frame, positions in the base frame",
    "equations": "",
}
_METHODS = {"newton-euler": "Newton\u2013Euler", "lagrange": "Lagrange"}


class _Writer:
    def __init__(self, eom):
        # the robot's symbols as the LaTeX report and the grade report name them (l_{c1})
        names = {**latex_symbol_names(eom.robot), **eom.symbol_names("latex")}
        self.eom, self.w, self.limit = eom, MathWriter(names), TIDY_NODE_LIMIT

    def scalar(self, expr) -> str:
        expr = sp.sympify(expr)
        if not expr.free_symbols or dag.larger_than(expr, self.limit):
            return self.w.expr(expr)
        eom = self.eom
        return self.w.terms(tidy_terms(expr, eom.q, eom.qd, eom.qdd), width=LINE_WIDTH)

    def value(self, value) -> str:
        if isinstance(value, sp.MatrixBase) and value.shape[1] != 1:
            rows = []
            for i in range(value.rows):
                cells = "".join(f"<mtd>{self.scalar(value[i, j])}</mtd>" for j in range(value.cols))
                rows.append(f"<mtr>{cells}</mtr>")
            return (
                '<mrow><mo stretchy="true">(</mo><mtable>'
                + "".join(rows)
                + '</mtable><mo stretchy="true">)</mo></mrow>'
            )
        return self.w.value(value, scalar=self.scalar)


def caption(note: str) -> str:
    """A step note as HTML, its formulas as inline MathML (``inertial force m v̇_C``),
    the rest escaped text (see :data:`armdyn.symbolic.notes.NOTE_FORMULAS`)."""
    out = []
    for text, k in note_parts(note):
        inner = None if k is None else latex_to_mathml(NOTE_FORMULAS[k][2])
        if inner is None:
            out.append(escape(text if k is None else NOTE_FORMULAS[k][1]))
        else:
            out.append(math_element(inner))
    return "".join(out)


def _equation(lhs: str, rhs: str, note: str = "") -> str:
    note = f' <span class="note">{caption(note)}</span>' if note else ""
    return f'<div class="eq">{math_element(f"<mrow>{lhs}<mo>=</mo>{rhs}</mrow>", display=True)}{note}</div>'


def _label(latex: str) -> str:
    inner = latex_to_mathml(latex)
    return inner if inner is not None else f"<mtext>{escape(latex)}</mtext>"


def _tau(k: int) -> str:
    return f"<msub><mi>\u03c4</mi><mn>{k + 1}</mn></msub>"


def _tau_block(eom, wr: _Writer) -> str:
    out = []
    if too_big_to_tidy(eom):
        import symengine as se

        subexprs, reduced = se.cse(se.sympify(list(eom.tau)))
        out.append(f'<p class="meta">{len(subexprs)} common subexpressions, then tau</p>')
        for sym, sub in subexprs:
            out.append(_equation(wr.w.expr(sp.sympify(sym)), wr.w.expr(sp.sympify(sub))))
        values = [wr.w.expr(sp.sympify(e)) for e in reduced]
    else:
        values = [wr.scalar(t) for t in eom.tau]
    base = 6 if eom.robot.floating else 0  # a floating base's wrench rows first
    for k, v in enumerate(values):
        if k < base:
            out.append(_equation(_label(BASE_ROWS[k][0]), v, f"({BASE_ROWS[k][2]})"))
        else:
            out.append(_equation(_tau(k - base), v, f"({eom.robot.coordinate_names[k - base]})"))
    return "".join(out)


def _group_title(eom, stage: str, link: str) -> str:
    robot = eom.robot
    if link in robot.links:
        return f"{link} \u00b7 frame {robot.link_index(link)}"
    if link in robot.coordinate_names:
        return f"joint {link} \u00b7 q{robot.coordinate_names.index(link) + 1}"
    return "whole robot"


def _steps_block(eom, wr: _Writer) -> str:
    out, stage, group = [], None, None
    for s in eom.steps:
        if s.stage != stage:
            if group is not None:
                out.append("</div>")
                group = None
            stage = s.stage
            note = _STAGE_NOTES.get(stage, "")
            out.append(
                f"<h3>{escape(_STAGE_TITLES.get(stage, stage))}"
                + (f' <span class="note">({escape(note)})</span>' if note else "")
                + "</h3>"
            )
        if s.link != group:
            if group is not None:
                out.append("</div>")
            group = s.link
            out.append(f'<div class="group"><h3>{escape(_group_title(eom, stage, s.link))}</h3>')
        out.append(_equation(_label(s.label), wr.value(s.value), s.note))
    if group is not None:
        out.append("</div>")
    return "".join(out)


def _terms_block(eom, wr: _Writer) -> str:
    """M, g and C of a small arm (``M qdd + C qd + g = tau``): as matrices when their
    rows fit a line, else entry by entry (M's upper triangle: it is symmetric; C's
    non-zero entries)."""
    out = ["<h3>Terms: M(q) q\u0308 + C(q, q\u0307) q\u0307 + g(q) = \u03c4</h3>"]
    n = eom.robot.dof

    def fits(mat):
        return all(sum(typeset_width(mat[i, j]) for j in range(mat.cols)) <= LINE_WIDTH for i in range(mat.rows))

    def entry(name, i, j=None):
        idx = f"<mn>{i + 1}</mn>" if j is None else f"<mrow><mn>{i + 1}</mn><mn>{j + 1}</mn></mrow>"
        return f"<msub><mi>{name}</mi>{idx}</msub>"

    for name, mat in (("M", eom.M), ("C", eom.C), ("g", eom.g)):
        if fits(mat):
            out.append(_equation(f"<mi>{name}</mi>", wr.value(mat)))
            continue
        for i in range(n):
            if name == "g":
                out.append(_equation(entry(name, i), wr.scalar(mat[i])))
                continue
            for j in range(i if name == "M" else 0, n):
                if name == "C" and mat[i, j] == 0:
                    continue
                note = "= M" + f"{j + 1}{i + 1}" if name == "M" and j > i else ""
                out.append(_equation(entry(name, i, j), wr.scalar(mat[i, j]), note))
    return "".join(out)


def agreement_body(report) -> str:
    rows = []
    for r in report.results:
        mark = '<span class="ok">OK</span>' if r.passed else '<span class="fail">FAIL</span>'
        err = "" if r.how == "exact" else f"{r.max_error:.2e}"
        rows.append(f"<tr><td>{mark}</td><td>{escape(r.name)}</td><td>{escape(r.how)}</td><td>{err}</td></tr>")
    head = (
        f"<p>Checks for <b>{escape(report.robot)}</b>: "
        + ('<span class="ok">all passed</span>' if report else '<span class="fail">FAILED</span>')
        + "</p>"
    )
    table = (
        '<table class="plain"><tr><th></th><th>check</th><th>how</th><th>max |difference|</th></tr>'
        + "".join(rows)
        + "</table>"
    )
    return head + table


def robot_body(robot) -> str:
    """Tables of the joints (placement, axis) and links (mass, centre of mass)."""
    w = MathWriter(latex_symbol_names(robot))

    def m(x):
        return math_element(w.expr(x))

    def vec(v):
        return math_element(w.value(sp.Matrix(v).T))  # a row reads best in a table

    def rotation(r):
        return "" if r == sp.eye(3) else math_element(w.value(r))

    # frames off the joint axis (the child link's frame placed in the moved joint frame):
    # columns only when some joint has one
    offsets = any(j.has_frame_offset for j in robot.joints)
    joints = []
    for j in robot.joints:
        k = robot.coordinate_index(j)
        q = m(robot.q[k]) if k is not None and j.nv == 1 else ""  # a ball joint's q: its quaternion
        frame = (
            (f"<td>{vec(j.frame_xyz) if j.has_frame_offset else ''}</td><td>{rotation(j.frame_rotation)}</td>")
            if offsets
            else ""
        )
        joints.append(
            f"<tr><td>{escape(j.name)}</td><td>{escape(j.type)}</td><td>{q}</td>"
            f"<td>{escape(j.parent)} \u2192 {escape(j.child)}</td><td>{vec(j.xyz)}</td>"
            f"<td>{rotation(j.rotation)}</td>"
            f"<td>{vec(j.axis) if j.movable and j.nv == 1 else ''}</td>{frame}</tr>"
        )
    frame_heads = ("<th>frame_xyz (joint frame)</th><th>frame_rotation</th>") if offsets else ""
    links = []
    for name, link in robot.links.items():
        if name == robot.base:
            continue
        inertia = "0" if link.inertia.is_zero_matrix else math_element(w.value(link.inertia))
        links.append(
            f"<tr><td>{escape(name)}</td><td>{m(link.mass)}</td><td>{vec(link.com)}</td><td>{inertia}</td></tr>"
        )
    params = ", ".join(sorted(robot.parameters)) or "none"
    return (
        f'<p class="meta"><b>{escape(robot.name)}</b> · {robot.dof} dof · gravity '
        f"{math_element(w.value(robot.gravity.T))} · parameters: {escape(params)}</p>"
        '<table class="plain"><tr><th>joint</th><th>type</th><th>q</th><th>parent \u2192 child</th>'
        "<th>xyz (parent frame)</th><th>rotation</th><th>axis</th>"
        + frame_heads
        + "</tr>"
        + "".join(joints)
        + "</table>"
        '<table class="plain"><tr><th>link</th><th>mass</th><th>centre of mass</th>'
        "<th>inertia about it</th></tr>" + "".join(links) + "</table>"
    )


def derivation_html(eoms, steps: bool = False, agreement=None) -> str:
    """The whole derivation report as a self-contained HTML page."""
    robot = eoms[0].robot
    body = [f"<h1>{escape(robot.name)}: equations of motion</h1>", robot_body(robot)]
    if steps and robot.meta.get("frames"):
        body.append(f'<p class="meta">Frames: {escape(" ".join(str(robot.meta["frames"]).split()))}</p>')
    for eom in eoms:
        wr = _Writer(eom)
        body.append(f"<h2>{escape(_METHODS.get(eom.method, eom.method))}</h2>")
        if steps:
            body.append(_steps_block(eom, wr))
            body.append("<h3>Result</h3>")
        body.append(_tau_block(eom, wr))
    if robot.floating:
        body.append(f'<p class="meta">{escape(FLOATING_NOTE)}</p>')  # no C: see newton_euler_floating.py
    if robot.multi_dof_joints:
        body.append(f'<p class="meta">{escape(spherical_note(robot))}</p>')  # no C: newton_euler_spherical.py
    if not (robot.floating or robot.multi_dof_joints) and robot.dof <= TERMS_MAX_DOF and not too_big_to_tidy(eoms[0]):
        body.append(_terms_block(eoms[0], _Writer(eoms[0])))
    if agreement is not None:
        body.append("<h2>Agreement</h2>" + agreement_body(agreement))
    return page(f"armdyn derive {robot.name}", "".join(body))


@register("html", EquationsOfMotion)
def eom_html(eom: EquationsOfMotion) -> str:
    """``EquationsOfMotion._repr_html_``: tau of one derivation, as a fragment."""
    head = (
        f'<p class="meta"><b>{escape(eom.robot.name)}</b> · '
        f"{escape(_METHODS.get(eom.method, eom.method))} · {eom.robot.dof} dof</p>"
    )
    return fragment(head + _tau_block(eom, _Writer(eom)))


@register("html", Robot)
def robot_html(robot: Robot) -> str:
    """``Robot._repr_html_``: joint and link tables, as a fragment."""
    return fragment(robot_body(robot))


@register("html", AgreementReport)
def agreement_html(report: AgreementReport) -> str:
    """``AgreementReport._repr_html_``: the checks as a table, as a fragment."""
    return fragment(agreement_body(report))
