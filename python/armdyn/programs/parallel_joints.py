"""Runs of parallel revolute joints: the compound angle ``q2 + q3`` (Khalil and Dombre,
*Modeling, Identification and Control of Robots*, 2002, sec. 9.5, as SYMORO's ``S23,
C23``).

A revolute joint about its child frame's z whose child frame is its parent's turned only
about that same axis (modified DH ``alpha = 0``: ``R = Rz(q)``), behind another revolute
joint about z, continues a *run* of parallel joints: from the link before the run (the
*anchor*) to the joint's child, the rotation is ``R0 Rz(q2 + q3 + ...)`` with ``R0`` the
first joint's constant rotation. Per state this costs one addition (the angle) and its
sine and cosine; it pays when the anchor's vectors are sparse (the first link of an arm
turns about the base's fixed axis: ``w1 = (0, 0, qd1)``):

* outward, the x, y components of the child's angular velocity and its U's last column
  (:func:`armdyn.programs.link_terms.column_from_parent`) come from the anchor's in one
  rotation each (two products instead of four products and two sums on the PUMA 560);
* inward, a link fixed to the base needs only its torque ``z . n``: the moments of the
  run are brought to it directly, ``R2 (N2 + (a2, 0, 0) x R3 f3) + R0 Rz(q2 + q3) (n3 +
  d3 z x f3)`` (the offset ``d3`` along the common axis turns with link 3), so the
  middle links' moments ``n2_x, n2_y`` are never formed (:func:`root_torque`).

Where a run's anchor is not sparse the compound form costs as much as the link-by-link
one plus the angle's addition, so the caller keeps the cheaper (:func:`cheaper`).
"""

from __future__ import annotations

from dataclasses import dataclass

import sympy as sp

from ..model import Robot
from .program import Builder, is_value
from .vectors import ZERO, cross, dot, mtv, mv, rows, turned_about_z, vadd

E3 = sp.Matrix([0, 0, 1])


@dataclass
class Run:
    """The rotation from a run's anchor link to one of its links: ``R0 Rz(angle)``.

    anchor: the link before the run (its first joint's parent); R0 (3x3 rows): the first
    joint's constant rotation (anchor axes); angle: the sum of the run's joint angles up
    to this link; tags: their joint numbers (``"23"``), for the temporaries' names."""

    anchor: str
    R0: list
    angle: sp.Expr
    tags: str

    def rotation(self, b: Builder) -> list:
        """(3x3 rows) the link's frame in the anchor's, with the compound angle's cosine and
        sine named once (``c23, s23``)."""
        angle = b.let(self.angle, f"q{self.tags}")
        return turned_about_z(self.R0, b.let(sp.cos(angle), f"c{self.tags}"), b.let(sp.sin(angle), f"s{self.tags}"))


def about_z(joint) -> bool:
    """The joint's axis is its frame's +z."""
    return all(is_value(joint.axis[i], E3[i]) for i in range(3))


def own_revolute_about_z(robot: Robot, joint) -> bool:
    """A revolute joint about +z with a coordinate of its own (not a mimic)."""
    k = robot.coordinate_index(joint)
    return joint.type == "revolute" and about_z(joint) and k is not None and robot.joint_coordinate(joint) == robot.q[k]


def parallel_runs(robot: Robot, angles: dict) -> dict:
    """``{link: Run}`` for every link that continues a run of parallel revolute joints
    (second joint of the run and after). ``robot``: canonical frames; ``angles``:
    ``{link: its joint angle}`` as the program names it (``q6t = q6 + th6`` for a leaf
    turned about its joint axis, :mod:`armdyn.programs.leaf_frames`)."""
    joint_of = {j.child: j for j in robot.joints}
    start, runs = {}, {}
    for joint in robot.joints:
        if not own_revolute_about_z(robot, joint):
            continue
        angle = angles[joint.child]
        tag = str(robot.coordinate_index(joint) + 1)
        parent = joint_of.get(joint.parent)
        pure = all(is_value(joint.rotation[i, k], i == k) for i in range(3) for k in range(3))
        if pure and parent is not None and joint.parent in start:
            first = start[joint.parent]
            runs[joint.child] = start[joint.child] = Run(first.anchor, first.R0, first.angle + angle, first.tags + tag)
        else:
            start[joint.child] = Run(joint.parent, rows(joint.rotation), angle, tag)
    return runs


def cheaper(compound: list, separate: list) -> bool:
    """True when the compound expressions cost fewer operations than the link-by-link
    ones, counting the compound angle's addition."""

    def cost(exprs):
        return sum(sp.count_ops(e) for e in exprs if e is not None)

    return cost(compound) + 1 < cost(separate)


def compound_angular(Ra, anchor_w, column_run, w_in, column) -> tuple:
    """``(w_in, column, compound)`` of a link continuing a run: the x, y components of
    ``R^T w_parent`` (``w_in`` (3,)) and U's column ``(U13, U23)`` read off the parent
    (``column``, or None) replaced by the anchor's turned by the compound rotation
    ``Ra`` (``anchor_w`` (3,); ``column_run``: that column read off the anchor's U, or
    None) where that is cheaper (:func:`cheaper`; it saves four products and two sums
    on the PUMA 560's link 3), and whether it was."""
    w_run = mtv(Ra, anchor_w)[:2]
    if cheaper([*w_run, *(column_run or ())], [*w_in[:2], *(column or ())]):
        return [*w_run, w_in[2]], column_run, True
    return w_in, column, False


def root_torque(robot: Robot, joint, links: dict, b: Builder):
    """The torque ``z . n`` of a base-fixed link (its joint ``joint``), with the runs of
    parallel joints behind it brought over by their compound rotations: of the moment of
    a link the base carries, only its component on the joint axis is needed (the base does
    not move), so the middle links' moments are not rotated one by one.

    A run link y behind x (``R_y = Rz(q_y)``, offset ``p_y``) adds to ``R_ax n_x``::

        R_ax (p_y' x R_y f_y) + R_ay (n_y + p_yz z x f_y)      (p_y' = (p_yx, p_yy, 0))

    the first with x's own moment (one rotation), the second with y's by the compound
    rotation; the offset along the common axis turns with y (``p_z z x R_y f = R_y (p_z z
    x f)``). Each rotated vector is only ever dotted with the axis: ``z . R v = (R^T z) . v``.

    links: ``{link: state}`` after the inward pass
    (:class:`~armdyn.programs.customized_ne.LinkState`): each link's joint frame ``R``,
    ``p`` (3x3 rows, (3,)), Euler moment ``N``, total force ``f`` and moment ``n`` (its
    axes), ``Rf`` (its force in its parent's axes, as the program named it), and, where
    its outward quantities used the compound form (``compound``), ``Ra`` (3x3 rows, its
    frame in the run's anchor's); b: the program's builder (it names the offsets' lever
    arms)."""

    def brought(x, Rax, extra=(ZERO, ZERO, ZERO)):
        """z . R_ax (n_x + extra) with x's children in a run expanded."""
        u = mtv(Rax, axis)  # R_ax^T z
        kids = [j.child for j in robot.children(x)]
        if not any(links[y].compound for y in kids):
            return dot(u, vadd(links[x].n, extra))
        own, out = vadd(links[x].N, extra), []
        for y in kids:
            ly = links[y]
            R, p = ly.R, ly.p
            if ly.compound:
                # z . R_ax (p' x R_y f_y) = (u x p') . R_y f_y, u x p' named: it is a
                # multiple of a sine or cosine of x's angle that x's offsets may use too
                arm = [b.let(e, f"p{y}_arm") for e in cross(u, [p[0], p[1], ZERO])]
                out.append(dot(arm, ly.Rf))
                out.append(brought(y, ly.Ra, [-p[2] * ly.f[1], p[2] * ly.f[0], ZERO]))
            else:
                own = vadd(own, mv(R, ly.n), cross(p, ly.Rf))
        return sp.Add(dot(u, own), *out)

    axis = list(joint.axis)
    link = joint.child
    total = [dot(axis, links[link].N)]
    for child in robot.children(link):
        c = links[child.child]
        total.append(brought(child.child, c.R))
        if not all(is_value(e, 0) for e in c.p):
            total.append(dot(axis, cross(c.p, c.Rf)))
    return sp.Add(*total)
