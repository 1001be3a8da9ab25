"""A floating base (root_joint="free-flyer"): armdyn.numeric's rnea, crba and aba and
armdyn.configuration against Pinocchio (buildModelFromUrdf(path, JointModelFreeFlyer()),
which shares no code with armdyn) on the floating robots of example-robot-data, and
against identities on random floating trees:

* aba(q, v, rnea(q, v, a)) = a; M symmetric positive definite;
  rnea(q, v, a) = M a + rnea(q, v, 0);
* the joint block of M is the fixed-base M of the same tree, and with the base at rest
  the joint torques are the fixed-base ones under gravity rotated into the base frame
  (R^T g): the quaternion's rotation, checked by the fixed-base engine;
* integrate(q, difference(q, q')) = q', and difference(q, integrate(q, v)) = v.
"""

from __future__ import annotations

import warnings

import numpy as np
import pytest
from optional import example_robot_data_dir, needs_pinocchio, pin
from random_models import random_robot
from test_joints_coriolis_regressor import model_parameters

import armdyn
import armdyn.numeric as numeric
from armdyn.errors import FloatingBaseError, ModelError
from armdyn.io import with_root_joint

TOL = 1e-10

#: example-robot-data's robots that it loads with a free-flyer root (its robots_loader)
FLOATING_URDFS = {
    "solo12": "solo_description/robots/solo12.urdf",
    "solo8": "solo_description/robots/solo.urdf",
    "anymal": "anymal_b_simple_description/robots/anymal.urdf",
    "anymal_kinova": "anymal_b_simple_description/robots/anymal-kinova.urdf",
    "anymal_c": "anymal_c_simple_description/urdf/anymal.urdf",
    "talos": "talos_data/robots/talos_reduced.urdf",
    "talos_full": "talos_data/robots/talos_full_v2.urdf",
    "hyq": "hyq_description/robots/hyq_no_sensors.urdf",
    "a1": "a1_description/urdf/a1.urdf",
    "go1": "go1_description/urdf/go1.urdf",
    "go2": "go2_description/urdf/go2.urdf",
    "b1": "b1_description/urdf/b1.urdf",
    "b1_z1": "b1_description/urdf/b1-z1.urdf",
    "laikago": "laikago_description/urdf/laikago.urdf",
    "bolt": "bolt_description/robots/bolt.urdf",
    "quadruped": "quadruped_description/urdf/quadruped.urdf",
    "romeo": "romeo_description/urdf/romeo.urdf",
    "icub": "icub_description/robots/icub.urdf",
    "icub_reduced": "icub_description/robots/icub_reduced.urdf",
    "g1": "g1_description/urdf/g1_29dof_rev_1_0.urdf",
    "simple_humanoid": "simple_humanoid_description/urdf/simple_humanoid.urdf",
    "hector": "hector_description/robots/quadrotor_base.urdf",
    "iris": "iris_description/robots/iris.urdf",
    "borinot": "borinot_description/urdf/borinot_flying_arm_2.urdf",
    "hextilt": "hextilt_description/urdf/hextilt_flying_arm_5.urdf",
    "alexander": "alexander_description/urdf/alexander_v1.lowerBodyOnly.urdf",
}
#: the ones every run must load (a silent skip of all would hide the comparison)
MUST_LOAD = ("solo12", "anymal", "talos")
#: robots with mimic joints (Pinocchio reads them as independent joints, armdyn as mimics):
#: not with a floating base yet, refused by name (test_mimic_joints_on_a_floating_base_refused)
WITH_MIMICS = ("talos_full", "romeo")


def random_quaternion(rng) -> np.ndarray:
    quat = rng.standard_normal(4)
    return quat / np.linalg.norm(quat)


def floating_state(robot, rng, scale: float = 1.0):
    """Random (q, v, a) of a floating robot: any base pose, joints in [-pi, pi]."""
    q = np.concatenate([rng.uniform(-1, 1, 3), random_quaternion(rng), rng.uniform(-np.pi, np.pi, robot.dof)])
    v, a = rng.uniform(-scale, scale, (2, robot.nv))
    return q, v, a


def rotation(quat) -> np.ndarray:
    """R of the unit quaternion (x, y, z, w), written out here (not armdyn's)."""
    x, y, z, w = quat
    return np.array(
        [
            [1 - 2 * (y * y + z * z), 2 * (x * y - z * w), 2 * (x * z + y * w)],
            [2 * (x * y + z * w), 1 - 2 * (x * x + z * z), 2 * (y * z - x * w)],
            [2 * (x * z - y * w), 2 * (y * z + x * w), 1 - 2 * (x * x + y * y)],
        ]
    )


def close(a, b) -> float:
    """Relative difference; NaN never passes (NaN > tol is False, so it is checked)."""
    a, b = np.asarray(a, dtype=float), np.asarray(b, dtype=float)
    assert np.isfinite(a).all() and np.isfinite(b).all()
    return float(np.max(np.abs(a - b), initial=0.0) / max(1.0, float(np.max(np.abs(b), initial=0.0))))


# ------------------------------------------------------------------ Pinocchio


def _load_pair(name: str):
    """(armdyn robot, Pinocchio model) of an example-robot-data robot, or a skip naming
    why armdyn does not read it."""
    urdf = example_robot_data_dir() / FLOATING_URDFS[name]
    if not urdf.is_file():
        pytest.fail(f"{urdf} is missing (example-robot-data layout changed?)")
    try:
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            robot = armdyn.load(urdf, strict=False, root_joint="free-flyer").without_joint_dynamics()
            robot = robot.bind() if robot.defaults else robot
    except ModelError as err:
        if name in MUST_LOAD:
            raise
        pytest.skip(f"armdyn does not read {name}: {err}")
    assert not robot.mimic_joints, f"{name} has mimic joints: list it in WITH_MIMICS"
    model = pin.buildModelFromUrdf(str(urdf), pin.JointModelFreeFlyer())
    return robot, model


@pytest.mark.parametrize("name", WITH_MIMICS)
def test_mimic_joints_on_a_floating_base_refused(name):
    urdf = example_robot_data_dir() / FLOATING_URDFS[name]
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        robot = armdyn.load(urdf, strict=False, root_joint="free-flyer").without_joint_dynamics()
    assert robot.mimic_joints
    with pytest.raises(FloatingBaseError, match="mimic"):
        numeric.compile_model(robot.bind() if robot.defaults else robot)


def pin_arrays(model, robot, q, v, a):
    """Pinocchio's (q, v, a) for armdyn's, and the permutation of velocities: the base
    part unchanged, joints by name (a continuous joint as cos, sin in Pinocchio)."""
    qp = np.zeros(model.nq)
    perm = np.zeros(model.nv, dtype=int)
    qp[:7], perm[:6] = q[:7], np.arange(6)
    for j in range(2, model.njoints):
        k = robot.coordinate_names.index(model.names[j])
        iq, iv = model.idx_qs[j], model.idx_vs[j]
        perm[iv] = 6 + k
        if model.joints[j].nq == 2:
            qp[iq : iq + 2] = np.cos(q[7 + k]), np.sin(q[7 + k])
        else:
            qp[iq] = q[7 + k]
    return qp, v[perm], a[perm], perm


@needs_pinocchio
@pytest.mark.parametrize("name", [n for n in FLOATING_URDFS if n not in WITH_MIMICS])
def test_dynamics_agree_with_pinocchio(name):
    robot, model = _load_pair(name)
    assert robot.floating and robot.nq == 7 + robot.dof and robot.nv == 6 + robot.dof
    assert model.nv == robot.nv, "the same number of velocities"
    data = model.createData()
    rng = np.random.default_rng(len(name))
    for _ in range(3):
        q, v, a = floating_state(robot, rng)
        qp, vp, ap, perm = pin_arrays(model, robot, q, v, a)
        tau = numeric.rnea(robot, q, v, a)
        assert close(tau[perm], pin.rnea(model, data, qp, vp, ap)) < TOL, "rnea"
        M = numeric.crba(robot, q)
        Mp = pin.crba(model, data, qp)
        Mp = np.triu(Mp) + np.triu(Mp, 1).T
        assert close(M[np.ix_(perm, perm)], Mp) < TOL, "crba"
        tau2 = rng.uniform(-10, 10, robot.nv)
        acc = numeric.aba(robot, q, v, tau2)
        # 1e-10, loosened only for an ill-conditioned M (icub's reaches cond 5e9): rounding
        # in either library is amplified by cond(M) in the solve
        assert close(acc[perm], pin.aba(model, data, qp, vp, tau2[perm])) < TOL * max(1.0, np.linalg.cond(M) / 1e8), (
            "aba"
        )
        # what runs on the free-rooted model (crates/armdyn-py/src/free_root.rs)
        C = numeric.coriolis_matrix(robot, q, v)
        assert close(C[np.ix_(perm, perm)], pin.computeCoriolisMatrix(model, data, qp, vp)) < TOL, "coriolis"
        link = list(robot.links)[-1]
        pin.computeJointJacobiansTimeVariation(model, data, qp, vp)
        pin.updateFramePlacements(model, data)
        dJ = pin.getFrameJacobianTimeVariation(model, data, model.getFrameId(link), pin.LOCAL_WORLD_ALIGNED)
        assert close(numeric.jacobian_dot(robot, q, v, link)[:, perm], dJ) < TOL, "jacobian_dot"
        Y = numeric.regressor(robot, q, v, a)
        assert close(Y @ model_parameters(robot.canonical()), tau) < TOL, "regressor"


@needs_pinocchio
@pytest.mark.parametrize("name", MUST_LOAD)
def test_arrays_pass_unchanged(name):
    """solo12, anymal and talos: armdyn's q, v, a are Pinocchio's, element for element
    (the same joint order, no continuous joints), so no permutation is needed."""
    robot, model = _load_pair(name)
    assert model.nq == robot.nq and model.nv == robot.nv
    assert list(model.names)[2:] == list(robot.coordinate_names)
    data = model.createData()
    rng = np.random.default_rng(7)
    q = pin.randomConfiguration(model, -np.ones(model.nq), np.ones(model.nq))
    q[3:7] = random_quaternion(rng)
    v, a = rng.uniform(-1, 1, (2, model.nv))
    assert close(numeric.rnea(robot, q, v, a), pin.rnea(model, data, q, v, a)) < TOL
    assert close(numeric.aba(robot, q, v, a), pin.aba(model, data, q, v, a)) < TOL * 1e3


@needs_pinocchio
def test_configuration_space_agrees_with_pinocchio():
    robot, model = _load_pair("solo12")
    rng = np.random.default_rng(3)
    for scale in (1e-9, 1e-3, 1.0, 3.0):
        q0 = numeric.random_configuration(robot, rng)
        q1 = numeric.random_configuration(robot, rng)
        v = rng.uniform(-scale, scale, robot.nv)
        assert close(numeric.integrate(robot, q0, v), pin.integrate(model, q0, v)) < TOL
        assert close(numeric.difference(robot, q0, q1), pin.difference(model, q0, q1)) < TOL
    assert close(numeric.neutral(robot), pin.neutral(model)) == 0.0


# ------------------------------------------------------------------ identities


def floating_tree(seed: int):
    rng = np.random.default_rng(seed)
    fixed = random_robot(rng, n_joints=int(rng.integers(2, 9)), tree=True)
    return with_root_joint(fixed, "free-flyer"), fixed, rng


def in_fixed_order(robot, fixed) -> np.ndarray:
    """For each of ``fixed``'s coordinates, its index among ``robot``'s joints (a floating
    robot orders its joints as Pinocchio does, depth first)."""
    return np.array([list(robot.coordinate_names).index(name) for name in fixed.coordinate_names])


@pytest.mark.parametrize("seed", range(8))
def test_identities_on_random_trees(seed):
    robot, fixed, rng = floating_tree(seed)
    assert robot.floating and not fixed.floating
    for _ in range(3):
        q, v, a = floating_state(robot, rng)
        tau = numeric.rnea(robot, q, v, a)
        M = numeric.crba(robot, q)
        assert close(M, M.T) == 0.0
        assert np.linalg.eigvalsh(M).min() > 0
        assert close(tau, M @ a + numeric.rnea(robot, q, v, np.zeros(robot.nv))) < TOL
        assert close(numeric.aba(robot, q, v, tau), a) < TOL * np.linalg.cond(M)
        # the joint block: the fixed-base M of the same tree (it does not see the base)
        k = in_fixed_order(robot, fixed)
        assert close(M[6:, 6:][np.ix_(k, k)], numeric.crba(fixed, q[7:][k])) < TOL


@pytest.mark.parametrize("seed", range(4))
def test_base_at_rest_is_the_fixed_base_under_rotated_gravity(seed):
    robot, fixed, rng = floating_tree(100 + seed)
    q, v, a = floating_state(robot, rng)
    v[:6] = a[:6] = 0.0
    g = np.array(robot.gravity, dtype=float).ravel()
    R = rotation(q[3:7])
    tilted = armdyn.Robot(fixed.name, fixed.links.values(), fixed.joints, tuple(R.T @ g), base=fixed.base)
    tau = numeric.rnea(robot, q, v, a)
    k = in_fixed_order(robot, fixed)
    assert close(tau[6:][k], numeric.rnea(tilted, q[7:][k], v[6:][k], a[6:][k])) < TOL


@pytest.mark.parametrize("seed", range(4))
def test_integrate_and_difference_are_inverse(seed):
    robot, _, rng = floating_tree(200 + seed)
    for scale in (0.0, 1e-7, 0.5, 3.0):
        q0 = numeric.random_configuration(robot, rng)
        q1 = numeric.random_configuration(robot, rng)
        d = numeric.difference(robot, q0, q1)
        q1b = numeric.integrate(robot, q0, d)
        # the same configuration; a quaternion and its negative are one rotation
        sign = np.sign(np.dot(q1b[3:7], q1[3:7]))
        assert close(q1b[:3], q1[:3]) < TOL and close(sign * q1b[3:7], q1[3:7]) < TOL and close(q1b[7:], q1[7:]) < TOL
        v = rng.uniform(-scale, scale, robot.nv)
        v[3:6] *= 0.5  # a rotation under pi, where the logarithm is the inverse
        assert close(numeric.difference(robot, q0, numeric.integrate(robot, q0, v)), v) < TOL
    # batches: row by row
    qs = np.array([numeric.random_configuration(robot, rng) for _ in range(3)])
    vs = rng.uniform(-1, 1, (3, robot.nv))
    out = numeric.integrate(robot, qs, vs)
    assert all(close(out[k], numeric.integrate(robot, qs[k], vs[k])) == 0.0 for k in range(3))


def test_one_free_body_mass_matrix_by_hand():
    """A robot of one link and a massless child on a fixed joint: M is the body's
    spatial inertia about the base origin, [[m 1, -m c^x], [m c^x, I_c - m c^x c^x]]."""
    m, c = 2.0, np.array([0.1, -0.2, 0.3])
    Ic = np.array([[0.3, 0.01, 0.02], [0.01, 0.4, 0.03], [0.02, 0.03, 0.5]])
    robot = armdyn.Robot(
        "body",
        [
            armdyn.Link("base", m, c.tolist(), Ic.tolist()),
            armdyn.Link("tip", 0.0, [0, 0, 0], np.zeros((3, 3)).tolist()),
        ],
        [armdyn.Joint("weld", "fixed", "base", "tip")],
        root_joint="free-flyer",
    )
    cx = np.array([[0, -c[2], c[1]], [c[2], 0, -c[0]], [-c[1], c[0], 0]])
    expected = np.block([[m * np.eye(3), -m * cx], [m * cx, Ic - m * cx @ cx]])
    q = numeric.neutral(robot)
    assert close(numeric.crba(robot, q), expected) < 1e-14
    # free fall: no wrench, the body accelerates at g (world), w = 0: a_lin = R^T g
    rng = np.random.default_rng(0)
    q[3:7] = random_quaternion(rng)
    acc = numeric.aba(robot, q, np.zeros(6), np.zeros(6))
    R = rotation(q[3:7])
    # the acceleration of the base origin when the body does not rotate: R^T g
    assert close(acc[:3], R.T @ np.array([0, 0, -9.81])) < 1e-12 and close(acc[3:], np.zeros(3)) < 1e-12


# ------------------------------------------------------------------ errors


def test_a_quaternion_not_unit_is_refused():
    robot, _, rng = floating_tree(1)
    q, v, a = floating_state(robot, rng)
    q[3:7] *= 1.01
    for call in (
        lambda: numeric.rnea(robot, q, v, a),
        lambda: numeric.crba(robot, q),
        lambda: numeric.aba(robot, q, v, a),
        lambda: numeric.integrate(robot, q, v),
    ):
        with pytest.raises(ValueError, match="quaternion"):
            call()


def test_shapes_are_named():
    robot, _, rng = floating_tree(2)
    q, v, a = floating_state(robot, rng)
    with pytest.raises(ValueError, match=rf"\({robot.nq},\)"):
        numeric.rnea(robot, q[7:], v, a)
    with pytest.raises(ValueError, match="qd"):
        numeric.rnea(robot, q, v[6:], a)


@pytest.mark.parametrize("threads", [None, 1, 2])
def test_batches_are_single_calls(threads):
    """Batches (SIMD lanes, leftover rows alone, threads) equal single calls bit for bit."""
    robot, _, rng = floating_tree(3)
    states = [floating_state(robot, rng) for _ in range(11)]
    Q, V, A = (np.array([s[k] for s in states]) for k in range(3))
    tau = numeric.rnea(robot, Q, V, A, threads=threads)
    M = numeric.crba(robot, Q, threads=threads)
    acc = numeric.aba(robot, Q, V, tau, threads=threads)
    for k, (q, v, a) in enumerate(states):
        assert np.array_equal(tau[k], numeric.rnea(robot, q, v, a))
        assert np.array_equal(M[k], numeric.crba(robot, q))
        assert np.array_equal(acc[k], numeric.aba(robot, q, v, tau[k]))


@pytest.mark.parametrize(
    "call",
    [
        lambda r, q, v: armdyn.derive(r, "lagrange"),
        lambda r, q, v: armdyn.prove_agreement(r),
        lambda r, q, v: armdyn.codegen(r, what="C"),  # the rest: test_codegen_floating.py
        lambda r, q, v: __import__("armdyn.identification", fromlist=["x"]).base_parameters(r),
        lambda r, q, v: __import__("armdyn.identification", fromlist=["x"]).regressor(r),
    ],
)
def test_unsupported_functions_say_so(call):
    robot, _, rng = floating_tree(4)
    q, v, _ = floating_state(robot, rng)
    with pytest.raises(FloatingBaseError, match="floating base"):
        call(robot, q, v)


def test_a_compiled_floating_model_pickles():
    import pickle

    robot, _, rng = floating_tree(6)
    q, v, a = floating_state(robot, rng)
    model = pickle.loads(pickle.dumps(numeric.compile_model(robot)))
    assert model.floating and model.nq == robot.nq and model.nv == robot.nv
    assert np.array_equal(model.rnea(q, v, a), numeric.rnea(robot, q, v, a))


def test_root_joint_is_checked_and_kept():
    robot, fixed, _ = floating_tree(5)
    with pytest.raises(ModelError, match="root_joint"):
        with_root_joint(fixed, "planar")
    assert robot.canonical().floating and robot.bind().floating
    assert not fixed.floating and fixed.nq == fixed.nv == fixed.dof
    assert "free-flyer" in repr(robot)
