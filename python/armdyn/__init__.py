"""armdyn: dynamics of robot arms, derived symbolically and computed numerically.

    import armdyn
    robot = armdyn.load("rp-arm")                  # a bundled model, or a .yaml/.urdf file
    eom = armdyn.derive(robot, "newton-euler")     # or "lagrange": tau, M, C, g, steps
    print(armdyn.prove_agreement(robot).text())    # Newton-Euler == Lagrange, M sym., tau = M qdd + C qd + g
    print(armdyn.grade("my-derivation.md").text()) # a student's derivation, step by step

Conventions: SI units, radians, ``M(q) qdd + C(q, qd) qd + g(q) = tau``; frames as in
:mod:`armdyn.model`.
"""

#: the package version (kept equal to pyproject.toml's; tests/test_hardening.py checks)
__version__ = "0.1.0"

from ._interrupt import quiet_until_main  # noqa: E402

quiet_until_main()  # Ctrl-C while `python -m armdyn` imports SymPy: one line, status 130

from typing import TYPE_CHECKING  # noqa: E402

from . import inertia, io  # noqa: E402
from .errors import ModelError, UnboundParameterError  # noqa: E402
from .io import bundled_robots, load  # noqa: E402
from .model import Joint, Link, Robot  # noqa: E402
from .printing import codegen  # noqa: E402  (armdyn.printing.compile builds the generated C)
from .symbolic import EquationsOfMotion, check, derive, prove_agreement  # noqa: E402

if TYPE_CHECKING:  # what __getattr__ below imports on first use, for type checkers (py.typed)
    from .centroidal import (  # noqa: F401
        center_of_mass,
        centroidal_momentum,
        centroidal_momentum_matrix,
        centroidal_momentum_matrix_rate,
        centroidal_momentum_rate,
        com_jacobian,
    )
    from .grading import grade  # noqa: F401
    from .identification import base_parameters, regressor  # noqa: F401
    from .numeric import (  # noqa: F401  # noqa: F401  # noqa: F401
        NumericModel,
        aba,
        aba_derivatives,
        bias,
        compile_model,
        coriolis_matrix,
        crba,
        forward_kinematics,
        gravity,
        gravity_derivatives,
        jacobian,
        jacobian_dot,
        kinetic_energy,
        minverse,
        potential_energy,
        rnea,
        rnea_derivatives,  # noqa: F401
    )

_NUMERIC = (
    "rnea",
    "crba",
    "aba",
    "gravity",
    "bias",
    "coriolis_matrix",
    "kinetic_energy",
    "potential_energy",
    "forward_kinematics",
    "jacobian",
    "NumericModel",
    "compile_model",
    "rnea_derivatives",
    "aba_derivatives",
    "minverse",
    "gravity_derivatives",
    "jacobian_dot",
)
_IDENTIFICATION = ("regressor", "base_parameters")
_CENTROIDAL = (
    "center_of_mass",
    "com_jacobian",
    "centroidal_momentum_matrix",
    "centroidal_momentum",
    "centroidal_momentum_rate",
    "centroidal_momentum_matrix_rate",
)


def __getattr__(name):
    if name == "grade":  # armdyn.grading.grade, imported on first use (it loads the grader)
        from .grading import grade

        globals()[name] = grade
        return grade
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
    if name in _CENTROIDAL:  # centre of mass and centroidal momentum (armdyn.centroidal)
        from . import centroidal

        value = getattr(centroidal, name)
        globals()[name] = value
        return value
    raise AttributeError(f"module 'armdyn' has no attribute {name!r}")


__all__ = [
    "__version__",
    *_NUMERIC,
    *_IDENTIFICATION,
    *_CENTROIDAL,
    "inertia",
    "io",
    "ModelError",
    "UnboundParameterError",
    "Joint",
    "Link",
    "Robot",
    "load",
    "bundled_robots",
    "derive",
    "check",
    "prove_agreement",
    "EquationsOfMotion",
    "grade",
    "codegen",
]
