"""The LaTeX a student writes for a derivation, read into SymPy.

Only what hand derivations of dynamics use is understood, and nothing is evaluated as
code: the text is tokenised and parsed here (a recursive-descent parser with a depth
bound), and every name goes through a ``resolve`` callback that maps the student's
symbols to the model's (or refuses them)::

    expr    := ["+" | "-"] term (("+" | "-") term)*
    term    := factor (["*" | "\\cdot" | "\\times" | "/" | juxtaposition] factor)*
               (a 3-vector \\times a 3-vector is the cross product, its right side a juxtaposed product)
    factor  := atom ["^" script]
    atom    := number | symbol | "(" expr ")" | "[" expr "]" | "{" expr "}"
             | "\\left(" expr "\\right)" | "\\frac{expr}{expr}" | "\\sqrt{expr}"
             | function [ "^" script ] argument | matrix
    symbol  := ["\\dot" | "\\ddot"] name ["_" script] ["^" script]   (wrappers such as
               \\mathbf, \\boldsymbol, \\hat are looked through)
    matrix  := "\\begin{pmatrix}" cell ("&" cell)* ("\\\\" ...)* "\\end{pmatrix}"  (also
               bmatrix, matrix, Bmatrix, vmatrix: rows by \\\\, cells by &)

Functions: \\sin \\cos \\tan \\exp \\ln \\log (also ``\\operatorname{sin}``);
``\\sin\\theta_1`` takes the next atom, ``\\sin^2\\theta`` is ``(\\sin\\theta)^2``. A symbol
reaches ``resolve`` as a :class:`Name` (letter or Greek name, number of dots, subscript and
superscript as text, and the scripts of ``{}^{2}_{1}R`` written before it). Primes
(``\\theta_1'``) count as dots: time derivatives. ``x^2_1`` is ``(x_1)^2``. Colours, spacing
and ``\\left.`` are dropped by the tokenizer; a ``{`` group starting with a sign after a
term (``a {\\color{red} - b}``) is added, not multiplied (braces are invisible in LaTeX).
"""

from __future__ import annotations

import sympy as sp

# the equations of a display block (split, sides): their own module, re-exported here
from .equations import side_offsets, sides, split_equations  # noqa: F401
from .latex_symbols import SymbolReader
from .latex_tables import (  # noqa: F401  (re-exported: the reader's tables and limits)
    ELIDED,
    FUNCTIONS,
    GREEK,
    MATRIX_ENVS,
    MAX_CALL_DEPTH,
    MAX_DEPTH,
    MAX_DIGITS,
    MAX_EXPONENT,
    MAX_LENGTH,
    MAX_SYMBOLIC_EXPONENT,
    SIZES,
    SPACES,
    UNICODE_GREEK,
    WRAPPERS,
    LatexError,
    Name,
    UnknownSymbol,
    short_number,
)
from .latex_tables import power as _power
from .latex_tokens import tokenize


class _Parser(SymbolReader):
    """The expressions (sums, products, powers, fractions, functions, brackets, matrices);
    the symbols are read by :class:`~armdyn.grading.latex_symbols.SymbolReader`."""

    def parse(self):
        try:
            value = self.expr()
            while self._closing_bar():  # \left. a \right| + b: the bar closes nothing
                value = value + self.expr() if self.peek()[0] != "eof" else value
        except LatexError as err:
            if err.pos is None:
                err.pos = self.at(self.i)
            raise
        while self.peek() in (("char", "."), ("char", ","), ("char", ";")):  # the sentence's end
            self.take()
        if self.peek()[0] != "eof":
            raise LatexError(f"unexpected '{self.peek()[1]}'", self.at(self.i))
        return value

    def _closing_bar(self) -> bool:
        """A ``\\right|`` (``\\right\\vert``) with no ``\\left`` before it (``\\left.`` is dropped): a bar
        around nothing, taken; with a script it evaluates at a point (``\\right|_{t=0}``): refused."""
        if self.peek() != ("cmd", "right") or self.peek(1) not in (("char", "|"), ("cmd", "vert"), ("cmd", "rvert")):
            return False
        if self.peek(2) in (("char", "_"), ("char", "^")):
            raise LatexError(
                "an evaluation bar \\right|_{...} (a value at a point) is not read: write the value there",
                self.at(self.i),
            )
        self.i += 2
        return True

    def expr(self):
        self.enter()
        sign = 1
        while self.peek() in (("char", "+"), ("char", "-")):
            sign *= -1 if self.take()[1] == "-" else 1
        value = sign * self.term()
        while self.peek() in (("char", "+"), ("char", "-")) or self._signed_group():
            if self._signed_group():  # a {\color{red} - b} term: the sign is inside
                value = value + self.term()
                continue
            op = self.take()[1]
            while self.peek() in (("char", "+"), ("char", "-")):  # "+ -b" (a row "+" then a row "-b")
                op = "-" if (op == "-") != (self.take()[1] == "-") else "+"
            nxt = self.term()
            value = value + nxt if op == "+" else value - nxt
        self.leave()
        return value

    def _starts_atom(self):
        kind, value = self.peek()
        if kind in ("num", "begin"):
            return True
        if kind == "char":
            return value.isalpha() or value in "([{"
        if kind == "cmd":
            return value not in ("right", "end", "\\", "cdot", "times", "}", "&") and value != "rbrace"
        return False

    def _signed_group(self) -> bool:
        """Is a ``{`` group starting with a sign next (``a {- b}``: braces are invisible in
        LaTeX, so that reads a - b, as a colour or an underbrace around a term writes it)?"""
        return self.peek() == ("char", "{") and self.peek(1) in (("char", "+"), ("char", "-"))

    def term(self):
        value = self.factor()
        while not self._signed_group():
            kind, tok = self.peek()
            if (kind, tok) == ("cmd", "times"):
                # a x b c: the cross product binds looser than juxtaposition (w x I w)
                self.take()
                right = self.factor()
                while self._starts_atom():
                    right = right * self.factor()
                value = _cross(value, right)
            elif (kind, tok) in (("char", "*"), ("cmd", "cdot"), ("cmd", "ast")):
                self.take()
                value = value * self.factor()
            elif (kind, tok) == ("char", "/"):
                self.take()
                value = value / self.factor()
            elif self._starts_atom():
                value = value * self.factor()
            else:
                return value
        return value

    def factor(self):
        self.enter()  # a^b^c...: each exponent nests one level
        base = self.atom()
        if self.peek() == ("char", "^"):
            at = self.at(self.i)
            self.take()
            if isinstance(base, sp.MatrixBase) and self._transpose_mark():
                self.leave()
                return base.T
            exponent = self.script_value()
            base = _power(base, exponent, at)
        self.leave()
        return base

    def _transpose_mark(self) -> bool:
        """After ``^`` on a matrix: ``T``, ``\\top``, ``\\intercal``, ``\\mathsf{T}``, in braces or
        not, in a typeface or not (``{\\mathrm{T}}``, ``{\\mathsf T}``): consumed when it is one."""
        n = self._script_length(0)
        if self.peek() != ("char", "{") and self.peek() in (("cmd", w) for w in WRAPPERS):
            n += self._script_length(1)  # ^\mathsf{T}: the typeface and its argument
        marks = [t for t in (self.peek(k) for k in range(n)) if t not in (("char", "{"), ("char", "}"))]
        marks = [t for t in marks if not (t[0] == "cmd" and t[1] in WRAPPERS)]
        if marks in ([("char", "T")], [("cmd", "top")], [("cmd", "intercal")]):
            self.i += n
            return True
        return False

    def script_value(self):
        """The exponent after ``^``: a group or a single token."""
        if self.peek() == ("char", "{"):
            self.take()
            value = self.expr()
            self.expect("char", "}")
            return value
        kind, tok = self.take()
        if kind == "num":
            return sp.Integer(tok) if tok.isdigit() else sp.Rational(tok)
        if kind == "char" and tok.isalpha():
            return self.resolve(Name(tok))
        raise LatexError(f"cannot read the exponent '{tok}'")

    def atom(self):
        kind, tok = self.peek()
        if kind == "num":
            self.take()
            return sp.Integer(tok) if tok.isdigit() else sp.Rational(tok)
        if kind == "begin":
            return self.matrix()
        if kind == "char":
            if tok in "([":
                self.take()
                value = self.expr()
                if tok == "(" and self.peek() == ("char", ","):  # (a, b, c): a row, usually ^T after it
                    row = self._row(value)
                    self.expect("char", ")")
                    return row
                self.expect("char", ")" if tok == "(" else "]")
                return value
            if tok == "{":
                self.take()
                if self.peek() == ("char", "}"):  # an empty group, e.g. {}^{1}
                    self.take()
                    if self.peek() in (("char", "^"), ("char", "_")):
                        return self._prescripted()
                    return sp.Integer(1)
                value = self.expr()
                self.expect("char", "}")
                return value
            if tok.isalpha():
                return self.symbol()
            raise LatexError(f"unexpected '{tok}'")
        if kind == "cmd":
            if tok == "left":
                self.take()
                opener = self.take()[1]
                if opener in ("(", "["):
                    value = self.expr()
                    if opener == "(" and self.peek() == ("char", ","):  # \left(a, b\right): a row too
                        value = self._row(value)
                    self.expect("cmd", "right")
                    self.take()
                    return value
                if opener in ("{", "lbrace"):
                    value = self.expr()
                    self.expect("cmd", "right")
                    self.take()
                    return value
                if opener in ("|", "vert", "lvert"):  # |x|: the absolute value of a scalar
                    at = self.at(self.i - 2)
                    value = self.expr()
                    self.expect("cmd", "right")
                    self.take()
                    if isinstance(value, sp.MatrixBase):
                        raise LatexError(
                            "\\left| ... \\right| around a matrix (a determinant or a norm) is not read", at
                        )
                    return sp.Abs(value)
                raise LatexError(f"unsupported bracket \\left{opener}")
            if tok in ("cancel", "bcancel", "xcancel"):  # struck through, still written: read as it stands
                self.take()
                return self._braced()
            if tok in ELIDED:
                raise LatexError(
                    f"\\{tok} in a matrix: a general matrix (its entries are not all written), not read as a value"
                    if self.matrices
                    else f"\\{tok}: {ELIDED[tok]}",
                    self.at(self.i),
                )
            if tok in ("pmatrix", "bmatrix", "matrix") and self.peek(1) == (
                "char",
                "{",
            ):  # plain TeX: \pmatrix{a \cr b}
                self.take()
                self.take()
                return self.matrix(tok, closer=("char", "}"))
            if tok in ("underbrace", "overbrace", "boxed"):  # a term's label or frame: the term is read
                self.take()
                value = self._braced()
                if tok != "boxed" and self.peek() in (("char", "_"), ("char", "^")):
                    self.take()
                    self.group_text()  # the label, words or a name: not part of the value
                return value
            if tok in ("frac", "dfrac", "tfrac"):
                derivative = self._time_derivative()
                if derivative is not None:
                    return derivative
                if self._derivative_fraction():
                    raise LatexError(
                        "a derivative written as a fraction (d/dt, \\partial): a value is read worked out, "
                        "in the joint variables and parameters",
                        self.at(self.i),
                    )
                self.take()
                self.enter()
                num = self._frac_arg()
                den = self._frac_arg()
                self.leave()
                return num / den
            if tok == "sqrt":
                self.take()
                self.enter_call()
                value = sp.sqrt(self._braced())
                self.calls -= 1
                return value
            if tok in FUNCTIONS:
                return self.function()
            if tok in ("dot", "ddot", "dddot") or tok in GREEK or tok in WRAPPERS:
                return self.symbol()
            if tok == "{":  # \{ as a bracket
                self.take()
                value = self.expr()
                self.expect("cmd", "}")
                return value
            raise LatexError(f"unsupported command \\{tok}")
        raise LatexError("unexpected end of equation" if kind == "eof" else f"unexpected '{tok}'")

    def _time_derivative(self):
        """``\\frac{d\\theta_1}{dt}``, ``\\frac{\\mathrm{d}^2 q}{\\mathrm{d}t^2}``: a symbol's time
        derivative (read as its dots), or None with nothing taken (an operator, a partial)."""
        saved = self.i, self.depth, self.calls  # an accent left open on error is closed again
        try:
            self.take()  # \frac
            self.expect("char", "{")
            order = self._d_mark()
            value = self._symbol(dots_added=order) if order else None
            if value is not None and self.take() == ("char", "}") and self.take() == ("char", "{"):
                if self._d_mark(False) == 1 and self.take() == ("char", "t") and self._d_order() == order:
                    if self.take() == ("char", "}"):
                        return value
        except UnknownSymbol:
            raise
        except LatexError:
            pass
        self.i, self.depth, self.calls = saved
        return None

    def _d_mark(self, ordered: bool = True) -> int:
        """Take ``d`` or ``\\mathrm{d}`` (and, when ``ordered``, a power ``^2``): the order, or 0."""
        if self.peek() == ("char", "d"):
            self.take()
        elif [self.peek(k) for k in range(4)] == [("cmd", "mathrm"), ("char", "{"), ("char", "d"), ("char", "}")]:
            self.i += 4
        else:
            return 0
        return self._d_order() if ordered else 1

    def _d_order(self) -> int:
        """A derivative's order written as a power after ``d`` or ``dt`` (``^2``, ``^{2}``): 1 if none."""
        if self.peek() != ("char", "^"):
            return 1
        self.take()
        braced = self.peek() == ("char", "{")
        if braced:
            self.take()
        kind, tok = self.take()
        if braced and self.take() != ("char", "}") or kind != "num" or not tok.isdigit() or int(tok) > 3:
            return 0
        return int(tok)

    def _derivative_fraction(self) -> bool:
        """Is the ``\\frac`` next ``\\frac{d}{dt}``, ``\\frac{\\mathrm{d}}{\\mathrm{d}t}`` or
        ``\\frac{\\partial L}{\\partial q}`` (an operator, not a quotient)?"""

        def starts_d(k: int, alone: bool) -> bool:  # the group at k starts with d, \mathrm{d}, \partial
            if self.peek(k) != ("char", "{"):
                return False
            first = self.peek(k + 1)
            if first == ("cmd", "partial"):
                return True
            if first == ("cmd", "mathrm"):
                return self.peek(k + 2) == ("char", "{") and self.peek(k + 3) == ("char", "d")
            after = self.peek(k + 2)  # d then a letter or a command: dt, d\theta (d_2 is a name)
            letter = after[0] == "cmd" or after[0] == "char" and (after[1].isalpha() or after[1] == "^")
            return first == ("char", "d") and (letter or alone and after == ("char", "}"))

        return starts_d(1, True) and starts_d(1 + self._script_length(1), False)

    def _frac_arg(self):
        """A fraction's numerator or denominator: a group, or one digit or symbol (``\\frac12``)."""
        kind, tok = self.peek()
        if (kind, tok) == ("char", "{"):
            return self._braced()
        if kind == "num":
            if len(tok) > 1 and tok[1].isdigit():  # \frac12: the digits are two arguments
                return sp.Integer(self._first_character())
            self.take()
            return sp.Integer(tok) if tok.isdigit() else sp.Rational(tok)
        if kind == "char" and tok.isalpha() or kind == "cmd" and tok in GREEK:
            start = self.at(self.i)
            _, base, _ = self._accented()
            return self._resolve(Name(base), start)
        return self._braced()

    def _row(self, first):
        """``first, b, c``: the rest of a comma-separated row after its first entry, as a 1×n matrix."""
        row = [first]
        while self.peek() == ("char", ","):
            self.take()
            row.append(self.expr())
        return sp.Matrix([row])

    def _braced(self):
        self.expect("char", "{")
        value = self.expr()
        self.expect("char", "}")
        return value

    def function(self):
        fn = FUNCTIONS[self.take()[1]]
        self.enter()  # \sin\sin\sin...: each nests one level
        self.enter_call()
        power = None
        at = self.at(self.i)
        if self.peek() == ("char", "^"):
            self.take()
            power = self.script_value()
        value = fn(self.atom())  # a bracketed group, or the next symbol: \sin\theta_1
        self.leave()
        self.calls -= 1
        return _power(value, power, at) if power is not None else value

    def matrix(self, env: str | None = None, closer: tuple | None = None):
        """``\\begin{pmatrix} ... \\end{pmatrix}`` (or plain TeX's ``\\pmatrix{...}``, ``closer``
        its brace, the opener taken): rows by ``\\\\`` (``\\cr``), cells by ``&``."""
        if env is None:
            env = self.take()[1]
        if env not in MATRIX_ENVS:
            raise LatexError(f"unsupported environment {env}")
        self.enter()
        self.matrices += 1
        rows, row = [], []
        while True:
            kind, tok = self.peek()
            if kind == "end" or closer is not None and (kind, tok) == closer:
                self.take()
                break
            if kind == "eof":
                raise LatexError(f"\\begin{{{env}}} without \\end{{{env}}}")
            if (kind, tok) == ("cmd", "\\"):
                self.take()
                continue
            cell = self.expr()
            row.append(cell)
            kind, tok = self.peek()
            if (kind, tok) == ("char", "&"):
                self.take()
                continue
            if (kind, tok) == ("cmd", "\\") or kind == "end" or closer is not None and (kind, tok) == closer:
                rows.append(row)
                row = []
                continue
            raise LatexError(f"unexpected '{tok}' in a matrix")
        if row:
            rows.append(row)
        self.matrices -= 1
        self.leave()
        if not rows or len({len(r) for r in rows}) != 1:
            raise LatexError("a matrix whose rows have different lengths")
        return sp.Matrix(rows)


def _cross(a, b):
    """``a \\times b``: the cross product of two 3-vectors, else the product."""
    if isinstance(a, sp.MatrixBase) and isinstance(b, sp.MatrixBase) and a.shape == b.shape == (3, 1):
        return a.cross(b)
    return a * b


def parse(text: str, resolve) -> sp.Expr | sp.Matrix:
    """Parse one LaTeX expression; ``resolve(Name) -> sympy`` maps each symbol. A
    :class:`LatexError` carries ``pos``, the offset in ``text`` where reading stopped."""
    positions: list[int] = []
    return _Parser(tokenize(text, positions), resolve, positions, len(text)).parse()
