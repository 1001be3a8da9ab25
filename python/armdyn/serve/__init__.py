"""``armdyn serve``: students submit derivations in a browser, instructors see the class.

A Starlette app (:mod:`.app`) served by uvicorn (:mod:`.server`); submissions in a
database through SQLAlchemy (:mod:`.storage`, schema versions in :mod:`.migrations`);
grading in worker processes with time and memory limits (:mod:`.pool`, :mod:`.worker`);
tokens, CSRF and the Content-Security-Policy in :mod:`.security`; the exercises a
request may name in :mod:`.exercises`. How to run it for a course: docs/serve.md.
"""

from __future__ import annotations
