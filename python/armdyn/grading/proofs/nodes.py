"""The typed expression tree of a proof line (:mod:`.expr` builds it, :mod:`.evaluate`
gives it a value, :mod:`.motion` differentiates it): names, numbers, sums, products in
their order, dot and cross products, quotients, powers, norms, transposes, skew matrices,
integrals over the body, sums over the particles, time derivatives and matrices."""

from __future__ import annotations

from dataclasses import dataclass
from fractions import Fraction

from ..latex import LatexError

#: kinetic energy of rotation: (name, subscript) as people write it
ENERGY = {("E", "rot"), ("E", "r"), ("E", "k"), ("E", "kin"), ("T", "rot"), ("E", "")}


class UnknownName(LatexError):
    """A name the proof checker gives no meaning to."""


@dataclass(frozen=True)
class Sym:
    """A name as written: base (``r``, ``omega``, ``I``, ``R``, ``1``...), bold typeface,
    subscript text (``C``, ``l_i``, ``ix``), frame label from the superscript (``c``) and
    whether the superscript transposes (``^T``, ``^{c\\mathrm{T}}``)."""

    base: str
    bold: bool = False
    sub: str = ""
    frame: str = ""
    transposed: bool = False

    def latex(self) -> str:
        """The name as plain text for messages: ``d``, ``omega_i``, ``I_{l_i}^c``, ``r_C^T``."""
        sub = "" if not self.sub else f"_{self.sub}" if len(self.sub) == 1 else f"_{{{self.sub}}}"
        sup = self.frame + ("T" if self.transposed else "")
        return self.base + sub + ("" if not sup else f"^{sup}" if len(sup) == 1 else f"^{{{sup}}}")


@dataclass(frozen=True)
class Num:
    value: Fraction


@dataclass(frozen=True)
class Add:
    terms: tuple  # ((sign +1/-1, node), ...)


@dataclass(frozen=True)
class Mul:
    factors: tuple  # left to right (matrix products keep their order)


@dataclass(frozen=True)
class Dot:
    a: object
    b: object


@dataclass(frozen=True)
class Cross:
    a: object
    b: object


@dataclass(frozen=True)
class Div:
    a: object
    b: object


@dataclass(frozen=True)
class Pow:
    base: object
    n: int


@dataclass(frozen=True)
class Norm:
    arg: object


@dataclass(frozen=True)
class Transpose:
    arg: object


@dataclass(frozen=True)
class Skew:
    arg: object
    transposed: bool = False


@dataclass(frozen=True)
class Integral:
    body: object
    domain: str = ""


@dataclass(frozen=True)
class Sum:
    """``\\sum_i m_i (...)``: the body summed over the particles (the masses are in it)."""

    body: object


@dataclass(frozen=True)
class Mass:
    """``m_i`` inside a sum over the particles: the particle's mass."""


@dataclass(frozen=True)
class Deriv:
    """The time derivative of ``arg`` (``\\dot X``, ``\\frac{d}{dt} X``)."""

    arg: object


@dataclass(frozen=True)
class Matrix:
    rows: tuple  # ((node, ...), ...)


def walk(node):
    """Every node of a tree, depth first."""
    stack = [node]
    while stack:
        n = stack.pop()
        yield n
        if isinstance(n, Add):
            stack.extend(t for _, t in n.terms)
        elif isinstance(n, Mul):
            stack.extend(n.factors)
        elif isinstance(n, (Dot, Cross, Div)):
            stack.extend((n.a, n.b))
        elif isinstance(n, (Pow,)):
            stack.append(n.base)
        elif isinstance(n, (Norm, Transpose, Skew)):
            stack.append(n.arg)
        elif isinstance(n, (Integral, Sum)):
            stack.append(n.body)
        elif isinstance(n, Deriv):
            stack.append(n.arg)
        elif isinstance(n, Matrix):
            stack.extend(c for row in n.rows for c in row)


def component(sym: Sym) -> tuple[str, int] | None:
    """``r_{ix}`` -> ("i", 0): a component of a per-element vector."""
    if sym.base == "r" and sym.sub and sym.sub[-1] in "xyz" and not sym.frame:
        return sym.sub[:-1], "xyz".index(sym.sub[-1])
    return None


def key(sym: Sym) -> str:
    """The name as a binding key (typeface of I matters, a transpose does not)."""
    bold = "b" if sym.bold and sym.base == "I" else ""
    return f"{sym.base}{bold}_{sym.sub}^{sym.frame}"
