"""What an attacker or an overloaded course found in ``armdyn serve``, each held here.

- a database error in a grading thread (a verdict PostgreSQL refuses, the database away)
  must not end the thread: the submission is failed with its reason or graded once the
  database answers, and the next submission is graded; a queue that does not move shows
  in ``/api/health``;
- NUL in a derivation, a student name or a submission id: 400/404 at the door, not 500;
- previews are bounded (503 with Retry-After) and ``/api/health`` answers meanwhile;
- instructor logins are throttled (429), short tokens refused, sessions end on logout
  and expire;
- grading workers do not inherit the server's secrets and load YAML models only;
- request heads that never finish are closed, and connections are capped;
- a trailing-slash redirect does not take its ``Location`` from the ``Host`` header.

The expectations come from the promises of docs/security.md, not from the server's own
output; every load is bounded in count and time and stays on 127.0.0.1.
"""

from __future__ import annotations

import socket
import threading
import time
from concurrent.futures import ThreadPoolExecutor

import pytest

pytest.importorskip("starlette")
pytest.importorskip("sqlalchemy")
pytest.importorskip("httpx")
pytest.importorskip("uvicorn")

import sqlalchemy as sa
from serve_support import EXERCISE, RIGHT, db_url, free_port, http  # noqa: F401

TOKEN = "instructor-secret-for-tests"
MD = {"content-type": "text/markdown"}


def client_for(url: str, **kw):
    from starlette.testclient import TestClient

    from armdyn.serve.app import Settings, build_app
    from armdyn.serve.exercises import catalogue

    kw.setdefault("exercises", catalogue())
    kw.setdefault("workers", 1)
    kw.setdefault("instructor_token", TOKEN)
    return TestClient(build_app(Settings(db=url, **kw)))


def wait_until(predicate, timeout: float, what: str):
    deadline = time.monotonic() + timeout
    while time.monotonic() < deadline:
        got = predicate()
        if got:
            return got
        time.sleep(0.2)
    raise AssertionError(f"not within {timeout} s: {what}")


def wait_ready(c):
    wait_until(lambda: c.get("/api/health").status_code == 200, 120, "the grading workers started")


def settled(c, body: dict, timeout: float = 120.0) -> dict:
    """The submission once done or failed."""

    def look():
        got = c.get(f"/api/submissions/{body['id']}?t={body['token']}").json()
        return got if got["status"] in ("done", "failed") else None

    return wait_until(look, timeout, f"submission {body['id']} graded")


# -- F2: database errors in grading threads


def test_refused_verdict_fails_the_submission_and_the_thread_lives(tmp_path, monkeypatch):
    """A verdict the database refuses (DataError) fails that submission with a reason; a
    database away for a moment or longer (OperationalError) only delays the write, the
    verdict is kept; the same thread then grades the next submission."""
    from armdyn.serve import pool as pool_mod
    from armdyn.serve.storage import Repository

    repo = Repository(f"sqlite:///{tmp_path / 'db.sqlite'}")
    real_finish, calls = repo.finish, []

    def finish(sid, result):
        calls.append(sid)
        if sid == "poison":
            raise sa.exc.DataError("INSERT", {}, ValueError("PostgreSQL text cannot contain NUL (0x00) bytes"))
        if sid == "blip" and calls.count("blip") <= 2:
            raise sa.exc.OperationalError("UPDATE", {}, ConnectionError("server closed the connection"))
        if sid == "outage" and calls.count("outage") <= 6:  # longer than the write's own tries
            raise sa.exc.OperationalError("UPDATE", {}, ConnectionError("the database system is starting up"))
        return real_finish(sid, result)

    monkeypatch.setattr(repo, "finish", finish)
    done = []
    pool = pool_mod.Pool(repo, {"rp-arm": "rp-arm"}, workers=1, on_done=done.extend)
    pool.start()
    try:
        wait_until(lambda: pool.ready, 120, "the worker started")
        text = EXERCISE.read_text(encoding="utf-8")
        repo.add("poison", "t", text + "\n<!-- 1 -->\n", "rp-arm")
        repo.add("blip", "t", text + "\n<!-- 2 -->\n", "rp-arm")
        repo.add("outage", "t", text + "\n<!-- 3 -->\n", "rp-arm")
        repo.add("after", "t", RIGHT.read_text(encoding="utf-8"), "rp-arm")
        pool.wake()
        wait_until(lambda: {"poison", "blip", "outage", "after"} <= set(done), 120, "all four settled")
        poison, blip, after = repo.get("poison"), repo.get("blip"), repo.get("after")
        outage = repo.get("outage")  # its verdict waited for the database, then was written
        assert outage["status"] == "done" and outage["first_wrong"] == "v_dot_1" and calls.count("outage") == 7
        assert poison["status"] == "failed" and "could not be stored" in poison["error"], poison
        assert poison["attempts"] == 1 and calls.count("poison") == 1  # a refused value is not retried
        assert blip["status"] == "done" and blip["first_wrong"] == "v_dot_1"  # hand-checked verdict
        assert after["status"] == "done" and after["passed"] is True
        assert pool.health()["threads"] == 1
    finally:
        pool.stop()
        repo.dispose()


def test_nul_in_a_verdict_is_stored_and_grading_goes_on(db_url):  # noqa: F811
    """YAML's "\\0" escape puts a real NUL in the exercise name, and so in the verdict's
    error message; PostgreSQL's text refuses NUL. The verdict is stored (the NUL shown
    escaped) and the next submission is graded."""
    with client_for(db_url) as c:
        wait_ready(c)
        r = c.post("/api/grade?wait=60", content=b'---\nrobot: "rp\\0arm"\n---\n$$\\tau_1 = 0$$\n', headers=MD)
        assert r.status_code in (200, 202), r.text
        first = settled(c, r.json())
        assert first["status"] == "done" and "unknown exercise" in first["error"] and "\0" not in first["error"]
        nxt = c.post("/api/grade?robot=rp-arm&wait=60", content=RIGHT.read_bytes(), headers=MD).json()
        assert settled(c, nxt)["passed"] is True
        assert c.get("/api/health").json()["status"] == "ok"


def test_nul_is_refused_at_the_door(db_url):  # noqa: F811
    with client_for(db_url) as c:
        wait_ready(c)
        r = c.post("/api/grade?robot=rp-arm", content=b"$$\\tau_1 = 0$$\n\n$$x = 1\x00$$\n", headers=MD)
        assert r.status_code == 400 and "NUL" in r.json()["error"] and "line 3" in r.json()["error"]
        r = c.post("/api/grade?robot=rp-arm&student=a%00b", content=RIGHT.read_bytes(), headers=MD)
        assert r.status_code == 400 and "student name" in r.json()["error"]
        r = c.get("/api/submissions/ab%00cd")
        assert r.status_code == 400 and "not a submission id" in r.json()["error"]
        assert c.get("/submissions/ab%00cd").status_code == 400
        assert c.get("/submissions/ab%00cd/report.html").status_code == 400
        assert c.get("/api/submissions/abcd").status_code == 404  # well-formed, not there


def test_health_tells_a_queue_that_does_not_move(tmp_path, monkeypatch):
    from armdyn.serve import pool as pool_mod

    monkeypatch.setattr(pool_mod, "STALL_SLACK", -28.0)  # stuck after 2 s instead of timeout + 30 s
    with client_for(f"sqlite:///{tmp_path / 'db.sqlite'}", timeout=30.0) as c:
        wait_ready(c)
        repo = c.app.state.server.repo
        real_claim = repo.claim

        def claim():
            raise sa.exc.OperationalError("SELECT", {}, OSError("database or disk is full"))

        monkeypatch.setattr(repo, "claim", claim)
        body = c.post("/api/grade?robot=rp-arm&wait=0", content=RIGHT.read_bytes(), headers=MD).json()
        assert body["status"] == "queued"

        def degraded():
            r = c.get("/api/health")
            return r if r.status_code == 503 else None

        r = wait_until(degraded, 20, "health reports the stuck queue")
        assert r.json()["status"] == "degraded" and any("not moved" in p for p in r.json()["problems"]), r.json()
        monkeypatch.setattr(repo, "claim", real_claim)  # the database is back: the same threads go on
        final = settled(c, body)
        assert final["passed"] is True, final
        wait_until(lambda: c.get("/api/health").status_code == 200, 20, "health ok again")


def test_a_database_that_does_not_answer_is_a_503_to_send_again(tmp_path, monkeypatch):
    """While the database restarts, a request gets 503 with Retry-After (not a 500 and a
    traceback), and a request waiting for its verdict waits on through the outage."""
    with client_for(f"sqlite:///{tmp_path / 'db.sqlite'}") as c:
        wait_ready(c)
        repo = c.app.state.server.repo
        real_add, real_summary = repo.add, repo.summary
        down = sa.exc.OperationalError("INSERT", {}, OSError("the database system is shutting down"))

        def add(*a, **kw):
            raise down

        monkeypatch.setattr(repo, "add", add)
        r = c.post("/api/grade?robot=rp-arm&wait=0", content=RIGHT.read_bytes(), headers=MD)
        assert r.status_code == 503 and r.headers["retry-after"] == "2", r.text
        assert "database" in r.json()["error"] and "Traceback" not in r.text
        monkeypatch.setattr(repo, "add", real_add)
        outage = {"calls": 0, "left": 2}

        def summary(sid):
            outage["calls"] += 1
            if outage["calls"] > 1 and outage["left"]:  # the first is the store's own, in add
                outage["left"] -= 1
                raise down
            return real_summary(sid)

        monkeypatch.setattr(repo, "summary", summary)
        r = c.post("/api/grade?robot=rp-arm&wait=60", content=RIGHT.read_bytes(), headers=MD)
        assert r.status_code == 200 and outage["left"] == 0, r.text
        assert settled(c, r.json())["passed"] is True


def test_health_tells_a_worker_that_cannot_start(tmp_path):
    """A grading worker that dies before it is ready (here: an address-space limit too
    small to import armdyn) is named among the problems, with why."""
    from armdyn.serve.pool import Pool
    from armdyn.serve.storage import Repository

    repo = Repository(f"sqlite:///{tmp_path / 'db.sqlite'}")
    pool = Pool(repo, {"rp-arm": "rp-arm"}, workers=1, memory_mb=40)
    pool.start()
    try:
        problems = wait_until(lambda: pool.problems(0), 120, "a problem reported")
        assert any("grading worker 0 cannot be started" in p for p in problems), problems
    finally:
        pool.stop()
        repo.dispose()


# -- F5, F6: the instructor's login


def csrf_of(c) -> str:
    import re

    return re.search(r'name="csrf" value="([^"]+)"', c.get("/instructor").text).group(1)


def test_login_is_throttled_per_client(tmp_path):
    with client_for(f"sqlite:///{tmp_path / 'db.sqlite'}", workers=1, login_per_client=5) as c:
        csrf = csrf_of(c)
        for i in range(5):
            assert c.post("/instructor/login", data={"token": f"wrong-{i}", "csrf": csrf}).status_code == 403
        r = c.post("/instructor/login", data={"token": TOKEN, "csrf": csrf}, follow_redirects=False)
        assert r.status_code == 429 and int(r.headers["retry-after"]) > 0 and "try again" in r.text
        # the API's Bearer is throttled alike: no instructor view while blocked
        assert "worker_pids" not in c.get("/api/health", headers={"authorization": f"Bearer {TOKEN}"}).json()


def test_throttle_counts_every_client_together():
    from armdyn.serve.security import Throttle

    t = Throttle(per_client=5, overall=8, window=60.0)
    for i in range(8):
        assert t.wait(f"10.0.0.{i}") == 0
        t.failed(f"10.0.0.{i}")
    assert 0 < t.wait("10.9.9.9") <= 60.0  # a client never seen is refused too: the overall limit
    t1 = Throttle(per_client=2, overall=100, window=60.0)
    t1.failed("a")
    t1.failed("a")
    assert t1.wait("a") > 0 and t1.wait("b") == 0


def test_short_instructor_token_is_refused(tmp_path):
    import subprocess
    import sys

    from serve_support import ROOT

    with pytest.raises(ValueError, match="at least 16"):
        client_for(f"sqlite:///{tmp_path / 'db.sqlite'}", instructor_token="change-me")
    out = subprocess.run(
        [sys.executable, "-m", "armdyn", "serve", "--instructor-token", "change-me", "--port", str(free_port())],
        capture_output=True,
        text=True,
        timeout=60,
        env={"PYTHONPATH": str(ROOT / "python"), "PATH": "/usr/bin:/bin"},
    )
    assert out.returncode == 2 and "at least 16" in out.stderr, out.stderr


def test_logout_revokes_the_session_and_sessions_expire(tmp_path, monkeypatch):
    from armdyn.serve import security

    with client_for(f"sqlite:///{tmp_path / 'db.sqlite'}") as c:
        csrf = csrf_of(c)
        assert c.post("/instructor/login", data={"token": TOKEN, "csrf": csrf}).status_code == 200
        cookie = c.cookies.get(security.INSTRUCTOR_COOKIE)
        assert cookie and TOKEN not in cookie
        assert c.get("/instructor/gradebook.csv", follow_redirects=False).status_code == 200
        c.post("/instructor/logout", data={"csrf": csrf})
        c.cookies.set(security.INSTRUCTOR_COOKIE, cookie)  # a copy kept by whoever saw it
        assert c.get("/instructor/gradebook.csv", follow_redirects=False).status_code == 303
        monkeypatch.setattr(security, "SESSION_SECONDS", 2)
        c.cookies.delete(security.INSTRUCTOR_COOKIE)
        c.post("/instructor/login", data={"token": TOKEN, "csrf": csrf})
        fresh = c.cookies.get(security.INSTRUCTOR_COOKIE)
        assert c.get("/instructor/gradebook.csv", follow_redirects=False).status_code == 200
        time.sleep(2.5)
        c.cookies.set(security.INSTRUCTOR_COOKIE, fresh)  # kept past its Max-Age: the server says no
        assert c.get("/instructor/gradebook.csv", follow_redirects=False).status_code == 303


# -- F10, xacro: the grading worker


def test_worker_does_not_inherit_the_secrets(monkeypatch):
    from armdyn.serve.pool import WorkerProcess

    monkeypatch.setenv("ARMDYN_INSTRUCTOR_TOKEN", "leak-me-instructor-token")
    monkeypatch.setenv("ARMDYN_SECRET", "leak-me-server-secret")
    monkeypatch.setenv("DATABASE_PASSWORD", "leak-me-db")
    proc = WorkerProcess({"rp-arm": "rp-arm"}, 2048)
    try:
        with open(f"/proc/{proc.pid}/environ", "rb") as f:
            env = dict(item.split(b"=", 1) for item in f.read().split(b"\0") if b"=" in item)
    finally:
        proc.kill()
    assert b"ARMDYN_SERVE_EXERCISES" in env  # the environment was read
    assert not [k for k, v in env.items() if b"leak-me" in v], sorted(env)


def test_worker_never_loads_a_xacro_model(tmp_path):
    from armdyn.serve.worker import Grader

    model = tmp_path / "arm.xacro"
    model.write_text('<robot name="x" xmlns:xacro="http://www.ros.org/wiki/xacro"/>\n', encoding="utf-8")
    got = Grader({"x": str(model)}).grade("$$\\tau_1 = 0$$\n", "x")
    assert got["ok"] and got["report_json"] is None and "not a YAML model" in got["error"]


# -- F3, F11, redirects: the HTTP layer under load (a real uvicorn on 127.0.0.1)


class LiveServer:
    """uvicorn in a thread of this process, with the limits given."""

    def __init__(self, tmp_path, **limits):
        import uvicorn

        from armdyn.serve.app import Settings, build_app
        from armdyn.serve.exercises import catalogue
        from armdyn.serve.server import config

        self.port = free_port()
        self.app = app = build_app(Settings(db=f"sqlite:///{tmp_path / 'db.sqlite'}", workers=1, exercises=catalogue()))
        self.server = uvicorn.Server(config(app, "127.0.0.1", self.port, **limits))
        self.thread = threading.Thread(target=self.server.run, daemon=True)
        self.base = f"http://127.0.0.1:{self.port}"

    def __enter__(self):
        self.thread.start()
        wait_until(lambda: self._health() == 200, 120, "the server is ready")
        return self

    def _health(self):
        try:
            return http("GET", self.base + "/api/health", timeout=5)[0]
        except OSError:
            return None

    def __exit__(self, *exc):
        self.server.should_exit = True
        self.thread.join(60)


def half_open(port: int, n: int, source: str = "127.0.0.1") -> list[socket.socket]:
    """``n`` connections from ``source`` that send part of a request head and then nothing."""
    socks = []
    for _ in range(n):
        s = socket.create_connection(("127.0.0.1", port), timeout=5, source_address=(source, 0))
        s.sendall(b"GET /api/health HTTP/1.1\r\nHost: 127.0.0.1\r\nX-Slow: ")
        socks.append(s)
    return socks


def closed_by_server(s: socket.socket, wait: float) -> bool:
    s.settimeout(wait)
    try:
        return s.recv(1024) == b""
    except (TimeoutError, socket.timeout):
        return False
    except OSError:
        return True  # reset


def test_unfinished_request_heads_are_closed_and_connections_capped(tmp_path):
    with LiveServer(tmp_path, header_seconds=2.0, max_connections=40) as live:
        socks = half_open(live.port, 30)
        try:
            t0 = time.monotonic()
            assert http("GET", live.base + "/api/health", timeout=5)[0] == 200  # under the cap: served
            assert time.monotonic() - t0 < 2.0
            extra = half_open(live.port, 20)  # past the cap: closed at once
            socks += extra
            assert sum(closed_by_server(s, 1.0) for s in extra[-5:]) == 5
            # every half-open connection is closed once its head is overdue
            deadline = time.monotonic() + 10
            assert all(closed_by_server(s, max(0.1, deadline - time.monotonic())) for s in socks)
            assert http("GET", live.base + "/api/health", timeout=5)[0] == 200
        finally:
            for s in socks:
                s.close()


def test_one_address_cannot_take_every_connection(tmp_path):
    """From an address that is not a trusted proxy at most a quarter of the connections;
    the attacker here is 127.0.0.2, the student 127.0.0.1 (Linux answers on all of 127/8)."""
    with LiveServer(tmp_path, header_seconds=30.0, max_connections=40, forwarded_allow_ips="127.0.0.1") as live:
        socks = half_open(live.port, 30, source="127.0.0.2")
        try:
            assert sum(closed_by_server(s, 1.0) for s in socks[-5:]) == 5  # past 10 from one address
            t0 = time.monotonic()
            assert http("GET", live.base + "/api/health", timeout=5)[0] == 200
            assert time.monotonic() - t0 < 2.0
        finally:
            for s in socks:
                s.close()


def test_previews_are_bounded_and_health_answers(tmp_path):
    text = ("$$\\tau_1 = m_1 \\ddot{q}_1 + g$$\n\n" * 6000)[:199_000].encode()
    with LiveServer(tmp_path) as live:
        url = live.base + "/api/preview?exercise=rp-arm"

        def preview(_):
            import urllib.error
            import urllib.request

            req = urllib.request.Request(url, data=text, method="POST", headers=MD)
            try:
                with urllib.request.urlopen(req, timeout=60) as r:
                    return r.status, None
            except urllib.error.HTTPError as err:
                return err.code, err.headers.get("retry-after")

        with ThreadPoolExecutor(24) as ex:
            futures = [ex.submit(preview, i) for i in range(24)]
            time.sleep(0.5)
            t0 = time.monotonic()
            status, _ = http("GET", live.base + "/api/health", timeout=30)
            health_seconds = time.monotonic() - t0
            results = [f.result(timeout=120) for f in futures]
        assert status == 200 and health_seconds < 5.0, health_seconds  # the 1 s target: benchmarks/bench_serve.py
        busy = [r for r in results if r[0] == 503]
        assert busy and all(r[1] and int(r[1]) > 0 for r in busy), results
        assert {r[0] for r in results} <= {200, 503}


def raw_get(port: int, target: str, host: str) -> bytes:
    """The status line and headers of ``GET target`` sent as raw bytes (no client rewrites it)."""
    with socket.create_connection(("127.0.0.1", port), timeout=10) as s:
        s.sendall(f"GET {target} HTTP/1.1\r\nHost: {host}\r\nConnection: close\r\n\r\n".encode())
        data = b""
        while b"\r\n\r\n" not in data:
            chunk = s.recv(4096)
            if not chunk:
                break
            data += chunk
    return data.split(b"\r\n\r\n")[0].lower()


def test_a_preview_whose_client_left_is_not_made(tmp_path):
    with LiveServer(tmp_path) as live:
        pool = live.app.state.server.pool
        made, release = [], threading.Event()

        def preview(markdown, exercise):
            made.append(markdown)
            release.wait(20)  # the first one holds the preview worker
            return {"ok": True, "html": "<p>ok</p>"}

        pool.preview = preview
        url = live.base + "/api/preview"
        first = threading.Thread(target=lambda: http("POST", url, b"$$first = 1$$", MD, timeout=30))
        first.start()
        wait_until(lambda: made, 10, "the first preview started")
        body = b"$$second = 2$$"
        with socket.create_connection(("127.0.0.1", live.port), timeout=5) as s:
            s.sendall(
                b"POST /api/preview HTTP/1.1\r\nHost: x\r\nContent-Type: text/markdown\r\n"
                + f"Content-Length: {len(body)}\r\n\r\n".encode()
                + body
            )
            time.sleep(0.5)  # it waits behind the first, then its client leaves
        time.sleep(0.5)
        release.set()
        first.join(30)
        time.sleep(1.0)
        assert made == ["$$first = 1$$"], made


def test_trailing_slash_redirect_is_relative(tmp_path):
    with LiveServer(tmp_path) as live:
        head = raw_get(live.port, "/instructor/", "evil.example")
        assert head.startswith(b"http/1.1 307") and b"\r\nlocation: /instructor\r\n" in head + b"\r\n", head
        for target in ("//evil.example/", "/\\evil.example/", "///evil.example/x/"):
            head = raw_get(live.port, target, "evil.example")
            location = [line for line in head.split(b"\r\n") if line.startswith(b"location:")]
            for line in location:  # a redirect, if any, stays on this site
                value = line.split(b":", 1)[1].strip()
                assert value.startswith(b"/") and not value.startswith((b"//", b"/\\")), head
