"""The grading processes, supervised from the web process.

Each of ``workers`` threads owns one worker process (:mod:`.worker`) and loops: claim
the oldest queued submission from the database, send it, wait for the verdict at most
``timeout`` seconds, store it. What can go wrong, and what happens:

- the student's input is bad: a verdict with ``error`` (status ``done``);
- the worker overruns the timeout or its memory limit: it is killed (a fresh one takes
  its place) and the submission is ``failed`` with the reason (a retry would overrun
  again);
- the worker dies (killed, crashed): the submission goes back to the queue, and is
  ``failed`` after ``max_attempts`` claims (see :mod:`.storage`);
- the server stops (SIGTERM): no new claims; running gradings get ``grace`` seconds,
  then their workers are killed and the submissions returned to the queue uncounted;
- the database fails (restarting, disk full, a value it refuses): the thread never
  dies of it. A write is tried ``STORE_TRIES`` times with back-off; a verdict the
  database refuses marks the submission ``failed`` with the reason; an outcome that
  cannot be written yet is kept (one per thread at most: a thread cannot claim
  meanwhile) and written once the database answers. :meth:`Pool.problems` tells an
  ended or stuck thread and a queue that does not move.

Workers start with a scrubbed environment (:func:`worker_env`): the instructor token and
the server's secret never reach the process that reads a student's text.

Previews go to one more worker of their own with a short timeout, so a preview never
waits behind gradings and the web process never parses a student's text itself.
"""

from __future__ import annotations

import json
import os
import select
import subprocess
import sys
import threading
import time

import sqlalchemy as sa

from .storage import FAILED, Repository

#: environment variables a worker inherits (everything else, the server's secrets
#: among it, stays in the web process)
WORKER_ENV = (
    *("PATH", "PYTHONPATH", "PYTHONHOME", "VIRTUAL_ENV", "LD_LIBRARY_PATH"),  # to find Python and armdyn
    *("HOME", "LANG", "LC_ALL", "LC_CTYPE", "TMPDIR", "SYMPY_CACHE_SIZE"),
)
STORE_TRIES = 4  # a database write: tried this often, with back-off 0.25, 0.5, 1 s
LOOP_BACKOFF = 2.0  # seconds a grading thread waits after its database failed
STALL_SLACK = 30.0  # seconds past the grading timeout before a quiet thread or queue counts as stuck


def worker_env(exercises: dict[str, str], memory_mb: int) -> dict[str, str]:
    """The environment of a grading worker: :data:`WORKER_ENV` and its own settings."""
    env = {k: v for k, v in os.environ.items() if k in WORKER_ENV}
    env.update(
        ARMDYN_SERVE_EXERCISES=json.dumps(exercises),
        ARMDYN_SERVE_MEMORY_MB=str(memory_mb),
        OPENBLAS_NUM_THREADS="1",
        OMP_NUM_THREADS="1",
    )
    return env


def clean_result(reply: dict) -> dict:
    """A worker's strings without NUL (PostgreSQL's text refuses it: an exercise name
    written ``rp\\0arm`` in YAML comes back in the error message as a real NUL)."""
    return {k: v.replace("\0", "\\0") if isinstance(v, str) else v for k, v in reply.items()}


class WorkerDied(RuntimeError):
    pass


class WorkerTimeout(RuntimeError):
    pass


class WorkerProcess:
    """One ``python -m armdyn.serve.worker`` and its pipes."""

    def __init__(self, exercises: dict[str, str], memory_mb: int, start_timeout: float = 120.0):
        env = worker_env(exercises, memory_mb)
        self.proc = subprocess.Popen(
            [sys.executable, "-m", "armdyn.serve.worker"],
            stdin=subprocess.PIPE,
            stdout=subprocess.PIPE,
            text=True,
            encoding="utf-8",
            env=env,
        )
        self.pid = self.proc.pid
        hello = self._read(start_timeout)
        if not hello.get("ready"):
            self.kill()
            raise WorkerDied(f"worker {self.pid} did not start: {hello}")

    def _read(self, timeout: float) -> dict:
        ready, _, _ = select.select([self.proc.stdout], [], [], timeout)
        if not ready:
            raise WorkerTimeout(f"no answer within {timeout:g} s")
        line = self.proc.stdout.readline()
        if not line:
            code = self.proc.wait()
            raise WorkerDied(f"the grading worker ended (exit {code})")
        return json.loads(line)

    def request(self, req: dict, timeout: float) -> dict:
        try:
            self.proc.stdin.write(json.dumps(req) + "\n")
            self.proc.stdin.flush()
        except (BrokenPipeError, OSError):
            code = self.proc.wait()
            raise WorkerDied(f"the grading worker ended (exit {code})") from None
        return self._read(timeout)

    def alive(self) -> bool:
        return self.proc.poll() is None

    def kill(self) -> None:
        if self.proc.poll() is None:
            self.proc.kill()
        self.proc.wait()
        for f in (self.proc.stdin, self.proc.stdout):
            try:
                f.close()
            except OSError:
                pass


class Pool:
    """``workers`` grading processes and one preview process (see the module docstring).

    on_done: called (from a pool thread) with the ids of submissions that just reached
             ``done`` or ``failed``.
    """

    def __init__(
        self,
        repo: Repository,
        exercises: dict[str, str],
        workers: int = 2,
        timeout: float = 60.0,
        memory_mb: int = 2048,
        preview_timeout: float = 5.0,
        grace: float = 10.0,
        on_done=None,
    ):
        self.repo = repo
        self.exercises = exercises
        self.n = max(1, workers)
        self.timeout = timeout
        self.memory_mb = memory_mb
        self.preview_timeout = preview_timeout
        self.grace = grace
        self.on_done = on_done or (lambda ids: None)
        self._wake = threading.Event()
        self._stopping = threading.Event()
        self._threads: list[threading.Thread] = []
        self._procs: dict[int, WorkerProcess | None] = {}
        self._ready = threading.Event()
        self._started = 0
        self._lock = threading.Lock()
        self._preview_lock = threading.Lock()
        self._preview: WorkerProcess | None = None
        self._unsettled: dict = {}  # id -> its outcome (a write) that the database did not take
        self._beats: dict[int, float] = {}  # thread -> when it last began a round
        self._no_start: dict[int, str] = {}  # thread -> why its worker did not start (last try)
        self._progress = time.monotonic()  # when a thread last claimed or stored work

    # -- life cycle
    def start(self) -> int:
        """Requeue what a previous server left running, start the threads. Returns the
        number of submissions recovered."""
        recovered = self.repo.recover()
        for i in range(self.n):
            t = threading.Thread(target=self._loop, args=(i,), name=f"armdyn-grader-{i}", daemon=True)
            t.start()
            self._threads.append(t)
        return recovered

    @property
    def ready(self) -> bool:
        """Every grading worker has started (and imported armdyn) at least once."""
        return self._ready.is_set()

    def pids(self) -> list[int]:
        with self._lock:
            return [p.pid for p in self._procs.values() if p is not None]

    def wake(self) -> None:
        """A submission was queued."""
        self._wake.set()

    def stop(self) -> None:
        """Graceful stop: no new claims; running gradings finish within ``grace``
        seconds or are returned to the queue."""
        self._stopping.set()
        self._wake.set()
        deadline = time.monotonic() + self.grace
        for t in self._threads:
            t.join(max(0.0, deadline - time.monotonic()))
        with self._lock:
            procs = [p for p in self._procs.values() if p is not None]
        for p in procs:
            if p.alive():
                p.proc.kill()  # its thread, still waiting, sees WorkerDied and releases the submission
        for t in self._threads:
            t.join(5.0)
        with self._preview_lock:
            if self._preview is not None:
                self._preview.kill()
                self._preview = None

    # -- grading
    def _spawn(self, i: int) -> WorkerProcess | None:
        try:
            proc = WorkerProcess(self.exercises, self.memory_mb)
        except (WorkerDied, WorkerTimeout, OSError) as err:
            print(f"armdyn serve: cannot start a grading worker: {err}", file=sys.stderr)
            self._no_start[i] = str(err)[:200]
            return None
        self._no_start.pop(i, None)
        with self._lock:
            self._procs[i] = proc
            self._started = len([p for p in self._procs.values() if p is not None])
            if self._started >= self.n:
                self._ready.set()
        return proc

    def _store(self, what, *args):
        """``what(*args)`` (a database write), tried :data:`STORE_TRIES` times with
        back-off while the database is unavailable; a value the database refuses
        (``DataError``, ``IntegrityError``) is not retried. Raises the last error."""
        for k in range(STORE_TRIES):
            try:
                return what(*args)
            except (sa.exc.DataError, sa.exc.IntegrityError):
                raise
            except sa.exc.SQLAlchemyError:
                if k == STORE_TRIES - 1 or self._stopping.wait(0.25 * 2**k):
                    raise
        raise AssertionError("unreachable")

    def _settle(self, sid: str, outcome) -> list[str]:
        """Write a grading's outcome (a callable doing the write, returning the ids it
        completed). A verdict the database refuses fails the submission with the reason;
        while the database is away the outcome waits in ``_unsettled`` (written later)."""
        try:
            return self._store(outcome)
        except (sa.exc.DataError, sa.exc.IntegrityError) as err:
            reason = f"the verdict could not be stored ({type(err).__name__}); retry"
            print(f"armdyn serve: submission {sid}: {reason}: {str(err)[:300]}", file=sys.stderr)
            outcome = lambda: [sid] if self.repo.give_up(sid, reason, False) else []  # noqa: E731
            try:
                return self._store(outcome)
            except sa.exc.SQLAlchemyError:
                pass
        except sa.exc.SQLAlchemyError as err:
            print(f"armdyn serve: submission {sid}: kept until the database answers: {str(err)[:200]}", file=sys.stderr)
        with self._lock:
            self._unsettled[sid] = outcome
        return []

    def _settle_backlog(self) -> list[str]:
        """Write the outcomes the database did not take earlier (oldest first)."""
        with self._lock:
            backlog = list(self._unsettled.items())
        done = []
        for sid, outcome in backlog:
            if not self._ping():
                break  # still away: the next round tries again
            with self._lock:
                self._unsettled.pop(sid, None)
            done += self._settle(sid, outcome)  # kept again if it fails again
        return done

    def _ping(self) -> bool:
        """Does the database answer? (one cheap read)"""
        try:
            self.repo.counts()
            return True
        except sa.exc.SQLAlchemyError:
            return False

    def _loop(self, i: int) -> None:
        proc = None
        while not self._stopping.is_set():
            self._beats[i] = time.monotonic()
            try:
                proc = self._round(i, proc)
            except Exception as err:  # noqa: BLE001 - the thread outlives any one failure
                print(f"armdyn serve: grading thread {i}: {type(err).__name__}: {str(err)[:300]}", file=sys.stderr)
                with self._lock:
                    proc = self._procs.get(i)
                self._stopping.wait(LOOP_BACKOFF)
        if proc is not None:
            proc.kill()
        with self._lock:
            self._procs[i] = None

    def _round(self, i: int, proc: WorkerProcess | None) -> WorkerProcess | None:
        """One claim-grade-store round of thread ``i``; returns its worker (None: gone)."""
        if proc is None or not proc.alive():
            proc = self._spawn(i)
            if proc is None:
                self._stopping.wait(2.0)
                return None
        if self._unsettled:
            ids = self._settle_backlog()
            if ids:
                self.on_done(ids)
        job = self.repo.claim()
        if job is None:
            self._progress = time.monotonic()  # the queue is empty: nothing is held up
            self._wake.wait(0.5)
            self._wake.clear()
            return proc
        self._progress = time.monotonic()
        ids = [job.id]
        try:
            reply = proc.request({"kind": "grade", "exercise": job.exercise, "markdown": job.markdown}, self.timeout)
        except WorkerTimeout:
            proc.kill()
            proc = None
            reason = f"grading took longer than {self.timeout:g} s (stopped)"
            ids = self._settle(job.id, lambda: [job.id] if self.repo.give_up(job.id, reason, retry=False) else [])
        except (WorkerDied, ValueError) as err:
            proc.kill()
            proc = None
            if self._stopping.is_set():
                self._store(self.repo.release, job.id)
                ids = []
            else:
                reason = f"{err}; retry"
                ids = self._settle(
                    job.id, lambda: [job.id] if self.repo.give_up(job.id, reason, True) == FAILED else []
                )
                if not ids:
                    self._wake.set()  # queued again
        else:
            if reply.get("ok"):
                ids = self._settle(job.id, lambda: self.repo.finish(job.id, clean_result(reply)))
            else:
                reason = str(reply.get("reason", "grading failed")).replace("\0", "\\0")
                ids = self._settle(job.id, lambda: [job.id] if self.repo.give_up(job.id, reason, retry=False) else [])
        self._progress = time.monotonic()
        if ids:
            self.on_done(ids)
        return proc

    def health(self) -> dict:
        """``threads``: grading threads alive; ``last_round``: seconds since the quietest
        thread began a round; ``since_progress``: seconds since a thread last claimed,
        stored or found the queue empty; ``unsettled``: outcomes waiting for the database."""
        now = time.monotonic()
        return {
            "threads": sum(t.is_alive() for t in self._threads),
            "last_round": round(now - min(self._beats.values(), default=now), 1),
            "since_progress": round(now - self._progress, 1),
            "unsettled": len(self._unsettled),
        }

    def problems(self, queued: int) -> list[str]:
        """What ``/api/health`` reports as degraded (empty: all well). A round may take a
        grading's ``timeout``; :data:`STALL_SLACK` more is stuck."""
        h, limit = self.health(), self.timeout + STALL_SLACK
        out = []
        if h["threads"] < self.n:
            out.append(f"{self.n - h['threads']} of {self.n} grading threads ended")
        if h["last_round"] > limit:
            out.append(f"a grading thread has been stuck for {h['last_round']:g} s")
        if queued and h["since_progress"] > limit:
            out.append(f"the queue has not moved for {h['since_progress']:g} s")
        if h["unsettled"]:
            out.append(f"{h['unsettled']} outcomes wait for the database")
        for i, why in sorted(self._no_start.items()):
            out.append(f"grading worker {i} cannot be started: {why}")
        return out

    # -- preview
    def preview(self, markdown: str, exercise: str | None) -> dict:
        """How each equation of ``markdown`` is read (blocking; call from a thread).
        One preview at a time, ``preview_timeout`` seconds at most."""
        with self._preview_lock:
            if self._stopping.is_set():
                return {"ok": False, "reason": "the server is stopping"}
            if self._preview is None or not self._preview.alive():
                try:
                    self._preview = WorkerProcess(self.exercises, min(self.memory_mb, 1024))
                except (WorkerDied, WorkerTimeout, OSError) as err:
                    self._preview = None
                    return {"ok": False, "reason": f"preview unavailable: {err}"}
            try:
                return self._preview.request(
                    {"kind": "preview", "exercise": exercise, "markdown": markdown}, self.preview_timeout
                )
            except (WorkerTimeout, WorkerDied, ValueError) as err:
                self._preview.kill()
                self._preview = None
                return {"ok": False, "reason": f"preview stopped: {err}"}
