"""One state through armdyn.numeric: the plain case (a C-contiguous float64 ``(n,)`` ndarray)
is read in place by the core; every other form of the same numbers is converted first and
must give the same result bit for bit, and bad input is refused with the argument named.

The values themselves are checked against armdyn.reference (the NumPy oracle, written
apart from the Rust core) so that the fast path is also right, not only self-consistent.
"""

from __future__ import annotations

import numpy as np
import pytest
from random_models import random_robot, random_state

from armdyn import numeric as num
from armdyn import reference as ref

CALLS = {
    "rnea": (num.rnea, ("q", "qd", "qdd")),
    "crba": (num.crba, ("q",)),
    "aba": (num.aba, ("q", "qd", "tau")),
    "gravity": (num.gravity, ("q",)),
    "bias": (num.bias, ("q", "qd")),
}


@pytest.fixture(scope="module")
def arm():
    """A random 5-joint chain with revolute and prismatic joints, and one state."""
    rng = np.random.default_rng(41)
    robot = random_robot(rng, n_joints=5, kinds="RP")
    state = {k: random_state(rng, robot.dof) for k in ("q", "qd", "qdd")}
    state["tau"] = state["qdd"]
    return robot, state


def _other_forms(x: np.ndarray) -> dict[str, object]:
    """The numbers of ``x`` (float64, (n,)) in the other forms numpy or a user may pass:
    all but the read-only array (read in place too) are converted first."""
    n = x.size
    strided = np.empty(2 * n)
    strided[::2] = x
    unaligned_buffer = np.zeros(8 * n + 1, dtype=np.uint8)
    unaligned = np.frombuffer(unaligned_buffer.data, dtype=np.float64, count=n, offset=1)
    unaligned[:] = x
    read_only = x.copy()
    read_only.flags.writeable = False

    class Sub(np.ndarray):
        pass

    return {
        "list": x.tolist(),
        "tuple": tuple(x.tolist()),
        "strided view": strided[::2],
        "reversed twice": x[::-1].copy()[::-1],
        "big-endian": x.astype(">f8"),
        "unaligned": unaligned,
        "read-only": read_only,
        "subclass": x.copy().view(Sub),
        "object array": np.array(x.tolist(), dtype=object),
    }


@pytest.mark.parametrize("name", CALLS)
def test_plain_state_matches_the_reference(arm, name):
    robot, state = arm
    fn, names = CALLS[name]
    got = fn(robot, *(state[k] for k in names))
    expected = getattr(ref, name)(robot, *(state[k] for k in names))
    scale = max(1.0, float(np.max(np.abs(expected))))
    assert np.max(np.abs(got - expected)) <= 1e-10 * scale, name


@pytest.mark.parametrize("name", CALLS)
def test_every_other_form_gives_the_same_bits(arm, name):
    robot, state = arm
    fn, names = CALLS[name]
    plain = fn(robot, *(state[k] for k in names))
    for slot, key in enumerate(names):
        for form, value in _other_forms(state[key]).items():
            args = [state[k] for k in names]
            args[slot] = value
            assert np.array_equal(fn(robot, *args), plain), f"{name}: {key} as {form}"


def test_integer_states_give_the_bits_of_their_floats(arm):
    robot, _ = arm
    ints = np.arange(robot.dof) % 3 - 1
    floats = ints.astype(np.float64)
    assert np.array_equal(num.rnea(robot, ints, ints, ints), num.rnea(robot, floats, floats, floats))
    assert np.array_equal(num.crba(robot, ints.astype(np.int32)), num.crba(robot, floats))
    assert np.array_equal(num.aba(robot, ints, ints, ints), num.aba(robot, floats, floats, floats))


def test_a_batch_of_one_row_is_the_single_call(arm):
    robot, state = arm
    q, qd, qdd = (state[k] for k in ("q", "qd", "qdd"))
    assert np.array_equal(num.rnea(robot, q[None], qd[None], qdd[None])[0], num.rnea(robot, q, qd, qdd))
    assert np.array_equal(num.crba(robot, q[None])[0], num.crba(robot, q))


@pytest.mark.parametrize("name", CALLS)
@pytest.mark.parametrize("bad", [np.nan, np.inf, -np.inf])
def test_non_finite_values_are_refused_by_argument_and_index(arm, name, bad):
    robot, state = arm
    fn, names = CALLS[name]
    for slot, key in enumerate(names):
        args = [state[k].copy() for k in names]
        args[slot][2] = bad
        with pytest.raises(ValueError, match=rf"{key} contains NaN or inf \(at {key}\[2\]\)"):
            fn(robot, *args)


@pytest.mark.parametrize("name", CALLS)
def test_wrong_lengths_name_the_argument_and_the_shape(arm, name):
    robot, state = arm
    fn, names = CALLS[name]
    n = robot.dof
    for slot, key in enumerate(names):
        args = [state[k] for k in names]
        args[slot] = np.zeros(n + 1)
        with pytest.raises(ValueError, match=rf"{key}: expected shape \({n},\).*got \[{n + 1}\]"):
            fn(robot, *args)
        args[slot] = np.zeros(())
        with pytest.raises(ValueError, match=rf"{key}: expected shape"):
            fn(robot, *args)


def test_non_real_arrays_are_still_refused(arm):
    robot, state = arm
    q = state["q"]
    with pytest.raises(ValueError, match="q: expected real numbers"):
        num.crba(robot, q.astype(complex))
    with pytest.raises(ValueError, match="qd: expected real numbers"):
        num.rnea(robot, q, q > 0, q)


def test_threads_by_position_or_keyword_alike(arm):
    robot, state = arm
    Q = np.stack([state["q"], state["qd"]])
    assert np.array_equal(num.crba(robot, Q, 1), num.crba(robot, Q, threads=1))
    with pytest.raises(TypeError, match="threads"):
        num.crba(robot, Q, 1.5)


def test_a_state_that_overflows_is_an_error_not_inf(arm):
    robot, state = arm
    huge = np.full(robot.dof, 1e300)
    with pytest.raises(ValueError, match="overflows"):
        num.rnea(robot, state["q"], huge, state["qdd"])
