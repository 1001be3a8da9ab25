"""What a regrade changed: the class's previous gradebook (``grades.json``) against the new
one, per student, after the key (a variant's ``model.yaml``) or the rubric changed.

    before = load_previous("grades.json")          # read before grade_class overwrites it
    changes = compare(before, new_gradebook)       # one Change per student whose score or steps changed
    print(report_lines(changes))

A step's state is its verdict and the points it earned of its points: a rubric that
weighs ``tau`` 3 instead of 2 changes the points of every ``tau_i``, a corrected key
changes verdicts. A student who is new, or gone, is a change too (old or new is None).
"""

from __future__ import annotations

import csv
import io
import json
from dataclasses import dataclass, field

from ..errors import ModelError
from .gradebook import cell_text


@dataclass
class StepChange:
    part: str
    step: str
    old: tuple[str, float, float] | None  # (status, points, max); None: not counted before
    new: tuple[str, float, float] | None

    def text(self) -> str:
        def state(s):
            return "not counted" if s is None else f"{s[0]} {s[1]:g}/{s[2]:g}"

        return f"{self.step} ({self.part}): {state(self.old)} -> {state(self.new)}"


@dataclass
class Change:
    student: str
    old: tuple[float, float] | None  # (total, max); None: no row before
    new: tuple[float, float] | None
    steps: list[StepChange] = field(default_factory=list)
    status: tuple[str | None, str | None] = (None, None)


def load_previous(path: str) -> dict:
    """The previous run's ``grades.json`` as ``{student: {"total", "max", "status", "steps"}}``.
    A file without per-step states (written before they were kept) still gives totals."""
    try:
        with open(path, encoding="utf-8") as fh:
            data = json.load(fh)
    except FileNotFoundError:
        raise ModelError(
            "no previous gradebook to compare with (run armdyn grade DIR once without --regrade)", source=path
        ) from None
    except (json.JSONDecodeError, UnicodeDecodeError) as err:
        raise ModelError(f"not a gradebook's JSON: {err}", source=path) from None
    if not isinstance(data, dict) or not isinstance(data.get("rows"), list):
        raise ModelError("not a gradebook's JSON (no rows)", source=path)
    steps = data.get("steps") if isinstance(data.get("steps"), dict) else {}
    return {
        str(r["student"]): {
            "total": r.get("total"),
            "max": r.get("max"),
            "status": r.get("status"),
            "steps": steps.get(str(r["student"])),
        }
        for r in data["rows"]
        if isinstance(r, dict) and "student" in r
    }


def _states(steps: list[dict] | None) -> dict[tuple[str, str], tuple[str, float, float]]:
    return {(s["part"], s["step"]): (s["status"], s["points"], s["max"]) for s in steps or ()}


def compare(before: dict, book) -> list[Change]:
    """One :class:`Change` per student whose total, maximum, status or any step's state
    differs between ``before`` (:func:`load_previous`) and ``book`` (a Gradebook), sorted."""
    after = {r["student"]: r for r in book.rows}
    changes = []
    for student in sorted(set(before) | set(after)):
        old, row = before.get(student), after.get(student)
        was = (old["total"], old["max"]) if old else None
        now = (row["total"], row["max"]) if row else None
        steps = []
        if old and row and old["steps"] is not None:
            a, b = _states(old["steps"]), _states(book.steps.get(student))
            for key in sorted(set(a) | set(b)):
                if a.get(key) != b.get(key):
                    steps.append(StepChange(key[0], key[1], a.get(key), b.get(key)))
        status = (old["status"] if old else None, row["status"] if row else None)
        if was != now or steps or status[0] != status[1]:
            changes.append(Change(student, was, now, steps, status))
    return changes


def _score(pair) -> str:
    return "-" if pair is None else f"{pair[0]:g}/{pair[1]:g}"


def report_lines(changes: list[Change], students: int) -> list[str]:
    """What ``armdyn grade DIR --regrade`` prints: one line per student changed, then its steps."""
    lines = [f"regrade: {len(changes)} of {students} students changed"]
    for c in changes:
        status = f" ({c.status[0]} -> {c.status[1]})" if c.status[0] != c.status[1] else ""
        lines.append(f"  {c.student}: {_score(c.old)} -> {_score(c.new)}{status}")
        lines.extend(f"    {s.text()}" for s in c.steps)
    return lines


def to_csv(changes: list[Change]) -> str:
    """``student,old_total,old_max,new_total,new_max,old_status,new_status,steps_changed``:
    the steps as ``step (part): old -> new`` joined by ``; ``."""
    out = io.StringIO()
    w = csv.writer(out, lineterminator="\n")
    w.writerow(["student", "old_total", "old_max", "new_total", "new_max", "old_status", "new_status", "steps_changed"])
    for c in changes:
        old, new = c.old or ("", ""), c.new or ("", "")
        steps = "; ".join(s.text() for s in c.steps)
        w.writerow([cell_text(c.student), *old, *new, c.status[0] or "", c.status[1] or "", cell_text(steps)])
    return out.getvalue()
