"""Which path rnea_derivatives, aba_derivatives and minverse take is decided in
armdyn.numeric: a Robot compiled to a plain NumericModel (or that model) goes straight to
the Rust entry, which takes compiled models only; a robot not compiled yet, mimic joints
and a Robot's f_ext go through Python first. Each path must give what the others give,
and an error of a bad argument must come out of either unchanged. The values themselves
are checked against Pinocchio, finite differences and identities in test_derivatives*.py;
here the second opinions are the other paths and NumPy's inverse of crba's M."""

from __future__ import annotations

import numpy as np
import pytest
from test_mimic import ARM

import armdyn
from armdyn import _core
from armdyn import numeric as num
from armdyn.io.urdf import load_urdf

ENTRIES = {
    "rnea_derivatives": lambda r, q, qd, x, **kw: num.rnea_derivatives(r, q, qd, x, **kw),
    "aba_derivatives": lambda r, q, qd, x, **kw: num.aba_derivatives(r, q, qd, x, **kw),
    "minverse": lambda r, q, qd, x, **kw: num.minverse(r, q, **kw),
}


def _states(dof, rows=0, seed=0):
    rng = np.random.default_rng(seed)
    shape = (rows, dof) if rows else (dof,)
    return tuple(rng.uniform(-1.5, 1.5, shape) for _ in range(3))


def _as_tuple(result):
    return result if isinstance(result, tuple) else (result,)


@pytest.mark.parametrize("rows", [0, 9])
@pytest.mark.parametrize("name", list(ENTRIES))
def test_first_call_cached_call_and_compiled_model_agree(name, rows):
    robot = armdyn.load("ur5")
    assert "_numeric_model" not in robot.__dict__  # not compiled yet: the first call compiles
    q, qd, x = _states(robot.dof, rows)
    first = ENTRIES[name](robot, q, qd, x)
    model = robot.__dict__["_numeric_model"]
    assert type(model) is num.NumericModel
    again = ENTRIES[name](robot, q, qd, x)  # the cached model, straight to the core
    compiled = ENTRIES[name](model, q, qd, x)
    for a, b, c in zip(_as_tuple(first), _as_tuple(again), _as_tuple(compiled)):
        assert np.isfinite(a).all()
        np.testing.assert_array_equal(a, b)
        np.testing.assert_array_equal(a, c)
    M = num.crba(robot, q)  # the last output: M (rnea_derivatives) or its inverse
    expected = M if name == "rnea_derivatives" else np.linalg.inv(M)
    np.testing.assert_allclose(_as_tuple(compiled)[-1], expected, rtol=1e-9, atol=1e-9)


@pytest.mark.parametrize("name", list(ENTRIES))
def test_mimic_joints_take_the_python_path(name):
    robot = load_urdf(ARM)
    q, qd, x = _states(robot.dof, seed=1)
    got = _as_tuple(ENTRIES[name](robot, q, qd, x))
    assert type(robot._numeric_model) is not num.NumericModel  # a MimicModel: the core refuses it
    M = num.crba(robot, q)
    expected = M if name == "rnea_derivatives" else np.linalg.inv(M)
    np.testing.assert_allclose(got[-1], expected, rtol=1e-9, atol=1e-9)


def test_the_core_entries_take_compiled_models_only():
    robot = armdyn.load("ur5")
    q = np.zeros(robot.dof)
    for entry, args in (
        (_core.rnea_derivatives, (q, q, q)),
        (_core.aba_derivatives, (q, q, q)),
        (_core.minverse, (q,)),
    ):
        with pytest.raises(TypeError, match="NumericModel"):
            entry(robot, *args)


@pytest.mark.parametrize("compiled", [False, True])
@pytest.mark.parametrize(
    "kwargs, error, words",
    [
        ({"frame": "up"}, ValueError, "frame: expected 'local' or 'world', got 'up'"),
        ({"frame": 3}, TypeError, "str"),
        ({"threads": 0}, ValueError, "threads"),
        ({"out": np.zeros((5, 5))}, ValueError, r"out: expected"),
    ],
)
def test_a_bad_argument_gives_the_same_error_on_either_path(compiled, kwargs, error, words):
    robot = armdyn.load("ur5")
    q = np.zeros(robot.dof)
    if compiled:
        num.compile_model(robot)
    for name in ENTRIES:
        if name == "minverse" and "frame" in kwargs:
            continue
        with pytest.raises(error, match=words):
            ENTRIES[name](robot, q, q, q, **kwargs)
