"""Generated code: operation counts, time to generate, and speed of the compiled C.

    PYTHONPATH=python python3 benchmarks/bench_codegen.py            # everything (~1 min)
    PYTHONPATH=python python3 benchmarks/bench_codegen.py --skip-numeric
    PYTHONPATH=python python3 benchmarks/bench_codegen.py --processes 6   # tau alone, 6 fresh processes
    PYTHONPATH=python python3 benchmarks/bench_codegen.py --numeric-only --numeric-repeat 31
    PYTHONPATH=python python3 benchmarks/bench_codegen.py --arms          # op counts, every bundled arm
    PYTHONPATH=python python3 benchmarks/bench_codegen.py --ledger        # write benchmarks/op_counts.json

1. Operation counts on the PUMA 560 with every parameter symbolic (60 inertial ones,
   kinematics and g too), counted as ``sympy.count_ops(visual=True)`` counts them
   (mul = MUL+DIV+POW, add = ADD+SUB) after common-subexpression elimination:
   armdyn's generated code vs armdyn.derive's expressions through ``sympy.cse`` (measured
   here, in this run) and the published figures of OpenSYMORO and SymPyBotics (theirs,
   quoted, not measured here).
2. Time to derive tau, M, C, g, the regressor and the base parameters (tau and the
   regressor in them) and generate C for the PUMA 560, in this process, as one table
   with the targets (<= 3 s; SymPyBotics quoted at 3.5-9.7 s for its set) and
   ratios: the first run (SymPy's caches cold) and the median of the next ones; tau
   alone by the customized Newton-Euler (target <= 0.1 s); ``armdyn.derive(robot).tau``.
3. The generated C for the PUMA's tau, numeric parameters (Corke's puma560 values),
   compiled with ``cc -O2``, one thread over 1e5 states, vs armdyn's Rust
   ``rnea(..., threads=1)`` on the same batch, alternating, 15 runs each (median and best).
"""

from __future__ import annotations

import argparse
import importlib.util
import json
import os
import statistics
import time
import warnings

import numpy as np
import sympy as sp

import armdyn
import armdyn.printing as printing

# published counts (OpenSYMORO: Khalil et al., "OpenSYMORO: an open-source software
# package for symbolic modelling of robots", IEEE/ASME AIM 2014, customized Newton-Euler;
# SymPyBotics: C. D. Sousa's package) -- their counts on the PUMA 560, not measured here
THEIRS = {
    ("tau", "OpenSYMORO"): (345, 296),
    ("tau, ungrouped", "OpenSYMORO"): (345, 296),
    ("tau, ungrouped", "SymPyBotics"): (365, 300),
    ("tau (base parameters)", "OpenSYMORO"): (301, 240),
    ("M", "OpenSYMORO"): (302, 215),
    ("tau", "SymPyBotics"): (365, 300),
}
TARGETS = {
    "tau": 0.8 * (345 + 296),
    "tau, ungrouped": 0.8 * (345 + 296),
    "tau (base parameters)": 433,
    "M": 0.8 * (302 + 215),
}


def cse_counts(exprs) -> tuple[int, int]:
    """(mul, add) of expressions after sympy.cse (mul = MUL+DIV+POW, add = ADD+SUB), as published."""
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
    print(
        "| quantity | model | armdyn codegen | armdyn.derive + sympy.cse | OpenSYMORO (quoted) | SymPyBotics (quoted) | target | codegen / OpenSYMORO |"
    )
    print("|---|---|---|---|---|---|---|---|")
    for name in ("puma560-craig", "puma560"):
        robot = load(name)
        eom = armdyn.derive(robot)
        what = ["tau", "M", "g", "C"]
        code = printing.codegen(robot, what=what)
        derived = {
            "tau": list(eom.tau),
            "tau, ungrouped": list(eom.tau),
            "M": [eom.M[i, j] for i in range(6) for j in range(i, 6)],
            "g": list(eom.g),
        }
        rows = [(w, code.op_counts[w]) for w in what]
        from armdyn.programs.customized_ne import customized_newton_euler

        # before the grouping: the customized Newton-Euler in the 60 standard parameters
        rows.insert(1, ("tau, ungrouped", customized_newton_euler(robot)[0].operation_counts()))
        if have_identification:
            base = printing.codegen(robot, what="tau", base=True)
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

            def fmt(t):
                return f"{t[0]} + {t[1]} = {sum(t)}" if t else "-"

            print(f"| {w} | {label} | {ours} | {before} | {fmt(sym)} | {fmt(spb)} | {target} | {ratio} |")
    print("\n(C: the Christoffel C matrix of M; OpenSYMORO and SymPyBotics quote no count for it.)\n")


SYMPYBOTICS_SECONDS = (3.5, 9.7)  # SymPyBotics' quoted time for its set of quantities for the PUMA 560, not run here


def _timed(fn, repeat):
    """(first run, median wall time, median CPU time of this process) of ``repeat`` runs
    after the first, in seconds. On a shared machine the CPU time (time.process_time) is
    the less noisy of the two: the wall time also counts the waits for a core."""
    t0 = time.perf_counter()
    fn()
    first = time.perf_counter() - t0
    wall, cpu = [], []
    for _ in range(repeat):
        t0, c0 = time.perf_counter(), time.process_time()
        fn()
        wall.append(time.perf_counter() - t0)
        cpu.append(time.process_time() - c0)
    return first, statistics.median(wall), statistics.median(cpu)


def generation_times(have_identification: bool, repeat: int) -> None:
    """One table: time to derive and print C, medians of ``repeat`` runs in this process
    (the first run, SymPy's caches cold, apart), with the targets and ratios."""
    from armdyn.programs.customized_ne import customized_newton_euler, standard_parameters
    from armdyn.programs.grouping import grouped_parameters

    robot = load("puma560-craig")
    what = ["tau", "M", "C", "g"] + (["regressor"] if have_identification else [])

    def standard():
        printing.codegen(robot, what=what, lang="c")

    def base():
        printing.codegen(robot, what=["tau", "regressor"], lang="c", base=True)

    def everything():
        standard()
        if have_identification:
            base()

    def tau_program():  # tau alone by the customized Newton-Euler, grouped parameters
        params, definitions = standard_parameters(robot)
        grouped, _ = grouped_parameters(robot, params, definitions)
        customized_newton_euler(robot, parameters=grouped)

    rows = [
        (
            f"{', '.join(what)}{' + base parameters (tau, regressor)' if have_identification else ''} -> C",
            _timed(everything, repeat),
            3.0,
            "SymPyBotics 3.5-9.7 s (its set)",
        )
    ]
    rows.append(("  of which " + ", ".join(what) + " -> C", _timed(standard, repeat), None, "-"))
    if have_identification:
        rows.append(("  of which base parameters + tau, regressor in them -> C", _timed(base, repeat), None, "-"))
    rows += [
        (
            "tau alone: customized Newton-Euler program",
            _timed(tau_program, repeat),
            0.1,
            "0.16-0.18 s (before the build's speed-up)",
        ),
        (
            "tau alone: armdyn.codegen(what='tau') -> C",
            _timed(lambda: printing.codegen(robot, what="tau"), repeat),
            None,
            "-",
        ),
        (
            "armdyn.derive(robot).tau (Craig's Newton-Euler, no CSE)",
            _timed(lambda: armdyn.derive(robot, "newton-euler"), repeat),
            None,
            "-",
        ),
    ]
    print(
        f"## Time to derive and generate C, puma560-craig, all parameters symbolic (median of {repeat}, "
        "first run apart)\n"
    )
    print(
        "| what | median (wall) | median (CPU) | first run | target | wall / target | CPU / target | reference "
        "| wall / SymPyBotics best |"
    )
    print("|---|---|---|---|---|---|---|---|---|")
    for k, (label, (first, median, cpu), target, ref) in enumerate(rows):
        cold = f"{first:.3f} s" if k == 0 else "-"  # only the first row's first run has cold caches
        tgt = f"<= {target:g} s" if target else "-"
        ratio = f"{median / target:.2f} | {cpu / target:.2f}" if target else "- | -"
        spb = f"{median / SYMPYBOTICS_SECONDS[0]:.2f}" if ref.startswith("SymPyBotics") else "-"
        print(f"| {label} | {median:.3f} s | {cpu:.3f} s | {cold} | {tgt} | {ratio} | {ref} | {spb} |")
    print()


def breakdown() -> None:
    """Where the operations of the PUMA's tau go: per quantity (the temporaries' name
    prefixes: w, wd, vd, U, F, N forward; Rf, f, n inward) and per link, for the
    standard-parameter (grouped) program."""
    import re
    from collections import defaultdict

    from armdyn.programs.program import Program

    robot = load("puma560-craig")
    prog = printing.codegen(robot, what="tau").programs["tau"]
    table = defaultdict(lambda: [0, 0])
    lines = []
    for sym, expr in prog.assignments:
        m = re.match(r"([A-Za-z_]+?)(\d)", sym.name)
        lines.append(((m.group(1), m.group(2)) if m else (sym.name, "-"), expr))
    # an output that is not a temporary is formed in place (a base-fixed link's torque)
    lines += [(("tau", str(k + 1)), e) for k, e in enumerate(prog.outputs) if not sp.sympify(e).is_Atom]
    for key, expr in lines:
        c = Program([], [expr], ()).operation_counts()
        table[key][0] += c["mul"]
        table[key][1] += c["add"]
    kinds = sorted({k for k, _ in table})
    links = sorted({j for _, j in table})
    print("## Where the operations of tau go, puma560-craig, grouped parameters (mul+add per link)\n")
    print("| quantity | " + " | ".join(f"link {j}" for j in links) + " | total |")
    print("|---|" + "---|" * (len(links) + 1))
    for k in kinds:
        cells = [table.get((k, j), [0, 0]) for j in links]
        if sum(a + b for a, b in cells) == 0:
            continue
        print(f"| {k} | " + " | ".join(f"{a}+{b}" for a, b in cells) + f" | {sum(a + b for a, b in cells)} |")
    print(
        "\n(wi: R^T w of the parent; w: w, its products and differences; wd, vd: accelerations;"
        " Up, a: U_parent p + vd_parent (link 2: a point's acceleration in the basis (u, v, z));"
        " A, B, C, D, J: links 2 and 3's inertia seen along joint 1's axis u (their Euler moments'"
        " two projections; A of both summed in link 2's row); W: link 2's own rates on u and v; p: link 3's origin along u and v;"
        " U: skew(wd) + skew(w)^2; F, N: the link's force and moment;"
        " Rf: a child's force rotated; f, n: inward sums; q: q + th of a leaf link's turned frame, q2 + q3 of"
        " the parallel joints; tau: joint 1's torque, formed from the moments of links 1-3 directly)\n"
    )


# tau alone by the customized Newton-Euler in a fresh process: SymPy's first sum (its
# one-time import of sympy.tensor inside Add.flatten, paid by any first SymPy sum in a
# process), then the first build, then the median of 9 more (CPU time, seconds), printed as
# "sympy_first_sum first median"
_TAU_IN_A_PROCESS = """
import statistics, time, warnings
import sympy
import armdyn
x, y = sympy.symbols("x y")
t0 = time.process_time()
x + y
first_sum = time.process_time() - t0
from armdyn.programs.customized_ne import customized_newton_euler, standard_parameters
from armdyn.programs.grouping import grouped_parameters
with warnings.catch_warnings():
    warnings.simplefilter("ignore")
    robot = armdyn.load("puma560-craig", strict=False)
def tau_program():
    params, definitions = standard_parameters(robot)
    grouped, _ = grouped_parameters(robot, params, definitions)
    customized_newton_euler(robot, parameters=grouped)
times = []
for _ in range(10):
    t0 = time.process_time()
    tau_program()
    times.append(time.process_time() - t0)
print(first_sum, times[0], statistics.median(times[1:]))
"""


def tau_in_processes(n: int) -> None:
    """tau alone (the time table's row) in ``n`` fresh processes, ``PYTHONHASHSEED`` 0 to
    n-1: the repeated builds' median depends on which expressions stay in SymPy's cache
    (1000 entries unless ``SYMPY_CACHE_SIZE`` says otherwise), which depends on the hash
    seed; the first build is what a user's one call costs once SymPy has made its first sum
    (that sum's one-time import is timed on its own, the first column)."""
    import os
    import subprocess
    import sys

    print(
        f"## tau alone by the customized Newton-Euler in {n} fresh processes, puma560-craig "
        f"(CPU s; SYMPY_CACHE_SIZE={os.environ.get('SYMPY_CACHE_SIZE', 'default')})\n"
    )
    print("| PYTHONHASHSEED | SymPy's first sum (one-time import) | first build | median of the next 9 | target |")
    print("|---|---|---|---|---|")
    sums, firsts, medians = [], [], []
    for seed in range(n):
        env = dict(os.environ, PYTHONHASHSEED=str(seed))
        out = subprocess.run(
            [sys.executable, "-c", _TAU_IN_A_PROCESS], env=env, check=True, capture_output=True, text=True
        ).stdout.split()
        first_sum, first, median = (float(v) for v in out)
        sums.append(first_sum)
        firsts.append(first)
        medians.append(median)
        print(f"| {seed} | {first_sum:.3f} | {first:.3f} | {median:.3f} | <= 0.1 |")
    print(
        f"| all | {min(sums):.3f}-{max(sums):.3f} | {min(firsts):.3f}-{max(firsts):.3f} | "
        f"{min(medians):.3f}-{max(medians):.3f} | <= 0.1 |\n"
    )


def numeric(n_states: int, repeat: int) -> None:
    robot = load("puma560")
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        robot = robot.bind()
    lib = printing.compile(robot, what="tau")
    rng = np.random.default_rng(0)
    Q, QD, QDD = (rng.uniform(-np.pi, np.pi, (n_states, robot.dof)) for _ in range(3))
    ref = armdyn.rnea(robot, Q, QD, QDD, threads=1)
    got = lib.tau(Q, QD, QDD)
    err = np.abs(got - ref).max() / np.abs(ref).max()
    assert err < 1e-12, err
    # the same code with the AVX2 clone switched off: SSE2 only, like the Rust core's build
    sse2 = printing.compile(lib.code, flags=["-DARMDYN_NO_CLONES"])
    assert np.abs(sse2.tau(Q, QD, QDD) - got).max() == 0.0
    t_c, t_rust, t_sse2 = [], [], []
    for _ in range(repeat):
        for fn, runs in (
            (lambda: lib.tau(Q, QD, QDD), t_c),
            (lambda: armdyn.rnea(robot, Q, QD, QDD, threads=1), t_rust),
            (lambda: sse2.tau(Q, QD, QDD), t_sse2),
        ):
            t0 = time.perf_counter()
            fn()
            runs.append(time.perf_counter() - t0)
    c, r = statistics.median(t_c), statistics.median(t_rust)
    print(
        f"## Generated C vs the Rust core, puma560 tau, {n_states:.0e} states, one thread "
        f"(runs alternating, {repeat} each)\n"
    )
    print("                               median        best")
    print(f"generated C (cc -O2, ctypes): {c * 1e9 / n_states:7.1f} ns/state {min(t_c) * 1e9 / n_states:7.1f} ns/state")
    print(
        f"armdyn.rnea(threads=1):       {r * 1e9 / n_states:7.1f} ns/state {min(t_rust) * 1e9 / n_states:7.1f} ns/state"
    )
    s2 = statistics.median(t_sse2)
    print(
        f"generated C, SSE2 only:       {s2 * 1e9 / n_states:7.1f} ns/state {min(t_sse2) * 1e9 / n_states:7.1f} ns/state"
        f"   (-DARMDYN_NO_CLONES; ratio to Rust: median {s2 / r:.2f}, best {min(t_sse2) / min(t_rust):.2f})"
    )
    # each round's own ratio too: C and Rust run back to back there, so a slow spell of the
    # machine hits both alike
    rounds = statistics.median(a / b for a, b in zip(t_c, t_rust))
    print(
        f"ratio generated C / Rust rnea: median {c / r:.2f}, best {min(t_c) / min(t_rust):.2f}, "
        f"median of the rounds' ratios {rounds:.2f}  (max rel. difference {err:.1e})"
    )


def every_arm() -> None:
    """Operation counts of every bundled arm's generated tau and g (grouped parameters,
    leaves turned) and of tau in the base parameters (up to 6 dof: the 7-dof arms' base
    parameters take minutes)."""
    from armdyn.io import bundled_robots

    print("## Operation counts of every bundled arm (mul + add)\n")
    print("| arm | dof | tau | g | tau, base parameters |")
    print("|---|---|---|---|---|")
    for entry in bundled_robots():
        robot = load(entry["name"])
        counts = printing.codegen(robot, what="tau,g").op_counts
        base = "-"
        if robot.dof <= 6 and importlib.util.find_spec("armdyn.identification") is not None:
            base = printing.codegen(robot, what="tau", base=True).op_counts["tau"]["total"]
        print(f"| {entry['name']} | {robot.dof} | {counts['tau']['total']} | {counts['g']['total']} | {base} |")


LEDGER = os.path.join(os.path.dirname(os.path.abspath(__file__)), "op_counts.json")
#: what the ledger counts, per arm and parameter set
LEDGER_QUANTITIES = ("tau", "g", "M", "C")


def write_ledger(path: str = LEDGER) -> None:
    """The operation-count ledger: ``codegen(...).op_counts`` of tau, g, M and C of every
    bundled arm, in the standard (grouped) and in the base parameters, as JSON
    ``{"arms": {arm: {"dof": n, "standard": {quantity: counts}, "base": {...}}}}``.
    tests/test_op_ledger.py recomputes it and fails when a count differs. The 7-dof arms'
    base parameters take minutes (the identification's base-parameter search)."""
    from armdyn.io import bundled_robots

    arms = {}
    for entry in bundled_robots():
        robot = load(entry["name"])
        row = {"dof": robot.dof}
        for key, base in (("standard", False), ("base", True)):
            t = time.perf_counter()
            row[key] = printing.codegen(robot, what=LEDGER_QUANTITIES, base=base).op_counts
            print(f"{entry['name']:14s} {key:8s} {time.perf_counter() - t:6.1f} s", flush=True)
        arms[entry["name"]] = row
    tmp = path + ".tmp"
    with open(tmp, "w") as fh:
        fh.write(ledger_text(arms))
    os.replace(tmp, path)
    print(f"wrote {path}")


def ledger_text(arms: dict) -> str:
    """The ledger as JSON text, one line per arm, parameter set and quantity (a change in
    the counts is a one-line diff)."""
    import re

    ledger = {
        "about": "operation counts per state of armdyn's generated code (mul + add = total; "
        "sympy.count_ops(visual=True) kinds), written by "
        "PYTHONPATH=python python3 benchmarks/bench_codegen.py --ledger",
        "arms": arms,
    }
    text = json.dumps(ledger, indent=1, sort_keys=True)
    # the innermost objects (the counts) on one line each
    return re.sub(r"\{\n\s+([^{}]*?)\n\s*\}", lambda m: "{" + " ".join(m.group(1).split()) + "}", text) + "\n"


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--repeat", type=int, default=5)
    ap.add_argument("--states", type=int, default=100_000)
    ap.add_argument("--skip-numeric", action="store_true")
    ap.add_argument("--numeric-only", action="store_true", help="only the generated C vs the Rust core")
    ap.add_argument("--numeric-repeat", type=int, default=15)
    ap.add_argument(
        "--processes",
        type=int,
        default=0,
        help="only time tau alone in this many fresh processes (PYTHONHASHSEED 0, 1, ...)",
    )
    ap.add_argument("--arms", action="store_true", help="only the operation counts of every bundled arm")
    ap.add_argument(
        "--ledger",
        action="store_true",
        help=f"only write the operation-count ledger ({os.path.relpath(LEDGER)}) of every bundled arm",
    )
    args = ap.parse_args()
    if args.ledger:
        write_ledger()
        return
    if args.arms:
        every_arm()
        return
    if args.processes:
        tau_in_processes(args.processes)
        return
    if args.numeric_only:
        numeric(args.states, args.numeric_repeat)
        return
    have_identification = importlib.util.find_spec("armdyn.identification") is not None
    generation_times(have_identification, args.repeat)  # first: SymPy's caches still cold
    op_count_table(have_identification)
    breakdown()
    if not args.skip_numeric:
        numeric(args.states, args.numeric_repeat)


if __name__ == "__main__":
    main()
