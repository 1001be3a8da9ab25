"""Symbolic equations of motion: Newton-Euler and Lagrange, and the proof they agree.

eom = derive(robot, method="newton-euler")   # or "lagrange"
eom.tau, eom.M, eom.C, eom.g, eom.steps
check(derive(robot), derive(robot, "lagrange")).text()

A floating base (``root_joint="free-flyer"``): Newton-Euler only, parametrised by the
base twist (newton_euler_floating.py); tau, M, g and bias have 6 + n rows. A spherical,
planar or floating joint (under a fixed or a floating base): Newton-Euler only, by its
velocity (newton_euler_spherical.py).
"""

from __future__ import annotations

from ..errors import FloatingBaseError
from ..model import Robot

# the LaTeX and HTML renderers register EquationsOfMotion._repr_latex_, the _repr_html_ of
# EquationsOfMotion, Robot and AgreementReport with armdyn.dispatch when imported
from . import report, report_html  # noqa: F401
from .agreement import AgreementReport, check
from .lagrange import lagrange
from .newton_euler import newton_euler
from .newton_euler_floating import FloatingEquationsOfMotion, newton_euler_floating
from .newton_euler_spherical import SphericalEquationsOfMotion, refuse_quasi_velocities
from .terms import EquationsOfMotion, Step

METHODS = {"newton-euler": newton_euler, "lagrange": lagrange}


def derive(robot: Robot | str, method: str = "newton-euler") -> EquationsOfMotion:
    """Closed-form equations of motion of ``robot`` (a Robot, a bundled name or a file).

    method: "newton-euler" (iterated Newton-Euler, Craig's outward/inward passes) or
            "lagrange" (Euler-Lagrange equations from T and V).
    Returns an :class:`EquationsOfMotion` with q, qd, qdd, tau (n x 1), M, C, g,
    parameters and steps.

    A floating base (``robot.floating``): Newton-Euler from the base's twist, a
    :class:`FloatingEquationsOfMotion` whose qd, qdd, tau have 6 + n rows (base twist,
    joints: Pinocchio's order) and that carries ``bias`` instead of ``C``; "lagrange"
    raises :class:`~armdyn.errors.FloatingBaseError`.

    Spherical, planar and floating joints: Newton-Euler by their velocity (a ball joint's
    angular velocity, a planar or floating joint's twist in its own frame), a
    :class:`SphericalEquationsOfMotion` (``bias`` instead of ``C``; under a floating base
    a :class:`FloatingEquationsOfMotion`); "lagrange" raises
    :class:`~armdyn.errors.ModelError` naming the joint.
    """
    if isinstance(robot, str):
        from ..io import load

        robot = load(robot)
    try:
        fn = METHODS[method]
    except KeyError:
        raise ValueError(f"unknown method {method!r}; choose one of {', '.join(METHODS)}") from None
    if robot.floating:
        if method != "newton-euler":
            raise FloatingBaseError(
                f"method {method!r} does not support a floating base (root_joint='free-flyer'): "
                "method 'newton-euler' derives it (a Lagrangian of the base's quaternion is another exercise)",
                f"robot '{robot.name}'",
                robot.meta.get("file"),
            )
        return newton_euler_floating(robot)
    return fn(robot)


def prove_agreement(robot: Robot | str, **kwargs) -> AgreementReport:
    """Derive by both methods and :func:`check` that they agree (kwargs go to check)."""
    if isinstance(robot, str):
        from ..io import load

        robot = load(robot)
    refuse_quasi_velocities(robot, "armdyn.prove_agreement (Newton-Euler against Lagrange)")
    return check(derive(robot, "newton-euler"), derive(robot, "lagrange"), **kwargs)


__all__ = [
    "derive",
    "prove_agreement",
    "check",
    "newton_euler",
    "lagrange",
    "EquationsOfMotion",
    "FloatingEquationsOfMotion",
    "SphericalEquationsOfMotion",
    "Step",
    "AgreementReport",
    "METHODS",
]
