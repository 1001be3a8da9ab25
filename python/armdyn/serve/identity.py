"""Who a student is, without an LMS: a roster, one secret personal link per student,
server-side sessions; each student's variant and deadline.

- **The roster** (``armdyn serve --roster roster.csv``): the CSV of ``armdyn exercise
  make --roster``, a header naming an ``id`` (or ``student``) column; optional columns
  ``name``, ``email`` (an LTI launch finds the student by it), ``lti_sub`` (the LMS's
  user id, when known), ``variant`` (else the variant folder named like the student,
  as ``exercise make --roster`` writes them, else the bundled exercise when no variant
  is served) and ``deadline`` (a personal extension).
- **A personal link** ``/link/<token>``: 32 random bytes, only the token's SHA-256 is
  stored (``student_links``); ``armdyn links`` issues them (and renews a leaked one).
  Opening it starts a session and redirects to ``/me``: the token does not stay in the
  address bar or the history.
- **A session**: a random cookie (``armdyn_me``, HttpOnly, SameSite=Lax so that a link
  opened from a mail works), whose SHA-256 the database keeps with the student, the
  exercise and the expiry (``student_sessions``), so it survives a restart.
- A student in a session submits to **their** exercise only: a front matter naming
  another served variant is refused with a message saying which (nothing is graded
  against the wrong model); asking for another's submission, statement or variant is
  refused (404 or 403) and logged.
"""

from __future__ import annotations

import csv
import logging
import os
import re
import time
from dataclasses import dataclass
from datetime import datetime, timezone

import sqlalchemy as sa

from ..errors import ModelError
from . import security
from .exercises import DEFAULT, ID, Exercise

log = logging.getLogger("armdyn.serve")

SESSION_COOKIE = "armdyn_me"
LINK_SESSION_SECONDS = 14 * 86400  # a personal link's session (the link opens a new one)
FRONT_CHARS = 4000  # how much of a submission's start is searched for its front matter
_FRONT = re.compile(r"\A---[ \t]*\r?\n(.*?)\r?\n---", re.S)
_NAMED = re.compile(r"^(variant|robot)[ \t]*:[ \t]*([\"']?)([A-Za-z0-9][A-Za-z0-9_.-]{0,63})\2[ \t]*(?:#.*)?$", re.M)

_meta = sa.MetaData()
LINKS = sa.Table(
    "student_links",
    _meta,
    sa.Column("student_id", sa.String(64), primary_key=True),
    sa.Column("link_hash", sa.String(64)),
    sa.Column("created_at", sa.Float),
)
SESSIONS = sa.Table(
    "student_sessions",
    _meta,
    sa.Column("token_hash", sa.String(64), primary_key=True),
    sa.Column("student_id", sa.String(64)),
    sa.Column("exercise", sa.String(100)),
    sa.Column("expires_at", sa.Float),
)


@dataclass(frozen=True)
class Student:
    """One roster row."""

    id: str
    name: str
    email: str
    variant: str
    lti_sub: str
    deadline: float | None
    line: int


class Refused(Exception):
    """A request refused for who is asking (403/404), or for what it sends (400/409):
    the app answers ``status`` with ``message``; the reason is logged."""

    def __init__(self, status: int, message: str, why: str | None = None):
        super().__init__(message)
        self.status, self.message = status, message
        if why:
            log.warning("armdyn serve: refused (%d): %s", status, why)


# -- the roster, deadlines


def parse_when(text: str, where: str) -> float:
    """An ISO 8601 time (``2026-12-10T23:59+01:00``; no zone: UTC) as Unix seconds."""
    value = text.strip()
    try:
        when = datetime.fromisoformat(value[:-1] + "+00:00" if value.endswith("Z") else value)
    except ValueError:
        raise ModelError(
            f"not a date and time: {value[:40]!r} (write e.g. 2026-12-10T23:59+01:00)", source=where
        ) from None
    if when.tzinfo is None:
        when = when.replace(tzinfo=timezone.utc)
    return when.timestamp()


def parse_deadlines(values: list[str] | None) -> dict[str, float]:
    """``--deadline [EXERCISE=]WHEN`` (repeatable): exercise id -> Unix seconds; ``*``
    (no ``EXERCISE=``) is every exercise without a deadline of its own."""
    out: dict[str, float] = {}
    for value in values or []:
        name, _, when = value.rpartition("=") if "=" in value.split("T")[0] else ("", "", value)
        out[name or "*"] = parse_when(when, "--deadline")
    return out


def load_roster(path: str, exercises: dict[str, Exercise]) -> dict[str, Student]:
    """id -> :class:`Student` of the roster CSV at ``path``; every problem is a
    :class:`ModelError` naming the file and line."""
    try:
        with open(path, newline="", encoding="utf-8-sig") as f:
            rows = list(csv.reader(f))
    except (OSError, UnicodeDecodeError) as err:
        raise ModelError(f"cannot read the roster ({err})", source=path) from None
    if not rows:
        raise ModelError("the roster is empty (expected a header line naming an 'id' column)", source=path)
    head = [h.strip().lower() for h in rows[0]]
    key = "id" if "id" in head else "student" if "student" in head else None
    if key is None:
        raise ModelError("the roster's header names no 'id' (or 'student') column", source=f"{path}:1")
    variants = [e.id for e in exercises.values() if e.variant]
    out: dict[str, Student] = {}
    emails: dict[str, str] = {}
    for n, raw in enumerate(rows[1:], start=2):
        if not any(c.strip() for c in raw):
            continue
        cell = dict(zip(head, (c.strip() for c in raw)))
        where = f"{path}:{n}"
        sid = cell.get(key, "")
        if not ID.match(sid):
            raise ModelError(f"student id {sid[:40]!r} is not letters, digits, '.', '_', '-'", source=where)
        if sid in out:
            raise ModelError(f"duplicate id '{sid}' (first on line {out[sid].line})", source=where)
        variant = cell.get("variant") or (sid if sid in exercises else None) or (None if variants else DEFAULT)
        if variant is None:
            raise ModelError(
                f"student '{sid}' has no variant: no 'variant' column and no variant folder '{sid}' "
                "among the --exercises",
                source=where,
            )
        if variant not in exercises:
            raise ModelError(f"student '{sid}': variant '{variant[:64]}' is not served", source=where)
        email = cell.get("email", "").lower()
        if email and email in emails:
            raise ModelError(f"email {email} is also student '{emails[email]}''s", source=where)
        emails[email] = sid
        deadline = parse_when(cell["deadline"], where) if cell.get("deadline") else None
        out[sid] = Student(sid, cell.get("name", ""), email, variant, cell.get("lti_sub", ""), deadline, n)
    return out


def deadline_of(settings, exercise: str | None, student: Student | None = None) -> float | None:
    """The deadline that applies: the student's own, the exercise's, or every exercise's."""
    if student is not None and student.deadline is not None:
        return student.deadline
    return settings.deadlines.get(exercise or "", settings.deadlines.get("*"))


def named_in_front_matter(markdown: str) -> list[tuple[str, str, int]]:
    """(key, value, line) of the ``variant:`` and ``robot:`` lines of a front matter,
    read by a bounded pattern (the web process never parses a student's text)."""
    head = _FRONT.match(markdown[:FRONT_CHARS])
    if head is None:
        return []
    body = head.group(1)
    return [(m.group(1), m.group(3), body.count("\n", 0, m.start()) + 2) for m in _NAMED.finditer(body)]


def front_matter_conflict(markdown: str, exercise: str, exercises: dict, whose: str) -> str | None:
    """A message when the front matter names a served exercise other than ``exercise``
    (``whose`` says where that one comes from), else None."""
    for key, value, line in named_in_front_matter(markdown):
        if value in exercises and value != exercise:
            return (
                f"line {line}: your front matter says {key}: {value}, but {whose} is '{exercise}'; nothing was "
                f"graded (a derivation of '{value}' graded against '{exercise}' would be marked wrong). Correct the "
                f"front matter to {key}: {exercise}, or remove the line"
            )
    return None


# -- links and sessions, in the database


class Store:
    """Personal links and student sessions (tables of migration 2)."""

    def __init__(self, engine: sa.Engine):
        self.engine = engine

    def issue(self, student_ids: list[str], renew: bool = False) -> dict[str, str]:
        """A new link token for each student who has none (every listed one with
        ``renew``: their old link stops working). Returns id -> token (shown once)."""
        out = {}
        with self.engine.begin() as conn:
            have = set(conn.execute(sa.select(LINKS.c.student_id)).scalars())
            for sid in student_ids:
                if sid in have and not renew:
                    continue
                token = security.new_token()
                conn.execute(LINKS.delete().where(LINKS.c.student_id == sid))
                conn.execute(
                    LINKS.insert().values(student_id=sid, link_hash=security.digest(token), created_at=time.time())
                )
                out[sid] = token
        return out

    def student_of_link(self, token: str) -> str | None:
        if not token or len(token) > 100:
            return None
        with self.engine.connect() as conn:
            return conn.execute(
                sa.select(LINKS.c.student_id).where(LINKS.c.link_hash == security.digest(token))
            ).scalar_one_or_none()

    def new_session(self, student_id: str, exercise: str, seconds: float) -> str:
        token = security.new_token()
        now = time.time()
        with self.engine.begin() as conn:
            conn.execute(SESSIONS.delete().where(SESSIONS.c.expires_at <= now))
            conn.execute(
                SESSIONS.insert().values(
                    token_hash=security.digest(token),
                    student_id=student_id,
                    exercise=exercise,
                    expires_at=now + seconds,
                )
            )
        return token

    def session(self, token: str | None) -> tuple[str, str] | None:
        """(student id, exercise) of a live session."""
        if not token or len(token) > 100:
            return None
        with self.engine.connect() as conn:
            row = conn.execute(
                sa.select(SESSIONS.c.student_id, SESSIONS.c.exercise, SESSIONS.c.expires_at).where(
                    SESSIONS.c.token_hash == security.digest(token)
                )
            ).first()
        if row is None or row.expires_at <= time.time():
            return None
        return row.student_id, row.exercise

    def end_session(self, token: str | None) -> None:
        if token:
            with self.engine.begin() as conn:
                conn.execute(SESSIONS.delete().where(SESSIONS.c.token_hash == security.digest(token)))


def set_session_cookie(response, request, token: str, seconds: float) -> None:
    response.set_cookie(
        SESSION_COOKIE,
        token,
        max_age=int(seconds),
        httponly=True,
        samesite="lax",  # a link followed from a mail or the LMS must carry it to /me
        secure=request.url.scheme == "https",
    )


def make_links(roster_path: str, db: str, base_url: str, exercises: dict, renew: list[str] | None = None) -> str:
    """``armdyn links``: issue the missing personal links (or renew the listed ones,
    ``['*']`` for all) and return them as CSV (id, name, email, variant, link); a
    student whose link was issued before is listed without it (only its hash is kept)."""
    import io

    from .storage import Repository

    roster = load_roster(roster_path, exercises)
    repo = Repository(db)
    try:
        store = Store(repo.engine)
        ids = list(roster)
        if renew:
            unknown = [r for r in renew if r != "*" and r not in roster]
            if unknown:
                raise ModelError(f"not on the roster: {', '.join(unknown)}", source=roster_path)
            fresh = store.issue(ids if "*" in renew else renew, renew=True)
            fresh.update(store.issue(ids))
        else:
            fresh = store.issue(ids)
    finally:
        repo.dispose()
    out = io.StringIO()
    w = csv.writer(out, lineterminator="\n")
    w.writerow(["id", "name", "email", "variant", "link"])
    base = base_url.rstrip("/")
    for sid, s in roster.items():
        link = f"{base}/link/{fresh[sid]}" if sid in fresh else "(issued before; renew it with --renew ID)"
        w.writerow([sid, s.name, s.email, s.variant, link])
    return out.getvalue()


# -- the web side


class Sessions:
    """ASGI middleware: the student session of a request, looked up once (in a thread)
    and left in ``request.state.student`` as ``(Student, exercise)`` or None."""

    def __init__(self, app, server):
        self.app, self.server = app, server

    async def __call__(self, scope, receive, send):
        if scope["type"] == "http":
            from starlette.concurrency import run_in_threadpool
            from starlette.requests import Request

            token = Request(scope).cookies.get(SESSION_COOKIE)
            who = None
            srv = self.server
            if token and srv.settings.roster is not None and srv.people is not None:
                try:
                    found = await run_in_threadpool(srv.people.session, token)
                except sa.exc.OperationalError:  # the database away: the route's own query answers 503
                    found = None
                if found is not None and found[0] in srv.settings.roster:
                    who = (srv.settings.roster[found[0]], found[1])
            scope.setdefault("state", {})["student"] = who
        await self.app(scope, receive, send)


def current(request) -> tuple[Student, str] | None:
    """(student, exercise) of the request's session (see :class:`Sessions`)."""
    return getattr(request.state, "student", None)


def owns(request, row: dict) -> bool:
    """Is ``row`` a submission of the session's student? (a student asking for another's
    is logged)"""
    who = current(request)
    if who is None or not row.get("student_id"):
        return False
    if row["student_id"] == who[0].id:
        return True
    log.warning("armdyn serve: student %s asked for submission %s of another student", who[0].id, row["id"])
    return False


def submitter(srv, request, markdown: str, requested: str | None, typed: str, form: bool) -> dict:
    """Who submits and to which exercise: ``{exercise, student, student_id, late}``.

    A student in a session submits to the session's exercise (another one asked for:
    403; a front matter naming another served exercise: 409, nothing stored). Without
    a session, a server with a roster takes submissions from the instructor only (401);
    without a roster, the typed name and the exercise asked for (from the page's menu,
    a front matter naming another exercise is refused too: the menu must not silently
    win)."""
    settings = srv.settings
    who = current(request)
    if who is not None:
        student, exercise = who
        if requested and requested != exercise:
            raise Refused(
                403,
                f"your exercise is '{exercise}': you cannot submit to '{requested}'",
                f"student {student.id} tried to submit to exercise {requested}",
            )
        clash = front_matter_conflict(markdown, exercise, settings.exercises, "your exercise (the roster's)")
        if clash:
            raise Refused(409, clash, f"student {student.id}: front matter names another exercise than {exercise}")
        deadline = deadline_of(settings, exercise, student)
        late = None if deadline is None else time.time() > deadline
        return {"exercise": exercise, "student": student.name or student.id, "student_id": student.id, "late": late}
    if settings.roster is not None and not srv.is_instructor(request):
        raise Refused(
            401,
            "this course knows its students: open your personal link (or the course's page in the LMS) first",
            "a submission without a student session on a server with a roster",
        )
    if form and requested:
        clash = front_matter_conflict(markdown, requested, settings.exercises, "the exercise chosen on the page")
        if clash:
            raise Refused(409, clash + " (or choose 'as my front matter says')")
    deadline = deadline_of(settings, requested)
    late = None if deadline is None else time.time() > deadline
    return {"exercise": requested, "student": typed, "student_id": None, "late": late}


def may_preview(srv, request, exercise: str | None) -> str | None:
    """The exercise a preview may read against: a student in a session, theirs only
    (another's: 403, logged); with a roster, nobody without a session but the instructor."""
    who = current(request)
    if who is not None:
        if exercise and exercise != who[1]:
            raise Refused(403, "this is not your exercise", f"student {who[0].id} asked for a preview of {exercise}")
        return who[1]
    if srv.settings.roster is not None and not srv.is_instructor(request):
        raise Refused(401, "open your personal link first", "a preview without a student session")
    return exercise


def check_statement(srv, request, wanted: str) -> None:
    """With a roster, a student sees only their own exercise's statement: :class:`Refused`
    (404 without a session, 403 for another's) otherwise; instructors see every one."""
    if srv.settings.roster is None or srv.is_instructor(request):
        return
    who = current(request)
    if who is None:
        raise Refused(404, "no such statement", f"statement of {wanted[:64]} asked without a session")
    if wanted != who[1]:
        raise Refused(403, "this is not your exercise", f"student {who[0].id} asked for the statement of {wanted[:64]}")


def statement_path(exercise: Exercise | None) -> str | None:
    """The variant's ``problem.html`` (written by ``armdyn exercise make``), if any."""
    if exercise is None or not exercise.variant:
        return None
    path = os.path.join(os.path.dirname(exercise.source), "problem.html")
    return path if os.path.isfile(path) else None


def routes(srv, web) -> list:
    """The personal link, the student's page and statement, logging out (``web``: the
    app's page helpers ``page``, ``student_key``, ``with_key``)."""
    from starlette.concurrency import run_in_threadpool
    from starlette.responses import FileResponse, HTMLResponse, RedirectResponse
    from starlette.routing import Route

    failed_links = security.Throttle(per_client=20, overall=200)

    async def open_link(request):
        client = request.client.host if request.client else "?"
        if srv.settings.roster is None or failed_links.wait(client) > 0:
            log.warning("armdyn serve: personal link refused from %s (no roster, or too many wrong links)", client)
            return HTMLResponse("No such link.", status_code=404)
        sid = await run_in_threadpool(srv.people.student_of_link, request.path_params["token"])
        if sid is None or sid not in srv.settings.roster:
            failed_links.failed(client)
            log.warning("armdyn serve: a wrong or renewed personal link from %s", client)
            return HTMLResponse(
                "This link is not (or no longer) valid: ask your instructor for your current one.", status_code=404
            )
        student = srv.settings.roster[sid]
        token = await run_in_threadpool(srv.people.new_session, sid, student.variant, LINK_SESSION_SECONDS)
        response = RedirectResponse("/me", status_code=303)  # the token leaves the address bar
        set_session_cookie(response, request, token, LINK_SESSION_SECONDS)
        return response

    async def me(request):
        who = current(request)
        if who is None:
            return web.page("me.html", status=401, student=None, instructor=False)
        student, exercise = who
        if exercise not in srv.settings.exercises:  # the server restarted without it
            return HTMLResponse(f"Your exercise '{exercise}' is not served any more: ask your instructor.", 404)
        key, new = web.student_key(request)
        mine = await run_in_threadpool(srv.repo.by_student, student.id)
        deadline = deadline_of(srv.settings, exercise, student)
        finished = [r for r in mine if r["status"] == "done" and r["graded_as"] == exercise]
        counted = None
        if finished:
            from .grades import counted as counted_of

            full = [await run_in_threadpool(srv.repo.get, r["id"]) for r in finished]
            pick, points, out_of = counted_of(full, srv.settings.policy, srv.settings.exercises, exercise)
            counted = {"id": pick["id"], "score": (points, out_of)}
        response = web.page(
            "me.html",
            student=student,
            exercise=srv.settings.exercises.get(exercise),
            statement=statement_path(srv.settings.exercises.get(exercise)) is not None,
            statement_html=web.statement_of.get(exercise, ""),
            deadline=deadline,
            past_deadline=deadline is not None and time.time() > deadline,
            policy=srv.settings.policy,
            counted=counted,
            mine=mine,
            csrf=srv.secrets.csrf_token(key),
            instructor=False,
        )
        return web.with_key(response, key, new, request)

    async def statement(request):
        """The student's own statement, the variant's whole problem.html (the drawing included)."""
        who = current(request)
        if who is None:
            raise Refused(404, "no such statement", "a statement asked without a session")
        path = statement_path(srv.settings.exercises.get(who[1]))
        if path is None:
            return HTMLResponse("No statement for this exercise.", status_code=404)
        return FileResponse(path, media_type="text/html; charset=utf-8")

    async def leave(request):
        form = await request.form()
        if not srv.secrets.csrf_ok(request.cookies.get(security.STUDENT_COOKIE), form.get("csrf")):
            return HTMLResponse("The form expired: reload the page and try again.", status_code=403)
        await run_in_threadpool(srv.people.end_session, request.cookies.get(SESSION_COOKIE))
        response = RedirectResponse("/me", status_code=303)
        response.delete_cookie(SESSION_COOKIE)
        return response

    return [
        Route("/link/{token}", open_link),
        Route("/me", me),
        Route("/me/logout", leave, methods=["POST"]),
        Route("/me/statement", statement),
    ]
