"""`armdyn grade` run as a student runs it: a fresh process on this checkout's sources."""

from __future__ import annotations

import os
import subprocess
import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent


def grade_cli(path, *extra, timeout: float = 60):
    """``python -m armdyn grade PATH EXTRA...``; ``timeout`` guards against a hang (the real
    times are a few seconds, mostly start-up)."""
    env = dict(os.environ, PYTHONPATH=str(ROOT / "python") + os.pathsep + os.environ.get("PYTHONPATH", ""))
    return subprocess.run(
        [sys.executable, "-m", "armdyn", "grade", str(path), *extra],
        capture_output=True,
        text=True,
        timeout=timeout,
        env=env,
    )
