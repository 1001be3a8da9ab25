"""Which reading of a text's robot its own steps support: when the text states more than one
gravity (a case shown in passing, a correction), or an x_k and a y_k that are not one point,
each reading is graded and the one with the fewest steps found wrong is kept, named in the
report's first note."""

from __future__ import annotations

from collections.abc import Callable

from ...errors import ModelError
from ..verdict import GradeReport
from .reader import TextModel

_FLAGGED = ("wrong", "follows-from-earlier-error")


def _flagged(report: GradeReport) -> int:
    return sum(v.status in _FLAGGED for v in report.steps)


def most_supported(
    model: TextModel, report: GradeReport, grade_with: Callable[[TextModel], GradeReport]
) -> tuple[TextModel, GradeReport]:
    """``(model, report)`` of the reading (``model`` or one of its alternatives) whose grading
    finds the fewest steps wrong; a tie keeps the reading most statements give (``model``)."""
    best, best_report, counts = model, report, [_flagged(report)]
    for other in model.alternatives:
        try:
            other_report = grade_with(other)
        except ModelError:
            continue
        counts.append(_flagged(other_report))
        if counts[-1] < _flagged(best_report):
            best, best_report = other, other_report
    if best is not model:
        best.conflicts.append(
            f"the reading kept is the one the text's steps agree with: {_flagged(best_report)} steps "
            f"found wrong with it, {counts[0]} with the reading most statements give"
        )
    return best, best_report


def _unknown_name(v) -> bool:
    return v.status == "unrecognised" and bool(v.key) and "unknown symbol" in v.message


def _read(report: GradeReport) -> int:
    """Steps about this arm read: the laws stated and definitions, the same whatever the arm, left out."""
    return sum(
        v.status not in ("unrecognised", "definition") and v.name not in ("law", "identity") for v in report.steps
    )


def _wrong(report: GradeReport) -> int:
    return sum(v.status == "wrong" for v in report.steps)


def disagreeing(report: GradeReport) -> bool:
    """Most of the steps are found wrong against the model read, each on its own (a slip
    carried through is one ``wrong`` and then ``follows``), or use names it does not have (at
    least 3): the reading is more likely wrong than the text."""
    steps = [  # the laws stated (L = T - V) and definitions say nothing of this arm: left out
        v
        for v in report.steps
        if v.key
        and v.name not in ("law", "identity")
        and v.status != "definition"
        and (v.status != "unrecognised" or _unknown_name(v))
    ]
    trouble = sum(v.status == "wrong" or _unknown_name(v) for v in steps)
    return trouble >= 3 and 2 * trouble > len(steps)


def carry_own_values(sub, report: GradeReport):
    """A step found wrong that is exactly what the text's own earlier values give, one of them
    found wrong (``V = V_1 + V_2 + V_3`` after a wrong ``V_3``, ``G_k = \\partial V/\\partial q_k``
    after it): ``follows-from-earlier-error``, as the method's own formulas mark the steps they
    compute. The text's values are read as :mod:`.own_values` reads them; only with two steps
    wrong or more (one alone inherits nothing). Returns that reading (an :class:`OwnValues`
    already run, for :func:`own_values_instead`), or None when there was none to make."""
    if sum(v.status == "wrong" for v in report.steps) < 2:
        return None
    from .own_values import OwnValues

    own = OwnValues(sub, "")
    own.run()
    by_line: dict[int, list] = {}
    for v in report.steps:
        if v.status == "wrong" and v.line in own.fits:
            lines, how = own.fits[v.line]
            earlier = [u for ln in lines for u in by_line.get(ln, []) if u.status in _FLAGGED]
            if earlier:
                cause = earlier[0].caused_by or earlier[0].name
                v.status, v.caused_by = "follows-from-earlier-error", cause
                v.message = f"follows from the error in {cause}: {how}"
        by_line.setdefault(v.line, []).append(v)
    report.first_wrong = next((v.name for v in report.steps if v.status == "wrong"), None)
    return own


def own_values_instead(sub, report: GradeReport, reading=None) -> GradeReport:
    """The text graded on its own values when the model read disagrees with most of its steps,
    kept when it finds fewer steps wrong (or as many, reading more); else ``report``.
    ``reading``: the :class:`OwnValues` :func:`carry_own_values` already ran, if any."""
    from .own_values import OwnValues

    wrong = _wrong(report)
    unknown = sum(_unknown_name(v) for v in report.steps)
    why = f"{wrong} found wrong" + (f", {unknown} using names it does not have" if unknown else "")
    reading = reading if reading is not None else OwnValues(sub, "")
    reading.why = f"the model read from the text disagrees with most of its steps ({why})"
    own = reading.run()
    if _wrong(own) < wrong or (_wrong(own) == wrong and _read(own) > _read(report)):
        return own
    return report
