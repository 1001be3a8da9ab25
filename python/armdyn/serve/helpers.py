"""What the web handlers share: the page templates, reading a request, shaping an answer.

Reading: a submission id from the path, the browser's key (a cookie), a Markdown body,
refusing a NUL; answering: an HTML page from ``templates/``, a JSON error, a submission
as the API shows it. :class:`BadRequest` is the 400 any handler may raise.
"""

from __future__ import annotations

import json
import os
import re
import time

import jinja2
from starlette.requests import Request
from starlette.responses import HTMLResponse, JSONResponse, Response

from . import security

HERE = os.path.dirname(os.path.abspath(__file__))
SID = re.compile(r"^[A-Za-z0-9_-]{1,24}$")  # a submission id (security.new_id)

_templates = jinja2.Environment(
    loader=jinja2.FileSystemLoader(os.path.join(HERE, "templates")), autoescape=True, undefined=jinja2.StrictUndefined
)


def _when(t) -> str:
    return time.strftime("%Y-%m-%d %H:%M:%S", time.gmtime(t)) if t else ""


_templates.filters["when"] = _when


def page(name: str, status: int = 200, **context) -> HTMLResponse:
    """The template ``name`` of ``templates/`` rendered with ``context`` (autoescaped)."""
    return HTMLResponse(_templates.get_template(name).render(**context), status_code=status)


def json_error(status: int, message: str) -> JSONResponse:
    """The API's error answer: ``{"error": message}`` with ``status``."""
    return JSONResponse({"error": message}, status_code=status)


class BadRequest(Exception):
    """A request this server cannot take (answered 400 with the message)."""


def no_nul(text: str, what: str) -> None:
    """Refuse a NUL character (no derivation holds one; PostgreSQL's text cannot)."""
    at = text.find("\0")
    if at >= 0:
        line = text.count("\n", 0, at) + 1
        raise BadRequest(f"{what} holds a NUL character (byte 0) on line {line}: remove it and send again")


def client_address(request: Request) -> str:
    """The client's address (the proxy's X-Forwarded-For when it is trusted)."""
    return request.client.host if request.client else "?"


def submission_id(request: Request) -> str:
    """The submission id of the path; a value that cannot be one (a NUL, a slash...) is 400."""
    sid = request.path_params["sid"]
    if not SID.match(sid):
        raise BadRequest("not a submission id (ids are up to 24 letters, digits, '-' and '_')")
    return sid


def student_key(request: Request) -> tuple[str, bool]:
    """The browser's key (new when it has none): (key, is_new)."""
    key = request.cookies.get(security.STUDENT_COOKIE)
    if key and 20 <= len(key) <= 100:
        return key, False
    return security.new_token(), True


def with_key(response: Response, key: str, new: bool, request: Request) -> Response:
    if new:
        response.set_cookie(
            security.STUDENT_COOKIE,
            key,
            max_age=180 * 86400,
            httponly=True,
            samesite="strict",
            secure=request.url.scheme == "https",
        )
    return response


def api_view(row: dict, full: dict | None = None) -> dict:
    """A submission as the API shows it: ``grade --json``'s fields plus its state."""
    out = {}
    if full is not None and full.get("report_json"):
        out.update(json.loads(full["report_json"]))
    out.update(
        {
            k: row[k]
            for k in (
                "id",
                "status",
                "attempts",
                "exercise",
                "graded_as",
                "passed",
                "first_wrong",
                "error",
                "cached",
                "created_at",
                "started_at",
                "finished_at",
                "late",
            )
        }
    )
    return out


async def text_body(request: Request) -> str:
    kind = request.headers.get("content-type", "").split(";")[0].strip().lower()
    if kind not in ("text/markdown", "text/x-markdown"):  # not text/plain: a cross-site form cannot send these
        raise BadRequest("send the derivation as the body with Content-Type: text/markdown")
    try:
        return (await request.body()).decode("utf-8")
    except UnicodeDecodeError as err:
        raise BadRequest(f"the body is not UTF-8 (byte {err.start})") from None
