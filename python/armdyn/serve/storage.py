"""Submissions in a database (SQLite file or PostgreSQL), through SQLAlchemy.

One table, ``submissions`` (schema and its versions: :mod:`.migrations`). A submission's
life: ``queued`` (accepted, on disk) -> ``running`` (a worker has it; ``attempts`` counts
the claims) -> ``done`` (a verdict, or the student's input error in ``error``) or
``failed`` (grading itself failed: timeout, memory limit, or workers killed
``max_attempts`` times). Every transition is one UPDATE guarded by the expected old
status, so a row is never claimed twice and never lost: a server that dies leaves rows
``queued`` or ``running``, and :meth:`Repository.recover` puts the running ones back in
the queue at the next start.

Identical work is done once: a submission whose exercise and text hash to those of one
already graded gets that verdict at once (``cached``), and queued twins are finished
together with the one a worker grades.
"""

from __future__ import annotations

import hashlib
import threading
import time
from dataclasses import dataclass

import sqlalchemy as sa
from sqlalchemy.orm import DeclarativeBase, Mapped, mapped_column

from .migrations import upgrade

QUEUED, RUNNING, DONE, FAILED = "queued", "running", "done", "failed"
STATUSES = (QUEUED, RUNNING, DONE, FAILED)


class Base(DeclarativeBase):
    pass


class Submission(Base):
    """One row of ``submissions`` (the columns of migration 1)."""

    __tablename__ = "submissions"
    id: Mapped[str] = mapped_column(sa.String(24), primary_key=True)
    token_hash: Mapped[str] = mapped_column(sa.String(64))
    owner_hash: Mapped[str | None] = mapped_column(sa.String(64))
    student: Mapped[str] = mapped_column(sa.String(200), default="")
    exercise: Mapped[str | None] = mapped_column(sa.String(100))
    graded_as: Mapped[str | None] = mapped_column(sa.String(100))
    markdown: Mapped[str] = mapped_column(sa.Text)
    content_hash: Mapped[str] = mapped_column(sa.String(64))
    status: Mapped[str] = mapped_column(sa.String(16))
    attempts: Mapped[int] = mapped_column(sa.Integer, default=0)
    passed: Mapped[bool | None] = mapped_column(sa.Boolean)
    first_wrong: Mapped[str | None] = mapped_column(sa.String(100))
    error: Mapped[str | None] = mapped_column(sa.Text)
    report_json: Mapped[str | None] = mapped_column(sa.Text)
    report_html: Mapped[str | None] = mapped_column(sa.Text)
    report_fragment: Mapped[str | None] = mapped_column(sa.Text)
    cached: Mapped[bool] = mapped_column(sa.Boolean, default=False)
    created_at: Mapped[float] = mapped_column(sa.Float)
    started_at: Mapped[float | None] = mapped_column(sa.Float)
    finished_at: Mapped[float | None] = mapped_column(sa.Float)
    student_id: Mapped[str | None] = mapped_column(sa.String(64))  # the roster's id (migration 2)
    late: Mapped[bool | None] = mapped_column(sa.Boolean)


T = Submission.__table__
#: the result columns a verdict fills in (copied to cache hits and queued twins)
RESULT = ("graded_as", "passed", "first_wrong", "error", "report_json", "report_html", "report_fragment")
#: the columns of a listing (no text, no report)
SUMMARY = (
    "id",
    "student",
    "exercise",
    "graded_as",
    "status",
    "attempts",
    "passed",
    "first_wrong",
    "error",
    "cached",
    "created_at",
    "started_at",
    "finished_at",
    "student_id",
    "late",
)


@dataclass
class Job:
    """A claimed submission, as a worker needs it."""

    id: str
    exercise: str | None
    markdown: str
    attempts: int


def content_hash(exercise: str | None, markdown: str, key: str = "") -> str:
    """sha256 of the exercise asked for, the text and ``key`` (what the exercise is graded
    against: its model file's digest and the grader's version): equal hashes grade alike."""
    return hashlib.sha256(f"{exercise or ''}\0{key}\0{markdown}".encode()).hexdigest()


def _engine(url: str) -> sa.Engine:
    if url.startswith("sqlite"):
        # one file shared by the request threads and the pool's threads; WAL lets
        # readers go on while a writer commits
        engine = sa.create_engine(url, connect_args={"check_same_thread": False, "timeout": 30})

        @sa.event.listens_for(engine, "connect")
        def _pragmas(dbapi_conn, _record):
            cur = dbapi_conn.cursor()
            cur.execute("PRAGMA journal_mode=WAL")
            cur.execute("PRAGMA synchronous=NORMAL")
            cur.close()

        return engine
    if url.startswith(("postgresql://", "postgres://")):
        url = "postgresql+psycopg://" + url.split("://", 1)[1]  # psycopg 3, not psycopg2
    return sa.create_engine(url, pool_pre_ping=True, pool_size=10, max_overflow=20)


class Repository:
    """All database access of the server. Thread-safe: each call is one transaction."""

    def __init__(self, url: str, max_attempts: int = 3):
        self.url = url
        self.engine = _engine(url)
        self.max_attempts = max_attempts
        self._claim_lock = threading.Lock()  # SQLite has no SKIP LOCKED; one claimer at a time
        upgrade(self.engine)

    def dispose(self) -> None:
        self.engine.dispose()

    # -- writing
    def add(
        self,
        sid: str,
        token_hash: str,
        markdown: str,
        exercise: str | None = None,
        student: str = "",
        owner_hash: str | None = None,
        student_id: str | None = None,
        late: bool | None = None,
        key: str = "",
    ) -> dict:
        """Accept a submission: stored ``queued``, or ``done`` at once when the same
        exercise (graded against the same ``key``: :func:`content_hash`) and text were
        graded before. Returns its summary row."""
        digest = content_hash(exercise, markdown, key)
        now = time.time()
        row = {
            "id": sid,
            "token_hash": token_hash,
            "owner_hash": owner_hash,
            "student": student[:200],
            "exercise": exercise,
            "markdown": markdown,
            "content_hash": digest,
            "status": QUEUED,
            "attempts": 0,
            "cached": False,
            "created_at": now,
            "student_id": student_id,
            "late": late,
        }
        with self.engine.begin() as conn:
            twin = (
                conn.execute(
                    sa.select(*(T.c[k] for k in RESULT)).where(T.c.content_hash == digest, T.c.status == DONE).limit(1)
                )
                .mappings()
                .first()
            )
            if twin is not None:
                row.update(dict(twin), status=DONE, cached=True, started_at=now, finished_at=now)
            conn.execute(T.insert().values(**row))
        return self.summary(sid)

    def claim(self) -> Job | None:
        """The oldest queued submission, now ``running`` with one more attempt (None: none queued)."""
        with self._claim_lock, self.engine.begin() as conn:
            while True:
                row = conn.execute(
                    sa.select(T.c.id, T.c.exercise, T.c.markdown, T.c.attempts)
                    .where(T.c.status == QUEUED)
                    .order_by(T.c.created_at, T.c.id)
                    .limit(1)
                ).first()
                if row is None:
                    return None
                done = conn.execute(
                    T.update()
                    .where(T.c.id == row.id, T.c.status == QUEUED)
                    .values(status=RUNNING, attempts=T.c.attempts + 1, started_at=time.time())
                )
                if done.rowcount == 1:
                    return Job(row.id, row.exercise, row.markdown, row.attempts + 1)

    def finish(self, sid: str, result: dict) -> list[str]:
        """Store a worker's result (keys of :data:`RESULT`) as ``done``, for this
        submission and its queued twins. Returns the ids it completed."""
        values = {k: result.get(k) for k in RESULT}
        now = time.time()
        with self.engine.begin() as conn:
            if not conn.execute(
                T.update().where(T.c.id == sid, T.c.status == RUNNING).values(status=DONE, finished_at=now, **values)
            ).rowcount:
                return []
            digest = conn.execute(sa.select(T.c.content_hash).where(T.c.id == sid)).scalar_one()
            twins = list(
                conn.execute(sa.select(T.c.id).where(T.c.content_hash == digest, T.c.status == QUEUED)).scalars()
            )
            if twins:
                conn.execute(
                    T.update()
                    .where(T.c.id.in_(twins), T.c.status == QUEUED)
                    .values(status=DONE, cached=True, started_at=now, finished_at=now, **values)
                )
        return [sid, *twins]

    def give_up(self, sid: str, reason: str, retry: bool) -> str:
        """A grading that did not end in a result: back to ``queued`` when ``retry`` and
        attempts remain, else ``failed`` with ``reason``. Returns the new status."""
        with self.engine.begin() as conn:
            attempts = conn.execute(sa.select(T.c.attempts).where(T.c.id == sid)).scalar_one()
            status = QUEUED if retry and attempts < self.max_attempts else FAILED
            error = reason if status == FAILED else None
            conn.execute(
                T.update()
                .where(T.c.id == sid, T.c.status == RUNNING)
                .values(status=status, error=error, finished_at=time.time() if status == FAILED else None)
            )
        return status

    def release(self, sid: str) -> None:
        """Put a running submission back in the queue without counting the attempt
        (the server is shutting down, the grading was not at fault)."""
        with self.engine.begin() as conn:
            conn.execute(
                T.update()
                .where(T.c.id == sid, T.c.status == RUNNING)
                .values(status=QUEUED, attempts=T.c.attempts - 1, started_at=None)
            )

    def recover(self) -> int:
        """At start-up: submissions left ``running`` by a server that died go back to
        the queue (or to ``failed`` once their attempts are used up). Returns how many."""
        with self.engine.begin() as conn:
            n = conn.execute(
                T.update()
                .where(T.c.status == RUNNING, T.c.attempts < self.max_attempts)
                .values(status=QUEUED, started_at=None)
            ).rowcount
            n += conn.execute(
                T.update()
                .where(T.c.status == RUNNING)
                .values(
                    status=FAILED,
                    finished_at=time.time(),
                    error=f"grading was interrupted {self.max_attempts} times (workers killed); retry",
                )
            ).rowcount
        return n

    def retry(self, sid: str) -> bool:
        """Queue a failed submission again (the instructor's or student's retry)."""
        with self.engine.begin() as conn:
            return (
                conn.execute(
                    T.update()
                    .where(T.c.id == sid, T.c.status == FAILED)
                    .values(status=QUEUED, attempts=0, error=None, finished_at=None)
                ).rowcount
                == 1
            )

    # -- reading
    def get(self, sid: str) -> dict | None:
        with self.engine.connect() as conn:
            row = conn.execute(sa.select(T).where(T.c.id == sid)).mappings().first()
        return dict(row) if row is not None else None

    def summary(self, sid: str) -> dict | None:
        with self.engine.connect() as conn:
            row = conn.execute(sa.select(*(T.c[k] for k in SUMMARY)).where(T.c.id == sid)).mappings().first()
        return dict(row) if row is not None else None

    def by_owner(self, owner_hash: str, limit: int = 50) -> list[dict]:
        with self.engine.connect() as conn:
            rows = (
                conn.execute(
                    sa.select(*(T.c[k] for k in SUMMARY))
                    .where(T.c.owner_hash == owner_hash)
                    .order_by(T.c.created_at.desc())
                    .limit(limit)
                )
                .mappings()
                .all()
            )
        return [dict(r) for r in rows]

    def by_student(self, student_id: str, limit: int = 200) -> list[dict]:
        """A roster student's submissions, newest first."""
        with self.engine.connect() as conn:
            rows = (
                conn.execute(
                    sa.select(*(T.c[k] for k in SUMMARY))
                    .where(T.c.student_id == student_id)
                    .order_by(T.c.created_at.desc())
                    .limit(limit)
                )
                .mappings()
                .all()
            )
        return [dict(r) for r in rows]

    def listing(self) -> list[dict]:
        """Every submission's summary, by student then time (the instructor's table)."""
        with self.engine.connect() as conn:
            rows = (
                conn.execute(sa.select(*(T.c[k] for k in SUMMARY)).order_by(T.c.student, T.c.created_at))
                .mappings()
                .all()
            )
        return [dict(r) for r in rows]

    def graded(self) -> list[dict]:
        """student, exercise, report_json, error of every finished submission (for the gradebook)."""
        cols = (
            T.c.id,
            T.c.student,
            T.c.exercise,
            T.c.graded_as,
            T.c.status,
            T.c.report_json,
            T.c.error,
            T.c.created_at,
            T.c.student_id,
            T.c.late,
        )
        with self.engine.connect() as conn:
            rows = (
                conn.execute(
                    sa.select(*cols).where(T.c.status.in_((DONE, FAILED))).order_by(T.c.student, T.c.created_at)
                )
                .mappings()
                .all()
            )
        return [dict(r) for r in rows]

    def counts(self) -> dict:
        with self.engine.connect() as conn:
            rows = conn.execute(sa.select(T.c.status, sa.func.count()).group_by(T.c.status)).all()
        out = {s: 0 for s in STATUSES}
        out.update({s: int(n) for s, n in rows})
        return out
