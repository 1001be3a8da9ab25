"""The statements a derivation makes about its robot: each equation (display or inline
math) whose left-hand side names a rotation, a position, the base acceleration, an
inertia, T or V, with its value parsed (unknown names become parameters)."""

from __future__ import annotations

import re
from dataclasses import dataclass

import sympy as sp

from ...errors import ModelError
from ..latex import LatexError, Name, parse, sides, split_equations
from ..notation import normalise, parse_lhs
from ..reader import Equation, Submission, math_blocks, read_text

#: more frames than this are refused (a hand derivation has a handful)
MAX_FRAMES = 24
#: inline equations read from the prose, at most
MAX_INLINE = 500
_TOL = 1e-9
_JOINT_BASES = ("theta", "vartheta", "q", "d")


@dataclass
class Statement:
    """One thing the text states: ``what`` (``R``, ``P``, ``Pc``, ``g``, ``V``, ``T``),
    frames/link, the value read, the line and the equation as written."""

    what: str
    line: int
    source: str
    value: object
    index: int | None = None
    frame: int | None = None


class Names:
    """Resolve the text's symbols: joint variables (``\\theta_k``, ``q_k``, ``d_k``) and
    their rates, ``s_{12}``/``c_1`` shorthand, ``\\pi``; any other name a parameter."""

    def __init__(self, joints: dict[int, str]):
        self.joints = joints  # joint index -> variable name

    def __call__(self, name: Name):
        sub = re.sub(r"[{}\s,_]|\\mathrm|\\text", "", name.sub or "")  # l_{c1} -> lc1
        base = "theta" if name.base == "vartheta" else name.base
        if base == "pi" and not sub:
            return sp.pi
        if base in ("s", "c", "S", "C") and not name.dots and sub.isdigit() and all(int(k) in self.joints for k in sub):
            angle = sum((sp.Symbol(self.joints[int(k)]) for k in sub), sp.Integer(0))
            return (sp.sin if base in "sS" else sp.cos)(angle)
        return sp.Symbol(base + sub + {0: "", 1: "_dot", 2: "_ddot"}.get(name.dots, "_d" + str(name.dots)))


def joint_candidates(sub: Submission) -> dict[int, str]:
    """Joint index -> variable name: ``\\theta_k`` or ``q_k`` first, else ``d_k``."""
    found: dict[int, str] = {}
    pattern = re.compile(r"(\\vartheta|\\theta|(?<![A-Za-z\\])q|(?<![A-Za-z\\])d)\}?\s*_\s*\{?\s*(\d+)\s*\}?")
    for eq in [*sub.equations, *_inline_equations(sub)]:
        if not eq.latex:
            continue
        for text in (eq.lhs, str(eq.value)):
            for m in pattern.finditer(text):
                k, base = int(m.group(2)), m.group(1).lstrip("\\").replace("vartheta", "theta")
                if k < 1 or k > MAX_FRAMES:
                    continue
                if k not in found or (found[k].startswith("d") and base != "d"):
                    found[k] = f"{base}{k}"
    return found


_INERTIA_LHS = re.compile(
    r"(?:\{\}\^\{?[Cc]_?\{?(\d+)\}?\}?)?I_\{?(?:[Cc]_?\{?)?(\d+)\}?\}?(?:\^\{?[Cc]_?\{?\d+\}?\}?)?"
)


_INLINE = re.compile(r"(?<![$\\])\$([^$\n]{1,2000})\$(?!\$)")


def _inline_equations(sub: Submission) -> list[Equation]:
    """The equations of the prose's inline math (``$P_1^0 = l_1(\\cos\\theta_1, ...)^T$``): a
    derivation often states its frames there. Display blocks are left to the reader."""
    try:
        text = read_text(sub.path)
    except (OSError, ModelError):
        return []
    blocks = [(a, b) for a, b, _, _ in math_blocks(text)]
    out: list[Equation] = []
    k = 0
    for m in _INLINE.finditer(text):
        while k < len(blocks) and blocks[k][1] <= m.start():
            k += 1
        if k < len(blocks) and blocks[k][0] <= m.start() < blocks[k][1]:
            continue
        for _, eq in split_equations(m.group(1), limit=20):
            parts = sides(eq)
            if len(parts) >= 2 and parts[-1].strip():
                line = text.count("\n", 0, m.start()) + 1
                for lhs in parts[:-1]:  # a = b = value: both name the value
                    if lhs.strip():
                        out.append(Equation(lhs.strip(), parts[-1].strip(), line, m.group(0)))
        if len(out) > MAX_INLINE:
            break
    return out


def read_statements(sub: Submission, names: Names) -> list[Statement]:
    out: list[Statement] = []
    for eq in [*sub.equations, *_inline_equations(sub)]:
        if not eq.latex or eq.problem:
            continue
        ref = parse_lhs(eq.lhs, lambda _latex: None)
        what = index = frame = None
        if ref is not None and ref.key in ("R", "P", "Pc", "T", "V"):
            what, index, frame = ref.key, ref.index, ref.frame
        elif ref is not None and ref.key == "v_dot" and ref.index == 0:
            what, index, frame = "g", 0, ref.frame
        else:
            m = _INERTIA_LHS.fullmatch(normalise(eq.lhs))
            if m:
                what, index = "I", int(m.group(2))
        if what is None:
            continue
        try:
            value = parse(str(eq.value), names)
        except (LatexError, RecursionError, ValueError, TypeError):
            continue  # the grader reports it as unreadable
        out.append(Statement(what, eq.line, " ".join(eq.source.split()), value, index, frame))
    return out


# ------------------------------------------------------------------ numeric checks
