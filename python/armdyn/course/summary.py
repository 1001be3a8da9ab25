"""The class summary page: where students went wrong first, and which kinds of slip.

    html = summary_html(gradebook)       # a self-contained page (CSP meta, chart as data: URI)

It shows, for the graded submissions, how many went wrong first at each step (a bar
chart and a table), the kinds of slip among all wrong steps ranked by count
(:mod:`.errorkinds`), each with one anonymised example (the step and the grader's
message, no student named), and how many submissions could not be graded and why.
The page is byte-identical for the same gradebook.
"""

from __future__ import annotations

from ..mathml import escape, text_with_math
from .chart import bar_chart_uri
from .errorkinds import KINDS
from .gradebook import Gradebook
from .page import course_page


def _ranked(counts: dict[str, int], order: tuple[str, ...] = ()) -> list[tuple[str, int]]:
    rank = {k: i for i, k in enumerate(order)}
    return sorted(counts.items(), key=lambda kv: (-kv[1], rank.get(kv[0], len(rank)), kv[0]))


def summary_html(gb: Gradebook, title: str = "Class summary") -> str:
    """The summary of ``gb`` as a complete HTML page (str)."""
    rows = gb.rows
    graded = [r for r in rows if r["status"] == "graded"]
    not_graded: dict[str, int] = {}
    for r in rows:
        if r["status"] != "graded":
            not_graded[r["status"]] = not_graded.get(r["status"], 0) + 1
    all_right = sum(1 for r in graded if not r["first_wrong"])
    out = [f"<h1>{escape(title)}</h1>"]
    mean = sum(r["total"] for r in graded) / len(graded) if graded else 0.0
    most = max((r["max"] for r in graded), default=0.0)
    out.append(
        f'<p class="meta"><b>{len(rows)}</b> submissions: <b>{len(graded)}</b> graded, '
        f"<b>{len(rows) - len(graded)}</b> not graded; <b>{all_right}</b> with no wrong step; "
        f"mean points <b>{mean:.2f}</b> (of up to {most:g}).</p>"
    )

    firsts = _ranked(gb.first_wrong_counts())
    out.append("<h2>First wrong step</h2>")
    if firsts:
        uri = bar_chart_uri(
            [k for k, _ in firsts], [v for _, v in firsts], "Students whose first wrong step is ...", "students", "step"
        )
        out.append(f'<img class="chart" alt="bar chart: students per first wrong step" src="{escape(uri)}">')
        out.append('<table class="grid"><tr><th>step</th><th class="num">students</th></tr>')
        out += [f'<tr><td><code>{escape(k)}</code></td><td class="num">{v}</td></tr>' for k, v in firsts]
        out.append("</table>")
    else:
        out.append("<p>No graded submission has a wrong step.</p>")

    out.append("<h2>Kinds of slip</h2>")
    kinds = _ranked(gb.kind_counts(), KINDS)
    if kinds:
        out.append(
            '<p class="meta">Every step graded <code>wrong</code> (not those that only carry an earlier '
            "error), by what the grader found; one example of each, anonymised.</p>"
        )
        out.append(
            '<table class="grid"><tr><th>kind</th><th class="num">wrong steps</th>'
            '<th class="num">students</th><th>example</th></tr>'
        )
        for kind, n in kinds:
            mine = [s for s in gb.slips if s.kind == kind]
            students = len({s.student for s in mine})
            ex = mine[0]
            out.append(
                f'<tr><td>{escape(kind)}</td><td class="num">{n}</td><td class="num">{students}</td>'
                f"<td><code>{escape(ex.step)}</code>: {text_with_math(ex.message)}</td></tr>"
            )
        out.append("</table>")
    else:
        out.append("<p>No wrong step.</p>")

    if not_graded:
        out.append("<h2>Not graded</h2>")
        out.append('<table class="grid"><tr><th>reason</th><th class="num">submissions</th></tr>')
        out += [f'<tr><td>{escape(k)}</td><td class="num">{v}</td></tr>' for k, v in _ranked(not_graded)]
        out.append("</table>")
        out.append('<p class="meta">The gradebook names them, with the reason in its <code>error</code> column.</p>')
    return course_page(title, "\n".join(out))
