"""What the names of a rigid-body proof mean, and the exact value of an expression tree
(:mod:`.expr`) on one point-mass body (:mod:`.body`).

Name rules (the typeface and the scripts decide; ``r_i``, ``I_{l_i}`` as in the exercise):

* ``\\mathbf{I}``, ``\\mathbf{1}``, ``\\mathbb{1}``, ``\\mathbb{I}``, ``\\mathbf{E}`` (bold, no
  script), ``I_3``, ``E_3``, ``1_3``: the 3x3 identity. A plain ``I`` or ``E`` with no script is
  the identity inside an integral or a sum over the particles; outside one, ``I`` is an
  inertia tensor (rule below), ``E`` the kinetic energy of rotation.
* ``I_X`` with a point ``X`` (one capital letter: ``O``, ``C``, ``P``): the inertia tensor
  about ``X``, ``sum_k m_k (|p_k - X|^2 1 - (p_k - X)(p_k - X)^T)``. ``I`` with any other
  subscript (``I_{l_i}``) or none: the inertia tensor about the reference point of the
  proof's per-element vector (``r_i``: link i's reference point; C when it has none yet),
  said in the verdict.
* ``I^c``, ``I^c_{l_i}``: the same tensor in frame c, ``R^c I R^{cT}`` (``I^c`` alone: the
  inertia tensor the proof last named).
* ``r`` (relative to ``O``), ``r_X`` (relative to point ``X``; ``r_i``: to link i's reference
  point): the position of a mass element, so only meaningful inside an integral or in a
  line that holds for every element (then checked for every element); ``r_{ix}``,
  ``r_{iy}``, ``r_{iz}``: its components (``x_i``, ``y_i``, ``z_i`` inside a sum over the
  particles, from the origin); ``\\rho`` (outside ``\\rho dV``): the position relative to C.
  The prose may say otherwise (:mod:`.prose`: the point ``r`` is measured from, the origin).
* ``I_X`` (plain) in a proof whose components are ``x_i``, ``y_i`` and never ``z_i``: the
  moment of inertia about the axis through X along z (the zz entry).
* The letters the prose makes scalars (a point's coordinates ``a``, ``b``; a worked
  example's ``m``, ``l``): integers drawn like the coordinates.
* ``d``, ``p``, ``\\omega``, ``\\omega_i``, ``a``, ``b``, ``u``, ``v``, ``w``: constant vectors (``d`` is
  bound by a definition such as ``r_P = r_C + d``); ``\\omega^c``: ``R^c \\omega`` (the angular
  velocity the proof last named); ``R``, ``R^c``, ``R_c``: rotations.
* ``M``: the body's mass; ``m_i`` inside a sum over the particles: the particle's mass;
  ``E_{rot}`` (``E``, ``T_{rot}``, ``E_{kin}`` outside an integral):
  ``1/2 sum_k m_k |\\omega x r_k|^2``.
* ``L``, ``H``, ``h`` (``L_X``: about point X): the angular momentum ``I_X \\omega``; ``N``,
  ``\\tau`` (``N_X``): the moment, ``I_X \\dot\\omega + \\omega x I_X \\omega`` (Euler's law);
  ``\\dot\\omega``: the angular acceleration, a constant vector of its own (:mod:`.motion`).
* Any other name: :class:`UnknownName` (the line is ``unrecognised``).
"""

from __future__ import annotations

from dataclasses import dataclass, field
from fractions import Fraction

from ..latex import LatexError
from .body import Instance
from .expr import (
    Add,
    Cross,
    Deriv,
    Div,
    Dot,
    Integral,
    Mass,
    Matrix,
    Mul,
    Norm,
    Num,
    Pow,
    Skew,
    Sum,
    Sym,
    Transpose,
    walk,
)
from .matrices import Mat, ShapeError
from .motion import MOMENT, MOMENTUM, derivative, momentum
from .nodes import ENERGY, UnknownName, component, key  # noqa: F401  (importers name them here)
from .prose import ProseFacts

#: letters a proof line uses for vectors (3, 1): positions, velocities, angular velocity
VECTOR_NAMES = {"d", "p", "omega", "a", "b", "u", "v", "w", "omegadot"}
#: a line whose (conservative) polynomial degree exceeds this is not evaluated
MAX_DEGREE = 400


class NotRational(LatexError):
    """An expression whose value is not rational (a norm that is not squared)."""


def is_point(sub: str) -> bool:
    return len(sub) == 1 and sub.isupper()


def element_point(sub: str) -> str:
    """The point a per-element vector ``r_<sub>`` is measured from."""
    if not sub:
        return "O"
    return sub if is_point(sub) else f"ref:{sub}"


@dataclass
class ProofState:
    """What the proof is about so far: the per-element vector's point, the angular
    velocity and the inertia tensor last named (the name rules refer to them)."""

    point: str | None = None
    point_sub: str = ""
    omega: str | None = None
    inertia: str | None = None
    facts: ProseFacts = field(default_factory=ProseFacts)
    components: set = field(default_factory=set)  # the coordinate axes the proof's lines use

    @property
    def planar(self) -> bool:
        """Components x_i, y_i and never z_i: moments of inertia about axes along z."""
        return bool(self.components) and "z" not in self.components

    def origin(self) -> str:
        return self.facts.origin or "O"

    def element_point(self, sym: Sym) -> str:
        """The point a per-element vector is measured from (the prose's word first)."""
        if sym.base == "rho":
            return self.facts.positions.get("rho", "C")
        if not sym.sub:
            return self.facts.positions.get("r") or self.origin()
        return element_point(sym.sub)

    def scan(self, nodes) -> None:
        for node in nodes:
            for n in walk(node):
                if isinstance(n, Sym) and n.base == "r" and component(n) is None:
                    self.point, self.point_sub = self.element_point(n), n.sub
                elif isinstance(n, Sym) and n.base == "r":
                    self.components.add("xyz"[component(n)[1]])
                elif isinstance(n, Sym) and n.base == "omega" and n.sub:
                    self.omega = n.sub


@dataclass
class Scope:
    """Evaluation context: the body, the bindings the text made (name key -> tree), the
    proof state, the mass element (inside an integral, or for a per-element line)."""

    inst: Instance
    env: dict
    state: ProofState
    elem: int | None = None
    in_integral: bool = False
    notes: set = field(default_factory=set)
    guard: int = 0

    def at(self, elem: int | None, in_integral: bool) -> Scope:
        s = Scope(self.inst, self.env, self.state, elem, in_integral, self.notes, self.guard)
        return s


class NeedElement(Exception):
    """A per-element vector outside an integral: the line holds element by element."""


def inertia(inst: Instance, point: str) -> Mat:
    cache = inst.cache
    if ("I", point) not in cache:
        total = Mat.zeros(3, 3)
        for k, m in enumerate(inst.masses):
            r = inst.element(k, point)
            total = total + (Mat.identity().scale(r.dot(r)) - r @ r.T).scale(m)
        cache[("I", point)] = total
    return cache[("I", point)]


def _sym(s: Sym, sc: Scope) -> Mat:
    k = key(s)
    if k in sc.env:
        node = sc.env[k][0]
        sc.guard += 1
        if sc.guard > 50:
            raise UnknownName(f"{s.latex()} is defined through itself")
        inner = sc.at(sc.elem if sc.elem is not None else 0, sc.in_integral)
        value = evaluate(node, inner)
        sc.guard -= 1
        return value.T if s.transposed else value
    value = _builtin(s, sc)
    return value.T if s.transposed else value


def _frame(value: Mat, s: Sym, sc: Scope, tensor: bool) -> Mat:
    if not s.frame:
        return value
    rot = sc.inst.rotation(s.frame)
    return rot @ value @ rot.T if tensor else rot @ value


def is_identity(s: Sym, in_integral: bool) -> bool:
    """The 3x3 identity as people write it (see the module docstring)."""
    if s.frame or s.base not in ("I", "1", "E"):
        return False
    if s.sub == "3":
        return True
    return not s.sub and (s.bold or (in_integral and s.base != "1") or s.base == "1")


def _builtin(s: Sym, sc: Scope) -> Mat:
    inst, state = sc.inst, sc.state
    if is_identity(s, sc.in_integral):
        if s.base == "I" and s.bold and not s.sub and not sc.in_integral:
            sc.notes.add("\\mathbf{I} (bold, no subscript) read as the identity: an inertia tensor is I_O, I_C")
        return Mat.identity()
    if not s.sub and not s.frame and s.base in state.facts.scalars:
        return Mat.scalar(inst.scalar(s.base).v[0])
    if s.base in MOMENTUM | MOMENT and not s.frame and (not s.sub or is_point(s.sub)):
        tree = momentum(s, state)
        if s.base in MOMENT:
            tree = derivative(tree, sc)
        point = s.sub or state.point or "C"
        what = "angular momentum I omega" if s.base in MOMENTUM else "moment dL/dt (Euler's law)"
        sc.notes.add(f"{s.latex()} read as the {what} about {point}")
        return evaluate(tree, sc)
    if s.base == "I" and is_point(s.sub) and not s.bold and not s.frame and state.planar:
        sc.notes.add(
            f"{s.latex()} read as the moment of inertia about the axis through {s.sub} along z "
            "(the proof's components are x_i, y_i)"
        )
        return Mat.scalar(inertia(inst, s.sub)[2, 2])
    if s.base == "I":
        if is_point(s.sub):
            point = s.sub
        elif s.sub or not s.frame:
            point = state.point or "C"
            if state.point is None:
                sc.notes.add(f"{s.latex()} read as the inertia tensor about the mass center C (no point named yet)")
            frame = f", in frame {s.frame}" if s.frame else ""
            sc.notes.add(
                f"{s.latex()} read as the inertia tensor about the reference point of r_{state.point_sub}" + frame
                if state.point_sub
                else f"{s.latex()} read as the inertia tensor about {point}" + frame
            )
        else:
            if state.inertia is None:
                raise UnknownName(f"{s.latex()}: the frame-{s.frame} version of which inertia tensor?")
            point = state.inertia
            sc.notes.add(f"{s.latex()} read as the inertia tensor last named, in frame {s.frame}")
        if not s.frame:
            state.inertia = point
        return _frame(inertia(inst, point), s, sc, tensor=True)
    if s.base in ("r", "rho"):
        comp = component(s)
        if sc.elem is None:
            raise NeedElement()
        if comp is not None:
            point = element_point(comp[0]) if comp[0] else state.origin()
            return Mat.scalar(inst.element(sc.elem, point).v[comp[1]])
        point = state.element_point(s)
        if s.base == "rho" and "rho" not in state.facts.positions:
            sc.notes.add(f"{s.base} read as the element's position relative to the mass center C")
        elif not s.sub and (s.base in state.facts.positions or state.facts.origin):
            sc.notes.add(f"{s.base} read as the element's position relative to {point} (as the text says)")
        return _frame(inst.element(sc.elem, point), s, sc, tensor=False)
    if s.base in VECTOR_NAMES:
        sub = s.sub
        if s.base == "omega" and not sub and s.frame and state.omega is not None:
            sub = state.omega
            sc.notes.add(f"{Sym(s.base, False, '', s.frame).latex()} read as R^{s.frame} omega_{sub}")
        if not sub and s.base in state.facts.distances:
            a, b, axis = state.facts.distances[s.base]
            sc.notes.add(
                f"{s.base} read as the offset between the axes through {a} and {b}"
                + (f" along {axis}" if axis else "")
                + " (as the text says)"
            )
        elif not sub and s.base in state.facts.vectors:
            sc.notes.add(f"{s.base} read as the vector of components the text gives")
        base_key = key(Sym(s.base, s.bold, sub))
        if base_key in sc.env:
            value = evaluate(sc.env[base_key][0], sc.at(sc.elem if sc.elem is not None else 0, sc.in_integral))
        else:
            value = inst.vector(f"{s.base}_{sub}" if sub else s.base)
        return _frame(value, s, sc, tensor=False)
    if s.base == "R":
        return inst.rotation(s.frame or s.sub)
    if s.base == "M" and not s.sub and not s.frame:
        return Mat.scalar(inst.mass)
    if (s.base, s.sub) in ENERGY and not s.frame:
        omega = inst.vector(f"omega_{state.omega}" if state.omega else "omega")
        point = state.point or "O"
        total = Fraction(0)
        for k, m in enumerate(inst.masses):
            v = omega.cross(inst.element(k, point))
            total += m * v.dot(v)
        sc.notes.add(
            f"{s.latex()} read as the kinetic energy of rotation 1/2 \\int |omega x r|^2 dm"
            + (f" (r = r_{state.point_sub})" if state.point_sub else f" (r relative to {point})")
        )
        return Mat.scalar(total / 2)
    raise UnknownName(f"unknown name {s.latex()} (not a rigid-body quantity this checker knows)")


def evaluate(node, sc: Scope) -> Mat:
    """The exact value of a tree on ``sc.inst`` (raises ShapeError, UnknownName, NeedElement)."""
    if isinstance(node, Num):
        return Mat.scalar(node.value)
    if isinstance(node, Sym):
        return _sym(node, sc)
    if isinstance(node, Add):
        total = None
        for sign, t in node.terms:
            v = evaluate(t, sc)
            v = v if sign > 0 else -v
            total = v if total is None else total + v
        return total
    if isinstance(node, Mul):
        value = None
        for f in node.factors:
            v = Mat.identity() if _identity_e(f, node, sc) else evaluate(f, sc)
            value = v if value is None else value @ v
        return value
    if isinstance(node, Dot):
        a, b = evaluate(node.a, sc), evaluate(node.b, sc)
        if a.is_scalar or b.is_scalar:
            return a @ b
        return Mat.scalar(a.dot(b))
    if isinstance(node, Cross):
        return evaluate(node.a, sc).cross(evaluate(node.b, sc))
    if isinstance(node, Div):
        a, b = evaluate(node.a, sc), evaluate(node.b, sc)
        if not b.is_scalar:
            raise ShapeError(f"divides by {b.kind()}")
        if b.v[0] == 0:
            raise ZeroDivisionError("division by zero")
        return a.scale(1 / b.v[0])
    if isinstance(node, Pow):
        if isinstance(node.base, Norm):
            x = evaluate(node.base.arg, sc)
            sq = Mat.scalar(x.dot(x)) if not x.is_scalar else x @ x
            if node.n % 2:
                raise NotRational("an odd power of a norm (only squared norms are rational)")
            return sq.power(node.n // 2)
        value = evaluate(node.base, sc)
        if value.shape == (3, 1) and node.n % 2 == 0 and node.n > 0:  # (w x r)^2: the squared norm
            sc.notes.add("a vector squared read as its squared norm")
            return Mat.scalar(value.dot(value)).power(node.n // 2)
        return value.power(node.n)
    if isinstance(node, Norm):
        x = evaluate(node.arg, sc)
        if x.is_scalar:
            return Mat.scalar(abs(x.v[0]))
        raise NotRational("a norm that is not squared (write \\|x\\|^2)")
    if isinstance(node, Transpose):
        return evaluate(node.arg, sc).T
    if isinstance(node, Skew):
        x = evaluate(node.arg, sc).as_vector("S(.)")
        m = Mat.rows([[0, -x[2], x[1]], [x[2], 0, -x[0]], [-x[1], x[0], 0]])
        return m.T if node.transposed else m
    if isinstance(node, Integral):
        total = None
        for k, m in enumerate(sc.inst.masses):
            v = evaluate(node.body, sc.at(k, True)).scale(m)
            total = v if total is None else total + v
        return total
    if isinstance(node, Sum):
        total = None
        for k in range(len(sc.inst.masses)):
            v = evaluate(node.body, sc.at(k, True))
            total = v if total is None else total + v
        return total
    if isinstance(node, Mass):
        if sc.elem is None:
            raise UnknownName("a particle's mass m_i outside a sum over the particles")
        return Mat.scalar(sc.inst.masses[sc.elem])
    if isinstance(node, Deriv):
        return evaluate(derivative(node.arg, sc), sc)
    if isinstance(node, Matrix):
        cells = []
        for row in node.rows:
            for c in row:
                v = evaluate(c, sc)
                if not v.is_scalar:
                    raise ShapeError(f"a matrix entry is {v.kind()}")
                cells.append(v.v[0])
        return Mat(len(node.rows), len(node.rows[0]), cells)
    raise TypeError(f"cannot evaluate {type(node).__name__}")


def _identity_e(factor, product: Mul, sc: Scope) -> bool:
    """A plain ``E`` outside an integral that multiplies a scalar made of vectors
    (``\\|d\\|^2 E``, ``d^T d E``) is the identity, not the energy (said in the verdict)."""
    if not (isinstance(factor, Sym) and factor.base == "E" and not factor.sub and not factor.frame):
        return False
    if factor.bold or sc.in_integral:
        return False  # the identity anyway
    for other in product.factors:
        if other is not factor and any(
            isinstance(n, (Norm, Dot)) or (isinstance(n, (Sym, Transpose)) and getattr(n, "transposed", True))
            for n in walk(other)
        ):
            sc.notes.add("E read as the identity (it multiplies a scalar such as |d|^2)")
            return True
    return False


def per_element(node, env: dict) -> bool:
    """Does the tree hold a per-element vector outside every integral (a pointwise line)?"""
    stack, seen = [node], set()
    while stack:
        n = stack.pop()
        if isinstance(n, (Integral, Sum)):
            continue
        if isinstance(n, Sym):
            if n.base in ("r", "rho"):
                return True
            k = key(n)
            if k in env and k not in seen:
                seen.add(k)
                stack.append(env[k][0])
            continue
        stack.extend(_children(n))
    return False


def _children(n):
    if isinstance(n, Add):
        return [t for _, t in n.terms]
    if isinstance(n, Mul):
        return list(n.factors)
    if isinstance(n, (Dot, Cross, Div)):
        return [n.a, n.b]
    if isinstance(n, Pow):
        return [n.base]
    if isinstance(n, (Norm, Transpose, Skew, Deriv)):
        return [n.arg]
    if isinstance(n, Matrix):
        return [c for row in n.rows for c in row]
    return []


def degree(node) -> int:
    """A conservative degree of the tree's value as a polynomial in the drawn integers once
    the denominators (the mass M in the mass center, 1 + |a|^2 of each Cayley rotation) are
    cleared: leaves count numerator plus denominator degree, products add, sums take the
    maximum, an integral adds the mass."""
    if isinstance(node, Num):
        return 0
    if isinstance(node, Sym):
        if is_identity(node, False):
            return 0
        if node.base == "I":
            return 7 + (8 if node.frame else 0)
        if node.base in MOMENTUM:
            return 10
        if node.base in MOMENT:
            return 16
        if node.base in ("E", "T"):
            return 12
        if node.base == "R":
            return 4
        if node.base == "M":
            return 1
        return 3 + (4 if node.frame else 0)
    if isinstance(node, Add):
        return max(degree(t) for _, t in node.terms)
    if isinstance(node, Mul):
        return sum(degree(f) for f in node.factors)
    if isinstance(node, (Dot, Cross, Div)):
        return degree(node.a) + degree(node.b)
    if isinstance(node, Pow):
        return abs(node.n) * degree(node.base)
    if isinstance(node, Norm):
        return degree(node.arg)
    if isinstance(node, (Transpose, Skew)):
        return degree(node.arg)
    if isinstance(node, Deriv):  # each rule multiplies by omega (degree 3) at most once per factor
        return 2 * degree(node.arg) + 3
    if isinstance(node, Sum):
        return degree(node.body)
    if isinstance(node, Mass):
        return 1
    if isinstance(node, Integral):
        return 1 + degree(node.body)
    if isinstance(node, Matrix):
        return max(degree(c) for row in node.rows for c in row)
    return 0
