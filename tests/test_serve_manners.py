"""What ``armdyn serve`` says, as a person running it in a terminal sees it: a real
server process (``python -m armdyn serve``), its stderr read here.

- a ready line with the URL once it serves (``--port 0``: the port it was given);
- one access-log line per request: method, path, status, time; never a link token,
  a name, a cookie or an Authorization header;
- Ctrl-C (SIGINT to the whole process group, as a terminal sends it): no traceback
  from the server or its grading workers, exit 0, the workers gone;
- a busy port: one clear sentence, exit 2, no traceback, before any worker starts;
- the OpenAPI document has every route of the app with the same path parameters and
  methods (read from Starlette's route table here, not from the document's maker).
"""

from __future__ import annotations

import os
import re
import signal
import socket
import subprocess
import sys
import time
import urllib.request

import pytest
from serve_support import ROOT, http

pytest.importorskip("starlette")
pytest.importorskip("uvicorn")

READY = re.compile(r"^armdyn serve: listening on (http://127\.0\.0\.1:(\d+)/)$", re.M)
TOKEN = "manners-instructor-token-xyz"


def serve(tmp_path, *args, name="serve") -> tuple[subprocess.Popen, object]:
    """``python -m armdyn serve`` in a session of its own (a terminal's process group),
    stderr to a file (returned open for reading)."""
    err = tmp_path / f"{name}.stderr"
    env = dict(os.environ, PYTHONPATH=str(ROOT / "python"))
    cmd = [sys.executable, "-m", "armdyn", "serve", "--db", f"sqlite:///{tmp_path / (name + '.db')}", *args]
    proc = subprocess.Popen(
        cmd, stdout=subprocess.DEVNULL, stderr=err.open("w"), env=env, start_new_session=True, cwd=tmp_path
    )
    return proc, err


def wait_ready(proc, err, timeout=120.0) -> str:
    deadline = time.monotonic() + timeout
    while time.monotonic() < deadline:
        m = READY.search(err.read_text())
        if m:
            return m.group(1)
        if proc.poll() is not None:
            raise AssertionError(f"the server exited ({proc.returncode}):\n{err.read_text()[-3000:]}")
        time.sleep(0.2)
    os.killpg(proc.pid, signal.SIGKILL)
    raise AssertionError(f"no ready line within {timeout} s:\n{err.read_text()[-3000:]}")


def alive(pid: int) -> bool:
    try:
        os.kill(pid, 0)
    except ProcessLookupError:
        return False
    # a zombie is dead for our purpose
    try:
        with open(f"/proc/{pid}/stat") as f:
            return f.read().split(")")[-1].split()[0] != "Z"
    except OSError:
        return False


@pytest.fixture
def running(tmp_path):
    proc, err = serve(tmp_path, "--port", "0", "--workers", "2", "--instructor-token", TOKEN)
    try:
        url = wait_ready(proc, err)
        yield proc, err, url
    finally:
        if proc.poll() is None:
            os.killpg(proc.pid, signal.SIGKILL)
            proc.wait()


def test_ready_line_access_log_and_clean_ctrl_c(running):
    proc, err, url = running
    # the ready line comes once the app answers: the URL it names serves the page at once
    with urllib.request.urlopen(url, timeout=30) as r:
        assert r.status == 200 and b"Grade your derivation" in r.read()
    deadline = time.monotonic() + 120
    while "armdyn serve: 2 grading worker(s) ready" not in err.read_text() and time.monotonic() < deadline:
        time.sleep(0.2)
    status, health = http("GET", url + "api/health", headers={"authorization": f"Bearer {TOKEN}"})
    assert status == 200 and len(health["worker_pids"]) == 2, health
    secret = "SeCrEtLinkToken1234567890abcdef"
    http("GET", f"{url}submissions/abcdef?t={secret}&exercise=rp-arm&student=Ada%20Lovelace")
    http(
        "POST",
        url + "api/preview?exercise=rp-arm",
        b"$$\\tau_1 = 0$$",
        {"content-type": "text/markdown", "cookie": "armdyn_student=COOKIEVALUE123", "authorization": "Bearer AUTHX"},
    )
    http("GET", url + "no/such/page")
    time.sleep(0.5)
    log = err.read_text()
    lines = [line for line in log.splitlines() if line.startswith("armdyn serve: 127.0.0.1 ")]
    by_path = {line.split()[4].split("?")[0]: line for line in lines}
    assert re.fullmatch(r"armdyn serve: 127\.0\.0\.1 GET / 200 \d+ ms", by_path["/"]), by_path
    assert re.fullmatch(
        r"armdyn serve: 127\.0\.0\.1 GET /submissions/abcdef\?t=\*&exercise=rp-arm&student=\* 404 \d+ ms",
        by_path["/submissions/abcdef"],
    ), by_path
    assert " POST /api/preview?exercise=rp-arm 200 " in by_path["/api/preview"]
    assert " GET /no/such/page 404 " in by_path["/no/such/page"]
    for leak in (secret, "Lovelace", "COOKIEVALUE", "AUTHX", TOKEN):
        assert leak not in log, leak

    os.killpg(proc.pid, signal.SIGINT)  # Ctrl-C in the terminal: the server and its workers
    code = proc.wait(60)
    log = err.read_text()
    assert code == 0, log[-3000:]
    assert "Traceback" not in log and "KeyboardInterrupt" not in log, log[-3000:]
    assert log.rstrip().endswith("armdyn serve: stopped"), log[-500:]
    time.sleep(0.5)
    assert not [p for p in health["worker_pids"] if alive(p)]


def test_busy_port_is_one_sentence_and_exit_2(tmp_path):
    with socket.socket() as taken:
        taken.bind(("127.0.0.1", 0))
        taken.listen(1)
        port = taken.getsockname()[1]
        started = time.monotonic()
        proc, err = serve(tmp_path, "--port", str(port), "--workers", "1")
        try:
            code = proc.wait(60)
        finally:
            if proc.poll() is None:
                os.killpg(proc.pid, signal.SIGKILL)
        took = time.monotonic() - started
    said = err.read_text()
    assert code == 2, said
    assert f"port {port} on 127.0.0.1 is already in use" in said and "--port" in said, said
    assert "Traceback" not in said and "Errno" not in said, said
    assert took < 30, f"the busy port was found only after {took:.0f} s (after starting workers?)"


def test_openapi_lists_every_route_with_its_parameters(tmp_path):
    from starlette.routing import Mount, Route
    from starlette.testclient import TestClient

    from armdyn.serve.app import Settings, build_app
    from armdyn.serve.exercises import catalogue

    app = build_app(Settings(db=f"sqlite:///{tmp_path / 'o.db'}", exercises=catalogue(), workers=1))
    spec = TestClient(app).get("/openapi.json").json()  # no lifespan: workers not started
    paths = spec["paths"]
    routes = [r for r in app.routes if isinstance(r, (Route, Mount))]
    assert len(routes) >= 15
    documented = set()
    for r in routes:
        if isinstance(r, Mount):
            path, methods, names = r.path + "/{path}", {"get"}, {"path"}
        else:
            path, methods, names = r.path, {m.lower() for m in r.methods} - {"head"}, set(r.param_convertors)
        assert path in paths, f"{path} is not in /openapi.json"
        assert set(paths[path]) == methods, (path, set(paths[path]), methods)
        for method, op in paths[path].items():
            in_path = {p["name"] for p in op["parameters"] if p["in"] == "path"}
            assert in_path == names, (path, method, in_path, names)
            assert all(p["required"] for p in op["parameters"] if p["in"] == "path")
            assert op.get("summary") and op.get("responses"), (path, method)
        documented.add(path)
    assert set(paths) == documented  # nothing documented that is not a route
    ids = [op["operationId"] for ops in paths.values() for op in ops.values()]
    assert len(ids) == len(set(ids)) and all(re.fullmatch(r"\w+", i) for i in ids), ids
    assert "/api/submissions/{sid}" in paths and "{id}" not in str(paths)
    assert paths["/api/grade"]["post"]["requestBody"]["content"]["text/markdown"]


def test_access_log_redaction_alone():
    from armdyn.serve.accesslog import redacted_target

    assert redacted_target("/a", b"") == "/a"
    assert redacted_target("/link/GudeB8fVKN37FL0_sdbtp6vQnvSe", b"") == "/link/*"  # a student's key
    assert redacted_target("/a", b"t=xyz&wait=5&robot=rp-arm") == "/a?t=*&wait=5&robot=rp-arm"
    assert redacted_target("/a", "student=Bob&token=abc") == "/a?student=*&token=*"
    assert redacted_target("/a b\n", b"") == "/a%20b%0A"  # a line of the log stays one line
