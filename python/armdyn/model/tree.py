"""The tree of a robot's joints: their order (checked, and Pinocchio's for a floating
robot) and the coordinates mimic joints follow."""

from __future__ import annotations

import sympy as sp

from ..errors import ModelError
from .joints import Joint


def pinocchio_order(base: str, by_parent: dict[str, list[Joint]]) -> list[Joint]:
    """The joints in the order Pinocchio's URDF parser gives a floating robot's
    coordinates: depth first from the base, a link's child joints by name (its URDF
    reader keeps them in a map), so that q and v pass unchanged between the two."""
    ordered: list[Joint] = []
    stack = sorted(by_parent.get(base, []), key=lambda j: j.name, reverse=True)
    while stack:
        j = stack.pop()
        ordered.append(j)
        stack.extend(sorted(by_parent.get(j.child, []), key=lambda b: b.name, reverse=True))
    return ordered


def tree_order(joints: list[Joint], links, base: str, name: str, root_joint) -> list[Joint]:
    """``joints`` checked (unique names, existing links, one parent per link, the base
    nobody's child, all reached from ``base``) and put in tree order: as given when that
    already is one, else breadth first from the base (the given order among siblings);
    a floating robot's (``root_joint``) in Pinocchio's order."""
    names: set[str] = set()
    child_of: dict[str, Joint] = {}
    for j in joints:
        where = f"joint '{j.name}'"
        if j.name in names:
            raise ModelError("duplicate joint name", where)
        names.add(j.name)
        if j.parent not in links:
            raise ModelError(f"parent link '{j.parent}' does not exist", where)
        if j.child not in links:
            raise ModelError(f"child link '{j.child}' does not exist", where)
        if j.child in child_of:
            raise ModelError(f"link '{j.child}' is already the child of joint '{child_of[j.child].name}'", where)
        if j.child == base:
            raise ModelError(f"the base link '{base}' cannot be a child", where)
        child_of[j.child] = j
    # breadth-first from the base keeps the given order among siblings
    ordered, reached = [], {base}
    by_parent: dict[str, list[Joint]] = {}
    for j in joints:
        by_parent.setdefault(j.parent, []).append(j)
    frontier = [base]
    while frontier:
        nxt = []
        for link in frontier:
            for j in by_parent.get(link, []):
                ordered.append(j)
                reached.add(j.child)
                nxt.append(j.child)
        frontier = nxt
    # keep the user's order where it already is a tree order (stable for DH chains)
    if len(ordered) != len(joints):
        placed = {j.name for j in ordered}
        stray = [j.name for j in joints if j.name not in placed]
        raise ModelError(f"joints not connected to the base '{base}' (a cycle?): {stray}", f"robot '{name}'")
    # the given order is a tree order when every joint comes after its parent joint
    # (the joint whose child is its parent link): one dict lookup per joint, O(n)
    if root_joint == "free-flyer":
        return pinocchio_order(base, by_parent)
    position = {j.name: i for i, j in enumerate(joints)}
    if all(b.parent not in child_of or position[child_of[b.parent].name] < position[b.name] for b in joints):
        return list(joints)
    return ordered


def resolve_mimics(joints, movable_joints, mimic_joints, coord_index) -> dict[str, tuple[int, sp.Expr, sp.Expr]]:
    """For every non-fixed joint, ``(k, multiplier, offset)`` with its own coordinate
    ``multiplier * q[k] + offset``; a chain of mimics is composed down to a joint
    with a coordinate. A missing or fixed leader, a leader of another type, and a
    loop are ModelErrors naming the mimic joint."""
    by_name = {j.name: j for j in joints}
    follows: dict[str, tuple[int, sp.Expr, sp.Expr]] = {}
    for j in movable_joints:
        k = coord_index[j.name]
        assert k is not None  # a movable joint has a coordinate of its own
        follows[j.name] = (k, sp.Integer(1), sp.Integer(0))
    for start in mimic_joints:
        chain: list[Joint] = []
        joint, seen = start, {start.name}
        while joint.name not in follows:  # walk up to a resolved joint (memoised: O(n) overall)
            where = f"joint '{joint.name}'"
            mimic = joint.mimic
            assert mimic is not None  # only mimic joints are still unresolved
            leader = by_name.get(mimic.joint)
            if leader is None:
                raise ModelError(f"mimics joint '{mimic.joint}', which does not exist", where)
            if leader.type == "fixed":
                raise ModelError(f"mimics joint '{leader.name}', which is fixed", where)
            if leader.type != joint.type:
                raise ModelError(
                    f"a {joint.type} joint cannot mimic the {leader.type} joint '{leader.name}' "
                    "(a mimic joint must be of its leader's type)",
                    where,
                )
            if leader.name in seen:
                loop = " -> ".join([j.name for j in chain] + [joint.name, leader.name])
                raise ModelError(f"mimic joints form a loop ({loop})", f"joint '{start.name}'")
            chain.append(joint)
            seen.add(leader.name)
            joint = leader
        for j in reversed(chain):  # q_j = m_j q_leader + o_j, q_leader = m q_k + o
            mimic = j.mimic
            assert mimic is not None
            k, m, o = follows[mimic.joint]
            follows[j.name] = (k, mimic.multiplier * m, mimic.multiplier * o + mimic.offset)
    return follows
