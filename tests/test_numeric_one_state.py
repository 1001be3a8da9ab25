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


# ------------------------------------------------------------------ results reused once dropped
# The core keeps a few small single-state results and writes a new result into one only
# when nothing else refers to it (scratch.rs, OutputPool): a result the caller holds, or
# anything seen through it, never changes.


def _fresh(fn, robot, *args):
    """The result computed on lists (the general path, a newly made array every time)."""
    return fn(robot, *(np.asarray(a).tolist() for a in args))


def test_held_results_never_change(arm):
    robot, state = arm
    rng = np.random.default_rng(5)
    held = []
    for _ in range(12):  # more calls than the pool has slots, each result kept
        q, qd, qdd = (random_state(rng, robot.dof) for _ in range(3))
        held.append(((q, qd, qdd), num.rnea(robot, q, qd, qdd), num.crba(robot, q)))
    for (q, qd, qdd), tau, M in held:
        assert np.array_equal(tau, _fresh(num.rnea, robot, q, qd, qdd))
        assert np.array_equal(M, _fresh(num.crba, robot, q))
    arrays = [a for _, tau, M in held for a in (tau, M)]
    assert len({id(a) for a in arrays}) == len(arrays)
    assert not any(np.shares_memory(a, b) for i, a in enumerate(arrays) for b in arrays[i + 1 :])


def test_a_dropped_result_is_written_whole_when_reused(arm):
    robot, state = arm
    rng = np.random.default_rng(6)
    for _ in range(6):
        q = random_state(rng, robot.dof)
        M = num.crba(robot, q)
        M[...] = np.nan  # scribbled on, then dropped: the next result must not show it
        del M
        q2 = random_state(rng, robot.dof)
        assert np.array_equal(num.crba(robot, q2), _fresh(num.crba, robot, q2))


def test_views_weak_references_and_changed_arrays_are_not_reused(arm):
    import weakref

    robot, state = arm
    q, qd = state["q"], state["qd"]
    rng = np.random.default_rng(7)
    row = num.crba(robot, q)[0]  # the result is dropped, its first row (a view) kept
    tau = num.gravity(robot, q)
    ref = weakref.ref(tau)
    expected_tau = tau.copy()
    del tau
    frozen = num.bias(robot, q, qd)
    frozen.flags.writeable = False
    del frozen
    flat = num.crba(robot, q)
    flat.shape = (robot.dof * robot.dof,)
    del flat
    for _ in range(8):
        q2 = random_state(rng, robot.dof)
        M2, g2, h2 = num.crba(robot, q2), num.gravity(robot, q2), num.bias(robot, q2, qd)
        assert M2.shape == (robot.dof, robot.dof) and M2.flags.writeable and h2.flags.writeable
        assert np.array_equal(M2, _fresh(num.crba, robot, q2))
        assert np.array_equal(g2, _fresh(num.gravity, robot, q2))
        assert np.array_equal(h2, _fresh(num.bias, robot, q2, qd))
    assert np.array_equal(row, _fresh(num.crba, robot, q)[0])
    alive = ref()
    assert alive is None or np.array_equal(alive, expected_tau)


def test_a_result_resizes_in_place_without_the_reference_check(arm):
    robot, state = arm
    M = num.crba(robot, state["q"])
    M.resize((robot.dof * robot.dof + 1,), refcheck=False)  # the pool's reference is not a view
    assert M.shape == (robot.dof * robot.dof + 1,)
    assert num.crba(robot, state["q"]).shape == (robot.dof, robot.dof)
