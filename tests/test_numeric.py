"""armdyn.numeric (the Rust core) against second opinions:

* Pinocchio and armdyn.reference to 1e-12 relative, for every function, on random chains and
  branched trees with mixed revolute/prismatic/fixed joints and arbitrary frames;
* the symbolic engine (lambdified Newton-Euler tau) on every bundled model;
* the identities of docs/architecture.md on random branched trees;
* batches == loops of single calls, bit for bit; threads=1 == threads=2, bit for bit;
* bad input: wrong shapes, NaN/inf -> ValueError naming the argument; unbound parameters ->
  UnboundParameterError naming them.
"""

from __future__ import annotations

import math
import warnings

import numpy as np
import pytest
import sympy as sp
from pinocchio_bridge import PinocchioRobot
from random_models import random_case, random_robot, random_state

import armdyn
from armdyn import numeric as num
from armdyn import reference as ref
from armdyn.errors import UnboundParameterError
from armdyn.model import Joint, Link, Robot

RTOL = 1e-12


def assert_rel(actual, expected, rtol=RTOL, what="", scale=None):
    """max |actual - expected| <= rtol * scale, scale = max |expected| unless given (for
    quantities that may vanish, pass their natural size, e.g. |M| |qd| for C)."""
    actual, expected = np.asarray(actual, dtype=float), np.asarray(expected, dtype=float)
    assert actual.shape == expected.shape, (what, actual.shape, expected.shape)
    scale = max(np.max(np.abs(expected)) if scale is None else scale, 1e-300)
    err = np.max(np.abs(actual - expected)) / scale
    assert err <= rtol, f"{what}: relative error {err:.2e} > {rtol:.0e}"


# the functions and how to call them on one state (q, qd, qdd) or a batch of them
CALLS = {
    "rnea": lambda f, r, q, qd, qdd, **kw: f.rnea(r, q, qd, qdd, **kw),
    "crba": lambda f, r, q, qd, qdd, **kw: f.crba(r, q, **kw),
    "aba": lambda f, r, q, qd, qdd, **kw: f.aba(r, q, qd, qdd, **kw),  # qdd used as tau
    "gravity": lambda f, r, q, qd, qdd, **kw: f.gravity(r, q, **kw),
    "bias": lambda f, r, q, qd, qdd, **kw: f.bias(r, q, qd, **kw),
    "coriolis_matrix": lambda f, r, q, qd, qdd, **kw: f.coriolis_matrix(r, q, qd, **kw),
    "kinetic_energy": lambda f, r, q, qd, qdd, **kw: f.kinetic_energy(r, q, qd, **kw),
    "potential_energy": lambda f, r, q, qd, qdd, **kw: f.potential_energy(r, q, **kw),
    "forward_kinematics": lambda f, r, q, qd, qdd, **kw: f.forward_kinematics(r, q, **kw),
}


def single_shape(name, robot):
    n, nl = robot.dof, len(robot.links)
    return {
        "crba": (n, n),
        "coriolis_matrix": (n, n),
        "kinetic_energy": (),
        "potential_energy": (),
        "forward_kinematics": (nl, 4, 4),
    }.get(name, (n,))


# ------------------------------------------------------------------ random models

CASES = [(seed, False) for seed in range(100, 104)] + [(seed, True) for seed in range(104, 110)]


@pytest.fixture(scope="module", params=CASES, ids=[f"{'tree' if t else 'chain'}{s}" for s, t in CASES])
def case(request):
    seed, tree = request.param
    return random_case(seed, tree, max_joints=11)


@pytest.fixture(scope="module")
def trees():
    """Random branched trees (at least one link with two children) for the identities."""
    out, rng = [], np.random.default_rng(2024)
    while len(out) < 4:
        robot = random_robot(rng, n_joints=9, tree=True)
        if robot.dof >= 3 and any(len(robot.children(link)) > 1 for link in robot.links):
            out.append(robot)
    return out


def _pin_args(name, q, qd, qdd):
    return {
        "rnea": (q, qd, qdd),
        "aba": (q, qd, qdd),
        "bias": (q, qd),
        "coriolis_matrix": (q, qd),
        "kinetic_energy": (q, qd),
    }.get(name, (q,))


def test_matches_pinocchio_and_reference(case):
    robot, P, states = case
    for q, qd, qdd in states:
        for name, call in CALLS.items():
            mine = call(num, robot, q, qd, qdd)
            assert np.shape(mine) == single_shape(name, robot), name
            oracle = call(ref, robot, q, qd, qdd)
            scale = None
            if name == "coriolis_matrix":
                scale = np.max(np.abs(ref.crba(robot, q))) * np.max(np.abs(qd))
            assert_rel(mine, oracle, what=f"{name} vs reference", scale=scale)
            theirs = getattr(P, name)(*_pin_args(name, q, qd, qdd))
            assert_rel(mine, theirs, what=f"{name} vs Pinocchio", scale=scale)
        for link in robot.links:
            J = num.jacobian(robot, q, link)
            assert_rel(J, P.jacobian(q, link), what=f"jacobian {link} vs Pinocchio")
            assert_rel(J, ref.jacobian(robot, q, link), what=f"jacobian {link} vs reference")


def test_batch_equals_single_calls_bit_for_bit(case):
    robot, _, _ = case
    rng = np.random.default_rng(7)
    N, n = 5, robot.dof
    Q, QD, QDD = (random_state(rng, N * n).reshape(N, n) for _ in range(3))
    for name, call in CALLS.items():
        batch = call(num, robot, Q, QD, QDD)
        assert batch.shape == (N,) + single_shape(name, robot), name
        assert batch.dtype == np.float64
        singles = np.array([call(num, robot, Q[i], QD[i], QDD[i]) for i in range(N)])
        assert np.array_equal(batch, singles), f"{name}: batch differs from single calls"
    link = list(robot.links)[-1]
    J = num.jacobian(robot, Q, link)
    assert J.shape == (N, 6, n)
    assert np.array_equal(J, np.array([num.jacobian(robot, Q[i], link) for i in range(N)]))


def test_threads_give_identical_results(trees):
    robot = trees[0]
    rng = np.random.default_rng(8)
    N, n = 4000, robot.dof
    Q, QD, QDD = (random_state(rng, N * n).reshape(N, n) for _ in range(3))
    for name, call in CALLS.items():
        one = call(num, robot, Q, QD, QDD, threads=1)
        two = call(num, robot, Q, QD, QDD, threads=2)
        default = call(num, robot, Q, QD, QDD)
        assert np.array_equal(one, two) and np.array_equal(one, default), name
    link = list(robot.links)[-1]
    assert np.array_equal(num.jacobian(robot, Q, link, threads=1), num.jacobian(robot, Q, link, threads=2))


def test_other_dtypes_and_layouts_are_converted(case):
    robot, _, _ = case
    rng = np.random.default_rng(9)
    n = robot.dof
    Q = random_state(rng, 6 * n).reshape(6, n)
    expected = num.rnea(robot, Q, Q, Q)
    fortran = np.asfortranarray(Q)
    strided = np.repeat(Q, 2, axis=0)[::2]  # not contiguous
    assert np.array_equal(num.rnea(robot, fortran, fortran, fortran), expected)
    assert np.array_equal(num.rnea(robot, strided, strided, strided), expected)
    assert np.array_equal(num.crba(robot, Q[0].tolist()), num.crba(robot, Q[0]))
    ints = np.arange(n) % 3 - 1
    assert np.array_equal(num.crba(robot, ints), num.crba(robot, ints.astype(np.float64)))
    f32 = Q[0].astype(np.float32)
    assert np.array_equal(num.crba(robot, f32), num.crba(robot, f32.astype(np.float64)))


# ------------------------------------------------------------------ identities (docs/architecture.md)


def test_identities_on_branched_trees(trees):
    rng = np.random.default_rng(10)
    h = 1e-6
    for robot in trees:
        n = robot.dof
        for _ in range(3):
            q, qd, qdd = (random_state(rng, n) for _ in range(3))
            M = num.crba(robot, q)
            C = num.coriolis_matrix(robot, q, qd)
            C_scale = np.max(np.abs(M)) * np.max(np.abs(qd))
            # rnea = M qdd + rnea(q, qd, 0); aba inverts rnea
            tau = num.rnea(robot, q, qd, qdd)
            assert_rel(tau, M @ qdd + num.rnea(robot, q, qd, np.zeros(n)), what="rnea = M qdd + h")
            assert_rel(num.bias(robot, q, qd), num.rnea(robot, q, qd, np.zeros(n)), what="bias")
            assert_rel(num.gravity(robot, q), num.rnea(robot, q, np.zeros(n), np.zeros(n)), what="gravity")
            assert_rel(num.aba(robot, q, qd, tau), qdd, 1e-10, what="aba(rnea) = qdd")
            # M symmetric positive definite; T = 1/2 qd' M qd
            assert_rel(M, M.T, 1e-14, what="M symmetric")
            assert np.all(np.linalg.eigvalsh(M) > 0)
            assert_rel(num.kinetic_energy(robot, q, qd), 0.5 * qd @ M @ qd, what="T")
            # g = dV/dq (central differences); C qd = h - g; Mdot - 2C skew
            E = np.eye(n)
            dV = (num.potential_energy(robot, q + h * E) - num.potential_energy(robot, q - h * E)) / (2 * h)
            assert_rel(num.gravity(robot, q), dV, 1e-7, what="g = dV/dq")
            assert_rel(C @ qd, num.bias(robot, q, qd) - num.gravity(robot, q), scale=C_scale * np.max(np.abs(qd)))
            Mdot = (num.crba(robot, q + h * qd) - num.crba(robot, q - h * qd)) / (2 * h)
            N = Mdot - 2 * C
            assert np.max(np.abs(N + N.T)) <= 1e-6 * C_scale


# ------------------------------------------------------------------ numeric == symbolic


def _bundled():
    return [entry["name"] for entry in armdyn.bundled_robots()]


def evaluate(exprs, values: dict) -> np.ndarray:
    """Float values of SymPy expressions at ``values`` (symbol -> float).

    The derivations are DAGs with much sharing (a 7-dof arm with non-DH frames has ~1e8
    operations as a tree), too big for lambdify; walking each distinct node once is fast.
    """
    functions = {sp.sin: np.sin, sp.cos: np.cos}
    memo: dict = {}

    def value(root):
        stack = [root]
        while stack:
            x = stack[-1]
            if x in memo:
                stack.pop()
                continue
            if x.is_Symbol or x.is_Number:
                memo[x] = values[x] if x.is_Symbol else float(x)
                stack.pop()
                continue
            pending = [a for a in x.args if a not in memo]
            if pending:
                stack.extend(pending)
                continue
            args = [memo[a] for a in x.args]
            if x.is_Add:
                memo[x] = math.fsum(args)
            elif x.is_Mul:
                memo[x] = math.prod(args)
            elif x.is_Pow:
                memo[x] = args[0] ** args[1]
            elif x.func in functions:
                memo[x] = float(functions[x.func](args[0]))
            else:
                raise TypeError(f"no numeric evaluation for {x.func}")
            stack.pop()
        return memo[root]

    return np.array([value(sp.sympify(e)) for e in exprs])


@pytest.mark.parametrize("name", _bundled())
def test_numeric_equals_symbolic_on_bundled_models(name):
    """tau, g and M of the symbolic Newton-Euler derivation at random states.

    Parameters without a published default get random values; the physical-validity check
    is relaxed (strict=False) because some published tables (e.g. Corke's puma560 link 1,
    inertia given about the joint axis only) break the triangle inequality.
    """
    rng = np.random.default_rng(11)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", UserWarning)
        robot = armdyn.load(name, strict=False)
        missing = sorted(set(robot.parameters) - set(robot.defaults))
        robot = robot.bind({k: rng.uniform(0.5, 1.5) for k in missing})
    eom = armdyn.derive(robot, "newton-euler")
    n = robot.dof

    def tau(q, qd, qdd):
        return evaluate(eom.tau, {**dict(zip(eom.q, q)), **dict(zip(eom.qd, qd)), **dict(zip(eom.qdd, qdd))})

    for _ in range(3):
        q, qd, qdd = (random_state(rng, n) for _ in range(3))
        z = np.zeros(n)
        assert_rel(num.rnea(robot, q, qd, qdd), tau(q, qd, qdd), what=f"{name} tau")
        g = tau(q, z, z)
        assert_rel(num.gravity(robot, q), g, what=f"{name} g", scale=max(np.max(np.abs(g)), 1.0))
        # tau is linear in qdd: M e_j = tau(q, 0, e_j) - g (the subtraction costs ~|g|/|M| eps)
        M = np.array([tau(q, z, e) - g for e in np.eye(n)]).T
        assert_rel(num.crba(robot, q), M, 1e-10, what=f"{name} M")


# ------------------------------------------------------------------ bad input


def _chain():
    return random_robot(np.random.default_rng(3), n_joints=4, kinds="R")


@pytest.mark.parametrize(
    "bad, arg",
    [
        ({"q": np.zeros(3)}, "q"),
        ({"q": np.zeros(5)}, "q"),
        ({"qd": np.zeros((2, 3))}, "qd"),
        ({"q": np.zeros((2, 2, 4))}, "q"),
        ({"qdd": np.zeros((3, 4))}, "qdd"),  # batch of 3 against single states
        ({"q": np.array([0.0, np.nan, 0.0, 0.0])}, "q"),
        ({"qd": np.array([0.0, 0.0, np.inf, 0.0])}, "qd"),
        ({"qdd": np.array([-np.inf, 0.0, 0.0, 0.0])}, "qdd"),
    ],
)
def test_bad_states_raise_value_error(bad, arg):
    robot = _chain()
    state = {"q": np.zeros(4), "qd": np.zeros(4), "qdd": np.zeros(4)}
    state.update(bad)
    with pytest.raises(ValueError, match=arg):
        num.rnea(robot, state["q"], state["qd"], state["qdd"])


def test_bad_batches_raise_value_error():
    robot = _chain()
    Q = np.zeros((5, 4))
    with pytest.raises(ValueError, match="qd"):
        num.rnea(robot, Q, np.zeros((4, 4)), Q)  # 4 rows against 5
    Q_nan = Q.copy()
    Q_nan[3, 1] = np.nan
    with pytest.raises(ValueError, match="q"):
        num.crba(robot, Q_nan)
    with pytest.raises(ValueError, match="tau"):
        num.aba(robot, Q, Q, np.full((5, 4), np.inf))
    with pytest.raises(ValueError):
        num.jacobian(robot, np.zeros(4), "no such link")


def test_unbound_parameters_are_named():
    m, l = sp.symbols("m_arm l_arm")
    robot = Robot(
        "sym",
        [Link("base"), Link("a", m, [l, 0, 0], np.diag([0.1, 0.2, 0.25]).tolist())],
        [Joint("j", "revolute", "base", "a", axis=[0, 1, 0])],
        parameters=[m, l],
    )
    with pytest.raises(UnboundParameterError, match="m_arm") as err:
        num.rnea(robot, [0.0], [0.0], [0.0])
    assert "l_arm" in str(err.value)
    bound = robot.bind({"m_arm": 2.0, "l_arm": 0.5})
    q, qd, qdd = np.array([0.3]), np.array([-0.7]), np.array([1.1])
    assert_rel(num.rnea(bound, q, qd, qdd), PinocchioRobot(bound).rnea(q, qd, qdd), what="bound rnea")


def test_compiled_model_is_cached_and_accepted():
    robot = _chain()
    q = random_state(np.random.default_rng(4), robot.dof)
    tau = num.gravity(robot, q)
    model = robot._numeric_model
    num.crba(robot, q)
    assert robot._numeric_model is model  # built once per robot, not per call
    assert isinstance(model, num.NumericModel)
    assert np.array_equal(num.gravity(model, q), tau)
