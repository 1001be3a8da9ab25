"""Identification models: armdyn vs SymPyBotics (symbolic) and vs Pinocchio (numeric).

    PYTHONPATH=python python benchmarks/bench_identification.py [--repeat 3] [--number 20000]

1. Symbolic, PUMA 560 (Craig's modified DH, the bundled ``puma560-craig``) with all 60
   inertial parameters symbolic and the geometry numeric (a2, a3, d3, d4 bound to Craig's
   values; gravity g symbolic):
   * ``armdyn.identification.regressor(robot)`` vs SymPyBotics' ``Dynamics.gen_regressor``
     (after its ``Geometry``), the same model;
   * ``armdyn.identification.base_parameters(robot)`` (regressor included) vs SymPyBotics'
     ``RobotDynCode(...)`` + ``calc_base_parms()`` (its only route to base parameters: it
     also generates tau, M, C, g and their common subexpressions, then groups by a
     numeric QR of the regressor at random states);
   * armdyn with friction and rotor inertia (Fv, Fc, Ia symbolic per joint), and with
     the geometry symbolic too (SymPyBotics' numeric QR cannot give symbolic lengths).
   Each armdyn time is the median of ``--repeat`` runs, SymPy's cache cleared before each;
   SymPyBotics is run once (it takes tens of seconds).
   SymPyBotics is not on PyPI; it is used when importable (a source checkout on
   PYTHONPATH). It calls ``numpy.mat``, removed in NumPy 2: the benchmark aliases it to
   ``numpy.asmatrix`` (same thing) before calling it, and changes nothing else.
2. Numeric, one state from Python: ``armdyn.numeric.regressor(robot, q, qd, qdd)`` vs
   ``pin.computeJointTorqueRegressor(model, data, q, v, a)`` on the bundled ``puma560``
   (numeric, published values) and ``ur5``: median over ``--repeat`` timeit runs of
   ``--number`` calls, the two alternating. Plus armdyn's batch per state (N = 1e4,
   threads=1). Ratio = armdyn / Pinocchio (below 1: armdyn faster). Checked equal first.

Not a test: timings depend on the machine and its load.
"""

from __future__ import annotations

import argparse
import os
import statistics
import sys
import time
import timeit
import warnings

import numpy as np
import sympy as sp

HERE = os.path.dirname(os.path.abspath(__file__))
sys.path.insert(0, os.path.join(HERE, "..", "tests"))

import armdyn  # noqa: E402
from armdyn import numeric as num  # noqa: E402
from armdyn.identification import base_parameters, regressor, with_symbolic_joint_terms  # noqa: E402


def median_time(f, repeat: int) -> tuple[float, object]:
    times, out = [], None
    for _ in range(repeat):
        sp.core.cache.clear_cache()
        t = time.perf_counter()
        out = f()
        times.append(time.perf_counter() - t)
    return statistics.median(times), out


def puma_craig(symbolic_geometry: bool = False):
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        robot = armdyn.load("puma560-craig", strict=False)
        if not symbolic_geometry:
            robot = robot.bind({k: robot.defaults[k] for k in ("a2", "a3", "d3", "d4")})
    return robot


def sympybotics_puma():
    """SymPyBotics' definition of the same arm (modified DH rows alpha, a, d, theta)."""
    import sympybotics

    q, pi = sympybotics.robotdef.q, sp.pi
    robot = puma_craig()
    d = {k: float(v) for k, v in armdyn.load("puma560-craig", strict=False).defaults.items()}
    rows = [
        (0, 0, 0, q),
        (-pi / 2, 0, 0, q),
        (0, d["a2"], d["d3"], q),
        (-pi / 2, d["a3"], d["d4"], q),
        (pi / 2, 0, 0, q),
        (-pi / 2, 0, 0, q),
    ]
    rbt = sympybotics.RobotDef("Puma", rows, dh_convention="modified")
    rbt.frictionmodel = None
    return rbt, robot


def symbolic_part(repeat: int):
    print("## Symbolic: PUMA 560 (puma560-craig), 60 inertial parameters symbolic\n")
    robot = puma_craig()
    t_reg, reg = median_time(lambda: regressor(robot), repeat)
    t_base, base = median_time(lambda: base_parameters(robot), repeat)
    friction = with_symbolic_joint_terms(robot)
    t_fric, base_f = median_time(lambda: base_parameters(friction), repeat)
    symbolic = puma_craig(symbolic_geometry=True)
    t_sym, base_s = median_time(lambda: base_parameters(symbolic), repeat)
    print(
        f"armdyn regressor ({reg.Y.shape[0]}x{reg.Y.shape[1]}):                       {t_reg:7.3f} s  (median of {repeat})"
    )
    print(f"armdyn base parameters, regressor included ({len(base.names)}):     {t_base:7.3f} s")
    print(f"armdyn base parameters with Fv, Fc, Ia ({len(base_f.names)}):          {t_fric:7.3f} s")
    print(f"armdyn base parameters, geometry symbolic too ({len(base_s.names)}):   {t_sym:7.3f} s")
    try:
        import sympybotics  # noqa: F401
    except ImportError as exc:
        print(
            f"\nSymPyBotics: not importable ({exc}); it is not on PyPI (`pip install sympybotics`:"
            " 'No matching distribution found'): put a source checkout on PYTHONPATH to compare."
        )
        return
    np.mat = np.asmatrix  # SymPyBotics predates NumPy 2 (see the module docstring)
    from sympybotics.dynamics.dynamics import Dynamics
    from sympybotics.geometry import Geometry

    rbtdef, _ = sympybotics_puma()
    sp.core.cache.clear_cache()
    t = time.perf_counter()
    dyn = Dynamics(rbtdef, Geometry(rbtdef))
    dyn.gen_regressor()
    t_spb_reg = time.perf_counter() - t
    sp.core.cache.clear_cache()
    t = time.perf_counter()
    code = sympybotics.RobotDynCode(rbtdef)
    code.calc_base_parms()
    t_spb_base = time.perf_counter() - t
    print(f"SymPyBotics gen_regressor ({dyn.H.shape[0]}x{dyn.H.shape[1]}):                {t_spb_reg:7.3f} s  (1 run)")
    print(
        f"SymPyBotics RobotDynCode + calc_base_parms ({dyn.n_base if hasattr(dyn, 'n_base') else code.dyn.n_base}): {t_spb_base:7.3f} s  (1 run)"
    )
    print(f"ratio armdyn/SymPyBotics: regressor {t_reg / t_spb_reg:.3f}, base parameters {t_base / t_spb_base:.3f}")
    beta = code.dyn.baseparms
    print(f"SymPyBotics' beta[0]: {sp.sympify(beta[0])}")
    print(f"armdyn's    {base.names[0]} = {base.beta[0]}\n")


def numeric_part(repeat: int, number: int):
    import pinocchio as pin
    from pinocchio_bridge import PinocchioRobot

    print("## Numeric regressor, one state from Python\n")
    rng = np.random.default_rng(0)
    for name in ("puma560", "ur5"):
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            robot = armdyn.load(name, strict=False).bind()
        P = PinocchioRobot(robot)
        n = robot.dof
        q, qd, qdd = (rng.uniform(-1, 1, n) for _ in range(3))
        ours = num.regressor(robot, q, qd, qdd)
        theirs = pin.computeJointTorqueRegressor(P.model, P.data, q, qd, qdd)
        assert np.allclose(ours, theirs, rtol=1e-11, atol=1e-11), "regressors differ"
        f_ours = timeit.Timer("f(r, a, b, c)", globals={"f": num.regressor, "r": robot, "a": q, "b": qd, "c": qdd})
        f_pin = timeit.Timer(
            "f(m, d, a, b, c)",
            globals={"f": pin.computeJointTorqueRegressor, "m": P.model, "d": P.data, "a": q, "b": qd, "c": qdd},
        )
        a_times, p_times = [], []
        for _ in range(repeat):
            a_times.append(f_ours.timeit(number) / number)
            p_times.append(f_pin.timeit(number) / number)
        ta, tp = statistics.median(a_times), statistics.median(p_times)
        N = 10_000
        Q, QD, QDD = (rng.uniform(-1, 1, (N, n)) for _ in range(3))
        tb = min(timeit.repeat(lambda: num.regressor(robot, Q, QD, QDD, threads=1), number=1, repeat=repeat)) / N
        print(
            f"{name:8s} armdyn {ta * 1e6:6.2f} us/call, Pinocchio {tp * 1e6:6.2f} us/call, ratio {ta / tp:.2f};"
            f" armdyn batch (N=1e4, 1 thread) {tb * 1e6:6.2f} us/state, ratio {tb / tp:.2f}"
        )


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--repeat", type=int, default=3)
    ap.add_argument("--number", type=int, default=20000)
    ap.add_argument("--skip-symbolic", action="store_true")
    args = ap.parse_args()
    if not args.skip_symbolic:
        symbolic_part(args.repeat)
    numeric_part(args.repeat, args.number)


if __name__ == "__main__":
    main()
