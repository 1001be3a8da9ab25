"""axe-core (Deque's accessibility rules engine, MPL-2.0) for the browser tests of
``armdyn serve``'s pages (tests/test_serve_pages.py).

It is not vendored: a pinned version (:data:`VERSION`) is fetched from the npm
registry with ``npm pack`` into a cache directory (``$ARMDYN_AXE_CACHE``, default
``~/.cache/armdyn-tests``), its tarball checked against the registry's published
SHA-512 (:data:`INTEGRITY`), and only ``axe.min.js`` and the licence kept. .ci/run
fetches it before the tests (``python3 tests/axe.py``); a test run without it fetches
it then; without npm or the registry the tests that need it skip alone, saying why.
``ARMDYN_AXE=/path/to/axe.min.js`` uses a copy at hand.

:func:`run_axe` injects the script into a page (over the DevTools protocol: the page's
Content-Security-Policy does not apply to it) and returns the violations of the WCAG
2.1 A/AA rules and axe's best practices, each as ``(impact, rule id, help, targets)``.
"""

from __future__ import annotations

import base64
import hashlib
import json
import os
import shutil
import subprocess
import sys
import tarfile
import tempfile
from pathlib import Path

VERSION = "4.10.3"
INTEGRITY = "sha512-Xm7bpRXnDSX2YE2YFfBk2FnF0ep6tmG7xPh8iHee8MIcrgq762Nkce856dYtJYLkuIoYZvGfTs/PbZhideTcEg=="
TAGS = ["wcag2a", "wcag2aa", "wcag21a", "wcag21aa", "best-practice"]


def cache_dir() -> Path:
    return Path(os.environ.get("ARMDYN_AXE_CACHE") or Path.home() / ".cache" / "armdyn-tests") / f"axe-core-{VERSION}"


def find_axe() -> Path | None:
    """``axe.min.js`` (``ARMDYN_AXE``, else the cache), or None."""
    env = os.environ.get("ARMDYN_AXE")
    if env:
        return Path(env) if Path(env).is_file() else None
    script = cache_dir() / "axe.min.js"
    return script if script.is_file() else None


def fetch_axe(timeout: float = 180.0) -> Path:
    """Fetch axe-core :data:`VERSION` with ``npm pack`` into :func:`cache_dir` (checked
    against :data:`INTEGRITY`); its ``axe.min.js``. Raises RuntimeError saying why not."""
    npm = shutil.which("npm")
    if npm is None:
        raise RuntimeError("npm is not installed (apt-get install -y npm), so axe-core cannot be fetched")
    target = cache_dir()
    with tempfile.TemporaryDirectory(prefix="armdyn-axe-") as tmp:
        done = subprocess.run(
            [npm, "pack", f"axe-core@{VERSION}", "--pack-destination", tmp, "--silent"],
            capture_output=True,
            text=True,
            timeout=timeout,
            cwd=tmp,
            check=False,
        )
        tarballs = list(Path(tmp).glob("axe-core-*.tgz"))
        if done.returncode != 0 or len(tarballs) != 1:
            raise RuntimeError(f"npm pack axe-core@{VERSION} failed (exit {done.returncode}): {done.stderr[-500:]}")
        data = tarballs[0].read_bytes()
        got = "sha512-" + base64.b64encode(hashlib.sha512(data).digest()).decode()
        if got != INTEGRITY:
            raise RuntimeError(f"axe-core {VERSION}: the tarball's SHA-512 is not the published one ({got})")
        staged = Path(tmp) / "out"
        staged.mkdir()
        with tarfile.open(tarballs[0]) as tar:
            for name, keep in (("package/axe.min.js", "axe.min.js"), ("package/LICENSE", "LICENSE")):
                member = tar.getmember(name)
                (staged / keep).write_bytes(tar.extractfile(member).read())
        target.parent.mkdir(parents=True, exist_ok=True)
        if target.exists():
            shutil.rmtree(target)
        shutil.move(str(staged), target)
    return target / "axe.min.js"


def require_axe() -> Path:
    """axe.min.js, fetched if need be; or skip the calling test (alone) saying why."""
    import pytest

    found = find_axe()
    if found is not None:
        return found
    if os.environ.get("ARMDYN_AXE"):
        pytest.skip(f"ARMDYN_AXE={os.environ['ARMDYN_AXE']} is not a file")
    try:
        return fetch_axe()
    except (RuntimeError, OSError, subprocess.TimeoutExpired) as err:
        pytest.skip(f"axe-core {VERSION} is not at hand: {err}")


def run_axe(page, script: Path) -> list[tuple]:
    """The violations axe finds in ``page`` (a tests/cdp.py Page, loaded):
    ``(impact, rule id, help, first targets)``, worst first."""
    source = script.read_text(encoding="utf-8")
    page.b.call("Runtime.evaluate", {"expression": source, "returnByValue": False}, page.session)
    result = page.eval(
        "axe.run(document, {runOnly: {type: 'tag', values: %s}, resultTypes: ['violations']})"
        ".then(function (r) { return JSON.stringify(r.violations.map(function (v) {"
        " return [v.impact, v.id, v.help, v.nodes.slice(0, 3).map(function (n) { return n.target.join(' '); })]; })); })"
        % json.dumps(TAGS),
        timeout=120,
    )
    order = {"critical": 0, "serious": 1, "moderate": 2, "minor": 3}
    return sorted((tuple(v) for v in json.loads(result)), key=lambda v: order.get(v[0], 4))


if __name__ == "__main__":  # .ci/run: fetch it before the tests
    try:
        print(f"axe-core {VERSION}: {find_axe() or fetch_axe()}")
    except (RuntimeError, OSError, subprocess.TimeoutExpired) as err:
        print(f"warning: {err}; the accessibility checks will skip", file=sys.stderr)
