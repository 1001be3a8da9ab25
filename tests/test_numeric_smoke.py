"""Smoke test of armdyn.numeric (the Rust core) against Pinocchio on a small branched
arm with revolute, prismatic and fixed joints, arbitrary placements and axes, built
independently in both libraries from the same numbers; plus the input checks."""

import numpy as np
import pytest
import sympy as sp
from optional import needs_pinocchio, pin

from armdyn import Joint, Link, Robot, numeric
from armdyn.errors import UnboundParameterError

RNG = np.random.default_rng(20240611)


def _rotation(rng):
    q, r = np.linalg.qr(rng.normal(size=(3, 3)))
    q = q @ np.diag(np.sign(np.diag(r)))
    return q if np.linalg.det(q) > 0 else -q


def _unit(rng):
    v = rng.normal(size=3)
    return v / np.linalg.norm(v)


def _inertia(rng):
    a, b = rng.uniform(0.01, 0.2, 2)
    c = rng.uniform(abs(a - b) + 0.005, a + b)
    r = _rotation(rng)
    return r @ np.diag([a, b, c]) @ r.T


# (parent link, type, axis or None for random)
LAYOUT = [
    ("base", "revolute", [0, 0, 1]),
    ("l1", "revolute", None),
    ("l2", "prismatic", None),
    ("l3", "fixed", None),
    ("l4", "revolute", [1, 0, 0]),
    ("l1", "prismatic", [0, -1, 0]),  # a second branch from l1
    ("l6", "revolute", None),
    ("base", "fixed", None),  # welded to the base
    ("l8", "revolute", [0, 1, 0]),
]


def build_pair(rng=RNG):
    """The same arm as an armdyn Robot and a Pinocchio model (+ frame ids per link);
    the Robot alone (model and ids None) when Pinocchio is not installed."""
    links = [Link("base")]
    joints = []
    rows = []
    for k, (parent, jtype, axis) in enumerate(LAYOUT, start=1):
        name = f"l{k}"
        rot, xyz = _rotation(rng), rng.uniform(-0.4, 0.4, 3)
        axis = np.array(axis, float) if axis is not None else _unit(rng)
        mass, com, inertia = rng.uniform(0.5, 3.0), rng.uniform(-0.2, 0.2, 3), _inertia(rng)
        links.append(Link(name, mass, com.tolist(), inertia.tolist()))
        joints.append(Joint(f"j{k}", jtype, parent, name, xyz.tolist(), rot.tolist(), axis.tolist()))
        rows.append((k, parent, jtype, name, rot, xyz, axis, mass, com, inertia))
    robot = Robot("smoke", links, joints, gravity=[0.4, -0.3, -9.81])
    if pin is None:
        return robot, None, None
    pmodel = pin.Model()
    pmodel.gravity = pin.Motion(np.array([0.4, -0.3, -9.81]), np.zeros(3))
    # per link: (pinocchio joint id, link frame placement in that joint's frame)
    carrier = {"base": (0, pin.SE3.Identity())}
    frame_ids = {"base": pmodel.addFrame(pin.Frame("base", 0, pin.SE3.Identity(), pin.FrameType.OP_FRAME))}
    for k, parent, jtype, name, rot, xyz, axis, mass, com, inertia in rows:
        pj, offset = carrier[parent]
        placement = offset * pin.SE3(rot, xyz)
        if jtype == "fixed":
            carrier[name] = (pj, placement)
        else:
            jm = (
                pin.JointModelRevoluteUnaligned(axis) if jtype == "revolute" else pin.JointModelPrismaticUnaligned(axis)
            )
            pj = pmodel.addJoint(pj, jm, placement, f"j{k}")
            carrier[name] = (pj, pin.SE3.Identity())
        pj, offset = carrier[name]
        if pj != 0:
            pmodel.appendBodyToJoint(pj, pin.Inertia(mass, com, inertia), offset)
        frame_ids[name] = pmodel.addFrame(pin.Frame(name, pj, offset, pin.FrameType.OP_FRAME))
    return robot, pmodel, frame_ids


@pytest.fixture(scope="module")
def pair():
    """(robot, Pinocchio model or None, frame ids or None): tests that use the
    Pinocchio half are marked @needs_pinocchio."""
    return build_pair()


def close(a, b, tol=1e-12):
    a, b = np.asarray(a), np.asarray(b)
    assert a.shape == b.shape
    assert np.max(np.abs(a - b), initial=0.0) <= tol * (1.0 + np.max(np.abs(b), initial=0.0)), (a, b)


@needs_pinocchio
def test_matches_pinocchio(pair):
    robot, pmodel, frame_ids = pair
    pdata = pmodel.createData()
    n = robot.dof
    assert n == pmodel.nv == 7
    for _ in range(10):
        q, qd, qdd = RNG.uniform(-3, 3, n), RNG.uniform(-2, 2, n), RNG.uniform(-2, 2, n)
        tau = pin.rnea(pmodel, pdata, q, qd, qdd)
        close(numeric.rnea(robot, q, qd, qdd), tau)
        m = pin.crba(pmodel, pdata, q)
        m = np.triu(m) + np.triu(m, 1).T
        close(numeric.crba(robot, q), m)
        close(numeric.aba(robot, q, qd, tau), pin.aba(pmodel, pdata, q, qd, tau), 1e-10)
        close(numeric.gravity(robot, q), pin.computeGeneralizedGravity(pmodel, pdata, q))
        close(numeric.bias(robot, q, qd), pin.nonLinearEffects(pmodel, pdata, q, qd))
        close(numeric.coriolis_matrix(robot, q, qd), pin.computeCoriolisMatrix(pmodel, pdata, q, qd))
        close(numeric.kinetic_energy(robot, q, qd), pin.computeKineticEnergy(pmodel, pdata, q, qd))
        pin.framesForwardKinematics(pmodel, pdata, q)
        # Pinocchio leaves out links welded to the base (l8); armdyn counts their constant
        l8 = robot.links["l8"]
        welded = (
            -float(l8.mass) * pmodel.gravity.linear @ pdata.oMf[frame_ids["l8"]].act(np.array(l8.com, float).ravel())
        )
        close(numeric.potential_energy(robot, q), pin.computePotentialEnergy(pmodel, pdata, q) + welded)
        x = numeric.forward_kinematics(robot, q)
        assert x.shape == (len(robot.links), 4, 4)
        pin.computeJointJacobians(pmodel, pdata, q)
        for k, name in enumerate(robot.links):
            close(x[k], pdata.oMf[frame_ids[name]].homogeneous)
            j = pin.getFrameJacobian(pmodel, pdata, frame_ids[name], pin.LOCAL_WORLD_ALIGNED)
            close(numeric.jacobian(robot, q, name), j)


def test_batch_equals_single_calls(pair):
    robot = pair[0]
    n = robot.dof
    for rows in (1, 5, 300):
        q, qd, qdd = (RNG.uniform(-3, 3, (rows, n)) for _ in range(3))
        for threads in (1, 2, None):
            for name, args in [
                ("rnea", (q, qd, qdd)),
                ("aba", (q, qd, qdd)),
                ("crba", (q,)),
                ("gravity", (q,)),
                ("bias", (q, qd)),
                ("coriolis_matrix", (q, qd)),
                ("kinetic_energy", (q, qd)),
                ("potential_energy", (q,)),
                ("forward_kinematics", (q,)),
            ]:
                f = getattr(numeric, name)
                out = f(robot, *args, threads=threads)
                loop = np.array([f(robot, *(a[r] for a in args)) for r in range(rows)])
                assert out.shape == loop.shape and out.dtype == np.float64
                assert np.array_equal(out, loop), name
            out = numeric.jacobian(robot, q, "l7", threads=threads)
            assert np.array_equal(out, np.array([numeric.jacobian(robot, q[r], "l7") for r in range(rows)]))


def test_inputs_are_converted_and_checked(pair):
    robot = pair[0]
    n = robot.dof
    q = RNG.uniform(-1, 1, n)
    want = numeric.rnea(robot, q, q, q)
    assert np.array_equal(numeric.rnea(robot, list(q), tuple(q), q), want)
    q32 = q.astype(np.float32)
    assert np.array_equal(numeric.rnea(robot, q32, q32, q32), numeric.rnea(robot, *[q32.astype(float)] * 3))
    qf = np.asfortranarray(np.stack([q, q]))
    assert np.array_equal(numeric.rnea(robot, qf, qf, qf)[1], want)
    assert np.array_equal(
        numeric.rnea(robot, np.stack([q, q])[:, ::1], q[None].repeat(2, 0), np.stack([q, q]))[0], want
    )
    with pytest.raises(ValueError, match="qd: expected shape"):
        numeric.rnea(robot, q, q[:-1], q)
    with pytest.raises(ValueError, match="qdd: shape"):
        numeric.rnea(robot, q, q, np.stack([q, q]))
    bad = q.copy()
    bad[2] = np.nan
    with pytest.raises(ValueError, match=r"qd contains NaN or inf \(at qd\[2\]\)"):
        numeric.rnea(robot, q, bad, q)
    bad[2] = np.inf
    with pytest.raises(ValueError, match=r"tau contains NaN or inf \(at tau\[1, 2\]\)"):
        numeric.aba(robot, np.stack([q, q]), np.stack([q, q]), np.stack([q, bad]))
    with pytest.raises(ValueError, match="q:"):
        numeric.crba(robot, ["a"] * n)
    with pytest.raises(ValueError, match="threads"):
        numeric.crba(robot, np.stack([q, q]), threads=0)
    with pytest.raises(ValueError, match="no link named 'nope'"):
        numeric.jacobian(robot, q, "nope")
    with pytest.raises(TypeError):
        numeric.rnea("not a robot", q, q, q)


def test_rust_panics_become_runtime_errors():
    from armdyn import _core

    for in_batch in (False, True):
        with pytest.raises(RuntimeError, match="armdyn internal error"):
            _core._test_panic(in_batch)


def test_empty_batches_and_fixed_only_robots(pair):
    robot = pair[0]
    assert numeric.rnea(robot, *[np.zeros((0, robot.dof))] * 3).shape == (0, robot.dof)
    assert numeric.kinetic_energy(robot, *[np.zeros((0, robot.dof))] * 2).shape == (0,)
    welded = Robot("welded", [Link("base"), Link("tool", 1.0)], [Joint("weld", "fixed", "base", "tool", xyz=[0, 0, 1])])
    assert numeric.crba(welded, []).shape == (0, 0)
    # welded links do not move, but count in V = -m g . p_c
    assert numeric.potential_energy(welded, []) == pytest.approx(9.81, rel=1e-15)
    assert np.array_equal(numeric.forward_kinematics(welded, [])[1][:3, 3], [0, 0, 1])


def test_unbound_parameters_and_caching():
    m1, l1 = sp.symbols("m1 l1")
    robot = Robot(
        "pendulum",
        [Link("base"), Link("arm", m1, [l1, 0, 0])],
        [Joint("j1", "revolute", "base", "arm", axis=[0, 1, 0])],
        parameters=[m1, l1],
    )
    with pytest.raises(UnboundParameterError, match=r"\['l1', 'm1'\]"):
        numeric.gravity(robot, [0.3])
    bound = robot.bind({"m1": 2.0, "l1": sp.Rational(1, 2)})
    # point mass m at (l, 0, 0) turned by q about +y sits at height z = -l sin q, so
    # V = m 9.81 z and g = dV/dq = -m 9.81 l cos q
    assert numeric.gravity(bound, [0.3])[0] == pytest.approx(-2.0 * 9.81 * 0.5 * np.cos(0.3), rel=1e-14)
    model = bound._numeric_model
    numeric.crba(bound, [0.1])
    assert bound._numeric_model is model
    assert numeric.compile_model(model) is model
    assert np.array_equal(numeric.crba(model, [0.1]), numeric.crba(bound, [0.1]))
