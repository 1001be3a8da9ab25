"""Time to derive tau symbolically, armdyn vs sympy.physics.mechanics, in one process.

    python benchmarks/bench_derive.py                 # armdyn only, puma560 (all inertia symbolic)
    python benchmarks/bench_derive.py --mechanics     # + sympy.physics.mechanics LagrangesMethod (minutes)
    python benchmarks/bench_derive.py --robot rp-arm --repeat 7

Prints the median of ``--repeat`` runs for Newton-Euler and Lagrange (tau only; M, C, g
are split off lazily and not timed), and, with --mechanics, one run of
sympy.physics.mechanics on the same model and the ratio armdyn / mechanics.

Like for like: both sides are timed to the same representation of the result, tau as
a SymPy Matrix (n x 1) of unsimplified expressions in plain symbols (q, qd, qdd) —
armdyn's ``derive(robot).tau``; for mechanics ``LagrangesMethod.form_lagranges_equations``
plus one ``xreplace`` of its dynamic symbols by the same plain symbols (the time of
each part is printed). The size of each result (operations, ``sympy.count_ops``) is
printed with ``--sizes``; ``--expand`` also times ``sympy.expand`` of both results
(a canonical form both must reach), for arms small enough to expand.
"""

from __future__ import annotations

import argparse
import statistics
import sys
import time
from pathlib import Path

import armdyn
from armdyn.symbolic import derive

sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "tests"))


def timed(fn, repeat: int) -> float:
    runs = []
    for _ in range(repeat):
        t0 = time.perf_counter()
        fn()
        runs.append(time.perf_counter() - t0)
    return statistics.median(runs)


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--robot", default="puma560")
    ap.add_argument("--repeat", type=int, default=5)
    ap.add_argument("--mechanics", action="store_true", help="also time sympy.physics.mechanics (slow)")
    ap.add_argument("--sizes", action="store_true", help="print count_ops of each tau (slow for big arms)")
    ap.add_argument("--expand", action="store_true", help="also time sympy.expand of each tau (small arms)")
    args = ap.parse_args()

    robot = armdyn.load(args.robot, strict=False)
    print(f"{robot.name}: {robot.dof} dof, {len(robot.parameters)} symbolic parameters")
    ne = timed(lambda: derive(robot, "newton-euler"), args.repeat)
    la = timed(lambda: derive(robot, "lagrange"), max(1, args.repeat // 2))
    print(f"armdyn newton-euler  tau: {ne:8.3f} s  (median of {args.repeat})")
    print(f"armdyn lagrange      tau: {la:8.3f} s  (median of {max(1, args.repeat // 2)})")
    if args.mechanics:
        import sympy as sp
        from mechanics_bridge import mechanics_equations, plain_symbols

        t0 = time.perf_counter()
        eqs, names = mechanics_equations(robot)
        t1 = time.perf_counter()
        tau_m = plain_symbols(eqs, names)
        t2 = time.perf_counter()
        mech = t2 - t0
        print(
            f"sympy.physics.mechanics LagrangesMethod: {t1 - t0:8.3f} s  + xreplace to plain symbols "
            f"{t2 - t1:.3f} s = {mech:.3f} s  (1 run)"
        )
        print(
            f"ratio armdyn/mechanics (same representation: unsimplified tau in plain symbols): "
            f"newton-euler {ne / mech:.4f}, lagrange {la / mech:.4f}"
        )
        results = {
            "armdyn newton-euler": derive(robot, "newton-euler").tau,
            "armdyn lagrange": derive(robot, "lagrange").tau,
            "mechanics": tau_m,
        }
        if args.sizes:
            for k, v in results.items():
                print(f"size of tau, {k:<20}: {sum(sp.count_ops(e) for e in v):>9} operations")
        if args.expand:
            for k, v in results.items():
                t0 = time.perf_counter()
                expanded = v.applyfunc(sp.expand)
                print(
                    f"sympy.expand of tau, {k:<20}: {time.perf_counter() - t0:8.3f} s, "
                    f"{sum(sp.count_ops(e) for e in expanded)} operations"
                )


if __name__ == "__main__":
    main()
