"""The web application (Starlette): the student's page, the instructor's page, the JSON API.

Routes (the JSON API is described in :mod:`.openapi`, served at ``/openapi.json``):

    GET  /                               student page: exercise, its statement, text, live preview, Grade, earlier ones
    GET  /exercises/{eid}/statement      an exercise's statement (HTML fragment, for the student page)
    POST /grade                          the student's form (CSRF) -> /submissions/{id}?t=TOKEN
    GET  /submissions/{id}               the submission and its report (link token, owner or instructor)
    GET  /submissions/{id}/report.html   the self-contained report (``armdyn grade --html``)
    GET  /instructor                     login, or submissions by student and exercise
    POST /instructor/login, /instructor/logout, /instructor/retry/{id}
    GET  /instructor/gradebook.csv       the gradebook (armdyn.course)
    GET  /instructor/summary             the class summary page (armdyn.course)
    GET  /api/health, POST /api/grade, GET /api/submissions/{id}, POST /api/preview
    GET  /link/{token}, /me, /me/statement; POST /me/logout             (--roster: :mod:`.identity`)
    GET|POST /lti/login, POST /lti/launch, /lti/deep-link, GET /lti/jwks     (--lti: :mod:`.lti_web`)

The web process stores and serves; it never reads a student's LaTeX itself: grading
and previews go to worker processes (:mod:`.pool`).
"""

from __future__ import annotations

import asyncio
import json
import os
import re
import sys
import time
from concurrent.futures import ThreadPoolExecutor
from dataclasses import dataclass, field
from types import SimpleNamespace

import jinja2
import sqlalchemy as sa
from starlette.applications import Starlette
from starlette.concurrency import run_in_threadpool
from starlette.exceptions import HTTPException
from starlette.requests import Request
from starlette.responses import HTMLResponse, JSONResponse, RedirectResponse, Response
from starlette.routing import Mount, Route
from starlette.staticfiles import StaticFiles

from . import identity, lti_web, security, waiting
from .exercises import DEFAULT, Exercise, ordered
from .openapi import schema
from .pages import INSTRUCTOR_LINKS, report_links, with_nav
from .pool import Pool
from .statement import statements
from .storage import DONE, FAILED, Repository

HERE = os.path.dirname(os.path.abspath(__file__))
MAX_BODY = 1_000_000  # bytes of a request; a derivation is a few kB
MAX_PREVIEW = 200_000  # bytes of text a preview reads
FORM_WAIT = 20.0  # seconds the Grade button waits for the verdict before showing "queued"
API_WAIT = 30.0  # default ?wait= of POST /api/grade
PREVIEW_SLOTS = 4  # previews running or waiting per server; past it 503 + Retry-After
PREVIEW_RETRY = 2  # seconds, the Retry-After of a preview refused for load
SID = re.compile(r"^[A-Za-z0-9_-]{1,24}$")  # a submission id (security.new_id)
PLAIN_PATH = re.compile(r"^[A-Za-z0-9/_.-]{1,200}$")  # a path redirected without its trailing slash


@dataclass
class Settings:
    """What ``armdyn serve`` was started with."""

    db: str = "sqlite:///armdyn-serve.db"
    exercises: dict[str, Exercise] = field(default_factory=dict)
    workers: int = 2
    timeout: float = 60.0
    memory_mb: int = 2048
    instructor_token: str | None = None
    secret: str | None = None
    max_attempts: int = 3
    grace: float = 10.0
    login_per_client: int = 10  # failed instructor logins per client in 5 min
    login_overall: int = 100  # failed instructor logins from everyone in 5 min
    roster: dict | None = None  # id -> identity.Student (``--roster``): students come by link or LTI
    deadlines: dict[str, float] = field(default_factory=dict)  # exercise id (or "*") -> Unix seconds
    policy: str = "latest"  # which submission the gradebook counts (grades.POLICIES)
    lti: object = None  # lti.Tool (``--lti``)


_templates = jinja2.Environment(
    loader=jinja2.FileSystemLoader(os.path.join(HERE, "templates")), autoescape=True, undefined=jinja2.StrictUndefined
)


def _when(t) -> str:
    return time.strftime("%Y-%m-%d %H:%M:%S", time.gmtime(t)) if t else ""


_templates.filters["when"] = _when


def _page(name: str, status: int = 200, **context) -> HTMLResponse:
    return HTMLResponse(_templates.get_template(name).render(**context), status_code=status)


def _error(status: int, message: str) -> JSONResponse:
    return JSONResponse({"error": message}, status_code=status)


class Server:
    """The state behind the routes: settings, database, pool, waiting requests."""

    def __init__(self, settings: Settings):
        self.settings = settings
        self.secrets = security.Secrets(settings.instructor_token, settings.secret)
        self.throttle = security.Throttle(settings.login_per_client, settings.login_overall)
        # previews wait on their own thread, never in the request threads the database uses
        self.preview_thread = ThreadPoolExecutor(1, thread_name_prefix="armdyn-preview")
        self.preview_lock = asyncio.Lock()
        self.previews = 0  # running or waiting (the event loop's thread only)
        self.repo: Repository | None = None
        self.pool: Pool | None = None
        self.loop: asyncio.AbstractEventLoop | None = None
        self.waiters: dict[str, asyncio.Event] = {}
        self.people: identity.Store | None = None
        self.done_hooks: list = []  # called in the event loop with the ids just graded (LTI score passback)

    # -- life cycle (the app's lifespan)
    async def startup(self) -> None:
        self.loop = asyncio.get_running_loop()
        s = self.settings
        self.repo = await run_in_threadpool(Repository, s.db, s.max_attempts)
        self.people = identity.Store(self.repo.engine)
        sources = {k: e.source for k, e in s.exercises.items()}
        self.pool = Pool(
            self.repo,
            sources,
            workers=s.workers,
            timeout=s.timeout,
            memory_mb=s.memory_mb,
            grace=s.grace,
            on_done=self._done_from_thread,
        )
        await run_in_threadpool(self.pool.start)

    async def shutdown(self) -> None:
        if self.pool is not None:
            await run_in_threadpool(self.pool.stop)
        if self.repo is not None:
            self.repo.dispose()
        self.preview_thread.shutdown(wait=False, cancel_futures=True)

    def _done_from_thread(self, ids: list[str]) -> None:
        if self.loop is not None:
            self.loop.call_soon_threadsafe(self._wake, ids)

    def _wake(self, ids: list[str]) -> None:
        for sid in ids:
            ev = self.waiters.pop(sid, None)
            if ev is not None:
                ev.set()
        for hook in self.done_hooks:
            hook(ids)

    async def wait(self, sid: str, seconds: float) -> dict:
        """The submission's summary once done/failed, or after ``seconds``."""
        deadline = time.monotonic() + max(0.0, seconds)
        while True:
            ev = self.waiters.setdefault(sid, asyncio.Event())
            try:
                row = await run_in_threadpool(self.repo.summary, sid)
            except sa.exc.OperationalError:  # the database restarting: wait on, within the budget
                if time.monotonic() + 1.0 >= deadline:
                    raise
                await asyncio.sleep(1.0)
                continue
            left = deadline - time.monotonic()
            if row is None or row["status"] in (DONE, FAILED) or left <= 0:
                return row
            try:
                await asyncio.wait_for(ev.wait(), min(left, 2.0))
            except asyncio.TimeoutError:
                pass

    async def accept(self, markdown: str, who: dict, owner_key: str | None) -> tuple:
        """Store a submission of ``who`` (:func:`.identity.submitter`'s exercise, student,
        student_id, late); returns (summary row, secret link token)."""
        _no_nul(markdown, "the derivation")
        _no_nul(who["student"], "the student name")
        token = security.new_token()
        owner = security.digest(owner_key) if owner_key else None
        fields = {**who, "student": who["student"].strip(), "owner_hash": owner}
        row = await run_in_threadpool(
            lambda: self.repo.add(security.new_id(), security.digest(token), markdown, **fields)
        )
        if row["status"] != DONE:
            self.pool.wake()
        return row, token

    # -- who may see what
    def is_instructor(self, request: Request) -> bool:
        """A live instructor session, or the instructor token as ``Bearer`` (a wrong one
        counts as a failed login, and is not even compared while its client is throttled)."""
        if self.secrets.session_ok(request.cookies.get(security.INSTRUCTOR_COOKIE)):
            return True
        auth = request.headers.get("authorization", "")
        if not auth.startswith("Bearer ") or self.secrets.instructor_token is None:
            return False
        client = _client(request)
        if self.throttle.wait(client) > 0:
            return False
        if self.secrets.instructor_ok(auth[7:]):
            return True
        self.throttle.failed(client)
        return False

    def may_see(self, request: Request, row: dict) -> bool:
        token = request.query_params.get("t")
        auth = request.headers.get("authorization", "")
        if not token and auth.startswith("Bearer "):
            token = auth[7:]
        if security.token_matches(token, row["token_hash"]):
            return True
        key = request.cookies.get(security.STUDENT_COOKIE)
        if key and row.get("owner_hash") and security.token_matches(key, row["owner_hash"]):
            return True
        return identity.owns(request, row) or self.is_instructor(request)

    def exercise_of(self, value: str | None) -> str | None:
        """A requested exercise id, checked against the whitelist (None: the front matter's)."""
        if not value:
            return None
        if value not in self.settings.exercises:
            raise _BadRequest(
                f"unknown exercise '{value[:64]}': this server grades " + ", ".join(sorted(self.settings.exercises))
            )
        return value


class _BadRequest(Exception):
    pass


def _no_nul(text: str, what: str) -> None:
    """Refuse a NUL character (no derivation holds one; PostgreSQL's text cannot)."""
    at = text.find("\0")
    if at >= 0:
        line = text.count("\n", 0, at) + 1
        raise _BadRequest(f"{what} holds a NUL character (byte 0) on line {line}: remove it and send again")


def _client(request: Request) -> str:
    """The client's address (the proxy's X-Forwarded-For when it is trusted)."""
    return request.client.host if request.client else "?"


def _sid(request: Request) -> str:
    """The submission id of the path; a value that cannot be one (a NUL, a slash...) is 400."""
    sid = request.path_params["sid"]
    if not SID.match(sid):
        raise _BadRequest("not a submission id (ids are up to 24 letters, digits, '-' and '_')")
    return sid


def _student_key(request: Request) -> tuple[str, bool]:
    """The browser's key (new when it has none): (key, is_new)."""
    key = request.cookies.get(security.STUDENT_COOKIE)
    if key and 20 <= len(key) <= 100:
        return key, False
    return security.new_token(), True


def _with_key(response: Response, key: str, new: bool, request: Request) -> Response:
    if new:
        response.set_cookie(
            security.STUDENT_COOKIE,
            key,
            max_age=180 * 86400,
            httponly=True,
            samesite="strict",
            secure=request.url.scheme == "https",
        )
    return response


def _api_view(row: dict, full: dict | None = None) -> dict:
    """A submission as the API shows it: ``grade --json``'s fields plus its state."""
    out = {}
    if full is not None and full.get("report_json"):
        out.update(json.loads(full["report_json"]))
    out.update(
        {
            k: row[k]
            for k in (
                "id",
                "status",
                "attempts",
                "exercise",
                "graded_as",
                "passed",
                "first_wrong",
                "error",
                "cached",
                "created_at",
                "started_at",
                "finished_at",
                "late",
            )
        }
    )
    return out


async def _text_body(request: Request) -> str:
    kind = request.headers.get("content-type", "").split(";")[0].strip().lower()
    if kind not in ("text/markdown", "text/x-markdown"):  # not text/plain: a cross-site form cannot send these
        raise _BadRequest("send the derivation as the body with Content-Type: text/markdown")
    try:
        return (await request.body()).decode("utf-8")
    except UnicodeDecodeError as err:
        raise _BadRequest(f"the body is not UTF-8 (byte {err.start})") from None


def build_app(settings: Settings) -> Starlette:
    """The ASGI app for ``settings`` (workers start with the app's lifespan)."""
    srv = Server(settings)
    menu = ordered(settings.exercises)
    # what identity's and LTI's pages share with these (passed: they do not import this module)
    web = SimpleNamespace(page=_page, student_key=_student_key, with_key=_with_key)
    statement_of = statements(settings.exercises)

    async def health(request: Request):
        """ok (200); starting, or degraded with its ``problems`` (503): a grading thread
        ended or stuck, a queue that does not move, the database away."""
        ready = srv.pool is not None and srv.pool.ready
        problems = []
        try:
            counts = await run_in_threadpool(srv.repo.counts) if srv.repo is not None else {}
        except Exception as err:  # noqa: BLE001 - any database failure is what health must tell
            counts = {}
            problems.append(f"the database does not answer ({type(err).__name__})")
        if ready:
            problems += srv.pool.problems(counts.get("queued", 0))
        status = "starting" if not ready else "degraded" if problems else "ok"
        body = {"status": status, "workers": settings.workers, "queue": counts}
        if problems:
            body["problems"] = problems
        if srv.is_instructor(request) and srv.pool is not None:
            body["worker_pids"] = srv.pool.pids()
        return JSONResponse(body, status_code=200 if status == "ok" else 503)

    async def api_grade(request: Request):
        q = request.query_params
        exercise = srv.exercise_of(q.get("robot") or q.get("variant") or q.get("exercise"))
        markdown = await _text_body(request)
        try:
            wait = min(120.0, max(0.0, float(q.get("wait", API_WAIT))))
        except ValueError:
            raise _BadRequest("wait must be a number of seconds") from None
        who = identity.submitter(srv, request, markdown, exercise, q.get("student", ""), form=False)
        row, token = await srv.accept(markdown, who, None)
        row = await srv.wait(row["id"], wait) if row["status"] not in (DONE, FAILED) else row
        full = await run_in_threadpool(srv.repo.get, row["id"])
        body = _api_view(row, full)
        body.update(token=token, url=f"/submissions/{row['id']}?t={token}")
        return JSONResponse(body, status_code=200 if row["status"] in (DONE, FAILED) else 202)

    async def api_submission(request: Request):
        full = await run_in_threadpool(srv.repo.get, _sid(request))
        if full is None or not srv.may_see(request, full):
            return _error(404, "no such submission (or not yours: give its token as ?t=)")
        return JSONResponse(await run_in_threadpool(waiting.with_position, srv.repo, full, _api_view(full, full)))

    async def api_preview(request: Request):
        """One preview worker, at most :data:`PREVIEW_SLOTS` previews running or waiting
        (more: 503 with Retry-After, before their body is read); one whose client has
        left is dropped unmade."""
        if srv.previews >= PREVIEW_SLOTS:
            busy = _error(503, f"too many previews at once; try again in {PREVIEW_RETRY} s")
            busy.headers["retry-after"] = str(PREVIEW_RETRY)
            return busy
        srv.previews += 1
        try:
            markdown = await _text_body(request)
            if len(markdown.encode()) > MAX_PREVIEW:
                return _error(413, f"a preview reads at most {MAX_PREVIEW} bytes")
            exercise = identity.may_preview(srv, request, srv.exercise_of(request.query_params.get("exercise")))
            async with srv.preview_lock:
                if await request.is_disconnected():
                    return Response(status_code=204)  # nobody reads it: do not make it
                loop = asyncio.get_running_loop()
                reply = await loop.run_in_executor(srv.preview_thread, srv.pool.preview, markdown, exercise)
        finally:
            srv.previews -= 1
        if not reply.get("ok"):
            return _error(503, reply.get("reason", "preview unavailable"))
        return JSONResponse({"html": reply["html"]})

    async def openapi(request: Request):
        return JSONResponse(schema(request.app.router.routes))

    # -- the student's pages
    async def student_page(request: Request):
        if settings.roster is not None:  # students are known: each has a page of their own
            return RedirectResponse("/me", status_code=303)
        key, new = _student_key(request)
        mine = await run_in_threadpool(srv.repo.by_owner, security.digest(key)) if not new else []
        response = _page(
            "student.html",
            exercises=menu,
            default=DEFAULT,
            statement=statement_of.get(DEFAULT, "<p>Choose an exercise to see its statement.</p>"),
            csrf=srv.secrets.csrf_token(key),
            mine=mine,
            instructor=False,
        )
        return _with_key(response, key, new, request)

    async def statement_part(request: Request):
        """An exercise's statement (HTML fragment: text escaped, math sanitized MathML)."""
        identity.check_statement(srv, request, request.path_params["eid"])
        html = statement_of.get(request.path_params["eid"])
        if html is None:
            return HTMLResponse("No such exercise.", status_code=404)
        return HTMLResponse(html, headers={"cache-control": "private, max-age=300"})

    async def grade_form(request: Request):
        key = request.cookies.get(security.STUDENT_COOKIE)
        form = await request.form()
        if not srv.secrets.csrf_ok(key, form.get("csrf")):
            return HTMLResponse(
                "The form expired or did not come from this site: reload the page and try again.", status_code=403
            )
        markdown = str(form.get("markdown") or "")
        upload = form.get("upload")
        if not markdown.strip() and upload is not None and hasattr(upload, "read"):
            try:
                markdown = (await upload.read()).decode("utf-8")
            except UnicodeDecodeError:
                return HTMLResponse("The uploaded file is not UTF-8 text.", status_code=400)
        if not markdown.strip():
            return HTMLResponse("Paste or upload your derivation first.", status_code=400)
        exercise = srv.exercise_of(str(form.get("exercise") or "") or None)
        who = identity.submitter(srv, request, markdown, exercise, str(form.get("student") or ""), form=True)
        owner = key if who["student_id"] is None else None  # a known student's are theirs, not the browser's
        row, token = await srv.accept(markdown, who, owner)
        await srv.wait(row["id"], FORM_WAIT)
        key_in_url = "" if who["student_id"] else f"?t={token}"  # a known student's session opens it
        return RedirectResponse(f"/submissions/{row['id']}{key_in_url}", status_code=303)

    async def submission_page(request: Request):
        full = await run_in_threadpool(srv.repo.get, _sid(request))
        if full is None or not srv.may_see(request, full):
            return HTMLResponse("No such submission, or not yours (the link needs its token).", status_code=404)
        key, new = _student_key(request)
        response = _page(
            "submission.html",
            s=full,
            position=await run_in_threadpool(waiting.position, srv.repo, full),
            token=request.query_params.get("t", ""),
            csrf=srv.secrets.csrf_token(key),
            instructor=srv.is_instructor(request),
        )
        return _with_key(response, key, new, request)

    async def report_page(request: Request):
        full = await run_in_threadpool(srv.repo.get, _sid(request))
        if full is None or not srv.may_see(request, full) or not full.get("report_html"):
            return HTMLResponse("No report (yet) for this submission.", status_code=404)
        links = report_links(full["id"], request.query_params.get("t"), srv.is_instructor(request))
        return HTMLResponse(with_nav(full["report_html"], links))

    # -- the instructor's pages
    async def instructor_page(request: Request):
        key, new = _student_key(request)
        csrf = srv.secrets.csrf_token(key)
        if not srv.is_instructor(request):
            response = _page(
                "login.html",
                csrf=csrf,
                configured=srv.secrets.instructor_token is not None,
                failed=False,
                instructor=False,
            )
            return _with_key(response, key, new, request)
        rows = await run_in_threadpool(srv.repo.listing)
        counts = await run_in_threadpool(srv.repo.counts)
        by_student: dict[str, list] = {}
        for r in rows:
            by_student.setdefault(r["student"] or "(no name)", []).append(r)
        exercises = sorted({r["graded_as"] or r["exercise"] or "?" for r in rows})
        return _with_key(
            _page(
                "instructor.html", by_student=by_student, exercises=exercises, counts=counts, csrf=csrf, instructor=True
            ),
            key,
            new,
            request,
        )

    async def login(request: Request):
        form = await request.form()
        if not srv.secrets.csrf_ok(request.cookies.get(security.STUDENT_COOKIE), form.get("csrf")):
            return HTMLResponse("The form expired: reload the page and try again.", status_code=403)
        client = _client(request)
        wait = srv.throttle.wait(client)
        if wait > 0:
            seconds = int(wait) + 1
            return HTMLResponse(
                f"Too many wrong instructor tokens: try again in {seconds} s.",
                status_code=429,
                headers={"retry-after": str(seconds)},
            )
        if not srv.secrets.instructor_ok(str(form.get("token") or "")):
            if srv.secrets.instructor_token is not None:
                srv.throttle.failed(client)
            key, _new = _student_key(request)
            return _page(
                "login.html",
                status=403,
                csrf=srv.secrets.csrf_token(key),
                configured=srv.secrets.instructor_token is not None,
                failed=True,
                instructor=False,
            )
        response = RedirectResponse("/instructor", status_code=303)
        response.set_cookie(
            security.INSTRUCTOR_COOKIE,
            srv.secrets.new_session(),
            httponly=True,
            samesite="strict",
            secure=request.url.scheme == "https",
            max_age=security.SESSION_SECONDS,
        )
        return response

    async def logout(request: Request):
        form = await request.form()
        if not srv.secrets.csrf_ok(request.cookies.get(security.STUDENT_COOKIE), form.get("csrf")):
            return HTMLResponse("The form expired: reload the page and try again.", status_code=403)
        srv.secrets.end_session(request.cookies.get(security.INSTRUCTOR_COOKIE))
        response = RedirectResponse("/instructor", status_code=303)
        response.delete_cookie(security.INSTRUCTOR_COOKIE)
        return response

    async def retry(request: Request):
        form = await request.form()
        if not srv.secrets.csrf_ok(request.cookies.get(security.STUDENT_COOKIE), form.get("csrf")):
            return HTMLResponse("The form expired: reload the page and try again.", status_code=403)
        full = await run_in_threadpool(srv.repo.get, _sid(request))
        if full is None or not srv.may_see(request, full):
            return HTMLResponse("No such submission.", status_code=404)
        if await run_in_threadpool(srv.repo.retry, full["id"]):
            srv.pool.wake()
        back = "/instructor" if srv.is_instructor(request) else f"/submissions/{full['id']}"
        return RedirectResponse(back, status_code=303)

    async def _gradebook():
        """One row per student and exercise, by the policy of ``--policy`` (:mod:`.grades`)."""
        from .grades import gradebook

        rows = await run_in_threadpool(srv.repo.graded)
        return gradebook(rows, settings.policy, settings.roster)

    async def gradebook_csv(request: Request):
        if not srv.is_instructor(request):
            return RedirectResponse("/instructor", status_code=303)
        gb = await _gradebook()
        return Response(
            gb.to_csv(),
            media_type="text/csv; charset=utf-8",
            headers={"content-disposition": 'attachment; filename="gradebook.csv"'},
        )

    async def summary_page(request: Request):
        if not srv.is_instructor(request):
            return RedirectResponse("/instructor", status_code=303)
        from ..course import summary_html

        return HTMLResponse(with_nav(summary_html(await _gradebook()), INSTRUCTOR_LINKS))

    async def bad_request(request: Request, exc: _BadRequest):
        if request.url.path.startswith("/api/"):
            return _error(400, str(exc))
        return HTMLResponse(jinja2.utils.markupsafe.escape(str(exc)), status_code=400)

    async def database_down(request: Request, exc: sa.exc.OperationalError):
        """503 with Retry-After while the database does not answer (a restart, a full
        disk): nothing was stored by this request, the client sends it again."""
        print(
            f"armdyn serve: {request.method} {request.url.path}: database not answering: "
            f"{str(exc.orig or exc).splitlines()[0][:200]}",
            file=sys.stderr,
        )
        message = "the database is not answering (restarting?); send the same request again in a few seconds"
        if request.url.path.startswith("/api/"):
            response = _error(503, message)
        else:
            response = HTMLResponse(f"<p>{message}.</p>", status_code=503)
        response.headers["Retry-After"] = "2"
        return response

    async def refused(request: Request, exc: identity.Refused):
        if request.url.path.startswith("/api/"):
            return _error(exc.status, exc.message)
        return HTMLResponse(jinja2.utils.markupsafe.escape(exc.message), status_code=exc.status)

    async def too_large(request: Request, exc: security.BodyTooLarge):
        return _error(413, f"request body larger than {MAX_BODY} bytes")

    async def not_found(request: Request, exc: HTTPException):
        """404; a path with a trailing slash goes to the same path without it, by a
        relative ``Location`` (never built from the ``Host`` header)."""
        path = request.url.path
        if exc.status_code == 404 and len(path) > 1 and path.endswith("/") and PLAIN_PATH.match(path):
            target = "/" + path.strip("/")  # one leading slash: "//host" would leave the site
            query = request.url.query
            return RedirectResponse(target + ("?" + query if query else ""), status_code=307)
        if path.startswith("/api/"):
            return JSONResponse({"error": exc.detail}, status_code=exc.status_code, headers=exc.headers)
        return HTMLResponse(
            jinja2.utils.markupsafe.escape(exc.detail), status_code=exc.status_code, headers=exc.headers
        )

    routes = [
        Route("/", student_page),
        Route("/exercises/{eid}/statement", statement_part),
        Route("/grade", grade_form, methods=["POST"]),
        Route("/submissions/{sid}", submission_page),
        Route("/submissions/{sid}/report.html", report_page),
        Route("/instructor", instructor_page),
        Route("/instructor/login", login, methods=["POST"]),
        Route("/instructor/logout", logout, methods=["POST"]),
        Route("/instructor/retry/{sid}", retry, methods=["POST"]),
        Route("/instructor/gradebook.csv", gradebook_csv),
        Route("/instructor/summary", summary_page),
        Route("/api/health", health),
        Route("/api/grade", api_grade, methods=["POST"]),
        Route("/api/submissions/{sid}", api_submission),
        Route("/api/preview", api_preview, methods=["POST"]),
        Route("/openapi.json", openapi),
        *identity.routes(srv, web),
        *lti_web.routes(srv, web),
        Mount("/static", StaticFiles(directory=os.path.join(HERE, "static")), name="static"),
    ]

    from contextlib import asynccontextmanager

    @asynccontextmanager
    async def lifespan(app):
        await srv.startup()
        try:
            yield
        finally:
            await srv.shutdown()

    app = Starlette(
        routes=routes,
        lifespan=lifespan,
        exception_handlers={
            _BadRequest: bad_request,
            security.BodyTooLarge: too_large,
            identity.Refused: refused,
            HTTPException: not_found,
            sa.exc.OperationalError: database_down,
        },
    )
    app.router.redirect_slashes = False  # Starlette's would build an absolute URL from Host
    app.state.server = srv
    app.add_middleware(identity.Sessions, server=srv)
    app.add_middleware(security.SecurityHeaders)
    app.add_middleware(security.BodyLimit, max_bytes=MAX_BODY)
    return app
