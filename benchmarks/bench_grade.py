"""How long `armdyn grade` takes, as a student runs it (whole process, imports included).

    python3 benchmarks/bench_grade.py [--runs 5]

1. the exercise (examples/grading/rp-arm-exercise.md, all four parts): target under 3 s;
2. a 6-dof derivation: PUMA 560 (published numbers), every Newton-Euler step written out
   from armdyn's own derivation into YAML, then one term added to one step (vc_dot_3):
   target under 10 s. The file is written to a temporary directory (about 2.6 MB: the
   steps are unexpanded expression trees).

3. proofs (grading/proofs): one proof line, the exercise's energy chain
   ``E_rot = 1/2 w^T I w = 1/2 w^T R I R^T w = 1/2 w^cT I^c w^c`` (three links, one wrong, so
   its counterexample search included), checked in process: target median under 0.2 s;
   and all the exercise's proof lines (7-3 and the energy proof) in process;
4. the whole exercise graded in a warm process (a course worker's cost): target under 1 s.

No other tool grades derivations, so there is no side-by-side ratio; for scale the table
also times `armdyn derive rp-arm` (the main job) the same way. Medians of --runs runs.
"""

from __future__ import annotations

import argparse
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import sympy as sp
import yaml

ROOT = Path(__file__).resolve().parent.parent


def puma_submission(path: Path, altered: str = "vc_dot_3") -> None:
    import warnings

    import armdyn

    warnings.simplefilter("ignore")  # the published PUMA inertias break the triangle inequality
    robot = armdyn.load("puma560", strict=False).bind()
    steps = []
    for s in armdyn.derive(robot, "newton-euler").steps:
        i = robot.link_index(s.link)
        key = f"tau_{robot.coordinate_index(robot.parent_joint(s.link)) + 1}" if s.name == "tau" else f"{s.name}_{i}"
        value = s.value
        if key == altered:
            value = value + sp.Matrix([sp.Rational(1, 2) * robot.qd[1] * robot.qd[2], 0, 0])
        steps.append(
            {"step": key, "value": [str(x) for x in value] if isinstance(value, sp.MatrixBase) else str(value)}
        )
    doc = {"robot": "puma560", "method": "newton-euler", "values": "published", "steps": steps}
    path.write_text(yaml.safe_dump(doc, width=10**9))


def timed(argv: list[str], runs: int) -> tuple[float, list[float], str]:
    times, out = [], ""
    for _ in range(runs + 1):  # one warm-up
        t0 = time.perf_counter()
        proc = subprocess.run(argv, capture_output=True, text=True, cwd=ROOT)
        times.append(time.perf_counter() - t0)
        out = proc.stdout
    return statistics.median(times[1:]), times[1:], out


def proof_line_times(runs: int) -> list[tuple[str, float, list[float], float]]:
    """In-process medians: one proof line (the energy chain, after the lines before it),
    and all the exercise's proof lines."""
    sys.path.insert(0, str(ROOT / "python"))
    from armdyn.grading.proofs import check_text
    from armdyn.grading.proofs.checker import ProofChecker
    from armdyn.grading.proofs.regions import proof_regions

    exercise = (ROOT / "examples" / "grading" / "rp-arm-exercise.md").read_text()
    energy = proof_regions(exercise, set())[1]
    one = []
    for _ in range(max(runs, 20) + 1):
        checker = ProofChecker()
        for d in energy[:-1]:  # the lines before the chain name r_i, I_{l_i}, R^c
            checker.display(d, "")
        t0 = time.perf_counter()
        verdicts = checker.display(energy[-1], "")
        one.append(time.perf_counter() - t0)
        if [v.status for v in verdicts] != ["correct", "wrong", "follows-from-earlier-error"]:
            raise SystemExit(f"unexpected verdicts on the energy chain: {verdicts}")
    whole = []
    for _ in range(runs + 1):
        t0 = time.perf_counter()
        check_text(exercise)
        whole.append(time.perf_counter() - t0)
    return [
        (
            "check one proof line (the energy chain: 3 links, 1 wrong + its counterexample)",
            statistics.median(one[1:]),
            one[1:],
            0.2,
        ),
        ("check all the exercise's proof lines (20 links)", statistics.median(whole[1:]), whole[1:], None),
        exercise_in_process(runs),
    ]


def exercise_in_process(runs: int) -> tuple[str, float, list[float], float]:
    """The whole exercise graded by ``armdyn.grade`` in a warm process (what a course's
    worker or the web app pays per submission): target median under 1 s."""
    import armdyn

    path = ROOT / "examples" / "grading" / "rp-arm-exercise.md"
    times = []
    for _ in range(runs + 1):  # the first run warms SymPy's caches and the model's terms
        t0 = time.perf_counter()
        armdyn.grade(str(path))
        times.append(time.perf_counter() - t0)
    return ("grade the exercise (46 equations, proofs checked)", statistics.median(times[1:]), times[1:], 1.0)


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--runs", type=int, default=5)
    args = ap.parse_args()
    py = [sys.executable, "-m", "armdyn"]
    with tempfile.TemporaryDirectory() as tmp:
        puma = Path(tmp) / "puma560-steps.yaml"
        puma_submission(puma)
        cases = [
            ("armdyn derive rp-arm (for scale)", py + ["derive", "rp-arm"], None),
            (
                "grade the exercise (rp-arm, 46 equations, proofs checked)",
                py + ["grade", "examples/grading/rp-arm-exercise.md"],
                3.0,
            ),
            (
                f"grade PUMA 560, 54 steps, one altered ({puma.stat().st_size / 1e6:.1f} MB)",
                py + ["grade", str(puma)],
                10.0,
            ),
        ]
        print("| case | median wall time (s) | runs | target |\n|---|---|---|---|")
        for label, argv, target in cases:
            med, times, out = timed(argv, args.runs)
            spread = f"{min(times):.2f}-{max(times):.2f}"
            print(f"| {label} | {med:.2f} ({spread}) | {args.runs} | {'' if target is None else f'< {target:g} s'} |")
            if "grade" in argv and "first wrong step" not in out:
                raise SystemExit(f"unexpected output of {' '.join(argv)}:\n{out}")
        for label, med, times, target in proof_line_times(args.runs):
            spread = f"{min(times):.3f}-{max(times):.3f}"
            print(
                f"| {label}, in process | {med:.3f} ({spread}) | {len(times)} | "
                f"{'' if target is None else f'< {target:g} s'} |"
            )


if __name__ == "__main__":
    main()
