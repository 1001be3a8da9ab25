"""Which model a derivation is graded against, and the grading: the model the caller or the
front matter names (the text's own statements are then only checked), else the robot the
text itself describes (:mod:`.robot_text`), else, when none can be read, the text's own
earlier values (:mod:`.robot_text.own_values`). ``armdyn.grade`` is :func:`grade`."""

from __future__ import annotations

import os
from collections.abc import Mapping

from ..errors import ModelError
from ..model import Robot
from .grader import Grader
from .reader import Submission, read
from .verdict import GradeReport


def _load_robot(name: str, sub: Submission, trusted: bool = False) -> Robot:
    from ..io import load

    candidate = os.path.join(sub.base_dir, name)
    source = candidate if os.path.isfile(candidate) else name
    try:
        return load(source, strict=False, trusted=trusted)
    except ModelError as err:
        raise err.located(source=sub.path) from None


def grade(
    submission: str | os.PathLike[str] | Submission,
    robot: str | Robot | None = None,
    symbols: dict | None = None,
    trusted: bool = False,
) -> GradeReport:
    """Grade a derivation.

    submission: path of a Markdown (.md) or YAML (.yaml) file, or a :class:`Submission`.
    robot:      the model whose frames the student used (bundled name, model file or
                Robot); default: the submission's front matter ``robot``.
    symbols:    extra mapping of the student's symbols to model names.
    trusted:    the model named by ``robot`` may be a ``.xacro`` file (expanding one runs
                its Python code); never applies to a model the front matter names.
    """
    sub = submission if isinstance(submission, Submission) else read(os.fspath(submission))
    read_model = None
    if isinstance(robot, Robot):
        model = robot
    elif robot or sub.robot:
        # a stated model wins: the text's statements are only checked; only a model given
        # by the caller (never the front matter's) may be a trusted .xacro
        model = _load_robot(robot or sub.robot or "", sub, trusted=bool(trusted and robot))
    else:
        from .robot_text import robot_from_text
        from .robot_text.own_values import grade_without_model

        try:
            read_model = robot_from_text(sub)  # the robot the text itself describes
        except ModelError as err:
            if not sub.equations:
                raise
            return grade_without_model(sub, err.message)  # what the text's own values decide
        model = read_model.robot
    # the grader's steps are those of revolute and prismatic joints (named as the model's)
    model.require_one_dof_joints("armdyn.grade")
    if sub.values is not None:
        try:
            # the reader admits "published" or a mapping parameter -> number
            model = model.bind(sub.values if isinstance(sub.values, Mapping) else None)
        except ModelError as err:
            raise err.located(source=sub.path) from None
    hint = sub.method if sub.method in ("newton-euler", "lagrange") else None
    report = Grader(sub, model, symbols).run(hint)
    if read_model is not None and read_model.alternatives:  # the statements allow other readings
        from .robot_text.support import most_supported

        def with_model(other):
            robot = other.robot
            if sub.values is not None:
                robot = robot.bind(sub.values if isinstance(sub.values, Mapping) else None)
            return Grader(sub, robot, symbols).run(hint)

        read_model, report = most_supported(read_model, report, with_model)
    from .robot_text.support import carry_own_values

    reading = carry_own_values(sub, report)  # a step the method has no formula for, on a wrong earlier one
    if read_model is not None:
        from .robot_text.support import disagreeing, own_values_instead

        if disagreeing(report):  # the reading, not the text, is likely wrong: the text's own values
            own = own_values_instead(sub, report, reading)
            if own is not report:
                return own
        report.model_note = read_model.note()  # the report's first line: what was graded against
        report.notes.insert(0, report.model_note)
    return report
