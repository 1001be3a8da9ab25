"""The arms an exercise can be about, each as one table of Craig's modified DH rows.

A kind is a chain of joints written in Craig's (modified) Denavit-Hartenberg form, row
``i`` = ``(alpha_{i-1}, a_{i-1}, d_i, theta_i, type)`` with ``alpha_0 = a_0 = 0`` (the
base frame's z is joint 1's axis, so Spong's table of the same arm needs no base
transform), plus where each link's mass sits in Craig's frame ``i`` (its centre of mass)
and which way a rod along the link lies (for its inertia). :mod:`.variants` draws the
numbers and writes the arm in one of three frame conventions.

Kinds (``KINDS``): ``rp`` (the assignment's arm: a turn, then a slide at ``l1`` off the
axis), ``rr`` and ``rrr`` (planar elbow arms), ``pr`` (a slide along z0, then a turn about
an axis across it), ``rrp`` (a spatial Stanford-like arm: base turn, shoulder, telescope).
"""

from __future__ import annotations

from dataclasses import dataclass

import sympy as sp

HALF_PI = sp.pi / 2


@dataclass(frozen=True)
class Row:
    """One joint in Craig's DH form and the link it moves.

    alpha, a:   twist and distance from z_{i-1} to z_i along x_{i-1} (SymPy)
    d, theta:   offset along / about z_i (the joint coordinate adds to d or theta)
    kind:       "revolute" | "prismatic"
    com:        the centre of mass in frame i, as a rod's extent: (start, end) points (3,)
                of the rod in frame i; a point mass sits at ``end``
    length:     the rod's length symbol name (for its inertia m l^2 / 12)
    """

    alpha: object
    a: object
    d: object
    theta: object
    kind: str
    rod: tuple
    length: str


@dataclass(frozen=True)
class Kind:
    """An arm: its rows, which lengths are parameters, the gravity directions that make
    sense (unit vectors in the base frame), and one sentence for the statement."""

    name: str
    rows: tuple
    lengths: tuple
    gravity: tuple
    title: str
    planar: bool


def _s(name):
    return sp.Symbol(name)


def _kinds() -> dict[str, Kind]:
    l1, l2, l3 = _s("l1"), _s("l2"), _s("l3")
    z = sp.Integer(0)
    planar_g = ((0, -1, 0), (-1, 0, 0), (0, 0, -1))
    out = {
        "rp": Kind(
            "rp",
            (
                Row(z, z, z, z, "revolute", ((z, z, z), (l1, z, z)), "l1"),
                # the slide runs along y1 at l1 from the axis: z2 = y1 (alpha_1 = -pi/2)
                Row(-HALF_PI, l1, z, z, "prismatic", ((z, z, -l2), (z, z, z)), "l2"),
            ),
            ("l1", "l2"),
            planar_g,
            "an RP arm: joint 1 turns about the z0 axis; joint 2 slides along a line "
            "perpendicular to link 1, at distance l1 from joint 1's axis",
            True,
        ),
        "rr": Kind(
            "rr",
            (
                Row(z, z, z, z, "revolute", ((z, z, z), (l1, z, z)), "l1"),
                Row(z, l1, z, z, "revolute", ((z, z, z), (l2, z, z)), "l2"),
            ),
            ("l1", "l2"),
            planar_g,
            "a planar RR (elbow) arm: both joints turn about axes parallel to z0",
            True,
        ),
        "rrr": Kind(
            "rrr",
            (
                Row(z, z, z, z, "revolute", ((z, z, z), (l1, z, z)), "l1"),
                Row(z, l1, z, z, "revolute", ((z, z, z), (l2, z, z)), "l2"),
                Row(z, l2, z, z, "revolute", ((z, z, z), (l3, z, z)), "l3"),
            ),
            ("l1", "l2", "l3"),
            planar_g,
            "a planar RRR arm: three joints turning about axes parallel to z0",
            True,
        ),
        "pr": Kind(
            "pr",
            (
                Row(z, z, z, z, "prismatic", ((z, z, -l1), (z, z, z)), "l1"),
                # joint 2 turns about an axis across the slide (alpha_1 = pi/2)
                Row(HALF_PI, z, z, z, "revolute", ((z, z, z), (l2, z, z)), "l2"),
            ),
            ("l1", "l2"),
            ((0, 0, -1), (-1, 0, 0)),
            "a PR arm: joint 1 slides along z0; joint 2 turns about an axis perpendicular to the slide",
            True,
        ),
        "rrp": Kind(
            "rrp",
            (
                Row(z, z, l1, z, "revolute", ((z, z, -l1), (z, z, z)), "l1"),
                Row(-HALF_PI, z, z, z, "revolute", ((z, z, z), (z, z, z)), "l1"),
                Row(HALF_PI, z, z, z, "prismatic", ((z, z, -l3), (z, z, z)), "l3"),
            ),
            ("l1", "l3"),
            ((0, 0, -1),),
            "a spatial RRP arm (Stanford-like): a base turn about the vertical z0 axis, a shoulder turning "
            "about a horizontal axis at height l1, and a telescopic link sliding across the shoulder axis",
            False,
        ),
    }
    return out


KINDS = _kinds()
