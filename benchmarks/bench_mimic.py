"""Robots with mimic joints: armdyn.numeric (armdyn.mimic.MimicModel: the Rust core on the
full tree, mapped by G in NumPy) vs Pinocchio's mimic model
(``buildModelFromUrdf(path, mimic=True)``), side by side in one process.

    PYTHONPATH=python python3 benchmarks/bench_mimic.py            # Panda with its hand, PR2, TIAGo Pro
    PYTHONPATH=python python3 benchmarks/bench_mimic.py --quick    # fewer repeats, N = 5e3

1. Per call from Python, one state: rnea and crba; forward dynamics: ``armdyn.aba`` vs
   Pinocchio's crba + nonLinearEffects + a NumPy Cholesky solve (Pinocchio 4.1 has no aba
   with mimic joints). Also armdyn's rnea on the same URDF read without ``<mimic>`` (every
   joint free: the Rust model alone), to show what the G mapping costs.
2. Batches of N = 2e4 states, 2 threads: armdyn's batched rnea vs ``pin.rneaInParallel``;
   armdyn's batched forward dynamics alone (it holds N full mass matrices at once).

Each time is the median of ``--repeat`` runs; the two libraries' runs alternate. Before
timing, armdyn == Pinocchio (rnea) is checked at a random state. Ratios are armdyn time /
Pinocchio time (below 1: armdyn faster). Not a test: timings depend on the machine's load.
"""

from __future__ import annotations

import os

os.environ.setdefault("OMP_WAIT_POLICY", "passive")  # see bench_numeric.py

import argparse  # noqa: E402
import importlib.metadata  # noqa: E402
import statistics  # noqa: E402
import sys  # noqa: E402
import timeit  # noqa: E402
import warnings  # noqa: E402
from pathlib import Path  # noqa: E402

import numpy as np  # noqa: E402
import pinocchio as pin  # noqa: E402

sys.path.insert(0, str(Path(__file__).resolve().parent.parent / "tests"))
from test_urdf import pin_configuration  # noqa: E402

from armdyn import numeric as num  # noqa: E402
from armdyn.io.urdf import load_urdf  # noqa: E402

ROBOTS = {
    "panda (hand)": "panda_description/urdf/panda.urdf",
    "pr2": "pr2_description/urdf/pr2.urdf",
    "tiago_pro": "tiago_pro_description/robots/tiago_pro.urdf",
}


def load(path: Path, text: str | None = None):
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        try:
            return load_urdf(text or path)
        except ValueError:
            return load_urdf(text or path, strict=False)  # published inertias that are not physical


def median_time(f, number: int, repeat: int) -> float:
    timer = timeit.Timer(f)
    return statistics.median(timer.timeit(number) / number for _ in range(repeat))


def pair(fa, fb, number: int, repeat: int) -> tuple[float, float]:
    """Medians of alternating runs of fa and fb (seconds per call)."""
    ta, tb = [], []
    for _ in range(repeat):
        ta.append(timeit.Timer(fa).timeit(number) / number)
        tb.append(timeit.Timer(fb).timeit(number) / number)
    return statistics.median(ta), statistics.median(tb)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--quick", action="store_true")
    args = parser.parse_args()
    number, repeat, N, batch_repeat = (2000, 5, 5_000, 3) if args.quick else (5000, 9, 20_000, 5)
    root = Path(
        importlib.metadata.distribution("example-robot-data").locate_file(
            "cmeel.prefix/share/example-robot-data/robots"
        )
    )
    rng = np.random.default_rng(0)
    print(f"Pinocchio {pin.__version__}; N = {N} for batches; times are medians, ratio = armdyn / Pinocchio")
    for label, rel in ROBOTS.items():
        path = root / rel
        # Pinocchio's rnea has no joint friction or damping: the URDF's <dynamics> left out
        robot = load(path).without_joint_dynamics()
        free = load(
            path, "\n".join(line for line in path.read_text().splitlines() if "<mimic" not in line)
        ).without_joint_dynamics()
        model = pin.buildModelFromUrdf(str(path), mimic=True)
        data = model.createData()
        n = robot.dof
        q, qd, qdd = rng.uniform(-1, 1, n), rng.uniform(-1, 1, n), rng.uniform(-1, 1, n)
        qp, perm = pin_configuration(model, robot, q)
        v, a = qd[perm], qdd[perm]
        tau = num.rnea(robot, q, qd, qdd)
        assert np.abs(tau[perm] - pin.rnea(model, data, qp, v, a)).max() < 1e-9 * max(1, np.abs(tau).max())
        tau_p = tau[perm]
        qf = rng.uniform(-1, 1, free.dof)

        def pin_fd():
            M = pin.crba(model, data, qp)
            M = np.triu(M) + np.triu(M, 1).T
            L = np.linalg.cholesky(M)
            return np.linalg.solve(L.T, np.linalg.solve(L, tau_p - pin.nonLinearEffects(model, data, qp, v)))

        print(f"\n{label}: {n} dof, {len(robot.mimic_joints)} mimic joints ({free.dof} joints free without <mimic>)")
        rows = [
            ("rnea", lambda: num.rnea(robot, q, qd, qdd), lambda: pin.rnea(model, data, qp, v, a)),
            ("crba", lambda: num.crba(robot, q), lambda: pin.crba(model, data, qp)),
            ("forward dynamics", lambda: num.aba(robot, q, qd, tau), pin_fd),
        ]
        for name, fa, fb in rows:
            ta, tb = pair(fa, fb, number, repeat)
            print(
                f"  per call {name:17s} armdyn {ta * 1e6:7.2f} us   Pinocchio {tb * 1e6:7.2f} us   ratio {ta / tb:5.2f}"
            )
        t_free = median_time(lambda: num.rnea(free, qf, qf, qf), number, repeat)
        print(f"  per call rnea, URDF without <mimic> (Rust model alone): {t_free * 1e6:.2f} us")

        Q, QD, QDD = (np.ascontiguousarray(rng.uniform(-1, 1, (N, n))) for _ in range(3))
        q_b = np.asfortranarray(np.column_stack([pin_configuration(model, robot, Q[r])[0] for r in range(N)]))
        v_b, a_b = np.asfortranarray(QD[:, perm].T), np.asfortranarray(QDD[:, perm].T)
        out = np.asfortranarray(np.zeros((model.nv, N)))
        pool = pin.ModelPool(model, 2)
        ours = num.rnea(robot, Q, QD, QDD, threads=2)
        pin.rneaInParallel(2, pool, q_b, v_b, a_b, out)
        assert np.abs(ours[:, perm].T - out).max() < 1e-9 * max(1, np.abs(out).max())
        ta, tb = pair(
            lambda: num.rnea(robot, Q, QD, QDD, threads=2),
            lambda: pin.rneaInParallel(2, pool, q_b, v_b, a_b, out),
            1,
            batch_repeat,
        )
        print(
            f"  batch rnea, 2 threads: armdyn {N / ta / 1e6:6.2f} M states/s   "
            f"Pinocchio rneaInParallel {N / tb / 1e6:6.2f} M states/s   time ratio {ta / tb:5.2f}"
        )
        ta = median_time(lambda: num.aba(robot, Q, QD, ours, threads=2), 1, batch_repeat)
        print(f"  batch forward dynamics, 2 threads: armdyn {N / ta / 1e3:6.1f} k states/s (no Pinocchio counterpart)")


if __name__ == "__main__":
    main()
