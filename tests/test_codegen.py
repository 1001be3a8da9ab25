"""Generated code (armdyn.codegen) against independent second opinions:

* the customized symbolic algorithms (customized Newton-Euler, composite-link M, the
  Christoffel C of the differentiated M program) against armdyn.derive's Craig
  Newton-Euler / Walker-Orin M / Christoffel C of that M: exactly on small arms, at
  random points on the larger ones;
* the compiled C, and the Python and NumPy printers, against the Rust core
  (Featherstone's spatial algorithms) on every bundled arm, to 1e-12;
* op counts against sympy.count_ops itself; bad input.
"""

from __future__ import annotations

import os
import shutil
import subprocess
import sys
import warnings

import numpy as np
import pytest
import sympy as sp

import armdyn
import armdyn.printing as printing
from armdyn.printing.compile import CompilerError, build_shared_library
from armdyn.programs.composite_mass_matrix import composite_mass_matrix
from armdyn.programs.coriolis_program import christoffel_program
from armdyn.programs.customized_ne import customized_newton_euler, standard_parameters
from armdyn.programs.program import Builder, _fast_count
from armdyn.symbolic import dag, derive

BUNDLED = [r["name"] for r in armdyn.bundled_robots()]
HAVE_CC = shutil.which(os.environ.get("CC", "cc")) or shutil.which("gcc")
needs_cc = pytest.mark.skipif(not HAVE_CC, reason="no C compiler")


def _random_value(name, rng):
    """Physical random values for parameters with no published value (products of
    inertia small, moments in [1, 1.5] so any two exceed the third)."""
    if name.startswith(("Ixy", "Ixz", "Iyz")):
        return float(rng.uniform(-0.05, 0.05))
    if name.startswith(("Ixx", "Iyy", "Izz")):
        return float(rng.uniform(1.0, 1.5))
    return float(rng.uniform(0.5, 2.0))


def _load(name):
    with warnings.catch_warnings():
        warnings.filterwarnings("ignore", message=".*(triangle inequality|positive semi-definite)")
        return armdyn.load(name, strict=False)


def _values(robot, rng):
    """Every model parameter: published value, else a random physical one."""
    return {p: float(robot.defaults[p]) if p in robot.defaults else _random_value(p, rng) for p in robot.parameters}


def _numeric(robot, values):
    with warnings.catch_warnings():
        warnings.filterwarnings("ignore", message=".*(triangle inequality|positive semi-definite)")
        return robot.bind(values)


def _states(rng, n, samples=11):
    """Random states; 11 by default: one block of 8 lanes through the C batch code (the
    sin/cos kernel, the addition formula) and 3 through its single-state function."""
    return tuple(rng.uniform(-np.pi, np.pi, (samples, n)) for _ in range(3))


def _close(got, want):
    got, want = np.asarray(got), np.asarray(want)
    assert got.shape == want.shape
    assert np.all(np.isfinite(got)) and np.all(np.isfinite(want))
    np.testing.assert_allclose(got, want, rtol=1e-12, atol=1e-12 * max(1.0, np.abs(want).max()))


# ------------------------------------------------- customized algorithms == derive
def _substituted(outputs, definitions):
    table = dict(definitions)
    return [sp.sympify(e).xreplace(table) for e in outputs]


def _is_zero(expr, robot) -> bool:
    """expr == 0 identically: expanded, with sin(q)^2 reduced by sin^2 + cos^2 = 1."""
    expr = sp.expand(sp.expand_trig(expr))
    for q in robot.q:
        s, c = sp.Dummy("s"), sp.Dummy("c")
        expr = sp.expand(expr.xreplace({sp.sin(q): s, sp.cos(q): c}))
        expr = sp.rem(expr, s**2 + c**2 - 1, s) if expr.has(s) else expr
        expr = sp.expand(expr).xreplace({s: sp.sin(q), c: sp.cos(q)})
    return sp.expand(expr) == 0


@pytest.mark.parametrize("name", ["rp-arm", "planar-2r", "planar-3r", "scara"])
def test_customized_algorithms_equal_derive_exactly(name):
    robot = armdyn.load(name)
    eom = derive(robot, "newton-euler")
    n = robot.dof
    tau_prog, defs = customized_newton_euler(robot)
    tau = _substituted(tau_prog.inlined(), defs)
    for k in range(n):
        assert _is_zero(tau[k] - eom.tau[k], robot), f"tau[{k}]"
    params, defs = standard_parameters(robot)
    b = Builder(reserved=robot.free_symbols() | set(robot.q) | set(robot.qd) | {s for s, _ in defs})
    M_prog, _ = composite_mass_matrix(robot, params, builder=b)
    C_prog = christoffel_program(robot, M_prog, b)
    M = _substituted(M_prog.inlined(), defs)
    C = _substituted(C_prog.inlined(), defs)
    for k in range(n * n):
        assert _is_zero(M[k] - eom.M[k // n, k % n], robot), f"M[{k // n}, {k % n}]"
        assert _is_zero(C[k] - eom.C[k // n, k % n], robot), f"C[{k // n}, {k % n}]"


# a shoulder, then two joints about axes through one point (alpha -90, +90: the PUMA's
# wrist in small), every inertial parameter symbolic; gravity along -y so that no
# component of the base acceleration is zero
WRIST_3R = """
name: wrist-3r
description: "3R arm, joints 2 and 3 sharing an origin, all inertia symbolic"
convention: modified-dh
parameters: {
  L1: 0.3, g: 9.81,
  m1: null, cx1: null, cy1: null, cz1: null, Ixx1: null, Iyy1: null, Izz1: null, Ixy1: null, Ixz1: null, Iyz1: null,
  m2: null, cx2: null, cy2: null, cz2: null, Ixx2: null, Iyy2: null, Izz2: null, Ixy2: null, Ixz2: null, Iyz2: null,
  m3: null, cx3: null, cy3: null, cz3: null, Ixx3: null, Iyy3: null, Izz3: null, Ixy3: null, Ixz3: null, Iyz3: null,
}
gravity: [0, -g, 0]
dh:
  - {name: q1, type: revolute, link: link1, a: 0, alpha: 0, d: 0, theta: 0, mass: m1, com: [cx1, cy1, cz1],
     inertia: {ixx: Ixx1, iyy: Iyy1, izz: Izz1, ixy: Ixy1, ixz: Ixz1, iyz: Iyz1}}
  - {name: q2, type: revolute, link: link2, a: L1, alpha: -pi/2, d: 0, theta: 0, mass: m2, com: [cx2, cy2, cz2],
     inertia: {ixx: Ixx2, iyy: Iyy2, izz: Izz2, ixy: Ixy2, ixz: Ixz2, iyz: Iyz2}}
  - {name: q3, type: revolute, link: link3, a: 0, alpha: pi/2, d: 0, theta: 0, mass: m3, com: [cx3, cy3, cz3],
     inertia: {ixx: Ixx3, iyy: Iyy3, izz: Izz3, ixy: Ixy3, ixz: Ixz3, iyz: Iyz3}}
"""


@pytest.fixture
def wrist_3r(tmp_path):
    path = tmp_path / "wrist-3r.yaml"
    path.write_text(WRIST_3R)
    return _load(str(path))


@pytest.mark.parametrize("grouped", [False, True])
def test_customized_tau_equals_derive_exactly_on_a_shared_origin_wrist(wrist_3r, grouped):
    """Exact symbolic equality with armdyn.derive (Craig's Newton-Euler) on a spatial 3R
    arm whose joints 2, 3 share an origin (alpha = -90, +90 deg), in the standard and in
    the grouped parameters: the frames where every program transformation applies (the
    norm invariant of the child's angular velocity read off the parent's U, zeros of the
    grouping, p = 0 between links)."""
    _customized_tau_equals_derive(wrist_3r, grouped)


def _customized_tau_equals_derive(robot, grouped: bool):
    """Asserts that the customized Newton-Euler's tau, with the standard or the grouped
    parameters, equals armdyn.derive's exactly; returns the program."""
    from armdyn.programs.grouping import grouped_parameters

    eom = derive(robot, "newton-euler")
    params, defs = standard_parameters(robot)
    if grouped:
        params, extra = grouped_parameters(robot, params, defs)
        defs = defs + extra
    tau_prog, tdefs = customized_newton_euler(robot, parameters=params)
    tau = _substituted(_substituted(tau_prog.inlined(), tdefs), defs)
    for k in range(robot.dof):
        assert _is_zero(tau[k] - eom.tau[k], robot), f"tau[{k}]"
    return tau_prog


def _evaluated(assignments, env):
    """The program's temporaries at one numeric point (``env``: every input, floats)."""
    env = dict(env)
    for s, e in assignments:
        env[s] = float(sp.sympify(e).xreplace(env))
    return env


def _model_point(robot, rng, definitions=()):
    """Random joint state and model parameters, with ``definitions`` evaluated."""
    values = _values(robot, rng)
    env = {sp.Symbol(k): v for k, v in values.items()}
    for group in (robot.q, robot.qd, robot.qdd):
        env.update({s: float(rng.uniform(-1.5, 1.5)) for s in group})
    return _evaluated(definitions, env)


@pytest.mark.parametrize("name", ["puma560-craig", "puma560", "stanford", "ur5"])
def test_customized_algorithms_equal_derive_at_random_points(name):
    """All parameters symbolic (as loaded); tau and M at random values of q, qd, qdd and
    of every parameter."""
    robot = armdyn.load(name, strict=False)
    rng = np.random.default_rng(20261201)
    eom = derive(robot, "newton-euler")
    samples = 4
    symbols = sorted(robot.free_symbols() | set(robot.q) | set(robot.qd) | set(robot.qdd), key=str)
    values = {s: rng.uniform(-1.5, 1.5, samples) for s in symbols}
    tau_ref = dag.evaluate(eom.tau, values)[:, 0, :]  # (n, samples)
    M_ref = dag.evaluate(eom.M, values)  # (n, n, samples)
    tau_prog, defs = customized_newton_euler(robot)
    M_prog, _ = composite_mass_matrix(robot)
    assert samples > 0
    for k in range(samples):
        env = {s: float(v[k]) for s, v in values.items()}
        for s, e in defs:
            env[s] = float(e.xreplace(env))
        _close(tau_prog.evaluate(env), tau_ref[:, k])
        _close(np.reshape(M_prog.evaluate(env), (robot.dof, robot.dof)), M_ref[:, :, k])


# --------------------------------------------------- generated code == Rust core
@needs_cc
@pytest.mark.parametrize("name", BUNDLED)
def test_compiled_c_equals_rust_core(name, tmp_path):
    rng = np.random.default_rng(8)
    robot = _numeric(_load(name), _values(_load(name), rng))
    lib = printing.compile(robot, what=("tau", "M", "C", "g"), directory=tmp_path)
    assert lib.code.parameters == []
    q, qd, qdd = _states(rng, robot.dof)
    _close(lib.tau(q, qd, qdd), armdyn.rnea(robot, q, qd, qdd))
    _close(lib.M(q), armdyn.crba(robot, q))
    _close(lib.C(q, qd), armdyn.coriolis_matrix(robot, q, qd))
    _close(lib.g(q), armdyn.gravity(robot, q))
    # one state in, one state out; equal to the batch row
    _close(lib.tau(q[2], qd[2], qdd[2]), lib.tau(q, qd, qdd)[2])
    assert lib.M(q[0]).shape == (robot.dof, robot.dof)


@needs_cc
@pytest.mark.parametrize("name", ["puma560-craig", "rp-arm", "stanford"])
def test_compiled_c_with_symbolic_parameters_equals_rust_core(name, tmp_path):
    """Parameters left symbolic: the generated code takes them (barycentric ones
    computed from their definitions) in p."""
    robot = _load(name)
    rng = np.random.default_rng(3)
    values = _values(robot, rng)
    lib = printing.compile(robot, directory=tmp_path)
    p = lib.code.parameter_values(values)
    bound = _numeric(robot, values)
    q, qd, qdd = _states(rng, robot.dof)
    _close(lib.tau(q, qd, qdd, p=p), armdyn.rnea(bound, q, qd, qdd))
    _close(lib.M(q, p=p), armdyn.crba(bound, q))
    _close(lib.C(q, qd, p=p), armdyn.coriolis_matrix(bound, q, qd))
    _close(lib.g(q, p=p), armdyn.gravity(bound, q))


def _exec(source):
    namespace: dict = {}
    exec(compile(source, "<generated>", "exec"), namespace)
    return namespace


@pytest.mark.parametrize("name", ["rp-arm", "planar-3r", "puma560", "panda", "iiwa14"])
def test_python_and_numpy_code_equal_rust_core(name):
    rng = np.random.default_rng(11)
    robot = _numeric(_load(name), _values(_load(name), rng))
    q, qd, qdd = _states(rng, robot.dof, samples=3)
    n = robot.dof
    want = {
        "tau": armdyn.rnea(robot, q, qd, qdd),
        "M": armdyn.crba(robot, q),
        "C": armdyn.coriolis_matrix(robot, q, qd),
        "g": armdyn.gravity(robot, q),
    }
    args = {"tau": (q, qd, qdd), "M": (q,), "C": (q, qd), "g": (q,)}
    py = printing.codegen(robot, lang="python")
    ns = _exec(py.source)
    for what, fn in py.functions.items():
        for k in range(len(q)):
            got = np.array(ns[fn](*(a[k] for a in args[what])), dtype=float)
            _close(got.reshape(want[what][k].shape), want[what][k])
    npy = printing.codegen(robot, lang="numpy")
    ns = _exec(npy.source)
    for what, fn in npy.functions.items():
        _close(ns[fn](*args[what]), want[what])  # a batch (N, n)
        _close(ns[fn](*(a[1] for a in args[what])), want[what][1])  # one state (n,)
    assert want["M"].shape == (len(q), n, n)


# ---------------------------------------------------------------- operation counts
def test_fast_op_count_equals_sympy_count_ops():
    code = printing.codegen(armdyn.load("stanford"), lang="c")
    checked = 0
    for prog in code.programs.values():
        for e in [e for _, e in prog.assignments] + [sp.sympify(o) for o in prog.outputs]:
            fast = _fast_count(e)
            visual = sp.count_ops(e, visual=True)
            d = {} if visual == 0 else {k.name: int(v) for k, v in visual.as_coefficients_dict().items()}
            want = (
                d.get("MUL", 0) + d.get("DIV", 0) + d.get("POW", 0),
                d.get("ADD", 0) + d.get("SUB", 0),
                d.get("SIN", 0) + d.get("COS", 0),
            )
            if fast is not None:
                assert (fast["mul"], fast["add"], fast["sin_cos"]) == want, e
                checked += 1
    assert checked > 100


def test_puma_mass_matrix_op_count_meets_target():
    """OpenSYMORO's published M for the PUMA 560 takes 302 mul + 215 add; target 0.8x."""
    for name in ("puma560-craig", "puma560"):
        counts = printing.codegen(armdyn.load(name, strict=False), what="M").op_counts["M"]
        assert counts["total"] <= 0.8 * (302 + 215), counts


def test_op_counts_are_in_the_header():
    code = printing.codegen(armdyn.load("rp-arm"), what="tau,g", lang="c")
    c = code.op_counts["tau"]
    assert f"rp_arm_tau: {c['mul']} mul, {c['add']} add, {c['sin_cos']} sin/cos" in code.source
    assert c["mul"] > 0 and c["add"] > 0


# -------------------------------------------------------------------- bad input
def test_bad_what_and_lang():
    robot = armdyn.load("rp-arm")
    with pytest.raises(ValueError, match="unknown quantity 'taux'"):
        printing.codegen(robot, what="tau,taux")
    with pytest.raises(ValueError, match="unknown language 'fortran'"):
        printing.codegen(robot, lang="fortran")
    with pytest.raises(ValueError, match="empty"):
        printing.codegen(robot, what="")


@needs_cc
def test_compiled_function_rejects_bad_arrays(tmp_path):
    robot = _numeric(_load("planar-2r"), _values(_load("planar-2r"), np.random.default_rng(1)))
    lib = printing.compile(robot, what="tau,M", directory=tmp_path)
    ok = np.zeros(2)
    with pytest.raises(ValueError, match=r"q must have shape \(2,\) or \(N, 2\)"):
        lib.tau(np.zeros(3), ok, ok)
    with pytest.raises(ValueError, match="qd contains NaN or inf"):
        lib.tau(ok, np.array([0.0, np.nan]), ok)
    with pytest.raises(ValueError, match="qdd contains NaN or inf"):
        lib.tau(ok, ok, np.array([np.inf, 0.0]))
    with pytest.raises(ValueError, match="qd has shape"):
        lib.tau(np.zeros((4, 2)), np.zeros((3, 2)), np.zeros((4, 2)))
    with pytest.raises(TypeError, match="takes q, qd, qdd"):
        lib.tau(ok, ok)
    with pytest.raises(TypeError, match="holds tau, M"):
        lib(ok)


@needs_cc
def test_symbolic_code_needs_p(tmp_path):
    lib = printing.compile(armdyn.load("rp-arm"), what="g", directory=tmp_path)
    with pytest.raises(ValueError, match="p is required"):
        lib(np.zeros(2))
    with pytest.raises(ValueError, match=r"p must have shape"):
        lib(np.zeros(2), p=np.zeros(1))


def test_missing_compiler_is_a_clear_error(tmp_path):
    with pytest.raises(CompilerError, match="no C compiler found"):
        build_shared_library("int x;", tmp_path, cc="/nonexistent/armdyn-cc")


@needs_cc
def test_compiler_failure_shows_its_message(tmp_path):
    with pytest.raises(CompilerError, match="failed on .*error"):
        build_shared_library("this is not C;", tmp_path)


# --------------------------------------------------------------------------- CLI
def _cli(*args, cwd=None):
    env = dict(os.environ, PYTHONPATH=os.path.join(os.path.dirname(__file__), "..", "python"))
    return subprocess.run(
        [sys.executable, "-m", "armdyn", *args], capture_output=True, text=True, env=env, cwd=cwd, timeout=600
    )


@needs_cc
def test_cli_writes_c_that_compiles(tmp_path):
    out = tmp_path / "gen"
    res = _cli("codegen", "planar-2r", "--what", "tau,M", "--lang", "c", "--bind", "--out", str(out))
    assert res.returncode == 0, res.stderr
    files = os.listdir(out)
    assert files == ["planar_2r_dynamics.c"]
    build_shared_library((out / files[0]).read_text(), tmp_path / "build")


def test_cli_unknown_what_is_one_line_and_writes_nothing(tmp_path):
    out = tmp_path / "gen"
    res = _cli("codegen", "rp-arm", "--what", "tau,jerk", "--out", str(out))
    assert res.returncode == 2
    assert res.stderr.startswith("armdyn: error:") and "jerk" in res.stderr
    assert len(res.stderr.strip().splitlines()) == 1
    assert not out.exists()


# ------------------------------------------------------------- base parameters
def _symbolic_planar_2r():
    """A planar 2R arm (parallel z axes, gravity in the plane) with all 20 inertial
    parameters symbolic."""
    names = [f"{k}{i}" for i in (1, 2) for k in ("m", "cx", "cy", "cz", "Ixx", "Iyy", "Izz", "Ixy", "Ixz", "Iyz")]
    P = {n_: sp.Symbol(n_) for n_ in names + ["l1", "g"]}
    links = [armdyn.Link("base")]
    for i in (1, 2):
        I = sp.Matrix(
            [
                [P[f"Ixx{i}"], P[f"Ixy{i}"], P[f"Ixz{i}"]],
                [P[f"Ixy{i}"], P[f"Iyy{i}"], P[f"Iyz{i}"]],
                [P[f"Ixz{i}"], P[f"Iyz{i}"], P[f"Izz{i}"]],
            ]
        )
        links.append(armdyn.Link(f"link{i}", P[f"m{i}"], [P[f"cx{i}"], P[f"cy{i}"], P[f"cz{i}"]], I))
    joints = [
        armdyn.Joint("q1", "revolute", "base", "link1"),
        armdyn.Joint("q2", "revolute", "link1", "link2", xyz=[P["l1"], 0, 0]),
    ]
    return armdyn.Robot("planar-2r-full", links, joints, gravity=[0, -P["g"], 0], parameters=P)


@needs_cc
def test_base_parameter_code_equals_rust_core(tmp_path):
    """Code in the base parameters of armdyn.identification (Khalil's grouping, exact)
    on a planar 2R with every parameter symbolic, compiled, against the Rust core with
    the same numbers."""
    from armdyn import identification

    robot = _symbolic_planar_2r()
    code = printing.codegen(robot, what="tau,g,M,C", base=True)
    assert all("at the base parameters" in code.sources[w] for w in ("tau", "g", "M", "C"))
    full = printing.codegen(robot, what="tau,M")
    # the standard-parameter code groups the parameters too (symbolic/grouping.py): the
    # base code costs no more than it, and less than the ungrouped customized Newton-Euler
    assert code.op_counts["tau"]["total"] <= full.op_counts["tau"]["total"]
    assert code.op_counts["tau"]["total"] < customized_newton_euler(robot)[0].operation_counts()["total"]
    rng = np.random.default_rng(4)
    values = {name: _random_value(name, rng) for name in robot.parameters}
    sym = {sp.Symbol(k): v for k, v in values.items()}
    reg = identification.regressor(robot)
    std = {str(s): float(sp.sympify(e).xreplace(sym)) for s, e in zip(reg.symbols, reg.pi)}
    std.update(values)
    lib = printing.compile(code, directory=tmp_path)
    p = code.parameter_values(std)
    bound = _numeric(robot, values)
    q, qd, qdd = _states(rng, 2)
    _close(lib.tau(q, qd, qdd, p=p), armdyn.rnea(bound, q, qd, qdd))
    _close(lib.g(q, p=p), armdyn.gravity(bound, q))
    _close(lib.M(q, p=p), armdyn.crba(bound, q))
    _close(lib.C(q, qd, p=p), armdyn.coriolis_matrix(bound, q, qd))


@needs_cc
@pytest.mark.parametrize("name", ["planar-2r", "puma560-craig", "stanford"])
def test_compiled_c_with_joint_friction_and_rotor_inertia_equals_rust_core(name, tmp_path):
    """Symbolic Ia, Fv, Fc per joint (armdyn.identification.with_symbolic_joint_terms):
    the generated tau, M, g, C (standard parameters) against the Rust core with the same
    numbers; both signs of qd (Coulomb friction) in the states."""
    from armdyn import identification

    robot = identification.with_symbolic_joint_terms(_load(name))
    rng = np.random.default_rng(12)
    values = _values(robot, rng)
    assert {"IA1", "FV1", "FC1"} <= set(values)
    lib = printing.compile(robot, what="tau,M,C,g", directory=tmp_path)
    p = lib.code.parameter_values(values)
    bound = _numeric(robot, values)
    q, qd, qdd = _states(rng, robot.dof)
    assert (qd > 0).any() and (qd < 0).any()
    _close(lib.tau(q, qd, qdd, p=p), armdyn.rnea(bound, q, qd, qdd))
    _close(lib.M(q, p=p), armdyn.crba(bound, q))
    _close(lib.g(q, p=p), armdyn.gravity(bound, q))
    _close(lib.C(q, qd, p=p), armdyn.coriolis_matrix(bound, q, qd))
    py = printing.codegen(robot, what="tau", lang="python")
    ns = _exec(py.source)
    p = py.parameter_values(values)  # this code's own parameter vector (tau alone needs fewer)
    for k in range(len(q)):
        _close(ns[py.functions["tau"]](q[k], qd[k], qdd[k], p), armdyn.rnea(bound, q[k], qd[k], qdd[k]))
