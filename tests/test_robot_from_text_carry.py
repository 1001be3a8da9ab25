"""A slip carried through steps the method has no formula for (V from the V_k, G from V), a
uniform link's length read from its halfway centre, and the no-model statuses (`consistent`,
a slip in a part of a value a step does not use). The truths are the corpus files' (established
by ``tests/corpus/truth.py`` with plain SymPy) or by hand, in the comments."""

from __future__ import annotations

from pathlib import Path

import yaml

from armdyn.grading import grade
from armdyn.grading.text import text as report_text

CORPUS = Path(__file__).resolve().parent / "corpus"
STATUS = {"right": "correct", "wrong": "wrong", "follows": "follows-from-earlier-error"}


def _unnamed(name: str, tmp_path) -> Path:
    text = (CORPUS / name).read_text(encoding="utf-8")
    out = tmp_path / name
    out.write_text("\n".join("# (robot removed)" if ln.startswith("robot:") else ln for ln in text.split("\n")))
    return out


def _truth(name: str) -> dict[int, str]:
    eqs = yaml.safe_load((CORPUS / name.replace(".md", ".truth.yaml")).read_text(encoding="utf-8"))["equations"]
    return {e["line"]: STATUS[e["truth"]] for e in eqs if e["truth"] in STATUS}


def test_a_dropped_term_of_the_potential_is_carried_to_v_and_g_with_the_model_named():
    # P_3 drops l_2 sin(q1 + q2); P = sum P_k and phi_k = dP/dq_k, written from it, carry it
    name = "planar-3r-gravity-slip.md"
    report = grade(CORPUS / name)
    got = {v.line: v.status for v in report.steps}
    assert got == _truth(name)
    carried = [v for v in report.steps if v.status == "follows-from-earlier-error"]
    assert carried and all(v.caused_by == "V_3" for v in carried)
    assert report.first_wrong == "V_3"


def test_a_uniform_links_length_is_read_from_its_halfway_centre(tmp_path):
    # link 2's centre at l_2/2 along q1 + q2: link 3 hangs from l_2 there, so P_3 (line 30),
    # which leaves it out, is the slip, and the verdicts are the named model's
    name = "planar-3r-gravity-slip.md"
    report = grade(_unnamed(name, tmp_path))
    assert report.model_note.startswith("model read from the text")
    assert "line 30 places link 3's mass centre with nothing along link 2" in report.model_note
    assert "line 29 makes link 2 uniform and l2 long" in report.model_note
    assert {v.line: v.status for v in report.steps} == _truth(name)


def test_a_centre_not_halfway_reads_no_length(tmp_path):
    # l_{c2} is a distance to the centre, not half a length: nothing is added to link 3
    text = r"""---
method: lagrange
---
Gravity $g$ acts along $-y_0$.

$$V_1 = m_1 g l_{c1}\sin q_1$$

$$V_2 = m_2 g\left(l_1\sin q_1 + l_{c2}\sin(q_1 + q_2)\right)$$

$$V = V_1 + V_2$$
"""
    path = tmp_path / "lc.md"
    path.write_text(text, encoding="utf-8")
    report = grade(path)
    assert "uniform" not in report.model_note
    assert [v.status for v in report.steps] == ["correct"] * 3


_NO_GEOMETRY = r"""---
method: lagrange
---
$$M = \begin{bmatrix} a + 2b\cos q_2 & c + b\cos q_2 \\ c + b\cos q_2 & c \end{bmatrix}$$

$$C = \begin{bmatrix} -b\sin q_2\,\dot q_2 & -b\sin q_2(\dot q_1 + \dot q_2) \\ SIGN b\sin q_2\,\dot q_1 & 0 \end{bmatrix}$$

$$G = \begin{bmatrix} m g\cos q_1 \\ 0 \end{bmatrix}$$

$$\tau_1 = (a + 2b\cos q_2)\ddot q_1 + (c + b\cos q_2)\ddot q_2 - b\sin q_2(2\dot q_1\dot q_2 + \dot q_2^2) + m g\cos q_1$$
"""


def test_no_model_agreeing_with_unchecked_values_is_consistent_not_correct(tmp_path):
    # Spong's C of this M has C_21 = +b sin q2 q1' (by hand: c_112 = -b s2, c_211 = b s2)
    path = tmp_path / "m.md"
    path.write_text(_NO_GEOMETRY.replace("SIGN ", ""), encoding="utf-8")
    report = grade(path)
    got = {v.name: v for v in report.steps}
    assert got["M"].status == "unrecognised"  # a starting value: nothing checks it
    assert got["C"].status == "consistent" and "line 4 could not be checked" in got["C"].message
    assert got["tau_1"].status == "consistent"
    assert report.tau_correct == [False, False] and not report.passed
    text = report_text(report)
    assert "tau_1 not checked" in text and "tau_1 right" not in text and "tau_1 wrong" not in text


def test_a_slip_in_a_row_a_torque_does_not_use_is_not_carried_to_it(tmp_path):
    # C_21 with the wrong sign: C is wrong; tau_1 uses row 1 only, which is right
    path = tmp_path / "m.md"
    path.write_text(_NO_GEOMETRY.replace("SIGN ", "-"), encoding="utf-8")
    got = {v.name: v.status for v in grade(path).steps}
    assert got["C"] == "wrong"
    assert got["tau_1"] == "consistent"
