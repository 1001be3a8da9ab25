"""The ``armdyn`` command line.

    armdyn derive ROBOT [--method newton-euler|lagrange|both] [--steps] [--format text|latex|markdown]
    armdyn check ROBOT [--exact | --numeric] [--samples N]
    armdyn robots
    armdyn show ROBOT [--q Q1,Q2,...] [--out arm.png]

ROBOT is a bundled model's name (see ``armdyn robots``) or a model file (.yaml, .urdf).
Bad input prints one line ``armdyn: error: ...`` and exits with status 2, no traceback.
"""

from __future__ import annotations

import argparse
import os
import sys
import time
import warnings

from .errors import ModelError


def _load(source: str, allow_nonphysical: bool = False):
    from .io import load

    return load(source, strict=not allow_nonphysical)


def cmd_derive(args) -> int:
    from .symbolic import check, derive
    from .symbolic.report import derivation_report, unicode_supported

    robot = _load(args.robot, args.allow_nonphysical)
    methods = ["newton-euler", "lagrange"] if args.method == "both" else [args.method]
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
    robot = _load(args.robot, args.allow_nonphysical)
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

    robot = _load(args.robot, args.allow_nonphysical)
    q = None
    if args.q is not None:
        try:
            q = [float(x) for x in args.q.split(",")]
        except ValueError:
            raise ValueError(f"--q must be comma-separated numbers, got {args.q!r}") from None
    print(show(robot, q=q, out=args.out))
    return 0


def build_parser() -> argparse.ArgumentParser:
    p = argparse.ArgumentParser(prog="armdyn", description="Dynamics of robot arms: derive and check equations of motion.")
    sub = p.add_subparsers(dest="command", required=True)

    def robot_arg(sp_):
        sp_.add_argument("robot", help="bundled model name (armdyn robots) or a .yaml/.urdf file")
        sp_.add_argument("--allow-nonphysical", action="store_true",
                         help="load models whose inertias break physical validity, with a warning")

    d = sub.add_parser("derive", help="derive the equations of motion symbolically")
    robot_arg(d)
    d.add_argument("--method", choices=["newton-euler", "lagrange", "both"], default="both")
    d.add_argument("--steps", action="store_true", help="show every intermediate step")
    d.add_argument("--format", choices=["text", "latex", "markdown"], default="text")
    d.add_argument("--timing", action="store_true", help="print derivation times to stderr")
    d.add_argument("--ascii", action="store_true",
                   help="text in plain ASCII (theta1_dot, tau1) instead of Unicode (θ̇₁, τ₁); "
                        "automatic when the terminal cannot print Unicode")
    d.set_defaults(func=cmd_derive)

    c = sub.add_parser("check", help="prove Newton-Euler == Lagrange, M symmetric, tau == M qdd + C qd + g")
    robot_arg(c)
    g = c.add_mutually_exclusive_group()
    g.add_argument("--exact", action="store_true", help="force exact symbolic checks")
    g.add_argument("--numeric", action="store_true", help="force checks at random numeric points")
    c.add_argument("--samples", type=int, default=25, help="random points for numeric checks (at least 1; the report says how many were used)")
    c.set_defaults(func=cmd_check)

    r = sub.add_parser("robots", help="list the bundled robot models")
    r.set_defaults(func=cmd_robots)

    s = sub.add_parser("show", help="table of joints and links, and a picture of the arm")
    robot_arg(s)
    s.add_argument("--q", help="joint values, comma-separated (default: zeros)")
    s.add_argument("--out", help="write a PNG picture of the arm here")
    s.set_defaults(func=cmd_show)
    return p


def _one_line_warning(message, category, filename, lineno, file=None, line=None):
    print(f"armdyn: warning: {message}", file=sys.stderr)


def main(argv: list[str] | None = None) -> int:
    args = build_parser().parse_args(argv)
    shown = warnings.showwarning
    warnings.showwarning = _one_line_warning  # e.g. --allow-nonphysical: one line, no source dump
    try:
        return args.func(args)
    except (ModelError, ValueError, FileNotFoundError) as err:
        print(f"armdyn: error: {err}", file=sys.stderr)
        return 2
    except KeyboardInterrupt:
        return 130
    except BrokenPipeError:  # e.g. `armdyn robots | head`
        sys.stderr.close()
        return 0
    except Exception as err:  # noqa: BLE001 - a bug: one line unless debugging
        if os.environ.get("ARMDYN_DEBUG"):
            raise
        print(f"armdyn: internal error: {type(err).__name__}: {err} (set ARMDYN_DEBUG=1 for a traceback)",
              file=sys.stderr)
        return 3
    finally:
        warnings.showwarning = shown


if __name__ == "__main__":
    sys.exit(main())
