"""The LaTeX reader's tokenizer and token cursor: :func:`tokenize` cuts an equation into
``(kind, value)`` tokens (dropping what only changes how it looks), :class:`Cursor` walks
them with the nesting bounds of :mod:`armdyn.grading.latex_tables`."""

from __future__ import annotations

import re

from .latex_tables import (
    MAX_CALL_DEPTH,
    MAX_DEPTH,
    MAX_DIGITS,
    MAX_LENGTH,
    SIZES,
    SPACES,
    UNICODE_GREEK,
    LatexError,
)

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


class Cursor:
    """A position in a token list, with the nesting depth and function-call depth open there."""

    def __init__(self, tokens, resolve, positions=None, length: int | None = None):
        self.t = tokens
        self.i = 0
        self.resolve = resolve
        self.depth = 0
        self.calls = 0  # function calls and square roots open around the current token
        self.matrices = 0  # matrices open around the current token
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
