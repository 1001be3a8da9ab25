"""LTI 1.3's routes (:mod:`.lti` holds the protocol) and the score passback.

GET|POST /lti/login        OIDC login initiation -> the platform's authorization endpoint
POST     /lti/launch       the signed launch: a student's page, the instructor's, or deep linking
POST     /lti/deep-link    the instructor's choice -> a signed LtiDeepLinkingResponse, posted back
GET      /lti/jwks         the tool's public keys
"""

from __future__ import annotations

import time
import urllib.parse

from . import security
from .identity import Refused, set_session_cookie
from .lti import (
    AGS_ENDPOINT,
    ASSIGNED,
    DL,
    LAUNCH_SESSION_SECONDS,
    LTI,
    SCORE_SCOPE,
    Ledger,
    exercise_for,
    is_instructor,
    log,
    student_for,
    verify_launch,
)

STATE_COOKIE = "armdyn_lti_state"
DEEP_LINK_SECONDS = 3600  # the chooser's form stays valid this long
SCORE_MAXIMUM = 100  # the line item a deep link creates; scores are sent as given/maximum


def _state_cookie(state: str) -> str:
    return f"{STATE_COOKIE}_{security.digest(state)[:16]}"  # one per login, so two tabs do not clash


def _client_id(claims: dict) -> str:
    """The tool's client id in a verified launch (its ``aud``, or ``azp`` among several)."""
    aud = claims["aud"]
    return aud if isinstance(aud, str) else claims.get("azp") or aud[0]


def passback(srv, tool, ledger: Ledger, sid: str) -> None:
    """Send the score the gradebook counts for the student of submission ``sid`` to
    every line item of their launches of that exercise (a failure is logged)."""
    from .grades import counted

    row = srv.repo.get(sid)
    if row is None or not row.get("student_id") or row["status"] != "done":
        return
    exercise = row.get("graded_as") or row.get("exercise")
    items = ledger.lineitems(row["student_id"], exercise)
    if not items:
        return
    mine = [srv.repo.get(r["id"]) for r in srv.repo.by_student(row["student_id"])]
    mine = [r for r in mine if r["status"] == "done" and (r.get("graded_as") or r.get("exercise")) == exercise]
    pick, given, maximum = counted(mine, srv.settings.policy, srv.settings.exercises, exercise)
    if maximum <= 0:
        return  # nothing gradable (an input error): nothing to send
    verdict = "every step right" if pick.get("passed") else f"first wrong step: {pick.get('first_wrong') or '-'}"
    comment = f"armdyn: {verdict} ({srv.settings.policy} submission{', late' if pick.get('late') else ''})"
    for item in items:
        platform = tool.platform(item["issuer"], item["client_id"])
        if platform is None:
            continue
        try:
            tool.post_score(platform, item["lineitem"], item["sub"], given, maximum, comment)
        except Exception as err:  # noqa: BLE001 - the platform away or refusing: log, never crash grading
            log.warning("armdyn serve: score of %s to %s not sent: %s", row["student_id"], item["lineitem"], err)


def routes(srv, web) -> list:
    """The routes above when ``--lti`` configured a tool, else none (``web``: the app's
    page helpers, ``page``)."""
    if srv.settings.lti is None:
        return []
    from starlette.concurrency import run_in_threadpool
    from starlette.responses import JSONResponse, RedirectResponse
    from starlette.routing import Route

    tool = srv.settings.lti
    ledger_box: list[Ledger] = []

    def ledger() -> Ledger:
        if not ledger_box:
            ledger_box.append(Ledger(srv.repo.engine))
        return ledger_box[0]

    def on_done(ids: list[str]) -> None:
        for sid in ids:
            tool.passbacks.submit(passback, srv, tool, ledger(), sid)

    srv.done_hooks.append(on_done)

    async def login(request):
        params = dict(request.query_params)
        if request.method == "POST":
            params.update({k: str(v) for k, v in (await request.form()).items()})
        issuer, hint = params.get("iss", ""), params.get("login_hint", "")
        if not issuer or not hint:
            raise Refused(400, "a login initiation needs iss and login_hint", "LTI login without iss or login_hint")
        platform = tool.platform(issuer, params.get("client_id"))
        if platform is None:
            raise Refused(403, "this platform is not registered with armdyn", f"LTI login from unknown {issuer[:200]}")
        state, nonce = await run_in_threadpool(ledger().new_state, platform)
        query = {
            "scope": "openid",
            "response_type": "id_token",
            "response_mode": "form_post",
            "prompt": "none",
            "client_id": platform.client_id,
            "redirect_uri": tool.url + "/lti/launch",
            "login_hint": hint,
            "state": state,
            "nonce": nonce,
        }
        if params.get("lti_message_hint"):
            query["lti_message_hint"] = params["lti_message_hint"]
        target = (
            platform.auth_login_url + ("&" if "?" in platform.auth_login_url else "?") + urllib.parse.urlencode(query)
        )
        response = RedirectResponse(target, status_code=302)
        https = request.url.scheme == "https"
        # the launch is a cross-site POST from the platform: only SameSite=None (with Secure) reaches it
        response.set_cookie(
            _state_cookie(state), state, max_age=600, httponly=True, secure=https, samesite="none" if https else "lax"
        )
        return response

    async def launch(request):
        form = await request.form()
        id_token, state = str(form.get("id_token") or ""), str(form.get("state") or "")
        if form.get("error"):
            raise Refused(400, f"the platform refused the login: {str(form.get('error'))[:100]}", "LTI login refused")
        if not id_token or not state or len(state) > 100:
            raise Refused(400, "a launch needs id_token and state", "LTI launch without id_token or state")
        if request.cookies.get(_state_cookie(state)) != state:
            raise Refused(403, "this launch was not started in this browser", "LTI launch without its state cookie")
        state_row = await run_in_threadpool(ledger().take_state, state)
        if state_row is None:
            raise Refused(403, "the launch's login is unknown, used or expired", "LTI launch with an unknown state")
        claims = await run_in_threadpool(verify_launch, tool, ledger(), id_token, state_row)
        kind = claims.get(LTI + "message_type")
        if kind == "LtiDeepLinkingRequest":
            response = await deep_linking(request, claims)
        elif kind == "LtiResourceLinkRequest":
            response = await resource_link(request, claims)
        else:
            raise Refused(400, f"unknown LTI message type {str(kind)[:60]}", "LTI launch of an unknown type")
        response.delete_cookie(_state_cookie(state))
        return response

    async def resource_link(request, claims):
        if is_instructor(claims):
            if srv.secrets.instructor_token is None:
                raise Refused(403, "the instructor page is closed (no instructor token)", "LTI instructor launch")
            response = RedirectResponse("/instructor", status_code=303)
            response.set_cookie(
                security.INSTRUCTOR_COOKIE,
                srv.secrets.new_session(),
                httponly=True,
                samesite="lax",
                secure=request.url.scheme == "https",
                max_age=security.SESSION_SECONDS,
            )
            return response
        student = await run_in_threadpool(student_for, srv.settings, ledger(), claims)
        exercise = exercise_for(srv.settings, claims, student)
        ags = claims.get(AGS_ENDPOINT) or {}
        link = (claims.get(LTI + "resource_link") or {}).get("id")
        if ags.get("lineitem") and SCORE_SCOPE in (ags.get("scope") or []) and link:
            await run_in_threadpool(
                ledger().remember_lineitem,
                issuer=claims["iss"],
                resource_link=str(link)[:255],
                student_id=student.id,
                client_id=_client_id(claims),
                sub=str(claims["sub"]),
                exercise=exercise,
                lineitem=str(ags["lineitem"])[:1000],
            )
        token = await run_in_threadpool(srv.people.new_session, student.id, exercise, LAUNCH_SESSION_SECONDS)
        response = RedirectResponse("/me", status_code=303)
        set_session_cookie(response, request, token, LAUNCH_SESSION_SECONDS)
        log.info("armdyn serve: LTI launch of %s on %s", student.id, exercise)
        return response

    async def deep_linking(request, claims):
        if not is_instructor(claims):
            raise Refused(403, "only an instructor adds exercises to a course", f"deep linking by {claims['sub']}")
        settings_claim = claims.get(DL + "deep_linking_settings") or {}
        back = settings_claim.get("deep_link_return_url")
        if not back or not str(back).startswith("https://") and not str(back).startswith("http://127.0.0.1"):
            raise Refused(400, "the platform gave no deep_link_return_url", "deep linking without a return URL")
        context = tool.sign(
            {
                "aud": "armdyn-deep-link",
                "exp": int(time.time()) + DEEP_LINK_SECONDS,
                "iss_platform": claims["iss"],
                "client_id": _client_id(claims),
                "deployment_id": claims[LTI + "deployment_id"],
                "return_url": back,
                "data": settings_claim.get("data"),
            }
        )
        choices = [(ASSIGNED, "the exercise: each student their own variant (the roster's)")]
        choices += [(e.id, e.title) for e in srv.settings.exercises.values() if not e.variant]
        return web.page("lti_pick.html", choices=choices, context=context, instructor=True)

    async def deep_link_answer(request):
        import jwt

        form = await request.form()
        try:
            ctx = jwt.decode(
                str(form.get("context") or ""),
                tool.private_key.public_key(),
                algorithms=["RS256"],
                audience="armdyn-deep-link",
            )
        except jwt.PyJWTError as err:
            raise Refused(
                403, "the form expired: add the exercise again from the LMS", f"deep link form: {err}"
            ) from None
        chosen = str(form.get("exercise") or "")
        if chosen != ASSIGNED and (chosen not in srv.settings.exercises or srv.settings.exercises[chosen].variant):
            raise Refused(400, "choose one of the exercises offered", f"deep link to {chosen[:64]}")
        title = "armdyn: dynamics derivation" if chosen == ASSIGNED else f"armdyn: {chosen}"
        now = int(time.time())
        item = {
            "type": "ltiResourceLink",
            "title": title,
            "url": tool.url + "/lti/launch",
            "custom": {"exercise": chosen},
            "lineItem": {"scoreMaximum": SCORE_MAXIMUM, "label": title, "resourceId": chosen},
        }
        claims = {
            "iss": ctx["client_id"],
            "aud": ctx["iss_platform"],
            "iat": now,
            "exp": now + 600,
            "nonce": security.new_token(),
            LTI + "message_type": "LtiDeepLinkingResponse",
            LTI + "version": "1.3.0",
            LTI + "deployment_id": ctx["deployment_id"],
            DL + "content_items": [item],
        }
        if ctx.get("data") is not None:
            claims[DL + "data"] = ctx["data"]
        response = web.page("lti_return.html", url=ctx["return_url"], jwt=tool.sign(claims), instructor=True)
        origin = "{0.scheme}://{0.netloc}".format(urllib.parse.urlsplit(ctx["return_url"]))
        # the one form that leaves this site: back to the platform that asked
        response.headers["content-security-policy"] = security.CSP.replace(
            "form-action 'self'", f"form-action 'self' {origin}"
        )
        return response

    async def jwks(request):
        return JSONResponse(tool.jwks())

    return [
        Route("/lti/login", login, methods=["GET", "POST"]),
        Route("/lti/launch", launch, methods=["POST"]),
        Route("/lti/deep-link", deep_link_answer, methods=["POST"]),
        Route("/lti/jwks", jwks),
    ]
