"""Tokens, CSRF, the Content-Security-Policy and the request body limit.

- A submission's secret link token: 32 random bytes (URL-safe); only its sha256 is
  stored, so a leaked database does not open the submissions' pages.
- A student's browser key (cookie ``armdyn_student``, HttpOnly, SameSite=Strict): lists
  their own earlier submissions; also only hashed in the database.
- The instructor token (``--instructor-token`` or ``ARMDYN_INSTRUCTOR_TOKEN``) is compared
  with :func:`hmac.compare_digest`; a logged-in instructor holds a cookie that is an
  HMAC of the server secret, compared the same way.
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

STUDENT_COOKIE = "armdyn_student"
INSTRUCTOR_COOKIE = "armdyn_instructor"

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
    several starts keep their cookies valid) and the instructor token."""

    def __init__(self, instructor_token: str | None, secret: str | None = None):
        self.instructor_token = instructor_token or None
        self.key = (secret or secrets.token_hex(32)).encode()

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

    def instructor_cookie(self) -> str:
        return self._mac("instructor:" + (self.instructor_token or ""))

    def instructor_cookie_ok(self, sent: str | None) -> bool:
        if self.instructor_token is None or not sent:
            return False
        return hmac.compare_digest(self.instructor_cookie(), sent)


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
