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

What it says (on stderr): one ready line with its address once the workers are up
(``armdyn serve: listening on http://127.0.0.1:8000/``) and one when the grading workers
are up, one line per request
(:mod:`.accesslog`: no query secrets, no cookies, no tokens), and on Ctrl-C or SIGTERM
that it is stopping and then that it stopped. A port already taken is one sentence and
exit status 2, before any worker starts. The grading workers ignore SIGINT: a Ctrl-C in
the terminal reaches the whole process group, and it is the server that stops them.
"""

from __future__ import annotations

import asyncio
import errno
import os
import resource
import socket
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
        access_log=False,  # ours (.accesslog) leaves the query's secrets out
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


def url_of(sock: socket.socket) -> str:
    """``http://HOST:PORT/`` of a listening socket (an IPv6 address in brackets; the
    wildcard addresses as the loopback one a browser on this machine can open)."""
    host, port = sock.getsockname()[:2]
    host = {"0.0.0.0": "127.0.0.1", "::": "::1"}.get(host, host)
    return f"http://[{host}]:{port}/" if ":" in host else f"http://{host}:{port}/"


def listen(host: str, port: int) -> socket.socket:
    """A socket bound to ``host:port`` (``port`` 0: a free one), or a :class:`ModelError`
    that says what to do when the port is taken or the address is not this machine's."""
    try:
        infos = socket.getaddrinfo(host, port, type=socket.SOCK_STREAM, flags=socket.AI_PASSIVE)
    except socket.gaierror as err:
        raise ModelError(f"--host {host!r} is not an address of this machine ({err.strerror})") from None
    family, kind, proto, _, address = infos[0]
    sock = socket.socket(family, kind, proto)
    sock.setsockopt(socket.SOL_SOCKET, socket.SO_REUSEADDR, 1)
    try:
        sock.bind(address)
    except OSError as err:
        sock.close()
        if err.errno == errno.EADDRINUSE:
            raise ModelError(
                f"port {port} on {host} is already in use (another armdyn serve, or another program): "
                f"stop it, or choose another port with --port"
            ) from None
        if err.errno in (errno.EACCES, errno.EPERM):
            raise ModelError(f"not allowed to listen on port {port} of {host} (ports below 1024 need root)") from None
        if err.errno == errno.EADDRNOTAVAIL:
            raise ModelError(f"--host {host!r} is not an address of this machine") from None
        raise ModelError(f"cannot listen on {host}:{port}: {err.strerror}") from None
    sock.listen(2048)
    sock.set_inheritable(False)
    return sock


def _say(message: str) -> None:
    print(f"armdyn serve: {message}", file=sys.stderr, flush=True)


def _server_class():
    """uvicorn's Server that says when it is ready and when it stops."""
    import uvicorn

    class Server(uvicorn.Server):
        url = ""
        state = None  # the app's Server (armdyn.serve.app): its pool says when workers are up

        async def startup(self, sockets=None) -> None:
            await super().startup(sockets=sockets)
            if not self.should_exit:
                _say(f"listening on {self.url}")
                self._announce = asyncio.ensure_future(self._workers_ready())

        async def _workers_ready(self) -> None:
            while not self.should_exit:
                pool = getattr(self.state, "pool", None)
                if pool is not None and pool.ready:
                    _say(f"{self.state.settings.workers} grading worker(s) ready")
                    return
                await asyncio.sleep(0.2)

        async def shutdown(self, sockets=None) -> None:
            _say("stopping: no new requests; open ones and running gradings may finish")
            await super().shutdown(sockets=sockets)

    return Server


def run(args) -> int:
    try:
        import uvicorn  # noqa: F401 - the extra is there
    except ImportError:
        raise ModelError("armdyn serve needs its extra: pip install 'armdyn[serve]'") from None
    from .app import build_app
    from .exercises import catalogue
    from .security import MIN_TOKEN_CHARS
    from .state import Settings

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
    sock = listen(args.host, args.port)  # before the workers start: a busy port fails at once
    from .accesslog import AccessLog

    inner = build_app(settings)
    server = _server_class()(config(AccessLog(inner), args.host, args.port, args.forwarded_allow_ips))
    server.url, server.state = url_of(sock), inner.state.server
    try:
        server.run(sockets=[sock])
    except KeyboardInterrupt:  # uvicorn raises the Ctrl-C again once it has shut down
        _say("stopped")
        return 0
    finally:
        sock.close()
    _say("stopped")
    return 0
