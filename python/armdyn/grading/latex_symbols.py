"""How the LaTeX reader reads a symbol: accents and typeface wrappers (``\\dot{\\theta}_1``,
``\\mathbf{v}``), sub- and superscripts, primes, and scripts written before a name
(``{}^{2}_{1}R``); each reaches the resolver as a :class:`~armdyn.grading.latex_tables.Name`."""

from __future__ import annotations

import sympy as sp

from .latex_tables import GREEK, WRAPPERS, LatexError, Name, UnknownSymbol, power
from .latex_tokens import Cursor


class SymbolReader(Cursor):
    """The symbol-reading part of the parser (:class:`armdyn.grading.latex._Parser` adds the
    expressions; :meth:`script_value` is its)."""

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

    def symbol(self):
        """[accents/wrappers] name [_sub] -> resolve(Name). A ``^`` after it is an
        exponent, read by :meth:`factor`."""
        return self._symbol()

    def _symbol(self, pre_sup: str = "", pre_sub: str = "", start: int | None = None, dots_added: int = 0):
        start = self.at(self.i) if start is None else start
        hat = self.peek() == ("cmd", "hat")
        dots, base, sub = self._accented()
        dots += dots_added  # written d\theta/dt: a time derivative
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
            value = self._glued_digits(name, start) if exponent is None else None
            if value is None:
                raise
        return power(value, exponent, at) if exponent is not None else value

    def _glued_digits(self, name: Name, start: int | None):
        """``m2`` typed for ``m_2`` (a letter no symbol has, digits right after it): the
        subscripted name when the resolver knows it (the digits taken, and said), else None."""
        kind, digits = self.peek()
        if name.sub or name.dots or len(name.base) != 1 or kind != "num" or not digits.isdigit():
            return None
        if start is None or self.at(self.i) != start + 1:  # "m 2": a product, as written
            return None
        try:
            value = self.resolve(Name(name.base, sub=digits))
        except LatexError:
            return None
        self.take()
        notes = getattr(self.resolve, "notes", None)
        if isinstance(notes, list):
            note = f"{name.base}{digits} read as {Name(name.base, sub=digits).latex()} (digits typed after a letter)"
            if note not in notes:
                notes.append(note)
        return value

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
        start = self.at(self.i - 1)
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
            if tok == "operatorname" and len(base) > 1:  # \operatorname{sin} is read by the tokenizer
                raise LatexError(
                    f"\\operatorname{{{base}}}: an operator that is not read (read: sin cos tan exp ln log)", start
                )
            return dots + inner, base, sub
        if kind == "cmd" and tok in GREEK:
            return 0, tok, ""
        if kind == "char" and tok.isalpha() or kind == "num":
            return 0, tok, ""
        raise LatexError(f"expected a symbol, found '{tok or 'end of equation'}'")
