"""Joint friction (viscous Fv, Coulomb Fc), rotor inertia Ia, torque offset and payloads
(docs/architecture.md: ``tau = M qdd + C qd + g + Ia qdd + Fv qd + Fc sign(qd) + offset``).

Second opinions:
* symbolic: Newton-Euler (terms added joint by joint) == Lagrange (the rotor inertia as
  the rotors' kinetic energy 1/2 Ia qd^2, friction as dissipative generalised forces);
* numeric: Rust core == NumPy reference == lambdified symbolic tau, on every bundled arm;
  identities rnea = crba qdd + rnea(q, qd, 0) and aba(rnea) = qdd with the terms;
* Pinocchio: armature through ``model.armature`` (rnea, crba, aba); Pinocchio has no
  Coulomb friction or offset in rnea, so its rigid part plus the closed form is compared;
* payload: ``with_payload`` == the same load as an extra link on a fixed joint (merged by
  each engine on its own), and == Pinocchio with the load appended to the body.
"""

from __future__ import annotations

import math
import warnings
from dataclasses import replace

import numpy as np
import pytest
import sympy as sp

import armdyn
from armdyn import numeric as num
from armdyn import reference as ref
from armdyn.errors import ModelError
from armdyn.io.urdf import load_urdf
from armdyn.io.yaml import load_yaml_string
from armdyn.model import Joint, Link, Robot

BUNDLED = [r["name"] for r in armdyn.bundled_robots()]
TERMS = ("armature", "damping", "friction", "torque_offset")


def numeric_arm(name: str, seed: int = 0) -> Robot:
    """A bundled arm bound to numbers: its published values, and random ones for
    parameters without (masses and moments in [0.5, 2], products of inertia small)."""
    rng = np.random.default_rng(seed)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        robot = armdyn.load(name, strict=False).bind()
        missing = sorted(s.name for s in robot.free_symbols())
        values = {
            n: (rng.uniform(0.01, 0.1) if n[:3] in ("Ixy", "Ixz", "Iyz") else rng.uniform(0.5, 2.0)) for n in missing
        }
        return robot.bind(values) if values else robot


def with_terms(robot: Robot, seed: int = 1, terms=TERMS) -> Robot:
    """The robot with random joint terms on every movable joint (offsets of both signs)."""
    rng = np.random.default_rng(seed)
    joints = []
    for j in robot.joints:
        if j.movable:
            new = {t: (rng.uniform(-1, 1) if t == "torque_offset" else rng.uniform(0.1, 1.0)) for t in terms}
            j = replace(j, **new)
        joints.append(j)
    with warnings.catch_warnings():  # published non-physical sets, warned about elsewhere
        warnings.simplefilter("ignore")
        return Robot(
            robot.name,
            robot.links.values(),
            joints,
            robot.gravity,
            robot.parameters,
            robot.meta,
            robot.base,
            robot.defaults,
            strict=False,
        )


def closed_form(robot, qd, qdd):
    out = []
    for k, j in enumerate(robot.movable_joints):
        v = {t: float(getattr(j, t) or 0) for t in TERMS}
        out.append(v["armature"] * qdd[k] + v["damping"] * qd[k] + v["friction"] * np.sign(qd[k]) + v["torque_offset"])
    return np.array(out)


def states(robot, rng, count=3):
    n = robot.dof
    out = [tuple(rng.uniform(-2, 2, n) for _ in range(3)) for _ in range(count)]
    q, qd, qdd = out[0]
    qd = qd.copy()
    qd[0] = 0.0  # Coulomb friction at rest: sign(0) = 0
    out.append((q, qd, qdd))
    return out


# ------------------------------------------------------------------ reading the files

YAML = """
name: two
parameters: [Jm, G]
joints:
  - {name: j1, type: revolute, parent: base, child: l1, damping: 0.5, friction: 0.25,
     rotor_inertia: Jm, gear_ratio: G, torque_offset: -0.1}
  - {name: j2, type: prismatic, parent: l1, child: l2, xyz: [1, 0, 0], armature: 0.3}
links:
  - {name: l1, mass: 1, com: [0.5, 0, 0], inertia: {ixx: 0.1, iyy: 0.1, izz: 0.1}}
  - {name: l2, mass: 2, inertia: 0}
"""


def test_yaml_terms_and_gear_ratio():
    robot = load_yaml_string(YAML)
    j1, j2 = robot.joints
    Jm, G = sp.symbols("Jm G")
    assert j1.armature == G**2 * Jm  # reflected through the gear
    assert (j1.damping, j1.friction, j1.torque_offset) == (sp.Float(0.5), sp.Float(0.25), sp.Float(-0.1))
    assert j2.armature == sp.Float(0.3) and j2.damping is None
    bound = robot.bind({"Jm": 0.01, "G": 50})
    assert math.isclose(float(bound.joints[0].armature), 25.0)


@pytest.mark.parametrize(
    "entry, message",
    [
        ("damping: -1", "damping -1"),
        ("friction: .nan", "friction"),
        ("armature: .inf", "armature"),
        ("armature: 1, rotor_inertia: 2", "either armature or rotor_inertia"),
        ("gear_ratio: 3", "gear_ratio without rotor_inertia"),
        ("rotor_inertia: -1, gear_ratio: 2", "armature -4 is negative"),
    ],
)
def test_bad_yaml_terms_name_file_and_joint(entry, message):
    text = f"""
name: bad
joints:
  - {{name: j1, type: revolute, parent: base, child: l1, {entry}}}
links:
  - {{name: l1, mass: 1, com: [0.5, 0, 0], inertia: 0}}
"""
    with pytest.raises(ModelError) as err:
        load_yaml_string(text, source="bad.yaml")
    line = str(err.value)
    assert "bad.yaml" in line and "joint 'j1'" in line and message in line, line
    assert "\n" not in line


def test_symbolic_terms_checked_when_bound():
    robot = load_yaml_string(YAML.replace("damping: 0.5", "damping: Jm"))
    with pytest.raises(ModelError, match="damping -1 is negative"):
        robot.bind({"Jm": -1, "G": 1})


def test_urdf_dynamics_read_and_validated(tmp_path):
    urdf = """<robot name="r"><link name="base"/><link name="l1"><inertial><mass value="1"/>
      <origin xyz="0.5 0 0"/><inertia ixx="0.1" iyy="0.1" izz="0.1" ixy="0" ixz="0" iyz="0"/></inertial></link>
      <joint name="j1" type="revolute"><parent link="base"/><child link="l1"/><axis xyz="0 0 1"/>
      <limit lower="-1" upper="1" effort="1" velocity="1"/><dynamics damping="DAMP" friction="0.2"/></joint></robot>"""
    robot = load_urdf(urdf.replace("DAMP", "0.3"))
    j = robot.joints[0]
    assert float(j.damping) == 0.3 and float(j.friction) == 0.2
    tau = num.rnea(robot, [0.1], [-2.0], [0.0])
    assert np.isfinite(tau).all()
    np.testing.assert_allclose(tau - ref.rnea(robot.subs({}), [0.1], [-2.0], [0.0]), 0, atol=1e-14)
    np.testing.assert_allclose(
        tau
        - num.rnea(
            Robot(robot.name, robot.links.values(), [replace(j, damping=None, friction=None)], robot.gravity),
            [0.1],
            [-2.0],
            [0.0],
        ),
        [0.3 * -2.0 - 0.2],
        rtol=1e-14,
    )
    bad = tmp_path / "bad.urdf"
    bad.write_text(urdf.replace("DAMP", "-0.3"))
    with pytest.raises(ModelError) as err:
        load_urdf(bad)
    assert "bad.urdf" in str(err.value) and "joint 'j1'" in str(err.value) and "negative" in str(err.value)


def test_dh_table_terms():
    text = """
name: dh
convention: standard-dh
dh:
  - {name: q1, type: revolute, a: 1, mass: 1, com: [-0.5, 0, 0], inertia: 0, damping: 0.2, armature: 0.1}
  - {name: q2, type: revolute, a: 1, mass: 1, com: [-0.5, 0, 0], inertia: 0, friction: 0.3, torque_offset: 0.05}
"""
    robot = load_yaml_string(text)
    assert float(robot.joints[0].damping) == 0.2 and float(robot.joints[1].torque_offset) == 0.05
    q, qd, qdd = np.array([0.3, -0.2]), np.array([0.5, -1.0]), np.array([1.0, 2.0])
    expected = [0.1 * 1.0 + 0.2 * 0.5, -0.3 + 0.05]
    plain = load_yaml_string(
        text.replace(", damping: 0.2, armature: 0.1", "").replace(", friction: 0.3, torque_offset: 0.05", "")
    )
    np.testing.assert_allclose(num.rnea(robot, q, qd, qdd) - num.rnea(plain, q, qd, qdd), expected, rtol=1e-13)


# ------------------------------------------------------------------ symbolic


def symbolic_terms(robot: Robot) -> Robot:
    joints = []
    for j in robot.joints:
        if j.movable:
            k = robot.link_index(j.child)
            j = replace(j, **{t: sp.Symbol(f"{t[:3]}{k}") for t in TERMS})
        joints.append(j)
    return Robot(
        robot.name,
        robot.links.values(),
        joints,
        robot.gravity,
        robot.parameters,
        robot.meta,
        robot.base,
        robot.defaults,
        strict=False,
    )


@pytest.mark.parametrize("name", ["rp-arm", "planar-2r", "planar-3r"])
def test_newton_euler_equals_lagrange_with_terms(name):
    robot = symbolic_terms(armdyn.load(name))
    report = armdyn.prove_agreement(robot, exact=True)
    assert report, report.text()
    assert any("Fv qd + Fc sign(qd)" in r.name for r in report.results)
    # the rotor inertias sit on M's diagonal, the friction outside M qdd + C qd + g
    eom = armdyn.derive(robot, "lagrange")
    rigid = armdyn.derive(armdyn.load(name), "lagrange")
    ia = [sp.Symbol(f"arm{robot.link_index(j.child)}") for j in robot.movable_joints]
    assert sp.expand(eom.M - rigid.M - sp.diag(*ia)) == sp.zeros(robot.dof, robot.dof)
    assert list(eom.friction) == [
        sp.Symbol(f"dam{robot.link_index(j.child)}") * robot.qd[k]
        + sp.Symbol(f"fri{robot.link_index(j.child)}") * sp.sign(robot.qd[k])
        for k, j in enumerate(robot.movable_joints)
    ]


def test_no_terms_no_change():
    robot = armdyn.load("planar-2r")
    eom = armdyn.derive(robot)
    assert not any(s.name == "tau_joint" for s in eom.steps)
    assert eom.friction == sp.zeros(2, 1)


# ------------------------------------------------------------------ numeric


@pytest.mark.parametrize("name", BUNDLED)
def test_engines_agree_with_terms(name):
    robot = with_terms(numeric_arm(name))
    rigid = numeric_arm(name)
    rng = np.random.default_rng(3)
    eom = armdyn.derive(robot) if robot.dof <= 4 else None
    f = sp.lambdify([robot.q, robot.qd, robot.qdd], eom.tau, "numpy") if eom else None
    checked = 0
    for q, qd, qdd in states(robot, rng):
        tau = num.rnea(robot, q, qd, qdd)
        assert np.isfinite(tau).all()
        scale = max(1.0, np.abs(tau).max())
        np.testing.assert_allclose(tau, ref.rnea(robot, q, qd, qdd), rtol=0, atol=1e-12 * scale)
        np.testing.assert_allclose(
            tau - num.rnea(rigid, q, qd, qdd), closed_form(robot, qd, qdd), rtol=0, atol=1e-12 * scale
        )
        if f is not None:
            np.testing.assert_allclose(np.ravel(f(q, qd, qdd)), tau, rtol=0, atol=1e-11 * scale)
        M = num.crba(robot, q)
        np.testing.assert_allclose(M, ref.crba(robot, q), rtol=0, atol=1e-12 * np.abs(M).max())
        # rnea = M qdd + rnea(q, qd, 0): Ia in M, friction and offset in the bias
        np.testing.assert_allclose(tau, M @ qdd + num.rnea(robot, q, qd, 0 * qdd), rtol=0, atol=1e-11 * scale)
        for engine in (num, ref):
            np.testing.assert_allclose(engine.aba(robot, q, qd, tau), qdd, rtol=0, atol=1e-9)
        T = num.kinetic_energy(robot, q, qd)
        assert math.isclose(T, 0.5 * qd @ M @ qd, rel_tol=1e-12)
        assert math.isclose(ref.kinetic_energy(robot, q, qd), T, rel_tol=1e-12)
        checked += 1
    assert checked == 4


def test_batch_equals_loop_with_terms():
    robot = with_terms(numeric_arm("puma560"))
    rng = np.random.default_rng(5)
    Q, QD, QDD = (rng.uniform(-2, 2, (13, 6)) for _ in range(3))
    QD[3] = 0.0
    for fn, args in ((num.rnea, (Q, QD, QDD)), (num.aba, (Q, QD, QDD))):
        batch = fn(robot, *args, threads=2)
        loop = np.array([fn(robot, *(a[i] for a in args)) for i in range(13)])
        np.testing.assert_array_equal(batch, loop)
    np.testing.assert_array_equal(num.crba(robot, Q), np.array([num.crba(robot, q) for q in Q]))


@pytest.mark.parametrize("name", ["puma560", "ur5", "panda", "iiwa14", "stanford"])
def test_pinocchio_armature_and_closed_form(name):
    pytest.importorskip("pinocchio")
    from pinocchio_bridge import PinocchioRobot

    robot = with_terms(numeric_arm(name))
    P = PinocchioRobot(robot)
    P.model.armature = np.array([float(robot.movable_joints[i].armature) for i in P.perm])
    P.data = P.model.createData()
    rng = np.random.default_rng(7)
    for q, qd, qdd in states(robot, rng):
        # Pinocchio's rnea has the armature but no friction or offset: add the closed form
        rest = closed_form(robot, qd, 0 * qdd)
        tau = num.rnea(robot, q, qd, qdd)
        scale = max(1.0, np.abs(tau).max())
        np.testing.assert_allclose(tau, P.rnea(q, qd, qdd) + rest, rtol=0, atol=1e-11 * scale)
        M = num.crba(robot, q)
        np.testing.assert_allclose(M, P.crba(q), rtol=0, atol=1e-12 * np.abs(M).max())
        np.testing.assert_allclose(num.aba(robot, q, qd, tau), P.aba(q, qd, tau - rest), rtol=0, atol=1e-9)


# ------------------------------------------------------------------ payload

PAYLOAD = dict(
    mass=1.7, com=[0.02, -0.03, 0.11], inertia=[[0.012, 0.001, 0.0], [0.001, 0.015, 0.002], [0.0, 0.002, 0.009]]
)


def as_fixed_link(robot: Robot, link: str) -> Robot:
    """The payload as its own link on a fixed joint at ``link``'s frame."""
    load = Link("payload", PAYLOAD["mass"], PAYLOAD["com"], PAYLOAD["inertia"])
    joint = Joint("payload_joint", "fixed", link, "payload")
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        return Robot(
            robot.name,
            list(robot.links.values()) + [load],
            robot.joints + [joint],
            robot.gravity,
            robot.parameters,
            robot.meta,
            robot.base,
            robot.defaults,
            strict=False,
        )


@pytest.mark.parametrize("name", BUNDLED)
def test_payload_equals_fixed_link(name):
    robot = with_terms(numeric_arm(name))
    link = robot.movable_joints[-1].child
    loaded = robot.with_payload(**PAYLOAD, link=link)
    assert loaded is not robot and robot.links[link].mass != loaded.links[link].mass
    other = as_fixed_link(robot, link)
    rng = np.random.default_rng(11)
    for q, qd, qdd in states(robot, rng, 2):
        for engine in (num, ref):
            tau = engine.rnea(loaded, q, qd, qdd)
            scale = max(1.0, np.abs(tau).max())
            np.testing.assert_allclose(tau, engine.rnea(other, q, qd, qdd), rtol=0, atol=1e-11 * scale)
            np.testing.assert_allclose(engine.crba(loaded, q), engine.crba(other, q), rtol=0, atol=1e-11 * scale)
        assert not np.allclose(num.rnea(loaded, q, qd, qdd), num.rnea(robot, q, qd, qdd))


def test_payload_pinocchio_and_default_link():
    pin = pytest.importorskip("pinocchio")
    from pinocchio_bridge import PinocchioRobot

    robot = numeric_arm("ur5")
    loaded = robot.with_payload(**PAYLOAD)  # default: the last link
    last = list(robot.links)[-1]
    assert loaded.links[last].mass == robot.links[last].mass + sp.Float(1.7)
    P = PinocchioRobot(robot)
    jid = P.model.getJointId(robot.movable_joints[-1].name)
    # the load in the last joint's frame: armdyn's last link frame there (bridge frame)
    placement = P.model.frames[P.frames[last]].placement
    P.model.appendBodyToJoint(jid, pin.Inertia(1.7, np.array(PAYLOAD["com"]), np.array(PAYLOAD["inertia"])), placement)
    P.data = P.model.createData()
    rng = np.random.default_rng(12)
    for q, qd, qdd in states(robot, rng, 2):
        np.testing.assert_allclose(num.rnea(loaded, q, qd, qdd), P.rnea(q, qd, qdd), rtol=1e-12, atol=1e-12)


def test_payload_symbolic_agrees():
    robot = armdyn.load("planar-2r")
    mp, cx = sp.symbols("mp cx")
    loaded = robot.with_payload(mp, [cx, 0, 0])
    assert mp in loaded.free_symbols() and "mp" in loaded.parameters
    assert armdyn.prove_agreement(loaded, exact=True)


@pytest.mark.parametrize(
    "kwargs, message",
    [
        (dict(mass=-1.0), "mass -1 is negative"),
        (dict(mass=1.0, inertia=[[1, 0, 0], [0, 1, 0], [0, 0, 3]]), "triangle inequality"),
        (dict(mass=1.0, inertia=[[1, 0, 0], [0, -1, 0], [0, 0, 1]]), "positive semi-definite"),
        (dict(mass=float("nan")), "not finite"),
        (dict(mass=1.0, com=[0, float("inf"), 0]), "not finite"),
        (dict(mass=1.0, com=[0, 0]), "3 components"),
        (dict(mass=1.0, link="nope"), "no link named 'nope'"),
        (dict(mass=1.0, link="base"), "does not move"),
    ],
)
def test_bad_payload(kwargs, message):
    robot = armdyn.load("ur5")
    if kwargs.get("link") == "base":
        kwargs["link"] = robot.base
    with pytest.raises(ModelError) as err:
        robot.with_payload(**kwargs)
    assert "payload" in str(err.value) and message in str(err.value), str(err.value)
