"""armdyn.numeric vs Pinocchio, side by side in one process, on UR5, Panda and iiwa14.

    python benchmarks/bench_numeric.py            # full run (a few minutes)
    python benchmarks/bench_numeric.py --quick    # smoke run: fewer repeats, N = 2e4
    python benchmarks/bench_numeric.py --cpu-time # single calls timed in on-CPU time (shared machines)

(with armdyn importable: ``maturin develop --release`` or ``pip install .``, or
``PYTHONPATH=python`` after a release build).

1. Per call from Python, one state: ``armdyn.rnea(robot, q, qd, qdd)`` vs
   ``pin.rnea(model, data, q, v, a)``, likewise crba and aba, on the same state. Each time is
   the median over ``--repeat`` runs of ``timeit`` with ``--number`` calls each; the runs of
   the two libraries alternate, so both see the same machine load.
2. Batch throughput, N states: ``armdyn.rnea(robot, Q, QD, QDD, threads=t)`` on (N, n)
   C-contiguous arrays vs ``pin.rneaInParallel(t, pool, q, v, a, tau)`` on (n, N)
   column-major arrays with a preallocated output (Pinocchio's fastest form), t = 1 and 2;
   likewise aba / abaInParallel. Median over ``--batch-repeat`` runs. armdyn allocates
   its output on every call. Runs alternate as above.

Before timing, each arm is checked: armdyn == Pinocchio (rnea, crba, aba) to 1e-12 at random
states. Ratios are armdyn time / Pinocchio time: below 1 means armdyn is faster. Targets:
per call <= 0.5 on UR5, Panda and iiwa14 (twice Pinocchio's speed from Python); batch rnea
<= 0.25 (4x the throughput), aba <= 0.5 (2x).

Not a test: timings depend on the machine and its load. Run it on an idle machine.
"""

from __future__ import annotations

import os

# Pinocchio's *InParallel run on OpenMP, whose idle workers by default spin on the cores for
# a while after each call, stealing them from the armdyn run that follows (measured: armdyn's
# 2-thread rnea on UR5 8.0 ms after a Pinocchio call vs 4.2 ms). Passive waiting removes that
# and leaves Pinocchio's own times unchanged (39.7 ms both ways). Set before OpenMP starts.
os.environ.setdefault("OMP_WAIT_POLICY", "passive")

import argparse  # noqa: E402
import platform  # noqa: E402
import statistics  # noqa: E402
import sys  # noqa: E402
import time  # noqa: E402
import timeit  # noqa: E402

import numpy as np  # noqa: E402
import pinocchio as pin  # noqa: E402

HERE = os.path.dirname(os.path.abspath(__file__))
sys.path.insert(0, HERE)
import arms  # noqa: E402  (also puts tests/ on sys.path for the Pinocchio bridge)
from pinocchio_bridge import PinocchioRobot  # noqa: E402

from armdyn import numeric as num  # noqa: E402


def per_call_run(f, args, number: int, clock=time.perf_counter):
    """A function timing one run of ``number`` calls ``f(*args)`` by ``clock``; returns seconds
    per call."""
    names = [f"a{i}" for i in range(len(args))]
    stmt = f"f({', '.join(names)})"  # a direct call, no lambda or *args layer
    timer = timeit.Timer(stmt, globals={"f": f, **dict(zip(names, args))}, timer=clock)
    return lambda: timer.timeit(number) / number


def batch_pairs(robot, model, Q, V, A, threads, repeat: int, relative: bool = False) -> list:
    """``(fn, t, armdyn s, Pinocchio s)`` for rnea and aba on the batch ``Q, V, A`` ((N, nq),
    (N, nv) C-contiguous) on ``t`` threads each: ``armdyn.rnea/aba(..., threads=t)`` against
    ``pin.rneaInParallel/abaInParallel`` into a preallocated output, medians of ``repeat``
    alternating runs. Pinocchio's batch is first checked equal to armdyn's to 1e-9 (``relative``:
    times the largest torque, at least 1)."""
    TAU = num.rnea(robot, Q, V, A)
    # Pinocchio's batches are (n, N) column-major: the transposes are views, no copy
    q_p, v_p, a_p, tau_p = Q.T, V.T, A.T, np.asfortranarray(TAU.T)
    out = np.zeros(tau_p.shape, order="F")
    scale = max(1.0, float(np.max(np.abs(TAU)))) if relative else 1.0
    assert np.max(np.abs(pin.rneaInParallel(1, pin.ModelPool(model, 1), q_p, v_p, a_p) - tau_p)) <= 1e-9 * scale
    found = []
    for t in threads:
        pool = pin.ModelPool(model, t)
        for fn, mine, theirs in (
            (
                "rnea",
                lambda: num.rnea(robot, Q, V, A, threads=t),
                lambda: pin.rneaInParallel(t, pool, q_p, v_p, a_p, out),
            ),
            (
                "aba",
                lambda: num.aba(robot, Q, V, TAU, threads=t),
                lambda: pin.abaInParallel(t, pool, q_p, v_p, tau_p, out),
            ),
        ):
            found.append((fn, t, *paired_medians(batch_run(mine), batch_run(theirs), repeat)))
    return found


def batch_run(f):
    """A function timing one call ``f()``; returns seconds."""

    def run():
        t0 = time.perf_counter()
        f()
        return time.perf_counter() - t0

    return run


def paired_medians(run_mine, run_theirs, repeat: int) -> tuple[float, float]:
    """Median times of two measurements taken in alternation (after one warm-up each), so
    both see the same machine load when it fluctuates."""
    run_mine(), run_theirs()
    mine, theirs = [], []
    for _ in range(repeat):
        mine.append(run_mine())
        theirs.append(run_theirs())
    return statistics.median(mine), statistics.median(theirs)


def fmt_time(t: float) -> str:
    if t < 1e-3:
        return f"{t * 1e6:8.2f} us"
    return f"{t * 1e3:8.2f} ms"


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--quick", action="store_true", help="few repeats and N = 2e4: a smoke run")
    parser.add_argument("--arms", default="ur5,panda,iiwa14", help="comma-separated subset of " + ",".join(arms.ARMS))
    parser.add_argument("--number", type=int, default=20000, help="calls per timeit run (per call)")
    parser.add_argument("--repeat", type=int, default=15, help="timeit runs per measurement (median)")
    parser.add_argument("--batch", type=float, default=1e5, help="N, states per batch")
    parser.add_argument("--batch-repeat", type=int, default=7, help="runs per batch measurement (median)")
    parser.add_argument("--threads", default="1,2", help="thread counts for batches")
    parser.add_argument(
        "--cpu-time",
        action="store_true",
        help="time single calls in this thread's CPU time (time.thread_time), not wall time: steadier on a shared machine",
    )
    args = parser.parse_args(argv)
    if args.quick:
        args.number, args.repeat, args.batch, args.batch_repeat = 2000, 5, 2e4, 3
    N = int(args.batch)
    threads = [int(t) for t in args.threads.split(",")]

    print(
        f"armdyn vs Pinocchio {pin.__version__}; Python {platform.python_version()}, numpy {np.__version__}; "
        f"{os.cpu_count()} CPUs, {platform.machine()}"
    )
    print(
        f"per call: median of {args.repeat} x {args.number} calls; batch: N = {N}, median of {args.batch_repeat}; "
        f"OMP_WAIT_POLICY={os.environ.get('OMP_WAIT_POLICY')}; load average {os.getloadavg()[0]:.2f}"
        + ("; single calls in CPU time" if args.cpu_time else "")
    )
    print("ratio = armdyn time / Pinocchio time (< 1: armdyn faster)\n")

    rows = []
    for name in args.arms.split(","):
        robot = arms.ARMS[name]()
        P = PinocchioRobot(robot)
        assert np.array_equal(P.perm, np.arange(robot.dof)), "a chain keeps its coordinate order"
        arms.assert_agree(robot, P, num)  # numeric == Pinocchio before any timing
        model, data = P.model, P.data
        rng = np.random.default_rng(0)
        q, v, a = (np.ascontiguousarray(rng.uniform(-np.pi, np.pi, robot.dof)) for _ in range(3))
        tau = pin.rnea(model, data, q, v, a)

        for fn, mine, theirs in (
            ("rnea", (num.rnea, (robot, q, v, a)), (pin.rnea, (model, data, q, v, a))),
            ("crba", (num.crba, (robot, q)), (pin.crba, (model, data, q))),
            ("aba", (num.aba, (robot, q, v, tau)), (pin.aba, (model, data, q, v, tau))),
        ):
            clock = time.thread_time if args.cpu_time else time.perf_counter
            t_mine, t_pin = paired_medians(
                per_call_run(*mine, args.number, clock), per_call_run(*theirs, args.number, clock), args.repeat
            )
            rows.append((name, fn, "1 state", t_mine, t_pin))

        Q, V, A = (np.ascontiguousarray(rng.uniform(-np.pi, np.pi, (N, robot.dof))) for _ in range(3))
        for fn, t, t_mine, t_pin in batch_pairs(robot, model, Q, V, A, threads, args.batch_repeat):
            rows.append((name, fn, f"N={N}, {t} thr", t_mine, t_pin))
        for t in threads:  # no crbaInParallel in Pinocchio: armdyn's throughput alone
            run = batch_run(lambda: num.crba(robot, Q, threads=t))
            t_mine, _ = paired_medians(run, lambda: 0.0, args.batch_repeat)
            rows.append((name, "crba", f"N={N}, {t} thr", t_mine, None))

    header = f"{'arm':7} {'fn':5} {'what':15} {'armdyn':>11} {'Pinocchio':>11} {'ratio':>6}   {'armdyn M/s':>10} {'Pinocchio M/s':>13}"
    print(header)
    print("-" * len(header))
    for name, fn, what, t_mine, t_pin in rows:
        n_states = 1 if what == "1 state" else N
        ratio = f"{t_mine / t_pin:6.2f}" if t_pin else "     -"
        rate = lambda t: f"{n_states / t / 1e6:10.2f}" if t else " " * 10  # noqa: E731
        print(
            f"{name:7} {fn:5} {what:15} {fmt_time(t_mine):>11} {fmt_time(t_pin) if t_pin else '-':>11} {ratio}   "
            f"{rate(t_mine) if n_states > 1 else '':>10} {(rate(t_pin) if t_pin else '') if n_states > 1 else '':>13}"
        )
    print(f"\nload average at the end: {os.getloadavg()[0]:.2f} (other processes share the cores: rerun if high)")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
