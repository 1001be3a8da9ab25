"""The web application (Starlette): the student's page, the instructor's page, the JSON API.

Routes (the JSON API is described in :mod:`.openapi`, served at ``/openapi.json``):

    GET  /                               student page: exercise, text, live preview, Grade, earlier ones
    POST /grade                          the student's form (CSRF) -> /submissions/{id}?t=TOKEN
    GET  /submissions/{id}               the submission and its report (link token, owner or instructor)
    GET  /submissions/{id}/report.html   the self-contained report (``armdyn grade --html``)
    GET  /instructor                     login, or submissions by student and exercise
    POST /instructor/login, /instructor/logout, /instructor/retry/{id}
    GET  /instructor/gradebook.csv       the gradebook (armdyn.course)
    GET  /instructor/summary             the class summary page (armdyn.course)
    GET  /api/health, POST /api/grade, GET /api/submissions/{id}, POST /api/preview

The web process stores and serves; it never reads a student's LaTeX itself: grading
and previews go to worker processes (:mod:`.pool`).
"""

from __future__ import annotations

import asyncio
import json
import os
import time
from dataclasses import dataclass, field

import jinja2
from starlette.applications import Starlette
from starlette.concurrency import run_in_threadpool
from starlette.requests import Request
from starlette.responses import HTMLResponse, JSONResponse, RedirectResponse, Response
from starlette.routing import Mount, Route
from starlette.staticfiles import StaticFiles

from . import security
from .exercises import DEFAULT, Exercise, ordered
from .openapi import schema
from .pool import Pool
from .storage import DONE, FAILED, Repository

HERE = os.path.dirname(os.path.abspath(__file__))
MAX_BODY = 1_000_000  # bytes of a request; a derivation is a few kB
MAX_PREVIEW = 200_000  # bytes of text a preview reads
FORM_WAIT = 20.0  # seconds the Grade button waits for the verdict before showing "queued"
API_WAIT = 30.0  # default ?wait= of POST /api/grade


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
        self.repo: Repository | None = None
        self.pool: Pool | None = None
        self.loop: asyncio.AbstractEventLoop | None = None
        self.waiters: dict[str, asyncio.Event] = {}

    # -- life cycle (the app's lifespan)
    async def startup(self) -> None:
        self.loop = asyncio.get_running_loop()
        s = self.settings
        self.repo = await run_in_threadpool(Repository, s.db, s.max_attempts)
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

    def _done_from_thread(self, ids: list[str]) -> None:
        if self.loop is not None:
            self.loop.call_soon_threadsafe(self._wake, ids)

    def _wake(self, ids: list[str]) -> None:
        for sid in ids:
            ev = self.waiters.pop(sid, None)
            if ev is not None:
                ev.set()

    async def wait(self, sid: str, seconds: float) -> dict:
        """The submission's summary once done/failed, or after ``seconds``."""
        deadline = time.monotonic() + max(0.0, seconds)
        while True:
            ev = self.waiters.setdefault(sid, asyncio.Event())
            row = await run_in_threadpool(self.repo.summary, sid)
            left = deadline - time.monotonic()
            if row is None or row["status"] in (DONE, FAILED) or left <= 0:
                return row
            try:
                await asyncio.wait_for(ev.wait(), min(left, 2.0))
            except asyncio.TimeoutError:
                pass

    async def accept(self, markdown: str, exercise: str | None, student: str, owner_key: str | None) -> tuple:
        """Store a submission; returns (summary row, secret link token)."""
        token = security.new_token()
        owner = security.digest(owner_key) if owner_key else None
        row = await run_in_threadpool(
            self.repo.add, security.new_id(), security.digest(token), markdown, exercise, student.strip(), owner
        )
        if row["status"] != DONE:
            self.pool.wake()
        return row, token

    # -- who may see what
    def is_instructor(self, request: Request) -> bool:
        if self.secrets.instructor_cookie_ok(request.cookies.get(security.INSTRUCTOR_COOKIE)):
            return True
        auth = request.headers.get("authorization", "")
        return auth.startswith("Bearer ") and self.secrets.instructor_ok(auth[7:])

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
        return self.is_instructor(request)

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

    async def health(request: Request):
        ready = srv.pool is not None and srv.pool.ready
        counts = await run_in_threadpool(srv.repo.counts) if srv.repo is not None else {}
        body = {"status": "ok" if ready else "starting", "workers": settings.workers, "queue": counts}
        if srv.is_instructor(request) and srv.pool is not None:
            body["worker_pids"] = srv.pool.pids()
        return JSONResponse(body, status_code=200 if ready else 503)

    async def api_grade(request: Request):
        q = request.query_params
        exercise = srv.exercise_of(q.get("robot") or q.get("variant") or q.get("exercise"))
        markdown = await _text_body(request)
        try:
            wait = min(120.0, max(0.0, float(q.get("wait", API_WAIT))))
        except ValueError:
            raise _BadRequest("wait must be a number of seconds") from None
        row, token = await srv.accept(markdown, exercise, q.get("student", ""), None)
        row = await srv.wait(row["id"], wait) if row["status"] not in (DONE, FAILED) else row
        full = await run_in_threadpool(srv.repo.get, row["id"])
        body = _api_view(row, full)
        body.update(token=token, url=f"/submissions/{row['id']}?t={token}")
        return JSONResponse(body, status_code=200 if row["status"] in (DONE, FAILED) else 202)

    async def api_submission(request: Request):
        full = await run_in_threadpool(srv.repo.get, request.path_params["sid"])
        if full is None or not srv.may_see(request, full):
            return _error(404, "no such submission (or not yours: give its token as ?t=)")
        return JSONResponse(_api_view(full, full))

    async def api_preview(request: Request):
        markdown = await _text_body(request)
        if len(markdown.encode()) > MAX_PREVIEW:
            return _error(413, f"a preview reads at most {MAX_PREVIEW} bytes")
        exercise = srv.exercise_of(request.query_params.get("exercise"))
        reply = await run_in_threadpool(srv.pool.preview, markdown, exercise)
        if not reply.get("ok"):
            return _error(503, reply.get("reason", "preview unavailable"))
        return JSONResponse({"html": reply["html"]})

    async def openapi(request: Request):
        return JSONResponse(schema())

    # -- the student's pages
    async def student_page(request: Request):
        key, new = _student_key(request)
        mine = await run_in_threadpool(srv.repo.by_owner, security.digest(key)) if not new else []
        response = _page(
            "student.html",
            exercises=menu,
            default=DEFAULT,
            csrf=srv.secrets.csrf_token(key),
            mine=mine,
            instructor=False,
        )
        return _with_key(response, key, new, request)

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
        row, token = await srv.accept(markdown, exercise, str(form.get("student") or ""), key)
        await srv.wait(row["id"], FORM_WAIT)
        return RedirectResponse(f"/submissions/{row['id']}?t={token}", status_code=303)

    async def submission_page(request: Request):
        full = await run_in_threadpool(srv.repo.get, request.path_params["sid"])
        if full is None or not srv.may_see(request, full):
            return HTMLResponse("No such submission, or not yours (the link needs its token).", status_code=404)
        key, new = _student_key(request)
        response = _page(
            "submission.html",
            s=full,
            token=request.query_params.get("t", ""),
            csrf=srv.secrets.csrf_token(key),
            instructor=srv.is_instructor(request),
        )
        return _with_key(response, key, new, request)

    async def report_page(request: Request):
        full = await run_in_threadpool(srv.repo.get, request.path_params["sid"])
        if full is None or not srv.may_see(request, full) or not full.get("report_html"):
            return HTMLResponse("No report (yet) for this submission.", status_code=404)
        return HTMLResponse(full["report_html"])

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
        if not srv.secrets.instructor_ok(str(form.get("token") or "")):
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
            srv.secrets.instructor_cookie(),
            httponly=True,
            samesite="strict",
            secure=request.url.scheme == "https",
            max_age=12 * 3600,
        )
        return response

    async def logout(request: Request):
        form = await request.form()
        if not srv.secrets.csrf_ok(request.cookies.get(security.STUDENT_COOKIE), form.get("csrf")):
            return HTMLResponse("The form expired: reload the page and try again.", status_code=403)
        response = RedirectResponse("/instructor", status_code=303)
        response.delete_cookie(security.INSTRUCTOR_COOKIE)
        return response

    async def retry(request: Request):
        form = await request.form()
        if not srv.secrets.csrf_ok(request.cookies.get(security.STUDENT_COOKIE), form.get("csrf")):
            return HTMLResponse("The form expired: reload the page and try again.", status_code=403)
        full = await run_in_threadpool(srv.repo.get, request.path_params["sid"])
        if full is None or not srv.may_see(request, full):
            return HTMLResponse("No such submission.", status_code=404)
        if await run_in_threadpool(srv.repo.retry, full["id"]):
            srv.pool.wake()
        back = "/instructor" if srv.is_instructor(request) else f"/submissions/{full['id']}"
        return RedirectResponse(back, status_code=303)

    async def _gradebook():
        from ..course import Gradebook

        rows = await run_in_threadpool(srv.repo.graded)
        items = [
            (
                r["student"] or "(no name)",
                r["graded_as"] or r["exercise"],
                json.loads(r["report_json"]) if r["report_json"] else None,
                None
                if r["report_json"]
                else (("failed: " if r["status"] == FAILED else "") + (r["error"] or "no verdict")),
            )
            for r in rows
        ]
        return Gradebook.from_results(items)

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

        return HTMLResponse(summary_html(await _gradebook()))

    async def bad_request(request: Request, exc: _BadRequest):
        if request.url.path.startswith("/api/"):
            return _error(400, str(exc))
        return HTMLResponse(jinja2.utils.markupsafe.escape(str(exc)), status_code=400)

    async def too_large(request: Request, exc: security.BodyTooLarge):
        return _error(413, f"request body larger than {MAX_BODY} bytes")

    routes = [
        Route("/", student_page),
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
        exception_handlers={_BadRequest: bad_request, security.BodyTooLarge: too_large},
    )
    app.state.server = srv
    app.add_middleware(security.SecurityHeaders)
    app.add_middleware(security.BodyLimit, max_bytes=MAX_BODY)
    return app
