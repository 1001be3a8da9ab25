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

import re

import numpy as np
import sympy as sp

from ..model import Robot
from ..symbolic.agreement import trig_reduce

COMPONENTS = "xyz"
_GREEK = {
    "alpha": "α", "beta": "β", "gamma": "γ", "delta": "δ", "theta": "θ", "phi": "φ", "psi": "ψ",
    "omega": "ω", "tau": "τ", "rho": "ρ", "sigma": "σ", "lambda": "λ", "mu": "μ", "eta": "η",
}
#: expressions larger than this (in nodes) are not tidied for messages
TIDY_LIMIT = 400


def split_name(name: str) -> tuple[str, str, int] | None:
    """A model symbol's name as ``(base, digits, dots)``: ``theta1_ddot`` ->
    ``("theta", "1", 2)``; None for a name not of that form."""
    m = re.fullmatch(r"([A-Za-z]+?)(\d*)(_dot|_ddot)?", name)
    if not m:
        return None
    base, digits, dots = m.groups()
    return base, digits, {"_dot": 1, "_ddot": 2, None: 0}[dots]


def display_name(name: str, ascii_only: bool = False) -> str:
    """``theta1_dot`` -> ``θ̇1``, ``d2_ddot`` -> ``d̈2``, ``l1`` -> ``l1``."""
    parts = None if ascii_only else split_name(name)
    if parts is None:
        return name
    base, digits, dots = parts
    base = _GREEK.get(base, base)
    accent = ("", "\u0307", "\u0308")[dots]
    return base + accent + digits


_LATIN = {v: k for k, v in _GREEK.items()}


def to_ascii(text: str) -> str:
    """A message printed with :func:`pretty` back in plain ASCII (``θ̇1`` -> ``theta1_dot``)."""
    def name(m):
        base, accent, digits = m.groups()
        dots = {"\u0307": "_dot", "\u0308": "_ddot"}.get(accent or "", "")
        return _LATIN.get(base, base) + digits + dots

    text = re.sub("([A-Za-z\u0370-\u03ff])([\u0307\u0308])?(\\d*)", name, text)
    for a, b in (("·", "*"), ("−", "-"), ("²", "**2"), ("³", "**3"), ("→", "->"), ("×", "x")):
        text = text.replace(a, b)
    return text.encode("ascii", "replace").decode()


def pretty(expr, ascii_only: bool = False) -> str:
    """One line, ``−l1·θ̇1²`` style."""
    expr = sp.sympify(expr)
    table = {s: sp.Symbol(display_name(s.name, ascii_only)) for s in expr.free_symbols}
    text = sp.sstr(expr.xreplace(table), order="none")
    if ascii_only:
        return text
    text = re.sub(r"\*\*2\b", "²", text)
    text = re.sub(r"\*\*3\b", "³", text)
    return text.replace("*", "·").replace("-", "−")


def tidy(expr, robot: Robot):
    """sin² + cos² reduced and expanded, for small expressions only."""
    expr = sp.sympify(expr)
    if sp.count_ops(expr) > TIDY_LIMIT:
        return expr
    try:
        return sp.expand(trig_reduce(expr, robot.q, keep_trig=True))
    except Exception:  # noqa: BLE001 - display only: fall back to the plain form
        return sp.expand(expr)


def _terms(expr) -> list:
    return list(sp.Add.make_args(sp.expand(expr)))


def describe(got, ref, robot: Robot, sampler, ascii_only: bool = False) -> str:
    """A sentence for ``got`` (student) versus ``ref`` (what it should be), scalars."""
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
                    return (f"{display_name(wrote.name, ascii_only)} written where "
                            f"{display_name(right.name, ascii_only)} belongs")
    d = tidy(got - ref, robot)
    # a factor missing (got = X where ref has s X) or extra
    for s in sorted((ref.free_symbols | got.free_symbols) - set(robot.q) - set(robot.qd) - set(robot.qdd), key=str):
        if not d.has(s):
            continue
        if np.allclose(fp(d.xreplace({s: 1})), 0, atol=1e-10):
            X = sp.factor(sp.cancel(d / (1 - s)))
            ref_terms = len(_terms(ref))
            if len(_terms(sp.expand(ref - s * X))) < ref_terms:
                return f"a factor {display_name(s.name, ascii_only)} missing on {_short(X, ascii_only)}"
            return f"an extra factor {display_name(s.name, ascii_only)} on {_short(-X, ascii_only)}"
    ref_terms = {t for t in _terms(tidy(ref, robot))}
    got_terms = {t for t in _terms(tidy(got, robot))}
    d_terms = _terms(d)
    word = "term" if len(d_terms) == 1 else "terms"
    if d_terms and all(-t in ref_terms for t in d_terms):
        return f"missing {word} {_short(-d, ascii_only)}"
    if d_terms and all(t in got_terms for t in d_terms):
        return f"extra {word} {_short(d, ascii_only)}"
    half = [-t / 2 for t in d_terms]
    if d_terms and all(t in ref_terms for t in half):
        return f"wrong sign on the {word} {_short(sp.Add(*half), ascii_only)}"
    return f"differs by {_short(d, ascii_only)}"


def _short(expr, ascii_only: bool) -> str:
    """The expression, factored when that is shorter: −lc2·(q̇1 + q̇2)²."""
    # full factorisation only for a few terms (it is the slow part of a report)
    factored = sp.factor(expr) if len(sp.Add.make_args(expr)) <= 4 else sp.factor_terms(expr)
    best = factored if sp.count_ops(factored) < sp.count_ops(expr) else expr
    return pretty(best, ascii_only)


def component_name(index: int, shape) -> str:
    if shape == (3, 1):
        return f"the {COMPONENTS[index]} component"
    if shape == (3, 3):
        return f"entry ({index // 3 + 1}, {index % 3 + 1})"
    return ""
