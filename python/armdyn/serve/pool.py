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
  then their workers are killed and the submissions returned to the queue uncounted.

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

from .storage import Repository


class WorkerDied(RuntimeError):
    pass


class WorkerTimeout(RuntimeError):
    pass


class WorkerProcess:
    """One ``python -m armdyn.serve.worker`` and its pipes."""

    def __init__(self, exercises: dict[str, str], memory_mb: int, start_timeout: float = 120.0):
        env = dict(
            os.environ,
            ARMDYN_SERVE_EXERCISES=json.dumps(exercises),
            ARMDYN_SERVE_MEMORY_MB=str(memory_mb),
            OPENBLAS_NUM_THREADS="1",
            OMP_NUM_THREADS="1",
        )
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
            return None
        with self._lock:
            self._procs[i] = proc
            self._started = len([p for p in self._procs.values() if p is not None])
            if self._started >= self.n:
                self._ready.set()
        return proc

    def _loop(self, i: int) -> None:
        proc = None
        while not self._stopping.is_set():
            if proc is None or not proc.alive():
                proc = self._spawn(i)
                if proc is None:
                    self._stopping.wait(2.0)
                    continue
            job = self.repo.claim()
            if job is None:
                self._wake.wait(0.5)
                self._wake.clear()
                continue
            ids = [job.id]
            try:
                reply = proc.request(
                    {"kind": "grade", "exercise": job.exercise, "markdown": job.markdown}, self.timeout
                )
            except WorkerTimeout:
                proc.kill()
                proc = None
                self.repo.give_up(job.id, f"grading took longer than {self.timeout:g} s (stopped)", retry=False)
            except (WorkerDied, ValueError) as err:
                proc.kill()
                proc = None
                if self._stopping.is_set():
                    self.repo.release(job.id)
                    ids = []
                elif self.repo.give_up(job.id, f"{err}; retry", retry=True) != "failed":
                    ids = []
                    self._wake.set()
            else:
                if reply.get("ok"):
                    ids = self.repo.finish(job.id, reply)
                else:
                    self.repo.give_up(job.id, str(reply.get("reason", "grading failed")), retry=False)
            if ids:
                self.on_done(ids)
        if proc is not None:
            proc.kill()
        with self._lock:
            self._procs[i] = None

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
