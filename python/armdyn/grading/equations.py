"""The equations of a display-math block: where it splits into equations (rows at
``\\\\`` or ``\\cr``, separators ``,`` ``;`` ``\\quad`` ``\\;\\;`` ``\\text{and}`` before another ``LHS = ...``),
what is blanked out (alignment ``&``, environment wrappers, ``\\tag``, ``\\label``, a
trailing ``\\text{for ...}``) and where the sides of ``A = B = C`` start. Everything here
keeps offsets into the block (for line and column in messages) and is linear in its
length: one regular-expression pass finds the marks at nesting depth 0.
"""

from __future__ import annotations

import bisect
import re

_MARKS = re.compile(r"\\(?:begin|end)\{[^}]*\}?|\\\\|\\[A-Za-z]+|\\.?|[{}()\[\]&,;=]", re.S)


def top_level(text: str, commands: bool = False):
    """Yield ``(index, mark)`` of the marks ``&``, ``,``, ``;``, ``=`` and ``\\\\`` at nesting
    depth 0: outside braces, brackets and matrix environments (with ``commands``, also
    every command there, ``\\quad``, ``\\text``...). One regular-expression pass over the
    text (only the characters that matter are looked at in Python)."""
    depth, env = 0, 0
    for m in _MARKS.finditer(text):
        tok = m.group(0)
        c = tok[0]
        if c == "\\":
            if tok.startswith("\\begin{"):
                env += 1
            elif tok.startswith("\\end{"):
                env -= 1
            elif env == 0 and depth == 0 and (tok == "\\\\" or commands):
                yield m.start(), tok
            continue
        if c in "{([":
            depth += 1
        elif c in "})]":
            depth -= 1
        elif depth == 0 and env == 0:
            yield m.start(), c


#: what a display block holds besides its equations: environment wrappers, tags and labels,
#: a row's extra space (\\[2pt]); blanked out (offsets stay those of the block)
_DROPPED = re.compile(
    r"\\(?:begin|end)\{(?:split|aligned|align\*?|gather\*?|gathered|equation\*?|alignedat|alignat\*?|multline\*?"
    r"|eqnarray\*?|flalign\*?)\}(?:\{\d+\})?"
    r"|\\(?:tag\*?|label)\{[^{}]*\}|\\(?:nonumber|notag)\b"
    r"|(?<=\\\\)\[\s*-?\d*\.?\d+\s*(?:pt|mm|cm|em|ex|in|bp)\s*\]"
)
#: a display that is one system of equations, a brace on the left: ``\\begin{cases} x = .. \\\\ y = ..
#: \\end{cases}`` or ``\\left\\{ \\begin{array}{l} .. \\end{array} \\right.``: its rows are equations
_SYSTEM_OPEN = re.compile(r"\s*(?:\\begin\{cases\}|\\left\\\{\s*\\begin\{array\}\{[lcr]*\})")
_SYSTEM_CLOSE = re.compile(r"(?:\\end\{cases\}|\\end\{array\}\s*\\right\s*\.)\s*\Z")


def _system_out(text: str) -> str:
    """``text`` with the brace of a display that is one system of equations blanked (its
    opening at the start and its closing at the end), so its rows split as any other."""
    opening = _SYSTEM_OPEN.match(text)
    if opening is None:
        return text
    tail = len(text) - len(text.rstrip()) + 24  # the closing is at most this far from the end
    closing = _SYSTEM_CLOSE.search(text, max(opening.end(), len(text) - tail))
    if closing is None:
        return text
    chars = list(text)
    _blank(chars, 0, opening.end())
    _blank(chars, closing.start(), closing.end())
    return "".join(chars)


#: prose in a display: \text{and} separates two equations, \text{for ...} ends one
_PROSE = re.compile(r"\\(?:text|textrm|textit|textbf|mbox|mathrm)\s*\{([^{}]*)\}")
_PAREN_PROSE = re.compile(r"\(\s*\\text\s*\{[^{}]*[A-Za-z]{2,}[^{}]*\}\s*\)")
_JOINER = re.compile(r"\s*(?:and|,|;|und|&)?\s*", re.IGNORECASE)
_SEPARATORS = (",", ";", "\\quad", "\\qquad")
#: two or more thin spaces in a row (``\\;\\;``) separate equations as ``\\quad`` does (one alone is
#: a product's spacing, ``m\\; v``, or an operator's, ``a \\;=\\; b``)
_SPACE_RUN = re.compile(r"(?:\\[;:>]\s*){2,}")
#: spacing an equation may start with (``\\;\\tau_2 = ...`` in a box)
_LEADER = re.compile(r"(?:\s|\\(?:[;:,! ]|quad|qquad)(?![A-Za-z]))*")


def _blank(chars: list[str], start: int, end: int) -> None:
    chars[start:end] = " " * (end - start)


def _prose_out(text: str) -> str:
    """``text`` with its top-level prose handled: ``\\text{and}`` (``\\text{,}``...) becomes a
    separator ``;``; a ``\\text{ for ...}`` with words after a value (``= v \\text{ for } ...``)
    is a trailing condition or comment: blanked with the rest of its row. Offsets are kept."""
    marks = list(top_level(text, commands=True))
    chars = None
    rows = [i for i, c in marks if c == "\\\\"] + [len(text)]
    blanked = -1  # blanked up to here already (each row's prose blanked once: linear)
    equals = -1  # the last top-level '=' of the current row
    for i, c in marks:
        if c in ("=", "\\\\"):
            equals = i if c == "=" else -1
        if i < blanked or c not in ("\\text", "\\textrm", "\\textit", "\\textbf", "\\mbox", "\\mathrm"):
            continue
        m = _PROSE.match(text, i)
        j = i - 1
        while j >= 0 and text[j].isspace():
            j -= 1
        if m is None or j >= 0 and text[j] in "_^":  # a name's script (m_\text{link}): not prose
            continue
        chars = chars if chars is not None else list(text)
        words = m.group(1)
        if _JOINER.fullmatch(words):
            _blank(chars, m.start(), m.end())
            chars[m.start()] = ";"
        elif c != "\\mathrm" and equals >= 0 and text[equals + 1 : i].strip() and re.search(r"[A-Za-z]{2,}", words):
            # words after a value (not a left-hand side, not the value itself): a comment
            blanked = rows[bisect.bisect_right(rows, i)]  # the end of its row
            _blank(chars, m.start(), blanked)
    equals_at = [i for i, c in marks if c == "="]
    for m in _PAREN_PROSE.finditer(text):  # "= v (\text{Coriolis})": a comment in parentheses
        k = bisect.bisect_right(rows, m.start())
        row = rows[k - 1] if k else -1  # where its row starts (-1: the first row)
        k = bisect.bisect_left(equals_at, m.start())
        if k and equals_at[k - 1] > row:
            chars = chars if chars is not None else list(text)
            _blank(chars, m.start(), m.end())
    return text if chars is None else "".join(chars)


def _unboxed(text: str) -> str:
    """``text`` with each top-level ``\\boxed{...}`` (a final answer framed) blanked to its
    content, so the equation inside is split as any other. Each box's content is scanned
    once (only top-level boxes: linear)."""
    chars = list(text)
    for i, c in list(top_level(text, commands=True)):
        if c != "\\boxed":
            continue
        j = i + len(c)
        while j < len(text) and text[j].isspace():
            j += 1
        if j >= len(text) or text[j] != "{":
            continue
        depth, k = 0, j
        while k < len(text):
            if text[k] == "\\":
                k += 2
                continue
            depth += {"{": 1, "}": -1}.get(text[k], 0)
            if depth == 0:
                _blank(chars, i, j + 1)
                chars[k] = " "
                break
            k += 1
    return "".join(chars)


#: SymPy's printed functions of time: ``\\theta_{1}{\\left(t \\right)}``, with
#: ``\\frac{d}{d t}`` (``\\frac{d^{2}}{d t^{2}}``) before it for a rate (an acceleration)
_NAME = r"\\?[A-Za-z]+(?:_\{[^{}]*\}|_[A-Za-z0-9])?"
_OF_TIME = re.compile(
    r"(?:\\frac\{d(?:\^\{?([12])\}?)?\}\{d\s*t(?:\^\{?[12]\}?)?\}\s*)?"
    r"(" + _NAME + r")\{\\left\(\s*t\s*\\right\)\}"
)


def _time_functions(text: str) -> str:
    """``text`` with SymPy's printed functions of time read as the textbooks write them:
    ``x{\\left(t \\right)}`` as ``x``, ``\\frac{d}{d t} x{\\left(t \\right)}`` as ``\\dot{x}``,
    ``\\frac{d^{2}}{d t^{2}} x{...}`` as ``\\ddot{x}``. Each is replaced by a shorter text
    padded with spaces, so offsets after it are kept."""

    def sub(m):
        order = m.group(1) or ("1" if m.group(0).startswith("\\frac") else "")
        name = m.group(2)
        new = {"": name, "1": "\\dot{" + name + "}", "2": "\\ddot{" + name + "}"}[order]
        return new + " " * (len(m.group(0)) - len(new))

    return _OF_TIME.sub(sub, text)


#: trigonometric functions typed as letters before a parenthesis (``r_1 cos(\\theta_1)``, as
#: blogs and MATLAB-minded notes write them): read as the functions
_BARE_TRIG = re.compile(r"(?<![\\A-Za-z])( ?)(sin|cos|tan)(?=\s*\()")
#: one column written as a matrix: ``\\left[ \\begin{array}{c} a \\\\ b \\end{array} \\right]``, bmatrix, pmatrix
_COLUMN = re.compile(
    r"\s*(?:\\left\s*[\[(]\s*)?\\begin\{(array|[bpB]?matrix)\}(?(1)(?:\{[lcr]\})?)(?P<body>.*)"
    r"\\end\{\1\}(?:\s*\\right\s*[\])])?\s*\Z",
    re.S,
)


def _bare_trig(text: str) -> str:
    """``cos(x)`` typed without its backslash read as ``\\cos(x)``: the backslash takes the
    place of the space before it when there is one (offsets after it kept)."""
    return _BARE_TRIG.sub(lambda m: "\\" + m.group(2), text)


def _column(text: str, start: int):
    """The entries ``(offset, text)`` of ``text`` when it is one column written as a matrix
    (``\\begin{bmatrix} x_1 \\\\ y_1 \\end{bmatrix}``), else None; offsets from ``start``."""
    m = _COLUMN.match(text)
    if m is None or (m.group(1) == "array" and not re.search(r"\\begin\{array\}\{[lcr]\}", text[: m.start("body")])):
        return None
    body, base = m.group("body"), start + m.start("body")
    marks = [i for i, c in top_level(body, commands=True) if c in ("\\\\", "&")]
    if any(body[i] == "&" for i in marks):
        return None
    out, s0 = [], 0
    for cut in marks + [len(body)]:
        entry = body[s0:cut]
        if entry.strip():
            out.append((base + s0 + len(entry) - len(entry.lstrip()), entry.strip()))
        s0 = cut + 2
    return out if len(out) >= 2 else None


def _components(off: int, equation: str) -> list[tuple[int, str]] | None:
    """``[x_1 \\\\ y_1] = [a \\\\ b]``, one column equal to one column: the equations of its
    rows (``x_1 = a``, ``y_1 = b``), each at its left-hand side's entry; else None."""
    cuts = [i for i, c in top_level(equation) if c == "="]
    if len(cuts) != 1 or "\\begin" not in equation[: cuts[0]]:
        return None
    left = _column(equation[: cuts[0]], off)
    right = _column(equation[cuts[0] + 1 :], off + cuts[0] + 1)
    if left is None or right is None or len(left) != len(right):
        return None
    return [(lo, f"{lt} = {rt}") for (lo, lt), (_, rt) in zip(left, right, strict=True)]


def split_equations(block: str, limit: int | None = None) -> list[tuple[int, str]]:
    """Split a display-math block into equations: at top-level ``\\\\`` and at top-level
    ``,``, ``;``, ``\\quad``, ``\\qquad`` or ``\\text{and}`` followed by another
    ``LHS = ...``. Returns ``(offset, text)`` pairs; alignment ``&``, environment wrappers
    (split, aligned, align, gather, multline, eqnarray, alignat...), ``\\tag``,
    ``\\label``, ``\\nonumber``, a ``\\boxed{..}`` frame and a trailing ``\\text{ for ...}`` are blanked out (so
    offsets still point into ``block``). Linear in the block's length; ``limit``: stop
    after that many equations (the caller refuses more)."""
    text = _DROPPED.sub(lambda m: " " * len(m.group(0)), block)
    if "\\begin" in text:
        text = _system_out(text)
    if "\\right)}" in text:
        text = _time_functions(text)
    if "(" in text:
        text = _bare_trig(text)
    if "\\boxed" in text:
        text = _unboxed(text)
    if "\\" in text:
        text = _prose_out(text)
    runs = {m.start(): m.end() for m in _SPACE_RUN.finditer(text)} if "\\;" in text or "\\:" in text else {}
    marks = [
        (i, "\\\\" if c == "\\cr" else c)  # plain TeX's \cr ends a row as \\ does
        for i, c in top_level(text, commands=True)
        if c in ("&", "=", "\\\\", "\\cr", *_SEPARATORS) or i in runs
    ]
    if any(c == "&" for _, c in marks):
        chars = list(text)
        for i, c in marks:
            if c == "&":
                chars[i] = " "
        text = "".join(chars)
    out: list[tuple[int, str]] = []
    start = 0
    pieces = [i for i, c in marks if c == "\\\\"] + [len(text)]
    ends = {i: 3 if text.startswith("\\cr", i) else 2 for i in pieces}  # the row mark's length
    k = 0  # index into marks
    for cut in pieces:
        # segments of this piece at top-level separators, each flagged: has a top-level '='?
        segments, s0, has_eq = [], start, False
        while k < len(marks) and marks[k][0] < cut:
            i, c = marks[k]
            if c in _SEPARATORS or i in runs:
                segments.append((s0, i, has_eq))
                s0, has_eq = runs.get(i) or i + (1 if c in ",;" else len(c)), False
            elif c == "=":
                has_eq = True
            k += 1
        segments.append((s0, cut, has_eq))
        cur_start, cur_end = segments[0][0], segments[0][1]
        for seg_start, seg_end, seg_eq in segments[1:]:
            if seg_eq:
                out.append((cur_start, text[cur_start:cur_end]))
                cur_start = seg_start
            cur_end = seg_end
            if limit is not None and len(out) > limit:
                break
        out.append((cur_start, text[cur_start:cur_end]))
        start = cut + ends[cut]
        if limit is not None and len(out) > limit:
            break
    result = []
    for off, t in out:
        lead = _LEADER.match(t).end()
        stripped = t[lead : _end(t, lead)]
        if stripped:
            at = off + lead
            rows = _components(at, stripped) if "\\begin" in stripped else None
            result.extend(rows or [(at, stripped)])
    return result


def _end(text: str, lead: int) -> int:
    """Where ``text``'s equation ends: before trailing spaces, spacing commands (``\\;``,
    ``\\quad``) and the sentence's ``.`` ``,`` ``;`` (not the ``;`` of a ``\\;``). Scanned from
    the end, each character once."""
    end = len(text)
    while end > lead:
        if text[end - 1].isspace():
            end -= 1
        elif text.endswith("\\qquad", lead, end) or text.endswith("\\quad", lead, end):
            end = text.rindex("\\", lead, end)
        elif end - 2 >= lead and text[end - 2] == "\\" and text[end - 1] in ";:,! ":
            end -= 2
        elif text[end - 1] in ".,;":
            end -= 1
        else:
            break
    return end


def side_offsets(equation: str) -> list[int]:
    """Offsets where each side of ``A = B = C`` starts (0, then one past each top-level ``=``)."""
    return [0] + [i + 1 for i, c in top_level(equation) if c == "="]


def sides(equation: str) -> list[str]:
    """The sides of ``A = B = C`` split at top-level ``=`` (``\\leq`` etc. not split)."""
    cuts = [i for i, c in top_level(equation) if c == "="]
    out, start = [], 0
    for cut in cuts + [len(equation)]:
        out.append(equation[start:cut].strip())
        start = cut + 1
    return out
