"""Grading a derivation whose robot cannot be read: only what its own earlier values decide.

When the text does not fix a model (:func:`~.robot_from_text` fails), a step can still be
checked against the values the text itself gave before it:

- a total from its parts (``T = T_1 + T_2``, ``V = V_1 + V_2``), ``L = T - V``;
- ``\\partial L/\\partial \\dot q_i``, its time derivative and ``\\partial L/\\partial q_i``
  from their ``L`` (or ``T`` and ``V``); ``\\tau_i`` from their ``L`` by the Lagrange
  equation, from their stated pieces, or from their ``M``, ``h``/``C``, ``G``;
- ``M`` (entries or the matrix) from their ``T`` or as the coefficients of ``\\ddot q`` in
  their ``\\tau``; ``G``/``g`` from their ``V`` or from their ``\\tau``; Christoffel symbols
  and ``C`` from their ``M``; Craig's ``V(q, \\dot q)`` from their ``M`` or ``\\tau``;
- velocities as time derivatives of their positions (``\\dot x_1``, ``v_1^2``); a link's
  ``T_k`` as ``m_k v_k^2 / 2`` of its position (a rotational part cannot be checked);
- the Lagrange equation as stated.

A step no earlier value decides (a starting value, a Newton-Euler vector needing the
frames) is ``unrecognised`` with that reason, never guessed. A step agreeing with earlier
values that were themselves found wrong is ``follows-from-earlier-error``; one agreeing with
earlier values of which one could not be checked (a step read but undecided, so perhaps
wrong) is ``consistent``: it is right only if that one is, which nothing here can say.
Nothing from the
text is evaluated as code: values are parsed by :mod:`..latex`.
"""

from __future__ import annotations

import dataclasses
import re

import sympy as sp

from ..latex import LatexError, parse
from ..laws import law_verdict
from ..named import plain
from ..notation import StepRef, parse_lhs
from ..reader import Submission
from ..statements import lagrange_law
from ..verdict import GradeReport, StepVerdict
from .geometry import same
from .own_steps import candidates, rotation
from .statements import MAX_FRAMES, Names, joint_candidates

#: equations looked at, at most; a value longer than this (characters) is not checked
MAX_EQUATIONS = 2000
MAX_VALUE = 20_000

#: Newton-Euler vectors (own_steps checks those that follow without the frames' rotations)
_VECTORS = ("omega", "omega_dot", "v_dot", "vc_dot", "F", "N", "f", "n", "R", "P", "Pc")
#: an argument list after a name the text gave a value to: M_{11}(\theta_2), K(\theta, \dot\theta)
_ARGS = re.compile(r"\(\s*(?:\\(?:dot|ddot)\s*\{?\s*)?\\?(?:theta|Theta|q|mathbf\{q\}|boldsymbol\{q\})[^()$]{0,80}\)")

_NAME_BEFORE = re.compile(r"(?<![\\A-Za-z])([A-Za-z])(_\{[^{}]{0,20}\}|_\w)?$")


class _Own:
    """One value the text gave: the value, its line, its step name, whether it carries a slip
    (``tainted``: the wrong step's name) and whether it rests on a value nothing could check
    (``unchecked``: ``"line N"`` of that step)."""

    def __init__(self, value, line: int, name: str, tainted: str | None, unchecked: str | None = None):
        self.value, self.line, self.name, self.tainted, self.unchecked = value, line, name, tainted, unchecked
        self.corrected = None  # a wrong value: what the text's earlier values give instead


class OwnValues:
    """The pass: each equation in order, judged against what the text's earlier values give."""

    def __init__(self, sub: Submission, why: str):
        self.sub, self.why = sub, why
        self.passed = False  # whether run() has been over the equations
        eqs = [e for e in sub.equations[:MAX_EQUATIONS]]
        joints, _ = joint_candidates(eqs, sub.symbols)
        # joints past a hand derivation's count are not read (n^3 Christoffel symbols stay small)
        joints = {k: v for k, v in joints.items() if k <= MAX_FRAMES}
        self.n = max(joints) if joints else 0
        self.names = Names(joints, sub.symbols)
        self.q = [sp.Symbol(joints.get(k, f"q{k}")) for k in range(1, self.n + 1)]
        self.qd = [sp.Symbol(f"{x}_dot") for x in self.q]
        self.qdd = [sp.Symbol(f"{x}_ddot") for x in self.q]
        self.own: dict[str, _Own] = {}  # canonical step name -> the text's value
        self.read_own = False  # whether the value being read used one of the text's earlier values
        #: line -> (the lines of the earlier values it fits, how): what each step follows from
        self.fits: dict[int, tuple[list[int], str]] = {}
        self.aliases: dict[str, str] = {}  # the symbol the text wrote (K1) -> canonical name (T_1)
        self.verdicts: list[StepVerdict] = []
        self.methods: list[str] = []
        self.seen: set = set(self.q) | set(self.qd) | set(self.qdd)  # symbols in the text's values so far
        #: the Christoffel symbols' index order, once a symbol fits only one ("first", "last")
        self.christoffel_order: str | None = None

    # -- reading
    def _resolve(self, name):
        key = self.aliases.get(plain(name))  # c_{121} the text gave a value: that, not the cosine shorthand
        if key in self.own:
            self.read_own = True
            return self.own[key].value
        value = self.names(name)
        if isinstance(value, sp.Symbol):
            key = self.aliases.get(value.name)
            if key in self.own:
                self.read_own = True
                return self.own[key].value
        return value

    def _read(self, text: str):
        def strip(m):  # M_{11}(\theta_2): the value the text named, not a product with theta
            named = _NAME_BEFORE.search(text[: m.start()].rstrip())
            if named and re.sub(r"[{}\s,_]", "", named.group(1) + (named.group(2) or "")) in self.aliases:
                return ""
            return m.group(0)

        text = _ARGS.sub(strip, text)
        try:
            return parse(text, self._resolve)
        except TypeError:  # g(\theta) given a vector, g the constant a factor: the vector only where it fits
            return parse(text, self._scalar_resolve)

    def _scalar_resolve(self, name):
        value = self._resolve(name)
        return self.names(name) if isinstance(value, sp.MatrixBase) else value

    def _coordinate_of(self, latex: str):
        try:
            value = parse(latex, self.names)
        except (LatexError, RecursionError):
            return None
        for order, vec in enumerate((self.q, self.qd)):
            if value in vec:
                return vec.index(value) + 1, order
        return None

    # -- calculus on the text's values
    def ddt(self, e):
        return sum(
            (e.diff(q) * qd + e.diff(qd) * qdd for q, qd, qdd in zip(self.q, self.qd, self.qdd, strict=True)),
            sp.Integer(0),
        )

    def get(self, *names: str) -> _Own | None:
        for n in names:
            if n in self.own:
                return self.own[n]
        return None

    def lagrangian(self):
        """(L, names used) from the text's own L, or T - V."""
        L = self.get("L")
        if L is not None:
            return L.value, [L]
        T, V = self.get("T"), self.get("V")
        if T is not None and V is not None:
            return T.value - V.value, [T, V]
        if T is not None and not self._mentions_gravity():
            return T.value, [T]
        return None, []

    def _mentions_gravity(self) -> bool:
        return any(k.startswith("V") or k.startswith("G") for k in self.own)

    def matrix(self, base: str):
        """The text's n x n matrix ``base`` (M), stated whole or entry by entry (symmetric)."""
        whole = self.get(base)
        if whole is not None and isinstance(whole.value, sp.MatrixBase) and whole.value.shape == (self.n, self.n):
            return whole.value, [whole]
        entries, used = sp.zeros(self.n, self.n), []
        for i in range(1, self.n + 1):
            for j in range(1, self.n + 1):
                e = self.get(f"{base}_{i}{j}", f"{base}_{j}{i}")
                if e is None:
                    return None, []
                entries[i - 1, j - 1] = e.value
                used.append(e)
        return entries, used

    def vector(self, base: str):
        whole = self.get(base)
        if whole is not None and isinstance(whole.value, sp.MatrixBase) and len(whole.value) == self.n:
            return sp.Matrix(whole.value).reshape(self.n, 1), [whole]
        out, used = [], []
        for i in range(1, self.n + 1):
            e = self.get(f"{base}_{i}")
            if e is None:
                return None, []
            out.append(e.value)
            used.append(e)
        return sp.Matrix(out), used

    def christoffel(self, M, i: int, j: int, k: int):
        """Spong's c_{ijk} = (dm_kj/dq_i + dm_ki/dq_j - dm_ij/dq_k) / 2 (free index k last)."""
        q = self.q
        return (M[k, j].diff(q[i]) + M[k, i].diff(q[j]) - M[i, j].diff(q[k])) / 2

    def coriolis(self, M):
        """The matrix C with C_kj = sum_i c_ijk qd_i, and the vector C qd."""
        n = self.n
        C = sp.Matrix(n, n, lambda k, j: sum(self.christoffel(M, i, j, k) * self.qd[i] for i in range(n)))
        return C, C * sp.Matrix(self.qd)

    # -- the pass
    def run(self) -> GradeReport:
        """The report, ``why`` its first note. The pass over the equations is made once: a
        second call (``why`` changed) reports the same verdicts."""
        if not self.passed:
            for eq in self.sub.equations[:MAX_EQUATIONS]:
                self._equation(eq)
            self.passed = True
        first_wrong = next((v.name for v in self.verdicts if v.status == "wrong"), None)
        tau_ok = [False] * self.n
        for v in self.verdicts:
            m = re.fullmatch(r"tau_(\d+)", v.name)
            if m and 1 <= int(m.group(1)) <= self.n and v.status == "correct":
                tau_ok[int(m.group(1)) - 1] = True
        note = (
            f"no model: the robot could not be read from the text ({self.why}); only the steps that "
            "follow from the text's own earlier values are graded, each against those values"
        )
        return GradeReport(
            robot="(none: not read from the text)",
            method="+".join(self.methods) or (self.sub.method or "lagrange"),
            submission=self.sub.path,
            steps=self.verdicts,
            first_wrong=first_wrong,
            tau_correct=tau_ok,
            notes=[note, *self.sub.notes],
            model_note=note,
        )

    def _add(self, eq, name: str, key: str, status: str, message: str, expected=None, got=None, caused_by=None):
        self.verdicts.append(
            StepVerdict(
                name=name,
                key=key,
                link="",
                status=status,
                label=eq.lhs,
                source=eq.source,
                line=eq.line,
                expected=expected,
                got=got,
                difference=_difference(got, expected) if status == "wrong" else None,
                message=message,
                caused_by=caused_by,
            )
        )
        v = self.verdicts[-1]
        v.part, v.task, v.column = eq.part, eq.task, eq.column

    def _equation(self, eq) -> None:
        if eq.problem or not eq.latex:
            self._add(eq, "", "", "unrecognised", eq.problem or "not LaTeX: no model to read it against")
            return
        stated = law_verdict(eq, max(self.n, 1))  # K_i = ..., L = K - P: the method's law, not a value
        if stated is not None:
            self._method(stated[1] or "lagrange")
            self.verdicts.append(stated[0])
            return
        value_text = str(eq.value)
        try:
            ref = parse_lhs(eq.lhs, self._coordinate_of)
        except (LatexError, RecursionError, ValueError):
            ref = None
        law = (lagrange_law(eq.lhs, value_text) or lagrange_law(value_text, eq.lhs)) if ref is None else None
        if law is not None:
            self._method("lagrange")
            self._add(eq, "lagrange_equation", "law", "correct" if law[0] else "wrong", law[1])
            return
        if ref is None:
            self._add(eq, "", "", "unrecognised", "not a step of Newton-Euler or Lagrange (skipped)")
            return
        name = ref.name
        if len(value_text) > MAX_VALUE:
            self._add(eq, name, ref.key, "unrecognised", f"{name}: too long to check ({len(value_text)} characters)")
            return
        self.read_own = False
        try:
            got = self._read(value_text)
        except (LatexError, RecursionError, ValueError, TypeError, ArithmeticError) as err:
            self._add(eq, name, ref.key, "unrecognised", f"{name}: cannot be read: {str(err)[:160]}")
            return
        # K = 1/2 q'^T D(q) q' with D never given: the law, if it is one; F_2 = m_2 v_{C_2} after
        # the text's v_{C_2}: a step of this arm built on that value, judged as one
        if self._unknown(got, []) and not self.read_own:
            stated = law_verdict(eq, max(self.n, 1), fallback=True)
            if stated is not None:
                self._method(stated[1] or "lagrange")
                self.verdicts.append(stated[0])
                return
        if ref.key in _VECTORS:
            self._method("newton-euler")
            self._judge(eq, ref, got)
            return
        if ref.key == "shorthand" and _has(got, self.qd):  # Lynch and Park's c_1: velocity products
            ref = dataclasses.replace(ref, key="h")
        self._method("lagrange")
        self._judge(eq, ref, got)

    def _method(self, m: str) -> None:
        if m not in self.methods:
            self.methods.append(m)

    def _judge(self, eq, ref: StepRef, got) -> None:
        name, key = ref.name, self._key(ref)
        try:
            cands, starting = rotation(self, ref, got) if ref.key == "R" else candidates(self, ref, key)
        except (ArithmeticError, TypeError, ValueError, AttributeError, IndexError, RecursionError) as err:
            cands, starting = [], f"could not be derived from the earlier values ({str(err)[:80]})"
        if self._scalar_name(eq, ref, got, cands):
            return
        status, message, expected, caused, unchecked = "unrecognised", "", None, None, None
        fitting = [c for c in cands if _fits(got, c[0])]
        orders = {o for c in fitting for o in ("first", "last") if f"(free index {o})" in c[2]}
        if ref.key == "christoffel" and len(orders) == 1:  # the text's index order, kept from here on
            self.christoffel_order = orders.pop()
        if fitting:
            value, used, how, complete = fitting[0]
            tainted = next((u.tainted for u in used if u.tainted), None)
            unchecked = next((u.unchecked for u in used if u.unchecked), None)
            lines = _lines(used)
            self.fits[eq.line] = (sorted({u.line for u in used if u.line}), f"{how}{lines}")
            if tainted and self._untouched(got, ref, key, [u for u in used if u.tainted]):
                tainted = None  # the slip is in a part of that value this step does not use
            if tainted:
                status, caused = "follows-from-earlier-error", tainted
                message = f"follows from the error in {tainted}: {how}{lines}"
            elif unchecked:
                status = "consistent"
                message = (
                    f"agrees with {how}{lines}; your {unchecked} could not be checked (no model), so neither can this"
                )
            else:
                status = "correct"
                message = f"{how}{lines}; no model to check those against"
            expected = _shaped(value, got)
        else:
            complete = [c for c in cands if c[3]]
            unknown = self._unknown(got, complete)
            if complete and unknown:  # a name given no value before: not a slip to call
                complete, cands = [], []
                starting = f"uses {', '.join(unknown)}, which the text gives no value before"
            if complete:
                value, used, how, _ = complete[0]
                lines = _lines(used)
                status, expected = "wrong", _shaped(value, got)
                message = f"not {how}{lines}, compared with your own earlier values"
            elif cands:
                message = f"{name}: {cands[0][2]} differs, and what else it holds cannot be checked without a model"
            else:
                message = f"{name}: {starting or 'no earlier value of the text decides it'} (no model)"
        self._add(eq, name, ref.key, status, message, expected=expected, got=got, caused_by=caused)
        joints = {*self.q, *self.qd, *self.qdd}
        if status == "unrecognised" and not _symbols(got) & joints and self._unknown(got, []):
            return  # L = K - P in names never given: a relation, no value of this arm to build on
        tainted = name if status == "wrong" else caused
        if status == "unrecognised":
            unchecked = f"line {eq.line}"
        self.own[key] = _Own(got, eq.line, name, tainted, unchecked)
        if status == "wrong":
            self.own[key].corrected = expected
        for alias in _aliases(eq.lhs, self.names):
            self.aliases.setdefault(alias, key)
            m = re.fullmatch(r"([A-Za-z]+)(\d)(\d)", alias)
            if m and key.startswith("M_"):  # b_{12} names b_{21} too: M is symmetric
                self.aliases.setdefault(m.group(1) + m.group(3) + m.group(2), key)
        self.seen |= _symbols(got)
        self.aliases.setdefault(key.replace("_", ""), key)

    def _untouched(self, got, ref: StepRef, key: str, tainted: list) -> bool:
        """Whether ``got`` is also what the wrong values it used give once corrected (``τ_1``
        from a C whose slip is in row 2 only): then it does not carry that slip."""
        if not all(u.tainted == u.name and u.corrected is not None for u in tainted):
            return False  # a value carrying a slip from further back: its right value is not known
        saved = [(u, u.value) for u in tainted]
        try:
            for u in tainted:
                u.value = u.corrected
            cands, _ = candidates(self, ref, key)
            return any(_fits(got, c[0]) for c in cands)
        except (ArithmeticError, TypeError, ValueError, AttributeError, IndexError, RecursionError):
            return False
        finally:
            for u, value in saved:
                u.value = value

    def _scalar_name(self, eq, ref: StepRef, got, cands) -> bool:
        """``h = m_2 l_1 l_{c2} \\sin q_2`` where h, the velocity products, has n entries: a
        shorthand the text defines, read as its value where used, not judged."""
        if not cands or isinstance(got, sp.MatrixBase):
            return False
        if not all(isinstance(c[0], sp.MatrixBase) and len(c[0]) > 1 for c in cands):
            return False
        key = f"defined_{ref.name}"
        self._add(
            eq,
            "",
            "",
            "definition",
            f"{ref.name} read as a name for a scalar the text uses later ({ref.name} has {len(cands[0][0])} entries)",
        )
        self.own[key] = _Own(got, eq.line, ref.name, None)
        for alias in _aliases(eq.lhs, self.names):
            self.aliases[alias] = key
        self.seen |= _symbols(got)
        return True

    def _unknown(self, got, candidates) -> list[str]:
        """Names in ``got`` that no earlier value and no candidate holds (b_{21} never given)."""
        known = self.seen.union(*(_symbols(c[0]) for c in candidates))
        return sorted(str(x) for x in _symbols(got) - known)

    @staticmethod
    def _key(ref: StepRef) -> str:
        """The canonical name a value is kept under: T, T_1, M, M_12, G_1, tau_1, c_121, dL_dqd_1..."""
        entry = "".join(str(k) for k in ref.entry)
        if ref.key in ("vc", "pc", "w", "Jv", "Jw"):
            return ref.name  # x_c1, xdot_c1, v_c1^2: one name each
        base = {"Tl": "T", "Vl": "V"}.get(ref.key, ref.key)
        if ref.key in _VECTORS and ref.frame is not None and ref.frame != ref.index:
            return f"{base}_{ref.index}^{ref.frame}"  # a vector in another frame than its link's
        if ref.index is not None:
            return f"{base}_{ref.index}"
        return f"{base}_{entry}" if entry else base


def _aliases(lhs: str, names: Names) -> list[str]:
    """The symbol names the text's left-hand side reads as (K_1 -> K1; M_{11}(\\theta_2) -> M11)."""
    head = re.split(r"\(|\\left\(", lhs, maxsplit=1)[0]
    found: list = []
    try:
        parse(head, lambda n: found.append(n) or sp.Integer(1))
    except (LatexError, RecursionError):
        return []
    if len(found) != 1:
        return []
    try:
        value = names(found[0])
    except LatexError:
        return [plain(found[0])]
    return [value.name] if isinstance(value, sp.Symbol) else [plain(found[0])]


def _difference(got, expected):
    """got - expected when both are of one shape, else None (nothing to subtract)."""
    if expected is None or isinstance(got, sp.MatrixBase) != isinstance(expected, sp.MatrixBase):
        return None
    try:
        return got - expected
    except (TypeError, ValueError, ArithmeticError):
        return None


def _lines(used) -> str:
    """`` (lines 3, 5)`` of the values used, or "" (the base at rest: no line)."""
    lines = sorted({u.line for u in used if u.line})
    return f" (line{'s' if len(lines) > 1 else ''} {', '.join(map(str, lines))})" if lines else ""


def _symbols(value) -> set:
    return set(getattr(value, "free_symbols", set()))


def _has(value, symbols) -> bool:
    return bool(getattr(value, "free_symbols", set()) & set(symbols))


def _flat(x):
    if isinstance(x, sp.MatrixBase):
        return sp.Matrix(x).reshape(len(x), 1)
    return x


def _fits(got, value) -> bool:
    """The text's value equals ``value`` (vectors compared as columns) at random points."""
    a, b = _flat(got), _flat(value)
    if isinstance(a, sp.MatrixBase) != isinstance(b, sp.MatrixBase):
        if isinstance(b, sp.MatrixBase) and len(b) == 1:
            b = b[0]
        elif isinstance(a, sp.MatrixBase) and len(a) == 1:
            a = a[0]
        else:
            return False
    if isinstance(a, sp.MatrixBase) and a.shape != b.shape:
        return False
    return same(a, b)


def _shaped(value, got):
    if isinstance(value, sp.MatrixBase) and isinstance(got, sp.MatrixBase) and len(value) == len(got):
        return sp.Matrix(value).reshape(*got.shape)
    return value


def grade_without_model(sub: Submission, why: str) -> GradeReport:
    """The report of a text whose robot could not be read (``why``): see the module's docstring."""
    return OwnValues(sub, why).run()
