"""Which part of an assignment each equation belongs to, from the student's headings.

An assignment is handed in as one file holding several tasks, each introduced by its
number on a line of its own (``7-3``, ``# 7-4``, ``## Exercise 7.4``, ``**Problem 2**``)
and usually answered under a ``Solution`` line. Every equation gets the part it sits in:

* after a number line, that number (``"7-4"``);
* in a task that has no number, ``None``. Such a task is recognised by a ``Solution``
  line that follows the previous task's answer with no number line between them (the
  exercise's rotational-energy proof and its Lagrange check): its equations must not be
  counted as the numbered part before it. It is named by the first line of its statement
  (:attr:`Part.title`, e.g. ``"Check the answer in 7-4 by Lagrangian mechanics."``) so
  a report can still tell two unnumbered tasks apart;
* before any number or task, ``None`` with an empty title.

Only the prose outside display math is looked at, in one pass over the lines.
"""

from __future__ import annotations

import bisect
import re
from dataclasses import dataclass

#: a task's number alone on a line, optionally as a heading or with a word before it
_NUMBER = re.compile(
    r"^\s*(?:#{1,6}\s*)?(?:\*\*|__)?\s*(?:(?:exercise|problem|question|task|part|aufgabe)\s*)?"
    r"(\d+(?:[-.]\d+)*[a-z]?)\s*[.:)]?\s*(?:\*\*|__)?\s*$",
    re.IGNORECASE,
)
_SOLUTION = re.compile(
    r"^\s*(?:#{1,6}\s*)?(?:\*\*|__)?\s*(?:solution|answer|proof)\s*[.:]?\s*(?:\*\*|__)?\s*[.:]?\s*$", re.IGNORECASE
)
#: characters of a task's statement kept as its title
TITLE_LENGTH = 80


@dataclass(frozen=True)
class Part:
    """A task of the assignment: ``number`` (``"7-4"``, or None when unnumbered),
    ``title`` (the first line of its statement) and ``line`` (1-based, where it starts)."""

    number: str | None
    title: str
    line: int


#: lines that may be a number or Solution line (found by one scan of the whole text)
_CANDIDATE = re.compile(
    r"^[ \t]*(?:#|\*\*|__|\d|exercise|problem|question|task|part|aufgabe|solution|answer|proof)"
    r"[^\n]{0,80}$",
    re.MULTILINE | re.IGNORECASE,
)
#: parts beyond this number are not looked for (an assignment has a handful)
MAX_PARTS = 500


def find_parts(text: str, line_of, lines: list[str], math_lines: set[int]) -> list[Part]:
    """The tasks in order of their first line (titles not yet filled in: see
    :func:`with_title`). ``text``: the file; ``line_of(offset)``: its 1-based line;
    ``lines``: its lines (0-based list); ``math_lines``: 1-based numbers of lines inside
    display math or the front matter (ignored). One regular-expression scan finds the
    candidate lines; only those are looked at in Python."""
    parts: list[Part] = []
    numbered_since_answer = False  # a number line came after the last Solution line
    answered = False  # a Solution line has been seen in the current task
    for cand in _CANDIDATE.finditer(text):
        k = line_of(cand.start())
        raw = cand.group(0)
        if k in math_lines:
            continue
        solution = _SOLUTION.match(raw)
        m = None if solution else _NUMBER.match(raw)
        if m:
            parts.append(Part(m.group(1), "", k))
            numbered_since_answer, answered = True, False
        elif solution:
            if answered and not numbered_since_answer or not parts:
                parts.append(Part(None, "", _statement_start(lines, k, math_lines)))
            answered, numbered_since_answer = True, False
        if len(parts) >= MAX_PARTS:
            break
    return parts


def _statement_start(lines: list[str], k: int, math_lines: set[int]) -> int:
    """The first line of the paragraph just above line ``k`` (the task's statement)."""
    j = k - 1
    while j >= 1 and not lines[j - 1].strip():
        j -= 1
    while j > 1 and lines[j - 2].strip() and j - 1 not in math_lines:
        j -= 1
    return max(j, 1)


def with_title(part: Part, lines: list[str], math_lines: set[int]) -> Part:
    """``part`` with its title: the first prose line of its statement (a dozen lines
    looked at, at most :data:`MAX_PARTS` parts)."""
    return Part(part.number, _title(lines, part.line, math_lines, skip_self=part.number is not None), part.line)


def _title(lines: list[str], k: int, math_lines: set[int], skip_self: bool = False) -> str:
    """The first prose line from line ``k`` on (markdown marks removed), shortened."""
    for j in range(k + (1 if skip_self else 0), min(len(lines), k + 12) + 1):
        text = lines[j - 1].strip()
        if not text or j in math_lines or _SOLUTION.match(text):
            continue
        text = re.sub(r"^#+\s*|\*\*|__|`", "", text).strip()
        return text if len(text) <= TITLE_LENGTH else text[: TITLE_LENGTH - 1] + "…"
    return ""


def part_of(parts: list[Part], line: int, starts: list[int] | None = None) -> Part | None:
    """The task line ``line`` (1-based) belongs to, or None before the first one.
    ``starts``: the parts' first lines, if the caller has them (many lookups)."""
    starts = [p.line for p in parts] if starts is None else starts
    k = bisect.bisect_right(starts, line) - 1
    return parts[k] if k >= 0 else None
