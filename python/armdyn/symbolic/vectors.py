"""3-vector arithmetic on plain sequences of SymPy expressions, for the customized
algorithms' straight-line programs.

SymPy's Matrix products go through its DomainMatrix machinery, about ten times slower for
these small products than the same sums written out; every function returns a list of
three expressions (a (3, 3) Matrix for :func:`turned_about_z`)."""

from __future__ import annotations

import sympy as sp


def mv(A, v) -> list:
    """A v (3,)."""
    return [sp.Add(*[A[i, k] * v[k] for k in range(3)]) for i in range(3)]


def mtv(A, v) -> list:
    """A^T v (3,)."""
    return [sp.Add(*[A[k, i] * v[k] for k in range(3)]) for i in range(3)]


def cross(a, c) -> list:
    """a x c (3,)."""
    return [a[1] * c[2] - a[2] * c[1], a[2] * c[0] - a[0] * c[2], a[0] * c[1] - a[1] * c[0]]


def vadd(*vs) -> list:
    """The sum of the vectors (3,)."""
    return [sp.Add(*[v[i] for v in vs]) for i in range(3)]


def vscale(x, a) -> list:
    """x a (3,)."""
    return [x * e for e in a]


def turned_about_z(R0, c, s) -> sp.Matrix:
    """``R0 Rz`` (3x3) for the rotation about z with cosine ``c`` and sine ``s``."""
    return sp.Matrix(3, 3, lambda i, k: R0[i, 0] * c + R0[i, 1] * s if k == 0 else
                     -R0[i, 0] * s + R0[i, 1] * c if k == 1 else R0[i, 2])
