"""Time to load a valid URDF with many joints, side by side with Pinocchio reading the
same file in the same process (``pinocchio.buildModelFromUrdf``).

    PYTHONPATH=python python3 benchmarks/bench_load.py [--sizes 1000 10000] [--repeat 3]

Models from tests/big_urdf.py: a chain and a random tree of N joints (random origins,
rpy, unit axes, inertias in rotated inertial frames; revolute, continuous, prismatic and
fixed joints; written in shuffled order, so the reader must sort them into tree order).

Timed, median of ``--repeat`` runs each:
  load:     ``armdyn.load(path)`` (parse, check, tree order, Robot built);
  compile:  the first ``armdyn.rnea`` call (the compiled Rust model is built then, from
            the floats the reader kept; no SymPy per joint);
  pinocchio: ``pin.buildModelFromUrdf(path)`` (the model only: its ``createData()``
            runs out of memory at 10^3 joints on this 24 GB machine). Run in a thread
            with a 1 GiB stack: its parser recurses along the tree and overflows the
            main thread's 8 MiB stack on a 10^4-joint chain (a segmentation fault).
The ratio is armdyn load / Pinocchio load. (armdyn's SymPy form of a joint is built
only when a symbolic function reads it: not timed here.)
"""

from __future__ import annotations

import argparse
import os
import statistics
import sys
import tempfile
import threading
import time
import warnings

import numpy as np

HERE = os.path.dirname(os.path.abspath(__file__))
sys.path.insert(0, os.path.join(HERE, "..", "tests"))
from big_urdf import big_urdf  # noqa: E402

import armdyn  # noqa: E402


def _time(f, repeat: int):
    times, out = [], None
    for _ in range(repeat):
        t0 = time.perf_counter()
        out = f()
        times.append(time.perf_counter() - t0)
    return statistics.median(times), out


def _in_big_stack(f):
    """``f()`` run in a thread with a 1 GiB stack (Pinocchio's recursive URDF parser)."""
    out = {}
    old = threading.stack_size(1 << 30)
    try:
        t = threading.Thread(target=lambda: out.setdefault("value", f()))
        t.start()
        t.join()
    finally:
        threading.stack_size(old)
    return out["value"]


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--sizes", type=int, nargs="+", default=[1000, 10000])
    ap.add_argument("--repeat", type=int, default=3)
    args = ap.parse_args()
    try:
        import pinocchio as pin
    except ImportError:
        pin = None
        print("pinocchio not installed: armdyn only")
    with tempfile.TemporaryDirectory() as tmp:
        for n in args.sizes:
            for tree in (False, True):
                text, _ = big_urdf(n, tree=tree, seed=1)
                path = os.path.join(tmp, f"big_{n}_{tree}.urdf")
                with open(path, "w") as fh:
                    fh.write(text)

                def load():
                    with warnings.catch_warnings():
                        warnings.simplefilter("error")  # every link has mass: nothing to warn about
                        return armdyn.load(path)

                t_load, robot = _time(load, args.repeat)
                zeros = np.zeros(robot.dof)
                compile_times = []
                for _ in range(args.repeat):
                    fresh = load()
                    t0 = time.perf_counter()
                    armdyn.rnea(fresh, zeros, zeros, zeros)
                    compile_times.append(time.perf_counter() - t0)
                t_compile = statistics.median(compile_times)
                kind = "tree " if tree else "chain"
                line = (
                    f"{n:>6} joints, {kind} ({robot.dof} dof): armdyn load {t_load:7.3f} s, "
                    f"compile (first rnea) {t_compile:6.3f} s"
                )
                if pin is not None:
                    t_pin = _in_big_stack(lambda: _time(lambda: pin.buildModelFromUrdf(path), args.repeat)[0])
                    line += f" | pinocchio load {t_pin:6.3f} s | ratio armdyn/pinocchio {t_load / t_pin:5.1f}"
                print(line, flush=True)


if __name__ == "__main__":
    main()
