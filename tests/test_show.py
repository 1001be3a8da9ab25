"""armdyn.show: the joint/link table, forward kinematics and the picture.

Second opinions: forward kinematics against Pinocchio (iiwa 14, its own URDF parser) and
a planar arm's closed form; the table's rpy against model.rpy_matrix (round trip); the
picture is read back as an image and the projected frame origins are checked to land
inside it.
"""

from __future__ import annotations

import warnings
from pathlib import Path

import matplotlib.image
import matplotlib.text
import numpy as np
import pytest
import sympy as sp

from armdyn.errors import ModelError
from armdyn.io import load
from armdyn.io.urdf import load_urdf
from armdyn.model import rpy_matrix
from armdyn.show import draw, frame_poses, numeric_robot, rpy, show, table

IIWA = Path(__file__).resolve().parent.parent / "python" / "armdyn" / "robots" / "iiwa14.urdf"


def test_frame_poses_match_pinocchio():
    pin = pytest.importorskip("pinocchio")
    robot = load_urdf(IIWA)
    model = pin.buildModelFromUrdf(str(IIWA))
    data = model.createData()
    rng = np.random.default_rng(0)
    for _ in range(5):
        q = rng.uniform(-2, 2, 7)
        pin.framesForwardKinematics(model, data, q)
        poses = frame_poses(robot, q)
        assert list(poses) == list(robot.links)
        for name, T in poses.items():
            assert np.allclose(T, data.oMf[model.getFrameId(name, pin.BODY)].homogeneous, atol=1e-12)


def test_frame_poses_of_planar_arm_by_hand():
    robot = load("planar-3r").bind()
    q = np.array([0.3, -0.7, 1.1])
    tip = frame_poses(robot, q)["flange"][:3, 3]  # DH frame 3: the end of link 3
    angles = np.cumsum(q)
    assert np.allclose(tip, [np.cos(angles).sum(), np.sin(angles).sum(), 0], atol=1e-14)


def test_rpy_round_trip():
    rng = np.random.default_rng(1)
    for r, p, y in [*rng.uniform(-3, 3, (20, 3)), (0.2, np.pi / 2, -0.4), (0.2, -np.pi / 2, 1.0)]:
        p = float(np.clip(p, -np.pi / 2, np.pi / 2))
        R = rpy_matrix(*(sp.Float(v) for v in (r, p, y)))
        again = rpy_matrix(*(sp.Float(v) for v in rpy(R)))
        assert np.allclose(np.array(again.evalf(), dtype=float), np.array(R.evalf(), dtype=float), atol=1e-12)


def test_table_lists_every_joint_and_link():
    robot = load_urdf(IIWA)
    text = table(robot)
    for name in [j.name for j in robot.joints] + list(robot.links):
        assert name in text
    assert "[-2.96706, 2.96706]" in text  # iiwa_joint_1 limits
    assert "(0, -0.03, 0.12)" in text and "5.76" in text  # iiwa_link_1 com and mass
    assert "no <inertial>" in text  # the massless base and flange are flagged
    assert "(1.5708, 0, 3.14159)" in text  # iiwa_joint_2 placement rpy


def test_show_writes_a_picture(tmp_path):
    out = tmp_path / "ur5.png"
    text = show(load("ur5"), q=[0, -1.2, 1.4, -1.8, -1.57, 0], out=out)
    assert "shoulder_pan_joint" in text
    image = matplotlib.image.imread(out)
    assert image.ndim == 3 and image.shape[0] > 300 and image.shape[1] > 300
    # not blank: a good share of pixels are drawn (links, arrows, text)
    assert (image[..., :3].mean(axis=2) < 0.9).mean() > 0.01


def test_picture_contains_every_frame_origin(tmp_path):
    """Project each frame origin with the axes' own projection: all fall inside the
    plotted box, so nothing of the arm is cut off."""
    robot = load("panda")
    q = [0, -0.6, 0, -2.2, 0, 1.6, 0.8]
    fig = draw(robot, q)
    ax = fig.axes[0]
    limits = np.array([ax.get_xlim(), ax.get_ylim(), ax.get_zlim()])
    for T in frame_poses(robot, q).values():
        p = T[:3, 3]
        assert np.all(p >= limits[:, 0]) and np.all(p <= limits[:, 1])
    spans = limits[:, 1] - limits[:, 0]
    # equal scales: each side of the drawn box is proportional to its axis range
    ratio = spans / np.asarray(ax.get_box_aspect())
    assert np.allclose(ratio, ratio[0])


@pytest.mark.parametrize("name, q", [("ur5", [0, -1.2, 1.4, -1.8, -1.57, 0]), ("panda", None), ("iiwa14", None)])
def test_joint_names_do_not_overlap(name, q):
    """Every movable joint is named once; the names' rendered boxes overlap neither each
    other nor the figure's edge."""
    fig = draw(load(name), q)
    fig.canvas.draw()
    renderer = fig.canvas.get_renderer()
    ax = fig.axes[0]
    robot = load(name)
    names = [t for t in ax.texts if t.get_text() in {j.name for j in robot.movable_joints}]
    assert sorted(t.get_text() for t in names) == sorted(j.name for j in robot.movable_joints)
    boxes = [matplotlib.text.Text.get_window_extent(t, renderer) for t in names]  # the text, not its leader line
    for i, a in enumerate(boxes):
        assert a.x0 >= 0 and a.y0 >= 0 and a.x1 <= fig.bbox.width and a.y1 <= fig.bbox.height, names[i].get_text()
        for b in boxes[i + 1 :]:
            assert not a.overlaps(b), (names[i].get_text(), a, b)


def test_symbolic_robot_is_bound_to_its_defaults():
    text = show(load("scara"))
    assert "0.325" in text and "8" in text  # a1 and m1 defaults


def test_free_parameters_are_named():
    with pytest.raises(ModelError) as info:
        numeric_robot(load("planar-2r"))  # no published values, only g
    assert "I1" in info.value.message and "m1" in info.value.message and "'planar-2r'" in info.value.element


def test_non_physical_defaults_need_the_relaxed_check():
    with pytest.raises(ModelError, match="triangle inequality"):
        show(load("stanford", strict=True))
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        assert "link5" in show(load("stanford", strict=False))


def test_wrong_q_is_a_value_error(tmp_path):
    robot = load("ur5")
    with pytest.raises(ValueError, match="6 values"):
        show(robot, q=[0, 1], out=tmp_path / "x.png")
    with pytest.raises(ValueError, match="NaN"):
        show(robot, q=[0, 1, 2, 3, 4, float("nan")], out=tmp_path / "x.png")
