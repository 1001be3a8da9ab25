"""LTI 1.3 against the real app: the tests are the platform (tests/lti_platform.py: its
own RSA key, key set, token endpoint and line item on 127.0.0.1).

Second opinions: the LTI 1.3 / Security Framework rules themselves (a token signed by
another key, for another client, expired, of another deployment, or replayed is
refused), PyJWT verifying the tool's JWTs with the key set the tool publishes, and for
the score a worked solution that is right in every step (so full marks: scoreGiven
equals scoreMaximum) against the same with one sign flipped (less than full).
"""

from __future__ import annotations

import html
import logging
import re
import time
import urllib.parse

import pytest

pytest.importorskip("starlette")
pytest.importorskip("sqlalchemy")
pytest.importorskip("httpx")
jwt = pytest.importorskip("jwt")

import yaml  # noqa: E402
from lti_platform import (  # noqa: E402
    CLIENT_ID,
    DEPLOYMENT,
    DL,
    INSTRUCTOR,
    LTI,
    TOOL_URL,
    Platform,
    new_key,
)
from serve_support import db_url  # noqa: E402, F401
from test_serve_identity import course, settings_for, wait_ready, wrong  # noqa: E402, F401

TOKEN = "instructor-secret-for-tests"


@pytest.fixture
def platform():
    p = Platform().start()
    yield p
    p.stop()


def app_for(course, db, platform, tmp_path, **kw):  # noqa: F811
    from starlette.testclient import TestClient

    from armdyn.serve.app import build_app
    from armdyn.serve.lti import Tool

    conf = tmp_path / "lti.yaml"
    conf.write_text(yaml.safe_dump({"url": TOOL_URL, "key": "tool.pem", "platforms": [platform.registration()]}))
    tool = Tool.load(str(conf))
    assert (tmp_path / "tool.pem").stat().st_mode & 0o077 == 0  # the key: owner only
    return TestClient(build_app(settings_for(course, db, lti=tool, **kw)))


def login(c, platform) -> dict:
    """The platform's login initiation; returns the parameters the tool sent to its
    authorization endpoint."""
    r = c.get(
        "/lti/login",
        params={"iss": platform.issuer, "login_hint": "hint-41", "target_link_uri": TOOL_URL + "/lti/launch"},
        follow_redirects=False,
    )
    assert r.status_code == 302, r.text
    target = urllib.parse.urlsplit(r.headers["location"])
    assert f"{target.scheme}://{target.netloc}{target.path}" == platform.base + "/auth"
    q = {k: v[0] for k, v in urllib.parse.parse_qs(target.query).items()}
    assert q["redirect_uri"] == TOOL_URL + "/lti/launch" and q["client_id"] == CLIENT_ID
    assert q["response_mode"] == "form_post" and q["scope"] == "openid" and q["login_hint"] == "hint-41"
    return q


def launch(c, platform, key=None, kid=None, **change):
    q = login(c, platform)
    token = platform.id_token(platform.claims(q["nonce"], **change), key=key, kid=kid)
    return c.post("/lti/launch", data={"id_token": token, "state": q["state"]}, follow_redirects=False), token, q


def test_launch_grades_and_passes_the_score_back(course, db_url, platform, tmp_path):  # noqa: F811
    ada_text = (course / "v" / "ada" / "solution.md").read_text(encoding="utf-8")
    with app_for(course, db_url, platform, tmp_path) as c:
        wait_ready(c)
        platform.tool_jwks = c.get("/lti/jwks").json()
        r, _, _ = launch(c, platform)  # ada, found by her email in the roster
        assert r.status_code == 303 and r.headers["location"] == "/me", r.text
        me = c.get("/me")
        assert 'id="my-exercise">ada<' in me.text
        csrf = re.search(r'name="csrf" value="([^"]+)"', me.text).group(1)
        graded = c.post("/grade", data={"markdown": ada_text, "csrf": csrf}, follow_redirects=False)
        sid = graded.headers["location"].split("/submissions/")[1]
        assert c.get(f"/api/submissions/{sid}").json()["passed"] is True
        deadline = time.monotonic() + 60
        while not platform.scores and time.monotonic() < deadline:
            time.sleep(0.2)
        assert platform.scores, platform.refusals
        path, auth, score = platform.scores[-1]
        assert path == "/lineitems/7/scores" and auth[7:] in platform.tokens
        assert score["userId"] == "lms-user-41" and score["gradingProgress"] == "FullyGraded"
        assert score["scoreMaximum"] > 0 and score["scoreGiven"] == score["scoreMaximum"]  # every step right
        assert re.match(r"^\d{4}-\d\d-\d\dT\d\d:\d\d:\d\d\.\d{3}Z$", score["timestamp"])
        # the assertion the tool authenticated with: its own client id, for the token endpoint
        claims = platform.assertions[-1]
        assert claims["iss"] == claims["sub"] == CLIENT_ID and claims["aud"] == platform.base + "/token"

        # a second, wrong submission: the policy (latest) sends the lower score
        csrf = re.search(r'name="csrf" value="([^"]+)"', c.get("/me").text).group(1)
        c.post("/grade", data={"markdown": wrong(ada_text), "csrf": csrf}, follow_redirects=False)
        deadline = time.monotonic() + 60
        while len(platform.scores) < 2 and time.monotonic() < deadline:
            time.sleep(0.2)
        lower = platform.scores[-1][2]
        assert lower["scoreMaximum"] == score["scoreMaximum"] and lower["scoreGiven"] < score["scoreGiven"]
        assert "tau_2" in lower["comment"]
        assert len(platform.assertions) == 1  # the access token was kept, not asked for again


def test_forged_and_replayed_launches_are_refused_and_logged(course, db_url, platform, tmp_path, caplog):  # noqa: F811
    from starlette.testclient import TestClient

    from armdyn.serve.lti_web import _state_cookie

    caplog.set_level(logging.WARNING, logger="armdyn.serve")
    with app_for(course, db_url, platform, tmp_path) as c:
        cases = [
            ("forged signature", dict(key=new_key()), 401, "InvalidSignatureError"),
            ("another tool's token", dict(aud="someone-else"), 403, "wrong audience"),
            ("another platform's token", dict(iss="https://lms.elsewhere"), 403, "wrong issuer"),
            ("expired", dict(exp=int(time.time()) - 3600, iat=int(time.time()) - 7200), 401, "expired"),
            ("issued in the future", dict(iat=int(time.time()) + 3600, exp=int(time.time()) + 7200), 401, "Immature"),
            ("unknown deployment", {LTI + "deployment_id": "deployment-99"}, 403, "unknown deployment"),
            ("not on the roster", dict(sub="lms-user-77", email="eve@example.edu"), 403, "not on the roster"),
            ("no nonce", dict(nonce=None), 401, "nonce"),
            ("a signature by the platform's key under another key id", dict(kid="unknown-kid"), 401, "key"),
        ]
        for what, change, status, logged in cases:
            caplog.clear()
            r, _, _ = launch(c, platform, **change)
            assert r.status_code == status, (what, r.status_code, r.text)
            assert "Traceback" not in r.text and len(r.text) < 300, what
            assert logged in caplog.text, (what, caplog.text)

        # a good launch, then its id_token again: with its own state (used) and with a fresh one
        good, token, q = launch(c, platform)
        assert good.status_code == 303
        again = c.post("/lti/launch", data={"id_token": token, "state": q["state"]}, follow_redirects=False)
        assert again.status_code == 403 and "not started in this browser" in again.text  # its cookie went
        c.cookies.set(_state_cookie(q["state"]), q["state"])  # even with the cookie put back: used
        again = c.post("/lti/launch", data={"id_token": token, "state": q["state"]}, follow_redirects=False)
        assert again.status_code == 403 and "used" in again.text
        fresh = login(c, platform)
        replay = c.post("/lti/launch", data={"id_token": token, "state": fresh["state"]}, follow_redirects=False)
        assert replay.status_code == 403 and "does not belong to its login" in replay.text

        # a launch posted by another browser (no state cookie): refused
        q = login(c, platform)
        stranger = TestClient(c.app)
        token = platform.id_token(platform.claims(q["nonce"]))
        assert stranger.post("/lti/launch", data={"id_token": token, "state": q["state"]}).status_code == 403
        # an unregistered platform cannot even start a login
        r = c.get("/lti/login", params={"iss": "https://lms.elsewhere", "login_hint": "x"}, follow_redirects=False)
        assert r.status_code == 403 and "not registered" in r.text

    from armdyn.serve.lti import Ledger
    from armdyn.serve.storage import Repository

    repo = Repository(db_url)  # the nonce ledger itself: a nonce serves once
    ledger = Ledger(repo.engine)
    assert ledger.use_nonce("n-1") is True and ledger.use_nonce("n-1") is False
    repo.dispose()


def test_deep_linking_returns_a_signed_resource_link(course, db_url, platform, tmp_path):  # noqa: F811
    with app_for(course, db_url, platform, tmp_path) as c:
        settings = {
            "deep_link_return_url": platform.base + "/deep-return",
            "accept_types": ["ltiResourceLink"],
            "accept_presentation_document_targets": ["window"],
            "data": "opaque-7",
        }
        dl = {
            LTI + "message_type": "LtiDeepLinkingRequest",
            LTI + "roles": [INSTRUCTOR],
            LTI + "resource_link": None,
            DL + "deep_linking_settings": settings,
        }
        # a learner may not add exercises to the course
        r, _, _ = launch(
            c, platform, **{**dl, LTI + "roles": ["http://purl.imsglobal.org/vocab/lis/v2/membership#Learner"]}
        )
        assert r.status_code == 403
        r, _, _ = launch(c, platform, **dl)
        assert r.status_code == 200, r.text
        context = re.search(r'name="context" value="([^"]+)"', r.text).group(1)
        assert 'value="assigned"' in r.text and 'value="rp-arm"' in r.text and 'value="ada"' not in r.text
        back = c.post("/lti/deep-link", data={"context": context, "exercise": "assigned"})
        assert back.status_code == 200
        assert f"form-action 'self' {platform.base}" in back.headers["content-security-policy"]
        action = html.unescape(re.search(r'<form method="post" action="([^"]+)"', back.text).group(1))
        assert action == platform.base + "/deep-return"
        answer = html.unescape(re.search(r'name="JWT" value="([^"]+)"', back.text).group(1))

        # the platform checks it with the key set the tool publishes
        keys = jwt.PyJWKSet.from_dict(c.get("/lti/jwks").json())
        key = keys[jwt.get_unverified_header(answer)["kid"]].key
        claims = jwt.decode(answer, key, algorithms=["RS256"], audience=platform.issuer, issuer=CLIENT_ID)
        assert claims[LTI + "message_type"] == "LtiDeepLinkingResponse" and claims[LTI + "version"] == "1.3.0"
        assert claims[LTI + "deployment_id"] == DEPLOYMENT and claims[DL + "data"] == "opaque-7"
        (item,) = claims[DL + "content_items"]
        assert item["type"] == "ltiResourceLink" and item["url"] == TOOL_URL + "/lti/launch"
        assert item["custom"] == {"exercise": "assigned"} and item["lineItem"]["scoreMaximum"] > 0
        with pytest.raises(jwt.InvalidSignatureError):  # and a key of its own does not verify it
            other = jwt.PyJWK.from_dict({**platform.jwks()["keys"][0]}).key
            jwt.decode(answer, other, algorithms=["RS256"], audience=platform.issuer)
        # a forged chooser form (not signed by the tool) is refused
        assert c.post("/lti/deep-link", data={"context": "x.y.z", "exercise": "assigned"}).status_code == 403
        assert c.post("/lti/deep-link", data={"context": context, "exercise": "ada"}).status_code == 400

        # the link it made, launched by a student: her own variant, whatever the link says
        r, _, _ = launch(c, platform, **{LTI + "custom": {"exercise": "assigned"}})
        assert r.status_code == 303 and 'id="my-exercise">ada<' in c.get("/me").text
        # a shared exercise (not a variant) named by the link: that one
        r, _, _ = launch(c, platform, **{LTI + "custom": {"exercise": "rp-arm"}})
        assert 'id="my-exercise">rp-arm<' in c.get("/me").text


def test_armdyn_serve_with_roster_and_lti(course, platform, tmp_path):  # noqa: F811
    """The command line: ``armdyn serve --roster --exercises --lti`` publishes the tool's
    key set, starts logins for the registered platform only, keeps students out of
    ``/me`` without a session; a broken --lti file stops the start with its name."""
    from serve_support import http, start_server

    conf = tmp_path / "lti.yaml"
    conf.write_text(yaml.safe_dump({"url": TOOL_URL, "platforms": [platform.registration()]}))
    extra = ["--roster", str(course / "roster.csv"), "--exercises", str(course / "v"), "--lti", str(conf)]
    server = start_server(tmp_path, f"sqlite:///{tmp_path / 'db.sqlite'}", extra=extra)
    try:
        status, keys = http("GET", server.base + "/lti/jwks")
        assert status == 200 and keys["keys"][0]["kty"] == "RSA" and (tmp_path / "lti-key.pem").exists()
        status, _ = http("GET", server.base + "/me")
        assert status == 401
        status, text = http("GET", server.base + "/lti/login?iss=https%3A%2F%2Flms.elsewhere&login_hint=1")
        assert status == 403 and "not registered" in text
    finally:
        assert server.stop() in (0, -15)  # uvicorn re-raises SIGTERM after its graceful shutdown
    conf.write_text("url: https://armdyn.test\nplatforms: [{issuer: x}]\n")
    import subprocess
    import sys

    from serve_support import ROOT

    run = subprocess.run(
        [sys.executable, "-m", "armdyn", "serve", *extra],
        capture_output=True,
        text=True,
        env={"PYTHONPATH": str(ROOT / "python"), "PATH": "/usr/bin:/bin"},
        timeout=120,
    )
    assert run.returncode == 2 and "lti.yaml" in run.stderr and "platform 1 lacks client_id" in run.stderr
