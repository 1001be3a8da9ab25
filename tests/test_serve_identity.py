"""Students known by a roster and a secret personal link: their own variant, statement
and submissions only; deadlines; the gradebook's policy. Real grading workers,
SQLite and PostgreSQL.

Second opinions: a variant's worked solution is right in every step by construction
(tests/test_course.py checks it against armdyn's derivation), so it earns every point;
the same solution with the sign of the centripetal force in tau_2 flipped
(``-d m thetadot^2`` becomes ``+d m thetadot^2``: the slide is pulled outward, not in)
is wrong there and earns less. Which student may see what is the promise of
docs/serve.md, checked request by request.
"""

from __future__ import annotations

import calendar
import csv
import html
import io
import logging
import re
import time

import pytest

pytest.importorskip("starlette")
pytest.importorskip("sqlalchemy")
pytest.importorskip("httpx")

from serve_support import db_url  # noqa: F401

from armdyn.errors import ModelError

TOKEN = "instructor-secret-for-tests"
MD = {"content-type": "text/markdown"}
ROSTER = (
    "id,name,email,deadline\n"
    "ada,Ada L.,ada@example.edu,\n"
    "bob,Bob K.,Bob@Example.edu,2020-01-01T00:00Z\n"  # an extension that ended long ago: bob is late
)


@pytest.fixture(scope="module")
def course(tmp_path_factory):
    """The roster and one variant per student (``armdyn exercise make --roster``)."""
    from armdyn.cli import main

    root = tmp_path_factory.mktemp("course")
    (root / "roster.csv").write_text(ROSTER, encoding="utf-8")
    assert (
        main(["exercise", "make", "rp", "--roster", str(root / "roster.csv"), "--seed", "7", "--out", str(root / "v")])
        == 0
    )
    return root


def settings_for(course, db, **kw):
    from armdyn.serve.app import Settings
    from armdyn.serve.exercises import catalogue
    from armdyn.serve.identity import load_roster, parse_deadlines

    exercises = catalogue(str(course / "v"))
    kw.setdefault("deadlines", parse_deadlines(["2100-01-01T00:00Z"]))  # far ahead: ada is on time
    return Settings(
        db=db,
        workers=1,
        instructor_token=TOKEN,
        exercises=exercises,
        roster=load_roster(str(course / "roster.csv"), exercises),
        **kw,
    )


def links(course, db) -> dict:
    from armdyn.serve.exercises import catalogue
    from armdyn.serve.identity import make_links

    text = make_links(str(course / "roster.csv"), db, "https://armdyn.test", catalogue(str(course / "v")))
    return {r["id"]: r["link"] for r in csv.DictReader(io.StringIO(text))}


def wait_ready(c, timeout=120.0):
    deadline = time.monotonic() + timeout
    while c.get("/api/health").status_code != 200:
        assert time.monotonic() < deadline, "the grading workers did not start"
        time.sleep(0.2)


def log_in(c, link: str):
    r = c.get(link.replace("https://armdyn.test", ""), follow_redirects=False)
    assert r.status_code == 303 and r.headers["location"] == "/me"  # the token leaves the address bar
    assert "armdyn_me" in r.headers["set-cookie"] and "httponly" in r.headers["set-cookie"].lower()
    return r


def csrf_of(page: str) -> str:
    return re.search(r'name="csrf" value="([^"]+)"', page).group(1)


def submit(c, text: str, **extra):
    page = c.get("/me")
    data = {"markdown": text, "csrf": csrf_of(page.text), **extra}
    return c.post("/grade", data=data, follow_redirects=False)


def wrong(solution: str) -> str:
    """The solution with the centripetal force's sign flipped in tau_2."""
    slip = solution.replace(r"\tau_{2} = - d_2 m_2 \dot\theta_1^{2}", r"\tau_{2} = d_2 m_2 \dot\theta_1^{2}", 1)
    assert slip != solution
    return slip


def test_personal_links_own_variant_and_nobody_elses(course, db_url, caplog):  # noqa: F811
    from starlette.testclient import TestClient

    from armdyn.serve.app import build_app

    caplog.set_level(logging.WARNING, logger="armdyn.serve")
    issued = links(course, db_url)
    assert set(issued) == {"ada", "bob"} and issued["ada"] != issued["bob"]
    again = links(course, db_url)  # a second run issues nothing new: only hashes are kept
    assert all(v.startswith("(issued before") for v in again.values())
    ada_text = (course / "v" / "ada" / "solution.md").read_text(encoding="utf-8")
    bob_text = (course / "v" / "bob" / "solution.md").read_text(encoding="utf-8")

    with TestClient(build_app(settings_for(course, db_url))) as ada:
        wait_ready(ada)
        # without a session: no menu of everyone's variants, no anonymous submission
        assert ada.get("/", follow_redirects=False).headers["location"] == "/me"
        assert ada.get("/me").status_code == 401
        anon = ada.post("/api/grade", content=ada_text.encode(), headers=MD)
        assert anon.status_code == 401 and "personal link" in anon.json()["error"]
        assert ada.post("/api/preview?exercise=bob", content=b"$$x = 1$$", headers=MD).status_code == 401
        assert ada.get("/link/not-a-real-link-token-at-all").status_code == 404
        assert "wrong or renewed personal link" in caplog.text

        log_in(ada, issued["ada"])
        me = ada.get("/me")
        assert me.status_code == 200 and 'id="my-exercise">ada<' in me.text and "bob" not in me.text
        assert "latest" in me.text  # the policy is stated
        statement = ada.get("/me/statement")
        assert statement.status_code == 200 and statement.text == (course / "v" / "ada" / "problem.html").read_text(
            encoding="utf-8"
        )
        assert ada.get("/exercises/ada/statement").status_code == 200  # the fragment beside her editor
        caplog.clear()
        assert ada.get("/exercises/bob/statement").status_code == 403
        assert "ada asked for the statement of bob" in caplog.text

        # her own solution: graded against her variant, every step right, on time
        r = submit(ada, ada_text)
        assert r.status_code == 303
        sid = r.headers["location"].split("/submissions/")[1].split("?")[0]
        got = ada.get(f"/api/submissions/{sid}").json()  # by her session alone, no token
        assert got["graded_as"] == "ada" and got["passed"] is True and got["late"] is False, got

        # another's solution (front matter variant: bob): refused, nothing stored
        before = len(ada.get("/me").text.split("/submissions/"))
        clash = submit(ada, bob_text)
        assert clash.status_code == 409
        message = html.unescape(clash.text)
        assert message.startswith("line 5: your front matter says variant: bob") and "is 'ada'" in message
        assert "nothing was graded" in message
        assert len(ada.get("/me").text.split("/submissions/")) == before
        # another's variant asked for outright: refused and logged
        caplog.clear()
        assert submit(ada, ada_text, exercise="bob").status_code == 403
        api = ada.post("/api/grade?variant=bob", content=ada_text.encode(), headers=MD)
        assert api.status_code == 403 and "your exercise is 'ada'" in api.json()["error"]
        assert "ada tried to submit to exercise bob" in caplog.text
        assert ada.post("/api/preview?exercise=bob", content=b"$$x = 1$$", headers=MD).status_code == 403
        own = ada.post("/api/preview", content=b"$$\\tau_1 = 0$$", headers=MD)
        assert own.status_code == 200 and "tau_1" in own.json()["html"]
        # the API, by her session: her variant, whatever the front matter's robot line says
        slip = ada.post("/api/grade", content=wrong(ada_text).encode(), headers=MD).json()
        assert slip["graded_as"] == "ada" and slip["passed"] is False and slip["first_wrong"] == "tau_2", slip

        bob = TestClient(ada.app)  # another browser; no second lifespan (it would start a second pool)
        log_in(bob, issued["bob"])
        caplog.clear()
        for path in (f"/submissions/{sid}", f"/api/submissions/{sid}", f"/submissions/{sid}/report.html"):
            assert bob.get(path).status_code == 404, path
        assert "bob asked for submission" in caplog.text
        assert sid not in bob.get("/me").text
        late = submit(bob, bob_text)
        bob_sid = late.headers["location"].split("/submissions/")[1].split("?")[0]
        row = bob.get(f"/api/submissions/{bob_sid}").json()
        assert row["graded_as"] == "bob" and row["passed"] is True and row["late"] is True
        assert "late" in bob.get("/me").text
        # logging out ends the session on the server
        bob.post("/me/logout", data={"csrf": csrf_of(bob.get("/me").text)})
        assert bob.get(f"/api/submissions/{bob_sid}").status_code == 404

        # the gradebook: one row per student, by the stated policy
        def book(client):
            text = client.get("/instructor/gradebook.csv", headers={"authorization": f"Bearer {TOKEN}"}).text
            return {r["student"]: r for r in csv.DictReader(io.StringIO(text))}

        latest = book(ada)
        assert set(latest) == {"ada", "bob"}
        assert latest["ada"]["policy"] == "latest" and latest["ada"]["submissions"] == "2"
        assert float(latest["ada"]["total"]) < float(latest["ada"]["max"])  # the slip came last
        assert latest["ada"]["late"] == "no" and latest["bob"]["late"] == "yes"
        assert float(latest["bob"]["total"]) == float(latest["bob"]["max"]) > 0

    with TestClient(build_app(settings_for(course, db_url, policy="best"))) as c:
        best = book(c)
        counted = best["ada"]["submission"]
        assert best["ada"]["policy"] == "best" and counted == ("'" + sid if sid[0] in "=+-@" else sid)  # CSV guard
        assert float(best["ada"]["total"]) == float(best["ada"]["max"]) > float(latest["ada"]["total"])


def test_menu_never_overrides_the_front_matter_silently(course, tmp_path):
    """Without a roster: a file naming variant bob, sent with the page's default exercise
    (rp-arm), is refused with a message instead of graded against rp-arm."""
    from starlette.testclient import TestClient

    from armdyn.serve.app import Settings, build_app
    from armdyn.serve.exercises import catalogue

    bob_text = (course / "v" / "bob" / "solution.md").read_text(encoding="utf-8")
    settings = Settings(db=f"sqlite:///{tmp_path / 'db.sqlite'}", workers=1, exercises=catalogue(str(course / "v")))
    with TestClient(build_app(settings)) as c:
        wait_ready(c)
        csrf = csrf_of(c.get("/").text)
        r = c.post("/grade", data={"markdown": bob_text, "csrf": csrf, "exercise": "rp-arm"}, follow_redirects=False)
        assert r.status_code == 409 and "variant: bob" in r.text and "'rp-arm'" in html.unescape(r.text)
        ok = c.post("/grade", data={"markdown": bob_text, "csrf": csrf, "exercise": ""}, follow_redirects=False)
        assert ok.status_code == 303  # as the front matter says: graded against bob
        sid = ok.headers["location"].split("/submissions/")[1].split("?")[0]
        got = c.get(f"/api/submissions/{sid}").json()
        assert got["graded_as"] == "bob" and got["passed"] is True


def test_roster_errors_name_file_and_line(course, tmp_path):
    from armdyn.serve.exercises import catalogue
    from armdyn.serve.identity import load_roster, parse_deadlines

    exercises = catalogue(str(course / "v"))
    bad = tmp_path / "r.csv"
    bad.write_text("id,name\nada,A\nada,B\n", encoding="utf-8")
    with pytest.raises(ModelError, match=r"r\.csv:3.*duplicate id 'ada' \(first on line 2\)"):
        load_roster(str(bad), exercises)
    bad.write_text("id,name\ncarl,C\n", encoding="utf-8")  # no variant folder carl, no variant column
    with pytest.raises(ModelError, match=r"r\.csv:2.*'carl' has no variant"):
        load_roster(str(bad), exercises)
    bad.write_text("id,variant\ncarl,nope\n", encoding="utf-8")
    with pytest.raises(ModelError, match="variant 'nope' is not served"):
        load_roster(str(bad), exercises)
    # without served variants every student does the bundled exercise
    assert load_roster(str(course / "roster.csv"), catalogue())["ada"].variant == "rp-arm"
    # deadlines: ISO 8601 with a zone, or UTC; per exercise or for all
    when = parse_deadlines(["2026-12-10T23:59+01:00", "ada=2026-12-11T00:00"])
    assert when["*"] == calendar.timegm((2026, 12, 10, 22, 59, 0))  # 23:59 at +01:00 is 22:59 UTC
    assert when["ada"] - when["*"] == 61 * 60
    with pytest.raises(ModelError, match="not a date and time"):
        parse_deadlines(["next friday"])


def test_links_command_and_serve_options(course, tmp_path):
    """``armdyn links`` writes the links owner-only and renews one on demand (the old
    one stops opening a session); ``armdyn serve``'s options reach the settings."""
    from armdyn.cli import build_parser, main
    from armdyn.serve.app import Settings
    from armdyn.serve.exercises import catalogue
    from armdyn.serve.identity import Store
    from armdyn.serve.server import course_settings
    from armdyn.serve.storage import Repository

    db = f"sqlite:///{tmp_path / 'db.sqlite'}"
    out = tmp_path / "links.csv"
    common = ["links", "--roster", str(course / "roster.csv"), "--db", db, "--exercises", str(course / "v")]
    assert main([*common, "--base-url", "https://armdyn.test/", "--out", str(out)]) == 0
    assert out.stat().st_mode & 0o077 == 0
    first = {r["id"]: r["link"] for r in csv.DictReader(io.StringIO(out.read_text()))}
    assert re.fullmatch(r"https://armdyn\.test/link/[A-Za-z0-9_-]{43}", first["ada"])
    assert main([*common, "--base-url", "https://armdyn.test", "--out", str(out), "--renew", "ada"]) == 0
    second = {r["id"]: r["link"] for r in csv.DictReader(io.StringIO(out.read_text()))}
    assert second["ada"] != first["ada"] and second["bob"].startswith("(issued before")
    repo = Repository(db)
    store = Store(repo.engine)
    assert store.student_of_link(first["ada"].rsplit("/", 1)[1]) is None  # renewed: the old link is dead
    assert store.student_of_link(second["ada"].rsplit("/", 1)[1]) == "ada"
    assert store.student_of_link(first["bob"].rsplit("/", 1)[1]) == "bob"
    repo.dispose()
    assert main([*common, "--base-url", "https://x", "--renew", "mallory"]) == 2  # not on the roster

    args = build_parser().parse_args(
        ["serve", "--roster", str(course / "roster.csv"), "--deadline", "ada=2026-12-11T00:00Z", "--policy", "best"]
    )
    settings = Settings(exercises=catalogue(str(course / "v")))
    course_settings(settings, args)
    assert settings.roster["bob"].variant == "bob" and settings.policy == "best"
    assert settings.deadlines == {"ada": calendar.timegm((2026, 12, 11, 0, 0, 0))}
    with pytest.raises(ModelError, match="--lti needs --roster"):
        course_settings(Settings(exercises=settings.exercises), build_parser().parse_args(["serve", "--lti", "x.yaml"]))
