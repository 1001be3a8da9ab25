"""Derivatives of the floating-base dynamics (root_joint="free-flyer"): armdyn.numeric's
rnea_derivatives, aba_derivatives and minverse on Pinocchio's tangent space, where d/dq
is the derivative along ``configuration.integrate(q, dq)`` at dq = 0 (every matrix is
(nv, nv), nv = 6 + dof):

* against Pinocchio (computeRNEADerivatives, computeABADerivatives, computeMinverse on
  buildModelFromUrdf(path, JointModelFreeFlyer()), which shares no code with armdyn) on
  the floating robots of example-robot-data;
* against central finite differences of armdyn.rnea and armdyn.aba along
  configuration.integrate (and along v), on those robots with their joint friction and
  on random floating trees; dtau/da is crba, dqdd/dtau = M^-1 = inv(crba);
* wrenches in the link frames (f_ext) against Pinocchio's fext; those fixed in space and
  bad quaternions are refused; batches (SIMD lanes, leftover rows, threads, out=) equal
  single calls bit for bit.
"""

from __future__ import annotations

import warnings

import numpy as np
import pytest
from optional import example_robot_data_dir, needs_pinocchio, pin
from test_floating import FLOATING_URDFS, MUST_LOAD, WITH_MIMICS, _load_pair, close, floating_state, floating_tree

import armdyn
import armdyn.numeric as numeric

TOL = 1e-10
#: finite differences: central, step EPS; their error is O(EPS^2) plus rounding / EPS
EPS = 1e-6
FD_TOL = 1e-6


def sym(A) -> np.ndarray:
    """Pinocchio fills the upper triangle of M and M^-1."""
    A = np.asarray(A)
    return np.triu(A) + np.triu(A, 1).T


def pin_state(model, robot, q, v, x):
    """Pinocchio's (q, v, x) and the velocity permutation (test_floating.pin_arrays)."""
    from test_floating import pin_arrays

    return pin_arrays(model, robot, q, v, x)


# ------------------------------------------------------------------ Pinocchio


@needs_pinocchio
@pytest.mark.parametrize("name", [n for n in FLOATING_URDFS if n not in WITH_MIMICS])
def test_derivatives_agree_with_pinocchio(name):
    robot, model = _load_pair(name)
    data = model.createData()
    rng = np.random.default_rng(10 + len(name))
    for _ in range(2):
        q, v, a = floating_state(robot, rng)
        qp, vp, ap, perm = pin_state(model, robot, q, v, a)
        P = np.ix_(perm, perm)
        dq, dv, M = numeric.rnea_derivatives(robot, q, v, a)
        assert dq.shape == dv.shape == M.shape == (robot.nv, robot.nv)
        pdq, pdv, pda = pin.computeRNEADerivatives(model, data, qp, vp, ap)
        assert close(dq[P], pdq) < TOL, "dtau_dq"
        assert close(dv[P], pdv) < TOL, "dtau_dv"
        assert close(M[P], sym(pda)) < TOL, "M"
        tau = rng.uniform(-10, 10, robot.nv)
        Adq, Adv, Minv = numeric.aba_derivatives(robot, q, v, tau)
        qdq, qdv, qmi = pin.computeABADerivatives(model, data, qp, vp, tau[perm])
        # rounding is amplified by cond(M): Pinocchio multiplies by its M^-1 (icub's
        # M reaches cond 1e8, where its dqdd_dq is off by 1e-9 of the largest entry
        # from numpy's solve with iterative refinement, and armdyn's by 4e-13)
        tol = TOL * max(1.0, np.linalg.cond(M) / 1e6)
        assert close(Adq[P], qdq) < tol, "dqdd_dq"
        assert close(Adv[P], qdv) < tol, "dqdd_dv"
        assert close(Minv[P], sym(qmi)) < tol, "Minv"
        assert close(numeric.minverse(robot, q)[P], sym(pin.computeMinverse(model, data, qp))) < tol, "minverse"


@needs_pinocchio
@pytest.mark.parametrize("name", MUST_LOAD)
def test_gravity_bias_and_gravity_derivatives_agree_with_pinocchio(name):
    """g(q), h(q, v) and dg/dq on the tangent space against computeGeneralizedGravity,
    nonLinearEffects and computeGeneralizedGravityDerivatives; one state and a batch."""
    robot, model = _load_pair(name)
    data = model.createData()
    rng = np.random.default_rng(21)
    Q, V = [], []
    for _ in range(3):
        q, v, _ = floating_state(robot, rng)
        qp, vp, _, perm = pin_state(model, robot, q, v, v)
        P = np.ix_(perm, perm)
        g = numeric.gravity(robot, q)
        assert g.shape == (robot.nv,) and close(g[perm], pin.computeGeneralizedGravity(model, data, qp)) < TOL
        assert close(numeric.bias(robot, q, v)[perm], pin.nonLinearEffects(model, data, qp, vp)) < TOL
        dg = numeric.gravity_derivatives(robot, q)
        assert close(dg[P], pin.computeGeneralizedGravityDerivatives(model, data, qp)) < TOL
        Q.append(q)
        V.append(v)
    Q, V = np.array(Q), np.array(V)
    assert np.array_equal(numeric.gravity(robot, Q)[1], numeric.gravity(robot, Q[1]))
    assert np.array_equal(numeric.bias(robot, Q, V)[2], numeric.bias(robot, Q[2], V[2]))
    assert np.array_equal(numeric.gravity_derivatives(robot, Q)[0], numeric.gravity_derivatives(robot, Q[0]))


@needs_pinocchio
@pytest.mark.parametrize("name", MUST_LOAD)
def test_arrays_pass_unchanged(name):
    """solo12, anymal, talos: Pinocchio's arrays as they are, large velocities."""
    robot, model = _load_pair(name)
    data = model.createData()
    rng = np.random.default_rng(5)
    q, v, a = floating_state(robot, rng, scale=20.0)
    dq, dv, M = numeric.rnea_derivatives(robot, q, v, a)
    pdq, pdv, pda = pin.computeRNEADerivatives(model, data, q, v, a)
    assert close(dq, pdq) < TOL and close(dv, pdv) < TOL and close(M, sym(pda)) < TOL


# ------------------------------------------------------------------ finite differences


def fd_columns(f, robot, q, v, x, eps=EPS):
    """Central differences of ``f(q, v, x)`` (rows of a batch) along integrate(q, eps e_i)
    and along v + eps e_i: (d/dq, d/dv), each (nv, nv), column i."""
    nv = robot.nv
    E = np.eye(nv) * eps
    Q = np.concatenate(
        [numeric.integrate(robot, np.tile(q, (nv, 1)), E), numeric.integrate(robot, np.tile(q, (nv, 1)), -E)]
    )
    V = np.concatenate([v + E, v - E])
    rows = f(Q, np.tile(v, (2 * nv, 1)), np.tile(x, (2 * nv, 1)))
    d_dq = (rows[:nv] - rows[nv:]).T / (2 * eps)
    rows = f(np.tile(q, (2 * nv, 1)), V, np.tile(x, (2 * nv, 1)))
    d_dv = (rows[:nv] - rows[nv:]).T / (2 * eps)
    return d_dq, d_dv


def check_against_finite_differences(robot, q, v, a):
    dq, dv, M = numeric.rnea_derivatives(robot, q, v, a)
    fq, fv = fd_columns(lambda Q, V, A: numeric.rnea(robot, Q, V, A), robot, q, v, a)
    assert close(dq, fq) < FD_TOL, "dtau_dq"
    assert close(dv, fv) < FD_TOL, "dtau_dv"
    assert close(M, numeric.crba(robot, q)) < 1e-12, "dtau_da = crba"
    tau = numeric.rnea(robot, q, v, a)
    Adq, Adv, Minv = numeric.aba_derivatives(robot, q, v, tau)
    cond = np.linalg.cond(M)
    gq, gv = fd_columns(lambda Q, V, T: numeric.aba(robot, Q, V, T), robot, q, v, tau)
    assert close(Adq, gq) < FD_TOL * max(1.0, cond / 1e4), "dqdd_dq"
    assert close(Adv, gv) < FD_TOL * max(1.0, cond / 1e4), "dqdd_dv"
    assert close(Minv @ M, np.eye(robot.nv)) < 1e-12 * cond, "Minv = inv(crba)"
    assert close(numeric.minverse(robot, q), Minv) < 1e-12 * cond


@pytest.mark.parametrize("name", MUST_LOAD)
def test_finite_differences_on_example_robots(name):
    """With the URDF's joint friction (talos: damping and Coulomb friction)."""
    urdf = example_robot_data_dir() / FLOATING_URDFS[name]
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        robot = armdyn.load(urdf, strict=False, root_joint="free-flyer")
    rng = np.random.default_rng(1)
    check_against_finite_differences(robot, *floating_state(robot, rng))


@pytest.mark.parametrize("seed", range(6))
def test_finite_differences_on_random_trees(seed):
    robot, _, rng = floating_tree(300 + seed)
    for _ in range(2):
        check_against_finite_differences(robot, *floating_state(robot, rng))


def test_a_free_body_in_free_fall():
    """One rigid body: with zero wrench it falls at g, so dqdd/dq is the derivative of
    the base-frame gravity R^T g along the base's own rotation (d(R^T g)/dtheta_k =
    -e_k x (R^T g)... written out here by hand) and 0 along its translation; and
    dqdd/dv of a body spinning about a principal axis is Euler's equations'."""
    m, Ic = 2.0, np.diag([0.3, 0.4, 0.5])
    robot = armdyn.Robot(
        "body",
        [armdyn.Link("base", m, [0, 0, 0], Ic.tolist()), armdyn.Link("tip", 0.0, [0, 0, 0], np.zeros((3, 3)).tolist())],
        [armdyn.Joint("weld", "fixed", "base", "tip")],
        root_joint="free-flyer",
    )
    rng = np.random.default_rng(0)
    q = numeric.random_configuration(robot, rng)
    dq, dv, Minv = numeric.aba_derivatives(robot, q, np.zeros(6), np.zeros(6))
    from test_floating import rotation

    gb = rotation(q[3:7]).T @ np.array(robot.gravity, dtype=float).ravel()
    # R(theta) = R exp(theta^): R^T g turns by -theta x, so d(R^T g)/dtheta_k = (R^T g) x e_k
    expected = np.zeros((6, 6))
    expected[:3, 3:] = np.array([np.cross(gb, e) for e in np.eye(3)]).T
    assert close(dq, expected) < 1e-12
    assert close(Minv, np.diag([1 / m] * 3 + list(1 / np.diag(Ic)))) < 1e-12
    # Euler: I wd + w x I w = 0; at w = (0, 0, s) the linearisation's angular block
    s = 1.5
    v = np.array([0, 0, 0, 0, 0, s])
    _, dv, _ = numeric.aba_derivatives(robot, q, v, np.zeros(6))
    I1, I2, I3 = np.diag(Ic)
    ang = np.array([[0, -(I3 - I2) * s / I1, 0], [-(I1 - I3) * s / I2, 0, 0], [0, 0, 0]])
    assert close(dv[3:, 3:], ang) < 1e-12


# ------------------------------------------------------------------ batches and errors


@pytest.mark.parametrize("threads", [None, 1, 2])
def test_batches_are_single_calls(threads):
    robot, _, rng = floating_tree(3)
    states = [floating_state(robot, rng) for _ in range(11)]
    Q, V, A = (np.array([s[k] for s in states]) for k in range(3))
    rd = numeric.rnea_derivatives(robot, Q, V, A, threads=threads)
    ad = numeric.aba_derivatives(robot, Q, V, A, threads=threads)
    mi = numeric.minverse(robot, Q, threads=threads)
    assert rd[0].shape == (11, robot.nv, robot.nv)
    for k, (q, v, a) in enumerate(states):
        assert all(np.array_equal(x[k], y) for x, y in zip(rd, numeric.rnea_derivatives(robot, q, v, a)))
        assert all(np.array_equal(x[k], y) for x, y in zip(ad, numeric.aba_derivatives(robot, q, v, a)))
        assert np.array_equal(mi[k], numeric.minverse(robot, q))


def test_out_arrays_and_compiled_models():
    robot, _, rng = floating_tree(7)
    q, v, a = floating_state(robot, rng)
    out = tuple(np.empty((robot.nv, robot.nv)) for _ in range(3))
    got = numeric.rnea_derivatives(robot, q, v, a, out=out)
    assert all(g is o for g, o in zip(got, out))
    model = numeric.compile_model(robot)
    assert all(np.array_equal(x, y) for x, y in zip(out, numeric.rnea_derivatives(model, q, v, a)))
    with pytest.raises(ValueError, match="shape"):
        numeric.aba_derivatives(robot, q, v, a, out=tuple(np.empty((robot.dof, robot.dof)) for _ in range(3)))


def pin_wrenches(model, robot, W):
    """armdyn's (nlinks, 6) link-frame wrenches as Pinocchio's per-joint forces: each moved
    from its link's frame to its joint's by the frame placement (the free flyer, joint 1,
    takes the base link's and those welded to it)."""
    fext = [pin.Force.Zero() for _ in range(model.njoints)]
    for k, link in enumerate(robot.links):
        frame = model.frames[model.getFrameId(link)]
        fext[frame.parentJoint] = fext[frame.parentJoint] + frame.placement.act(pin.Force(W[k, :3], W[k, 3:]))
    return fext


@needs_pinocchio
@pytest.mark.parametrize("name", MUST_LOAD)
def test_link_frame_wrenches_agree_with_pinocchio(name):
    """f_ext in the link frames (Pinocchio's fext): tau = rnea - sum J^T w; batches too."""
    robot, model = _load_pair(name)
    data = model.createData()
    rng = np.random.default_rng(21)
    states = [floating_state(robot, rng) for _ in range(5)]
    W = rng.uniform(-20, 20, (5, len(robot.links), 6))
    for k, (q, v, a) in enumerate(states):
        fext = pin_wrenches(model, robot, W[k])
        dq, dv, M = numeric.rnea_derivatives(robot, q, v, a, W[k])
        pdq, pdv, pda = pin.computeRNEADerivatives(model, data, q, v, a, fext)
        assert close(dq, pdq) < TOL and close(dv, pdv) < TOL and close(M, sym(pda)) < TOL
        Adq, Adv, Minv = numeric.aba_derivatives(robot, q, v, a, W[k])
        qdq, qdv, qmi = pin.computeABADerivatives(model, data, q, v, a, fext)
        tol = TOL * max(1.0, np.linalg.cond(M) / 1e6)
        assert close(Adq, qdq) < tol and close(Adv, qdv) < tol and close(Minv, sym(qmi)) < tol
    Q, V, A = (np.array([s[j] for s in states]) for j in range(3))
    batch = numeric.aba_derivatives(robot, Q, V, A, W, threads=2)
    for k in range(5):
        single = numeric.aba_derivatives(robot, Q[k], V[k], A[k], W[k])
        assert all(np.array_equal(b[k], x) for b, x in zip(batch, single))


def test_wrenches_fixed_in_space_are_refused():
    robot, _, rng = floating_tree(8)
    q, v, a = floating_state(robot, rng)
    f_ext = np.zeros((len(robot.links), 6))
    for call in (numeric.rnea_derivatives, numeric.aba_derivatives):
        with pytest.raises(NotImplementedError, match="frame='local'"):
            call(robot, q, v, a, f_ext, "world")
        with pytest.raises(ValueError, match="f_ext"):
            call(robot, q, v, a, f_ext[1:])


def test_bad_states_are_refused():
    robot, _, rng = floating_tree(9)
    q, v, a = floating_state(robot, rng)
    bad = q.copy()
    bad[3:7] *= 1.01
    for call in (
        lambda: numeric.rnea_derivatives(robot, bad, v, a),
        lambda: numeric.aba_derivatives(robot, bad, v, a),
        lambda: numeric.minverse(robot, bad),
    ):
        with pytest.raises(ValueError, match="quaternion"):
            call()
    with pytest.raises(ValueError, match=rf"\({robot.nq},\)"):
        numeric.rnea_derivatives(robot, q[7:], v, a)
    with pytest.raises(ValueError, match="qd"):
        numeric.aba_derivatives(robot, q, v[6:], a)
    nan = v.copy()
    nan[0] = np.nan
    with pytest.raises(ValueError, match="NaN"):
        numeric.rnea_derivatives(robot, q, nan, a)
