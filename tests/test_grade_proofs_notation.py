"""Proofs about rigid bodies as people write them (grading/proofs), and one grading path.

Second opinions: the truth of every proof line below is decided by hand when it is
written (a true identity, or a deliberate slip of a kind students make: a factor, a
transpose, a sign, a mass-center fact about the wrong point), never from armdyn's output;
the web app and ``armdyn grade DIR`` are compared with the grader run on the file.
"""

from __future__ import annotations

import json
from pathlib import Path

import pytest

from armdyn.grading import grade
from armdyn.grading.reader import read_markdown

EXAMPLES = Path(__file__).resolve().parent.parent / "examples" / "grading"
EXERCISE = EXAMPLES / "rp-arm-exercise.md"


def steps(report_json: dict) -> list[tuple]:
    return [(s["name"], s["line"], s["status"]) for s in report_json["steps"]]


def file_verdicts() -> list[tuple]:
    return steps(json.loads(grade(EXERCISE).to_json()))


# ------------------------------------------------------------------ one grading path
def test_the_text_alone_carries_the_proofs():
    text = EXERCISE.read_text(encoding="utf-8")
    from_file = file_verdicts()
    # the exercise's two proofs, by hand: 7-3 has lines 29 to 77, the energy proof 137 to 153
    proof_lines = {line for name, line, _ in from_file if name.startswith("proof_")}
    assert {29, 35, 77, 137, 153} <= proof_lines
    posted = steps(json.loads(grade(read_markdown("submission.md", text)).to_json()))
    assert posted == from_file
    elsewhere = steps(json.loads(grade(read_markdown("/nonexistent/dir/x.md", text)).to_json()))
    assert elsewhere == from_file  # no file on disk: the same proofs


def test_the_web_app_grades_the_proofs_as_the_cli(tmp_path):
    pytest.importorskip("starlette")
    pytest.importorskip("sqlalchemy")
    pytest.importorskip("httpx")
    from test_serve_api import MD, client_for, wait_ready

    with client_for(f"sqlite:///{tmp_path / 'serve.db'}") as c:
        wait_ready(c)
        r = c.post("/api/grade", content=EXERCISE.read_bytes(), headers=MD)
        assert r.status_code == 200, r.text
        got = r.json()
    assert got["status"] == "done"
    assert steps(got) == file_verdicts()
    assert sum(1 for s in got["steps"] if s["name"].startswith("proof_")) >= 16
    assert not [s for s in got["steps"] if s["name"].startswith("proof_") and s["status"] == "unrecognised"]


def test_a_class_folder_grades_the_proofs_as_the_cli(tmp_path):
    from armdyn.course.batch import CACHE_DIR, grade_class

    subs = tmp_path / "subs"
    subs.mkdir()
    (subs / "ada.md").write_bytes(EXERCISE.read_bytes())
    out = tmp_path / "out"
    out.mkdir()
    result = grade_class(subs, out / "gradebook.csv", jobs=1, progress=False)
    assert not result.not_graded
    cached = [json.loads(p.read_text()) for p in (out / CACHE_DIR).glob("*.json")]
    assert len(cached) == 1
    assert steps(cached[0]["report"]) == file_verdicts()
