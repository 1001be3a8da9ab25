"""The expression reader: names, tokens and the recursive-descent parser of model-file arithmetic.

The grammar, the whitelists and the limits are documented in :mod:`armdyn.io.expressions`,
which exports all of this; the bounds every built value is checked against are in
:mod:`armdyn.io.expression_bounds`. Nothing here is passed to ``eval``: the string is
tokenised and parsed.
"""

from __future__ import annotations

import math
import numbers
import re
import reprlib
import time
from typing import Mapping

import sympy as sp

from ..errors import ModelError
from .expression_bounds import (
    ParseError,
    check_combined_exponents,
    check_power_size,
    clip,
    constant_problem,
    float_value,
    power,
)

#: Functions an expression may call (name -> SymPy function, number of arguments).
FUNCTIONS = {
    "sin": (sp.sin, 1),
    "cos": (sp.cos, 1),
    "tan": (sp.tan, 1),
    "asin": (sp.asin, 1),
    "acos": (sp.acos, 1),
    "atan": (sp.atan, 1),
    "atan2": (sp.atan2, 2),
    "sinh": (sp.sinh, 1),
    "cosh": (sp.cosh, 1),
    "tanh": (sp.tanh, 1),
    "sqrt": (sp.sqrt, 1),
    "exp": (sp.exp, 1),
    "log": (sp.log, 1),
    "abs": (sp.Abs, 1),
}

#: Named constants.
CONSTANTS = {"pi": sp.pi}

#: Longest expression string accepted (characters).
MAX_LENGTH = 10_000
#: Deepest nesting accepted (parentheses, calls, unary signs, exponents).
MAX_DEPTH = 100
#: Most digits of an integer literal (a float64 is at most about 1.8e308).
MAX_INT_DIGITS = 400
#: Deepest nesting of function calls (SymPy's real and imaginary parts of
#: ``cos(cos(...(x)))`` take time exponential in it: 20 levels never finished).
MAX_CALL_DEPTH = 6
#: CPU seconds one expression may take to read (a backstop: each step above is bounded,
#: a long expression of many such steps is not).
MAX_SECONDS = 2.0

#: Names a parameter may not take (they already mean something in an expression).
RESERVED = frozenset(FUNCTIONS) | frozenset(CONSTANTS)

_NAME_RE = re.compile(r"[A-Za-z][A-Za-z0-9_]*\Z")
_TOKEN_RE = re.compile(
    r"""\s*(?:
        (?P<number>(?:\d+\.?\d*|\.\d+)(?:[eE][+-]?\d+)?)
      | (?P<name>[A-Za-z_][A-Za-z0-9_]*)
      | (?P<op>\*\*|[-+*/^(),])
    )""",
    re.VERBOSE,
)


_SHORT = reprlib.Repr()
_SHORT.maxlevel, _SHORT.maxlist, _SHORT.maxdict, _SHORT.maxstring, _SHORT.maxother = 2, 4, 4, 40, 40


def shown(value) -> str:
    """A short ``repr`` of a user's value for messages (nested or huge values cut)."""
    return _SHORT.repr(value)


def quoted(text) -> str:
    """``'text'`` for messages; ``repr`` when it holds newlines or control characters,
    so that an error stays one line."""
    text = str(text)
    if len(text) > 120:  # a hostile 10k-character expression is shown by its start
        text = f"{text[:100]}... ({len(text)} characters)"
    return f"'{text}'" if text.isprintable() else repr(text)


def check_name(name, what: str, element=None, source=None) -> str:
    """Return ``name`` if it is a non-empty one-line string, else raise ModelError."""
    if not isinstance(name, str) or not name or not name.isprintable():
        raise ModelError(f"{what}: expected a name (a one-line string), got {shown(name)}", element, source)
    return name


def check_parameter_name(name, element: str | None = "parameters", source: str | None = None) -> str:
    """Return ``name`` if it may name a parameter, else raise ModelError."""
    if not isinstance(name, str) or not _NAME_RE.match(name):
        raise ModelError(
            f"parameter name {shown(name)} is not an identifier (letters, digits, '_'; starting with a letter)",
            element,
            source,
        )
    if name in RESERVED:
        raise ModelError(f"parameter name '{name}' is reserved (a function or constant)", element, source)
    return name


def make_parameters(names, element: str | None = "parameters", source: str | None = None) -> dict[str, sp.Symbol]:
    """Plain symbols (no assumptions) for the declared parameter names, in order."""
    out: dict[str, sp.Symbol] = {}
    for name in names:
        check_parameter_name(name, element, source)
        if name in out:
            raise ModelError(f"parameter '{name}' declared twice", element, source)
        out[name] = sp.Symbol(name)
    return out


def _tokens(text: str):
    """Split ``text`` into (kind, string) tokens; anything else is an error."""
    pos, out = 0, []
    text = text.rstrip()
    while pos < len(text):
        m = _TOKEN_RE.match(text, pos)
        if not m or m.end() == pos:
            bad = text[pos:].lstrip()[:1]
            raise ParseError(f"unexpected character {bad!r}")
        kind = m.lastgroup
        out.append((kind, m.group(kind)))
        pos = m.end()
    return out


class _UnknownName(Exception):
    pass


class _ValueProblem(Exception):
    """A constant in the expression that is not a finite real float64."""


class _Parser:
    """Recursive descent over the token list (grammar in :mod:`armdyn.io.expressions`)."""

    def __init__(self, tokens, parameters: Mapping[str, sp.Symbol]):
        self.tokens = tokens
        self.i = 0
        self.parameters = parameters
        self.depth = 0
        self.floats: dict = {}  # constant node -> its float64 value (see bounded)
        self.calls = 0  # function calls open around the current position
        self.started = time.process_time()

    def nested(self, parse):
        """``parse()`` one level deeper; refused beyond MAX_DEPTH (the recursion would
        otherwise end in RecursionError, or SymPy's own, on ~200 parentheses)."""
        self.depth += 1
        try:
            if self.depth > MAX_DEPTH:
                raise ParseError(f"nested more than {MAX_DEPTH} levels deep")
            return self.bounded(parse())
        finally:
            self.depth -= 1

    def bounded(self, value):
        """``value``, unless it is a constant (no parameter in it) or has a constant part
        (the numeric coefficient of a product, the constant term of a sum) that is not a
        finite real float64. SymPy keeps constants exact and its floats have unbounded
        exponents, so without this ``sin(cosh(999**2))`` makes mpmath compute a million
        digits of pi (when anything asks whether it is real), ``sinh(7...7)`` leaves
        mpmath's global precision beyond what it can convert, ``sin(exp(1e300))`` reaches
        the interpreter's int-to-float limits, and ``m1*1e300*1e300`` overflows once
        ``m1`` is bound. Values are memoised by node (see :func:`.expression_bounds.constant_problem`)."""
        if time.process_time() - self.started > MAX_SECONDS:
            raise ParseError(f"more than {MAX_SECONDS:g} s of CPU time to read it (too complex)")
        if not isinstance(value, sp.Basic):
            return value
        if value.free_symbols:
            if not (value.is_Add or value.is_Mul):
                return value
            constant = [a for a in value.args if not a.free_symbols]
            if not constant:
                return value
            part = value.func(*constant)
        else:
            part = value
        problem = constant_problem(part, self.floats)
        if problem:
            raise _ValueProblem(f"the value {clip(str(part))} is {problem}")
        return value

    def peek(self):
        return self.tokens[self.i] if self.i < len(self.tokens) else (None, None)

    def take(self, op=None):
        kind, tok = self.peek()
        if kind is None:
            raise ParseError(f"missing '{op}'" if op else "unexpected end")
        if op is not None and tok != op:
            raise ParseError(f"expected '{op}', found '{tok}'")
        self.i += 1
        return kind, tok

    def parse(self):
        if not self.tokens:
            raise ParseError("empty expression")
        value = self.expr()
        if self.i != len(self.tokens):
            raise ParseError(f"unexpected '{self.tokens[self.i][1]}'")
        return value

    def expr(self):
        # the terms are collected and added once: adding them one by one re-sorts the
        # growing sum each time (quadratic: 1000 terms took seconds)
        terms = [self.term()]
        while self.peek()[1] in ("+", "-"):
            _, op = self.take()
            rhs = self.term()
            terms.append(rhs if op == "+" else -rhs)
        return self.bounded(sp.Add(*terms)) if len(terms) > 1 else terms[0]

    def term(self):
        factors = [self.unary()]
        while self.peek()[1] in ("*", "/"):
            _, op = self.take()
            rhs = self.unary()
            factors.append(rhs if op == "*" else self.bounded(sp.Pow(rhs, -1)))  # a / b is a * b**-1, as in SymPy
        if len(factors) == 1:
            return factors[0]
        value = self.bounded(sp.Mul(*factors))
        check_combined_exponents(value)
        return value

    def unary(self):
        if self.peek()[1] in ("+", "-"):
            _, op = self.take()
            value = self.nested(self.unary)
            return value if op == "+" else -value
        return self.power()

    def power(self):
        base = self.atom()
        if self.peek()[1] in ("**", "^"):
            self.take()
            exponent = self.nested(self.unary)
            check_power_size(base, exponent)
            value = self.bounded(power(base, exponent))
            check_combined_exponents(value)  # SymPy folds (a**k)**m into a**(k m)
            return value
        return base

    def atom(self):
        kind, tok = self.take()
        if kind == "number":
            if any(c in tok for c in ".eE"):
                # through a float64, as a YAML float would be: sp.Float("1e999999") alone
                # takes minutes, and such a number is no model value
                x = float(tok)
                if not math.isfinite(x):
                    raise ParseError(f"the number {clip(tok)} is beyond the float64 range")
                return sp.Float(x)
            if len(tok) > MAX_INT_DIGITS:  # Python itself refuses int() of > 4300 digits
                raise ParseError(
                    f"an integer of {len(tok)} digits is beyond the float64 range (at most {MAX_INT_DIGITS} digits)"
                )
            return self.bounded(sp.Integer(tok))
        if tok == "(":
            value = self.nested(self.expr)
            self.take(")")
            return value
        if kind == "name":
            if tok in self.parameters:
                return self.parameters[tok]
            if tok in CONSTANTS:
                return CONSTANTS[tok]
            if tok in FUNCTIONS:
                func, nargs = FUNCTIONS[tok]
                self.take("(")
                self.calls += 1
                if self.calls > MAX_CALL_DEPTH:
                    raise ParseError(f"function calls nested more than {MAX_CALL_DEPTH} deep")
                args = [self.nested(self.expr)]
                while self.peek()[1] == ",":
                    self.take()
                    args.append(self.nested(self.expr))
                self.take(")")
                self.calls -= 1
                if len(args) != nargs:
                    raise ParseError(f"{tok}() takes {nargs} argument(s), got {len(args)}")
                if func is sp.sqrt:  # sqrt(x**2) is (x**2)**(1/2): see power
                    return self.bounded(power(args[0], sp.S.Half))
                return self.bounded(func(*args))
            raise _UnknownName(tok)
        raise ParseError(f"unexpected '{tok}'")


def parse_expression(
    value,
    parameters: Mapping[str, sp.Symbol],
    element: str | None = None,
    source: str | None = None,
    what: str | None = None,
) -> sp.Expr:
    """A model-file value as a SymPy expression.

    value:      int, float, SymPy expression, or a string (grammar in :mod:`armdyn.io.expressions`).
    parameters: name -> Symbol of the declared parameters (the only names allowed
                besides :data:`FUNCTIONS` and :data:`CONSTANTS`).
    element, source: where the value sits, for the error message.
    what:       the field's name (e.g. ``"xyz"``), prefixed to error messages.

    Raises ModelError for an unknown name, an unparseable string, a value of the wrong
    type (bool, None, list...) or a result that is not finite (``1/0``).
    """
    prefix = f"{what}: " if what else ""
    if isinstance(value, bool) or value is None:
        raise ModelError(f"{prefix}expected a number or expression, got {shown(value)}", element, source)
    if isinstance(value, numbers.Integral):
        return sp.Integer(int(value))
    if isinstance(value, numbers.Real) and not isinstance(value, sp.Basic):
        if not math.isfinite(value):  # YAML's .nan / .inf
            raise ModelError(f"{prefix}the value {value} is not finite", element, source)
        result = sp.Float(float(value))
    elif isinstance(value, sp.Basic):
        stray = value.free_symbols - set(parameters.values())
        if stray:
            names = ", ".join(sorted(str(s) for s in stray))
            raise ModelError(f"{prefix}unknown parameter(s) {names} in expression '{value}'", element, source)
        result = value
    elif isinstance(value, str):
        if len(value) > MAX_LENGTH:
            message = f"{prefix}expression of {len(value)} characters is longer than {MAX_LENGTH}: {quoted(value)}"
            raise ModelError(message, element, source)
        try:
            result = _Parser(_tokens(value), parameters).parse()
        except _UnknownName as exc:
            message = f"{prefix}unknown parameter '{exc}' in expression {quoted(value)}"
            raise ModelError(message, element, source) from None
        except ParseError as exc:
            raise ModelError(f"{prefix}cannot parse expression {quoted(value)} ({exc})", element, source) from None
        except _ValueProblem as exc:
            raise ModelError(f"{prefix}expression {quoted(value)}: {exc}", element, source) from None
        except (TypeError, ValueError, ZeroDivisionError, OverflowError) as exc:
            raise ModelError(f"{prefix}cannot evaluate expression {quoted(value)} ({exc})", element, source) from None
    else:
        raise ModelError(
            f"{prefix}expected a number or expression, got {type(value).__name__} {shown(value)}", element, source
        )
    if result.has(sp.zoo, sp.nan, sp.oo, -sp.oo):
        raise ModelError(f"{prefix}expression {quoted(value)} is not finite ({clip(str(result), 60)})", element, source)
    if result.has(sp.I):
        raise ModelError(f"{prefix}expression {quoted(value)} is not real ({clip(str(result), 60)})", element, source)
    if not result.free_symbols:
        # a constant must be a finite float64 (exp(exp(exp(100))), 1.5**(10**10): no)
        if not math.isfinite(float_value(result)):
            message = f"{prefix}expression {quoted(value)} is not a finite real float64 number"
            raise ModelError(message, element, source)
    elif not isinstance(value, str) and result.is_real is False:
        # (a parsed string had every constant part checked real as it was built; asking
        # SymPy rebuilds what power left unevaluated, in exponential time)
        raise ModelError(f"{prefix}expression {quoted(value)} is not real ({clip(str(result), 60)})", element, source)
    return result


def is_zero(expr) -> bool:
    """True if ``expr`` is identically zero (``0``, ``0.0``); False for symbols."""
    return sp.sympify(expr).is_zero is True
