"""The JSON API and the pages of ``armdyn serve`` through Starlette's TestClient, with
real grading workers, against SQLite and PostgreSQL.

Second opinions: the verdicts are compared with ``armdyn.grade`` run here, in this
process, on the same text, and with the hand-checked verdicts of the examples
(examples/grading/README.md: the exercise's first wrong step is v_dot_1, both torques
right; rp-arm-dalembert.md is right throughout).
"""

from __future__ import annotations

import json
import re
import time

import pytest

pytest.importorskip("starlette")
pytest.importorskip("sqlalchemy")
pytest.importorskip("httpx")

from serve_support import EXERCISE, RIGHT, db_url  # noqa: F401

from armdyn.grading import grade
from armdyn.grading.reader import read_markdown

TOKEN = "instructor-secret-for-tests"
MD = {"content-type": "text/markdown"}


def client_for(url: str, **kw):
    from starlette.testclient import TestClient

    from armdyn.serve.app import Settings, build_app
    from armdyn.serve.exercises import catalogue

    kw.setdefault("exercises", catalogue())
    settings = Settings(db=url, workers=1, instructor_token=TOKEN, **kw)
    return TestClient(build_app(settings))


def wait_ready(c, timeout=120.0):
    deadline = time.monotonic() + timeout
    while time.monotonic() < deadline:
        if c.get("/api/health").status_code == 200:
            return
        time.sleep(0.2)
    raise AssertionError("the grading workers did not start")


def live_markup(html: str) -> set:
    """The element names of ``html`` (parsed, not searched), plus "on*"/"javascript:" when an
    attribute would run script: what a browser would make live."""
    from html.parser import HTMLParser

    found = set()

    class P(HTMLParser):
        def handle_starttag(self, tag, attrs):
            found.add(tag)
            for k, v in attrs:
                if k.startswith("on") or "javascript:" in (v or "").lower():
                    found.add(f"{k}=javascript")

    P().feed(html)
    return found


def here(path) -> dict:
    """The verdict of armdyn.grade in this process (the second opinion)."""
    return json.loads(grade(read_markdown("submission.md", path.read_text(encoding="utf-8"))).to_json())


def test_grade_api_matches_armdyn_grade(db_url, tmp_path):  # noqa: F811
    text = EXERCISE.read_text(encoding="utf-8")
    with client_for(db_url) as c:
        wait_ready(c)
        r = c.post("/api/grade", content=text.encode(), headers=MD)
        assert r.status_code == 200, r.text
        got = r.json()
        assert got["status"] == "done" and got["graded_as"] == "rp-arm"
        assert got["first_wrong"] == "v_dot_1" and got["tau_correct"] == [True, True] and got["passed"] is False
        mine = here(EXERCISE)
        assert [(s["name"], s["status"]) for s in got["steps"]] == [(s["name"], s["status"]) for s in mine["steps"]]
        assert got["steps"] == mine["steps"]

        # the submission: only with its token
        assert c.get(f"/api/submissions/{got['id']}").status_code == 404
        assert c.get(f"/api/submissions/{got['id']}?t=wrong-token").status_code == 404
        again = c.get(f"/api/submissions/{got['id']}", headers={"authorization": f"Bearer {got['token']}"})
        assert again.status_code == 200 and again.json()["steps"] == mine["steps"]
        page = c.get(got["url"])
        assert page.status_code == 200 and "First wrong step" in page.text
        report = c.get(f"/submissions/{got['id']}/report.html?t={got['token']}")
        assert report.status_code == 200 and report.text.startswith("<!DOCTYPE html>")

        # the same text again: the stored verdict, marked cached, equal
        twin = c.post("/api/grade?robot=rp-arm", content=text.encode(), headers=MD).json()
        assert twin["first_wrong"] == "v_dot_1"
        right = c.post("/api/grade?robot=rp-arm", content=RIGHT.read_bytes(), headers=MD).json()
        assert right["passed"] is True and right["first_wrong"] is None == here(RIGHT)["first_wrong"]
        assert right["tau_correct"] == here(RIGHT)["tau_correct"] == [True, True]


def test_bad_input_is_a_verdict_not_a_crash(tmp_path):
    with client_for(f"sqlite:///{tmp_path / 'db.sqlite'}") as c:
        wait_ready(c)
        # a path in the front matter is not an exercise id: refused, nothing opened
        r = c.post("/api/grade", content=b"---\nrobot: ../../../etc/passwd\n---\n$$\\tau_1 = 0$$\n", headers=MD)
        body = r.json()
        assert r.status_code == 200 and body["status"] == "done" and "unknown exercise" in body["error"]
        assert c.post("/api/grade?robot=/etc/passwd", content=b"x", headers=MD).status_code == 400
        assert (
            c.post("/api/grade?robot=rp-arm", content=b"x", headers={"content-type": "application/json"}).status_code
            == 400
        )
        assert c.post("/api/grade?robot=rp-arm", content=b"\xff\xfe", headers=MD).status_code == 400
        no_step = c.post("/api/grade?robot=rp-arm", content=b"$$x = 1$$", headers=MD).json()
        assert no_step["status"] == "done" and "no step" in no_step["error"]
        big = c.post("/api/grade?robot=rp-arm", content=b"a" * 1_100_000, headers=MD)
        assert big.status_code == 413
        assert c.get("/api/submissions/nonexistent").status_code == 404


def test_headers_preview_and_openapi(tmp_path):
    with client_for(f"sqlite:///{tmp_path / 'db.sqlite'}") as c:
        wait_ready(c)
        page = c.get("/")
        csp = page.headers["content-security-policy"]
        assert "script-src 'self'" in csp and "unsafe-inline" not in csp.split("script-src")[1].split(";")[0]
        assert page.headers["referrer-policy"] == "no-referrer"
        assert "<script" not in page.text.replace('<script src="/static/app.js" defer></script>', "")
        # the preview: MathML for each equation, the step it names, nothing executable
        hostile = (
            "$$\\dot{v}_1^1 = \\begin{pmatrix} g \\\\ 0 \\\\ 0 \\end{pmatrix}$$\n"
            "$$\\tau_1 = \\text{<script>alert(1)</script>} + \\href{javascript:alert(2)}{x}$$\n"
            "<img src=x onerror=alert(3)>\n"
        )
        r = c.post("/api/preview?exercise=rp-arm", content=hostile.encode(), headers=MD)
        assert r.status_code == 200
        html = r.json()["html"]
        assert "<math" in html and "v_dot_1" in html and "tau_1" in html
        tags = live_markup(html)
        assert not tags & {"script", "img", "iframe", "a"} and not any("=" in t for t in tags), tags
        assert "&lt;script&gt;" in html  # the student's markup shown as text
        spec = c.get("/openapi.json").json()
        assert spec["openapi"].startswith("3.") and {"/api/grade", "/api/submissions/{sid}", "/api/health"} <= set(
            spec["paths"]
        )


def test_forms_need_csrf_and_instructor_token(tmp_path):
    text = EXERCISE.read_text(encoding="utf-8")
    with client_for(f"sqlite:///{tmp_path / 'db.sqlite'}") as c:
        wait_ready(c)
        page = c.get("/")
        csrf = re.search(r'name="csrf" value="([^"]+)"', page.text).group(1)
        assert c.post("/grade", data={"markdown": text, "csrf": "forged"}).status_code == 403
        r = c.post(
            "/grade",
            data={"markdown": text, "csrf": csrf, "exercise": "rp-arm", "student": "Ada"},
            follow_redirects=False,
        )
        assert r.status_code == 303 and "/submissions/" in r.headers["location"]
        mine = c.get("/")
        assert "Your earlier submissions" in mine.text and "v_dot_1" in mine.text
        # another browser (no cookie, no token) sees nothing of it
        sid = r.headers["location"].split("/submissions/")[1].split("?")[0]
        from starlette.testclient import TestClient

        stranger = TestClient(c.app)
        assert stranger.get(f"/submissions/{sid}").status_code == 404
        # instructor: wrong token refused, right one logs in; gradebook lists Ada
        assert c.get("/instructor/gradebook.csv", follow_redirects=False).status_code == 303
        assert c.post("/instructor/login", data={"token": "nope", "csrf": csrf}).status_code == 403
        assert c.post("/instructor/login", data={"token": TOKEN, "csrf": "forged"}).status_code == 403
        ok = c.post("/instructor/login", data={"token": TOKEN, "csrf": csrf}, follow_redirects=False)
        assert ok.status_code == 303
        table = c.get("/instructor")
        assert "Ada" in table.text and "v_dot_1" in table.text
        csv = c.get("/instructor/gradebook.csv")
        assert csv.status_code == 200 and csv.headers["content-type"].startswith("text/csv")
        lines = csv.text.strip().splitlines()
        head = lines[0].split(",")
        row = dict(zip(head, lines[1].split(",")))
        assert row["student"] == "Ada" and row["first_wrong"] == "v_dot_1"
        assert c.get("/instructor/summary").status_code == 200


def test_variants_by_id_from_exercise_make(tmp_path):
    from armdyn.cli import main
    from armdyn.serve.exercises import catalogue

    out = tmp_path / "variants"
    assert main(["exercise", "make", "rp", "--count", "2", "--seed", "7", "--out", str(out)]) == 0
    exercises = catalogue(str(out))
    assert {"v001", "v002", "rp-arm"} <= set(exercises)
    solution = (out / "v001" / "solution.md").read_bytes()
    with client_for(f"sqlite:///{tmp_path / 'db.sqlite'}", exercises=exercises) as c:
        wait_ready(c)
        assert "variant v001" in c.get("/").text
        own = c.post("/api/grade", content=solution, headers=MD).json()  # front matter: variant v001
        assert own["graded_as"] == "v001" and own["passed"] is True, own
        other = c.post("/api/grade?variant=v002", content=solution, headers=MD).json()
        assert other["graded_as"] == "v002" and other["passed"] is False and other["first_wrong"]
        # a variant is an id, not a path
        assert c.post(f"/api/grade?variant={out / 'v001'}", content=solution, headers=MD).status_code == 400
