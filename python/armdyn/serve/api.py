"""The JSON API's handlers: health, grading a derivation, a submission, a live preview.

``/api/health``, ``POST /api/grade``, ``/api/submissions/{id}``, ``POST /api/preview``
and ``/openapi.json`` (the document :mod:`.openapi` builds from the app's route table);
the route table itself is in :func:`.app.build_app`.
"""

from __future__ import annotations

import asyncio

from starlette.concurrency import run_in_threadpool
from starlette.requests import Request
from starlette.responses import JSONResponse, Response

from . import identity, waiting
from .helpers import BadRequest, api_view, json_error, submission_id, text_body
from .openapi import schema
from .state import Server
from .storage import DONE, FAILED

MAX_PREVIEW = 200_000  # bytes of text a preview reads
API_WAIT = 30.0  # default ?wait= of POST /api/grade
PREVIEW_SLOTS = 4  # previews running or waiting per server; past it 503 + Retry-After
PREVIEW_RETRY = 2  # seconds, the Retry-After of a preview refused for load


class ApiHandlers:
    """The API's endpoints, on the state of ``srv``."""

    def __init__(self, srv: Server):
        self.srv = srv
        self.settings = srv.settings

    async def health(self, request: Request):
        """ok (200); starting, or degraded with its ``problems`` (503): a grading thread
        ended or stuck, a queue that does not move, the database away."""
        ready = self.srv.pool is not None and self.srv.pool.ready
        problems = []
        try:
            counts = await run_in_threadpool(self.srv.repo.counts) if self.srv.repo is not None else {}
        except Exception as err:  # noqa: BLE001 - any database failure is what health must tell
            counts = {}
            problems.append(f"the database does not answer ({type(err).__name__})")
        if ready:
            problems += self.srv.pool.problems(counts.get("queued", 0))
        status = "starting" if not ready else "degraded" if problems else "ok"
        body = {"status": status, "workers": self.settings.workers, "queue": counts}
        if problems:
            body["problems"] = problems
        if self.srv.is_instructor(request) and self.srv.pool is not None:
            body["worker_pids"] = self.srv.pool.pids()
        return JSONResponse(body, status_code=200 if status == "ok" else 503)

    async def api_grade(self, request: Request):
        q = request.query_params
        exercise = self.srv.exercise_of(q.get("robot") or q.get("variant") or q.get("exercise"))
        markdown = await text_body(request)
        try:
            wait = min(120.0, max(0.0, float(q.get("wait", API_WAIT))))
        except ValueError:
            raise BadRequest("wait must be a number of seconds") from None
        who = identity.submitter(self.srv, request, markdown, exercise, q.get("student", ""), form=False)
        row, token = await self.srv.accept(markdown, who, None)
        row = await self.srv.wait(row["id"], wait) if row["status"] not in (DONE, FAILED) else row
        full = await run_in_threadpool(self.srv.repo.get, row["id"])
        body = api_view(row, full)
        body.update(token=token, url=f"/submissions/{row['id']}?t={token}")
        return JSONResponse(body, status_code=200 if row["status"] in (DONE, FAILED) else 202)

    async def api_submission(self, request: Request):
        full = await run_in_threadpool(self.srv.repo.get, submission_id(request))
        if full is None or not self.srv.may_see(request, full):
            return json_error(404, "no such submission (or not yours: give its token as ?t=)")
        return JSONResponse(await run_in_threadpool(waiting.with_position, self.srv.repo, full, api_view(full, full)))

    async def api_preview(self, request: Request):
        """One preview worker, at most :data:`PREVIEW_SLOTS` previews running or waiting
        (more: 503 with Retry-After, before their body is read); one whose client has
        left is dropped unmade."""
        if self.srv.previews >= PREVIEW_SLOTS:
            busy = json_error(503, f"too many previews at once; try again in {PREVIEW_RETRY} s")
            busy.headers["retry-after"] = str(PREVIEW_RETRY)
            return busy
        self.srv.previews += 1
        try:
            markdown = await text_body(request)
            if len(markdown.encode()) > MAX_PREVIEW:
                return json_error(413, f"a preview reads at most {MAX_PREVIEW} bytes")
            exercise = identity.may_preview(
                self.srv, request, self.srv.exercise_of(request.query_params.get("exercise"))
            )
            async with self.srv.preview_lock:
                if await request.is_disconnected():
                    return Response(status_code=204)  # nobody reads it: do not make it
                loop = asyncio.get_running_loop()
                reply = await loop.run_in_executor(self.srv.preview_thread, self.srv.pool.preview, markdown, exercise)
        finally:
            self.srv.previews -= 1
        if not reply.get("ok"):
            return json_error(503, reply.get("reason", "preview unavailable"))
        return JSONResponse({"html": reply["html"]})

    async def openapi(self, request: Request):
        return JSONResponse(schema(request.app.router.routes))
