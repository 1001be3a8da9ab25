"""No student or model text runs in a browser: script-injection payloads in every field
that reaches armdyn's HTML.

The payloads (tests/html_payloads.py: script tags, img onerror, svg onload,
``javascript:`` in ``\\href``, ``\\style``, entity-encoded and mixed-case variants,
``</math>`` and ``]]>`` breakouts, unicode escapes, a NUL byte...) go into

* a grade report from a Markdown and from a YAML submission (``armdyn grade --html``):
  left-hand sides, values, the front matter's symbols, and the model's joint names
  (the expected values print them);
* a grade report built by hand whose recognised steps carry the payloads as labels
  (the path through latex2mathml) and as the student's notation for symbols;
* ``armdyn derive MODEL --format html --steps`` of models whose robot, link and joint
  names are payloads (the step labels are LaTeX made from those names);
* the Jupyter fragments (``_repr_html_``) of Robot, EquationsOfMotion, GradeReport and
  AgreementReport.

Each page is checked statically by a tokenizer independent of the sanitizer
(html_payloads.html_findings: no element outside armdyn's vocabulary, no on*
attribute, no style/src/link attribute but the report's own ``#step-N`` anchors, no
``javascript:`` URL) and every payload's token must be in its visible text (it reached
the page, as text). Then headless Chromium loads each page, once as written and once
with its Content-Security-Policy taken out (the escaping alone must hold), lets its
timers run, and the dumped DOM must show no canary, the page's own title and content.
A control page with a live script shows that the browser check sees an executed
payload, and that the policy stops it.
"""

from __future__ import annotations

import html
import json
import os
import re
import subprocess
import sys
from pathlib import Path

import pytest
import sympy as sp
import yaml
from browser import dump_dom, require_chromium, without_csp
from html_payloads import CANARY, PAYLOADS, html_findings, scan, visible_text

from armdyn.grading.html import report_html
from armdyn.grading.verdict import GradeReport, StepVerdict
from armdyn.htmlpage import CSP, page
from armdyn.mathml import escape, latex_to_mathml, math_element
from armdyn.mathml_sanitize import ATTRIBUTES, ELEMENTS, MAX_DEPTH, clean_mathml, sanitize_mathml

ROOT = Path(__file__).resolve().parents[1]
RP_ARM = (ROOT / "python" / "armdyn" / "robots" / "rp-arm.yaml").read_text()
# the fields of rp-arm.yaml a payload replaces: robot name, two links, two joints
_SLOTS = ("robot", "link1", "link2", "theta1", "d2")


def _hostile_model(names: dict) -> str:
    """rp-arm.yaml with names replaced: ``names`` maps a slot of _SLOTS to its new name."""
    text = RP_ARM
    for slot, new in names.items():
        q = json.dumps(new)  # a YAML double-quoted scalar
        if slot == "robot":
            text = text.replace("name: rp-arm", f"name: {q}")
        else:
            text = re.sub(rf"(name|parent|child): {slot}\b", lambda m, q=q: f"{m.group(1)}: {q}", text)
    return text


def _groups() -> list[dict]:
    """The payloads, five at a time, over the slots of a model (names must be printable:
    the model reader refuses the others, see test_unprintable_model_name_is_refused)."""
    out = []
    printable = [(t, p) for t, p in PAYLOADS if p.isprintable()]
    for k in range(0, len(printable), len(_SLOTS)):
        chunk = printable[k : k + len(_SLOTS)]
        out.append({slot: p for slot, (_, p) in zip(_SLOTS, chunk)})
    return out


def _cli(*args, cwd: Path) -> subprocess.CompletedProcess:
    env = {**os.environ, "PYTHONPATH": str(ROOT / "python")}
    return subprocess.run(
        [sys.executable, "-m", "armdyn", *args],
        cwd=cwd,
        env=env,
        capture_output=True,
        text=True,
        timeout=300,
        check=False,
    )


def _assert_static(markup: str, tokens: list[str], csp: bool) -> None:
    found = html_findings(markup)
    assert not found, f"live markup in the page: {found[:8]}"
    text = visible_text(markup)
    missing = [t for t in tokens if t not in text]
    assert not missing, f"payloads that never reached the page as text: {missing}"
    metas = [m for m in scan(markup).meta if (m.get("http-equiv") or "").lower() == "content-security-policy"]
    if csp:
        assert [m.get("content") for m in metas] == [CSP]
        for directive in ("default-src 'none'", "base-uri 'none'", "form-action 'none'"):
            assert directive in CSP
        assert "script-src" not in CSP and "'unsafe-eval'" not in CSP  # script falls under default-src 'none'
    else:
        assert not metas


def _title(markup: str) -> str:
    m = re.search(r"<title>(.*?)</title>", markup, re.DOTALL)
    return html.unescape(m.group(1)) if m else ""


def _assert_nothing_ran(path: Path, chromium: str, tmp_path: Path) -> None:
    """Load ``path`` as written and without its policy: no payload may have run."""
    source = path.read_text(encoding="utf-8")
    bare = tmp_path / f"{path.stem}-no-csp.html"
    bare.write_text(without_csp(source), encoding="utf-8")
    n_math = source.count("<math")
    for variant in (path, bare):
        dom = dump_dom(variant, chromium)
        assert CANARY not in dom, f"{variant.name}: a payload ran (the canary is in the page)"
        assert "<pwned-canary" not in dom.lower(), f"{variant.name}: a payload became an element"
        assert 'class="armdyn' in dom, f"{variant.name}: the page is gone (navigated away?)"
        assert _title(dom) == _title(source), f"{variant.name}: the title changed to {_title(dom)!r}"
        assert dom.count("<math") == n_math > 0, f"{variant.name}: math elements {dom.count('<math')} of {n_math}"


# ------------------------------------------------------------------ the sanitizer


def test_payload_list_is_long_and_distinct():
    assert len(PAYLOADS) >= 20
    assert len({t for t, _ in PAYLOADS}) == len({p for _, p in PAYLOADS}) == len(PAYLOADS)


def test_sanitizer_keeps_mathml_and_drops_the_rest():
    # what latex2mathml writes for a label in the field's notation survives unchanged
    good = (
        '<mrow><msub><mover accent="true"><mi>&#952;</mi><mo>&#729;</mo></mover><mn>1</mn></msub>'
        '<mo stretchy="true" fence="true" form="prefix">(</mo><mfrac><mi>a</mi><mi>b</mi></mfrac>'
        '<mo stretchy="true" fence="true" form="postfix">)</mo><mspace width="0.1667em"></mspace>'
        '<mtable columnalign="left right"><mtr><mtd class="hl"><mi mathvariant="bold">x</mi></mtd></mtr>'
        "</mtable></mrow>"
    )
    assert clean_mathml(good).markup == good and clean_mathml(good).dropped == clean_mathml(good).stripped == 0
    bad = (
        '<mrow href="javascript:alert(1)" style="color:red" onclick="x()" id="main" xlink:href="x">'
        '<mi onmouseover="x()">a</mi><script>alert(1)</script><svg onload="x()"><text>t</text></svg>'
        '<mtext>&lt;img src=x onerror=alert(1)&gt;</mtext><annotation-xml encoding="text/html">'
        '<img src="x"/></annotation-xml><mstyle mathcolor="url(javascript:x)" displaystyle="true">'
        '<mi>b</mi></mstyle><mi class="hl evil">c</mi><mspace width="calc(1em)" height="99999em"/><math><mi>d</mi></math></mrow>'
    )
    with pytest.raises(ValueError):  # xlink: undeclared prefix: not well-formed
        clean_mathml(bad)
    bad = bad.replace(' xlink:href="x"', "")
    out = clean_mathml(bad)
    assert out.markup == (
        "<mrow><mi>a</mi><mtext>&lt;img src=x onerror=alert(1)&gt;</mtext>"
        '<mstyle displaystyle="true"><mi>b</mi></mstyle><mi>c</mi><mspace></mspace></mrow>'
    )
    assert out.dropped == 4  # script, svg, annotation-xml, the nested math
    assert out.stripped == 9  # href, style, onclick, id, onmouseover, mathcolor, class, width, height


def test_sanitizer_output_passes_an_independent_html_check():
    """Every payload, converted by latex2mathml and sanitized (or shown as text), read
    back by the standard library's HTML tokenizer: only whitelisted elements and
    attributes, and the payload's token is there as text."""
    import xml.etree.ElementTree as ET

    for token, payload in PAYLOADS:
        inner = latex_to_mathml(payload)
        markup = math_element(inner if inner is not None else f"<mtext>{escape(payload)}</mtext>")
        assert not html_findings(markup), (payload, html_findings(markup))
        root = ET.fromstring(markup)  # well-formed XML, too
        for el in root.iter():
            assert el.tag.split("}")[-1] in ELEMENTS
            for name, value in el.attrib.items():
                assert name in ATTRIBUTES and ATTRIBUTES[name].fullmatch(value), (name, value)
        if inner is None:
            assert token in visible_text(markup), payload


def test_sanitizer_is_idempotent_and_bounded():
    text = "<mrow>" * (MAX_DEPTH + 50) + "<mi>x</mi>" + "</mrow>" * (MAX_DEPTH + 50)
    out = clean_mathml(text)
    assert out.dropped == 1 and out.markup.count("<mrow>") == MAX_DEPTH and "<mi>" not in out.markup
    for _, payload in PAYLOADS:
        inner = latex_to_mathml(payload)
        if inner is not None:
            assert sanitize_mathml(inner) == inner
    assert sanitize_mathml("<mi>a</mi></mrow><script>").startswith("<merror>")
    assert sanitize_mathml('<!DOCTYPE x [<!ENTITY a "b">]><mi>&a;</mi>').startswith("<merror>")


def test_label_with_markup_falls_back_to_escaped_source():
    # the documented cases: \text{<script>} became a live element, \href and \style live attributes
    assert latex_to_mathml(r"\text{<script>alert(1)</script>}") is None
    assert latex_to_mathml(r"\href{javascript:alert(1)}{x}") == "<mrow><mrow><mrow><mi>x</mi></mrow></mrow></mrow>"
    assert latex_to_mathml(r"\style{color:red}{x}") == "<mrow><mrow><mi>x</mi></mrow></mrow>"


# ------------------------------------------------------------------ pages


def _grade_model(tmp_path: Path) -> Path:
    model = tmp_path / "hostile-rp.yaml"
    model.write_text(_hostile_model({"theta1": PAYLOADS[0][1], "d2": PAYLOADS[2][1]}), encoding="utf-8")
    return model


def _markdown_submission(model: Path) -> str:
    front = yaml.safe_dump(
        {"robot": model.name, "method": "newton-euler", "symbols": {f"L_{{{p}}}": "l1" for _, p in PAYLOADS[:3]}}
    )
    lines = [
        "---",
        front.strip(),
        "---",
        "",
        "A wrong first step, so the expected values show the model's names:",
        "",
        r"$$ \omega_1 = \begin{pmatrix} 0 \\ 0 \\ 0 \end{pmatrix} $$",
        "",
    ]
    for _, p in PAYLOADS:
        lines += [f"$$ {p} = 0 $$", ""]  # a hostile left-hand side
    for k, (_, p) in enumerate(PAYLOADS):
        lines += [f"$$ x_{{{k}}} = {p} $$", ""]  # a hostile value
    return "\n".join(lines)


def _yaml_submission(model: Path) -> str:
    steps = {r"\omega_1": [0, 0, 0]}
    steps.update({p: "0" for _, p in PAYLOADS})
    steps.update({f"x_{{{k}}}": p for k, (_, p) in enumerate(PAYLOADS)})
    return yaml.safe_dump(
        {
            "robot": model.name,
            "method": "newton-euler",
            "symbols": {f"L_{{{p}}}": "l1" for _, p in PAYLOADS[:3]},
            "steps": steps,
        },
        allow_unicode=False,
    )


@pytest.mark.parametrize("fmt", ["md", "yaml"])
def test_grade_report_from_hostile_submission(tmp_path, fmt):
    model = _grade_model(tmp_path)
    sub = tmp_path / f"submission.{fmt}"
    sub.write_text(_markdown_submission(model) if fmt == "md" else _yaml_submission(model), encoding="utf-8")
    out = tmp_path / f"report-{fmt}.html"
    done = _cli("grade", str(sub), "--html", str(out), cwd=tmp_path)
    assert done.returncode in (0, 1) and out.exists(), done.stderr[-2000:]
    markup = out.read_text(encoding="utf-8")
    _assert_static(markup, [t for t, _ in PAYLOADS], csp=True)
    # the model's joint names reached the page through the expected values (as text)
    assert "wrong" in markup and "Q01Q" in visible_text(markup.split("expected", 1)[-1])
    _assert_nothing_ran(out, require_chromium(), tmp_path)


def _hand_report() -> GradeReport:
    """Recognised steps (every status) whose labels are payloads: the MathML path."""
    th, thd = sp.symbols("theta1 theta1_dot")
    statuses = ["correct", "wrong", "follows-from-earlier-error", "correct-by-convention", "correct-but-unsupported"]
    steps = []
    for k, (_, p) in enumerate(PAYLOADS):
        status = statuses[k % len(statuses)]
        exp, got = sp.Matrix([0, 0, thd]), sp.Matrix([0, 0, thd if status != "wrong" else 2 * thd])
        diff = got - exp if status in ("wrong", "follows-from-earlier-error") else None
        steps.append(
            StepVerdict(
                name=f"step{k}",
                key="omega",
                link="link1",
                status=status,
                label=p,
                source=p,
                line=k + 1,
                expected=exp,
                got=got,
                difference=diff,
                message=p,
                convention=p,
                frame=p,
                caused_by="step0" if k else "",
            )
        )
    steps.append(
        StepVerdict(
            name=PAYLOADS[1][1],
            key="",
            link="",
            status="unrecognised",
            label=PAYLOADS[1][1],
            source=PAYLOADS[1][1],
            line=99,
            expected=None,
            got=None,
            difference=None,
            message=PAYLOADS[3][1],
        )
    )
    return GradeReport(
        robot=PAYLOADS[4][1],
        method=PAYLOADS[5][1],
        submission=PAYLOADS[6][1],
        steps=steps,
        first_wrong="step1",
        tau_correct=[False],
        notes=[p for _, p in PAYLOADS],
        symbol_latex={th: PAYLOADS[7][1], thd: PAYLOADS[8][1]},
    )


def test_grade_report_with_hostile_labels(tmp_path):
    out = tmp_path / "labels.html"
    out.write_text(report_html(_hand_report()), encoding="utf-8")
    markup = out.read_text(encoding="utf-8")
    _assert_static(markup, [t for t, _ in PAYLOADS], csp=True)
    _assert_nothing_ran(out, require_chromium(), tmp_path)


def test_derive_html_of_hostile_model(tmp_path):
    import armdyn
    from armdyn.io.yaml import load_yaml_string
    from armdyn.symbolic.report import derivation_report

    chromium = require_chromium()
    for k, names in enumerate(_groups()):
        model = tmp_path / f"hostile-{k}.yaml"
        model.write_text(_hostile_model(names), encoding="utf-8")
        out = tmp_path / f"derive-{k}.html"
        if k == 0:  # the command line, as a user runs it
            done = _cli("derive", str(model), "--steps", "--method", "both", "--format", "html", cwd=tmp_path)
            assert done.returncode == 0, done.stderr[-2000:]
            out.write_text(done.stdout, encoding="utf-8")
        else:  # the same function in-process (faster)
            robot = load_yaml_string(model.read_text(encoding="utf-8"), source=str(model))
            eoms = [armdyn.derive(robot, "newton-euler"), armdyn.derive(robot, "lagrange")]
            out.write_text(derivation_report(eoms, "html", steps=True, agreement=armdyn.check(*eoms)), encoding="utf-8")
        markup = out.read_text(encoding="utf-8")
        tokens = [t for t, p in PAYLOADS if p in names.values()]
        _assert_static(markup, tokens, csp=True)
        _assert_nothing_ran(out, chromium, tmp_path)


def test_unprintable_model_name_is_refused():
    from armdyn.errors import ModelError
    from armdyn.io.yaml import load_yaml_string

    nul = [p for _, p in PAYLOADS if not p.isprintable()]
    assert nul
    for slot in _SLOTS[1:]:
        with pytest.raises(ModelError, match="expected a name"):
            load_yaml_string(_hostile_model({slot: nul[0]}), source="hostile.yaml")


def test_jupyter_fragments_of_hostile_objects(tmp_path):
    import armdyn
    from armdyn.io.yaml import load_yaml_string

    parts, tokens = [], []
    for k, names in enumerate(_groups()):
        robot = load_yaml_string(_hostile_model(names), source=f"hostile-{k}.yaml")
        eom = armdyn.derive(robot)
        parts += [
            robot._repr_html_(),
            eom._repr_html_(),
            armdyn.check(eom, armdyn.derive(robot, "lagrange"))._repr_html_(),
        ]
        tokens += [t for t, p in PAYLOADS if p in names.values()]
    parts.append(_hand_report()._repr_html_())
    for part in parts:
        assert not html_findings(part), html_findings(part)[:5]
        assert "<html" not in part and "Content-Security-Policy" not in part  # a fragment
    # a notebook-like page holding the fragments, with no policy of its own
    notebook = tmp_path / "notebook.html"
    notebook.write_text(
        '<!DOCTYPE html><html><head><meta charset="utf-8"><title>notebook</title></head><body>'
        + "".join(f'<div class="cell">{p}</div>' for p in parts)
        + "</body></html>",
        encoding="utf-8",
    )
    _assert_static(notebook.read_text(encoding="utf-8"), tokens, csp=False)
    _assert_nothing_ran(notebook, require_chromium(), tmp_path)


def test_browser_check_sees_a_script_and_the_policy_stops_it(tmp_path):
    """Control: a page with a live script (as no armdyn page has) shows the canary when
    its policy is taken out, and not with the policy in force."""
    chromium = require_chromium()
    js = PAYLOADS[0][1].split("<script>")[1].split("</script>")[0]
    live = tmp_path / "live.html"
    live.write_text(page("control", f'<p>x</p><img src="x" onerror="{js}"><script>{js}</script>'), encoding="utf-8")
    assert CANARY not in dump_dom(live, chromium)
    bare = tmp_path / "live-bare.html"
    bare.write_text(without_csp(live.read_text(encoding="utf-8")), encoding="utf-8")
    assert dump_dom(bare, chromium).count(CANARY) == 2  # the inline script and the image's handler
