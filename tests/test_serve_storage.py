"""armdyn.serve.storage against SQLite and PostgreSQL: the life of a submission.

The expected states are the ones the design states (queued -> running -> done/failed,
attempts counted, nothing lost), checked transition by transition; the cache is
checked against the definition (same exercise and text -> the same stored result).
"""

from __future__ import annotations

import threading

import pytest

pytest.importorskip("sqlalchemy")
pytest.importorskip("alembic")

from serve_support import db_url  # noqa: F401 - the parametrized fixture

from armdyn.serve.migrations import MIGRATIONS, current_version
from armdyn.serve.storage import DONE, FAILED, QUEUED, RUNNING, Repository

RESULT = {
    "graded_as": "rp-arm",
    "passed": False,
    "first_wrong": "v_dot_1",
    "error": None,
    "report_json": '{"first_wrong": "v_dot_1"}',
    "report_html": "<p>page</p>",
    "report_fragment": "<p>f</p>",
}


def test_schema_versioned_and_idempotent(db_url):  # noqa: F811
    repo = Repository(db_url)
    with repo.engine.connect() as conn:
        assert current_version(conn) == len(MIGRATIONS) >= 1
    Repository(db_url).dispose()  # a second start applies nothing and keeps the rows
    repo.add("a1", "h", "text")
    again = Repository(db_url)
    assert again.get("a1")["markdown"] == "text"
    repo.dispose()
    again.dispose()


def test_fifo_claim_finish_and_cache(db_url):  # noqa: F811
    repo = Repository(db_url)
    first = repo.add("s1", "tok1", "$$x = 1$$", "rp-arm", "ada", "owner-a")
    repo.add("s2", "tok2", "$$x = 2$$", "rp-arm", "bob", "owner-b")
    twin = repo.add("s3", "tok3", "$$x = 1$$", "rp-arm", "cy", "owner-c")  # same text, s1 not graded yet
    assert first["status"] == twin["status"] == QUEUED
    job = repo.claim()
    assert (job.id, job.attempts) == ("s1", 1)
    assert repo.summary("s1")["status"] == RUNNING
    assert sorted(repo.finish("s1", RESULT)) == ["s1", "s3"]  # the queued twin is finished with it
    for sid in ("s1", "s3"):
        row = repo.get(sid)
        assert (row["status"], row["first_wrong"], row["report_html"]) == (DONE, "v_dot_1", "<p>page</p>")
    assert repo.get("s3")["cached"] and not repo.get("s1")["cached"]
    later = repo.add("s4", "tok4", "$$x = 1$$", "rp-arm", "dee")  # graded before: done at once
    assert later["status"] == DONE and later["cached"] and later["first_wrong"] == "v_dot_1"
    other = repo.add("s5", "tok5", "$$x = 1$$", "planar-2r")  # another exercise: not the same work
    assert other["status"] == QUEUED
    # the same exercise and text, but its model corrected since (another grading key): graded again
    corrected = repo.add("s6", "tok6", "$$x = 1$$", "rp-arm", "eve", key="0.1.0:model digest after the fix")
    assert corrected["status"] == QUEUED and not corrected["cached"]
    assert repo.claim().id == "s2"
    assert [r["id"] for r in repo.by_owner("owner-a")] == ["s1"]
    assert repo.counts() == {QUEUED: 2, RUNNING: 1, DONE: 3, FAILED: 0}
    repo.dispose()


def test_killed_worker_retries_then_fails(db_url):  # noqa: F811
    repo = Repository(db_url, max_attempts=2)
    repo.add("k1", "t", "text")
    assert repo.claim().attempts == 1
    assert repo.give_up("k1", "worker killed", retry=True) == QUEUED
    assert repo.claim().attempts == 2
    assert repo.give_up("k1", "worker killed", retry=True) == FAILED
    row = repo.get("k1")
    assert row["status"] == FAILED and row["error"] == "worker killed"
    assert repo.claim() is None
    assert repo.retry("k1") and repo.get("k1")["status"] == QUEUED and repo.get("k1")["attempts"] == 0
    repo.dispose()


def test_restart_recovers_running_and_release_does_not_count(db_url):  # noqa: F811
    repo = Repository(db_url, max_attempts=2)
    for i in range(3):
        repo.add(f"r{i}", "t", f"text {i}")
    a, b = repo.claim(), repo.claim()
    repo.release(b.id)  # a graceful stop: back in the queue, the attempt not counted
    assert repo.get(b.id)["attempts"] == 0 and repo.get(b.id)["status"] == QUEUED
    repo.dispose()
    # the server died with `a` running: the next start puts it back in the queue
    again = Repository(db_url, max_attempts=2)
    assert again.recover() == 1
    assert again.get(a.id)["status"] == QUEUED
    assert again.claim().id == a.id and again.get(a.id)["attempts"] == 2
    again.dispose()
    third = Repository(db_url, max_attempts=2)  # died again: attempts used up -> failed, not lost
    assert third.recover() == 1
    assert third.get(a.id)["status"] == FAILED and "interrupted" in third.get(a.id)["error"]
    assert third.counts() == {QUEUED: 2, RUNNING: 0, DONE: 0, FAILED: 1}
    third.dispose()


def test_concurrent_claims_never_share_a_submission(db_url):  # noqa: F811
    repo = Repository(db_url)
    n = 40
    for i in range(n):
        repo.add(f"c{i:02d}", "t", f"text {i}")
    got, lock = [], threading.Lock()

    def claimer():
        while (job := repo.claim()) is not None:
            with lock:
                got.append(job.id)

    threads = [threading.Thread(target=claimer) for _ in range(6)]
    for t in threads:
        t.start()
    for t in threads:
        t.join()
    assert sorted(got) == [f"c{i:02d}" for i in range(n)]  # each exactly once
    repo.dispose()
