"""A DH table written in the text as a Markdown table: each row's frame turned and placed
from the one before, as the statements the rest of the reading uses.

The convention is read from the column names: ``a_{i-1}``, ``\\alpha_{i-1}`` (Craig's
modified DH: ``T_i = Rx(alpha_{i-1}) Tx(a_{i-1}) Rz(theta_i) Tz(d_i)``) or ``a_i``, ``\\alpha_i``
(standard DH, Spong's and Corke's: ``A_i = Rz(theta_i) Tz(d_i) Tx(a_i) Rx(alpha_i)``);
the assumption is named.
"""

from __future__ import annotations

import re
from dataclasses import dataclass

import sympy as sp

from ..latex import LatexError, parse
from ..reader import Equation
from .statements import Names, Statement

#: a DH table longer than this is refused (see MAX_FRAMES)
MAX_ROWS = 64


@dataclass
class DhTable:
    """A Markdown DH table: ``modified`` (Craig's columns), its header's line and its rows,
    each ``(line, {"a": cell, "alpha": cell, "d": cell, "theta": cell})``."""

    modified: bool
    line: int
    rows: list


def _column(cell: str) -> tuple[str, bool] | None:
    """The DH quantity a header cell names and whether it is indexed i-1 (Craig's)."""
    s = re.sub(r"[\s$]|\\mathrm|\\text", "", cell)
    previous = bool(re.search(r"i-1", s))
    if "alpha" in s:
        return "alpha", previous
    if "theta" in s:
        return "theta", previous
    if re.fullmatch(r"\{?a\}?(_\{?i(-1)?\}?)?", s):
        return "a", previous
    if re.fullmatch(r"\{?d\}?(_\{?i\}?)?", s):
        return "d", previous
    return None


def _cells(line: str) -> list[str]:
    return [c.strip() for c in line.strip().strip("|").split("|")]


def _table(header: list[str], line: int, rows: list[tuple[int, list[str]]]) -> DhTable | None:
    """A DH table from a header's cells (naming a, alpha, d and theta) and its rows' cells."""
    columns = [_column(c) for c in header]
    if not {"a", "alpha", "d", "theta"} <= {c[0] for c in columns if c}:
        return None
    modified = any(c[1] for c in columns if c and c[0] in ("a", "alpha"))
    kept = [
        (at, {c[0]: cell.strip("$ ") for c, cell in zip(columns, cells) if c})
        for at, cells in rows[: MAX_ROWS + 1]
        if len(cells) == len(columns)
    ]
    return DhTable(modified, line, kept)


#: a DH table written in LaTeX: ``\begin{array}{c|cccc} i & a_{i-1} & ... \\ \hline 1 & ...``
_LATEX_TABLE = re.compile(r"\\begin\{(array|tabular|matrix|bmatrix|pmatrix)\}(\{[^{}]{0,200}\})?")
#: LaTeX tables looked at, at most, and the length of one (bounded time on any text)
MAX_LATEX_TABLES = 200
MAX_LATEX_TABLE_CHARS = 20_000


_RULE = re.compile(r"\\(?:hline|toprule|midrule|bottomrule)")
_RULES = re.compile(r"\s*(?:\\(?:hline|toprule|midrule|bottomrule)\s*)*")


def _latex_tables(text: str) -> list[DhTable]:
    """The DH tables written as a LaTeX array, tabular or matrix (rows split at ``\\\\``, cells at ``&``)."""
    out: list[DhTable] = []
    for n, m in enumerate(_LATEX_TABLE.finditer(text)):
        end = text.find("\\end{" + m.group(1) + "}", m.end(), m.end() + MAX_LATEX_TABLE_CHARS)
        if n >= MAX_LATEX_TABLES:
            break
        if end < 0:
            continue
        body, start = text[m.end() : end], m.end()
        rows, at = [], 0
        for part in re.split(r"\\\\", body):
            lead = _RULES.match(part).end()  # the row's line: where its first cell is
            line = text.count("\n", 0, start + at + lead) + 1
            at += len(part) + 2
            cells = [_RULE.sub("", c).strip() for c in part.split("&")]
            if any(cells):
                rows.append((line, cells))
        if len(rows) >= 2:
            table = _table(rows[0][1], rows[0][0], rows[1:])
            if table is not None:
                out.append(table)
    return out


def dh_tables(text: str) -> list[DhTable]:
    """The DH tables of a Markdown text (a header naming a, alpha, d and theta): Markdown
    tables, then tables written as a LaTeX array, tabular or matrix."""
    lines = text.split("\n")
    out: list[DhTable] = []
    k = 0
    while k < len(lines):
        line = lines[k]
        if line.lstrip().startswith("|") and k + 1 < len(lines) and re.fullmatch(r"\s*\|?[\s:|-]+\|?\s*", lines[k + 1]):
            j = k + 2
            while j < len(lines) and lines[j].lstrip().startswith("|") and j - k <= MAX_ROWS + 2:
                j += 1
            table = _table(_cells(line), k + 1, [(i + 1, _cells(lines[i])) for i in range(k + 2, j)])
            if table is not None:
                out.append(table)
                k = j
                continue
        k += 1
    return out + _latex_tables(text)


def table_equations(tables: list[DhTable]) -> list[Equation]:
    """The rows as text, so the joint variables in them are found with the others."""
    return [Equation("", " ".join(row.values()), line, "") for t in tables for line, row in t.rows]


def _rx(a):
    c, s = sp.cos(a), sp.sin(a)
    return sp.Matrix([[1, 0, 0], [0, c, -s], [0, s, c]])


def _rz(a):
    c, s = sp.cos(a), sp.sin(a)
    return sp.Matrix([[c, -s, 0], [s, c, 0], [0, 0, 1]])


def dh_statements(tables: list[DhTable], names: Names) -> tuple[list[Statement], list[str], list[str]]:
    """Each row k as the rotation of frame k in frame k-1 and frame k's origin in frame k-1;
    the assumptions made (the convention) and the rows that cannot be read."""
    statements: list[Statement] = []
    assumptions: list[str] = []
    problems: list[str] = []
    for table in tables[:1]:
        kind = (
            "modified DH (Craig): the columns are a_{i-1}, alpha_{i-1}"
            if table.modified
            else "standard DH (Spong, Corke): the columns are a_i, alpha_i"
        )
        assumptions.append(f"the DH table of line {table.line} is {kind}")
        for k, (line, row) in enumerate(table.rows, start=1):
            try:
                a, alpha, d, theta = (parse(row[c], names) for c in ("a", "alpha", "d", "theta"))
            except (LatexError, RecursionError, ValueError, TypeError) as err:
                problems.append(f"line {line}: DH row {k} cannot be read ({str(err)[:80]})")
                continue
            if table.modified:
                axes = _rx(alpha) * _rz(theta)
                origin = sp.Matrix([a, 0, 0]) + _rx(alpha) * sp.Matrix([0, 0, d])
            else:
                axes = _rz(theta) * _rx(alpha)
                origin = sp.Matrix([a * sp.cos(theta), a * sp.sin(theta), d])
            source = "DH row " + " | ".join(row[c] for c in ("a", "alpha", "d", "theta"))
            statements.append(Statement("R", line, source, axes, k, k - 1))
            statements.append(Statement("P", line, source, origin, k, k - 1))
    return statements, assumptions, problems
