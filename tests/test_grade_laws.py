"""The laws of the method stated before they are used (grading/laws.py) and definitions.

Every statement below is written here by hand and its truth decided by hand from the
textbooks (Craig ch. 6; Spong, Hutchinson & Vidyasagar ch. 7; Lynch & Park ch. 8): a right
law in several notations must be ``correct``, each deliberate slip ``wrong`` naming it, and
an equation in one robot's symbols no law at all. The exact-arithmetic core is checked
against plain SymPy identities (a rotation is orthogonal).
"""

from __future__ import annotations

import pytest
import sympy as sp

from armdyn.grading import grade
from armdyn.grading.latex import sides
from armdyn.grading.law_reading import Values, cayley
from armdyn.grading.laws import judge

RIGHT = [
    # kinetic energy of a body: Craig's k_i, Spong's with R I R^T, planar scalars, point mass
    r"k_i = \frac{1}{2} m_i v_{C_i}^T v_{C_i} + \frac{1}{2} {}^{C_i}\omega_i^T\, {}^{C_i}I_i\, {}^{C_i}\omega_i",
    r"K_i = \frac12 m_i v_{c_i}^T v_{c_i} + \frac12 \omega_i^T R_i I_i R_i^T \omega_i",
    r"T = \frac12 m v^2 + \frac12 I\omega^2",
    r"\mathcal{E}_K = \tfrac{1}{2} m v^2 + \tfrac{1}{2} I \omega^2",
    r"K_i = \frac{1}{2} m_i v_i^2",
    r"K_i = \frac12 m_i v_{c_i} \cdot v_{c_i} + \frac12 \omega_i \cdot I_i \omega_i",
    r"K_i = \frac{1}{2} m_i \|v_{c_i}\|^2 + \frac12 \omega_i^T I_i \omega_i",
    # total kinetic energy (also the link's formula summed)
    r"K = \frac12 \sum_{i=1}^{n} \left(m_i v_{c_i}^T v_{c_i} + \omega_i^T I_i \omega_i\right)",
    r"K = \sum_{i=1}^{n} K_i",
    r"T = \frac{1}{2}\dot{q}^T D(q) \dot{q}",
    r"k = \sum_{i=1}^{n} k_i = k(\Theta, \dot\Theta) = \frac{1}{2}\dot\Theta^T M(\Theta)\dot\Theta",
    # potential energy: Craig's (g down, a reference level), Spong's (g up), m g h
    r"u_i = -m_i\,{}^0g^T\,{}^0P_{C_i} + u_{ref}",
    r"P_i = m_i g^T r_{c_i}",
    r"P = m g h",
    r"V = \sum_{i=1}^{n} V_i",
    r"P = \sum_{i=1}^{n} m_i g^T r_{c_i}",
    r"U_i = m_i g y_{c_i}",
    r"L = \sum_{i=1}^{n} (K_i - P_i)",
    # the Lagrangian and the Lagrange equation
    r"\mathcal{L} = K - P",
    r"L = T - V",
    r"L(\Theta, \dot\Theta) = k(\Theta, \dot\Theta) - u(\Theta)",
    r"\tau = \frac{d}{dt}\frac{\partial L}{\partial \dot q} - \frac{\partial L}{\partial q}",
    r"\tau_i = \frac{d}{dt}\frac{\partial \mathcal{L}}{\partial \dot\theta_i} - \frac{\partial \mathcal{L}}{\partial \theta_i}",
    # Spong's mass matrix, Christoffel symbols (free index last, and first as Lynch & Park), gravity term
    r"D(q) = \sum_{i=1}^{n} m_i J_{v_i}^T J_{v_i} + J_{\omega_i}^T R_i I_i R_i^T J_{\omega_i}",
    r"c_{ijk} = \frac12\left(\frac{\partial d_{kj}}{\partial q_i} + \frac{\partial d_{ki}}{\partial q_j}"
    r" - \frac{\partial d_{ij}}{\partial q_k}\right)",
    r"\Gamma_{ijk} = \frac12\left(\frac{\partial m_{ij}}{\partial \theta_k} + \frac{\partial m_{ik}}{\partial \theta_j}"
    r" - \frac{\partial m_{jk}}{\partial \theta_i}\right)",
    r"C_{kj} = \sum_{i=1}^{n} c_{ijk}\dot q_i",
    r"\phi_k = \frac{\partial P}{\partial q_k}",
    # the gravity vector from the Jacobians, g along gravity (minus) or against it (Spong)
    r"G = -J_{v_1}^T m_1 g - J_{v_2}^T m_2 g",
    r"G(q) = \sum_{i=1}^{n} J_{v_i}^T m_i g",
    # the inverse rotation
    r"{}^{i}_{i+1}R = \bigl(\,{}^{i+1}_{i}R\bigr)^T",
    # Craig's outward and inward iterations (revolute and prismatic)
    r"{}^{i+1}\omega_{i+1} = {}^{i+1}_{i}R\,{}^{i}\omega_i + \dot\theta_{i+1}\,{}^{i+1}\hat Z_{i+1}",
    r"{}^{i+1}\omega_{i+1} = {}^{i+1}_{i}R\,{}^{i}\omega_i",
    r"{}^{i+1}\dot\omega_{i+1} = {}^{i+1}_{i}R\,{}^{i}\dot\omega_i + {}^{i+1}_{i}R\,{}^{i}\omega_i \times"
    r" \dot\theta_{i+1}\,{}^{i+1}\hat Z_{i+1} + \ddot\theta_{i+1}\,{}^{i+1}\hat Z_{i+1}",
    r"{}^{i+1}\dot v_{i+1} = {}^{i+1}_{i}R\left({}^{i}\dot\omega_i \times {}^{i}P_{i+1} + {}^{i}\omega_i \times"
    r" \left({}^{i}\omega_i \times {}^{i}P_{i+1}\right) + {}^{i}\dot v_i\right)",
    r"{}^{i}\dot v_{C_i} = {}^{i}\dot\omega_i \times {}^{i}P_{C_i} + {}^{i}\omega_i \times \left({}^{i}\omega_i"
    r" \times {}^{i}P_{C_i}\right) + {}^{i}\dot v_i",
    r"{}^{i}F_{i} = m_i\,{}^{i}\dot v_{C_i}",
    r"{}^{i}N_{i} = {}^{C_i}I_i\,{}^{i}\dot\omega_i + {}^{i}\omega_i \times {}^{C_i}I_i\,{}^{i}\omega_i",
    r"{}^{i}f_{i} = {}^{i}_{i+1}R\,{}^{i+1}f_{i+1} + {}^{i}F_{i}",
    r"{}^{i}n_{i} = {}^{i}N_{i} + {}^{i}_{i+1}R\,{}^{i+1}n_{i+1} + {}^{i}P_{C_i}\times{}^{i}F_{i}"
    r" + {}^{i}P_{i+1}\times{}^{i}_{i+1}R\,{}^{i+1}f_{i+1}",
    r"\tau_i = {}^{i}n_i^T\,{}^{i}\hat Z_i",
    r"\tau_i = {}^in^{T}_i\; {}^i\hat{Z}_i",
]


@pytest.mark.parametrize("statement", RIGHT)
def test_a_right_law_is_correct(statement):
    result = judge(sides(statement), n_links=2)
    assert result is not None, statement
    assert result.status == "correct", (statement, result.message)
    assert "as in the textbooks" in result.message


# (statement, what the message must name): each one slip, decided by hand
WRONG = [
    (r"L = K + P", "potential energy"),
    (r"\mathcal{L} = P - K", "wrong sign"),
    (r"T = m v^2 + \frac12 I\omega^2", "½"),
    (r"k_i = m_i v_{C_i}^T v_{C_i} + \frac{1}{2} \omega_i^T I_i \omega_i", "½"),
    (
        r"c_{ijk} = \frac12\left(\frac{\partial d_{kj}}{\partial q_i} - \frac{\partial d_{ki}}{\partial q_j}"
        r" - \frac{\partial d_{ij}}{\partial q_k}\right)",
        "sign",
    ),
    (r"{}^{i+1}\omega_{i+1} = {}^{i}_{i+1}R\,{}^{i}\omega_i + \dot\theta_{i+1}\,{}^{i+1}\hat Z_{i+1}", "transposed"),
    (r"{}^{i}f_{i} = {}^{i+1}_{i}R\,{}^{i+1}f_{i+1} + {}^{i}F_{i}", "transposed"),
    (r"{}^{i}F_{i} = m_i\,{}^{i}v_{C_i}", "velocity"),
    (r"{}^{i}_{i+1}R = {}^{i+1}_{i}R", "transposed"),
    (r"\phi_k = -\frac{\partial P}{\partial q_k}", "sign"),
    (r"{}^{i}N_{i} = {}^{C_i}I_i\,{}^{i}\dot\omega_i - {}^{i}\omega_i \times {}^{C_i}I_i\,{}^{i}\omega_i", "sign"),
    (r"K = \frac{1}{2}\dot{q}^T D(q)", None),  # shapes that do not fit: not judged (below)
]


@pytest.mark.parametrize("statement, named", [w for w in WRONG if w[1]])
def test_a_slip_in_a_law_is_wrong_and_named(statement, named):
    result = judge(sides(statement), n_links=2)
    assert result is not None and result.status == "wrong", (statement, result)
    assert named in result.message


def test_what_cannot_be_told_is_not_judged():
    # a form the table does not hold is never called wrong
    assert judge(sides(r"K = \frac{1}{2}\dot{q}^T D(q)"), 2) is None or judge(
        sides(r"K = \frac{1}{2}\dot{q}^T D(q)"), 2
    ).status in ("unrecognised",)
    pattern = judge(sides(r"K = K_1 + K_2 + \cdots + K_n"), 2)
    assert pattern is not None and pattern.status == "unrecognised" and "pattern" in pattern.message


@pytest.mark.parametrize(
    "statement",
    [
        r"T = \frac12 m_1 l_1^2 \dot\theta_1^2",  # one robot's value: a step, not a law
        r"f_{n+1} = 0",  # the free end: statements.py's
        r"\tau_1 = m_1 l_1^2 \ddot\theta_1",
        r"X = a + b",
    ],
)
def test_a_step_in_a_robots_symbols_is_no_law(statement):
    assert judge(sides(statement), n_links=2) is None


def test_the_random_rotations_are_exactly_orthogonal():
    import random

    rng = random.Random(3)
    for _ in range(5):
        r = cayley(rng)
        assert r.T * r == sp.eye(3) and r.det() == 1
    values = Values(seed=1, n=3)
    r02 = values.rotation(0, 2)
    assert r02 == values.rotation(0, 1) * values.rotation(1, 2)
    assert values.rotation(2, 0) == r02.T


DERIVATION = r"""---
robot: planar-2r
---
The laws first (Spong's energy form), then the two-link arm.

$$K_i = \frac12 m_i v_{c_i}^T v_{c_i} + \frac12 \omega_i^T I_i \omega_i$$

$$P_i = m_i g h_i$$

$$\mathcal{L} = K - P$$

$$\tau_i = \frac{d}{dt}\frac{\partial \mathcal{L}}{\partial \dot q_i} - \frac{\partial \mathcal{L}}{\partial q_i}$$

$$\mathbf{q} = \begin{pmatrix} \theta_1 \\ \theta_2 \end{pmatrix}$$

$$L = K + P$$
"""


def test_a_derivation_states_laws_first(tmp_path):
    path = tmp_path / "laws.md"
    path.write_text(DERIVATION, encoding="utf-8")
    report = grade(path)
    by_line = {v.line: v for v in report.steps}
    assert by_line[6].status == "correct"  # K_i (a proof's checker may read it too: right either way)
    assert by_line[8].status == "correct"  # P_i = m_i g h_i
    assert by_line[10].status == "correct"  # L = K - P
    assert by_line[12].status == "correct"  # the Lagrange equation, index i
    assert by_line[14].status == "definition"  # the joint vector: setup
    assert by_line[16].status == "wrong" and "potential energy" in by_line[16].message
    assert report.first_wrong == "law"
    assert not report.passed


def test_definitions_pass_and_are_listed(tmp_path):
    # a clean derivation with a definition and a setup line passes (exit status 0)
    body = (
        "---\nrobot: planar-2r\n---\n"
        "$$\\mathbf{q} = \\begin{pmatrix} \\theta_1 \\\\ \\theta_2 \\end{pmatrix}$$\n\n"
        "$$X = m_2 l_1 l_{c2}$$\n\n"
        "$$\\mathcal{L} = K - P$$\n"
    )
    path = tmp_path / "defs.md"
    path.write_text(body, encoding="utf-8")
    report = grade(path)
    statuses = [v.status for v in report.steps]
    assert statuses == ["definition", "definition", "correct"]
    assert report.passed
    text = report.text()
    assert "definition" in text and "law" in text
    data = report.to_dict()
    assert [s["status"] for s in data["steps"]] == statuses
    assert "definition" in report._repr_html_()


@pytest.mark.parametrize("name", ["planar-2r-laws-energy", "planar-2r-laws-craig-ne"])
def test_the_corpus_files_that_state_laws_first(name):
    # the truth (tests/corpus/specs_laws.py: laws by hand, steps by first principles) is met
    # exactly: every equation read, the slip in a law found at its line, no false alarm
    import sys
    from pathlib import Path

    corpus = Path(__file__).parent / "corpus"
    sys.path.insert(0, str(Path(__file__).parent.parent / "benchmarks"))
    import bench_corpus

    fs = bench_corpus.score(corpus / f"{name}.md", corpus / f"{name}.truth.yaml")
    assert not fs.refused and fs.read == fs.equations
    assert fs.slips == 1 and fs.slips_found == 1
    assert not fs.false_alarms and not fs.missed


def test_an_identity_is_correct_and_a_non_identity_not_judged(tmp_path):
    # by hand: c2 c23 + s2 s23 = cos(q2 + q3 - q2) = c3; the planar cross product
    # (0, 0, w) x (p_x, p_y, 0) = (-w p_y, w p_x, 0); c2 c23 - s2 s23 is cos(q2 + q2 + q3), not c3
    body = (
        "---\nrobot: planar-3r\n---\n"
        "$$c_2 c_{23} + s_2 s_{23} = c_3$$\n\n"
        "$$\\begin{bmatrix}0\\\\0\\\\w\\end{bmatrix}\\times\\begin{bmatrix}p_x\\\\p_y\\\\0\\end{bmatrix}"
        " = \\begin{bmatrix}-w p_y\\\\ w p_x\\\\ 0\\end{bmatrix}$$\n\n"
        "$$c_2 c_{23} - s_2 s_{23} = c_3$$\n\n"
        "$$\\mathcal{L} = K - P$$\n"
    )
    path = tmp_path / "identities.md"
    path.write_text(body, encoding="utf-8")
    report = grade(path)
    got = [(v.line, v.name, v.status) for v in report.steps]
    assert got[:3] == [(4, "identity", "correct"), (6, "identity", "correct"), (8, "", "unrecognised")]


def test_a_rotation_written_in_an_index_is_checked_for_every_frame(tmp_path):
    # by hand: the planar arm's frame i+1 turns by theta_{i+1} about Z_i, so {}^{i+1}_{i}R is
    # Rz(theta_{i+1}) transposed: rows (c, s, 0), (-s, c, 0), (0, 0, 1); the other sign is wrong
    right = r"\begin{bmatrix} c_{i+1} & s_{i+1} & 0 \\ -s_{i+1} & c_{i+1} & 0 \\ 0 & 0 & 1 \end{bmatrix}"
    wrong = r"\begin{bmatrix} c_{i+1} & -s_{i+1} & 0 \\ s_{i+1} & c_{i+1} & 0 \\ 0 & 0 & 1 \end{bmatrix}"
    body = (
        "---\nrobot: planar-2r\n---\n"
        f"$${{}}^{{i+1}}_{{i}}R = {right}$$\n\n"
        f"$${{}}^{{i+1}}_{{i}}R = {wrong}$$\n\n"
        "$$\\mathcal{L} = K - P$$\n"
    )
    path = tmp_path / "indexed.md"
    path.write_text(body, encoding="utf-8")
    report = grade(path)
    first, second = report.steps[0], report.steps[1]
    assert first.status == "correct" and "i = 0, i = 1" in first.message
    assert second.status == "wrong" and "i = 0, i = 1" in second.message


@pytest.mark.parametrize(
    "statement",
    [
        "K = M(" + "q " * 40,  # an argument list that never closes
        "K = M(" + "\\dot q , " * 40 + "x)",
        "K = " + "\\sum_{i=1}^{n} " * 400 + "K_i",
        "K_i = " + " = ".join(["K_i"] * 400),
        "K_i = " + "\\|v" * 3000 + "\\|^2",
        "c_{ijk} = " + " + ".join(["\\frac{\\partial d_{kj}}{\\partial q_i}"] * 200),
    ],
)
def test_hostile_statements_end_in_bounded_time(statement):
    import time

    start = time.perf_counter()
    result = judge(sides(statement), n_links=3)
    assert time.perf_counter() - start < 2.0
    assert result is None or result.status == "unrecognised"


def test_an_inertia_tensor_as_the_models_is_setup(tmp_path):
    # planar-2r.yaml states each link's inertia about its mass centre as diag(0, I_i, I_i)
    body = (
        "---\nrobot: planar-2r\n---\n"
        "$${}^{C_1}I_1 = \\begin{bmatrix} 0 & 0 & 0 \\\\ 0 & I_1 & 0 \\\\ 0 & 0 & I_1 \\end{bmatrix}$$\n\n"
        "$${}^{C_2}I_2 = \\begin{bmatrix} 0 & 0 & 0 \\\\ 0 & 0 & 0 \\\\ 0 & 0 & I_2 \\end{bmatrix}$$\n\n"
        "$$\\mathcal{L} = K - P$$\n"
    )
    path = tmp_path / "inertia.md"
    path.write_text(body, encoding="utf-8")
    report = grade(path)
    assert [v.status for v in report.steps] == ["definition", "unrecognised", "correct"]
    assert "as the model's" in report.steps[0].message
