"""The MathML printer (armdyn.mathml): structure of the markup, parsed with xml.etree.

Expected structures are written from the notation (θ̇₁ is a dot accent on θ with the
index 1 outside it, as Craig and the exercise typeset it) and, where latex2mathml is
installed, compared with an independent converter's rendering of the LaTeX one would
write by hand (``\\dot{\\theta}_1``).
"""

from __future__ import annotations

import unicodedata
import xml.etree.ElementTree as ET

import pytest
import sympy as sp

from armdyn.mathml import DDOT, DOT, MathWriter, latex_to_mathml, to_mathml

NS = "{http://www.w3.org/1998/Math/MathML}"


def parse(markup: str) -> ET.Element:
    """The <math> element (or content wrapped in an mrow), namespace stripped."""
    if not markup.startswith("<math"):
        markup = f'<mrow xmlns="http://www.w3.org/1998/Math/MathML">{markup}</mrow>'
    root = ET.fromstring(markup)
    for e in root.iter():
        e.tag = e.tag.replace(NS, "")
    return root


def body(root: ET.Element) -> ET.Element:
    """The single meaningful child under <math>/<mrow> wrappers."""
    while root.tag in ("math", "mrow") and len(root) == 1:
        root = root[0]
    return root


def shape(e: ET.Element):
    """Tag tree with leaf texts, ignoring attributes and redundant single-child mrows."""
    while e.tag == "mrow" and len(e) == 1:
        e = e[0]
    if len(e) == 0:
        return (e.tag, (e.text or "").strip())
    return (e.tag, tuple(shape(c) for c in e))


def sym(name):
    return sp.Symbol(name)


def test_dotted_coordinate_is_accent_inside_subscript():
    e = body(parse(to_mathml(sym("theta1_dot"))))
    assert e.tag == "msub"
    mover, index = e[0], e[1]
    assert mover.tag == "mover" and mover.get("accent") == "true"
    assert mover[0].tag == "mi" and unicodedata.name(mover[0].text) == "GREEK SMALL LETTER THETA"
    assert mover[1].tag == "mo" and mover[1].text == DOT == "\u02d9"
    assert index.tag == "mn" and index.text == "1"


def test_double_dot_and_latin_coordinate():
    e = body(parse(to_mathml(sym("d2_ddot"))))
    assert shape(e) == ("msub", (("mover", (("mi", "d"), ("mo", DDOT))), ("mn", "2")))


def test_same_structure_as_latex_written_by_hand():
    pytest.importorskip("latex2mathml")
    for name, latex in [
        ("theta1_dot", r"\dot{\theta}_1"),
        ("d2_ddot", r"\ddot{d}_2"),
        ("l1", "l_1"),
        ("alpha3", r"\alpha_3"),
        ("theta12", r"\theta_{12}"),
    ]:
        ours = shape(body(parse(to_mathml(sym(name)))))
        theirs = shape(body(parse(latex_to_mathml(latex))))
        assert ours == theirs, (name, ours, theirs)


@pytest.mark.parametrize(
    "name, base, index",
    [
        ("l1", "l", ("mn", "1")),
        ("m2", "m", ("mn", "2")),
        ("theta12", "\u03b8", ("mn", "12")),
        ("Theta3", "\u0398", ("mn", "3")),
        ("a_i", "a", ("mi", "i")),
        ("I1xx", "I", ("mrow", (("mn", "1"), ("mi", "x"), ("mi", "x")))),
    ],
)
def test_indices_and_greek(name, base, index):
    e = body(parse(to_mathml(sym(name))))
    assert e.tag == "msub" and e[0].text == base and shape(e[1]) == index


def test_plain_names():
    assert shape(body(parse(to_mathml(sym("g"))))) == ("mi", "g")
    assert shape(body(parse(to_mathml(sym("lambda"))))) == ("mi", "\u03bb")


def test_power_of_indexed_symbol_stacks_index_and_exponent():
    e = body(parse(to_mathml(sym("theta1_dot") ** 2)))
    assert e.tag == "msubsup"
    assert e[0].tag == "mover" and shape(e[1]) == ("mn", "1") and shape(e[2]) == ("mn", "2")


def test_column_vector_is_table_in_stretchy_parentheses_with_highlight():
    q = sp.symbols("theta1 theta1_dot theta1_ddot")
    e = body(parse(to_mathml(sp.Matrix([q[0], q[1] / 2, 0]), highlight=[0, 2])))
    assert e.tag == "mrow" and [c.tag for c in e] == ["mo", "mtable", "mo"]
    assert (e[0].text, e[2].text) == ("(", ")")
    assert e[0].get("stretchy") == "true" and e[2].get("stretchy") == "true"
    rows = e[1].findall("mtr")
    assert len(rows) == 3
    assert [r.get("class") for r in rows] == ["hl", None, "hl"]
    assert rows[1].find(".//mfrac") is not None  # theta1_dot / 2


def test_sin_cos_as_function_names():
    th, d = sym("theta1"), sym("d2")
    e = body(parse(to_mathml(sp.sin(th))))
    tags = [c.tag for c in e if c.tag != "mspace"]
    assert tags == ["mi", "mo", "msub"] and e.find("mi").text == "sin"
    assert e.find("mo").text == "\u2061"  # FUNCTION APPLICATION, no parentheses around a symbol
    e = body(parse(to_mathml(sp.cos(th + d))))
    parens = [m for m in e.iter("mo") if m.text in "()"]
    assert len(parens) == 2 and all(p.get("stretchy") == "true" for p in parens)
    e = body(parse(to_mathml(sp.sin(th) ** 2)))
    sup = e.find("msup")
    assert sup is not None and shape(sup) == ("msup", (("mi", "sin"), ("mn", "2")))


def test_fraction_and_stretchy_parentheses_around_a_sum():
    l1, m1, m2 = sp.symbols("l1 m1 m2")
    root = parse(to_mathml((m1 + m2) * l1 / 2))
    assert root.find(".//mfrac") is not None
    parens = [m for m in root.iter("mo") if m.text in "()"]
    assert len(parens) == 2 and all(p.get("stretchy") == "true" for p in parens)


def test_minus_is_a_minus_sign():
    root = parse(to_mathml(-sym("l1") * sym("theta1_dot") ** 2 + sym("g")))
    ops = [m.text for m in root.iter("mo")]
    assert "\u2212" in ops and "-" not in ops


def test_student_notation_replaces_model_names():
    pytest.importorskip("latex2mathml")
    qd = sym("theta1_dot")
    root = parse(to_mathml(sym("l1") * qd, symbol_latex={qd: r"\dot{q}_1"}))
    texts = [e.text for e in root.iter() if e.text and e.text.strip()]
    assert "q" in texts and "\u03b8" not in texts
    mover = root.find(".//mover")
    assert mover is not None and mover.get("accent") == "true"


def test_bad_latex_in_mapping_falls_back_to_model_name():
    qd = sym("theta1_dot")
    root = parse(to_mathml(qd, symbol_latex={qd: r"\dot{"}))
    assert root.find(".//mover") is not None  # printed from the model name


def test_text_is_escaped_and_wellformed():
    root = parse(to_mathml(sym("a<b&c") + sp.Function("f<x>")(sym("x"))))
    texts = [e.text for e in root.iter() if e.text]
    assert "a<b&c" in "".join(texts) and "f<x>" in "".join(texts)


def test_terms_folds_signs_and_unit_coefficients():
    l1, m2, qdd, qd = sp.symbols("l1 m2 theta1_ddot theta1_dot")
    w = MathWriter()
    markup = w.terms([(sp.Integer(1), qdd), (-l1 * m2, qd**2), (m2 + l1, qdd)])
    root = parse(markup)
    top = body(root)
    ops = [c.text for c in top if c.tag == "mo"]
    assert ops[:2] == ["\u2212", "\u2062"] and ("+" in ops)
    assert top[0].tag == "msub"  # the leading "1" coefficient is not printed
    assert parse(w.terms([])).find(".//mn").text == "0"


def test_power_of_symbol_in_student_notation_stacks_too():
    pytest.importorskip("latex2mathml")
    qd = sym("theta1_dot")
    e = body(parse(to_mathml(qd**2, symbol_latex={qd: r"\dot{\theta}_1"})))
    assert e.tag == "msubsup" and e[0].tag == "mover" and shape(e[2]) == ("mn", "2")


def test_multi_letter_names_are_italic_letters():
    e = body(parse(to_mathml(sym("Ixx1"))))
    assert shape(e) == ("msub", (("mrow", (("mi", "I"), ("mi", "x"), ("mi", "x"))), ("mn", "1")))


def test_long_sums_break_into_lines_with_leading_signs():
    syms = sp.symbols("a0:12")
    terms = [((-1) ** k * syms[k], sp.Integer(1)) for k in range(12)]
    w = MathWriter()
    one = body(parse(w.terms(terms)))
    assert one.tag == "mrow" and one.find("mtable") is None
    table = body(parse(w.terms(terms, width=10)))
    assert table.tag == "mtable"
    rows = table.findall("mtr")
    assert len(rows) >= 3
    # every term is printed exactly once, and each continuation line starts with its sign
    indices = sorted(int(e[1].text) for e in table.iter("msub"))
    assert indices == list(range(12))
    for r in rows[1:]:
        cell = r.find("mtd")
        assert cell[0].tag == "mspace"
        first = cell[1][0]
        assert first.tag == "mo" and first.text in ("+", "\u2212") and first.get("form") == "prefix"


def test_negative_numbers_use_a_minus_sign():
    root = parse(to_mathml(sp.Matrix([[1, 0], [0, -1]])))
    assert all("-" not in (e.text or "") for e in root.iter("mn"))
    assert "\u2212" in [e.text for e in root.iter("mo")]
    root = parse(to_mathml(sp.Float(-2.5) * sym("g")))
    assert all("-" not in (e.text or "") for e in root.iter("mn"))
