"""The model a class's or the web app's submission is graded against when its text names
none: the robot the text describes, checked against the variant the course assigned.

    model, notes = model_for(sub, assigned=variant_robot, assigned_name="v017")
    report = grade(sub, robot=model); report.notes[:0] = notes

The text's model is compared with the assigned one as dynamics (the mass matrix M, the
Coriolis matrix C and the gravity torques g at random states, each parameter given one
random value by its name); a difference is a warning note, never a refusal. A text whose
robot cannot be read is graded against the assigned model (noted), or, when the course
assigns none, on its own values (``model`` None: :func:`~armdyn.grading.grade` does that). Only the caller's models are loaded here: nothing the text names.
"""

from __future__ import annotations

import random

import numpy as np

from ...errors import ModelError
from ...model import Robot
from ..reader import Submission
from . import robot_from_text

#: random states the two models are compared at
STATES = 3
_RTOL = 1e-7


def _bound(robot: Robot, values: dict[str, float]) -> Robot:
    return robot.bind({name: values[name] for name in robot.parameters})


def dynamics_differ(read: Robot, assigned: Robot, seed: int = 0) -> str | None:
    """Why the two models' dynamics differ (dofs, M, C or g at a random state), or None when
    they agree. Each parameter gets one random value by its name in both models; a value
    that is not a finite number is a difference, never a match."""
    from ...numeric import coriolis_matrix, crba, gravity

    if read.dof != assigned.dof:
        return f"{read.dof} joints, the assigned model has {assigned.dof}"
    rng = random.Random(seed)
    names = sorted(set(read.parameters) | set(assigned.parameters))
    values = {name: rng.uniform(0.4, 1.6) for name in names}
    try:
        a, b = _bound(read, values), _bound(assigned, values)
    except ModelError as err:
        return f"its parameters cannot be given values ({err})"
    only = sorted(set(read.parameters) - set(assigned.parameters))
    for _ in range(STATES):
        q = np.array([rng.uniform(-1.5, 1.5) for _ in range(read.dof)])
        qd = np.array([rng.uniform(-1.5, 1.5) for _ in range(read.dof)])
        for label, f, args in (
            ("the mass matrix M", crba, (q,)),
            ("the Coriolis matrix C", coriolis_matrix, (q, qd)),
            ("the gravity torques g", gravity, (q,)),
        ):
            try:
                x, y = np.asarray(f(a, *args), dtype=float), np.asarray(f(b, *args), dtype=float)
            except (ModelError, TypeError, ValueError, ArithmeticError) as err:
                return f"{label} cannot be evaluated ({' '.join(str(err).split())[:120]})"
            if not (np.all(np.isfinite(x)) and np.all(np.isfinite(y))) or not np.allclose(
                x, y, rtol=_RTOL, atol=_RTOL * (1 + np.abs(y).max())
            ):
                extra = f"; parameters only the text has: {', '.join(only)}" if only else ""
                return f"{label} differs at q = {np.round(q, 3).tolist()}{extra}"
    return None


def model_for(sub: Submission, assigned: Robot | None = None, assigned_name: str | None = None):
    """``(model, notes)`` for a submission that names no model: the robot its text describes
    (the note that says so first), with a warning when its dynamics differ from the
    assigned model's; the assigned model when the text's cannot be read (noted). Without
    an assigned model an unreadable text gives ``(None, [])`` (graded on its own values by
    :func:`~armdyn.grading.grade`), or the :class:`ModelError` when it has no equation."""
    try:
        read = robot_from_text(sub)
    except ModelError as err:
        if assigned is None and sub.equations:
            return None, []  # grade(sub, robot=None) grades the text on its own values, saying why
        if assigned is None:
            raise
        why = " ".join(str(err).split())[:300]
        return assigned, [f"graded against the assigned model {assigned_name or assigned.name}: {why}"]
    notes = [read.note()]
    if assigned is not None:
        differs = dynamics_differ(read.robot, assigned)
        if differs:
            notes.insert(
                0,
                f"WARNING: the robot your text describes is not your assigned model "
                f"{assigned_name or assigned.name} ({differs}); graded against the robot your text describes",
            )
    return read.robot, notes
