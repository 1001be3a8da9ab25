"""A fixed child kept as its own frame, or merged into its parent by the parallel axis
theorem (armdyn.inertia.combine), must give the same dynamics in both engines."""

from __future__ import annotations

import numpy as np
import pytest
import sympy as sp
from random_models import random_robot

import armdyn
from armdyn import inertia
from armdyn.model import Joint, Link, Robot
from armdyn.symbolic import dag, derive


def merge_fixed_joints(robot: Robot) -> Robot:
    """The same robot with every fixed joint's child lumped into its parent link.

    Children of a merged link are re-attached to the parent with their placements
    composed; inertias are combined with inertia.Body.in_frame + inertia.combine."""
    links = {name: link for name, link in robot.links.items()}
    joints = list(robot.joints)
    while any(j.type == "fixed" for j in joints):
        fixed = next(j for j in joints if j.type == "fixed")
        parent, child = links[fixed.parent], links[fixed.child]
        R, p = fixed.transform()
        moved = inertia.Body(child.mass, child.com, child.inertia).in_frame(R, p)
        body = inertia.combine([inertia.Body(parent.mass, parent.com, parent.inertia), moved])
        links[parent.name] = Link(parent.name, body.mass, body.com, body.inertia)
        del links[child.name]
        rewired = []
        for j in joints:
            if j is fixed:
                continue
            if j.parent == child.name:  # placement in the child -> placement in the parent
                j = Joint(j.name, j.type, parent.name, j.child, p + R * j.xyz, R * j.rotation, j.axis)
            rewired.append(j)
        joints = rewired
    return Robot(robot.name + "-merged", links.values(), joints, robot.gravity, robot.parameters)


@pytest.mark.parametrize("seed", range(4))
def test_merged_fixed_joints_same_numeric_dynamics(seed):
    rng = np.random.default_rng(seed)
    robot = random_robot(rng, n_joints=8, tree=bool(seed % 2), kinds="RPFF")
    merged = merge_fixed_joints(robot)
    assert merged.dof == robot.dof and all(j.type != "fixed" for j in merged.joints)
    q, qd, qdd = rng.uniform(-np.pi, np.pi, (3, 20, robot.dof))
    for fn, args in ((armdyn.rnea, (q, qd, qdd)), (armdyn.crba, (q,)), (armdyn.aba, (q, qd, qdd))):
        a, b = fn(robot, *args), fn(merged, *args)
        assert np.allclose(a, b, rtol=1e-11, atol=1e-11 * np.abs(a).max())


def test_merged_fixed_joint_same_symbolic_tau():
    """A symbolic two-link arm with a symbolic tool welded on by a fixed joint."""
    m1, m2, mt, l1, l2, d, g = sp.symbols("m1 m2 mt l1 l2 d g")
    links = [
        Link("base"),
        Link("l1", m1, [l1 / 2, 0, 0], sp.diag(0, m1 * l1**2 / 12, m1 * l1**2 / 12)),
        Link("l2", m2, [l2 / 2, 0, 0], sp.diag(0, m2 * l2**2 / 12, m2 * l2**2 / 12)),
        Link("tool", mt, [0, 0, d], sp.diag(mt * d**2, mt * d**2, 0)),
    ]
    joints = [
        Joint("q1", "revolute", "base", "l1", axis=[0, 1, 0]),
        Joint("q2", "revolute", "l1", "l2", xyz=[l1, 0, 0], axis=[0, 1, 0]),
        Joint("weld", "fixed", "l2", "tool", xyz=[l2, 0, 0], rotation=armdyn.model.rot_y(sp.pi / 2)),
    ]
    robot = Robot("welded", links, joints, [0, 0, -g], [m1, m2, mt, l1, l2, d, g])
    merged = merge_fixed_joints(robot)
    kept, lumped = derive(robot).tau, derive(merged, "lagrange").tau
    rng = np.random.default_rng(0)
    syms = list(robot.q) + list(robot.qd) + list(robot.qdd) + [m1, m2, mt, l1, l2, d, g]
    values = dict(zip(syms, rng.uniform(0.3, 2.0, (len(syms), 10))))
    assert np.allclose(dag.evaluate(kept, values), dag.evaluate(lumped, values), rtol=1e-12, atol=1e-12)
