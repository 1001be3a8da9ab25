"""Values written in SymPy syntax (``theta1_dot**2*l1``), as YAML submissions give them:
tokenised and parsed here with the same bounds as LaTeX values (number size, powers,
nesting, length); nothing is evaluated as Python (no ``sympify`` of the text)."""

from __future__ import annotations

import re

import sympy as sp

from .latex import (
    MAX_CALL_DEPTH,
    MAX_DEPTH,
    MAX_DIGITS,
    MAX_LENGTH,
    MAX_SYMBOLIC_EXPONENT,
    LatexError,
    UnknownSymbol,
    short_number,
)

#: functions a value in SymPy syntax may call
SYMPY_FUNCTIONS = {"sin", "cos", "tan", "exp", "log", "sqrt", "Abs", "sec", "csc", "cot"}
_BIG_POWER = re.compile(r"(\*\*|\^)\s*\(?\s*\d{4,}|\d+\s*(\*\*|\^)\s*\d+\s*(\*\*|\^)")
_SYNTAX = re.compile(r"[A-Za-z_][A-Za-z_0-9]*|\d+(?:\.\d*)?(?:[eE][-+]?\d+)?|\.\d+(?:[eE][-+]?\d+)?|\*\*|[-+*/^(),\s]")


def _check_numbers(text: str) -> None:
    """Refuse, before SymEngine computes it, a number of more than :data:`MAX_DIGITS`
    digits, written or produced by powers of powers (``((9**99)**99)**99``). The size
    (log10 of a bound of the magnitude) of every purely numeric part is estimated by one
    operator-precedence pass over the tokens, iterative (a sum of 10^5 terms is fine),
    evaluating nothing. ``text`` has passed the checks of :func:`parse_sympy_syntax`."""
    import math

    for m in re.finditer(r"\d+", text):
        if len(m.group(0)) > MAX_DIGITS:
            raise LatexError(f"a number with {len(m.group(0))} digits (at most {MAX_DIGITS})")
    tokens = [t for t in _SYNTAX.findall(text) if not t.isspace()]
    prec = {"+": 1, "-": 1, "*": 2, "/": 2, "**": 3, "^": 3}
    values: list = []  # log10 of a bound of the magnitude of each part's numbers (a symbol: 0)
    ops: list = []  # operators, "(" and "f(" (a function call)

    def reduce_one():
        op = ops.pop()
        if len(values) < 2:
            raise IndexError
        b, a = values.pop(), values.pop()
        if op in ("**", "^"):
            if b > 6:
                raise LatexError(f"an exact power with an exponent of about 10^{int(b)}")
            size = a * 10**b  # (c x)^e holds c^e: SymEngine distributes an integer power
            if size > MAX_DIGITS:
                raise LatexError(f"a number of about {int(size)} digits (at most {MAX_DIGITS})")
        elif op in ("*", "/"):
            size = a + b
        else:  # |u + v| <= |u| + |v|: a sum of n terms grows by log10(n), not by n
            size = max(a, b) + math.log10(1 + 10 ** (min(a, b) - max(a, b)))
        values.append(size)

    try:
        previous = None
        for k, tok in enumerate(tokens):
            unary = tok in ("+", "-") and (previous is None or previous in prec or previous in ("(", ","))
            if unary:
                pass  # a sign does not change a magnitude
            elif tok in prec:
                right = tok in ("**", "^")
                while (
                    ops and ops[-1] in prec and (prec[ops[-1]] > prec[tok] or prec[ops[-1]] == prec[tok] and not right)
                ):
                    reduce_one()
                ops.append(tok)
            elif tok == "(":
                ops.append("f(" if previous is not None and (previous[0].isalpha() or previous[0] == "_") else "(")
                if ops[-1] == "f(" and ops.count("f(") > MAX_CALL_DEPTH:
                    raise LatexError(f"nesting of functions deeper than {MAX_CALL_DEPTH} levels")
            elif tok in (")", ","):
                while ops and ops[-1] not in ("(", "f("):
                    reduce_one()
                if tok == ",":
                    values.pop()  # an argument of a function: checked, not a magnitude
                else:
                    opener = ops.pop()
                    if opener == "f(":
                        values.pop()
                        values.append(0.0)  # sin, cos, exp...: left symbolic, no big integer
            elif tok[0].isdigit() or tok[0] == ".":
                number = float(tok) if len(tok) < 300 else float("inf")
                values.append(max(0.0, math.log10(number)) if 0 < number < float("inf") else 0.0)
            elif k + 1 < len(tokens) and tokens[k + 1] == "(":
                pass  # a function's name: its call is marked at the "("
            else:
                values.append(0.0)  # a symbol: magnitude 1 (only its numeric coefficient grows)
            previous = tok
        while ops:
            reduce_one()
    except (IndexError, OverflowError):  # not LatexError (a ValueError): that is the answer
        return  # malformed: SymEngine's parser reports it


def parse_sympy_syntax(text: str, names: dict, symengine: bool = False):
    """An expression in SymPy syntax (``l1*theta1_dot**2 + g*sin(theta1)``) as SymPy.

    Parsed by SymEngine's C++ parser (no Python ``eval``) after checks that keep it
    bounded: only names, numbers, ``+ - * / ** ^ ( ) ,``; parentheses nested at most
    :data:`MAX_DEPTH` deep; no exact power with a huge exponent, no functions nested beyond
    :data:`MAX_CALL_DEPTH`; then every name must be
    one of ``names`` (name -> SymPy symbol) or a whitelisted function, and no power of
    them have an exponent beyond :data:`MAX_SYMBOLIC_EXPONENT`. ``symengine``:
    return the SymEngine expression (no conversion: large generated derivations)."""
    import symengine as se

    if len(text) > 50 * MAX_LENGTH:
        raise LatexError(f"expression too long ({len(text)} characters)")
    pos, depth = 0, 0
    for m in _SYNTAX.finditer(text):
        if m.start() != pos:
            raise LatexError(f"unexpected character {text[pos]!r}")
        pos = m.end()
        tok = m.group(0)
        if tok == "(":
            depth += 1
            if depth > MAX_DEPTH:
                raise LatexError(f"parentheses nested deeper than {MAX_DEPTH} levels")
        elif tok == ")":
            depth -= 1
            if depth < 0:
                raise LatexError("unbalanced ')'")
    if pos != len(text):
        raise LatexError(f"unexpected character {text[pos]!r}")
    if depth:
        raise LatexError("unbalanced '('")
    if _BIG_POWER.search(text):
        raise LatexError("an exact power with a huge exponent")
    _check_numbers(text)
    try:
        value = se.sympify(text)
    except Exception as exc:  # noqa: BLE001 - SymEngine's parse errors have several types
        raise LatexError(f"cannot parse {text[:60]!r} ({exc})") from None
    for fn in value.atoms(se.FunctionSymbol) if hasattr(se, "FunctionSymbol") else ():
        raise LatexError(f"unknown function {fn}")
    for power in value.atoms(se.Pow):
        if power.exp.is_Number and power.base.free_symbols and abs(power.exp) > MAX_SYMBOLIC_EXPONENT:
            raise LatexError(f"an exponent of {short_number(power.exp)} (at most {MAX_SYMBOLIC_EXPONENT})")
    table = {}
    for sym in value.free_symbols:
        name = str(sym)
        if name not in names:
            raise UnknownSymbol(f"unknown symbol {name}")
        table[sym] = se.sympify(names[name])
    value = value.xreplace(table) if table else value
    return value if symengine else sp.sympify(value)
