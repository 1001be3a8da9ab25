"""Where the math is in a Markdown derivation: the front matter, and every display block.

Display math is found in the forms derivations use: ``$$ ... $$``, ``\\[ ... \\]``, a
GitHub ```` ```math ```` fence (```` ```latex ```` / ```` ```tex ```` too when the body is
math, not a LaTeX document), an environment written in the Markdown body without ``$$``
(``equation``, ``align``, ``aligned``, ``split``, ``gather``, ``gathered``, ``multline``,
``eqnarray``, ``alignat``, ``flalign``, starred or not), and a line that is only
``$ ... $`` (inline math on a line of its own, as notebooks write it). Other fenced code
blocks are not math: a ``$$`` inside them is not read.

One regular-expression scan finds the openers in order; each closer is looked for once
with ``str.find`` (or one search), and an opener of a kind that is never closed ends the
search for that kind: reading stays linear in the file's size.
"""

from __future__ import annotations

import re

#: environments read as display math where they stand in the Markdown body
DISPLAY_ENVS = (
    "equation",
    "align",
    "aligned",
    "alignat",
    "alignedat",
    "split",
    "gather",
    "gathered",
    "multline",
    "eqnarray",
    "flalign",
)

_OPENER = re.compile(
    r"(?P<dollars>\$\$)"
    r"|(?P<bracket>\\\[)"
    r"|^(?P<fence>[ \t]{0,3}(?P<ticks>`{3,}|~{3,})[ \t]*(?P<lang>[^\s`{]*)[^\n]*)$"
    r"|\\begin\{(?P<env>(?:" + "|".join(DISPLAY_ENVS) + r")\*?)\}(?:\{\d+\})?"
    r"|^[ \t]*(?P<inline>\$(?=[^$\s])[^$\n]*[^$\s\\]\$)[ \t]*[.,;]?[ \t]*$",
    re.MULTILINE,
)
#: a ```latex fence holding a document or a preamble, not an equation
_DOCUMENT = re.compile(r"\\(documentclass|usepackage|section|begin\{document\}|newcommand)\b")


def _fence_end(text: str, ticks: str, pos: int) -> tuple[int, int]:
    """(start, end) of the line closing a fence opened with ``ticks``, or (len, len)."""
    closer = re.compile(r"^[ \t]{0,3}" + re.escape(ticks[0]) + "{" + str(len(ticks)) + r",}[ \t]*$", re.MULTILINE)
    m = closer.search(text, pos)
    return (m.start(), m.end()) if m else (len(text), len(text))


_LONE = re.compile(r"[ \t]*(?:\$(?=[^$\s])[^$\n]*[^$\s\\]\$[ \t]*[.,;]?)?[ \t]*")


def _alone(text: str, at: int, step: int) -> bool:
    """Is the line before (``step`` -1, ``at`` its newline) or after (+1, ``at`` past its
    start's newline) a ``$ ... $`` line blank, missing, or a ``$ ... $`` line too? (A
    paragraph of lone ``$ ... $`` lines is display math; one inside prose is not.)"""
    if at < 0 or at > len(text):
        return True
    if step < 0:
        start = text.rfind("\n", 0, at) + 1
        end = at
    else:
        start, end = at, text.find("\n", at)
        end = len(text) if end < 0 else end
    return _LONE.fullmatch(text, start, end) is not None


def math_blocks(text: str, start: int = 0):
    """``(block_start, block_end, body_start, body)`` of each display block from ``start``
    on (see the module docstring), in the order written."""
    return (block for block in regions(text, start) if block[3] is not None)


def regions(text: str, start: int = 0):
    """As :func:`math_blocks`, with fenced code blocks too (``body`` None): what is not
    prose (no heading or task number is looked for there)."""
    closed_off: set[str] = set()  # kinds ($$, \[, an environment's name) never closed further on
    pos = start
    while True:
        m = _OPENER.search(text, pos)
        if m is None:
            return
        kind = m.lastgroup
        if kind in ("ticks", "lang"):
            kind = "fence"
        if kind == "fence":
            body_start = min(m.end() + 1, len(text))
            close_start, close_end = _fence_end(text, m.group("ticks"), body_start)
            body = text[body_start:close_start]
            lang = m.group("lang").lower()
            if lang == "math" or lang in ("latex", "tex") and "=" in body and not _DOCUMENT.search(body):
                yield m.start(), close_end, body_start, body
            else:
                yield m.start(), close_end, body_start, None
            pos = max(close_end, m.end())
            continue
        if kind == "inline":
            pos = m.end()
            if not (_alone(text, m.start() - 1, -1) and _alone(text, m.end() + 1, 1)):
                continue  # a sentence's math, on a line of the paragraph: prose
            yield m.start("inline"), m.end("inline"), m.start("inline") + 1, m.group("inline")[1:-1]
            continue
        closer = {"dollars": "$$", "bracket": "\\]"}.get(kind) or "\\end{" + m.group("env") + "}"
        key = closer if kind != "env" else m.group("env")
        if key in closed_off:
            pos = m.end()
            continue
        end = text.find(closer, m.end())
        if end < 0:  # never closed: no block of this kind from here on
            closed_off.add(key)
            pos = m.end()
            continue
        if end > m.end():
            yield m.start(), end + len(closer), m.end(), text[m.end() : end]
        pos = end + len(closer)


_COMMENT_OR_BLANK = re.compile(r"\ufeff?(?:\s*<!--.*?-->)*\s*", re.DOTALL)


def front_matter(text: str) -> tuple[int, int, int] | None:
    """``(yaml_start, yaml_end, body_start)`` of the front matter between ``---`` lines at
    the top (after blank lines or ``<!-- ... -->`` comments, which do not hide it), or
    None when there is none. ``yaml_end`` is -1 when the opening ``---`` is never closed."""
    lead = _COMMENT_OR_BLANK.match(text).end()
    newline = text.rfind("\n", 0, lead)
    at = newline + 1 if newline >= 0 else (1 if text.startswith("\ufeff") else 0)  # --- starts a line
    if not re.compile(r"---[ \t]*(\n|$)").match(text, at):
        return None
    end = re.compile(r"^---[ \t]*$", re.MULTILINE).search(text, at + 3)
    if end is None:
        return at + 3, -1, len(text)
    return at + 3, end.start(), end.end()
