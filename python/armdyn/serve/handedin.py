"""``armdyn submissions``: the texts a server's gradebook counts, as files for
``armdyn grade DIR`` (a regrade with another rubric or a corrected key, ``--regrade``).

One file per student, ``OUT/<student>.md``: the submission ``policy`` counts for them
(:func:`.grades.choose`, as the server's gradebook does), byte for byte as handed in.
A student with submissions to two exercises gets the latest exercise's (a roster gives
each student one).
"""

from __future__ import annotations

import os

from ..course.batch import safe_file_name
from .grades import choose, who_of
from .storage import Repository


def write_handed_in(db: str, out: str, policy: str = "latest") -> list[str]:
    """Write each student's counted submission into ``out``; the paths written, sorted."""
    repo = Repository(db)
    try:
        groups: dict[str, list[dict]] = {}
        for row in repo.graded():
            groups.setdefault(who_of(row), []).append(row)
        os.makedirs(out, exist_ok=True)
        written = []
        for student, rows in sorted(groups.items()):
            latest_exercise = max(rows, key=lambda r: r["created_at"])
            same = [
                r
                for r in rows
                if (r["graded_as"] or r["exercise"]) == (latest_exercise["graded_as"] or latest_exercise["exercise"])
            ]
            full = repo.get(choose(same, policy)["id"])
            path = os.path.join(out, safe_file_name(student) + ".md")
            with open(path, "w", encoding="utf-8", newline="") as fh:
                fh.write(full["markdown"])
            written.append(path)
        return written
    finally:
        repo.dispose()
