"""The ``armdyn`` command line.

    armdyn derive ROBOT [--method newton-euler|lagrange|both] [--steps] [--format text|latex|markdown|html]
                        [--root-joint free-flyer]
    armdyn check ROBOT [--exact | --numeric] [--samples N]
    armdyn robots
    armdyn show ROBOT [--q Q1,Q2,...] [--out arm.png] [--3d [--frames] --out arm.html]
    armdyn grade SUBMISSION [--robot MODEL] [--json] [--html OUT.html] [--ascii] [--to-yaml] [--show-model]
    armdyn grade DIR --gradebook grades.csv [--rubric R.yaml] [--html-dir DIR] [--variants DIR] [--jobs N]
    armdyn exercise make KIND (--count N | --roster roster.csv) --seed S --out DIR
    armdyn links --roster roster.csv --base-url URL [--db URL] [--renew ID...]
    armdyn serve [--host H] [--port P] [--db URL] [--workers N] [--exercises DIR] [--instructor-token T]
    armdyn codegen ROBOT [--what tau,M,C,g,bias,regressor] [--base] [--lang c|python|numpy] [--bind] [--out DIR]
                   [--root-joint free-flyer]
    armdyn simulate ROBOT --duration T --dt DT [--q0 ...] [--controller pd --target ...] [--plot run.png] [--animate run.gif] [--3d run.html]

ROBOT is a bundled model's name (see ``armdyn robots``) or a model file (.yaml, .urdf, MJCF .xml).
Bad input prints one line ``armdyn: error: ...`` and exits with status 2, no traceback.
Ctrl-C prints ``armdyn: interrupted`` and exits with status 130, writing nothing.
``simulate`` exits with status 4 when the state became NaN/inf (see armdyn.simulate_cli).
"""

from __future__ import annotations

import argparse
import os
import sys
import time
import warnings

from ._interrupt import raise_from_now_on
from .errors import ModelError


def _load(source: str, allow_nonphysical: bool = False, strict: bool = False, trusted: bool = False, root_joint=None):
    """A model file (strict unless --allow-nonphysical) or a bundled model (as published,
    one warning if it is not physical, unless --strict); a .xacro file only with
    --trust-xacro (``trusted``: expanding one runs its Python code); ``root_joint``
    "free-flyer": the root link floats (``armdyn.load``'s option)."""
    from .io import load

    strict_ = True if strict else (False if allow_nonphysical else None)
    return load(source, strict=strict_, trusted=trusted, root_joint=root_joint)


def cmd_derive(args) -> int:
    from .symbolic import check, derive
    from .symbolic.report import derivation_report, unicode_supported

    robot = _load(args.robot, args.allow_nonphysical, args.strict, args.trust_xacro, args.root_joint)
    methods = ["newton-euler", "lagrange"] if args.method == "both" else [args.method]
    if (robot.floating or robot.multi_dof_joints) and args.method == "both":
        methods = ["newton-euler"]
        what = "a floating base" if robot.floating else f"a {robot.multi_dof_joints[0].type} joint"
        print(
            f"armdyn derive: {what} is derived by Newton-Euler only (no Lagrange, no agreement check)",
            file=sys.stderr,
        )
    eoms = []
    for m in methods:
        t0 = time.perf_counter()
        eoms.append(derive(robot, m))
        if args.timing:
            print(f"# {m}: derived in {time.perf_counter() - t0:.3f} s", file=sys.stderr)
    agreement = check(eoms[0], eoms[1], structure=False) if len(eoms) == 2 else None
    ascii_only = args.ascii or not unicode_supported(sys.stdout)
    print(derivation_report(eoms, args.format, steps=args.steps, agreement=agreement, ascii=ascii_only))
    return 0 if agreement is None or agreement else 1


def cmd_check(args) -> int:
    from .symbolic import prove_agreement

    if args.samples < 1:  # before the (slow) derivation: zero samples would check nothing
        raise ValueError(f"--samples must be at least 1, got {args.samples}")
    robot = _load(args.robot, args.allow_nonphysical, args.strict, args.trust_xacro)
    exact = True if args.exact else (False if args.numeric else None)
    report = prove_agreement(robot, exact=exact, samples=args.samples)
    print(report.text())
    return 0 if report else 1


def cmd_robots(args) -> int:
    from .io import bundled_robots

    rows = bundled_robots()
    w = max(len(r["name"]) for r in rows)
    print(f"{'name':<{w}}  dof  {'convention':<12} description")
    for r in rows:
        desc = r.get("description") or "(no description)"
        print(f"{r['name']:<{w}}  {r['dof']:>3}  {r.get('convention') or '':<12} {desc}")
        src = " ".join((r.get("source") or "").split())
        if src:
            src = src if len(src) <= 110 else src[:107] + "..."
            print(f"{'':<{w}}       {'':<12} source: {src}")
    return 0


def cmd_show(args) -> int:
    from .show import show

    robot = _load(args.robot, args.allow_nonphysical, args.strict, args.trust_xacro, args.root_joint)
    q = None
    if args.q is not None:
        try:
            q = [float(x) for x in args.q.split(",")]
        except ValueError:
            raise ValueError(f"--q must be comma-separated numbers, got {args.q!r}") from None
        if robot.floating or robot.multi_dof_joints:
            q = _configuration_q(robot, q)
    if args.three_d:  # a 3-D page (armdyn.viewer) instead of the matplotlib picture
        from ._io_atomic import destination
        from .show import numeric_robot, table
        from .viewer import view

        out = args.out or "arm.html"
        if not out.lower().endswith((".html", ".htm")):
            raise ValueError(f"{out}: --3d writes an HTML page (give a .html name)")
        destination(out)
        robot = numeric_robot(robot)
        page = view(robot, q, frames=args.frames)
        print(table(robot))
        page.save(out)
        print(f"wrote {out}")
        return 0
    print(show(robot, q=q, out=args.out))
    if args.out is not None:
        print(f"wrote {args.out}")
    return 0


def _configuration_q(robot, q: list[float]) -> list[float]:
    """``--q`` of a robot whose configuration holds quaternions (a floating base, spherical or
    floating joints) or a planar joint's (cos, sin): a floating robot's joints alone (the base
    at the origin, unturned) or its whole configuration. A quaternion or pair typed to a few
    digits is normalised when within 1e-4 of unit length (said on stderr); further off it is
    refused, naming it."""
    from .configuration import neutral

    joints = robot.nq - 7 if robot.floating else robot.nq
    if robot.floating and len(q) == joints:
        q = [*neutral(robot)[:7], *q]
    if len(q) != robot.nq:
        if robot.floating:
            raise ValueError(
                f"--q: {len(q)} values for a floating robot with {len(robot.movable_joints)} joints: give the "
                f"{joints} joint coordinates, or {robot.nq} (base position, quaternion x y z w, joints)"
            )
        raise ValueError(
            f"--q: {len(q)} values for '{robot.name}': give {robot.nq} (quaternions x y z w, planar x y cos sin)"
        )
    blocks = [("the base quaternion", 3, 4)] if robot.floating else []
    at = {"spherical": (0, 4), "floating": (3, 4), "planar": (2, 2)}
    for name, kind, iq, _ in robot.configuration_layout:
        if kind in at:
            what = "(cos, sin)" if kind == "planar" else "quaternion"
            blocks.append((f"joint '{name}''s {what}", iq + at[kind][0], at[kind][1]))
    q = list(q)
    for what, start, n in blocks:
        part = q[start : start + n]
        norm = sum(x * x for x in part) ** 0.5
        if abs(norm - 1.0) > 1e-4:
            raise ValueError(f"--q: {what} {part} has length {norm:.6g}, not 1")
        if norm != 1.0:
            print(f"note: {what} normalised (its length was {norm:.9g})", file=sys.stderr)
            q[start : start + n] = [x / norm for x in part]
    return q


def cmd_grade(args) -> int:
    if os.path.isdir(args.submission):  # a folder: the whole class (armdyn.course)
        from .course.cli import cmd_grade_class

        if args.trust_xacro:
            raise ValueError("--trust-xacro is refused for a class folder: a student's model is never trusted")
        return cmd_grade_class(args)
    from .grading import grade
    from .grading.reader import read

    try:
        submission = read(args.submission)
        if args.to_yaml:
            print(submission.to_yaml(), end="")
            return 0
        if args.show_model:
            from .grading.robot_text import show_model

            print(show_model(submission, args.robot), end="")
            return 0
        report = grade(submission, robot=args.robot, trusted=args.trust_xacro)
    except ModelError as err:
        if not args.json:
            raise
        from .grading.text import error_json

        print(error_json(err, args.submission))  # scripts read one JSON object either way
        return 2
    if args.html is not None:  # "" is an error of the writer, not "no report"
        from .grading.html import write_report_html  # all or nothing

        try:
            write_report_html(report, args.html)
        except OSError as exc:
            raise ValueError(f"cannot write {args.html} ({exc.strerror})") from None
    if args.json:
        print(report.to_json())
    else:
        print(report.text(ascii_only=args.ascii))
    return 0 if report.passed else 1


def cmd_serve(args) -> int:
    from .serve.server import run

    return run(args)


def cmd_submissions(args) -> int:
    """``armdyn submissions``: the counted submissions as files (docs/serve.md)."""
    from .serve.handedin import write_handed_in
    from .serve.server import db_url

    written = write_handed_in(db_url(args.db), args.out, args.policy)
    print(f"wrote {len(written)} submission(s) into {args.out}")
    return 0


def cmd_links(args) -> int:
    """``armdyn links``: the roster's personal links, as CSV (docs/serve.md)."""
    from .serve.exercises import catalogue
    from .serve.identity import make_links
    from .serve.server import db_url

    text = make_links(args.roster, db_url(args.db), args.base_url, catalogue(args.exercises), args.renew)
    if args.out:
        fd = os.open(args.out, os.O_WRONLY | os.O_CREAT | os.O_TRUNC, 0o600)  # secrets: owner only
        with os.fdopen(fd, "w", encoding="utf-8") as f:
            f.write(text)
    else:
        print(text, end="")
    return 0


def cmd_codegen(args) -> int:
    from .printing import codegen, write_files

    robot = _load(args.robot, args.allow_nonphysical, args.strict, args.trust_xacro, args.root_joint)
    if args.bind:
        robot = robot.bind()
    code = codegen(robot, what=args.what, lang=args.lang, base=args.base)
    if args.out is None:
        print(code.source)
        return 0
    (path,) = write_files([code], args.out)
    print(f"wrote {path}")
    for what, c in code.op_counts.items():
        print(f"  {code.functions[what]}: {c['mul']} mul, {c['add']} add, {c['sin_cos']} sin/cos")
    if code.parameters:
        print(f"  parameters p[0..{len(code.parameters) - 1}]: {', '.join(s.name for s in code.parameters)}")
    return 0


def cmd_simulate(args) -> int:
    import numpy as np

    from ._io_atomic import destination
    from .simulate_cli import run

    for path, ext in ((args.plot, (".png", ".svg", ".pdf")), (args.animate, (".gif",)), (args.three_d, (".html",))):
        if path is not None:
            destination(path)  # refused before the run: not a regular file, read-only, ""
            if not path.lower().endswith(ext):
                raise ValueError(f"{path}: expected a file name ending in {' or '.join(ext)}")
            folder = os.path.dirname(os.path.abspath(path))
            if not os.path.isdir(folder):
                raise ValueError(f"{path}: folder {folder} does not exist")
    if not (np.isfinite(args.fps) and args.fps > 0):
        raise ValueError(f"--fps must be positive, got {args.fps}")
    return run(args, _load(args.robot, args.allow_nonphysical, args.strict, args.trust_xacro))


def build_parser() -> argparse.ArgumentParser:
    p = argparse.ArgumentParser(
        prog="armdyn", description="Dynamics of robot arms: derive and check equations of motion."
    )
    from . import __version__

    p.add_argument("--version", action="version", version=f"armdyn {__version__}")
    sub = p.add_subparsers(dest="command", required=True)

    def robot_arg(sp_):
        sp_.add_argument("robot", help="bundled model name (armdyn robots) or a .yaml/.urdf/.xml (MJCF) file")
        sp_.add_argument(
            "--allow-nonphysical",
            action="store_true",
            help="load model files whose inertias break physical validity, with a warning",
        )
        sp_.add_argument(
            "--strict",
            action="store_true",
            help="refuse non-physical inertias in bundled models too (they load as published, "
            "with one warning, by default)",
        )
        trust_xacro_arg(sp_)

    def trust_xacro_arg(sp_, what="a .xacro model"):
        sp_.add_argument(
            "--trust-xacro",
            action="store_true",
            help=f"allow {what}: expanding it runs the Python code in its ${{...}} (only for files you trust)",
        )

    d = sub.add_parser("derive", help="derive the equations of motion symbolically")
    robot_arg(d)
    d.add_argument("--method", choices=["newton-euler", "lagrange", "both"], default="both")
    d.add_argument("--steps", action="store_true", help="show every intermediate step")
    d.add_argument("--format", choices=["text", "latex", "markdown", "html"], default="text")
    d.add_argument("--timing", action="store_true", help="print derivation times to stderr")
    d.add_argument(
        "--root-joint",
        choices=["free-flyer"],
        help="the root link floats (a free-flyer base, as armdyn.load(path, root_joint=...)): "
        "Newton-Euler from the base twist, tau = wrench on the base then the joints",
    )
    d.add_argument(
        "--ascii",
        action="store_true",
        help="text in plain ASCII (theta1_dot, tau1) instead of Unicode (θ̇₁, τ₁); "
        "automatic when the terminal cannot print Unicode",
    )
    d.set_defaults(func=cmd_derive)

    c = sub.add_parser("check", help="prove Newton-Euler == Lagrange, M symmetric, tau == M qdd + C qd + g")
    robot_arg(c)
    g = c.add_mutually_exclusive_group()
    g.add_argument("--exact", action="store_true", help="force exact symbolic checks")
    g.add_argument("--numeric", action="store_true", help="force checks at random numeric points")
    c.add_argument(
        "--samples",
        type=int,
        default=25,
        help="random points for numeric checks (at least 1; the report says how many were used)",
    )
    c.set_defaults(func=cmd_check)

    r = sub.add_parser("robots", help="list the bundled robot models")
    r.set_defaults(func=cmd_robots)

    s = sub.add_parser("show", help="table of joints and links, and a picture of the arm")
    robot_arg(s)
    s.add_argument(
        "--q",
        help="joint values, comma-separated (default: zeros); a floating robot's whole configuration "
        "(base position, quaternion x y z w, joints) or its joints alone (the base at the origin)",
    )
    s.add_argument(
        "--root-joint",
        choices=["free-flyer"],
        help="the root link floats (a free-flyer base, as armdyn.load(path, root_joint=...))",
    )
    s.add_argument(
        "--out", "-o", help="write a PNG picture of the arm here (with --3d: an HTML page, default arm.html)"
    )
    s.add_argument(
        "--3d",
        dest="three_d",
        action="store_true",
        help="write a 3-D view (HTML page, three.js inlined: opens offline in a browser) instead of a picture",
    )
    s.add_argument("--frames", action="store_true", help="with --3d: draw each link frame's axes")
    s.set_defaults(func=cmd_show)

    gr = sub.add_parser(
        "grade",
        help="check a student's own derivation step by step (first wrong step)",
        description="Grade a derivation written in Markdown with LaTeX display math (or YAML). "
        "Exit status: 0 every step correct, 1 some step wrong, 2 bad input.",
    )
    gr.add_argument(
        "submission",
        help="the derivation: a .md file (LaTeX display math) or a .yaml file; "
        "or a folder of them: the whole class (see --gradebook)",
    )
    gr.add_argument("--robot", help="the model whose frames the student used (default: the front matter's robot)")
    gr.add_argument("--json", action="store_true", help="print the verdicts as one JSON object")
    gr.add_argument("--html", metavar="OUT.html", help="also write a self-contained HTML report")
    gr.add_argument("--ascii", action="store_true", help="plain ASCII text (no Unicode dots and marks)")
    gr.add_argument("--to-yaml", action="store_true", help="print the steps as read (the YAML format) and stop")
    gr.add_argument(
        "--show-model",
        action="store_true",
        help="print the robot read from the text (YAML, each item with its line; what was assumed) and stop",
    )
    trust_xacro_arg(gr, "a .xacro model given with --robot (never one the front matter names, never for a folder)")
    gr.set_defaults(func=cmd_grade)
    from .course.cli import add_batch_arguments, add_exercise_parser

    add_batch_arguments(gr)
    add_exercise_parser(sub)
    sv = sub.add_parser(
        "serve",
        help="web app: students submit derivations, instructors see the class",
        description="Serve the grading web app (docs/serve.md). Needs: pip install 'armdyn[serve]'.",
    )
    sv.add_argument("--host", default="127.0.0.1", help="address to listen on (default 127.0.0.1)")
    sv.add_argument("--port", type=int, default=8000)
    sv.add_argument("--db", help="sqlite:///PATH (default sqlite:///armdyn-serve.db) or postgresql://USER@HOST/DB")
    sv.add_argument("--workers", type=int, default=2, help="grading processes (default 2)")
    sv.add_argument("--exercises", metavar="DIR", help="variants made by `armdyn exercise make` (DIR/<id>/model.yaml)")
    sv.add_argument("--instructor-token", help="the instructor's login token (or env ARMDYN_INSTRUCTOR_TOKEN)")
    sv.add_argument("--timeout", type=float, default=60.0, help="seconds one grading may take (default 60)")
    sv.add_argument("--memory-mb", type=int, default=2048, help="address-space limit of a worker (default 2048)")
    sv.add_argument(
        "--forwarded-allow-ips",
        default="127.0.0.1",
        help="proxies whose X-Forwarded-* headers are trusted (default 127.0.0.1)",
    )
    sv.add_argument("--roster", metavar="CSV", help="the class: students come by personal link or LTI (docs/serve.md)")
    sv.add_argument(
        "--deadline",
        action="append",
        metavar="[EXERCISE=]WHEN",
        help="ISO 8601 deadline of an exercise (or of all); later submissions are marked late (repeatable)",
    )
    sv.add_argument("--policy", choices=("latest", "best"), default="latest", help="submission the gradebook counts")
    sv.add_argument("--lti", metavar="YAML", help="LTI 1.3: the tool's key and the platforms (docs/serve.md)")
    sv.set_defaults(func=cmd_serve)
    ln = sub.add_parser(
        "links",
        help="print the roster's secret personal links for armdyn serve",
        description="Issue each roster student's personal link for `armdyn serve --roster` (docs/serve.md).",
    )
    ln.add_argument("--roster", required=True, metavar="CSV")
    ln.add_argument("--db", help="the server's database (default sqlite:///armdyn-serve.db)")
    ln.add_argument("--exercises", metavar="DIR", help="the variants the server serves")
    ln.add_argument("--base-url", required=True, help="the server's address as students reach it, https://...")
    ln.add_argument("--renew", nargs="+", metavar="ID", help="replace these students' links ('*': all)")
    ln.add_argument("--out", help="write the CSV here (mode 600) instead of printing it")
    ln.set_defaults(func=cmd_links)
    hi = sub.add_parser(
        "submissions",
        help="write each student's counted submission of armdyn serve as a file, for armdyn grade DIR",
        description="One OUT/<student>.md per student: the submission the gradebook counts (docs/serve.md).",
    )
    hi.add_argument("--db", help="the server's database (default sqlite:///armdyn-serve.db)")
    hi.add_argument("--policy", choices=("latest", "best"), default="latest", help="which submission to write")
    hi.add_argument("--out", required=True, help="the folder to write into")
    hi.set_defaults(func=cmd_submissions)
    cg = sub.add_parser("codegen", help="generate C, Python or NumPy code for tau, M, C, g, the bias, the regressor")
    robot_arg(cg)
    cg.add_argument(
        "--what",
        help="comma-separated: tau,M,C,g,bias,regressor (default tau,M,C,g; tau,M,g,bias for a floating base "
        "or joints of several coordinates, where C does not apply)",
    )
    cg.add_argument("--base", action="store_true", help="in the base parameters (needs armdyn.identification)")
    cg.add_argument("--lang", choices=["c", "python", "numpy"], default="c")
    cg.add_argument("--bind", action="store_true", help="bind the model's published parameter values first")
    cg.add_argument("--out", help="directory to write the source file into (default: print it)")
    cg.add_argument(
        "--root-joint",
        choices=["free-flyer"],
        help="the root link floats (a free-flyer base, as armdyn.load(path, root_joint=...)): the code takes "
        "Pinocchio's q (base position, quaternion x y z w, joints), v and a (base twist, joint rates)",
    )
    cg.set_defaults(func=cmd_codegen)
    m = sub.add_parser(
        "simulate",
        help="integrate the forward dynamics; plot and animate the run",
        description="Integrate the forward dynamics; plot and animate the run. Exit status: 0 done, "
        "2 bad input, 4 the state became NaN/inf (the run stopped there; what was "
        "computed is reported and written), 130 interrupted (nothing written).",
    )
    robot_arg(m)
    m.add_argument("--duration", type=float, required=True, help="seconds")
    m.add_argument("--dt", type=float, required=True, help="fixed step (s)")
    m.add_argument("--method", choices=["rk4", "euler"], default="rk4")
    m.add_argument("--q0", help="initial joint values, comma-separated (one value: all joints; default 0)")
    m.add_argument("--qd0", help="initial joint velocities, comma-separated (default 0)")
    m.add_argument(
        "--controller",
        choices=["pd", "pd-gravity", "computed-torque"],
        help="joint PD, PD with gravity compensation, or computed torque (default: passive)",
    )
    m.add_argument(
        "--target",
        help="controller set point, comma-separated joint values (a ball joint's quaternion x,y,z,w as in --q0; "
        "with a floating base the joints' only)",
    )
    m.add_argument("--kp", help="controller gains, comma-separated (pd: 100 M_ii(target), computed-torque: 25)")
    m.add_argument("--kd", help="controller damping, comma-separated (pd: 20 M_ii(target), computed-torque: 10)")
    m.add_argument("--stride", type=int, help="store every k-th step (default: about 2000 samples)")
    m.add_argument("--plot", help="write q, qd, tau and energy plots here (.png/.svg/.pdf)")
    m.add_argument("--animate", help="write an animation of the arm here (.gif)")
    m.add_argument(
        "--3d",
        dest="three_d",
        metavar="RUN.html",
        help="write a 3-D animation (HTML page: play/pause, time slider; at most 500 frames) here",
    )
    m.add_argument(
        "--fps",
        type=float,
        default=20.0,
        help="animation frame rate (the GIF plays in real time; at most 300 frames, longer runs get longer frames)",
    )
    m.add_argument("--quiet", action="store_true", help="no progress bar")
    m.set_defaults(func=cmd_simulate)
    return p


def _one_line_warning(message, category, filename, lineno, file=None, line=None):
    print(f"armdyn: warning: {message}", file=sys.stderr)


def main(argv: list[str] | None = None) -> int:
    args = build_parser().parse_args(argv)
    shown = warnings.showwarning
    warnings.showwarning = _one_line_warning  # e.g. --allow-nonphysical: one line, no source dump
    try:
        raise_from_now_on()  # Ctrl-C: KeyboardInterrupt, caught below (before: see armdyn._interrupt)
        return args.func(args)
    except (ModelError, ValueError, FileNotFoundError) as err:
        print(f"armdyn: error: {err}", file=sys.stderr)
        return 2
    except KeyboardInterrupt:  # Ctrl-C: outputs are staged in temporary files, so nothing is half-written
        print("armdyn: interrupted", file=sys.stderr)
        return 130
    except BrokenPipeError:  # e.g. `armdyn robots | head`
        sys.stderr.close()
        return 0
    except Exception as err:
        if os.environ.get("ARMDYN_DEBUG"):
            raise
        print(
            f"armdyn: internal error: {type(err).__name__}: {err} (set ARMDYN_DEBUG=1 for a traceback)", file=sys.stderr
        )
        return 3
    finally:
        warnings.showwarning = shown


if __name__ == "__main__":
    sys.exit(main())
