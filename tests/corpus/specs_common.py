"""Symbols and shorthand the spec modules transcribe the corpus in (plain SymPy)."""

from dataclasses import dataclass, field
from typing import Any, Callable

import sympy as sp

q1, q2, q3, q4 = sp.symbols("q1:5")
qd1, qd2, qd3, qd4 = sp.symbols("qd1:5")
qdd1, qdd2, qdd3, qdd4 = sp.symbols("qdd1:5")
m1, m2, m3, m4, l1, l2, l3, lc1, lc2, I1, I2, g = sp.symbols("m1 m2 m3 m4 l1 l2 l3 lc1 lc2 I1 I2 g")
a1, a2, d1, lq = sp.symbols("a1 a2 d1 lq")
sin, cos, Rational, Matrix = sp.sin, sp.cos, sp.Rational, sp.Matrix
half = Rational(1, 2)
s1, c1, s2, c2, s3, c3 = sin(q1), cos(q1), sin(q2), cos(q2), sin(q3), cos(q3)
s12, c12 = sin(q1 + q2), cos(q1 + q2)
s23, c23 = sin(q2 + q3), cos(q2 + q3)
s123, c123 = sin(q1 + q2 + q3), cos(q1 + q2 + q3)


def vec(*xs):
    """A column vector."""
    return Matrix(list(xs))


def z(x):
    """(0, 0, x)^T."""
    return Matrix([0, 0, x])


@dataclass
class Eq:
    """One equation of a corpus file, transcribed by hand.

    anchor:   text of its left-hand side as written (found on the equation's line)
    quantity: the key of the first-principles value it states (``truth_models`` ``Q``)
    rhs:      its (last) right-hand side as written, in SymPy
    id:       a short name other equations' ``carried`` refer to
    why:      for a deliberate slip: what is wrong
    after:    ``id`` of the earlier slip it carries (it ``follows``)
    carried:  f(values by id) -> what the method gives from the student's earlier values
    span:     lines the equation takes beyond its first (a continuation)
    """

    anchor: str
    quantity: str
    rhs: Any
    id: str = ""
    why: str = ""
    after: str = ""
    carried: Callable[[dict], Any] | None = None
    span: int = 0


@dataclass
class Proof:
    """One line of a proof: both sides as functions of a random body (see :func:`body`)."""

    anchor: str
    lhs: Callable[[dict], Any]
    rhs: Callable[[dict], Any]
    why: str = ""
    span: int = 0
    id: str = field(default="")


@dataclass
class Stated:
    """A law of the method stated before it is used (``k_i = ...``, ``c_{ijk} = ...``): no
    model quantity, so its truth is decided by hand against the textbook: ``not-a-step``
    when it is the law as the textbooks state it, ``wrong`` with ``why`` for a slip."""

    anchor: str
    law: str
    why: str = ""
    span: int = 0


QS = (q1, q2, q3, q4)
QDS = (qd1, qd2, qd3, qd4)
QDDS = (qdd1, qdd2, qdd3, qdd4)


def ddt(expr):
    """d/dt of an expression in q, qd (chain rule: q' = qd, qd' = qdd)."""
    return sum(sp.diff(expr, q) * qd + sp.diff(expr, qd) * qdd for q, qd, qdd in zip(QS, QDS, QDDS, strict=True))


def lagrange_steps(L, n):
    """dL/dqd_i, d/dt dL/dqd_i, dL/dq_i, tau_i of a Lagrangian, i = 1..n."""
    out = {}
    for i in range(n):
        out[f"dqd{i + 1}"] = sp.diff(L, QDS[i])
        out[f"ddt{i + 1}"] = ddt(out[f"dqd{i + 1}"])
        out[f"dq{i + 1}"] = sp.diff(L, QS[i])
        out[f"tau{i + 1}"] = out[f"ddt{i + 1}"] - out[f"dq{i + 1}"]
    return out
