"""URDF reader (armdyn.io.urdf) against hand-derived values and against Pinocchio's own
URDF parser (pin.buildModelFromUrdf), which shares no code with it.

For each URDF compared: the pose of every link frame at random q (armdyn: products of
Joint.transform; Pinocchio: its BODY frames), each moving body's inertia (armdyn: the
child link plus everything welded to it by fixed joints, combined here with NumPy;
Pinocchio: model.inertias, where its parser merged them), and rnea / crba / aba at random
states (armdyn.reference, and armdyn.numeric once it exists) to 1e-12 relative.
"""

from __future__ import annotations

import importlib.metadata
import time
import warnings
from pathlib import Path

import numpy as np
import pytest
import sympy as sp

import armdyn.reference as reference
from armdyn.errors import ModelError
from armdyn.io.urdf import MasslessWarning, load_urdf
from armdyn.show import frame_poses

pin = pytest.importorskip("pinocchio")

# shared/ sits beside the repository (CI) or at /work/shared (development machines)
IIWA = next(
    (p for p in (Path(__file__).resolve().parents[2] / "shared", Path("/work/shared"))
     if (p / "data" / "iiwa14_dynamics_only.urdf").is_file()),
    Path("/work/shared"),
) / "data" / "iiwa14_dynamics_only.urdf"
BUNDLED_IIWA = Path(__file__).resolve().parent.parent / "python" / "armdyn" / "robots" / "iiwa14.urdf"
RTOL = 1e-12
SINGULAR = 1e12  # condition number of M above which forward dynamics is not compared


def example_robot_data_dir() -> Path | None:
    """``robots/`` of the example-robot-data wheel, or None if it is not installed."""
    try:
        dist = importlib.metadata.distribution("example-robot-data")
    except importlib.metadata.PackageNotFoundError:
        return None
    path = Path(dist.locate_file("cmeel.prefix/share/example-robot-data/robots"))
    return path if path.is_dir() else None


def engines():
    """armdyn's dynamics engines to compare: the NumPy reference, and the Rust-backed
    armdyn.numeric when it is built."""
    out = [reference]
    try:
        import armdyn.numeric as numeric

        out.append(numeric)
    except ImportError:
        pass
    return out


# ------------------------------------------------------------ Pinocchio helpers


def pin_configuration(model, robot, q: np.ndarray):
    """Pinocchio's (q, velocity permutation) for armdyn's coordinates ``q``.

    Pinocchio orders joints depth-first and represents a continuous joint by
    (cos q, sin q); ``perm[k]`` is the armdyn coordinate of Pinocchio's velocity k.
    """
    qp = np.zeros(model.nq)
    perm = np.zeros(model.nv, dtype=int)
    for j in range(1, model.njoints):
        k = robot.coordinate_index(model.names[j])
        iq, iv = model.idx_qs[j], model.idx_vs[j]
        perm[iv] = k
        if model.joints[j].nq == 2:
            qp[iq : iq + 2] = np.cos(q[k]), np.sin(q[k])
        else:
            qp[iq] = q[k]
    return qp, perm


def random_coordinates(robot, rng) -> np.ndarray:
    return np.array([rng.uniform(-np.pi, np.pi) if j.type == "revolute" else rng.uniform(-0.3, 0.3)
                     for j in robot.movable_joints])


def floats(m) -> np.ndarray:
    return np.array(sp.Matrix(m).evalf(), dtype=float)


def body_inertia(robot, link: str):
    """(mass, com (3,), inertia about com (3,3)) of ``link`` plus every link welded to it
    by fixed joints, in ``link``'s frame: the rigid body Pinocchio builds."""
    parts, stack = [], [(link, np.eye(4))]
    while stack:
        name, T = stack.pop()
        ln = robot.links[name]
        R, p = T[:3, :3], T[:3, 3]
        parts.append((float(ln.mass), R @ floats(ln.com).ravel() + p, R @ floats(ln.inertia) @ R.T))
        for j in robot.children(name):
            if not j.movable:
                R, p = j.transform(0)
                local = np.eye(4)
                local[:3, :3], local[:3, 3] = floats(R), floats(p).ravel()
                stack.append((j.child, T @ local))
    mass = sum(m for m, _, _ in parts)
    com = sum(m * c for m, c, _ in parts) / mass if mass > 0 else np.zeros(3)
    inertia = np.zeros((3, 3))
    for m, c, ic in parts:  # parallel axis theorem about the combined centre of mass
        d = c - com
        inertia += ic + m * (d @ d * np.eye(3) - np.outer(d, d))
    return mass, com, inertia


def close(a, b, rtol=RTOL) -> float:
    """Relative difference, scaled by the larger magnitude (at least 1)."""
    a, b = np.asarray(a, dtype=float), np.asarray(b, dtype=float)
    return float(np.abs(a - b).max(initial=0.0) / max(1.0, np.abs(b).max(initial=0.0)))


def compare_with_pinocchio(
    robot, model, rng, states: int = 2, rtol: float = RTOL, dynamics: bool = True, same_frames: bool = True
) -> bool:
    """Assert that ``robot`` (armdyn) and ``model`` (Pinocchio, fixed base, parsed from
    the same URDF) agree: frames and body inertias (when both name the same link frames,
    ``same_frames``), and rnea/crba/aba. Returns False if aba was left out because the
    mass matrix is singular (cond > SINGULAR), else True."""
    data = model.createData()
    skipped_aba = False
    assert model.nv == robot.dof
    for _ in range(states if same_frames else 0):
        # kinematics: every armdyn link frame that Pinocchio also has
        q = random_coordinates(robot, rng)
        qp, _ = pin_configuration(model, robot, q)
        pin.framesForwardKinematics(model, data, qp)
        ours = frame_poses(robot, q)
        for name, T in ours.items():
            if model.existFrame(name, pin.BODY):
                theirs = data.oMf[model.getFrameId(name, pin.BODY)].homogeneous
                assert close(T, theirs) < rtol * 10, f"pose of link '{name}'"
    # inertias of the moving bodies
    for j in range(1, model.njoints if same_frames else 1):
        joint = next(jt for jt in robot.joints if jt.name == model.names[j])
        mass, com, inertia = body_inertia(robot, joint.child)
        theirs = model.inertias[j]
        assert abs(mass - theirs.mass) <= rtol * max(1, mass), f"mass of body '{joint.child}'"
        if mass > 0:
            assert close(com, theirs.lever) < rtol * 10, f"com of body '{joint.child}'"
        assert close(inertia, theirs.inertia) < rtol * 10, f"inertia of body '{joint.child}'"
    if not dynamics or robot.dof == 0:
        return True
    for engine in engines():
        for _ in range(states):
            q, qd, qdd = (random_coordinates(robot, rng), rng.uniform(-1, 1, robot.dof), rng.uniform(-1, 1, robot.dof))
            qp, perm = pin_configuration(model, robot, q)
            tau = pin.rnea(model, data, qp, qd[perm], qdd[perm])
            # URDF <dynamics damping friction> enter armdyn's tau (Fv qd + Fc sign(qd)),
            # not Pinocchio's rnea/aba: compared with that closed form added
            fr = np.array([float(j.damping or 0) * v + float(j.friction or 0) * np.sign(v)
                           for j, v in zip(robot.movable_joints, qd)])[perm]
            assert close(engine.rnea(robot, q, qd, qdd)[perm] - fr, tau) < rtol, f"{engine.__name__}.rnea"
            M = pin.crba(model, data, qp)
            M = np.triu(M) + np.triu(M, 1).T
            assert close(engine.crba(robot, q)[np.ix_(perm, perm)], M) < rtol, f"{engine.__name__}.crba"
            if np.linalg.cond(M) > SINGULAR:
                skipped_aba = True  # a body with no mass or inertia: qdd is not defined
                continue
            # aba is a linear solve: compare the torque it implies (M qdd + h), whose
            # error does not grow with the condition number of M, and qdd itself
            ours = engine.aba(robot, q, qd, tau_ours := engine.rnea(robot, q, qd, qdd))[perm]
            theirs = pin.aba(model, data, qp, qd[perm], tau_ours[perm] - fr)
            implied = pin.rnea(model, data, qp, qd[perm], ours) + fr
            assert close(implied, tau_ours[perm]) < rtol, f"{engine.__name__}.aba (implied torque)"
            # (friction much larger than the rigid torque costs digits in tau - friction)
            digits = max(1.0, np.abs(fr).max(initial=0) / max(np.abs(tau).max(initial=0), 1e-300))
            assert close(ours, theirs) < rtol * max(1.0, np.linalg.cond(M)) * digits, f"{engine.__name__}.aba"
    return not skipped_aba


# ------------------------------------------------------------ hand-made URDFs

FEATURES = """<?xml version="1.0"?>
<!-- a test arm -->
<robot name="features">
  <link name="base"/>
  <joint name="spin" type="continuous">
    <parent link="base"/><child link="l1"/>
    <origin xyz="0 0 0.5"/>
    <axis xyz="0 0 1"/>
    <limit effort="10" velocity="2" lower="-1" upper="1"/>
    <dynamics damping="0.25" friction="0.5"/>
  </joint>
  <link name="l1">
    <inertial>
      <origin xyz="0.1 0.2 0.3" rpy="0 0 1.5707963267948966"/>
      <mass value="2"/>
      <inertia ixx="1" iyy="2" izz="3" ixy="0" ixz="0" iyz="0"/>
    </inertial>
    <visual><geometry><box size="1 1 1"/></geometry></visual>
  </link>
  <joint name="slide" type="prismatic">
    <parent link="l1"/><child link="l2"/>
    <origin xyz="1 0 0" rpy="1.5707963267948966 0 0"/>
    <axis xyz="0 0.6 0.8"/>
    <limit effort="100" velocity="1" lower="0" upper="0.4"/>
  </joint>
  <link name="l2">
    <inertial><mass value="1"/><inertia ixx="0.1" iyy="0.1" izz="0.1" ixy="0" ixz="0" iyz="0"/></inertial>
  </link>
  <joint name="weld" type="fixed">
    <parent link="l2"/><child link="tool"/>
    <origin xyz="0 0 0.2"/>
    <axis xyz="0 0 0"/>
  </joint>
  <link name="tool"/>
  <joint name="roll" type="revolute">
    <parent link="tool"/><child link="l3"/>
    <limit effort="1" velocity="1" lower="-3" upper="3"/>
  </joint>
  <link name="l3">
    <inertial><mass value="0.5"/><inertia ixx="0.01" iyy="0.02" izz="0.02" ixy="0" ixz="0" iyz="0"/></inertial>
  </link>
  <gazebo reference="l1"><material>Gazebo/Red</material></gazebo>
</robot>
"""


def test_features_read_as_written():
    robot = load_urdf(FEATURES)
    assert robot.name == "features" and robot.base == "base"
    assert [j.type for j in robot.joints] == ["revolute", "prismatic", "fixed", "revolute"]
    assert robot.dof == 3 and robot.coordinate_names == ["spin", "slide", "roll"]
    spin, slide, weld, roll = robot.joints
    # continuous: no position limits (URDF ignores them), the rest kept
    assert spin.lower is None and spin.upper is None
    assert float(spin.effort) == 10 and float(spin.velocity) == 2
    assert float(spin.damping) == 0.25 and float(spin.friction) == 0.5
    assert (float(slide.lower), float(slide.upper)) == (0, 0.4)
    assert slide.damping is None and slide.friction is None
    # axis default is URDF's (1, 0, 0); the fixed joint's zero axis is ignored
    assert list(roll.axis) == [1, 0, 0]
    assert np.allclose(floats(slide.axis).ravel(), [0, 0.6, 0.8])
    # rpy: roll pi/2 about x maps y to z
    assert np.allclose(floats(slide.rotation) @ [0, 1, 0], [0, 0, 1])
    assert robot.gravity.T.tolist() == [[0, 0, -9.81]]
    assert robot.meta["source"] == "a test arm" and robot.meta["convention"] == "urdf"


def test_inertial_origin_rotation_is_honoured():
    """<inertial> rpy = yaw pi/2 turns the inertial frame's x into the link's y, so the
    tensor diag(1, 2, 3) reads diag(2, 1, 3) in the link frame (by hand)."""
    l1 = load_urdf(FEATURES).links["l1"]
    assert float(l1.mass) == 2
    assert np.allclose(floats(l1.com).ravel(), [0.1, 0.2, 0.3])
    assert np.allclose(floats(l1.inertia), np.diag([2, 1, 3]), atol=1e-15)


def test_link_without_inertial_is_massless_and_reported():
    robot = load_urdf(FEATURES)
    assert robot.meta["massless_links"] == ["base", "tool"]
    tool = robot.links["tool"]
    assert tool.mass == 0 and tool.inertia == sp.zeros(3, 3)


def test_joint_moving_nothing_warns():
    start = FEATURES.index('<link name="l3">')
    end = FEATURES.index("</link>", start) + len("</link>")
    xml = FEATURES[:start] + '<link name="l3"/>' + FEATURES[end:]
    with pytest.warns(MasslessWarning, match="roll"):
        robot = load_urdf(xml)
    assert robot.meta["massless_links"] == ["base", "tool", "l3"]


def test_features_agree_with_pinocchio():
    robot = load_urdf(FEATURES)
    model = pin.buildModelFromXML(FEATURES)
    compare_with_pinocchio(robot, model, np.random.default_rng(1), states=3)


def test_path_and_text_give_the_same_robot(tmp_path):
    path = tmp_path / "arm.urdf"
    path.write_text(FEATURES)
    a, b = load_urdf(path), load_urdf(str(path))
    c = load_urdf(FEATURES)
    assert a.meta["file"] == str(path) and "file" not in c.meta
    for r in (b, c):
        assert [j.name for j in r.joints] == [j.name for j in a.joints]
        assert all(r.links[n].inertia == a.links[n].inertia for n in a.links)


def test_slightly_unnormalised_axis_is_normalised():
    robot = load_urdf(FEATURES.replace('"0 0.6 0.8"', '"0 0.6000001 0.8"'))
    axis = floats(robot.joints[1].axis).ravel()
    assert abs(np.linalg.norm(axis) - 1) < 1e-15


@pytest.mark.parametrize(
    "change, element, words",
    [
        (('type="continuous"', 'type="floating"'), "joint 'spin'", "floating joints are not supported yet"),
        (('type="continuous"', 'type="planar"'), "joint 'spin'", "planar joints are not supported yet"),
        (('<axis xyz="0 0 1"/>', '<axis xyz="0 0 1"/><mimic joint="slide"/>'), "joint 'spin'", "mimic joints"),
        (('"0 0.6 0.8"', '"0 0.6 0.9"'), "joint 'slide'", "not a unit vector"),
        (('"0 0.6 0.8"', '"0 0 0"'), "joint 'slide'", "axis is zero"),
        (('<mass value="2"/>', '<mass value="two"/>'), "link 'l1'", "not a finite number"),
        (('<mass value="2"/>', '<mass value="inf"/>'), "link 'l1'", "not a finite number"),
        (('<mass value="2"/>', '<mass value="${m1}"/>'), "link 'l1'", "xacro"),
        (('<mass value="2"/>', ""), "link 'l1'", "has no <mass>"),
        (('ixx="1" ', ""), "link 'l1'", "no 'ixx' attribute"),
        (('<origin xyz="1 0 0"', '<origin xyz="1 0"'), "joint 'slide'", "expected 3 numbers"),
        (('<child link="l2"/>', "<child/>"), "joint 'slide'", "no 'link' attribute"),
        (('<child link="l2"/>', ""), "joint 'slide'", "has no <child>"),
        (('<origin xyz="0 0 0.5"/>', '<origin xyz="0 0 0.5"/><origin xyz="0 0 1"/>'), "joint 'spin'", "more than one"),
    ],
)
def test_bad_elements_are_one_clear_error(change, element, words):
    with pytest.raises(ModelError) as info:
        load_urdf(FEATURES.replace(*change))
    err = info.value
    assert err.element == element and words in err.message and err.source == "<urdf>"
    assert "\n" not in str(err)


# ------------------------------------------------------------ iiwa 14 (Drake)


@pytest.mark.parametrize("path", [IIWA, BUNDLED_IIWA], ids=["shared", "bundled"])
def test_iiwa14_agrees_with_pinocchio(path):
    if not path.is_file():
        pytest.skip(f"{path} not present")
    robot = load_urdf(path)
    assert robot.dof == 7 and robot.meta["massless_links"] == ["base", "iiwa_link_ee"]
    compare_with_pinocchio(robot, pin.buildModelFromUrdf(str(path)), np.random.default_rng(7), states=3)


# ------------------------------------------------------------ example-robot-data


def unsupported_joint(path: Path) -> str | None:
    """Why Pinocchio's URDF would be out of scope: a floating/planar/mimic joint, read
    here with a plain XML scan (independent of the reader under test)."""
    import xml.etree.ElementTree as ET

    root = ET.parse(path).getroot()
    for j in root.findall("joint"):
        if j.get("type") in ("floating", "planar"):
            return f"{j.get('type')} joint '{j.get('name')}'"
        if j.find("mimic") is not None:
            return f"mimic joint '{j.get('name')}'"
    return None


def test_example_robot_data_sweep(capsys):
    """Every URDF of the example-robot-data wheel: those without floating, planar or
    mimic joints load (strict; the ones whose published inertias are not physical load
    with strict=False, which is what it is for) and agree with Pinocchio; the others get
    the one-line "not supported yet" ModelError. ``ur3.urdf`` holds an empty <robot>
    (its xacro expanded to nothing) and is rejected as having no link."""
    robots_dir = example_robot_data_dir()
    if robots_dir is None:
        pytest.skip("example-robot-data is not installed (pip install example-robot-data)")
    files = sorted(robots_dir.rglob("*.urdf"))
    assert len(files) >= 60
    rng = np.random.default_rng(2024)
    counts = dict.fromkeys(
        ["agree", "agree (non-physical, strict=False)", "rejected as unsupported", "rejected: no robot"], 0
    )
    singular = []  # mass matrix singular: aba not compared
    start = time.perf_counter()
    for path in files:
        name = str(path.relative_to(robots_dir))
        why = unsupported_joint(path)
        if why is not None:
            with pytest.raises(ModelError) as info:
                load_urdf(path)
            assert "not supported yet" in info.value.message, name
            assert info.value.source == str(path) and info.value.element in why, name
            counts["rejected as unsupported"] += 1
            continue
        if name.endswith("ur3.urdf"):
            with pytest.raises(ModelError, match="no <link>"):
                load_urdf(path)
            counts["rejected: no robot"] += 1
            continue
        with warnings.catch_warnings():
            warnings.simplefilter("ignore", MasslessWarning)
            try:
                robot, key = load_urdf(path), "agree"
            except ModelError as err:
                # only physical validity may fail, and strict=False must then load it
                with pytest.warns(UserWarning):
                    robot = load_urdf(path, strict=False)
                key = "agree (non-physical, strict=False)"
                assert err.element and err.element.startswith("link '"), (name, str(err))
        try:
            if not compare_with_pinocchio(robot, pin.buildModelFromUrdf(str(path)), rng, states=1):
                singular.append(name)
        except AssertionError as err:
            raise AssertionError(f"{name}: {err}") from None
        counts[key] += 1
    seconds = time.perf_counter() - start
    with capsys.disabled():
        summary = ", ".join(f"{v} {k}" for k, v in counts.items())
        print(f"\nexample-robot-data: {len(files)} URDFs in {seconds:.1f} s: {summary}")
        print(f"  aba not compared (singular mass matrix): {singular}")
    assert sum(counts.values()) == len(files)
    assert counts["agree"] + counts["agree (non-physical, strict=False)"] >= 50
