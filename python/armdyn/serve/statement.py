"""The problem statement shown beside the student's editor.

A variant made by ``armdyn exercise make`` has its statement in its folder:
``problem.md`` (Markdown + LaTeX) and ``problem.html`` (the same, with a drawing of the
arm). The statement is read from ``problem.md`` back into the blocks it was written
from (:func:`armdyn.course.statement.statement_markdown`'s inverse) and rendered as
the variant's page is (:func:`armdyn.course.statement.statement_body`: every text
escaped, math as sanitized MathML); the drawing is taken from ``problem.html`` only
when it is an SVG ``data:`` image (an SVG shown as an image runs no script). A bundled
model has no folder: its statement is the model's description. Read once, at start-up.
"""

from __future__ import annotations

import os
import re

from ..mathml import escape
from .exercises import Exercise

MAX_STATEMENT = 200_000  # bytes of problem.md read
MAX_DRAWING = 4_000_000  # bytes of problem.html read for its drawing
_DRAWING = re.compile(r'<img class="chart" alt="[^"<>]*" src="(data:image/svg\+xml;base64,[A-Za-z0-9+/=]+)">')


def markdown_blocks(text: str) -> list[tuple]:
    """The blocks of a statement's Markdown (headings, paragraphs, display math, code,
    numbered lists, tables), as :func:`armdyn.course.statement.statement_blocks` makes them."""
    blocks: list[tuple] = []
    lines = text.splitlines()
    i = 0
    while i < len(lines):
        line = lines[i]
        if not line.strip():
            i += 1
        elif line.startswith("```"):
            j = i + 1
            while j < len(lines) and not lines[j].startswith("```"):
                j += 1
            blocks.append(("code", "\n".join(lines[i + 1 : j])))
            i = j + 1
        elif line.startswith("## "):
            blocks.append(("h2", line[3:].strip()))
            i += 1
        elif line.startswith("# "):
            blocks.append(("h1", line[2:].strip()))
            i += 1
        elif line.startswith("|"):
            rows = []
            while i < len(lines) and lines[i].startswith("|"):
                cells = [c.strip() for c in lines[i].strip().strip("|").split("|")]
                if not all(re.fullmatch(r"-+", c) for c in cells):
                    rows.append(cells)
                i += 1
            blocks.append(("table", rows[0], rows[1:]))
        elif re.match(r"\d+\. ", line):
            items = []
            while i < len(lines) and re.match(r"\d+\. ", lines[i]):
                items.append(lines[i].split(". ", 1)[1])
                i += 1
            blocks.append(("list", items))
        elif line.startswith("$$") and line.rstrip().endswith("$$") and len(line.strip()) > 4:
            blocks.append(("math", line.strip()[2:-2]))
            i += 1
        else:
            para = []
            while i < len(lines) and lines[i].strip() and not lines[i].startswith(("#", "|", "```", "$$")):
                para.append(lines[i].strip())
                i += 1
            if not para:  # a line no rule above takes: shown as text
                para.append(lines[i].strip())
                i += 1
            blocks.append(("p", " ".join(para)))
    return blocks


def _read(path: str, limit: int) -> str | None:
    try:
        with open(path, "rb") as f:
            data = f.read(limit + 1)
    except OSError:
        return None
    if len(data) > limit:
        return None
    return data.decode("utf-8", "replace")


def statement_fragment(exercise: Exercise) -> str:
    """HTML of ``exercise``'s statement, headings from ``<h3>``."""
    from ..course.statement import statement_body

    if exercise.variant:
        folder = os.path.dirname(exercise.source)
        text = _read(os.path.join(folder, "problem.md"), MAX_STATEMENT)
        if text:
            page = _read(os.path.join(folder, "problem.html"), MAX_DRAWING) or ""
            m = _DRAWING.search(page)
            return statement_body(markdown_blocks(text), m.group(1) if m else None, level=3)[1]
        return (
            f"<h3>Variant {escape(exercise.id)}</h3><p>Its folder has no <code>problem.md</code>: "
            "the statement is the one your instructor handed out.</p>"
        )
    from ..io import bundled_robots

    entry = next((e for e in bundled_robots() if e["name"] == exercise.id), {})
    joints = f"{entry['dof']} joints" if entry.get("dof") else ""
    return (
        f"<h3>{escape(exercise.title[:1].upper() + exercise.title[1:])}</h3>"
        f"<p>{escape(entry.get('description', exercise.id))}{' (' + joints + ')' if joints else ''}.</p>"
        "<p>The statement is the one your instructor handed out; the grader uses armdyn's model "
        f"<code>{escape(exercise.id)}</code>: its frames, joints and masses.</p>"
    )


def statements(exercises: dict[str, Exercise]) -> dict[str, str]:
    """id -> statement HTML of every exercise."""
    return {k: statement_fragment(e) for k, e in exercises.items()}
