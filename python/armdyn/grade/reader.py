"""Read a student's derivation: Markdown with LaTeX display math, or YAML.

Both give a :class:`Submission`: the front matter (which model, which method, symbol
mapping) and the equations in the order written, each with its line number. The
Markdown reader's output is exactly what a YAML submission states directly
(:meth:`Submission.to_yaml` prints it), so the two formats grade alike.

Markdown: an optional front matter between ``---`` lines at the top (YAML: ``robot``,
``method``, ``symbols``), then any text; every ``$$ ... $$`` or ``\\[ ... \\]`` block is
split into equations (at ``\\\\`` and at commas before another ``LHS = ...``).

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

import os
import re
from dataclasses import dataclass, field

import yaml

from ..errors import ModelError
from ..io.yaml_screen import screen

#: a submission larger than this is refused (a derivation is a few kB)
MAX_BYTES = 5_000_000


@dataclass
class Equation:
    """One equation as written: ``lhs`` (LaTeX or a step name), ``value`` (the last
    right-hand side: LaTeX, SymPy syntax, or a list of components), ``line`` (1-based),
    ``source`` (the whole equation as written) and ``latex`` (is ``value`` LaTeX?)."""

    lhs: str
    value: object
    line: int
    source: str
    latex: bool = True


@dataclass
class Submission:
    path: str
    robot: str | None = None
    method: str | None = None
    symbols: dict = field(default_factory=dict)
    values: object = None  # "published" or {parameter: number}: numbers the student used
    equations: list[Equation] = field(default_factory=list)
    base_dir: str = "."

    def to_yaml(self) -> str:
        """The submission as the YAML format states it (what the Markdown reader read)."""
        data = {k: v for k, v in (("robot", self.robot), ("method", self.method)) if v}
        if self.symbols:
            data["symbols"] = dict(self.symbols)
        if self.values is not None:
            data["values"] = self.values
        data["steps"] = [{"line": e.line, "step": e.lhs, "value": e.value} for e in self.equations]
        return yaml.safe_dump(data, sort_keys=False, allow_unicode=True, width=100)


def _read_text(path: str) -> str:
    try:
        size = os.path.getsize(path)
    except OSError as exc:
        raise ModelError(f"cannot read the submission ({exc.strerror})", source=path) from None
    if size > MAX_BYTES:
        raise ModelError(f"the file is {size} bytes; a derivation of at most {MAX_BYTES} bytes is expected",
                         source=path)
    try:
        with open(path, encoding="utf-8") as fh:
            return fh.read()
    except UnicodeDecodeError:
        raise ModelError("not a UTF-8 text file", source=path) from None
    except OSError as exc:
        raise ModelError(f"cannot read the submission ({exc.strerror})", source=path) from None


_LOADER = getattr(yaml, "CSafeLoader", yaml.SafeLoader)  # libyaml when present: 100x faster


def _safe_yaml(text: str, where: str):
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


def _front(meta, path: str, sub: Submission) -> None:
    if meta is None:
        return
    if not isinstance(meta, dict):
        raise ModelError("the front matter must be a mapping (robot: ..., method: ...)", source=path)
    allowed = {"robot", "method", "symbols", "values", "convention", "title", "author", "steps", "notes"}
    unknown = sorted(str(k) for k in meta if k not in allowed)
    if unknown:
        raise ModelError(f"unknown key(s) {', '.join(unknown)} (expected {', '.join(sorted(allowed))})",
                         source=path)
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
    if values is not None and values != "published" and not (
            isinstance(values, dict) and all(isinstance(v, (int, float)) and not isinstance(v, bool)
                                              for v in values.values())):
        raise ModelError("'values' must be 'published' or a mapping parameter -> number", source=path)
    sub.values = values


_MATH = re.compile(r"\$\$(.+?)\$\$|\\\[(.+?)\\\]", re.S)


def read_markdown(path: str, text: str | None = None) -> Submission:
    """Read a Markdown derivation (see the module docstring)."""
    from .latex import sides, split_equations

    text = _read_text(path) if text is None else text
    sub = Submission(path, base_dir=os.path.dirname(os.path.abspath(path)))
    body_start = 0
    if text.startswith("---"):
        end = re.search(r"^---\s*$", text[3:], re.M)
        if end is None:
            raise ModelError("front matter opened with '---' is never closed", source=f"{path}:1")
        _front(_safe_yaml(text[3:3 + end.start()], path), path, sub)
        body_start = 3 + end.end()
    for m in _MATH.finditer(text, body_start):
        group = 1 if m.group(1) is not None else 2
        block, block_start = m.group(group), m.start(group)
        for offset, eq in split_equations(block):
            parts = sides(eq)
            if len(parts) < 2:
                continue
            line = text.count("\n", 0, block_start + offset) + 1
            sub.equations.append(Equation(parts[0], parts[-1], line, " ".join(eq.split())))
    return sub


def read_yaml(path: str, text: str | None = None) -> Submission:
    """Read a YAML derivation (see the module docstring)."""
    text = _read_text(path) if text is None else text
    data = _safe_yaml(text, path)
    if not isinstance(data, dict) or "steps" not in data:
        raise ModelError("a YAML submission is a mapping with 'steps' (and 'robot', 'method')", source=path)
    sub = Submission(path, base_dir=os.path.dirname(os.path.abspath(path)))
    _front({k: v for k, v in data.items() if k != "steps"}, path, sub)
    lines = _step_lines(text)
    steps = data["steps"]
    items = []
    if isinstance(steps, dict):
        items = [(str(k), v, None) for k, v in steps.items()]
    elif isinstance(steps, list):
        for entry in steps:
            if not (isinstance(entry, dict) and "step" in entry and "value" in entry):
                raise ModelError("each entry of 'steps' needs 'step' and 'value'", source=path)
            items.append((str(entry["step"]), entry["value"], entry.get("line")))
    else:
        raise ModelError("'steps' must be a mapping (step: value) or a list", source=path)
    for n, (name, value, line) in enumerate(items):
        if isinstance(value, (list, tuple)):
            if any(isinstance(v, (list, dict)) for v in value):
                value = [list(v) if isinstance(v, (list, tuple)) else v for v in value]
        elif not isinstance(value, (str, int, float)) or isinstance(value, bool):
            where = f"{path}:{lines[n]}" if n < len(lines) else path
            raise ModelError(f"step '{name}': the value must be an expression or a list of them", source=where)
        is_latex = any("\\" in str(v) for v in (value if isinstance(value, list) else [value]))
        line = line if isinstance(line, int) else (lines[n] if n < len(lines) else 0)
        sub.equations.append(Equation(name, value, line, f"{name}: {value}", latex=is_latex))
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
