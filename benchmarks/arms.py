"""The arms the benchmarks time: UR5, Franka Emika Panda and KUKA LBR iiwa 14.

Each is an armdyn.Robot built from published numbers, and a Pinocchio model of the same arm
built from that Robot by tests/pinocchio_bridge.py. ``python benchmarks/arms.py`` checks
them: armdyn's reference implementation == Pinocchio on each arm, and the hand-built UR5 and
Panda == the URDFs of the ``example-robot-data`` package loaded by Pinocchio's own URDF
parser (an independent transcription); likewise iiwa14 == its URDF parsed by Pinocchio.

Sources
-------
UR5 (CB3), 6 R.
    Kinematics: Universal Robots, "DH Parameters for calculations of kinematics and
    dynamics" (universal-robots.com support article; also the CB3 user manual, table
    "Denavit-Hartenberg parameters for the UR5 serie 3"): standard DH,
    d1 = 0.089159, a2 = -0.425, a3 = -0.39225, d4 = 0.10915, d5 = 0.09465, d6 = 0.0823,
    alpha = (pi/2, 0, 0, pi/2, -pi/2, 0).
    Inertia: UR publishes masses and centres of mass but no inertia tensors for the CB3 UR5,
    so the complete inertial set of ROS-Industrial's ur_description (ur5.urdf.xacro, as
    shipped in example-robot-data 6.0.0, ur5_robot.urdf: masses 3.7, 8.393, 2.275, 1.219,
    1.219, 0.1879 kg, cylinder-approximated tensors) is used, re-expressed in the DH frames
    (its link frames differ from DH frames by axis permutations and offsets along the link).
Franka Emika Panda, 7 R + hand.
    Kinematics: Franka Control Interface documentation, "Robot and interface
    specifications" (frankaemika.github.io/docs/control_parameters.html): modified (Craig)
    DH, d1 = 0.333, d3 = 0.316, a4 = 0.0825, a5 = -0.0825, d5 = 0.384, a7 = 0.088,
    flange d = 0.107, alpha = (0, -pi/2, pi/2, pi/2, -pi/2, pi/2, pi/2).
    Inertia: the commonly used identified set of C. Gaz, M. Cognetti, A. Oliva, P. Robuffo
    Giordano, A. De Luca, "Dynamic identification of the Franka Emika Panda robot with
    retrieval of feasible parameters using penalty-based optimization", IEEE RA-L 4(4),
    2019, as in franka_description's panda.urdf (example-robot-data 6.0.0); the link frames
    there ARE the Craig frames. The hand (0.73 kg) and two fingers (0.015 kg each, closed)
    are rigidly attached (fixed joints), as Pinocchio's reduced model with the fingers locked.
KUKA LBR iiwa 14, 7 R.
    shared/data/iiwa14_dynamics_only.urdf (the bundled iiwa14.urdf holds the same numbers; transcribed from Drake's
    iiwa14_no_collision.urdf, BSD-3-Clause), read by the tiny loader below (joint origins,
    axes and inertials only; the project's URDF reader is not used here on purpose).
"""

from __future__ import annotations

import os
import sys
import xml.etree.ElementTree as ET

import numpy as np

from armdyn.io import ROBOTS_DIR
from armdyn.model import Joint, Link, Robot

HERE = os.path.dirname(os.path.abspath(__file__))
sys.path.insert(0, os.path.join(HERE, "..", "tests"))
from pinocchio_bridge import PinocchioRobot  # noqa: E402

# shared/data/iiwa14_dynamics_only.urdf beside the repository; the bundled copy otherwise
_SHARED = os.path.join(HERE, "..", "..", "shared", "data", "iiwa14_dynamics_only.urdf")
IIWA_URDF = _SHARED if os.path.exists(_SHARED) else os.path.join(ROBOTS_DIR, "iiwa14.urdf")


# --------------------------------------------------------------------------- small helpers


def _rx(a):
    c, s = np.cos(a), np.sin(a)
    return np.array([[1, 0, 0], [0, c, -s], [0, s, c]])


def _rz(a):
    c, s = np.cos(a), np.sin(a)
    return np.array([[c, -s, 0], [s, c, 0], [0, 0, 1]])


def _rpy(r, p, y):
    """URDF roll-pitch-yaw, Rz(y) Ry(p) Rx(r)."""
    cp, sp_ = np.cos(p), np.sin(p)
    ry = np.array([[cp, 0, sp_], [0, 1, 0], [-sp_, 0, cp]])
    return _rz(y) @ ry @ _rx(r)


def _link(name, mass, com, inertia, R=np.eye(3), p=np.zeros(3)) -> Link:
    """A Link whose inertial data (com, tensor about com) is given in a frame F; (R, p) is
    F's pose in the link frame: com_link = p + R com, I_link = R I R^T."""
    inertia = np.asarray(inertia, dtype=float)
    if inertia.shape == (3,):
        inertia = np.diag(inertia)
    I_link = R @ inertia @ R.T
    return Link(name, mass, (p + R @ np.asarray(com, dtype=float)).tolist(), (0.5 * (I_link + I_link.T)).tolist())


# --------------------------------------------------------------------------- tiny URDF loader


def urdf_robot(path: str) -> Robot:
    """Joints (revolute/continuous/prismatic/fixed: origin, axis) and inertials of a URDF."""
    root = ET.parse(path).getroot()

    def origin(elem):
        o = elem.find("origin")
        xyz = np.array([float(x) for x in (o.get("xyz", "0 0 0") if o is not None else "0 0 0").split()])
        rpy = [float(x) for x in (o.get("rpy", "0 0 0") if o is not None else "0 0 0").split()]
        return xyz, _rpy(*rpy)

    links = []
    for elem in root.findall("link"):
        inertial = elem.find("inertial")
        if inertial is None:
            links.append(Link(elem.get("name")))
            continue
        p, R = origin(inertial)
        i = {k: float(v) for k, v in inertial.find("inertia").attrib.items()}
        tensor = np.array(
            [[i["ixx"], i["ixy"], i["ixz"]], [i["ixy"], i["iyy"], i["iyz"]], [i["ixz"], i["iyz"], i["izz"]]]
        )
        links.append(_link(elem.get("name"), float(inertial.find("mass").get("value")), np.zeros(3), tensor, R, p))
    joints = []
    for elem in root.findall("joint"):
        kind = {"continuous": "revolute"}.get(elem.get("type"), elem.get("type"))
        xyz, R = origin(elem)
        axis = elem.find("axis")
        axis = [float(x) for x in axis.get("xyz").split()] if axis is not None else [1.0, 0.0, 0.0]
        joints.append(
            Joint(
                elem.get("name"),
                kind,
                elem.find("parent").get("link"),
                elem.find("child").get("link"),
                xyz=xyz.tolist(),
                rotation=R.tolist(),
                axis=axis,
            )
        )
    return Robot(root.get("name"), links, joints)


# --------------------------------------------------------------------------- DH tables


def standard_dh_robot(name, rows, inertials, base_link=None) -> Robot:
    """Revolute arm from a standard DH table (Spong/Corke), ``A_i = Rz(q_i) Tz(d_i) Tx(a_i) Rx(alpha_i)``.

    rows: (d, a, alpha) per joint. inertials: (mass, com, inertia) per link in DH frame i.
    armdyn's link frame i is DH frame i-1 moved by ``Rz(q_i) Tz(d_i)`` (the motion comes
    last in armdyn), so DH frame i = link frame i * Tx(a_i) Rx(alpha_i): that transform
    starts joint i+1's placement, moves link i's inertial data, and ends in a fixed joint to
    the massless link ``tool0`` (DH frame n).
    """
    links = [base_link or Link("base")]
    joints = []
    prev = (np.zeros(3), np.eye(3))  # Tx(a_{i-1}) Rx(alpha_{i-1}) as (p, R)
    for i, ((d, a, alpha), (m, com, inertia)) in enumerate(zip(rows, inertials), start=1):
        p, R = prev
        joints.append(
            Joint(
                f"joint{i}",
                "revolute",
                links[-1].name,
                f"link{i}",
                xyz=(p + R @ [0, 0, d]).tolist(),
                rotation=R.tolist(),
            )
        )
        prev = (np.array([a, 0.0, 0.0]), _rx(alpha))
        links.append(_link(f"link{i}", m, com, inertia, prev[1], prev[0]))
    joints.append(Joint("tool0", "fixed", links[-1].name, "tool0", xyz=prev[0].tolist(), rotation=prev[1].tolist()))
    links.append(Link("tool0"))
    return Robot(name, links, joints)


def modified_dh_robot(name, rows, inertials, base_link=None) -> Robot:
    """Revolute arm from a modified (Craig) DH table, ``T_i = Rx(alpha_{i-1}) Tx(a_{i-1}) Rz(q_i) Tz(d_i)``.

    rows: (a_{i-1}, d_i, alpha_{i-1}) per joint; armdyn's link frame i IS Craig's frame i
    (Tz(d_i) commutes with Rz(q_i)), so inertials (mass, com, inertia) in frame i are used as
    they are.
    """
    links = [base_link or Link("base")]
    joints = []
    for i, ((a, d, alpha), (m, com, inertia)) in enumerate(zip(rows, inertials), start=1):
        R = _rx(alpha)
        joints.append(
            Joint(
                f"joint{i}",
                "revolute",
                links[-1].name,
                f"link{i}",
                xyz=(np.array([a, 0, 0]) + R @ [0, 0, d]).tolist(),
                rotation=R.tolist(),
            )
        )
        links.append(_link(f"link{i}", m, com, inertia))
    return Robot(name, links, joints)


# --------------------------------------------------------------------------- the arms

PI = np.pi

# UR5: (d, a, alpha) standard DH, Universal Robots.
UR5_DH = [
    (0.089159, 0.0, PI / 2),
    (0.0, -0.425, 0.0),
    (0.0, -0.39225, 0.0),
    (0.10915, 0.0, PI / 2),
    (0.09465, 0.0, -PI / 2),
    (0.0823, 0.0, 0.0),
]
# ur_description inertials (mass, com, principal moments) re-expressed in DH frame i
# (the cylinder tensors are diagonal in both frames; axes permuted).
UR5_INERTIA = [
    (3.7, [0.0, 0.0, 0.0], [0.010267495893, 0.00666, 0.010267495893]),
    (8.393, [0.145, 0.0, 0.13585], [0.0151074, 0.22689067591, 0.22689067591]),
    (2.275, [0.14225, 0.0, 0.01615], [0.004095, 0.049443313556, 0.049443313556]),
    (1.219, [0.0, -0.093, 0.0], [0.111172755531, 0.111172755531, 0.21942]),
    (1.219, [0.0, 0.09465, 0.0], [0.111172755531, 0.21942, 0.111172755531]),
    (0.1879, [0.0, 0.0, -0.0823], [0.0171364731454, 0.033822, 0.0171364731454]),
]


def ur5() -> Robot:
    return standard_dh_robot("ur5", UR5_DH, UR5_INERTIA)


# Panda: (a_{i-1}, d_i, alpha_{i-1}) modified DH, Franka Emika.
PANDA_DH = [
    (0.0, 0.333, 0.0),
    (0.0, 0.0, -PI / 2),
    (0.0, 0.316, PI / 2),
    (0.0825, 0.0, PI / 2),
    (-0.0825, 0.384, -PI / 2),
    (0.0, 0.0, PI / 2),
    (0.088, 0.0, PI / 2),
]
PANDA_FLANGE_D = 0.107


def _tensor(ixx, ixy, ixz, iyy, iyz, izz):
    return [[ixx, ixy, ixz], [ixy, iyy, iyz], [ixz, iyz, izz]]


# Gaz et al. 2019 (franka_description): mass, com, inertia about com, in Craig frame i.
PANDA_INERTIA = [
    (4.970684, [0.003875, 0.002081, -0.04762], _tensor(0.70337, -0.000139, 0.006772, 0.70661, 0.019169, 0.009117)),
    (0.646926, [-0.003141, -0.02872, 0.003495], _tensor(0.007962, -0.003925, 0.010254, 0.02811, 0.000704, 0.025995)),
    (3.228604, [0.027518, 0.039252, -0.066502], _tensor(0.037242, -0.004761, -0.011396, 0.036155, -0.012805, 0.01083)),
    (3.587895, [-0.05317, 0.104419, 0.027454], _tensor(0.025853, 0.007796, -0.001332, 0.019552, 0.008641, 0.028323)),
    (1.225946, [-0.011953, 0.041065, -0.038437], _tensor(0.035549, -0.002117, -0.004037, 0.029474, 0.000229, 0.008627)),
    (1.666555, [0.060149, -0.014117, -0.010517], _tensor(0.001964, 0.000109, -0.001158, 0.004354, 0.000341, 0.005433)),
    (0.735522, [0.010517, -0.004252, 0.061597], _tensor(0.012516, -0.000428, -0.001196, 0.010027, -0.000741, 0.004815)),
]


def panda() -> Robot:
    """7-dof Panda with its hand and closed fingers rigidly attached."""
    arm = modified_dh_robot("panda", PANDA_DH, PANDA_INERTIA)
    finger = (0.015, [0.0, 0.0, 0.0], [2.375e-06, 2.375e-06, 7.5e-07])
    links = list(arm.links.values()) + [
        Link("flange"),
        _link("hand", 0.73, [-0.01, 0.0, 0.03], [0.001, 0.0025, 0.0017]),
        _link("leftfinger", *finger),
        _link("rightfinger", *finger),
    ]
    joints = arm.joints + [
        Joint("flange", "fixed", "link7", "flange", xyz=[0, 0, PANDA_FLANGE_D]),
        Joint("hand", "fixed", "flange", "hand", rotation=_rz(-PI / 4).tolist()),
        Joint("leftfinger", "fixed", "hand", "leftfinger", xyz=[0, 0, 0.0584]),
        Joint("rightfinger", "fixed", "hand", "rightfinger", xyz=[0, 0, 0.0584]),
    ]
    return Robot("panda", links, joints)


def iiwa14() -> Robot:
    return urdf_robot(IIWA_URDF)


ARMS = {"ur5": ur5, "panda": panda, "iiwa14": iiwa14}


# --------------------------------------------------------------------------- checks


def assert_agree(robot: Robot, pinocchio: PinocchioRobot, f, rng=None, states=5, rtol=1e-12) -> None:
    """Raise AssertionError unless ``f`` (a module with rnea, crba, aba: armdyn.numeric or
    armdyn.reference) agrees with Pinocchio on ``robot`` at random states."""
    rng = rng or np.random.default_rng(0)
    for _ in range(states):
        q, qd, qdd = (rng.uniform(-np.pi, np.pi, robot.dof) for _ in range(3))
        for name, mine, theirs in (
            ("rnea", f.rnea(robot, q, qd, qdd), pinocchio.rnea(q, qd, qdd)),
            ("crba", f.crba(robot, q), pinocchio.crba(q)),
            ("aba", f.aba(robot, q, qd, qdd), pinocchio.aba(q, qd, qdd)),
        ):
            err = np.max(np.abs(mine - theirs)) / np.max(np.abs(theirs))
            assert err <= rtol, f"{robot.name}: {f.__name__}.{name} differs from Pinocchio by {err:.1e}"


def _example_robot_data_urdf(relative: str) -> str:
    import pinocchio  # the cmeel prefix holding example-robot-data sits next to Pinocchio's

    prefix = os.path.abspath(os.path.join(os.path.dirname(pinocchio.__file__), "..", "..", "..", ".."))
    path = os.path.join(prefix, "share", "example-robot-data", "robots", relative)
    if not os.path.exists(path):
        raise FileNotFoundError(f"{path} (pip install example-robot-data)")
    return path


def check_urdfs(rtol=1e-9) -> dict:
    """Compare the hand-built arms with URDFs parsed by Pinocchio's own parser: UR5 and Panda
    with example-robot-data's, iiwa14 with the same file our tiny loader read. M, rnea and
    the tool position at random states; returns the max relative (pose: absolute, m) errors.

    The UR5's DH base frame is ur_description's base_link turned by pi about z (gravity is
    along z in both, so M and tau do not see it). The Panda's finger joints are locked at 0
    (pin.buildReducedModel), as in panda() where they are fixed.
    """
    import pinocchio as pin

    out = {}
    rng = np.random.default_rng(1)
    ur_model = pin.buildModelFromUrdf(_example_robot_data_urdf("ur_description/urdf/ur5_robot.urdf"))
    pd_full = pin.buildModelFromUrdf(_example_robot_data_urdf("panda_description/urdf/panda.urdf"))
    fingers = [pd_full.getJointId(n) for n in ("panda_finger_joint1", "panda_finger_joint2")]
    pd_model = pin.buildReducedModel(pd_full, fingers, pin.neutral(pd_full))
    iiwa_model = pin.buildModelFromUrdf(IIWA_URDF)
    cases = (  # robot, their model, our link, their frame at the same point, their base in ours
        (ur5(), ur_model, "tool0", "ee_link", pin.SE3(_rz(PI), np.zeros(3)).inverse()),
        (panda(), pd_model, "flange", "panda_link8", pin.SE3.Identity()),
        (iiwa14(), iiwa_model, "iiwa_link_ee", "iiwa_link_ee", pin.SE3.Identity()),
    )
    for robot, model, link, frame, base in cases:
        data = model.createData()
        mine = PinocchioRobot(robot)
        err = {"M": 0.0, "tau": 0.0, "tool position": 0.0}
        for _ in range(5):
            q, v, a = (rng.uniform(-np.pi, np.pi, robot.dof) for _ in range(3))
            M = pin.crba(model, data, q)
            M = np.triu(M) + np.triu(M, 1).T
            err["M"] = max(err["M"], np.max(np.abs(mine.crba(q) - M)) / np.max(np.abs(M)))
            tau = pin.rnea(model, data, q, v, a)
            err["tau"] = max(err["tau"], np.max(np.abs(mine.rnea(q, v, a) - tau)) / np.max(np.abs(tau)))
            pin.framesForwardKinematics(model, data, q)
            theirs = (base * data.oMf[model.getFrameId(frame)]).translation
            ours = mine.forward_kinematics(q)[list(robot.links).index(link)][:3, 3]
            err["tool position"] = max(err["tool position"], np.max(np.abs(ours - theirs)))
        out[robot.name] = err
        assert max(err.values()) <= rtol, f"{robot.name} differs from the URDF: {err}"
    return out


if __name__ == "__main__":
    from armdyn import reference

    for name, build in ARMS.items():
        robot = build()
        assert_agree(robot, PinocchioRobot(robot), reference)
        print(f"{name}: {robot!r}: armdyn.reference == Pinocchio (rnea, crba, aba) to 1e-12")
    for name, err in check_urdfs().items():
        print(f"{name} vs the URDF parsed by Pinocchio: " + ", ".join(f"{k} {v:.1e}" for k, v in err.items()))
