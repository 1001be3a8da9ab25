"""The two-rate links' closed forms (armdyn.programs.two_rate_link: the second link of an
arm and the links further along its run) against the textbook recursion done in NumPy, and
the customized Newton-Euler that uses them against the Rust core's rnea (spatial vectors,
no closed forms) on arms made to switch them on and off."""

from __future__ import annotations

import numpy as np
import pytest
import sympy as sp
from random_models import random_link

import armdyn
from armdyn.model import Joint, Robot
from armdyn.programs.customized_ne import Forms, customized_newton_euler
from armdyn.programs.program import Builder
from armdyn.programs.two_rate_link import TwoRateLink, euler_projections, in_frame, lower_column, point_acceleration

RX = [[1, 0, 0], [0, 0, 1], [0, -1, 0]]  # alpha = -90 deg: the next axis perpendicular


def _rz(q):
    c, s = np.cos(q), np.sin(q)
    return np.array([[c, -s, 0.0], [s, c, 0.0], [0.0, 0.0, 1.0]])


def _textbook(rng, R0):
    """Link L on a base-fixed root, by the recursion of Craig/Khalil in NumPy: (u in L's
    axes, w_L, wd_L, the rates)."""
    a, ad, b, bd, q = rng.uniform(-2, 2, 5)
    R = np.asarray(R0, float) @ _rz(q)  # L's frame in the root's
    e3 = np.array([0.0, 0.0, 1.0])
    wi = R.T @ (a * e3)
    w = wi + b * e3
    wd = R.T @ (ad * e3) + bd * e3 + np.cross(wi, b * e3)
    return R.T @ e3, w, wd, (a, ad, b, bd)


def _second(u, rates, gz=None):
    a, ad, b, bd = (sp.Float(x) for x in rates)
    u = [sp.Float(u[0]), sp.Float(u[1]), sp.S.Zero]
    v = [u[1], -u[0], sp.S.Zero]
    W = [bd * u[i] + b * b * v[i] for i in range(2)]
    return TwoRateLink("root", u, v, a, ad, b, bd, a * a, b * b, 2 * a * b, W, None if gz is None else sp.Float(gz))


@pytest.mark.parametrize("grouped", [False, True])
def test_euler_projections_equal_the_moment_projected(grouped):
    """u . E and e3 . E of the closed form == the Euler moment E = J wd + w x (J w) of the
    textbook recursion, projected, for random J (YY = 0 after the grouping) and states;
    the root's J33 rides in A."""
    rng = np.random.default_rng(3)
    for _ in range(20):
        u, w, wd, rates = _textbook(rng, RX)
        assert abs(u[2]) < 1e-15
        J = rng.uniform(-1, 1, (3, 3))
        J = J + J.T
        if grouped:
            J[1, 1] = 0.0
        E = J @ wd + np.cross(w, J @ w)
        J33_root = rng.uniform(0.5, 1.5)
        Js = [[sp.S.Zero if x == 0 else sp.Float(x) for x in row] for row in J]
        A, rest, along_z = euler_projections(Builder(), Js, _second(u, rates), "2", sp.Float(J33_root))
        along_u = float(A) * rates[1] + float(rest)  # u . E = a' A + rest
        np.testing.assert_allclose(along_u, u @ E + J33_root * rates[1], rtol=1e-12, atol=1e-12)
        np.testing.assert_allclose(float(along_z), E[2], rtol=1e-12, atol=1e-12)
        # with gravity gz along the root's axis folded in: + ((gz MS) x u)_z; the u part the same
        gMS = rng.uniform(-1, 1, 3)
        A, rest, along_zg = euler_projections(
            Builder(), Js, _second(u, rates), "2", gravity=[sp.Float(x) for x in gMS[:2]]
        )
        np.testing.assert_allclose(float(A) * rates[1] + float(rest), u @ E, rtol=1e-12, atol=1e-12)
        np.testing.assert_allclose(float(along_zg), E[2] + np.cross(gMS, u)[2], rtol=1e-12, atol=1e-12)


def test_lower_column_equals_the_textbook_U():
    """U31 = w_x w_z - wd_y and U32 = w_y w_z + wd_x of the textbook recursion equal the
    closed forms from the last column, -U13 + 2 a b u1 and -U23 + 2 a b u2."""
    rng = np.random.default_rng(6)
    for _ in range(20):
        u, w, wd, rates = _textbook(rng, RX)
        column = [sp.Float(w[0] * w[2] + wd[1]), sp.Float(w[1] * w[2] - wd[0])]  # U13, U23
        got = [float(x) for x in lower_column(_second(u, rates), column)]
        want = [w[0] * w[2] - wd[1], w[1] * w[2] + wd[0]]
        np.testing.assert_allclose(got, want, rtol=1e-12, atol=1e-12)


def test_point_acceleration_equals_the_textbook_one():
    """A point p of L accelerates by gz u + wd x p + w x (w x p) (its origin on the root's
    axis, gravity along it): the closed form's components in (u, v, e3), put back in L's
    axes, equal it."""
    rng = np.random.default_rng(4)
    for _ in range(20):
        u, w, wd, rates = _textbook(rng, RX)
        p, gz = rng.uniform(-1, 1, 3), rng.uniform(5, 10)
        want = gz * u + np.cross(wd, p) + np.cross(w, np.cross(w, p))
        s = _second(u, rates, gz)
        A = point_acceleration(Builder(), s, [sp.Float(x) for x in p], "2")
        got = np.array([float(x) for x in in_frame(A, s.u, s.v)])
        np.testing.assert_allclose(got, want, rtol=1e-12, atol=1e-12)


def _arm(origin, gravity, run: bool):
    """Root about the base's z, a second joint turned by alpha = -90 deg with its origin
    at ``origin`` (root axes), then a third joint parallel to it (a run, the PUMA's
    offsets) or turned again, then a leaf; random physical inertias."""
    rng = np.random.default_rng(31)
    eye = np.eye(3).tolist()
    spec = [
        ("j1", "l0", "l1", [0, 0, 0.3], eye),
        ("j2", "l1", "l2", origin, RX),
        ("j3", "l2", "l3", [0.43, 0, 0.15], eye if run else RX),
        ("j4", "l3", "l4", [0.02, 0.43, 0], RX),
    ]
    links = [random_link(rng, "l0")] + [random_link(rng, f"l{k}") for k in range(1, 5)]
    joints = [Joint(n, "revolute", p, c, xyz=x, rotation=r, axis=[0, 0, 1]) for n, p, c, x, r in spec]
    return Robot("second-link-arm", links, joints, gravity=gravity)


@pytest.mark.parametrize(
    "origin, gravity, run",
    [
        ([0, 0, 0], (0, 0, -9.81), True),  # PUMA-like: every closed form on
        ([0, 0, 0.2], (0, 0, -9.81), False),  # origin on the root axis, no run
        ([0.1, 0.05, 0], (0, 0, -9.81), True),  # origin off the axis: L's origin accelerates otherwise
        ([0, 0, 0], (1.5, -3.0, -9.0), True),  # gravity off the root axis
    ],
)
@pytest.mark.parametrize(
    "forms",
    [
        Forms(run_links="never"),
        Forms(run_links="always"),
        Forms(two_rate_links=False),
        Forms(two_rate_links=False, run_links="never"),
    ],
    ids=repr,
)
def test_customized_tau_with_two_rate_links_equals_rust_rnea(origin, gravity, run, forms):
    """tau of the customized Newton-Euler (standard parameters) == the Rust rnea at random
    states, on arms where the second link's closed forms apply in full, in part, or not
    (its origin off the root's axis, gravity tilted), with and without the closed forms of
    the second link and of the run's link 3. On the PUMA-like arm the second link's form
    saves operations (on the others it may not: origin off the root's axis, no run)."""
    robot = _arm(origin, gravity, run)
    prog, defs = customized_newton_euler(robot, forms=forms)
    if forms.two_rate_links and origin == [0, 0, 0] and run:
        plain, _ = customized_newton_euler(robot, forms=Forms(two_rate_links=False, run_links=forms.run_links))
        assert prog.operation_counts()["total"] < plain.operation_counts()["total"]
    values = {s: float(e) for s, e in defs}
    rng = np.random.default_rng(5)
    for _ in range(5):
        q, qd, qdd = (rng.uniform(-1.5, 1.5, robot.dof) for _ in range(3))
        env = dict(values)
        for group, v in ((robot.q, q), (robot.qd, qd), (robot.qdd, qdd)):
            env.update({s: float(x) for s, x in zip(group, v)})
        got, want = np.array(prog.evaluate(env), dtype=float), armdyn.rnea(robot, q, qd, qdd)
        assert np.all(np.isfinite(got))
        np.testing.assert_allclose(got, want, rtol=1e-11, atol=1e-11 * max(1.0, np.abs(want).max()))


@pytest.mark.parametrize("run", [True, False])
def test_default_keeps_the_shorter_of_with_and_without_run_links(run):
    """The default (run_links "shorter") gives the program of the two, with and without the
    run links' closed forms, that has fewer operations."""
    robot = _arm([0, 0, 0], (0, 0, -9.81), run)
    totals = [
        customized_newton_euler(robot, forms=Forms(run_links=r))[0].operation_counts()["total"]
        for r in ("always", "never")
    ]
    assert customized_newton_euler(robot)[0].operation_counts()["total"] == min(totals)


def test_forms_rejects_an_unknown_run_links_choice():
    with pytest.raises(ValueError, match="run_links"):
        Forms(run_links="sometimes")
