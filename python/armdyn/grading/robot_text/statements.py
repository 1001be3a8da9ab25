"""The statements a derivation makes about its robot: each equation (display or inline
math) whose left-hand side names a rotation, a position, the base acceleration, an
inertia, T or V, with its value parsed (unknown names become parameters)."""

from __future__ import annotations

import re
from dataclasses import dataclass

import sympy as sp

from ...errors import ModelError
from ..display import math_blocks
from ..latex import LatexError, Name, parse, sides, split_equations
from ..notation import normalise, parse_lhs
from ..reader import Equation, Submission, read_text

#: more frames than this are refused (a hand derivation has a handful)
MAX_FRAMES = 24
#: inline equations read from the prose, at most
MAX_INLINE = 500
#: the ``frame`` of a point mass's place written without the ``c`` (``x_1``): a mass centre
#: written ``x_{c1}`` for the same link wins over it
POINT = -1
#: a statement's value longer than this (characters) is not read for the robot
MAX_STATEMENT = 6000
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


def _flat(sub: str) -> str:
    return re.sub(r"[{}\s,_]|\\mathrm|\\text", "", sub or "")  # l_{c1} -> lc1


def symbol_key(latex: str) -> tuple[str, str] | None:
    """``(base, subscript)`` of one symbol written in LaTeX (``\\theta_1`` -> ("theta", "1"))."""
    found: list[Name] = []
    try:
        parse(latex, lambda name: found.append(name) or sp.Integer(1))
    except (LatexError, RecursionError):
        return None
    return (found[0].base, _flat(found[0].sub)) if len(found) == 1 and not found[0].dots else None


class Names:
    """Resolve the text's symbols: joint variables (``\\theta_k``, ``q_k``, ``d_k``) and
    their rates, ``s_{12}``/``c_1`` shorthand, ``\\pi``; any other name a parameter.
    ``explicit``: the front matter's ``symbols`` (the student's symbol -> the name to use)."""

    def __init__(self, joints: dict[int, str], explicit: dict | None = None):
        self.joints = joints  # joint index -> variable name
        self.explicit: dict[tuple[str, str], str] = {}
        for student, target in (explicit or {}).items():
            key = symbol_key(str(student))
            if key is not None and re.fullmatch(r"[A-Za-z]\w{0,40}", str(target)):
                self.explicit[key] = str(target)

    def named(self, base: str, sub: str) -> str:
        """The name a symbol gets: the front matter's, else the text's own (``l_{c1}`` -> ``lc1``)."""
        return (
            self.explicit.get((base, sub)) or self.explicit.get((base.replace("vartheta", "theta"), sub)) or base + sub
        )

    def __call__(self, name: Name):
        sub = _flat(name.sub)
        base = "theta" if name.base == "vartheta" else name.base
        if base == "pi" and not sub:
            return sp.pi
        if name.hat and base in ("X", "Y", "Z", "x", "y", "z") and not name.dots:
            # Craig's \hat X_1: the unit vector along frame 1's x axis, written in frame 1
            return sp.Matrix([1 if base.lower() == a else 0 for a in "xyz"])
        if base in ("s", "c", "S", "C") and not name.dots and sub.isdigit() and all(int(k) in self.joints for k in sub):
            angle = sum((sp.Symbol(self.joints[int(k)]) for k in sub), sp.Integer(0))
            return (sp.sin if base in "sS" else sp.cos)(angle)
        suffix = {0: "", 1: "_dot", 2: "_ddot"}.get(name.dots, "_d" + str(name.dots))
        named = self.named(base, sub) + suffix
        if not re.fullmatch(r"[A-Za-z][A-Za-z0-9_]{0,60}", named):  # it becomes a model parameter's name
            raise LatexError(f"the symbol {name.latex()} cannot name a parameter")
        return sp.Symbol(named)


def all_equations(sub: Submission) -> tuple[list[Equation], str]:
    """The display equations the reader found, then those of the prose's inline math; and
    the Markdown text ("" for a YAML submission or a file that cannot be read again)."""
    try:
        text = read_text(sub.path) if sub.path.endswith(".md") else ""
    except (OSError, ModelError):
        text = ""
    return [*sub.equations, *_inline_equations(text)], text


def joint_candidates(equations: list[Equation], explicit: dict | None = None) -> tuple[dict[int, str], dict[int, str]]:
    """Joint index -> variable name (``\\theta_k`` or ``q_k`` first, else ``d_k``; renamed by
    the front matter's ``symbols``), and joint index -> the base written (theta, q, d)."""
    found: dict[int, str] = {}
    pattern = re.compile(r"(\\vartheta|\\theta|(?<![A-Za-z\\])q|(?<![A-Za-z\\])d)\}?\s*_\s*\{?\s*(\d+)\s*\}?")
    for eq in equations:
        if not eq.latex:
            continue
        for text in (eq.lhs, str(eq.value)):
            for m in pattern.finditer(text):
                k, base = int(m.group(2)), m.group(1).lstrip("\\").replace("vartheta", "theta")
                if k < 1 or (base == "d" and len(m.group(2)) > 1):
                    continue  # d_{12}: an entry of Spong's inertia matrix D(q), not a slide
                if k not in found or (found[k].startswith("d") and base != "d"):
                    found[k] = f"{base}{k}"
    names = Names({}, explicit)
    bases = {k: v.rstrip("0123456789") for k, v in found.items()}
    return {k: names.named(b, str(k)) for k, b in bases.items()}, bases


_INERTIA_LHS = re.compile(
    r"(?:\{\}\^\{?[Cc]_?\{?(\d+)\}?\}?)?I_\{?(?:[Cc]_?\{?)?(\d+)\}?\}?(?:\^\{?[Cc]_?\{?\d+\}?\}?)?"
)


_INLINE = re.compile(r"(?<![$\\])\$([^$\n]{1,2000})\$(?!\$)")


def _inline_equations(text: str) -> list[Equation]:
    """The equations of the prose's inline math (``$P_1^0 = l_1(\\cos\\theta_1, ...)^T$``): a
    derivation often states its frames there. Display blocks are left to the reader."""
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


#: a left-hand side written for a generic link i: ``{}^{i}P_{C_i}``, ``r_{i,c_i}``, ``R_i^{i-1}``
_GENERIC = re.compile(r"(?<![A-Za-z\\])i(?![A-Za-z])")
_GENERIC_SUB = re.compile(r"(?<![A-Za-z\\])i(?![A-Za-z])|(?<=\{[cC])i(?=\})")
_SPONG_R = re.compile(r"r_\{(\d+),\s*(?:[cC]_?\{?(\d+)\}?|(\d+))\}")
_CENTRE = re.compile(r"([prxyz])_\{?[cC]_?\{?(\d+)\}?\}?|([xyz])_\{?(\d)\}?")  # x_1: a point mass's place
_DIAG = re.compile(r"\\(?:mathrm|operatorname|text)\{diag\}\s*\((.*)\)", re.S)
_ELEMENTARY = re.compile(r"R_\{?([xyz])\}?\s*\((.*)\)", re.S)
#: ``g``, ``\mathbf{g}``, ``\vec g``, ``\boldsymbol{g}``, ``\vec{g}_0``: the gravity vector stated
_GRAVITY_LHS = re.compile(
    r"(?:\\(?:mathbf|vec|boldsymbol|bm|underline)\s*\{?\s*g\s*\}?|g)(?:\s*_\s*\{?\s*0\s*\}?)?(?:\^\{?\s*0\s*\}?)?"
)
#: ``m2d_2``: a mass written without its underscore before another factor (m_2 d_2)
_GLUED_MASS = re.compile(r"(?<![A-Za-z\\_^{])m(\d)(?=[A-Za-z\\])")
_SPACED = re.compile(r"\[(.*)\]\s*\^\s*\{?(?:T|\\top|\\mathrm\{T\})\}?", re.S)


def _instances(eq: Equation, n: int) -> list[tuple[str, str, str]]:
    """``(lhs, value, note)``: the equation itself, or, when its left-hand side is written
    for a generic link i, one instance for each link 1..n."""
    if not _GENERIC.search(normalise(eq.lhs)):
        return [(eq.lhs, str(eq.value), "")]

    def put(text: str, k: int) -> str:
        text = text.replace("i-1", str(k - 1)).replace("i+1", str(k + 1))
        return _GENERIC_SUB.sub(str(k), text)

    return [(put(eq.lhs, k), put(str(eq.value), k), f" (i = {k})") for k in range(1, n + 1)]


def _split_top(text: str, seps: str) -> list[str]:
    parts, depth, start = [], 0, 0
    for j, ch in enumerate(text):
        depth += {"(": 1, "{": 1, "[": 1, ")": -1, "}": -1, "]": -1}.get(ch, 0)
        if depth == 0 and text.startswith(seps, j):
            parts.append(text[start:j])
            start = j + len(seps)
    return [*parts, text[start:]]


def _value(text: str, names: Names):
    """A statement's value: LaTeX, also ``\\mathrm{diag}(a, b, c)``, an elementary rotation
    ``R_z(\\theta_1)`` and a row ``[a\\ b\\ c]^T`` (each entry parsed on its own)."""
    text = _GLUED_MASS.sub(r"m_\1 ", text.strip())
    m = _DIAG.fullmatch(text)
    if m:
        items = [parse(p, names) for p in _split_top(m.group(1), ",")]
        return sp.diag(*items) if len(items) == 3 else None
    m = _ELEMENTARY.fullmatch(text)
    if m:
        a = parse(m.group(2), names)
        c, s = sp.cos(a), sp.sin(a)
        return {
            "x": sp.Matrix([[1, 0, 0], [0, c, -s], [0, s, c]]),
            "y": sp.Matrix([[c, 0, s], [0, 1, 0], [-s, 0, c]]),
            "z": sp.Matrix([[c, -s, 0], [s, c, 0], [0, 0, 1]]),
        }[m.group(1)]
    m = _SPACED.fullmatch(text)
    if m and "," not in m.group(1):
        items = [p for p in re.split(r"\\[ ,;:]|\\quad|&", m.group(1)) if p.strip()]
        if len(items) == 3:
            return sp.Matrix([parse(p, names) for p in items])
    return parse(text, names)


def _what(lhs: str):
    """``(what, index, frame)`` a left-hand side states, or None."""
    ref = parse_lhs(lhs, lambda _latex: None)
    if ref is not None and ref.key in ("P", "Pc") and ref.origin not in (None, ref.index - (ref.key == "P")):
        # Craig's {}^{j}P_{C_i} starts at frame j's origin: at the base's, the mass centre in the base frame
        return ("C", ref.index, 0) if ref.key == "Pc" and ref.origin == 0 else None
    if ref is not None and ref.key in ("R", "P", "Pc", "T", "V", "Tl", "Vl"):
        return ref.key, ref.index, ref.frame
    if ref is not None and ref.key == "Jv" and ref.index is not None:
        return "CJ", ref.index, 0  # Spong's J_{v_{ck}}: link k's mass centre's velocity Jacobian
    if ref is not None and ref.key == "v_dot" and ref.index == 0:
        return "g", 0, ref.frame
    if _GRAVITY_LHS.fullmatch(lhs.strip()):
        return "gv", 0, 0  # the gravity vector itself, in the base frame
    s = normalise(lhs)
    m = _INERTIA_LHS.fullmatch(s)
    if m:
        return "I", int(m.group(2)), None
    m = _CENTRE.fullmatch(s)  # an energy method's mass centre in the base frame: p_{c2}, x_{c2}
    if m is None and ref is not None and ref.key == "pc" and ref.part in ("x", "y", "z") and ref.index:
        return "C" + ref.part, ref.index, POINT  # P_{2,x}: a component of a point's place, named by its link
    if m:
        if m.group(1):
            return ("C" if m.group(1) in "pr" else "C" + m.group(1)), int(m.group(2)), 0
        return "C" + m.group(3), int(m.group(4)), POINT
    m = _SPONG_R.fullmatch(s)  # Spong's r_{i,c_i} (to the mass centre), r_{i,i+1} (to the next joint)
    if m and m.group(2) and m.group(2) == m.group(1):
        return "Pc", int(m.group(1)), int(m.group(1))
    if m and m.group(3) and int(m.group(3)) == int(m.group(1)) + 1:
        return "P", int(m.group(3)), int(m.group(1))
    return None


def read_statements(equations: list[Equation], names: Names, n: int) -> list[Statement]:
    """What the equations state about the robot of ``n`` joints, in the order written."""
    out: list[Statement] = []
    named: dict = {}  # the symbol of a stated coordinate (x_{c1}, P_{1,y}) -> its value
    for eq in equations:
        if not eq.latex or eq.problem:
            continue
        for lhs, text, note in _instances(eq, n):
            found = _what(lhs)
            if found is None or len(text) > MAX_STATEMENT:  # longer than any arm's geometry by hand
                continue
            try:
                value = _value(text, names)
            except (LatexError, RecursionError, ValueError, TypeError):
                continue  # the grader reports it as unreadable
            if value is None:
                continue
            what, index, frame = found
            if what in ("V", "Vl", "T", "Tl") and named:  # PE = m_1 g P_{1,y}: the heights stated before
                value = value.subs(named) if not isinstance(value, sp.MatrixBase) else value
            elif what in ("Cx", "Cy", "Cz") and not isinstance(value, sp.MatrixBase):
                name = _name_of(lhs, names)
                if name is not None:
                    named[name] = value
            out.append(Statement(what, eq.line, " ".join(eq.source.split()) + note, value, index, frame))
    return out


def _name_of(lhs: str, names: Names):
    """The symbol a left-hand side is parsed to (``P_{1,y}`` -> ``P1y``), or None."""
    try:
        sym = parse(lhs, names)
    except (LatexError, RecursionError, ValueError, TypeError):
        return None
    return sym if isinstance(sym, sp.Symbol) else None


# ------------------------------------------------------------------ numeric checks
