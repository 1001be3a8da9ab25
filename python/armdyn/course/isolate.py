"""Run one grading task in a forked child with a time and memory limit.

A submission may be hostile (huge expressions, deep nesting): each is graded in a child
process forked from the (already imported) parent, so it starts in milliseconds, with
``RLIMIT_AS`` set in the child (the parent's address space plus the budget) and a
wall-clock deadline kept by the parent, which kills the child when it passes. Whatever the child does (hang, exhaust memory, crash), the
parent gets one JSON-able dict back: the task's result, or ``{"error": "<status>: why"}``
with status ``timeout``, ``memory`` or ``crashed``.

:class:`ChildPool` runs up to ``jobs`` such children at once from one thread (a
``select`` loop over their pipes: no threads, so forking stays safe). POSIX only.
"""

from __future__ import annotations

import faulthandler
import json
import os
import resource
import select
import signal
import time
from dataclasses import dataclass

_CHUNK = 1 << 20


def _address_space() -> int:
    """Bytes of address space this process has mapped now (Linux: /proc/self/statm; 0
    where that is not available, so the cap is then the budget alone)."""
    try:
        with open("/proc/self/statm") as f:
            return int(f.read().split()[0]) * os.sysconf("SC_PAGE_SIZE")
    except (OSError, ValueError, IndexError):
        return 0


def _child(fn, arg, memory_bytes: int | None, w: int) -> None:
    """In the child: limit memory, run, write the JSON result, exit without cleanup."""
    code = 0
    try:
        signal.signal(signal.SIGINT, signal.SIG_IGN)  # Ctrl-C is the parent's to handle
        faulthandler.disable()  # a crash is reported by the parent, in one line
        if memory_bytes:
            # on top of what the child shares with its parent: a parent that has loaded
            # more (Jupyter, a test runner, Dask) must not leave its children less room
            cap = _address_space() + memory_bytes
            resource.setrlimit(resource.RLIMIT_AS, (cap, cap))
        try:
            result = fn(arg)
        except MemoryError:
            result = {"error": f"memory: more than {memory_bytes // (1 << 20)} MB"}
        except RecursionError:
            result = {"error": "crashed: nested too deeply (recursion limit)"}
        except Exception as exc:  # noqa: BLE001 - any failure of one submission is reported, not raised
            result = {"error": f"crashed: {type(exc).__name__}: {' '.join(str(exc).split())[:300]}"}
        data = json.dumps(result).encode("utf-8")
        view = memoryview(data)
        while view:
            n = os.write(w, view[:_CHUNK])
            view = view[n:]
    except BaseException:  # noqa: BLE001 - e.g. MemoryError while encoding: the parent sees no result
        code = 3
    finally:
        os._exit(code)


@dataclass
class _Running:
    key: object
    pid: int
    fd: int
    deadline: float
    chunks: list


class ChildPool:
    """Up to ``jobs`` forked children at once, each running ``fn(arg)`` (see the module
    docstring). ``run(items)`` yields ``(key, result)`` as children finish."""

    def __init__(self, fn, jobs: int, timeout: float, memory_mb: int | None):
        self.fn = fn
        self.jobs = max(1, int(jobs))
        self.timeout = float(timeout)
        self.memory_bytes = int(memory_mb) << 20 if memory_mb else None

    def _start(self, key, arg) -> _Running:
        r, w = os.pipe()
        pid = os.fork()
        if pid == 0:  # pragma: no cover - the child's side
            os.close(r)
            _child(self.fn, arg, self.memory_bytes, w)
        os.close(w)
        return _Running(key, pid, r, time.monotonic() + self.timeout, [])

    def _finish(self, job: _Running, killed: bool) -> dict:
        if killed:
            try:
                os.kill(job.pid, signal.SIGKILL)
            except ProcessLookupError:
                pass
        os.close(job.fd)
        _, status = os.waitpid(job.pid, 0)
        if killed:
            return {"error": f"timeout: more than {self.timeout:g} s"}
        data = b"".join(job.chunks)
        if data:
            try:
                return json.loads(data)
            except ValueError:
                pass
        if os.WIFSIGNALED(status):
            sig = os.WTERMSIG(status)
            name = signal.Signals(sig).name if sig in signal.Signals._value2member_map_ else str(sig)
            return {"error": f"crashed: killed by {name}"}
        return {"error": f"crashed: exit status {os.waitstatus_to_exitcode(status)} without a result"}

    def run(self, items):
        """``items``: iterable of ``(key, arg)``; yields ``(key, result dict)``."""
        pending = iter(items)
        running: dict[int, _Running] = {}
        exhausted = False
        try:
            while True:
                while not exhausted and len(running) < self.jobs:
                    try:
                        key, arg = next(pending)
                    except StopIteration:
                        exhausted = True
                        break
                    job = self._start(key, arg)
                    running[job.fd] = job
                if not running:
                    return
                now = time.monotonic()
                wait = max(0.0, min(j.deadline for j in running.values()) - now)
                ready, _, _ = select.select(list(running), [], [], wait)
                for fd in ready:
                    job = running[fd]
                    data = os.read(fd, _CHUNK)
                    if data:
                        job.chunks.append(data)
                        continue
                    del running[fd]
                    yield job.key, self._finish(job, killed=False)
                now = time.monotonic()
                for fd in [fd for fd, j in running.items() if j.deadline <= now]:
                    job = running.pop(fd)
                    yield job.key, self._finish(job, killed=True)
        finally:
            for job in running.values():  # interrupted: leave no child behind
                self._finish(job, killed=True)


def run_isolated(fn, arg, timeout: float, memory_mb: int | None) -> dict:
    """``fn(arg)`` in one forked child (for a Dask task: the same limits on a worker)."""
    for _, result in ChildPool(fn, 1, timeout, memory_mb).run([(0, arg)]):
        return result
    return {"error": "crashed: no result"}
