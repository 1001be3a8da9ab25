"""armdyn: dynamics of robot arms, derived symbolically and computed numerically.

    import armdyn
    robot = armdyn.load("rp-arm")                  # a bundled model, or a .yaml/.urdf file
    eom = armdyn.derive(robot, "newton-euler")     # or "lagrange": tau, M, C, g, steps
    print(armdyn.prove_agreement(robot).text())    # Newton-Euler == Lagrange, M sym., Mdot-2C skew

Conventions: SI units, radians, ``M(q) qdd + C(q, qd) qd + g(q) = tau``; frames as in
:mod:`armdyn.model`.
"""

from . import inertia, io
from .errors import ModelError, UnboundParameterError
from .io import bundled_robots, load
from .model import Joint, Link, Robot
from .symbolic import EquationsOfMotion, check, derive, prove_agreement

_NUMERIC = (
    "rnea", "crba", "aba", "gravity", "bias", "coriolis_matrix", "kinetic_energy",
    "potential_energy", "forward_kinematics", "jacobian", "NumericModel", "compile_model",
)
_IDENTIFICATION = ("regressor", "base_parameters")


def __getattr__(name):
    # the numeric API lives in armdyn.numeric (over the compiled Rust core), imported on
    # first use so that symbolic work does not load the extension
    if name in _NUMERIC:
        from . import numeric

        value = getattr(numeric, name)
        globals()[name] = value  # later lookups skip __getattr__ (it costs ~1 us a call)
        return value
    if name in _IDENTIFICATION:  # symbolic regressor and base parameters (armdyn.identification)
        from . import identification

        value = getattr(identification, name)
        globals()[name] = value
        return value
    raise AttributeError(f"module 'armdyn' has no attribute {name!r}")


__all__ = [
    *_NUMERIC, *_IDENTIFICATION,
    "inertia", "io", "ModelError", "UnboundParameterError", "Joint", "Link", "Robot",
    "load", "bundled_robots", "derive", "check", "prove_agreement", "EquationsOfMotion",
]
