"""A class graded: N submissions of exercise 7-4 (the bundled ``rp-arm``) through
``armdyn grade DIR --gradebook --html-dir --jobs J``, timed, with the peak memory of the
whole process tree (the CLI and its forked children, summed, sampled from /proc).

    PYTHONPATH=python python3 benchmarks/bench_course.py [--count 100] [--jobs 2]

Each submission is armdyn's worked solution of ``rp-arm`` in the exercise's frames with
one slip injected at a random step (three in four) or none, under its own student id;
all are different files. The run starts with an empty cache (``--no-cache``). Not a
test: timings depend on the machine and its load.
"""

from __future__ import annotations

import argparse
import os
import resource
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parent.parent


def make_class(folder: Path, count: int, seed: int) -> None:
    import armdyn
    from armdyn.course.solution import inject_slip, solution_markdown, solution_steps

    robot = armdyn.load("rp-arm")
    steps = solution_steps(robot)
    rng = np.random.default_rng(seed)
    for i in range(count):
        mine = steps
        if i % 4:
            mine, _ = inject_slip(steps, rng, robot.q)
        front = {"student": f"s{i:03d}", "robot": "rp-arm", "method": "both"}
        (folder / f"s{i:03d}.md").write_text(solution_markdown(robot, mine, front, "exercise 7-4"))


def tree_rss_kb(pid: int) -> int:
    """Resident memory (kB) of ``pid`` and all its descendants."""
    children: dict[int, list[int]] = {}
    rss: dict[int, int] = {}
    for entry in os.listdir("/proc"):
        if not entry.isdigit():
            continue
        try:
            with open(f"/proc/{entry}/stat") as fh:
                fields = fh.read().rsplit(")", 1)[1].split()
            ppid, pages = int(fields[1]), int(fields[21])
        except (OSError, IndexError, ValueError):
            continue
        children.setdefault(ppid, []).append(int(entry))
        rss[int(entry)] = pages * os.sysconf("SC_PAGE_SIZE") // 1024
    total, todo = 0, [pid]
    while todo:
        p = todo.pop()
        total += rss.get(p, 0)
        todo += children.get(p, [])
    return total


def main() -> int:
    ap = argparse.ArgumentParser()
    ap.add_argument("--count", type=int, default=100)
    ap.add_argument("--jobs", type=int, default=2)
    ap.add_argument("--seed", type=int, default=1)
    args = ap.parse_args()
    with tempfile.TemporaryDirectory() as tmp:
        tmp = Path(tmp)
        subs = tmp / "submissions"
        subs.mkdir()
        make_class(subs, args.count, args.seed)
        cmd = [
            sys.executable,
            "-m",
            "armdyn",
            "grade",
            str(subs),
            "--gradebook",
            str(tmp / "out" / "grades.csv"),
            "--html-dir",
            str(tmp / "reports"),
            "--jobs",
            str(args.jobs),
            "--no-cache",
        ]
        (tmp / "out").mkdir()
        env = {**os.environ, "PYTHONPATH": str(ROOT / "python")}
        t0 = time.perf_counter()
        proc = subprocess.Popen(cmd, env=env, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
        peak = 0
        while proc.poll() is None:
            peak = max(peak, tree_rss_kb(proc.pid))
            time.sleep(0.05)
        seconds = time.perf_counter() - t0
        out, err = proc.communicate()
        usage = resource.getrusage(resource.RUSAGE_CHILDREN)  # the CLI and its (waited) children
        cpu = usage.ru_utime + usage.ru_stime
        reports = len(list((tmp / "reports").glob("*.html")))
        rows = (tmp / "out" / "grades.csv").read_text().count("\n") - 1
    print(out.strip())
    if err.strip():
        print(err.strip(), file=sys.stderr)
    load = os.getloadavg()[0]
    print(
        "| submissions | jobs | wall time (s) | CPU time, all processes (s) | peak RSS, process tree (MB) "
        "| reports | gradebook rows | load average |"
    )
    print("|---|---|---|---|---|---|---|---|")
    print(
        f"| {args.count} | {args.jobs} | {seconds:.1f} | {cpu:.1f} | {peak / 1024:.0f} | {reports} | {rows} "
        f"| {load:.1f} |"
    )
    return proc.returncode


if __name__ == "__main__":
    raise SystemExit(main())
