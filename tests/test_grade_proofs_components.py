"""Proofs in components and with the prose's own names (grading/proofs/prose.py): ``x_i``,
``y_i`` of particles, a point ``A = (a, b, 0)``, the planar moment ``I_A``, ``\\boldsymbol{\\rho}``
from the mass centre, ``r`` from the point the text names, rows ``&= ...`` that continue a
chain, and a worked example's scalars.

Second opinion: the truth of every line is decided by hand when it is written. With the
origin at the mass centre C and A = (a, b, 0): ``sum m_i x_i = 0``, ``I_A = I_C + M(a^2 + b^2)``
(the moment about the axis through A along z); ``(r + s)^T (r + s)`` has the cross term twice;
a uniform rod's ``1/12 + 1/4 = 1/3``. A slip is a false identity by that arithmetic.
"""

from __future__ import annotations

from pathlib import Path

from armdyn.grading.proofs import check_text

CORPUS = Path(__file__).resolve().parent / "corpus"

PLANAR_SETUP = (
    "# Parallel axis theorem\n\n"
    "Place the origin at the mass centre C of a body of particles $m_i$ at $(x_i, y_i, z_i)$. "
    "Let A be the point $(a, b, 0)$ and $d$ the distance between the axis through C along $z$ "
    "and the parallel axis through A.\n\n"
)

INTEGRAL_SETUP = (
    "# Parallel axis theorem\n\n"
    "Let $\\mathbf{r}$ be the position of the mass element $dm$ relative to a point A, "
    "$\\boldsymbol{\\rho}$ its position relative to the mass centre C.\n\n"
)


def doc(setup: str, *blocks: str) -> str:
    """The setup prose then each block as its own display, separated by a sentence."""
    return setup + "\n\nSo\n\n".join(blocks) + "\n"


def by_line(text: str) -> dict[int, list[str]]:
    out: dict[int, list[str]] = {}
    for v in check_text(text):
        out.setdefault(v.line, []).append(v.status)
    return out


def line_of(text: str, needle: str) -> int:
    return next(k for k, line in enumerate(text.splitlines(), start=1) if needle in line)


# ------------------------------------------------------------------ the corpus proofs
def test_corpus_proofs_read_and_agree_with_their_truth():
    import yaml

    for name in ("parallel-axis-integral", "parallel-axis-particles", "rotational-energy-particles"):
        text = (CORPUS / f"{name}.md").read_text(encoding="utf-8")
        truth = yaml.safe_load((CORPUS / f"{name}.truth.yaml").read_text(encoding="utf-8"))
        got = by_line(text)
        for eq in truth["equations"]:
            assert eq["truth"] == "right"
            assert got.get(eq["line"]), (name, eq["line"])
            assert set(got[eq["line"]]) == {"correct"}, (name, eq["line"], got[eq["line"]])


# ------------------------------------------------------------------ components of particles
def test_planar_components_and_a_continued_row():
    text = doc(
        PLANAR_SETUP,
        "\\begin{align*}\n"
        "I_A &= \\sum_i m_i\\left[(x_i - a)^2 + (y_i - b)^2\\right] \\\\\n"
        "    &= \\sum_i m_i (x_i^2 + y_i^2) - 2a\\sum_i m_i x_i - 2b\\sum_i m_i y_i + (a^2 + b^2)\\sum_i m_i\n"
        "\\end{align*}",
        "$$\\sum_i m_i x_i = 0$$",
        "$$I_C = \\sum_i m_i (x_i^2 + y_i^2)$$",
        "\\begin{align*}\nI_A &= I_C + M(a^2 + b^2) \\\\\n    &= I_C + M d^2\n\\end{align*}",
    )
    got = by_line(text)
    for needle in ("I_A &= \\sum", "&= \\sum_i m_i (x_i^2", "x_i = 0", "I_C = ", "M(a^2 + b^2)", "M d^2"):
        assert got[line_of(text, needle)] == ["correct"], needle
    messages = " ".join(v.message for v in check_text(text))
    assert "moment of inertia about the axis through A along z" in messages
    assert "states \\int r_C dm = 0" in messages  # sum m_i x_i = 0 is the mass-centre fact


def test_planar_slips_are_caught_at_their_line():
    text = doc(
        PLANAR_SETUP,
        "\\begin{align*}\n"
        "I_A &= \\sum_i m_i\\left[(x_i - a)^2 + (y_i - b)^2\\right] \\\\\n"
        "    &= \\sum_i m_i (x_i^2 + y_i^2) + (a^2 - b^2)\\sum_i m_i\n"  # sign of b^2
        "\\end{align*}",
        "$$I_A = I_C + M d$$",  # d not squared: a vector
        "$$I_A = I_C - M d^2$$",  # sign of the shift
        "$$I_C = \\sum_i m_i (x_i^2 + y_i^2 + 1)$$",  # an extra M
    )
    got = by_line(text)
    assert got[line_of(text, "I_A &= \\sum")] == ["correct"]
    assert got[line_of(text, "(a^2 - b^2)")] == ["wrong"]
    assert got[line_of(text, "M d$$")] == ["wrong"]
    assert got[line_of(text, "- M d^2")] == ["wrong"]
    assert got[line_of(text, "+ 1)")] == ["wrong"]


def test_the_origin_comes_from_the_text():
    # without "origin at the mass centre" the components are measured from O: the first
    # moment of the masses about an arbitrary origin is not zero
    line = "$$\\sum_i m_i x_i = 0$$"
    assert by_line("# Moments\n\nThe first moment:\n\n" + line + "\n")[5] == ["wrong"]
    text = "# Moments\n\nPlace the origin at the mass center C.\n\n" + line + "\n"
    assert by_line(text)[5] == ["correct"]


def test_tensor_form_with_the_texts_vector():
    setup = (
        PLANAR_SETUP + "Proof of the tensor form. With $\\mathbf{p} = (a, b, 0)^T$ the position of A relative to C,\n\n"
    )
    right = "$$\\mathbf{I}_A = \\mathbf{I}_C + M\\left(\\mathbf{p}^T\\mathbf{p}\\,\\mathbf{1} - \\mathbf{p}\\,\\mathbf{p}^T\\right)$$"
    slip = "$$\\mathbf{I}_A = \\mathbf{I}_C + M\\left(\\mathbf{p}\\,\\mathbf{p}^T - \\mathbf{p}^T\\mathbf{p}\\,\\mathbf{1}\\right)$$"
    text = doc(setup, right, slip)
    got = by_line(text)
    assert got[line_of(text, "\\mathbf{1} - \\mathbf{p}")] == ["correct"]
    assert got[line_of(text, "\\mathbf{p}^T - ")] == ["wrong"]


# ------------------------------------------------------------------ integrals with rho and the text's r
def test_rho_and_r_as_the_text_defines_them():
    text = doc(
        INTEGRAL_SETUP,
        "$$\\mathbf{I}_A = \\int_B \\left(\\mathbf{r}^T\\mathbf{r}\\,\\mathbf{1} - \\mathbf{r}\\,\\mathbf{r}^T\\right) dm$$",
        "$$\\mathbf{r} = \\boldsymbol{\\rho} + \\mathbf{d}$$",
        "$$\\int_B \\boldsymbol{\\rho}\\, dm = \\mathbf{0}$$",
        "$$\\int_V \\boldsymbol{\\rho}\\,\\rho\\,dV = \\mathbf{0}$$",  # bold rho the position, rho dV the mass
        "$$\\mathbf{r}^T\\mathbf{r} = \\boldsymbol{\\rho}^T\\boldsymbol{\\rho} + 2\\,\\mathbf{d}^T\\boldsymbol{\\rho}"
        " + \\mathbf{d}^T\\mathbf{d}$$",
        "$$\\mathbf{r}^T\\mathbf{r} = \\boldsymbol{\\rho}^T\\boldsymbol{\\rho} + \\mathbf{d}^T\\boldsymbol{\\rho}"
        " + \\mathbf{d}^T\\mathbf{d}$$",  # slip: the cross term once
        "$$\\mathbf{I}_A = \\mathbf{I}_C + M\\left(\\mathbf{d}^T\\mathbf{d}\\,\\mathbf{1} - \\mathbf{d}\\,\\mathbf{d}^T\\right)$$",
    )
    got = by_line(text)
    assert got[line_of(text, "\\mathbf{I}_A = \\int_B")] == ["correct"]
    assert got[line_of(text, "\\mathbf{r} = \\boldsymbol")] == ["correct"]  # defines d = C - A
    assert got[line_of(text, "\\int_B \\boldsymbol{\\rho}")] == ["correct"]
    assert got[line_of(text, "\\rho\\,dV")] == ["correct"]
    assert got[line_of(text, "+ 2\\,\\mathbf{d}^T")] == ["correct"]
    assert got[line_of(text, "} + \\mathbf{d}^T\\boldsymbol")] == ["wrong"]
    assert got[line_of(text, "\\mathbf{I}_C + M")] == ["correct"]
    defines = next(v for v in check_text(text) if v.line == line_of(text, "\\mathbf{r} = \\boldsymbol"))
    assert "d = C - A" in defines.message


def test_the_point_r_is_measured_from_decides_the_line():
    # the definition of I_A holds with r from A, not with r from the origin O
    line = "$$\\mathbf{I}_A = \\int_B \\left(\\mathbf{r}^T\\mathbf{r}\\,\\mathbf{1} - \\mathbf{r}\\,\\mathbf{r}^T\\right) dm$$"
    from_a = "# T\n\nLet $\\mathbf{r}$ be the position of the mass element relative to a point A.\n\n" + line + "\n"
    from_o = "# T\n\nLet $\\mathbf{r}$ be the position of the mass element relative to the origin O.\n\n" + line + "\n"
    assert by_line(from_a)[5] == ["correct"]
    assert by_line(from_o)[5] == ["wrong"]


# ------------------------------------------------------------------ a worked example's scalars
THEOREM = (
    "# Parallel axis theorem\n\nProof.\n\n$$\\mathbf{I}_A = \\mathbf{I}_C + M\\left(\\mathbf{d}^T\\mathbf{d}\\,\\mathbf{1}"
    " - \\mathbf{d}\\,\\mathbf{d}^T\\right)$$\n\n"
)
ROD_END = (
    THEOREM
    + "**Example.** A uniform rod of mass $m$ and length $l$ about an axis through one end,\nperpendicular to it:\n\n"
)
ROD = THEOREM + "**Example.** A uniform rod of mass $m$ and length $l$:\n\n"


def example(text: str) -> list:
    return [v for v in check_text(text) if v.line == line_of(text, "I_{")]


def test_a_rod_about_its_end_is_checked_against_its_mass_distribution():
    # by hand: int_0^l (m/l) x^2 dx = m l^2 / 3; 1/12 + (1/2)^2 = 1/3
    right = ROD_END + "$$I_{end} = \\frac{1}{12} m l^2 + m\\left(\\frac{l}{2}\\right)^2 = \\frac{1}{3} m l^2$$\n"
    v = example(right)
    assert [x.status for x in v] == ["correct", "correct"]
    assert "uniform rod" in v[0].message and "through one end" in v[0].message
    # the distance l for l/2: 1/12 + 1 = 13/12, not 1/3; the arithmetic after it is right
    slip = ROD_END + "$$I_{end} = \\frac{1}{12} m l^2 + m l^2 = \\frac{13}{12} m l^2$$\n"
    assert [x.status for x in example(slip)] == ["wrong", "correct"]
    # about its centre: m l^2 / 12, so the end's value there is a slip
    centre = ROD_END.replace("one end", "its centre") + "$$I_{mid} = \\frac{1}{3} m l^2$$\n"
    assert [x.status for x in example(centre)] == ["wrong"]


def test_a_worked_example_without_its_axis_is_an_identity_in_its_scalars():
    right = ROD + "$$I_{end} = \\frac{1}{12} m l^2 + m\\left(\\frac{l}{2}\\right)^2 = \\frac{1}{3} m l^2$$\n"
    slip = ROD + "$$I_{end} = \\frac{1}{12} m l^2 + m\\left(\\frac{l}{2}\\right)^2 = \\frac{1}{4} m l^2$$\n"
    v = example(right)
    assert [x.status for x in v] == ["correct", "correct"]
    assert "defines I_{end}" in v[0].message and "taken as written" in v[0].message
    assert "identity in the example's scalars l, m" in v[1].message
    assert [x.status for x in example(slip)] == ["correct", "wrong"]


def test_a_body_of_mass_m_is_not_an_example():
    # no shape named: m is not a worked example's scalar, so "I_{end} = m" stays unread, not defined
    text = "# T\n\nProve it for a body of mass $m$.\n\n$$I_{end} = \\frac{1}{3} m$$\n"
    assert [v.status for v in check_text(text)] == ["unrecognised"]


def test_hostile_prose_ends_quickly():
    import time

    prose = "Let $\\mathbf{r}$ be the position of " + "$a$ the position relative to " * 20000
    text = "# T\n\n" + prose + "\n\n$$\\int_B \\mathbf{r}\\, dm = \\mathbf{0}$$\n"
    start = time.perf_counter()
    check_text(text)
    assert time.perf_counter() - start < 4
