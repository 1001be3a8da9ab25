"""Establish, with plain SymPy, the truth of every equation of the corpus; write or check
the ``<name>.truth.yaml`` sidecars.

    python tests/corpus/truth.py            # write the truth files
    python tests/corpus/truth.py --check    # exit 1 when a truth file disagrees with SymPy

Every equation of a corpus file is transcribed by hand into SymPy in the spec modules
(``specs_*.py``: one :class:`Eq` per equation, its right-hand side as written, in the order
of the file; the line is found from the left-hand side's text, searched from the previous
equation's line on). Its truth is then decided here, never taken from the spec:

* ``right``: equal to the first-principles value (``truth_models``) at random states and
  parameter sets;
* ``wrong``: it differs, and the spec says why (a slip of its own); a spec that calls a
  right equation wrong, or leaves a wrong one unexplained, is an error;
* ``follows``: it differs, but equals what the method gives from the student's own earlier
  values (the spec's ``carried``, computed here from the transcriptions it names): wrong only
  because it carries the slip of the line named in ``from``.

Proof lines (``Proof``) are checked on random rigid bodies (particles) instead.
No armdyn import: this is the independent second opinion the benchmark scores armdyn by.
"""

from __future__ import annotations

import argparse
import math
import random
import sys
from pathlib import Path
from typing import Any

import sympy as sp
import yaml

HERE = Path(__file__).resolve().parent
sys.path.insert(0, str(HERE))

import truth_models  # noqa: E402
from specs_common import Eq, Proof, Stated  # noqa: E402

TRIALS = 4
RTOL = 1e-8
_CHECKED: set[str] = set()


def body(rng: random.Random, n: int = 5) -> dict:
    """A random rigid body: n particles (masses m, positions r about the origin), its
    mass M, mass centre c, positions about the mass centre rc, a point p (the other
    axis' point), an angular velocity w and a unit axis u."""
    m = [rng.uniform(0.2, 2.0) for _ in range(n)]
    r = [sp.Matrix([rng.uniform(-1, 1) for _ in range(3)]) for _ in range(n)]
    M = sum(m)
    c = sum((mi * ri for mi, ri in zip(m, r, strict=True)), sp.zeros(3, 1)) / M
    u = sp.Matrix([rng.uniform(-1, 1) for _ in range(3)])
    return {
        "m": m,
        "r": r,
        "M": M,
        "c": c,
        "rc": [ri - c for ri in r],
        "p": sp.Matrix([rng.uniform(-1, 1) for _ in range(3)]),
        "w": sp.Matrix([rng.uniform(-2, 2) for _ in range(3)]),
        "u": u / u.norm(),
    }


def skew(v):
    """S(v): S(v) x = v x x."""
    return sp.Matrix([[0, -v[2], v[1]], [v[2], 0, -v[0]], [-v[1], v[0], 0]])


def inertia(b: dict, about) -> sp.Matrix:
    """The body's inertia tensor about the point ``about``, by its definition."""
    out = sp.zeros(3, 3)
    for mi, ri in zip(b["m"], b["r"], strict=True):
        d = ri - about
        out += mi * ((d.T * d)[0] * sp.eye(3) - d * d.T)
    return out


def _flat(v) -> list[float]:
    if isinstance(v, sp.MatrixBase):
        return [complex(sp.N(x)).real for x in v]
    if isinstance(v, list | tuple):
        return [x for e in v for x in _flat(e)]
    return [complex(sp.N(v)).real]


def same(a, b) -> bool:
    """a == b numerically (lists of floats); NaN is never equal."""
    fa, fb = _flat(a), _flat(b)
    if len(fa) != len(fb):
        return False
    scale = max([1.0] + [abs(x) for x in fa + fb])
    return all(math.isfinite(x) and math.isfinite(y) and abs(x - y) <= RTOL * scale for x, y in zip(fa, fb))


def _locate(lines: list[str], anchor: str, start: int) -> int:
    for i in range(start, len(lines)):
        if anchor in lines[i]:
            return i
    raise SystemExit(f"anchor {anchor!r} not found after line {start + 1}")


def establish(name: str, spec: dict) -> dict:
    """The truth of every equation of corpus file ``name``, decided with SymPy."""
    path = HERE / name
    lines = path.read_text(encoding="utf-8").splitlines()
    rng = random.Random(name)
    out = {"file": name, "robot": spec["robot"], "equations": []}
    pos = 0
    values: dict[str, Any] = {}
    where: dict[str, int] = {}
    arm = truth_models.arm(spec["robot"]) if any(isinstance(e, Eq) for e in spec["eqs"]) else None
    if arm is not None and arm.name not in _CHECKED:
        arm.check()  # Newton-Euler and Lagrange agree on this arm's torques
        _CHECKED.add(arm.name)
    states = []
    if arm is not None:
        for _ in range(TRIALS):
            states.append({s: sp.Float(rng.uniform(0.3, 1.7)) for s in arm.symbols()})
    bodies = [body(rng) for _ in range(TRIALS)]
    for e in spec["eqs"]:
        i = _locate(lines, e.anchor, pos)
        pos = i + 1
        entry: dict[str, Any] = {"line": i + 1, "lhs": _lhs(e.anchor)}
        if not entry["lhs"]:  # an align* row '&= ...': one more link of the equation above
            prev = out["equations"][-1]
            entry["lhs"] = prev["lhs"]
            entry["continues"] = prev["line"]
        if e.span:
            entry["last_line"] = i + 1 + e.span
        if isinstance(e, Stated):  # a law stated in general symbols: decided by hand
            entry["quantity"] = f"law: {e.law}"
            entry["truth"] = "wrong" if e.why else "not-a-step"
            if e.why:
                entry["why"] = e.why
            out["equations"].append(entry)
            continue
        if isinstance(e, Proof):
            forms = e.rhs if isinstance(e.rhs, list | tuple) else [e.rhs]
            ok = all(same(e.lhs(b), f(b)) for b in bodies for f in forms)
            entry["quantity"] = "proof"
        else:
            entry["quantity"] = e.quantity
            key, _, idx = e.quantity.partition("[")
            truth = arm.Q[key] if not idx else arm.Q[key][int(idx.rstrip("]"))]
            rhs = sp.Matrix(e.rhs) if isinstance(e.rhs, list) else e.rhs
            if e.id:
                values[e.id] = rhs
                where[e.id] = i + 1
            ok = all(same(_at(rhs, s), _at(truth, s)) for s in states)
        label = f"{name}:{i + 1} ({e.anchor})"
        if ok:
            if e.why or getattr(e, "after", ""):
                raise SystemExit(f"{label}: the spec calls it wrong, SymPy finds it right")
            entry["truth"] = "right"
        elif isinstance(e, Eq) and e.after:
            carried = e.carried(values)
            carried = sp.Matrix(carried) if isinstance(carried, list) else carried
            if not all(same(_at(rhs, s), _at(carried, s)) for s in states):
                raise SystemExit(f"{label}: not what the method gives from the earlier values")
            entry["truth"] = "follows"
            entry["from"] = where[e.after]
        elif e.why:
            entry["truth"] = "wrong"
            entry["why"] = e.why
        else:
            raise SystemExit(f"{label}: SymPy finds it wrong, and the spec says nothing about it")
        out["equations"].append(entry)
    return out


def _lhs(anchor: str) -> str:
    """The left-hand side as written: the anchor up to its first '=', without the display
    delimiters and alignment marks."""
    head = anchor.split("=", 1)[0]
    for mark in ("$$", "\\[", "&"):
        head = head.replace(mark, "")
    return head.strip()


def _at(expr, state):
    # xreplace with Floats evaluates at once (subs would re-simplify the big unexpanded trees)
    return expr.xreplace(state) if hasattr(expr, "xreplace") else expr


def all_specs() -> dict[str, dict]:
    """Every corpus file's spec, by file name."""
    import specs_lagrange
    import specs_laws
    import specs_names
    import specs_newton_euler
    import specs_proofs
    import specs_public

    out = {}
    for mod in (specs_newton_euler, specs_lagrange, specs_names, specs_proofs, specs_public, specs_laws):
        out.update(mod.SPECS)
    return out


def dump(truth: dict) -> str:
    """The truth file's text."""
    head = (
        "# The truth of every equation of this corpus file, established by tests/corpus/truth.py\n"
        "# with plain SymPy (first principles, random states). Do not edit: run truth.py.\n"
    )
    return head + yaml.safe_dump(truth, sort_keys=False, allow_unicode=True, width=1000)


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--check", action="store_true", help="compare with the truth files instead of writing them")
    ap.add_argument("files", nargs="*", help="only these corpus files (names)")
    args = ap.parse_args(argv)
    specs = all_specs()
    names = args.files or sorted(specs)
    bad = 0
    for name in names:
        truth = establish(name, specs[name])
        target = HERE / (name[: -len(".md")] + ".truth.yaml")
        text = dump(truth)
        if args.check:
            if not target.exists() or yaml.safe_load(target.read_text(encoding="utf-8")) != truth:
                print(f"DIFFERS  {target.name}")
                bad += 1
            else:
                print(f"ok       {target.name}")
        else:
            target.write_text(text, encoding="utf-8")
            print(f"wrote    {target.name}")
    missing = sorted(p.name for p in HERE.glob("*.md") if p.name not in specs and p.name != "README.md")
    for m in missing:
        print(f"NO SPEC  {m}")
    return 1 if bad or missing else 0


if __name__ == "__main__":
    sys.exit(main())
