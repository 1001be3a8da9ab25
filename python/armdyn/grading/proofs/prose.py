"""What a proof's prose says its names mean: the facts a line alone cannot tell.

Read from the sentences before each display block, with inline math ``$...$``:

* "Let $\\mathbf{r}$ be the position of the mass element relative to a point A",
  "$\\boldsymbol{\\rho}$ its position relative to the mass centre C": the per-element vector
  that name stands for (``r`` relative to A, ``ρ`` relative to C);
* "Place the origin at the mass centre C": the point plain ``r`` and the components
  ``x_i``, ``y_i``, ``z_i`` are measured from;
* "Let A be the point $(a, b, 0)$", "$A = (a, b, 0)$": the point's coordinates (relative to
  the origin); their letters are the proof's scalars;
* "$\\mathbf{p} = (a, b, 0)^T$": a constant vector given by its components;
* "$d$ the distance between the axis through C along $z$ and the parallel axis through
  A": ``d`` is the offset between the two axes (``d^2`` its square);
* "a uniform rod of mass $m$ and length $l$": ``m``, ``l`` are a worked example's scalars
  (a shape is named: "a body of mass $m$" says nothing); "... about an axis through one
  end (its centre), perpendicular to it": the example's moment of inertia, which the first
  name of the example's line stands for (:func:`rod_moment`).

Only letters and the parser of :mod:`.expr` are used (nothing is evaluated); a sentence
that does not match says nothing.
"""

from __future__ import annotations

import re
from dataclasses import dataclass, field
from fractions import Fraction

from .expr import Mul, Num, Pow, ProofSyntaxError, Sym, parse_side

_CENTRE = r"(?:the\s+)?(?:mass\s+cent(?:re|er)|cent(?:re|er)\s+of\s+mass|barycent(?:re|er))"
#: "$X$ [be|is|denotes] the/its position [of ...] relative to|from [a point|the mass centre] P"
_POSITION = re.compile(
    r"\$([^$]{1,60})\$\s*(?:,\s*)?(?:be|is|denotes?|for)?\s*(?:the|its)\s+position\b"
    r"(?:[^.;$]|\$[^$]{0,40}\$){0,80}?\b(?:relative\s+to|from|with\s+respect\s+to)\s+"
    r"(?:(" + _CENTRE + r")\s*\$?([A-Z])?\$?|(?:a\s+|the\s+)?(?:point\s+)?\$?([A-Z])\$?)(?![A-Za-z])",
    re.IGNORECASE,
)
_ORIGIN = re.compile(r"\borigin\s+(?:is\s+)?(?:placed\s+)?at\s+(?:(" + _CENTRE + r")|(?:the\s+point\s+)?\$?([A-Z])\b)")
#: "A be the point $(a, b, 0)$", "$A = (a, b, 0)$"
_POINT = re.compile(
    r"\b([A-Z])\s+(?:be|is|denotes?)\s+the\s+point\s+\$\s*\(([^$()]{1,80})\)\s*\$|\$\s*([A-Z])\s*=\s*\(([^$()]{1,80})\)\s*\$"
)
#: "$\mathbf{p} = (a, b, 0)^T$"
_VECTOR = re.compile(r"\$([^$=]{1,40})=\s*\(([^$()]{1,80})\)\s*(?:\^\s*\{?\s*(?:T|\\top)\s*\}?)?\s*\$")
_DISTANCE = re.compile(
    r"\$([^$]{1,20})\$\s*(?:is\s+|be\s+|for\s+)?the\s+distance\s+between\s+the\s+(?:axis|line)\s+through\s+\$?([A-Z])\$?"
    r"(?:\s+(?:along|parallel\s+to)\s+\$?([xyz])\$?)?\s+and\s+the\s+(?:parallel\s+)?(?:axis|line)\s+through\s+\$?([A-Z])\b"
)
#: "a uniform rod of mass $m$ and length $l$ about an axis through one end, perpendicular to it"
_ROD = re.compile(
    r"\buniform\s+(?:thin\s+|slender\s+)?(?:rod|bar|beam)\s+of\s+mass\s+\$\s*([A-Za-z])\s*\$\s+and\s+length\s+"
    r"\$\s*([A-Za-z])\s*\$[^.;]{0,40}?\b(?:about|around)\s+(?:an?\s+|the\s+)?axis\s+through\s+(?:one\s+|its\s+|an\s+)?"
    r"(end|cent(?:re|er)|middle|midpoint)\b[^.;]{0,40}?\bperpendicular",
    re.IGNORECASE,
)
#: a uniform rod's mass distribution for its second moments: Simpson's rule, exact for the
#: quadratic integrand (position along the rod in units of its length, share of the mass)
ROD_POINTS = ((Fraction(0), Fraction(1, 6)), (Fraction(1, 2), Fraction(2, 3)), (Fraction(1), Fraction(1, 6)))
#: "a uniform rod of mass $m$ and length $l$": a worked example's scalars (a named shape, so
#: that "a body of mass $m$" stays the body's own mass)
_SHAPE = re.compile(
    r"\b(?:rod|bar|beam|disk|disc|sphere|ball|cylinder|plate|ring|hoop|cube|block|shell)s?\b[^.;]{0,120}", re.IGNORECASE
)
_PARAMETER = re.compile(
    r"\b(?:mass|length|radius|width|height|side|thickness)\s+\$\s*([A-Za-z]|\\[a-z]+)\s*\$",
    re.IGNORECASE,
)


@dataclass
class ProseFacts:
    """What the prose said so far (accumulated over a proof)."""

    positions: dict = field(default_factory=dict)  # name base -> point (r -> A, rho -> C)
    origin: str | None = None
    points: dict = field(default_factory=dict)  # point -> (x, y, z) trees, relative to the origin
    vectors: dict = field(default_factory=dict)  # name base -> (x, y, z) trees
    distances: dict = field(default_factory=dict)  # name base -> (from point, to point, axis or "")
    scalars: set = field(default_factory=set)  # letters read as scalars
    rod: tuple | None = None  # (mass letter, length letter, axis at "end" or "centre") of a worked example
    said: list = field(default_factory=list)  # how each was read, for the verdicts

    def read(self, prose: str) -> None:
        """Add what one stretch of prose says."""
        for m in _POSITION.finditer(prose):
            sym = _name(m.group(1))
            point = "C" if m.group(2) else m.group(4)
            if sym is not None and not sym.sub and point and sym.base in ("r", "rho"):
                self._say(
                    f"{sym.latex()} read as the element's position relative to {point} (as the text says)",
                    sym.base not in self.positions,
                )
                self.positions[sym.base] = point
        m = _ORIGIN.search(prose)
        if m is not None and self.origin is None:
            self.origin = "C" if m.group(1) else m.group(2)
        for m in _POINT.finditer(prose):
            point, coords = (m.group(1), m.group(2)) if m.group(1) else (m.group(3), m.group(4))
            trees = _coordinates(coords)
            if trees is not None and point not in self.points and point != "C":
                self.points[point] = trees
                self._scalars(trees)
        for m in _VECTOR.finditer(prose):
            sym = _name(m.group(1))
            trees = _coordinates(m.group(2))
            if sym is not None and not sym.sub and trees is not None and sym.base not in self.vectors:
                self.vectors[sym.base] = trees
                self._scalars(trees)
        for m in _DISTANCE.finditer(prose):
            sym = _name(m.group(1))
            if sym is not None and not sym.sub:
                self.distances[sym.base] = (m.group(2), m.group(4), m.group(3) or "")
        m = _ROD.search(prose)
        if m is not None:
            self.rod = (m.group(1), m.group(2), "end" if m.group(3).lower() == "end" else "centre")
        for shape in _SHAPE.finditer(prose):
            for m in _PARAMETER.finditer(shape.group(0)):
                sym = _name(m.group(1))
                if sym is not None and sym.base not in ("M",):
                    self.scalars.add(sym.base)

    def _scalars(self, trees) -> None:
        for t in trees:
            if isinstance(t, Sym) and not t.sub and len(t.base) == 1 and t.base.islower():
                self.scalars.add(t.base)

    def _say(self, text: str, new: bool) -> None:
        if new:
            self.said.append(text)


def rod_moment(mass: str, length: str, axis: str):
    """The moment of inertia of a uniform rod about a perpendicular axis through its end or
    its centre, from its mass distribution: ``sum share (x - x_axis)^2 * mass * length^2``
    (``m l^2 / 3``, ``m l^2 / 12``) as a tree in the example's two scalars."""
    at = Fraction(0) if axis == "end" else Fraction(1, 2)
    factor = sum((share * (x - at) ** 2 for x, share in ROD_POINTS), Fraction(0))
    return Mul((Num(factor), Sym(mass), Pow(Sym(length), 2)))


def _name(text: str) -> Sym | None:
    try:
        node = parse_side(text)
    except ProofSyntaxError:
        return None
    return node if isinstance(node, Sym) and not node.transposed and not node.frame else None


def _coordinates(text: str):
    """``a, b, 0`` -> three trees, or None."""
    parts = text.split(",")
    if len(parts) != 3:
        return None
    try:
        return tuple(parse_side(p) for p in parts)
    except ProofSyntaxError:
        return None
