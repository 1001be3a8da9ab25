"""A leaf link's frame turned about its joint axis to put its first moment on y
(armdyn.programs.leaf_frames): tau exactly armdyn.derive's for any angle, the turned
inertia grouped onto the parent, and the compiled code right where the first moment is
zero (against the Rust core)."""

from __future__ import annotations

import numpy as np
import sympy as sp
from test_codegen import WRIST_3R, _close, _load, _model_point, _numeric, _states, _substituted, _values, needs_cc

import armdyn
import armdyn.printing as printing
from armdyn.programs.customized_ne import customized_newton_euler, standard_parameters
from armdyn.symbolic import derive


def _wrist_3r(tmp_path):
    """The wrist arm of test_codegen (joints 2, 3 sharing an origin), every parameter symbolic."""
    path = tmp_path / "wrist-3r.yaml"
    path.write_text(WRIST_3R)
    return _load(str(path))


def _is_zero_in(expr, angles) -> bool:
    """expr == 0 identically: expanded (trig sums too), sin^2 + cos^2 = 1 for each angle."""
    expr = sp.expand(sp.expand_trig(expr))
    for q in angles:
        s, c = sp.Dummy("s"), sp.Dummy("c")
        expr = sp.expand(expr.xreplace({sp.sin(q): s, sp.cos(q): c}))
        expr = sp.rem(expr, s**2 + c**2 - 1, s) if expr.has(s) else expr
        expr = sp.expand(expr).xreplace({s: sp.sin(q), c: sp.cos(q)})
    return sp.expand(expr) == 0


def test_turned_leaf_frame_gives_the_same_tau_exactly_for_any_angle(tmp_path):
    """The leaf link's frame turned about its joint axis by a free angle th (joint angle
    q3 + th, first moment and inertia turned with it, grouped parameters): tau equals
    armdyn.derive's exactly, for every th. And the angle turn_leaf_frames picks puts the
    first moment on y: its MX' is zero and its MY' is |(MX, MY)| (exact)."""
    from armdyn.programs.grouping import grouped_parameters
    from armdyn.programs.leaf_frames import _turned, turn_leaf_frames

    robot = _wrist_3r(tmp_path)
    eom = derive(robot, "newton-euler")
    params, defs = standard_parameters(robot)
    params, extra = grouped_parameters(robot, params, defs)
    defs = defs + extra
    th = sp.Symbol("th")
    turned = dict(params)
    turned["link3"] = _turned(*params["link3"], sp.cos(th), sp.sin(th))
    tau_prog, tdefs = customized_newton_euler(robot, parameters=turned, turns={"link3": th})
    tau = _substituted(_substituted(tau_prog.inlined(), tdefs), defs)
    for k in range(robot.dof):
        assert _is_zero_in(tau[k] - eom.tau[k], list(robot.q) + [th]), f"tau[{k}]"
    # the chosen angle
    chosen, new, turns = turn_leaf_frames(robot, params, defs)
    assert set(turns) == {"link3"}
    M, MS, J = params["link3"]
    assert chosen["link3"][1][0] == 0
    r = sp.sqrt(MS[0] ** 2 + MS[1] ** 2)
    th = dict(new)[turns["link3"]].args[0][0]  # the angle where |(MX, MY)| != 0
    _, MSt, _ = _turned(M, MS, J, sp.cos(th), sp.sin(th))
    assert sp.simplify(MSt[0]) == 0 and sp.simplify(MSt[1] - r) == 0
    assert sp.simplify(dict(new)[chosen["link3"][1][1]] - r) == 0


def test_turned_leaf_inertia_rides_on_its_parent(tmp_path):
    """After the leaf's frame is turned, its YY' (nonzero again) is grouped onto the parent
    like Khalil's YY: the leaf's YY is 0 and the parent's XX, ZZ take it; tau of the
    customized Newton-Euler with these parameters equals armdyn.derive's at random
    points (the turned parameters are Piecewise in the model's)."""
    from armdyn.programs.grouping import grouped_parameters
    from armdyn.programs.leaf_frames import turn_leaf_frames

    robot = _wrist_3r(tmp_path)
    params, defs = standard_parameters(robot)
    params, extra = grouped_parameters(robot, params, defs)
    defs = defs + extra
    turned, new, turns = turn_leaf_frames(robot, params, defs)
    assert set(turns) == {"link3"} and turned["link3"][2][1, 1] == 0
    assert turned["link2"][2][0, 0] != params["link2"][2][0, 0]
    tau_prog, tdefs = customized_newton_euler(robot, parameters=turned, turns=turns)
    eom = derive(robot, "newton-euler")
    rng = np.random.default_rng(8)
    for _ in range(3):
        env = _model_point(robot, rng, defs + new + tdefs)
        got = np.array(tau_prog.evaluate(env), dtype=float)
        want = np.array([float(e.xreplace(env)) for e in eom.tau], dtype=float)
        _close(got, want)


@needs_cc
def test_turned_leaf_frame_with_zero_first_moment_is_finite_and_right(tmp_path):
    """A leaf whose first moment is zero (MX = MY = 0, the symmetric end link of most
    arms) at run time: the turning angle is 0 (no division by |(MX, MY)| = 0), the
    parameter vector is finite and tau, g equal the Rust core."""
    robot = _load("puma560-craig")
    rng = np.random.default_rng(5)
    values = _values(robot, rng)
    values.update(cx6=0.0, cy6=0.0)
    lib = printing.compile(robot, what="tau,g", directory=tmp_path)
    assert any(str(s).startswith("th6") for s in lib.code.parameters)
    p = lib.code.parameter_values(values)
    assert np.all(np.isfinite(p)) and p.size > 0
    bound = _numeric(robot, values)
    q, qd, qdd = _states(rng, robot.dof)
    _close(lib.tau(q, qd, qdd, p=p), armdyn.rnea(bound, q, qd, qdd))
    _close(lib.g(q, p=p), armdyn.gravity(bound, q))
