"""A class's and the web app's submission that names no model: graded against the robot
its text describes, warned when that differs (as dynamics) from the variant the course
assigned, graded against the assigned one when the text's cannot be read."""

from __future__ import annotations

import math
import os
import shutil

import pytest
import sympy as sp

import armdyn
from armdyn.course.batch import discover, grade_class, grade_task
from armdyn.errors import ModelError
from armdyn.grading import grade
from armdyn.grading.reader import read
from armdyn.grading.robot_text import robot_from_text
from armdyn.grading.robot_text.assigned import dynamics_differ
from armdyn.io import bundled_files
from armdyn.serve.worker import FROM_TEXT, Grader

HERE = os.path.dirname(__file__)
EXAMPLES = os.path.join(HERE, "..", "examples", "grading")


def _text(name: str, front: str = "") -> str:
    """An example with its ``robot:`` line replaced by ``front`` or a comment (lines kept)."""
    lines = open(os.path.join(EXAMPLES, name), encoding="utf-8").read().split("\n")
    return "\n".join((front or "# (robot removed)") if ln.startswith("robot:") else ln for ln in lines)


def _verdicts(report) -> list:
    return [(v.line, v.name, v.status) for v in report.steps]


@pytest.fixture()
def klass(tmp_path):
    """Variants (a bundled model's YAML each) and four submissions."""
    variants = tmp_path / "variants"
    for vid, model in (("v2r", "planar-2r"), ("vrp", "rp-arm"), ("vsc", "scara")):
        (variants / vid).mkdir(parents=True)
        shutil.copy(bundled_files()[model], variants / vid / "model.yaml")
    subs = tmp_path / "subs"
    subs.mkdir()
    (subs / "alice.md").write_text(_text("planar-2r-lagrange.md", "variant: v2r"), "utf-8")
    (subs / "bob.md").write_text(_text("planar-2r-lagrange.md", "variant: vrp"), "utf-8")
    (subs / "carol.md").write_text(_text("scara-lagrange.md", "variant: vsc"), "utf-8")
    named = open(os.path.join(EXAMPLES, "planar-2r-lagrange.md"), encoding="utf-8").read()
    (subs / "dave.md").write_text(named.replace("robot: planar-2r", "robot: planar-2r\nvariant: v2r"), "utf-8")
    return subs, variants


def test_dynamics_compared_at_random_states():
    planar = armdyn.load("planar-2r")
    read_model = robot_from_text(read(os.path.join(EXAMPLES, "planar-2r-lagrange.md")))
    # the text's symbols are the model's (l_{c1} -> lc1): the same arm agrees
    assert dynamics_differ(read_model.robot, planar) is None
    # no gravity: M and C agree, g differs (a closed form: g_2 = m2 lc2 g cos(q1 + q2) != 0)
    no_g = planar.subs({"g": 0})
    assert "gravity torques" in dynamics_differ(read_model.robot, no_g)
    # a longer second link: M differs (M_22 = m2 lc2^2 + I2 by hand)
    longer = planar.subs({"lc2": 2 * sp.Symbol("lc2")})
    assert "mass matrix" in dynamics_differ(read_model.robot, longer)
    assert "2 joints, the assigned model has 3" == dynamics_differ(read_model.robot, armdyn.load("planar-3r"))
    # NaN never passes
    with pytest.warns(UserWarning, match="not a finite real number"):
        nan_mass = planar.subs({"m2": math.nan})
    assert dynamics_differ(nan_mass, planar) is not None


def test_class_without_robot_graded_from_the_text_and_warned(klass):
    subs, variants = klass
    found = discover(str(subs), str(variants))
    by = {t.student: t for t in found.tasks}
    assert {s: t.from_text for s, t in by.items()} == {"alice": True, "bob": True, "carol": True, "dave": False}
    named = grade(os.path.join(EXAMPLES, "planar-2r-lagrange.md"))

    alice = grade_task(by["alice"].__dict__)["report"]
    assert alice["notes"][0].startswith("model read from the text")
    assert not any("WARNING" in n for n in alice["notes"])
    assert [(s["line"], s["name"], s["status"]) for s in alice["steps"]] == _verdicts(named)

    bob = grade_task(by["bob"].__dict__)["report"]  # an RR text, an RP variant assigned
    assert bob["notes"][0].startswith("WARNING: the robot your text describes is not your assigned model variant vrp")
    assert [(s["line"], s["name"], s["status"]) for s in bob["steps"]] == _verdicts(named)

    carol = grade_task(by["carol"].__dict__)["report"]  # the SCARA text cannot be read: the variant's model
    assert carol["notes"][0].startswith("graded against the assigned model variant vsc: ")
    assert "q3 moves nothing" in carol["notes"][0]
    scara = grade(os.path.join(EXAMPLES, "scara-lagrange.md"))
    assert [(s["line"], s["name"], s["status"]) for s in carol["steps"]] == _verdicts(scara)

    dave = grade_task(by["dave"].__dict__)["report"]  # names its model: the variant's, as before
    assert not any("read from the text" in n or "WARNING" in n for n in dave["notes"])


def test_class_report_carries_the_warning(klass, tmp_path):
    subs, variants = klass
    result = grade_class(
        str(subs), str(tmp_path / "grades.csv"), html_dir=str(tmp_path / "html"), jobs=1, variants=str(variants)
    )
    assert not result.not_graded
    assert "is not your assigned model variant vrp" in (tmp_path / "html" / "bob.html").read_text("utf-8")
    assert "is not your assigned model" not in (tmp_path / "html" / "alice.html").read_text("utf-8")


def test_serve_worker_grades_the_texts_robot():
    g = Grader({"planar-2r": "planar-2r", "rp-arm": "rp-arm"})
    plain = g.grade(_text("planar-2r-lagrange.md"), None)
    assert plain["error"] is None and plain["graded_as"] == FROM_TEXT
    assert "model read from the text" in plain["report_json"] and "WARNING" not in plain["report_json"]
    # a served variant named in the front matter: compared, warned
    warned = g.grade(_text("planar-2r-lagrange.md", "variant: rp-arm"), None)
    assert warned["graded_as"] == FROM_TEXT and "is not your assigned model exercise rp-arm" in warned["report_json"]
    same = g.grade(_text("planar-2r-lagrange.md", "variant: planar-2r"), None)
    assert same["graded_as"] == FROM_TEXT and "WARNING" not in same["report_json"]
    # an exercise chosen in the request names the model: graded against it, as before
    chosen = g.grade(_text("planar-2r-lagrange.md"), "planar-2r")
    assert chosen["graded_as"] == "planar-2r" and "read from the text" not in chosen["report_json"]
    # a text whose robot cannot be read and no variant: graded on its own values, saying why
    bad = g.grade(_text("scara-lagrange.md"), None)
    assert bad["error"] is None and bad["graded_as"] == FROM_TEXT
    assert "no model: the robot could not be read from the text" in bad["report_json"]
    # an unknown variant is not a path to open: the text's robot, nothing loaded
    odd = g.grade(_text("planar-2r-lagrange.md", "variant: ../../etc/passwd"), None)
    assert odd["graded_as"] == FROM_TEXT and odd["error"] is None
    with pytest.raises(ModelError, match="unknown exercise"):
        g.robot("../../etc/passwd")


def test_the_cache_key_holds_the_graders_source():
    # a changed grader (robot_text included) must re-grade: its source is in the fingerprint
    import hashlib

    from armdyn import __version__
    from armdyn.course.batch import _grader_fingerprint

    assert _grader_fingerprint() != hashlib.sha256(__version__.encode()).hexdigest()
