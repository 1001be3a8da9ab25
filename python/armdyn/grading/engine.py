"""Grading: one verdict per step, errors carried forward.

For each step the student wrote, in their order:

1. **Right?** Their value is compared with the expected one in each named convention
   (the usual one first). Equal in the usual one: ``correct``; in another:
   ``correct-by-convention`` (named).
2. **Supported?** The method's formula for the step is re-applied to the student's own
   earlier values (where they wrote an input step, their value; where they did not, what
   the method gives from theirs). A right value that none of these reproduces is
   ``correct-but-unsupported``, whichever earlier step held the error: the value a wrong
   step should have had (kept for the steps after it, see below) is a *repair*, never
   the student's own, at any depth.
3. **Carried forward?** A wrong value that one of those reproduces, with an earlier
   error in its inputs, ``follows-from-earlier-error`` (``caused_by`` names the earliest
   such error). Otherwise it is ``wrong``, explained against what the student's own
   earlier values give (so a slip is described by itself, not mixed with inherited ones).

Downstream, a step stands for the student's value; a step that is wrong on its own also
for what it should have been from their inputs (a slip that the student did not carry on
does not make every later step "wrong").

Equality is decided numerically at a few random points of every symbol (coordinates,
velocities, accelerations, parameters) with a relative tolerance of 1e-8, so exactness
modulo ``sin^2 + cos^2 = 1`` and any arrangement of terms count as equal; NaN never does.
Symbolic values are only built for what is shown (expected values, differences).
"""

from __future__ import annotations

import itertools
from dataclasses import dataclass

import numpy as np
import symengine as se
import sympy as sp

from .methods import Convention, Method, evaluate_context

#: sample points for the numeric comparison
SAMPLES = 4
RTOL = 1e-8
#: candidate combinations tried per step (inputs x conventions), beyond which the rest is skipped
MAX_COMBINATIONS = 64
#: the student's own rotations carried through the formulas beside the model's (World.use_rotation)
MAX_ALTERNATIVES = 3


def entries(value) -> tuple[list, tuple]:
    """The entries (row-major) and shape of a SymPy or SymEngine scalar or matrix."""
    if isinstance(value, (sp.MatrixBase, se.DenseMatrix)):
        return list(value), tuple(value.shape)
    return [value], (1, 1)


def to_sympy(value):
    """A SymEngine value (a generated derivation's step) as SymPy; SymPy unchanged."""
    if isinstance(value, se.DenseMatrix):
        return sp.Matrix(value.tolist())
    if isinstance(value, se.Basic):
        return sp.sympify(value)
    return value


class NumMat:
    """A float matrix with SymPy's matrix interface (``*`` multiplies matrices, ``.T``,
    ``.cross``, ``.dot``), so the Newton-Euler step formulas written for SymPy run on
    numbers at the sample points at NumPy speed."""

    __slots__ = ("a",)
    __array_priority__ = 100  # numpy scalars defer to our __rmul__

    def __init__(self, a):
        self.a = np.asarray(a, dtype=float)

    @staticmethod
    def of(x):
        if isinstance(x, NumMat):
            return x.a
        if isinstance(x, sp.MatrixBase):
            return np.array(x.evalf(), dtype=float)
        return float(x)

    @property
    def T(self):
        return NumMat(self.a.T)

    def __mul__(self, o):
        o = self.of(o)
        return NumMat(self.a @ o) if isinstance(o, np.ndarray) else NumMat(self.a * o)

    def __rmul__(self, o):
        o = self.of(o)
        return NumMat(o @ self.a) if isinstance(o, np.ndarray) else NumMat(o * self.a)

    def __add__(self, o):
        return NumMat(self.a + self.of(o))

    __radd__ = __add__

    def __sub__(self, o):
        return NumMat(self.a - self.of(o))

    def __rsub__(self, o):
        return NumMat(self.of(o) - self.a)

    def __neg__(self):
        return NumMat(-self.a)

    def cross(self, o):
        return NumMat(np.cross(self.a.ravel(), self.of(o).ravel()).reshape(3, 1))

    def dot(self, o):
        return float(self.a.ravel() @ self.of(o).ravel())


def _to_num(x):
    """A context entry evaluated at a point as NumMat / float (strings, lists as they are)."""
    if isinstance(x, sp.MatrixBase):
        return NumMat(np.array(x.evalf(), dtype=float))
    if isinstance(x, sp.Basic):
        return float(x)
    if isinstance(x, dict):
        return {k: _to_num(v) for k, v in x.items()}
    return x


def _from_num(x) -> np.ndarray:
    if isinstance(x, NumMat):
        return x.a.reshape(x.a.shape if x.a.ndim == 2 else (-1, 1))
    if isinstance(x, sp.MatrixBase):
        return np.array(x.evalf(), dtype=float)
    return np.array([[float(x)]])


class Sampler:
    """Random points of every symbol and fingerprints (values at those points)."""

    def __init__(self, symbols, robot, seed: int = 20261201):
        rng = np.random.default_rng(seed)
        self.symbols = sorted(set(symbols), key=str)
        q = set(robot.q)
        self.points = []
        for _ in range(SAMPLES):
            pt = {}
            for s in self.symbols:
                pt[s] = float(rng.uniform(-2.5, 2.5)) if s in q else float(rng.uniform(0.4, 1.6))
            self.points.append(pt)
        self._se_points = [{se.Symbol(s.name): se.RealDouble(v) for s, v in pt.items()} for pt in self.points]

    def fingerprint(self, value) -> np.ndarray:
        """(SAMPLES, rows, cols) values of a SymPy or SymEngine expression or matrix."""
        items, shape = entries(value)
        flat = [x if isinstance(x, se.Basic) else se.sympify(x) for x in items]
        out = np.empty((SAMPLES, len(flat)))
        # substitution, not Lambdify: building a Lambdify grows faster than linearly with
        # the expression (minutes for a generated 6-dof step), substituting is linear
        for k, pt in enumerate(self._se_points):
            out[k] = [_real(x.subs(pt) if x.free_symbols else x) for x in flat]
        return out.reshape(SAMPLES, *shape)


def _real(x) -> float:
    """A number as a float; NaN for what is not a finite real (0/0, log(-1)): NaN never
    compares equal, so such a value is never judged right."""
    try:
        return float(x)
    except (RuntimeError, TypeError, ValueError, OverflowError):
        return float("nan")


def equal(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """Per component (rows, cols): True where equal at every sample point."""
    if a.shape != b.shape:
        return np.zeros(a.shape[1:], dtype=bool)
    scale = np.maximum(1.0, np.maximum(np.abs(a), np.abs(b)).max(axis=0))
    ok = np.abs(a - b) <= RTOL * scale
    ok &= np.isfinite(a) & np.isfinite(b)
    return ok.all(axis=0)


@dataclass
class Value:
    """A candidate value of a step: numbers at the sample points, a way to build it
    symbolically, the student's wrong steps it inherits (``origins``) and the wrong steps
    whose value was replaced by what it should have been (``repaired``): a candidate with
    repairs is not what the student's own values give, so it never supports a step."""

    fp: np.ndarray
    build: object  # callable () -> sympy value
    origins: frozenset = frozenset()
    repaired: frozenset = frozenset()

    def sym(self):
        if callable(self.build):
            self.build = self.build()
        if isinstance(self.build, (se.DenseMatrix, se.Basic)):
            self.build = to_sympy(self.build)
        return self.build


class World:
    """A method's steps with the student's values put in as they are given."""

    def __init__(self, method: Method, ctx: dict, sampler: Sampler, numeric: bool):
        self.method = method
        self.sampler = sampler
        self.numeric = numeric  # formulas evaluate at points (True) or symbolically (False)
        self.ctx = ctx
        self.ctx_points = [_to_num(evaluate_context(ctx, pt)) for pt in sampler.points] if numeric else None
        exp_sym = method.expected(ctx)
        self.expected: dict = {}
        for ref in method.refs:
            self.expected[ref] = Value(self._fp_of(ref, exp_sym), exp_sym[ref])
        self.given: dict = {}  # ref -> list[Value]
        self._computed: dict = {}
        #: the student's own rotations, as the formulas would use them: (step name, ctx, ctx at the points)
        self.alternatives: list[tuple[str, dict, list | None]] = []
        #: names of alternatives not (yet) known to be errors: a value through one is never a reference
        self.unconfirmed: set[str] = set()

    def use_rotation(self, name: str, i: int, rotation, confirmed: bool) -> None:
        """Also carry the student's rotation ``rotation`` (frame-i coordinates to its parent
        frame, as the step ``name`` wrote it) through the formulas: a later step that it
        reproduces follows from ``name``. ``confirmed``: ``name`` is already an error. One
        per joint (the first written), at most :data:`MAX_ALTERNATIVES`: each multiplies
        the candidates of every formula."""
        if len(self.alternatives) >= MAX_ALTERNATIVES or any(
            a[1][i]["R"] is not self.ctx[i]["R"] for a in self.alternatives
        ):
            return
        ctx = {k: (dict(v) if isinstance(k, int) else v) for k, v in self.ctx.items()}
        ctx[i]["R"] = sp.Matrix(rotation)
        ctx["R0"] = {0: sp.eye(3)}
        for k in [x for x in ctx if isinstance(x, int)]:  # in the order the model built them: parents first
            ctx["R0"][k] = ctx["R0"][ctx[k]["parent"]] * ctx[k]["R"]
        points = [_to_num(evaluate_context(ctx, pt)) for pt in self.sampler.points] if self.numeric else None
        self.alternatives.append((name, ctx, points))
        if not confirmed:
            self.unconfirmed.add(name)
        self.invalidate()

    def _fp_of(self, ref, exp_sym):
        if self.numeric:
            if not hasattr(self, "_exp_points"):
                self._exp_points = [self.method.expected(c) for c in self.ctx_points]
            return np.stack([_from_num(e[ref]) for e in self._exp_points])
        return self.sampler.fingerprint(exp_sym[ref])

    # -- applying formulas and conventions to candidate values
    def apply(self, fn, values: list[Value], alternative=None) -> Value:
        """fn(ctx, *inputs) on candidate values: numbers at the points, symbols lazily
        (``alternative``: one of :attr:`alternatives`, whose context is used and whose
        name joins the origins)."""
        origins = frozenset().union(*(v.origins for v in values)) if values else frozenset()
        repaired = frozenset().union(*(v.repaired for v in values)) if values else frozenset()
        ctx, points = self.ctx, self.ctx_points
        if alternative is not None:
            origins, ctx, points = origins | {alternative[0]}, alternative[1], alternative[2]
        if self.numeric:
            fp = np.stack([_from_num(fn(c, *(_as_input(v.fp[k]) for v in values))) for k, c in enumerate(points)])
            return Value(fp, lambda: to_sympy(fn(ctx, *(v.sym() for v in values))), origins, repaired)
        sym = fn(ctx, *(v.sym() for v in values))
        return Value(self.sampler.fingerprint(sym), sym, origins, repaired)

    def candidates(self, ref) -> list[Value]:
        """What the student's work gives for ``ref``: their value(s) if they wrote it,
        else the method's formula over their inputs' candidates."""
        if ref in self.given:
            return self.given[ref]
        if ref in self._computed:
            return self._computed[ref]
        if ref not in self.method.formulas:
            out = [self.expected[ref]]
        else:
            out = self.carried(ref)
        self._computed[ref] = out
        return out

    def carried(self, ref, extra_refs=()) -> list[Value]:
        """The formula for ``ref`` over every combination of its inputs' candidates
        (and of ``extra_refs``, returned alongside as the last inputs)."""
        out = []
        for formula in self.method.formulas.get(ref, []):
            pools = [self.candidates(r) for r in formula.inputs]
            for combo in itertools.islice(itertools.product(*pools), MAX_COMBINATIONS):
                out.append(self.apply(formula.fn, list(combo)))
                out += [self.apply(formula.fn, list(combo), alt) for alt in self.alternatives]
        return _dedupe(out)

    def invalidate(self):
        self._computed.clear()


def _as_input(fp_k: np.ndarray):
    if fp_k.shape == (1, 1):
        return float(fp_k[0, 0])
    return NumMat(fp_k)


def _dedupe(values: list[Value]) -> list[Value]:
    """Candidates with distinct values; of equal ones, the fewest inherited errors and
    (independently: both are ways to the same numbers) the fewest repairs."""
    out: list[Value] = []
    for v in values:
        for j, w in enumerate(out):
            if equal(v.fp, w.fp).all():
                best = v if len(v.origins) < len(w.origins) else w
                repaired = min(v.repaired, w.repaired, key=len)
                out[j] = Value(best.fp, best.build, best.origins, repaired) if repaired != best.repaired else best
                break
        else:
            out.append(v)
    return out


@dataclass
class Judgement:
    status: str
    convention: str | None
    origins: frozenset
    reference: Value | None  # what the student's value is compared with when wrong
    conv: Convention  # the convention the value was judged in
    canon: Value | None = None  # the reference in canonical form


def judge(world: World, ref, got: Value, extra_candidates) -> Judgement:
    """The status of the student's value ``got`` (fingerprinted, shown form) of ``ref``."""
    method = world.method
    conventions = method.conventions_of(ref)
    exp = world.expected[ref]

    def shown(conv, value: Value, extras: list[Value]) -> Value:
        return world.apply(lambda c, v, *x: conv.forward(v, c, *x), [value, *extras])

    def extras_of(conv):
        return [extra_candidates(r) for r in conv.extra]

    # 1. right in some convention?
    for conv in conventions:
        for extras in itertools.product(*([world.expected[r]] for r in conv.extra)):
            if equal(got.fp, shown(conv, exp, list(extras)).fp).all():
                supported = _supported(world, ref, got, conv, extras_of)
                status = (
                    ("correct" if not conv.name else "correct-by-convention")
                    if supported
                    else "correct-but-unsupported"
                )
                return Judgement(status, conv.name or None, frozenset(), None, conv)
    # 2. carried forward from the student's own earlier values?
    carried = world.carried(ref) if ref in method.formulas else []
    best, best_key = None, None
    for conv in conventions:
        for value in carried:
            for extras in itertools.product(*extras_of(conv)):
                s = shown(conv, value, list(extras))
                ok = equal(got.fp, s.fp)
                if ok.all() and s.origins:
                    return Judgement("follows-from-earlier-error", conv.name or None, s.origins, s, conv, value)
                if s.origins & world.unconfirmed:
                    continue  # a rotation not known to be wrong is no reference for a slip
                key = (int((~ok).sum()), len(s.origins), conventions.index(conv))
                if best_key is None or key < best_key:
                    best, best_key = Judgement("wrong", conv.name or None, s.origins, s, conv, value), key
    if best is None:  # a leaf (given data) or no formula: compare with the expected value
        for conv in conventions:
            s = shown(conv, exp, [world.expected[r] for r in conv.extra])
            key = (int((~equal(got.fp, s.fp)).sum()), 0, conventions.index(conv))
            if best_key is None or key < best_key:
                best, best_key = Judgement("wrong", conv.name or None, frozenset(), s, conv, exp), key
    return best


def _supported(world: World, ref, got: Value, conv, extras_of) -> bool:
    """Does the formula over the student's own values give ``got``? (Leaves: yes.) A
    candidate that replaces a wrong earlier step by what it should have been (``repaired``,
    at any depth) is not the student's own."""
    if ref not in world.method.formulas:
        return True
    for value in world.carried(ref):
        if value.repaired:
            continue
        for extras in itertools.product(*extras_of(conv)):
            if any(e.repaired for e in extras):
                continue
            s = world.apply(lambda c, v, *x: conv.forward(v, c, *x), [value, *extras])
            if equal(got.fp, s.fp).all():
                return True
    return False


def canonical(world: World, conv, got: Value, extras: list[Value], origins) -> Value:
    """The student's shown value back in canonical form (for later steps)."""
    v = world.apply(lambda c, s, *x: conv.inverse(s, c, *x), [got, *extras])
    return Value(v.fp, v.build, frozenset(origins))
