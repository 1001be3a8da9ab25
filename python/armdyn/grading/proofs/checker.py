"""Check a proof line by line: each ``=`` of a chain ``A = B = C`` is one link, judged by
evaluating both sides exactly on random point-mass bodies (:mod:`.body`, :mod:`.evaluate`).

Per link (statuses of :mod:`armdyn.grading.verdict`):

* ``correct``: the two sides agree on every instance. If they disagree once the point
  named C is *not* the mass center, the link relies on ``\\int r_C dm = 0`` and says so.
* ``follows-from-earlier-error``: they disagree, but agree once the names carry the
  meaning the student's own earlier (wrong) definition gave them.
* ``wrong``: they disagree; a counterexample is searched among small bodies
  (:func:`.counterexample.find`). A chain whose two ends agree while a link fails has its
  slip in the middle: the first failing link is ``wrong``, the next one (which compares
  that wrong middle expression with the rest of the chain) follows from it.
* ``unrecognised``: a name with no meaning here, an unreadable side, or a value that is
  not rational.

Definitions bind names: ``r_P = r_C + d`` (a constant vector met for the first time, as
one term of a sum) defines ``d`` and checks it is constant over the body; ``X = ...`` with
a name that has no meaning yet defines it; ``I_O = \\int ... dm`` and ``I^c = R^c I R^{cT}``
are checked against the inertia tensor's definition and the frame change.
"""

from __future__ import annotations

import re
import time
from dataclasses import dataclass, field
from fractions import Fraction

from ..latex import LatexError, sides
from .body import random_instance
from .counterexample import find, sentence
from .evaluate import (
    MAX_DEGREE,
    VECTOR_NAMES,
    NeedElement,
    NotRational,
    ProofState,
    Scope,
    UnknownName,
    degree,
    evaluate,
    key,
)
from .expr import Add, Integral, Mass, Mul, Num, ProofSyntaxError, Sum, Sym, parse_side, walk
from .matrices import Mat, ShapeError, SizeError
from .prose import rod_moment
from .regions import Display

#: random instances per link: with the degree cap and at least 2^31 values per draw, a false
#: pass has probability at most (2 MAX_DEGREE / 2^31)^K < 1e-19 (docs/grading.md)
K = 3
_ORDINALS = {"first": 0, "second": 1, "third": 2, "fourth": 3, "fifth": 4}
_JOIN = re.compile(r"\b(first|second|third|fourth|fifth|last)\s+(integral|term|summand)\b", re.IGNORECASE)
_VANISH = re.compile(
    r"\b(first|second|third|fourth|fifth|last)\s+(integral|term|summand)\s+(vanishes|is zero)", re.IGNORECASE
)
_FROM_TO = re.compile(r"from\s+\$?\s*(?:\\mathbf\{)?([A-Z])\}?\s*\$?\s+to\s+\$?\s*(?:\\mathbf\{)?([A-Z])\b")


@dataclass
class LinkVerdict:
    """The verdict on one link ``left = right`` of a proof line."""

    line: int
    label: str
    source: str
    status: str
    message: str
    left: object = None  # Mat on the counterexample
    right: object = None
    counterexample: dict | None = None
    caused_by: str | None = None
    cause: LinkVerdict | None = None  # the wrong link this one follows from (named later)
    name: str = "proof"


class _Failure(Exception):
    def __init__(self, status: str, message: str):
        super().__init__(message)
        self.status, self.message = status, message


@dataclass
class ProofChecker:
    """One proof: its bindings and state across lines."""

    deadline: float = field(default_factory=lambda: time.perf_counter() + 4.0)

    def __post_init__(self):
        self.state = ProofState()
        self.defs: dict = {}  # name key -> (tree, line): definitions the text made
        self.overrides: dict = {}  # name key -> (tree, line): the student's wrong definitions
        self.seen: set = set()  # constant vectors named so far
        self.sums: list = []  # (line, tree) of sums met, for "the second integral"
        self.notes: set = set()  # how the names of the current link were read
        self.named: set = set()  # inertia tensors whose definition was met
        self.instances = [random_instance(seed) for seed in range(K)]
        self.uncentered = random_instance(1000, centered=False)
        self.placed: dict = {}  # what the prose fixed: points, vectors (shared by every instance)
        for inst in (*self.instances, self.uncentered):
            inst.placed = self.placed
        self.last = None  # (tree, text) of the last expression of the previous line: a row "= ..." continues it

    # -- evaluation
    def _pairs(self, left, right, inst, env):
        """[(element or None, left value, right value)] on one instance."""
        inst.placed = self.placed
        sc = Scope(inst, env, self.state, notes=self.notes)
        try:
            return [(None, evaluate(left, sc), evaluate(right, sc))]
        except NeedElement:
            pass
        out = []
        for k in range(len(inst)):
            sc = Scope(inst, env, self.state, elem=k, notes=self.notes)
            out.append((k, evaluate(left, sc), evaluate(right, sc)))
        return out

    def _agree(self, left, right, env, instances) -> bool:
        for inst in instances:
            for _, a, b in self._pairs(left, right, inst, env):
                if a.shape != b.shape and not (_zero(a) or _zero(b)):
                    raise _Failure("wrong", f"the left side is {a.kind()}, the right side {b.kind()}")
                if not _same(a, b):
                    return False
        return True

    def _guarded(self, fn):
        try:
            return fn()
        except ShapeError as err:
            raise _Failure("wrong", f"{err} (a transpose or a factor missing?)") from None
        except (UnknownName, NotRational, ProofSyntaxError) as err:
            raise _Failure("unrecognised", str(err)) from None
        except LatexError as err:
            raise _Failure("unrecognised", str(err)) from None
        except SizeError as err:
            raise _Failure("unrecognised", f"too large to evaluate: {err}") from None
        except ZeroDivisionError:
            raise _Failure("wrong", "a division by zero") from None
        except RecursionError:
            raise _Failure("unrecognised", "nested too deeply") from None

    # -- one link
    def link(self, left, right, line: int, label: str, source: str, prefix: str = "") -> LinkVerdict:
        if time.perf_counter() > self.deadline:
            return LinkVerdict(
                line, label, source, "unrecognised", "not checked: the proof checker's time budget (4 s) is spent"
            )
        try:
            return self._link(left, right, line, label, source, prefix)
        except _Failure as f:
            return LinkVerdict(line, label, source, f.status, (prefix + f.message) if prefix else f.message)

    def _link(self, left, right, line, label, source, prefix) -> LinkVerdict:
        self.state.scan([left, right])
        if max(degree(left), degree(right)) > MAX_DEGREE:
            raise _Failure("unrecognised", f"too many factors to evaluate (degree over {MAX_DEGREE})")
        self.notes = set()  # how names were read (filled while evaluating)
        agree = self._guarded(lambda: self._agree(left, right, self.defs, self.instances))
        said = "; ".join(sorted(self.notes))
        if agree:
            msg = prefix
            try:
                if not self._agree(left, right, self.defs, [self.uncentered]):
                    fact = "uses \\int r_C dm = 0: C is the center of mass"
                    if _states_center_fact(left, right):
                        fact = "states \\int r_C dm = 0: true, C is the center of mass (usable from here on)"
                    msg = _join(msg, fact)
            except (_Failure, ArithmeticError, LatexError, NeedElement):
                pass
            return LinkVerdict(line, label, source, "correct", _join(msg, said))
        env = {**self.defs, **self.overrides}
        if self.overrides and self._guarded(lambda: self._agree(left, right, env, self.instances)):
            first = min(self.overrides.values(), key=lambda v: v[1])
            return LinkVerdict(
                line,
                label,
                source,
                "follows-from-earlier-error",
                _join(prefix, f"right with your own definition at line {first[1]}, which is wrong"),
                cause=first[2],
            )
        example = self._guarded(
            lambda: find(
                lambda inst: self._pairs(left, right, inst, self.defs), self.instances[0], self._defined_values
            )
        )
        msg = _join(prefix, "the two sides differ")
        if example is not None:
            msg = _join(msg, "counterexample: " + sentence(example))
        return LinkVerdict(
            line,
            label,
            source,
            "wrong",
            _join(msg, said),
            left=example["left_value"] if example else None,
            right=example["right_value"] if example else None,
            counterexample=example["data"] if example else None,
        )

    def _defined_values(self, inst) -> dict:
        out = {}
        for k, (tree, _) in self.defs.items():
            if k.split("_")[0] in VECTOR_NAMES:
                try:
                    out[k.split("^")[0].rstrip("_")] = evaluate(tree, Scope(inst, {}, self.state, elem=0)).tolist()
                except (ArithmeticError, ShapeError, LatexError, NeedElement):
                    pass
        return out

    # -- definitions
    def _define_vector(self, left, right, line, label, source) -> LinkVerdict | None:
        """``r_P = r_C + d`` with ``d`` met for the first time: d := r_P - r_C."""
        for side, other, flip in ((right, left, False), (left, right, True)):
            terms = side.terms if isinstance(side, Add) else ((1, side),)
            fresh = [
                (s, t)
                for s, t in terms
                if isinstance(t, Sym)
                and t.base in VECTOR_NAMES
                and t.base not in self.state.facts.scalars
                and (t.base != "omega" or (t.sub and len(terms) == 1))  # omega_B = R^T omega: a new name
                and not t.frame
                and not t.transposed
                and key(t) not in self.seen
            ]
            if len(fresh) != 1 or any(
                key(n) in self.seen for n in walk(other) if isinstance(n, Sym) and key(n) == key(fresh[0][1])
            ):
                continue
            sign, sym = fresh[0]
            rest = [(-s, t) for s, t in terms if t is not sym]
            solved = Add(((sign, other), *((sign * s, t) for s, t in rest)))
            self.seen.add(key(sym))
            self.defs[key(sym)] = (solved, line)
            inst = self.instances[0]
            try:
                values = [evaluate(solved, Scope(inst, {}, self.state, elem=k)) for k in range(len(inst))]
            except (ShapeError, LatexError, NeedElement, ArithmeticError) as err:
                return LinkVerdict(line, label, source, "unrecognised", f"cannot read {sym.latex()}: {err}")
            if any(v != values[0] for v in values):
                return LinkVerdict(
                    line, label, source, "wrong", f"defines {sym.latex()}, but it is not constant over the body"
                )
            what = ""
            names = [p for p in inst.points if not p.startswith("ref:")]
            for a in names:
                for b in names:
                    if a != b and values[0] == inst.points[a] - inst.points[b]:
                        what = f" = {a} - {b}"
            self.constant_def = (sym.latex(), what)
            return LinkVerdict(line, label, source, "correct", f"defines {sym.latex()}{what} (constant over the body)")
        return None

    def _rotation_alias(self, left, right, line: int) -> str:
        """``\\omega^c = R \\omega``, ``I^c = R I R^T``: a quantity in frame c defined with a
        rotation ``R`` the proof has not named. The line defines R: it is read as R^c (or
        R^{cT}) when that makes the line true; "" (nothing defined) otherwise."""
        if not isinstance(left, Sym) or not left.frame or left.transposed or isinstance(right, Exception):
            return ""
        plain = [n for n in walk(right) if isinstance(n, Sym) and n.base == "R" and not n.frame and not n.sub]
        if not plain or key(plain[0]) in self.defs:
            return ""
        name = key(plain[0])
        for transposed in (False, True):
            self.defs[name] = (Sym("R", False, "", left.frame, transposed), line)
            try:
                if self._guarded(lambda: self._agree(left, right, self.defs, self.instances)):
                    what = f"R^{{{left.frame}T}}" if transposed else f"R^{left.frame}"
                    return (
                        f"defines {left.latex()} with R read as {what}, the rotation "
                        f"{'from' if transposed else 'into'} frame {left.frame} (a definition: consistent)"
                    )
            except _Failure:
                pass
            del self.defs[name]
        return ""

    def _is_new_name(self, node) -> bool:
        if not isinstance(node, Sym) or node.transposed or key(node) in self.defs:
            return False
        try:
            evaluate(node, Scope(self.instances[0], self.defs, ProofState(**vars(self.state)), elem=0))
        except UnknownName:
            return True
        except Exception:  # noqa: BLE001
            return False
        return False

    # -- one display line
    def display(self, d: Display, next_prose: str) -> list[LinkVerdict]:
        if d.prose:
            self._read_prose(d.prose)
        raw = sides(d.text)
        source = " ".join(d.text.split())
        trees = []
        for text in raw:
            try:
                trees.append(parse_side(text))
            except ProofSyntaxError as err:
                trees.append(err)
        continued = len(raw) > 1 and not raw[0].strip() and self.last is not None
        if continued:  # a row "= ..." continues the chain of the row before
            trees[0], raw[0] = self.last
        self.last = (trees[-1], raw[-1]) if len(raw) > 1 and not isinstance(trees[-1], Exception) else None
        example = self._example_scalars(trees)
        for t in trees:
            if isinstance(t, Add) and len(t.terms) > 1:
                self.sums.append((d.line, t))  # a sum whose "second integral" the prose may name
        if len(raw) == 1:
            return [self._continuation(d, trees[0], source)]
        out = []
        for j in range(len(raw) - 1):
            label = f"{raw[j]} = {raw[j + 1]}"
            a, b = trees[j], trees[j + 1]
            bad = a if isinstance(a, Exception) else b if isinstance(b, Exception) else None
            if bad is not None:
                out.append(LinkVerdict(d.line, label, source, "unrecognised", f"cannot read: {bad}"))
                continue
            rod = self.state.facts.rod
            if j == 0 and not continued and example and _named(a) and rod and key(a) not in self.defs:
                self.defs[key(a)] = (rod_moment(*rod), d.line)  # the example's moment, checked
                self.state.facts.rod = None
                v = self.link(a, b, d.line, label, source)
                where = "one end" if rod[2] == "end" else "its centre"
                v.message = _join(
                    f"{a.latex()} read as the moment of inertia of the uniform rod (mass {rod[0]}, length {rod[1]}) "
                    f"about a perpendicular axis through {where}, from its mass distribution (as the text says)",
                    v.message,
                )
                out.append(v)
                continue
            if j == 0 and not continued and (self._is_new_name(a) or (example and _named(a))):
                self.defs[key(a)] = (b, d.line)  # K = ... (= ...): names the first expression
                what = "a definition: nothing to check"
                if example:
                    what = (
                        f"a worked example's value in its scalars {example}, taken as written: the checker's "
                        "bodies are point masses, so it cannot tell whether the formula fits the example's body"
                    )
                out.append(LinkVerdict(d.line, label, source, "correct", f"defines {a.latex()} ({what})"))
                continue
            if j == 0:
                alias = self._rotation_alias(a, b, d.line)
                if alias:
                    out.append(LinkVerdict(d.line, label, source, "correct", alias))
                    continue
            if len(raw) == 2:
                v = self._define_vector(a, b, d.line, label, source)
                if v is not None:
                    remark = self._direction_remark(next_prose)
                    if remark:
                        v.message = _join(v.message, remark)
                    out.append(v)
                    continue
            for t in (a, b):
                self.seen |= {key(n) for n in walk(t) if isinstance(n, Sym) and n.base in VECTOR_NAMES}
            v = self.link(a, b, d.line, label, source)
            if example and v.status == "correct":
                v.message = _join(
                    f"an identity in the example's scalars {example}, checked for all their values", v.message
                )
            if (
                v.status == "correct"
                and len(raw) == 2
                and isinstance(a, Sym)
                and a.base == "I"
                and a.sub
                and not a.transposed
                and key(a) not in self.named
            ):  # a definition: say what it agrees with
                self.named.add(key(a))
                if a.frame:
                    what = f"the frame change of the inertia tensor into frame {a.frame}: R^{a.frame} I R^{a.frame}T"
                elif len(a.sub) == 1 and a.sub.isupper() and self.state.planar and not a.bold:
                    what = f"the moment of inertia about the axis through {a.sub} along z"
                elif len(a.sub) == 1 and a.sub.isupper():
                    what = f"the inertia tensor about {a.sub}"
                else:
                    what = f"the inertia tensor {a.latex()}"
                v.message = _join(f"agrees with {what}", v.message)
            if v.status == "wrong" and len(raw) == 2 and isinstance(a, Sym) and not a.transposed:
                self.overrides[key(a)] = (b, d.line, v)  # later lines may rely on the student's version
                if a.base == "I" and len(a.sub) == 1 and a.sub.isupper() and not a.frame:
                    v.message = _join(f"not the inertia tensor about {a.sub}", v.message)
            out.append(v)
        if len(raw) > 2:
            self._chain_ends(trees, raw, out)
        return out

    def _read_prose(self, prose: str) -> None:
        """Take in what the prose says the names mean (:mod:`.prose`) and fix those values."""
        facts = self.state.facts
        facts.read(prose)
        for point, coords in facts.points.items():
            self.placed["point", point] = _placed_point(coords, self.state)
        for name, coords in facts.vectors.items():
            self.placed["vector", name] = _placed_vector(coords, self.state)
            self.seen.add(key(Sym(name)))
            self.seen.add(key(Sym(name, True)))
        for name, (a, b, axis) in facts.distances.items():
            self.placed["vector", name] = _offset(a, b, axis)
            self.seen.add(key(Sym(name)))
            self.seen.add(key(Sym(name, True)))

    def _example_scalars(self, trees) -> str:
        """A line whose right-hand sides use only a worked example's scalars (``m``, ``l`` of "a rod of
        mass $m$ and length $l$") and numbers: those scalars as text ("m, l"), else ""."""
        scalars = self.state.facts.scalars
        if len(trees) < 2 or any(isinstance(t, Exception) for t in trees):
            return ""
        names = {n.base for t in trees[1:] for n in walk(t) if isinstance(n, Sym)}
        if not names or not names <= scalars:
            return ""
        return ", ".join(sorted(names))

    def _chain_ends(self, trees, raw, out) -> None:
        failing = [j for j, v in enumerate(out) if v.status == "wrong"]
        if not failing or any(isinstance(t, Exception) for t in trees):
            return
        try:
            ends = self._agree(trees[0], trees[-1], self.defs, self.instances)
        except Exception:  # noqa: BLE001
            return
        if not ends:
            return
        first = failing[0]
        middle = _short(raw[first + 1]) if first + 1 < len(raw) - 1 else _short(raw[first])
        note = f"the chain's ends agree: the slip is in the middle expression {middle}"
        for j in failing:
            out[j].message = _join(note, out[j].message)
            if j > first and j - 1 in failing:
                out[j].status = "follows-from-earlier-error"
                out[j].counterexample = out[j].left = out[j].right = None
                out[j].cause = out[first]
                out[j].message = _join(note, "this link compares that wrong expression with the next one")

    def _continuation(self, d: Display, tree, source) -> LinkVerdict:
        label = _short(d.text)
        if isinstance(tree, Exception):
            return LinkVerdict(d.line, label, source, "unrecognised", f"cannot read: {tree}")
        m = _JOIN.search(d.prose)
        if m is None:
            return LinkVerdict(
                d.line, label, source, "unrecognised", "an expression without '=' and no sentence saying what it equals"
            )
        word, noun = m.group(1).lower(), m.group(2).lower()
        summand = self._summand(word, noun, exclude=tree)
        if summand is None:
            return LinkVerdict(d.line, label, source, "unrecognised", f"no earlier sum has a {word} {noun}")
        line, (sign, term) = summand
        left = term if sign > 0 else Add(((-1, term),))
        prefix = f"the {word} {noun} of line {line} equals this"
        return self.link(left, tree, d.line, f"\\text{{({word} {noun} of line {line})}} = {d.text}", source, prefix)

    def _summand(self, word: str, noun: str, exclude=None):
        """The latest sum's ``word`` (first, second... last) summand: (line, (sign, tree))."""
        for line, s in reversed(self.sums):
            if exclude is not None and any(s is n for n in walk(exclude)):
                continue
            if noun == "integral" and not all(isinstance(t, Integral) for _, t in s.terms):
                continue
            index = len(s.terms) - 1 if word == "last" else _ORDINALS[word]
            if index < len(s.terms):
                return line, s.terms[index]
        return None

    def vanishing(self, d: Display) -> LinkVerdict | None:
        """Prose "the third integral vanishes": that summand of the latest sum is zero."""
        m = _VANISH.search(d.prose)
        if m is None:
            return None
        word, noun = m.group(1).lower(), m.group(2).lower()
        summand = self._summand(word, noun)
        if summand is None:
            return None
        line, (sign, term) = summand
        return self.link(
            term,
            Num(Fraction(0)),
            d.line,
            f"\\text{{({word} {noun} of line {line})}} = 0",
            f"the {word} {noun} vanishes",
            f"the {word} {noun} of line {line} vanishes",
        )

    def _direction_remark(self, prose: str) -> str:
        m = _FROM_TO.search(prose or "")
        if m is None or not getattr(self, "constant_def", None):
            return ""
        name, what = self.constant_def
        a, b = m.group(1), m.group(2)
        if what == f" = {a} - {b}":
            return (
                f"remark: {name}{what} points from {b} to {a}, while the text says from {a} to {b} "
                "(the result is unchanged: only |d|^2 and d d^T enter)"
            )
        return ""


def _named(node) -> bool:
    """A name with a subscript that no scalar of a worked example could be (``I_{end}``)."""
    return isinstance(node, Sym) and not node.transposed and not node.frame and bool(node.sub)


def _placed_point(coords, state):
    """A point at the prose's coordinates relative to the origin."""

    def place(inst):
        sc = Scope(inst, {}, state)
        values = [evaluate(t, sc).v[0] for t in coords]
        return inst.point(state.origin()) + Mat.col(values)

    return place


def _placed_vector(coords, state):
    def place(inst):
        sc = Scope(inst, {}, state)
        return Mat.col([evaluate(t, sc).v[0] for t in coords])

    return place


def _offset(a: str, b: str, axis: str):
    """The vector from point a to point b; without its component along ``axis`` (the offset
    between two parallel axes along it)."""

    def place(inst):
        v = inst.point(b) - inst.point(a)
        return Mat.col([0 if axis and i == "xyz".index(axis) else x for i, x in enumerate(v.v)])

    return place


def _zero(m) -> bool:
    return m.is_scalar and m.v[0] == 0


def _same(a, b) -> bool:
    if a.shape == b.shape:
        return a == b
    z = a if _zero(a) else b
    other = b if z is a else a
    return not any(other.v) if _zero(z) else False


def _states_center_fact(left, right) -> bool:
    """``\\int r_C dm = 0`` as written (either order)."""
    pair = (left, right)
    zero = any(isinstance(t, Num) and t.value == 0 for t in pair)
    integral = any(isinstance(t, Integral) and isinstance(t.body, Sym) and t.body.base in ("r", "rho") for t in pair)
    moment = any(  # \sum_i m_i x_i = 0: the same fact in one component
        isinstance(t, Sum)
        and isinstance(t.body, Mul)
        and len(t.body.factors) == 2
        and any(isinstance(f, Mass) for f in t.body.factors)
        and any(isinstance(f, Sym) and f.base == "r" for f in t.body.factors)
        for t in pair
    )
    return zero and (integral or moment)


def _short(text: str, n: int = 60) -> str:
    text = " ".join(text.split())
    return text if len(text) <= n else text[: n - 3] + "..."


def _join(a: str, b: str) -> str:
    return f"{a}; {b}" if a and b else a or b
