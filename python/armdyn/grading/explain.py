"""Readable explanations of a wrong step: what differs, said the way a tutor would.

``describe`` turns ``got - reference`` for one component into a sentence:

* ``sign flipped``;
* ``θ̇1 written where θ̈1 belongs`` (a coordinate's derivative swapped for another);
* ``a factor l1 missing on m2·(…)`` (``got - ref = (1 - s) X``);
* ``missing term −l1·θ̇1²`` / ``extra term …`` (the difference is a sub-sum of one side);
* otherwise ``differs by …``.

Expressions print in Unicode with the field's dots (``θ̇1``, ``d̈2``) unless ``ascii``.
"""

from __future__ import annotations

import math
import re

import numpy as np
import sympy as sp
from sympy.functions.elementary.trigonometric import TrigonometricFunction

from ..model import Robot
from ..symbolic import dag
from ..symbolic.agreement import trig_reduce
from ..symbolic.names import GREEK, UnicodeTextPrinter, unicode_name

COMPONENTS = "xyz"
#: expressions larger than this (in nodes) are not tidied for messages
TIDY_LIMIT = 400
#: angle sums expanded (sin(q1 + q2) -> sin q1 cos q2 + ...) only up to this many nodes after
#: expansion: beyond it the difference is shown as it is, with a note (bounded time)
EXPAND_LIMIT = 2000
#: the note added when a difference was too large to simplify
NOT_SIMPLIFIED = "difference not simplified (too large)"
#: a difference with more nodes than this is not even printed in a message
PRINT_LIMIT = 1000
#: the message for a wrong step whose difference is too large to simplify or print
TOO_LARGE = "difference too large to simplify"


def expanded_terms(expr, cap: int = EXPAND_LIMIT) -> int:
    """An upper estimate of how many terms SymPy's ``expand`` (and ``expand_trig``, and
    the sin² + cos² reduction) would make of ``expr``, or of any part of it, counting
    no further than ``cap`` (more than ``cap``: ``cap + 1``). Linear in the tree's size,
    so it can guard those calls: ``count_ops`` does not see that ``(a + b + … )^20``
    of seven symbols expands into 230 230 terms."""
    worst = 0

    def terms(e) -> int:
        nonlocal worst
        if worst > cap:
            return cap + 1
        if e.is_Atom:
            n = 1
        elif e.is_Add:
            n = sum(terms(a) for a in e.args)
        elif e.is_Mul:
            n = 1
            for a in e.args:
                n = min(n * terms(a), cap + 1)
        elif e.is_Pow:
            base, exp = terms(e.base), terms(e.exp)
            if e.exp.is_Integer:
                k = abs(int(e.exp)) if abs(e.exp) <= cap else cap + 1
                # a sum of t terms to the k-th: C(k + t - 1, t - 1) monomials; a sine or
                # cosine to the k-th becomes k / 2 + 1 terms in sin² + cos² = 1
                if base == 1 or k <= 1:
                    n = base
                else:
                    n = math.comb(k + base - 1, base - 1) if k <= cap else cap + 1
                if isinstance(e.base, (sp.sin, sp.cos)):
                    n = min(n * (k // 2 + 1), cap + 1)
            else:
                n = max(base, exp)
        else:  # a function: its arguments are expanded; an angle sum splits in two per term
            inner = [terms(a) for a in e.args]
            n = 1
            if isinstance(e, TrigonometricFunction) and e.args:
                for t in sp.Add.make_args(e.args[0]):
                    c = t.as_coeff_Mul()[0]
                    n = min(n * 2 * (int(min(abs(c), cap)) if c.is_Integer and c != 0 else 1), 2 * cap + 2)
                n = max(1, n // 2)
            worst = max(worst, *inner)
        n = min(n, cap + 1)
        worst = max(worst, n)
        return n

    terms(sp.sympify(expr))
    return min(worst, cap + 1)


def affordable(expr) -> bool:
    """True if ``expr`` may be expanded, factored or simplified for a message: at most
    :data:`TIDY_LIMIT` operations, at most :data:`EXPAND_LIMIT` terms once expanded."""
    expr = sp.sympify(expr)
    return sp.count_ops(expr) <= TIDY_LIMIT and expanded_terms(expr) <= EXPAND_LIMIT


def split_name(name: str) -> tuple[str, str, int] | None:
    """A model symbol's name as ``(base, digits, dots)``: ``theta1_ddot`` ->
    ``("theta", "1", 2)``; None for a name not of that form."""
    m = re.fullmatch(r"([A-Za-z]+?)(\d*)(_dot|_ddot)?", name)
    if not m:
        return None
    base, digits, dots = m.groups()
    return base, digits, {"_dot": 1, "_ddot": 2, None: 0}[dots]


def display_name(name: str, ascii_only: bool = False) -> str:
    """``theta1_dot`` -> ``θ̇₁``, ``d2_ddot`` -> ``d̈₂``, ``l1`` -> ``l₁``: the names
    ``armdyn derive`` prints (:func:`armdyn.symbolic.names.unicode_name`)."""
    if ascii_only:
        return name
    m = re.fullmatch(r"(.+?)(_dot|_ddot)?", name)
    return unicode_name(m.group(1), m.group(2) or "") or name


_LATIN = {v: k for k, v in GREEK.items()}


_SUBSCRIPT = str.maketrans("₀₁₂₃₄₅₆₇₈₉", "0123456789")
_SUPERSCRIPT = {c: str(k) for k, c in enumerate("⁰¹²³⁴⁵⁶⁷⁸⁹")}


def to_ascii(text: str) -> str:
    """A message printed with :func:`pretty` back in plain ASCII (``θ̇₁`` -> ``theta1_dot``)."""

    def name(m):
        base, accent, digits = m.groups()
        dots = {"\u0307": "_dot", "\u0308": "_ddot"}.get(accent or "", "")
        return _LATIN.get(base, base) + digits.translate(_SUBSCRIPT) + dots

    text = text.replace("ᵀ", "^T").replace("Ṁ", "M\u0307")  # a transpose; Ṁ precomposed
    text = re.sub("([A-Za-z\u0370-\u03ff])([\u0307\u0308])?([\\d₀-₉]*)", name, text)
    text = re.sub("[⁰¹²³⁴⁵⁶⁷⁸⁹]+", lambda m: "**" + "".join(_SUPERSCRIPT[c] for c in m.group(0)), text)
    for a, b in (
        ("·", "*"),
        ("−", "-"),
        ("→", "->"),
        ("×", "x"),
        ("…", "..."),
        ("½", "1/2"),
        ("∂", "d"),
        ("Γ", "Gamma"),
    ):
        text = text.replace(a, b)
    return text.encode("ascii", "replace").decode()


def pretty(expr, ascii_only: bool = False, shorthand: dict | None = None) -> str:
    """One line, ``−l₁·θ̇₁²`` style: derive's symbol names, ``·`` and ``−``.
    ``shorthand``: sin/cos terms -> the student's own symbols (``sin(q1 + q2)`` -> ``s₁₂``)."""
    expr = sp.sympify(expr)
    if shorthand:
        expr = expr.xreplace(shorthand)
    if ascii_only:
        return to_ascii(sp.sstr(expr, order="none")) if shorthand else sp.sstr(expr, order="none")
    names = {s: display_name(s.name) for s in expr.free_symbols}
    text = UnicodeTextPrinter(names, order="none").doprint(expr)
    # powers the printer leaves as ** (exponents past 9, symbolic ones): ^, never "··"
    return text.replace("**", "^").replace("*", "·").replace("-", "−")


def reduce(expr, robot: Robot):
    """``expr`` with angle sums expanded (sin(q1 + q2) -> sin q1 cos q2 + cos q1 sin q2),
    sin² + cos² = 1 applied and everything expanded: terms that cancel are gone. None
    when it is too large to do in bounded time (:data:`TIDY_LIMIT`, :data:`EXPAND_LIMIT`)."""
    expr = sp.sympify(expr)
    if not affordable(expr):
        return None
    try:
        expanded = sp.expand_trig(expr)
        if sp.count_ops(expanded) > EXPAND_LIMIT:
            return None
        return sp.expand(trig_reduce(expanded, robot.q, keep_trig=True))
    except Exception:  # noqa: BLE001 - display only: the caller falls back to the plain form
        return None


def tidy(expr, robot: Robot):
    """A difference as shown: simplified (:func:`reduce`) when that has fewer terms than
    the plain reduction (a sign slip in ``l1 θ̇1² c2`` is ``2 l1 θ̇1² c2``, not four terms
    of which three cancel), else sin² + cos² reduced and expanded; as it is when large."""
    expr = sp.sympify(expr)
    if not affordable(expr):
        return expr
    try:
        plain = sp.expand(trig_reduce(expr, robot.q, keep_trig=True))
    except Exception:  # noqa: BLE001 - display only: fall back to the plain form
        plain = sp.expand(expr)
    full = reduce(expr, robot)
    if full is not None and (full == 0 or len(_terms(full)) < len(_terms(plain))):
        return full
    return plain


#: entries larger than this (nodes) are not rewritten into angle sums for display
CONTRACT_LIMIT = 150


def contract(value, shorthand: dict | None):
    """``value`` (expression or matrix) with products of sines and cosines gathered back
    into the angle sums the student abbreviated (``sin q1 cos q2 + cos q1 sin q2`` ->
    ``sin(q1 + q2)``, shown as their ``s₁₂``), so that an expected value reads in their
    notation. Only when they used such a shorthand, and only for small entries."""
    if not shorthand or not any(isinstance(k.args[0], sp.Add) for k in shorthand):
        return value

    def one(x):
        x = sp.sympify(x)
        if sp.count_ops(x) > CONTRACT_LIMIT or not affordable(x):
            return x
        try:
            return sp.trigsimp(sp.expand(x))
        except Exception:  # noqa: BLE001 - display only: keep the value as it is
            return x

    if isinstance(value, sp.MatrixBase):
        return value.applyfunc(one)
    return one(value)


def _terms(expr) -> list:
    return list(sp.Add.make_args(sp.expand(expr)))


def describe(got, ref, robot: Robot, sampler, ascii_only: bool = False, shorthand: dict | None = None) -> str:
    """A sentence for ``got`` (student) versus ``ref`` (what it should be), scalars;
    expressions in the student's ``shorthand`` where they used one."""
    got, ref = sp.sympify(got), sp.sympify(ref)
    fp = sampler.fingerprint
    g = fp(got)
    if np.allclose(fp(-ref), g, rtol=1e-8, atol=1e-10) and not np.allclose(g, 0):
        return "sign flipped"
    # a coordinate's derivative written for another
    seqs = [robot.q, robot.qd, robot.qdd]
    for k in range(robot.dof):
        for a in range(3):
            for b in range(3):
                if a == b:
                    continue
                right, wrote = seqs[a][k], seqs[b][k]
                if not ref.has(right):
                    continue
                if np.allclose(fp(ref.xreplace({right: wrote})), g, rtol=1e-8, atol=1e-10):
                    return (
                        f"{display_name(wrote.name, ascii_only)} written where "
                        f"{display_name(right.name, ascii_only)} belongs"
                    )
    if not (affordable(got - ref) and affordable(got) and affordable(ref)):
        # printed as it is: expanding or factoring it could take hours
        if dag.larger_than(got - ref, PRINT_LIMIT):
            return TOO_LARGE
        return f"differs by {pretty(got - ref, ascii_only, shorthand)} ({NOT_SIMPLIFIED})"
    d = tidy(got - ref, robot)
    # a factor missing (got = X where ref has s X) or extra
    for s in sorted((ref.free_symbols | got.free_symbols) - set(robot.q) - set(robot.qd) - set(robot.qdd), key=str):
        if not d.has(s):
            continue
        if np.allclose(fp(d.xreplace({s: 1})), 0, atol=1e-10):
            X = sp.factor(sp.cancel(d / (1 - s)))
            ref_terms = len(_terms(ref))
            if len(_terms(sp.expand(ref - s * X))) < ref_terms:
                return f"a factor {display_name(s.name, ascii_only)} missing on {_short(X, ascii_only, shorthand)}"
            return f"an extra factor {display_name(s.name, ascii_only)} on {_short(-X, ascii_only, shorthand)}"
    # compare term by term in one form: angle sums expanded when the difference was
    full = reduce(got - ref, robot)
    same_form = full is not None and d == full
    form = (
        (lambda e: reduce(e, robot) if reduce(e, robot) is not None else tidy(e, robot))
        if same_form
        else (lambda e: tidy(e, robot))
    )
    ref_terms = set(_terms(form(ref)))
    got_terms = set(_terms(form(got)))
    d_terms = _terms(d)
    word = "term" if len(d_terms) == 1 else "terms"
    if d_terms and all(-t in ref_terms for t in d_terms):
        return f"missing {word} {_short(-d, ascii_only, shorthand)}"
    if d_terms and all(t in got_terms for t in d_terms):
        return f"extra {word} {_short(d, ascii_only, shorthand)}"
    half = [-t / 2 for t in d_terms]
    if d_terms and all(t in ref_terms for t in half):
        return f"wrong sign on the {word} {_short(sp.Add(*half), ascii_only, shorthand)}"
    return f"differs by {_short(d, ascii_only, shorthand)}"


def _short(expr, ascii_only: bool, shorthand: dict | None = None) -> str:
    """The expression, factored when that is shorter: −lc2·(q̇1 + q̇2)²."""
    if not affordable(expr):
        return pretty(expr, ascii_only, shorthand)
    # full factorisation only for a few terms (it is the slow part of a report)
    factored = sp.factor(expr) if len(sp.Add.make_args(expr)) <= 4 else sp.factor_terms(expr)
    best = factored if sp.count_ops(factored) < sp.count_ops(expr) else expr
    return pretty(best, ascii_only, shorthand)


def component_name(index: int, shape) -> str:
    if shape == (3, 1):
        return f"the {COMPONENTS[index]} component"
    if shape == (3, 3):
        return f"entry ({index // 3 + 1}, {index % 3 + 1})"
    return ""
