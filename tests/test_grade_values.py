"""Values written through names the student gave values to: ``\\ell``, earlier steps by name
(``d_{11}``, ``\\phi_1``, ``{}^{2}F_2``), definitions (``X = ...``), ``KE - PE``.

Every derivation here is checked first against plain SymPy (the planar elbow's Lagrange
equations derived by hand below), never against armdyn's output."""

from __future__ import annotations

from pathlib import Path

import sympy as sp
import yaml

from armdyn.grading import grade
from armdyn.grading.latex import Name, parse

CORPUS = Path(__file__).parent / "corpus"

HEADER = r"""---
robot: planar-2r
method: lagrange
symbols:
  'q_1': q1
  'q_2': q2
  '\ell_1': l1
  '\ell_{c1}': lc1
  '\ell_{c2}': lc2
  'm_1': m1
  'm_2': m2
  'I_1': I1
  'I_2': I2
  'g': g
---

"""

# the planar elbow by hand (Spong 7.4.2): mass centres, energies, Lagrange's equations
q1, q2, qd1, qd2, qdd1, qdd2 = sp.symbols("q1 q2 qd1 qd2 qdd1 qdd2")
l1, lc1, lc2, m1, m2, I1, I2, g = sp.symbols("l1 lc1 lc2 m1 m2 I1 I2 g")
t = sp.Symbol("t")


def _lagrange():
    a1, a2 = sp.Function("a1")(t), sp.Function("a2")(t)
    pc1 = sp.Matrix([lc1 * sp.cos(a1), lc1 * sp.sin(a1)])
    pc2 = sp.Matrix([l1 * sp.cos(a1) + lc2 * sp.cos(a1 + a2), l1 * sp.sin(a1) + lc2 * sp.sin(a1 + a2)])
    v1, v2 = pc1.diff(t), pc2.diff(t)
    w1, w2 = a1.diff(t), a1.diff(t) + a2.diff(t)
    K = (m1 * v1.dot(v1) + m2 * v2.dot(v2) + I1 * w1**2 + I2 * w2**2) / 2
    P = g * (m1 * pc1[1] + m2 * pc2[1])
    L = K - P
    taus = [sp.diff(L.diff(a.diff(t)), t) - L.diff(a) for a in (a1, a2)]
    subs = {
        a1.diff(t, 2): qdd1,
        a2.diff(t, 2): qdd2,
        a1.diff(t): qd1,
        a2.diff(t): qd2,
    }
    plain = lambda e: e.subs(subs).subs({a1: q1, a2: q2})  # noqa: E731
    return [sp.expand(plain(x)) for x in taus], plain(K), plain(P)


TAU, K_HAND, P_HAND = _lagrange()
# the entries written below, by hand
D11 = m1 * lc1**2 + m2 * (l1**2 + lc2**2 + 2 * l1 * lc2 * sp.cos(q2)) + I1 + I2
D12 = m2 * (lc2**2 + l1 * lc2 * sp.cos(q2)) + I2
D22 = m2 * lc2**2 + I2
H = -m2 * l1 * lc2 * sp.sin(q2)
PHI1 = (m1 * lc1 + m2 * l1) * g * sp.cos(q1) + m2 * lc2 * g * sp.cos(q1 + q2)
PHI2 = m2 * lc2 * g * sp.cos(q1 + q2)


def _same(a, b) -> bool:
    return sp.simplify(sp.expand_trig(sp.expand(a - b))) == 0


def test_the_hand_entries_are_lagranges():
    # τ = D q̈ + C q̇ + φ with Spong's c_121 = c_211 = c_221 = h, c_112 = -h
    tau1 = D11 * qdd1 + D12 * qdd2 + 2 * H * qd1 * qd2 + H * qd2**2 + PHI1
    tau2 = D12 * qdd1 + D22 * qdd2 - H * qd1**2 + PHI2
    assert _same(tau1, TAU[0]) and _same(tau2, TAU[1])
    assert not _same(tau1 - I2 * qdd2, TAU[0])  # the slip used below is one


def write(tmp_path, body: str, name: str = "d.md"):
    path = tmp_path / name
    path.write_text(HEADER + body)
    return path


def by_line(report):
    return {v.line: v for v in report.steps}


ENTRIES = r"""$$d_{11} = m_1\ell_{c1}^2 + m_2\left(\ell_1^2 + \ell_{c2}^2 + 2\ell_1\ell_{c2}\cos q_2\right) + I_1 + I_2$$

$$d_{12} = m_2\left(\ell_{c2}^2 + \ell_1\ell_{c2}\cos q_2\right) + I_2$$

$$d_{22} = m_2\ell_{c2}^2 + I_2$$

$$c_{121} = -m_2\ell_1\ell_{c2}\sin q_2$$

$$c_{211} = -m_2\ell_1\ell_{c2}\sin q_2$$

$$c_{221} = -m_2\ell_1\ell_{c2}\sin q_2$$

$$\phi_1 = (m_1\ell_{c1} + m_2\ell_1) g\cos q_1 + m_2\ell_{c2} g\cos(q_1 + q_2)$$

"""
TAU1_BY_NAMES = (
    r"$$\tau_1 = d_{11}\ddot q_1 + d_{12}\ddot q_2 + c_{121}\dot q_1\dot q_2 + c_{211}\dot q_2\dot q_1"
    r" + c_{221}\dot q_2^2 + \phi_1$$" + "\n"
)


def test_ell_is_the_letter_l():
    seen: list[Name] = []
    value = parse(r"\ell_{c1}^2 + \ell_1 + ℓ", lambda n: seen.append(n) or sp.Symbol(n.base + n.sub))
    assert [(n.base, n.sub) for n in seen] == [("l", "c1"), ("l", "1"), ("l", "")]
    assert value == sp.Symbol("lc1") ** 2 + sp.Symbol("l1") + sp.Symbol("l")


def test_ell_values_are_graded(tmp_path):
    report = grade(write(tmp_path, r"$$d_{22} = m_2\ell_{c2}^2 + I_2$$" + "\n"))
    (d22,) = report.steps
    assert d22.key == "M" and d22.status == "correct", d22.message
    report = grade(write(tmp_path, r"$$d_{22} = m_2\ell_{c2}^2 + I_1$$" + "\n"))
    assert report.steps[0].status == "wrong"


def test_a_torque_through_the_entries_written_before_it(tmp_path):
    report = grade(write(tmp_path, ENTRIES + TAU1_BY_NAMES))
    tau = report.steps[-1]
    assert tau.name == "tau_1" and tau.status == "correct", tau.message
    assert all(v.status == "correct" for v in report.steps), [(v.name, v.status, v.message) for v in report.steps]


def test_a_wrong_entry_is_carried_into_the_torque(tmp_path):
    body = ENTRIES.replace(r"\ell_1\ell_{c2}\cos q_2\right) + I_2$$", r"\ell_1\ell_{c2}\cos q_2\right)$$")
    report = grade(write(tmp_path, body + TAU1_BY_NAMES))
    d12 = next(v for v in report.steps if v.label == "d_{12}")
    tau = report.steps[-1]
    assert d12.status == "wrong"
    assert tau.status == "follows-from-earlier-error", tau.message
    assert tau.caused_by == d12.name and f"line {d12.line}" in tau.message


def test_a_model_quantity_not_written_is_the_models_and_said(tmp_path):
    body = r"$$\tau_2 = d_{21}\ddot q_1 + d_{22}\ddot q_2 + c_{112}\dot q_1^2 + \phi_2$$" + "\n"
    report = grade(write(tmp_path, body))
    (tau,) = report.steps
    assert tau.status == "correct", tau.message
    assert "d_{21} not written: the model's value used" in tau.message
    assert "\\phi_{2} not written" in tau.message or "phi_2 not written" in tau.message.replace("\\", "")


def test_a_definition_is_used_in_later_values(tmp_path):
    body = (
        r"$$h = -m_2\ell_1\ell_{c2}\sin q_2$$" + "\n\n"
        r"$$\tau_2 = (m_2(\ell_{c2}^2 + \ell_1\ell_{c2}\cos q_2) + I_2)\ddot q_1 + (m_2\ell_{c2}^2 + I_2)\ddot q_2"
        r" - h\dot q_1^2 + m_2\ell_{c2} g\cos(q_1 + q_2)$$" + "\n"
    )
    report = grade(write(tmp_path, body))
    h, tau = report.steps
    assert h.status == "unrecognised" and h.message.startswith("defines h (used in later steps)")
    assert tau.status == "correct", tau.message


def test_a_definition_after_its_use(tmp_path):
    body = (
        r"$$\tau_2 = X\ddot q_1 + (m_2\ell_{c2}^2 + I_2)\ddot q_2 + m_2\ell_1\ell_{c2}\sin q_2\,\dot q_1^2 + Y$$"
        + "\n\nwhere\n\n"
        + r"$$X = m_2(\ell_{c2}^2 + \ell_1\ell_{c2}\cos q_2) + I_2$$"
        + "\n\n"
        + r"$$Y = m_2\ell_{c2} g\cos(q_1 + q_2)$$"
        + "\n"
    )
    report = grade(write(tmp_path, body))
    assert report.steps[0].status == "correct", report.steps[0].message
    assert [v.message.split(" (")[0] for v in report.steps[1:]] == ["defines X", "defines Y"]


def test_a_definition_through_a_definition(tmp_path):
    body = (
        r"$$s = \sin q_2$$" + "\n\n" + r"$$h = -m_2\ell_1\ell_{c2} s$$" + "\n\n"
        r"$$\tau_2 = (m_2(\ell_{c2}^2 + \ell_1\ell_{c2}\cos q_2) + I_2)\ddot q_1 + (m_2\ell_{c2}^2 + I_2)\ddot q_2"
        r" - h\dot q_1^2 + m_2\ell_{c2} g\cos(q_1 + q_2)$$" + "\n"
    )
    report = grade(write(tmp_path, body))
    assert report.steps[-1].status == "correct", report.steps[-1].message


def test_a_definition_against_the_shorthand_is_used_and_said(tmp_path):
    body = r"$$c_2 = \sin q_2$$" + "\n\n" + r"$$d_{22} = m_2\ell_{c2}^2 + I_2 + c_2 - \sin q_2$$" + "\n"
    report = grade(write(tmp_path, body))
    c2, d22 = report.steps
    # the definition itself is checked as the shorthand it names (sin for cos: wrong, at its line)
    assert c2.status == "wrong" and c2.line == 17, (c2.status, c2.message)
    assert "sine and cosine swapped" in c2.message
    assert d22.status == "correct"  # graded with the definition: c_2 - sin q_2 = 0
    body = r"$$c_2 = \sin q_2$$" + "\n\n" + r"$$d_{12} = m_2(\ell_{c2}^2 + \ell_1\ell_{c2} c_2) + I_2$$" + "\n"
    report = grade(write(tmp_path, body))
    d12 = report.steps[1]
    # wrong only through the student's own c_2: it follows from that line's error
    assert d12.status == "follows-from-earlier-error" and "line 17" in d12.message, d12.message


def test_a_cycle_of_definitions_is_not_read(tmp_path):
    body = r"$$X = Y + 1$$" + "\n\n" + r"$$Y = 2X$$" + "\n\n" + r"$$\tau_2 = X$$" + "\n"
    report = grade(write(tmp_path, body))
    tau = report.steps[-1]
    assert tau.status == "unrecognised" and "defined through itself" in tau.message


def test_kinetic_minus_potential_by_their_names(tmp_path):
    # K and P by hand, written out
    k = (
        r"\frac12 m_1\ell_{c1}^2\dot q_1^2 + \frac12 m_2(\ell_1^2\dot q_1^2 + \ell_{c2}^2(\dot q_1 + \dot q_2)^2"
        r" + 2\ell_1\ell_{c2}\cos q_2\,\dot q_1(\dot q_1 + \dot q_2)) + \frac12 I_1\dot q_1^2"
        r" + \frac12 I_2(\dot q_1 + \dot q_2)^2"
    )
    p = r"(m_1\ell_{c1} + m_2\ell_1) g\sin q_1 + m_2\ell_{c2} g\sin(q_1 + q_2)"
    k_sym = (
        m1 * lc1**2 * qd1**2 / 2
        + m2 * (l1**2 * qd1**2 + lc2**2 * (qd1 + qd2) ** 2 + 2 * l1 * lc2 * sp.cos(q2) * qd1 * (qd1 + qd2)) / 2
        + I1 * qd1**2 / 2
        + I2 * (qd1 + qd2) ** 2 / 2
    )
    assert _same(k_sym, K_HAND)
    assert _same((m1 * lc1 + m2 * l1) * g * sp.sin(q1) + m2 * lc2 * g * sp.sin(q1 + q2), P_HAND)
    for lagrangian in (r"KE - PE", r"K.E. - P.E.", r"\mathrm{KE} - \mathrm{PE}"):
        body = f"$$KE = {k}$$\n\n$$PE = {p}$$\n\n$$L = {lagrangian}$$\n"
        report = grade(write(tmp_path, body))
        assert report.steps[-1].status == "correct", (lagrangian, report.steps[-1].message)
    body = f"$$KE = {k} + \\dot q_1^2$$\n\n$$PE = {p}$$\n\n$$L = KE - PE$$\n"
    report = grade(write(tmp_path, body))
    assert report.steps[-1].status == "follows-from-earlier-error"


def _truth(name: str) -> dict:
    return {e["line"]: e for e in yaml.safe_load((CORPUS / f"{name}.truth.yaml").read_text())["equations"]}


def _agrees(verdict, truth) -> bool:
    if truth["truth"] == "right":
        return verdict.status in ("correct", "correct-by-convention")
    if truth["truth"] == "wrong":
        return verdict.status == "wrong"
    return verdict.status in ("follows-from-earlier-error", "wrong")


def test_newton_euler_step_names_in_values_against_the_corpus_truth():
    # {}^{2}F_2 = m_2 {}^{2}\dot v_{C_2}, {}^{2}f_2 = {}^{2}F_2: read through the earlier steps
    report = grade(CORPUS / "planar-2r-craig-align.md")
    truth, steps = _truth("planar-2r-craig-align"), by_line(report)
    for line in (57, 66):
        assert _agrees(steps[line], truth[line]), (line, steps[line].status, steps[line].message)


def test_spong_names_and_a_where_clause_against_the_corpus_truth():
    # a_{c,3} uses X and Y defined after it; f_3 = m_3 a_{c,3} - m_3 g_3 carries its slip
    report = grade(CORPUS / "planar-3r-spong-ne-slip.md")
    truth, steps = _truth("planar-3r-spong-ne-slip"), by_line(report)
    assert truth[48]["truth"] == "wrong" and steps[48].status == "wrong"
    assert truth[60]["truth"] == "follows" and steps[60].status == "follows-from-earlier-error"
    assert steps[52].message.startswith("defines X")


NE_HEADER = HEADER.replace("method: lagrange", "method: newton-euler")


def test_a_torque_of_step_names_only(tmp_path):
    # τ_1 = n_1ᵀ ẑ_1 is the revolute joint's torque by definition: read through n_1 (not
    # written: the method's), it is right; through a written n_1 that is wrong, it carries it
    body = r"$$\tau_1 = n_1^{1T}\hat Z_1^1$$" + "\n"
    report = grade(write(tmp_path, body, "a.md"))
    assert report.steps[0].status == "correct", report.steps[0].message
    body = r"$$n_1^1 = \begin{pmatrix} 0 \\ 0 \\ 0 \end{pmatrix}$$" + "\n\n" + body
    path = tmp_path / "b.md"
    path.write_text(NE_HEADER + body)
    n1, tau = grade(path).steps
    assert n1.status == "wrong" and tau.status == "follows-from-earlier-error", tau.message


def test_a_name_of_another_meaning_is_not_a_wrong_shorthand(tmp_path):
    # Lynch & Park's c_1 is the velocity-product entry: no note that it contradicts cos q_1
    body = r"$$c_1 = -m_2\ell_1\ell_{c2}\sin q_2\,(2\dot q_1\dot q_2 + \dot q_2^2)$$" + "\n"
    report = grade(write(tmp_path, body + r"$$d_{22} = m_2\ell_{c2}^2 + I_2$$" + "\n"))
    first = report.steps[0]  # graded as entry 1 of c(q, q_dot), not as a wrong cos q_1
    assert first.status == "correct" and "velocity-product" in first.message and not report.notes, first.message
    # a shorthand used before a later definition of that name keeps its meaning
    body = r"$$d_{12} = m_2(\ell_{c2}^2 + \ell_1\ell_{c2} c_2) + I_2$$" + "\n\n" + r"$$c_2 = \dot q_2^2$$" + "\n"
    assert grade(write(tmp_path, body)).steps[0].status == "correct"


def test_hostile_chains_of_definitions_end_quickly(tmp_path):
    import time

    # each definition squares the last, or nests a sine: the parser's limits hold through names
    squares = "".join(f"$$X_{{{k}}} = X_{{{k - 1}}}^{{20}} + q_1$$\n\n" for k in range(1, 40))
    sines = "".join(f"$$W_{{{k}}} = \\sin(W_{{{k - 1}}})$$\n\n" for k in range(1, 40))  # W: no shorthand
    for chain, last in ((squares, "X_{39}"), (sines, "W_{39}")):
        body = "$$X_{0} = q_2$$\n\n$$W_{0} = q_2$$\n\n" + chain + f"$$\\tau_2 = {last}$$\n"
        start = time.perf_counter()
        report = grade(write(tmp_path, body))
        assert time.perf_counter() - start < 20
        tau = report.steps[-1]
        if last.startswith("W"):  # sin(sin(...)) 39 deep: refused, as written out it would be
            assert tau.status == "unrecognised" and "nesting of functions" in tau.message, tau.message
        else:  # (...(q_2^20 + q_1)^20 ...)^20: a huge degree, never a pass
            assert tau.status in ("wrong", "unrecognised")


def test_entries_of_a_matrix_written_whole(tmp_path):
    # d_{12} and \phi_2 not written by themselves: the entries of the student's D(q), g(q)
    d = (
        r"$$D(q) = \begin{pmatrix} m_1\ell_{c1}^2 + m_2(\ell_1^2 + \ell_{c2}^2 + 2\ell_1\ell_{c2}\cos q_2) + I_1 + I_2"
        r" & m_2(\ell_{c2}^2 + \ell_1\ell_{c2}\cos q_2) + I_2 \\ m_2(\ell_{c2}^2 + \ell_1\ell_{c2}\cos q_2) + I_2"
        r" & m_2\ell_{c2}^2 + I_2 \end{pmatrix}$$" + "\n\n"
    )
    tau = r"$$\tau_2 = d_{21}\ddot q_1 + d_{22}\ddot q_2 + m_2\ell_1\ell_{c2}\sin q_2\,\dot q_1^2 + \phi_2$$" + "\n"
    report = grade(write(tmp_path, d + tau))
    last = report.steps[-1]
    assert last.status == "correct" and "d_{21} read as the entry of D(q) (line 17)" in last.message, last.message
    assert "\\phi_{2} not written" in last.message
    wrong = d.replace(r"& m_2\ell_{c2}^2 + I_2 \end", r"& m_2\ell_{c2}^2 \end")  # I_2 missing in d_22
    report = grade(write(tmp_path, wrong + tau))
    assert report.steps[0].status == "wrong"
    assert report.steps[-1].status == "follows-from-earlier-error", report.steps[-1].message
