"""A rubric: how many points each step of a graded derivation is worth.

A rubric is a small YAML file (every key optional; this is :meth:`Rubric.default`)::

    points:                      # points of a step, by step name (tau_1) or step key (tau);
      tau: 2                     #   a name wins over its key; steps not listed: `default`
    default: 1
    parts:                       # optional: scale each part's steps to this many points
      newton-euler: 10           #   (parts: newton-euler, lagrange, proof)
      lagrange: 5
    required: [tau_1, tau_2]     # optional: the steps every submission must write (a tau
                                 #   in both methods), or per part: {lagrange: [tau_1]}; one
                                 #   missing scores 0 of its points. Without it every step
                                 #   of the student's exercise kind is required
                                 #   (armdyn.course.expected); a required step the kind does
                                 #   not have is not asked of it
    credit:                      # fraction of a step's points, by verdict status
      correct: 1
      correct-by-convention: 1
      follows-from-earlier-error: 0.5
      correct-but-unsupported: 0.5
      consistent: 0.5            # no model: agrees with the text's own unchecked values
      wrong: 0

A step's part is the ``part`` field of the grade JSON when it has one, else read from its
key: Lagrange's steps (T, V, L, the derivatives of L, and a tau after them) are part
``lagrange``, the links of a proof (``proof_<line>``) ``proof``, the others
``newton-euler``. Unrecognised equations score nothing and are
not counted. Points are rounded to 2 decimals. ``parts`` totals count only the parts the
student's exercise kind has (a proof has no Newton-Euler part).
"""

from __future__ import annotations

import math
import os
from dataclasses import dataclass, field

from ..errors import ModelError
from ..io.textfile import read_text

#: credit (fraction of a step's points) per verdict status, by default
DEFAULT_CREDIT = {
    "correct": 1.0,
    "correct-by-convention": 1.0,
    "follows-from-earlier-error": 0.5,
    "correct-but-unsupported": 0.5,
    "consistent": 0.5,
    "wrong": 0.0,
    "unrecognised": 0.0,
}
_KEYS = ("points", "default", "parts", "required", "credit")
#: the largest rubric file read (bytes): a rubric is a few lines
MAX_BYTES = 1 << 20


@dataclass
class Rubric:
    """Points per step (``points`` by name or key, else ``default_points``: the file's
    ``default``), optional part totals (``parts``), required steps and the credit per
    status (fractions in [0, 1])."""

    points: dict[str, float] = field(default_factory=lambda: {"tau": 2.0})
    default_points: float = 1.0
    parts: dict[str, float] = field(default_factory=dict)
    required: list[str] = field(default_factory=list)
    required_by_part: dict[str, list[str]] = field(default_factory=dict)
    credit: dict[str, float] = field(default_factory=lambda: dict(DEFAULT_CREDIT))
    source: str = "<default rubric>"

    @classmethod
    def default(cls) -> Rubric:
        """Every step 1 point, each tau 2; wrong 0, inherited or unsupported half."""
        return cls()

    @classmethod
    def load(cls, path) -> Rubric:
        """Read a rubric file; a bad one raises :class:`ModelError` naming ``file:line``."""
        path = os.fspath(path)
        text = read_text(path, "rubric", MAX_BYTES)
        return cls.from_text(text, path)

    @classmethod
    def from_text(cls, text: str, source: str = "<rubric>") -> Rubric:
        # the model loader's YAML reader: lines kept, duplicate keys refused
        from ..io.yaml import parse_text

        try:
            data = parse_text(text, source)
        except RecursionError:
            raise ModelError("rubric nested too deeply", source=source) from None
        if data is None:
            data = {}
        if not isinstance(data, dict):
            raise ModelError(
                "a rubric is a mapping (points:, default:, parts:, required:, credit:)", source=f"{source}:1"
            )
        top = f"{source}:{getattr(data, 'line', 1) or 1}"
        unknown = [k for k in data if k not in _KEYS]
        if unknown:
            raise ModelError(
                f"unknown key {unknown[0]!r} (known: {', '.join(_KEYS)})",
                source=_line_of(text, source, unknown[0], top),
            )
        rubric = cls(source=source)
        rubric.default_points = _number(data.get("default", 1.0), "default", _line_of(text, source, "default", top))
        rubric.points = dict(rubric.points)
        for key in ("points", "parts", "credit"):
            if key not in data:
                continue
            where = _line_of(text, source, key, top)
            value = data[key]
            if not isinstance(value, dict):
                raise ModelError(f"{key} must be a mapping of name: number", source=where)
            at = f"{source}:{getattr(value, 'line', None)}" if getattr(value, "line", None) else where
            table = {str(k): _number(v, f"{key}.{k}", _line_of(text, source, str(k), at)) for k, v in value.items()}
            if key == "credit":
                bad = [k for k in table if k not in DEFAULT_CREDIT]
                if bad:
                    raise ModelError(
                        f"credit: unknown status {bad[0]!r} (known: {', '.join(DEFAULT_CREDIT)})",
                        source=_line_of(text, source, bad[0], at),
                    )
                over = [k for k, v in table.items() if v > 1]
                if over:
                    raise ModelError(
                        f"credit.{over[0]} must be a fraction in [0, 1], got {table[over[0]]}",
                        source=_line_of(text, source, over[0], at),
                    )
                rubric.credit = {**DEFAULT_CREDIT, **table}
            elif key == "points":
                rubric.points = table
            else:
                rubric.parts = table
        if "required" in data:
            req = data["required"]
            where = _line_of(text, source, "required", top)
            if isinstance(req, dict):
                from .expected import PARTS

                for part, names in req.items():
                    if part not in PARTS or not isinstance(names, list) or not all(isinstance(x, str) for x in names):
                        raise ModelError(
                            f"required.{part}: a part ({', '.join(PARTS)}) with a list of step names",
                            source=_line_of(text, source, str(part), where),
                        )
                    rubric.required_by_part[str(part)] = list(names)
            elif not isinstance(req, list) or not all(isinstance(x, str) for x in req):
                raise ModelError(
                    "required must be a list of step names (tau_1, v_dot_2, ...) or one such list per part",
                    source=where,
                )
            else:
                rubric.required = list(req)
        return rubric

    # -- scoring
    def step_points(self, name: str, key: str) -> float:
        """The points of one step: by its name, else its key, else ``default``."""
        if name in self.points:
            return self.points[name]
        return self.points.get(key, self.default_points)

    def required_steps(self, expected) -> set[tuple[str, str]] | None:
        """``(part, name)`` of the steps a submission of the kind ``expected`` (an
        :class:`~.expected.Expected`) must write: the rubric's ``required`` that the kind
        has, else every step of the kind; None when neither says (only the steps written
        count)."""
        from .expected import parts_of_name

        if not self.required and not self.required_by_part:
            return set(expected.steps) if expected is not None and expected.steps else None
        asked = {(p, n) for n in self.required for p in parts_of_name(n)}
        asked |= {(p, n) for p, names in self.required_by_part.items() for n in names}
        if expected is None:
            return {(p, n) for p, n in asked if not n.startswith("proof_")}
        return asked & set(expected.steps)

    def to_dict(self) -> dict:
        return {
            "points": dict(sorted(self.points.items())),
            "default": self.default_points,
            "parts": dict(sorted(self.parts.items())),
            "required": list(self.required)
            if not self.required_by_part
            else {**({"any": list(self.required)} if self.required else {}), **self.required_by_part},
            "credit": dict(sorted(self.credit.items())),
        }

    def fingerprint(self) -> str:
        """A stable text of the rubric's content (for the batch cache key)."""
        import json

        return json.dumps(self.to_dict(), sort_keys=True)


def _number(value, what: str, where: str) -> float:
    if isinstance(value, bool) or not isinstance(value, (int, float)):
        raise ModelError(f"{what} must be a number, got {value!r}", source=where)
    value = float(value)
    if not math.isfinite(value) or value < 0 or value > 1e6:
        raise ModelError(f"{what} must be a number in [0, 1e6], got {value}", source=where)
    return value


def _line_of(text: str, source: str, key: str, fallback: str) -> str:
    """``file:line`` of the first line that starts (after indentation) with ``key:``."""
    for k, line in enumerate(text.splitlines(), 1):
        stripped = line.lstrip().lstrip("-").lstrip()
        if stripped.startswith((f"{key}:", f"'{key}':", f'"{key}":')):
            return f"{source}:{k}"
    return fallback
