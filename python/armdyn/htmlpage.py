"""The frame of armdyn's HTML reports: one stylesheet, a page and a fragment.

Reports are self-contained: inline CSS, math as MathML (rendered natively by browsers),
no script, no web font, no network. Every rule is scoped under ``.armdyn`` so that a
fragment can sit inside a Jupyter notebook without restyling it.

A page carries a Content-Security-Policy (:data:`CSP`) that lets it load and run
nothing but its own inline stylesheet and ``data:`` images: a second line of defence
behind the escaping and the MathML whitelist (:mod:`armdyn.mathml_sanitize`), should
student or model text ever get through as markup. A Jupyter fragment cannot carry one
(the notebook's page sets its own policy); it relies on the escaping alone.

Colours of the statuses (text on a pale background, readable in print):
correct green, correct-by-convention blue, wrong red, follows-from-earlier-error amber,
correct-but-unsupported violet, consistent (not checked) grey on blue with a dashed rule,
unrecognised grey.
"""

from __future__ import annotations

from .mathml import escape

#: every page: no script, no fetch, no frame, no form, no base URL; inline CSS only
CSP = "default-src 'none'; style-src 'unsafe-inline'; img-src data:; base-uri 'none'; form-action 'none'"

CSS = """
.armdyn { --ink:#1f2328; --muted:#59636e; --rule:#d1d9e0; --paper:#ffffff; --tint:#f6f8fa;
  --ok:#1a7f37; --ok-bg:#dafbe1; --conv:#0550ae; --conv-bg:#ddf4ff; --bad:#b42318; --bad-bg:#ffebe9;
  --hl:#ffd8d3; --carry:#8a5300; --carry-bg:#fff1c2; --hl-carry:#ffe7a3; --unsup:#6639ba; --unsup-bg:#f3ecff;
  --grey:#6e7781; --grey-bg:#eff2f5;
  color:var(--ink); font:15px/1.55 "Segoe UI","Helvetica Neue","Liberation Sans",Arial,sans-serif;
  max-width:1100px; margin:0 auto; padding:24px 28px 48px; box-sizing:border-box; }
.armdyn.inline { padding:4px 0; max-width:none; margin:0; }
.armdyn *, .armdyn *::before, .armdyn *::after { box-sizing:inherit; }
.armdyn math { font-family:"Latin Modern Math","STIX Two Math","DejaVu Math TeX Gyre","Cambria Math",math;
  font-size:1.12em; }
.armdyn h1 { font-size:1.55em; font-weight:600; margin:0 0 4px; letter-spacing:-0.01em; }
.armdyn h2 { font-size:1.15em; font-weight:600; margin:28px 0 10px; padding-bottom:4px;
  border-bottom:1px solid var(--rule); }
.armdyn h3 { font-size:1em; font-weight:600; margin:18px 0 6px; color:var(--muted); }
.armdyn .meta { color:var(--muted); margin:0 0 18px; }
.armdyn .meta b { color:var(--ink); font-weight:600; }
.armdyn code, .armdyn pre { font-family:"DejaVu Sans Mono","Liberation Mono",Menlo,Consolas,monospace;
  font-size:0.86em; }
.armdyn pre { white-space:pre-wrap; word-break:break-word; margin:6px 0 0; padding:8px 10px;
  background:var(--tint); border-radius:6px; color:var(--muted); }
.armdyn a { color:var(--conv); text-decoration:underline; text-underline-offset:2px; }
.armdyn a:hover { text-decoration-thickness:2px; }

/* summary */
.armdyn .summary { display:grid; grid-template-columns:1fr auto; gap:14px 28px; align-items:start;
  padding:16px 20px; border:1px solid var(--rule); border-radius:10px; background:var(--tint); }
.armdyn .verdict { font-size:1.12em; font-weight:600; }
.armdyn .verdict.pass { color:var(--ok); }
.armdyn .verdict.fail { color:var(--bad); }
.armdyn .verdict .sub { display:block; font-size:0.82em; font-weight:400; color:var(--muted); margin-top:2px; }
.armdyn .taus { display:flex; flex-wrap:wrap; gap:8px; justify-content:flex-end; }
.armdyn .tau { display:inline-flex; align-items:center; gap:8px; padding:4px 12px; border-radius:999px;
  border:1px solid var(--rule); background:var(--paper); white-space:nowrap; }
.armdyn .tau.right { border-color:var(--ok); }
.armdyn .tau.notright { border-color:var(--bad); }
.armdyn .tau .word { font-size:0.86em; font-weight:600; }
.armdyn .tau.right .word { color:var(--ok); }
.armdyn .tau.notright .word { color:var(--bad); }
.armdyn .tau.unsupported { border-color:var(--unsup); }
.armdyn .tau.unsupported .word { color:var(--unsup); }
.armdyn .counts { grid-column:1 / -1; display:flex; flex-wrap:wrap; gap:6px 8px; }
.armdyn .notes { grid-column:1 / -1; margin:0; padding-left:18px; color:var(--muted); font-size:0.93em; }

/* badges */
.armdyn .badge { display:inline-block; padding:1px 10px; border-radius:999px; font-size:0.8em;
  font-weight:600; letter-spacing:0.01em; white-space:nowrap; border:1px solid transparent; }
.armdyn .badge .n { font-variant-numeric:tabular-nums; margin-right:4px; }
.armdyn .s-correct { color:var(--ok); background:var(--ok-bg); }
.armdyn .s-correct-by-convention { color:var(--conv); background:var(--conv-bg); }
.armdyn .s-wrong { color:var(--bad); background:var(--bad-bg); }
.armdyn .s-follows-from-earlier-error { color:var(--carry); background:var(--carry-bg); }
.armdyn .s-correct-but-unsupported { color:var(--unsup); background:var(--unsup-bg); }
.armdyn .s-consistent { color:var(--grey); background:var(--conv-bg); }
.armdyn .s-definition { color:#3d4a5c; background:#e8eef5; }
.armdyn .s-unrecognised { color:var(--grey); background:var(--grey-bg); }

/* steps */
.armdyn ol.steps { list-style:none; margin:0; padding:0; }
.armdyn .step { border:1px solid var(--rule); border-left:4px solid var(--rule); border-radius:8px;
  padding:10px 16px 12px; margin:0 0 10px; background:var(--paper); break-inside:avoid; }
.armdyn .step.st-correct { border-left-color:var(--ok); }
.armdyn .step.st-correct-by-convention { border-left-color:var(--conv); }
.armdyn .step.st-wrong { border-left-color:var(--bad); }
.armdyn .step.st-follows-from-earlier-error { border-left-color:#d4a72c; }
.armdyn .step.st-correct-but-unsupported { border-left-color:var(--unsup); }
.armdyn .step.st-consistent { border-left-color:var(--conv); border-left-style:dashed; }
.armdyn .step.st-definition { border-left-color:#8aa0b8; }
.armdyn .step.st-unrecognised { border-left-color:var(--rule); background:var(--tint); color:var(--muted); }
.armdyn .step.first { box-shadow:0 0 0 2px var(--bad-bg); }
.armdyn .head { display:flex; flex-wrap:wrap; align-items:baseline; gap:4px 12px; }
.armdyn .head .label { font-size:1.08em; min-width:3em; }
.armdyn .head .title { color:var(--muted); }
.armdyn .skip { display:grid; grid-template-columns:3.2em 1fr; gap:0 8px; margin-top:6px; }
.armdyn .skip .ln { color:var(--muted); font-size:0.84em; text-align:right; padding-top:9px;
  font-variant-numeric:tabular-nums; }
.armdyn .skip pre { margin:0; }
.armdyn .skip .why { color:var(--muted); font-size:0.88em; margin:2px 0 0 2px; }
.armdyn .skip .written { max-width:100%; overflow-x:auto; padding:4px 0; }
.armdyn .skip details { margin-top:2px; }
.armdyn .head .where { color:var(--muted); font-size:0.86em; margin-left:auto; }
.armdyn .message { margin:6px 0 0; }
.armdyn .message .why { color:var(--muted); }
.armdyn .compare { display:flex; flex-wrap:wrap; gap:8px 14px; margin-top:8px; }
.armdyn .side { flex:1 1 auto; min-width:0; max-width:100%; overflow-x:auto; padding:6px 12px 8px;
  border-radius:6px; background:var(--tint); }
.armdyn .side .cap { display:block; font-size:0.76em; font-weight:600; text-transform:uppercase;
  letter-spacing:0.06em; color:var(--muted); }
.armdyn .side math { margin:4px 0 2px; }
/* display-style math laid out from the left: a wide formula scrolls instead of being
   cut on both sides, as centred block math would be */
.armdyn .side math[display=block], .armdyn .eq math[display=block], .armdyn .skip .written math[display=block] {
  display:inline math; math-style:normal; }
.armdyn .side.diff { background:var(--bad-bg); }
.armdyn mtd { padding:2px 6px; }
.armdyn mtd.hl { background:var(--hl); border-radius:4px; }
.armdyn .st-follows-from-earlier-error mtd.hl { background:var(--hl-carry); }
.armdyn .st-follows-from-earlier-error .side.diff { background:var(--carry-bg); }
.armdyn mtd.zero { color:#8c959f; }
.armdyn mtd.left { text-align:left; math-style:normal; }
.armdyn mtext.long { font-family:"Segoe UI","Helvetica Neue","Liberation Sans",Arial,sans-serif;
  font-size:0.8em; color:var(--muted); }
.armdyn details { margin-top:6px; font-size:0.92em; }
.armdyn details summary { cursor:pointer; color:var(--muted); }
.armdyn .legend { display:flex; flex-wrap:wrap; gap:6px 14px; font-size:0.86em; color:var(--muted);
  margin:8px 0 14px; }

/* derivation pages and small tables */
/* an equation and its caption share a row while both fit, else the caption wraps under
   it; a formula wider than the page (MathML Core does not break lines) scrolls alone */
.armdyn .eq { display:flex; flex-wrap:wrap; align-items:center; justify-content:space-between; gap:6px 24px;
  padding:5px 0; }
.armdyn .eq > math { margin:2px 0; max-width:100%; overflow-x:auto; overflow-y:hidden; }
.armdyn .eq .note { flex:1 1 16em; color:var(--muted); font-size:0.84em; text-align:right; }
.armdyn .note math { font-size:1.1em; }
.armdyn .group { border:1px solid var(--rule); border-radius:8px; padding:6px 16px 10px; margin:0 0 10px;
  break-inside:avoid; }
.armdyn .group > h3 { margin-top:6px; }
.armdyn table.plain { border-collapse:collapse; margin:6px 0 10px; font-size:0.95em; }
.armdyn table.plain th, .armdyn table.plain td { text-align:left; padding:4px 12px 4px 0;
  border-bottom:1px solid var(--rule); vertical-align:middle; }
.armdyn table.plain th { font-weight:600; color:var(--muted); font-size:0.86em; }
.armdyn .ok { color:var(--ok); font-weight:600; }
.armdyn .fail { color:var(--bad); font-weight:600; }

@media print {
  .armdyn { max-width:none; padding:0; font-size:11pt; }
  .armdyn .step, .armdyn .group, .armdyn .summary { break-inside:avoid; }
  .armdyn .side { overflow:visible; }
  .armdyn, .armdyn * { -webkit-print-color-adjust:exact; print-color-adjust:exact; }
  .armdyn details { display:none; }
}
"""


def page(title: str, body: str, extra_css: str = "") -> str:
    """A complete, self-contained HTML5 document around ``body`` (already HTML), with
    ``extra_css`` after armdyn's stylesheet."""
    return (
        "<!DOCTYPE html>\n"
        '<html lang="en">\n<head>\n<meta charset="utf-8">\n'
        f'<meta http-equiv="Content-Security-Policy" content="{CSP}">\n'
        '<meta name="viewport" content="width=device-width, initial-scale=1">\n'
        f"<title>{escape(title)}</title>\n"
        f"<style>{CSS}{extra_css}\nbody {{ margin:0; background:#ffffff; }}\n</style>\n"
        "</head>\n<body>\n"
        f'<main class="armdyn">\n{body}\n</main>\n'
        "</body>\n</html>\n"
    )


def fragment(body: str) -> str:
    """``body`` with the stylesheet, for Jupyter's ``_repr_html_`` (no html/head/body)."""
    return f'<div class="armdyn inline"><style>{CSS}</style>{body}</div>'
