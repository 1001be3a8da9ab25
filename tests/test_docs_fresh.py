"""README's ``armdyn simulate`` console block and the docs pictures are the ones
docs/regenerate.py makes now: the simulations are rerun (without drawing) and compared
with the README block; the pictures' hashes and the script's parameters are compared
with what the script recorded (docs/regenerate.json) when it last drew them."""

from __future__ import annotations

import hashlib
import json
import re
import sys
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parent.parent
sys.path.insert(0, str(ROOT / "docs"))
import regenerate  # noqa: E402

NUMBER = re.compile(r"[-+]?\d+\.?\d*(?:[eE][-+]?\d+)?")


def _same_line(shown: str, fresh: str):
    """Same words; integers equal, other numbers to 4 significant digits (the last printed
    digit of a drift may differ across SIMD kernels)."""
    assert NUMBER.sub("#", shown) == NUMBER.sub("#", fresh), (shown, fresh)
    for a, b in zip(NUMBER.findall(shown), NUMBER.findall(fresh)):
        if re.fullmatch(r"[-+]?\d+", a):
            assert a == b, (shown, fresh)
        else:
            assert float(a) == pytest.approx(float(b), rel=1e-3, abs=1e-12), (shown, fresh)


def test_readme_simulate_block_is_current():
    readme = regenerate.readme_block((ROOT / "README.md").read_text())
    shown = [line for line in readme if not line.startswith(("wrote ", "GIF: "))]
    fresh = regenerate.block(draw=False)
    assert len(shown) == len(fresh), "\n".join(["README:", *shown, "now:", *fresh])
    for a, b in zip(shown, fresh):
        _same_line(a, b)


def test_pictures_are_the_recorded_ones():
    manifest = json.loads(regenerate.MANIFEST.read_text())
    # the script's parameters are those the pictures were drawn with
    assert manifest["pictures"] == json.loads(json.dumps(regenerate.PICTURES))
    assert manifest["simulations"] == regenerate.SIMULATIONS
    assert manifest["readme_block"] == regenerate.readme_block((ROOT / "README.md").read_text())
    assert sorted(manifest["sha256"]) == sorted(regenerate.pictures())
    for path, digest in manifest["sha256"].items():
        assert hashlib.sha256((ROOT / path).read_bytes()).hexdigest() == digest, f"{path} changed since it was drawn"
