"""The access log of ``armdyn serve``: one line per request on stderr.

    armdyn serve: 127.0.0.1 GET /submissions/Xy3?t=* 200 41 ms

The client's address, the method, the path, the status and the time to the end of the
response. The query keeps its parameter names, but only the values of :data:`SHOWN`
(exercise ids and a wait): a submission's link token (``?t=``), a personal link's token
(``/link/*``), a student's name or
anything else a client put there is logged as ``*``. No header is logged: no cookie,
no ``Authorization``. A request whose client left before an answer is logged with
status 499 (nginx's "client closed request"); one the app failed on, 500.
"""

from __future__ import annotations

import sys
import time
from urllib.parse import parse_qsl, quote

#: query parameters whose values are logged (none of them is a secret or a name)
SHOWN = frozenset({"exercise", "robot", "variant", "wait"})
_MAX_PATH = 300  # characters of a path logged (a longer one is cut, with "...")


def redacted_target(path: str, query: bytes | str) -> str:
    """``path?query`` as logged: only :data:`SHOWN` values, every other value ``*``."""
    # a personal link's token is a student's key: never logged
    path = "/link/*" if path.startswith("/link/") else quote(path, safe="/-_.~%")
    if len(path) > _MAX_PATH:
        path = path[:_MAX_PATH] + "..."
    if isinstance(query, bytes):
        query = query.decode("latin-1")
    if not query:
        return path
    pairs = parse_qsl(query, keep_blank_values=True)
    shown = [f"{quote(k[:40])}={quote(v[:64]) if k in SHOWN else '*'}" for k, v in pairs[:20]]
    return f"{path}?{'&'.join(shown)}" if shown else f"{path}?*"


class AccessLog:
    """ASGI middleware: log each HTTP request once its response is sent (or abandoned)."""

    def __init__(self, app, stream=None):
        self.app = app
        self.stream = stream

    async def __call__(self, scope, receive, send):
        if scope["type"] != "http":
            return await self.app(scope, receive, send)
        start = time.monotonic()
        status = [None]
        done = [False]

        async def logged_send(message):
            if message["type"] == "http.response.start":
                status[0] = message["status"]
            await send(message)
            if message["type"] == "http.response.body" and not message.get("more_body", False):
                done[0] = True

        try:
            await self.app(scope, receive, logged_send)
        except BaseException:
            if status[0] is None:
                status[0] = 500
            raise
        finally:
            code = status[0] if done[0] or status[0] is not None else 499
            self._write(scope, code, time.monotonic() - start)

    def _write(self, scope, status, seconds: float) -> None:
        client = scope.get("client")
        who = client[0] if client else "-"
        target = redacted_target(scope.get("path", ""), scope.get("query_string", b""))
        line = f"armdyn serve: {who} {scope.get('method', '-')} {target} {status} {seconds * 1000:.0f} ms\n"
        stream = self.stream or sys.stderr
        try:
            stream.write(line)
            stream.flush()
        except (OSError, ValueError):  # a closed stderr must not fail the request
            pass
