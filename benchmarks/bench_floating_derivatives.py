"""Derivatives on a floating base: armdyn.numeric vs Pinocchio per call from Python, side by
side in one process, on example-robot-data's solo12, anymal and talos (free-flyer root).

    python benchmarks/bench_floating_derivatives.py            # full run
    python benchmarks/bench_floating_derivatives.py --quick    # smoke run: fewer repeats

(with armdyn importable: ``PYTHONPATH=python`` after a release build).

``armdyn.numeric.rnea_derivatives(robot, q, v, a)`` vs
``pin.computeRNEADerivatives(model, data, q, v, a)`` on the same arrays (Pinocchio's layout;
d/dq on the tangent space in both), likewise ``aba_derivatives`` vs
``computeABADerivatives`` and ``minverse`` vs ``computeMinverse``. armdyn returns three
fresh (nv, nv) arrays per call (Pinocchio returns views of its Data). Each time is the
median over ``--repeat`` runs of ``timeit`` with ``--number`` calls each, the two
libraries' runs alternating (bench_numeric.paired_medians). Before timing each robot is
checked: armdyn == Pinocchio to 1e-10 (relative, the aba results scaled by cond(M) / 1e6
as in tests/test_floating_derivatives.py). Ratios are armdyn time / Pinocchio time.

Not a test: timings depend on the machine and its load.
"""

from __future__ import annotations

import argparse
import os
import platform
import sys

import numpy as np
import pinocchio as pin

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from bench_floating import ROBOTS, load_pair  # noqa: E402
from bench_numeric import paired_medians, per_call_run  # noqa: E402

from armdyn import numeric as num  # noqa: E402


def relative(mine, theirs) -> float:
    theirs = np.asarray(theirs)
    return float(np.max(np.abs(mine - theirs)) / max(1.0, np.max(np.abs(theirs))))


def sym(A) -> np.ndarray:
    """Pinocchio fills the upper triangle of M and M^-1."""
    A = np.asarray(A)
    return np.triu(A) + np.triu(A, 1).T


def check(robot, model, data, q, v, a, tau) -> None:
    """armdyn == Pinocchio on this state, or an AssertionError naming what differs."""
    tol = 1e-10
    for what, mine, theirs in zip(
        ("dtau_dq", "dtau_dv", "M"),
        num.rnea_derivatives(robot, q, v, a),
        pin.computeRNEADerivatives(model, data, q, v, a),
    ):
        assert relative(mine, sym(theirs) if what == "M" else theirs) < tol, what
    M = num.crba(robot, q)
    tol_aba = tol * max(1.0, np.linalg.cond(M) / 1e6)
    for what, mine, theirs in zip(
        ("dqdd_dq", "dqdd_dv", "Minv"),
        num.aba_derivatives(robot, q, v, tau),
        pin.computeABADerivatives(model, data, q, v, tau),
    ):
        assert relative(mine, sym(theirs) if what == "Minv" else theirs) < tol_aba, what
    assert relative(num.minverse(robot, q), sym(pin.computeMinverse(model, data, q))) < tol_aba, "minverse"


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--quick", action="store_true")
    parser.add_argument("--repeat", type=int, default=15)
    parser.add_argument("--number", type=int, default=2000)
    args = parser.parse_args()
    repeat, number = (5, 300) if args.quick else (args.repeat, args.number)
    print(f"{platform.processor() or platform.machine()}, Python {platform.python_version()}, pin {pin.__version__}")
    print(f"median of {repeat} runs x {number} calls; ratio = armdyn / Pinocchio\n")
    print("| robot | nv | algorithm | armdyn (us) | Pinocchio (us) | ratio |")
    print("| --- | --- | --- | --- | --- | --- |")
    rng = np.random.default_rng(0)
    for name in ROBOTS:
        robot, model = load_pair(name)
        data = model.createData()
        q = num.random_configuration(robot, rng)
        v, a = rng.uniform(-1, 1, (2, robot.nv))
        tau = num.rnea(robot, q, v, a)
        check(robot, model, data, q, v, a, tau)
        cases = {
            "rnea_derivatives": (
                (num.rnea_derivatives, (robot, q, v, a)),
                (pin.computeRNEADerivatives, (model, data, q, v, a)),
            ),
            "aba_derivatives": (
                (num.aba_derivatives, (robot, q, v, tau)),
                (pin.computeABADerivatives, (model, data, q, v, tau)),
            ),
            "minverse": ((num.minverse, (robot, q)), (pin.computeMinverse, (model, data, q))),
        }
        for algo, ((f, fa), (g, ga)) in cases.items():
            mine, theirs = paired_medians(per_call_run(f, fa, number), per_call_run(g, ga, number), repeat)
            print(f"| {name} | {robot.nv} | {algo} | {mine * 1e6:.2f} | {theirs * 1e6:.2f} | {mine / theirs:.2f} |")


if __name__ == "__main__":
    main()
