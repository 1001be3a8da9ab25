"""The gradebook of a class: one row per submission, points per part, as CSV and JSON.

    gb = Gradebook.from_results(items, rubric=Rubric.load("rubric.yaml"))
    gb.rows          # list of dicts, one per submission, sorted by student then variant
    gb.to_csv()      # str: the columns of :data:`COLUMNS` + one ``points_<part>`` per part
    gb.to_json()     # str: {"columns", "rows", "slips", "rubric"}

``items`` yields ``(student, variant, grade_json, error)``: ``grade_json`` is a grade
report's JSON object (``json.loads(report.to_json())``), or None when the submission could
not be graded, and then ``error`` says why in one line (``status`` of the row is the
word before the first colon when it is one of :data:`FAILURES`, else ``error``).

Only the grade JSON's stable fields are read (``steps[].name/status/message``,
an optional ``steps[].part``, ``first_wrong``, ``tau_correct``, ``method``).
"""

from __future__ import annotations

import csv
import io
import json
import re
from dataclasses import dataclass, field

from ..grading.verdict import STATUSES
from .errorkinds import classify
from .rubric import Rubric

#: row statuses: graded, or why not
FAILURES = ("error", "timeout", "memory", "crashed", "no-variant", "duplicate")
#: Lagrange's step keys (a tau after one of them belongs to the Lagrange part)
LAGRANGE_KEYS = ("T", "V", "L", "dL_dqd", "ddt_dL_dqd", "dL_dq")
#: the fixed columns, in CSV order; ``points_<part>`` columns go after ``error``
COLUMNS = (
    "student",
    "variant",
    "status",
    "error",
    "total",
    "max",
    "first_wrong",
    "first_wrong_kind",
    "tau_correct",
    *(f"n_{s.replace('-', '_')}" for s in STATUSES),
)


@dataclass
class Slip:
    """One wrong step of one submission (for the class summary)."""

    student: str
    step: str
    kind: str
    message: str
    first: bool


@dataclass
class Gradebook:
    """Rows (dicts with :data:`COLUMNS` and ``points_<part>``), the parts seen, the slips."""

    rows: list[dict]
    parts: list[str]
    slips: list[Slip] = field(default_factory=list)
    rubric: Rubric = field(default_factory=Rubric.default)

    @classmethod
    def from_results(cls, items, rubric: Rubric | None = None) -> Gradebook:
        rubric = rubric or Rubric.default()
        rows, slips = [], []
        for item in items:
            student, variant, report, error = item
            row, row_slips = _row(str(student), None if variant is None else str(variant), report, error, rubric)
            rows.append(row)
            slips.extend(row_slips)
        parts = sorted({p for r in rows for p in r["_parts"]} | set(rubric.parts))
        for r in rows:
            got = r.pop("_parts")
            for p in parts:
                r[f"points_{p}"] = got.get(p, (0.0, 0.0))[0] if r["status"] == "graded" else 0.0
        rows.sort(key=lambda r: (r["student"], r["variant"] or ""))
        slips.sort(key=lambda s: (s.student, s.step))
        return cls(rows=rows, parts=parts, slips=slips, rubric=rubric)

    @property
    def columns(self) -> list[str]:
        head = list(COLUMNS)
        at = head.index("error") + 1
        return head[:at] + [f"points_{p}" for p in self.parts] + head[at:]

    def to_csv(self) -> str:
        """One header line and one line per row (``\\n`` line ends); a cell a spreadsheet
        would run as a formula, split on ``,`` or on ``;``, is quoted with ``'`` (:func:`_cell`)."""
        out = io.StringIO()
        w = csv.writer(out, lineterminator="\n")
        cols = self.columns
        w.writerow(cols)
        for r in self.rows:
            w.writerow([_cell(r[c]) for c in cols])
        return out.getvalue()

    def to_json(self) -> str:
        data = {
            "columns": self.columns,
            "rows": [{c: r[c] for c in self.columns} for r in self.rows],
            "slips": [s.__dict__ for s in self.slips],
            "rubric": self.rubric.to_dict(),
        }
        return json.dumps(data, indent=1, sort_keys=True, ensure_ascii=False) + "\n"

    # -- what the summary counts
    def first_wrong_counts(self) -> dict[str, int]:
        """first wrong step -> how many graded submissions went wrong first there."""
        counts: dict[str, int] = {}
        for r in self.rows:
            if r["status"] == "graded" and r["first_wrong"]:
                counts[r["first_wrong"]] = counts.get(r["first_wrong"], 0) + 1
        return counts

    def kind_counts(self) -> dict[str, int]:
        """kind of slip -> how many wrong steps (status ``wrong``) are of that kind."""
        counts: dict[str, int] = {}
        for s in self.slips:
            counts[s.kind] = counts.get(s.kind, 0) + 1
        return counts


#: where a spreadsheet may start a cell: the cell's start, or after a separator it splits
#: on (``,``, or ``;`` in locales whose decimal mark is a comma) or a line break, then
#: blanks; a formula starts with one of ``= + - @`` (a tab or CR may precede it)
_FORMULA_START = re.compile(r"(^|[,;\r\n])([ ]*)(?=[=+\-@\t\r])")


def _cell(value) -> str:
    """A CSV cell no spreadsheet opens as a formula, whichever separator it splits on:
    ``'`` before every ``= + - @ TAB CR`` that starts the cell or follows ``,``, ``;``
    or a line break (``Ada;=cmd|...`` -> ``'Ada;'=cmd|...``; the text after a quote is
    shown, not run)."""
    if value is None:
        return ""
    if isinstance(value, float):
        return f"{value:.2f}".rstrip("0").rstrip(".")
    return _FORMULA_START.sub(lambda m: m.group(1) + m.group(2) + "'", str(value))


def part_of_steps(steps: list[dict], method: str | None) -> list[str]:
    """The part of each step: its ``part`` field, else ``newton-euler`` / ``lagrange``
    from its key (a tau belongs to the method of the steps before it), ``proof`` for the
    links of a proof (``proof_<line>``)."""
    context = "lagrange" if method == "lagrange" else "newton-euler"
    out = []
    for s in steps:
        key = s.get("key") or _key_of(s.get("name") or "")
        if s.get("part"):
            out.append(s["part"])
            continue
        if key == "proof":
            out.append("proof")  # a link of a rigid-body proof (grade.proofs)
            continue
        if key in LAGRANGE_KEYS:
            context = "lagrange"
        elif key and key != "tau":
            context = "newton-euler"
        out.append(context)
    return out


def _key_of(name: str) -> str:
    """A step's key from its name: ``v_dot_1`` -> ``v_dot``, ``T`` -> ``T``, ``R_0^1`` -> ``R``."""
    if name in ("T", "V", "L") or not name:
        return name
    if name.startswith("R_"):
        return "R"
    if name.startswith("proof_"):
        return "proof"
    head, _, tail = name.rpartition("_")
    return head if tail.isdigit() else name


def _row(student: str, variant: str | None, report: dict | None, error: str | None, rubric: Rubric):
    row = {
        "student": student,
        "variant": variant,
        "status": "graded",
        "error": None,
        "total": 0.0,
        "max": 0.0,
        "first_wrong": None,
        "first_wrong_kind": None,
        "tau_correct": None,
        **{f"n_{s.replace('-', '_')}": 0 for s in STATUSES},
        "_parts": {},
    }
    if report is None:
        word = (error or "error").split(":", 1)[0].strip()
        row["status"] = word if word in FAILURES else "error"
        row["error"] = " ".join((error or "not graded").split())
        row["max"] = _rubric_max(rubric)
        return row, []
    steps = [s for s in report.get("steps", []) if isinstance(s, dict)]
    parts_of = part_of_steps(steps, report.get("method"))
    earned: dict[str, list[float]] = {}
    seen = set()
    slips = []
    first = report.get("first_wrong")
    for s, part in zip(steps, parts_of):
        status = s.get("status", "unrecognised")
        if status in STATUSES:
            row[f"n_{status.replace('-', '_')}"] += 1
        name = s.get("name") or ""
        if not name:
            continue  # an equation that names no step: not counted
        seen.add(name)
        pts = rubric.step_points(name, s.get("key") or _key_of(name))
        acc = earned.setdefault(part, [0.0, 0.0])
        acc[0] += pts * rubric.credit.get(status, 0.0)
        acc[1] += pts
        if status == "wrong":
            message = s.get("message") or ""
            slips.append(
                Slip(
                    student=student,
                    step=name,
                    kind=classify(message),
                    message=message,
                    first=name == first and not any(x.first for x in slips),
                )
            )
    for name in rubric.required:
        if name not in seen:
            key = _key_of(name)
            part = "lagrange" if key in LAGRANGE_KEYS else "newton-euler"
            earned.setdefault(part, [0.0, 0.0])[1] += rubric.step_points(name, key)
    for part, total in rubric.parts.items():  # scaled to the rubric's part totals
        got, most = earned.get(part, [0.0, 0.0])
        earned[part] = [total * got / most if most else 0.0, total]
    row["_parts"] = {p: (round(a, 2), round(b, 2)) for p, (a, b) in earned.items()}
    row["total"] = round(sum(a for a, _ in row["_parts"].values()), 2)
    row["max"] = round(sum(b for _, b in row["_parts"].values()), 2)
    row["first_wrong"] = first
    row["first_wrong_kind"] = next((x.kind for x in slips if x.first), None)
    taus = report.get("tau_correct") or []
    row["tau_correct"] = f"{sum(1 for t in taus if t)}/{len(taus)}"
    return row, slips


def _rubric_max(rubric: Rubric) -> float:
    return round(sum(rubric.parts.values()), 2) if rubric.parts else 0.0
