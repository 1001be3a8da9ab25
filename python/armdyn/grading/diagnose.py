"""Why an equation could not be read, said so that the student can fix it: the exact
line and column, the problem, and a hint for the forms students commonly write that
the reader does not take (or takes only in another spelling)."""

from __future__ import annotations

import re

_HINTS = [
    (
        re.compile(r"unexpected ','|found ','"),
        "a vector written as a row needs parentheses and a transpose, (a,\\ b,\\ c)^T, or a pmatrix column",
    ),
    (
        re.compile(r"expected '\}'|unbalanced '\{'"),
        "a '{' group (a \\frac{..}{..}, a subscript, a \\dot{..}) is not closed where it should be",
    ),
    (re.compile(r"expected '\)'|expected '\]'"), "a '(' or '[' is not closed (or closed by the other kind)"),
    (re.compile(r"unsupported bracket"), "use \\left( ... \\right) or \\left[ ... \\right], or plain ( )"),
    (re.compile(r"unsupported command \\(big|Big)"), "sizing commands go before a bracket: \\big( ... \\big)"),
    (
        re.compile(r"unsupported command"),
        "values are read with + - \\cdot \\frac \\sqrt ^ _, \\sin \\cos \\tan, and pmatrix/bmatrix vectors",
    ),
    (re.compile(r"nesting deeper"), "write the expression with fewer nested groups"),
    (re.compile(r"exponent|digits|power"), "a derivation's values have small exponents and numbers"),
]


def hint(problem: str) -> str:
    """A hint for a reader's message, or ""."""
    for pattern, text in _HINTS:
        if pattern.search(problem):
            return text
    return ""


def location(path: str, line: int, column: int) -> str:
    """``path:line:column`` (``path:line`` when the column is not known)."""
    return f"{path}:{line}:{column}" if column else f"{path}:{line}"


def cannot_read(problem: str) -> str:
    """``cannot read the value: <problem> (hint: ...)``."""
    extra = hint(problem)
    return f"cannot read the value: {problem}" + (f" (hint: {extra})" if extra else "")
