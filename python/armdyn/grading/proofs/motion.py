"""Time derivatives in a rigid-body proof: ``\\dot R``, ``\\dot L``, ``\\frac{d}{dt}(I \\omega)``.

What is understood (the body turns with angular velocity ``\\omega`` about a point fixed
in it, every named point is fixed in the body, everything is written in the world frame):

* ``\\dot\\omega``: the angular acceleration, a constant vector of its own (drawn at random,
  like ``\\omega``);
* ``\\dot R = S(\\omega) R`` for a rotation (the body's attitude);
* ``\\dot r_X = \\omega \\times r_X`` for a mass element's position relative to a point X of
  the body;
* ``\\dot I_X = S(\\omega) I_X - I_X S(\\omega)`` for an inertia tensor (``I_X = R I_X^b R^T``);
* ``L_X = I_X \\omega`` (``L``, ``H``, ``h``: the angular momentum about X, a point of the
  body that is its mass center or fixed), so ``\\dot L = I \\dot\\omega + \\omega \\times I \\omega``;
* ``N_X`` (``N``, ``\\tau``): the moment about X, ``\\dot L_X`` (Euler's law);
* the masses, ``M``, numbers and the constant vectors (``a``, ``b``, ``u``, ``v``, ``w``,
  ``p``) do not change; a name the proof defined is differentiated through its definition;
  sums, products (in their order), transposes, skew matrices and integrals over the body by
  the usual rules.

A quantity in another frame (``\\omega^c``, ``I^c``), a second derivative or a norm that is
not squared is not differentiated (the line is ``unrecognised``, saying so).
"""

from __future__ import annotations

from fractions import Fraction

from .expr import Add, Cross, Deriv, Div, Dot, Integral, Mass, Matrix, Mul, Norm, Num, Pow, Skew, Sum, Sym, Transpose
from .nodes import ENERGY, UnknownName, component, key

#: names of the angular momentum and of the moment (torque) about a point
MOMENTUM = {"L", "H", "h"}
MOMENT = {"N", "tau"}
_CONSTANT_VECTORS = {"a", "b", "u", "v", "w", "p"}
ZERO = Num(Fraction(0))


def omega(state) -> Sym:
    """The angular velocity the proof names (``\\omega_i`` once it wrote one)."""
    return Sym("omega", False, state.omega or "")


def momentum(s: Sym, state) -> Mul:
    """``L_X`` as ``I_X \\omega`` (X: the subscript point, else the proof's point, else C)."""
    point = s.sub if len(s.sub) == 1 and s.sub.isupper() else state.point or "C"
    return Mul((Sym("I", False, point), omega(state)))


def _is_zero(node) -> bool:
    return isinstance(node, Num) and node.value == 0


def _add(terms):
    kept = tuple((sign, t) for sign, t in terms if not _is_zero(t))
    if not kept:
        return ZERO
    return kept[0][1] if len(kept) == 1 and kept[0][0] == 1 else Add(kept)


def _product(factors, build):
    """Leibniz's rule for a product of the ``factors`` in order."""
    terms = []
    for j, f in enumerate(factors):
        df = derivative(f[0], f[1])
        if not _is_zero(df):
            terms.append((1, build([df if k == j else g[0] for k, g in enumerate(factors)])))
    return _add(terms)


def derivative(node, sc):
    """The tree of ``d/dt node`` (raises UnknownName for what is not understood)."""
    if isinstance(node, (Num, Mass)):
        return ZERO
    if isinstance(node, Sym):
        return _sym(node, sc)
    if isinstance(node, Add):
        return _add(tuple((sign, derivative(t, sc)) for sign, t in node.terms))
    if isinstance(node, Mul):
        return _product([(f, sc) for f in node.factors], lambda fs: Mul(tuple(fs)))
    if isinstance(node, Dot):
        return _product([(node.a, sc), (node.b, sc)], lambda fs: Dot(*fs))
    if isinstance(node, Cross):
        return _product([(node.a, sc), (node.b, sc)], lambda fs: Cross(*fs))
    if isinstance(node, Div):
        if not _is_zero(derivative(node.b, sc)):
            raise UnknownName("the time derivative of a quotient by a changing quantity is not understood")
        da = derivative(node.a, sc)
        return ZERO if _is_zero(da) else Div(da, node.b)
    if isinstance(node, Pow):
        if isinstance(node.base, Norm) and node.n == 2:  # d/dt |x|^2 = 2 x . x'
            dx = derivative(node.base.arg, sc)
            return ZERO if _is_zero(dx) else Mul((Num(Fraction(2)), Dot(node.base.arg, dx)))
        if node.n < 1:
            raise UnknownName("the time derivative of a negative power is not understood")
        return _product([(node.base, sc)] * node.n, lambda fs: Mul(tuple(fs)))
    if isinstance(node, Transpose):
        d = derivative(node.arg, sc)
        return ZERO if _is_zero(d) else Transpose(d)
    if isinstance(node, Skew):
        d = derivative(node.arg, sc)
        return ZERO if _is_zero(d) else Skew(d, node.transposed)
    if isinstance(node, (Integral, Sum)):  # the mass elements keep their mass
        d = derivative(node.body, sc)
        return ZERO if _is_zero(d) else type(node)(d) if isinstance(node, Sum) else Integral(d, node.domain)
    if isinstance(node, Matrix):
        return Matrix(tuple(tuple(derivative(c, sc) for c in row) for row in node.rows))
    if isinstance(node, Deriv):
        raise UnknownName("second time derivatives are not understood in a rigid-body proof")
    if isinstance(node, Norm):
        raise UnknownName("the time derivative of a norm that is not squared is not understood")
    raise UnknownName(f"cannot differentiate {type(node).__name__}")


def _sym(s: Sym, sc):
    state, env = sc.state, sc.env
    if key(s) in env:
        sc.guard += 1
        if sc.guard > 50:
            raise UnknownName(f"{s.latex()} is defined through itself")
        d = derivative(env[key(s)][0], sc)
        sc.guard -= 1
        return Transpose(d) if s.transposed and not _is_zero(d) else d
    plain = Sym(s.base, s.bold, s.sub, s.frame)
    if s.frame and s.base != "R":
        raise UnknownName(f"the time derivative of {s.latex()} (a quantity in frame {s.frame}) is not understood")
    if s.base in ("M", "m") or (s.base in ("I", "1", "E") and (s.bold or sc.in_integral) and not s.sub):
        return ZERO  # the mass, the identity
    if s.base == "omega":
        sc.notes.add("\\dot\\omega read as the angular acceleration (a vector of its own)")
        d = Sym("omegadot", False, s.sub)
    elif s.base in _CONSTANT_VECTORS or s.base == "d":
        return ZERO
    elif s.base == "R":
        d = Mul((Skew(omega(state)), plain))
        sc.notes.add("\\dot R read as S(omega) R (omega in the world frame)")
    elif s.base in ("r", "rho"):
        if component(s) is not None:
            raise UnknownName(f"the time derivative of a component ({s.latex()}) is not understood")
        d = Cross(omega(state), plain)
        sc.notes.add("\\dot r read as omega x r (a point of the body)")
    elif s.base == "I" and state.planar and not s.bold:
        raise UnknownName(f"the time derivative of a moment about an axis ({s.latex()}) is not understood")
    elif s.base == "I":
        w = Skew(omega(state))
        d = Add(((1, Mul((w, plain))), (-1, Mul((plain, w)))))
        sc.notes.add("\\dot I read as S(omega) I - I S(omega) (the tensor turns with the body)")
    elif s.base in MOMENTUM:
        return (
            derivative(momentum(plain, state), sc)
            if not s.transposed
            else Transpose(derivative(momentum(plain, state), sc))
        )
    elif (s.base, s.sub) in ENERGY:  # 1/2 \int (w x r).(w x r) dm
        r = Sym("r", False, state.point_sub)
        tree = Mul((Num(Fraction(1, 2)), Integral(Dot(Cross(omega(state), r), Cross(omega(state), r)))))
        return derivative(tree, sc)
    elif s.base == "omegadot":
        raise UnknownName("second time derivatives are not understood in a rigid-body proof")
    else:
        raise UnknownName(f"the time derivative of {s.latex()} is not understood")
    return Transpose(d) if s.transposed else d
