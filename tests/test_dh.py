"""DH tables -> armdyn's general frames (armdyn.io.dh), and the bundled DH models.

Second opinions:
* frames: the DH matrix products written out here with NumPy 4x4 matrices
  (A_i = Rz Tz Tx Rx for standard DH, T_i = Rx Tx Rz Tz for Craig's modified DH),
  independent of model.py's rotations and of the converter;
* the standard and the modified table of the same arm give the same poses;
* Craig's PUMA and Corke's PUMA are related by a sign identity derived by hand;
* dynamics: a standard-DH arm and its modified-DH twin have the same tau when the
  inertial data of each link come from the same point masses, summed directly in each
  convention's frame (no tensor rotation formula involved).
"""

from __future__ import annotations

import numpy as np
import pytest
import sympy as sp

import armdyn
from armdyn.io import load
from armdyn.io.dh import from_dh

try:  # armdyn may export it at the top level; the package has it in any case
    derive = armdyn.derive
except AttributeError:
    from armdyn.symbolic import derive


# ------------------------------------------------------------ independent 4x4 matrices
def Rx(a):
    c, s = np.cos(a), np.sin(a)
    return np.array([[1, 0, 0, 0], [0, c, -s, 0], [0, s, c, 0], [0, 0, 0, 1.0]])


def Rz(a):
    c, s = np.cos(a), np.sin(a)
    return np.array([[c, -s, 0, 0], [s, c, 0, 0], [0, 0, 1, 0], [0, 0, 0, 1.0]])


def Tx(x):
    T = np.eye(4)
    T[0, 3] = x
    return T


def Tz(z):
    T = np.eye(4)
    T[2, 3] = z
    return T


def standard_A(a, alpha, d, theta):
    return Rz(theta) @ Tz(d) @ Tx(a) @ Rx(alpha)


def modified_T(alpha, a, d, theta):
    return Rx(alpha) @ Tx(a) @ Rz(theta) @ Tz(d)


def link_poses(robot, q, values=None):
    """Pose (4x4 float) of every link frame in the base frame at joint values q (dof,)."""
    values = {robot.parameters[k]: v for k, v in (values or {}).items()}
    poses = {robot.base: np.eye(4)}
    for joint in robot.joints:
        i = robot.coordinate_index(joint)
        R, p = joint.transform(0 if i is None else sp.Float(q[i]))
        T = np.eye(4)
        T[:3, :3] = np.array(R.xreplace(values).evalf(), dtype=float)
        T[:3, 3] = np.array(p.xreplace(values).evalf(), dtype=float).ravel()
        poses[joint.child] = poses[joint.parent] @ T
    return poses


def random_table(rng, n):
    """n rows: mixed revolute/prismatic, twists exact multiples of pi/2 or arbitrary."""
    rows = []
    for i in range(n):
        alpha = sp.pi / 2 * int(rng.integers(-2, 3)) if rng.random() < 0.5 else sp.Float(rng.uniform(-3, 3))
        rows.append(
            {
                "name": f"j{i + 1}",
                "type": "prismatic" if rng.random() < 0.35 else "revolute",
                "a": sp.Float(rng.uniform(-1, 1)),
                "alpha": alpha,
                "d": sp.Float(rng.uniform(-1, 1)),
                "theta": sp.Float(rng.uniform(-3, 3)),
            }
        )
    return rows


def _f(x):
    return float(sp.sympify(x))


def _row_values(row, x):
    """a, alpha, d, theta of a row with the joint value x added to theta or d."""
    rev = row["type"] == "revolute"
    d = _f(row["d"]) + (0 if rev else x)
    theta = _f(row["theta"]) + (x if rev else 0)
    return _f(row["a"]), _f(row["alpha"]), d, theta


def dh_product(rows, q, link_transform):
    """DH frames 1..n (list of 4x4): the running product of ``link_transform`` per row,
    ``standard_A(a, alpha, d, theta)`` or ``modified_T(alpha, a, d, theta)``."""
    T, out = np.eye(4), []
    for row, x in zip(rows, q):
        a, alpha, d, theta = _row_values(row, x)
        T = T @ link_transform(a=a, alpha=alpha, d=d, theta=theta)
        out.append(T)
    return out


# Corke's mdl_puma560 (standard DH) and Craig's PUMA table (modified DH), typed from
# the publications, symbols for the lengths the model files make parameters.
CORKE = [  # a, alpha, d
    (0, np.pi / 2, 0),
    ("a2", 0, 0),
    ("a3", -np.pi / 2, "d3"),
    (0, np.pi / 2, "d4"),
    (0, -np.pi / 2, 0),
    (0, 0, 0),
]
CRAIG = [  # alpha_{i-1}, a_{i-1}, d_i
    (0, 0, 0),
    (-np.pi / 2, 0, 0),
    (0, "a2", "d3"),
    (-np.pi / 2, "a3", "d4"),
    (np.pi / 2, 0, 0),
    (-np.pi / 2, 0, 0),
]


def _num(x, values):
    return values[x] if isinstance(x, str) else x


@pytest.fixture(scope="module")
def puma():
    return load("puma560")


@pytest.fixture(scope="module")
def craig():
    return load("puma560-craig")


# ------------------------------------------------------------------ kinematics
def test_puma560_frames_are_corke_standard_dh_frames(puma):
    rng = np.random.default_rng(1)
    for _ in range(3):
        values = {k: rng.uniform(0.05, 0.8) for k in ("a2", "a3", "d3", "d4")}
        q = rng.uniform(-np.pi, np.pi, 6)
        poses = link_poses(puma, q, values)
        T = np.eye(4)
        for i, (a, alpha, d) in enumerate(CORKE):
            a, d = _num(a, values), _num(d, values)
            T = T @ standard_A(a, alpha, d, q[i])
            # DH frame i = armdyn link frame i * Tx(a_i) Rx(alpha_i)
            np.testing.assert_allclose(poses[f"link{i + 1}"] @ Tx(a) @ Rx(alpha), T, atol=1e-12)
    assert "flange" not in puma.links  # a6 = alpha6 = 0: DH frame 6 is link frame 6


def test_puma560_craig_frames_are_craig_frames(craig):
    rng = np.random.default_rng(2)
    for _ in range(3):
        values = {k: rng.uniform(0.05, 0.8) for k in ("a2", "a3", "d3", "d4")}
        q = rng.uniform(-np.pi, np.pi, 6)
        poses = link_poses(craig, q, values)
        T = np.eye(4)
        for i, (alpha, a, d) in enumerate(CRAIG):
            T = T @ modified_T(alpha, _num(a, values), _num(d, values), q[i])
            np.testing.assert_allclose(poses[f"link{i + 1}"], T, atol=1e-12)


def test_craig_and_corke_puma_are_related_by_the_sign_identity(puma, craig):
    """By hand: Rx(-pi/2) = Rx(pi/2) Rx(pi), and pushing Rx(pi) = diag(1, -1, -1) to the
    end flips every later Rz(q) and Tz(d) (it commutes with Rx and Tx). Hence
    T_craig(q; a2, a3, d3, d4) = T_corke(q1, -q2..-q6; a2, a3, -d3, -d4) Rx(pi)."""
    rng = np.random.default_rng(3)
    for _ in range(3):
        v = {k: rng.uniform(0.05, 0.8) for k in ("a2", "a3", "d3", "d4")}
        q = rng.uniform(-np.pi, np.pi, 6)
        flipped = np.concatenate([q[:1], -q[1:]])
        lhs = link_poses(craig, q, v)["link6"]
        rhs = link_poses(puma, flipped, {**v, "d3": -v["d3"], "d4": -v["d4"]})["link6"] @ Rx(np.pi)
        np.testing.assert_allclose(lhs, rhs, atol=1e-12)


@pytest.mark.parametrize("convention", ["standard", "modified"])
@pytest.mark.parametrize("seed", range(4))
def test_random_tables_match_the_dh_products(convention, seed):
    rng = np.random.default_rng(seed)
    rows = random_table(rng, 5)
    robot = from_dh("random", rows, convention, strict=False)
    assert [j.type for j in robot.movable_joints] == [r["type"] for r in rows]
    q = rng.uniform(-2, 2, 5)
    poses = link_poses(robot, q)
    if convention == "standard":
        frames = dh_product(rows, q, standard_A)
        for i, row in enumerate(rows):
            dh_frame = poses[f"link{i + 1}"] @ Tx(_f(row["a"])) @ Rx(_f(row["alpha"]))
            np.testing.assert_allclose(dh_frame, frames[i], atol=1e-12)
        # the last row's Tx(a_n) Rx(alpha_n) is the fixed flange: DH frame n
        np.testing.assert_allclose(poses["flange"], frames[-1], atol=1e-12)
        assert robot.joints[-1].type == "fixed" and robot.dof == 5
    else:
        frames = dh_product(rows, q, modified_T)
        for i in range(5):
            np.testing.assert_allclose(poses[f"link{i + 1}"], frames[i], atol=1e-12)
        assert "flange" not in robot.links


def _shift_to_modified(rows):
    """The modified table of the arm a standard table describes: alpha_{i-1}, a_{i-1}
    of the previous standard row, d_i and theta_i unchanged."""
    out, prev = [], {"a": 0, "alpha": 0}
    for row in rows:
        out.append({**row, "a": prev["a"], "alpha": prev["alpha"]})
        prev = row
    return out


@pytest.mark.parametrize("seed", range(3))
def test_standard_and_modified_tables_of_one_arm_give_the_same_pose(seed):
    rng = np.random.default_rng(10 + seed)
    std_rows = random_table(rng, 4)
    mod_rows = _shift_to_modified(std_rows)
    std = from_dh("std", std_rows, "standard", strict=False)
    mod = from_dh("mod", mod_rows, "modified", strict=False)
    q = rng.uniform(-2, 2, 4)
    ps, pm = link_poses(std, q), link_poses(mod, q)
    last = std_rows[-1]
    # end effector: the standard flange = modified frame n moved by the last row's a, alpha
    np.testing.assert_allclose(ps["flange"], pm["link4"] @ Tx(_f(last["a"])) @ Rx(_f(last["alpha"])), atol=1e-12)
    for i in range(4):
        np.testing.assert_allclose(ps[f"link{i + 1}"], pm[f"link{i + 1}"], atol=1e-12)


def test_puma560_standard_and_modified_tables_give_the_same_end_effector(puma):
    rows = [
        {"name": f"q{i + 1}", "type": "revolute", "a": a, "alpha": al, "d": d}
        for i, (a, al, d) in enumerate(
            [(0, "pi/2", 0), ("a2", 0, 0), ("a3", "-pi/2", "d3"), (0, "pi/2", "d4"), (0, "-pi/2", 0), (0, 0, 0)]
        )
    ]
    mod = from_dh("puma-mod", _shift_to_modified(rows), "modified", parameters=["a2", "a3", "d3", "d4"])
    rng = np.random.default_rng(4)
    v = dict(a2=0.4318, a3=0.0203, d3=0.15005, d4=0.4318)
    for _ in range(3):
        q = rng.uniform(-np.pi, np.pi, 6)
        # Corke's last row has a6 = alpha6 = 0, so the flange offset is the identity
        end_std = link_poses(puma, q, v)["link6"]
        end_mod = link_poses(mod, q, v)["link6"] @ Tx(0) @ Rx(0)
        np.testing.assert_allclose(end_std, end_mod, atol=1e-12)


def test_quarter_turn_twists_stay_exact(puma, craig):
    """alpha = pi/2 gives exact 0/1 entries (no 6e-17), and moved inertial data stay
    plain symbols (hand-derived: DH frame 1 = link frame 1 * Rx(pi/2), so a DH-frame
    point (x, y, z) is (x, -z, y) in the link frame and Iyy_dh becomes Izz)."""
    for robot in (puma, craig):
        for j in robot.joints:
            assert all(isinstance(e, sp.Integer) and e in (-1, 0, 1) for e in j.rotation), j.name
            assert not j.xyz.atoms(sp.Float)
    s = sp.Symbol
    link1 = puma.links["link1"]
    assert list(link1.com) == [s("cx1"), -s("cz1"), s("cy1")]
    assert link1.inertia[2, 2] == s("Iyy1") and link1.inertia[1, 1] == s("Izz1")
    assert link1.inertia[0, 1] == -s("Ixz1")
    assert list(puma.links["link2"].com) == [s("a2") + s("cx2"), s("cy2"), s("cz2")]
    assert "link frame" in puma.meta["frames"] and puma.meta["convention"] == "standard-dh"


def test_from_dh_python_api_equals_the_yaml_model(puma):
    a2, a3, d3, d4 = sp.symbols("a2 a3 d3 d4")
    table = [(0, sp.pi / 2, 0), (a2, 0, 0), (a3, -sp.pi / 2, d3), (0, sp.pi / 2, d4), (0, -sp.pi / 2, 0), (0, 0, 0)]
    rows = []
    for i, (a, alpha, d) in enumerate(table, start=1):
        rows.append(
            {
                "name": f"q{i}", "type": "revolute", "a": a, "alpha": alpha, "d": d,
                "mass": f"m{i}", "com": [f"cx{i}", f"cy{i}", f"cz{i}"],
                "inertia": {k: f"I{k[1:]}{i}" for k in ("ixx", "iyy", "izz", "ixy", "ixz", "iyz")},
            }
        )  # fmt: skip
    names = list(puma.parameters)
    robot = from_dh("puma560", rows, "standard", gravity=(0, 0, "-g"), parameters=names)
    for j1, j2 in zip(robot.joints, puma.joints):
        assert (j1.name, j1.parent, j1.child) == (j2.name, j2.parent, j2.child)
        assert j1.xyz == j2.xyz and j1.rotation == j2.rotation
    for name, link in robot.links.items():
        other = puma.links[name]
        assert link.mass == other.mass and link.com == other.com and link.inertia == other.inertia
    assert robot.gravity == puma.gravity
    # parameters inferred from the SymPy values when not declared
    inferred = from_dh("k", [{"name": "q1", "type": "revolute", "a": a2, "d": "2*a2"}], "modified")
    assert set(inferred.parameters) == {"a2"}


def test_dh_errors_name_the_joint():
    with pytest.raises(armdyn.ModelError, match="joint 'q2': unknown key.*'alfa'"):
        from_dh("x", [{"name": "q1", "type": "revolute"}, {"name": "q2", "type": "revolute", "alfa": 1}])
    with pytest.raises(armdyn.ModelError, match="joint 'q1': a: unknown parameter 'L'"):
        from_dh("x", [{"name": "q1", "type": "revolute", "a": "L"}], parameters=[])
    with pytest.raises(armdyn.ModelError, match="unknown DH convention"):
        from_dh("x", [{"name": "q1", "type": "revolute"}], convention="craig")


# ------------------------------------------------------------------ dynamics
def _points(rng, n=4):
    """A rigid body as n point masses: (masses (n,), positions (n, 3))."""
    return rng.uniform(0.2, 2.0, n), rng.uniform(-0.3, 0.3, (n, 3))


def _inertials(masses, points):
    """mass, com and inertia about the com by direct summation over point masses."""
    m = masses.sum()
    c = (masses[:, None] * points).sum(0) / m
    r = points - c
    inertia = sum(mi * (ri @ ri * np.eye(3) - np.outer(ri, ri)) for mi, ri in zip(masses, r))
    return m, c, inertia


def _dh_to_craig_frame(points, a, alpha):
    """Positions in standard DH frame i -> Craig's frame i (= link frame i):
    DH frame i = Craig frame i * Tx(a_i) Rx(alpha_i)."""
    T = Tx(a) @ Rx(alpha)
    return points @ T[:3, :3].T + T[:3, 3]


def _standard_rows_with_bodies(std_rows, bodies):
    """Standard rows with each body's inertial data summed in DH frame i."""
    out = []
    for row, (masses, points) in zip(std_rows, bodies):
        m, c, inertia = _inertials(masses, points)
        out.append({**row, "mass": float(m), "com": [float(x) for x in c], "inertia": inertia.tolist()})
    return out


def _modified_rows_with_bodies(std_rows, bodies):
    """The modified twin; each body's points are first moved into Craig's frame i
    (with the STANDARD row i's a_i, alpha_i), then summed there."""
    out = []
    for row, srow, (masses, points) in zip(_shift_to_modified(std_rows), std_rows, bodies):
        m, c, inertia = _inertials(masses, _dh_to_craig_frame(points, _f(srow["a"]), _f(srow["alpha"])))
        out.append({**row, "mass": float(m), "com": [float(x) for x in c], "inertia": inertia.tolist()})
    return out


def _tau_at(eom, state):
    subs = dict(zip(list(eom.q) + list(eom.qd) + list(eom.qdd), state))
    return np.array([float(sp.sympify(t).xreplace(subs).evalf()) for t in eom.tau])


def _assert_same_tau(robot_a, robot_b, rng, states=3):
    e_a = derive(robot_a, method="newton-euler")
    e_b = derive(robot_b, method="newton-euler")
    for _ in range(states):
        state = rng.uniform(-1.5, 1.5, 3 * robot_a.dof)
        np.testing.assert_allclose(_tau_at(e_a, state), _tau_at(e_b, state), rtol=1e-9, atol=1e-9)


PUMA_ROWS = [
    {"name": f"q{i + 1}", "type": "revolute", "a": a, "alpha": al, "d": d}
    for i, (a, al, d) in enumerate(
        [
            (0, sp.pi / 2, 0),
            (0.4318, 0, 0),
            (0.0203, -sp.pi / 2, 0.15005),
            (0, sp.pi / 2, 0.4318),
            (0, -sp.pi / 2, 0),
            (0, 0, 0),
        ]
    )
]


@pytest.mark.parametrize("seed", range(2))
def test_standard_and_modified_dh_give_the_same_dynamics_random_arm(seed):
    rng = np.random.default_rng(20 + seed)
    rows = random_table(rng, 3)  # arbitrary twists make big expressions: keep it small
    rows[1 - seed]["type"] = "prismatic"  # mixed joint types whatever the draw
    bodies = [_points(rng) for _ in rows]
    gravity = (0.3, -1.2, -9.81)
    std = from_dh("std", _standard_rows_with_bodies(rows, bodies), "standard", gravity=gravity)
    mod = from_dh("mod", _modified_rows_with_bodies(rows, bodies), "modified", gravity=gravity)
    _assert_same_tau(std, mod, rng)


def test_bundled_puma560_dynamics_match_its_modified_twin():
    """The bundled file (inertial data symbolic, in DH frames) bound to point-mass
    bodies, against a modified table built here with the bodies moved point by point."""
    rng = np.random.default_rng(40)
    bodies = [_points(rng, 3) for _ in PUMA_ROWS]
    values = {"a2": 0.4318, "a3": 0.0203, "d3": 0.15005, "d4": 0.4318, "g": 9.81}
    entries = {"Ixx": (0, 0), "Iyy": (1, 1), "Izz": (2, 2), "Ixy": (0, 1), "Ixz": (0, 2), "Iyz": (1, 2)}
    for i, (masses, points) in enumerate(bodies, start=1):
        m, c, inertia = _inertials(masses, points)
        values.update({f"m{i}": m, f"cx{i}": c[0], f"cy{i}": c[1], f"cz{i}": c[2]})
        values.update({f"{name}{i}": inertia[rc] for name, rc in entries.items()})
    std = load("puma560").bind({k: float(v) for k, v in values.items()})
    mod = from_dh("mod", _modified_rows_with_bodies(PUMA_ROWS, bodies), "modified", gravity=(0, 0, -9.81))
    _assert_same_tau(std, mod, rng, states=2)
