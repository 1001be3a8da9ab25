"""A self-contained course page: armdyn's report stylesheet plus a Content-Security-Policy
that allows nothing but inline styles and ``data:`` images (no script, no network)."""

from __future__ import annotations

from ..htmlpage import CSS
from ..mathml import escape

#: the page's policy: it loads nothing, runs nothing
CSP = "default-src 'none'; img-src data:; style-src 'unsafe-inline'; base-uri 'none'; form-action 'none'"

_EXTRA_CSS = """
.armdyn table.grid { border-collapse:collapse; margin:8px 0 16px; }
.armdyn table.grid th, .armdyn table.grid td { padding:4px 12px; border-bottom:1px solid var(--rule);
  text-align:left; vertical-align:top; }
.armdyn table.grid td.num, .armdyn table.grid th.num { text-align:right; font-variant-numeric:tabular-nums; }
.armdyn img.chart { max-width:100%; height:auto; display:block; margin:8px 0 16px; }
"""


def course_page(title: str, body: str) -> str:
    """A complete HTML5 document around ``body`` (already HTML), with the CSP meta."""
    return (
        "<!DOCTYPE html>\n"
        '<html lang="en">\n<head>\n<meta charset="utf-8">\n'
        f'<meta http-equiv="Content-Security-Policy" content="{CSP}">\n'
        '<meta name="viewport" content="width=device-width, initial-scale=1">\n'
        f"<title>{escape(title)}</title>\n"
        f"<style>{CSS}{_EXTRA_CSS}\nbody {{ margin:0; background:#ffffff; }}\n</style>\n"
        "</head>\n<body>\n"
        f'<main class="armdyn">\n{body}\n</main>\n'
        "</body>\n</html>\n"
    )
