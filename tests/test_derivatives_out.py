"""``out=`` of rnea_derivatives, aba_derivatives and minverse: the caller's arrays are
written and returned, with exactly the values a call with fresh outputs gives (those
values are checked against Pinocchio, finite differences and identities in
test_derivatives*.py), every element overwritten, and bad arrays refused before anything
is written."""

from __future__ import annotations

import numpy as np
import pytest
from test_mimic import ARM

import armdyn
from armdyn import numeric as num
from armdyn.io.urdf import load_urdf

N = 37  # not a multiple of the SIMD width: lanes and the one-by-one tail both write


@pytest.fixture(scope="module")
def ur5():
    return armdyn.load("ur5")


def _states(robot, rows, seed=0):
    rng = np.random.default_rng(seed)
    shape = (rows, robot.dof) if rows else (robot.dof,)
    return tuple(rng.uniform(-1.5, 1.5, shape) for _ in range(3))


def _nan_like(arrays):
    return tuple(np.full_like(a, np.nan) for a in arrays)


CALLS = {
    "rnea_derivatives": lambda r, q, qd, x, **kw: num.rnea_derivatives(r, q, qd, x, **kw),
    "aba_derivatives": lambda r, q, qd, x, **kw: num.aba_derivatives(r, q, qd, x, **kw),
    "minverse": lambda r, q, qd, x, **kw: num.minverse(r, q, **kw),
}


@pytest.mark.parametrize("rows", [0, N])
@pytest.mark.parametrize("threads", [1, 2])
@pytest.mark.parametrize("name", list(CALLS))
def test_out_equals_fresh_outputs(ur5, name, rows, threads):
    q, qd, x = _states(ur5, rows)
    fresh = CALLS[name](ur5, q, qd, x, threads=threads)
    many = isinstance(fresh, tuple)
    out = _nan_like(fresh) if many else np.full_like(fresh, np.nan)
    got = CALLS[name](ur5, q, qd, x, threads=threads, out=out)
    if many:
        assert isinstance(got, tuple) and len(got) == 3
        assert all(g is o for g, o in zip(got, out))
    else:
        assert got is out
    for g, f in zip(got if many else (got,), fresh if many else (fresh,)):
        assert np.isfinite(g).all()  # every element written (the NaN fill is gone)
        np.testing.assert_array_equal(g, f)


def test_out_with_external_wrenches(ur5):
    q, qd, qdd = _states(ur5, N, seed=1)
    f_ext = np.random.default_rng(2).normal(size=(N, len(ur5.links), 6))
    fresh = num.rnea_derivatives(ur5, q, qd, qdd, f_ext=f_ext, frame="world")
    out = _nan_like(fresh)
    got = num.rnea_derivatives(ur5, q, qd, qdd, f_ext=f_ext, frame="world", out=out)
    assert all(g is o for g, o in zip(got, out))
    for g, f in zip(got, fresh):
        np.testing.assert_array_equal(g, f)
    with pytest.raises(ValueError, match="out.*shares memory with f_ext"):
        num.aba_derivatives(ur5, q, qd, qdd, f_ext=f_ext, out=(f_ext.reshape(-1)[: N * 36].reshape(N, 6, 6),) + out[1:])


@pytest.mark.parametrize("name", list(CALLS))
def test_out_on_a_mimic_robot(name):
    robot = load_urdf(ARM)
    q, qd, x = _states(robot, 5, seed=3)
    fresh = CALLS[name](robot, q, qd, x)
    many = isinstance(fresh, tuple)
    out = _nan_like(fresh) if many else np.full_like(fresh, np.nan)
    got = CALLS[name](robot, q, qd, x, out=out)
    for g, o, f in zip(got if many else (got,), out if many else (out,), fresh if many else (fresh,)):
        assert g is o
        np.testing.assert_array_equal(g, f)
    with pytest.raises(ValueError, match="out.*expected shape"):
        CALLS[name](robot, q[0], qd[0], x[0], out=out)


def test_bad_out_is_refused_before_anything_is_written(ur5):
    q, qd, qdd = _states(ur5, N, seed=4)
    good = tuple(np.full((N, 6, 6), 7.0) for _ in range(3))
    read_only = np.empty((N, 6, 6))
    read_only.flags.writeable = False
    buffer = np.zeros(N * 6 + N * 36)
    cases = [
        ((np.empty((N, 6, 5)),) + good[1:], r"out\[0\]: expected shape"),
        ((np.empty((N, 6, 6), dtype=np.float32),) + good[1:], r"out\[0\]: expected a float64"),
        ((np.empty((N, 6, 12))[:, :, ::2],) + good[1:], r"out\[0\]: must be C-contiguous"),
        ((good[0], read_only, good[2]), r"out\[1\]: is read-only"),
        ((good[0], good[0], good[2]), r"out\[1\]: shares memory with out\[0\]"),
        (good[:2], "out: expected 3 arrays, got 2"),
        (good[0], "out: expected a tuple of numpy arrays"),
        ((buffer[N * 6 - 6 : N * 6 - 6 + N * 36].reshape(N, 6, 6),) + good[1:], r"out\[0\]: shares memory with q"),
    ]
    q_in = buffer[: N * 6].reshape(N, 6)
    q_in[...] = q
    for out, message in cases:
        with pytest.raises(ValueError, match=message):
            num.rnea_derivatives(ur5, q_in, qd, qdd, out=out)
        for g in good:
            assert (g == 7.0).all()  # untouched
    with pytest.raises(ValueError, match="out: expected 1 arrays, got 2"):
        num.minverse(ur5, q, out=good[:2])
