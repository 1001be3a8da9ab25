"""Shared by tests/test_serve_*.py: the databases to test against, a real server.

``db_url`` (a fixture, parametrized): a fresh SQLite file, and a fresh PostgreSQL
database when ``ARMDYN_TEST_POSTGRES_URL`` names one (.ci/run starts one from Debian's
packages; without it the PostgreSQL case skips alone, and under
ARMDYN_REQUIRE_OPTIONAL=1 that skip is a failure). "Fresh" on PostgreSQL: the
server's tables are dropped first (the tests run one at a time).

:func:`start_server` runs ``python -m armdyn serve`` on a free port of 127.0.0.1 and
waits until ``/api/health`` says ready.
"""

from __future__ import annotations

import json
import os
import signal
import socket
import subprocess
import sys
import time
import urllib.error
import urllib.request
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]
EXAMPLES = ROOT / "examples" / "grading"
EXERCISE = EXAMPLES / "rp-arm-exercise.md"  # hand-checked: first wrong v_dot_1, both torques right
RIGHT = EXAMPLES / "rp-arm-dalembert.md"  # hand-checked: every step right
PG_ENV = "ARMDYN_TEST_POSTGRES_URL"


def _drop_postgres_tables(url: str) -> None:
    import sqlalchemy as sa

    from armdyn.serve.storage import _engine

    engine = _engine(url)
    with engine.begin() as conn:
        conn.execute(
            sa.text(
                "DROP TABLE IF EXISTS submissions, armdyn_schema, student_links, student_sessions, "
                "lti_states, lti_nonces, lti_users, lti_lineitems"
            )
        )
    engine.dispose()


@pytest.fixture(params=["sqlite", "postgresql"])
def db_url(request, tmp_path):
    if request.param == "sqlite":
        return f"sqlite:///{tmp_path / 'serve.db'}"
    url = os.environ.get(PG_ENV)
    if not url:
        pytest.skip(f"{PG_ENV} is not set (.ci/run starts a PostgreSQL from Debian's packages)")
    pytest.importorskip("psycopg")
    url = _worker_schema(url)
    _drop_postgres_tables(url)
    return url


def _worker_schema(url: str) -> str:
    """``url`` with its own schema for this pytest-xdist worker (``gw0``, ``gw1``, ...; ``main``
    without xdist): test files on different workers run at the same time against the one
    test database, and each test starts by dropping the tables."""
    import sqlalchemy as sa

    from armdyn.serve.storage import _engine

    schema = os.environ.get("PYTEST_XDIST_WORKER", "main")
    assert schema.isidentifier(), schema
    engine = _engine(url)
    with engine.begin() as conn:
        conn.execute(sa.text(f"CREATE SCHEMA IF NOT EXISTS {schema}"))
    engine.dispose()
    return f"{url}{'&' if '?' in url else '?'}options=-csearch_path%3D{schema}"


def free_port() -> int:
    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        return s.getsockname()[1]


def http(method: str, url: str, body: bytes | None = None, headers: dict | None = None, timeout: float = 60.0):
    """(status, parsed JSON or text) of one request (urllib: no client library needed)."""
    req = urllib.request.Request(url, data=body, method=method, headers=headers or {})
    try:
        with urllib.request.urlopen(req, timeout=timeout) as r:
            status, raw, kind = r.status, r.read(), r.headers.get("content-type", "")
    except urllib.error.HTTPError as err:
        status, raw, kind = err.code, err.read(), err.headers.get("content-type", "")
    text = raw.decode("utf-8", "replace")
    return status, (json.loads(text) if kind.startswith("application/json") else text)


class Server:
    def __init__(self, proc: subprocess.Popen, port: int, log: Path):
        self.proc, self.port, self.log = proc, port, log
        self.base = f"http://127.0.0.1:{port}"

    def stop(self, sig=signal.SIGTERM, timeout: float = 40.0) -> int:
        if self.proc.poll() is None:
            self.proc.send_signal(sig)
        try:
            return self.proc.wait(timeout)
        except subprocess.TimeoutExpired:
            self.proc.kill()
            self.proc.wait()
            raise AssertionError(f"the server did not stop within {timeout} s of {sig!r}") from None


def start_server(
    tmp_path: Path, db: str, workers: int = 1, token: str | None = None, extra=(), timeout: float = 120.0
) -> Server:
    port = free_port()
    log = tmp_path / f"server-{port}.log"
    env = dict(os.environ, PYTHONPATH=str(ROOT / "python"))
    cmd = [sys.executable, "-m", "armdyn", "serve", "--port", str(port), "--db", db, "--workers", str(workers), *extra]
    if token:
        cmd += ["--instructor-token", token]
    proc = subprocess.Popen(cmd, stdout=log.open("w"), stderr=subprocess.STDOUT, env=env)
    server = Server(proc, port, log)
    deadline = time.monotonic() + timeout
    while time.monotonic() < deadline:
        if proc.poll() is not None:
            raise AssertionError(f"the server exited ({proc.returncode}):\n{log.read_text()[-3000:]}")
        try:
            status, _ = http("GET", server.base + "/api/health", timeout=5)
            if status == 200:
                return server
        except OSError:
            pass
        time.sleep(0.3)
    server.stop(signal.SIGKILL)
    raise AssertionError(f"the server was not ready within {timeout} s:\n{log.read_text()[-3000:]}")
