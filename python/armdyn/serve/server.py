"""Start the server: ``armdyn serve`` (uvicorn, one process; workers are its children).

uvicorn turns SIGTERM/SIGINT into a graceful shutdown: it stops accepting connections,
lets open requests finish (at most ``GRACEFUL_SECONDS``), then runs the app's shutdown,
which stops the grading pool (:meth:`armdyn.serve.pool.Pool.stop`).
"""

from __future__ import annotations

import os
import sys

from ..errors import ModelError

GRACEFUL_SECONDS = 15


def db_url(value: str | None) -> str:
    """``--db``: a SQLAlchemy URL (``sqlite:///path``, ``postgresql://user@host/db``)."""
    url = value or os.environ.get("ARMDYN_DB") or "sqlite:///armdyn-serve.db"
    if not url.startswith(("sqlite:", "postgresql:", "postgres:", "postgresql+psycopg:")):
        raise ModelError(f"--db must be sqlite:///PATH or postgresql://..., got {url.split(':')[0]!r}")
    return url


def run(args) -> int:
    try:
        import uvicorn
    except ImportError:
        raise ModelError("armdyn serve needs its extra: pip install 'armdyn[serve]'") from None
    from .app import Settings, build_app
    from .exercises import catalogue

    token = args.instructor_token or os.environ.get("ARMDYN_INSTRUCTOR_TOKEN")
    if args.workers < 1:
        raise ModelError("--workers must be at least 1")
    settings = Settings(
        db=db_url(args.db),
        exercises=catalogue(args.exercises),
        workers=args.workers,
        timeout=args.timeout,
        memory_mb=args.memory_mb,
        instructor_token=token,
        secret=os.environ.get("ARMDYN_SECRET"),
    )
    if token is None:
        print(
            "armdyn serve: no --instructor-token (or ARMDYN_INSTRUCTOR_TOKEN): the instructor page is closed",
            file=sys.stderr,
        )
    app = build_app(settings)
    uvicorn.run(
        app,
        host=args.host,
        port=args.port,
        log_level="warning",
        proxy_headers=True,
        forwarded_allow_ips=args.forwarded_allow_ips,
        timeout_graceful_shutdown=GRACEFUL_SECONDS,
    )
    return 0
