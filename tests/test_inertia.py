"""armdyn.inertia against independent second opinions: direct summation over point
clouds, SymPy integration of the defining integral, midpoint-rule integration, the
reduced-mass formula, and the exercise's proofs (parallel axis theorem, rotational
energy invariant under a change of frame)."""

import xml.etree.ElementTree as ET
from pathlib import Path

import numpy as np
import pytest
import sympy as sp

from armdyn import inertia as inr
from armdyn.errors import ModelError
from armdyn.io import ROBOTS_DIR
from armdyn.model import rot_x, rot_y, rot_z, rpy_matrix

RNG = np.random.default_rng(7)

URDF = Path(ROBOTS_DIR) / "iiwa14.urdf"  # the KUKA iiwa 14 (Drake's dynamics numbers), bundled


# ---------------------------------------------------------------- oracles


def S(r):
    """Cross-product matrix, built independently of the code under test."""
    return np.array([[0, -r[2], r[1]], [r[2], 0, -r[0]], [-r[1], r[0], 0]])


def cloud_inertia(masses, points, about):
    """sum m S(r)^T S(r), r from ``about``: the exercise's form of sum m(|r|^2 1 - r r^T)."""
    return sum(m * S(p - about).T @ S(p - about) for m, p in zip(masses, points))


def grid_inertia(weights, points):
    """Vectorised sum w (|p|^2 1 - p p^T) over many points (about the origin)."""
    sq = np.einsum("nk,nk->n", points, points)
    return np.einsum("n,nij->ij", weights, sq[:, None, None] * np.eye(3) - np.einsum("ni,nj->nij", points, points))


def about_com(masses, points):
    """Total mass, centre of mass and inertia about it of a point cloud."""
    c = masses @ points / masses.sum()
    return masses.sum(), c, cloud_inertia(masses, points, c)


def cloud(n=40):
    return RNG.uniform(0.1, 2.0, n), RNG.normal(size=(n, 3)) * [1.0, 0.5, 2.0] + [0.3, -1.0, 0.7]


def random_rotation():
    q, r = np.linalg.qr(RNG.normal(size=(3, 3)))
    q = q * np.sign(np.diag(r))
    return q if np.linalg.det(q) > 0 else -q


def is_zero(m):
    return sp.Matrix(m).applyfunc(sp.simplify) == sp.zeros(*sp.Matrix(m).shape)


# ---------------------------------------------------------- parallel axis


def test_parallel_axis_matches_direct_summation():
    masses, points = cloud()
    M, c, I_C = about_com(masses, points)
    for _ in range(5):
        P, Q = RNG.normal(size=(2, 3)) * 3
        I_P = cloud_inertia(masses, points, P)
        assert np.allclose(inr.parallel_axis(I_C, M, P - c), I_P)
        assert np.allclose(inr.to_com(I_P, M, P - c), I_C)
        assert np.allclose(inr.shift(cloud_inertia(masses, points, Q), M, c, Q, P), I_P)
        assert np.allclose(inr.Body(M, c, I_C).inertia_about(P), I_P)


def test_parallel_axis_proof_symbolic():
    """The exercise's proof: I_P - I_C - M(|d|^2 1 - d d^T) is the cross term
    2(d.s)1 - s d^T - d s^T in the first moment s = sum m r_C, hence 0 about the com."""
    n = 3
    m = sp.symbols(f"m1:{n + 1}", positive=True)
    r = [sp.Matrix(sp.symbols(f"x{i} y{i} z{i}")) for i in range(1, n + 1)]
    d = sp.Matrix(sp.symbols("dx dy dz"))
    M = sum(m)

    def K(v):
        return (v.T * v)[0] * sp.eye(3) - v * v.T

    I_C = sum((mi * K(ri) for mi, ri in zip(m, r)), sp.zeros(3, 3))
    I_P = sum((mi * K(ri - d) for mi, ri in zip(m, r)), sp.zeros(3, 3))  # P = C + d
    delta = (I_P - inr.parallel_axis(I_C, M, d)).expand()
    assert delta != sp.zeros(3, 3)  # without the first-moment condition it is not zero
    s = sum((mi * ri for mi, ri in zip(m, r)), sp.zeros(3, 1))
    cross = -(2 * (d.T * s)[0] * sp.eye(3) - s * d.T - d * s.T)
    assert (delta - cross).expand() == sp.zeros(3, 3)
    # impose sum m r_C = 0 by solving for the last point
    com = {c: sp.solve(s[k], c)[0] for k, c in enumerate(r[-1])}
    assert delta.subs(com).applyfunc(sp.cancel) == sp.zeros(3, 3)


def test_round_trip_is_identity():
    I, m, d = inr.box(2.0, 0.3, 0.4, 0.5), 2.0, RNG.normal(size=3)
    assert np.allclose(inr.to_com(inr.parallel_axis(I, m, d), m, d), I)
    Isym = sp.Matrix(3, 3, lambda i, j: sp.Symbol(f"I{min(i, j)}{max(i, j)}"))
    ms, ds = sp.Symbol("m"), sp.symbols("a b c")
    back = inr.to_com(inr.parallel_axis(Isym, ms, ds), ms, ds)
    assert isinstance(back, sp.MatrixBase) and is_zero(back - Isym)


# ---------------------------------------------------------- change of frame


def test_rotate_matches_rotated_cloud():
    masses, points = cloud()
    R = random_rotation()
    I_B = cloud_inertia(masses, points, np.zeros(3))
    I_A = cloud_inertia(masses, points @ R.T, np.zeros(3))  # v_A = R v_B
    assert np.allclose(inr.rotate(I_B, R), I_A)


def test_rotate_direction_by_hand():
    # B is A turned 90 deg about z: B's x axis is A's y axis, so I_A,yy = I_B,xx
    I_A = inr.rotate(np.diag([1.0, 2.0, 3.0]), np.array(rot_z(sp.pi / 2), dtype=float))
    assert np.allclose(I_A, np.diag([2.0, 1.0, 3.0]))
    I_A = inr.rotate(sp.diag(*sp.symbols("A B C")), rot_z(sp.pi / 2))
    assert I_A == sp.diag(*sp.symbols("B A C"))


def test_rotational_energy_frame_invariant():
    R = random_rotation()
    I, w = inr.box(1.5, 0.2, 0.7, 0.4), RNG.normal(size=3)
    I = inr.rotate(I, random_rotation())  # not diagonal
    assert np.isclose(inr.rotational_energy(inr.rotate(I, R), R @ w), inr.rotational_energy(I, w))
    assert np.isclose(inr.rotational_energy(I, w), 0.5 * w @ I @ w)
    # symbolic: a general symmetric tensor, a symbolic rotation
    Isym = sp.Matrix(3, 3, lambda i, j: sp.Symbol(f"I{min(i, j)}{max(i, j)}"))
    wsym = sp.Matrix(sp.symbols("wx wy wz"))
    angles = sp.symbols("roll pitch yaw")
    Rs = rpy_matrix(*angles)
    E_B = inr.rotational_energy(Isym, wsym)
    E_A = inr.rotational_energy(inr.rotate(Isym, Rs), Rs * wsym)
    pythagoras = {sp.sin(t) ** 2: 1 - sp.cos(t) ** 2 for t in angles}
    assert sp.expand(sp.expand(E_A - E_B).subs(pythagoras)) == 0
    body = inr.Body(sp.Symbol("m"), sp.zeros(3, 1), Isym)
    v = sp.Matrix(sp.symbols("vx vy vz"))
    T = inr.kinetic_energy(body, v, wsym)
    assert sp.expand(T - (sp.Symbol("m") * (v.T * v)[0] + (wsym.T * Isym * wsym)[0]) / 2) == 0


# --------------------------------------------------------------- primitives

m, L, a, b, c, r, ri, h = sp.symbols("m L a b c r r_i h", positive=True)
s, phi, theta, x, y, z = sp.symbols("s phi theta x y z", real=True)


def integrate_tensor(density, pos, *limits):
    """Integral of density (|pos|^2 1 - pos pos^T) over limits (density includes the
    Jacobian)."""
    pos = sp.Matrix(pos)
    K = (pos.T * pos)[0] * sp.eye(3) - pos * pos.T
    return K.applyfunc(lambda e: sp.integrate(sp.expand(density * e), *limits))


@pytest.mark.parametrize(
    "formula, integral",
    [
        (lambda: inr.rod(m, L), lambda: integrate_tensor(m / L, [0, 0, z], (z, -L / 2, L / 2))),
        (
            lambda: inr.box(m, a, b, c),
            lambda: integrate_tensor(
                m / (a * b * c), [x, y, z], (x, -a / 2, a / 2), (y, -b / 2, b / 2), (z, -c / 2, c / 2)
            ),
        ),
        (
            lambda: inr.cylinder(m, r, h, r_inner=ri),
            lambda: integrate_tensor(
                m / (sp.pi * (r**2 - ri**2) * h) * s,
                [s * sp.cos(phi), s * sp.sin(phi), z],
                (s, ri, r),
                (phi, 0, 2 * sp.pi),
                (z, -h / 2, h / 2),
            ),
        ),
        (
            lambda: inr.sphere(m, r),
            lambda: integrate_tensor(
                m / (sp.Rational(4, 3) * sp.pi * r**3) * s**2 * sp.sin(theta),
                [s * sp.sin(theta) * sp.cos(phi), s * sp.sin(theta) * sp.sin(phi), s * sp.cos(theta)],
                (s, 0, r),
                (theta, 0, sp.pi),
                (phi, 0, 2 * sp.pi),
            ),
        ),
        (
            lambda: inr.sphere(m, r, hollow=True),
            lambda: integrate_tensor(
                m / (4 * sp.pi * r**2) * r**2 * sp.sin(theta),
                [r * sp.sin(theta) * sp.cos(phi), r * sp.sin(theta) * sp.sin(phi), r * sp.cos(theta)],
                (theta, 0, sp.pi),
                (phi, 0, 2 * sp.pi),
            ),
        ),
    ],
    ids=["rod", "box", "tube", "sphere", "shell"],
)
def test_primitive_equals_sympy_integral(formula, integral):
    got = formula()
    assert isinstance(got, sp.MatrixBase)
    assert is_zero(got - integral())


def midpoints(lo, hi, n):
    edges = np.linspace(lo, hi, n + 1)
    return (edges[:-1] + edges[1:]) / 2, (hi - lo) / n


def test_box_and_solid_cylinder_against_midpoint_rule():
    # box: uniform grid of equal point masses
    sides, mass = np.array([0.3, 0.5, 0.8]), 3.0
    axes = [midpoints(-l / 2, l / 2, 30)[0] for l in sides]
    pts = np.stack(np.meshgrid(*axes, indexing="ij"), -1).reshape(-1, 3)
    I_grid = grid_inertia(np.full(len(pts), mass / len(pts)), pts)
    assert np.allclose(inr.box(mass, *sides), I_grid, rtol=2e-3, atol=1e-12)
    # cylinder: midpoint rule in (s, phi, z) with weights s ds dphi dz, then axis swapped
    rad, hgt = 0.2, 0.9
    (sv, ds), (pv, dp) = midpoints(0, rad, 40), midpoints(0, 2 * np.pi, 40)
    zv, dz = midpoints(-hgt / 2, hgt / 2, 40)
    S_, P_, Z_ = (g.ravel() for g in np.meshgrid(sv, pv, zv, indexing="ij"))
    w = mass / (np.pi * rad**2 * hgt) * S_ * ds * dp * dz
    along_z = np.stack([S_ * np.cos(P_), S_ * np.sin(P_), Z_], -1)
    for axis, cols in (("z", [0, 1, 2]), ("x", [2, 0, 1]), ("y", [1, 2, 0])):
        p = along_z[:, cols]  # the axial coordinate goes to the chosen axis' column
        assert np.allclose(inr.cylinder(mass, rad, hgt, axis=axis), grid_inertia(w, p), rtol=2e-3, atol=1e-9), axis


def test_axis_argument_is_a_rotation():
    # rot_y(90 deg) takes z to x, rot_x(-90 deg) takes z to y
    for axis, R in (("x", rot_y(sp.pi / 2)), ("y", rot_x(-sp.pi / 2))):
        assert inr.cylinder(m, r, h, axis=axis) == inr.rotate(inr.cylinder(m, r, h), R)
        assert inr.rod(m, L, axis=axis) == inr.rotate(inr.rod(m, L), R)
    assert np.array_equal(inr.point_mass(2.0), np.zeros((3, 3)))
    with pytest.raises(ValueError, match="axis"):
        inr.rod(1.0, 1.0, axis="w")


def test_kind_follows_input():
    assert isinstance(inr.box(1.0, 1, 2, 3), np.ndarray)
    assert isinstance(inr.box(m, 1, 2, 3), sp.MatrixBase)
    assert isinstance(inr.parallel_axis(np.eye(3), 1.0, [1, 2, 3]), np.ndarray)
    assert isinstance(inr.parallel_axis(np.eye(3), 1.0, [a, 2, 3]), sp.MatrixBase)
    assert isinstance(inr.rotational_energy(np.eye(3), [1, 2, 3]), float)


# ----------------------------------------------------------------- combine


def test_two_boxes_side_by_side_are_one_long_box():
    def halves(mb, xb, yb, zb):
        half = inr.box(mb, xb, yb, zb)
        return inr.combine([inr.Body(mb, [-xb / 2, 0, 0], half), inr.Body(mb, [xb / 2, 0, 0], half)])

    whole = halves(1.3, 0.4, 0.2, 0.7)
    assert np.isclose(whole.mass, 2.6) and np.allclose(whole.com, 0)
    assert np.allclose(whole.inertia, inr.box(2.6, 0.8, 0.2, 0.7))
    whole = halves(m, a, b, c)
    assert whole.mass == 2 * m and whole.com == sp.zeros(3, 1)
    assert is_zero(whole.inertia - inr.box(2 * m, 2 * a, b, c))


def test_combine_matches_whole_cloud():
    masses, points = cloud(60)
    parts = []
    for idx in np.array_split(RNG.permutation(60), 3):
        Mi, ci, Ii = about_com(masses[idx], points[idx])
        R = random_rotation()  # describe each part in its own frame B, then bring it back
        local = inr.Body(Mi, R.T @ ci, R.T @ Ii @ R)
        parts.append(local.in_frame(R, np.zeros(3)))
    whole = inr.combine(parts)
    M, c, I_C = about_com(masses, points)
    assert np.isclose(whole.mass, M) and np.allclose(whole.com, c) and np.allclose(whole.inertia, I_C)


def test_combine_rotated_box_and_reduced_mass():
    # a box turned 90 deg about z and moved: its x extent lies along A's y
    box = inr.Body(2.0, np.zeros(3), inr.box(2.0, 0.1, 0.3, 0.5))
    placed = box.in_frame(np.array(rot_z(sp.pi / 2), dtype=float), [1, 2, 3])
    assert np.allclose(placed.com, [1, 2, 3]) and np.allclose(placed.inertia, inr.box(2.0, 0.3, 0.1, 0.5))
    # two point masses l apart: I = m1 m2 / (m1 + m2) l^2 across the line joining them
    m1, m2, l = sp.symbols("m1 m2 l", positive=True)
    dumbbell = inr.combine([inr.Body(m1, [0, 0, 0], sp.zeros(3)), inr.Body(m2, [l, 0, 0], inr.point_mass(m2))])
    mu = m1 * m2 / (m1 + m2)
    assert is_zero(dumbbell.com - sp.Matrix([m2 * l / (m1 + m2), 0, 0]))
    assert is_zero(dumbbell.inertia - sp.diag(0, mu * l**2, mu * l**2))
    massless = inr.combine([inr.Body(0.0, [1, 2, 3], np.zeros((3, 3)))] * 2)
    assert massless.mass == 0 and np.array_equal(massless.com, np.zeros(3))


# ------------------------------------------------------- physical validity


def test_flags_bad_bodies():
    assert inr.physical_violations(-2, np.eye(3)) == ["mass -2 is negative"]
    asym = np.eye(3)
    asym[0, 1] = 0.1
    assert any("not symmetric" in v for v in inr.physical_violations(1, asym))
    assert any("positive semi-definite" in v for v in inr.physical_violations(1, np.diag([-0.1, 1, 1])))
    assert inr.physical_violations(1, np.diag([0.1, 0.1, 0.5])) == [
        "inertia breaks the triangle inequality: Ixx + Iyy < Izz (principal moments 0.1, 0.1, 0.5)"
    ]
    # diagonal entries 1, 1, 1 pass the triangle inequality; the principal moments
    # 0.1, 1, 1.9 do not
    sneaky = np.array([[1, 0, 0], [0, 1, 0.9], [0, 0.9, 1]])
    assert np.all(np.linalg.eigvalsh(sneaky) > 0)
    assert inr.physical_violations(1, sneaky) == [
        "inertia breaks the triangle inequality: I1 + I2 < I3 (principal moments 0.1, 1, 1.9)"
    ]
    assert inr.physical_violations(sp.Integer(-3), sp.diag(1, 1, 3)) == [
        "mass -3 is negative",
        "inertia breaks the triangle inequality: Ixx + Iyy < Izz (principal moments 1, 1, 3)",
    ]


def test_accepts_physical_bodies():
    for _ in range(20):
        mass, (p, q, t) = RNG.uniform(0.1, 5), RNG.uniform(0.01, 2, 3)
        shapes = (
            inr.box(mass, p, q, t),
            inr.box(mass, p, q, 0),
            inr.rod(mass, p),
            inr.point_mass(mass),
            inr.cylinder(mass, p, q, "y", t * p / 2),
            inr.sphere(mass, p),
            inr.sphere(mass, q, hollow=True),
        )
        for I in shapes:
            assert inr.physical_violations(mass, inr.rotate(I, random_rotation())) == []
        masses, points = cloud(RNG.integers(2, 30))
        M, _, I_C = about_com(masses, points)
        assert inr.physical_violations(M, I_C) == []
        M, _, I_C = about_com(masses, points * [1, 1, 0])  # planar: on the triangle inequality's edge
        assert inr.physical_violations(M, I_C) == []
    for link in ET.parse(URDF).getroot().iter("inertial"):
        e = link.find("inertia").attrib
        rows = [["ixx", "ixy", "ixz"], ["ixy", "iyy", "iyz"], ["ixz", "iyz", "izz"]]
        I = np.array([[e[k] for k in row] for row in rows], dtype=float)
        assert inr.physical_violations(float(link.find("mass").get("value")), I) == []


def test_symbolic_tensors_not_flagged():
    Ixx, Iyy, Izz, Ixy = sp.symbols("Ixx Iyy Izz Ixy")
    assert inr.physical_violations(m, sp.diag(Ixx, Iyy, Izz)) == []
    assert inr.physical_violations(m, sp.Matrix([[Ixx, Ixy, 0], [Ixy, Iyy, 0], [0, 0, Izz]])) == []
    assert inr.physical_violations(m, inr.cylinder(m, r, h)) == []


def test_check_physical_raises_or_warns():
    with pytest.raises(ModelError) as err:
        inr.check_physical(-2, np.eye(3), "link 'l2'", "arm.yaml")
    assert str(err.value) == "arm.yaml: link 'l2': mass -2 is negative"
    with pytest.warns(UserWarning, match="triangle inequality"):
        inr.check_physical(1, np.diag([0.1, 0.1, 0.5]), "link 'l2'", strict=False)
    inr.check_physical(1, inr.box(1, 1, 2, 3))  # fine: no error
