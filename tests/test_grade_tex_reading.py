"""Values read as TeX shows them, and a blog's front matter set aside, not refused.

Found on public derivations nobody here wrote: `m_32l_2` (TeX's unbraced subscript is one
character: the page shows m₃2l₂, and the author's closed form needs the 2), plain TeX's
`\\cr` ending matrix rows, and a site generator's front matter (title, layout, tags)
above the derivation. The expected torques are the RP arm's, by hand (the closed forms of
tests/test_grade_reading.py, checked there against a plain SymPy Lagrangian).
"""

from __future__ import annotations

import pytest
import sympy as sp
from test_grade_reading import TAU_1, TAU_2

from armdyn.errors import ModelError
from armdyn.grading import grade
from armdyn.grading.latex import Name, parse


def _plain(name: Name):
    return sp.Symbol(name.base + name.sub)


def test_an_unbraced_subscript_is_one_character():
    m3, l2, c3 = sp.symbols("m3 l2 c3")
    assert parse(r"m_3l_2^2 + m_32l_2l_{c_3}c_3", _plain) == m3 * l2**2 + 2 * m3 * l2 * sp.Symbol("lc_3") * c3
    assert parse(r"m_{32}", _plain) == sp.Symbol("m32")  # braced: the whole group
    assert parse(r"\frac12 m_1", _plain) == sp.Symbol("m1") / 2


def test_plain_tex_cr_ends_a_row():
    a, b = sp.symbols("a b")
    assert parse(r"\begin{bmatrix} a \cr b \end{bmatrix}", _plain) == sp.Matrix([a, b])


def test_a_site_generators_front_matter_is_set_aside_with_a_note(tmp_path):
    path = tmp_path / "post.md"
    path.write_text(
        "---\ntitle: Dynamics of an RP arm\nlayout: post\ntags: [robotics]\nrobot: rp-arm\n---\n"
        f"$$\\tau_1 = {TAU_1}$$\n\n$$\\tau_2 = {TAU_2}$$\n",
        encoding="utf-8",
    )
    report = grade(str(path))
    assert [(v.name, v.status) for v in report.steps] == [("tau_1", "correct"), ("tau_2", "correct")]
    assert any("layout, tags set aside" in n for n in report.notes), report.notes


def test_a_yaml_submission_still_refuses_an_unknown_key(tmp_path):
    path = tmp_path / "steps.yaml"
    path.write_text("robot: rp-arm\nrobto: x\nsteps:\n  tau_2: m2*g\n", encoding="utf-8")
    with pytest.raises(ModelError, match="unknown key"):
        grade(str(path))


def test_a_torque_that_could_not_be_read_is_said_so_not_called_wrong(tmp_path):
    path = tmp_path / "t.md"
    path.write_text(f"---\nrobot: rp-arm\n---\n$$\\tau_1 = {{m_1$$\n\n$$\\tau_2 = {TAU_2}$$\n", encoding="utf-8")
    text = grade(str(path)).text()
    assert "final torques: tau_1 not read (line 4); tau_2 right" in text, text
