"""Time to derive tau symbolically, armdyn vs sympy.physics.mechanics, in one process.

    python benchmarks/bench_derive.py                 # armdyn only, puma560 (all inertia symbolic)
    python benchmarks/bench_derive.py --mechanics     # + sympy.physics.mechanics LagrangesMethod (minutes)
    python benchmarks/bench_derive.py --robot rp-arm --repeat 7

Prints the median of ``--repeat`` runs for Newton-Euler and Lagrange (tau only; M, C, g
are split off lazily and not timed), and, with --mechanics, one run of
sympy.physics.mechanics on the same model and the ratio armdyn / mechanics.
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
    args = ap.parse_args()

    robot = armdyn.load(args.robot, strict=False)
    print(f"{robot.name}: {robot.dof} dof, {len(robot.parameters)} symbolic parameters")
    ne = timed(lambda: derive(robot, "newton-euler"), args.repeat)
    la = timed(lambda: derive(robot, "lagrange"), max(1, args.repeat // 2))
    print(f"armdyn newton-euler  tau: {ne:8.3f} s  (median of {args.repeat})")
    print(f"armdyn lagrange      tau: {la:8.3f} s  (median of {max(1, args.repeat // 2)})")
    if args.mechanics:
        from mechanics_bridge import mechanics_tau

        t0 = time.perf_counter()
        mechanics_tau(robot)
        mech = time.perf_counter() - t0
        print(f"sympy.physics.mechanics LagrangesMethod: {mech:8.3f} s  (1 run)")
        print(f"ratio armdyn/mechanics: newton-euler {ne / mech:.4f}, lagrange {la / mech:.4f}")


if __name__ == "__main__":
    main()
