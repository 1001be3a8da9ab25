"""The class summary page: per exercise kind, where students went wrong first, which
kinds of slip, how many steps only carried an earlier error or were right but unsupported;
and which submissions could not be graded, and why.

    html = summary_html(gradebook)       # a self-contained page (CSP meta, charts as data: URIs)

One section per exercise kind (an ``rp`` arm and a proof are never pooled: their steps,
points and slips differ): the students graded, the mean of their points of that kind's
maximum, how many went wrong first at each step (a bar chart and a table; a proof's link
named by its equation), the kinds of slip among the wrong steps ranked by count
(:mod:`.slipkinds`, else :mod:`.errorkinds`), each with one anonymised example, and the
steps that carry an earlier error or are right but unsupported. Then the submissions not
graded, by reason (the reason without the file's name: the page names no student), and
the policy that chose one submission per student. The page is byte-identical for the
same gradebook.
"""

from __future__ import annotations

import re

from ..mathml import escape, text_with_math
from .chart import bar_chart_uri
from .errorkinds import KINDS
from .gradebook import Gradebook
from .page import course_page

_POLICY_TEXT = {
    "latest": "the latest graded submission (the latest one when none was graded)",
    "best": "the graded submission with the most points (the later one on a tie)",
}
_STATUS_TEXT = {
    "timeout": "took longer than the time limit",
    "memory": "needed more memory than the limit",
    "crashed": "the grader's process crashed",
    "no-variant": "no variant for the student (no folder of that name, no variant: in the front matter)",
    "duplicate": "a second file for the same student (the first, by file name, was graded)",
}
#: a file's path (a student's name) with its line: ``subs/ada.md:14:`` -> ``line 14:``
_PATH_LINE = re.compile(r"(?:[^\s:'\"]*[/\\])?[^\s/\\:'\"]+\.(?:md|ya?ml)(?::(\d+))?(?::\d+)?:?")


def _ranked(counts: dict[str, int], order: tuple[str, ...] = ()) -> list[tuple[str, int]]:
    rank = {k: i for i, k in enumerate(order)}
    return sorted(counts.items(), key=lambda kv: (-kv[1], rank.get(kv[0], len(rank)), kv[0]))


def reason_of(status: str, error: str | None) -> str:
    """Why a submission was not graded, without the file's name: the grader's reason for
    ``error`` (``line 14: not UTF-8 text``), else the status's meaning."""
    if status in _STATUS_TEXT:
        return _STATUS_TEXT[status]
    text = (error or "").partition(": ")[2] if (error or "").startswith(f"{status}: ") else (error or "")
    text = _PATH_LINE.sub(lambda m: f"line {m.group(1)}:" if m.group(1) else "", text)
    text = " ".join(text.replace(" :", ":").split()).strip(" :")
    return text or "not graded"


def _kind_section(gb: Gradebook, kind: str) -> list[str]:
    rows = [r for r in gb.rows if (r["kind"] or "") == kind]
    graded = [r for r in rows if r["status"] == "graded"]
    name = kind or "exercise of unknown kind"
    out = [f"<h2>{escape(name)}</h2>"]
    mean = sum(r["total"] for r in graded) / len(graded) if graded else 0.0
    most = max((r["max"] for r in graded), default=0.0)
    all_right = sum(1 for r in graded if not r["first_wrong"])
    carried = sum(r["n_follows_from_earlier_error"] for r in graded)
    unsupported = sum(r["n_correct_but_unsupported"] for r in graded)
    out.append(
        f'<p class="meta"><b>{len(rows)}</b> students: <b>{len(graded)}</b> graded, '
        f"<b>{len(rows) - len(graded)}</b> not graded; <b>{all_right}</b> with no wrong step; "
        f"mean points <b>{mean:.2f}</b> of <b>{most:g}</b>.</p>"
    )
    firsts = _ranked(gb.first_wrong_counts(kind))
    out.append("<h3>First wrong step</h3>")
    if firsts:
        uri = bar_chart_uri(
            [k for k, _ in firsts], [v for _, v in firsts], "Students whose first wrong step is ...", "students", "step"
        )
        out.append(f'<img class="chart" alt="bar chart: students per first wrong step" src="{escape(uri)}">')
        out.append('<table class="grid first"><tr><th>step</th><th class="num">students</th></tr>')
        out += [f'<tr><td><code>{escape(k)}</code></td><td class="num">{v}</td></tr>' for k, v in firsts]
        out.append("</table>")
    else:
        out.append("<p>No graded submission has a wrong step.</p>")

    out.append("<h3>Kinds of slip</h3>")
    kinds = _ranked(gb.kind_counts(kind), KINDS)
    if kinds:
        out.append(
            '<p class="meta">Every step graded <code>wrong</code> (not those that only carry an earlier '
            "error), by what its value shows; one example of each, anonymised.</p>"
        )
        out.append(
            '<table class="grid kinds"><tr><th>kind</th><th class="num">wrong steps</th>'
            '<th class="num">students</th><th>example</th></tr>'
        )
        for slip_kind, n in kinds:
            mine = [s for s in gb.slips if s.kind == slip_kind and s.exercise == kind]
            students = len({s.student for s in mine})
            ex = mine[0]
            out.append(
                f'<tr><td>{escape(slip_kind)}</td><td class="num">{n}</td><td class="num">{students}</td>'
                f"<td><code>{escape(ex.step)}</code>: {text_with_math(ex.message)}</td></tr>"
            )
        out.append("</table>")
    else:
        out.append("<p>No wrong step.</p>")
    out.append(
        '<table class="grid carried"><tr><th>steps that</th><th class="num">steps</th><th class="num">students</th></tr>'
        f'<tr><td>carry an earlier error (right from the student\'s own wrong values)</td><td class="num">{carried}</td>'
        f'<td class="num">{sum(1 for r in graded if r["n_follows_from_earlier_error"])}</td></tr>'
        f"<tr><td>are right but unsupported (not what the student's own earlier steps give)</td>"
        f'<td class="num">{unsupported}</td>'
        f'<td class="num">{sum(1 for r in graded if r["n_correct_but_unsupported"])}</td></tr></table>'
    )
    return out


def summary_html(gb: Gradebook, title: str = "Class summary") -> str:
    """The summary of ``gb`` as a complete HTML page (str)."""
    rows = gb.rows
    handed = sum(r.get("submissions") or 1 for r in rows)
    out = [f"<h1>{escape(title)}</h1>"]
    out.append(
        f'<p class="meta"><b>{len(rows)}</b> students, <b>{handed}</b> submissions; one row per student: '
        f"{escape(_POLICY_TEXT.get(gb.policy, gb.policy))}. Exercises: "
        + ", ".join(f"<b>{escape(k or 'unknown')}</b>" for k in gb.kinds())
        + ".</p>"
    )
    for kind in gb.kinds():
        out += _kind_section(gb, kind)

    reasons: dict[str, int] = {}
    for r in [*(r for r in rows if r["status"] != "graded"), *gb.set_aside]:
        if r["status"] != "graded":
            why = reason_of(r["status"], r["error"])
            key = f"{r['status']}: {why}"
            reasons[key] = reasons.get(key, 0) + 1
    if reasons:
        out.append("<h2>Not graded</h2>")
        out.append('<table class="grid notgraded"><tr><th>reason</th><th class="num">submissions</th></tr>')
        out += [f'<tr><td>{escape(k)}</td><td class="num">{v}</td></tr>' for k, v in _ranked(reasons)]
        out.append("</table>")
        out.append(
            '<p class="meta">The gradebook names them, with the full reason in its <code>error</code> column.</p>'
        )
    return course_page(title, "\n".join(out))
