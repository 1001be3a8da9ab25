"""The server's gradebook: one row per student and exercise, by a stated policy.

Every submission is kept with its verdict; the gradebook counts one of them per student
and exercise: the **latest** (the default: what the student handed in last, as a
teacher collecting papers would) or the **best** (the highest total of the rubric; of
equal totals, the latest). The row says which policy chose it, how many submissions
there were, when the chosen one came and whether it came after the deadline. With a
roster, a student who handed in nothing has a row too (status ``no-submission``).
"""

from __future__ import annotations

import json
import time
from dataclasses import dataclass

from ..course import Gradebook

POLICIES = ("latest", "best")
#: the columns added to :data:`armdyn.course.gradebook.COLUMNS`, after them
EXTRA = ("policy", "submissions", "submitted_at", "late", "submission")
NOTHING = "no-submission"


@dataclass
class ServedGradebook(Gradebook):
    """:class:`armdyn.course.Gradebook` with the server's columns (:data:`EXTRA`)."""

    @property
    def columns(self) -> list[str]:
        base = super().columns  # the course's columns have policy and submissions too: once each
        return [*base, *(c for c in EXTRA if c not in base)]


def _item(row: dict) -> tuple:
    """(student, exercise, report, error) of a stored submission, as the course's gradebook takes it."""
    report = json.loads(row["report_json"]) if row.get("report_json") else None
    error = None
    if report is None:
        error = ("failed: " if row["status"] == "failed" else "") + (row.get("error") or "no verdict")
    return (who_of(row), row.get("graded_as") or row.get("exercise"), report, error)


def who_of(row: dict) -> str:
    return row.get("student_id") or row.get("student") or "(no name)"


def total_of(row: dict) -> tuple[float, float]:
    """(points, out of) of one stored submission under the default rubric."""
    scored = Gradebook.from_results([_item(row)]).rows[0]
    return float(scored["total"]), float(scored["max"])


def choose(rows: list[dict], policy: str) -> dict:
    """The submission ``policy`` counts among one student's ``rows`` for one exercise."""
    if policy == "best":
        return max(rows, key=lambda r: (total_of(r)[0], r["created_at"]))
    return max(rows, key=lambda r: r["created_at"])


def gradebook(rows: list[dict], policy: str = "latest", roster: dict | None = None) -> ServedGradebook:
    """One row per student and exercise from the finished submissions ``rows``
    (:meth:`armdyn.serve.storage.Repository.graded`); ``roster`` (id -> student) adds
    a row for each student without a submission."""
    if policy not in POLICIES:
        raise ValueError(f"gradebook policy must be one of {', '.join(POLICIES)}, not {policy!r}")
    groups: dict[tuple, list[dict]] = {}
    for r in rows:
        groups.setdefault((who_of(r), r.get("graded_as") or r.get("exercise")), []).append(r)
    chosen = {key: choose(group, policy) for key, group in groups.items()}
    items = [_item(r) for r in chosen.values()]
    seen = {who for who, _ in groups}
    missing = [s for sid, s in sorted((roster or {}).items()) if sid not in seen]
    items += [(s.id, s.variant, None, f"{NOTHING}: nothing handed in") for s in missing]
    base = Gradebook.from_results(items)
    for row in base.rows:
        key = (row["student"], row["variant"])
        group = groups.get(key)
        if group is None:
            row.update(status=NOTHING, policy=policy, submissions=0, submitted_at="", late="", submission="")
            continue
        pick = chosen[key]
        row.update(
            policy=policy,
            submissions=len(group),
            submitted_at=time.strftime("%Y-%m-%dT%H:%M:%SZ", time.gmtime(pick["created_at"])),
            late="" if pick.get("late") is None else ("yes" if pick["late"] else "no"),
            submission=pick["id"],
        )
    return ServedGradebook(rows=base.rows, parts=base.parts, slips=base.slips, rubric=base.rubric)
