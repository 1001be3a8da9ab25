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
powers with a non-integer exponent are left as written (see :func:`_power`).

This module also converts the shaped values of a model (scalars, 3-vectors,
3x3 matrices, inertia tensors, rotations) with the same rules; every failure is a
:class:`~armdyn.errors.ModelError` naming the offending expression.
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
#: Most digits an exact power (integer or rational base and exponent) may produce.
MAX_POWER_DIGITS = 10_000
#: Most digits of an integer literal (a float64 is at most about 1.8e308).
MAX_INT_DIGITS = 400
#: Largest |numerator| of a rational exponent (``a**(10**20)`` would hang once bound; SymPy
#: splits ``x**n`` into real and imaginary parts by expanding ``(a + i b)**n``, in time
#: growing as n^3: 0.3 s for n = 100, minutes for n = 1000).
MAX_EXPONENT = 100
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
            raise _ParseError(f"unexpected character {bad!r}")
        kind = m.lastgroup
        out.append((kind, m.group(kind)))
        pos = m.end()
    return out


class _ParseError(Exception):
    pass


class _UnknownName(Exception):
    pass


class _ValueProblem(Exception):
    """A constant in the expression that is not a finite real float64."""


class _Parser:
    """Recursive descent over the token list (grammar in the module docstring)."""

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
                raise _ParseError(f"nested more than {MAX_DEPTH} levels deep")
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
        ``m1`` is bound. Values are memoised by node (see :func:`_float_node`)."""
        if time.process_time() - self.started > MAX_SECONDS:
            raise _ParseError(f"more than {MAX_SECONDS:g} s of CPU time to read it (too complex)")
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
        problem = _constant_problem(part, self.floats)
        if problem:
            raise _ValueProblem(f"the value {_clip(str(part))} is {problem}")
        return value

    def peek(self):
        return self.tokens[self.i] if self.i < len(self.tokens) else (None, None)

    def take(self, op=None):
        kind, tok = self.peek()
        if kind is None:
            raise _ParseError(f"missing '{op}'" if op else "unexpected end")
        if op is not None and tok != op:
            raise _ParseError(f"expected '{op}', found '{tok}'")
        self.i += 1
        return kind, tok

    def parse(self):
        if not self.tokens:
            raise _ParseError("empty expression")
        value = self.expr()
        if self.i != len(self.tokens):
            raise _ParseError(f"unexpected '{self.tokens[self.i][1]}'")
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
        _check_combined_exponents(value)
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
            _check_power_size(base, exponent)
            value = self.bounded(_power(base, exponent))
            _check_combined_exponents(value)  # SymPy folds (a**k)**m into a**(k m)
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
                    raise _ParseError(f"the number {_clip(tok)} is beyond the float64 range")
                return sp.Float(x)
            if len(tok) > MAX_INT_DIGITS:  # Python itself refuses int() of > 4300 digits
                raise _ParseError(
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
                    raise _ParseError(f"function calls nested more than {MAX_CALL_DEPTH} deep")
                args = [self.nested(self.expr)]
                while self.peek()[1] == ",":
                    self.take()
                    args.append(self.nested(self.expr))
                self.take(")")
                self.calls -= 1
                if len(args) != nargs:
                    raise _ParseError(f"{tok}() takes {nargs} argument(s), got {len(args)}")
                if func is sp.sqrt:  # sqrt(x**2) is (x**2)**(1/2): see _power
                    return self.bounded(_power(args[0], sp.S.Half))
                return self.bounded(func(*args))
            raise _UnknownName(tok)
        raise _ParseError(f"unexpected '{tok}'")


def _clip(text: str, limit: int = 30) -> str:
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


def _constant_problem(expr, memo: dict) -> str | None:
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


def _power(base, exponent):
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


def _check_power_size(base, exponent) -> None:
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
            raise _ParseError(
                f"the power {_clip(str(base))}**{_clip(str(exponent))} is too large (exponents up "
                f"to {MAX_EXPONENT}, results within float64's range)"
            )
        return
    if exponent.free_symbols:
        # b**(y + 999) is b**999 * b**y to SymPy when it works exactly (cos() looks for a
        # multiple of pi with polynomial gcds: 1e-300**999 as an exact fraction has 300000
        # digits), so the constant term and the coefficient count as exponents too
        for constant in (exponent.as_coeff_Add()[0], exponent.as_coeff_Mul()[0]):
            if constant.is_Number and constant not in (0, 1):
                _check_power_size(base, constant)
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
        raise _ParseError(
            f"the power {_clip(str(base))}**{_clip(str(exponent))} is too large (exponents up to "
            f"{MAX_EXPONENT}, exact results up to {MAX_POWER_DIGITS} digits)"
        )


def _check_combined_exponents(value) -> None:
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
            raise _ParseError(f"the power {_clip(str(f))} has an exponent beyond {MAX_EXPONENT}")


def parse_expression(
    value,
    parameters: Mapping[str, sp.Symbol],
    element: str | None = None,
    source: str | None = None,
    what: str | None = None,
) -> sp.Expr:
    """A model-file value as a SymPy expression.

    value:      int, float, SymPy expression, or a string (grammar in the module docstring).
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
        except _ParseError as exc:
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
        raise ModelError(
            f"{prefix}expression {quoted(value)} is not finite ({_clip(str(result), 60)})", element, source
        )
    if result.has(sp.I):
        raise ModelError(f"{prefix}expression {quoted(value)} is not real ({_clip(str(result), 60)})", element, source)
    if not result.free_symbols:
        # a constant must be a finite float64 (exp(exp(exp(100))), 1.5**(10**10): no)
        if not math.isfinite(float_value(result)):
            message = f"{prefix}expression {quoted(value)} is not a finite real float64 number"
            raise ModelError(message, element, source)
    elif not isinstance(value, str) and result.is_real is False:
        # (a parsed string had every constant part checked real as it was built; asking
        # SymPy rebuilds what _power left unevaluated, in exponential time)
        raise ModelError(f"{prefix}expression {quoted(value)} is not real ({_clip(str(result), 60)})", element, source)
    return result


def is_zero(expr) -> bool:
    """True if ``expr`` is identically zero (``0``, ``0.0``); False for symbols."""
    return sp.sympify(expr).is_zero is True


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
