"""The gradebook of a class: one row per student, points per part of the student's
exercise kind, as CSV and JSON.

    gb = Gradebook.from_results(items, rubric=Rubric.load("rubric.yaml"), policy="latest")
    gb.rows          # list of dicts, one per student, sorted by student
    gb.to_csv()      # str: the columns of :attr:`Gradebook.columns`
    gb.to_json()     # str: {"columns", "rows", "slips", "steps", "set_aside", "policy", "rubric"}
    gb.steps         # student -> the counted submission's steps: part, step, status, points, max

``items`` yields ``(student, variant, grade_json, error)`` or ``(student, variant,
grade_json, error, kind)`` in the order the submissions were handed in: ``grade_json``
is a grade report's JSON object (``json.loads(report.to_json())``), or None when the
submission could not be graded, and then ``error`` says why in one line (``status`` of
the row is the word before the first colon when it is one of :data:`FAILURES`, else
``error``); ``kind`` is the exercise kind (``rp``, ``parallel-axis``; see
:mod:`.expected`), else it is read from the report (a proof, or an arm of as many joints
as torques). ``rubrics`` maps a kind to its own rubric (``rubric`` for the others).

A student who handed in more than once has one row: with ``policy="latest"`` the last
graded submission (else the last one), with ``"best"`` the graded one with the most
points (the later on a tie); ``submissions`` says how many there were, and the others are
in ``set_aside``. Points are counted per part of the kind only (Newton-Euler and Lagrange
for an arm, proof for a proof); every step the kind asks (:meth:`.Rubric.required_steps`)
and was not written scores 0 of its points, so a derivation that stops half-way scores
what it shows. The final torques are judged per method (``tau_newton-euler``,
``tau_lagrange``: the last ``tau_i`` of each method written, right or right but
unsupported).

Only the grade JSON's stable fields are read (``steps[].name/status/message/label``,
``first_wrong``, ``tau_correct``, ``method``), plus an optional ``steps[].slip_kind``
(:mod:`.slipkinds`, set when the class is graded by :mod:`.batch`).
"""

from __future__ import annotations

import csv
import io
import json
import re
from dataclasses import dataclass, field

from ..grading.notation import LAGRANGE_KEYS as _LAGRANGE_KEYS
from ..grading.verdict import STATUSES
from .errorkinds import classify
from .expected import LAGRANGE, NE, PARTS, PROOF, Expected, expected_for, expected_from_report, key_of
from .rubric import Rubric

#: row statuses: graded, or why not
FAILURES = ("error", "timeout", "memory", "crashed", "no-variant", "duplicate")
#: how one submission of several is chosen for a student's row
POLICIES = ("latest", "best")
#: statuses of a torque that count as right (supported or not)
_TAU_RIGHT = ("correct", "correct-by-convention", "correct-but-unsupported")
#: the fixed columns before the points and after them, in CSV order
HEAD = ("student", "variant", "kind", "status", "error", "submissions", "policy")
TAIL = (
    "total",
    "max",
    "first_wrong",
    "first_wrong_kind",
    "tau_newton-euler",
    "tau_lagrange",
    *(f"n_{s.replace('-', '_')}" for s in STATUSES),
)
COLUMNS = HEAD + TAIL


@dataclass
class Slip:
    """One wrong step of one submission (for the class summary): ``step`` its name
    (a proof's link: its equation), ``kind`` the kind of slip."""

    student: str
    step: str
    kind: str
    message: str
    first: bool
    exercise: str = ""


@dataclass
class Gradebook:
    """Rows (dicts with :attr:`columns`), the parts seen, the slips of the rows, the
    submissions set aside (not the one chosen for a row), the policy."""

    rows: list[dict]
    parts: list[str]
    slips: list[Slip] = field(default_factory=list)
    rubric: Rubric = field(default_factory=Rubric.default)
    policy: str = "latest"
    set_aside: list[dict] = field(default_factory=list)
    steps: dict[str, list[dict]] = field(default_factory=dict)

    @classmethod
    def from_results(cls, items, rubric: Rubric | None = None, policy: str = "latest", rubrics=None) -> Gradebook:
        if policy not in POLICIES:
            raise ValueError(f"policy must be one of {', '.join(POLICIES)}, got {policy!r}")
        rubric = rubric or Rubric.default()
        rubrics = dict(rubrics or {})
        by_student: dict[str, list] = {}
        for order, item in enumerate(items):
            student, variant, report, error = item[:4]
            kind = item[4] if len(item) > 4 else None
            student = str(student)
            row, row_slips = _row(
                student,
                None if variant is None else str(variant),
                report,
                error,
                rubrics.get(kind, rubric),
                kind,
            )
            row["_order"] = order
            by_student.setdefault(student, []).append((row, row_slips))
        rows, slips, set_aside, steps = [], [], [], {}
        for student, tried in by_student.items():
            chosen = _choose(tried, policy)
            steps[student] = chosen[0]["_steps"]
            for r, _ in tried:
                r.pop("_steps")
            for r, _ in tried:
                if r is not chosen[0]:
                    set_aside.append({k: r[k] for k in ("student", "variant", "kind", "status", "error", "total")})
            row, row_slips = chosen
            row["submissions"], row["policy"] = len(tried), policy
            rows.append(row)
            slips.extend(row_slips)
        parts = [p for p in PARTS if any(p in r["_parts"] for r in rows)]
        for r in rows:
            got = r.pop("_parts")
            r.pop("_order")
            for p in parts:
                r[f"points_{p}"] = (got[p][0] if r["status"] == "graded" else 0.0) if p in got else None
        rows.sort(key=lambda r: (r["student"], r["variant"] or ""))
        slips.sort(key=lambda s: (s.student, s.step))
        set_aside.sort(key=lambda r: (r["student"], r["variant"] or ""))
        return cls(rows=rows, parts=parts, slips=slips, rubric=rubric, policy=policy, set_aside=set_aside, steps=steps)

    @property
    def columns(self) -> list[str]:
        return [*HEAD, *(f"points_{p}" for p in self.parts), *TAIL]

    def to_csv(self) -> str:
        """One header line and one line per row (``\\n`` line ends); a cell a spreadsheet
        would run as a formula, split on ``,`` or on ``;``, is quoted with ``'`` (:func:`cell_text`)."""
        out = io.StringIO()
        w = csv.writer(out, lineterminator="\n")
        cols = self.columns
        w.writerow(cols)
        for r in self.rows:
            w.writerow([cell_text(r[c]) for c in cols])
        return out.getvalue()

    def to_json(self) -> str:
        data = {
            "columns": self.columns,
            "rows": [{c: r[c] for c in self.columns} for r in self.rows],
            "slips": [s.__dict__ for s in self.slips],
            "set_aside": self.set_aside,
            "steps": self.steps,
            "policy": self.policy,
            "rubric": self.rubric.to_dict(),
        }
        return json.dumps(data, indent=1, sort_keys=True, ensure_ascii=False) + "\n"

    # -- what the summary counts
    def kinds(self) -> list[str]:
        """The exercise kinds of the rows, sorted (``""`` for a row whose kind is not known)."""
        return sorted({r["kind"] or "" for r in self.rows})

    def first_wrong_counts(self, kind: str | None = None) -> dict[str, int]:
        """first wrong step -> how many graded students (of ``kind``, or all) went wrong first there."""
        counts: dict[str, int] = {}
        for r in self.rows:
            if r["status"] == "graded" and r["first_wrong"] and kind in (None, r["kind"] or ""):
                counts[r["first_wrong"]] = counts.get(r["first_wrong"], 0) + 1
        return counts

    def kind_counts(self, kind: str | None = None) -> dict[str, int]:
        """kind of slip -> how many wrong steps (status ``wrong``, of exercise ``kind`` or all)."""
        counts: dict[str, int] = {}
        for s in self.slips:
            if kind in (None, s.exercise):
                counts[s.kind] = counts.get(s.kind, 0) + 1
        return counts


def _choose(tried: list, policy: str):
    graded = [t for t in tried if t[0]["status"] == "graded"]
    if not graded:
        return tried[-1]
    if policy == "best":
        return max(graded, key=lambda t: (t[0]["total"], t[0]["_order"]))
    return graded[-1]


#: where a spreadsheet may start a cell: the cell's start, or after a separator it splits
#: on (``,``, or ``;`` in locales whose decimal mark is a comma) or a line break, then
#: blanks; a formula starts with one of ``= + - @`` (a tab or CR may precede it)
_FORMULA_START = re.compile(r"(^|[,;\r\n])([ ]*)(?=[=+\-@\t\r])")


def cell_text(value) -> str:
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
    """The method part of each step: ``proof`` for the links of a proof (``proof_<line>``),
    else ``newton-euler`` / ``lagrange`` from its key (a tau belongs to the method of the
    steps before it). The grade JSON's own ``part`` field is the assignment's numbered
    part (``7-4``), not a method: it is not used."""
    context = LAGRANGE if method == LAGRANGE else NE
    out = []
    for s in steps:
        key = s.get("key") or key_of(s.get("name") or "")
        if key == "proof":
            out.append(PROOF)
            continue
        if key in _LAGRANGE_KEYS:
            context = LAGRANGE
        elif key and key != "tau":
            context = NE
        out.append(context)
    return out


def proof_statement(step: dict) -> str:
    """A link of a proof named by its equation (its LaTeX, without bold, sizing and
    spacing commands, at most 80 characters), not by its line."""
    text = str(step.get("label") or step.get("name") or "")
    text = re.sub(r"\\(mathbf|boldsymbol|mathrm|bm)\{([^{}]*)\}", r"\2", text)
    text = re.sub(r"\\(left|right|,|;|!|quad)", " ", text)
    text = " ".join(text.split())
    return text if len(text) <= 80 else text[:79] + "…"


def _tau_counts(steps: list[dict], parts_of: list[str], dof: int) -> dict[str, str | None]:
    """Per method: how many of the final torques (the last ``tau_i`` written in that
    method) are right, as ``right/joints``."""
    last: dict[str, dict[str, str]] = {NE: {}, LAGRANGE: {}}
    for s, part in zip(steps, parts_of):
        name = s.get("name") or ""
        if key_of(name) == "tau" and part in last:
            last[part][name] = s.get("status", "")
    out = {}
    for part, taus in last.items():
        joints = max(dof, len(taus))
        out[part] = f"{sum(1 for st in taus.values() if st in _TAU_RIGHT)}/{joints}" if joints else None
    return out


def _expected(kind: str | None, report: dict | None) -> Expected | None:
    if kind:
        try:
            return expected_for(kind)
        except KeyError:
            pass
    return expected_from_report(report) if report is not None else None


def _row(student: str, variant: str | None, report: dict | None, error: str | None, rubric: Rubric, kind):
    expected = _expected(kind, report)
    row = {
        "student": student,
        "variant": variant,
        "kind": kind or (expected.kind if expected else None),
        "status": "graded",
        "error": None,
        "submissions": 1,
        "policy": None,
        "total": 0.0,
        "max": 0.0,
        "first_wrong": None,
        "first_wrong_kind": None,
        "tau_newton-euler": None,
        "tau_lagrange": None,
        **{f"n_{s.replace('-', '_')}": 0 for s in STATUSES},
        "_parts": {},
    }
    if report is None:
        word = (error or "error").split(":", 1)[0].strip()
        row["status"] = word if word in FAILURES else "error"
        row["error"] = " ".join((error or "not graded").split())
    steps = [s for s in (report or {}).get("steps", []) if isinstance(s, dict)]
    parts_of = part_of_steps(steps, (report or {}).get("method"))
    earned: dict[str, list[float]] = {p: [0.0, 0.0] for p in (expected.parts if expected else ())}
    seen, slips, links, counted = set(), [], 0, []
    first = (report or {}).get("first_wrong")
    exercise = row["kind"] or ""
    for s, part in zip(steps, parts_of):
        status = s.get("status", "unrecognised")
        if status in STATUSES:
            row[f"n_{status.replace('-', '_')}"] += 1
        name = s.get("name") or ""
        if not name:
            continue  # an equation that names no step: not counted
        if expected is not None and part not in expected.parts:
            continue  # a step of a part the exercise does not have: not counted
        seen.add((part, name))
        links += part == PROOF
        pts = rubric.step_points(name, s.get("key") or key_of(name))
        acc = earned.setdefault(part, [0.0, 0.0])
        acc[0] += pts * rubric.credit.get(status, 0.0)
        acc[1] += pts
        counted.append(
            {"part": part, "step": name, "status": status, "points": pts * rubric.credit.get(status, 0.0), "max": pts}
        )
        if status == "wrong":
            message = s.get("message") or ""
            slips.append(
                Slip(
                    student=student,
                    step=proof_statement(s) if part == PROOF else name,
                    kind=s.get("slip_kind") or classify(message),
                    message=message,
                    first=name == first and not any(x.first for x in slips),
                    exercise=exercise,
                )
            )
    for part, name in sorted(rubric.required_steps(expected) or ()):
        if (part, name) not in seen:
            earned.setdefault(part, [0.0, 0.0])[1] += rubric.step_points(name, key_of(name))
            counted.append(
                {
                    "part": part,
                    "step": name,
                    "status": "missing",
                    "points": 0.0,
                    "max": rubric.step_points(name, key_of(name)),
                }
            )
    if expected is not None and expected.links > links:  # a proof that stops early: its missing links
        earned.setdefault(PROOF, [0.0, 0.0])[1] += (expected.links - links) * rubric.step_points("proof", "proof")
    for part, total in rubric.parts.items():  # scaled to the rubric's part totals
        if expected is not None and part not in expected.parts:
            continue
        got, most = earned.get(part, [0.0, 0.0])
        earned[part] = [total * got / most if most else 0.0, total]
        for c in counted:  # each step scaled as its part is
            if c["part"] == part:
                c["points"], c["max"] = (c["points"] * total / most, c["max"] * total / most) if most else (0.0, 0.0)
    row["_parts"] = {p: (round(a, 2), round(b, 2)) for p, (a, b) in earned.items()}
    row["_steps"] = [dict(c, points=round(c["points"], 2), max=round(c["max"], 2)) for c in counted]
    row["total"] = round(sum(a for a, _ in row["_parts"].values()), 2)
    row["max"] = round(sum(b for _, b in row["_parts"].values()), 2)
    chosen = next((x for x in slips if x.first), None)
    row["first_wrong"] = chosen.step if chosen is not None else first
    row["first_wrong_kind"] = chosen.kind if chosen is not None else None
    if report is not None and (expected is None or PROOF not in expected.parts):
        taus = _tau_counts(steps, parts_of, expected.dof if expected else 0)
        for part in (NE, LAGRANGE):
            if expected is None or part in expected.parts:
                row[f"tau_{part}"] = taus[part]
    return row, slips
