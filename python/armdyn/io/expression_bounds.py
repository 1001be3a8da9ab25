"""The bounds on the values an expression builds, so that hostile input ends in bounded time.

:mod:`armdyn.io.expression_parser` checks every value it builds with these: each constant
part must be a finite real float64, computed node by node with Python floats
(:func:`float_value`); an exact power may not produce more than :data:`MAX_POWER_DIGITS`
digits nor an exponent beyond :data:`MAX_EXPONENT`; a power of a power with a non-integer
exponent is left as written (:func:`power`). A refusal is a :class:`ParseError`.
"""

from __future__ import annotations

import math

import sympy as sp

#: Most digits an exact power (integer or rational base and exponent) may produce.
MAX_POWER_DIGITS = 10_000
#: Largest |numerator| of a rational exponent (``a**(10**20)`` would hang once bound; SymPy
#: splits ``x**n`` into real and imaginary parts by expanding ``(a + i b)**n``, in time
#: growing as n^3: 0.3 s for n = 100, minutes for n = 1000).
MAX_EXPONENT = 100


class ParseError(Exception):
    """An expression that cannot be read, or whose value is past a bound (the message says which)."""


def clip(text: str, limit: int = 30) -> str:
    """``text`` cut to ``limit`` characters for a message, saying how long it was."""
    return text if len(text) <= limit else f"{text[:limit]}... ({len(text)} characters)"


#: SymPy functions -> float functions, for :func:`float_value`.
_MATH = {
    sp.sin: math.sin,
    sp.cos: math.cos,
    sp.tan: math.tan,
    sp.asin: math.asin,
    sp.acos: math.acos,
    sp.atan: math.atan,
    sp.atan2: math.atan2,
    sp.sinh: math.sinh,
    sp.cosh: math.cosh,
    sp.tanh: math.tanh,
    sp.exp: math.exp,
    sp.log: math.log,
    sp.Abs: abs,
}


def float_value(expr) -> float:
    """The float64 value of a constant expression (no free symbols), computed with
    Python floats node by node, so it takes time linear in the expression's size
    (SymPy's ``evalf`` of ``exp(exp(exp(100)))`` does not finish). NaN if a step
    overflows, leaves the reals or is not one of the whitelisted functions."""
    try:
        return _float_node(sp.sympify(expr), {})
    except (OverflowError, ValueError, TypeError, ZeroDivisionError, KeyError):
        return math.nan


def constant_problem(expr, memo: dict) -> str | None:
    """What keeps a constant expression from being a finite real float64 (``None`` if
    nothing): its value overflows, is complex or NaN, or is SymPy's infinity."""
    try:
        x = _float_node(expr, memo)
    except OverflowError:
        return "beyond the float64 range"
    except (ValueError, ZeroDivisionError):  # a complex power, a math domain error
        return "not real"
    except (TypeError, KeyError):  # float(zoo), I, an unknown function
        return "not real" if expr.has(sp.I) else "not finite"
    if math.isinf(x):
        return "beyond the float64 range"
    return None if x == x else "not finite"


def _float_node(e, memo: dict) -> float:
    """``float_value`` of one node; ``memo`` maps nodes already computed to their value."""
    if e in memo:
        return memo[e]
    if e.is_Number:
        value = int(e.p) / int(e.q) if e.is_Rational else float(e)  # true division: OverflowError when out of range
        if value == 0 and e != 0:  # 1e-300**999 is a SymPy Float of 1e-299700: beyond float64 as well
            raise OverflowError("underflow")
        return value
    if e is sp.pi:
        return math.pi
    if e is sp.E:
        return math.e
    args = [_float_node(a, memo) for a in e.args]
    if e.is_Add:
        value = math.fsum(args)
    elif e.is_Mul:
        value = math.prod(args)
    elif e.is_Pow:
        value = args[0] ** args[1]
        if isinstance(value, complex):
            raise ValueError("not real")
        value = float(value)
    else:
        value = float(_MATH[e.func](*args))
    memo[e] = value
    return value


def power(base, exponent):
    """``base**exponent``, left unevaluated when ``base`` is itself a power of an
    expression in the parameters and ``exponent`` is not an integer. SymPy would decide
    whether ``(b**e)**x`` may become ``b**(e x)`` by working out the real and imaginary
    parts and the argument of ``b``, in time exponential in the nesting of ``b``
    (``sqrt(cos(cos(...cos(m)...))**2)`` with 15 cosines took 30 s, 20 never ended); with
    parameters that carry no assumptions it can only decide "no" anyway."""
    if base.is_Pow and base.free_symbols and not exponent.is_Integer:
        return sp.Pow(base, exponent, evaluate=False)
    return base**exponent


def _digits(x: sp.Rational) -> int:
    """Decimal digits of an exact rational's numerator and denominator, roughly."""
    return max(int(x.p).bit_length(), int(x.q).bit_length()) * 30103 // 100000 + 1


def check_power_size(base, exponent) -> None:
    """Refuse ``base**exponent`` when SymPy could be made to compute an exact number of
    more than MAX_POWER_DIGITS digits, now or once parameters are bound: an exponent
    p/q with |p| > MAX_EXPONENT, or |b|^|p| with more than MAX_POWER_DIGITS digits
    (about |p| log10|b|; a q-th root is no larger)."""
    if exponent.is_Float:
        # a float power is computed in floating point, but SymPy's floats have unbounded
        # exponents: 2.0**999.0**999.0**999.0 overflows, sin() of it kills the process
        e = abs(float(exponent))
        too_big = not e <= MAX_EXPONENT
        if not too_big and not base.free_symbols and base not in (0, 1, -1):
            size = abs(float_value(base))
            too_big = not (math.isfinite(size) and size > 0 and e * abs(math.log10(size)) <= 308)
        if too_big:
            raise ParseError(
                f"the power {clip(str(base))}**{clip(str(exponent))} is too large (exponents up "
                f"to {MAX_EXPONENT}, results within float64's range)"
            )
        return
    if exponent.free_symbols:
        # b**(y + 999) is b**999 * b**y to SymPy when it works exactly (cos() looks for a
        # multiple of pi with polynomial gcds: 1e-300**999 as an exact fraction has 300000
        # digits), so the constant term and the coefficient count as exponents too
        for constant in (exponent.as_coeff_Add()[0], exponent.as_coeff_Mul()[0]):
            if constant.is_Number and constant not in (0, 1):
                check_power_size(base, constant)
        return
    if not isinstance(exponent, sp.Rational) or exponent == 0:
        return
    p = abs(int(exponent.p))
    too_big = p > MAX_EXPONENT
    if not too_big and not base.free_symbols and base not in (0, 1, -1):
        if isinstance(base, sp.Rational):
            digits = _digits(base)
        else:
            size = abs(float_value(base))
            digits = abs(math.log10(size)) + 1 if math.isfinite(size) and size > 0 else math.inf
        too_big = p * digits > MAX_POWER_DIGITS
    if too_big:
        raise ParseError(
            f"the power {clip(str(base))}**{clip(str(exponent))} is too large (exponents up to "
            f"{MAX_EXPONENT}, exact results up to {MAX_POWER_DIGITS} digits)"
        )


def check_combined_exponents(value) -> None:
    """Refuse a power (alone or as a factor) whose exponent SymPy combined beyond
    MAX_EXPONENT: ``(a**1000)**1000`` is ``a**1000000``, which binding ``a = 10``
    would turn into a million-digit integer."""
    for f in value.args if value.is_Mul else (value,):
        if (
            f.is_Pow
            and isinstance(f.exp, sp.Rational)
            and abs(int(f.exp.p)) > MAX_EXPONENT
            or f.is_Pow
            and f.exp.is_Float
            and not abs(float(f.exp)) <= MAX_EXPONENT
        ):
            raise ParseError(f"the power {clip(str(f))} has an exponent beyond {MAX_EXPONENT}")
