"""Which reading of a text's robot its own steps support: when the text states more than one
gravity (a case shown in passing, a correction), each reading is graded and the one with the
fewest steps found wrong is kept, named in the report's first note."""

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
            f"the gravity read is the one the text's steps agree with: {_flagged(best_report)} steps "
            f"found wrong with it, {counts[0]} with the gravity most statements give"
        )
    return best, best_report
