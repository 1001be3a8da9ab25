"""Tokens, CSRF, the Content-Security-Policy and the request body limit.

- A submission's secret link token: 32 random bytes (URL-safe); only its sha256 is
  stored, so a leaked database does not open the submissions' pages.
- A student's browser key (cookie ``armdyn_student``, HttpOnly, SameSite=Strict): lists
  their own earlier submissions; also only hashed in the database.
- The instructor token (``--instructor-token`` or ``ARMDYN_INSTRUCTOR_TOKEN``, at least
  :data:`MIN_TOKEN_CHARS` characters) is compared with :func:`hmac.compare_digest`;
  wrong tries are throttled (:class:`Throttle`: per client and overall). A logged-in
  instructor holds a session cookie: a random token whose hash the server keeps with
  its expiry (:data:`SESSION_SECONDS`); logging out ends the session on the server.
- CSRF: every form carries ``HMAC(secret, "csrf:" + browser key)``; a POST whose field
  does not match is refused (the SameSite cookie is the second line).
- Every response gets :data:`CSP` (scripts only from this server's ``/static``, no
  inline script, nothing fetched from elsewhere) and a no-referrer policy (links carry
  tokens).
"""

from __future__ import annotations

import hashlib
import hmac
import secrets
import time
from collections import OrderedDict, deque

STUDENT_COOKIE = "armdyn_student"
INSTRUCTOR_COOKIE = "armdyn_instructor"
MIN_TOKEN_CHARS = 16  # an instructor token shorter than this is refused at start-up
SESSION_SECONDS = 12 * 3600  # an instructor's login lasts this long (or until logout)
MAX_SESSIONS = 1000  # sessions kept; past it the oldest ends

CSP = (
    "default-src 'none'; script-src 'self'; style-src 'self' 'unsafe-inline'; img-src 'self' data:; "
    "connect-src 'self'; form-action 'self'; base-uri 'none'; frame-ancestors 'none'"
)
HEADERS = [
    (b"content-security-policy", CSP.encode()),
    (b"x-content-type-options", b"nosniff"),
    (b"referrer-policy", b"no-referrer"),
    (b"x-frame-options", b"DENY"),
]


def new_token() -> str:
    return secrets.token_urlsafe(32)


def new_id() -> str:
    """A submission id: short, random, not guessable from its neighbours."""
    return secrets.token_urlsafe(9)


def digest(token: str) -> str:
    return hashlib.sha256(token.encode()).hexdigest()


def token_matches(token: str | None, stored_digest: str | None) -> bool:
    """Does ``token`` hash to ``stored_digest``? (constant-time compare)"""
    if not token or not stored_digest:
        return False
    return hmac.compare_digest(digest(token), stored_digest)


class Secrets:
    """The server's secret (random per start unless ``ARMDYN_SECRET`` is set, so that
    several starts keep their CSRF tokens valid), the instructor token, and the
    instructor sessions (in memory: a restart logs everyone out)."""

    def __init__(self, instructor_token: str | None, secret: str | None = None):
        if instructor_token and len(instructor_token) < MIN_TOKEN_CHARS:
            raise ValueError(
                f"the instructor token has {len(instructor_token)} characters; use at least {MIN_TOKEN_CHARS} "
                "(e.g. python -c 'import secrets; print(secrets.token_urlsafe(24))')"
            )
        self.instructor_token = instructor_token or None
        self.key = (secret or secrets.token_hex(32)).encode()
        self._sessions: OrderedDict[str, float] = OrderedDict()  # sha256 of the cookie -> expiry

    def _mac(self, message: str) -> str:
        return hmac.new(self.key, message.encode(), hashlib.sha256).hexdigest()

    def csrf_token(self, browser_key: str) -> str:
        return self._mac("csrf:" + browser_key)

    def csrf_ok(self, browser_key: str | None, sent: str | None) -> bool:
        if not browser_key or not sent:
            return False
        return hmac.compare_digest(self.csrf_token(browser_key), sent)

    def instructor_ok(self, sent: str | None) -> bool:
        """The instructor token as typed (constant time; False when none is configured)."""
        if self.instructor_token is None or not sent:
            return False
        return hmac.compare_digest(sent.encode(), self.instructor_token.encode())

    def new_session(self) -> str:
        """A fresh instructor session: the cookie's value (only its hash is kept)."""
        token = new_token()
        now = time.time()
        for old in [k for k, exp in self._sessions.items() if exp <= now]:
            del self._sessions[old]
        while len(self._sessions) >= MAX_SESSIONS:
            self._sessions.popitem(last=False)
        self._sessions[digest(token)] = now + SESSION_SECONDS
        return token

    def session_ok(self, sent: str | None) -> bool:
        """A live session (not expired, not logged out) of a configured instructor."""
        if self.instructor_token is None or not sent or len(sent) > 100:
            return False
        expiry = self._sessions.get(digest(sent))
        return expiry is not None and expiry > time.time()

    def end_session(self, sent: str | None) -> None:
        if sent:
            self._sessions.pop(digest(sent), None)


class Throttle:
    """Failed instructor logins in a sliding ``window`` (seconds): at most ``per_client``
    from one client address and ``overall`` from all; past either, :meth:`wait` says how
    long to wait (the right token is refused too meanwhile, so guessing gains nothing)."""

    def __init__(self, per_client: int = 10, overall: int = 100, window: float = 300.0, clients: int = 10000):
        self.per_client, self.overall, self.window, self.clients = per_client, overall, window, clients
        self._all: deque[float] = deque()
        self._by: OrderedDict[str, deque[float]] = OrderedDict()

    def _trim(self, q: deque, now: float) -> deque:
        while q and q[0] <= now - self.window:
            q.popleft()
        return q

    def wait(self, client: str) -> float:
        """Seconds until ``client`` may try again (0: now)."""
        now = time.monotonic()
        waits = [0.0]
        for q, limit in ((self._trim(self._all, now), self.overall), (self._by.get(client), self.per_client)):
            if q is not None and len(self._trim(q, now)) >= limit:
                waits.append(q[len(q) - limit] + self.window - now)
        return max(waits)

    def failed(self, client: str) -> None:
        now = time.monotonic()
        self._all.append(now)
        q = self._by.pop(client, None) or deque()
        q.append(now)
        self._by[client] = q
        while len(self._by) > self.clients:
            self._by.popitem(last=False)


class SecurityHeaders:
    """ASGI middleware: :data:`HEADERS` on every HTTP response."""

    def __init__(self, app):
        self.app = app

    async def __call__(self, scope, receive, send):
        if scope["type"] != "http":
            return await self.app(scope, receive, send)

        async def send_with_headers(message):
            if message["type"] == "http.response.start":
                names = {k for k, _ in message.get("headers", [])}
                message["headers"] = list(message.get("headers", [])) + [h for h in HEADERS if h[0] not in names]
            await send(message)

        await self.app(scope, receive, send_with_headers)


class BodyLimit:
    """ASGI middleware: a request body over ``max_bytes`` gets 413 (by Content-Length
    before reading, or as soon as a chunked body passes the limit)."""

    def __init__(self, app, max_bytes: int):
        self.app = app
        self.max_bytes = max_bytes

    async def __call__(self, scope, receive, send):
        if scope["type"] != "http":
            return await self.app(scope, receive, send)
        for name, value in scope.get("headers", []):
            if name == b"content-length":
                try:
                    too_big = int(value) > self.max_bytes
                except ValueError:
                    too_big = True
                if too_big:
                    return await self._refuse(send)
        seen = 0

        async def counted():
            nonlocal seen
            message = await receive()
            if message["type"] == "http.request":
                seen += len(message.get("body", b""))
                if seen > self.max_bytes:
                    raise BodyTooLarge
            return message

        started = False

        async def tracked_send(message):
            nonlocal started
            started = started or message["type"] == "http.response.start"
            await send(message)

        try:
            await self.app(scope, counted, tracked_send)
        except BodyTooLarge:
            if not started:
                await self._refuse(send)

    async def _refuse(self, send):
        body = f'{{"error": "request body larger than {self.max_bytes} bytes"}}'.encode()
        await send(
            {
                "type": "http.response.start",
                "status": 413,
                "headers": [(b"content-type", b"application/json"), (b"content-length", str(len(body)).encode())],
            }
        )
        await send({"type": "http.response.body", "body": body})


class BodyTooLarge(Exception):
    """Raised while reading a body past the limit; the app answers 413."""
