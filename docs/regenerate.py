"""Regenerate the pictures in docs/ and README.md's ``armdyn simulate`` console block.

    PYTHONPATH=python python3 docs/regenerate.py          # from the repository root

One script makes all of them, so they cannot drift apart: the bundled arms' pictures
(``armdyn show``), the falling-UR5 plot and GIF and the console block (``armdyn
simulate``, its output pasted into README.md between the ``armdyn simulate`` fence).
It records what it did in ``docs/regenerate.json``: the commands, the README block, and
the SHA-256 of every picture. ``tests/test_docs_fresh.py`` reruns the simulations
(cheap: no drawing) and compares their output with the README block, and checks that
the pictures are the ones recorded here with these parameters.
"""

from __future__ import annotations

import contextlib
import hashlib
import io
import json
import math
import os
import re
import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent
MANIFEST = ROOT / "docs" / "regenerate.json"

#: picture of each bundled arm: joint values (rad)
PICTURES = {
    "ur5": [0, -1.2, 1.4, -1.8, -1.57, 0],
    "panda": [0, -0.6, 0, -2.2, 0, 1.6, 0.8],
    "iiwa14": [0.3, 0.6, 0, -1.2, 0, 0.8, 0],
    "puma560": [0, math.pi / 4, math.pi, 0, math.pi / 4, 0],  # Corke's nominal pose qn
}

#: the README's simulate examples: CLI arguments (after ``armdyn``); the pictures they
#: write are part of the docs
SIMULATIONS = [
    [
        "simulate",
        "ur5",
        "--duration",
        "3",
        "--dt",
        "1e-3",
        "--q0",
        "0,-0.3,0.3,0,0,0",
        "--plot",
        "docs/ur5-falling.png",
        "--animate",
        "docs/ur5-falling.gif",
    ],
    [
        "simulate",
        "ur5",
        "--duration",
        "4",
        "--dt",
        "1e-3",
        "--controller",
        "pd-gravity",
        "--target",
        "0.4,-1,1,0.2,0.3,0.1",
    ],
]

#: console lines left out of the README (long vectors)
ELIDED = ("q_final", "qd_final")


def _without_outputs(argv: list[str]) -> list[str]:
    """``argv`` without --plot/--animate (the cheap numeric part)."""
    out, skip = [], False
    for a in argv:
        if skip:
            skip = False
        elif a in ("--plot", "--animate"):
            skip = True
        else:
            out.append(a)
    return out


def console(argv: list[str], draw: bool = True) -> list[str]:
    """The console lines of ``armdyn *argv`` (its stdout, run in this process from the
    repository root; ``draw=False``: without writing the pictures, whose lines are then
    left out), long vectors replaced by ``...``."""
    from armdyn.cli import main

    run = argv if draw else _without_outputs(argv)
    buf = io.StringIO()
    here = os.getcwd()
    os.chdir(ROOT)
    try:
        with contextlib.redirect_stdout(buf):
            code = main(run + ["--quiet"])
    finally:
        os.chdir(here)
    if code != 0:
        raise RuntimeError(f"armdyn {' '.join(run)} exited with {code}")
    lines, elided = [], False
    for line in buf.getvalue().splitlines():
        if line.startswith(ELIDED):
            if not elided:
                lines.append("...")
            elided = True
            continue
        if not draw and (line.startswith("wrote ") or line.startswith("GIF: ")):
            continue
        lines.append(line)
    return lines


def block(draw: bool = True) -> list[str]:
    """The README console block: ``$ armdyn ...`` then its output, for each simulation."""
    out = []
    for argv in SIMULATIONS:
        out.append("$ armdyn " + " ".join(argv))
        out += console(argv, draw)
    return out


def readme_block(text: str) -> list[str]:
    """The lines of README.md's ``console`` fence that starts with ``$ armdyn simulate``."""
    m = re.search(r"```console\n(\$ armdyn simulate.*?)```", text, re.S)
    if m is None:
        raise ValueError("README.md: no ```console block starting with '$ armdyn simulate'")
    return m.group(1).rstrip("\n").split("\n")


def sha256(path: Path) -> str:
    return hashlib.sha256(path.read_bytes()).hexdigest()


def pictures() -> list[str]:
    """The docs pictures this script writes (paths relative to the root)."""
    out = [f"docs/{name}.png" for name in PICTURES]
    for argv in SIMULATIONS:
        out += [argv[i + 1] for i, a in enumerate(argv) if a in ("--plot", "--animate")]
    return out


def main() -> int:
    import warnings

    import armdyn
    from armdyn.show import show

    for name, q in PICTURES.items():
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")  # puma560 as published: warned about elsewhere
            show(armdyn.load(name), q=q, out=ROOT / "docs" / f"{name}.png")
    lines = block(draw=True)
    readme = ROOT / "README.md"
    text = readme.read_text()
    old = "\n".join(readme_block(text))
    readme.write_text(text.replace(old, "\n".join(lines), 1))
    manifest = {
        "pictures": PICTURES,
        "simulations": SIMULATIONS,
        "readme_block": lines,
        "sha256": {p: sha256(ROOT / p) for p in pictures()},
    }
    MANIFEST.write_text(json.dumps(manifest, indent=1) + "\n")
    print("\n".join(lines))
    print(f"wrote {', '.join(pictures())}, README.md's simulate block and {MANIFEST.relative_to(ROOT)}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
