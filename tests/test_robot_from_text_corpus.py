"""Every example and corpus derivation graded with its ``robot:`` line removed (the model
read from the text) against the same file graded with its bundled model: the same
verdicts (line, name, status per equation), or the reason it cannot, documented in
docs/grading.md ("The corpus without `robot:`"), is the error the reading gives."""

from __future__ import annotations

import glob
import os
import re

import pytest

from armdyn.errors import ModelError
from armdyn.grading import grade
from armdyn.grading.reader import read
from armdyn.grading.robot_text import robot_from_text

HERE = os.path.dirname(__file__)
ROOT = os.path.join(HERE, "..")
FILES = sorted(
    p
    for d in (os.path.join(ROOT, "examples", "grading"), os.path.join(HERE, "corpus"))
    for p in glob.glob(os.path.join(d, "*.md"))
    if not p.endswith("README.md")
)

_NO_POSITION = "frame 2's origin is not stated"
#: file -> the error the reading gives (what the text does not state), or the lines whose
#: verdicts differ (a slip in the only statement of the geometry becomes the geometry read)
NOT_SAME: dict[str, str | set[int]] = {
    # the quill's height is stated (z_{c3}), not where links 1 and 2 put it in the plane
    "scara-lagrange.md": "joint variable q3 moves nothing",
    # Craig's P_2, {}^{i}P_{C_i} used only in products, and no ω_1, ω̇_1 to solve them from
    # (its transposed rotation is found at its line on the text's own values)
    "planar-2r-craig-transposed.md": _NO_POSITION,
    # the closed-form M, c, g only: the geometry is in words
    "planar-2r-lynch-park.md": _NO_POSITION,
    "planar-2r-lynch-park-gamma.md": _NO_POSITION,
    "planar-2r-siciliano.md": _NO_POSITION,
    "planar-2r-spong-christoffel.md": _NO_POSITION,
    "planar-2r-mls-constants.md": _NO_POSITION,
    # the laws stated first, then Craig's iteration with {}^{i}P_{i+1} used in products only
    "planar-2r-laws-craig-ne.md": _NO_POSITION,
    # the laws stated first, then D's entries, Christoffel symbols and phi_k: the geometry in words
    "planar-2r-laws-energy.md": "joint variable q1 moves nothing",  # M, C, N in lumped constants only
    "planar-2r-asada-slotine.md": _NO_POSITION,  # H_ij, h_ijk, G_i only
    # the forward recursion of link 2 only: links 1 and 3 are placed in words
    "planar-3r-spong-superscripts.md": _NO_POSITION,
    # links 1 and 3 are placed (x_{c1}, y_{c3}, P_1, P_3); link 2 only in words
    "planar-3r-rods-energy.md": "frame 2's origin is not stated",
    # vectors in frame i; masses only as m_i of a generic link in the prose
    "planar-3r-spong-ne-slip.md": "no mass of link 1",
    # the planar links' geometry in words; only the quill's height and energies stated
    "scara-inertia-matrix-slip.md": "no variable of joint 3 is written",
    "scara-mathfence-slip.md": "moves with other joints than joint 3",
}


def _unnamed(path: str, tmp_path) -> str:
    """The file with its front matter's ``robot:`` line made a comment (lines kept)."""
    lines = open(path, encoding="utf-8").read().split("\n")
    assert sum(ln.startswith("robot:") for ln in lines) == 1, "each file names its robot once"
    out = tmp_path / os.path.basename(path)
    out.write_text("\n".join("# (robot removed)" if ln.startswith("robot:") else ln for ln in lines), "utf-8")
    return str(out)


def _verdicts(report):
    return [(v.line, v.name, v.status) for v in report.steps]


def test_every_file_is_listed_here():
    names = {os.path.basename(p) for p in FILES}
    assert len(names) == len(FILES) == 42
    assert set(NOT_SAME) <= names


@pytest.mark.parametrize("path", FILES, ids=os.path.basename)
def test_same_verdicts_without_robot_or_the_documented_reason(path, tmp_path):
    named = _verdicts(grade(path))
    assert named, "the file grades some equation with its model"
    expected = NOT_SAME.get(os.path.basename(path))
    unnamed_path = _unnamed(path, tmp_path)
    if isinstance(expected, str):
        with pytest.raises(ModelError, match="cannot read the robot from the text: .*" + re.escape(expected)):
            robot_from_text(read(unnamed_path))
        report = grade(unnamed_path)  # never refused: graded against its own earlier values
        assert report.model_note.startswith("no model:") and expected in report.model_note
        assert [v.line for v in report.steps] == sorted(v.line for v in report.steps)
        return
    report = grade(unnamed_path)
    assert report.notes[0].startswith("model read from the text")
    unnamed = _verdicts(report)
    if expected is None:
        assert unnamed == named
    else:
        assert [v[:2] for v in unnamed] == [v[:2] for v in named]
        assert {a[0] for a, b in zip(named, unnamed, strict=True) if a != b} == expected
