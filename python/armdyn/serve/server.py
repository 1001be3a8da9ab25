"""Start the server: ``armdyn serve`` (uvicorn, one process; workers are its children).

uvicorn turns SIGTERM/SIGINT into a graceful shutdown: it stops accepting connections,
lets open requests finish (at most ``GRACEFUL_SECONDS``), then runs the app's shutdown,
which stops the grading pool (:meth:`armdyn.serve.pool.Pool.stop`).

Connections are bounded (:class:`GuardedH11`): a request whose headers are not complete
within ``HEADER_SECONDS`` of the connection (or of the previous response) is closed, an
idle keep-alive connection after ``KEEP_ALIVE_SECONDS``; past ``MAX_CONNECTIONS`` open
ones (kept below the open-file limit), or past a quarter of them from one address that
is not a trusted proxy, a new connection is closed at once. So half-open connections
can neither pile up nor starve the server of file descriptors, and one client cannot
take every connection.
"""

from __future__ import annotations

import os
import resource
import sys

from ..errors import ModelError

GRACEFUL_SECONDS = 15
HEADER_SECONDS = 10.0  # from connection (or last response) to a complete request head
KEEP_ALIVE_SECONDS = 5  # an idle keep-alive connection is closed after this
MAX_HEAD_BYTES = 64 * 1024  # h11's limit on an incomplete request head
MAX_CONNECTIONS = 800  # open connections; kept under the open-file limit (see open_file_budget)
FILES_RESERVED = 200  # descriptors kept for the database, worker pipes, logs, static files


def db_url(value: str | None) -> str:
    """``--db``: a SQLAlchemy URL (``sqlite:///path``, ``postgresql://user@host/db``)."""
    url = value or os.environ.get("ARMDYN_DB") or "sqlite:///armdyn-serve.db"
    if not url.startswith(("sqlite:", "postgresql:", "postgres:", "postgresql+psycopg:")):
        raise ModelError(f"--db must be sqlite:///PATH or postgresql://..., got {url.split(':')[0]!r}")
    return url


def open_file_budget(wanted: int = MAX_CONNECTIONS) -> int:
    """Raise the soft open-file limit to the hard one; the connections the rest allows."""
    soft, hard = resource.getrlimit(resource.RLIMIT_NOFILE)
    if hard == resource.RLIM_INFINITY or hard > soft:
        try:
            target = 65536 if hard == resource.RLIM_INFINITY else hard
            resource.setrlimit(resource.RLIMIT_NOFILE, (target, hard))
            soft = target
        except (ValueError, OSError):
            pass
    return max(16, min(wanted, soft - FILES_RESERVED))


def guarded_protocol(header_seconds: float, max_connections: int, proxies: str = "127.0.0.1"):
    """uvicorn's h11 protocol with a deadline on request heads and connection caps (all,
    and per address for addresses not in ``proxies``, the trusted proxies: behind a
    proxy every student comes from its address)."""
    from collections import Counter

    from uvicorn.protocols.http.h11_impl import H11Protocol

    trusted = {p.strip() for p in proxies.split(",")}
    per_peer = None if "*" in trusted else max(4, max_connections // 4)
    peers: Counter = Counter()

    class GuardedH11(H11Protocol):
        def connection_made(self, transport) -> None:
            super().connection_made(transport)
            self._head_timer = None
            self._awaited = self.cycle
            self._peer = self.client[0] if self.client else "?"
            peers[self._peer] += 1
            crowded = per_peer is not None and self._peer not in trusted and peers[self._peer] > per_peer
            if len(self.connections) > max_connections or crowded:
                transport.abort()  # over a cap: free the descriptor now
                return
            self._arm()

        def _arm(self) -> None:
            if self._head_timer is None:
                self._awaited = self.cycle
                self._head_timer = self.loop.call_later(header_seconds, self._head_overdue)

        def _disarm(self) -> None:
            if self._head_timer is not None:
                self._head_timer.cancel()
                self._head_timer = None

        def _head_overdue(self) -> None:
            self._head_timer = None
            if self.cycle is self._awaited and not self.transport.is_closing():
                self.transport.close()  # no complete request head in time

        def data_received(self, data: bytes) -> None:
            idle = self.cycle is None or self.cycle.response_complete
            if idle:
                self._arm()  # a new request starts: its head has header_seconds
            super().data_received(data)
            if self.cycle is not self._awaited:
                self._disarm()  # the head arrived

        def on_response_complete(self) -> None:
            super().on_response_complete()
            self._disarm()  # keep-alive: uvicorn's idle timer takes over

        def connection_lost(self, exc) -> None:
            self._disarm()
            peers[self._peer] -= 1
            if peers[self._peer] <= 0:
                del peers[self._peer]
            super().connection_lost(exc)

    return GuardedH11


def config(app, host: str, port: int, forwarded_allow_ips: str = "127.0.0.1", **limits):
    """The uvicorn configuration of ``armdyn serve`` (``limits``: ``header_seconds``,
    ``max_connections`` to override the module's constants, e.g. in tests)."""
    import uvicorn

    header_seconds = limits.get("header_seconds", HEADER_SECONDS)
    max_connections = limits.get("max_connections") or open_file_budget()
    return uvicorn.Config(
        app,
        host=host,
        port=port,
        http=guarded_protocol(header_seconds, max_connections, forwarded_allow_ips),
        log_level="warning",
        proxy_headers=True,
        forwarded_allow_ips=forwarded_allow_ips,
        timeout_graceful_shutdown=GRACEFUL_SECONDS,
        timeout_keep_alive=KEEP_ALIVE_SECONDS,
        h11_max_incomplete_event_size=MAX_HEAD_BYTES,
    )


def course_settings(settings, args) -> None:
    """``--roster``, ``--deadline``, ``--policy``, ``--lti`` into ``settings``."""
    from .grades import POLICIES
    from .identity import load_roster, parse_deadlines

    if getattr(args, "roster", None):
        settings.roster = load_roster(args.roster, settings.exercises)
    settings.deadlines = parse_deadlines(getattr(args, "deadline", None))
    settings.policy = getattr(args, "policy", None) or "latest"
    if settings.policy not in POLICIES:
        raise ModelError(f"--policy must be one of {', '.join(POLICIES)}")
    if getattr(args, "lti", None):
        from .lti import Tool

        if settings.roster is None:
            raise ModelError("--lti needs --roster: a launch is mapped to a roster student (by email or LTI sub)")
        settings.lti = Tool.load(args.lti)


def run(args) -> int:
    try:
        import uvicorn
    except ImportError:
        raise ModelError("armdyn serve needs its extra: pip install 'armdyn[serve]'") from None
    from .app import Settings, build_app
    from .exercises import catalogue
    from .security import MIN_TOKEN_CHARS

    token = args.instructor_token or os.environ.get("ARMDYN_INSTRUCTOR_TOKEN")
    if args.workers < 1:
        raise ModelError("--workers must be at least 1")
    if token is not None and len(token) < MIN_TOKEN_CHARS:
        raise ModelError(
            f"the instructor token is {len(token)} characters long; it must have at least {MIN_TOKEN_CHARS} "
            "(make one: python -c 'import secrets; print(secrets.token_urlsafe(24))')"
        )
    settings = Settings(
        db=db_url(args.db),
        exercises=catalogue(args.exercises),
        workers=args.workers,
        timeout=args.timeout,
        memory_mb=args.memory_mb,
        instructor_token=token,
        secret=os.environ.get("ARMDYN_SECRET"),
    )
    course_settings(settings, args)
    if token is None:
        print(
            "armdyn serve: no --instructor-token (or ARMDYN_INSTRUCTOR_TOKEN): the instructor page is closed",
            file=sys.stderr,
        )
    app = build_app(settings)
    uvicorn.Server(config(app, args.host, args.port, args.forwarded_allow_ips)).run()
    return 0
