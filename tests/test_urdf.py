"""URDF reader (armdyn.io.urdf) against hand-derived values and against Pinocchio's own
URDF parser (pin.buildModelFromUrdf), which shares no code with it.

For each URDF compared: the pose of every link frame at random q (armdyn: products of
Joint.transform; Pinocchio: its BODY frames), each moving body's inertia (armdyn: the
child link plus everything welded to it by fixed joints, combined here with NumPy;
Pinocchio: model.inertias, where its parser merged them), and rnea / crba / aba at random
states (armdyn.reference, and armdyn.numeric once it exists) to 1e-12 relative.
"""

from __future__ import annotations

import time
import warnings
from pathlib import Path

import numpy as np
import pytest
import sympy as sp
from optional import example_robot_data_dir, needs_pinocchio, pin

import armdyn.reference as reference
from armdyn.errors import ModelError
from armdyn.io.urdf import MasslessWarning, load_urdf
from armdyn.show import frame_poses

# shared/ sits beside the repository (CI) or at /work/shared (development machines)
IIWA = (
    next(
        (
            p
            for p in (Path(__file__).resolve().parents[2] / "shared", Path("/work/shared"))
            if (p / "data" / "iiwa14_dynamics_only.urdf").is_file()
        ),
        Path("/work/shared"),
    )
    / "data"
    / "iiwa14_dynamics_only.urdf"
)
BUNDLED_IIWA = Path(__file__).resolve().parent.parent / "python" / "armdyn" / "robots" / "iiwa14.urdf"
RTOL = 1e-12
SINGULAR = 1e12  # condition number of M above which forward dynamics is not compared


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
    A mimic joint (``buildModelFromUrdf(path, mimic=True)``) has no q of its own.
    """
    qp = np.zeros(model.nq)
    perm = np.zeros(model.nv, dtype=int)
    for j in range(1, model.njoints):
        if model.joints[j].shortname() == "JointModelMimic":
            continue
        k = robot.coordinate_index(model.names[j])
        iq, iv = model.idx_qs[j], model.idx_vs[j]
        perm[iv] = k
        if model.joints[j].nq == 2:
            qp[iq : iq + 2] = np.cos(q[k]), np.sin(q[k])
        else:
            qp[iq] = q[k]
    return qp, perm


def random_coordinates(robot, rng) -> np.ndarray:
    return np.array(
        [rng.uniform(-np.pi, np.pi) if j.type == "revolute" else rng.uniform(-0.3, 0.3) for j in robot.movable_joints]
    )


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
            # not Pinocchio's rnea/aba: compared with that closed form added (a mimic
            # joint's own damping is not modelled: its leader's coordinate carries none)
            fr = np.array(
                [
                    float(j.damping or 0) * v + float(j.friction or 0) * np.sign(v)
                    for j, v in zip(robot.movable_joints, qd)
                ]
            )[perm]
            assert close(engine.rnea(robot, q, qd, qdd)[perm] - fr, tau) < rtol, f"{engine.__name__}.rnea"
            M = pin_mass_matrix(model, data, qp)
            assert close(engine.crba(robot, q)[np.ix_(perm, perm)], M) < rtol, f"{engine.__name__}.crba"
            if np.linalg.cond(M) > SINGULAR:
                skipped_aba = True  # a body with no mass or inertia: qdd is not defined
                continue
            # aba is a linear solve: compare the torque it implies (M qdd + h), whose
            # error does not grow with the condition number of M, and qdd itself
            ours = engine.aba(robot, q, qd, tau_ours := engine.rnea(robot, q, qd, qdd))[perm]
            if has_mimic(model):  # Pinocchio 4.1 has no aba with mimic joints: its M and h
                theirs = np.linalg.solve(M, tau_ours[perm] - fr - pin.nonLinearEffects(model, data, qp, qd[perm]))
            else:
                theirs = pin.aba(model, data, qp, qd[perm], tau_ours[perm] - fr)
            implied = pin.rnea(model, data, qp, qd[perm], ours) + fr
            assert close(implied, tau_ours[perm]) < rtol, f"{engine.__name__}.aba (implied torque)"
            # (friction much larger than the rigid torque costs digits in tau - friction)
            digits = max(1.0, np.abs(fr).max(initial=0) / max(np.abs(tau).max(initial=0), 1e-300))
            assert close(ours, theirs) < rtol * max(1.0, np.linalg.cond(M)) * digits, f"{engine.__name__}.aba"
    return not skipped_aba


def pin_mass_matrix(model, data, qp) -> np.ndarray:
    """Pinocchio's joint-space inertia matrix (full, symmetric).

    With mimic joints, Pinocchio 4.1's crba disagrees with its own rnea when a joint with
    a coordinate lies below a mimic joint (tests/test_mimic.py's arm: the fingers below
    the mimicking wrist; ``M e_k != rnea(q, 0, e_k) - rnea(q, 0, 0)``), while its rnea
    agrees with armdyn's three engines. So for a model with mimic joints M is read off
    its rnea, column by column (exact: rnea is affine in the acceleration), and its
    crba is checked against that only where no coordinate sits below a mimic joint
    (every example-robot-data gripper)."""
    M = pin.crba(model, data, qp)
    M = np.triu(M) + np.triu(M, 1).T
    if not has_mimic(model):
        return M
    v = np.zeros(model.nv)
    h = pin.rnea(model, data, qp, v, v)
    M_rnea = np.column_stack([pin.rnea(model, data, qp, v, e) - h for e in np.eye(model.nv)])
    mimic = [model.joints[j].shortname() == "JointModelMimic" for j in range(model.njoints)]

    def below_mimic(j):
        j = model.parents[j]
        while j > 0 and not mimic[j]:
            j = model.parents[j]
        return j > 0

    if not any(below_mimic(j) for j in range(1, model.njoints) if not mimic[j]):
        assert close(M, M_rnea) < RTOL, "Pinocchio's crba == its rnea's M"
    return M_rnea


def has_mimic(model) -> bool:
    """Whether a Pinocchio model has mimic joints."""
    return any(model.joints[j].shortname() == "JointModelMimic" for j in range(1, model.njoints))


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


@needs_pinocchio
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
        (
            ('type="continuous"', 'type="floating"'),
            "joint 'spin'",
            "a floating joint takes no lower, upper, velocity",
        ),
        (
            ('type="continuous"', 'type="planar"'),
            "joint 'spin'",
            "a planar joint takes no lower, upper, velocity",
        ),
        (
            ('<axis xyz="0 0 1"/>', '<axis xyz="0 0 1"/><mimic joint="slide"/>'),
            "joint 'spin'",
            "a revolute joint cannot mimic the prismatic joint 'slide'",
        ),
        (
            ('<axis xyz="0 0 1"/>', '<axis xyz="0 0 1"/><mimic joint="elbow"/>'),
            "joint 'spin'",
            "mimics joint 'elbow', which does not exist",
        ),
        (('<axis xyz="0 0 1"/>', '<axis xyz="0 0 1"/><mimic joint="weld"/>'), "joint 'spin'", "'weld', which is fixed"),
        (('<axis xyz="0 0 1"/>', '<axis xyz="0 0 1"/><mimic joint="spin"/>'), "joint 'spin'", "loop (spin -> spin)"),
        (
            ('<axis xyz="0 0 1"/>', '<axis xyz="0 0 1"/><mimic joint="roll" multiplier="x"/>'),
            "joint 'spin'",
            "<mimic> multiplier is 'x', not a finite number",
        ),
        (('<axis xyz="0 0 1"/>', '<axis xyz="0 0 1"/><mimic/>'), "joint 'spin'", "<mimic> has no 'joint' attribute"),
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


# the exercise's copy beside the repository is compared too when it is there (it is not
# part of the repository, so its absence is not a skip)
@needs_pinocchio
@pytest.mark.parametrize(
    "path", [BUNDLED_IIWA] + ([IIWA] if IIWA.is_file() else []), ids=["bundled", "shared"][: 1 + IIWA.is_file()]
)
def test_iiwa14_agrees_with_pinocchio(path):
    robot = load_urdf(path)
    assert robot.dof == 7 and robot.meta["massless_links"] == ["base", "iiwa_link_ee"]
    compare_with_pinocchio(robot, pin.buildModelFromUrdf(str(path)), np.random.default_rng(7), states=3)


# ------------------------------------------------------------ example-robot-data


def unsupported_joint(path: Path) -> str | None:
    """Why Pinocchio's URDF would be out of scope: a floating/planar joint, read here
    with a plain XML scan (independent of the reader under test)."""
    import xml.etree.ElementTree as ET

    root = ET.parse(path).getroot()
    for j in root.findall("joint"):
        if j.get("type") in ("floating", "planar"):
            return f"{j.get('type')} joint '{j.get('name')}'"
    return None


def xml_mimics(path: Path) -> dict[str, tuple[str, float, float]]:
    """``{mimic joint: (leader, multiplier, offset)}`` of the non-fixed joints with a
    ``<mimic>``, read with a plain XML scan (independent of the reader under test)."""
    import xml.etree.ElementTree as ET

    out = {}
    for j in ET.parse(path).getroot().findall("joint"):
        m = j.find("mimic")
        if m is not None and j.get("type") != "fixed":
            out[j.get("name")] = (m.get("joint"), float(m.get("multiplier", 1)), float(m.get("offset", 0)))
    return out


def compare_reduced_with_pinocchio(robot, path: Path, rng, states: int = 1, rtol: float = RTOL) -> bool:
    """For a URDF whose mimic model Pinocchio cannot build: Pinocchio's model with every
    joint free (``buildModelFromUrdf(path)``), constrained here by the principle of
    virtual work. With the map read from the XML, ``q_full = G q + o`` (one level of
    mimic; ``G`` (nv_full, dof)), armdyn's reduced dynamics must be
    ``tau = G^T rnea_full(q_full, G qd, G qdd)``, ``M = G^T M_full G``, and aba's qdd
    must reproduce its torque through Pinocchio's rnea. Returns False if aba was left out
    because the mass matrix is singular, else True."""
    mimics = xml_mimics(path)
    compared_aba = True
    model = pin.buildModelFromUrdf(str(path))
    data = model.createData()
    G = np.zeros((model.nv, robot.dof))
    follow = []  # (pinocchio joint, armdyn coordinate, multiplier, offset)
    for j in range(1, model.njoints):
        leader, mult, off = mimics.get(model.names[j], (model.names[j], 1.0, 0.0))
        assert leader not in mimics, f"{model.names[j]}: a chain of mimics (not handled here)"
        k = robot.coordinate_index(leader)
        G[model.idx_vs[j], k] = mult
        follow.append((j, k, mult, off))
    for engine in engines():
        for _ in range(states):
            q, qd, qdd = (random_coordinates(robot, rng), rng.uniform(-1, 1, robot.dof), rng.uniform(-1, 1, robot.dof))
            qp = np.zeros(model.nq)
            for j, k, mult, off in follow:
                x, iq = mult * q[k] + off, model.idx_qs[j]
                if model.joints[j].nq == 2:
                    qp[iq : iq + 2] = np.cos(x), np.sin(x)
                else:
                    qp[iq] = x
            # URDF damping/friction of the independent joints enter armdyn's tau, not
            # Pinocchio's rnea: added in closed form (as in check_against_pinocchio)
            fr = np.array(
                [
                    float(j.damping or 0) * v + float(j.friction or 0) * np.sign(v)
                    for j, v in zip(robot.movable_joints, qd)
                ]
            )
            tau = G.T @ pin.rnea(model, data, qp, G @ qd, G @ qdd) + fr
            tau_ours = engine.rnea(robot, q, qd, qdd)
            assert close(tau_ours, tau) < rtol, f"{engine.__name__}.rnea"
            M = pin.crba(model, data, qp)
            M = G.T @ (np.triu(M) + np.triu(M, 1).T) @ G
            assert close(engine.crba(robot, q), M) < rtol, f"{engine.__name__}.crba"
            if np.linalg.cond(M) > SINGULAR:
                compared_aba = False
                continue
            ours = engine.aba(robot, q, qd, tau_ours)
            implied = G.T @ pin.rnea(model, data, qp, G @ qd, G @ ours) + fr
            assert close(implied, tau_ours) < rtol, f"{engine.__name__}.aba (implied torque)"
    return compared_aba


@needs_pinocchio
def test_example_robot_data_sweep(capsys):
    """Every URDF of the example-robot-data wheel loads (strict; the ones whose published
    inertias are not physical load with strict=False, which is what it is for) and
    agrees with Pinocchio; mimic joints included:

    * with Pinocchio's own mimic model (``buildModelFromUrdf(path, mimic=True)``) where
      Pinocchio 4.1 builds it;
    * where it refuses ("the parent joint of the mimic joint is not in the kinematic
      tree": romeo, talos_full_v2), with Pinocchio's unconstrained model reduced by
      virtual work (:func:`compare_reduced_with_pinocchio`);
    * ``alex_psyonic_hands.urdf`` names mimic leaders that do not exist
      (``index_q1`` for ``Left_index_q1``...): a one-line ModelError naming the mimic
      joint and the missing leader (Pinocchio refuses it too).

    ``ur3.urdf`` holds an empty <robot> (its xacro expanded to nothing) and is rejected
    as having no link."""
    robots_dir = example_robot_data_dir()
    files = sorted(robots_dir.rglob("*.urdf"))
    assert len(files) >= 60
    rng = np.random.default_rng(2024)
    counts = dict.fromkeys(
        [
            "agree",
            "agree (non-physical, strict=False)",
            "rejected as unsupported",
            "rejected: mimic leader missing",
            "rejected: no robot",
        ],
        0,
    )
    with_mimic = {
        "Pinocchio mimic model": 0,
        "Pinocchio free model reduced by G": 0,
        "(<mimic> on fixed joints only)": 0,
    }
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
        mimics = xml_mimics(path)
        joints = {j for j in _xml_joint_names(path)}
        missing = {m: leader for m, (leader, _, _) in mimics.items() if leader not in joints}
        if missing:
            with pytest.raises(ModelError) as info, warnings.catch_warnings():
                warnings.simplefilter("ignore", UserWarning)  # its inertias are not physical either
                load_urdf(path, strict=False)
            mimic, leader = next((m, l) for m, l in missing.items() if info.value.element == f"joint '{m}'")
            assert f"'{leader}', which does not exist" in info.value.message and info.value.source == str(path), name
            with pytest.raises(Exception, match="mimic"):  # Pinocchio's view
                pin.buildModelFromUrdf(str(path), mimic=True)
            counts["rejected: mimic leader missing"] += 1
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
        assert len(robot.mimic_joints) == len(mimics), name
        try:
            if mimics:
                try:
                    model = pin.buildModelFromUrdf(str(path), mimic=True)
                except ValueError as err:
                    assert "mimic" in str(err), (name, str(err))
                    if not compare_reduced_with_pinocchio(robot, path, rng):
                        singular.append(name)
                    with_mimic["Pinocchio free model reduced by G"] += 1
                else:
                    assert has_mimic(model), name
                    if not compare_with_pinocchio(robot, model, rng, states=1):
                        singular.append(name)
                    with_mimic["Pinocchio mimic model"] += 1
            elif not compare_with_pinocchio(robot, pin.buildModelFromUrdf(str(path)), rng, states=1):
                singular.append(name)
            if not mimics and "<mimic" in path.read_text():
                with_mimic["(<mimic> on fixed joints only)"] += 1
        except AssertionError as err:
            raise AssertionError(f"{name}: {err}") from None
        counts[key] += 1
    seconds = time.perf_counter() - start
    with capsys.disabled():
        summary = ", ".join(f"{v} {k}" for k, v in counts.items())
        print(f"\nexample-robot-data: {len(files)} URDFs in {seconds:.1f} s: {summary}")
        print(f"  with <mimic>, agreeing: {', '.join(f'{v} {k}' for k, v in with_mimic.items())}")
        print(f"  aba not compared (singular mass matrix): {singular}")
    assert sum(counts.values()) == len(files)
    assert counts["agree"] + counts["agree (non-physical, strict=False)"] >= 62
    assert with_mimic["Pinocchio mimic model"] + with_mimic["Pinocchio free model reduced by G"] >= 8


def _xml_joint_names(path: Path) -> list[str]:
    import xml.etree.ElementTree as ET

    return [j.get("name") for j in ET.parse(path).getroot().findall("joint")]
