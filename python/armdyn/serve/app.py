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
The handlers are in :mod:`.api` (the JSON API), :mod:`.student` and :mod:`.instructor`
(the pages), on the state of :mod:`.state`, with what they share in :mod:`.helpers`;
this module holds the route table, the error answers and :func:`build_app`.
"""

from __future__ import annotations

import os
import re
import sys
from types import SimpleNamespace

import jinja2
import sqlalchemy as sa
from starlette.applications import Starlette
from starlette.exceptions import HTTPException
from starlette.requests import Request
from starlette.responses import HTMLResponse, JSONResponse, RedirectResponse
from starlette.routing import Mount, Route
from starlette.staticfiles import StaticFiles

from . import identity, lti_web, security
from .api import API_WAIT, MAX_PREVIEW, PREVIEW_RETRY, PREVIEW_SLOTS, ApiHandlers
from .helpers import HERE, SID, BadRequest, json_error, page, student_key, with_key
from .instructor import InstructorPages
from .state import Server, Settings
from .student import FORM_WAIT, StudentPages

__all__ = [
    "API_WAIT",
    "FORM_WAIT",
    "HERE",
    "MAX_BODY",
    "MAX_PREVIEW",
    "PLAIN_PATH",
    "PREVIEW_RETRY",
    "PREVIEW_SLOTS",
    "SID",
    "Server",
    "Settings",
    "build_app",
]

MAX_BODY = 1_000_000  # bytes of a request; a derivation is a few kB
PLAIN_PATH = re.compile(r"^[A-Za-z0-9/_.-]{1,200}$")  # a path redirected without its trailing slash


async def bad_request(request: Request, exc: BadRequest):
    if request.url.path.startswith("/api/"):
        return json_error(400, str(exc))
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
        response = json_error(503, message)
    else:
        response = HTMLResponse(f"<p>{message}.</p>", status_code=503)
    response.headers["Retry-After"] = "2"
    return response


async def refused(request: Request, exc: identity.Refused):
    if request.url.path.startswith("/api/"):
        return json_error(exc.status, exc.message)
    return HTMLResponse(jinja2.utils.markupsafe.escape(exc.message), status_code=exc.status)


async def too_large(request: Request, exc: security.BodyTooLarge):
    return json_error(413, f"request body larger than {MAX_BODY} bytes")


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
    return HTMLResponse(jinja2.utils.markupsafe.escape(exc.detail), status_code=exc.status_code, headers=exc.headers)


def build_app(settings: Settings) -> Starlette:
    """The ASGI app for ``settings`` (workers start with the app's lifespan)."""
    srv = Server(settings)
    # what identity's and LTI's pages share with these (passed: they do not import this module)
    api, student, instructor = ApiHandlers(srv), StudentPages(srv), InstructorPages(srv)
    web = SimpleNamespace(page=page, student_key=student_key, with_key=with_key, statement_of=student.statement_of)

    routes = [
        Route("/", student.student_page),
        Route("/exercises/{eid}/statement", student.statement_part),
        Route("/grade", student.grade_form, methods=["POST"]),
        Route("/submissions/{sid}", student.submission_page),
        Route("/submissions/{sid}/report.html", student.report_page),
        Route("/instructor", instructor.instructor_page),
        Route("/instructor/login", instructor.login, methods=["POST"]),
        Route("/instructor/logout", instructor.logout, methods=["POST"]),
        Route("/instructor/retry/{sid}", instructor.retry, methods=["POST"]),
        Route("/instructor/gradebook.csv", instructor.gradebook_csv),
        Route("/instructor/summary", instructor.summary_page),
        Route("/api/health", api.health),
        Route("/api/grade", api.api_grade, methods=["POST"]),
        Route("/api/submissions/{sid}", api.api_submission),
        Route("/api/preview", api.api_preview, methods=["POST"]),
        Route("/openapi.json", api.openapi),
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
            BadRequest: bad_request,
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
