"""The grading pool's limits: a grading over the time limit is stopped and marked
failed (not retried, not lost); the memory limit really caps a worker's address space."""

from __future__ import annotations

import subprocess
import sys
import time

import pytest
from serve_support import EXERCISE, ROOT

pytest.importorskip("sqlalchemy")


def test_timeout_kills_the_worker_and_fails_the_submission(tmp_path):
    from armdyn.serve.pool import Pool
    from armdyn.serve.storage import Repository

    repo = Repository(f"sqlite:///{tmp_path / 'db.sqlite'}")
    done = []
    pool = Pool(repo, {"rp-arm": "rp-arm"}, workers=1, timeout=0.01, on_done=done.extend)
    pool.start()
    try:
        deadline = time.monotonic() + 120
        while not pool.ready and time.monotonic() < deadline:
            time.sleep(0.1)
        first = pool.pids()
        repo.add("slow", "t", EXERCISE.read_text(encoding="utf-8"), "rp-arm")
        pool.wake()
        while "slow" not in done and time.monotonic() < deadline:
            time.sleep(0.1)
        row = repo.get("slow")
        assert row["status"] == "failed" and "longer than 0.01 s" in row["error"] and row["attempts"] == 1
        while pool.pids() == first and time.monotonic() < deadline:  # a fresh worker replaces the killed one
            time.sleep(0.1)
        assert pool.pids() and pool.pids() != first
    finally:
        pool.stop()
        repo.dispose()


def test_memory_limit_caps_the_address_space():
    code = (
        "from armdyn.serve.worker import limit_memory\n"
        "limit_memory(300)\n"
        "try:\n    block = bytearray(600 * 2**20)\nexcept MemoryError:\n    print('capped')\n"
        "else:\n    print('allocated', len(block))\n"
    )
    out = subprocess.run(
        [sys.executable, "-c", code],
        check=False,
        capture_output=True,
        text=True,
        timeout=120,
        env={"PYTHONPATH": str(ROOT / "python"), "PATH": "/usr/bin:/bin"},
    )
    assert out.stdout.strip() == "capped", out.stdout + out.stderr


def test_worker_report_is_grade_html():
    """The worker builds the report's body once; the page and the fragment must still be
    exactly what ``armdyn grade --html`` (report_html) and Jupyter (repr_html) show."""
    from armdyn.grading import grade
    from armdyn.grading.html import report_html, repr_html
    from armdyn.grading.reader import read_markdown
    from armdyn.serve.worker import SUBMISSION, Grader

    text = EXERCISE.read_text(encoding="utf-8")
    got = Grader({"rp-arm": "rp-arm"}).grade(text, None)
    report = grade(read_markdown(SUBMISSION, text))
    assert got["report_html"] == report_html(report)
    assert got["report_fragment"] == repr_html(report)
    assert got["first_wrong"] == "v_dot_1" and got["graded_as"] == "rp-arm"
