"""The public API is typed (armdyn ships ``py.typed``): mypy passes on the public modules
with the configuration in pyproject.toml, and a user's code sees real types through
``armdyn.<name>`` (a wrong use is reported, which an untyped ``Any`` would let through)."""

from __future__ import annotations

import os
import re
import subprocess
import sys
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parent.parent

CLIENT = """
import numpy as np
import armdyn

robot = armdyn.load("rp-arm")
eom = armdyn.derive(robot, "lagrange")
tau = armdyn.rnea(robot, np.zeros(2), np.zeros(2), np.zeros(2))
report = armdyn.grade("derivation.md")
ok_eom: armdyn.EquationsOfMotion = eom
ok_tau: np.ndarray = tau
wrong_tau: str = tau
wrong_eom: str = eom
wrong_report: str = report
wrong_robot: str = armdyn.load("rp-arm")
"""


def _mypy(*args: str, cwd: Path, cache: Path) -> subprocess.CompletedProcess:
    pytest.importorskip("mypy")
    env = {**os.environ, "PYTHONPATH": str(ROOT / "python"), "MYPY_CACHE_DIR": str(cache / ".mypy_cache")}
    return subprocess.run(
        [sys.executable, "-m", "mypy", *args],
        cwd=cwd,
        env=env,
        capture_output=True,
        text=True,
        timeout=600,
        check=False,
    )


def test_package_is_marked_typed():
    assert (ROOT / "python" / "armdyn" / "py.typed").is_file()
    assert (ROOT / "python" / "armdyn" / "_core.pyi").is_file()  # the compiled extension's names


def test_mypy_passes_on_the_public_modules(tmp_path):
    done = _mypy("--config-file", str(ROOT / "pyproject.toml"), cwd=ROOT, cache=tmp_path)
    assert done.returncode == 0, done.stdout[-4000:] + done.stderr[-2000:]
    assert "Success" in done.stdout


def test_user_code_sees_the_public_types(tmp_path):
    client = tmp_path / "client.py"
    client.write_text(CLIENT, encoding="utf-8")
    done = _mypy("--ignore-missing-imports", "--follow-imports=silent", str(client), cwd=tmp_path, cache=tmp_path)
    lines = {int(m.group(1)) for m in re.finditer(r"client\.py:(\d+): error:", done.stdout)}
    source = CLIENT.splitlines()
    wrong = {i for i, text in enumerate(source, start=1) if text.startswith("wrong_")}
    assert lines == wrong, done.stdout[-4000:]  # every wrong use found, the right ones accepted
