"""The tables and limits of the LaTeX reader (:mod:`armdyn.grading.latex`): the bounds that keep
hostile input in bounded time, the commands it knows (functions, typeface wrappers, spacing,
sizes, matrix environments), its errors, and :class:`Name`, a symbol as the student wrote it."""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import sympy as sp

from ..symbolic.names import GREEK as GREEK_LETTERS

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
    "mathbb",
    "mathfrak",
    "mathscr",
    "mathtt",
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
#: what elides terms or entries (\cdots), or sums or integrates over an index: a general
#: formula, not a value; why each is not read
ELIDED = {
    **dict.fromkeys(
        ("cdots", "ldots", "dots", "vdots", "ddots"), "elided terms (not all written), not read as a value"
    ),
    "sum": "a sum over an index (its terms not written), not read as a value",
    "prod": "a product over an index (its factors not written), not read as a value",
    "int": "an integral, not read as a value (write what it gives)",
    "cancelto": "a term struck out towards a value, not read (write the expression after cancelling)",
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


def power(base, exponent, at):
    """``base ** exponent``, refused before SymPy computes it when it would be huge:
    a numeric exponent beyond :data:`MAX_EXPONENT`, a power of a power whose combined
    exponent is (x^{99})^{99}, or a number of more than :data:`MAX_DIGITS` digits."""
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
