"""The course's command line: ``armdyn exercise make`` and ``armdyn grade DIR`` (batch).

Exit status of ``armdyn exercise make``: 0 every variant written; 1 some roster rows
refused (each named ``roster.csv:line`` on stderr; the others written); 2 bad input.

Exit status of ``armdyn grade DIR``: 0 every submission graded (whatever its marks);
1 some submission not graded (each named on stderr with the reason: ``error`` for a
file the grader refuses, with its line, ``timeout``, ``memory``, ``crashed``,
``no-variant``, ``duplicate``; all the others are graded and in the gradebook);
2 bad input (a rubric that does not parse, named ``file:line``; no such folder): nothing
graded, nothing written.
"""

from __future__ import annotations

import os
import sys


def add_batch_arguments(parser) -> None:
    """The options of ``armdyn grade DIR`` (a folder argument switches to batch mode)."""
    b = parser.add_argument_group("a whole class (SUBMISSION is a folder)")
    b.add_argument(
        "--gradebook",
        metavar="grades.csv",
        help="write the gradebook here (and grades.json, "
        "summary.html beside it); default grades.csv in the folder's parent",
    )
    b.add_argument(
        "--rubric",
        metavar="rubric.yaml",
        help="points per step or part, for every student (default: with --variants each student's kind's "
        "rubric-<kind>.yaml there, else the default of docs/course.md)",
    )
    b.add_argument(
        "--policy",
        choices=("latest", "best"),
        default="latest",
        help="a student who handed in twice: the latest graded submission (default) or the best",
    )
    b.add_argument("--html-dir", metavar="DIR", help="write one HTML report per student here")
    b.add_argument(
        "--variants",
        metavar="DIR",
        help="the folder armdyn exercise make wrote: grade each submission against its variant's model.yaml",
    )
    b.add_argument("--jobs", type=int, help="submissions graded at once (default: the cores)")
    b.add_argument("--timeout", type=float, default=60.0, help="seconds per submission (default 60)")
    b.add_argument(
        "--memory-mb",
        type=int,
        default=1024,
        help="memory each submission may allocate, MB, beyond what the grader has loaded (default 1024)",
    )
    b.add_argument("--no-cache", action="store_true", help="grade everything again (ignore .armdyn-cache)")
    b.add_argument("--dask", metavar="SCHEDULER", help="grade on this Dask scheduler (address)")
    b.add_argument(
        "--regrade",
        action="store_true",
        help="after the key or the rubric changed: print, per student, the old and new score and the steps "
        "that changed (against the gradebook's previous JSON), and write regrade.csv beside the gradebook",
    )


def cmd_grade_class(args) -> int:
    from .batch import grade_class
    from .rubric import Rubric

    folder = args.submission
    if args.jobs is not None and args.jobs < 1:
        raise ValueError(f"--jobs must be at least 1, got {args.jobs}")
    if args.timeout <= 0:
        raise ValueError(f"--timeout must be positive, got {args.timeout}")
    rubric = Rubric.load(args.rubric) if args.rubric else None
    gradebook = args.gradebook or os.path.join(os.path.dirname(os.path.abspath(folder)), "grades.csv")
    before = None
    if getattr(args, "regrade", False):
        from .regrade import load_previous

        before = load_previous(os.path.splitext(gradebook)[0] + ".json")  # before this run overwrites it
    result = grade_class(
        folder,
        gradebook,
        rubric=rubric,
        html_dir=args.html_dir,
        jobs=args.jobs,
        variants=args.variants,
        timeout=args.timeout,
        memory_mb=args.memory_mb,
        use_cache=not args.no_cache,
        dask=args.dask,
        policy=args.policy,
    )
    for line in result.notes:
        print(f"armdyn: note: {line}", file=sys.stderr)
    for line in result.not_graded:
        print(f"armdyn: not graded: {line}", file=sys.stderr)
    rows = result.gradebook.rows
    graded = sum(1 for r in rows if r["status"] == "graded")
    handed = sum(r["submissions"] for r in rows)
    print(
        f"graded {graded} of {len(rows)} students ({handed} submissions) ({result.cached} unchanged, from the cache) in "
        f"{result.seconds:.1f} s; wrote {gradebook}, {os.path.splitext(gradebook)[0]}.json, "
        f"{os.path.join(os.path.dirname(os.path.abspath(gradebook)), 'summary.html')}"
        + (f" and reports in {args.html_dir}" if args.html_dir else "")
    )
    if before is not None:
        from .regrade import compare, report_lines, to_csv

        changes = compare(before, result.gradebook)
        path = os.path.join(os.path.dirname(os.path.abspath(gradebook)), "regrade.csv")
        with open(path, "w", encoding="utf-8", newline="") as fh:
            fh.write(to_csv(changes))
        print("\n".join(report_lines(changes, len(rows))) + f"\nwrote {path}")
    return 0 if not result.not_graded else 1


def add_exercise_parser(sub) -> None:
    from .kinds import KINDS
    from .proofkinds import PROOF_KINDS
    from .variants import CONVENTIONS

    e = sub.add_parser("exercise", help="make a variant of an exercise per student")
    esub = e.add_subparsers(dest="exercise_command", required=True)
    m = esub.add_parser(
        "make",
        help="write problem.md/.html, model.yaml, solution.md per student or variant",
        description="Exit status: 0 all written, 1 some roster rows refused (named on stderr), 2 bad input.",
    )
    m.add_argument("kind", choices=[*KINDS, *PROOF_KINDS], help="the arm (or proof) of the exercise")
    g = m.add_mutually_exclusive_group(required=True)
    g.add_argument("--count", type=int, help="this many variants, ids v001, v002, ...")
    g.add_argument("--roster", metavar="roster.csv", help="one variant per student (CSV with an 'id' column)")
    m.add_argument("--seed", type=int, default=0, help="the same seed and roster give the same files")
    m.add_argument("--convention", choices=CONVENTIONS, help="use these frames for every variant (default: drawn)")
    m.add_argument("--out", required=True, help="the folder to write into (one sub-folder per id)")
    m.add_argument(
        "--force", action="store_true", help="overwrite variant folders (and the kind's rubric) already there"
    )
    m.set_defaults(func=cmd_exercise_make)


def cmd_exercise_make(args) -> int:
    from .exercise import make_exercise

    result = make_exercise(
        args.kind,
        args.out,
        seed=args.seed,
        count=args.count,
        roster=args.roster,
        convention=args.convention,
        force=args.force,
    )
    for line in result.problems:
        print(f"armdyn: error: {line}", file=sys.stderr)
    from .exercise import rubric_path

    print(
        f"wrote {len(result.written)} variant(s) of '{args.kind}' into {args.out} "
        f"(rubric: {rubric_path(args.out, args.kind)})"
    )
    return 1 if result.problems else 0
