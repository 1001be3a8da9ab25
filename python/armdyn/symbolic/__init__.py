"""Symbolic equations of motion: Newton-Euler and Lagrange, and the proof they agree.

eom = derive(robot, method="newton-euler")   # or "lagrange"
eom.tau, eom.M, eom.C, eom.g, eom.steps
check(derive(robot), derive(robot, "lagrange")).text()
"""

from __future__ import annotations

from ..model import Robot

# the LaTeX and HTML renderers register EquationsOfMotion._repr_latex_, the _repr_html_ of
# EquationsOfMotion, Robot and AgreementReport with armdyn.dispatch when imported
from . import report, report_html  # noqa: F401
from .agreement import AgreementReport, check
from .lagrange import lagrange
from .newton_euler import newton_euler
from .terms import EquationsOfMotion, Step

METHODS = {"newton-euler": newton_euler, "lagrange": lagrange}


def derive(robot: Robot | str, method: str = "newton-euler") -> EquationsOfMotion:
    """Closed-form equations of motion of ``robot`` (a Robot, a bundled name or a file).

    method: "newton-euler" (iterated Newton-Euler, Craig's outward/inward passes) or
            "lagrange" (Euler-Lagrange equations from T and V).
    Returns an :class:`EquationsOfMotion` with q, qd, qdd, tau (n x 1), M, C, g,
    parameters and steps.
    """
    if isinstance(robot, str):
        from ..io import load

        robot = load(robot)
    robot.require_fixed_base("armdyn.derive")
    try:
        fn = METHODS[method]
    except KeyError:
        raise ValueError(f"unknown method {method!r}; choose one of {', '.join(METHODS)}") from None
    return fn(robot)


def prove_agreement(robot: Robot | str, **kwargs) -> AgreementReport:
    """Derive by both methods and :func:`check` that they agree (kwargs go to check)."""
    return check(derive(robot, "newton-euler"), derive(robot, "lagrange"), **kwargs)


__all__ = [
    "derive",
    "prove_agreement",
    "check",
    "newton_euler",
    "lagrange",
    "EquationsOfMotion",
    "Step",
    "AgreementReport",
    "METHODS",
]
