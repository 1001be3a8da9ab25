"""The instructor's pages: login and logout, the submissions, a retry, the gradebook, the summary.

``/instructor``, ``POST /instructor/login``, ``/instructor/logout``,
``/instructor/retry/{id}``, ``/instructor/gradebook.csv`` and ``/instructor/summary``;
the route table itself is in :func:`.app.build_app`.
"""

from __future__ import annotations

from starlette.concurrency import run_in_threadpool
from starlette.requests import Request
from starlette.responses import HTMLResponse, RedirectResponse, Response

from . import security
from .helpers import client_address, page, student_key, submission_id, with_key
from .pages import INSTRUCTOR_LINKS, with_nav
from .state import Server


class InstructorPages:
    """The instructor's endpoints, on the state of ``srv``."""

    def __init__(self, srv: Server):
        self.srv = srv
        self.settings = srv.settings

    async def instructor_page(self, request: Request):
        key, new = student_key(request)
        csrf = self.srv.secrets.csrf_token(key)
        if not self.srv.is_instructor(request):
            response = page(
                "login.html",
                csrf=csrf,
                configured=self.srv.secrets.instructor_token is not None,
                failed=False,
                instructor=False,
            )
            return with_key(response, key, new, request)
        rows = await run_in_threadpool(self.srv.repo.listing)
        counts = await run_in_threadpool(self.srv.repo.counts)
        by_student: dict[str, list] = {}
        for r in rows:
            by_student.setdefault(r["student"] or "(no name)", []).append(r)
        exercises = sorted({r["graded_as"] or r["exercise"] or "?" for r in rows})
        return with_key(
            page(
                "instructor.html", by_student=by_student, exercises=exercises, counts=counts, csrf=csrf, instructor=True
            ),
            key,
            new,
            request,
        )

    async def login(self, request: Request):
        form = await request.form()
        if not self.srv.secrets.csrf_ok(request.cookies.get(security.STUDENT_COOKIE), form.get("csrf")):
            return HTMLResponse("The form expired: reload the page and try again.", status_code=403)
        client = client_address(request)
        wait = self.srv.throttle.wait(client)
        if wait > 0:
            seconds = int(wait) + 1
            return HTMLResponse(
                f"Too many wrong instructor tokens: try again in {seconds} s.",
                status_code=429,
                headers={"retry-after": str(seconds)},
            )
        if not self.srv.secrets.instructor_ok(str(form.get("token") or "")):
            if self.srv.secrets.instructor_token is not None:
                self.srv.throttle.failed(client)
            key, _new = student_key(request)
            return page(
                "login.html",
                status=403,
                csrf=self.srv.secrets.csrf_token(key),
                configured=self.srv.secrets.instructor_token is not None,
                failed=True,
                instructor=False,
            )
        response = RedirectResponse("/instructor", status_code=303)
        response.set_cookie(
            security.INSTRUCTOR_COOKIE,
            self.srv.secrets.new_session(),
            httponly=True,
            samesite="strict",
            secure=request.url.scheme == "https",
            max_age=security.SESSION_SECONDS,
        )
        return response

    async def logout(self, request: Request):
        form = await request.form()
        if not self.srv.secrets.csrf_ok(request.cookies.get(security.STUDENT_COOKIE), form.get("csrf")):
            return HTMLResponse("The form expired: reload the page and try again.", status_code=403)
        self.srv.secrets.end_session(request.cookies.get(security.INSTRUCTOR_COOKIE))
        response = RedirectResponse("/instructor", status_code=303)
        response.delete_cookie(security.INSTRUCTOR_COOKIE)
        return response

    async def retry(self, request: Request):
        form = await request.form()
        if not self.srv.secrets.csrf_ok(request.cookies.get(security.STUDENT_COOKIE), form.get("csrf")):
            return HTMLResponse("The form expired: reload the page and try again.", status_code=403)
        full = await run_in_threadpool(self.srv.repo.get, submission_id(request))
        if full is None or not self.srv.may_see(request, full):
            return HTMLResponse("No such submission.", status_code=404)
        if await run_in_threadpool(self.srv.repo.retry, full["id"]):
            self.srv.pool.wake()
        back = "/instructor" if self.srv.is_instructor(request) else f"/submissions/{full['id']}"
        return RedirectResponse(back, status_code=303)

    async def _gradebook(self):
        """One row per student and exercise, by the policy of ``--policy`` (:mod:`.grades`)."""
        from .grades import gradebook

        rows = await run_in_threadpool(self.srv.repo.graded)
        return gradebook(rows, self.settings.policy, self.settings.roster, self.settings.exercises)

    async def gradebook_csv(self, request: Request):
        if not self.srv.is_instructor(request):
            return RedirectResponse("/instructor", status_code=303)
        gb = await self._gradebook()
        return Response(
            gb.to_csv(),
            media_type="text/csv; charset=utf-8",
            headers={"content-disposition": 'attachment; filename="gradebook.csv"'},
        )

    async def summary_page(self, request: Request):
        if not self.srv.is_instructor(request):
            return RedirectResponse("/instructor", status_code=303)
        from ..course import summary_html

        return HTMLResponse(with_nav(summary_html(await self._gradebook()), INSTRUCTOR_LINKS))
