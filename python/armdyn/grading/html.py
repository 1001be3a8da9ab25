"""The grade report as a page people read: self-contained HTML with MathML.

:func:`report_html` turns a :class:`~armdyn.grading.verdict.GradeReport` into one HTML5
document (inline CSS, math as MathML, no script, no network), laid out as:

* a summary: the first wrong step (a link to it), each final torque right or not,
  the number of steps of each status, the grader's notes;
* one card per step, in the student's order: the student's left-hand side (their
  LaTeX), the status as a coloured badge with the convention / the step an error is
  carried from / the message, the student's value beside the expected one with the
  wrong components of a vector highlighted (``StepVerdict.components``, 0-based), and
  the difference ``got - expected``; unrecognised equations greyed, with their source
  text (escaped).

Values are printed in the field's notation, the derivation report's (``GradeReport.symbol_latex``), and tidied
for reading (terms collected by joint accelerations, then velocity products, then the
rest, as :func:`armdyn.symbolic.tidy.tidy_terms` does), so the two sides list the
same kinds of terms in the same order. Tidying is for display only.

:func:`repr_html` is the same content as a fragment for Jupyter
(``GradeReport._repr_html_``).
"""

from __future__ import annotations

import sympy as sp

from ..dispatch import register
from ..htmlpage import fragment, page
from ..mathml import MathWriter, escape, latex_to_mathml, math_element, text_with_math
from .explain import affordable
from .verdict import STATUSES, GradeReport, StepVerdict

__all__ = ["report_html", "write_report_html", "repr_html", "STATUS_TEXT"]

STATUS_TEXT = {
    "correct": "correct",
    "correct-by-convention": "correct by convention",
    "wrong": "wrong",
    "follows-from-earlier-error": "follows from an earlier error",
    "correct-but-unsupported": "correct but unsupported",
    "consistent": "consistent, not checked",
    "unrecognised": "unrecognised",
    "definition": "definition",
}
_AXES = "xyz"
#: a report whose values have more nodes than this in all is printed as SymPy orders
#: it, not tidied (tidying costs ~0.3 s per component of a 6-dof arm: fine for a hand
#: derivation, minutes for one generated from a 6-dof model)
TIDY_BUDGET = 8000
#: and no single expression larger than this (nodes) is tidied
_TIDY_NODE_LIMIT = 400
#: expressions larger than this (nodes) are not printed at all (SymPy's printer takes
#: ~1 ms a node): the page says how large they are instead
PRINT_NODE_LIMIT = 1000
#: break sums wider than this (units of mathml.typeset_width): half a 1000 px page
LINE_WIDTH = 28


def _coordinates(values) -> tuple[list, list, list]:
    """Joint coordinates, velocities, accelerations among the symbols of ``values``,
    by the model's naming (``<joint>``, ``<joint>_dot``, ``<joint>_ddot``)."""
    syms = {}
    for v in values:
        if v is not None:
            for s in sp.sympify(v).free_symbols:
                syms[s.name] = s
    joints = sorted(
        {n[: -len("_ddot")] for n in syms if n.endswith("_ddot")}
        | {n[: -len("_dot")] for n in syms if n.endswith("_dot") and not n.endswith("_ddot")}
    )

    def sym(name):
        return syms.get(name, sp.Symbol(name))

    return [sym(j) for j in joints], [sym(j + "_dot") for j in joints], [sym(j + "_ddot") for j in joints]


def _nodes(expr, cap: int) -> int:
    """Nodes of the expanded tree of ``expr``, counting stops at ``cap``."""
    n = 0
    for n, _ in enumerate(sp.preorder_traversal(sp.sympify(expr)), 1):
        if n >= cap:
            break
    return n


class _Writer:
    """MathML for one report: the student's notation, tidied scalars."""

    def __init__(self, report: GradeReport):
        self.w = MathWriter(report.symbol_latex)
        # no model (the text graded on its own values): every expected value is the text's own
        self.own_only = report.model_note.startswith("no model")
        values = []
        for s in report.steps:
            for v in (s.expected, s.got, s.difference):
                if isinstance(v, sp.MatrixBase):
                    values += list(v)
                elif v is not None:
                    values.append(v)
        self.q, self.qd, self.qdd = _coordinates(values)
        self.tidy = sum(_nodes(v, PRINT_NODE_LIMIT + 1) for v in values) <= TIDY_BUDGET

    def scalar(self, expr) -> str:
        from ..symbolic import dag
        from ..symbolic.tidy import tidy_terms

        expr = sp.sympify(expr)
        if dag.larger_than(expr, PRINT_NODE_LIMIT):
            return f'<mtext class="long">[more than {PRINT_NODE_LIMIT} nodes: too long to print]</mtext>'
        if self.tidy and expr.free_symbols and not dag.larger_than(expr, _TIDY_NODE_LIMIT) and affordable(expr):
            try:
                return self.w.terms(tidy_terms(expr, self.q, self.qd, self.qdd), width=LINE_WIDTH)
            except Exception:  # noqa: BLE001 - display only: fall back to SymPy's order
                pass
        return self.w.expr(expr)

    def value(self, value, highlight=()) -> str:
        return self.w.value(value, highlight, scalar=self.scalar)

    def difference(self, value, components) -> str:
        """got - expected; in a vector the right components are a grey 0."""
        if not isinstance(value, sp.MatrixBase):
            return self.scalar(value)
        zeros = [i for i, v in enumerate(value) if sp.sympify(v) == 0]  # grey, so the eye skips them
        return self.w.column([self.scalar(v) for v in value], components, muted=zeros)


def _label(step: StepVerdict) -> str:
    """The student's left-hand side as MathML content, or the step's name as text."""
    inner = latex_to_mathml(step.label) if step.label else None
    return inner if inner is not None else f"<mtext>{escape(step.label or step.name)}</mtext>"


def _badge(status: str, count: int | None = None) -> str:
    n = f'<span class="n">{count}</span>' if count is not None else ""
    return f'<span class="badge s-{escape(status)}">{n}{escape(STATUS_TEXT.get(status, status))}</span>'


def _tau_label(i: int) -> str:
    return f"<msub><mi>\u03c4</mi><mn>{i + 1}</mn></msub>"


def _side(caption: str, label: str, value: str, cls: str = "") -> str:
    eq = math_element(f"<mrow>{label}<mo>=</mo>{value}</mrow>", display=True)
    return f'<div class="side {cls}"><span class="cap">{escape(caption)}</span>{eq}</div>'


def _components_text(components: list[int], vector: bool) -> str:
    if not vector or not components:
        return ""
    names = [(_AXES[i] if i < 3 else str(i + 1)) for i in components]
    return ", ".join(names) + (" component" if len(names) == 1 else " components")


def _wrong_rows(step: StepVerdict) -> list[int]:
    """Rows to highlight: the wrong components; for an inherited error (whose
    components, compared with the student's own earlier values, are all right) the
    rows where the value differs from the expected one."""
    if step.status not in ("wrong", "follows-from-earlier-error"):
        return []
    if step.components or not isinstance(step.difference, sp.MatrixBase):
        return list(step.components)
    return [i for i, d in enumerate(step.difference) if sp.sympify(d) != 0]


def _against_expected(step: StepVerdict) -> bool:
    """True when ``difference`` is got - expected (as the verdict documents); False when
    the grader compared with what the student's own earlier steps give instead (a wrong
    step after an earlier slip): the caption then says so."""
    from ..symbolic import dag
    from ..symbolic.agreement import trig_reduce

    if step.got is None or step.expected is None or step.difference is None:
        return True
    try:
        gap = (
            sp.Matrix(step.got) - sp.Matrix(step.expected) - sp.Matrix(step.difference)
            if isinstance(step.got, sp.MatrixBase)
            else sp.Matrix([step.got - step.expected - step.difference])
        )
        if any(dag.larger_than(e, _TIDY_NODE_LIMIT) for e in gap):
            return "own earlier steps" not in step.message
        q = sorted({x for e in gap for x in e.free_symbols}, key=lambda x: x.name)
        return all(trig_reduce(e, q) == 0 for e in gap)
    except Exception:  # noqa: BLE001 - display only
        return "own earlier steps" not in step.message


#: the two references a step is compared with, as the report names them
EXERCISE_REFERENCE = "expected (from the exercise's model)"
OWN_REFERENCE = "expected from your own earlier steps"


def reference(step: StepVerdict) -> tuple[object, str]:
    """(value, name) of what ``step.difference`` was taken against: the exercise's value
    (``step.expected``), or, after an earlier slip, what the student's own earlier steps
    give (``got - difference``: the grader compared with that), so the expected value
    shown and the difference always name one reference."""
    if step.got is None or step.difference is None or _against_expected(step):
        return step.expected, EXERCISE_REFERENCE
    if isinstance(step.got, sp.MatrixBase):
        own = (sp.Matrix(step.got) - sp.Matrix(step.difference)).applyfunc(sp.expand)
    else:
        own = sp.expand(sp.sympify(step.got) - sp.sympify(step.difference))
    return own, OWN_REFERENCE


def _step_card(i: int, step: StepVerdict, w: _Writer, anchors: dict, first: int | None) -> str:
    cls = f"step st-{escape(step.status)}" + (" first" if i == first else "")
    where = [f"line {step.line}"] if step.line else []
    if step.frame:
        where.append(f"in frame {escape(step.frame)}")
    if step.part or step.task:  # the assignment's part (or the unnumbered task's title)
        where.append(f"part {escape(step.part)}" if step.part else text_with_math(step.task))
    head = (
        f'<div class="head"><span class="label">{math_element(_label(step))}</span>'
        f'{_badge(step.status)}<span class="where">{" · ".join(where)}</span></div>'
    )
    parts = [head]

    message = text_with_math(step.message)
    said = [message] if message else []
    if step.convention and step.convention not in step.message:
        said.append(f'<span class="why">convention:</span> {text_with_math(step.convention)}')
    if step.caused_by:
        target = anchors.get(step.caused_by)
        name = escape(step.caused_by)
        link = f'<a href="#step-{target}">{name}</a>' if target is not None else name
        if message and name in message:  # the message names it: make that the link
            said[0] = message.replace(name, link, 1)
        else:
            said.append(f'<span class="why">carried from</span> {link}')
    hl = _wrong_rows(step)
    vector = isinstance(step.expected, sp.MatrixBase) or isinstance(step.got, sp.MatrixBase)
    which = _components_text(hl, vector)
    if which:
        said.append(f'<span class="why">wrong:</span> {escape(which)}')
    if said:
        parts.append('<p class="message">' + " · ".join(said) + "</p>")

    label = _label(step)
    sides = []
    proof = step.key == "proof"  # a wrong proof link: its two sides' values on the counterexample
    if step.got is not None:
        caption = "yours = expected" if step.status == "correct" else "yours"
        sides.append(_side("left side, on the counterexample" if proof else caption, label, w.value(step.got, hl)))
    shown_diff = step.difference is not None and step.status in ("wrong", "follows-from-earlier-error")
    value, than = reference(step) if shown_diff and not proof else (step.expected, EXERCISE_REFERENCE)
    if w.own_only:
        value, than = step.expected, OWN_REFERENCE + " (no model)"
    if step.expected is not None and (step.status != "correct" or step.got is None):
        if proof:
            sides.append(_side("right side, on the counterexample", label, w.value(step.expected, hl)))
        else:
            sides.append(_side(than, label, w.value(value, hl)))
            if than == OWN_REFERENCE and not w.own_only:  # the exercise's value too, named as such
                sides.append(_side(EXERCISE_REFERENCE, label, w.value(step.expected, hl), "textbook"))
    if shown_diff:
        than = "the right side" if proof else than.split(" (")[0]
        sides.append(
            _side(f"difference: yours \u2212 {than}", "<mi>\u0394</mi>", w.difference(step.difference, hl), "diff")
        )
    if sides:
        parts.append('<div class="compare">' + "".join(sides) + "</div>")
    if step.source:
        parts.append(f"<details><summary>as written</summary><pre>{escape(step.source)}</pre></details>")
    return f'<li class="{cls}" id="step-{i}">{"".join(parts)}</li>'


def _unrecognised_card(run: list[tuple[int, StepVerdict]]) -> str:
    """Consecutive unrecognised equations in one greyed card: each one's line, left-hand
    side and source text (escaped), and why it was skipped."""
    lines = [s.line for _, s in run if s.line]
    span = ""
    if lines:
        span = f"line {lines[0]}" if len(lines) == 1 or lines[0] == lines[-1] else f"lines {lines[0]}\u2013{lines[-1]}"
    n = len(run)
    title = "1 equation not recognised as a step" if n == 1 else f"{n} equations not recognised as steps"
    head = (
        f'<div class="head">{_badge("unrecognised")}<span class="title">{title}: skipped</span>'
        f'<span class="where">{span}</span></div>'
    )
    reasons = {s.message for _, s in run if s.message}
    common = reasons.pop() if len(reasons) == 1 and all(s.message for _, s in run) else None
    rows = []
    for i, s in run:
        why = "" if common or not s.message else f'<div class="why">{text_with_math(s.message)}</div>'
        rows.append(
            f'<div class="skip" id="step-{i}"><span class="ln">{s.line or ""}</span>'
            f"<div>{_as_written(s.source or s.label)}{why}</div></div>"
        )
    note = f'<p class="message"><span class="why">{text_with_math(common)}</span></p>' if common else ""
    return f'<li class="step st-unrecognised">{head}{note}{"".join(rows)}</li>'


def _as_written(source: str) -> str:
    """An equation the grader skipped, as math when its LaTeX converts (through the
    sanitizer: :func:`armdyn.mathml.latex_to_mathml`), with the source under "as
    written"; else the source as escaped text."""
    inner = latex_to_mathml(source.strip().strip("$").strip()) if _looks_like_latex(source) else None
    if inner is None:
        return f"<pre>{escape(source)}</pre>"
    return (
        f'<div class="written">{math_element(inner, display=True)}</div>'
        f"<details><summary>as written</summary><pre>{escape(source)}</pre></details>"
    )


def _looks_like_latex(source: str) -> bool:
    """TeX markup (a command, a script, a group): plain text like ``tau1 = m*x`` would
    come out of a LaTeX conversion as a product of letters."""
    return any(c in source for c in "\\_^{")


def _tau_step(report: GradeReport, i: int) -> StepVerdict | None:
    for s in report.steps:
        if s.key == "tau" and s.name in (f"tau_{i + 1}", f"tau{i + 1}"):
            return s
    return None


def _summary(report: GradeReport, anchors: dict, labels: dict) -> str:
    graded = [s for s in report.steps if s.status != "unrecognised"]
    if report.first_wrong is not None:
        k = anchors.get(report.first_wrong)
        step = report.steps[k] if k is not None else None
        shown = math_element(labels[k]) if k is not None else escape(report.first_wrong)
        line = f" (line {step.line})" if step is not None and step.line else ""
        name = f"go to the step {report.first_wrong}" + line  # its math alone names no link for a screen reader
        link = f'<a href="#step-{k}" aria-label="{escape(name)}">{shown}</a>' if k is not None else shown
        verdict = (
            f'<div class="verdict fail">First wrong step: {link}{line}'
            f'<span class="sub">{text_with_math(step.message) if step is not None and step.message else ""}</span></div>'
        )
    elif not graded:
        verdict = (
            '<div class="verdict fail">No step was recognised<span class="sub">see the equations below</span></div>'
        )
    elif report.passed:
        verdict = '<div class="verdict pass">Every step is right<span class="sub">(correct, or correct by a named convention)</span></div>'
    elif any(s.status == "correct-but-unsupported" for s in graded):
        n = sum(s.status == "correct-but-unsupported" for s in graded)
        verdict = (
            '<div class="verdict fail">No step is wrong, but not every one follows from the ones before'
            f'<span class="sub">{n} correct but unsupported</span></div>'
        )
    elif any(s.status == "consistent" for s in graded):
        n = sum(s.status == "consistent" for s in graded)
        verdict = (
            '<div class="verdict fail">No step is wrong, but not every one could be checked'
            f'<span class="sub">{n} consistent with your own values, which no model could check</span></div>'
        )
    else:  # every step read is right, but some equations were not read: not checked, not a pass
        n = len(report.steps) - len(graded)
        verdict = (
            '<div class="verdict fail">Every step read is right, but not every equation was read'
            f'<span class="sub">{n} not recognised or not readable: see below</span></div>'
        )

    taus = []
    for i, ok in enumerate(report.tau_correct):
        step = _tau_step(report, i)
        if ok:
            word, cls = "right", "right"
            if step is not None and step.status == "correct-but-unsupported":
                word, cls = "right, but not from your steps", "right unsupported"
        elif step is not None and step.status == "consistent":
            word, cls = "not checked: no model", "unsupported"
        elif step is not None and step.status == "unrecognised":
            word, cls = "not read", "unsupported"
        else:
            word, cls = ("not given" if step is None else "not right"), "notright"
        taus.append(
            f'<span class="tau {cls}">{math_element(_tau_label(i))}<span class="word">{escape(word)}</span></span>'
        )

    counts = {s: 0 for s in STATUSES}
    for s in report.steps:
        counts[s.status] = counts.get(s.status, 0) + 1
    chips = "".join(_badge(s, n) for s, n in counts.items() if n)
    notes = "".join(f"<li>{escape(n)}</li>" for n in report.notes if n != report.model_note)
    return (
        '<section class="summary">'
        f'{verdict}<div class="taus">{"".join(taus)}</div>'
        f'<div class="counts">{chips}</div>' + (f'<ul class="notes">{notes}</ul>' if notes else "") + "</section>"
    )


def report_body(report: GradeReport) -> str:
    """The report's content without a page around it: :func:`report_html` wraps it in a
    page, :func:`repr_html` in a fragment (the web app builds it once and wraps it twice)."""
    w = _Writer(report)
    anchors: dict[str, int] = {}
    for i, s in enumerate(report.steps):
        anchors.setdefault(s.name, i)
    labels = {i: _label(s) for i, s in enumerate(report.steps)}
    first = anchors.get(report.first_wrong) if report.first_wrong is not None else None
    names = {"newton-euler": "Newton\u2013Euler", "lagrange": "Lagrange"}
    method = " and ".join(names.get(m, m) for m in report.method.split("+"))
    head = (
        (f'<p class="meta model-note">{escape(report.model_note)}</p>' if report.model_note else "")
        + "<h1>Grade report</h1>"
        f'<p class="meta"><b>{escape(report.submission)}</b> · robot <b>{escape(report.robot)}</b> · '
        f"method <b>{escape(method)}</b> · {len(report.steps)} equations</p>"
    )
    cards, run = [], []
    for i, s in enumerate(report.steps):
        if s.status == "unrecognised":
            run.append((i, s))
            continue
        if run:
            cards.append(_unrecognised_card(run))
            run = []
        cards.append(_step_card(i, s, w, anchors, first))
    if run:
        cards.append(_unrecognised_card(run))
    cards = "".join(cards)
    return (
        head
        + _summary(report, anchors, labels)
        + "<h2>Steps, in your order</h2>"
        + '<p class="legend">Highlighted rows are the wrong components; \u0394 is yours minus the value named above it.</p>'
        + f'<ol class="steps">{cards}</ol>'
    )


def report_html(report: GradeReport) -> str:
    """The whole report as one self-contained HTML5 page (a string)."""
    return page(f"armdyn grade: {report.submission}", report_body(report))


def write_report_html(report: GradeReport, path) -> None:
    """Write :func:`report_html` to ``path`` (UTF-8) all at once: the page is built
    first and moved into place, so a failure leaves no half-written file."""
    from .._io_atomic import atomic_write_text

    atomic_write_text(path, report_html(report))


@register("html", GradeReport)
def repr_html(report: GradeReport) -> str:
    """The report as an HTML fragment, for ``GradeReport._repr_html_`` in Jupyter."""
    return fragment(report_body(report))
