"""Two builds of armdyn's Rust extension side by side: the speed benchmarks run with each
in turn, alternating, so both see the same machine load; medians over the runs.

    python benchmarks/compare_builds.py --before /tmp/old/_core.cpython-311-x86_64-linux-gnu.so
    python benchmarks/compare_builds.py --before A.so --after B.so --runs 3

``--after`` defaults to the build in python/armdyn. Each build gets a copy of python/armdyn
with its own ``_core*.so``; every run of each script is

    bench_numeric.py --quick
    bench_derivatives.py --quick --no-cpp
    bench_simulate.py --states 1000 --steps 200

(Pinocchio and MuJoCo are timed in the same process as armdyn, so the ratios are what
compare across builds). Prints one Markdown table: per call and per batch, the ratio to
Pinocchio (or MuJoCo), or armdyn's own time where the reference has no such call.
"""

from __future__ import annotations

import argparse
import glob
import os
import re
import shutil
import statistics
import subprocess
import sys
import tempfile

HERE = os.path.dirname(os.path.abspath(__file__))
PYTHON_TREE = os.path.join(HERE, "..", "python")

SCRIPTS = [
    ["bench_numeric.py", "--quick"],
    ["bench_derivatives.py", "--quick", "--no-cpp"],
    ["bench_simulate.py", "--states", "1000", "--steps", "200"],
]

# bench_numeric: "ur5  rnea  1 state  0.62 us  1.04 us  0.60" or a batch row; the ratio
# is recomputed from the two times (the scripts print it to two digits)
NUMERIC = re.compile(r"^(\w+)\s+(rnea|crba|aba)\s+(1 state|N=\d+, \d thr)\s+([\d.]+) (us|ms)\s+(?:([\d.]+) (us|ms)|-)")
# bench_derivatives per call: "ur5  rnea_derivatives  1.29us  3.05us  0.42"
DERIV_CALL = re.compile(r"^(\w+)\s+(rnea_derivatives|aba_derivatives|minverse)\s+([\d.]+)us\s+([\d.]+)us\s+[\d.]+$")
# bench_derivatives batch: "ur5  rnea_derivatives  1  10.8ms ..."
DERIV_BATCH = re.compile(r"^(\w+)\s+(rnea_derivatives|aba_derivatives|minverse)\s+(\d)\s+([\d.]+)ms")
# bench_simulate: "armdyn (stride = steps)  0.056  3.558e+06  56.2 us" and "MuJoCo rollout ..."
SIMULATE = re.compile(r"^(armdyn \(stride = \w+\)|MuJoCo rollout)\s+[\d.]+\s+\S+\s+([\d.]+) us")


UNIT = {"us": 1e-6, "ms": 1e-3}


def parse(text: str) -> dict[str, float]:
    """The measurements of one run of the three scripts: name -> value."""
    out: dict[str, float] = {}
    sim: dict[str, float] = {}
    for line in text.splitlines():
        if m := NUMERIC.match(line):
            arm, fn, what, own, unit, pin, pin_unit = m.groups()
            if pin is not None:
                out[f"{arm} {fn} {what} (ratio)"] = float(own) * UNIT[unit] / (float(pin) * UNIT[pin_unit])
            else:  # crba batch: Pinocchio has no batched crba
                out[f"{arm} {fn} {what} (ms)"] = float(own) * UNIT[unit] * 1e3
        elif m := DERIV_CALL.match(line):
            arm, fn, own, pin = m.groups()
            out[f"{arm} {fn} 1 state (ratio)"] = float(own) / float(pin)
        elif m := DERIV_BATCH.match(line):
            arm, fn, threads, ms = m.groups()
            out[f"{arm} {fn} N=20000, {threads} thr (ms)"] = float(ms)
        elif m := SIMULATE.match(line):
            sim[m.group(1)] = float(m.group(2))
    mujoco = sim.pop("MuJoCo rollout", None)
    for what, us in sim.items():
        if mujoco:
            out[f"ur5 simulate, {what[len('armdyn ') :]} (ratio to MuJoCo)"] = us / mujoco
    return out


def tree_with(so: str, where: str) -> str:
    """A copy of python/armdyn under ``where`` with ``so`` as its extension module."""
    dst = os.path.join(where, "armdyn")
    shutil.copytree(os.path.join(PYTHON_TREE, "armdyn"), dst, ignore=shutil.ignore_patterns("_core*.so", "__pycache__"))
    shutil.copy(so, os.path.join(dst, os.path.basename(so)))
    return where


def run(tree: str) -> str:
    env = dict(os.environ, PYTHONPATH=tree)
    text = []
    for script in SCRIPTS:
        done = subprocess.run(
            [sys.executable, os.path.join(HERE, script[0]), *script[1:]],
            env=env,
            capture_output=True,
            text=True,
            check=True,
        )
        text.append(done.stdout)
    return "\n".join(text)


def main(argv=None) -> int:
    p = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("--before", required=True, help="the _core*.so of the first build")
    p.add_argument("--after", help="the _core*.so of the second build (default: python/armdyn's)")
    p.add_argument("--runs", type=int, default=3, help="runs of every script per build (median)")
    args = p.parse_args(argv)
    after = args.after or next(iter(glob.glob(os.path.join(PYTHON_TREE, "armdyn", "_core*.so"))), None)
    if after is None:
        p.error("no build in python/armdyn: pass --after")
    for so in (args.before, after):
        if not os.path.isfile(so):
            p.error(f"{so}: no such file")
    results: dict[str, list[dict[str, float]]] = {"before": [], "after": []}
    with tempfile.TemporaryDirectory() as tmp:
        trees = {k: tree_with(so, os.path.join(tmp, k)) for k, so in (("before", args.before), ("after", after))}
        for r in range(args.runs):
            for k in ("before", "after"):
                print(f"run {r + 1} of {args.runs}: {k}", file=sys.stderr, flush=True)
                results[k].append(parse(run(trees[k])))
    names = [n for n in results["before"][0] if all(n in res for runs in results.values() for res in runs)]
    load = os.getloadavg()[0]
    print(f"medians of {args.runs} alternating runs per build; load average at the end {load:.2f}")
    print()
    print("| what | before | after | after / before |")
    print("|---|---:|---:|---:|")
    for n in names:
        b = statistics.median(res[n] for res in results["before"])
        a = statistics.median(res[n] for res in results["after"])
        print(f"| {n} | {b:.3f} | {a:.3f} | {a / b:.2f} |")
    return 0


if __name__ == "__main__":
    sys.exit(main())
