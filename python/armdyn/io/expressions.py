"""Numbers and expressions in model files, turned into SymPy.

A value in a model file is a number (``0.4318``, ``2``) or a string holding an
arithmetic expression of the model's declared parameters::

    "l1"   "-g"   "pi/2"   "m2*l1**2/12"   "sqrt(2)/2"   "0.5*a^2"   "1e-3"

Grammar (``^`` is a synonym of ``**``; ``-a**2`` is ``-(a**2)``; ``**`` is
right-associative, as in Python)::

    expr   := term (("+" | "-") term)*
    term   := unary (("*" | "/") unary)*
    unary  := ("+" | "-") unary | power
    power  := atom (("**" | "^") unary)?
    atom   := NUMBER | NAME | FUNCTION "(" expr ("," expr)* ")" | "(" expr ")"

Names are looked up in two tables only: the declared parameters (each a plain
``sp.Symbol(name)`` with no assumptions, so ``sp.Symbol("m1")`` written by a user
matches) and the whitelist :data:`FUNCTIONS` / :data:`CONSTANTS`. Nothing is ever
passed to ``eval`` or ``sympy.parse_expr``: the string is tokenised and parsed here,
so attribute access, dunders, string literals, lambdas and SymPy's special one-letter
names (``S``, ``N``, ``E``, ``I``, ``Q``, ``O``) cannot reach the interpreter; a
parameter called ``E``, ``beta`` or ``lambda`` is just a Symbol of that name.

Integers stay exact (``1/12`` is ``Rational(1, 12)``); decimals become ``sp.Float``
(as a YAML float would).

Hostile input is refused in bounded time: an expression longer than
:data:`MAX_LENGTH` characters or nested deeper than :data:`MAX_DEPTH` (parentheses,
function calls, unary signs and exponents each count a level) is an error, and so is
an exact power whose result would have more than :data:`MAX_POWER_DIGITS` digits
(``10**10**10`` would otherwise make SymPy compute a 10^10-digit integer) or whose
exponent exceeds :data:`MAX_EXPONENT`, and so are function calls nested deeper than
:data:`MAX_CALL_DEPTH` and a value taking more than :data:`MAX_SECONDS` of CPU time. A
decimal number must fit a float64, and every constant part must evaluate to a finite real
float64 as it is built: a constant (``exp(exp(exp(100)))`` stops at ``exp(exp(100))``),
the coefficient of a product (``m1*1e300*1e300``), the constant term of a sum. Powers of
powers with a non-integer exponent are left as written (see
:func:`armdyn.io.expression_bounds.power`).

This module also converts the shaped values of a model (scalars, 3-vectors,
3x3 matrices, inertia tensors, rotations) with the same rules; every failure is a
:class:`~armdyn.errors.ModelError` naming the offending expression.

The reader itself is :mod:`armdyn.io.expression_parser`, the bounds on what it builds
:mod:`armdyn.io.expression_bounds`; everything public of both is exported from here.
"""

from __future__ import annotations

from typing import Mapping

import sympy as sp

from ..errors import ModelError
from .expression_bounds import MAX_EXPONENT, MAX_POWER_DIGITS, float_value
from .expression_parser import (
    CONSTANTS,
    FUNCTIONS,
    MAX_CALL_DEPTH,
    MAX_DEPTH,
    MAX_INT_DIGITS,
    MAX_LENGTH,
    MAX_SECONDS,
    RESERVED,
    check_name,
    check_parameter_name,
    is_zero,
    make_parameters,
    parse_expression,
    quoted,
    shown,
)


# ------------------------------------------------------------------ shaped values
def parse_vector(value, parameters, element=None, source=None, what=None, length=3) -> sp.Matrix:
    """A list of ``length`` values -> (length, 1) column Matrix."""
    prefix = f"{what}: " if what else ""
    if not isinstance(value, sp.MatrixBase) and hasattr(value, "tolist"):  # a NumPy array
        value = value.tolist()
    if not isinstance(value, (list, tuple, sp.MatrixBase)):
        raise ModelError(f"{prefix}expected a list of {length} values, got {shown(value)}", element, source)
    items = list(value)
    if len(items) != length:
        raise ModelError(f"{prefix}expected {length} values, got {len(items)}", element, source)
    return sp.Matrix([parse_expression(v, parameters, element, source, what) for v in items])


def parse_matrix3(value, parameters, element=None, source=None, what="matrix") -> sp.Matrix:
    """A list of 3 rows of 3 values -> 3x3 Matrix."""
    if isinstance(value, sp.MatrixBase):
        value = value.tolist()
    if (
        not isinstance(value, (list, tuple))
        or len(value) != 3
        or not all(isinstance(r, (list, tuple)) and len(r) == 3 for r in value)
    ):
        raise ModelError(f"{what}: expected a 3x3 matrix (3 rows of 3 values), got {shown(value)}", element, source)
    return sp.Matrix([[parse_expression(v, parameters, element, source, what) for v in row] for row in value])


INERTIA_KEYS = ("ixx", "iyy", "izz", "ixy", "ixz", "iyz")


def parse_inertia(value, parameters, element=None, source=None, what="inertia") -> sp.Matrix:
    """An inertia tensor (3x3 Matrix) from one of three forms:

    * ``0``: a point mass (zero tensor). No other scalar is accepted.
    * a 3x3 matrix (must be symmetric);
    * a mapping ``{ixx, iyy, izz, ixy, ixz, iyz}``: the diagonal is required, missing
      products of inertia are 0 (principal axes). ``I = [[ixx, ixy, ixz], [ixy, iyy, iyz],
      [ixz, iyz, izz]]`` (URDF's convention: products enter the tensor with a + sign).
    """
    if isinstance(value, Mapping):
        unknown = [k for k in value if k not in INERTIA_KEYS]
        if unknown:
            raise ModelError(
                f"{what}: unknown key(s) {', '.join(map(shown, unknown))} (expected {', '.join(INERTIA_KEYS)})",
                element,
                source,
            )
        missing = [k for k in ("ixx", "iyy", "izz") if k not in value]
        if missing:
            raise ModelError(f"{what}: missing {', '.join(missing)}", element, source)
        c = {k: parse_expression(value.get(k, 0), parameters, element, source, f"{what}.{k}") for k in INERTIA_KEYS}
        return sp.Matrix(
            [
                [c["ixx"], c["ixy"], c["ixz"]],
                [c["ixy"], c["iyy"], c["iyz"]],
                [c["ixz"], c["iyz"], c["izz"]],
            ]
        )
    if isinstance(value, (list, tuple, sp.MatrixBase)):
        tensor = parse_matrix3(value, parameters, element, source, what)
        if any(sp.simplify(tensor[i, j] - tensor[j, i]) != 0 for i, j in ((0, 1), (0, 2), (1, 2))):
            raise ModelError(f"{what}: the matrix is not symmetric", element, source)
        return tensor
    scalar = parse_expression(value, parameters, element, source, what)
    if not is_zero(scalar):
        raise ModelError(
            f"{what}: a scalar inertia must be 0 (a point mass); give a 3x3 matrix or "
            "{ixx, iyy, izz, ixy, ixz, iyz} otherwise",
            element,
            source,
        )
    return sp.zeros(3, 3)


def check_rotation(rotation: sp.Matrix, element=None, source=None, what="rotation", tol=1e-9) -> sp.Matrix:
    """Raise ModelError unless ``rotation`` (3x3) is a proper rotation (R^T R = I, det R = +1).

    Numeric matrices are checked to ``tol``; symbolic ones must simplify exactly.
    Typing 0.7071 for sqrt(2)/2 fails on purpose: write ``sqrt(2)/2``.
    """
    gram = rotation.T * rotation - sp.eye(3)
    det = rotation.det() - 1
    if rotation.free_symbols:
        ok = all(sp.simplify(e) == 0 for e in list(gram) + [det])
        if not ok:
            raise ModelError(f"{what}: cannot show the matrix is a rotation (R^T R = I, det R = 1)", element, source)
        return rotation
    err = max(abs(float(e)) for e in list(gram))
    if err > tol:
        raise ModelError(f"{what}: the matrix is not orthonormal (max |R^T R - I| = {err:.3g})", element, source)
    if abs(float(det)) > 1e-6:
        raise ModelError(
            f"{what}: the matrix is a reflection (det = {float(det) + 1:.3g}), not a rotation", element, source
        )
    return rotation


def parse_inertials(data: Mapping, parameters, element=None, source=None):
    """``(mass, com, inertia)`` from the ``mass``, ``com`` and ``inertia`` keys of ``data``.

    mass:    default 0.
    com:     (3, 1), default 0.
    inertia: (3, 3) about the centre of mass (see :func:`parse_inertia`). Required when
             the mass is not identically zero: a massive link never gets a guessed tensor;
             write ``inertia: 0`` for a point mass.
    """
    mass = parse_expression(data.get("mass", 0), parameters, element, source, "mass")
    com = parse_vector(data.get("com", [0, 0, 0]), parameters, element, source, "com")
    if "inertia" in data:
        inertia = parse_inertia(data["inertia"], parameters, element, source)
    elif not is_zero(mass):
        raise ModelError("the link has a mass but no inertia (write 'inertia: 0' for a point mass)", element, source)
    else:
        inertia = sp.zeros(3, 3)
    return mass, com, inertia


LIMIT_KEYS = ("lower", "upper", "velocity", "effort")


def parse_joint_extras(data: Mapping, parameters, element=None, source=None) -> dict:
    """Keyword arguments for :class:`armdyn.Joint` from the optional ``limits``
    (mapping with keys ``lower, upper, velocity, effort``), ``damping`` (Fv), ``friction``
    (Coulomb Fc), ``armature`` (reflected rotor inertia Ia) or ``rotor_inertia`` with
    ``gear_ratio`` (Ia = gear_ratio^2 rotor_inertia), and ``torque_offset`` entries of ``data``. Absent values are left out (the Joint keeps None)."""
    out = {}
    limits = data.get("limits")
    if limits is not None:
        if not isinstance(limits, Mapping):
            raise ModelError(f"limits: expected a mapping with keys {', '.join(LIMIT_KEYS)}", element, source)
        unknown = [k for k in limits if k not in LIMIT_KEYS]
        if unknown:
            raise ModelError(
                f"limits: unknown key(s) {', '.join(map(shown, unknown))} (expected {', '.join(LIMIT_KEYS)})",
                element,
                source,
            )
        for key, value in limits.items():
            if value is not None:
                out[key] = parse_expression(value, parameters, element, source, f"limits.{key}")
    for key in ("damping", "friction", "armature", "torque_offset"):
        if data.get(key) is not None:
            out[key] = parse_expression(data[key], parameters, element, source, key)
    # rotor inertia reflected through the gear: Ia = gear_ratio^2 * rotor_inertia
    if data.get("rotor_inertia") is not None:
        if "armature" in out:
            raise ModelError("give either armature or rotor_inertia (with gear_ratio), not both", element, source)
        rotor = parse_expression(data["rotor_inertia"], parameters, element, source, "rotor_inertia")
        gear = parse_expression(data.get("gear_ratio", 1), parameters, element, source, "gear_ratio")
        out["armature"] = gear**2 * rotor
    elif data.get("gear_ratio") is not None:
        raise ModelError("gear_ratio without rotor_inertia", element, source)
    return out


__all__ = [
    "FUNCTIONS",
    "CONSTANTS",
    "RESERVED",
    "MAX_LENGTH",
    "MAX_DEPTH",
    "MAX_POWER_DIGITS",
    "MAX_INT_DIGITS",
    "MAX_EXPONENT",
    "MAX_CALL_DEPTH",
    "MAX_SECONDS",
    "float_value",
    "INERTIA_KEYS",
    "check_parameter_name",
    "check_name",
    "quoted",
    "shown",
    "make_parameters",
    "parse_expression",
    "is_zero",
    "parse_vector",
    "parse_matrix3",
    "parse_inertia",
    "check_rotation",
    "parse_inertials",
    "parse_joint_extras",
    "LIMIT_KEYS",
]
