"""Exact evaluation of symbolic matrices at random rational points: ranks and dependencies.

What :mod:`armdyn.identification` decides its base parameters with: a matrix (a regressor)
is evaluated at random exact points (rational points of the unit circle for sin/cos of an
angle, small rationals for the rest), as Fractions or modulo the prime :data:`PRIME`;
stacked over states, its reduced row echelon form gives the rank and the pivots, and
rational reconstruction turns a residue back into a fraction.
"""

from __future__ import annotations

import math
import random
from fractions import Fraction

import sympy as sp

from .symbolic import dag


def nonzero_fraction(rng: random.Random) -> Fraction:
    """A random nonzero small rational (a zero length would make the geometry special)."""
    return Fraction(rng.choice([-1, 1]) * rng.randint(1, 30), rng.randint(1, 12))


def _exact_point(symbols_sin_cos, scalars, rng: random.Random):
    """Random exact values: rational points of the unit circle for each angle, small
    rationals for everything else."""
    values = {}
    for x in symbols_sin_cos:
        t = Fraction(rng.randint(-20, 20), rng.randint(1, 20))
        values[sp.sin(x)] = 2 * t / (1 + t * t)
        values[sp.cos(x)] = (1 - t * t) / (1 + t * t)
    for s in scalars:
        values[s] = Fraction(rng.randint(-30, 30), rng.randint(1, 12))
    return values


#: the Mersenne prime 2^127 - 1: ranks and dependencies are computed modulo it (exact
#: integer arithmetic, fast), coefficients recovered by rational reconstruction and checked
#: in exact rational arithmetic at a further random point
PRIME = 2**127 - 1


def _exact_evaluate(matrix: sp.Matrix, values: dict, modulus: int | None = None) -> list[list]:
    """Entries of ``matrix`` at exact rational ``values`` (keys: symbols, sin(x), cos(x);
    values: Fractions), shared subexpressions visited once. With ``modulus``, the
    entries modulo that prime (ints), which is much faster."""
    memo: dict = {}
    p = modulus

    def num(x: Fraction):
        return x if p is None else x.numerator * pow(x.denominator, -1, p) % p

    def node(e, args):
        if e in values:
            return num(values[e])
        if e.is_Rational:
            return num(Fraction(int(e.p), int(e.q)))
        if e.is_Float:  # the decimal as written (0.4318 -> 2159/5000): small exact numbers
            return num(Fraction(repr(float(e))))
        if e.is_Add:
            r = sum(args[1:], args[0])
            return r if p is None else r % p
        if e.is_Mul:
            r = args[0]
            for a in args[1:]:
                r = r * a if p is None else r * a % p
            return r
        if e.is_Pow and e.exp.is_Integer:
            return args[0] ** int(e.exp) if p is None else pow(args[0], int(e.exp), p)
        if isinstance(e, sp.sign):
            if p is not None:  # the sign of the rational value, not of its residue
                x = values[e.args[0]]
            else:
                x = args[0]
            return num(Fraction((x > 0) - (x < 0)))
        if e.is_Symbol:
            raise KeyError(f"no value for symbol {e}")
        raise ValueError(f"cannot evaluate {e} exactly (only polynomials in parameters, sin/cos of symbols and sign)")

    def ev(entry):
        return dag.fold(sp.sympify(entry), node, memo, leaf=values.__contains__)

    return [[ev(matrix[i, j]) for j in range(matrix.shape[1])] for i in range(matrix.shape[0])]


def rational(a: int, p: int = PRIME) -> Fraction:
    """The fraction n/d with |n|, d <= sqrt(p/2) congruent to ``a`` mod p (rational
    reconstruction by the extended Euclidean algorithm, Wang 1981)."""
    bound = math.isqrt(p // 2)
    r0, r1, s0, s1 = p, a % p, 0, 1
    while r1 > bound:
        q = r0 // r1
        r0, r1, s0, s1 = r1, r0 - q * r1, s1, s0 - q * s1
    if s1 == 0 or abs(s1) > bound:
        raise ArithmeticError("rational reconstruction failed")
    return Fraction(r1, s1)


def angles_and_scalars(Y: sp.Matrix):
    """Symbols that appear inside sin/cos (angles) and the others."""
    angles, scalars, seen = set(), set(), set()
    stack = list(set(Y))
    while stack:  # one visit per distinct subexpression
        e = stack.pop()
        if e in seen:
            continue
        seen.add(e)
        if isinstance(e, (sp.sin, sp.cos)):
            if not e.args[0].is_Symbol:
                raise ValueError(f"cannot evaluate {e} exactly: only sin/cos of a single symbol are handled")
            angles.add(e.args[0])
        elif e.is_Symbol:
            scalars.add(e)
        stack.extend(e.args)
    return sorted(angles, key=str), sorted(scalars - angles, key=str)


def stacked_exact(Y: sp.Matrix, states: int, seed: int = 0, fixed: dict | None = None, modulus: int | None = None):
    """Y evaluated exactly at ``states`` random rational points, stacked: a list of rows
    (states * dof rows of Fractions, or of ints modulo ``modulus``). Symbols in ``fixed``
    (symbol -> Fraction) keep those values at every point (the geometry), the others
    change from point to point."""
    rng = random.Random(seed)
    angles, scalars = angles_and_scalars(Y)
    fixed = dict(fixed or {})
    rows = []
    for _ in range(states):
        values = _exact_point([a for a in angles if a not in fixed], [s for s in scalars if s not in fixed], rng)
        for s, v in fixed.items():
            if s in angles:
                t = v
                values[sp.sin(s)], values[sp.cos(s)] = 2 * t / (1 + t * t), (1 - t * t) / (1 + t * t)
            else:
                values[s] = v
        rows += _exact_evaluate(Y, values, modulus)
    return rows


def rref(rows: list[list], ncols: int, modulus: int | None = None):
    """Reduced row echelon form, in exact rational arithmetic (Fractions) or modulo a
    prime (ints): ``(R, pivots)``."""
    p = modulus
    A = [list(r) for r in rows]
    pivots, r = [], 0
    for c in range(ncols):
        piv = next((i for i in range(r, len(A)) if A[i][c] != 0), None)
        if piv is None:
            continue
        A[r], A[piv] = A[piv], A[r]
        inv = 1 / A[r][c] if p is None else pow(A[r][c], -1, p)
        A[r] = [x * inv for x in A[r]] if p is None else [x * inv % p for x in A[r]]
        for i in range(len(A)):
            if i != r and A[i][c] != 0:
                f = A[i][c]
                if p is None:
                    A[i] = [x - f * y for x, y in zip(A[i], A[r])]
                else:
                    A[i] = [(x - f * y) % p for x, y in zip(A[i], A[r])]
        pivots.append(c)
        r += 1
        if r == len(A):
            break
    return A[:r], pivots


def exact_rank(Y: sp.Matrix, states: int | None = None, seed: int = 0, state_symbols=()) -> int:
    """Rank of Y stacked over random rational states, in exact arithmetic modulo
    :data:`PRIME` (equal to the rank over the rationals but with probability ~1e-38 per
    pivot). Symbols other
    than ``state_symbols`` (the geometry, gravity) get one random value for all states."""
    states = states or (Y.shape[1] // max(Y.shape[0], 1) + 3)
    angles, scalars = angles_and_scalars(Y)
    rng = random.Random(seed + 1)
    fixed = {s: nonzero_fraction(rng) for s in angles + scalars if s not in set(state_symbols)}
    return len(rref(stacked_exact(Y, states, seed, fixed, PRIME), Y.shape[1], PRIME)[1])
