"""Read a student's derivation: Markdown with LaTeX display math, or YAML.

Both give a :class:`Submission`: the front matter (which model, which method, symbol
mapping) and the equations in the order written, each with its line number. The
Markdown reader's output is exactly what a YAML submission states directly
(:meth:`Submission.to_yaml` prints it), so the two formats grade alike.

Markdown: an optional front matter between ``---`` lines at the top (after blank lines
or ``<!-- -->`` comments; YAML: ``robot``, ``method``, ``symbols``), then any text; every
display block (``$$``, ``\\[``, ```` ```math ````, a bare ``align``... environment, inline
``$ ... $`` lines written as steps: :mod:`.display`) is split into equations (at ``\\\\`` and at
separators before another ``LHS = ...``: :func:`.equations.split_equations`), each with its
line, the column where its value starts, and the part of the assignment it is in
(:mod:`.parts`). A row or block with no left-hand side that starts with ``=``, ``+``, ``-``
or ``\\Rightarrow`` continues the equation before it (:func:`_continue`), and a block that
is only ``LHS =`` takes the next block as its value; a chain so joined keeps where each of
its sides was written (:attr:`Equation.sides_at`). Reading is linear in the file's size and bounded: at most
:data:`MAX_BYTES` bytes and :data:`MAX_EQUATIONS` equations; an equation with an
unbalanced brace is kept with ``problem`` naming the brace's line and column.

YAML::

    robot: rp-arm                  # bundled name or a model file (relative to this file)
    method: newton-euler           # or lagrange; optional
    symbols: {"l_{c1}": lc1}       # optional: the student's symbol -> the model's name
    values: published              # optional: the student used the model's published numbers
                                   # (or a mapping parameter -> number)
    steps:                         # step -> value, in order
      "\\dot{v}_1^1": ["g*sin(theta1) - l1*theta1_dot**2", "l1*theta1_ddot + g*cos(theta1)", 0]
      tau_1: "..."                 # names as armdyn reports them also work
"""

from __future__ import annotations

import bisect
import os
import re
from dataclasses import dataclass, field

import yaml

from ..errors import ModelError
from ..io import textfile
from ..io.yaml_screen import screen
from .display import front_matter, regions

#: a submission larger than this is refused (a derivation is a few kB)
MAX_BYTES = 5_000_000
#: equations beyond this number are refused (the whole exercise has about fifty; grading
#: takes up to ~10 ms an equation, so this bounds a file's work to a few seconds)
MAX_EQUATIONS = 500


@dataclass
class Equation:
    """One equation as written: ``lhs`` (LaTeX or a step name), ``value`` (the last
    right-hand side: LaTeX, SymPy syntax, or a list of components), ``line`` (1-based),
    ``source`` (the whole equation as written) and ``latex`` (is ``value`` LaTeX?);
    ``column`` (1-based) and ``offset`` (0-based, in the file) of where ``value`` starts;
    ``problem``: why the equation cannot be read at all (an unbalanced brace), or "";
    ``part``: the assignment's part it belongs to (``"7-4"``, None: unnumbered or none)
    and ``task``: that task's title (see :mod:`.parts`)."""

    lhs: str
    value: object
    line: int
    source: str
    latex: bool = True
    column: int = 0
    offset: int = -1
    problem: str = ""
    part: str | None = None
    task: str = ""
    spans: tuple = ()  # (offset in value, offset in the file) of each piece of a joined value
    rows: int = 1  # rows or blocks joined into this equation (see _continue)
    blocks: int = 1  # display blocks joined into this equation (a chain split over $$ blocks)
    #: file offsets where each side of ``LHS = A = ... = value`` starts, the left-hand side's
    #: first (a chain joined from rows or blocks: each member is located where it was written)
    sides_at: tuple = ()

    def offset_of(self, pos: int) -> int:
        """The file offset of character ``pos`` of ``value`` (a value joined from rows
        or blocks written apart maps each piece to where it was written)."""
        start, at = 0, self.offset
        for piece_start, piece_offset in self.spans:
            if piece_start <= pos:
                start, at = piece_start, piece_offset
        return at + pos - start


@dataclass
class Submission:
    path: str
    robot: str | None = None
    method: str | None = None
    symbols: dict = field(default_factory=dict)
    values: object = None  # "published" or {parameter: number}: numbers the student used
    equations: list[Equation] = field(default_factory=list)
    base_dir: str = "."
    lines: LineIndex | None = None  # line/column of offsets in the Markdown text

    parts: list = field(default_factory=list)  # the assignment's parts (.parts.Part), Markdown only
    text: str = field(default="", repr=False)  # the Markdown text as read (its proofs are graded from it)
    notes: list = field(default_factory=list)  # what the reader set aside, said in the report

    def part_at(self, line: int) -> tuple[str | None, str]:
        """(part number or None, task title or "") of a 1-based line (see :mod:`.parts`)."""
        from .parts import part_of

        part = part_of(self.parts, line)
        return (part.number, part.title) if part is not None else (None, "")

    def locate(self, offset: int) -> tuple[int, int]:
        """1-based (line, column) of a 0-based offset in the submission's text."""
        return self.lines.locate(offset) if self.lines is not None else (0, 0)

    def to_yaml(self) -> str:
        """The submission as the YAML format states it (what the Markdown reader read)."""
        data = {k: v for k, v in (("robot", self.robot), ("method", self.method)) if v}
        if self.symbols:
            data["symbols"] = dict(self.symbols)
        if self.values is not None:
            data["values"] = self.values
        data["steps"] = [
            {"line": e.line, "step": e.lhs, "value": e.value, **({"part": e.part} if e.part else {})}
            for e in self.equations
        ]
        return yaml.safe_dump(data, sort_keys=False, allow_unicode=True, width=100)


def read_text(path: str) -> str:
    """A submission file's text: UTF-8, at most ``MAX_BYTES`` (:mod:`armdyn.io.textfile`)."""
    return textfile.read_text(path, "submission", MAX_BYTES)


_LOADER = getattr(yaml, "CSafeLoader", yaml.SafeLoader)  # libyaml when present: 100x faster


def safe_yaml(text: str, where: str):
    """YAML with no aliases (an alias bomb cannot expand), no deep nesting, no huge
    integers (:func:`armdyn.io.yaml_screen.screen`, shared with model files) and no
    Python tags."""
    screen(text, where, "a submission")
    try:
        return yaml.load(text, Loader=_LOADER)
    except yaml.YAMLError as exc:
        mark = getattr(exc, "problem_mark", None)
        line = f":{mark.line + 1}" if mark is not None else ""
        problem = getattr(exc, "problem", None) or str(exc).splitlines()[0]
        raise ModelError(f"malformed YAML ({problem})", source=where + line) from None
    except ValueError as exc:  # an integer beyond Python's conversion limit (thousands of digits)
        raise ModelError(f"a value YAML cannot read ({str(exc).split(';')[0]})", source=where) from None


def _front(meta, path: str, sub: Submission, strict: bool = True) -> None:
    """Read the front matter (or a YAML submission's keys) into ``sub``. ``strict``: an
    unknown key is an error (YAML submissions); else (a Markdown file, whose front matter
    may be a blog's or a site generator's: title, layout, tags, ...) it is set aside with
    a note naming it, so a misspelt ``robot`` is still seen."""
    if meta is None:
        return
    if not isinstance(meta, dict):
        raise ModelError("the front matter must be a mapping (robot: ..., method: ...)", source=path)
    allowed = {"robot", "method", "symbols", "values", "convention", "title", "author", "steps", "notes"}
    allowed |= {"student", "variant"}  # a course's bookkeeping (armdyn.course), not graded
    unknown = sorted(str(k) for k in meta if k not in allowed)
    if unknown and not strict:
        sub.notes.append(f"front matter: {', '.join(unknown)} set aside (armdyn reads {', '.join(sorted(allowed))})")
    elif unknown:
        raise ModelError(f"unknown key(s) {', '.join(unknown)} (expected {', '.join(sorted(allowed))})", source=path)
    for key in ("robot", "method"):
        value = meta.get(key)
        if value is not None and not isinstance(value, str):
            raise ModelError(f"'{key}' must be a string, got {type(value).__name__}", source=path)
    sub.robot = meta.get("robot")
    method = meta.get("method")
    if method is not None and method not in ("newton-euler", "lagrange", "both"):
        raise ModelError(f"method '{method}' is not one of newton-euler, lagrange, both", source=path)
    sub.method = method
    symbols = meta.get("symbols") or {}
    if not isinstance(symbols, dict) or not all(isinstance(v, str) for v in symbols.values()):
        raise ModelError("'symbols' must map the student's symbols to model names (strings)", source=path)
    sub.symbols = {str(k): v for k, v in symbols.items()}
    values = meta.get("values")
    if (
        values is not None
        and values != "published"
        and not (
            isinstance(values, dict)
            and all(isinstance(v, (int, float)) and not isinstance(v, bool) for v in values.values())
        )
    ):
        raise ModelError("'values' must be 'published' or a mapping parameter -> number", source=path)
    sub.values = values


class LineIndex:
    """Line and column of any offset in a text, from one pass over its newlines
    (a bisection per lookup: reading stays linear in the file's size)."""

    def __init__(self, text: str):
        self.newlines = [m.start() for m in re.finditer("\n", text)]

    def locate(self, offset: int) -> tuple[int, int]:
        k = bisect.bisect_left(self.newlines, offset)
        line_start = self.newlines[k - 1] + 1 if k else 0
        return k + 1, offset - line_start + 1

    def line(self, offset: int) -> int:
        return bisect.bisect_left(self.newlines, offset) + 1


_BRACES = re.compile(r"\\.|[{}]", re.S)


def unbalanced_brace(text: str) -> tuple[int, str] | None:
    """``(offset, what)`` of the first brace that does not pair up in ``text``
    (``\\{``, ``\\}`` and ``\\\\`` are not braces), or None. ``what``: "open" or "close"."""
    stack = []
    for m in _BRACES.finditer(text):
        c = m.group(0)
        if c == "{":
            stack.append(m.start())
        elif c == "}":
            if not stack:
                return m.start(), "close"
            stack.pop()
    return (stack[-1], "open") if stack else None


def read_markdown(path: str, text: str | None = None) -> Submission:
    """Read a Markdown derivation (see the module docstring)."""
    from .parts import find_parts, with_title

    text = read_text(path) if text is None else text
    index = LineIndex(text)
    sub = Submission(path, base_dir=os.path.dirname(os.path.abspath(path)), lines=index, text=text)
    body_start = 0
    front = front_matter(text)
    if front is not None:
        yaml_start, yaml_end, body_start = front
        if yaml_end < 0:
            raise ModelError(
                "front matter opened with '---' is never closed", source=f"{path}:{index.line(yaml_start)}"
            )
        blank = "\n" * (index.line(yaml_start) - 1)  # YAML's error lines count from the file's top
        _front(safe_yaml(blank + text[yaml_start:yaml_end], path), path, sub, strict=False)
    hidden = set(range(1, index.line(body_start) + 1))  # front matter and display math: no headings there
    for outer_start, outer_end, block_start, block in regions(text, body_start):
        hidden.update(range(index.line(outer_start), index.line(outer_end) + 1))
        if block is not None:  # math, not code
            _read_block(sub, index, block_start, block)
    lines = text.split("\n")
    sub.parts = [with_title(p, lines, hidden) for p in find_parts(text, index.line, lines, hidden)]
    for eq in sub.equations:
        eq.part, eq.task = sub.part_at(eq.line)
    return sub


#: spacing before a row's content (``&\quad + ...``)
_LEAD = re.compile(r"(?:\s|~|\\(?:quad|qquad|[,;:! ])|\\(?:hspace\*?|phantom|hphantom)\{[^{}]*\})*")


def _read_block(sub: Submission, index: LineIndex, block_start: int, block: str) -> None:
    """Append the equations of one display block to ``sub`` (a row or block that starts
    with ``=``, ``+`` or ``-`` and has no left-hand side of its own continues the
    equation before it)."""
    from .equations import side_offsets, split_equations
    from .latex import MAX_LENGTH

    def unreadable(head: str, text: str, start: int, problem: str) -> None:
        line, col = index.locate(start)
        sub.equations.append(
            Equation(head, text, line, " ".join(text.split()), column=col, offset=start, problem=problem)
        )

    if len(block) > MAX_LENGTH:  # not split: one unreadable equation, refused in bounded time
        unreadable(
            block[:40].strip(),
            block[:200],
            block_start,
            f"display math too long ({len(block)} characters, at most {MAX_LENGTH})",
        )
        return
    for n, (offset, eq) in enumerate(split_equations(block, limit=MAX_EQUATIONS)):
        start = block_start + offset
        if len(eq) > MAX_LENGTH:
            unreadable(eq[:40], eq[:200], start, f"equation too long ({len(eq)} characters, at most {MAX_LENGTH})")
            continue
        brace = unbalanced_brace(eq)
        if brace is not None:
            at, what = brace
            b_line, b_col = index.locate(start + at)
            problem = (
                f"the '{{' opened at line {b_line}, column {b_col} is never closed"
                if what == "open"
                else f"the '}}' at line {b_line}, column {b_col} closes no '{{'"
            )
            unreadable(eq.split("=", 1)[0].strip() if "=" in eq else eq[:40], eq, start, f"unbalanced brace: {problem}")
            continue
        cuts = side_offsets(eq)
        lead = _LEAD.match(eq).end()
        arrow = _ARROW.match(eq, lead)
        if arrow is not None:  # "\\Rightarrow ...": implied by the equation before; the arrow set aside
            eq = " " * arrow.end() + eq[arrow.end() :]
            lead, cuts = _LEAD.match(eq).end(), side_offsets(eq)
            if len(cuts) < 2 and lead < len(eq):  # "\\Rightarrow value": the chain's next member
                eq, cuts, lead = eq[: lead - 1] + "=" + eq[lead:], [0, lead], lead - 1
        if eq.startswith("=", lead) or eq.startswith(("+", "-"), lead) and len(cuts) < 2:
            _continue(sub, index, eq, start, cuts, new_block=n == 0)
            continue
        if len(cuts) < 2:
            if _awaits_value(sub):  # "\tau_1 =" closed a block: this one is its value
                _continue(sub, index, eq, start, [0], new_block=n == 0)
            continue
        value = eq[cuts[-1] :]
        skip = len(value) - len(value.lstrip())
        line, col = index.locate(start + cuts[-1] + skip)
        sub.equations.append(
            Equation(
                eq[: cuts[1] - 1].strip(),
                value.strip(),
                index.line(start),
                " ".join(eq.split()),
                column=col,
                offset=start + cuts[-1] + skip,
                sides_at=_sides_at(eq, start, cuts),
            )
        )
        if len(sub.equations) > MAX_EQUATIONS:
            raise ModelError(
                f"more than {MAX_EQUATIONS} equations (a derivation has a few dozen)",
                source=f"{sub.path}:{index.line(start)}",
            )


#: rows (or blocks) continuing one equation beyond which it is refused (bounds the joining)
MAX_ROWS = 200
#: an implication arrow starting a row or block (``\Rightarrow = ...``, ``\implies ...``)
_ARROW = re.compile(r"\\(?:Rightarrow|Longrightarrow|implies|therefore)(?![A-Za-z])")


_SPACES = re.compile(r"\s*")


def _sides_at(eq: str, start: int, cuts: list[int]) -> tuple:
    """File offsets where each side of ``eq`` (written at ``start``) starts, past its spaces
    (each side's spaces looked at once: linear however many sides)."""
    return tuple(start + _SPACES.match(eq, c).end() for c in cuts)


def _awaits_value(sub: Submission) -> bool:
    """Does the last equation end at its ``=`` (``\\tau_1 =`` alone in a block: the value
    is in the next one)?"""
    last = sub.equations[-1] if sub.equations else None
    return last is not None and not last.problem and last.value == "" and last.rows == 1


def _continue(sub: Submission, index: LineIndex, eq: str, start: int, cuts: list[int], new_block=False) -> None:
    """Join a row or block with no left-hand side (``= ...``, ``+ ...``) to the equation
    before it: the value becomes its last right-hand side (``= ...``) or grows by it
    (``+ ...``). Nothing before it to continue: not an equation (skipped). More than
    :data:`MAX_ROWS` rows, or a joined value over ``MAX_LENGTH``: the equation is refused."""
    from .latex import MAX_LENGTH

    if not sub.equations or sub.equations[-1].problem or not isinstance(sub.equations[-1].value, str):
        return
    prev = sub.equations[-1]
    prev.rows += 1
    prev.blocks += new_block
    if prev.rows > MAX_ROWS or max(len(prev.value), len(prev.source)) + len(eq) > MAX_LENGTH:
        prev.problem = f"more than {MAX_ROWS} rows or {MAX_LENGTH} characters continue this equation"
        return
    prev.source = f"{prev.source} {' '.join(eq.split())}"
    if len(cuts) >= 2 or prev.value == "":  # "= b", "= b = c", the value of "a =": the last side is the value now
        value = eq[cuts[-1] :]
        skip = len(value) - len(value.lstrip())
        prev.value, prev.offset, prev.spans = value.strip(), start + cuts[-1] + skip, ()
        prev.column = index.locate(prev.offset)[1]
        if len(cuts) >= 2:
            prev.sides_at = (*prev.sides_at, *_sides_at(eq, start, cuts)[1:])
        elif prev.sides_at:  # the value of "a =": its side starts here
            prev.sides_at = (*prev.sides_at[:-1], prev.offset)
        return
    prev.spans = (*(prev.spans or ((0, prev.offset),)), (len(prev.value) + 1, start))
    prev.value = f"{prev.value} {eq}"


def read_yaml(path: str, text: str | None = None) -> Submission:
    """Read a YAML derivation (see the module docstring)."""
    text = read_text(path) if text is None else text
    data = safe_yaml(text, path)
    if not isinstance(data, dict) or "steps" not in data:
        raise ModelError("a YAML submission is a mapping with 'steps' (and 'robot', 'method')", source=path)
    sub = Submission(path, base_dir=os.path.dirname(os.path.abspath(path)))
    _front({k: v for k, v in data.items() if k != "steps"}, path, sub)
    lines = _step_lines(text)
    steps = data["steps"]
    items = []
    if isinstance(steps, dict):
        items = [(str(k), v, None, None) for k, v in steps.items()]
    elif isinstance(steps, list):
        for entry in steps:
            if not (isinstance(entry, dict) and "step" in entry and "value" in entry):
                raise ModelError("each entry of 'steps' needs 'step' and 'value'", source=path)
            items.append((str(entry["step"]), entry["value"], entry.get("line"), entry.get("part")))
    else:
        raise ModelError("'steps' must be a mapping (step: value) or a list", source=path)
    if len(items) > MAX_EQUATIONS:
        raise ModelError(f"more than {MAX_EQUATIONS} steps (a derivation has a few dozen)", source=path)
    for n, (name, value, line, part) in enumerate(items):
        if isinstance(value, (list, tuple)):
            # components, or rows of components: nothing nested deeper (and no deep repr later)
            if any(
                isinstance(v, dict)
                or isinstance(v, (list, tuple))
                and any(isinstance(x, (list, tuple, dict)) for x in v)
                for v in value
            ):
                where = f"{path}:{lines[n]}" if n < len(lines) else path
                raise ModelError(
                    f"step '{name}': a value is an expression, a list of them or a list of rows", source=where
                )
            if any(isinstance(v, list) for v in value):
                value = [list(v) if isinstance(v, (list, tuple)) else v for v in value]
        elif not isinstance(value, (str, int, float)) or isinstance(value, bool):
            where = f"{path}:{lines[n]}" if n < len(lines) else path
            raise ModelError(f"step '{name}': the value must be an expression or a list of them", source=where)
        is_latex = any("\\" in str(v) for v in (value if isinstance(value, list) else [value]))
        line = line if isinstance(line, int) else (lines[n] if n < len(lines) else 0)
        sub.equations.append(
            Equation(
                name, value, line, f"{name}: {value}", latex=is_latex, part=str(part) if part is not None else None
            )
        )
    return sub


def _step_lines(text: str) -> list[int]:
    """Line numbers of the entries under ``steps:`` (for messages)."""
    try:
        node = yaml.compose(text, Loader=_LOADER)
    except yaml.YAMLError:
        return []
    if not isinstance(node, yaml.MappingNode):
        return []
    for key, value in node.value:
        if getattr(key, "value", None) == "steps":
            if isinstance(value, yaml.MappingNode):
                return [k.start_mark.line + 1 for k, _ in value.value]
            if isinstance(value, yaml.SequenceNode):
                return [v.start_mark.line + 1 for v in value.value]
    return []


def read(path: str) -> Submission:
    """Read a submission by its extension: .yaml/.yml, else Markdown."""
    if path.lower().endswith((".yaml", ".yml")):
        return read_yaml(path)
    return read_markdown(path)
