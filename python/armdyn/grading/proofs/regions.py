"""Where the proofs are in a Markdown submission, and their display lines with the prose
before each (the grader's own reader keeps only equations with ``=``; a proof also has
bare expressions that continue a sentence, and prose such as "the second integral").

A proof starts at prose that says so ("Prove ...", "Proof", "Show that ...") or at a
display line about a rigid body's mass distribution (:func:`about_a_body`: an integral over
the body ``\\int ... dm`` or ``\\rho dV``, a sum over the particles ``\\sum_i m_i ...``, the
rotational energy ``E_{rot}``, ``\\omega^T I \\omega``). It goes on across its own
sub-headings (Solution, Proof, Answer, Step 2, Case 1, or any heading deeper than its
first one) and ends at the next exercise: another heading, an exercise number on its own
line (``7-4``), a new instruction ("Check ...", "Formulate ...", "Derive ..."), or an
equation the grader recognised as a Newton-Euler or Lagrange step.

A display line holding several equations separated by ``\\qquad``, ``\\quad``, ``;`` or
``\\text{and}`` (commas: :func:`armdyn.grading.latex.split_equations`) is read as that many
lines, each with the same line number.
"""

from __future__ import annotations

import bisect
import re
from dataclasses import dataclass

from ..display import front_matter, math_blocks
from ..latex import split_equations

_START = re.compile(r"\b(prove|proof|show that)\b", re.IGNORECASE)
_KEEP_HEADING = re.compile(r"^\W*(solution|proof|answer|demonstration|step|case|lemma|claim)\b", re.IGNORECASE)
_INSTRUCTION = re.compile(r"^\W*(check|formulate|derive|compute|calculate|find|determine|solve|write)\b", re.IGNORECASE)
_EXERCISE_NUMBER = re.compile(r"^\W*\d+([-.]\d+)+\W*$")


#: display lines before a proof found by its content that are read with it (its definitions)
MAX_BEFORE = 20


@dataclass
class Display:
    """One equation (or bare expression) of a display block: ``text`` as written, its
    1-based ``line``, the ``prose`` before its block ("" for the block's later equations)."""

    line: int
    text: str
    prose: str


def _body_start(text: str) -> int:
    front = front_matter(text)
    return front[2] if front is not None else 0


#: what a display line about a body's mass distribution has (a proof without a "Prove"):
#: an integral sign then a mass differential, a sum sign then a particle's mass, the
#: rotational energy, w^T I (each a linear search)
_INTEGRAL = re.compile(r"\\int(?![A-Za-z])")
_DIFFERENTIAL = re.compile(r"\bd\s*m\b|\\mathrm\{d\}\s*m|\\rho\s*(?:\\,\s*)?d\s*V")
_SUM = re.compile(r"\\sum(?![A-Za-z])")
_PARTICLE_MASS = re.compile(r"\bm_")
_BODY = re.compile(
    r"E_\{?\s*(?:\\(?:mathrm|text)\{)?rot"  # the rotational energy
    r"|\\omega[^\s^]{0,40}\^\{?\s*(?:T|\\top|\\mathrm\{T\})\}?\s*(?:\\mathbf\{)?I"  # w^T I w
)
_SEPARATORS = re.compile(r"\\qquad|\\quad|\\text\{\s*(?:and|,)\s*\}|;")


def about_a_body(equation: str) -> bool:
    """Does a display line speak of a rigid body's mass distribution (see the module docstring)?"""
    for sign, inside in ((_INTEGRAL, _DIFFERENTIAL), (_SUM, _PARTICLE_MASS)):
        m = sign.search(equation)
        if m is not None and inside.search(equation, m.end()) is not None:
            return True
    return _BODY.search(equation) is not None


def several(equation: str) -> list[tuple[int, str]]:
    """``A = B \\qquad C = D`` -> [(0, "A = B"), (offset, "C = D")]: split at top-level
    separators when every piece has an ``=`` (else the line as it is)."""
    from ..equations import top_level

    if _SEPARATORS.search(equation) is None:
        return [(0, equation)]
    equals = [i for i, c in top_level(equation) if c == "="]  # in order
    depth_zero = _depth_zero(equation)
    cuts = [m for m in _SEPARATORS.finditer(equation) if depth_zero[m.start()]]
    pieces, start = [], 0
    for m in cuts:
        pieces.append((start, equation[start : m.start()]))
        start = m.end()
    pieces.append((start, equation[start:]))
    pieces = [(o, t) for o, t in pieces if t.strip(" ,.;")]
    if (len(pieces) == 1 and pieces[0][0] == 0) or not all(
        bisect.bisect_left(equals, o) < bisect.bisect_left(equals, o + len(t)) for o, t in pieces
    ):  # every piece has an '=' of its own
        return [(0, equation)]
    out = []
    for o, t in pieces:
        lead = len(t) - len(t.lstrip())
        t = t.strip().rstrip(".,;").strip()
        if t:
            out.append((o + lead, t))
    return out


def _depth_zero(text: str) -> list[bool]:
    """For each character: outside every brace, bracket and parenthesis?"""
    out, depth = [], 0
    for c in text:
        if c in "{([":
            depth += 1
        elif c in "})]":
            depth -= 1
        out.append(depth <= 0)
    return out


@dataclass
class _Where:
    """Reading state: inside a proof? the level of its first sub-heading (0: none yet)."""

    in_proof: bool = False
    level: int = 0
    boundary: bool = False  # a heading, exercise number or instruction since last asked
    by_heading: bool = False  # the proof started at a heading "Proof" (its section's lines are its setup)

    def end(self) -> None:
        self.in_proof, self.level = False, 0


def _update(where: _Where, prose: str) -> bool:
    """Follow the prose before a display block; True when a proof starts in it."""
    started = False
    for raw in prose.splitlines():
        line = raw.strip()
        if not line:
            continue
        level = len(line) - len(line.lstrip("#")) if line.startswith("#") else 0
        body = line.lstrip("#").strip()
        if level and where.in_proof:
            if _KEEP_HEADING.match(body) or (where.level and level > where.level):
                where.level = where.level or level  # the proof's own sub-headings
                continue
            where.end()
        if level and not _KEEP_HEADING.match(body):
            where.boundary = True  # a new section (a proof's own headings keep what came before)
        if _START.search(body):
            started = started or not where.in_proof  # "Proof" inside a proof continues it
            if not where.in_proof:
                where.in_proof, where.level, where.by_heading = True, 0, bool(level)
        elif _EXERCISE_NUMBER.match(body) or _INSTRUCTION.match(body):
            where.end()
            where.boundary = True
    return started


def proof_regions(text: str, step_lines: set[int]) -> list[list[Display]]:
    """The proofs of a submission, each a list of its display lines in order."""
    regions: list[list[Display]] = []
    where = _Where()
    before: list[Display] = []  # this section's display lines before a proof found by its content
    pos = _body_start(text)
    counted, line_at = 0, 1  # line numbers counted incrementally: linear in the text's length
    for outer_start, outer_end, block_start, block in math_blocks(text, pos):  # linear, as the reader's
        prose = text[pos:outer_start]
        pos = outer_end
        if _update(where, prose) or (where.in_proof and not regions):
            regions.append(before[-MAX_BEFORE:] if where.by_heading else [])
        if where.boundary or where.in_proof:
            before, where.boundary = [], False
        first = True
        for offset, eq in split_equations(block):
            line_at += text.count("\n", counted, block_start + offset)
            counted = block_start + offset
            line = line_at
            if line in step_lines:
                where.end()  # a dynamics step: the proof is over
                before = []
                continue
            if not where.in_proof and about_a_body(eq):
                where.in_proof = True  # a proof found by what its lines say, with its section's definitions
                regions.append(before[-MAX_BEFORE:])
            lines = [Display(line, part, prose if first else "") for _, part in several(eq)]
            first = False
            (regions[-1] if where.in_proof else before).extend(lines)
    return [r for r in regions if r]
