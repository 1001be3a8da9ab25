"""A self-contained course page: armdyn's report stylesheet plus a Content-Security-Policy
that allows nothing but inline styles and ``data:`` images (no script, no network)."""

from __future__ import annotations

from ..htmlpage import page

_EXTRA_CSS = """
.armdyn table.grid { border-collapse:collapse; margin:8px 0 16px; }
.armdyn table.grid th, .armdyn table.grid td { padding:4px 12px; border-bottom:1px solid var(--rule);
  text-align:left; vertical-align:top; }
.armdyn table.grid td.num, .armdyn table.grid th.num { text-align:right; font-variant-numeric:tabular-nums; }
.armdyn img.chart { max-width:100%; height:auto; display:block; margin:8px 0 16px; }
"""


def course_page(title: str, body: str) -> str:
    """A complete HTML5 document around ``body`` (already HTML): armdyn's page with the
    course tables' styles."""
    return page(title, body, extra_css=_EXTRA_CSS)
