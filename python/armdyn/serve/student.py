"""The student's pages: the exercise page, a statement, the Grade form, a submission, its report.

``/``, ``/exercises/{eid}/statement``, ``POST /grade``, ``/submissions/{id}`` and
``/submissions/{id}/report.html``; the route table itself is in :func:`.app.build_app`.
"""

from __future__ import annotations

from starlette.concurrency import run_in_threadpool
from starlette.requests import Request
from starlette.responses import HTMLResponse, RedirectResponse

from . import identity, security, waiting
from .exercises import DEFAULT, ordered
from .helpers import page, student_key, submission_id, with_key
from .pages import report_links, with_nav
from .state import Server
from .statement import statements

FORM_WAIT = 20.0  # seconds the Grade button waits for the verdict before showing "queued"


class StudentPages:
    """The student's endpoints, on the state of ``srv``."""

    def __init__(self, srv: Server):
        self.srv = srv
        self.settings = srv.settings
        self.menu = ordered(srv.settings.exercises)
        self.statement_of = statements(srv.settings.exercises)

    async def student_page(self, request: Request):
        if self.settings.roster is not None:  # students are known: each has a page of their own
            return RedirectResponse("/me", status_code=303)
        key, new = student_key(request)
        mine = await run_in_threadpool(self.srv.repo.by_owner, security.digest(key)) if not new else []
        response = page(
            "student.html",
            exercises=self.menu,
            default=DEFAULT,
            statement=self.statement_of.get(DEFAULT, "<p>Choose an exercise to see its statement.</p>"),
            csrf=self.srv.secrets.csrf_token(key),
            mine=mine,
            instructor=False,
        )
        return with_key(response, key, new, request)

    async def statement_part(self, request: Request):
        """An exercise's statement (HTML fragment: text escaped, math sanitized MathML)."""
        identity.check_statement(self.srv, request, request.path_params["eid"])
        html = self.statement_of.get(request.path_params["eid"])
        if html is None:
            return HTMLResponse("No such exercise.", status_code=404)
        return HTMLResponse(html, headers={"cache-control": "private, max-age=300"})

    async def grade_form(self, request: Request):
        key = request.cookies.get(security.STUDENT_COOKIE)
        form = await request.form()
        if not self.srv.secrets.csrf_ok(key, form.get("csrf")):
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
        exercise = self.srv.exercise_of(str(form.get("exercise") or "") or None)
        who = identity.submitter(self.srv, request, markdown, exercise, str(form.get("student") or ""), form=True)
        owner = key if who["student_id"] is None else None  # a known student's are theirs, not the browser's
        row, token = await self.srv.accept(markdown, who, owner)
        await self.srv.wait(row["id"], FORM_WAIT)
        key_in_url = "" if who["student_id"] else f"?t={token}"  # a known student's session opens it
        return RedirectResponse(f"/submissions/{row['id']}{key_in_url}", status_code=303)

    async def submission_page(self, request: Request):
        full = await run_in_threadpool(self.srv.repo.get, submission_id(request))
        if full is None or not self.srv.may_see(request, full):
            return HTMLResponse("No such submission, or not yours (the link needs its token).", status_code=404)
        key, new = student_key(request)
        response = page(
            "submission.html",
            s=full,
            position=await run_in_threadpool(waiting.position, self.srv.repo, full),
            token=request.query_params.get("t", ""),
            csrf=self.srv.secrets.csrf_token(key),
            instructor=self.srv.is_instructor(request),
        )
        return with_key(response, key, new, request)

    async def report_page(self, request: Request):
        full = await run_in_threadpool(self.srv.repo.get, submission_id(request))
        if full is None or not self.srv.may_see(request, full) or not full.get("report_html"):
            return HTMLResponse("No report (yet) for this submission.", status_code=404)
        links = report_links(full["id"], request.query_params.get("t"), self.srv.is_instructor(request))
        return HTMLResponse(with_nav(full["report_html"], links))
