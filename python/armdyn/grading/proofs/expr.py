"""Read one side of a proof line (LaTeX) into a typed expression tree; nothing is executed.

A small recursive-descent parser over :func:`armdyn.grading.latex.tokenize`'s tokens. Its
own tree rather than SymPy because the algebra of a rigid-body proof is not commutative
(``d r_C^T`` is not ``r_C d^T``, ``R I R^T`` is not ``I``), mixes scalars, vectors and 3x3
matrices, and holds integrals over the body; the tree is evaluated exactly on point-mass
bodies (:mod:`.evaluate`), which decides equality without any symbolic simplifier::

    expr    := ["+" | "-"] term (("+" | "-") term)*
    term    := factor (["\\cdot" | "*" | "\\times" | "/" | juxtaposition] factor)*
    factor  := atom ["^" script]           (script: an integer power, T / \\top / \\mathrm{T})
    atom    := number | name [scripts] | "(" expr ")" | "[" expr "]" ["_\\times"] | "{" expr "}"
             | "\\|" expr "\\|" | "\\frac{expr}{expr}" | "S" ["^T"] "(" expr ")"
             | "\\int" ["_" script] expr ("dm" | "\\rho dV") | "\\sum" ["_" index] term
             | ("\\tilde" | "\\hat") name | "\\dot" atom | "\\frac{d}{dt}" factor | "\\frac{dX}{dt}"
             | matrix environment

A sum over the particles ``\\sum_i m_i (...)`` is read with its index: ``m_i`` is the
particle's mass (:class:`Mass`), ``r_i`` its position (relative to O; ``r_{i,C}`` or
``r_{C,i}`` relative to C). ``\\tilde r``, ``\\hat r`` and ``r^\\times`` are the skew matrix
of ``r``; ``\\dot X``, ``\\frac{dX}{dt}``, ``\\frac{d}{dt}(...)`` its time derivative
(:class:`Deriv`, evaluated in :mod:`.motion`).

Names keep their typeface (bold ``\\mathbf{I}`` is the identity, plain ``I_{l_i}`` an inertia
tensor), subscript and superscript as text (:class:`Sym`); what a name means is decided
when it is evaluated. Limits (bounded time on hostile input): :data:`MAX_TOKENS`,
:data:`MAX_DEPTH`, :data:`MAX_INTEGRALS` nested integrals, integer exponents of at most
:data:`MAX_POWER`.
"""

from __future__ import annotations

import re
from fractions import Fraction

from ..latex import LatexError, tokenize
from .nodes import (  # noqa: F401  (re-exported: the tree's node types)
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

MAX_TOKENS = 4000
MAX_DEPTH = 40
MAX_INTEGRALS = 3
MAX_POWER = 8

_BOLD = {"mathbf", "boldsymbol", "bm", "pmb", "mathbold", "mathbb"}  # \mathbb{1}: the identity too
_WRAPPERS = {
    "mathrm",
    "mathit",
    "vec",
    "bar",
    "mathsf",
    "operatorname",
    "text",
    "mathcal",
    "textrm",
    "mathbb",
} | _BOLD
_MATRIX_ENVS = {"pmatrix", "bmatrix", "Bmatrix", "matrix", "smallmatrix", "array"}
#: subscripts that name the mass center: read as C
_CENTER = {"G": "C", "cm": "C", "CM": "C", "com": "C", "CoM": "C"}
_PARTICLE_POINT = re.compile(r"^(?:[a-z]+|\\?[a-z]+)[,/]([A-Z]|cm|G)$|^([A-Z]|cm|G)[,/][a-z]+$")
_STOP_CHARS = {"+", "-", ")", "]", "}", "=", "&", ",", ".", ";", "eof"}


class ProofSyntaxError(LatexError):
    """A proof line that could not be read (the message says what)."""


def _script_text(tokens) -> str:
    """A script's tokens as plain text: wrappers and braces dropped (``c\\mathrm{T}`` -> ``cT``)."""
    out = []
    for kind, value in tokens:
        if kind == "cmd" and (value in _WRAPPERS or value in ("left", "right")):
            continue
        if kind == "cmd" and value == "top":
            out.append("T")
        elif kind == "cmd" and value == "times":
            out.append("×")
        elif value in ("{", "}"):
            continue
        elif kind == "cmd":
            out.append(value)
        else:
            out.append(value)
    return "".join(out)


class _Parser:
    def __init__(self, tokens):
        if len(tokens) > MAX_TOKENS:
            raise ProofSyntaxError(f"a proof line of {len(tokens)} tokens (at most {MAX_TOKENS})")
        self.t = tokens
        self.i = 0
        self.depth = 0
        self.integrals = 0
        self.norms = 0
        self.sums: list = []  # the indices of the sums over particles being read

    def peek(self, k=0):
        j = self.i + k
        return self.t[j] if j < len(self.t) else ("eof", "eof")

    def take(self):
        tok = self.peek()
        self.i += 1
        return tok

    def expect(self, value):
        tok = self.take()
        if tok[1] != value:
            raise ProofSyntaxError(f"expected '{value}', found '{tok[1]}'")

    def enter(self):
        self.depth += 1
        if self.depth > MAX_DEPTH:
            raise ProofSyntaxError(f"nested deeper than {MAX_DEPTH} levels")

    # -- grammar
    def parse(self):
        node = self.expr()
        if self.peek()[0] != "eof":
            raise ProofSyntaxError(f"unexpected '{self.peek()[1]}'")
        return node

    def expr(self):
        self.enter()
        terms = []
        sign = 1
        if self.peek()[1] in ("+", "-"):
            sign = -1 if self.take()[1] == "-" else 1
        terms.append((sign, self.term()))
        while self.peek()[1] in ("+", "-"):
            sign = -1 if self.take()[1] == "-" else 1
            terms.append((sign, self.term()))
        self.depth -= 1
        if len(terms) == 1 and terms[0][0] == 1:
            return terms[0][1]
        return Add(tuple(terms))

    def differential(self) -> str | None:
        """``dm`` / ``dV`` / ``\\mathrm{d}m`` ahead (only inside an integral)."""
        if not self.integrals:
            return None
        k, v = self.peek()
        if (k, v) == ("char", "d") and self.peek(1)[1] in ("m", "V"):
            return self.peek(1)[1]
        if (
            k == "cmd"
            and v in ("mathrm", "text", "operatorname")
            and self.peek(1)[1] == "{"
            and self.peek(2)[1] == "d"
            and self.peek(3)[1] == "}"
            and self.peek(4)[1] in ("m", "V")
        ):
            return self.peek(4)[1]
        return None

    def take_differential(self):
        if self.peek()[1] == "d":
            self.i += 2
        else:
            self.i += 5

    def at_term_end(self) -> bool:
        k, v = self.peek()
        if k == "eof" or (k == "char" and v in _STOP_CHARS) or (k == "cmd" and v in ("right", "\\")):
            return True
        if k == "end":
            return True
        if self.norms and ((k == "cmd" and v in ("|", "rVert", "Vert")) or (k == "char" and v == "|")):
            return True
        return self.differential() is not None

    def term(self):
        self.enter()
        node = self.factor()
        factors = [node]
        while not self.at_term_end():
            k, v = self.peek()
            if k == "cmd" and v == "cdot":
                self.take()
                factors = [Dot(_mul(factors), self.factor())]
            elif k == "cmd" and v == "times":  # w \times I w: the product after it, w x (I w)
                self.take()
                right = [self.factor()]
                while not self.at_term_end() and not (self.peek()[0] == "cmd" and self.peek()[1] in ("cdot", "times")):
                    if self.peek()[1] in ("*", "/"):
                        break
                    right.append(self.factor())
                factors = [Cross(_mul(factors), _mul(right))]
            elif (k, v) == ("char", "*"):
                self.take()
                factors.append(self.factor())
            elif (k, v) == ("char", "/"):
                self.take()
                factors = [Div(_mul(factors), self.factor())]
            else:
                factors.append(self.factor())
        self.depth -= 1
        return _mul(factors)

    def script_tokens(self):
        """The tokens of one script: a single token or a braced group."""
        tok = self.take()
        if tok[1] != "{":
            if tok[0] == "cmd" and tok[1] in _WRAPPERS and self.peek()[1] == "{":
                return [tok] + self.script_tokens()
            return [tok]
        out, depth = [], 1
        while True:
            t = self.take()
            if t[0] == "eof":
                raise ProofSyntaxError("a script's '{' is never closed")
            if t[1] == "{":
                depth += 1
            elif t[1] == "}":
                depth -= 1
                if depth == 0:
                    return out
            out.append(t)

    def power(self, node):
        """``^`` after an atom: an integer power or a transpose."""
        while self.peek()[1] == "^":
            self.take()
            toks = self.script_tokens()
            text = _script_text(toks)
            if text == "T":
                node = Transpose(node)
                continue
            try:
                n = int(text)
            except ValueError:
                raise ProofSyntaxError(f"cannot read the exponent '{text}' (an integer or T)") from None
            if abs(n) > MAX_POWER:
                raise ProofSyntaxError(f"exponent {text[:20]} is too large (at most {MAX_POWER})")
            node = Pow(node, n)
        return node

    def factor(self):
        self.enter()
        node = self.power(self.atom())
        self.depth -= 1
        return node

    def group(self, close):
        node = self.expr()
        self.expect(close)
        return node

    def atom(self):
        k, v = self.take()
        if k == "num":
            return Num(Fraction(v))
        if k == "char" and v in ("(", "["):
            node = self.group(")" if v == "(" else "]")
            if v == "[" and self.peek()[1] == "_" and self.peek(1)[1] == "times":
                self.i += 2
                return Skew(node)
            return node
        if k == "char" and v == "{":
            node = self.group("}")
            return self.scripts_after(node) if isinstance(node, Sym) else node  # {\bf r}_i
        if k == "cmd" and v == "left":
            d = self.take()
            if d[1] in ("|", "Vert", "lVert"):
                return self.norm_rest()
            node = self.expr()
            self.expect("right")
            self.take()
            return node
        if (k == "cmd" and v in ("|", "Vert", "lVert")) or (k == "char" and v == "|"):
            return self.norm_rest()
        if k == "cmd" and v in ("frac", "dfrac", "tfrac"):
            derivative = self.time_derivative()
            if derivative is not None:
                return derivative
            a = self.frac_argument()
            b = self.frac_argument()
            return Div(a, b)
        if k == "cmd" and v == "int":
            return self.integral()
        if k == "cmd" and v == "sum":
            return self.particle_sum()
        if k == "cmd" and v in ("tilde", "hat", "widetilde", "widehat"):
            return self.skew_of_name()
        if k == "cmd" and v == "dot":
            self.enter()
            inner = self.atom()
            self.depth -= 1
            return Deriv(self.scripts_after(inner) if isinstance(inner, Sym) else inner)
        if k == "cmd" and v == "ddot":
            raise ProofSyntaxError("second time derivatives are not understood in a rigid-body proof")
        if k == "begin":
            return self.matrix(v)
        if k == "cmd" and v in ("bf", "rm", "it", "sf"):  # {\bf I}: an old-style font switch
            return self.name(self.take(), v == "bf")
        if k == "cmd" and v in _WRAPPERS:
            bold = v in _BOLD
            if self.peek()[1] != "{":
                return self.name(self.take(), bold)
            self.take()
            inner = self.take()
            if inner[0] == "num" and inner[1] != "1" and self.peek()[1] == "}":
                self.take()
                return Num(Fraction(inner[1]))  # \mathbf{0}: the zero vector (compares with any shape)
            if self.peek()[1] == "}":
                self.take()
                return self.name(inner, bold)
            self.i -= 1  # \mathbf{r_C}: scripts inside the braces
            node = self.name(self.take(), bold)
            self.expect("}")
            return self.scripts_after(node)
        if k in ("char", "cmd") and (v.isalpha() or v == "1"):
            return self.name((k, v), False)
        raise ProofSyntaxError(f"unexpected '{v}'")

    def frac_argument(self):
        """``{expr}``, or one digit of ``\\frac12``."""
        k, v = self.peek()
        if k == "num" and v.isdigit():
            if len(v) > 1:
                self.t[self.i] = ("num", v[1:])  # \frac12: numerator 1, the rest follows
            else:
                self.i += 1
            return Num(Fraction(int(v[0])))
        self.expect("{")
        return self.group("}")

    def _is_d(self, k: int) -> int:
        """Tokens of a ``d`` (or ``\\mathrm{d}``) at offset k, 0 if none."""
        if self.peek(k) == ("char", "d"):
            return 1
        if self.peek(k)[1] in ("mathrm", "text", "operatorname") and [self.peek(k + j)[1] for j in (1, 2, 3)] == [
            "{",
            "d",
            "}",
        ]:
            return 4
        return 0

    def time_derivative(self):
        """``\\frac{d}{dt} X`` or ``\\frac{dX}{dt}`` after ``\\frac``, else None (nothing taken)."""
        if self.peek()[1] != "{":
            return None
        n = self._is_d(1)
        if not n:
            return None
        if self.peek(1 + n)[1] == "}":  # \frac{d}{dt}
            after = 2 + n
            m = self._is_d(after + 1)
            if self.peek(after)[1] != "{" or not m or self.peek(after + 1 + m) != ("char", "t"):
                return None
            if self.peek(after + 2 + m)[1] != "}":
                return None
            self.i += after + 3 + m
            self.enter()
            node = Deriv(self.term())  # d/dt 1/2 w^T I w: the whole product after it
            self.depth -= 1
            return node
        save = self.i
        self.i += 1 + n
        try:
            inner = self.expr()
            self.expect("}")
            self.expect("{")
            m = self._is_d(0)
            if not m or self.peek(m) != ("char", "t") or self.peek(m + 1)[1] != "}":
                raise ProofSyntaxError("not a time derivative")
            self.i += m + 2
        except ProofSyntaxError:
            self.i = save
            return None
        return Deriv(inner)

    def particle_sum(self):
        """``\\sum_i m_i ...`` (the index from the script, else from the first ``m_x``)."""
        index = None
        while self.peek()[1] in ("_", "^"):
            mark = self.take()[1]
            text = _script_text(self.script_tokens())
            if mark == "_":
                index = text.split("=")[0].strip() or None
        if len(self.sums) >= MAX_INTEGRALS:
            raise ProofSyntaxError(f"sums nested deeper than {MAX_INTEGRALS}")
        self.sums.append(index)
        body = self.term()
        self.sums.pop()
        if not any(isinstance(n, Mass) for n in walk(body)):
            raise ProofSyntaxError("a sum over the particles without their masses m_i")
        return Sum(body)

    def particle(self, node: Sym):
        """A name inside a sum over particles: ``m_i`` the mass, ``r_i`` the position."""
        index = self.sums[-1]
        if node.base == "m" and not node.frame and node.sub and node.sub.isalpha() and node.sub.islower():
            if index is None:
                self.sums[-1] = index = node.sub
            if node.sub == index:
                return Mass()
        if node.base in ("x", "y", "z") and index and node.sub == index and not node.frame:
            return Sym("r", node.bold, node.base, "", node.transposed)  # x_i: particle i's coordinate
        if node.base == "r" and index and node.sub and (node.sub.startswith(index) or node.sub.endswith(index)):
            sub = node.sub[len(index) :] if node.sub.startswith(index) else node.sub[: -len(index)]
            sub = sub.strip(",/ ")
            return Sym("r", node.bold, _CENTER.get(sub, sub), node.frame, node.transposed)
        return node

    def skew_of_name(self):
        """``\\tilde{r}_C``, ``\\hat\\omega``: the skew matrix of the name (scripts after it)."""
        if self.peek()[1] == "{":
            self.take()
            inner = self.atom()
            self.expect("}")
        else:
            inner = self.atom()
        if isinstance(inner, Sym):
            inner = self.scripts_after(inner)
        if isinstance(inner, Sym) and inner.base in ("I", "R", "M", "E", "1"):
            return inner  # \tilde{\mathbf{I}}: a tilde that marks a tensor, not a skew matrix
        transposed = isinstance(inner, Sym) and inner.transposed
        if transposed:
            inner = Sym(inner.base, inner.bold, inner.sub, inner.frame, False)
        if isinstance(inner, Transpose):
            inner, transposed = inner.arg, True
        return Skew(inner, transposed)

    def norm_rest(self):
        self.norms += 1
        node = self.expr()
        self.norms -= 1
        if self.peek()[1] == "right":
            self.take()
        tok = self.take()
        if tok[1] not in ("|", "Vert", "rVert"):
            raise ProofSyntaxError("a norm \\| is never closed")
        return Norm(node)

    def name(self, tok, bold):
        kind, value = tok
        if kind not in ("char", "cmd", "num") or not (value.isalpha() or value == "1"):
            raise ProofSyntaxError(f"unexpected '{value}'")
        node = Sym(value, bold)
        return self.scripts_after(node)

    def scripts_after(self, node):
        if not isinstance(node, Sym):
            return node
        sub, sup = node.sub, node.frame + ("T" if node.transposed else "")
        while self.peek()[1] in ("_", "^"):
            mark = self.peek()[1]
            save = self.i
            self.take()
            toks = self.script_tokens()
            text = _script_text(toks)
            if mark == "_":
                sub += text
            else:
                if text.lstrip("-").isdigit():
                    self.i = save  # a power: handled by factor()
                    break
                sup += text
        skew = "×" in sup  # r^\times: the skew matrix of r
        sup = sup.replace("×", "")
        transposed = sup.endswith("T")
        frame = sup[:-1] if transposed else sup
        if node.base == "r":
            m = _PARTICLE_POINT.match(sub)  # r_{k,P}: particle k relative to P, in a line about each particle
            sub = next(g for g in m.groups() if g) if m else sub
        node = Sym(node.base, node.bold, _CENTER.get(sub, sub), frame, False if skew else transposed)
        if self.sums:
            node = self.particle(node)
            if isinstance(node, Mass):
                return node
        if skew:
            return Skew(Sym(node.base, node.bold, node.sub, node.frame), transposed)
        if node.base == "S" and self.peek()[1] in ("(", "left"):
            if self.peek()[1] == "left":
                self.take()
            self.expect("(")
            arg = self.expr()
            if self.peek()[1] == "right":
                self.take()
            self.expect(")")
            return Skew(arg, node.transposed)
        return node

    def integral(self):
        domain = ""
        while self.peek()[1] in ("_", "^"):
            mark = self.take()[1]
            text = _script_text(self.script_tokens())
            if mark == "^":
                raise ProofSyntaxError("an integral with bounds: only integrals over the body are understood")
            domain = text
        self.integrals += 1
        if self.integrals > MAX_INTEGRALS:
            raise ProofSyntaxError(f"integrals nested deeper than {MAX_INTEGRALS}")
        body = Num(Fraction(1)) if self.differential() is not None else self.expr()  # \int dm = M
        kind = self.differential()
        if kind is None:
            raise ProofSyntaxError("an integral without dm (or \\rho dV)")
        self.take_differential()
        self.integrals -= 1
        if kind == "V":
            body = _strip_density(body)
        return Integral(body, domain)

    def matrix(self, env):
        if env not in _MATRIX_ENVS:
            raise ProofSyntaxError(f"environment '{env}' is not a matrix")
        self.enter()
        rows, row = [], []
        while True:
            if self.peek()[0] == "end":
                self.take()
                break
            if self.peek()[0] == "eof":
                raise ProofSyntaxError(f"\\begin{{{env}}} is never closed")
            row.append(self.expr())
            k, v = self.peek()
            if v == "&":
                self.take()
            elif k == "cmd" and v == "\\":
                self.take()
                rows.append(tuple(row))
                row = []
            elif k != "end":
                raise ProofSyntaxError(f"unexpected '{v}' in a matrix")
        if row:
            rows.append(tuple(row))
        if not rows or len({len(r) for r in rows}) != 1:
            raise ProofSyntaxError("a matrix whose rows have different lengths")
        self.depth -= 1
        return Matrix(tuple(rows))


def _mul(factors):
    return factors[0] if len(factors) == 1 else Mul(tuple(factors))


def _is_rho(node) -> bool:
    return isinstance(node, Sym) and node.base == "rho" and not node.sub and not node.frame


def _strip_density(body):
    """``f \\rho dV`` is ``f dm``: take the density factor out of the integrand (the last
    plain ``\\rho``: a bold one, as in ``\\boldsymbol{\\rho}\\,\\rho\\,dV``, is a position)."""
    if _is_rho(body):
        return Num(Fraction(1))
    if isinstance(body, Mul) and any(_is_rho(f) for f in body.factors):
        rest = list(body.factors)
        plain = [j for j, f in enumerate(rest) if _is_rho(f) and not f.bold]
        del rest[plain[-1] if plain else max(j for j, f in enumerate(rest) if _is_rho(f))]
        return _mul(rest)
    raise ProofSyntaxError("an integral over dV without the density \\rho: only mass integrals (\\rho dV = dm)")


def parse_side(text: str):
    """One side of a proof line -> expression tree (raises :class:`ProofSyntaxError`)."""
    try:
        tokens = tokenize(text)
    except LatexError as err:
        raise ProofSyntaxError(str(err)) from None
    try:
        return _Parser(tokens).parse()
    except RecursionError:
        raise ProofSyntaxError("nested too deeply") from None
    except ValueError as err:  # Fraction of a malformed number
        raise ProofSyntaxError(str(err)) from None
