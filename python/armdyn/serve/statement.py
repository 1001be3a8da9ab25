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


def _read(path: str, limit: int) -> str | None:
    """The file's text, or None when it is missing, too large or not text (the page then
    says the statement is missing rather than failing)."""
    from ..errors import ModelError
    from ..io.textfile import read_text

    try:
        return read_text(path, "statement", limit)
    except ModelError:
        return None


def statement_fragment(exercise: Exercise) -> str:
    """HTML of ``exercise``'s statement, headings from ``<h3>``."""
    from ..course.statement import markdown_blocks, statement_body

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
