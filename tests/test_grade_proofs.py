"""Proof lines about rigid bodies in ``armdyn grade`` (grading/proofs).

Second opinions: the verdicts expected of the examples are worked out by hand (and in
examples/grading/README.md); every counterexample armdyn shows is re-evaluated here with
plain NumPy on its point masses (inertia tensors summed by hand, cross products by
np.cross), never through armdyn's evaluator; mutations of right proofs must be caught.
"""

from __future__ import annotations

import json
import time
from fractions import Fraction
from pathlib import Path

import numpy as np
import pytest

from armdyn.errors import ModelError
from armdyn.grading import grade
from armdyn.grading.proofs import check_text

EXAMPLES = Path(__file__).resolve().parent.parent / "examples" / "grading"
EXERCISE = EXAMPLES / "rp-arm-exercise.md"
PARALLEL = EXAMPLES / "parallel-axis-proof.md"
ENERGY = EXAMPLES / "rotational-energy-proof.md"


def proof_status(report) -> dict:
    out: dict = {}
    for v in report.steps:
        if v.key == "proof":
            out.setdefault(v.line, []).append(v.status)
    return out


def frac(x) -> float:
    return float(Fraction(x))


def arr(x) -> np.ndarray:
    if isinstance(x, list) and x and isinstance(x[0], list):
        return np.array([[frac(c) for c in row] for row in x])
    if isinstance(x, list):
        return np.array([frac(c) for c in x])
    return np.array(frac(x))


def body(ce: dict):
    masses = np.array([frac(m) for m in ce["masses"]])
    points = np.array([[frac(c) for c in p] for p in ce["points"]])
    return masses, points


def inertia_about(masses, points, point) -> np.ndarray:
    total = np.zeros((3, 3))
    for m, p in zip(masses, points):
        r = p - point
        total += m * (r @ r * np.eye(3) - np.outer(r, r))
    return total


# ---------------------------------------------------------------- the exercise


@pytest.fixture(scope="module")
def exercise():
    return grade(EXERCISE)


def test_exercise_parallel_axis_proof_is_right_line_by_line(exercise):
    status = {line: s for line, s in proof_status(exercise).items() if line < 85}
    assert sorted(status) == [29, 35, 41, 45, 49, 53, 57, 61, 65, 69, 73, 77]
    assert all(s == ["correct"] * len(s) for s in status.values()), status
    by_line = {v.line: v for v in exercise.steps if v.key == "proof"}
    assert "defines d = C - P" in by_line[35].message
    assert "from P to C" in by_line[35].message  # the prose says "from C to P"
    assert "second integral of line 61" in by_line[69].message
    assert "uses \\int r_C dm = 0" in by_line[77].message
    for line in (29, 41, 45, 49, 53, 57, 61, 65, 69):  # pure algebra: no fact needed
        assert "r_C dm = 0" not in by_line[line].message, line


def test_exercise_energy_chain_middle_link_is_wrong_with_a_counterexample(exercise):
    links = [v for v in exercise.steps if v.key == "proof" and v.line == 153]
    assert [v.status for v in links] == ["correct", "wrong", "follows-from-earlier-error"]
    wrong = links[1]
    assert "ends agree" in wrong.message and "middle expression" in wrong.message
    ce = wrong.counterexample
    masses, points = body(ce)
    assert len(masses) <= 3 and all(m == int(m) and 1 <= m <= 3 for m in masses)
    ref = arr(ce["named_points"]["ref:i"])
    omega = arr(ce["vectors"]["omega_i"])
    rot = arr(ce["rotations"]["c"])
    assert np.allclose(rot @ rot.T, np.eye(3)) and np.isclose(np.linalg.det(rot), 1)
    assert sorted(np.abs(rot).sum(axis=0)) == [1, 1, 1] and np.trace(rot) == 1  # a quarter turn
    inertia = inertia_about(masses, points, ref)
    left = 0.5 * omega @ inertia @ omega
    right = 0.5 * omega @ rot @ inertia @ rot.T @ omega
    assert left == pytest.approx(frac(ce["left"])) and right == pytest.approx(frac(ce["right"]))
    assert not np.isclose(left, right)
    # the chain's ends agree on it: w^T I w = (R w)^T (R I R^T) (R w)
    assert 0.5 * (rot @ omega) @ (rot @ inertia @ rot.T) @ (rot @ omega) == pytest.approx(left)
    assert wrong.got == pytest.approx(left) and wrong.expected == pytest.approx(right)


def test_exercise_dynamics_verdict_unchanged(exercise):
    assert exercise.first_wrong == "v_dot_1"
    assert exercise.tau_correct == [True, True]


def test_json_has_one_entry_per_link_and_the_counterexample():
    from armdyn.grading.text import to_json

    data = json.loads(to_json(grade(EXERCISE)))
    proofs = [s for s in data["steps"] if (s["name"] or "").startswith("proof_")]
    assert len(proofs) == 13 + 4 + 3  # 7-3: 13 links; energy: 4 single links + a chain of 3
    wrong = [s for s in proofs if s["status"] == "wrong"]
    assert len(wrong) == 1 and wrong[0]["line"] == 153 and wrong[0]["name"] == "proof_153.2"
    follows = next(s for s in proofs if s["name"] == "proof_153.3")
    assert follows["status"] == "follows-from-earlier-error" and follows["caused_by"] == "proof_153.2"
    assert set(wrong[0]["counterexample"]) >= {"masses", "points", "vectors", "rotations", "left", "right"}
    assert all("counterexample" not in s for s in proofs if s["status"] != "wrong")


# ---------------------------------------------------------------- the examples


def test_parallel_axis_example_verdict():
    r = grade(PARALLEL)
    assert proof_status(r) == {
        16: ["correct"],
        20: ["correct"],
        24: ["correct"],
        28: ["wrong"],
        32: ["correct", "correct"],
        36: ["correct"],
    }
    assert r.first_wrong == "proof_28" and not r.passed
    wrong = next(v for v in r.steps if v.status == "wrong")
    ce = wrong.counterexample
    masses, points = body(ce)
    center = masses @ points / masses.sum()
    assert np.allclose(center, arr(ce["named_points"]["C"]))
    p = center - arr(ce["named_points"]["A"])  # r_A = r_C + p
    assert np.allclose(p, arr(ce["defined"]["p"]))
    rc = points[ce["element"]] - center
    left = (rc + p) @ (rc + p)
    right = rc @ rc + p @ rc + p @ p
    assert left == pytest.approx(frac(ce["left"])) and right == pytest.approx(frac(ce["right"]))
    assert left != pytest.approx(right)


def test_rotational_energy_example_verdict():
    r = grade(ENERGY)
    assert proof_status(r) == {
        16: ["correct", "correct"],
        20: ["wrong"],
        24: ["correct", "correct"],
        28: ["correct"],
        30: ["correct"],
        34: ["correct"] * 3,
    }
    wrong = next(v for v in r.steps if v.status == "wrong")
    ce = wrong.counterexample
    masses, points = body(ce)
    ri = points[ce["element"]] - arr(ce["named_points"]["ref:i"])
    omega = arr(ce["vectors"]["omega_i"])
    left, right = np.cross(omega, ri), np.cross(ri, omega)  # S(a) b = a x b
    assert np.allclose(left, arr(ce["left"])) and np.allclose(right, arr(ce["right"]))
    assert not np.allclose(left, right)


def test_cli_json_and_exit_status(capsys, tmp_path):
    from armdyn.cli import main

    assert main(["grade", str(PARALLEL), "--json"]) == 1
    data = json.loads(capsys.readouterr().out)
    wrong = [s for s in data["steps"] if s["status"] == "wrong"]
    assert [s["name"] for s in wrong] == ["proof_28"] and data["first_wrong"] == "proof_28"
    assert wrong[0]["got"] != wrong[0]["expected"] and wrong[0]["counterexample"]["element"] is not None
    fixed = tmp_path / "fixed.md"
    fixed.write_text(fixed_parallel())
    assert main(["grade", str(fixed)]) == 0  # the slip repaired: every link right
    assert "WRONG" not in capsys.readouterr().out


# ---------------------------------------------------------------- mutations


def fixed_parallel() -> str:
    return PARALLEL.read_text().replace(
        r"+ \mathbf{p}^T \mathbf{r}_C + \mathbf{p}^T \mathbf{p}$$",
        r"+ 2 \mathbf{p}^T \mathbf{r}_C + \mathbf{p}^T \mathbf{p}$$",
    )


def fixed_energy() -> str:
    return ENERGY.read_text().replace(r"S(\omega_i) r_i = S(r_i) \omega_i", r"S(\omega_i) r_i = -S(r_i) \omega_i")


LAST = r"M \left( \mathbf{p}^T \mathbf{p} \mathbf{1} - \mathbf{p} \mathbf{p}^T \right)$$" + "\n"
MUTATIONS = [
    # (text, old, new, what students do)
    (fixed_parallel, r"\mathbf{1} - \mathbf{r}_A \mathbf{r}_A^T", r"\mathbf{1} + \mathbf{r}_A \mathbf{r}_A^T", "sign"),
    (
        fixed_parallel,
        r"+ 2 \mathbf{p}^T \mathbf{r}_C + \mathbf{p}^T \mathbf{p}$$",
        r"- 2 \mathbf{p}^T \mathbf{r}_C + \mathbf{p}^T \mathbf{p}$$",
        "sign",
    ),
    (fixed_parallel, "= \\mathbf{I}_C + " + LAST, "= \\mathbf{I}_C + 2 " + LAST, "factor 2"),
    (
        fixed_parallel,
        "= \\mathbf{I}_C + " + LAST,
        "= \\mathbf{I}_C + " + LAST.replace(r"\mathbf{p} \mathbf{p}^T", r"\mathbf{p} \mathbf{p}"),
        "transpose dropped",
    ),
    (
        fixed_parallel,
        r"\int_{\mathcal{B}} \mathbf{r}_C \, dm",
        r"\int_{\mathcal{B}} \mathbf{r}_A \, dm",
        "mass-center fact about A",
    ),
    (fixed_energy, r"= -S(r_i) \omega_i", r"= S(r_i) \omega_i", "sign"),
    (fixed_energy, r"S^T(r_i) S(r_i) \rho dV", r"S(r_i) S(r_i) \rho dV", "transpose dropped"),
    (fixed_energy, r"E_{rot} = \frac{1}{2} \int", r"E_{rot} = \int", "factor 2"),
    (
        fixed_energy,
        r"$$\frac{1}{2}\omega^{c\mathrm{T}} I^c_{l_i} \omega^c",
        r"$$\frac{1}{2}\omega_i^T I^c_{l_i} \omega^c",
        "frame change applied to one factor only",
    ),
    (
        fixed_energy,
        r"I^c_{l_i} = \mathbf{R}^c I_{l_i} \mathbf{R}^{c\mathrm{T}}",
        r"I^c_{l_i} = \mathbf{R}^c I_{l_i}",
        "frame change applied to one side only",
    ),
    (
        lambda: EXERCISE.read_text(),
        r"2\mathbf{d}^T\mathbf{r}_C + \|\mathbf{d}\|^2.$$",
        r"\mathbf{d}^T\mathbf{r}_C + \|\mathbf{d}\|^2.$$",
        "factor 2",
    ),
    (
        lambda: EXERCISE.read_text(),
        r"\int_{\mathcal{B}} \mathbf{r}_C dm = \mathbf{0}",
        r"\int_{\mathcal{B}} \mathbf{r}_P dm = \mathbf{0}",
        "mass-center fact about P",
    ),
    (lambda: EXERCISE.read_text(), r"$$M\left(\|\mathbf{d}\|^2", r"$$2M\left(\|\mathbf{d}\|^2", "factor 2"),
    (
        lambda: EXERCISE.read_text(),
        r"\mathbf{d} \mathbf{r}_C^T + \mathbf{d} \mathbf{d}^T.$$",
        r"\mathbf{d} \mathbf{r}_C + \mathbf{d} \mathbf{d}^T.$$",
        "transpose dropped",
    ),
    (
        lambda: EXERCISE.read_text(),
        r"\mathbf{I}_P = \mathbf{I}_C + M \left(",
        r"\mathbf{I}_P = \mathbf{I}_C - M \left(",
        "sign",
    ),
]


def test_the_fixed_examples_are_all_correct():
    for text in (fixed_parallel(), fixed_energy()):
        verdicts = check_text(text)
        assert verdicts and all(v.status == "correct" for v in verdicts), [(v.line, v.message) for v in verdicts]


@pytest.mark.parametrize("make, old, new, kind", MUTATIONS, ids=[f"{m[3]}-{i}" for i, m in enumerate(MUTATIONS)])
def test_one_line_mutations_are_caught(make, old, new, kind):
    text = make()
    assert text.count(old) == 1, old
    mutated = text.replace(old, new)
    line = text[: text.index(old)].count("\n") + 1
    start = text.rfind("$$", 0, text.index(old) + 2)
    block_line = text[:start].count("\n") + 1  # the display's own line
    verdicts = check_text(mutated)
    bad = [v for v in verdicts if v.status in ("wrong", "follows-from-earlier-error")]
    assert bad, f"{kind}: not caught"
    assert any(v.line in (line, block_line) and v.status == "wrong" for v in bad), [
        (v.line, v.status, v.message) for v in bad
    ]
    before = {v.line: v.status for v in check_text(text) if v.status == "wrong"}
    assert line not in before and block_line not in before  # the line was right before the mutation


def test_definitions_facts_and_unknown_names():
    text = "\n\n".join(
        [
            "Prove it.",
            r"$$\int_{\mathcal{B}} dm = M$$",
            r"$$\mathbf{I}_C = \int_{\mathcal{B}} \left( \|\mathbf{r}_C\|^2 \mathbf{I} + "
            r"\mathbf{r}_C \mathbf{r}_C^T \right) dm$$",
            r"$$\mathbf{I}_C - 2 \int_{\mathcal{B}} \mathbf{r}_C \mathbf{r}_C^T dm = "
            r"\int_{\mathcal{B}} \left( \|\mathbf{r}_C\|^2 \mathbf{I} - \mathbf{r}_C \mathbf{r}_C^T \right) dm$$",
            r"$$J = \int_{\mathcal{B}} \mathbf{r}_C \mathbf{r}_C^T dm$$",
            r"$$\mathbf{I}_C = \int_{\mathcal{B}} \|\mathbf{r}_C\|^2 dm \, \mathbf{I} - J$$",
            r"$$\mathbf{I}_C = \sum_k m_k \mathbf{r}_k$$",
            r"$$\mathbf{r}_C \cdot \mathbf{r}_C = \|\mathbf{r}_C\|$$",
            r"$$\mathbf{r}_P = \mathbf{r}_C + \mathbf{d}$$",
            r"$$\mathbf{r}_C = \mathbf{r} + \mathbf{a} + \mathbf{r}_P$$",
        ]
    )
    got = [(v.line, v.status) for v in check_text(text)]
    assert got == [
        (3, "correct"),
        (5, "wrong"),
        (7, "follows-from-earlier-error"),
        (9, "correct"),
        (11, "correct"),
        (13, "wrong"),  # a sum over the particles is read: I_C is a matrix, sum m_k r_k a vector
        (15, "unrecognised"),
        (17, "correct"),
        (19, "wrong"),
    ]
    v = {v.line: v for v in check_text(text)}
    assert "not the inertia tensor about C" in v[5].message and v[7].caused_by == "proof_5"
    assert "defines J" in v[9].message and "the right side a vector" in v[13].message and "squared" in v[15].message
    assert "not constant over the body" in v[19].message  # a = r_C - r - r_P varies with the element


def test_other_notations_and_a_bare_proof_heading():
    text = "\n\n".join(
        [
            "Proof.",
            r"$$[\mathbf{r}]_\times \boldsymbol{\omega} = -\boldsymbol{\omega} \times \mathbf{r} = "
            r"\mathbf{r} \times \boldsymbol{\omega}$$",
            r"$$\left\| \mathbf{r} \right\|^2 = \mathbf{r}^\top \mathbf{r} = \mathbf{r} \cdot \mathbf{r}$$",
            r"$$S^T(\mathbf{r}) S(\mathbf{r}) = \|\mathbf{r}\|^2 \mathbf{1} - \mathbf{r}\mathbf{r}^T$$",
            r"$$\int_{\mathcal{B}} \int_{\mathcal{B}} \mathbf{r}^T \mathbf{r} \, dm \, dm = "
            r"M \int_{\mathcal{B}} \mathbf{r}^T \mathbf{r} \, dm$$",
            r"$$S(\mathbf{r}) S(\mathbf{r}) = \|\mathbf{r}\|^2 \mathbf{1} - \mathbf{r}\mathbf{r}^T$$",
        ]
    )
    got = [(v.line, v.status) for v in check_text(text)]
    assert got == [
        (3, "correct"),
        (3, "correct"),
        (5, "correct"),
        (5, "correct"),
        (7, "correct"),
        (9, "correct"),
        (11, "wrong"),
    ]  # S(r) S(r) = -S^T(r) S(r)


def test_a_chain_that_names_its_first_expression():
    text = (
        "Proof.\n\n$$K = \\frac{1}{2} \\int_{\\mathcal{B}} (\\omega \\times \\mathbf{r})^T "
        "(\\omega \\times \\mathbf{r}) dm"
        " = \\frac{1}{2} \\omega^T \\mathbf{I}_O \\omega = \\omega^T \\mathbf{I}_O \\omega$$\n"
    )
    v = check_text(text)
    assert [x.status for x in v] == ["correct", "correct", "wrong"] and "defines K" in v[0].message
    ce = v[2].counterexample  # NumPy: w^T I_O w on the counterexample is twice the left side
    masses, points = body(ce)
    omega = arr(ce["vectors"]["omega"])
    inertia = inertia_about(masses, points, arr(ce["named_points"]["O"]))
    assert frac(ce["left"]) == pytest.approx(0.5 * omega @ inertia @ omega)
    assert frac(ce["right"]) == pytest.approx(omega @ inertia @ omega) != frac(ce["left"])


# ---------------------------------------------------------------- hostile input

HEAD = "---\nrobot: rp-arm\n---\nProve it.\n\n"


@pytest.mark.parametrize(
    "line",
    [
        "(" * 500 + r"\mathbf{d}" + ")" * 500 + " = 0",
        r"E_{rot} = {{{9}^{99}}^{99}}^{99}",
        r"M = \int \int \int \int \mathbf{r} dm dm dm dm",
        r"\mathbf{I}_O = " + " ".join([r"\mathbf{I}_O"] * 3000),
        r"\|" * 200 + "x" + r"\|" * 200 + " = 1",
        r"E_{rot} = <script>alert(1)</script>",
    ],
)
def test_hostile_proof_lines_end_quickly_with_a_clear_verdict(tmp_path, line):
    path = tmp_path / "hostile.md"
    path.write_text(HEAD + f"$${line}$$\n\n$$\\tau_2 = 0$$\n")
    t0 = time.perf_counter()
    r = grade(path)
    assert time.perf_counter() - t0 < 5
    proof = [v for v in r.steps if v.key == "proof"]
    assert proof and all(v.status == "unrecognised" and v.line == 6 and v.message for v in proof)


def test_ten_thousand_proof_lines_are_refused_naming_the_file(tmp_path):
    path = tmp_path / "long.md"
    path.write_text(
        HEAD + "".join(f"$$\\mathbf{{r}}_P = \\mathbf{{r}}_C + \\mathbf{{d}}_{{{k}}}$$\n" for k in range(10_000))
    )
    t0 = time.perf_counter()
    with pytest.raises(ModelError, match="proof lines") as err:
        check_text(path.read_text(), str(path))
    assert time.perf_counter() - t0 < 5
    assert f"{path}:10005" in str(err.value)
    # through armdyn grade its reader refuses first (at most 500 equations in a file)
    with pytest.raises(ModelError, match="proof lines|more than 500 equations"):
        grade(path)


def test_html_escapes_proof_text(tmp_path):
    from armdyn.grading.html import report_html

    path = tmp_path / "x.md"
    path.write_text(HEAD + "$$E_{rot} = <img src=x onerror=alert(1)>$$\n\n$$\\tau_2 = 0$$\n")
    html = report_html(grade(path))
    assert "<img src=x" not in html
    shown = report_html(grade(ENERGY))  # the counterexample is on the page
    assert "left side, on the counterexample" in shown and "for the mass element at" in shown
