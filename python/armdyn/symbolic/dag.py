"""Operations on expressions as DAGs (shared subexpressions visited once).

A recursive derivation builds each result from its parent's: link 7's torque contains
link 1's velocity thousands of times over, as the same object. SymPy's ``free_symbols``
and ``xreplace`` walk the expanded tree and take exponentially long on such
expressions (minutes for a 7-dof arm with numeric URDF frames); these memoised versions
take time proportional to the number of distinct subexpressions.
"""

from __future__ import annotations

import numpy as np
import sympy as sp


def larger_than(expr, limit: int) -> bool:
    """True if the expanded tree of ``expr`` has more than ``limit`` nodes; stops
    counting at the limit, so it is cheap on huge expressions. Used to decide whether
    an exact check or a hand-style display is affordable."""
    for count, _ in enumerate(sp.preorder_traversal(expr)):
        if count > limit:
            return True
    return False


def free_symbols(exprs) -> set:
    """Union of the free symbols of ``exprs`` (an expression, a matrix or an iterable)."""
    seen, out = set(), set()
    stack = list(exprs) if not isinstance(exprs, sp.Basic) or isinstance(exprs, sp.MatrixBase) else [exprs]
    while stack:
        e = stack.pop()
        if e in seen:
            continue
        seen.add(e)
        if e.is_Symbol:
            out.add(e)
        else:
            stack.extend(e.args)
    return out


def xreplace(expr, mapping: dict):
    """``expr.xreplace(mapping)`` (or entrywise on a matrix), visiting shared
    subexpressions once."""
    if isinstance(expr, sp.MatrixBase):
        memo: dict = {}
        return expr.applyfunc(lambda e: _xreplace(e, mapping, memo))
    return _xreplace(expr, mapping, {})


def fold(root, node, memo: dict, leaf=None):
    """Evaluate the expression DAG under ``root`` bottom-up: ``node(e, results of e.args)``
    once per distinct subexpression (results kept in ``memo``, which callers may share
    between roots). ``e`` is a leaf, ``node(e, [])``, when it has no args, is a Number or
    ``leaf(e)`` is true. An iterative post-order walk: deep expressions must not hit the
    recursion limit."""
    stack = [(root, False)]
    while stack:
        e, ready = stack.pop()
        if e in memo:
            continue
        if not e.args or e.is_Number or (leaf is not None and leaf(e)):
            memo[e] = node(e, [])
        elif ready:
            memo[e] = node(e, [memo[a] for a in e.args])
        else:
            stack.append((e, True))
            stack.extend((a, False) for a in e.args if a not in memo)
    return memo[root]


def _xreplace(expr, mapping, memo):
    def node(e, args):
        if e in mapping:
            return mapping[e]
        if not args or all(a is b for a, b in zip(args, e.args)):
            return e
        return e.func(*args)

    return fold(sp.sympify(expr), node, memo, leaf=mapping.__contains__)


_NUMPY_FUNCS = {sp.sin: np.sin, sp.cos: np.cos, sp.tan: np.tan, sp.exp: np.exp, sp.log: np.log, sp.Abs: np.abs}


def evaluate(matrix: sp.Matrix, values: dict) -> np.ndarray:
    """Evaluate every entry of ``matrix`` (rows, cols) at arrays of symbol values (each
    (samples,)), giving (rows, cols, samples). Far cheaper than ``lambdify(cse=True)``
    for a one-off evaluation of a large derived expression."""
    samples = len(next(iter(values.values()))) if values else 1
    memo: dict = {}

    def node(e, args):
        if e.is_Number or e.is_NumberSymbol:
            return float(e)
        if e.is_Symbol:
            return values[e]
        if e.is_Add:
            return sum(args[1:], args[0])
        if e.is_Mul:
            r = args[0]
            for a in args[1:]:
                r = r * a
            return r
        if e.is_Pow:
            return np.power(args[0], args[1])
        if e.func in _NUMPY_FUNCS:
            return _NUMPY_FUNCS[e.func](args[0])
        f = sp.lambdify(list(e.free_symbols), e, modules="numpy")  # anything rarer
        return f(*(values[s] for s in e.free_symbols))

    rows, cols = matrix.shape
    out = np.empty((rows, cols, samples))
    for i in range(rows):
        for j in range(cols):
            out[i, j] = fold(sp.sympify(matrix[i, j]), node, memo)
    return out
