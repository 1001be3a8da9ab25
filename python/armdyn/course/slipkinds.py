"""The kind of a wrong step, read from its values: the student's value against the
expected one (an arm's step), or the two sides of a proof's link on its counterexample.

    kinds = slip_kinds(report)      # {index of a wrong step: kind}, for the steps it can tell

Each kind is one independent test on the difference ``D = got - expected`` (after
``sin^2 + cos^2 = 1`` and expansion), tried in this order on the first wrong component:

=================================  ===============================================================
kind                               test
=================================  ===============================================================
transposed rotation                the whole vector is the expected one with ``sin q_i`` -> ``-sin q_i``
                                   for a revolute ``q_i`` (``R^T`` where ``R`` belongs: ``R_z(q)^T = R_z(-q)``),
                                   changing two components or more (one: a term's sign, as likely)
wrong sign                         ``got = -expected``, or ``D = -2 t`` for a term ``t`` of the expected
derivative mixed up                ``got`` is the expected with ``q̈_i`` -> ``q̇_i`` (or back) in one term or all
missing term                       the terms of ``got`` are some of the expected's
inertia about the wrong point      (``N_i``, ``T``) ``D`` is one link's mass times a squared length times
                                   rates: the parallel-axis term of an inertia taken about another point
extra term                         the expected's terms are some of ``got``'s
factor missing / extra factor      ``got`` has ``r t`` for a term ``t`` (or the whole value) with ``r`` a
                                   number or a symbol's power: ``|r| < 1`` or ``1/l``: missing; else extra
wrong shape                        a vector for a scalar or the other way
=================================  ===============================================================

A proof's link (``L = R`` differ on a small body; its counterexample gives both sides, the
masses, the points and the vectors the proof defined) is tested the same way:

=========================================  ========================================================
kind                                       test
=========================================  ========================================================
proof: sign                                ``R = -L``, or ``L - R = ±2 c`` for a candidate term ``c``
proof: transpose                           ``R = L^T``, or a frame change written ``R^T X R`` for ``R X R^T``
proof: mass-centre fact about wrong point  one side 0, the other ``±M (C - X)`` or ``±M v``: ``∫ r dm = 0``
                                           said of a point ``X`` that is not the mass centre
proof: dropped term                        ``L - R = ±c`` for a candidate term the link does not write
proof: factor                              ``L = c R`` (``c`` an integer, its inverse or ``M``), or ``L - R = ±c`` or ``±(M - 1) c`` for a
                                           candidate term the link writes (``2 d^T r`` written ``d^T r``,
                                           ``M (d^T d 1 - d d^T)`` written without ``M``)
=========================================  ========================================================

Candidate terms: for each vector ``v`` (defined, or ``C - X`` for a named point): ``M v v^T``,
``M v^T v 1``, ``v^T v 1 - v v^T`` and ``M`` times it; per named point ``∑ m r r^T``,
``∑ m r^T r 1``; for a link about one mass element at ``e``: ``v^T (e - X)``, ``v^T v``,
``|e - X|^2``. A step no test recognises is left to :func:`.errorkinds.classify` (its message).
"""

from __future__ import annotations

import re
from fractions import Fraction

import sympy as sp

#: the kinds a proof slip can have, in the order a summary lists them when counts tie
PROOF_SLIPS = (
    "proof: sign",
    "proof: transpose",
    "proof: mass-centre fact about the wrong point",
    "proof: factor",
    "proof: dropped term",
)
#: expressions larger than this are not tested (the message says what it can)
MAX_OPS = 2000


def slip_kinds(report) -> dict[int, str]:
    """``{index in report.steps: kind}`` for each wrong step whose kind a test finds."""
    names = [s for s in (report.symbol_latex or {}) if isinstance(s, sp.Symbol)]
    rates = {s.name: s for s in names}
    coords = [s for s in names if f"{s.name}_dot" in rates]
    out = {}
    for k, v in enumerate(report.steps):
        if v.status != "wrong":
            continue
        try:
            if v.key == "proof" or str(v.name).startswith("proof_"):
                kind = proof_kind(v.counterexample or {}, v.label or "")
            else:
                kind = arm_kind(v.key, v.expected, v.got, coords, rates)
        except (TypeError, ValueError, ZeroDivisionError, AttributeError, sp.SympifyError):
            kind = None  # a value of a form the tests do not know: the message decides
        if kind:
            out[k] = kind
    return out


# ------------------------------------------------------------------ an arm's step
def _canon(x, q):
    from ..symbolic.agreement import trig_reduce

    return sp.expand(trig_reduce(sp.sympify(x), list(q), keep_trig=True))


def _terms(x) -> set:
    return {t for t in sp.Add.make_args(x) if t != 0}


def arm_kind(key: str, expected, got, coords, rates: dict) -> str | None:
    """The kind of a wrong arm step with values ``expected`` and ``got`` (SymPy); ``coords``
    the joint coordinates, ``rates`` name -> symbol (``theta1_dot``, ``theta1_ddot``)."""
    if expected is None or got is None:
        return None
    vec_e, vec_g = isinstance(expected, sp.MatrixBase), isinstance(got, sp.MatrixBase)
    if vec_e != vec_g or (vec_e and expected.shape != got.shape):
        return "wrong shape"
    es = list(expected) if vec_e else [expected]
    gs = list(got) if vec_g else [got]
    if any(sp.count_ops(x) > MAX_OPS for x in es + gs):
        return None
    es = [_canon(x, coords) for x in es]
    gs = [_canon(x, coords) for x in gs]
    wrong = [i for i in range(len(es)) if sp.expand(gs[i] - es[i]) != 0]
    if not wrong:
        return None
    for q in coords if vec_e else ():  # R^T for R about z: sin q -> -sin q in the whole vector,
        turned = [_canon(x.xreplace({sp.sin(q): -sp.sin(q)}), coords) for x in es]
        changed = sum(1 for a, b in zip(turned, es) if sp.expand(a - b) != 0)
        if changed >= 2 and all(sp.expand(a - b) == 0 for a, b in zip(turned, gs)):
            return "transposed rotation"  # in two components (one: a term's sign, as likely)
    e, g = es[wrong[0]], gs[wrong[0]]
    d = sp.expand(g - e)
    te, tg = _terms(e), _terms(g)
    if e != 0 and sp.expand(g + e) == 0 or any(sp.expand(d + 2 * t) == 0 for t in te):
        return "wrong sign"
    for q in coords:
        qd, qdd = rates.get(f"{q.name}_dot"), rates.get(f"{q.name}_ddot")
        if qd is None or qdd is None:
            continue
        for a, b in ((qdd, qd), (qd, qdd)):
            if sp.expand(e.xreplace({a: b}) - g) == 0 and e.has(a):
                return "derivative mixed up"
            if any(t.has(a) and sp.expand(d - (t.xreplace({a: b}) - t)) == 0 for t in te):
                return "derivative mixed up"
    if tg < te:
        return "missing term"
    if key in ("N", "T") and _parallel_axis_term(d, rates):
        return "inertia about the wrong point"
    if te < tg:
        return "extra term"
    for whole, t in [(True, e)] + [(False, t) for t in te]:
        if t == 0:
            continue
        r = sp.cancel(d / t + 1)  # got has r*t where t belongs
        kind = _factor_kind(r, rates)
        if kind and (whole or sp.expand(g - (e - t + r * t)) == 0):
            return kind
    return None


def _motion(rates: dict) -> set:
    """The joint rates and accelerations (``theta1_dot``, ``d2_ddot``) among the model's symbols."""
    return {s for s in rates.values() if s.name.endswith(("_dot", "_ddot"))}


def _factor_kind(r, rates: dict) -> str | None:
    """``factor missing`` / ``extra factor`` when ``r`` is a number or a product of powers
    of model symbols other than the motion's (not 0, not ±1)."""
    if r.is_Number:
        if r in (0, 1, -1):
            return None
        return "factor missing" if abs(r) < 1 else "extra factor"
    if r.free_symbols & _motion(rates) or not r.is_Mul and not r.is_Pow and not r.is_Symbol:
        return None
    num, den = sp.fraction(r)
    if num.is_Number and den.free_symbols:
        return "factor missing"
    if den.is_Number and num.free_symbols:
        return "extra factor"
    return None


def _parallel_axis_term(d, rates: dict) -> bool:
    """``d`` is one link's mass times (a squared length or a number) times rates only, as
    the term ``m r^2 ω̇`` (or ``m r^2 ω^2 / 2``) that an inertia about another point adds."""
    if d == 0 or d.has(sp.Symbol("g")):
        return False
    masses = {s for s in d.free_symbols if re.fullmatch(r"m_?\d+", s.name)}
    if len(masses) != 1:
        return False
    (m,) = masses
    rest = sp.expand(d / m)
    motion = _motion(rates)
    if rest.has(m) or not rest.free_symbols & motion:
        return False
    for t in _terms(rest):
        if any(f"{s.name}_dot" in rates for s in t.free_symbols):
            return False  # a joint coordinate (d2): a term of the motion, not of an inertia
        lengths = [s for s in t.free_symbols if s not in motion]
        if lengths and sp.Poly(t, *lengths).total_degree() != 2:
            return False
    return True


# ------------------------------------------------------------------ a proof's link
def _num(text) -> sp.Rational:
    f = Fraction(str(text).strip())  # a number's text, never evaluated
    return sp.Rational(f.numerator, f.denominator)


def _value(x):
    """A counterexample's value: a number, a vector (list) or a matrix (list of lists)."""
    if isinstance(x, (list, tuple)):
        if x and isinstance(x[0], (list, tuple)):
            return sp.Matrix([[_num(c) for c in row] for row in x])
        return sp.Matrix([_num(c) for c in x])
    return _num(x)


def _plain(label: str) -> str:
    """A link's LaTeX without bold, braces, sizing and blanks, for finding a term's names."""
    text = re.sub(r"\\(mathbf|boldsymbol|bm|mathrm)\b", "", label)
    text = re.sub(r"\\(left|right)\b|[{}\s]|\\[,;!]", "", text)
    return text.replace(r"\top", "T")


def _is_zero(x) -> bool:
    return (x == sp.zeros(*x.shape)) if isinstance(x, sp.MatrixBase) else x == 0


def _ratio(a, b):
    """``k`` with ``a = k b`` (numbers, vectors or matrices of one shape), or None."""
    if isinstance(a, sp.MatrixBase) != isinstance(b, sp.MatrixBase):
        return None
    if isinstance(a, sp.MatrixBase):
        if a.shape != b.shape or _is_zero(b):
            return None
        i = next(k for k in range(len(b)) if b[k] != 0)
        k = a[i] / b[i]
        return k if a == k * b else None
    return None if b == 0 else a / b


def proof_kind(example: dict, label: str) -> str | None:
    """The kind of a wrong proof link from its counterexample (both sides' values on a small
    body) and its LaTeX (which terms the link writes)."""
    if "left" not in example or "right" not in example:
        return None
    left, right = _value(example["left"]), _value(example["right"])
    masses = [_num(m) for m in example.get("masses") or []]
    M = sum(masses, sp.Integer(0))
    points = [sp.Matrix([_num(c) for c in p]) for p in example.get("points") or []]
    named = {k: sp.Matrix([_num(c) for c in p]) for k, p in (example.get("named_points") or {}).items()}
    centre = example.get("center_of_mass")
    defined = {k: _value(v) for k, v in (example.get("defined") or {}).items()}
    vectors = {k: v for k, v in defined.items() if isinstance(v, sp.MatrixBase) and v.shape == (3, 1)}
    rotations = [_value(v) for v in (example.get("rotations") or {}).values()]
    if not _is_zero(left) and right == -left:
        return "proof: sign"
    if isinstance(left, sp.MatrixBase) and left.shape == (3, 3) and isinstance(right, sp.MatrixBase):
        if right == left.T and left != right:
            return "proof: transpose"
        for Rm in rotations:
            if isinstance(Rm, sp.MatrixBase) and Rm.shape == (3, 3):
                twice, back = Rm * Rm, Rm.T * Rm.T
                if right in (back * left * twice, twice * left * back) and left != right:
                    return "proof: transpose"
    if centre in named and (_is_zero(left) or _is_zero(right)):
        other = right if _is_zero(left) else left
        offsets = [named[centre] - p for k, p in named.items() if k != centre] + list(vectors.values())
        if any(other in (M * v, -M * v) for v in offsets if not _is_zero(v)):
            return "proof: mass-centre fact about the wrong point"
    k = _ratio(left, right)
    if k is not None and k not in (0, 1, -1) and (k.p in (1, -1) or k.q == 1 or k in (M, 1 / M)):
        return "proof: factor"  # a whole side off by a factor (1/2, 2, M)
    diff = left - right
    text = _plain(label).split("=", 1)[-1]
    written_off = False  # a term the link writes, off by a unit (2t written t) or by the mass
    for cand, _ in _candidates(example, M, masses, points, named, vectors, diff):
        k = _ratio(diff, cand[0])
        if k is None:
            continue
        if k in (2, -2):
            return "proof: sign"
        written = any(re.search(p, text) for p in cand[1])
        if k in (1, -1) and not written:
            return "proof: dropped term"
        written_off = written_off or (written and k in (1, -1, M - 1, 1 - M))
    if written_off:
        return "proof: factor"
    return None


def _candidates(example, M, masses, points, named, vectors, diff):
    """``((value, [regexes of the term as written]), how)`` for the terms a link may have."""
    out = []
    offsets = dict(vectors)
    element = example.get("element")
    if isinstance(diff, sp.MatrixBase) and diff.shape == (3, 3):
        one = sp.eye(3)
        for name, v in offsets.items():
            a = re.escape(name)
            out.append(((M * (v.T * v)[0] * one - M * v * v.T, [rf"M\(?{a}\^T{a}"]), "square"))
            out.append(((M * v * v.T, [rf"{a}{a}\^T"]), "square"))
            out.append(((M * (v.T * v)[0] * one, [rf"{a}\^T{a}"]), "square"))
            out.append((((v.T * v)[0] * one - v * v.T, [rf"{a}\^T{a}"]), "square"))
        for x, p in named.items():
            rs = [q - p for q in points]
            out.append(
                ((sum((m * r * r.T for m, r in zip(masses, rs)), sp.zeros(3, 3)), [rf"r_{x}r_{x}\^T"]), "square")
            )
            out.append(
                (
                    (sum(((m * (r.T * r)[0]) for m, r in zip(masses, rs)), sp.Integer(0)) * one, [rf"r_{x}\^Tr_{x}"]),
                    "square",
                )
            )
    elif not isinstance(diff, sp.MatrixBase) and isinstance(element, int) and 0 <= element < len(points):
        e = points[element]
        for x, p in named.items():
            r = e - p
            out.append((((r.T * r)[0], [rf"r_{x}\^Tr_{x}"]), "square"))
            for name, v in offsets.items():
                a = re.escape(name)
                out.append((((v.T * r)[0], [rf"{a}\^Tr_{x}", rf"r_{x}\^T{a}"]), "cross"))
        for name, v in offsets.items():
            a = re.escape(name)
            out.append((((v.T * v)[0], [rf"{a}\^T{a}"]), "square"))
    return [c for c in out if not _is_zero(c[0][0])]
