"""Build a Pinocchio model from an armdyn.Robot, as an independent second opinion.

Mapping (armdyn conventions in armdyn/model.py):

* one Pinocchio joint per movable joint, in ``robot.joints`` order, so Pinocchio's
  ``q``/``v`` are armdyn's coordinates in the same order. A coordinate axis (+x, +y, +z)
  gives JointModelRX/RY/RZ (PX/PY/PZ); any other unit axis gives
  JointModelRevoluteUnaligned / JointModelPrismaticUnaligned.
* a Pinocchio joint frame is armdyn's child link frame; its placement in the parent joint's
  frame is (pose of the parent link in that joint's frame) * SE3(rotation, xyz).
* fixed joints are merged: the child link is rigidly attached to the Pinocchio joint that
  carries its parent link (``appendBodyToJoint``, at the composed placement); links welded to
  the base go to the universe (joint 0).
* every armdyn link gets a BODY frame named after it, so forward kinematics and Jacobians
  can be compared link by link.
"""

from __future__ import annotations

import numpy as np
import pinocchio as pin

from armdyn.model import Robot


def _floats(matrix) -> np.ndarray:
    return np.array([[float(x) for x in row] for row in matrix.tolist()])


#: joints of several coordinates: the same layouts as armdyn's (armdyn.model.joints.MULTI_DOF)
_MULTI_DOF = {"spherical": pin.JointModelSpherical, "planar": pin.JointModelPlanar, "floating": pin.JointModelFreeFlyer}


def _joint_model(kind: str, axis: np.ndarray):
    if kind in _MULTI_DOF:
        return _MULTI_DOF[kind]()
    aligned = {
        "revolute": (pin.JointModelRX, pin.JointModelRY, pin.JointModelRZ),
        "prismatic": (pin.JointModelPX, pin.JointModelPY, pin.JointModelPZ),
    }[kind]
    for i in range(3):
        if np.array_equal(axis, np.eye(3)[i]):
            return aligned[i]()
    if kind == "revolute":
        return pin.JointModelRevoluteUnaligned(axis)
    return pin.JointModelPrismaticUnaligned(axis)


def depth_first(robot: Robot) -> list:
    """``robot.joints`` re-ordered depth first (children in their given order).

    Pinocchio's CRBA (and the algorithms built on it) assume every joint's subtree occupies
    contiguous velocity indices, i.e. a depth-first joint order; armdyn allows any tree order
    (e.g. breadth first), so the bridge permutes the coordinates.
    """
    out = []

    def visit(link):
        for j in robot.children(link):
            out.append(j)
            visit(j.child)

    visit(robot.base)
    return out


def to_pinocchio(robot: Robot) -> tuple[pin.Model, dict[str, int], np.ndarray]:
    """Return ``(model, frames, perm)``: the Pinocchio model; for each armdyn link name, the id
    of the BODY frame placed at that link's frame; and ``perm`` (nv,) such that Pinocchio's
    velocity coordinate i is armdyn's ``perm[i]`` (``v_pin = v[perm]``). The configuration's
    permutation is :func:`configuration_permutation` (the same when every joint has one
    coordinate)."""
    if getattr(robot, "mimic_joints", None):  # the bridge builds free joints only
        raise NotImplementedError(
            f"robot '{robot.name}' has mimic joints: use pin.buildModelFromUrdf(path, mimic=True)"
        )
    model = pin.Model()
    model.name = robot.name
    model.gravity = pin.Motion(_floats(robot.gravity).ravel(), np.zeros(3))
    # where each link sits: (pinocchio joint id, placement of the link frame in that joint's frame)
    where = {robot.base: (0, pin.SE3.Identity())}
    perm = []
    for joint in depth_first(robot):
        parent_id, parent_in_joint = where[joint.parent]
        placement = parent_in_joint * pin.SE3(_floats(joint.rotation), _floats(joint.xyz).ravel())
        # a link frame off its joint's axis (frame_xyz/frame_rotation) sits at that fixed
        # offset in the joint's frame
        offset = pin.SE3(_floats(joint.frame_rotation), _floats(joint.frame_xyz).ravel())
        if joint.movable:
            axis = _floats(joint.axis).ravel()
            jid = model.addJoint(parent_id, _joint_model(joint.type, axis), placement, joint.name)
            where[joint.child] = (jid, offset)
            first = robot.coordinate_index(joint)
            perm.extend(range(first, first + joint.nv))
        else:
            where[joint.child] = (parent_id, placement * offset)
    frames = {}
    for name, link in robot.links.items():
        jid, placement = where[name]
        if name != robot.base:
            inertia = pin.Inertia(float(link.mass), _floats(link.com).ravel(), _floats(link.inertia))
            model.appendBodyToJoint(jid, inertia, placement)
        frames[name] = model.addFrame(pin.Frame(f"link:{name}", jid, placement, pin.FrameType.BODY))
    return model, frames, np.array(perm, dtype=int)


def configuration_permutation(robot: Robot) -> np.ndarray:
    """(nq,) such that Pinocchio's configuration coordinate i is armdyn's ``[i]``, for the
    model :func:`to_pinocchio` builds (joints depth first, each joint's block whole)."""
    first_q = {name: iq for name, _, iq, _ in robot.configuration_layout}
    return np.array(
        [k for j in depth_first(robot) if j.movable for k in range(first_q[j.name], first_q[j.name] + j.nq)]
    )


class PinocchioRobot:
    """Pinocchio's answers for an armdyn.Robot, in armdyn's coordinate order and output
    conventions (full symmetric M, poses in list(robot.links) order, Jacobian rows [v; w]
    in base axes, potential energy including the links welded to the base)."""

    def __init__(self, robot: Robot):
        self.robot = robot
        self.model, self.frames, self.perm = to_pinocchio(robot)
        self.data = self.model.createData()
        self.inv = np.argsort(self.perm)  # armdyn index -> pinocchio index
        self.qperm = configuration_permutation(robot)
        self.welded = welded_potential_energy(robot)

    def _p(self, x):  # armdyn order -> pinocchio order (a configuration by its own permutation)
        x = np.asarray(x, dtype=float)
        return x[self.qperm] if len(x) != len(self.perm) else x[self.perm]

    def _a(self, y):  # pinocchio order -> armdyn order
        return np.asarray(y)[self.inv]

    def _mat(self, A):  # Pinocchio hands back a 1x1 matrix as a vector when n = 1
        n = len(self.perm)
        return np.asarray(A).reshape(n, n)[np.ix_(self.inv, self.inv)]

    def rnea(self, q, qd, qdd):
        return self._a(pin.rnea(self.model, self.data, self._p(q), self._p(qd), self._p(qdd)))

    def crba(self, q):
        M = np.asarray(pin.crba(self.model, self.data, self._p(q))).reshape(len(self.perm), -1)
        return self._mat(np.triu(M) + np.triu(M, 1).T)  # Pinocchio fills the upper triangle

    def aba(self, q, qd, tau):
        return self._a(pin.aba(self.model, self.data, self._p(q), self._p(qd), self._p(tau)))

    def gravity(self, q):
        return self._a(pin.computeGeneralizedGravity(self.model, self.data, self._p(q)))

    def bias(self, q, qd):
        return self._a(pin.nonLinearEffects(self.model, self.data, self._p(q), self._p(qd)))

    def coriolis_matrix(self, q, qd):
        return self._mat(pin.computeCoriolisMatrix(self.model, self.data, self._p(q), self._p(qd)))

    def kinetic_energy(self, q, qd):
        return pin.computeKineticEnergy(self.model, self.data, self._p(q), self._p(qd))

    def potential_energy(self, q):
        return pin.computePotentialEnergy(self.model, self.data, self._p(q)) + self.welded

    def forward_kinematics(self, q):
        pin.framesForwardKinematics(self.model, self.data, self._p(q))
        return np.array([self.data.oMf[self.frames[name]].homogeneous for name in self.robot.links])

    def jacobian(self, q, link: str):
        pin.computeJointJacobians(self.model, self.data, self._p(q))
        pin.updateFramePlacements(self.model, self.data)
        J = pin.getFrameJacobian(self.model, self.data, self.frames[link], pin.LOCAL_WORLD_ALIGNED)
        return np.asarray(J).reshape(6, -1)[:, self.inv]


def welded_potential_energy(robot: Robot) -> float:
    """Potential energy of the base link and the links welded to it (a constant).

    Pinocchio's computePotentialEnergy leaves out the bodies of the universe (joint 0);
    armdyn's potential_energy includes every link. The difference is this constant.
    """
    g = _floats(robot.gravity).ravel()
    pose = {robot.base: (np.eye(3), np.zeros(3))}
    for joint in robot.joints:
        if joint.movable or joint.parent not in pose:
            continue
        R0, p0 = pose[joint.parent]
        pose[joint.child] = (R0 @ _floats(joint.rotation), p0 + R0 @ _floats(joint.xyz).ravel())
    V = 0.0
    for name, (R, p) in pose.items():
        link = robot.links[name]
        V -= float(link.mass) * g @ (p + R @ _floats(link.com).ravel())
    return V
