"""The course material: the statement's drawing has every label on its object, the worked
solution is written in a teacher's notation (and still grades correct), and comes as HTML.

The drawing's geometry is checked against positions worked out here by hand for the
assignment's RP arm (Craig's frames: joint 1 at the origin, link 1 along
(cos θ1, sin θ1), the slide along y1 = (-sin θ1, cos θ1) from l1 out, frame 2 at its end).
"""

from __future__ import annotations

import math
import re

import numpy as np
import pytest
import yaml

import armdyn
from armdyn.course.drawing import ANGLE, NOMINAL, SLIDE, _figure
from armdyn.course.exercise import make_exercise
from armdyn.course.variants import draw_variant
from armdyn.io.yaml import load_yaml_string


def _labels(kind, convention, **kw):
    import matplotlib.pyplot as plt

    v = draw_variant(kind, "s1", seed=2, convention=convention, symbolic=True, **kw)
    robot = load_yaml_string(yaml.safe_dump(v.model_dict(), sort_keys=False), "m.yaml")
    fig = _figure(v, robot)
    try:
        return {t.get_text(): np.array(t.get_position(), float) for t in fig.axes[0].texts}
    finally:
        plt.close(fig)


def test_rp_drawing_labels_sit_on_their_objects():
    at = _labels("rp", "craig")
    l1 = NOMINAL["l1"]
    u = np.array([math.cos(ANGLE), math.sin(ANGLE)])  # link 1
    y1 = np.array([-math.sin(ANGLE), math.cos(ANGLE)])  # the slide
    start, end = l1 * u, l1 * u + SLIDE * y1
    # the angle at joint 1 (the origin), between x0 and link 1
    theta = at[r"$\theta_{1}$"]
    assert np.linalg.norm(theta) < 0.7
    bisector = math.atan2(theta[1], theta[0])
    assert 0 < bisector < ANGLE  # inside the angle
    # d2 beside the middle of the slide, l1 beside the middle of link 1
    assert np.linalg.norm(at["$d_{2}$"] - (start + end) / 2) < 0.45
    assert np.linalg.norm(at["$l_{1}$"] - l1 * u / 2) < 0.45
    assert "$l_{2}$" in at
    # frames 0 and 1 at the origin, frame 2 at the slide's end: their axes labelled there
    for name in ("$x_{0}$", "$y_{0}$", "$x_{1}$", "$y_{1}$"):
        assert np.linalg.norm(at[name]) < 0.45, name
    assert np.linalg.norm(at["$x_{2}$"] - end) < 0.45 and np.linalg.norm(at["$z_{2}$"] - end) < 0.45
    assert "$m_{1}$" in at and "$m_{2}$" in at
    assert any(k.startswith("$g$") for k in at) or "$g$" in at


@pytest.mark.parametrize("kind, joints", [("rr", ("theta", "theta")), ("rrr", ("theta",) * 3), ("pr", ("d", "theta"))])
def test_every_joint_and_length_is_labelled(kind, joints):
    at = _labels(kind, "offaxis")
    for i, j in enumerate(joints, 1):
        assert (rf"$\{j}_{{{i}}}$" if j == "theta" else f"${j}_{{{i}}}$") in at
    for i in range(1, len(joints) + 1):
        assert f"$l_{{{i}}}$" in at and f"$m_{{{i}}}$" in at
        assert any(k.startswith(f"$x_{{{i}}}$") for k in at)


def test_solution_in_a_teachers_notation(tmp_path):
    make_exercise("rp", tmp_path, seed=1, count=1, convention="craig")
    text = (tmp_path / "v001" / "solution.md").read_text()
    assert r"\dot\theta_1" in text and r"\ddot d_2" in text and r"\sin \theta_1" in text
    for raw in (r"\dot{\theta_{1}}", r"\sin{\left(", r"\theta_{1}", r"\dot{d_{2}}"):
        assert raw not in text, raw
    # terms collected: tau_1 (Lagrange's, the last line) names theta1'' once
    tau1 = [line for line in text.splitlines() if line.startswith(r"$$\tau_{1} = ")][-1]
    assert len(re.findall(r"\\ddot\\theta_1(?![0-9])", tau1)) == 1
    report = armdyn.grade(str(tmp_path / "v001" / "solution.md"))
    assert report.passed and report.first_wrong is None
    page = (tmp_path / "v001" / "solution.html").read_text()
    assert page.count('display="block"') == text.count("$$") // 2 and "<pre>" not in page  # every step
    assert "default-src 'none'" in page
