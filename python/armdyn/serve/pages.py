"""A way back on the self-contained pages the server passes on.

The class summary (:func:`armdyn.course.summary_html`) and the one-page report
(``armdyn grade --html``) are complete documents made for reading offline: no link
leads out of them. Served by ``armdyn serve``, they get a navigation bar at the top
of their body (plain links; their own Content-Security-Policy allows inline styles
only, so the bar is styled inline). The links are built here; a submission's token
is carried over only when it has a token's form.
"""

from __future__ import annotations

import re

from ..mathml import escape

_TOKEN = re.compile(r"^[A-Za-z0-9_-]{20,100}$")  # security.new_token's form

_BAR = (
    '<nav aria-label="armdyn serve" style="display:flex;flex-wrap:wrap;gap:4px 16px;padding:10px 24px;'
    "background:#f6f8fa;border-bottom:1px solid #d1d9e0;font:15px/1.5 'Segoe UI','Helvetica Neue',"
    "'Liberation Sans',Arial,sans-serif\">{links}</nav>\n"
)
_LINK = '<a href="{href}" style="color:#0550ae">{text}</a>'


def with_nav(page: str, links: list[tuple[str, str]]) -> str:
    """``page`` (a complete HTML document) with a bar of ``links`` ((href, text) pairs,
    hrefs of this site) right after its ``<body>``."""
    bar = _BAR.format(links=" ".join(_LINK.format(href=escape(h), text=escape(t)) for h, t in links))
    at = page.find("<body>")
    if at < 0:
        return bar + page
    at += len("<body>")
    return page[:at] + "\n" + bar + page[at:]


INSTRUCTOR_LINKS = [
    ("/instructor", "← The class"),
    ("/instructor/summary", "Class summary"),
    ("/instructor/gradebook.csv", "Gradebook (CSV)"),
    ("/", "Student page"),
]


def report_links(sid: str, token: str | None, instructor: bool) -> list[tuple[str, str]]:
    """The bar of a submission's one-page report: back to the submission (its token
    kept), or the instructor's pages."""
    if instructor:
        return [(f"/submissions/{sid}", "← The submission"), *INSTRUCTOR_LINKS]
    back = f"/submissions/{sid}" + (f"?t={token}" if token and _TOKEN.match(token) else "")
    return [(back, "← The submission"), ("/", "Submit another derivation")]
