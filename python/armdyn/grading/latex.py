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

import re
from dataclasses import dataclass, field

import sympy as sp

from ..symbolic.names import GREEK as GREEK_LETTERS

# the equations of a display block (split, sides): their own module, re-exported here
from .equations import side_offsets, sides, split_equations  # noqa: F401

#: nesting depth (parentheses, groups, fractions, matrices) beyond which input is refused
MAX_DEPTH = 60
#: largest numeric exponent accepted (10^{10^{10}} must not make SymPy compute)
MAX_EXPONENT = 100
#: characters in one equation beyond which it is refused
MAX_LENGTH = 200_000
#: digits of a number written or of a numeric power (9^{99^{99}}) beyond which it is refused
MAX_DIGITS = 400
#: largest numeric exponent of an expression in the symbols (x^{999}): SymPy splits x^n into
#: real and imaginary parts by expanding (a + i b)^n, in time growing as n^3 (0.3 s for 100)
MAX_SYMBOLIC_EXPONENT = 20
#: function calls and square roots nested in each other beyond which input is refused: SymPy
#: works out real and imaginary parts (when it simplifies sqrt(x^2) or shows a difference) in
#: time exponential in this nesting (12 nested cosines took 20 s, 16 over a minute)
MAX_CALL_DEPTH = 4

#: Greek letters written \alpha ... \Omega (symbolic/names.py holds the one table)
GREEK = frozenset(GREEK_LETTERS)
#: a Greek letter typed as Unicode -> its LaTeX name
UNICODE_GREEK = {letter: name for name, letter in GREEK_LETTERS.items()}
FUNCTIONS = {
    "sin": sp.sin,
    "cos": sp.cos,
    "tan": sp.tan,
    "exp": sp.exp,
    "ln": sp.log,
    "log": sp.log,
    "sec": sp.sec,
    "csc": sp.csc,
    "cot": sp.cot,
}
#: wrappers that change a symbol's typeface, not its meaning
WRAPPERS = {
    "mathbf",
    "boldsymbol",
    "bm",
    "mathrm",
    "mathit",
    "vec",
    "hat",
    "bar",
    "mathbold",
    "pmb",
    "mathsf",
    "operatorname",
    "text",
    "mathcal",
    "tilde",
}
SPACES = {
    ",",
    ";",
    ":",
    "!",
    " ",
    "quad",
    "qquad",
    "displaystyle",
    "textstyle",
    "left.",
    "right.",
    "limits",
    "nolimits",
}
#: sizing commands before a delimiter (\big( ... \big)): they change its size, not the math
SIZES = {
    "big",
    "Big",
    "bigg",
    "Bigg",
    "bigl",
    "bigr",
    "Bigl",
    "Bigr",
    "biggl",
    "biggr",
    "Biggl",
    "Biggr",
    "bigm",
    "Bigm",
}
MATRIX_ENVS = {"pmatrix", "bmatrix", "Bmatrix", "matrix", "vmatrix", "smallmatrix", "array"}


class LatexError(ValueError):
    """LaTeX that could not be read (the message says what; ``pos``, when known, is the
    0-based character offset in the parsed text where reading stopped)."""

    def __init__(self, message: str, pos: int | None = None):
        super().__init__(message)
        self.pos = pos


class UnknownSymbol(LatexError):
    """A symbol the resolver does not know."""


@dataclass(frozen=True)
class Name:
    """A symbol as the student wrote it: ``\\ddot{\\theta}_1`` is Name("theta", 2, "1", "")."""

    base: str
    dots: int = 0
    sub: str = ""
    sup: str = ""
    pre_sup: str = ""  # {}^{2}_{1}R: the scripts written before the name (a step's frames)
    pre_sub: str = ""
    #: written under \hat (``\hat X_1``: a unit vector); not part of the name's identity
    hat: bool = field(default=False, compare=False)

    def latex(self) -> str:
        base = f"\\{self.base}" if self.base in GREEK else self.base
        if self.dots:
            base = "\\" + "d" * self.dots + "ot{" + base + "}"
        sub = f"_{{{self.sub}}}" if self.sub else ""
        pre = ""
        if self.pre_sup or self.pre_sub:
            pre = (
                "{}"
                + (f"^{{{self.pre_sup}}}" if self.pre_sup else "")
                + (f"_{{{self.pre_sub}}}" if self.pre_sub else "")
            )
        return pre + base + sub


_TOKEN = re.compile(
    r"(?P<skip>\\(?:color|textcolor)\s*\{[^{}]*\}|\\(?:left|right)\.|\\[hv]space\*?\{[^{}]*\}|~)"
    r"|\\(?:operatorname|mathrm)\s*\{\s*(?P<fn>sin|cos|tan|exp|ln|log|sec|csc|cot)\s*\}"
    r"|\\begin\{(?P<begin>[A-Za-z*]+)\}(?:\{[^{}]*\})?"
    r"|\\end\{(?P<end>[A-Za-z*]+)\}"
    r"|\\(?P<cmd>[A-Za-z]+|.)"
    r"|(?P<num>\d+(?:\.\d*)?|\.\d+)"
    r"|(?P<char>\S)"
    r"|(?P<space>\s+)",
    re.S,
)


def tokenize(text: str, positions: list | None = None) -> list[tuple[str, str]]:
    """Tokens ``(kind, value)``: kind is begin, end, cmd, num or char; spaces, sizing
    commands and colours (``\\color{red}``, ``\\textcolor{red}``) dropped. ``positions``, if given, receives each token's offset in ``text``."""
    if len(text) > MAX_LENGTH:
        raise LatexError(f"equation too long ({len(text)} characters, at most {MAX_LENGTH})")
    out = []
    for m in _TOKEN.finditer(text):
        kind = m.lastgroup
        if kind in ("space", "skip"):  # \color{red}, \left., ~: how it looks, not what it says
            continue
        value = m.group(kind)
        if kind == "fn":  # \operatorname{sin}: \sin
            kind = "cmd"
        if kind == "cmd" and value == "cr":  # plain TeX's row end, as in \pmatrix{a \cr b}
            value = "\\"
        if kind == "cmd" and (value in SPACES or value in SIZES):
            continue
        if kind == "num" and len(value) > MAX_DIGITS:
            raise LatexError(f"a number with {len(value)} digits (at most {MAX_DIGITS})", m.start())
        if kind == "char" and value in UNICODE_GREEK:
            kind, value = "cmd", UNICODE_GREEK[value]
        if (kind, value) in (("cmd", "ell"), ("char", "\u2113")):  # \ell, ℓ: the letter l (a length)
            kind, value = "char", "l"
        out.append((kind, value))
        if positions is not None:
            positions.append(m.start())
    return out


class _Parser:
    def __init__(self, tokens, resolve, positions=None, length: int | None = None):
        self.t = tokens
        self.i = 0
        self.resolve = resolve
        self.depth = 0
        self.calls = 0  # function calls and square roots open around the current token
        self.positions = positions or []
        self.length = length

    def at(self, k: int) -> int | None:
        """The text offset of token ``k`` (the end of the text past the last one)."""
        if k >= len(self.positions):
            return self.length
        return self.positions[max(k, 0)] if self.positions else None

    # -- helpers
    def peek(self, k=0):
        j = self.i + k
        return self.t[j] if j < len(self.t) else ("eof", "")

    def take(self):
        tok = self.peek()
        self.i += 1
        return tok

    def expect(self, kind, value=None):
        tok = self.take()
        if tok[0] != kind or (value is not None and tok[1] != value):
            want = value if value is not None else kind
            found = "\\" + tok[1] if tok[0] == "cmd" else tok[1]
            raise LatexError(f"expected '{want}', found '{found or 'end of equation'}'", self.at(self.i - 1))
        return tok

    def enter(self):
        self.depth += 1
        if self.depth > MAX_DEPTH:
            raise LatexError(f"nesting deeper than {MAX_DEPTH} levels", self.at(self.i))

    def leave(self):
        self.depth -= 1

    def enter_call(self):
        """One function call (or square root) deeper; refused beyond MAX_CALL_DEPTH."""
        self.calls += 1
        if self.calls > MAX_CALL_DEPTH:
            raise LatexError(f"nesting of functions deeper than {MAX_CALL_DEPTH} levels", self.at(self.i))

    # -- grammar
    def parse(self):
        try:
            value = self.expr()
        except LatexError as err:
            if err.pos is None:
                err.pos = self.at(self.i)
            raise
        while self.peek() in (("char", "."), ("char", ","), ("char", ";")):  # the sentence's end
            self.take()
        if self.peek()[0] != "eof":
            raise LatexError(f"unexpected '{self.peek()[1]}'", self.at(self.i))
        return value

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
            nxt = self.term()
            value = _plus(value, nxt if op == "+" else -nxt)
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
        """After ``^`` on a matrix: ``T``, ``\\top``, ``{T}``, ``{\\mathrm{T}}`` (consumed)."""
        marks = (
            [("char", "T")],
            [("cmd", "top")],
            [("char", "{"), ("char", "T"), ("char", "}")],
            [("char", "{"), ("cmd", "top"), ("char", "}")],
            [("char", "{"), ("cmd", "mathrm"), ("char", "{"), ("char", "T"), ("char", "}"), ("char", "}")],
        )
        for mark in marks:
            if all(self.peek(k) == tok for k, tok in enumerate(mark)):
                self.i += len(mark)
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

    def group_text(self) -> str:
        """The raw text of a ``{...}`` group or of a single token (for sub/superscripts)."""
        if self.peek() == ("char", "{"):
            self.take()
            depth, parts = 1, []
            while True:
                kind, tok = self.take()
                if kind == "eof":
                    raise LatexError("unbalanced '{'")
                if (kind, tok) == ("char", "{"):
                    depth += 1
                elif (kind, tok) == ("char", "}"):
                    depth -= 1
                    if depth == 0:
                        return "".join(parts)
                if kind == "cmd" and tok not in WRAPPERS:
                    parts.append(tok)
                elif kind in ("num", "char") and tok not in "{}":
                    parts.append(tok)
        kind, tok = self.peek()
        if kind == "num" and len(tok) > 1:
            # TeX: an unbraced script is one character, so m_32 l_2 is m_3 * 2 * l_2 (as the
            # page shows it)
            return self._first_character()
        self.take()
        if kind in ("num", "char", "cmd"):
            return tok
        raise LatexError("missing subscript or superscript")

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
                raise LatexError(f"unsupported bracket \\left{opener}")
            if tok in ("underbrace", "overbrace", "boxed"):  # a term's label or frame: the term is read
                self.take()
                value = self._braced()
                if tok != "boxed" and self.peek() in (("char", "_"), ("char", "^")):
                    self.take()
                    self.group_text()  # the label, words or a name: not part of the value
                return value
            if tok in ("frac", "dfrac", "tfrac"):
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
            letter = after[0] == "cmd" or after[0] == "char" and after[1].isalpha()
            return first == ("char", "d") and (letter or alone and after == ("char", "}"))

        return starts_d(1, True) and starts_d(1 + self._script_length(1), False)

    def _prescripted(self):
        """``{}^{2}_{1}R``: a name with its scripts written before it (a step's frames)."""
        scripts, start = {"^": "", "_": ""}, self.at(self.i - 2)  # at the "{}"
        while self.peek() in (("char", "^"), ("char", "_")) and not scripts[self.peek()[1]]:
            mark = self.take()[1]
            scripts[mark] = self.group_text()
        kind, tok = self.peek()
        if not (
            kind == "char" and tok.isalpha() or kind == "cmd" and (tok in GREEK or tok in WRAPPERS or "dot" in tok)
        ):
            raise LatexError("scripts written before nothing ({}^{..} needs a name after it)", self.at(self.i))
        return self._symbol(pre_sup=scripts["^"], pre_sub=scripts["_"], start=start)

    def _first_character(self) -> str:
        """Take the first character of the number token here, leaving the rest in the
        stream (TeX reads an unbraced argument or script as one character)."""
        tok = self.t[self.i][1]
        self.t[self.i] = ("num", tok[1:])
        if self.i < len(self.positions):
            self.positions[self.i] += 1
        return tok[0]

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

    def symbol(self):
        """[accents/wrappers] name [_sub] -> resolve(Name). A ``^`` after it is an
        exponent, read by :meth:`factor`."""
        return self._symbol()

    def _symbol(self, pre_sup: str = "", pre_sub: str = "", start: int | None = None):
        start = self.at(self.i) if start is None else start
        hat = self.peek() == ("cmd", "hat")
        dots, base, sub = self._accented()
        if base[0].isdigit() and not (pre_sup or pre_sub):  # \mathbf{0}: a number in bold
            return sp.Rational(base)
        primes = self._primes()
        if not sub and self.peek() == ("char", "_"):
            self.take()
            sub = self.group_text()
        primes += self._primes()
        exponent, at = None, self.at(self.i)
        if not sub and self.peek() == ("char", "^") and self.peek(self._script_length(1) + 1) == ("char", "_"):
            self.take()  # \dot{\theta}^2_1: the power written before the subscript
            exponent = self.script_value()
            self.take()
            sub = self.group_text()
        name = Name(base, dots + primes, sub, pre_sup=pre_sup, pre_sub=pre_sub, hat=hat)
        try:
            value = self._resolve(name, start)
        except UnknownSymbol as err:
            if pre_sup or pre_sub:
                raise UnknownSymbol(
                    f"{name.latex()} names a step (its frames written before it): a value is read in the "
                    "joint variables and parameters, not through an earlier step's name",
                    start,
                ) from None
            if primes:
                raise UnknownSymbol(f"{err} (a prime ' is read as a time derivative)", err.pos) from None
            raise
        return _power(value, exponent, at) if exponent is not None else value

    def _primes(self) -> int:
        """How many primes follow (``\\theta_1''``): each a time derivative."""
        n = 0
        while self.peek() == ("char", "'"):
            self.take()
            n += 1
        return n

    def _script_length(self, k: int) -> int:
        """Tokens in the script starting ``k`` tokens ahead: a ``{...}`` group or one token."""
        if self.peek(k) != ("char", "{"):
            return 1
        depth, n = 0, 0
        while True:
            tok = self.peek(k + n)
            n += 1
            if tok[0] == "eof":
                return n
            if tok == ("char", "{"):
                depth += 1
            elif tok == ("char", "}"):
                depth -= 1
                if depth == 0:
                    return n

    def _resolve(self, name: Name, start: int | None):
        """``resolve(name)``; an unknown symbol's error points at where it starts."""
        try:
            return self.resolve(name)
        except LatexError as err:
            if err.pos is None:
                err.pos = start
            raise

    def _accented(self) -> tuple[int, str, str]:
        """(number of dots, base name, subscript written inside the braces) of an
        accented or wrapped symbol: ``\\dot{\\theta}``, ``\\dot{\\theta_1}``, ``\\mathbf{v}``."""
        kind, tok = self.take()
        if kind == "cmd" and (tok in ("dot", "ddot", "dddot") or tok in WRAPPERS):
            self.enter()  # \dot{\dot{...}}: each accent nests one level (left unbalanced on error)
            dots = {"dot": 1, "ddot": 2, "dddot": 3}.get(tok, 0)
            if self.peek() != ("char", "{"):
                inner, base, sub = self._accented()
                self.leave()
                return dots + inner, base, sub
            self.take()
            inner, base, sub = self._accented()
            while self.peek() != ("char", "}"):
                k2, t2 = self.peek()
                if k2 == "eof":
                    raise LatexError("unbalanced '{'")
                if (k2, t2) == ("char", "_") and not sub:
                    self.take()
                    sub = self.group_text()
                elif k2 in ("char", "num") and t2.isalnum() and tok in WRAPPERS:
                    self.take()
                    base += t2  # \mathrm{ab}: a multi-letter name
                else:
                    raise LatexError(f"unexpected '{t2}' inside \\{tok}{{...}}")
            self.take()
            self.leave()
            return dots + inner, base, sub
        if kind == "cmd" and tok in GREEK:
            return 0, tok, ""
        if kind == "char" and tok.isalpha() or kind == "num":
            return 0, tok, ""
        raise LatexError(f"expected a symbol, found '{tok or 'end of equation'}'")

    def matrix(self):
        env = self.take()[1]
        if env not in MATRIX_ENVS:
            raise LatexError(f"unsupported environment {env}")
        self.enter()
        rows, row = [], []
        while True:
            kind, tok = self.peek()
            if kind == "end":
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
            if (kind, tok) == ("cmd", "\\") or kind == "end":
                rows.append(row)
                row = []
                continue
            raise LatexError(f"unexpected '{tok}' in a matrix")
        if row:
            rows.append(row)
        self.leave()
        if not rows or len({len(r) for r in rows}) != 1:
            raise LatexError("a matrix whose rows have different lengths")
        return sp.Matrix(rows)


def _plus(a, b):
    """``a + b``; a 1x1 matrix (``v^T v``, ``\\dot q^T M \\dot q``) added to a scalar is its entry."""
    if isinstance(a, sp.MatrixBase) != isinstance(b, sp.MatrixBase):
        a = a[0, 0] if isinstance(a, sp.MatrixBase) and a.shape == (1, 1) else a
        b = b[0, 0] if isinstance(b, sp.MatrixBase) and b.shape == (1, 1) else b
    return a + b


def _cross(a, b):
    """``a \\times b``: the cross product of two 3-vectors, else the product."""
    if isinstance(a, sp.MatrixBase) and isinstance(b, sp.MatrixBase) and a.shape == b.shape == (3, 1):
        return a.cross(b)
    return a * b


def _power(base, exponent, at):
    """``base ** exponent``, refused before SymPy computes it when it would be huge:
    a numeric exponent beyond :data:`MAX_EXPONENT`, a power of a power whose combined
    exponent is (x^{99})^{99}, or a number of more than :data:`MAX_DIGITS` digits."""
    import math

    if isinstance(base, sp.MatrixBase) or isinstance(exponent, sp.MatrixBase):
        raise LatexError("a power of a matrix (only ^T, a transpose, is read)", at)
    if exponent.is_Number:
        limit = MAX_SYMBOLIC_EXPONENT if base.free_symbols else MAX_EXPONENT
        if abs(exponent) > limit:
            raise LatexError(f"an exponent of {short_number(exponent)} (at most {limit})", at)
        inner = base.exp if base.is_Pow and base.exp.is_Number else 1
        if abs(inner * exponent) > limit:
            raise LatexError(f"a power of a power with exponent {short_number(inner * exponent)} (at most {limit})", at)
        if base.is_Number and base != 0:
            digits = (
                float(abs(exponent)) * abs(math.log10(abs(float(base))) if abs(base) < 1e300 else 300)
                if abs(base) != 1
                else 0.0
            )
            if not base.is_Float and (base.is_Integer or base.is_Rational) and digits > MAX_DIGITS:
                raise LatexError(f"a number of about {int(digits)} digits (at most {MAX_DIGITS})", at)
    return base**exponent


def short_number(x) -> str:
    text = str(x)
    return text if len(text) <= 20 else f"{text[:8]}...({len(text)} digits)"


def parse(text: str, resolve) -> sp.Expr | sp.Matrix:
    """Parse one LaTeX expression; ``resolve(Name) -> sympy`` maps each symbol. A
    :class:`LatexError` carries ``pos``, the offset in ``text`` where reading stopped."""
    positions: list[int] = []
    return _Parser(tokenize(text, positions), resolve, positions, len(text)).parse()
