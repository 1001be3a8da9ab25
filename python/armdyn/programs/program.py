"""Straight-line programs: the form generated code takes before it is printed.

A :class:`Program` is a list of assignments ``t = expr`` (each ``expr`` built from
inputs, parameters and earlier temporaries) and a list of outputs. The customized
symbolic algorithms (:mod:`armdyn.programs.customized_ne`,
:mod:`armdyn.programs.composite_mass_matrix`) build one directly with a
:class:`Builder`, naming each intermediate quantity as Khalil's customized
Newton-Euler does; any other SymPy expression becomes one through common
subexpression elimination (:func:`from_expressions`).

Operation counts follow ``sympy.count_ops(visual=True)`` on the assignments and the
outputs: ``mul`` = MUL + DIV + POW, ``add`` = ADD + SUB, ``sin_cos`` = SIN + COS
(negation, NEG, costs nothing: it folds into the next operation).
"""

from __future__ import annotations

import re
from dataclasses import dataclass, field

import sympy as sp


def is_value(expr, value: float) -> bool:
    """``expr`` is the number ``value``, exact or float (SymPy 1.14: ``Float(0.0) != 0``, so
    frames read from URDF, whose entries are Floats, need this test)."""
    expr = sp.sympify(expr)
    return bool(expr.is_Number) and float(expr) == float(value)


def is_atom(expr) -> bool:
    """A value that needs no temporary: a number, a symbol, or minus a symbol."""
    if expr.is_Atom:
        return True
    if expr.is_Mul and len(expr.args) == 2 and expr.args[0] == -1 and expr.args[1].is_Symbol:
        return True
    return False


@dataclass
class Program:
    """``assignments``: list of (Symbol, expr) in order of evaluation;
    ``outputs``: flat list of expressions (row-major when ``shape`` is 2-d);
    ``shape``: (n,) or (rows, cols) of the output."""

    assignments: list = field(default_factory=list)
    outputs: list = field(default_factory=list)
    shape: tuple = ()

    def pruned(self) -> "Program":
        """The program without assignments no output depends on (dead code)."""
        needed = set()
        for e in self.outputs:
            needed |= sp.sympify(e).free_symbols
        kept = []
        for s, e in reversed(self.assignments):
            if s in needed:
                kept.append((s, e))
                needed |= e.free_symbols
        return Program(kept[::-1], list(self.outputs), self.shape)

    def inlined(self) -> list:
        """The outputs with every temporary substituted back (expressions of the inputs).

        For proofs on small arms; the expressions grow with the program's depth."""
        values: dict = {}
        for s, e in self.assignments:
            values[s] = e.xreplace(values)
        return [sp.sympify(e).xreplace(values) for e in self.outputs]

    def evaluate(self, values: dict) -> list:
        """Outputs at numeric ``values`` (symbol -> float), evaluated line by line."""
        env = dict(values)
        for s, e in self.assignments:
            env[s] = _number(e, env)
        return [_number(sp.sympify(e), env) for e in self.outputs]

    def operation_counts(self) -> dict:
        """{'mul', 'add', 'sin_cos', 'other', 'total'} counted as count_ops(visual=True)."""
        total = {"mul": 0, "add": 0, "sin_cos": 0, "other": 0}
        kinds = {
            "MUL": "mul",
            "DIV": "mul",
            "POW": "mul",
            "ADD": "add",
            "SUB": "add",
            "SIN": "sin_cos",
            "COS": "sin_cos",
        }
        exprs = [e for _, e in self.assignments] + [sp.sympify(e) for e in self.outputs]
        for e in exprs:
            fast = _fast_count(e)
            if fast is not None:
                for key, n in fast.items():
                    total[key] += n
                continue
            visual = sp.count_ops(e, visual=True)
            if visual == 0:
                continue
            for sym, n in visual.as_coefficients_dict().items():
                name = sym.name
                if name == "NEG":
                    continue
                total[kinds.get(name, "other")] += int(n)
        total["total"] = total["mul"] + total["add"]
        return total


def _fast_count(e):
    """count_ops(visual=True) for sums of products of symbols, integers, floats,
    positive integer powers, sin and cos (what the builders emit): ADD+SUB = terms - 1,
    MUL = factors - 1 (a coefficient other than +-1 is a factor; -1 is a free NEG),
    POW per power. None for anything else (then SymPy counts)."""
    out = {"mul": 0, "add": 0, "sin_cos": 0, "other": 0}
    stack = [e]
    while stack:
        x = stack.pop()
        if x.is_Atom:
            if x.is_Rational and not x.is_Integer:
                return None
            continue
        if x.is_Add:
            out["add"] += len(x.args) - 1
            stack.extend(x.args)
        elif x.is_Mul:
            factors = [a for a in x.args if not (a.is_Number and abs(a) == 1)]
            if any(a.is_Rational and not a.is_Integer for a in factors):
                return None
            out["mul"] += max(len(factors) - 1, 0)
            stack.extend(factors)
        elif x.is_Pow and x.exp.is_Integer and x.exp > 1:
            out["mul"] += 1
            stack.append(x.base)
        elif isinstance(x, (sp.sin, sp.cos)):
            out["sin_cos"] += 1
            stack.append(x.args[0])
        else:
            return None
    return out


def _number(expr, env):
    value = expr.xreplace(env) if expr.free_symbols else expr
    return float(value)


def names(symbols) -> set:
    """The names of ``symbols`` as printed (``str(s)``; a plain Symbol's read off
    directly: SymPy's printer costs microseconds a call, and the builders ask for
    hundreds)."""
    return {s.name if type(s) is sp.Symbol else str(s) for s in symbols}


def _key(expr, terms, negated: bool = False):
    """A dictionary key for ``expr`` (or ``-expr``): a sum by its terms and their
    coefficients (``terms``: ``expr.as_coefficients_dict().items()``, None when ``expr``
    is not a sum), so that the key of ``-expr`` costs no new SymPy sum (negating a sum
    rebuilds it: the most expensive step of building a program)."""
    if terms is not None:
        return ("+", frozenset(((t, -c) for t, c in terms) if negated else terms))
    return -expr if negated else expr


class Builder:
    """Collects assignments: :meth:`let` names a non-trivial expression as a temporary
    and returns the symbol; numbers, symbols and their negatives are returned as they
    are, so zeros and ones propagate (SymPy drops ``0*x`` and ``1*x`` on construction)."""

    def __init__(self, reserved=()):
        self.assignments: list = []
        self._used = names(reserved)
        self._memo: dict = {}

    def name(self, hint: str) -> sp.Symbol:
        base = re.sub(r"\W", "_", hint) or "t"
        name, k = base, 1
        while name in self._used:
            k += 1
            name = f"{base}_{k}"
        self._used.add(name)
        return sp.Symbol(name)

    def let(self, expr, hint: str = "t"):
        expr = sp.sympify(expr)
        if is_atom(expr):
            return expr
        # the same expression computed twice is one temporary (e.g. a product of two
        # velocity components met in two cross products)
        terms = expr.as_coefficients_dict().items() if expr.is_Add else None
        key = _key(expr, terms)
        known = self._memo.get(key)
        if known is not None:
            return known
        neg = self._memo.get(_key(expr, terms, negated=True))
        if neg is not None:
            return -neg
        s = self.name(hint)
        self.assignments.append((s, expr))
        self._memo[key] = s
        return s

    def vector(self, v, hint: str) -> list:
        """The 3-vector ``v`` with each component named (``{hint}x``, ``{hint}y``, ``{hint}z``)."""
        return [self.let(v[k], f"{hint}{'xyz'[k]}") for k in range(3)]

    def program(self, outputs, shape) -> Program:
        return Program(list(self.assignments), list(outputs), tuple(shape)).pruned()


def from_expressions(exprs, shape, hint: str = "x", reserved=()) -> Program:
    """A program for arbitrary SymPy expressions by SymPy's common subexpression
    elimination (temporaries ``x0, x1, ...``)."""
    used = names(reserved)
    symbols = (sp.Symbol(f"{hint}{k}") for k in range(10**9) if f"{hint}{k}" not in used)
    replacements, reduced = sp.cse(list(exprs), symbols=symbols, order="none")
    return Program(list(replacements), list(reduced), tuple(shape)).pruned()
