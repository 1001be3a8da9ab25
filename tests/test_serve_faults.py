"""Nothing accepted is ever lost: a grading worker killed with SIGKILL, then the server
itself, under load; and a graceful stop (SIGTERM) with work still queued.

After the restart every accepted submission is there, with a verdict or in the
``failed`` state (which the student or instructor may retry); the verdicts are the
hand-checked ones of examples/grading/README.md (the exercise: first wrong v_dot_1;
rp-arm-dalembert.md: every step right), whatever happened to the worker grading them.
"""

from __future__ import annotations

import os
import signal
import time
from concurrent.futures import ThreadPoolExecutor

import pytest
from serve_support import EXERCISE, RIGHT, http, start_server

pytest.importorskip("starlette")
pytest.importorskip("uvicorn")

TOKEN = "fault-test-token"
AUTH = {"authorization": f"Bearer {TOKEN}"}


def submit(base: str, n: int, tag: str) -> list[dict]:
    """``n`` distinct submissions (a comment line makes each text unique: no cache),
    alternating the exercise and the right derivation; accepted without waiting."""
    texts = [
        (EXERCISE if i % 2 == 0 else RIGHT).read_text(encoding="utf-8") + f"\n<!-- {tag} {i} -->\n" for i in range(n)
    ]

    def one(i):
        status, body = http(
            "POST", f"{base}/api/grade?wait=0&student=s{i}", texts[i].encode(), {"content-type": "text/markdown"}
        )
        assert status in (200, 202), body
        return {"id": body["id"], "token": body["token"], "right": i % 2 == 1}

    with ThreadPoolExecutor(8) as ex:
        return list(ex.map(one, range(n)))


def settle(base: str, accepted: list[dict], timeout: float = 240.0) -> dict:
    """id -> the API's view once every submission is done or failed."""
    deadline, out = time.monotonic() + timeout, {}
    while time.monotonic() < deadline:
        for a in accepted:
            if a["id"] not in out:
                status, body = http("GET", f"{base}/api/submissions/{a['id']}?t={a['token']}")
                assert status == 200, f"submission {a['id']} lost: {status} {body}"
                if body["status"] in ("done", "failed"):
                    out[a["id"]] = body
        if len(out) == len(accepted):
            return out
        time.sleep(0.5)
    raise AssertionError(f"{len(accepted) - len(out)} submissions still not graded after {timeout} s")


def check_verdicts(accepted: list[dict], final: dict) -> None:
    for a in accepted:
        body = final[a["id"]]
        if body["status"] == "failed":
            assert "retry" in body["error"], body  # a state the student can act on
            continue
        assert body["error"] is None, body
        if a["right"]:
            assert body["passed"] is True and body["first_wrong"] is None
        else:
            assert body["first_wrong"] == "v_dot_1" and body["tau_correct"] == [True, True]


def gone(pid: int) -> bool:
    try:
        with open(f"/proc/{pid}/status") as f:
            return any(line.startswith("State:") and "Z" in line for line in f)
    except FileNotFoundError:
        return True


def test_kill9_worker_then_server_loses_nothing(tmp_path):
    db = f"sqlite:///{tmp_path / 'serve.db'}"
    srv = start_server(tmp_path, db, workers=2, token=TOKEN)
    try:
        accepted = submit(srv.base, 12, "kill")
        # a worker is killed while grading, then (with work queued) the whole server
        time.sleep(1.0)
        _, health = http("GET", f"{srv.base}/api/health", headers=AUTH)
        victims = health["worker_pids"]
        assert len(victims) == 2
        os.kill(victims[0], signal.SIGKILL)
        time.sleep(1.5)
        _, health = http("GET", f"{srv.base}/api/health", headers=AUTH)
        survivors = health["worker_pids"]
        srv.stop(signal.SIGKILL)
    finally:
        if srv.proc.poll() is None:
            srv.stop(signal.SIGKILL)
    # orphaned workers see their pipe close and end (after the grading in hand at most)
    deadline = time.monotonic() + 60
    while time.monotonic() < deadline and not all(gone(p) for p in survivors):
        time.sleep(0.5)
    assert all(gone(p) for p in survivors), "grading workers outlived their server"

    again = start_server(tmp_path, db, workers=2, token=TOKEN)
    try:
        final = settle(again.base, accepted)
        check_verdicts(accepted, final)
        assert sum(b["status"] == "done" for b in final.values()) >= len(accepted) - 1
        # at least one of them was interrupted and graded again
        assert max(b["attempts"] for b in final.values()) >= 2
    finally:
        again.stop()


def test_sigterm_is_graceful_and_queued_work_resumes(tmp_path):
    db = f"sqlite:///{tmp_path / 'serve.db'}"
    srv = start_server(tmp_path, db, workers=1, token=TOKEN)
    accepted = submit(srv.base, 6, "term")
    _, health = http("GET", f"{srv.base}/api/health", headers=AUTH)
    workers = health["worker_pids"]
    code = srv.stop(signal.SIGTERM)
    assert code in (0, -signal.SIGTERM), srv.log.read_text()[-2000:]
    assert all(gone(p) for p in workers), "SIGTERM left grading workers behind"
    again = start_server(tmp_path, db, workers=2, token=TOKEN)
    try:
        final = settle(again.base, accepted)
        assert all(b["status"] == "done" for b in final.values()), final
        check_verdicts(accepted, final)
    finally:
        again.stop()
