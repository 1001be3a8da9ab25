"""The server's state: what ``armdyn serve`` was started with, and what the routes share.

:class:`Settings` holds the command line's choices; :class:`Server` the database, the
grading pool, the requests waiting for a verdict, and who may see what (instructor
session or token, a submission's link token, its owner).
"""

from __future__ import annotations

import asyncio
import hashlib
import time
from concurrent.futures import ThreadPoolExecutor
from dataclasses import dataclass, field

import sqlalchemy as sa
from starlette.concurrency import run_in_threadpool
from starlette.requests import Request

from . import identity, security
from .exercises import Exercise
from .helpers import BadRequest, client_address, no_nul
from .pool import Pool
from .storage import DONE, FAILED, Repository


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
        no_nul(markdown, "the derivation")
        no_nul(who["student"], "the student name")
        token = security.new_token()
        owner = security.digest(owner_key) if owner_key else None
        fields = {**who, "student": who["student"].strip(), "owner_hash": owner}
        key = await run_in_threadpool(self.grading_key, who.get("exercise"))
        row = await run_in_threadpool(
            lambda: self.repo.add(security.new_id(), security.digest(token), markdown, key=key, **fields)
        )
        if row["status"] != DONE:
            self.pool.wake()
        return row, token

    def grading_key(self, exercise: str | None) -> str:
        """What a verdict depends on besides the text: the grader's version and, for a
        variant, its model file as it is now (an instructor who corrects a variant's model
        gets identical texts graded again, not the old verdict back)."""
        from .. import __version__
        from ..errors import ModelError
        from ..io.textfile import read_bytes

        ex = self.settings.exercises.get(exercise or "")
        model = ""
        if ex is not None and ex.variant:
            try:
                model = hashlib.sha256(read_bytes(ex.source, "model", 4_000_000)).hexdigest()
            except ModelError:
                model = "unreadable"
        return f"{__version__}:{model}"

    # -- who may see what
    def is_instructor(self, request: Request) -> bool:
        """A live instructor session, or the instructor token as ``Bearer`` (a wrong one
        counts as a failed login, and is not even compared while its client is throttled)."""
        if self.secrets.session_ok(request.cookies.get(security.INSTRUCTOR_COOKIE)):
            return True
        auth = request.headers.get("authorization", "")
        if not auth.startswith("Bearer ") or self.secrets.instructor_token is None:
            return False
        client = client_address(request)
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
            raise BadRequest(
                f"unknown exercise '{value[:64]}': this server grades " + ", ".join(sorted(self.settings.exercises))
            )
        return value
