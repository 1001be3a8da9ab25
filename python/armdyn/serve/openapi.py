"""The OpenAPI 3.1 description of ``armdyn serve`` (served at ``/openapi.json``), made
from the app's route table: every route is in it, under the same path and path
parameters, with the methods it answers. What a route takes and returns (query
parameters, bodies, responses) is written here for the JSON API (:data:`_DETAILS`);
a route without such details is described by its handler's docstring, and the pages
(HTML) are tagged ``pages``."""

from __future__ import annotations

import inspect
import re

_STEP = {
    "type": "object",
    "description": "one step's verdict, as `armdyn grade --json` prints it",
    "properties": {
        k: {}
        for k in (
            "name",
            "link",
            "status",
            "expected",
            "got",
            "difference",
            "convention",
            "caused_by",
            "line",
            "label",
            "message",
            "components",
        )
    },
}

_SUBMISSION = {
    "type": "object",
    "required": ["id", "status"],
    "properties": {
        "id": {"type": "string"},
        "status": {
            "enum": ["queued", "running", "done", "failed"],
            "description": "done: a verdict (or the student's input error in `error`); "
            "failed: grading itself failed (timeout, memory, workers killed): retry",
        },
        "attempts": {"type": "integer"},
        "exercise": {"type": ["string", "null"], "description": "as requested (null: the front matter's robot)"},
        "graded_as": {"type": ["string", "null"]},
        "passed": {"type": ["boolean", "null"]},
        "first_wrong": {"type": ["string", "null"]},
        "error": {"type": ["string", "null"]},
        "cached": {"type": "boolean", "description": "the verdict of an identical earlier submission"},
        "created_at": {"type": "number"},
        "started_at": {"type": ["number", "null"]},
        "finished_at": {"type": ["number", "null"]},
        "robot": {"type": "string"},
        "method": {"type": "string"},
        "submission": {"type": "string"},
        "steps": {"type": "array", "items": _STEP},
        "tau_correct": {"type": "array", "items": {"type": "boolean"}},
        "token": {"type": "string", "description": "POST only: the secret that opens this submission"},
        "url": {"type": "string", "description": "POST only: its page, token included"},
        "position": {
            "type": "integer",
            "description": "GET only, while queued: its place in the grading queue (1: graded next)",
        },
    },
}

_ERROR = {"type": "object", "properties": {"error": {"type": "string"}}}


def _json(schema: dict, description: str) -> dict:
    return {"description": description, "content": {"application/json": {"schema": schema}}}


def _details() -> dict:
    """(path, method) -> the hand-written part of an operation."""
    exercise = {
        "name": "robot",
        "in": "query",
        "schema": {"type": "string"},
        "description": "exercise id (bundled model name or variant id); `variant=` and `exercise=` "
        "are the same; default: the front matter's `robot:`",
    }
    token = {
        "name": "t",
        "in": "query",
        "schema": {"type": "string"},
        "description": "the submission's token (or `Authorization: Bearer TOKEN`)",
    }
    return {
        ("/api/health", "get"): {
            "summary": "ready to grade?",
            "responses": {
                "200": _json({"type": "object"}, "workers started"),
                "503": _json(
                    {"type": "object"},
                    "starting, or degraded: its problems (a grading thread ended or stuck, a queue that does not "
                    "move, the database away)",
                ),
            },
        },
        ("/api/grade", "post"): {
            "summary": "grade a derivation",
            "parameters": [
                exercise,
                {"name": "student", "in": "query", "schema": {"type": "string"}},
                {
                    "name": "wait",
                    "in": "query",
                    "schema": {"type": "number", "maximum": 120},
                    "description": "seconds to wait for the verdict (default 30; 0: return at once)",
                },
            ],
            "requestBody": {"required": True, "content": {"text/markdown": {"schema": {"type": "string"}}}},
            "responses": {
                "200": _json(_SUBMISSION, "graded (status done or failed)"),
                "202": _json(_SUBMISSION, "accepted, not graded yet: poll GET /api/submissions/{sid}"),
                "400": _json(_ERROR, "unknown exercise, not UTF-8, wrong content type"),
                "413": _json(_ERROR, "body too large"),
            },
        },
        ("/api/submissions/{sid}", "get"): {
            "summary": "a submission and its verdict",
            "parameters": [token],
            "responses": {
                "200": _json(_SUBMISSION, "the submission"),
                "400": _json(_ERROR, "not a submission id (up to 24 of A-Z a-z 0-9 - _)"),
                "404": _json(_ERROR, "unknown, or the token does not match"),
            },
        },
        ("/api/preview", "post"): {
            "summary": "how each equation is read (sanitized MathML, an HTML fragment)",
            "parameters": [{"name": "exercise", "in": "query", "schema": {"type": "string"}}],
            "requestBody": {"required": True, "content": {"text/markdown": {"schema": {"type": "string"}}}},
            "responses": {
                "200": _json({"type": "object", "properties": {"html": {"type": "string"}}}, "the preview"),
                "503": _json(_ERROR, "too many previews at once (Retry-After), or the preview worker stopped"),
            },
        },
        ("/submissions/{sid}", "get"): {"parameters": [token]},
        ("/submissions/{sid}/report.html", "get"): {"parameters": [token]},
    }


_PARAM = re.compile(r"{([^}:]+)(?::[^}]*)?}")


def _summary_of(endpoint) -> str:
    doc = inspect.getdoc(endpoint) or ""
    first = doc.split("\n\n")[0].replace("\n", " ").strip()
    return first or getattr(endpoint, "__name__", "").replace("_", " ")


def _is_page(path: str) -> bool:
    return not path.startswith("/api/") and path != "/openapi.json"


def schema(routes) -> dict:
    """The OpenAPI document of ``routes`` (the app's route table: Starlette ``Route``
    objects; mounts such as ``/static`` are listed with their ``{path}``)."""
    from starlette.routing import Mount, Route

    details = _details()
    paths: dict[str, dict] = {}
    for route in routes:
        if isinstance(route, Mount):
            path, methods, endpoint = route.path + "/{path}", {"GET"}, None
            summary = f"files under {route.path}/"
        elif isinstance(route, Route):
            path, methods, endpoint = route.path, set(route.methods or {"GET"}), route.endpoint
            summary = _summary_of(endpoint)
        else:
            continue
        names = _PARAM.findall(path)
        for method in sorted(m.lower() for m in methods - {"HEAD"}):
            op = {"summary": summary, "operationId": method + "_" + (re.sub(r"\W+", "_", path).strip("_") or "root")}
            extra = details.get((path, method), {})
            op.update({k: v for k, v in extra.items() if k != "parameters"})
            op["parameters"] = [
                {"name": n, "in": "path", "required": True, "schema": {"type": "string"}} for n in names
            ] + list(extra.get("parameters", []))
            if _is_page(path):
                op["tags"] = ["pages"]
            op.setdefault(
                "responses",
                {"200": {"description": "an HTML page" if _is_page(path) else "the answer"}},
            )
            paths.setdefault(path, {})[method] = op
    return {
        "openapi": "3.1.0",
        "info": {
            "title": "armdyn serve",
            "version": "1",
            "description": "Grade dynamics derivations (Markdown + LaTeX) step by step. The JSON API is under "
            "/api/; the routes tagged `pages` answer HTML for browsers.",
        },
        "paths": paths,
    }
