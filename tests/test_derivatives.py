"""Derivatives of the dynamics, M^-1, dg/dq, dJ/dt and external forces (armdyn.numeric,
the Rust core) against second opinions:

* Pinocchio (computeRNEADerivatives, computeABADerivatives, computeMinverse,
  computeGeneralizedGravityDerivatives, getFrameJacobianTimeVariation, rnea/aba with
  fext) to 1e-10 relative, on every bundled arm and on 50 random chains and trees with
  mixed revolute/prismatic/fixed joints;
* armdyn.reference: forward-mode differentiation of RBDA's tables (a different
  algorithm from the core's Carpentier-Mansard recursions), the same tolerance;
* central differences of the core's existing rnea/aba/jacobian (about 1e-7);
* identities: M Minv = I; dqdd/dq = -Minv dtau/dq at qdd = aba(q, qd, tau) (computed
  here from rnea_derivatives and minverse; note that aba_derivatives is built on this
  identity, so for it the checks that count are Pinocchio, the reference and the
  finite differences);
* batches equal loops of single calls bit for bit, on 1 and 2 threads;
* bad input gives ValueError naming the argument.
"""

from __future__ import annotations

import warnings

import numpy as np
import pytest
from random_models import random_robot, random_state

import armdyn
from armdyn import numeric as num
from armdyn import reference as ref

RTOL = 1e-10


def assert_rel(actual, expected, rtol=RTOL, what="", scale=None):
    """max |actual - expected| <= rtol * scale (scale: max |expected| unless given); both finite."""
    actual, expected = np.asarray(actual, dtype=float), np.asarray(expected, dtype=float)
    assert actual.shape == expected.shape, (what, actual.shape, expected.shape)
    assert np.all(np.isfinite(actual)) and np.all(np.isfinite(expected)), f"{what}: not finite"
    scale = max(np.max(np.abs(expected)) if scale is None else scale, 1e-300)
    err = np.max(np.abs(actual - expected)) / scale
    assert err <= rtol, f"{what}: relative error {err:.2e} > {rtol:.0e}"


@pytest.fixture(scope="module")
def pin_bridge():
    pytest.importorskip("pinocchio")
    from pinocchio_derivatives import PinocchioDerivatives

    return PinocchioDerivatives


def _bundled_robots():
    out = []
    rng = np.random.default_rng(5)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", UserWarning)
        for entry in armdyn.bundled_robots():
            robot = armdyn.load(entry["name"], strict=False)
            missing = sorted(set(robot.parameters) - set(robot.defaults))
            out.append((entry["name"], robot.bind({k: rng.uniform(0.5, 1.5) for k in missing})))
    return out


BUNDLED = _bundled_robots()


def _random_robots(count=50, seed=900):
    """`count` random robots: even ones branched trees, odd ones chains; 3..10 joints,
    mixed revolute (R), prismatic (P) and fixed (F)."""
    rng = np.random.default_rng(seed)
    return [random_robot(rng, n_joints=int(rng.integers(3, 11)), tree=k % 2 == 0, kinds="RRPF") for k in range(count)]


RANDOM = _random_robots()
ALL = [(name, r) for name, r in BUNDLED] + [(f"random{k}", r) for k, r in enumerate(RANDOM)]
assert len(RANDOM) == 50 and len(BUNDLED) >= 5


def _states(robot, seed, count=2):
    rng = np.random.default_rng(seed)
    return [tuple(random_state(rng, robot.dof) for _ in range(3)) for _ in range(count)]


def _scales(robot, q, qd, expected, kind):
    """Natural sizes of the three outputs: a derivative may vanish identically (dtau/dqd of
    a joint on the base about its own axis is 0, rounding aside), so each is compared to
    max(its largest entry, |M| |qd| for dtau/dqd, or |Minv| |M| |qd| for dqdd/dqd)."""
    M, Minv = num.crba(robot, q), num.minverse(robot, q)
    v = np.max(np.abs(M)) * max(np.max(np.abs(qd)), 1.0)
    if kind == "aba":
        v *= np.max(np.abs(Minv))
    return [max(np.max(np.abs(e)), v) for e in expected]


def _jd_scale(Jd, qd):
    """dJ/dt vanishes for links near the base (or moved by prismatic joints only): compare
    it to its natural size, |qd| (times the arms' lengths, of order 1 m)."""
    return max(np.max(np.abs(Jd)), np.max(np.abs(qd)))


def _wrenches(robot, rng):
    return rng.uniform(-5.0, 5.0, size=(len(robot.links), 6))


# ------------------------------------------------------------------ against Pinocchio


@pytest.mark.parametrize("name, robot", ALL, ids=[a for a, _ in ALL])
def test_against_pinocchio(name, robot, pin_bridge):
    P = pin_bridge(robot)
    rng = np.random.default_rng(31)
    for q, qd, x in _states(robot, 17):
        mine = num.rnea_derivatives(robot, q, qd, x)
        theirs = P.rnea_derivatives(q, qd, x)
        for a, b, what, sc in zip(mine, theirs, ("dtau_dq", "dtau_dqd", "M"), _scales(robot, q, qd, theirs, "rnea")):
            assert_rel(a, b, what=f"{name} rnea {what}", scale=sc)
        assert_rel(mine[2], num.crba(robot, q), 1e-12, what=f"{name} M = crba")
        mine = num.aba_derivatives(robot, q, qd, x)
        theirs = P.aba_derivatives(q, qd, x)
        for a, b, what, sc in zip(mine, theirs, ("dqdd_dq", "dqdd_dqd", "Minv"), _scales(robot, q, qd, theirs, "aba")):
            assert_rel(a, b, what=f"{name} aba {what}", scale=sc)
        assert_rel(num.minverse(robot, q), P.minverse(q), what=f"{name} minverse")
        assert_rel(num.gravity_derivatives(robot, q), P.gravity_derivatives(q), what=f"{name} dg/dq")
        for link in robot.links:
            Jd = P.jacobian_dot(q, qd, link)
            assert_rel(
                num.jacobian_dot(robot, q, qd, link), Jd, what=f"{name} jacobian_dot {link}", scale=_jd_scale(Jd, qd)
            )
        # external wrenches in link frames (Pinocchio's fext move with the joints)
        W = _wrenches(robot, rng)
        assert_rel(num.rnea(robot, q, qd, x, f_ext=W), P.rnea_ext(q, qd, x, W), what=f"{name} rnea f_ext")
        assert_rel(num.aba(robot, q, qd, x, f_ext=W), P.aba_ext(q, qd, x, W), what=f"{name} aba f_ext")
        assert_rel(
            num.rnea(robot, q, qd, x, f_ext=W, frame="world"),
            P.rnea_ext(q, qd, x, W, "world"),
            what=f"{name} rnea f_ext world",
        )
        assert_rel(
            num.aba(robot, q, qd, x, f_ext=W, frame="world"),
            P.aba_ext(q, qd, x, W, "world"),
            what=f"{name} aba f_ext world",
        )
        mine = num.rnea_derivatives(robot, q, qd, x, f_ext=W)
        theirs = P.rnea_derivatives(q, qd, x, W)
        for a, b, what, sc in zip(mine, theirs, ("dtau_dq", "dtau_dqd", "M"), _scales(robot, q, qd, theirs, "rnea")):
            assert_rel(a, b, what=f"{name} rnea f_ext {what}", scale=sc)
        mine = num.aba_derivatives(robot, q, qd, x, f_ext=W)
        theirs = P.aba_derivatives(q, qd, x, W)
        for a, b, what, sc in zip(mine, theirs, ("dqdd_dq", "dqdd_dqd", "Minv"), _scales(robot, q, qd, theirs, "aba")):
            assert_rel(a, b, what=f"{name} aba f_ext {what}", scale=sc)


# ------------------------------------------------------------------ against the reference


REF_CASES = ALL[::3]  # the NumPy oracle is slow: every third robot


@pytest.mark.parametrize("name, robot", REF_CASES, ids=[a for a, _ in REF_CASES])
def test_against_reference(name, robot):
    rng = np.random.default_rng(41)
    ((q, qd, x),) = _states(robot, 23, count=1)
    W = _wrenches(robot, rng)
    for frame in ("local", "world"):
        for f_ext in (None, W):
            mine = num.rnea_derivatives(robot, q, qd, x, f_ext=f_ext, frame=frame)
            theirs = ref.rnea_derivatives(robot, q, qd, x, f_ext, frame)
            for a, b, what, sc in zip(
                mine, theirs, ("dtau_dq", "dtau_dqd", "M"), _scales(robot, q, qd, theirs, "rnea")
            ):
                assert_rel(a, b, what=f"{name} rnea {what} {frame} {f_ext is not None}", scale=sc)
            mine = num.aba_derivatives(robot, q, qd, x, f_ext=f_ext, frame=frame)
            theirs = ref.aba_derivatives(robot, q, qd, x, f_ext, frame)
            for a, b, what, sc in zip(
                mine, theirs, ("dqdd_dq", "dqdd_dqd", "Minv"), _scales(robot, q, qd, theirs, "aba")
            ):
                assert_rel(a, b, what=f"{name} aba {what} {frame} {f_ext is not None}", scale=sc)
        assert_rel(
            num.rnea(robot, q, qd, x, f_ext=W, frame=frame),
            ref.rnea_ext(robot, q, qd, x, W, frame),
            what=f"{name} rnea f_ext {frame}",
        )
        assert_rel(
            num.aba(robot, q, qd, x, f_ext=W, frame=frame),
            ref.aba_ext(robot, q, qd, x, W, frame),
            what=f"{name} aba f_ext {frame}",
        )
    assert_rel(num.minverse(robot, q), ref.minverse(robot, q), what=f"{name} minverse")
    assert_rel(num.gravity_derivatives(robot, q), ref.gravity_derivatives(robot, q), what=f"{name} dg/dq")
    for link in robot.links:
        Jd = ref.jacobian_dot(robot, q, qd, link)
        assert_rel(
            num.jacobian_dot(robot, q, qd, link), Jd, what=f"{name} jacobian_dot {link}", scale=_jd_scale(Jd, qd)
        )


# ------------------------------------------------------------------ finite differences, identities

FD_CASES = ALL[::5]


def _central(f, x, h=1e-6):
    """Central differences of f (returning an (m,) or (6, n) array) along each coordinate of x:
    an array with the coordinate as the last axis."""
    cols = []
    for e in np.eye(len(x)):
        cols.append((np.asarray(f(x + h * e)) - np.asarray(f(x - h * e))) / (2 * h))
    return np.stack(cols, axis=-1)


@pytest.mark.parametrize("name, robot", FD_CASES, ids=[a for a, _ in FD_CASES])
def test_against_central_differences(name, robot):
    rng = np.random.default_rng(53)
    ((q, qd, x),) = _states(robot, 29, count=1)
    W = _wrenches(robot, rng)
    tol = 1e-6
    for frame in ("local", "world"):
        for f_ext in (None, W):
            kw = {"f_ext": f_ext, "frame": frame}
            mine = num.rnea_derivatives(robot, q, qd, x, **kw)
            fd = (
                _central(lambda y: num.rnea(robot, y, qd, x, **kw), q),
                _central(lambda y: num.rnea(robot, q, y, x, **kw), qd),
                _central(lambda y: num.rnea(robot, q, qd, y, **kw), x),
            )
            for a, b, what, sc in zip(mine, fd, ("dtau_dq", "dtau_dqd", "M"), _scales(robot, q, qd, fd, "rnea")):
                assert_rel(a, b, tol, f"{name} {what} {frame}", scale=sc)
            mine = num.aba_derivatives(robot, q, qd, x, **kw)
            fd = (
                _central(lambda y: num.aba(robot, y, qd, x, **kw), q),
                _central(lambda y: num.aba(robot, q, y, x, **kw), qd),
                _central(lambda y: num.aba(robot, q, qd, y, **kw), x),
            )
            for a, b, what, sc in zip(mine, fd, ("dqdd_dq", "dqdd_dqd", "Minv"), _scales(robot, q, qd, fd, "aba")):
                assert_rel(a, b, tol, f"{name} {what} {frame}", scale=sc)
    assert_rel(num.gravity_derivatives(robot, q), _central(lambda y: num.gravity(robot, y), q), tol, f"{name} dg/dq")
    for link in robot.links:
        fd = _central(lambda t: num.jacobian(robot, q + t[0] * qd, link), np.zeros(1))[..., 0]
        assert_rel(
            num.jacobian_dot(robot, q, qd, link), fd, tol, f"{name} jacobian_dot {link}", scale=_jd_scale(fd, qd)
        )


@pytest.mark.parametrize("name, robot", ALL[::4], ids=[a for a, _ in ALL[::4]])
def test_identities(name, robot):
    n = robot.dof
    for q, qd, tau in _states(robot, 37):
        Minv = num.minverse(robot, q)
        M = num.crba(robot, q)
        assert_rel(M @ Minv, np.eye(n), 1e-10, what=f"{name} M Minv = I", scale=1.0)
        assert_rel(Minv, Minv.T, 1e-14, what=f"{name} Minv symmetric")
        qdd = num.aba(robot, q, qd, tau)
        dtau_dq, dtau_dqd, _ = num.rnea_derivatives(robot, q, qd, qdd)
        dqdd_dq, dqdd_dqd, Minv2 = num.aba_derivatives(robot, q, qd, tau)
        sc = _scales(robot, q, qd, (dqdd_dq, dqdd_dqd), "aba")
        assert_rel(dqdd_dq, -Minv @ dtau_dq, what=f"{name} dqdd/dq = -Minv dtau/dq", scale=sc[0])
        assert_rel(dqdd_dqd, -Minv @ dtau_dqd, what=f"{name} dqdd/dqd = -Minv dtau/dqd", scale=sc[1])
        # Two roundings of the same inverse (minverse moves body inertias to the base frame
        # from the centre of mass, aba_derivatives from the body origin), so they agree to
        # ~eps cond(M), as each does with the exact inverse of M and Pinocchio's does:
        # iiwa14 cond(M) ~ 3e3, up to 5e-13 apart; stanford ~ 1e6, up to 7e-12.
        tol = max(1e-13, 1e-15 * np.linalg.cond(M))
        assert_rel(Minv2, Minv, tol, what=f"{name} aba_derivatives Minv = minverse")
        # dg/dq = dtau/dq at qd = qdd = 0; M = dtau/dqdd is the CRBA's
        z = np.zeros(n)
        assert_rel(
            num.gravity_derivatives(robot, q), num.rnea_derivatives(robot, q, z, z)[0], 1e-12, what=f"{name} dg/dq"
        )
        # dtau/dqdd does not depend on qd; dtau/dqd is linear in qd: dtau/dqd(2 qd) = 2 dtau/dqd(qd)
        assert_rel(
            num.rnea_derivatives(robot, q, 2 * qd, qdd)[1],
            2 * dtau_dqd,
            1e-12,
            what=f"{name} linear in qd",
            scale=2 * _scales(robot, q, qd, (dtau_dqd,), "rnea")[0],
        )


# ------------------------------------------------------------------ batches

BATCH_CASES = [ALL[0], ALL[len(BUNDLED)], ALL[len(BUNDLED) + 1]]


@pytest.mark.parametrize("name, robot", BATCH_CASES, ids=[a for a, _ in BATCH_CASES])
def test_batches_equal_single_calls_bit_for_bit(name, robot):
    rng = np.random.default_rng(61)
    n, nl = robot.dof, len(robot.links)
    for N in (1, 7, 300):
        Q, QD, X = (random_state(rng, N * n).reshape(N, n) for _ in range(3))
        W = rng.uniform(-3, 3, size=(N, nl, 6))
        link = list(robot.links)[-1]
        calls = {
            "rnea_derivatives": lambda i, **kw: num.rnea_derivatives(robot, Q[i], QD[i], X[i], **kw),
            "aba_derivatives": lambda i, **kw: num.aba_derivatives(robot, Q[i], QD[i], X[i], **kw),
        }
        for name_, call in calls.items():
            for kw_single, kw_batch in (
                ({}, {}),
                ({"f_ext": W[0]}, {"f_ext": W}),
                ({"f_ext": W[0], "frame": "world"}, {"f_ext": W, "frame": "world"}),
            ):
                for threads in (1, 2):
                    batch = getattr(num, name_)(robot, Q, QD, X, threads=threads, **kw_batch)
                    assert len(batch) == 3
                    for k in range(3):
                        assert batch[k].shape == (N, n, n) and batch[k].flags.c_contiguous
                        want = np.array(
                            [
                                call(i, **{**kw_single, **({"f_ext": W[i]} if "f_ext" in kw_single else {})})[k]
                                for i in range(N)
                            ]
                        )
                        assert np.array_equal(batch[k], want), f"{name_}[{k}] N={N} threads={threads} {kw_batch.keys()}"
        for threads in (1, 2):
            for f, args, single in (
                (num.minverse, (Q,), lambda i: num.minverse(robot, Q[i])),
                (num.gravity_derivatives, (Q,), lambda i: num.gravity_derivatives(robot, Q[i])),
                (num.jacobian_dot, (Q, QD, link), lambda i: num.jacobian_dot(robot, Q[i], QD[i], link)),
            ):
                batch = f(robot, *args, threads=threads)
                assert np.array_equal(batch, np.array([single(i) for i in range(N)])), (f.__name__, N, threads)
            for frame in ("local", "world"):
                tau = num.rnea(robot, Q, QD, X, f_ext=W, frame=frame, threads=threads)
                assert np.array_equal(
                    tau, np.array([num.rnea(robot, Q[i], QD[i], X[i], f_ext=W[i], frame=frame) for i in range(N)])
                )
                qdd = num.aba(robot, Q, QD, X, f_ext=W, frame=frame, threads=threads)
                assert np.array_equal(
                    qdd, np.array([num.aba(robot, Q[i], QD[i], X[i], f_ext=W[i], frame=frame) for i in range(N)])
                )


# ------------------------------------------------------------------ bad input


def _robot():
    return random_robot(np.random.default_rng(3), n_joints=4, kinds="R")


@pytest.mark.parametrize(
    "call, match",
    [
        (lambda r, z, W: num.rnea_derivatives(r, np.zeros(3), z, z), "q: expected shape"),
        (lambda r, z, W: num.aba_derivatives(r, z, np.zeros((2, 4)), z), "qd"),
        (lambda r, z, W: num.minverse(r, np.array([0.0, np.nan, 0.0, 0.0])), r"q contains NaN or inf \(at q\[1\]\)"),
        (lambda r, z, W: num.gravity_derivatives(r, np.array([0.0, 0.0, 0.0, np.inf])), r"q\[3\]"),
        (lambda r, z, W: num.aba_derivatives(r, z, z, np.array([np.inf, 0, 0, 0])), "tau contains NaN"),
        (lambda r, z, W: num.jacobian_dot(r, z, z, "no-such-link"), "no link named 'no-such-link'"),
        (lambda r, z, W: num.jacobian_dot(r, z, z, 17), "link: index 17 out of range"),
        (lambda r, z, W: num.rnea(r, z, z, z, f_ext=W[:-1]), r"f_ext: expected shape \(5, 6\)"),
        (lambda r, z, W: num.aba(r, z, z, z, f_ext=W[:, :3]), r"f_ext: expected shape \(5, 6\)"),
        (lambda r, z, W: num.rnea_derivatives(r, z, z, z, f_ext=W.ravel()), "f_ext: expected shape"),
        (
            lambda r, z, W: num.aba_derivatives(r, np.zeros((2, 4)), np.zeros((2, 4)), np.zeros((2, 4)), f_ext=W),
            r"f_ext: expected shape \(2, 5, 6\)",
        ),
        (
            lambda r, z, W: num.rnea(r, z, z, z, f_ext=np.where(np.arange(30).reshape(5, 6) == 14, np.nan, W)),
            r"f_ext contains NaN or inf \(at f_ext\[2, 2\], link 'link2'\)",
        ),
        (lambda r, z, W: num.rnea(r, z, z, z, f_ext=W, frame="body"), "frame: expected 'local' or 'world'"),
        (lambda r, z, W: num.rnea_derivatives(r, z, z, z, threads=0), "^threads: expected None or an integer"),
    ],
)
def test_bad_input_raises_value_error(call, match):
    robot = _robot()
    with pytest.raises(ValueError, match=match):
        call(robot, np.zeros(4), np.ones((5, 6)))
