"""The grade report as plain text (what a student reads in a terminal) and as JSON
(what scripts and course graders read; field names are stable).

``GradeReport.text``, ``to_dict`` and ``to_json`` call these through :mod:`armdyn.dispatch`."""

from __future__ import annotations

import json
import re
import unicodedata

import symengine as se
import sympy as sp

from ..dispatch import register
from ..symbolic.newton_euler import VECTOR_STEP_TEXT
from .explain import display_name, pretty, to_ascii
from .verdict import GradeReport, StepVerdict

_MARK = {
    "correct": ("✓", "ok"),
    "correct-by-convention": ("✓", "ok"),
    "wrong": ("✗", "XX"),
    "follows-from-earlier-error": ("→", "->"),
    "correct-but-unsupported": ("?", "??"),
    "consistent": ("~", "~~"),
    "unrecognised": ("·", "--"),
    "definition": ("=", "=="),
}
_KEY_TEXT = {
    **VECTOR_STEP_TEXT,
    "tau": "τ",
    "dL_dqd": "∂L/∂q̇",
    "dL_dq": "∂L/∂q",
    "ddt_dL_dqd": "d/dt ∂L/∂q̇",
    "dT_dq": "∂T/∂q",
    "dV_dq": "∂V/∂q",
}
#: the message of an equation that names no step (listed by line, not one by one)
NOT_A_STEP = "not a step of Newton-Euler or Lagrange (skipped)"


def step_title(v: StepVerdict, ascii_only: bool = False) -> str:
    """``v̇_1`` (Unicode) or the step's name (ASCII)."""
    if v.name in ("law", "identity") and not v.key:  # a law stated in general symbols, an identity (laws.py)
        return v.name
    if v.key == "law":
        if v.name == "matrix_form":  # M q̈ + C q̇ + g = τ stated
            return "matrix form" if not ascii_only else v.name
        return "Lagrange eq." if not ascii_only else "lagrange_equation"
    if ascii_only or v.key not in _KEY_TEXT:
        return v.name or "?"
    index = v.name.rsplit("_", 1)[-1]
    return f"{_KEY_TEXT[v.key]}_{index}"


def _value(value, ascii_only: bool, shorthand: dict | None = None) -> str:
    if value is None:
        return ""
    if isinstance(value, str):
        return value
    if isinstance(value, sp.MatrixBase):
        if value.shape[1] == 1:
            return "[" + ", ".join(pretty(x, ascii_only, shorthand) for x in value) + "]"
        return (
            "["
            + "; ".join(", ".join(pretty(x, ascii_only, shorthand) for x in value.row(i)) for i in range(value.rows))
            + "]"
        )
    return pretty(value, ascii_only, shorthand)


def _width(s: str) -> int:
    """Columns on a terminal: combining accents (the dot of θ̇) take none."""
    return sum(1 for ch in s if not unicodedata.combining(ch))


def _pad(s: str, width: int) -> str:
    return s + " " * max(0, width - _width(s))


@register("text", GradeReport)
def text(report: GradeReport, ascii_only: bool = False, details: bool = True) -> str:
    """The report: one line per step, values for the wrong ones, then the summary."""
    lines = [f"note: {report.model_note}"] if report.model_note else []  # first: what it was graded against
    lines += [f"armdyn grade {report.submission}: robot '{report.robot}', {report.method}", ""]
    skipped = []
    width = max((_width(step_title(v, ascii_only)) for v in report.steps if v.status != "unrecognised"), default=6)
    group = object()
    for v in report.steps:
        if v.status == "unrecognised" and not v.key and v.message == NOT_A_STEP:
            skipped.append(v.line)
            continue
        if (v.part, v.task) != group:
            group = (v.part, v.task)
            if v.part or v.task:
                lines.append(
                    f"part {v.part}" + (f": {v.task}" if v.task else "")
                    if v.part
                    else f"(task without a number) {v.task}"
                )
        mark = _MARK[v.status][1 if ascii_only else 0]
        what = v.status
        if v.status == "follows-from-earlier-error":
            what = f"follows from the error in {v.caused_by}"
            if v.convention:
                what += f" ({v.convention})"
        elif v.status == "correct-by-convention":
            what = f"correct ({v.convention})"
            extra = v.message.removeprefix(v.convention or "").lstrip("; ")  # e.g. a chain member not checked
            what += f": {extra}" if extra else ""
        elif v.status == "correct" and v.message:
            what = f"correct: {v.message}"
        elif v.status in ("wrong", "correct-but-unsupported", "consistent", "unrecognised", "definition"):
            what = f"{v.status.upper() if v.status == 'wrong' else v.status}: {v.message}"
        lines.append(f"  {mark} line {v.line:>4}  {_pad(step_title(v, ascii_only), width)}  {what}")
        if details and v.status == "wrong":
            mine, other = ("left:    ", "right:   ") if v.key == "proof" else ("yours:   ", "expected:")  # proof: sides
            if v.got is not None:
                lines.append(f"{'':>{16 + width}}{mine} {_value(v.got, ascii_only, report.shorthand)}")
            if v.expected is not None:
                lines.append(f"{'':>{16 + width}}{other} {_value(v.expected, ascii_only, report.shorthand)}")
    if skipped:
        shown = ", ".join(map(str, skipped[:12])) + (", ..." if len(skipped) > 12 else "")
        lines.append(
            f"  {'·' if not ascii_only else '--'} {len(skipped)} equation(s) not recognised as steps, skipped "
            f"(lines {shown})"
        )
    lines.append("")
    counts = {}
    for v in report.steps:
        counts[v.status] = counts.get(v.status, 0) + 1
    lines.append("steps: " + ", ".join(f"{counts[s]} {s}" for s in counts))
    if report.first_wrong:
        first = next(v for v in report.steps if v.name == report.first_wrong and v.status == "wrong")
        lines.append(f"first wrong step: {step_title(first, ascii_only)} (line {first.line}): {first.message}")
    else:
        lines.append("first wrong step: none")
    taus = []
    for k, ok in enumerate(report.tau_correct, start=1):
        last = [v for v in report.steps if v.key == "tau" and v.name == f"tau_{k}"]
        if not last:
            taus.append(f"tau_{k} not given")
        elif all(v.status == "unrecognised" for v in last):  # written, but could not be graded
            taus.append(f"tau_{k} not read (line {last[-1].line})")
        elif ok and last[-1].status == "correct-but-unsupported":
            taus.append(f"tau_{k} right, but not supported by the steps before it")
        elif last[-1].status == "consistent":
            taus.append(f"tau_{k} not checked (agrees with your own values; no model)")
        else:
            taus.append(f"tau_{k} {'right' if ok else 'wrong'}")
    lines.append("final torques: " + "; ".join(taus))
    for note in report.notes:
        if note != report.model_note:
            lines.append(f"note: {note}")
    out = "\n".join(lines)
    return to_ascii(out) if ascii_only else out


def _str(value):
    if value is None:
        return None
    if isinstance(value, se.DenseMatrix):
        return [str(x) for x in value]
    if isinstance(value, se.Basic):
        return str(value)
    if isinstance(value, sp.MatrixBase):
        return (
            [str(x) for x in value]
            if value.shape[1] == 1
            else [[str(x) for x in value.row(i)] for i in range(value.rows)]
        )
    return str(value)


@register("dict", GradeReport)
def to_dict(report: GradeReport) -> dict:
    """The JSON object: robot, method, steps [...], first_wrong, tau_correct."""
    steps = []
    for v in report.steps:
        steps.append(
            {
                "name": v.name or None,
                "link": v.link or None,
                "status": v.status,
                "expected": _str(v.expected),
                "got": _str(v.got),
                "difference": _str(v.difference),
                "convention": v.convention,
                "caused_by": v.caused_by,
                "line": v.line,
                "label": v.label,
                "message": v.message,
                "components": v.components,
                "part": v.part,
                "task": v.task or None,
                "column": v.column or None,
                **({"counterexample": v.counterexample} if v.counterexample else {}),
            }
        )
    return {
        "robot": report.robot,
        "method": report.method,
        "submission": report.submission,
        "steps": steps,
        "first_wrong": report.first_wrong,
        "tau_correct": list(report.tau_correct),
        "notes": list(report.notes),
    }


@register("json", GradeReport)
def to_json(report: GradeReport) -> str:
    return json.dumps(to_dict(report), indent=2, ensure_ascii=False)


def error_json(err, path: str) -> str:
    """A submission that cannot be graded, as JSON: ``{"error", "file", "line", "column"}``
    (line and column null where not known). ``err``: a ModelError whose ``source`` is
    ``file``, ``file:line`` or ``file:line:column``."""
    source = getattr(err, "source", None) or path
    line = column = None
    m = re.fullmatch(r"(.*?):(\d+)(?::(\d+))?", source)
    if m:
        source, line, column = m.group(1), int(m.group(2)), int(m.group(3)) if m.group(3) else None
    message = getattr(err, "message", None) or str(err)
    if getattr(err, "element", None):
        message = f"{err.element}: {message}"
    return json.dumps({"error": message, "file": source, "line": line, "column": column}, ensure_ascii=False)


__all__ = ["text", "to_dict", "to_json", "error_json", "step_title", "display_name"]
