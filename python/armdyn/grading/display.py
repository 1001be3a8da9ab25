"""Where the math is in a Markdown derivation: the front matter, and every display block.

Display math is found in the forms derivations use: ``$$ ... $$``, ``\\[ ... \\]``, a
GitHub ```` ```math ```` fence (```` ```latex ```` / ```` ```tex ```` too when the body is
math, not a LaTeX document), an environment written in the Markdown body without ``$$``
(``equation``, ``align``, ``aligned``, ``split``, ``gather``, ``gathered``, ``multline``,
``eqnarray``, ``alignat``, ``flalign``, starred or not), and inline math written as
steps: a line that is only ``$ ... $`` after at most a list marker and a short lead
(``where``, ``So,``, ``Label:``), each ``$LHS = ...$`` of it an equation, and ``$+ ...$``
lines continuing the equation just above (:func:`_inline`); inline math in a sentence is
prose. Other fenced code blocks are not math: a ``$$`` inside them is not read.

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

#: one inline ``$ ... $`` (not empty, not ``$$``, no space just inside the dollars)
_MATH = r"\$(?=[^$\s])[^$\n]*[^$\s\\]\$"
#: a list item's marker: ``*``, ``-``, ``+``, ``1.``, ``1)``, ``a)``, ``(a)``
_MARKER = r"(?:[*+-]|\d{1,3}[.)]|[A-Za-z][.)]|\([A-Za-z0-9]{1,3}\))[ \t]+"
#: a short lead before the math: a connective (``where``, ``so``...) or a label ending in ``:``
_PROSE = (
    r"(?:(?i:where|so|thus|hence|then|therefore|and|with|giving|i\.e\.)\b,?"
    r"|(?:[^$\s:`]|" + _MATH + r")(?:[^$\n:`]|" + _MATH + r"){0,79}?:)[ \t]+"
)
#: between two inline equations of one line
#: (no two runs of spaces side by side: a line of spaces is split one way, in linear time)
_SEP = r"[ \t]*(?:[,;][ \t]*)?(?:(?i:and|so|thus|hence)\b[ \t]*)?"
#: what may end a math line: spaces and one of . , ; :
_END = r"[ \t]*(?:[.,;:][ \t]*)?"
#: a lead of more words than this is a sentence: its math is prose
MAX_LEAD_WORDS = 5

_OPENER = re.compile(
    r"(?P<dollars>\$\$)"
    r"|(?P<bracket>\\\[)"
    r"|^(?P<fence>[ \t]{0,3}(?P<ticks>`{3,}|~{3,})[ \t]*(?P<lang>[^\s`{]*)[^\n]*)$"
    r"|\\begin\{(?P<env>(?:" + "|".join(DISPLAY_ENVS) + r")\*?)\}(?:\{\d+\})?"
    r"|^(?P<lead>[ \t]*(?:" + _MARKER + r")?(?:" + _PROSE + r")?)"
    r"(?P<inline>" + _MATH + r"(?:" + _SEP + _MATH + r")*)" + _END + "$",
    re.MULTILINE,
)
#: a ```latex fence holding a document or a preamble, not an equation
_DOCUMENT = re.compile(r"\\(documentclass|usepackage|section|begin\{document\}|newcommand)\b")


def _fence_end(text: str, ticks: str, pos: int) -> tuple[int, int]:
    """(start, end) of the line closing a fence opened with ``ticks``, or (len, len)."""
    closer = re.compile(r"^[ \t]{0,3}" + re.escape(ticks[0]) + "{" + str(len(ticks)) + r",}[ \t]*$", re.MULTILINE)
    m = closer.search(text, pos)
    return (m.start(), m.end()) if m else (len(text), len(text))


#: a line that is math only: inline (after at most a list marker), or a display block's edge
_MATH_LINE = re.compile(
    r"[ \t]*(?:(?:"
    + _MARKER
    + r")?"
    + _MATH
    + r"(?:"
    + _SEP
    + _MATH
    + r")*"
    + _END
    + r"|(?:\$\$|\\\[|\\\]|\\(?:begin|end)\{)[^\n]*)?"
)
#: a line that introduces what follows: a heading, a sentence ending in ``:`` or ``.``, or a
#: short one (at most MAX_LEAD_WORDS words) ending in ``,`` or a connective (``So,``, ``where``)
_INTRO = re.compile(
    r"[ \t]*#{1,6}[ \t][^\n]*|[^\n]*[:.][*_]*[ \t]*"
    r"|(?P<short>[^\n]*(?:,|\b(?i:where|so|thus|hence|then|therefore|and|with|giving)))[*_]*[ \t]*"
)
_ONE_MATH = re.compile(_MATH)
_MARKER_RE = re.compile(r"[ \t]*(?:" + _MARKER + ")?")
#: what a continuation's math starts with (after spacing): ``+``, ``-`` or ``=``
_CONTINUES = re.compile(r"(?:\s|~|\\(?:quad|qquad|[,;:! ]))*[-+=]")
#: between the end of the block a continuation line continues and that line: one line break
_NEXT_LINE = re.compile(r"[ \t]*[.,;:]?[ \t]*\n")


def _words(prose: str) -> int:
    """How many words ``prose`` has (an inline ``$ ... $`` counts as one)."""
    return len(_ONE_MATH.sub("x", prose).split())


def _alone(text: str, at: int, step: int) -> bool:
    """Is the line before (``step`` -1, ``at`` its newline) or after (+1, ``at`` past its
    start's newline) a math line blank, missing, or math only (``$ ... $`` lines, a display
    block's edge)? The line before may also be one that introduces it (:data:`_INTRO`:
    ``So,``, ``... as follows:``, a heading). (A paragraph of such lines is display math; a math line inside a
    paragraph of prose is prose.)"""
    if at < 0 or at > len(text):
        return True
    if step < 0:
        start = text.rfind("\n", 0, at) + 1
        end = at
    else:
        start, end = at, text.find("\n", at)
        end = len(text) if end < 0 else end
    if _MATH_LINE.fullmatch(text, start, end) is not None:
        return True
    intro = _INTRO.fullmatch(text, start, end) if step < 0 else None
    return intro is not None and (intro.group("short") is None or _words(intro.group("short")) <= MAX_LEAD_WORDS)


def _after_math(text: str, at: int) -> bool:
    """Is the line before (``at`` its newline) a math line, not blank (``$ ... $`` only, or a
    display block's edge)? The last line of a run of math lines is read whatever follows."""
    if at <= 0:
        return False
    start = text.rfind("\n", 0, at) + 1
    return bool(text[start:at].strip()) and _MATH_LINE.fullmatch(text, start, at) is not None


def _is_equation(body: str) -> bool:
    """Does ``body`` hold a top-level ``=`` with something on its left?"""
    from .equations import side_offsets

    cuts = side_offsets(body)
    return len(cuts) >= 2 and body[: cuts[1] - 1].strip() != ""


def _inline(text: str, m: re.Match, last_end: int):
    """The blocks of a line of inline math ``m`` (see :data:`_OPENER`): after an optional
    list marker and a short lead (``where``, ``so``, ``Label:``), each ``$ LHS = ... $``
    is an equation; a line that is only ``$+ ...$`` (``-``, ``=``) continues the block
    ending on the line just before (``last_end``), else it is not read (it never jumps over
    a line that was not read). A lead of more than :data:`MAX_LEAD_WORDS` words is a
    sentence, and a line with no list marker is read only in a paragraph of math lines
    (:func:`_alone`): otherwise its math is prose."""
    lead = m.group("lead")
    marker = _MARKER_RE.match(lead).end()
    prose = lead[marker:]
    if _words(prose) > MAX_LEAD_WORDS:
        return
    after = _alone(text, m.end() + 1, 1) or _after_math(text, m.start() - 1)  # a run of math lines may end in prose
    if not lead[:marker].strip() and not (_alone(text, m.start() - 1, -1) and after):
        return  # a sentence's math, on a line of the paragraph: prose
    pieces = [(p.start(), p.end()) for p in _ONE_MATH.finditer(text, m.start("inline"), m.end("inline"))]
    if len(pieces) == 1 and not prose.strip():
        start, end = pieces[0]
        body = text[start + 1 : end - 1]
        if not _CONTINUES.match(body) or last_end >= 0 and _NEXT_LINE.fullmatch(text, last_end, m.start()):
            yield start, end, start + 1, body
        return
    for start, end in pieces:
        body = text[start + 1 : end - 1]
        if not _CONTINUES.match(body) and _is_equation(body):
            yield start, end, start + 1, body


def math_blocks(text: str, start: int = 0):
    """``(block_start, block_end, body_start, body)`` of each display block from ``start``
    on (see the module docstring), in the order written."""
    return (block for block in regions(text, start) if block[3] is not None)


def regions(text: str, start: int = 0):
    """As :func:`math_blocks`, with fenced code blocks too (``body`` None): what is not
    prose (no heading or task number is looked for there)."""
    closed_off: set[str] = set()  # kinds ($$, \[, an environment's name) never closed further on
    pos = start
    last_end = -1  # end of the last block that may hold an equation (a `$+ ...$` line continues it)
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
                last_end = close_end
            else:
                yield m.start(), close_end, body_start, None
            pos = max(close_end, m.end())
            continue
        if kind == "inline":
            pos = m.end()
            for block in _inline(text, m, last_end):
                last_end = block[1]
                yield block
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
            last_end = end + len(closer)
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
