"""Pinocchio's derivatives, M^-1, Jacobian time variation and external forces for an
armdyn.Robot, in armdyn's coordinate order and conventions (an independent second
opinion for tests/test_derivatives.py and benchmarks/bench_derivatives.py).

External wrenches: armdyn takes one ``[f; n]`` per link (``list(robot.links)`` order),
in the link frame (``"local"``) or about the base origin in base axes (``"world"``);
Pinocchio takes one ``pin.Force`` per joint, in the joint's frame. A link's wrench is
moved to the joint carrying it with the link frame's placement (``SE3.act``), or, for
``"world"``, with the joint's pose at q (``oMi.actInv``). Links welded to the base
(joint 0) are left out: they do not act on the joints.
"""

from __future__ import annotations

import numpy as np
import pinocchio as pin
from pinocchio_bridge import PinocchioRobot


def _sym(A, n):
    A = np.asarray(A).reshape(n, n)
    return np.triu(A) + np.triu(A, 1).T  # Pinocchio fills the upper triangle of M, Minv


class PinocchioDerivatives(PinocchioRobot):
    def fext(self, q, f_ext, frame="local"):
        """armdyn's (nlinks, 6) wrenches as Pinocchio's per-joint forces."""
        W = np.asarray(f_ext, dtype=float)
        out = [pin.Force.Zero() for _ in range(self.model.njoints)]
        if frame == "world":
            pin.forwardKinematics(self.model, self.data, self._p(q))
        for k, name in enumerate(self.robot.links):
            frame_ = self.model.frames[self.frames[name]]
            jid = frame_.parentJoint
            if jid == 0:
                continue
            w = pin.Force(W[k, :3], W[k, 3:])
            if frame == "local":
                out[jid] = out[jid] + frame_.placement.act(w)
            else:
                out[jid] = out[jid] + self.data.oMi[jid].actInv(w)
        return out

    def rnea_ext(self, q, qd, qdd, f_ext, frame="local"):
        fx = self.fext(q, f_ext, frame)
        return self._a(pin.rnea(self.model, self.data, self._p(q), self._p(qd), self._p(qdd), fx))

    def aba_ext(self, q, qd, tau, f_ext, frame="local"):
        fx = self.fext(q, f_ext, frame)
        return self._a(pin.aba(self.model, self.data, self._p(q), self._p(qd), self._p(tau), fx))

    def rnea_derivatives(self, q, qd, qdd, f_ext=None):
        """(dtau_dq, dtau_dqd, M); f_ext in link frames (Pinocchio's fext move with the joints)."""
        args = [self.model, self.data, self._p(q), self._p(qd), self._p(qdd)]
        if f_ext is not None:
            args.append(self.fext(q, f_ext, "local"))
        dq, dv, da = pin.computeRNEADerivatives(*args)
        n = len(self.perm)
        return self._mat(dq), self._mat(dv), self._mat(_sym(da, n))

    def aba_derivatives(self, q, qd, tau, f_ext=None):
        args = [self.model, self.data, self._p(q), self._p(qd), self._p(tau)]
        if f_ext is not None:
            args.append(self.fext(q, f_ext, "local"))
        dq, dv, dtau = pin.computeABADerivatives(*args)
        n = len(self.perm)
        return self._mat(dq), self._mat(dv), self._mat(_sym(dtau, n))

    def minverse(self, q):
        return self._mat(_sym(pin.computeMinverse(self.model, self.data, self._p(q)), len(self.perm)))

    def gravity_derivatives(self, q):
        return self._mat(pin.computeGeneralizedGravityDerivatives(self.model, self.data, self._p(q)))

    def jacobian_dot(self, q, qd, link):
        pin.computeJointJacobiansTimeVariation(self.model, self.data, self._p(q), self._p(qd))
        pin.updateFramePlacements(self.model, self.data)
        Jd = pin.getFrameJacobianTimeVariation(self.model, self.data, self.frames[link], pin.LOCAL_WORLD_ALIGNED)
        return np.asarray(Jd).reshape(6, -1)[:, self.inv]
