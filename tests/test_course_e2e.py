"""A course from roster to gradebook, end to end, small: five students with their own
variants and personal links hand in to a real ``armdyn serve`` process around a
deadline; then a class regraded after its rubric changed.

Second opinions: a variant's worked solution is right in every step by construction
(tests/test_course.py checks it against armdyn's derivation), so under the kind's rubric
it earns every point, counted by hand: an RP arm has 21 Newton-Euler steps (the base's
3, then 6 per link and 3 per link back) and 11 Lagrange steps (T, V, L, then 4 per
coordinate), every step 1 point but each of the 4 torques 2: 23 + 13 = 36. The late
marks follow the clock of this test (submitted before or after the deadline it gave).
The queue position is checked against the statuses of the submissions ahead, read at
the same moment.
"""

from __future__ import annotations

import csv
import http.cookiejar
import io
import json
import time
import urllib.request
from datetime import datetime, timezone

import numpy as np
import pytest

pytest.importorskip("starlette")
pytest.importorskip("sqlalchemy")

from serve_support import start_server

TOKEN = "instructor-secret-for-tests"
IDS = ["s1", "s2", "s3", "s4", "s5"]


def make_course(root, ids, seed=11):
    from armdyn.cli import main

    (root / "roster.csv").write_text("id,name\n" + "".join(f"{i},Student {i}\n" for i in ids), encoding="utf-8")
    assert (
        main(
            [
                "exercise",
                "make",
                "rp",
                "--roster",
                str(root / "roster.csv"),
                "--seed",
                str(seed),
                "--out",
                str(root / "v"),
            ]
        )
        == 0
    )


def slipped(root, sid: str, seed: int) -> str:
    """The variant's worked solution with one slip injected (a different text, one wrong step at least)."""
    from armdyn.course.solution import inject_slip, solution_markdown, solution_steps
    from armdyn.io.yaml import load_yaml_string

    robot = load_yaml_string((root / "v" / sid / "model.yaml").read_text(encoding="utf-8"), "model.yaml")
    steps, _ = inject_slip(solution_steps(robot), np.random.default_rng(seed), robot.q)
    front = {"robot": "model.yaml", "method": "both", "student": sid, "variant": sid}
    return solution_markdown(robot, steps, front, f"Exercise {sid}")


class Browser:
    """A student's browser: cookies kept between requests."""

    def __init__(self, base: str):
        self.base = base
        self.opener = urllib.request.build_opener(urllib.request.HTTPCookieProcessor(http.cookiejar.CookieJar()))

    def get(self, path: str) -> str:
        with self.opener.open(path if path.startswith("http") else self.base + path, timeout=60) as r:
            return r.read().decode()

    def submit(self, text: str) -> dict:
        req = urllib.request.Request(
            self.base + "/api/grade?wait=0",
            data=text.encode(),
            method="POST",
            headers={"content-type": "text/markdown"},
        )
        with self.opener.open(req, timeout=60) as r:
            return json.loads(r.read())

    def state(self, sid: str) -> dict:
        return json.loads(self.get(f"/api/submissions/{sid}"))


def test_five_students_around_a_deadline(tmp_path):
    from armdyn.grading import grade
    from armdyn.grading.reader import read_markdown
    from armdyn.serve.exercises import catalogue
    from armdyn.serve.identity import make_links

    make_course(tmp_path, IDS)
    db = f"sqlite:///{tmp_path}/course.db"
    deadline = int(time.time()) + 40  # the first three hand in before it, the last two after
    when = datetime.fromtimestamp(deadline, timezone.utc).isoformat()
    server = start_server(
        tmp_path,
        db,
        workers=1,
        token=TOKEN,
        extra=["--roster", str(tmp_path / "roster.csv"), "--exercises", str(tmp_path / "v"), "--deadline", when],
    )
    try:
        text = make_links(str(tmp_path / "roster.csv"), db, server.base, catalogue(str(tmp_path / "v")))
        link = {r["id"]: r["link"] for r in csv.DictReader(io.StringIO(text))}
        texts = {
            sid: slipped(tmp_path, sid, k) if k % 2 else (tmp_path / "v" / sid / "solution.md").read_text()
            for k, sid in enumerate(IDS)
        }
        browsers = {sid: Browser(server.base) for sid in IDS}
        for sid, b in browsers.items():
            assert f'id="my-exercise">{sid}<' in b.get(link[sid])  # the link opens /me on their own variant

        sent = {sid: browsers[sid].submit(texts[sid]) for sid in IDS[:3]}  # at once: one worker, a queue
        assert time.time() < deadline, "the server took too long to start for this test's deadline"
        third = sent["s3"]["id"]
        page = browsers["s3"].get(f"/submissions/{third}")
        seen = []
        for _ in range(200):  # the position against the statuses ahead, read in one consistent moment
            ahead = [browsers[s].state(sent[s]["id"])["status"] for s in ("s1", "s2")]
            mine = browsers["s3"].state(third)
            again = [browsers[s].state(sent[s]["id"])["status"] for s in ("s1", "s2")]
            if mine["status"] != "queued":
                break
            if ahead == again:
                assert mine["position"] == 1 + ahead.count("queued"), (ahead, mine)
                seen.append(mine["position"])
            time.sleep(0.1)
        assert seen and seen == sorted(seen, reverse=True)  # it only moves forward
        if browsers["s3"].state(third)["status"] == "queued" or seen[0] > 1:
            assert 'aria-live="polite"' in page and "Waiting in the queue: number" in page

        time.sleep(max(0.0, deadline + 1 - time.time()))
        sent.update({sid: browsers[sid].submit(texts[sid]) for sid in IDS[3:]})
        done = {}
        for sid in IDS:
            for _ in range(600):
                body = browsers[sid].state(sent[sid]["id"])
                if body["status"] in ("done", "failed"):
                    break
                assert "position" not in body or body["status"] == "queued"
                time.sleep(0.5)
            done[sid] = body
        for k, sid in enumerate(IDS):
            b = done[sid]
            assert b["status"] == "done" and b["late"] is (k >= 3), (sid, b["late"])
            mine = json.loads(
                grade(read_markdown(f"{sid}.md", texts[sid]), robot=str(tmp_path / "v" / sid / "model.yaml")).to_json()
            )
            assert [(s["name"], s["status"]) for s in b["steps"]] == [(s["name"], s["status"]) for s in mine["steps"]]
            assert (b["first_wrong"] is None) is (k % 2 == 0)  # the slipped ones have a wrong step
        req = urllib.request.Request(
            server.base + "/instructor/gradebook.csv", headers={"authorization": f"Bearer {TOKEN}"}
        )
        with urllib.request.urlopen(req, timeout=60) as r:
            book = r.read().decode()
        header = book.splitlines()[0].split(",")
        assert len(header) == len(set(header)), header  # each column once
        rows = {row["student"]: row for row in csv.DictReader(io.StringIO(book))}
        assert sorted(rows) == IDS
        for k, sid in enumerate(IDS):
            assert rows[sid]["late"] == ("yes" if k >= 3 else "no")
            assert float(rows[sid]["max"]) == 36
            assert (float(rows[sid]["total"]) == 36) is (k % 2 == 0)

        from armdyn.serve.handedin import write_handed_in

        written = write_handed_in(db, str(tmp_path / "handed-in"))  # for armdyn grade DIR --regrade
        assert [p.rsplit("/", 1)[1] for p in written] == [f"{sid}.md" for sid in IDS]
        for sid in IDS:
            assert (tmp_path / "handed-in" / f"{sid}.md").read_text(encoding="utf-8") == texts[sid]
    finally:
        server.stop()


def grade_dir(tmp_path, *extra):
    from armdyn.cli import main

    args = ["grade", str(tmp_path / "subs"), "--variants", str(tmp_path / "v"), "--jobs", "1"]
    return main([*args, "--gradebook", str(tmp_path / "out" / "grades.csv"), *extra])


def test_regrade_after_the_rubric_changed(tmp_path, capsys):
    make_course(tmp_path, ["ada", "alan"], seed=5)
    (tmp_path / "subs").mkdir()
    full = (tmp_path / "v" / "ada" / "solution.md").read_text()
    (tmp_path / "subs" / "ada.md").write_text(full)
    alan = (tmp_path / "v" / "alan" / "solution.md").read_text()
    (tmp_path / "subs" / "alan.md").write_text(alan.split("## Lagrange")[0])  # Newton-Euler only

    assert grade_dir(tmp_path, "--regrade") == 2  # nothing to compare with yet
    assert "grades.json" in capsys.readouterr().err
    assert grade_dir(tmp_path) == 0
    rows = {r["student"]: r for r in csv.DictReader((tmp_path / "out" / "grades.csv").open())}
    assert (float(rows["ada"]["total"]), float(rows["ada"]["max"])) == (36, 36)
    assert (float(rows["alan"]["total"]), float(rows["alan"]["max"])) == (23, 36)  # 11 Lagrange steps: 0 of 13
    capsys.readouterr()

    assert grade_dir(tmp_path, "--regrade") == 0  # nothing changed
    assert "regrade: 0 of 2 students changed" in capsys.readouterr().out

    rubric = tmp_path / "v" / "rubric-rp.yaml"
    rubric.write_text(rubric.read_text().replace("  tau: 2", "  tau: 3"))
    assert grade_dir(tmp_path, "--regrade") == 0
    out = capsys.readouterr().out
    assert "regrade: 2 of 2 students changed" in out
    assert "  ada: 36/36 -> 40/40\n" in out and "  alan: 23/36 -> 25/40\n" in out
    for part in ("newton-euler", "lagrange"):
        for tau in ("tau_1", "tau_2"):
            assert f"    {tau} ({part}): correct 2/2 -> correct 3/3" in out.split("  alan:")[0]
            if part == "newton-euler":
                assert f"    {tau} ({part}): correct 2/2 -> correct 3/3" in out.split("  alan:")[1]
            else:
                assert f"    {tau} ({part}): missing 0/2 -> missing 0/3" in out.split("  alan:")[1]
    assert out.count("->") == 2 + 8  # two students, four torques each: no other step changed
    changed = list(csv.DictReader((tmp_path / "out" / "regrade.csv").open()))
    assert [(r["student"], r["old_total"], r["new_total"], r["new_max"]) for r in changed] == [
        ("ada", "36.0", "40.0", "40.0"),
        ("alan", "23.0", "25.0", "40.0"),
    ]
    assert changed[1]["steps_changed"].count(";") == 3


def test_course_pages_as_a_class_sees_them(tmp_path):
    """The pages of a roster course in headless Chromium: a student's /me (their own
    variant, a late mark after their deadline), their statement and report; the
    instructor's class and summary. With ``ARMDYN_SERVE_SCREENSHOTS=DIR`` the
    screenshots go to DIR (docs/img is made this way)."""
    from browser import require_chromium
    from test_serve_pages import login, shoot, viewport

    from armdyn.serve.exercises import catalogue
    from armdyn.serve.identity import make_links

    chromium = require_chromium()
    pytest.importorskip("websocket")
    import test_serve_pages
    from cdp import Browser as Chromium

    test_serve_pages.TOKEN = TOKEN  # its login() types this token
    make_course(tmp_path, ["ada", "alan"], seed=5)
    roster = tmp_path / "roster.csv"  # alan's own deadline has passed: his submission is late
    roster.write_text("id,name,deadline\nada,Ada L.,\nalan,Alan T.,2026-01-05T12:00Z\n", encoding="utf-8")
    db = f"sqlite:///{tmp_path}/course.db"
    extra = ["--roster", str(roster), "--exercises", str(tmp_path / "v"), "--deadline", "2100-01-01T12:00Z"]
    server = start_server(tmp_path, db, workers=1, token=TOKEN, extra=extra)
    browser = Chromium(chromium)
    try:
        text = make_links(str(roster), db, server.base, catalogue(str(tmp_path / "v")))
        link = {r["id"]: r["link"] for r in csv.DictReader(io.StringIO(text))}
        alan = Browser(server.base)
        alan.get(link["alan"])
        late = alan.submit((tmp_path / "v" / "alan" / "solution.md").read_text())
        assert late["late"] is True

        page = browser.page()
        viewport(page, 1280, 900)
        page.b.call("Page.navigate", {"url": link["ada"]}, page.session)  # redirected to /me
        page.wait_for("location.pathname === '/me' && document.readyState === 'complete'", 60, "/me")
        page.eval(
            "(function () { var t = document.getElementById('markdown'); t.focus(); t.value = "
            + json.dumps(slipped(tmp_path, "ada", 3))
            + "; t.dispatchEvent(new Event('input')); return true; })()"
        )
        page.wait_for("document.querySelectorAll('#preview math').length > 10", 60, "the preview")
        shoot(page, "course-me-editor.png", tmp_path, full=False)
        page.eval("document.getElementById('grade-button').click(); true")
        page.wait_for("!!document.querySelector('.report .step.first')", 120, "the report")
        shoot(page, "course-report.png", tmp_path, full=False)
        page.goto(server.base + "/me")
        mine = page.eval("document.getElementById('mine').textContent")
        assert "first wrong" in mine and "late" not in mine  # ada's deadline is the course's, far ahead
        shoot(page, "course-me.png", tmp_path)
        page.goto(server.base + "/me/statement")
        assert "ada" in page.eval("document.body.textContent")
        shoot(page, "course-statement.png", tmp_path, full=False)

        login(page, server)
        assert page.eval("document.body.textContent.includes('Alan T.')")
        viewport(page, 1280, 420)
        shoot(page, "course-class.png", tmp_path, full=False)
        page.goto(server.base + "/instructor/summary")
        shoot(page, "course-summary.png", tmp_path)
    finally:
        browser.close()
        server.stop()


def test_the_served_gradebook_scores_each_kind_by_its_rubric(tmp_path):
    """A mixed class (an RP arm and an RR arm: different kinds, each with the rubric ``exercise
    make`` wrote for it) scored by the server's gradebook exactly as ``armdyn grade DIR
    --variants`` scores the same files: the batch is the independent second opinion."""
    import csv
    import json

    import armdyn
    from armdyn.cli import main
    from armdyn.serve.exercises import catalogue
    from armdyn.serve.grades import gradebook

    for kind, sid in (("rp", "ada"), ("rr", "bob")):
        roster = tmp_path / f"{kind}.csv"
        roster.write_text(f"id,name\n{sid},{sid}\n", encoding="utf-8")
        args = ["exercise", "make", kind, "--roster", str(roster), "--seed", "5", "--out", str(tmp_path / "v")]
        assert main(args) == 0
    subs = tmp_path / "subs"
    subs.mkdir()
    rows = []
    for k, sid in enumerate(("ada", "bob")):
        text = (tmp_path / "v" / sid / "solution.md").read_text(encoding="utf-8")
        (subs / f"{sid}.md").write_text(text, encoding="utf-8")
        report = armdyn.grade(str(subs / f"{sid}.md"), robot=str(tmp_path / "v" / sid / "model.yaml"))
        rows.append(
            {
                "id": f"s{k}",
                "student_id": sid,
                "graded_as": sid,
                "exercise": sid,
                "status": "done",
                "report_json": json.dumps(json.loads(report.to_json())),
                "created_at": 1000.0 + k,
                "late": False,
            }
        )
    served = {
        r["student"]: (float(r["total"]), float(r["max"]))
        for r in gradebook(rows, exercises=catalogue(str(tmp_path / "v"))).rows
    }
    assert grade_dir(tmp_path) in (0, 1)
    with open(tmp_path / "out" / "grades.csv", newline="", encoding="utf-8") as fh:
        batch = {r["student"]: (float(r["total"]), float(r["max"])) for r in csv.DictReader(fh)}
    assert served == batch
    assert served["ada"][1] != served["bob"][1]  # two kinds, two rubrics
    assert all(total == most for total, most in served.values())  # the worked solutions: full marks
