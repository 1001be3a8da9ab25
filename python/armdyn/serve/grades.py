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


def _item(row: dict, kinds: dict | None = None) -> tuple:
    """(student, exercise, report, error, kind) of a stored submission, as the course's
    gradebook takes it; ``kinds``: exercise id -> its exercise kind (``rp``, ``rr``, a proof)."""
    report = json.loads(row["report_json"]) if row.get("report_json") else None
    error = None
    if report is None:
        error = ("failed: " if row["status"] == "failed" else "") + (row.get("error") or "no verdict")
    exercise = row.get("graded_as") or row.get("exercise")
    return (who_of(row), exercise, report, error, (kinds or {}).get(exercise))


def exercise_kinds(exercises: dict | None) -> tuple[dict, dict]:
    """(exercise id -> kind, kind -> rubric) of the served variants, as ``armdyn grade DIR
    --variants`` finds them: each variant folder's kind (its ``variant.yaml``) and the kind's
    rubric ``rubric-<kind>.yaml`` beside the folders, when ``exercise make`` wrote it."""
    import os

    from ..course.exercise import rubric_path, variant_kind
    from ..course.rubric import Rubric

    kinds, rubrics = {}, {}
    for ex in (exercises or {}).values():
        if not ex.variant:
            continue
        folder = os.path.dirname(ex.source)
        kind = variant_kind(folder)
        if kind is None:
            continue
        kinds[ex.id] = kind
        path = rubric_path(os.path.dirname(folder), kind)
        if kind not in rubrics and os.path.isfile(path):
            rubrics[kind] = Rubric.load(path)
    return kinds, rubrics


def who_of(row: dict) -> str:
    return row.get("student_id") or row.get("student") or "(no name)"


def total_of(row: dict, kinds: dict | None = None, rubrics: dict | None = None) -> tuple[float, float]:
    """(points, out of) of one stored submission under its kind's rubric (the default one
    when its exercise has no kind)."""
    scored = Gradebook.from_results([_item(row, kinds)], rubrics=rubrics).rows[0]
    return float(scored["total"]), float(scored["max"])


def counted(rows: list[dict], policy: str, exercises: dict | None, exercise: str) -> tuple[dict, float, float]:
    """(the submission ``policy`` counts among one student's ``rows`` for ``exercise``, its
    points, out of): scored by the exercise kind's rubric, as the gradebook scores it, so the
    student's page, the LMS's grade column and the CSV say the same."""
    ex = (exercises or {}).get(exercise)
    kinds, rubrics = exercise_kinds({exercise: ex} if ex is not None else {})
    pick = choose(rows, policy, kinds, rubrics)
    return (pick, *total_of(pick, kinds, rubrics))


def choose(rows: list[dict], policy: str, kinds: dict | None = None, rubrics: dict | None = None) -> dict:
    """The submission ``policy`` counts among one student's ``rows`` for one exercise."""
    if policy == "best":
        return max(rows, key=lambda r: (total_of(r, kinds, rubrics)[0], r["created_at"]))
    return max(rows, key=lambda r: r["created_at"])


def gradebook(
    rows: list[dict], policy: str = "latest", roster: dict | None = None, exercises: dict | None = None
) -> ServedGradebook:
    """One row per student and exercise from the finished submissions ``rows``
    (:meth:`armdyn.serve.storage.Repository.graded`); ``roster`` (id -> student) adds
    a row for each student without a submission; ``exercises`` (the served catalogue)
    gives each variant's kind, so a mixed class is scored as ``armdyn grade DIR --variants``
    scores it: each student by their own kind's rubric."""
    kinds, rubrics = exercise_kinds(exercises)
    if policy not in POLICIES:
        raise ValueError(f"gradebook policy must be one of {', '.join(POLICIES)}, not {policy!r}")
    groups: dict[tuple, list[dict]] = {}
    for r in rows:
        groups.setdefault((who_of(r), r.get("graded_as") or r.get("exercise")), []).append(r)
    chosen = {key: choose(group, policy, kinds, rubrics) for key, group in groups.items()}
    items = [_item(r, kinds) for r in chosen.values()]
    seen = {who for who, _ in groups}
    missing = [s for sid, s in sorted((roster or {}).items()) if sid not in seen]
    items += [(s.id, s.variant, None, f"{NOTHING}: nothing handed in") for s in missing]
    base = Gradebook.from_results(items, rubrics=rubrics)
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
