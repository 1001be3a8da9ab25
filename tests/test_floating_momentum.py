"""Centre of mass, centroidal momentum, world-frame kinematics and energies
(armdyn.centroidal; armdyn.numeric's forward_kinematics, jacobian, kinetic_energy and
potential_energy on a floating base) against Pinocchio (buildModelFromUrdf, with
JointModelFreeFlyer for the floating robots of example-robot-data that test_floating.py
loads, without for UR5, Kinova and Panda, whose fingers are a mimic pair), and against
identities that need no second library:

* h_G = A_G v is the sum of the links' momenta (each from its pose, Jacobian and inertia
  as the URDF gives them), moved to the centre of mass, itself the links' mean position;
* c' = J_c v, A_G' and h_G' = (A_G v)' by central differences along ``integrate(q, t v)``
  (a constant velocity: the base twist is constant in the base frame);
* a robot flying freely (no base wrench, any joint torques) changes its centroidal
  momentum by gravity alone: h_G' = [m g; 0];
* T = 1/2 v^T M v (M by the CRBA) and V = -m g . c; the link Jacobians by central
  differences of the link poses;
* batches equal single calls bit for bit; bad input is refused by name.
"""

from __future__ import annotations

import warnings

import numpy as np
import pytest
from optional import example_robot_data_dir, needs_pinocchio, pin
from random_models import random_robot
from test_floating import FLOATING_URDFS, WITH_MIMICS, _load_pair, close, floating_state, floating_tree, pin_arrays

import armdyn
import armdyn.numeric as numeric
from armdyn import centroidal
from armdyn.io import with_root_joint

TOL = 1e-10
FRAMES = {"local": "LOCAL", "world": "WORLD", "local_world_aligned": "LOCAL_WORLD_ALIGNED"}
#: fixed-base arms of example-robot-data without mimic joints
FIXED_URDFS = {"ur5": "ur_description/urdf/ur5_robot.urdf", "kinova": "kinova_description/robots/kinova.urdf"}


# ------------------------------------------------------------------ Pinocchio


def pin_configuration(model, robot, q):
    """Pinocchio's q and the permutation of velocities (``v_pin = v[perm]``)."""
    zero = np.zeros(robot.nv)
    qp, _, _, perm = pin_arrays(model, robot, q, zero, zero)
    return qp, perm


def fixed_pin_configuration(model, names, q):
    """:func:`pin_configuration` for a fixed base whose coordinates are ``names`` (a
    continuous joint is cos, sin in Pinocchio)."""
    qp, perm = np.zeros(model.nq), np.zeros(model.nv, dtype=int)
    for j in range(1, model.njoints):
        k = list(names).index(model.names[j])
        iq, perm[model.idx_vs[j]] = model.idx_qs[j], k
        qp[iq : iq + model.joints[j].nq] = [np.cos(q[k]), np.sin(q[k])] if model.joints[j].nq == 2 else q[k]
    return qp, perm


def pinocchio_dag(dA, robot, q, v):
    """Pinocchio's ``dAg`` from the time derivative of A_G: ``c' x`` the linear rows added
    to the angular ones (it moves the moments to a centre of mass standing still)."""
    A = centroidal.centroidal_momentum_matrix(robot, q)
    cdot = centroidal.com_jacobian(robot, q) @ v
    return np.concatenate([dA[:3], dA[3:] + np.cross(cdot, A[:3].T).T])


def compare_with_pinocchio(robot, model, states, floating: bool):
    data = model.createData()
    for q, v, a in states:
        if floating:
            qp, perm = pin_configuration(model, robot, q)
        else:
            qp, perm = fixed_pin_configuration(model, robot.coordinate_names, q)
        vp, ap = v[perm], a[perm]
        assert close(centroidal.center_of_mass(robot, q), pin.centerOfMass(model, data, qp)) < TOL, "com"
        Jc = centroidal.com_jacobian(robot, q)
        assert close(Jc[:, perm], pin.jacobianCenterOfMass(model, data, qp)) < TOL, "com_jacobian"
        Ag = pin.computeCentroidalMap(model, data, qp)
        assert close(centroidal.centroidal_momentum_matrix(robot, q)[:, perm], Ag) < TOL, "A_G"
        hg = pin.computeCentroidalMomentum(model, data, qp, vp).vector
        assert close(centroidal.centroidal_momentum(robot, q, v), hg) < TOL, "h_G"
        pin.computeCentroidalMomentumTimeVariation(model, data, qp, vp, ap)
        assert close(centroidal.centroidal_momentum_rate(robot, q, v, a), data.dhg.vector) < TOL, "h_G'"
        dA = pinocchio_dag(centroidal.centroidal_momentum_matrix_rate(robot, q, v), robot, q, v)
        # (a fresh Data: after computeCentroidalMomentumTimeVariation Pinocchio 4.1's dAg
        # differs, a stale workspace)
        assert close(dA[:, perm], pin.computeCentroidalMapTimeVariation(model, model.createData(), qp, vp)) < TOL
        assert close(numeric.kinetic_energy(robot, q, v), pin.computeKineticEnergy(model, data, qp, vp)) < TOL
        if floating:  # (a fixed base's potential counts its base link; Pinocchio's does not)
            assert close(numeric.potential_energy(robot, q), pin.computePotentialEnergy(model, data, qp)) < TOL


@needs_pinocchio
@pytest.mark.parametrize("name", [n for n in FLOATING_URDFS if n not in WITH_MIMICS])
def test_centroidal_quantities_agree_with_pinocchio(name):
    robot, model = _load_pair(name)
    rng = np.random.default_rng(len(name) + 100)
    compare_with_pinocchio(robot, model, [floating_state(robot, rng) for _ in range(3)], floating=True)


@needs_pinocchio
@pytest.mark.parametrize("name", [n for n in FLOATING_URDFS if n not in WITH_MIMICS])
def test_kinematics_agree_with_pinocchio(name):
    """Every link's world pose, and its Jacobian in Pinocchio's three frames."""
    robot, model = _load_pair(name)
    data = model.createData()
    rng = np.random.default_rng(len(name) + 200)
    for _ in range(2):
        q, _, _ = floating_state(robot, rng)
        qp, perm = pin_configuration(model, robot, q)
        pin.computeJointJacobians(model, data, qp)
        pin.updateFramePlacements(model, data)
        poses = numeric.forward_kinematics(robot, q)
        compared = 0
        for k, link in enumerate(robot.links):
            if not model.existFrame(link, pin.BODY):
                continue
            fid = model.getFrameId(link, pin.BODY)
            assert close(poses[k], data.oMf[fid].homogeneous) < TOL, link
            for frame, pin_frame in FRAMES.items():
                J = numeric.jacobian(robot, q, link, reference_frame=frame)
                Jp = pin.getFrameJacobian(model, data, fid, getattr(pin, pin_frame))
                assert close(J[:, perm], Jp) < TOL, (link, frame)
            compared += 1
        assert compared >= len(robot.links) // 2, "most links have a Pinocchio frame of their name"


def load_fixed(name: str):
    urdf = example_robot_data_dir() / FIXED_URDFS[name]
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        robot = armdyn.load(urdf, strict=False).without_joint_dynamics()
    return (robot.bind() if robot.defaults else robot), pin.buildModelFromUrdf(str(urdf))


@needs_pinocchio
@pytest.mark.parametrize("name", FIXED_URDFS)
def test_fixed_base_agrees_with_pinocchio(name):
    """A fixed base: the mass of the moving links only (the base is Pinocchio's universe)."""
    robot, model = load_fixed(name)
    rng = np.random.default_rng(5)
    states = [rng.uniform(-np.pi, np.pi, (3, robot.dof)) for _ in range(3)]
    compare_with_pinocchio(robot, model, states, floating=False)


@needs_pinocchio
def test_mimic_joints_agree_with_pinocchio():
    """panda's fingers are a mimic pair: armdyn's quantities in its 8 coordinates are the
    full tree's (Pinocchio's 9 joints, the follower free) at q_full = G q + o, the matrices
    times G."""
    urdf = example_robot_data_dir() / "panda_description/urdf/panda.urdf"
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        robot = armdyn.load(urdf, strict=False).without_joint_dynamics()
    robot = robot.bind() if robot.defaults else robot
    mimic = numeric.compile_model(robot)
    model = pin.buildModelFromUrdf(str(urdf))
    data = model.createData()
    assert model.nv == len(mimic.offset) == robot.dof + 1
    rng = np.random.default_rng(9)
    for _ in range(3):
        q, v, a = rng.uniform(-1, 1, (3, robot.dof))
        qp, perm = fixed_pin_configuration(model, mimic.full.coordinate_names, mimic.G @ q + mimic.offset)
        vp, ap = (mimic.G @ v)[perm], (mimic.G @ a)[perm]
        assert close(centroidal.center_of_mass(robot, q), pin.centerOfMass(model, data, qp)) < TOL
        for ours, theirs in (
            (centroidal.com_jacobian(robot, q), pin.jacobianCenterOfMass(model, data, qp)),
            (centroidal.centroidal_momentum_matrix(robot, q), pin.computeCentroidalMap(model, data, qp)),
        ):
            full = np.zeros_like(theirs)
            full[:, perm] = theirs
            assert close(ours, full @ mimic.G) < TOL
        hg = pin.computeCentroidalMomentum(model, data, qp, vp).vector
        assert close(centroidal.centroidal_momentum(robot, q, v), hg) < TOL
        pin.computeCentroidalMomentumTimeVariation(model, data, qp, vp, ap)
        assert close(centroidal.centroidal_momentum_rate(robot, q, v, a), data.dhg.vector) < TOL
        full = np.zeros((6, model.nv))
        full[:, perm] = pin.computeCentroidalMapTimeVariation(model, model.createData(), qp, vp)
        dA = pinocchio_dag(centroidal.centroidal_momentum_matrix_rate(robot, q, v), robot, q, v)
        assert close(dA, full @ mimic.G) < TOL
    Q = rng.uniform(-1, 1, (4, robot.dof))
    batch = centroidal.centroidal_momentum_matrix(robot, Q)
    assert all(np.array_equal(batch[k], centroidal.centroidal_momentum_matrix(robot, Q[k])) for k in range(4))


# ------------------------------------------------------------------ identities


def float_array(x) -> np.ndarray:
    return np.array(np.asarray(x).tolist(), dtype=float)


def moving_links(robot) -> set[str]:
    """The links whose mass counts: all of a floating robot's; a fixed one's but the base
    and the links welded to it."""
    if robot.floating:
        return set(robot.links)
    welded = {robot.base}
    for j in robot.joints:  # tree order: a parent before its children
        if j.type == "fixed" and j.parent in welded:
            welded.add(j.child)
    return set(robot.links) - welded


def by_links(robot, q, v):
    """(m, c, h_G) summed link by link from the world poses and LOCAL_WORLD_ALIGNED
    Jacobians of the link frames, each link's mass, centre of mass and inertia tensor
    about it (link frame) as the description gives them."""
    poses = numeric.forward_kinematics(robot, q)
    m, mc, p, k_o = 0.0, np.zeros(3), np.zeros(3), np.zeros(3)
    moving = moving_links(robot)
    for k, (name, link) in enumerate(robot.links.items()):
        if name not in moving:
            continue
        mass, com, inertia = float(link.mass), float_array(link.com).ravel(), float_array(link.inertia)
        R, o = poses[k, :3, :3], poses[k, :3, 3]
        c = o + R @ com
        vo, w = np.split(numeric.jacobian(robot, q, name) @ v, 2)
        vc = vo + np.cross(w, c - o)
        m, mc, p = m + mass, mc + mass * c, p + mass * vc
        k_o += R @ inertia @ R.T @ w + mass * np.cross(c, vc)
    c = mc / m
    return m, c, np.concatenate([p, k_o - np.cross(c, p)])


def robots():
    """Random floating trees, a floating tree with link frames off the joints, and random
    fixed-base trees (their base link has mass, which does not count)."""
    out = [floating_tree(seed)[0] for seed in range(4)]
    rng = np.random.default_rng(11)
    out.append(with_root_joint(random_robot(rng, n_joints=6, tree=True, frame_offsets=True), "free-flyer"))
    out += [random_robot(np.random.default_rng(20 + s), n_joints=5, tree=True) for s in range(2)]
    return out


def state(robot, rng):
    if robot.floating:
        return floating_state(robot, rng)
    return rng.uniform(-np.pi, np.pi, (3, robot.dof))


def derivative(f, robot, q, v, h: float = 1e-6):
    """d/dt f(integrate(q, t v)) at t = 0 by central differences."""
    return (f(numeric.integrate(robot, q, h * v)) - f(numeric.integrate(robot, q, -h * v))) / (2 * h)


@pytest.mark.parametrize("index", range(7))
def test_momentum_is_the_sum_of_the_links(index):
    robot = robots()[index]
    rng = np.random.default_rng(index)
    for _ in range(3):
        q, v, _ = state(robot, rng)
        m, c, h = by_links(robot, q, v)
        assert close(centroidal.center_of_mass(robot, q), c) < TOL
        A = centroidal.centroidal_momentum_matrix(robot, q)
        assert A.shape == (6, robot.nv)
        assert close(A @ v, h) < TOL
        assert close(centroidal.centroidal_momentum(robot, q, v), h) < TOL
        assert close(centroidal.com_jacobian(robot, q), A[:3] / m) < TOL


@pytest.mark.parametrize("index", range(7))
def test_rates_by_central_differences(index):
    robot = robots()[index]
    rng = np.random.default_rng(50 + index)
    q, v, _ = state(robot, rng)
    Jc = centroidal.com_jacobian(robot, q)
    assert close(Jc @ v, derivative(lambda x: centroidal.center_of_mass(robot, x), robot, q, v)) < 1e-7
    dA = derivative(lambda x: centroidal.centroidal_momentum_matrix(robot, x), robot, q, v)
    assert close(centroidal.centroidal_momentum_matrix_rate(robot, q, v), dA) < 1e-7
    assert close(centroidal.centroidal_momentum_rate(robot, q, v, np.zeros(robot.nv)), dA @ v) < 1e-7
    # the link Jacobians (world axes): the velocity of the origin and the angular velocity
    for k, link in enumerate(robot.links):
        J = numeric.jacobian(robot, q, link)
        pose = derivative(lambda x: numeric.forward_kinematics(robot, x)[k], robot, q, v)
        R = numeric.forward_kinematics(robot, q)[k, :3, :3]
        W = pose[:3, :3] @ R.T  # R' R^T = [w]x
        assert close(J @ v, np.r_[pose[:3, 3], W[2, 1], W[0, 2], W[1, 0]]) < 1e-7, link


@pytest.mark.parametrize("seed", range(4))
def test_free_flight_changes_momentum_by_gravity_alone(seed):
    robot, _, rng = floating_tree(300 + seed)
    q, v, _ = floating_state(robot, rng)
    tau = np.r_[np.zeros(6), rng.uniform(-5, 5, robot.dof)]  # joint torques are internal
    a = numeric.aba(robot, q, v, tau)
    g = np.array(robot.gravity, dtype=float).ravel()
    rate = centroidal.centroidal_momentum_rate(robot, q, v, a)
    mass = sum(float(link.mass) for link in robot.links.values())
    assert close(rate, np.r_[mass * g, np.zeros(3)]) < TOL * np.linalg.cond(numeric.crba(robot, q))


@pytest.mark.parametrize("index", range(7))
def test_energies(index):
    robot = robots()[index]
    rng = np.random.default_rng(80 + index)
    q, v, _ = state(robot, rng)
    M = numeric.crba(robot, q)
    assert close(numeric.kinetic_energy(robot, q, v), 0.5 * v @ M @ v) < TOL
    if robot.floating:
        mass, c, _ = by_links(robot, q, v)
        g = np.array(robot.gravity, dtype=float).ravel()
        assert close(numeric.potential_energy(robot, q), -mass * g @ c) < TOL


def test_jacobian_frames_relate():
    """LOCAL = R^T LOCAL_WORLD_ALIGNED; WORLD's linear rows are v - w x p."""
    robot = robots()[4]
    assert any(j.has_frame_offset for j in robot.joints), "link frames off the joints"
    q, _, _ = floating_state(robot, np.random.default_rng(1))
    poses = numeric.forward_kinematics(robot, q)
    for k, link in enumerate(robot.links):
        R, p = poses[k, :3, :3], poses[k, :3, 3]
        J = numeric.jacobian(robot, q, link)
        local = numeric.jacobian(robot, q, link, reference_frame="local")
        world = numeric.jacobian(robot, q, k, reference_frame="WORLD")
        assert close(local, np.r_[R.T @ J[:3], R.T @ J[3:]]) < TOL
        assert close(world, np.r_[J[:3] - np.cross(J[3:].T, p).T, J[3:]]) < TOL


# ------------------------------------------------------------------ batches and errors

CALLS = {
    "center_of_mass": lambda r, q, v, a, t: centroidal.center_of_mass(r, q, threads=t),
    "com_jacobian": lambda r, q, v, a, t: centroidal.com_jacobian(r, q, threads=t),
    "centroidal_momentum_matrix": lambda r, q, v, a, t: centroidal.centroidal_momentum_matrix(r, q, threads=t),
    "centroidal_momentum": lambda r, q, v, a, t: centroidal.centroidal_momentum(r, q, v, threads=t),
    "centroidal_momentum_rate": lambda r, q, v, a, t: centroidal.centroidal_momentum_rate(r, q, v, a, threads=t),
    "centroidal_momentum_matrix_rate": lambda r, q, v, a, t: centroidal.centroidal_momentum_matrix_rate(
        r, q, v, threads=t
    ),
    "forward_kinematics": lambda r, q, v, a, t: numeric.forward_kinematics(r, q, threads=t),
    "jacobian": lambda r, q, v, a, t: numeric.jacobian(r, q, 2, reference_frame="local", threads=t),
    "kinetic_energy": lambda r, q, v, a, t: numeric.kinetic_energy(r, q, v, threads=t),
    "potential_energy": lambda r, q, v, a, t: numeric.potential_energy(r, q, threads=t),
}


@pytest.mark.parametrize("threads", [None, 1, 2])
@pytest.mark.parametrize("floating", [True, False])
def test_batches_are_single_calls(threads, floating):
    robot = robots()[1 if floating else 5]
    rng = np.random.default_rng(4)
    states = [state(robot, rng) for _ in range(40)]
    Q, V, A = (np.array([s[k] for s in states]) for k in range(3))
    for name, call in CALLS.items():
        batch = call(robot, Q, V, A, threads)
        assert batch.shape[0] == len(states), name
        for k, (q, v, a) in enumerate(states):
            assert np.array_equal(batch[k], call(robot, q, v, a, None)), name


@pytest.mark.parametrize("name", CALLS)
def test_bad_input_is_refused_by_name(name):
    robot, _, rng = floating_tree(6)
    call = CALLS[name]
    q, v, a = floating_state(robot, rng)
    bad = q.copy()
    bad[3:7] *= 1.01
    with pytest.raises(ValueError, match="quaternion"):
        call(robot, bad, v, a, None)
    with pytest.raises(ValueError, match=rf"q: expected shape \({robot.nq},\)"):
        call(robot, q[7:], v, a, None)
    bad = q.copy()
    bad[-1] = np.nan
    with pytest.raises(ValueError, match="q contains NaN"):
        call(robot, bad, v, a, None)
    if name in ("centroidal_momentum", "centroidal_momentum_rate", "centroidal_momentum_matrix_rate", "kinetic_energy"):
        bad = v.copy()
        bad[0] = np.inf
        with pytest.raises(ValueError, match="contains NaN or inf"):
            call(robot, q, bad, a, None)
        with pytest.raises(ValueError, match=rf"\({robot.nv},\)"):
            call(robot, q, v[6:], a, None)
    with pytest.raises(ValueError, match="threads"):
        call(robot, q, v, a, 0)


def test_a_massless_robot_has_no_centre_of_mass():
    link = armdyn.Link("base", 0.0, [0, 0, 0], np.zeros((3, 3)).tolist())
    tip = armdyn.Link("tip", 0.0, [0, 0, 0], np.zeros((3, 3)).tolist())
    robot = armdyn.Robot("empty", [link, tip], [armdyn.Joint("j", "revolute", "base", "tip")], root_joint="free-flyer")
    q = numeric.neutral(robot)
    for call in (centroidal.center_of_mass, centroidal.com_jacobian, centroidal.centroidal_momentum_matrix):
        with pytest.raises(ValueError, match="no mass"):
            call(robot, q)


def test_unknown_frame_and_link_are_named():
    robot, _, rng = floating_tree(7)
    q, _, _ = floating_state(robot, rng)
    with pytest.raises(ValueError, match="reference_frame"):
        numeric.jacobian(robot, q, 1, reference_frame="body")
    with pytest.raises(ValueError, match="no link named 'nope'"):
        numeric.jacobian(robot, q, "nope")


def test_an_overflow_is_a_value_error():
    """Finite inputs whose products overflow: refused, never inf or NaN handed back."""
    robot, _, rng = floating_tree(8)
    q, v, a = floating_state(robot, rng)
    with pytest.raises(ValueError, match="too large"):
        centroidal.centroidal_momentum_rate(robot, q, v * 1e200, a)
    with pytest.raises(ValueError, match="overflow"):
        numeric.kinetic_energy(robot, q, v * 1e200)


def test_a_compiled_model_and_the_top_level_names():
    """The functions take a compiled model as they take the Robot; armdyn exports them."""
    robot, _, rng = floating_tree(9)
    q, v, _ = floating_state(robot, rng)
    model = numeric.compile_model(robot)
    assert np.array_equal(armdyn.center_of_mass(model, q), centroidal.center_of_mass(robot, q))
    assert np.array_equal(armdyn.centroidal_momentum(model, q, v), centroidal.centroidal_momentum(robot, q, v))
    assert np.array_equal(numeric.jacobian(model, q, 2), numeric.jacobian(robot, q, 2))
    assert set(centroidal.__all__) <= set(armdyn.__all__)
