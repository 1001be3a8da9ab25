"""The kinds of slip read from the values (armdyn.course.slipkinds): each test gives the
expected value and a student's value made by hand with the slip (plain SymPy), or a proof
link's two sides on a small body computed here by hand; and the worked proofs' injected
slips (each named when written) are classified as named. The arm's kinds also through the
grader: a slip made by hand in a worked solution, graded, classified.
"""

from __future__ import annotations

import numpy as np
import pytest
import sympy as sp

import armdyn
from armdyn.course.slipkinds import arm_kind, proof_kind, slip_kinds

th1, th2, d2, l1, l2, m1, m2, g = sp.symbols("theta1 theta2 d2 l1 l2 m1 m2 g")
th1d, th1dd, th2d, th2dd, d2d, d2dd = sp.symbols("theta1_dot theta1_ddot theta2_dot theta2_ddot d2_dot d2_ddot")
RATES = {s.name: s for s in (th1, th2, d2, l1, l2, m1, m2, g, th1d, th1dd, th2d, th2dd, d2d, d2dd)}
COORDS = [th1, th2, d2]

# an RP arm's v_dot_2 (Craig's frames) and a rod's N_1, T: written out by hand
V2 = sp.Matrix([-d2 * th1dd - 2 * d2d * th1d + g * sp.cos(th1) - l1 * th1d**2, 0, -d2 * th1d**2 + d2dd + l1 * th1dd])
N1 = sp.Matrix([0, 0, m1 * l1**2 * th1dd / 12])
T = m1 * (l1 / 2) ** 2 * th1d**2 / 2 + m1 * l1**2 / 12 * th1d**2 / 2
# a planar elbow's link-2 vector: R(theta2)^T applied to (a, b): both components change with R -> R^T
A, B = l1 * th1dd, l1 * th1d**2
W2 = sp.Matrix([A * sp.cos(th2) + B * sp.sin(th2), -A * sp.sin(th2) + B * sp.cos(th2), 0])


@pytest.mark.parametrize(
    "key, expected, got, kind",
    [
        ("v_dot", V2, V2 + sp.Matrix([d2d * th1d, 0, 0]), "factor missing"),  # 2 d2' th1' written once
        ("v_dot", V2, V2 + sp.Matrix([0, 0, l1 * th1dd]), "extra factor"),  # l1 th1'' written twice
        ("v_dot", V2, V2 - sp.Matrix([0, 0, d2dd]), "missing term"),
        ("v_dot", V2, V2 + sp.Matrix([0, 0, l2 * th1dd]), "extra term"),
        ("v_dot", V2, V2 + sp.Matrix([2 * l1 * th1d**2, 0, 0]), "wrong sign"),
        ("v_dot", V2, -V2, "wrong sign"),
        ("v_dot", V2, V2.subs(th1dd, th1d), "derivative mixed up"),  # th1' for th1''
        ("v_dot", V2, V2 + sp.Matrix([0, 0, l1 * th1d - l1 * th1dd]), "derivative mixed up"),  # in one term
        ("N", N1, N1 * 4, "inertia about the wrong point"),  # m l^2/3 about the joint, not m l^2/12
        ("N", sp.zeros(3, 1), sp.Matrix([0, 0, m1 * l1**2 * th1dd]), "inertia about the wrong point"),
        ("T", T, T + m1 * l1**2 / 8 * th1d**2, "inertia about the wrong point"),
        ("omega_dot", W2, W2.subs(sp.sin(th2), -sp.sin(th2)), "transposed rotation"),
        ("F", V2 * m2, V2, "factor missing"),  # m2 forgotten
        ("F", V2, V2[0], "wrong shape"),
    ],
)
def test_arm_kinds(key, expected, got, kind):
    assert arm_kind(key, expected, got, COORDS, RATES) == kind


def test_a_single_sign_is_not_a_transposed_rotation():
    """sin q -> -sin q in a scalar or in one component is a term's sign, not R^T."""
    tau = m2 * l2 * th2d**2 * sp.sin(th2) + m1 * g * l1 * sp.cos(th1)
    assert arm_kind("tau", tau, tau.subs(sp.sin(th2), -sp.sin(th2)), COORDS, RATES) == "wrong sign"


def test_no_kind_for_an_unrelated_value():
    assert arm_kind("v_dot", V2, V2 + sp.Matrix([sp.cos(th2) ** 3 * l2, 0, 0]), COORDS, RATES) == "extra term"
    # a term replaced by an unrelated one: none of the tests, the message decides
    other = V2 + sp.Matrix([l1 * th1d**2 + l2 * th1d * sp.sin(th1), 0, 0])
    assert arm_kind("v_dot", V2, other, COORDS, RATES) is None


# ------------------------------------------------------------------ proofs, by hand
BODY = {
    "masses": ["2", "3"],
    "points": [["0", "0", "0"], ["5", "0", "0"]],  # mass centre at x = 3
    "named_points": {"C": ["3", "0", "0"], "A": ["1", "2", "0"]},
    "center_of_mass": "C",
    "rotations": {},
    "defined": {"d": ["2", "-2", "0"]},  # C - A
    "element": None,
}


def _example(left, right, **extra):
    return {**BODY, "left": left, "right": right, **extra}


def _m(rows):
    return [[str(x) for x in r] for r in rows]


def test_proof_kinds_by_hand():
    # the mass-centre fact said of A: sum m (p - A) = M (C - A) = 5 (2, -2, 0), not 0
    assert proof_kind(_example(["10", "-10", "0"], "0"), r"\int r_A dm = 0") == (
        "proof: mass-centre fact about the wrong point"
    )
    assert proof_kind(_example("7", "-7"), "x = y") == "proof: sign"
    assert proof_kind(_example("10", "20"), "E = 2 E") == "proof: factor"  # 1/2 forgotten
    # a frame change written R^T X R where R X R^T belongs, R = 90 degrees about z
    R = sp.Matrix([[0, -1, 0], [1, 0, 0], [0, 0, 1]])
    X = sp.Matrix([[1, 2, 4], [2, 5, 0], [4, 0, 3]])  # an x-z product: R X R^T != R^T X R
    rot = {"R": _m(R.tolist())}
    left, right = R * X * R.T, R.T * X * R
    assert proof_kind(_example(_m(left.tolist()), _m(right.tolist()), rotations=rot), "I^c = R^T I R") == (
        "proof: transpose"
    )
    # I_A = I_C + M (d^T d 1 - d d^T): written without M (M = 5): L - R = 4 (d^T d 1 - d d^T)
    d = sp.Matrix([2, -2, 0])
    par = (d.T * d)[0] * sp.eye(3) - d * d.T
    IC = sp.diag(0, 30 / sp.Integer(5) * 1, 6)  # any tensor: it cancels in L - R
    assert proof_kind(
        _example(_m((IC + 5 * par).tolist()), _m((IC + par).tolist())), r"I_A = I_C + (d^T d 1 - d d^T)"
    ) == ("proof: factor")
    # ... and with the term dropped
    assert proof_kind(_example(_m((IC + 5 * par).tolist()), _m(IC.tolist())), r"I_A = I_C") == "proof: dropped term"
    # about the mass element e = (0, 0, 0): r_C = (-3, 0, 0), d = (2, -2, 0); by hand
    # r_C^T r_C = 9, d^T r_C = -6, d^T d = 8, and (r_C + d)^T (r_C + d) = |(-1, -2, 0)|^2 = 5
    one = {"element": 0}
    assert proof_kind(_example("5", str(9 - 6 + 8), **one), r"(r_C+d)^T(r_C+d) = r_C^T r_C + d^T r_C + d^T d") == (
        "proof: factor"  # the cross term's 2 forgotten
    )
    assert proof_kind(_example("5", str(9 - 12), **one), r"(r_C+d)^T(r_C+d) = r_C^T r_C + 2 d^T r_C") == (
        "proof: dropped term"  # d^T d dropped
    )


def test_the_worked_proofs_slips_are_classified_as_named(tmp_path):
    from armdyn.course.proofkinds import PROOF_KINDS, PROOF_MODEL, proof_blocks, proof_markdown, slippable_lines

    named = {
        "wrong sign": "proof: sign",
        "factor missing": "proof: factor",
        "missing term": "proof: dropped term",
        "transposed": "proof: transpose",
    }
    (tmp_path / "model.yaml").write_text(PROOF_MODEL)
    for kind in PROOF_KINDS:
        for seed in range(2):  # two notations each
            _, blocks = proof_blocks(kind, np.random.default_rng(seed))
            for k in slippable_lines(blocks):
                for j, name in enumerate(blocks[k].slip_names):
                    text, _ = proof_markdown(blocks, {"robot": "model.yaml"}, "p", slip=(k, j))
                    (tmp_path / "p.md").write_text(text)
                    report = armdyn.grade(str(tmp_path / "p.md"))
                    first = next(i for i, s in enumerate(report.steps) if s.status == "wrong")
                    assert slip_kinds(report).get(first) == named[name], (kind, seed, name)
