"""The sine/cosine shorthand defined as an equation: ``c_1 = \\cos\\theta_1``,
``s_{12} = \\sin(\\theta_1 + \\theta_2)``, ``C_{12}``, ``S_1`` (Craig; Spong, Hutchinson &
Vidyasagar). Read as the definition of the shorthand and checked: right when the value is
the sine or cosine of the sum of the joint angles the shorthand names.

The same letters name other things, told apart by the value: a value holding joint rates
is Lynch & Park's velocity-product vector entry ``c_i`` (``c(θ, θ̇)``) or a Coriolis matrix
entry ``C_{jk}``; a value in the joint angles alone is the shorthand's definition; anything
else is the student's own name.
"""

from __future__ import annotations

import sympy as sp

from .engine import equal
from .explain import describe, pretty, tidy
from .verdict import StepVerdict


def shorthand_function(ref, robot):
    """sin or cos of the angle sum that ``ref`` (``s_{12}``: alias ``s``, entry (1, 2)) names."""
    angle = sum((robot.q[k - 1] for k in ref.entry), sp.Integer(0))
    return (sp.sin if ref.alias in ("s", "S") else sp.cos)(angle)


def shorthand_reading(ref, value, robot, step_ref):
    """(the reading of ``c_1``, ``C_{12}``... given its value, what was assumed), or (None, why)."""
    from .text import NOT_A_STEP

    if isinstance(value, sp.MatrixBase) or not all(1 <= k <= robot.dof for k in ref.entry):
        return None, NOT_A_STEP
    symbols = value.free_symbols
    if symbols & set(robot.qd):  # joint rates: a Coriolis term, in the letters' other meaning
        name = f"{ref.alias}_{''.join(map(str, ref.entry))}"
        if ref.alias == "c" and len(ref.entry) == 1:
            return step_ref("h", entry=ref.entry, alias="c"), (
                f"{name} read as entry {ref.entry[0]} of Lynch & Park's velocity-product vector c(θ, θ̇) "
                "(the value holds joint rates)"
            )
        if ref.alias in ("c", "C") and len(ref.entry) == 2:
            return step_ref("C", entry=ref.entry, alias=ref.alias), (
                f"{name} read as entry ({ref.entry[0]}, {ref.entry[1]}) of the Coriolis matrix C(q, q̇) "
                "(the value holds joint rates)"
            )
        return None, NOT_A_STEP
    if ref.alias in ("c", "C") and len(ref.entry) == 2 and _coriolis_like(value, symbols, robot):
        # C_{11} = 0, C_{12} = -m_2 l_1 l_{c2} sin(theta_2): no shorthand (a sum's cosine is in the
        # angles alone, never 0), so the Coriolis entry, judged (its missing rates are the slip)
        name = f"{ref.alias}_{''.join(map(str, ref.entry))}"
        return step_ref("C", entry=ref.entry, alias=ref.alias), (
            f"{name} read as entry ({ref.entry[0]}, {ref.entry[1]}) of the Coriolis matrix C(q, q̇) (the value is "
            "not the sine or cosine shorthand's: zero, or the joint angles with the model's parameters)"
        )
    if not symbols or not symbols <= set(robot.q):
        return None, NOT_A_STEP  # a length, a constant: the student's own name
    return ref, ""


def _coriolis_like(value, symbols, robot) -> bool:
    """Zero, or a value in the joint angles and the model's other parameters (masses,
    lengths): what a Coriolis entry written without its rates looks like; a shorthand's
    value is in the angles alone."""
    if value == 0:
        return True
    angles = symbols & set(robot.q)
    return bool(angles) and bool(symbols - set(robot.q))


def grade_shorthand(ref, eq, value, robot, sampler) -> StepVerdict:
    """The verdict on a shorthand's definition ``s_{12} = \\sin(\\theta_1 + \\theta_2)``."""
    name = f"{ref.alias}_{''.join(map(str, ref.entry))}"
    expected = shorthand_function(ref, robot)
    fp = sampler.fingerprint
    base = dict(name=name, key="shorthand", link="", label=eq.lhs, source=eq.source, line=eq.line)
    what = f"{name} is the shorthand for {pretty(expected)}"
    if equal(fp(value), fp(expected)).all():
        return StepVerdict(status="correct", expected=expected, got=value, message=f"{what}: its definition", **base)
    other = shorthand_function(type(ref)(ref.key, alias="c" if ref.alias in "sS" else "s", entry=ref.entry), robot)
    if equal(fp(value), fp(other)).all():
        why = f"the value is the {'cosine' if ref.alias in 'sS' else 'sine'}: sine and cosine swapped"
    else:
        why = describe(value, expected, robot, sampler)
    return StepVerdict(
        status="wrong",
        expected=expected,
        got=value,
        difference=tidy(value - expected, robot),
        message=f"{why} ({what})",
        **base,
    )
