"""Where the proofs are in a Markdown submission, and their display lines with the prose
before each (the grader's own reader keeps only equations with ``=``; a proof also has
bare expressions that continue a sentence, and prose such as "the second integral").

A proof starts at prose that says so ("Prove ...", "Proof", "Show that ...") and ends at
the next exercise: a heading other than Solution/Proof/Answer, an exercise number on its
own line (``7-4``), a new instruction ("Check ...", "Formulate ...", "Derive ..."), or an
equation the grader recognised as a Newton-Euler or Lagrange step.
"""

from __future__ import annotations

import re
from dataclasses import dataclass

from ..display import front_matter, math_blocks
from ..latex import split_equations

_START = re.compile(r"\b(prove|proof|show that)\b", re.IGNORECASE)
_KEEP_HEADING = re.compile(r"^\W*(solution|proof|answer|demonstration)\b", re.IGNORECASE)
_INSTRUCTION = re.compile(r"^\W*(check|formulate|derive|compute|calculate|find|determine|solve|write)\b", re.IGNORECASE)
_EXERCISE_NUMBER = re.compile(r"^\W*\d+([-.]\d+)+\W*$")


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


def _update(in_proof: bool, prose: str) -> tuple[bool, bool]:
    """(in a proof after this prose, a proof started here)."""
    started = False
    for raw in prose.splitlines():
        line = raw.strip()
        if not line:
            continue
        heading = line.startswith("#")
        body = line.lstrip("#").strip()
        if _START.search(body):
            started = started or not in_proof  # "Proof" inside a proof continues it
            in_proof = True
        elif heading and not _KEEP_HEADING.match(body) or _EXERCISE_NUMBER.match(body) or _INSTRUCTION.match(body):
            in_proof = False
    return in_proof, started


def proof_regions(text: str, step_lines: set[int]) -> list[list[Display]]:
    """The proofs of a submission, each a list of its display lines in order."""
    regions: list[list[Display]] = []
    in_proof = False
    pos = _body_start(text)
    counted, line_at = 0, 1  # line numbers counted incrementally: linear in the text's length
    for outer_start, outer_end, block_start, block in math_blocks(text, pos):  # linear, as the reader's
        prose = text[pos:outer_start]
        pos = outer_end
        in_proof, started = _update(in_proof, prose)
        if started or (in_proof and not regions):
            regions.append([])
        first = True
        for offset, eq in split_equations(block):
            line_at += text.count("\n", counted, block_start + offset)
            counted = block_start + offset
            line = line_at
            if line in step_lines:
                in_proof = False  # a dynamics step: the proof is over
            if in_proof:
                regions[-1].append(Display(line, eq, prose if first else ""))
            first = False
    return [r for r in regions if r]
