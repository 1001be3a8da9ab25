"""Coriolis matrix entries written one by one (``C_{11} = ...``), as exam answers write
them, on Spong's planar elbow arm (bundled ``planar-2r``).

The hand closed form (Spong, Hutchinson & Vidyasagar, section 7.4.2, the model file's
header): with ``h = -m_2 l_1 l_{c2} \\sin q_2`` the Christoffel factorisation is
``C = [[h q̇_2, h (q̇_1 + q̇_2)], [-h q̇_1, 0]]`` and ``C q̇ = (2 h q̇_1 q̇_2 + h q̇_2^2, -h q̇_1^2)``.
``C' = [[0, h (2 q̇_1 + q̇_2)], [-h q̇_1, 0]]`` gives the same product: another factorisation.
"""

from __future__ import annotations

import armdyn

H = r"m_2 l_1 l_{c2} \sin q_2"  # -h
HEAD = "---\nrobot: planar-2r\n---\n"


def _grade(tmp_path, entries: dict[str, str]):
    text = HEAD + "\n".join(f"$$C_{{{k}}} = {v}$$\n" for k, v in entries.items())
    path = tmp_path / "c.md"
    path.write_text(text)
    return {v.name: v.status for v in armdyn.grade(str(path)).steps}


def test_christoffel_entries_are_correct(tmp_path):
    got = _grade(
        tmp_path, {"11": rf"-{H}\,\dot q_2", "12": rf"-{H}(\dot q_1 + \dot q_2)", "21": rf"{H}\,\dot q_1", "22": "0"}
    )
    assert got == {"C_11": "correct", "C_12": "correct", "C_21": "correct", "C_22": "correct"}


def test_entries_without_their_rates_are_wrong_zero_entries_read(tmp_path):
    """The exam slip: the entries written without q̇ (C_{12} = -h, no rates). C_{11} = 0 and
    C_{22} = 0 are read as entries (no shorthand is zero): C_{22} is right, C_{11} is not the
    Christoffel entry and the matrix they make does not give C q̇."""
    got = _grade(tmp_path, {"11": "0", "12": rf"-{H}", "21": rf"{H}", "22": "0"})
    assert got == {"C_11": "wrong", "C_12": "wrong", "C_21": "wrong", "C_22": "correct"}


def test_another_factorisation_is_right_by_convention(tmp_path):
    got = _grade(tmp_path, {"11": "0", "12": rf"-{H}(2\dot q_1 + \dot q_2)", "21": rf"{H}\,\dot q_1", "22": "0"})
    assert got == {
        "C_11": "correct-by-convention",
        "C_12": "correct-by-convention",
        "C_21": "correct",
        "C_22": "correct",
    }


def test_a_wrong_entry_in_another_factorisation_stays_wrong(tmp_path):
    got = _grade(tmp_path, {"11": "0", "12": rf"-{H}(2\dot q_1 - \dot q_2)", "21": rf"{H}\,\dot q_1", "22": "0"})
    assert got["C_11"] == "wrong" and got["C_12"] == "wrong"


def test_the_shorthand_is_still_the_shorthand(tmp_path):
    path = tmp_path / "s.md"
    path.write_text(HEAD + "$$c_{12} = \\cos(q_1 + q_2)$$\n\n$$C_{12} = \\cos(q_1 + q_2)$$\n")
    steps = armdyn.grade(str(path)).steps
    assert [(v.key, v.status) for v in steps] == [("shorthand", "correct"), ("shorthand", "correct")]
