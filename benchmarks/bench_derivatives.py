"""armdyn's derivatives of the dynamics vs Pinocchio's, side by side in one process, on
UR5, Panda and iiwa14.

    python benchmarks/bench_derivatives.py            # full run
    python benchmarks/bench_derivatives.py --quick    # smoke run: fewer repeats, N = 2e4

(with armdyn importable: ``PYTHONPATH=python`` after a release build.)

1. Per call from Python, one state: ``armdyn.rnea_derivatives(robot, q, qd, qdd)`` vs
   ``pin.computeRNEADerivatives(model, data, q, v, a)``; likewise ``aba_derivatives`` vs
   ``computeABADerivatives`` and ``minverse`` vs ``computeMinverse``. Each time is the median
   over ``--repeat`` runs of ``timeit`` with ``--number`` calls; the two libraries' runs
   alternate, so both see the same machine load. Both return fresh arrays (Pinocchio returns
   its result matrices as new NumPy arrays; armdyn allocates (n, n) outputs per call; neither
   symmetrises its M or Minv (armdyn's are full, Pinocchio fills the upper triangle).
2. Batch throughput: ``armdyn.rnea_derivatives(robot, Q, QD, QDD, threads=t)`` on (N, n)
   arrays, t = 1 and 2, in million states per second, with outputs (N, n, n) allocated by
   each call ("fresh") and written into the caller's arrays (``out=``, allocated once: what
   a loop over batches does, and what Pinocchio's per-call time does with its ``Data``),
   compared with the rate of Pinocchio's per-call time (Pinocchio has no batched derivatives):
   ``1 / t_call`` for its Python call measured here (an upper bound on its C++ call time, so
   a lower bound on its rate), and ``2 / t_call`` ("both cores") — the target is
   ``>= 4 x`` that rate of its C++ call.
3. Pinocchio's C++ per-call times (benchmarks/pinocchio_cpp: bench.cpp compiled with
   g++ -O3 -march=native when the pip ``pin`` package's headers and ``cmeel-eigen`` are
   there; skipped with a note otherwise, or with ``--no-cpp``), on the models its URDF
   parser builds from the same arms, and armdyn's batch rate on the most threads asked
   for against ``2 / t_C++`` (both cores): the target is ``>= 4``. The C++ timing
   and armdyn's batches alternate in ``--batch-repeat`` rounds per arm (a short C++ run,
   then one batch of each kind), medians over the rounds: on a shared machine both sides
   then see the same stretch of load.

Before timing, each arm is checked: armdyn == Pinocchio to 1e-10. Ratios are armdyn time /
Pinocchio time: below 1 means armdyn is faster. Not a test: timings depend on the machine
and its load.
"""

from __future__ import annotations

import argparse
import functools
import os
import platform
import statistics
import sys

import numpy as np
import pinocchio as pin

HERE = os.path.dirname(os.path.abspath(__file__))
sys.path.insert(0, HERE)
import arms  # noqa: E402  (also puts tests/ on sys.path for the Pinocchio bridge)
from bench_numeric import batch_run, paired_medians, per_call_run  # noqa: E402  (the same timers as bench_numeric)
from pinocchio_derivatives import PinocchioDerivatives  # noqa: E402

from armdyn import numeric as num  # noqa: E402


def _pinocchio_cpp():
    """benchmarks/pinocchio_cpp/run.py as a module."""
    import importlib.util

    spec = importlib.util.spec_from_file_location("pinocchio_cpp_run", os.path.join(HERE, "pinocchio_cpp", "run.py"))
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


def check(robot, P, rng):
    q, v, a = (rng.uniform(-np.pi, np.pi, robot.dof) for _ in range(3))
    for mine, theirs in (
        (num.rnea_derivatives(robot, q, v, a), P.rnea_derivatives(q, v, a)),
        (num.aba_derivatives(robot, q, v, a), P.aba_derivatives(q, v, a)),
        ((num.minverse(robot, q),), (P.minverse(q),)),
    ):
        for x, y in zip(mine, theirs):
            err = np.max(np.abs(x - y)) / np.max(np.abs(y))
            assert err <= 1e-10, err


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--quick", action="store_true")
    parser.add_argument("--arms", default="ur5,panda,iiwa14")
    parser.add_argument("--number", type=int, default=20000)
    parser.add_argument("--repeat", type=int, default=11)
    parser.add_argument("--batch", type=float, default=1e5)
    parser.add_argument("--batch-repeat", type=int, default=5)
    parser.add_argument("--threads", default="1,2")
    parser.add_argument("--no-cpp", action="store_true", help="leave out Pinocchio's C++ timing")
    args = parser.parse_args(argv)
    if args.quick:
        args.number, args.repeat, args.batch, args.batch_repeat = 2000, 5, 2e4, 3
    N = int(args.batch)
    threads = [int(t) for t in args.threads.split(",")]
    print(
        f"armdyn vs Pinocchio {pin.__version__}; Python {platform.python_version()}; {os.cpu_count()} CPUs; "
        f"SIMD kernels {num._core.simd_kernels()}; load average {os.getloadavg()[0]:.2f}"
    )
    print(f"per call: median of {args.repeat} x {args.number} calls; batch: N = {N}, median of {args.batch_repeat}\n")
    rows, batch_rows = [], []
    cpp, cpp_models, cpp_module = {}, None, None
    if not args.no_cpp:
        cpp_module = _pinocchio_cpp()
        why = cpp_module.missing_headers(cpp_module.prefix())
        if why:
            print(f"Pinocchio C++ timing skipped: {why}")
        else:
            cpp_module.build(cpp_module.prefix())  # once (cached by the source's hash)
            cpp_models = cpp_module.urdf_models()
    for name in args.arms.split(","):
        robot = arms.ARMS[name]()
        P = PinocchioDerivatives(robot)
        assert np.array_equal(P.perm, np.arange(robot.dof))
        rng = np.random.default_rng(0)
        check(robot, P, rng)
        model, data = P.model, P.data
        q, v, a = (np.ascontiguousarray(rng.uniform(-np.pi, np.pi, robot.dof)) for _ in range(3))
        tau = pin.rnea(model, data, q, v, a)
        pin_call = {}
        for fn, mine, theirs in (
            (
                "rnea_derivatives",
                (num.rnea_derivatives, (robot, q, v, a)),
                (pin.computeRNEADerivatives, (model, data, q, v, a)),
            ),
            (
                "aba_derivatives",
                (num.aba_derivatives, (robot, q, v, tau)),
                (pin.computeABADerivatives, (model, data, q, v, tau)),
            ),
            ("minverse", (num.minverse, (robot, q)), (pin.computeMinverse, (model, data, q))),
        ):
            t_mine, t_pin = paired_medians(
                per_call_run(*mine, args.number), per_call_run(*theirs, args.number), args.repeat
            )
            rows.append((name, fn, t_mine, t_pin))
            pin_call[fn] = t_pin
        Q, V, A = (np.ascontiguousarray(rng.uniform(-np.pi, np.pi, (N, robot.dof))) for _ in range(3))
        TAU = num.rnea(robot, Q, V, A)
        n = robot.dof
        calls = {}  # (function, threads, "fresh" outputs or the caller's "out") -> a timed batch call
        for fn, f, X in (
            ("rnea_derivatives", num.rnea_derivatives, A),
            ("aba_derivatives", num.aba_derivatives, TAU),
            ("minverse", None, None),
        ):
            out = np.empty((N, n, n)) if f is None else tuple(np.empty((N, n, n)) for _ in range(3))
            for t in threads:
                for kind, o in (("fresh", None), ("out", out)):
                    if f is None:
                        call = functools.partial(num.minverse, robot, Q, threads=t, out=o)
                    else:
                        call = functools.partial(f, robot, Q, V, X, threads=t, out=o)
                    batch_run(call)()  # warm-up (first touch of out, thread pool)
                    calls[fn, t, kind] = batch_run(call)
        # rounds: Pinocchio's C++ per-call times (a short run) and one armdyn batch of each
        # kind, alternating, so that both are sampled over the same stretch of this shared
        # machine's time; medians over the rounds
        times = {key: [] for key in calls}
        cpp_rounds = []
        for _ in range(args.batch_repeat):
            if cpp_models is not None:
                cpp_rounds.append(cpp_module.run(number=args.number, repeat=3, models={name: cpp_models[name]})[name])
            for key, timed in calls.items():
                times[key].append(timed())
        for (fn, t, kind), ts in times.items():
            if kind == "fresh":
                batch_rows.append(
                    (name, fn, t, statistics.median(ts), statistics.median(times[fn, t, "out"]), pin_call[fn])
                )
        if cpp_rounds:
            cpp[name] = {k: statistics.median(r[k] for r in cpp_rounds) for k in ("rnea", *pin_call)}

    print(f"{'arm':7} {'function':17} {'armdyn':>9} {'Pinocchio':>10} {'ratio':>6}")
    for name, fn, t_mine, t_pin in rows:
        print(f"{name:7} {fn:17} {t_mine * 1e6:7.2f}us {t_pin * 1e6:8.2f}us {t_mine / t_pin:6.2f}")
    print(
        f"\nbatch of N = {N}: armdyn M states/s (fresh outputs; out=: into the caller's arrays) vs the rate of "
        "Pinocchio's per-call time (Python call: 1 core, 2 cores)"
    )
    print(
        f"{'arm':7} {'function':17} {'thr':>3} {'armdyn':>9} {'M/s':>6} {'out= M/s':>8} {'pin 1 core':>10} "
        f"{'pin 2 cores':>11} {'x (2 cores)':>11} {'x out=':>6}"
    )
    for name, fn, t, tb, tb_out, t_pin in batch_rows:
        rate, rate_out = N / tb / 1e6, N / tb_out / 1e6
        r1 = 1 / t_pin / 1e6
        print(
            f"{name:7} {fn:17} {t:3d} {tb * 1e3:7.1f}ms {rate:6.2f} {rate_out:8.2f} {r1:10.2f} {2 * r1:11.2f} "
            f"{rate / (2 * r1):11.2f} {rate_out / (2 * r1):6.2f}"
        )
    if cpp:
        t = max(threads)
        print(
            f"\nPinocchio C++ per call (g++ -O3 -march=native; per round the median of 3 x {args.number} calls, "
            f"then the median of {args.batch_repeat} rounds alternating with armdyn's batches) vs armdyn's "
            f"batch of N = {N} on {t} threads; target: armdyn rate >= 4 x 2 / t_C++ (both cores)"
        )
        print(
            f"{'arm':7} {'function':17} {'C++ us':>7} {'C++ 2 cores M/s':>15} {'armdyn M/s':>10} {'x':>6} "
            f"{'out= M/s':>8} {'x out=':>6}"
        )
        for name, fn, tt, tb, tb_out, _ in batch_rows:
            if tt != t or name not in cpp:
                continue
            t_cpp = cpp[name][fn]
            rate_cpp = 2 / t_cpp / 1e6
            rate, rate_out = N / tb / 1e6, N / tb_out / 1e6
            print(
                f"{name:7} {fn:17} {t_cpp * 1e6:7.3f} {rate_cpp:15.2f} {rate:10.2f} {rate / rate_cpp:6.2f} "
                f"{rate_out:8.2f} {rate_out / rate_cpp:6.2f}"
            )
        for name, r in cpp.items():
            print(f"{name:7} {'rnea':17} {r['rnea'] * 1e6:7.3f} (for scale)")
    print(f"\nload average at the end: {os.getloadavg()[0]:.2f}")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
