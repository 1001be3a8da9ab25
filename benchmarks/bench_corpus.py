"""How well `armdyn grade` reads and judges derivations in the field's notations.

    python benchmarks/bench_corpus.py                 # tests/corpus/
    python benchmarks/bench_corpus.py --dir DIR ...   # and any other directory of .md + .truth.yaml
    python benchmarks/bench_corpus.py --no-corpus --dir DIR   # that directory only
    python benchmarks/bench_corpus.py --no-robot      # each file with its `robot:` line removed

Every ``X.md`` with a sidecar ``X.truth.yaml`` (written by ``tests/corpus/truth.py`` with
plain SymPy, independently of armdyn) is graded in process with ``armdyn.grade``. Each
step the grader reports is matched to the truth's equation by line (an equation spans
``line`` .. ``last_line``). Per file and in total it prints:

* equations: how many the truth file lists;
* read: equations with a step whose status is not ``unrecognised``;
* agree: read equations whose verdicts agree with the truth (neither of the two below);
* false alarms: a ``wrong`` / ``follows-from-earlier-error`` verdict on a ``right`` equation;
* missed: ``correct`` / ``correct-by-convention`` / ``correct-but-unsupported`` on a ``wrong``
  or ``follows`` equation;
* slips found: ``wrong`` equations given ``wrong`` at their line;
* refused: the grader raised (what ``armdyn grade`` exits 2 for);
* steps the grader reported at lines no truth equation spans;
* the median time per file.

Targets: >= 95 % of equations read, every slip found at its line, no false alarm.

With ``--no-robot`` each file is graded with its front matter's ``robot:`` line made a
comment (lines kept), so the model is the one read from the text (docs/grading.md, "The
robot read from the text"); a file whose robot cannot be read counts as refused, and the
time reading the model takes is printed too. Targets then: >= 75 % of equations read,
<= 2 % of the verdicts wrong (false alarms and missed), reading the model < 0.5 s.
"""

from __future__ import annotations

import argparse
import re
import statistics
import sys
import tempfile
import time
from dataclasses import dataclass, field
from pathlib import Path

import yaml

ROOT = Path(__file__).resolve().parent.parent
CORPUS = ROOT / "tests" / "corpus"

RIGHT_OK = {"correct", "correct-by-convention", "correct-but-unsupported"}
FLAGGED = {"wrong", "follows-from-earlier-error"}
PASSES = {"correct", "correct-by-convention"}


@dataclass
class FileScore:
    """One corpus file's score."""

    name: str
    equations: int = 0
    read: int = 0
    right_eqs: int = 0
    slips: int = 0
    slips_found: int = 0
    follows: int = 0
    false_alarms: list = field(default_factory=list)
    missed: list = field(default_factory=list)
    refused: str = ""
    seconds: float = 0.0
    extra: int = 0  # steps at lines no truth equation spans (prose read as an equation?)
    agree: int = 0  # read equations whose verdict agrees with the truth
    model_seconds: float = 0.0  # --no-robot: reading the model from the text
    steps: int = 0  # equations that are dynamics steps (truth not "not-a-step")
    steps_read: int = 0


def pairs(directory: Path):
    """(markdown, truth) pairs of a directory, by name."""
    for md in sorted(directory.glob("*.md")):
        truth = md.with_name(md.name[: -len(".md")] + ".truth.yaml")
        if truth.exists():
            yield md, truth


# a line that only opens a display (the grader may report an equation at its block's opener)
_OPENER = re.compile(r"^\s*(\$\$|\\\[|\\begin\{[A-Za-z*]+\}|```math)\s*$")


def spans(equations, lines: list[str]) -> list[tuple[int, int]]:
    """(first, last) line of each truth equation: its lines, and the opener lines just above
    the first when it is the block's first equation."""
    out = []
    for e in equations:
        first = e["line"]
        while first > 1 and _OPENER.match(lines[first - 2]):
            first -= 1
        out.append((first, e.get("last_line", e["line"])))
    return out


def match(steps, equations, lines: list[str]):
    """Steps by the index of the truth equation whose lines hold them."""
    out: dict[int, list] = {}
    bounds = spans(equations, lines)
    for st in steps:
        for k, (first, last) in enumerate(bounds):
            if first <= (st.line or 0) <= last:
                out.setdefault(k, []).append(st)
                break
    return out


def judge(equation: dict, steps: list) -> tuple[bool, str]:
    """(read, problem): problem is '' when the verdicts agree with the truth, else
    'false alarm' or 'missed'. An equation no step reads has no verdict to judge."""
    read = [s for s in steps if s.status != "unrecognised"]
    if not read:
        return False, ""
    statuses = {s.status for s in read}
    truth = equation["truth"]
    if truth == "not-a-step":  # a law stated, a definition, a prose formula: any verdict but wrong is fine
        return True, "false alarm" if statuses & FLAGGED else ""
    if truth == "right":
        return True, "false alarm" if statuses & FLAGGED else ""
    if statuses & RIGHT_OK and not statuses & FLAGGED:
        return True, "missed"
    return True, ""


def without_robot(md: Path, into: Path) -> Path:
    """A copy of ``md`` in ``into`` with its front matter's ``robot:`` line made a comment."""
    lines = md.read_text(encoding="utf-8").split("\n")
    out = into / md.name
    out.write_text("\n".join("# (robot removed)" if ln.startswith("robot:") else ln for ln in lines), "utf-8")
    return out


def score(md: Path, truth_path: Path, no_robot: bool = False) -> FileScore:
    """Grade one file (with its ``robot:`` removed when ``no_robot``) and score it against its truth."""
    import armdyn
    from armdyn.errors import ModelError

    truth = yaml.safe_load(truth_path.read_text(encoding="utf-8"))
    eqs = truth["equations"]
    fs = FileScore(md.name, equations=len(eqs))
    fs.right_eqs = sum(e["truth"] == "right" for e in eqs)
    fs.slips = sum(e["truth"] == "wrong" for e in eqs)
    fs.follows = sum(e["truth"] == "follows" for e in eqs)
    fs.steps = sum(e["truth"] != "not-a-step" for e in eqs)
    graded = md
    if no_robot:
        from armdyn.grading.reader import read
        from armdyn.grading.robot_text import robot_from_text

        graded = without_robot(md, Path(tempfile.mkdtemp(prefix="bench-no-robot-")))
        t0 = time.perf_counter()
        try:
            robot_from_text(read(str(graded)))
        except (ModelError, ValueError, RecursionError):
            pass  # the grading below says why
        fs.model_seconds = time.perf_counter() - t0
    t0 = time.perf_counter()
    try:
        report = armdyn.grade(graded)
    except (ModelError, ValueError, RecursionError) as err:
        fs.seconds = time.perf_counter() - t0
        fs.refused = f"{type(err).__name__}: {str(err).splitlines()[0][:160]}"
        return fs
    fs.seconds = time.perf_counter() - t0
    by_eq = match(report.steps, eqs, md.read_text(encoding="utf-8").splitlines())
    fs.extra = len(report.steps) - sum(len(v) for v in by_eq.values())
    for k, e in enumerate(eqs):
        steps = by_eq.get(k, [])
        read, problem = judge(e, steps)
        fs.read += read
        fs.steps_read += read and e["truth"] != "not-a-step"
        fs.agree += read and not problem
        if problem == "false alarm":
            fs.false_alarms.append(e["line"])
        elif problem == "missed":
            fs.missed.append(e["line"])
        if e["truth"] == "wrong" and any(s.status == "wrong" for s in steps):
            fs.slips_found += 1
    return fs


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--dir", action="append", type=Path, help="also a directory of .md + .truth.yaml (repeatable)")
    ap.add_argument("--no-corpus", action="store_true", help="only the --dir directories, not tests/corpus/")
    ap.add_argument("--no-robot", action="store_true", help="grade each file with its robot: line removed")
    args = ap.parse_args(argv)
    dirs = ([] if args.no_corpus else [CORPUS]) + (args.dir or [])
    scores = [score(md, tr, args.no_robot) for d in dirs for md, tr in pairs(d)]
    if not scores:
        print("no .md with a .truth.yaml found", file=sys.stderr)
        return 2
    w = max(len(s.name) for s in scores)
    head = f"{'file':<{w}}  eqs  read  agree  slips found  false alarms  missed   time"
    print(head)
    print("-" * len(head))
    for s in scores:
        if s.refused:
            print(f"{s.name:<{w}}  {s.equations:>3}  REFUSED ({s.refused})")
            continue
        fa = ",".join(map(str, s.false_alarms)) or "0"
        mi = ",".join(map(str, s.missed)) or "0"
        print(
            f"{s.name:<{w}}  {s.equations:>3}  {s.read:>4}  {s.agree:>5}  {s.slips_found:>2}/{s.slips:<2}"
            f"       {fa:<12}  {mi:<6}  {s.seconds:5.2f}s"
        )
    n = sum(s.equations for s in scores)
    read = sum(s.read for s in scores)
    slips = sum(s.slips for s in scores)
    found = sum(s.slips_found for s in scores)
    fa = sum(len(s.false_alarms) for s in scores)
    missed = sum(len(s.missed) for s in scores)
    refused = sum(bool(s.refused) for s in scores)
    med = statistics.median(s.seconds for s in scores)
    print("-" * len(head))
    print(f"files {len(scores)}, refused {refused}                        (target: 0 refused)")
    print(f"equations {n}, read {read} = {100 * read / n:.1f} %               (target: >= 95 %)")
    steps = sum(s.steps for s in scores)
    if steps != n:  # truth files that mark some equations not-a-step (laws stated, definitions)
        steps_read = sum(s.steps_read for s in scores)
        print(f"  of them dynamics steps {steps}, read {steps_read} = {100 * steps_read / steps:.1f} %")
    agree = sum(s.agree for s in scores)
    print(f"verdicts that agree with the truth {agree}/{read} of the equations read")
    print(f"slips found at their line {found}/{slips}                  (target: all)")
    print(f"false alarms {fa}                                  (target: 0)")
    print(f"missed slips or carried errors {missed}                  (target: 0)")
    print(f"steps at lines the truth does not list {sum(s.extra for s in scores)}")
    print(f"median time per file {med:.2f} s")
    if args.no_robot:
        wrong = fa + missed
        print(f"verdicts wrong {wrong}/{read} = {100 * wrong / max(read, 1):.1f} %            (target: <= 2 %)")
        slowest = max(scores, key=lambda s: s.model_seconds)
        print(
            f"reading the model: median {statistics.median(s.model_seconds for s in scores):.2f} s, "
            f"at most {slowest.model_seconds:.2f} s ({slowest.name})   (target: < 0.5 s)"
        )
    return 0


if __name__ == "__main__":
    sys.exit(main())
