"""A rigid body made of point masses, with the points, constant vectors and rotations a
proof names: one *instance* on which both sides of a proof line are evaluated exactly.

A body is ``N`` point masses ``m_k > 0`` at positions ``p_k`` (world frame, (3, 1)). The
per-element vectors of a proof are differences: ``r_X`` of element ``k`` is
``p_k - X`` with ``X`` a named point (``r`` alone: ``X = O``). Point ``C`` is the mass
center, ``sum_k m_k p_k / M`` (``centered=True``), or an arbitrary point
(``centered=False``: the instance on which a line that relies on "C is the mass center"
fails, so the verdict can name that fact). Other points (``O``, ``P``, link ``i``'s
reference point), constant vectors (``d``, ``omega``...) and rotations (``R^c``) are drawn
the first time a proof names them.

Random instances (:func:`random_instance`) draw integers from a range of ``2^32`` values
and rotations by the Cayley transform of a rational skew matrix,
``R = ((1 - |a|^2) I + 2 a a^T + 2 [a]x) / (1 + |a|^2)``, exactly orthogonal with
``det R = 1``. Small instances (:func:`small_instances`) are what a counterexample shows:
two or three unit-ish masses at small integer points (mass center at integer
coordinates), small integer vectors, 90 degree rotations about a coordinate axis.
"""

from __future__ import annotations

import random
from fractions import Fraction

from .matrices import Mat

#: random integers are drawn from [-SPAN, SPAN] (masses from [1, SPAN])
SPAN = 2**31
#: point masses in a random body (four points in general position span every inertia tensor)
POINTS = 4

_QUARTER_TURNS = {
    "x": ((1, 0, 0), (0, 0, -1), (0, 1, 0)),
    "y": ((0, 0, 1), (0, 1, 0), (-1, 0, 0)),
    "z": ((0, -1, 0), (1, 0, 0), (0, 0, 1)),
}


def cayley(a) -> Mat:
    """The rotation ``((1 - |a|^2) I + 2 a a^T + 2 [a]x) / (1 + |a|^2)`` of a rational 3-vector."""
    x, y, z = (Fraction(v) for v in a)
    n = x * x + y * y + z * z
    s = 1 + n
    m = [[(1 - n) * (i == j) + 2 * u * v for j, v in enumerate((x, y, z))] for i, u in enumerate((x, y, z))]
    skew = [[0, -z, y], [z, 0, -x], [-y, x, 0]]
    return Mat.rows([[(m[i][j] + 2 * skew[i][j]) / s for j in range(3)] for i in range(3)])


class Instance:
    """One body with its named points, vectors and rotations (drawn on first use).

    masses:    list of N positive Fractions
    positions: list of N (3, 1) Mats, world frame
    centered:  point C is the mass center (else an arbitrary point)
    """

    def __init__(
        self, masses, positions, rng: random.Random, small: bool, centered: bool = True, rotation_axis: str = "z"
    ):
        self.masses = [Fraction(m) for m in masses]
        self.positions = [p if isinstance(p, Mat) else Mat.col(p) for p in positions]
        self.rng = rng
        self.small = small
        self.centered = centered
        self.rotation_axis = rotation_axis
        self.points: dict[str, Mat] = {}
        self.vectors: dict[str, Mat] = {}
        self.rotations: dict[str, Mat] = {}
        self.rotation_text: dict[str, str] = {}
        self.cache: dict = {}
        self.placed: dict = {}  # (kind, name) -> fn(instance) -> Mat: what the proof's prose fixed
        total = sum(self.masses, Fraction(0))
        self.mass = total
        center = [sum((m * p.v[i] for m, p in zip(self.masses, self.positions)), Fraction(0)) / total for i in range(3)]
        self.points["C"] = Mat.col(center) if centered else self._draw_vector()

    def __len__(self) -> int:
        return len(self.masses)

    def _int(self) -> int:
        return self.rng.choice((-1, 0, 1, 2)) if self.small else self.rng.randint(-SPAN, SPAN)

    def _draw_vector(self) -> Mat:
        while True:
            v = Mat.col([self._int() for _ in range(3)])
            if any(v.v):
                return v

    def point(self, name: str) -> Mat:
        if name not in self.points and ("point", name) in self.placed:
            self.points[name] = self.placed["point", name](self)
        if name not in self.points:
            at_origin = self.small and (name == "O" or name.startswith("ref:"))  # simpler by hand
            self.points[name] = Mat.col([0, 0, 0]) if at_origin else self._draw_vector()
        return self.points[name]

    def vector(self, name: str) -> Mat:
        if name not in self.vectors and ("vector", name) in self.placed:
            self.vectors[name] = self.placed["vector", name](self)
        if name not in self.vectors:
            self.vectors[name] = self._draw_vector()
        return self.vectors[name]

    def scalar(self, name: str) -> Mat:
        """A scalar the proof names (a coordinate ``a``, a worked example's ``l``), drawn on use."""
        if name not in self.vectors:
            self.vectors[name] = Mat.scalar(self._int() or 1)
        return self.vectors[name]

    def rotation(self, label: str) -> Mat:
        if label not in self.rotations:
            if self.small:
                axes = "zxy"
                axis = axes[(axes.index(self.rotation_axis) + len(self.rotations)) % 3]
                self.rotations[label] = Mat.rows(_QUARTER_TURNS[axis])
                self.rotation_text[label] = f"90 degrees about {axis}"
            else:
                self.rotations[label] = cayley([self.rng.randint(-SPAN, SPAN) for _ in range(3)])
        return self.rotations[label]

    def element(self, k: int, point: str) -> Mat:
        """Element k's position relative to a named point, (3, 1)."""
        return self.positions[k] - self.point(point)

    def describe(self) -> dict:
        """The instance as plain data (strings for fractions) for a report or a test."""
        return {
            "masses": [str(m) for m in self.masses],
            "points": [p.tolist() for p in self.positions],
            "named_points": {k: v.tolist() for k, v in self.points.items()},
            "vectors": {k: v.tolist() for k, v in self.vectors.items()},
            "rotations": {k: v.tolist() for k, v in self.rotations.items()},
            "center_of_mass": "C" if self.centered else "C is NOT the mass center here",
        }


def random_instance(seed: int, centered: bool = True) -> Instance:
    """A body of :data:`POINTS` point masses with integer masses in [1, SPAN] and
    coordinates in [-SPAN, SPAN]; points, vectors and rotations drawn likewise on use."""
    rng = random.Random(seed)
    masses = [rng.randint(1, SPAN) for _ in range(POINTS)]
    positions = [[rng.randint(-SPAN, SPAN) for _ in range(3)] for _ in range(POINTS)]
    return Instance(masses, positions, rng, small=False, centered=centered)


def small_instances(count: int = 200, seed: int = 7):
    """Small bodies for counterexamples, simplest first: 2 then 3 points, masses 1..3,
    coordinates in {-1, 0, 1, 2} with the mass center at integer coordinates."""
    rng = random.Random(seed)
    made = 0
    tries = 0
    while made < count and tries < 50 * count:
        tries += 1
        n = 2 if made < count // 2 else 3
        masses = [rng.choice((1, 1, 2, 3)) for _ in range(n)]
        positions = [[rng.choice((-1, 0, 1, 2)) for _ in range(3)] for _ in range(n)]
        total = sum(masses)
        if any(sum(m * p[i] for m, p in zip(masses, positions)) % total for i in range(3)):
            continue  # a mass center at integer coordinates: easier to check by hand
        if len({tuple(p) for p in positions}) < n:
            continue
        made += 1
        yield Instance(masses, positions, random.Random(rng.random()), small=True, rotation_axis="zxy"[made % 3])
