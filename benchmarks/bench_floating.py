"""A floating base: armdyn.numeric vs Pinocchio per call from Python, side by side in one
process, on example-robot-data's solo12, anymal and talos (free-flyer root).

    python benchmarks/bench_floating.py            # full run
    python benchmarks/bench_floating.py --quick    # smoke run: fewer repeats

(with armdyn importable: ``PYTHONPATH=python`` after a release build).

``armdyn.numeric.rnea(robot, q, v, a)`` vs ``pin.rnea(model, data, q, v, a)`` on the same
arrays (Pinocchio's layout: q = base position, quaternion x y z w, joints), likewise
crba and aba, and the centroidal momentum matrix (``armdyn.centroidal_momentum_matrix`` vs
``pin.computeCentroidalMap``), the centre of mass Jacobian (``com_jacobian`` vs
``pin.jacobianCenterOfMass``) and the centroidal momentum (``centroidal_momentum`` vs
``pin.computeCentroidalMomentum``). Each time is the median over ``--repeat`` runs of ``timeit`` with
``--number`` calls each; the runs of the two libraries alternate, so both see the same
machine load. Before timing each robot is checked: armdyn == Pinocchio to 1e-10.
Ratios are armdyn time / Pinocchio time: below 1 means armdyn is faster.

Batches (``--batch N``, default 20000; 0 skips them): ``armdyn.numeric.rnea(robot, Q, V, A,
threads=t)`` and ``aba`` on (N, nq) / (N, nv) C-contiguous arrays, its output allocated by
each call, vs ``pin.rneaInParallel(t, pool, q, v, a, out)`` / ``abaInParallel`` on the
column-major transposes into a preallocated output (Pinocchio's fastest form), t = 1 and 2,
median of ``--batch-repeat`` runs, alternating.

Not a test: timings depend on the machine and its load.
"""

from __future__ import annotations

import os

# as bench_numeric: OpenMP's idle workers must not spin on the cores after a Pinocchio batch
os.environ.setdefault("OMP_WAIT_POLICY", "passive")

import argparse  # noqa: E402
import importlib.metadata  # noqa: E402
import platform  # noqa: E402
import sys  # noqa: E402
import warnings  # noqa: E402
from pathlib import Path  # noqa: E402

import numpy as np  # noqa: E402
import pinocchio as pin  # noqa: E402

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from bench_numeric import batch_pairs, paired_medians, per_call_run  # noqa: E402  (the same timing as the arms')

import armdyn  # noqa: E402
from armdyn import centroidal as cen  # noqa: E402
from armdyn import numeric as num  # noqa: E402

ROBOTS = {
    "solo12": "solo_description/robots/solo12.urdf",
    "anymal": "anymal_b_simple_description/robots/anymal.urdf",
    "talos": "talos_data/robots/talos_reduced.urdf",
}


def load_pair(name: str):
    """(armdyn robot, Pinocchio model) of ``ROBOTS[name]`` with a free-flyer root, the URDF's
    joint friction left out (Pinocchio's algorithms have none); their joints in one order."""
    urdf = robots_dir() / ROBOTS[name]
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        robot = armdyn.load(urdf, strict=False, root_joint="free-flyer").without_joint_dynamics()
    model = pin.buildModelFromUrdf(str(urdf), pin.JointModelFreeFlyer())
    assert list(model.names)[2:] == list(robot.coordinate_names), "the same joint order"
    return robot, model


def robots_dir() -> Path:
    dist = importlib.metadata.distribution("example-robot-data")
    return Path(dist.locate_file("cmeel.prefix/share/example-robot-data/robots"))


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--quick", action="store_true")
    parser.add_argument("--repeat", type=int, default=15)
    parser.add_argument("--number", type=int, default=2000)
    parser.add_argument("--batch", type=int, default=20000, help="states per batch (0: no batches)")
    parser.add_argument("--batch-repeat", type=int, default=7)
    args = parser.parse_args()
    repeat, number = (5, 300) if args.quick else (args.repeat, args.number)
    print(f"{platform.processor() or platform.machine()}, Python {platform.python_version()}, pin {pin.__version__}")
    print(f"median of {repeat} runs x {number} calls; ratio = armdyn / Pinocchio\n")
    print("| robot | nv | algorithm | armdyn (us) | Pinocchio (us) | ratio |")
    print("| --- | --- | --- | --- | --- | --- |")
    rng = np.random.default_rng(0)
    batches: list[tuple] = []
    for name in ROBOTS:
        robot, model = load_pair(name)
        data = model.createData()
        q = num.random_configuration(robot, rng)
        v, a = rng.uniform(-1, 1, (2, robot.nv))
        tau = num.rnea(robot, q, v, a)
        assert np.max(np.abs(tau - pin.rnea(model, data, q, v, a))) < 1e-10 * max(1, np.max(np.abs(tau)))
        M = pin.crba(model, data, q)
        assert np.max(np.abs(num.crba(robot, q) - (np.triu(M) + np.triu(M, 1).T))) < 1e-10 * np.max(np.abs(M))
        assert np.max(np.abs(num.aba(robot, q, v, tau) - a)) < 1e-8
        A = pin.computeCentroidalMap(model, data, q)
        assert np.max(np.abs(cen.centroidal_momentum_matrix(robot, q) - A)) < 1e-10 * np.max(np.abs(A))
        Jc = pin.jacobianCenterOfMass(model, data, q)
        assert np.max(np.abs(cen.com_jacobian(robot, q) - Jc)) < 1e-10 * max(1, np.max(np.abs(Jc)))
        h = pin.computeCentroidalMomentum(model, data, q, v).vector
        assert np.max(np.abs(cen.centroidal_momentum(robot, q, v) - h)) < 1e-10 * max(1, np.max(np.abs(h)))
        cases = {
            "rnea": ((num.rnea, (robot, q, v, a)), (pin.rnea, (model, data, q, v, a))),
            "crba": ((num.crba, (robot, q)), (pin.crba, (model, data, q))),
            "aba": ((num.aba, (robot, q, v, tau)), (pin.aba, (model, data, q, v, tau))),
            "centroidal map": (
                (cen.centroidal_momentum_matrix, (robot, q)),
                (pin.computeCentroidalMap, (model, data, q)),
            ),
            "com jacobian": ((cen.com_jacobian, (robot, q)), (pin.jacobianCenterOfMass, (model, data, q))),
            "centroidal momentum": (
                (cen.centroidal_momentum, (robot, q, v)),
                (pin.computeCentroidalMomentum, (model, data, q, v)),
            ),
        }
        for algo, ((f, fa), (g, ga)) in cases.items():
            mine, theirs = paired_medians(per_call_run(f, fa, number), per_call_run(g, ga, number), repeat)
            print(f"| {name} | {robot.nv} | {algo} | {mine * 1e6:.2f} | {theirs * 1e6:.2f} | {mine / theirs:.2f} |")
        if args.batch:
            batches.append((name, robot, model))
    if batches:
        n_states = 2000 if args.quick else args.batch
        print(f"\nbatches of {n_states} states; ratio = armdyn / Pinocchio's *InParallel (out preallocated)\n")
        print("| robot | algorithm | threads | armdyn (ms) | Pinocchio (ms) | ratio | Pinocchio / armdyn |")
        print("| --- | --- | --- | --- | --- | --- | --- |")
    for name, robot, model in batches:
        batch_rows(name, robot, model, n_states, 3 if args.quick else args.batch_repeat, rng)


def batch_rows(name: str, robot, model, n: int, repeat: int, rng) -> None:
    """The batch table's rows of one robot (see the module doc), checked equal first."""
    Q = np.ascontiguousarray([num.random_configuration(robot, rng) for _ in range(n)])
    V, A = (np.ascontiguousarray(rng.uniform(-1, 1, (n, robot.nv))) for _ in range(2))
    for algo, t, m, p in batch_pairs(robot, model, Q, V, A, (1, 2), repeat, relative=True):
        print(f"| {name} | {algo} | {t} | {m * 1e3:.2f} | {p * 1e3:.2f} | {m / p:.2f} | {p / m:.1f}x |")


if __name__ == "__main__":
    main()
