"""How every report lays out an expression: tidied as written by hand, or through CSE.

Small expressions are shown the way one writes them by hand (:func:`tidy_terms`):
sin^2 + cos^2 reduced, terms collected by joint accelerations, then velocity products,
then the rest (gravity), each coefficient factored. A derivation whose torques have
more than :data:`TIDY_NODE_LIMIT` nodes (a 6-dof arm with symbolic inertia) is shown as
common subexpressions instead (:func:`too_big_to_tidy`). The text, LaTeX, Markdown
(report.py) and HTML (report_html.py) reports share these rules. Tidying is for
display only: the derivations themselves never call ``simplify``.
"""

from __future__ import annotations

import functools

import sympy as sp

from . import dag
from .agreement import trig_reduce
from .terms import EquationsOfMotion

#: expressions with more nodes than this are printed via common subexpressions
TIDY_NODE_LIMIT = 3000


def too_big_to_tidy(eom: EquationsOfMotion) -> bool:
    """Some joint torque of ``eom`` has more than :data:`TIDY_NODE_LIMIT` nodes: the
    reports print tau through common subexpressions."""
    return any(dag.larger_than(t, TIDY_NODE_LIMIT) for t in eom.tau)


def tidy_terms(expr, q, qd, qdd) -> list[tuple]:
    """``expr`` as an ordered list of ``(coefficient, monomial)``: joint-acceleration
    terms, velocity-product terms, then the rest (gravity), coefficients factored.
    Empty list for zero. Memoised: reports show the same values again and again (a
    class graded against one model), and factoring is the slow part of a report."""
    return list(_tidy_terms(sp.sympify(expr), tuple(q), tuple(qd), tuple(qdd)))


#: coefficients of more terms than this are shown with their common factors taken out
#: (``factor_terms``), not factored: factoring a long polynomial of many symbols with
#: float coefficients (a ball joint's rotation entries under a floating base) takes seconds
FACTOR_TERMS_LIMIT = 12


@functools.lru_cache(maxsize=4096)
def _tidy_terms(expr, q, qd, qdd) -> tuple:
    e = trig_reduce(expr, q, keep_trig=True)
    if e == 0:
        return ()
    motion = list(qdd) + [qd[i] * qd[j] for i in range(len(qd)) for j in range(i, len(qd))]
    parts = _by_motion(e, set(qd) | set(qdd), set(motion))
    terms = [(_factor(parts[m]), m) for m in motion if m in parts]
    rest = parts.get(sp.S.One, 0)
    if rest != 0:
        trig = [f(qi) for qi in q for f in (sp.sin, sp.cos)]
        for mono, coef in sp.collect(sp.expand(rest), trig, evaluate=False).items():
            terms.append((_factor(coef), mono))
    return tuple(terms)


def _by_motion(e, rates: set, motion: set) -> dict:
    """The expanded ``e`` as ``{monomial: coefficient}`` over the ``motion`` monomials (a
    joint acceleration, a product of two rates), the rest under 1: ``sp.collect``'s
    result, term by term (collect matches each product by substitution, seconds for the
    hundreds of products of a floating base's twist)."""
    parts: dict = {}
    for term in sp.Add.make_args(e):
        mono, coef = [], []
        for factor in sp.Mul.make_args(term):
            (mono if factor.as_base_exp()[0] in rates else coef).append(factor)
        m = sp.Mul(*mono)
        if m not in motion:  # no motion monomial (gravity, a cubic term): the rest keeps it whole
            m, coef = sp.S.One, [term]
        parts.setdefault(m, []).append(sp.Mul(*coef))
    return {m: sp.Add(*coefs) for m, coefs in parts.items()}


def _factor(coef):
    return sp.factor(coef) if len(sp.Add.make_args(coef)) <= FACTOR_TERMS_LIMIT else sp.factor_terms(coef)
