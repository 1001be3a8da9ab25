"""3-vector arithmetic on plain sequences of SymPy expressions, for the customized
algorithms' straight-line programs.

A vector is a sequence of three expressions, a 3x3 matrix a sequence of three rows
(``A[i][k]``); every function returns lists. SymPy's Matrix goes through its
DomainMatrix machinery, about ten times slower for these small products than the same
sums written out, and creating one costs tens of microseconds.

Products and sums skip the integer zeros and ones before SymPy sees them
(:func:`times`, :func:`plus`): SymPy would give the same result (``0*x = 0``,
``1*x = x``, ``x + 0 = x``) but only after building, hashing and caching the trivial
expression, and the frames of DH arms are mostly zeros and ones (more than half of the
products a customized program writes down are by one of them). The results are the
same SymPy objects as SymPy's own arithmetic gives; so are those of :func:`expanded`
and :func:`expanded_times`, which skip SymPy's expand where its result is known.
"""

from __future__ import annotations

import sympy as sp

ZERO, ONE = sp.S.Zero, sp.S.One

#: the entries of a symmetric 3x3 matrix on and above the diagonal, in the order of the
#: standard parameters (XX, XY, YY, XZ, YZ, ZZ)
UPPER = ((0, 0), (0, 1), (1, 1), (0, 2), (1, 2), (2, 2))


def times(a, b):
    """a b, without building the product when a factor is the integer 0 or 1."""
    if a is ZERO or b is ZERO:
        return ZERO
    if a is ONE:
        return b
    if b is ONE:
        return a
    return a * b


def plus(*terms):
    """The sum of ``terms``, without the integer zeros (0 for none)."""
    terms = [t for t in terms if t is not ZERO]
    if not terms:
        return ZERO
    return terms[0] if len(terms) == 1 else sp.Add(*terms)


def minus(a, b):
    """a - b, without building the sum when a term is the integer 0."""
    if b is ZERO:
        return a
    return -b if a is ZERO else a - b


def expanded(e):
    """``sp.expand(e)``, without SymPy's expansion passes when ``e`` is already a sum of
    monomials (numbers, symbols and their positive integer powers, multiplied): expand
    returns those unchanged, and even then costs about a millisecond on a cold cache."""
    return e if all(_is_monomial(t) for t in sp.Add.make_args(e)) else sp.expand(e)


def expanded_times(a, b):
    """a b, expanded (``sp.expand(a*b)``) when a and b are sums of monomials with rational
    coefficients: the sum of the products of their terms, the one expanded form of the
    product, without expand's passes over the tree (with float coefficients, the order in
    which expand adds up like terms could round differently: then ``a*b``)."""
    A, B = sp.Add.make_args(a), sp.Add.make_args(b)
    if len(A) * len(B) == 1 or not all(_is_monomial(t, rational=True) for t in (*A, *B)):
        return times(a, b)
    return plus(*[times(s, t) for s in A for t in B])


def _is_monomial(t, rational: bool = False) -> bool:
    """t is a number (a rational one if ``rational``), a symbol, a positive integer power
    of a symbol, or a product of those."""
    if t.is_Mul:
        return all(not f.is_Mul and _is_monomial(f, rational) for f in t.args)
    if t.is_Pow:
        return t.base.is_Symbol and t.exp.is_Integer and t.exp > 0
    return t.is_Symbol or (t.is_Rational if rational else t.is_Number)


def rows(A) -> list:
    """The rows of a 3x3 matrix (a SymPy Matrix or a sequence of rows) as lists."""
    return A.tolist() if isinstance(A, sp.MatrixBase) else [list(r) for r in A]


def dot(a, c):
    """a . c."""
    return plus(*[times(a[i], c[i]) for i in range(3)])


def mv(A, v) -> list:
    """A v (3,)."""
    return [plus(*[times(A[i][k], v[k]) for k in range(3)]) for i in range(3)]


def mtv(A, v) -> list:
    """A^T v (3,)."""
    return [plus(*[times(A[k][i], v[k]) for k in range(3)]) for i in range(3)]


def cross(a, c) -> list:
    """a x c (3,)."""
    return [
        minus(times(a[1], c[2]), times(a[2], c[1])),
        minus(times(a[2], c[0]), times(a[0], c[2])),
        minus(times(a[0], c[1]), times(a[1], c[0])),
    ]


def vadd(*vs) -> list:
    """The sum of the vectors (3,)."""
    return [plus(*[v[i] for v in vs]) for i in range(3)]


def vscale(x, a) -> list:
    """x a (3,)."""
    return [times(x, e) for e in a]


def turned_about_z(R0, c, s) -> list:
    """``R0 Rz`` (3x3 rows) for the rotation about z with cosine ``c`` and sine ``s``;
    ``R0``: rows."""
    return [[plus(times(r[0], c), times(r[1], s)), minus(times(r[1], c), times(r[0], s)), r[2]] for r in R0]
