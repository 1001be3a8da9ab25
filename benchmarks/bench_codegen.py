"""Generated code: operation counts, time to generate, and speed of the compiled C.

    PYTHONPATH=python python3 benchmarks/bench_codegen.py            # everything (~1 min)
    PYTHONPATH=python python3 benchmarks/bench_codegen.py --skip-numeric

1. Operation counts on the PUMA 560 with every parameter symbolic (60 inertial ones,
   kinematics and g too), counted as ``sympy.count_ops(visual=True)`` counts them
   (mul = MUL+DIV+POW, add = ADD+SUB) after common-subexpression elimination:
   armdyn's generated code vs armdyn.derive's expressions through ``sympy.cse`` (measured
   here, in this run) and the figures of OpenSYMORO and SymPyBotics quoted in issue 8
   (theirs, not measured here).
2. Time to derive tau, M, C, g (+ the regressor and base parameters when
   armdyn.identification is present) and generate C for the PUMA 560, in this process:
   the first run (SymPy's caches cold) and the median of the next ones; and the time of
   ``armdyn.derive(robot).tau`` (Craig's Newton-Euler) alone.
3. The generated C for the PUMA's tau, numeric parameters (Corke's puma560 values),
   compiled with ``cc -O2``, one thread over 1e5 states, vs armdyn's Rust
   ``rnea(..., threads=1)`` on the same batch, alternating, 15 runs each (median and best).
"""

from __future__ import annotations

import argparse
import importlib.util
import statistics
import time
import warnings

import numpy as np
import sympy as sp

import armdyn
import armdyn.codegen as codegen

# quoted from issue 8 (OpenSYMORO: Khalil et al., "OpenSYMORO: an open-source software
# package for symbolic modelling of robots", IEEE/ASME AIM 2014, customized Newton-Euler;
# SymPyBotics: C. D. Sousa's package) -- their counts on the PUMA 560, not measured here
THEIRS = {
    ("tau", "OpenSYMORO"): (345, 296),
    ("tau (base parameters)", "OpenSYMORO"): (301, 240),
    ("M", "OpenSYMORO"): (302, 215),
    ("tau", "SymPyBotics"): (365, 300),
}
TARGETS = {"tau": 0.8 * (345 + 296), "tau (base parameters)": 433, "M": 0.8 * (302 + 215)}


def cse_counts(exprs) -> tuple[int, int]:
    """(mul, add) of expressions after sympy.cse, as issue 8 counts them."""
    reps, reduced = sp.cse(list(exprs))
    visual = sp.count_ops([r for _, r in reps] + list(reduced), visual=True)
    d = {} if visual == 0 else {s.name: int(c) for s, c in visual.as_coefficients_dict().items()}
    return d.get("MUL", 0) + d.get("DIV", 0) + d.get("POW", 0), d.get("ADD", 0) + d.get("SUB", 0)


def load(name):
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        return armdyn.load(name, strict=False)


def op_count_table(have_identification: bool) -> None:
    print("## Operation counts, PUMA 560, all parameters symbolic (mul + add = total)\n")
    print("| quantity | model | armdyn codegen | armdyn.derive + sympy.cse | OpenSYMORO (quoted) | SymPyBotics (quoted) | target | codegen / OpenSYMORO |")
    print("|---|---|---|---|---|---|---|---|")
    for name in ("puma560-craig", "puma560"):
        robot = load(name)
        eom = armdyn.derive(robot)
        what = ["tau", "M", "g", "C"]
        code = codegen.codegen(robot, what=what)
        derived = {"tau": list(eom.tau), "M": [eom.M[i, j] for i in range(6) for j in range(i, 6)], "g": list(eom.g)}
        rows = [(w, code.op_counts[w]) for w in what]
        if have_identification:
            base = codegen.codegen(robot, what="tau", base=True)
            rows.insert(1, ("tau (base parameters)", base.op_counts["tau"]))
        label = {"puma560-craig": "modified DH", "puma560": "standard DH"}[name]
        for w, c in rows:
            ours = f"{c['mul']} + {c['add']} = {c['total']}"
            if w in derived:
                m, a = cse_counts(derived[w])
                before = f"{m} + {a} = {m + a}"
            else:
                before = "-"
            sym = THEIRS.get((w, "OpenSYMORO"))
            spb = THEIRS.get((w, "SymPyBotics"))
            ratio = f"{c['total'] / sum(sym):.2f}" if sym else "-"
            target = f"<= {TARGETS[w]:.0f}" if w in TARGETS else "-"
            fmt = (lambda t: f"{t[0]} + {t[1]} = {sum(t)}" if t else "-")
            print(f"| {w} | {label} | {ours} | {before} | {fmt(sym)} | {fmt(spb)} | {target} | {ratio} |")
    print("\n(C: the Christoffel C matrix of M; OpenSYMORO and SymPyBotics quote no count for it.)\n")


def generation_times(have_identification: bool, repeat: int) -> None:
    robot = load("puma560-craig")
    what = ["tau", "M", "C", "g"] + (["regressor"] if have_identification else [])

    def everything():
        t0 = time.perf_counter()
        codegen.codegen(robot, what=what, lang="c")
        if have_identification:
            codegen.codegen(robot, what=["tau", "regressor"], lang="c", base=True)
        return time.perf_counter() - t0

    first = everything()
    rest = [everything() for _ in range(repeat)]
    print("## Time to derive and generate C, puma560-craig, all parameters symbolic\n")
    print(f"{', '.join(what)}{' + base parameters' if have_identification else ''} -> C: "
          f"first run {first:.2f} s, then median {statistics.median(rest):.2f} s (of {repeat})")
    ne = []
    for _ in range(repeat):
        t0 = time.perf_counter()
        armdyn.derive(robot, "newton-euler")
        ne.append(time.perf_counter() - t0)
    print(f"armdyn.derive(robot).tau (Craig's Newton-Euler): median {statistics.median(ne):.3f} s")
    from armdyn.symbolic.customized_ne import customized_newton_euler

    cne = []
    for _ in range(repeat):
        t0 = time.perf_counter()
        customized_newton_euler(robot)
        cne.append(time.perf_counter() - t0)
    print(f"customized Newton-Euler program for tau alone: median {statistics.median(cne):.3f} s\n")


def numeric(n_states: int, repeat: int) -> None:
    robot = load("puma560")
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        robot = robot.bind()
    lib = codegen.compile(robot, what="tau")
    rng = np.random.default_rng(0)
    Q, QD, QDD = (rng.uniform(-np.pi, np.pi, (n_states, robot.dof)) for _ in range(3))
    ref = armdyn.rnea(robot, Q, QD, QDD, threads=1)
    got = lib.tau(Q, QD, QDD)
    err = np.abs(got - ref).max() / np.abs(ref).max()
    assert err < 1e-12, err
    # the same code with the AVX2 clone switched off: SSE2 only, like the Rust core's build
    sse2 = codegen.compile(lib.code, flags=["-DARMDYN_NO_CLONES"])
    assert np.abs(sse2.tau(Q, QD, QDD) - got).max() == 0.0
    t_c, t_rust, t_sse2 = [], [], []
    for _ in range(repeat):
        for fn, runs in ((lambda: lib.tau(Q, QD, QDD), t_c), (lambda: armdyn.rnea(robot, Q, QD, QDD, threads=1), t_rust),
                         (lambda: sse2.tau(Q, QD, QDD), t_sse2)):
            t0 = time.perf_counter()
            fn()
            runs.append(time.perf_counter() - t0)
    c, r = statistics.median(t_c), statistics.median(t_rust)
    print(f"## Generated C vs the Rust core, puma560 tau, {n_states:.0e} states, one thread "
          f"(runs alternating, {repeat} each)\n")
    print("                               median        best")
    print(f"generated C (cc -O2, ctypes): {c * 1e9 / n_states:7.1f} ns/state {min(t_c) * 1e9 / n_states:7.1f} ns/state")
    print(f"armdyn.rnea(threads=1):       {r * 1e9 / n_states:7.1f} ns/state {min(t_rust) * 1e9 / n_states:7.1f} ns/state")
    s2 = statistics.median(t_sse2)
    print(f"generated C, SSE2 only:       {s2 * 1e9 / n_states:7.1f} ns/state {min(t_sse2) * 1e9 / n_states:7.1f} ns/state"
          f"   (-DARMDYN_NO_CLONES; ratio to Rust: median {s2 / r:.2f}, best {min(t_sse2) / min(t_rust):.2f})")
    print(f"ratio generated C / Rust rnea: median {c / r:.2f}, best {min(t_c) / min(t_rust):.2f}"
          f"  (max rel. difference {err:.1e})")


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--repeat", type=int, default=5)
    ap.add_argument("--states", type=int, default=100_000)
    ap.add_argument("--skip-numeric", action="store_true")
    ap.add_argument("--numeric-repeat", type=int, default=15)
    args = ap.parse_args()
    have_identification = importlib.util.find_spec("armdyn.identification") is not None
    generation_times(have_identification, args.repeat)  # first: SymPy's caches still cold
    op_count_table(have_identification)
    if not args.skip_numeric:
        numeric(args.states, args.numeric_repeat)


if __name__ == "__main__":
    main()
